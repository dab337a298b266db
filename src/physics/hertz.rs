//! Hertz theory of the dry circular contact (docs/model.md section 2) and the equivalent
//! solid that replaces ball and disc in the elastic model (docs/model.md section 6).
use std::f64::consts::PI;

/// An isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub e: f64,
    /// Poisson's ratio nu (dimensionless).
    pub nu: f64,
}

impl Material {
    /// A material from Young's modulus `e` (Pa) and Poisson's ratio `nu`.
    pub fn new(e: f64, nu: f64) -> Self {
        Material { e, nu }
    }

    /// Plane-strain compliance (1 - nu^2)/E (1/Pa).
    pub fn plane_strain_compliance(&self) -> f64 {
        (1.0 - self.nu * self.nu) / self.e
    }

    /// Lamé's first parameter lambda = E nu / ((1 + nu)(1 - 2 nu)) (Pa).
    pub fn lame_lambda(&self) -> f64 {
        self.e * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
    }

    /// Shear modulus mu = E / (2 (1 + nu)) (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.e / (2.0 * (1.0 + self.nu))
    }
}

/// Reduced (effective) modulus E' of the pair (Pa):
/// 2/E' = (1 - nu_B^2)/E_B + (1 - nu_D^2)/E_D.
///
/// This is the convention of Hamrock & Dowson and of the paper (Table 1: E' = 230.77 GPa
/// for steel on steel); note E' = 2 E* with the E* of Johnson's *Contact Mechanics*.
pub fn reduced_modulus(b: Material, d: Material) -> f64 {
    2.0 / (b.plane_strain_compliance() + d.plane_strain_compliance())
}

/// The equivalent solid of docs/model.md section 6: one elastic body whose surface
/// displacement under a pressure equals the sum of the two bodies' displacements.
///
/// Solves (1 - nu_eq^2)/E_eq = sum_i (1 - nu_i^2)/E_i and
/// (1 + nu_eq)/E_eq = sum_i (1 + nu_i)/E_i, i.e. with A and B the two sums:
/// nu_eq = 1 - A/B, E_eq = (1 + nu_eq)/B.
///
/// 1 - nu_eq is a weighted mean of the 1 - nu_i (weights (1 + nu_i)/E_i > 0), so nu_eq lies
/// between the two Poisson ratios: it is < 0.5 whenever both are. Same material twice gives
/// E_eq = E/2, nu_eq = nu.
pub fn equivalent_solid(b: Material, d: Material) -> Material {
    let a = b.plane_strain_compliance() + d.plane_strain_compliance();
    let bb = (1.0 + b.nu) / b.e + (1.0 + d.nu) / d.e;
    let nu = 1.0 - a / bb;
    Material { e: (1.0 + nu) / bb, nu }
}

/// The dry Hertz solution of a ball of radius R on a flat disc (circular contact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// Hertz contact radius a = (3 L R / (2 E'))^(1/3) (m).
    pub a: f64,
    /// Maximum Hertz pressure p_H = 3 L / (2 pi a^2) (Pa).
    pub ph: f64,
    /// Reduced modulus E' (Pa), see [`reduced_modulus`].
    pub e_prime: f64,
    /// Normal load L (N).
    pub load: f64,
    /// Reduced radius of curvature R (m); R = R_B for a ball on a flat disc.
    pub radius: f64,
}

impl Hertz {
    /// Hertz solution for normal load `load` (N), radius `radius` (m, R_B), ball and disc
    /// materials.
    pub fn new(load: f64, radius: f64, ball: Material, disc: Material) -> Self {
        Self::from_reduced_modulus(load, radius, reduced_modulus(ball, disc))
    }

    /// Hertz solution from the reduced modulus E' directly.
    pub fn from_reduced_modulus(load: f64, radius: f64, e_prime: f64) -> Self {
        let a = (3.0 * load * radius / (2.0 * e_prime)).cbrt();
        let ph = 3.0 * load / (2.0 * PI * a * a);
        Hertz { a, ph, e_prime, load, radius }
    }

    /// Hertz pressure p(x, z) = p_H sqrt(1 - (x^2 + z^2)/a^2) inside the contact, 0 outside
    /// (Pa); x, z in m.
    pub fn pressure(&self, x: f64, z: f64) -> f64 {
        let s = 1.0 - (x * x + z * z) / (self.a * self.a);
        if s > 0.0 {
            self.ph * s.sqrt()
        } else {
            0.0
        }
    }

    /// Mutual approach of the two bodies delta = a^2 / R (m).
    pub fn approach(&self) -> f64 {
        self.a * self.a / self.radius
    }

    /// Mean contact pressure p_m = L / (pi a^2) = 2 p_H / 3 (Pa).
    pub fn mean_pressure(&self) -> f64 {
        self.load / (PI * self.a * self.a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::test_util::rel;

    const STEEL: Material = Material { e: 210e9, nu: 0.3 };

    #[test]
    fn table1_hertz() {
        let h = Hertz::new(1500.0, 0.08, STEEL, STEEL);
        assert!(rel(h.e_prime, 230.77e9) < 1e-4, "E' = {}", h.e_prime);
        assert!(rel(h.a, 0.92052e-3) < 1e-4, "a = {}", h.a);
        assert!(rel(h.ph, 0.84522e9) < 1e-4, "p_H = {}", h.ph);
        assert!(rel(h.mean_pressure(), 2.0 / 3.0 * h.ph) < 1e-12);
        assert_eq!(h.pressure(0.0, 0.0), h.ph);
        assert_eq!(h.pressure(h.a, 0.1 * h.a), 0.0);
        assert!(rel(h.pressure(0.6 * h.a, 0.0), 0.8 * h.ph) < 1e-12);
    }

    #[test]
    fn reduced_modulus_steel() {
        // 2/E' = 2 * 0.91 / 210e9  ->  E' = 210e9 / 0.91
        assert!(rel(reduced_modulus(STEEL, STEEL), 210e9 / 0.91) < 1e-14);
    }

    #[test]
    fn equivalent_solid_same_material() {
        let eq = equivalent_solid(STEEL, STEEL);
        assert!(rel(eq.e, 105e9) < 1e-12);
        assert!(rel(eq.nu, 0.3) < 1e-12);
    }

    #[test]
    fn equivalent_solid_steel_glass() {
        // By hand: A = 0.91/210e9 + 0.96/75e9 = 17.1333e-12, B = 1.3/210e9 + 1.2/75e9
        // = 22.19048e-12; nu = 1 - A/B = 0.227897, E = (1 + nu)/B = 55.3344 GPa.
        let glass = Material::new(75e9, 0.2);
        let eq = equivalent_solid(STEEL, glass);
        assert!(rel(eq.nu, 0.227897) < 1e-5, "nu_eq = {}", eq.nu);
        assert!(rel(eq.e, 55.3344e9) < 1e-5, "E_eq = {}", eq.e);
        assert!(eq.nu < 0.5 && eq.nu > 0.2 && eq.nu < 0.3);
        // Both defining relations hold.
        let a = STEEL.plane_strain_compliance() + glass.plane_strain_compliance();
        let b = 1.3 / 210e9 + 1.2 / 75e9;
        assert!(rel(eq.plane_strain_compliance(), a) < 1e-12);
        assert!(rel((1.0 + eq.nu) / eq.e, b) < 1e-12);
    }

    #[test]
    fn equivalent_solid_poisson_bounded() {
        for &(e1, n1, e2, n2) in &[(1e9, 0.49, 300e9, -0.5), (5e6, 0.499, 1e12, 0.0), (70e9, 0.33, 2e9, 0.45)] {
            let eq = equivalent_solid(Material::new(e1, n1), Material::new(e2, n2));
            assert!(eq.nu < 0.5 && eq.nu >= n1.min(n2) - 1e-12 && eq.nu <= n1.max(n2) + 1e-12);
            assert!(eq.e > 0.0);
        }
    }

    #[test]
    fn lame_constants() {
        assert!(rel(STEEL.shear_modulus(), 210e9 / 2.6) < 1e-14);
        assert!(rel(STEEL.lame_lambda(), 210e9 * 0.3 / (1.3 * 0.4)) < 1e-14);
    }
}
