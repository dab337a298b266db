//! Film-thickness regression formulas for point contacts (Hamrock-Dowson,
//! Nijenbanning-Venner-Moes), used as references for the full-system solution (paper
//! Table 2 compares with Hamrock-Dowson).
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

/// Central film of Nijenbanning, Venner and Moes (1994), "Film thickness in
/// elastohydrodynamically lubricated elliptic contacts", Wear 176, 217-229, for a circular
/// contact (D = 1), in Moes' scaling H = h/(R sqrt(2U)) with M = W (2U)^(-3/4) and
/// L = G (2U)^(1/4) ([`super::scales::MoesParameters`]).
///
/// The fit blends the four asymptotes of the central film: rigid-isoviscous (H_RI ~ M^-2),
/// elastic-isoviscous (H_EI ~ M^(-2/15)), rigid-piezoviscous (H_RP ~ L^(2/3)) and
/// elastic-piezoviscous (H_EP ~ M^(-1/12) L^(3/4)); [`nijenbanning_asymptotes`] gives them.
/// It is a curve fit to numerical films (Barus viscosity, incompressible lubricant), good
/// to a few per cent in the piezoviscous-elastic regime and about 10 % at light loads: it
/// lies 9.5 % above an independent converged multigrid film at M = 10, L = 6 and 1.1 %
/// below one at M = 500, L = 8. A reference, not a check.
pub fn nijenbanning_central(m: f64, l: f64) -> f64 {
    let [h_ri, h_ei, h_rp, h_ep] = nijenbanning_asymptotes(m, l);
    let s = 1.5 * (1.0 + (-1.2 * h_ei / h_ri).exp());
    let isoviscous = (h_ri.powf(1.5) + (h_ei.powi(-4) + 0.1f64.powi(4)).powf(-3.0 / 8.0)).powf(2.0 * s / 3.0);
    let piezoviscous = (h_rp.powi(-8) + h_ep.powi(-8)).powf(-s / 8.0);
    (isoviscous + piezoviscous).powf(1.0 / s)
}

/// The four asymptotes of [`nijenbanning_central`] at D = 1, in Moes' scaling:
/// [H_RI, H_EI, H_RP, H_EP].
pub fn nijenbanning_asymptotes(m: f64, l: f64) -> [f64; 4] {
    // The ellipticity factors at D = 1: (1 + 0.796)^(-15/7), (1 + 0.63)^(-14/25),
    // (1 + 0.691)^(-2/3), (1 + 0.63)^(-7/20).
    [
        145.0 * 1.796f64.powf(-15.0 / 7.0) * m.powi(-2),
        3.18 * 1.63f64.powf(-14.0 / 25.0) * m.powf(-2.0 / 15.0),
        1.29 * 1.691f64.powf(-2.0 / 3.0) * l.powf(2.0 / 3.0),
        1.48 * 1.63f64.powf(-7.0 / 20.0) * m.powf(-1.0 / 12.0) * l.powf(0.75),
    ]
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

    /// Moes-scaled central films of an independent finite-difference multigrid solver
    /// (Barus, incompressible, circular contact, extrapolated from 513^2 and 1025^2 grids):
    /// the fit lies within its stated spread of them, above at light load.
    #[test]
    fn nijenbanning_central_against_independent_films() {
        // (M, L, converged Hc). NVM's own papers give its spread as a few per cent where
        // the film is elastic-piezoviscous and up to about 10 % between the regimes.
        for (m, l, hc, lo, hi) in [(10.0, 6.0, 3.5625, 0.05, 0.12), (500.0, 8.0, 3.714, -0.03, 0.0)] {
            let d = nijenbanning_central(m, l) / hc - 1.0;
            assert!((lo..=hi).contains(&d), "M = {m}, L = {l}: NVM {} against {hc} ({d:+.4})", nijenbanning_central(m, l));
        }
    }

    /// Far inside each regime the blend is its asymptote (the fit is built that way).
    #[test]
    fn nijenbanning_central_tends_to_its_asymptotes() {
        // (M, L, which asymptote, tolerance)
        for (m, l, k, tol) in [(1e5, 1e-3, 1, 0.003), (1e-3, 1e-3, 0, 0.003), (1.0, 1e4, 2, 0.003), (1e6, 100.0, 3, 0.003)] {
            let h = nijenbanning_central(m, l);
            let a = nijenbanning_asymptotes(m, l)[k];
            assert!(rel(h, a) < tol, "M = {m}, L = {l}: {h} against asymptote {k} {a}");
        }
        // There the blend has the published exponents of H_EP: M^(-1/12) L^(3/4).
        let (m, l, e) = (1e12, 300.0, 1e-3);
        let dm = (nijenbanning_central(m * (1.0 + e), l) / nijenbanning_central(m, l)).ln() / (1.0 + e).ln();
        let dl = (nijenbanning_central(m, l * (1.0 + e)) / nijenbanning_central(m, l)).ln() / (1.0 + e).ln();
        assert!((dm + 1.0 / 12.0).abs() < 2e-3 && (dl - 0.75).abs() < 2e-3, "exponents {dm}, {dl}");
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
