//! Cavitation by penalty (physics.md section 5): the term xi * area_i * pen(P_i) is added to
//! Reynolds row i (lumped at the nodes), with pen a C1 version of min(P, 0). Where the film
//! cavitates the penalty balances the Reynolds residual and holds P at -O(1/xi); where
//! P >= 0 it is exactly zero, so it never perturbs the pressurised film.

/// Width delta (in units of p_H) of the smoothed cavitation penalty; 0 gives the plain
/// min(P, 0).
pub const CAVITATION_SMOOTHING: f64 = 1e-3;

/// The cavitation penalty function and its derivative: a C1 version of min(P, 0) that is
/// exactly 0 for P >= 0 (so the penalty never touches the pressurised film):
/// -P^2/(2 delta) on [-delta, 0], P + delta/2 below -delta.
pub fn penalty_law(p: f64) -> (f64, f64) {
    let d = CAVITATION_SMOOTHING;
    if p >= 0.0 {
        (0.0, 0.0)
    } else if d == 0.0 || p < -d {
        (p + 0.5 * d, 1.0)
    } else {
        (-p * p / (2.0 * d), -p / d)
    }
}

