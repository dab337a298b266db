//! The Ree-Eyring disc stress in dimensionless variables: Newton with a backtracking line
//! search on the convex potential, the film integrals by composite Gauss-Legendre.

// ---------------------------------------------------------------------------------------
// Dimensionless Ree-Eyring problem: find s0 with G*(s0) = integral_0^1 s F(|s|) dY = b,
// s(Y) = s0 + Y a.

/// Newton iteration cap.
pub(super) const MAX_NEWTON: usize = 100;
/// Relative residual tolerance: |G* - b| <= REL_TOL (|b| + integral |s| F(|s|) dY). The
/// second term is the magnitude of the integrand, which sets the floating-point floor of
/// G* when large stresses of both signs cancel across the film. The smallest eigenvalue of
/// dG*/ds0 is >= integral F dY, which is >= 1 and >= magnitude / max_Y |s|, so the criterion
/// bounds the error of s0 by about REL_TOL (|b| + max_Y |s(Y)|): the disc stress is accurate
/// to ~1e-12 of the largest stress in the film even where G* itself cannot be.
pub(super) const REL_TOL: f64 = 1e-12;
/// Armijo sufficient-decrease constant of the line search on Psi.
pub(super) const ARMIJO: f64 = 1e-4;
/// Maximum number of step halvings in one line search.
pub(super) const MAX_HALVINGS: usize = 60;

/// Why the dimensionless solve failed (residuals dimensionless).
#[derive(Debug)]
pub(super) enum Failure {
    Overflow,
    NoConvergence { iterations: usize, residual: f64, tolerance: f64 },
}

/// Newton with line search on Psi*(s0) = Phi*(s0) - s0 . b; returns s0.
pub(super) fn solve_dimensionless(b: [f64; 2], a: [f64; 2]) -> Result<[f64; 2], Failure> {
    let (mut s0, mut int) = start(b, a);
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

/// The |a| from which the collinear start is tried as well: below it the uniform-film start
/// takes 3-8 steps and the second candidate's integrals cost more than they save (per
/// point, one core: 15.5 against 10.7 us at |a| = 1.5, 78 against 75 us at 10, 107 against
/// 126 us at 15, 255 against 592 us at 50).
pub(super) const COLLINEAR_FROM: f64 = 10.0;

/// Where Newton starts, with the film integrals there: of [`starting_stress`] and, across a
/// film whose stress changes by [`COLLINEAR_FROM`] units or more, [`collinear_stress`], the
/// one of lower potential Psi* (Newton with the line search converges from either; the
/// lower one is nearer the minimum). Where the pressure gradient dominates (|a| of 30 to
/// 200 under the outlet spike of a thick film), the uniform-film start lies tens of units
/// from the solution, and Newton, which gains about one unit per step on the exponential,
/// took 13-31 steps of 30-200 panels each; from the collinear start it takes 0-10.
fn start(b: [f64; 2], a: [f64; 2]) -> ([f64; 2], FilmIntegrals) {
    let uniform = starting_stress(b, a);
    let at_uniform = film_integrals(uniform, a);
    if norm(a) < COLLINEAR_FROM {
        return (uniform, at_uniform);
    }
    let collinear = collinear_stress(b, a);
    let at_collinear = film_integrals(collinear, a);
    let psi = |s: [f64; 2], int: &FilmIntegrals| if int.is_finite() { int.phi - dot(s, b) } else { f64::INFINITY };
    if psi(collinear, &at_collinear) < psi(uniform, &at_uniform) {
        (collinear, at_collinear)
    } else {
        (uniform, at_uniform)
    }
}

/// The solution where b is parallel to a, extended to any b: along e = a/|a| the exact
/// one-dimensional solution of integral_0^1 sinh(sigma + |a| Y) dY = b.e, that is
/// sinh(sigma + |a|/2) = |a| (b.e) / (2 sinh(|a|/2)), and across it the component
/// tau = (b.e_perp) / integral_0^1 F(|sigma + |a| Y|) dY (the transverse equation with
/// the magnitude of s taken from its parallel part).
pub(super) fn collinear_stress(b: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    let len = norm(a);
    let e = [a[0] / len, a[1] / len];
    let (along, across) = (dot(b, e), b[1] * e[0] - b[0] * e[1]);
    let half = 0.5 * len;
    let sinh_half = half.sinh();
    let x = len * along / (2.0 * sinh_half);
    let sigma = if x.is_finite() && sinh_half.is_finite() {
        x.asinh() - half
    } else {
        // sinh(|a|/2) overflows: ln|x| = ln(|a| |b.e|) - |a|/2, and asinh of a large x is
        // ln(2|x|).
        let ln_x = (len * along.abs()).ln() - half;
        along.signum() * if ln_x > 20.0 { ln_x + std::f64::consts::LN_2 } else { ln_x.exp().asinh() } - half
    };
    let mut f_mean = 0.0;
    for_each_node(panel_count(a), |y, w| f_mean += w * eyring_factors((sigma + y * len).abs()).f);
    let tau = if f_mean.is_finite() && f_mean > 0.0 { (across / f_mean).clamp(-700.0, 700.0) } else { 0.0 };
    [sigma * e[0] - tau * e[1], sigma * e[1] + tau * e[0]]
}

/// Uniform-film solution in the direction of b, asinh(|b|) b/|b|, shifted by the Newtonian
/// pressure-gradient term -a/2.
pub(super) fn starting_stress(b: [f64; 2], a: [f64; 2]) -> [f64; 2] {
    let nb = norm(b);
    let k = if nb > 0.0 { nb.asinh() / nb } else { 0.0 };
    [k * b[0] - 0.5 * a[0], k * b[1] - 0.5 * a[1]]
}

/// Backtracking on Psi* along the Newton step: accepts the first lambda = 1, 1/2, 1/4, ...
/// with finite integrals and Psi*(s0 + lambda step) <= Psi*(s0) + ARMIJO lambda r.step
/// (plus a rounding allowance, so that steps near the solution, where Psi* changes by less
/// than its rounding error, are not rejected). Overflow counts as "too far".
pub(super) fn line_search(
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
pub(super) struct FilmIntegrals {
    /// G* = integral s F(|s|) dY.
    pub(super) g: [f64; 2],
    /// dG*/ds0 = integral [F(|s|) I + s s^T F'(|s|)/|s|] dY.
    pub(super) hess: [[f64; 2]; 2],
    /// Phi* = integral (cosh|s| - 1) dY.
    pub(super) phi: f64,
    /// integral |s| F(|s|) dY = integral sinh|s| dY >= |G*|.
    pub(super) magnitude: f64,
}

impl FilmIntegrals {
    pub(super) fn is_finite(&self) -> bool {
        let h = self.hess;
        [self.g[0], self.g[1], h[0][0], h[0][1], h[1][1], self.phi, self.magnitude].iter().all(|v| v.is_finite())
    }
}

/// Integrates G*, dG*/ds0, Phi* and the magnitude with the composite Gauss-Legendre rule.
pub(super) fn film_integrals(s0: [f64; 2], a: [f64; 2]) -> FilmIntegrals {
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
pub(super) fn panel_count(a: [f64; 2]) -> usize {
    let m = norm(a).ceil() + 1.0;
    if m.is_finite() {
        m.clamp(1.0, 200.0) as usize
    } else {
        200
    }
}

/// 5-point Gauss-Legendre nodes on [-1, 1] (positive half; the rule is symmetric):
/// 0, (1/3) sqrt(5 -+ 2 sqrt(10/7)). Exact for polynomials of degree <= 9.
pub(super) const GL_X: [f64; 3] = [0.0, 0.538_469_310_105_683_1, 0.906_179_845_938_664];
/// Matching weights: 128/225, (322 +- 13 sqrt 70)/900.
pub(super) const GL_W: [f64; 3] = [128.0 / 225.0, 0.478_628_670_499_366_5, 0.236_926_885_056_189_1];

/// Calls `visit(Y, weight)` for every node of the composite 5-point Gauss-Legendre rule
/// with `m` equal panels on [0, 1].
pub(super) fn for_each_node(m: usize, mut visit: impl FnMut(f64, f64)) {
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
pub(super) struct EyringFactors {
    pub(super) f: f64,
    pub(super) fp_over_t: f64,
    pub(super) cosh_m1: f64,
}

/// Below this t the Taylor series are used (no 0/0 at t = 0, no cancellation near it).
pub(super) const SERIES_T: f64 = 0.5;

/// F(t) = sum_k t^(2k)/(2k+1)!, F'(t)/t = sum_{k>=1} 2k t^(2k-2)/(2k+1)! (-> 1/3 at t = 0),
/// cosh t - 1 = 2 sinh^2(t/2) (no cancellation).
pub(super) fn eyring_factors(t: f64) -> EyringFactors {
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
pub(super) fn solve_2x2(m: [[f64; 2]; 2], r: [f64; 2]) -> [f64; 2] {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    [(m[1][1] * r[0] - m[0][1] * r[1]) / det, (m[0][0] * r[1] - m[1][0] * r[0]) / det]
}

pub(super) fn dot(u: [f64; 2], v: [f64; 2]) -> f64 {
    u[0] * v[0] + u[1] * v[1]
}

pub(super) fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}
