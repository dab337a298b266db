//! Cavitation by penalty (docs/model.md section 5): the term xi * area_i * pen(P_i) is added to
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

/// The lowest pressure (units of p_H) one Newton step may bring a nodal pressure to. The
/// penalty holds a cavitated pressure at -O(1/xi) (the hard suite's deepest converged nodal
/// pressure is -9e-4 p_H), but at a node the linearisation still treats as pressurised a
/// Newton step can predict -1 p_H (heavy-3gpa's side lobe from a coarser mesh's pressure):
/// the full step's residual there is then 20-50 times the current one, the backtracking
/// line search settles at its smallest step (0.1) and Newton crawls at 10 % per iteration.
/// Clipping such components at the floor lets the rest of the step through; the next
/// Jacobian has the penalty active at that node. 100 times the deepest converged pressure,
/// so a step towards a converged cavitated state is never clipped.
pub const PRESSURE_STEP_FLOOR: f64 = -0.1;

/// The Newton step `y` of a nodal pressure `p` (the update is p - y) clipped so that the new
/// pressure is not below `floor`; a pressure already below the floor may not fall further.
pub fn clip_pressure_step(p: f64, y: f64, floor: f64) -> f64 {
    let lowest = p.min(floor);
    if p - y < lowest {
        p - lowest
    } else {
        y
    }
}
