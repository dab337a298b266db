//! Per-point shear-stress law of an isothermal lubricant film (docs/model.md section 7).
//!
//! Across the film 0 <= y <= h (y measured from the disc surface D; y = h is the ball
//! surface B) the momentum balance of the thin film gives stresses linear in y, with
//! g = (dp/dx, dp/dz) the pressure gradient:
//!
//!   tau_yx(y) = tau_x0 + y g_x,   tau_yz(y) = tau_z0 + y g_z.
//!
//! The shear rate follows from the rheology. Ree-Eyring, with the equivalent stress
//! tau_e = sqrt(tau_yx^2 + tau_yz^2) and the Eyring stress tau0:
//!
//!   gammadot_yj = (tau_yj / eta) F(tau_e),   F(t) = sinh(t/tau0) / (t/tau0),   j = x, z;
//!
//! Newtonian: F = 1. The viscosity eta = eta(p) is constant across the film (isothermal,
//! p independent of y). The no-slip conditions fix the unknown disc stress
//! t0 = (tau_x0, tau_z0) through the two flow-rate (velocity-jump) constraints
//!
//!   G(t0) := integral_0^h gammadot dy = (dU, dW) = (U_B - U_D, W_B - W_D).
//!
//! Newtonian: closed form t0 = eta (dU, dW)/h - h g/2.
//!
//! Ree-Eyring: G is the gradient of the strictly convex potential
//! Phi(t0) = integral_0^h (tau0^2/eta) (cosh(tau_e/tau0) - 1) dy, so the solution minimises
//! Psi(t0) = Phi(t0) - t0 . (dU, dW). It is found by Newton's method with the exact
//! symmetric Jacobian
//!
//!   dG/dt0 = integral_0^h (1/eta) [F(tau_e) I + tau tau^T F'(tau_e)/tau_e] dy,
//!
//! safeguarded by a backtracking line search on Psi. Everything is computed in the
//! dimensionless variables s = tau/tau0 and Y = y/h, so that the numbers are O(1):
//! s(Y) = s0 + Y a with a = h g / tau0, and the constraint reads
//! integral_0^1 s F(|s|) dY = b with b = eta (dU, dW) / (h tau0).
//! The Y-integrals use composite 5-point Gauss-Legendre on m equal panels, m =
//! clamp(ceil(|a|) + 1, 1, 200): the integrand grows like exp(|s|) and varies on the scale
//! dY ~ 1/|a|, so each panel spans at most one unit of s (for |a| < 200; relative
//! quadrature error < 4e-13 there, growing like (|a|/200)^10 beyond, where EHL films are
//! far outside: there h |g| / tau0 is O(1) or less). Stresses beyond ~700 tau0 overflow
//! sinh and are reported as [`ShearError::Overflow`].
use std::fmt;

/// Shear-stress (rheological) law of the lubricant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShearLaw {
    /// Ree-Eyring: gammadot = (tau/eta) sinh(tau_e/tau0)/(tau_e/tau0); tau0 (Pa) > 0 is
    /// the Eyring stress (paper Table 1: 6.2e6 Pa).
    ReeEyring { tau0: f64 },
    /// Newtonian: gammadot = tau/eta.
    Newtonian,
}

/// Local state of the film at one point of the contact plane (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmPoint {
    /// Viscosity eta(p) (Pa s), > 0.
    pub eta: f64,
    /// Film thickness h (m), > 0.
    pub h: f64,
    /// Pressure gradient g = (dp/dx, dp/dz) (Pa/m).
    pub grad_p: [f64; 2],
    /// Sliding velocity (dU, dW) = (U_B - U_D, W_B - W_D) (m/s).
    pub slide: [f64; 2],
}

/// The velocity jump across the film produced by a given disc stress t0, and its Jacobian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmSlide {
    /// G(t0) = integral_0^h gammadot dy (m/s): the (dU, dW) that t0 would produce.
    pub slide: [f64; 2],
    /// dG/dt0 (m/(s Pa)), symmetric positive definite.
    pub jacobian: [[f64; 2]; 2],
}

/// Why the shear stress at a point could not be computed.
#[derive(Debug, Clone, PartialEq)]
pub enum ShearError {
    /// An input is out of its domain: `field` = `value` must be `expected`.
    Invalid { field: &'static str, value: f64, expected: &'static str },
    /// The shear-rate integrals overflow (stresses beyond ~700 tau0 somewhere in the film).
    Overflow {
        /// h |grad p| / tau0: the stress variation across the film in units of tau0.
        stress_range: f64,
        /// eta |slide| / (h tau0): the uniform-film shear rate in units of tau0/eta.
        slide_number: f64,
    },
    /// Newton did not reach |G(t0) - slide| <= tolerance.
    NoConvergence {
        /// Newton iterations performed.
        iterations: usize,
        /// Last residual |G(t0) - slide| (m/s).
        residual: f64,
        /// Required residual (m/s).
        tolerance: f64,
    },
}

impl fmt::Display for ShearError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ShearError::Invalid { field, value, expected } => {
                write!(f, "shear stress: {field} = {value} must be {expected}")
            }
            ShearError::Overflow { stress_range, slide_number } => write!(
                f,
                "Ree-Eyring shear stress: the shear-rate integrals overflow (stresses beyond ~700 tau0) \
                 with h |grad p| / tau0 = {stress_range:e} and eta |slide| / (h tau0) = {slide_number:e}"
            ),
            ShearError::NoConvergence { iterations, residual, tolerance } => write!(
                f,
                "Ree-Eyring shear stress: Newton did not converge in {iterations} iterations: \
                 flow-rate residual |G(t0) - slide| = {residual:e} m/s > tolerance {tolerance:e} m/s"
            ),
        }
    }
}

impl std::error::Error for ShearError {}

/// Shear stress on the disc surface (y = 0): t0 = (tau_x0, tau_z0) in Pa, the solution of
/// integral_0^h gammadot dy = (dU, dW). With zero slide and zero pressure gradient the
/// result is exactly (0, 0).
pub fn disc_shear_stress(law: &ShearLaw, pt: &FilmPoint) -> Result<[f64; 2], ShearError> {
    validate(law, pt)?;
    match *law {
        ShearLaw::Newtonian => Ok(newtonian_disc_stress(pt)),
        ShearLaw::ReeEyring { tau0 } => ree_eyring_disc_stress(tau0, pt),
    }
}

/// Shear stress at height y (m) above the disc given the disc stress t0: t0 + y g (Pa).
/// y = h gives the stress on the ball surface.
pub fn shear_at(t0: [f64; 2], grad_p: [f64; 2], y: f64) -> [f64; 2] {
    [t0[0] + y * grad_p[0], t0[1] + y * grad_p[1]]
}

/// The velocity jump G(t0) = integral_0^h gammadot dy that a disc stress t0 (Pa) would
/// produce at this point (`pt.slide` is ignored), with the exact Jacobian dG/dt0.
/// [`disc_shear_stress`] solves G(t0) = pt.slide.
pub fn film_slide(law: &ShearLaw, pt: &FilmPoint, t0: [f64; 2]) -> Result<FilmSlide, ShearError> {
    validate(law, pt)?;
    check_finite("t0[0]", t0[0])?;
    check_finite("t0[1]", t0[1])?;
    let (eta, h, g) = (pt.eta, pt.h, pt.grad_p);
    match *law {
        ShearLaw::Newtonian => {
            // gammadot = (t0 + y g)/eta, integrated exactly over [0, h].
            let slide = [(h * t0[0] + 0.5 * h * h * g[0]) / eta, (h * t0[1] + 0.5 * h * h * g[1]) / eta];
            Ok(FilmSlide { slide, jacobian: [[h / eta, 0.0], [0.0, h / eta]] })
        }
        ShearLaw::ReeEyring { tau0 } => {
            let s0 = [t0[0] / tau0, t0[1] / tau0];
            let a = [h * g[0] / tau0, h * g[1] / tau0];
            let int = film_integrals(s0, a);
            if !int.is_finite() {
                return Err(overflow(tau0, pt));
            }
            // G = (h tau0/eta) G*, dG/dt0 = (h tau0/eta) H* / tau0 = (h/eta) H*.
            let (gs, js) = (h * tau0 / eta, h / eta);
            Ok(FilmSlide {
                slide: [gs * int.g[0], gs * int.g[1]],
                jacobian: [[js * int.hess[0][0], js * int.hess[0][1]], [js * int.hess[1][0], js * int.hess[1][1]]],
            })
        }
    }
}

/// Newtonian closed form t0 = eta (dU, dW)/h - h g/2.
fn newtonian_disc_stress(pt: &FilmPoint) -> [f64; 2] {
    let (eta, h, g, u) = (pt.eta, pt.h, pt.grad_p, pt.slide);
    [eta * u[0] / h - 0.5 * h * g[0], eta * u[1] / h - 0.5 * h * g[1]]
}

/// Ree-Eyring disc stress: Newton on the dimensionless problem, then back to Pa.
fn ree_eyring_disc_stress(tau0: f64, pt: &FilmPoint) -> Result<[f64; 2], ShearError> {
    let (eta, h) = (pt.eta, pt.h);
    let b = [eta * pt.slide[0] / (h * tau0), eta * pt.slide[1] / (h * tau0)];
    let a = [h * pt.grad_p[0] / tau0, h * pt.grad_p[1] / tau0];
    match solve_dimensionless(b, a) {
        // + 0.0 turns a -0.0 into 0.0.
        Ok(s0) => Ok([tau0 * s0[0] + 0.0, tau0 * s0[1] + 0.0]),
        Err(Failure::Overflow) => Err(overflow(tau0, pt)),
        Err(Failure::NoConvergence { iterations, residual, tolerance }) => {
            let scale = h * tau0 / eta; // G = scale * G*
            Err(ShearError::NoConvergence { iterations, residual: scale * residual, tolerance: scale * tolerance })
        }
    }
}

fn overflow(tau0: f64, pt: &FilmPoint) -> ShearError {
    ShearError::Overflow { stress_range: pt.h * norm(pt.grad_p) / tau0, slide_number: pt.eta * norm(pt.slide) / (pt.h * tau0) }
}

/// Checks h, eta > 0 finite, tau0 > 0 finite, grad_p and slide finite.
fn validate(law: &ShearLaw, pt: &FilmPoint) -> Result<(), ShearError> {
    check_positive("h (film thickness, m)", pt.h)?;
    check_positive("eta (viscosity, Pa s)", pt.eta)?;
    if let ShearLaw::ReeEyring { tau0 } = *law {
        check_positive("tau0 (Ree-Eyring stress, Pa)", tau0)?;
    }
    check_finite("grad_p[0] (dp/dx, Pa/m)", pt.grad_p[0])?;
    check_finite("grad_p[1] (dp/dz, Pa/m)", pt.grad_p[1])?;
    check_finite("slide[0] (dU, m/s)", pt.slide[0])?;
    check_finite("slide[1] (dW, m/s)", pt.slide[1])
}

fn check_positive(field: &'static str, value: f64) -> Result<(), ShearError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ShearError::Invalid { field, value, expected: "a positive finite number" })
    }
}

fn check_finite(field: &'static str, value: f64) -> Result<(), ShearError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ShearError::Invalid { field, value, expected: "finite" })
    }
}

mod eyring;
#[cfg(test)]
mod tests;

use eyring::*;
