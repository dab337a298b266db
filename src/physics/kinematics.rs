//! Surface velocities of ball B and disc D on the contact plane (docs/model.md section 3, the
//! paper's lost Eqs. (1)-(2)).
//!
//! Frame: x rolling direction, y normal (disc towards ball), z transverse; origin at the
//! contact centre. Ball B turns at omega_B about an axis through its centre (0, R_B, 0)
//! with direction (0, cos lambda, sin lambda); disc D turns at omega_D about an axis
//! parallel to y crossing the contact plane at z = -R_D. On y = 0:
//! - U_B = omega_B (R_B sin lambda + z cos lambda), W_B = -omega_B x cos lambda;
//! - U_D = omega_D (R_D + z), W_D = -omega_D x.
//!
//! Given (Ue, SRR, lambda): U_BO = Ue (1 + SRR/2), U_DO = Ue (1 - SRR/2),
//! omega_B = U_BO/(R_B sin lambda), omega_D = U_DO/R_D.
//!
//! Both fields are rigid rotations, so the mean velocity (Um, Wm) has Um = Um(z) and
//! Wm = Wm(x): it is divergence-free, d Um/dx + d Wm/dz = 0.
use std::fmt;

/// Why a [`Kinematics`] could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum KinematicsError {
    /// lambda = 0: the ball would spin infinitely fast (omega_B = U_BO/(R_B sin lambda)).
    ZeroTilt,
    /// lambda outside (0, pi/2] (radians).
    TiltOutOfRange(f64),
    /// A radius (R_B or R_D) is not a positive finite number.
    BadRadius(&'static str, f64),
    /// Ue or SRR is not finite.
    NotFinite(&'static str, f64),
}

impl fmt::Display for KinematicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KinematicsError::ZeroTilt => {
                write!(f, "tilt angle lambda = 0 is singular: the ball spin omega_B = U_BO/(R_B sin lambda) is infinite")
            }
            KinematicsError::TiltOutOfRange(l) => {
                write!(f, "tilt angle lambda = {} deg is outside (0, 90] deg", l.to_degrees())
            }
            KinematicsError::BadRadius(name, v) => write!(f, "{name} = {v} m must be a positive finite number"),
            KinematicsError::NotFinite(name, v) => write!(f, "{name} = {v} must be finite"),
        }
    }
}

impl std::error::Error for KinematicsError {}

/// Velocities of both surfaces at one point of the contact plane (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceVelocities {
    /// U_B: x velocity of the ball surface.
    pub ub: f64,
    /// W_B: z velocity of the ball surface.
    pub wb: f64,
    /// U_D: x velocity of the disc surface.
    pub ud: f64,
    /// W_D: z velocity of the disc surface.
    pub wd: f64,
}

impl SurfaceVelocities {
    /// Mean entrainment velocity Um = (U_B + U_D)/2 (paper Eq. 7).
    pub fn um(&self) -> f64 {
        0.5 * (self.ub + self.ud)
    }
    /// Mean entrainment velocity Wm = (W_B + W_D)/2 (paper Eq. 7).
    pub fn wm(&self) -> f64 {
        0.5 * (self.wb + self.wd)
    }
    /// Sliding velocity dU = U_B - U_D.
    pub fn du(&self) -> f64 {
        self.ub - self.ud
    }
    /// Sliding velocity dW = W_B - W_D.
    pub fn dw(&self) -> f64 {
        self.wb - self.wd
    }
}

/// Rolling, sliding and spinning kinematics of the ball-on-disc contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Entrainment speed Ue = (U_BO + U_DO)/2 (m/s).
    pub ue: f64,
    /// Slide-to-roll ratio SRR = (U_BO - U_DO)/Ue (fraction).
    pub srr: f64,
    /// Tilt angle lambda between the y axis and the ball's rotation axis (rad).
    pub lambda: f64,
    /// Ball radius R_B (m).
    pub r_b: f64,
    /// Radius of the contact track on the disc R_D (m).
    pub r_d: f64,
    /// Ball angular speed omega_B (rad/s).
    pub omega_b: f64,
    /// Disc angular speed omega_D (rad/s).
    pub omega_d: f64,
    /// Ball surface speed at the contact centre U_BO (m/s).
    pub u_bo: f64,
    /// Disc surface speed at the contact centre U_DO (m/s).
    pub u_do: f64,
    /// false for the "uniform" model: U_B = U_BO, U_D = U_DO, W_B = W_D = 0 everywhere.
    pub spin: bool,
}

impl Kinematics {
    /// Full kinematics with spin: Ue (m/s), SRR (fraction), lambda (rad, in (0, pi/2]),
    /// R_B and R_D (m). lambda = 0 is rejected ([`KinematicsError::ZeroTilt`]).
    pub fn new(ue: f64, srr: f64, lambda_rad: f64, r_b: f64, r_d: f64) -> Result<Self, KinematicsError> {
        if !ue.is_finite() {
            return Err(KinematicsError::NotFinite("Ue", ue));
        }
        if !srr.is_finite() {
            return Err(KinematicsError::NotFinite("SRR", srr));
        }
        if lambda_rad == 0.0 {
            return Err(KinematicsError::ZeroTilt);
        }
        if !(lambda_rad > 0.0 && lambda_rad <= std::f64::consts::FRAC_PI_2 * (1.0 + 1e-12)) {
            return Err(KinematicsError::TiltOutOfRange(lambda_rad));
        }
        if !(r_b.is_finite() && r_b > 0.0) {
            return Err(KinematicsError::BadRadius("R_B", r_b));
        }
        if !(r_d.is_finite() && r_d > 0.0) {
            return Err(KinematicsError::BadRadius("R_D", r_d));
        }
        let u_bo = ue * (1.0 + 0.5 * srr);
        let u_do = ue * (1.0 - 0.5 * srr);
        Ok(Kinematics {
            ue,
            srr,
            lambda: lambda_rad,
            r_b,
            r_d,
            omega_b: u_bo / (r_b * lambda_rad.sin()),
            omega_d: u_do / r_d,
            u_bo,
            u_do,
            spin: true,
        })
    }

    /// Uniform kinematics without spin (the classical EHL point contact): U_B = U_BO,
    /// U_D = U_DO, W_B = W_D = 0. Angular speeds are reported as for lambda = 90 deg.
    pub fn uniform(ue: f64, srr: f64, r_b: f64, r_d: f64) -> Result<Self, KinematicsError> {
        let mut k = Self::new(ue, srr, std::f64::consts::FRAC_PI_2, r_b, r_d)?;
        k.spin = false;
        Ok(k)
    }

    /// U_B(x, z) = omega_B (R_B sin lambda + z cos lambda) (m/s); x, z in m.
    pub fn u_b(&self, _x: f64, z: f64) -> f64 {
        if self.spin {
            self.omega_b * (self.r_b * self.lambda.sin() + z * self.lambda.cos())
        } else {
            self.u_bo
        }
    }
    /// W_B(x, z) = -omega_B x cos lambda (m/s).
    pub fn w_b(&self, x: f64, _z: f64) -> f64 {
        if self.spin {
            -self.omega_b * x * self.lambda.cos()
        } else {
            0.0
        }
    }
    /// U_D(x, z) = omega_D (R_D + z) (m/s).
    pub fn u_d(&self, _x: f64, z: f64) -> f64 {
        if self.spin {
            self.omega_d * (self.r_d + z)
        } else {
            self.u_do
        }
    }
    /// W_D(x, z) = -omega_D x (m/s).
    pub fn w_d(&self, x: f64, _z: f64) -> f64 {
        if self.spin {
            -self.omega_d * x
        } else {
            0.0
        }
    }
    /// All four surface velocities at (x, z) (m).
    pub fn at(&self, x: f64, z: f64) -> SurfaceVelocities {
        SurfaceVelocities { ub: self.u_b(x, z), wb: self.w_b(x, z), ud: self.u_d(x, z), wd: self.w_d(x, z) }
    }
    /// Um = (U_B + U_D)/2 (m/s).
    pub fn um(&self, x: f64, z: f64) -> f64 {
        self.at(x, z).um()
    }
    /// Wm = (W_B + W_D)/2 (m/s).
    pub fn wm(&self, x: f64, z: f64) -> f64 {
        self.at(x, z).wm()
    }
    /// dU = U_B - U_D (m/s).
    pub fn du(&self, x: f64, z: f64) -> f64 {
        self.at(x, z).du()
    }
    /// dW = W_B - W_D (m/s).
    pub fn dw(&self, x: f64, z: f64) -> f64 {
        self.at(x, z).dw()
    }
    /// z_c (m) of the spin centre (0, z_c), about which the mean velocity (Um, Wm) turns
    /// at (omega_B cos lambda + omega_D)/2 (Um = Wm = 0 there):
    /// z_c = -2 Ue / (omega_B cos lambda + omega_D). The lubricant's streamlines are circles
    /// about it: where the circle through a point stays inside the pressurised zone, the
    /// Couette flow never leaves the contact (closed streamlines). None without spin
    /// (uniform entrainment).
    pub fn spin_centre(&self) -> Option<f64> {
        self.spin.then(|| -2.0 * self.ue / (self.omega_b * self.lambda.cos() + self.omega_d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spin_centre_where_the_mean_velocity_vanishes() {
        // R_B = 0.08 m, R_D = 0.04 m, Ue = 3 m/s, SRR = 5 %; z_c = -2 Ue/(omega_B cos lambda +
        // omega_D) evaluated by hand (docs/model.md section 3): -1.33999572e-3 m at 0.5 deg
        // (outside the Hertz circle, a = 0.92e-3 m), -6.7550108e-4 m at 0.25 deg (inside).
        for (deg, zc) in [(0.5, -1.33999572e-3), (0.25, -6.7550108e-4)] {
            let k = Kinematics::new(3.0, 0.05, f64::to_radians(deg), 0.08, 0.04).unwrap();
            let z = k.spin_centre().unwrap();
            assert!((z / zc - 1.0).abs() < 1e-7, "{deg} deg: {z} vs {zc}");
            assert!(k.um(0.0, z).abs() < 1e-9 && k.wm(0.0, z).abs() < 1e-12);
        }
        assert!(Kinematics::uniform(3.0, 0.05, 0.08, 0.04).unwrap().spin_centre().is_none());
    }
    use crate::physics::test_util::rel;

    const A: f64 = 0.92052e-3;

    #[test]
    fn reverse_flow_at_half_degree() {
        let k = Kinematics::new(3.0, 0.0, 0.5f64.to_radians(), 0.08, 0.04).unwrap();
        // omega_B = 3/(0.08 sin 0.5 deg) = 4297.2 rad/s; U_B(0,-a) = 3 - 4297.2 a cos(0.5 deg)
        let ub = k.u_b(0.0, -A);
        assert!((ub - (-0.956)).abs() < 1e-3, "U_B = {ub}");
        assert!(rel(k.omega_b, 4297.2) < 1e-4);
        // Entrainment lowest at z = -a, highest at z = +a.
        assert!(k.um(0.0, -A) < k.um(0.0, 0.0) && k.um(0.0, 0.0) < k.um(0.0, A));
    }

    #[test]
    fn centre_values_and_srr() {
        let k = Kinematics::new(2.0, 0.1, 30f64.to_radians(), 0.08, 0.04).unwrap();
        assert!(rel(k.u_bo, 2.1) < 1e-14 && rel(k.u_do, 1.9) < 1e-14);
        let v = k.at(0.0, 0.0);
        assert!(rel(v.ub, 2.1) < 1e-12 && rel(v.ud, 1.9) < 1e-12);
        assert!(rel(v.um(), 2.0) < 1e-12 && rel(v.du(), 0.2) < 1e-12);
        assert!(rel((k.u_bo - k.u_do) / k.ue, 0.1) < 1e-12);
        assert!(rel(k.omega_d, 1.9 / 0.04) < 1e-14);
    }

    #[test]
    fn pure_rolling_at_90_deg() {
        let k = Kinematics::new(1.0, 0.0, 90f64.to_radians(), 0.08, 0.04).unwrap();
        // The ball adds no spin: U_B = U_BO, W_B = 0.
        assert!((k.u_b(A, A) - 1.0).abs() < 1e-12);
        assert!(k.w_b(A, A).abs() < 1e-12);
        // The disc spins: W_D = -omega_D x, U_D = omega_D (R_D + z).
        assert!(rel(k.w_d(A, 0.0), -A / 0.04) < 1e-12);
        assert!(rel(k.u_d(0.0, A), 1.0 + A / 0.04) < 1e-12);
    }

    #[test]
    fn mean_velocity_divergence_free() {
        let k = Kinematics::new(3.0, 0.05, 2f64.to_radians(), 0.08, 0.04).unwrap();
        let h = 1e-6;
        let (x, z) = (0.3e-3, -0.2e-3);
        let div = (k.um(x + h, z) - k.um(x - h, z)) / (2.0 * h) + (k.wm(x, z + h) - k.wm(x, z - h)) / (2.0 * h);
        assert!(div.abs() < 1e-6);
    }

    #[test]
    fn uniform_has_no_spin() {
        let k = Kinematics::uniform(2.0, 0.1, 0.08, 0.04).unwrap();
        let v = k.at(A, -A);
        assert_eq!((v.ub, v.wb, v.ud, v.wd), (2.1, 0.0, 1.9, 0.0));
    }

    #[test]
    fn rejects_bad_input() {
        assert_eq!(Kinematics::new(3.0, 0.0, 0.0, 0.08, 0.04), Err(KinematicsError::ZeroTilt));
        assert!(matches!(Kinematics::new(3.0, 0.0, -0.1, 0.08, 0.04), Err(KinematicsError::TiltOutOfRange(_))));
        assert!(matches!(Kinematics::new(3.0, 0.0, 2.0, 0.08, 0.04), Err(KinematicsError::TiltOutOfRange(_))));
        assert!(matches!(Kinematics::new(3.0, 0.0, 0.1, 0.0, 0.04), Err(KinematicsError::BadRadius("R_B", _))));
        assert!(matches!(Kinematics::new(3.0, 0.0, 0.1, 0.08, -1.0), Err(KinematicsError::BadRadius("R_D", _))));
        assert!(matches!(Kinematics::new(f64::NAN, 0.0, 0.1, 0.08, 0.04), Err(KinematicsError::NotFinite(..))));
        assert!(Kinematics::new(3.0, 0.0, 0.0, 0.08, 0.04).unwrap_err().to_string().contains("singular"));
    }
}
