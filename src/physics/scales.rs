//! Dimensionless scaling (docs/model.md section 5) and the Moes dimensionless groups.
//!
//! The solver works in Hertzian units: X = x/a, Z = z/a, P = p/p_H, H = h R/a^2, and the
//! same scale for the normal displacement, U2 = u2 R/a^2. In these units the Hertzian
//! pressure on a half-space gives a surface displacement -(1 - (X^2 + Z^2)/2) inside the
//! contact and the load balance reads integral P dX dZ = 2 pi / 3.
use std::f64::consts::PI;

use super::hertz::Hertz;

/// Reference scales of the Hertzian non-dimensionalisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    /// Length scale: Hertz radius a (m).
    pub a: f64,
    /// Pressure scale: Hertz pressure p_H (Pa).
    pub ph: f64,
    /// Reduced radius of curvature R (m) (R_B for a ball on a flat disc).
    pub r: f64,
    /// Reduced modulus E' (Pa).
    pub e_prime: f64,
}

impl Scales {
    /// Scales of a Hertz solution.
    pub fn from_hertz(h: &Hertz) -> Self {
        Scales { a: h.a, ph: h.ph, r: h.radius, e_prime: h.e_prime }
    }

    /// Film/displacement scale a^2/R (m): h = H a^2/R.
    pub fn film_scale(&self) -> f64 {
        self.a * self.a / self.r
    }

    /// X = x/a.
    pub fn x_to_dimensionless(&self, x: f64) -> f64 {
        x / self.a
    }
    /// x = X a (m).
    pub fn x_from_dimensionless(&self, x: f64) -> f64 {
        x * self.a
    }
    /// P = p/p_H.
    pub fn p_to_dimensionless(&self, p: f64) -> f64 {
        p / self.ph
    }
    /// p = P p_H (Pa).
    pub fn p_from_dimensionless(&self, p: f64) -> f64 {
        p * self.ph
    }
    /// H = h R/a^2 (also used for the normal displacement: U2 = u2 R/a^2).
    pub fn h_to_dimensionless(&self, h: f64) -> f64 {
        h / self.film_scale()
    }
    /// h = H a^2/R (m).
    pub fn h_from_dimensionless(&self, h: f64) -> f64 {
        h * self.film_scale()
    }

    /// Dimensionless load of the load balance: integral P dX dZ = L/(p_H a^2) = 2 pi/3
    /// for a Hertzian scale pair (a, p_H) of load L.
    pub fn dimensionless_load(&self, load: f64) -> f64 {
        load / (self.ph * self.a * self.a)
    }

    /// Speed parameter lambda_bar = 12 eta_R u_m R^2 / (a^3 p_H) of the dimensionless
    /// Reynolds equation
    /// d/dX(rho_bar H^3/eta_bar dP/dX) + d/dZ(...) = lambda_bar [d(rho_bar Um_bar H)/dX + ...],
    /// with u_m the mean (entrainment) speed in m/s, eta_R in Pa.s and velocities scaled by
    /// u_m (Venner & Lubrecht 2000 write 6 eta_0 u_s R^2/(a^3 p_H), u_s = 2 u_m).
    pub fn speed_parameter(&self, eta_r: f64, um: f64) -> f64 {
        12.0 * eta_r * um * self.r * self.r / (self.a.powi(3) * self.ph)
    }
}

/// The classical dimensionless groups of a point contact and Moes' reduced pair (M, L).
///
/// Convention (Venner & Lubrecht 2000, Moes 1992): U is built on the mean entrainment speed
/// u_m = Ue = (u_1 + u_2)/2, so 2U = eta_R (u_1 + u_2)/(E' R) is Moes' sum-velocity group:
/// - W = L/(E' R^2), U = eta_R Ue/(E' R), G = alpha E';
/// - M = W (2U)^(-3/4), L_M = G (2U)^(1/4).
///
/// W, U, G here are exactly the Hamrock-Dowson groups (see
/// [`crate::physics::film_formulas`]). Table 1 at Ue = 1 m/s: M = 834, L_M = 5.67.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoesParameters {
    /// Load parameter W = L/(E' R^2).
    pub w: f64,
    /// Speed parameter U = eta_R Ue/(E' R).
    pub u: f64,
    /// Material parameter G = alpha E'.
    pub g: f64,
    /// Moes load parameter M = W (2U)^(-3/4).
    pub m: f64,
    /// Moes lubricant parameter L = G (2U)^(1/4).
    pub l: f64,
}

impl MoesParameters {
    /// Groups from load L (N), entrainment speed Ue (m/s), eta_R (Pa.s), alpha (1/Pa),
    /// E' (Pa) and R (m).
    pub fn new(load: f64, ue: f64, eta_r: f64, alpha: f64, e_prime: f64, r: f64) -> Self {
        let w = load / (e_prime * r * r);
        let u = eta_r * ue / (e_prime * r);
        let g = alpha * e_prime;
        MoesParameters { w, u, g, m: w * (2.0 * u).powf(-0.75), l: g * (2.0 * u).powf(0.25) }
    }
}

/// 2 pi / 3: the dimensionless Hertzian load integral P dX dZ.
pub const HERTZ_DIMENSIONLESS_LOAD: f64 = 2.0 * PI / 3.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::hertz::{Hertz, Material};
    use crate::physics::test_util::rel;

    fn table1() -> Hertz {
        let steel = Material::new(210e9, 0.3);
        Hertz::new(1500.0, 0.08, steel, steel)
    }

    #[test]
    fn round_trips_and_scales() {
        let s = Scales::from_hertz(&table1());
        assert!(rel(s.film_scale(), 0.92052e-3f64.powi(2) / 0.08) < 3e-4);
        assert!(rel(s.x_from_dimensionless(s.x_to_dimensionless(1.23e-4)), 1.23e-4) < 1e-15);
        assert!(rel(s.p_from_dimensionless(s.p_to_dimensionless(3e8)), 3e8) < 1e-15);
        assert!(rel(s.h_from_dimensionless(s.h_to_dimensionless(2.5e-7)), 2.5e-7) < 1e-15);
        assert_eq!(s.x_to_dimensionless(s.a), 1.0);
        assert_eq!(s.p_to_dimensionless(s.ph), 1.0);
        // H = h R / a^2: h = 0.25 um -> H = 0.25e-6 * 0.08 / 0.92052e-3^2 = 0.023603
        assert!(rel(s.h_to_dimensionless(0.25e-6), 0.023603) < 1e-4);
        assert!(rel(s.dimensionless_load(1500.0), HERTZ_DIMENSIONLESS_LOAD) < 1e-12);
    }

    #[test]
    fn speed_parameter_table1() {
        // 12 * 0.012 * 1 * 0.08^2 / (0.92052e-3^3 * 0.84522e9) = 1.3979e-3
        let s = Scales::from_hertz(&table1());
        assert!(rel(s.speed_parameter(0.012, 1.0), 1.3979e-3) < 1e-4);
    }

    #[test]
    fn moes_table1() {
        let h = table1();
        let m = MoesParameters::new(1500.0, 1.0, 0.012, 23e-9, h.e_prime, 0.08);
        // W = 1500 / (230.77e9 * 0.0064) = 1.015625e-6; U = 0.012 / (230.77e9 * 0.08) = 6.5e-13;
        // G = 23e-9 * 230.77e9 = 5307.7
        assert!(rel(m.w, 1.015625e-6) < 1e-12);
        assert!(rel(m.u, 6.5e-13) < 1e-12);
        assert!(rel(m.g, 5307.69) < 1e-6);
        // M = W (1.3e-12)^(-3/4) = 834.21, L = G (1.3e-12)^(1/4) = 5.6675
        assert!(rel(m.m, 834.21) < 1e-5, "M = {}", m.m);
        assert!(rel(m.l, 5.6675) < 1e-4, "L = {}", m.l);
    }
}
