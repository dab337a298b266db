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
                jacobian: [
                    [js * int.hess[0][0], js * int.hess[0][1]],
                    [js * int.hess[1][0], js * int.hess[1][1]],
                ],
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
            Err(ShearError::NoConvergence {
                iterations,
                residual: scale * residual,
                tolerance: scale * tolerance,
            })
        }
    }
}

fn overflow(tau0: f64, pt: &FilmPoint) -> ShearError {
    ShearError::Overflow {
        stress_range: pt.h * norm(pt.grad_p) / tau0,
        slide_number: pt.eta * norm(pt.slide) / (pt.h * tau0),
    }
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

// ---------------------------------------------------------------------------------------
// Dimensionless Ree-Eyring problem: find s0 with G*(s0) = integral_0^1 s F(|s|) dY = b,
// s(Y) = s0 + Y a.

/// Newton iteration cap.
const MAX_NEWTON: usize = 100;
/// Relative residual tolerance: |G* - b| <= REL_TOL (|b| + integral |s| F(|s|) dY). The
/// second term is the magnitude of the integrand, which sets the floating-point floor of
/// G* when large stresses of both signs cancel across the film. The smallest eigenvalue of
/// dG*/ds0 is >= integral F dY, which is >= 1 and >= magnitude / max_Y |s|, so the criterion
/// bounds the error of s0 by about REL_TOL (|b| + max_Y |s(Y)|): the disc stress is accurate
/// to ~1e-12 of the largest stress in the film even where G* itself cannot be.
const REL_TOL: f64 = 1e-12;
/// Armijo sufficient-decrease constant of the line search on Psi.
const ARMIJO: f64 = 1e-4;
/// Maximum number of step halvings in one line search.
const MAX_HALVINGS: usize = 60;

/// Why the dimensionless solve failed (residuals dimensionless).
#[derive(Debug)]
enum Failure {
    Overflow,
    NoConvergence { iterations: usize, residual: f64, tolerance: f64 },
}

/// Newton with line search on Psi*(s0) = Phi*(s0) - s0 . b; returns s0.
fn solve_dimensionless(b: [f64; 2], a: [f64; 2]) -> Result<[f64; 2], Failure> {
    let mut s0 = starting_stress(b, a);
    let mut int = film_integrals(s0, a);
    if !int.is_finite() {
        return Err(Failure::Overflow);
    }
    let mut residual = f64::INFINITY;
    let mut tolerance = 0.0;
    for iterations in 0..MAX_NEWTON {
        let r = [int.g[0] - b[0], int.g[1] - b[1]];
        residual = norm(r);
        tolerance = REL_TOL * (norm(b) + int.magnitude);
        if residual <= tolerance {
            return Ok(s0);
        }
        let step = solve_2x2(int.hess, [-r[0], -r[1]]);
        match line_search(s0, &int, step, r, b, a) {
            Some((s_new, int_new)) => (s0, int) = (s_new, int_new),
            None => return Err(Failure::NoConvergence { iterations, residual, tolerance }),
        }
    }
    Err(Failure::NoConvergence { iterations: MAX_NEWTON, residual, tolerance })
}

/// Uniform-film solution in the direction of b, asinh(|b|) b/|b|, shifted by the Newtonian
/// pressure-gradient term -a/2.
fn starting_stress(b: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    let nb = norm(b);
    let k = if nb > 0.0 { nb.asinh() / nb } else { 0.0 };
    [k * b[0] - 0.5 * a[0], k * b[1] - 0.5 * a[1]]
}

/// Backtracking on Psi* along the Newton step: accepts the first lambda = 1, 1/2, 1/4, ...
/// with finite integrals and Psi*(s0 + lambda step) <= Psi*(s0) + ARMIJO lambda r.step
/// (plus a rounding allowance, so that steps near the solution, where Psi* changes by less
/// than its rounding error, are not rejected). Overflow counts as "too far".
fn line_search(
    s0: [f64; 2],
    int: &FilmIntegrals,
    step: [f64; 2],
    r: [f64; 2],
    b: [f64; 2],
    a: [f64; 2],
) -> Option<([f64; 2], FilmIntegrals)> {
    let psi0 = int.phi - dot(s0, b);
    let slope = dot(r, step); // directional derivative of Psi*, < 0 for SPD Hessian
    let allowance = 16.0 * f64::EPSILON * (int.phi + dot(s0, b).abs());
    let mut lambda = 1.0;
    for _ in 0..=MAX_HALVINGS {
        let trial = [s0[0] + lambda * step[0], s0[1] + lambda * step[1]];
        let t = film_integrals(trial, a);
        if t.is_finite() && t.phi - dot(trial, b) <= psi0 + ARMIJO * lambda * slope + allowance {
            return Some((trial, t));
        }
        lambda *= 0.5;
    }
    None
}

/// The film integrals over Y in [0, 1] at the dimensionless disc stress s0.
#[derive(Debug, Clone, Copy)]
struct FilmIntegrals {
    /// G* = integral s F(|s|) dY.
    g: [f64; 2],
    /// dG*/ds0 = integral [F(|s|) I + s s^T F'(|s|)/|s|] dY.
    hess: [[f64; 2]; 2],
    /// Phi* = integral (cosh|s| - 1) dY.
    phi: f64,
    /// integral |s| F(|s|) dY = integral sinh|s| dY >= |G*|.
    magnitude: f64,
}

impl FilmIntegrals {
    fn is_finite(&self) -> bool {
        let h = self.hess;
        [self.g[0], self.g[1], h[0][0], h[0][1], h[1][1], self.phi, self.magnitude]
            .iter()
            .all(|v| v.is_finite())
    }
}

/// Integrates G*, dG*/ds0, Phi* and the magnitude with the composite Gauss-Legendre rule.
fn film_integrals(s0: [f64; 2], a: [f64; 2]) -> FilmIntegrals {
    let mut int = FilmIntegrals { g: [0.0; 2], hess: [[0.0; 2]; 2], phi: 0.0, magnitude: 0.0 };
    for_each_node(panel_count(a), |y, w| {
        let s = [s0[0] + y * a[0], s0[1] + y * a[1]];
        let t = norm(s);
        let e = eyring_factors(t);
        let (wf, wd) = (w * e.f, w * e.fp_over_t);
        int.g[0] += wf * s[0];
        int.g[1] += wf * s[1];
        int.hess[0][0] += wf + wd * s[0] * s[0];
        int.hess[0][1] += wd * s[0] * s[1];
        int.hess[1][1] += wf + wd * s[1] * s[1];
        int.phi += w * e.cosh_m1;
        int.magnitude += wf * t;
    });
    int.hess[1][0] = int.hess[0][1];
    int
}

/// Number of Gauss-Legendre panels on [0, 1]: clamp(ceil(|a|) + 1, 1, 200), so that s
/// changes by at most one unit (one e-fold of the integrand) per panel when |a| < 200.
fn panel_count(a: [f64; 2]) -> usize {
    let m = norm(a).ceil() + 1.0;
    if m.is_finite() {
        m.clamp(1.0, 200.0) as usize
    } else {
        200
    }
}

/// 5-point Gauss-Legendre nodes on [-1, 1] (positive half; the rule is symmetric):
/// 0, (1/3) sqrt(5 -+ 2 sqrt(10/7)). Exact for polynomials of degree <= 9.
const GL_X: [f64; 3] = [0.0, 0.538_469_310_105_683_1, 0.906_179_845_938_664];
/// Matching weights: 128/225, (322 +- 13 sqrt 70)/900.
const GL_W: [f64; 3] = [128.0 / 225.0, 0.478_628_670_499_366_5, 0.236_926_885_056_189_1];

/// Calls `visit(Y, weight)` for every node of the composite 5-point Gauss-Legendre rule
/// with `m` equal panels on [0, 1].
fn for_each_node(m: usize, mut visit: impl FnMut(f64, f64)) {
    let half = 0.5 / m as f64; // half panel width
    for k in 0..m {
        let mid = (2 * k + 1) as f64 * half;
        visit(mid, GL_W[0] * half);
        for i in 1..3 {
            visit(mid - GL_X[i] * half, GL_W[i] * half);
            visit(mid + GL_X[i] * half, GL_W[i] * half);
        }
    }
}

/// F(t) = sinh t / t, F'(t)/t and cosh t - 1 for the dimensionless equivalent stress t >= 0.
#[derive(Debug, Clone, Copy, PartialEq)]
struct EyringFactors {
    f: f64,
    fp_over_t: f64,
    cosh_m1: f64,
}

/// Below this t the Taylor series are used (no 0/0 at t = 0, no cancellation near it).
const SERIES_T: f64 = 0.5;

/// F(t) = sum_k t^(2k)/(2k+1)!, F'(t)/t = sum_{k>=1} 2k t^(2k-2)/(2k+1)! (-> 1/3 at t = 0),
/// cosh t - 1 = 2 sinh^2(t/2) (no cancellation).
fn eyring_factors(t: f64) -> EyringFactors {
    let cosh_m1 = 2.0 * (0.5 * t).sinh().powi(2);
    if t < SERIES_T {
        let t2 = t * t;
        // Ratios of successive terms t^2/((2k)(2k+1)), k = 7, ..., 1 (Horner form);
        // the first omitted term is < 1e-16 relative at t = 0.5.
        let f = [210.0, 156.0, 110.0, 72.0, 42.0, 20.0, 6.0].iter().fold(1.0, |acc, d| 1.0 + t2 / d * acc);
        // Coefficients 2k/(2k+1)! for k = 8, ..., 1.
        const C: [f64; 8] = [
            1.0 / 22_230_464_256_000.0,
            1.0 / 93_405_312_000.0,
            1.0 / 518_918_400.0,
            1.0 / 3_991_680.0,
            1.0 / 45_360.0,
            1.0 / 840.0,
            1.0 / 30.0,
            1.0 / 3.0,
        ];
        let fp_over_t = C.iter().fold(0.0, |acc, c| acc * t2 + c);
        EyringFactors { f, fp_over_t, cosh_m1 }
    } else {
        let (sh, ch) = (t.sinh(), t.cosh());
        EyringFactors { f: sh / t, fp_over_t: (t * ch - sh) / (t * t * t), cosh_m1 }
    }
}

/// Solves the symmetric positive definite 2x2 system m x = r by Cramer's rule.
fn solve_2x2(m: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [(m[1][1] * r[0] - m[0][1] * r[1]) / det, (m[0][0] * r[1] - m[1][0] * r[0]) / det]
}

fn dot(u: [f64; 2], v: [f64; 2]) -> f64 {
    u[0] * v[0] + u[1] * v[1]
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Paper Table 1 Eyring stress (Pa) and a typical EHL film point.
    const TAU0: f64 = 6.2e6;
    const ETA: f64 = 0.08;
    const H: f64 = 2.0e-7;
    const RE: ShearLaw = ShearLaw::ReeEyring { tau0: TAU0 };

    fn point(grad_p: [f64; 2], slide: [f64; 2]) -> FilmPoint {
        FilmPoint { eta: ETA, h: H, grad_p, slide }
    }

    fn rotate(v: [f64; 2], angle: f64) -> [f64; 2] {
        let (s, c) = angle.sin_cos();
        [c * v[0] - s * v[1], s * v[0] + c * v[1]]
    }

    fn dist(u: [f64; 2], v: [f64; 2]) -> f64 {
        norm([u[0] - v[0], u[1] - v[1]])
    }

    /// Independent reference: integral_0^h gammadot dy by composite Simpson with `n` (even)
    /// intervals, using sinh directly (no series, no Gauss-Legendre). Returns the integral
    /// and integral |gammadot| dy (the magnitude that sets the rounding floor).
    fn simpson_slide(law: &ShearLaw, pt: &FilmPoint, t0: [f64; 2], n: usize) -> ([f64; 2], f64) {
        let dy = pt.h / n as f64;
        let (mut g, mut mag) = ([0.0; 2], 0.0);
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            } * dy
                / 3.0;
            let tau = shear_at(t0, pt.grad_p, i as f64 * dy);
            let te = norm(tau);
            let factor = match *law {
                ShearLaw::ReeEyring { tau0 } if te > 0.0 => (te / tau0).sinh() / (te / tau0),
                _ => 1.0,
            };
            g[0] += w * tau[0] / pt.eta * factor;
            g[1] += w * tau[1] / pt.eta * factor;
            mag += w * te / pt.eta * factor;
        }
        (g, mag)
    }

    /// Slide (m/s) giving the dimensionless uniform-film number eta |slide|/(h tau0) = n.
    fn slide_for(n: f64, angle: f64) -> [f64; 2] {
        rotate([n * H * TAU0 / ETA, 0.0], angle)
    }

    /// Gradient (Pa/m) giving h |g| / tau0 = n.
    fn grad_for(n: f64, angle: f64) -> [f64; 2] {
        rotate([n * TAU0 / H, 0.0], angle)
    }

    #[test]
    fn gauss_legendre_rule_exact_for_degree_9_and_accurate_for_exponentials() {
        // Degree <= 9 exact on one and on several panels (up to rounding).
        for m in [1, 3, 7] {
            for k in 0..=9 {
                let mut q = 0.0;
                for_each_node(m, |y, w| q += w * y.powi(k));
                assert!((q - 1.0 / (k + 1) as f64).abs() < 1e-15, "m = {m}, Y^{k}: {q}");
            }
        }
        // Degree 10 is not exact on one panel: the rule really has 5 points.
        let mut q = 0.0;
        for_each_node(1, |y, w| q += w * y.powi(10));
        assert!((q - 1.0 / 11.0).abs() > 1e-7);
        // The integrand of the solver grows like exp(|a| Y). The 5-point error on a panel
        // of width L is L^11 (5!)^4 / (11 (10!)^3) f^(10) = 3.9e-13 (c L)^10 L f, and the
        // panel count keeps c L < 1, so the relative error is < 3.9e-13 (observed 3.1e-13
        // at c = 50, c L = 0.98): well below the 1e-12 Newton tolerance.
        for c in [0.3, 5.0, 50.0, 150.0, -80.0] {
            let mut q = 0.0;
            for_each_node(panel_count([c, 0.0]), |y, w| q += w * (c * y).exp());
            let exact = c.exp_m1() / c;
            assert!(((q - exact) / exact).abs() < 4e-13, "c = {c}: {q} vs {exact}");
        }
    }

    #[test]
    fn eyring_factors_series_and_closed_forms_agree() {
        let z = eyring_factors(0.0);
        assert_eq!(z, EyringFactors { f: 1.0, fp_over_t: 1.0 / 3.0, cosh_m1: 0.0 });
        // Series branch against sinh/t (no cancellation in it) and against the closed form
        // (t cosh t - sinh t)/t^3 (cancellation ~ eps/t^2, hence the looser tolerance).
        for t in [1e-3, 0.05, 0.3, 0.4999] {
            let e = eyring_factors(t);
            let fp = (t * t.cosh() - t.sinh()) / t.powi(3);
            assert!(((e.f - t.sinh() / t) / e.f).abs() < 4e-16, "F({t})");
            assert!(((e.fp_over_t - fp) / fp).abs() < 1e-15 / (t * t), "F'/t({t})");
            assert!(((e.cosh_m1 - (t.cosh() - 1.0)) / e.cosh_m1).abs() < 1e-15 / (t * t));
        }
        // Continuity across the branch switch.
        let (lo, hi) = (eyring_factors(SERIES_T * (1.0 - 1e-15)), eyring_factors(SERIES_T));
        assert!(((lo.f - hi.f) / hi.f).abs() < 1e-15);
        assert!(((lo.fp_over_t - hi.fp_over_t) / hi.fp_over_t).abs() < 1e-14);
    }

    #[test]
    fn zero_slide_and_zero_gradient_give_exactly_zero() {
        for law in [RE, ShearLaw::Newtonian] {
            let t0 = disc_shear_stress(&law, &point([0.0; 2], [0.0; 2])).unwrap();
            assert_eq!(t0, [0.0, 0.0]);
            assert!(t0[0].is_sign_positive() && t0[1].is_sign_positive());
        }
    }

    /// Test 1. g = 0: the stress is uniform across the film, so sinh(|t0|/tau0) =
    /// eta |slide|/(h tau0) and t0 is parallel to the slide (outside closed form).
    #[test]
    fn uniform_film_limit_matches_asinh_law() {
        for n in [1e-3, 1e-1, 1.0, 10.0, 1e2, 1e3, 1e4] {
            for angle in [0.0, 0.7, 2.0, -2.9] {
                let slide = slide_for(n, angle);
                let t0 = disc_shear_stress(&RE, &point([0.0; 2], slide)).unwrap();
                let expected = TAU0 * n.asinh();
                let rel = (norm(t0) - expected).abs() / expected;
                assert!(rel < 1e-10, "n = {n}, angle {angle}: |t0| = {} vs {expected} ({rel:e})", norm(t0));
                let sin_between = (t0[0] * slide[1] - t0[1] * slide[0]) / (norm(t0) * norm(slide));
                assert!(sin_between.abs() < 1e-12 && dot(t0, slide) > 0.0, "not parallel: {sin_between:e}");
            }
        }
    }

    /// Test 2. tau0 >> all stresses: Ree-Eyring -> Newtonian eta slide/h - h g/2. The
    /// first correction is relative O((tau/tau0)^2 / 6) ~ 1e-13 here, so 1e-9 is safe
    /// (tighter than the ~1e-6 the physics needs).
    #[test]
    fn newtonian_limit_for_huge_tau0() {
        let slide = [1.3, -0.4];
        let grad = [3e12, -1.5e12];
        let pt = point(grad, slide);
        let newton = newtonian_disc_stress(&pt);
        let scale = (ETA * norm(slide) / H).max(H * norm(grad));
        let law = ShearLaw::ReeEyring { tau0: 1e6 * scale };
        let t0 = disc_shear_stress(&law, &pt).unwrap();
        let rel = dist(t0, newton) / norm(newton);
        assert!(rel < 1e-9, "{t0:?} vs {newton:?}: {rel:e}");
        assert_eq!(disc_shear_stress(&ShearLaw::Newtonian, &pt).unwrap(), newton);
    }

    /// Test 3. Newtonian closed form with a pressure gradient satisfies the flow-rate
    /// constraint integral_0^h (t0 + y g)/eta dy = slide (Simpson is exact for a linear
    /// integrand, so only rounding remains).
    #[test]
    fn newtonian_closed_form_satisfies_flow_rate_constraint() {
        let law = ShearLaw::Newtonian;
        for (slide, grad) in
            [([2.0, 0.0], [1e12, 0.0]), ([-0.5, 0.8], [-4e12, 7e11]), ([0.0, 0.0], [2e13, -3e13])]
        {
            let pt = point(grad, slide);
            let t0 = disc_shear_stress(&law, &pt).unwrap();
            let (g, mag) = simpson_slide(&law, &pt, t0, 2000);
            assert!(dist(g, slide) <= 1e-12 * (norm(slide) + mag), "{g:?} vs {slide:?}");
            let fs = film_slide(&law, &pt, t0).unwrap();
            assert!(dist(fs.slide, slide) <= 1e-12 * (norm(slide) + mag));
        }
    }

    /// Test 4a. Strongly non-Newtonian stresses with a pressure gradient (h|g|/tau0 = 5..50)
    /// in general directions: the returned t0 satisfies the constraint evaluated by an
    /// independent 20000-interval Simpson rule. Simpson's error is ~ (|a|/20000)^4/180 <=
    /// 3e-13 relative, and the floor of any evaluation is eps times integral |gammadot| dy
    /// (stresses of both signs cancel), so the check is relative to |slide| + that
    /// magnitude. Where |slide| dominates the magnitude this is a plain relative check
    /// (observed errors <= 1.4e-13).
    #[test]
    fn strongly_non_newtonian_with_gradient_satisfies_constraint() {
        for stress_range in [5.0, 20.0, 50.0] {
            for (n, slide_angle, grad_angle) in
                [(0.3, 0.0, 1.0), (30.0, 2.0, -0.5), (3e3, -1.0, 2.5), (1e5, 0.4, 0.4)]
            {
                let pt = point(grad_for(stress_range, grad_angle), slide_for(n, slide_angle));
                let t0 = disc_shear_stress(&RE, &pt).unwrap();
                let (g, mag) = simpson_slide(&RE, &pt, t0, 20000);
                let err = dist(g, pt.slide) / (norm(pt.slide) + mag);
                assert!(err < 1e-8, "range {stress_range}, n {n}: {g:?} vs {:?} ({err:e})", pt.slide);
            }
        }
    }

    /// Test 4b. g parallel to the slide: the problem is one-dimensional along e = g/|g| and
    /// G = (h tau0/eta) (cosh(s0 + a) - cosh(s0))/a in closed form, hence
    /// s0 = -a/2 + asinh(b a / (2 sinh(a/2))) (a, b signed components along e).
    #[test]
    fn collinear_gradient_matches_closed_form() {
        for a in [0.5, 5.0, -20.0, 50.0] {
            for b in [0.0, 0.2, -7.0, 1e4] {
                let angle = 0.9;
                let pt = point(grad_for(a, angle), slide_for(b, angle));
                let s0 = -0.5 * a + (b * a / (2.0 * (0.5 * a).sinh())).asinh();
                let expected = rotate([TAU0 * s0, 0.0], angle);
                let t0 = disc_shear_stress(&RE, &pt).unwrap();
                let err = dist(t0, expected) / (norm(expected) + TAU0);
                assert!(err < 1e-12, "a {a}, b {b}: {t0:?} vs {expected:?} ({err:e})");
            }
        }
    }

    /// Test 4c. Symmetries: t0(-g, -slide) = -t0(g, slide) (tau -> -tau leaves F unchanged),
    /// and rotating (slide, g) by an angle rotates t0 (the law is isotropic).
    #[test]
    fn sign_flip_and_rotation_symmetry() {
        for (range, n) in [(0.0, 2.0), (5.0, 0.5), (30.0, 200.0)] {
            let pt = point(grad_for(range, 0.3), slide_for(n, -1.2));
            let t0 = disc_shear_stress(&RE, &pt).unwrap();
            let flipped = point([-pt.grad_p[0], -pt.grad_p[1]], [-pt.slide[0], -pt.slide[1]]);
            let tf = disc_shear_stress(&RE, &flipped).unwrap();
            assert!(dist(tf, [-t0[0], -t0[1]]) <= 1e-14 * norm(t0), "flip: {tf:?} vs {t0:?}");
            let scale = norm(t0) + H * norm(pt.grad_p);
            for angle in [0.5, 1.9, -2.7] {
                let rotated = point(rotate(pt.grad_p, angle), rotate(pt.slide, angle));
                let tr = disc_shear_stress(&RE, &rotated).unwrap();
                let err = dist(tr, rotate(t0, angle)) / scale;
                assert!(err < 1e-10, "range {range}, angle {angle}: {err:e}");
            }
        }
    }

    /// Test 5. The analytic Jacobian dG/dt0 matches central differences of G. Step 1e-5 tau0:
    /// truncation ~ (1e-5)^2 / 6 and rounding ~ eps/1e-5, both < 1e-10 relative to |J|
    /// (observed <= 5e-11), so 1e-8 is a safe and still sharp bound.
    #[test]
    fn jacobian_matches_finite_differences() {
        let cases = [
            ([0.0, 0.0], [0.01, -0.02]),   // tiny stresses: series branch everywhere
            ([0.3, 0.1], [-0.1, 0.2]),     // crosses |s| = 0.5 inside the film
            ([1.0, -2.0], [5.0, 3.0]),     // strongly non-Newtonian
            ([-12.0, 4.0], [30.0, -10.0]), // large gradient, many panels
        ];
        for (s0, a) in cases {
            let pt = point([a[0] * TAU0 / H, a[1] * TAU0 / H], [0.0; 2]);
            let t0 = [s0[0] * TAU0, s0[1] * TAU0];
            let j = film_slide(&RE, &pt, t0).unwrap().jacobian;
            let jmax = j.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let d = 1e-5 * TAU0;
            for col in 0..2 {
                let (mut tp, mut tm) = (t0, t0);
                tp[col] += d;
                tm[col] -= d;
                let gp = film_slide(&RE, &pt, tp).unwrap().slide;
                let gm = film_slide(&RE, &pt, tm).unwrap().slide;
                for row in 0..2 {
                    let fd = (gp[row] - gm[row]) / (2.0 * d);
                    let err = (fd - j[row][col]).abs() / jmax;
                    assert!(
                        err < 1e-8,
                        "s0 {s0:?}, a {a:?}, J[{row}][{col}] = {} vs fd {fd} ({err:e})",
                        j[row][col]
                    );
                }
            }
            assert_eq!(j[0][1], j[1][0]);
        }
    }

    /// The potential Phi* really is the potential of G*: central differences of Phi*
    /// reproduce G* (this is what makes the line search on Psi* valid).
    #[test]
    fn potential_gradient_is_the_flow_integral() {
        for (s0, a) in [([0.2, -0.1], [0.4, 0.3]), ([2.0, 1.0], [-6.0, 2.0]), ([-8.0, 3.0], [20.0, 5.0])] {
            let g = film_integrals(s0, a).g;
            let d = 1e-5;
            for k in 0..2 {
                let (mut sp, mut sm) = (s0, s0);
                sp[k] += d;
                sm[k] -= d;
                let fd = (film_integrals(sp, a).phi - film_integrals(sm, a).phi) / (2.0 * d);
                assert!((fd - g[k]).abs() < 1e-7 * norm(g).max(1.0), "s0 {s0:?}: {fd} vs {}", g[k]);
            }
        }
    }

    /// Robustness: Newton converges over a wide parameter sweep (pseudo-random directions),
    /// from weakly to extremely non-Newtonian and with large pressure gradients (up to
    /// h|g|/tau0 = 400, i.e. stresses of +-200 tau0 and sinh ~ 1e86), and the returned t0
    /// meets the solver's criterion |G - slide| <= 1e-12 (|slide| + integral |gammadot| dy)
    /// (checked with 1e-11; the magnitude is taken from an independent Simpson rule).
    #[test]
    fn converges_over_wide_parameter_range() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut angle = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU
        };
        for range in [0.0, 1e-3, 0.3, 3.0, 30.0, 150.0, 400.0] {
            for n in [0.0, 1e-8, 1e-3, 1.0, 1e3, 1e8] {
                let pt = point(grad_for(range, angle()), slide_for(n, angle()));
                let t0 = disc_shear_stress(&RE, &pt).unwrap_or_else(|e| panic!("range {range}, n {n}: {e}"));
                let g = film_slide(&RE, &pt, t0).unwrap().slide;
                let (_, mag) = simpson_slide(&RE, &pt, t0, 2000);
                let err = dist(g, pt.slide);
                assert!(err <= 1e-11 * (norm(pt.slide) + mag), "range {range}, n {n}: {err:e} vs {mag:e}");
            }
        }
    }

    /// Test 6. Invalid inputs are rejected with a message naming the field.
    #[test]
    fn invalid_inputs_name_the_field() {
        let good = point([1e12, 0.0], [1.0, 0.0]);
        let cases: [(ShearLaw, FilmPoint, &str); 8] = [
            (RE, FilmPoint { h: 0.0, ..good }, "h (film thickness"),
            (RE, FilmPoint { h: -1e-7, ..good }, "h (film thickness"),
            (ShearLaw::Newtonian, FilmPoint { h: f64::INFINITY, ..good }, "h (film thickness"),
            (RE, FilmPoint { eta: f64::NAN, ..good }, "eta (viscosity"),
            (ShearLaw::Newtonian, FilmPoint { eta: f64::INFINITY, ..good }, "eta (viscosity"),
            (ShearLaw::ReeEyring { tau0: 0.0 }, good, "tau0"),
            (RE, FilmPoint { grad_p: [0.0, f64::NAN], ..good }, "grad_p[1]"),
            (RE, FilmPoint { slide: [f64::NEG_INFINITY, 0.0], ..good }, "slide[0]"),
        ];
        for (law, pt, field) in cases {
            let err = disc_shear_stress(&law, &pt).unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, ShearError::Invalid { .. }) && msg.contains(field), "{msg}");
            assert!(film_slide(&law, &pt, [0.0; 2]).is_err());
        }
        let msg = film_slide(&RE, &good, [f64::NAN, 0.0]).unwrap_err().to_string();
        assert!(msg.contains("t0[0]"), "{msg}");
    }

    /// Stresses beyond ~700 tau0 overflow sinh: reported as such, not as a panic or NaN.
    #[test]
    fn overflow_and_no_convergence_are_reported() {
        let err = disc_shear_stress(&RE, &point(grad_for(2000.0, 0.0), [0.0; 2])).unwrap_err();
        assert!(matches!(err, ShearError::Overflow { .. }), "{err}");
        assert!(err.to_string().contains("overflow"), "{err}");
        let msg = ShearError::NoConvergence { iterations: 100, residual: 1e-3, tolerance: 1e-12 }.to_string();
        assert!(msg.contains("did not converge") && msg.contains("residual"), "{msg}");
    }
}
