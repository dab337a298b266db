//! Film-thickness regression formulas for point contacts, used as references for the
//! full-system solution (paper Table 2 compares with Hamrock-Dowson).
//!
//! Conventions (Hamrock & Dowson 1977, "Isothermal elastohydrodynamic lubrication of point
//! contacts, Part III - Fully flooded results", J. Lubr. Technol. 99(2), 264-276):
//! - U = eta_0 u/(E' R_x) with u the *mean* surface speed (u_a + u_b)/2 (= Ue here);
//! - W = w/(E' R_x^2), G = alpha E', H = h/R_x;
//! - E' = 2 / ((1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b) (same as [`super::hertz::reduced_modulus`]);
//! - k = a/b ellipticity (k = 1 for a circular contact); R_x = R_B for a ball on a flat disc.
//!
//! With these conventions Table 1 gives h_c = 0.247, 0.392, 0.515 um at Ue = 1, 2, 3 m/s,
//! matching the paper's Table 2 column (0.25, 0.40, 0.52) to its rounding.
/// The Hamrock-Dowson dimensionless groups (U, G, W) and ellipticity k.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmGroups {
    /// Speed parameter U = eta_0 u/(E' R_x), u = mean speed.
    pub u: f64,
    /// Materials parameter G = alpha E'.
    pub g: f64,
    /// Load parameter W = w/(E' R_x^2).
    pub w: f64,
    /// Ellipticity k = a/b (1 for circular contacts).
    pub k: f64,
}

impl FilmGroups {
    /// Groups for a circular contact (k = 1) from load (N), mean speed Ue (m/s), eta_0
    /// (Pa.s), alpha (1/Pa), E' (Pa), R_x (m).
    pub fn circular(load: f64, ue: f64, eta0: f64, alpha: f64, e_prime: f64, rx: f64) -> Self {
        FilmGroups { u: eta0 * ue / (e_prime * rx), g: alpha * e_prime, w: load / (e_prime * rx * rx), k: 1.0 }
    }
}

/// Hamrock-Dowson central film thickness (dimensionless, H_c = h_c/R_x):
/// H_c = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^(-0.73 k)).
pub fn hamrock_dowson_central(f: &FilmGroups) -> f64 {
    2.69 * f.u.powf(0.67) * f.g.powf(0.53) * f.w.powf(-0.067) * (1.0 - 0.61 * (-0.73 * f.k).exp())
}

/// Hamrock-Dowson minimum film thickness (dimensionless, H_min = h_min/R_x):
/// H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^(-0.68 k)).
pub fn hamrock_dowson_minimum(f: &FilmGroups) -> f64 {
    3.63 * f.u.powf(0.68) * f.g.powf(0.49) * f.w.powf(-0.073) * (1.0 - (-0.68 * f.k).exp())
}

/// Isoviscous-rigid minimum film thickness (dimensionless, H_min = h_min/R_x), from
/// Brewe, Hamrock & Taylor 1979, "Effect of geometry on hydrodynamic film thickness",
/// J. Lubr. Technol. 101(2), 231-239, as restated in Hamrock, *Fundamentals of Fluid Film
/// Lubrication*: H_hat_min = H_min (W/U)^2 = 128 alpha_r lambda_b^2
/// [0.131 atan(alpha_r/2) + 1.683]^2, lambda_b = (1 + 2/(3 alpha_r))^(-1), with
/// alpha_r = R_y/R_x (= 1 for a circular contact). Quoted from the secondary source; use it
/// as an order-of-magnitude reference for light loads only.
pub fn isoviscous_rigid_minimum(f: &FilmGroups, alpha_r: f64) -> f64 {
    let lambda_b = 1.0 / (1.0 + 2.0 / (3.0 * alpha_r));
    let c = 0.131 * (alpha_r / 2.0).atan() + 1.683;
    let h_hat = 128.0 * alpha_r * lambda_b * lambda_b * c * c;
    h_hat * (f.u / f.w).powi(2)
}

/// SI convenience wrapper: the Hamrock-Dowson films of one operating point, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HamrockDowson {
    /// The dimensionless groups.
    pub groups: FilmGroups,
    /// R_x (m).
    pub rx: f64,
}

impl HamrockDowson {
    /// Circular contact (k = 1): load (N), mean speed Ue (m/s), eta_0 (Pa.s), alpha (1/Pa),
    /// E' (Pa), R_x (m).
    pub fn circular(load: f64, ue: f64, eta0: f64, alpha: f64, e_prime: f64, rx: f64) -> Self {
        HamrockDowson { groups: FilmGroups::circular(load, ue, eta0, alpha, e_prime, rx), rx }
    }
    /// Central film thickness h_c (m).
    pub fn central_film_thickness(&self) -> f64 {
        hamrock_dowson_central(&self.groups) * self.rx
    }
    /// Minimum film thickness h_min (m).
    pub fn minimum_film_thickness(&self) -> f64 {
        hamrock_dowson_minimum(&self.groups) * self.rx
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::test_util::rel;

    fn table1(ue: f64) -> HamrockDowson {
        HamrockDowson::circular(1500.0, ue, 0.012, 23e-9, 210e9 / 0.91, 0.08)
    }

    #[test]
    fn central_matches_paper_table2() {
        for (ue, paper_um) in [(1.0, 0.25), (2.0, 0.40), (3.0, 0.52)] {
            let hc = table1(ue).central_film_thickness() * 1e6;
            assert!((hc - paper_um).abs() < 0.01, "Ue = {ue}: hc = {hc} um, paper {paper_um}");
        }
    }

    #[test]
    fn central_hand_value() {
        // U = 6.5e-13, G = 5307.69, W = 1.015625e-6, k = 1:
        // 2.69 * U^0.67 * G^0.53 * W^-0.067 * (1 - 0.61 e^-0.73) = 3.08304e-6 -> 0.246643 um
        let hc = table1(1.0).central_film_thickness();
        assert!(rel(hc, 0.246643e-6) < 1e-5, "hc = {hc}");
        // Speed exponent 0.67.
        let r = table1(3.0).central_film_thickness() / hc;
        assert!(rel(r, 3f64.powf(0.67)) < 1e-12);
    }

    #[test]
    fn minimum_hand_value() {
        // 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^-0.68) * 0.08 = 0.135417 um
        let hm = table1(1.0).minimum_film_thickness();
        assert!(rel(hm, 0.135417e-6) < 1e-5, "hm = {hm}");
        assert!(hm < table1(1.0).central_film_thickness());
    }

    #[test]
    fn isoviscous_rigid_circular() {
        // alpha_r = 1: lambda_b = 0.6, c = 0.131 atan(0.5) + 1.683 = 1.743738,
        // H_hat = 128 * 0.36 * 1.743738^2 = 140.1118
        let f = FilmGroups { u: 1e-11, g: 0.0, w: 1e-7, k: 1.0 };
        let h = isoviscous_rigid_minimum(&f, 1.0);
        assert!(rel(h / (1e-11f64 / 1e-7).powi(2), 140.1118) < 1e-6);
    }
}
