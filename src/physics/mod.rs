//! Physics of the EHL point contact as small pure functions and types, PETSc-free.
//!
//! Every item names the paper symbol it implements (see `docs/model.md`):
//! - [`hertz`]: reduced modulus E', Hertz radius a and peak pressure p_H, equivalent solid.
//! - [`rheology`]: viscosity laws eta(p) (Roelands, Barus, constant) and density laws
//!   rho(p) (Dowson-Higginson, incompressible), each with its exact derivative d/dp for the
//!   Newton Jacobian.
//! - [`scales`]: the Hertzian scaling used by the solver (X = x/a, P = p/p_H,
//!   H = h R/a^2) and the Moes dimensionless groups M, L.
//! - [`film_formulas`]: the film-thickness curve fits of Hamrock-Dowson and Nijenbanning-Venner-Moes (references).
//! - [`kinematics`]: surface velocities of ball B and disc D under rolling, sliding and spin.
//!
//! All functions take and return SI units unless their name or doc says "dimensionless".
pub mod film_formulas;
pub mod hertz;
pub mod kinematics;
pub mod rheology;
pub mod scales;

pub use film_formulas::{FilmGroups, HamrockDowson};
pub use hertz::{equivalent_solid, reduced_modulus, Hertz, Material};
pub use kinematics::{Kinematics, KinematicsError, SurfaceVelocities};
pub use rheology::{DensityLaw, ViscosityLaw};
pub use scales::{MoesParameters, Scales};

#[cfg(test)]
pub(crate) mod test_util {
    /// Relative difference |a - b| / |b|.
    pub fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }
    /// Central finite difference of `f` at `x` with step `h`.
    pub fn fd(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
        (f(x + h) - f(x - h)) / (2.0 * h)
    }
}
