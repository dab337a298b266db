//! Cavitation by penalty (docs/model.md section 5): the term xi * area_i * pen(P_i) is added to
//! Reynolds row i (lumped at the nodes), with pen a C1 version of min(P, 0). Where the film
//! cavitates the penalty balances the Reynolds residual and holds P at -O(1/xi); where
//! P >= 0 it is exactly zero, so it never perturbs the pressurised film.

/// Width delta (in units of p_H) of the smoothed cavitation penalty; 0 gives the plain
/// min(P, 0).
pub const CAVITATION_SMOOTHING: f64 = 1e-3;

/// How a residual treats cavitation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cavitation {
    /// Negative pressures are kept.
    Off,
    /// The penalty xi pen(P) ([`penalty_law`]) with the factor xi.
    Penalty(f64),
    /// The complementarity form ([`complementarity`]): where P <= 0 the residual is the
    /// cavitation multiplier and counts as zero ([`pressurised`]).
    Complementarity,
}

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

/// Smoothing mu of the complementarity function (units of p_H): its root has
/// P F = mu^2 instead of 0.
pub const COMPLEMENTARITY_SMOOTHING: f64 = 1e-6;

/// The complementarity form of the Reynolds cavitation condition at one node: P >= 0,
/// F >= 0 and P F = 0, with F the node's (row-scaled) Reynolds residual, written as the
/// smoothed Fischer-Burmeister equation phi(P, F) = P + F - sqrt(P^2 + F^2 + 2 mu^2) = 0.
/// Returns phi and its derivatives in P and F. The solution does not depend on a penalty
/// factor. With mu = 0, phi has a kink at P = F = 0, where the free boundary's own nodes
/// tend to sit; mu = 1e-6 p_H makes phi and its Jacobian smooth everywhere, and moves a
/// cavitated node's P to mu^2/F (1e-12 p_H and less) and a degenerate node's to mu, far
/// below any film's resolution.
pub fn complementarity(p: f64, f: f64) -> (f64, f64, f64) {
    let mu = COMPLEMENTARITY_SMOOTHING;
    let r = (p * p + f * f + 2.0 * mu * mu).sqrt();
    (p + f - r, 1.0 - p / r, 1.0 - f / r)
}

/// Width (units of p_H) of the ramp of [`pressurised`].
pub const PRESSURISED_RAMP: f64 = 1e-3;

/// How far a point is pressurised, from 0 (P <= 0, cavitated) to 1 (P >= [`PRESSURISED_RAMP`]):
/// a C1 ramp, so that the residual that uses it stays continuous in P.
pub fn pressurised<const N: usize>(p: super::dual::Dual<N>) -> super::dual::Dual<N> {
    let t = p * (1.0 / PRESSURISED_RAMP);
    if t.v <= 0.0 {
        super::dual::Dual::constant(0.0)
    } else if t.v >= 1.0 {
        super::dual::Dual::constant(1.0)
    } else {
        t * t * (t * -2.0 + 3.0)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reynolds::dual::Dual;

    /// phi vanishes on the complementarity set (P = 0 <= F or F = 0 <= P) up to the
    /// smoothing's mu^2/F (mu at the origin) and nowhere else, and its derivatives are
    /// those of the formula.
    #[test]
    fn fischer_burmeister_vanishes_on_the_complementarity_set() {
        let mu = COMPLEMENTARITY_SMOOTHING;
        for (p, f) in [(0.0, 0.3), (0.7, 0.0)] {
            assert!(complementarity(p, f).0.abs() < 2.0 * mu * mu / (p + f), "({p}, {f})");
        }
        assert!(complementarity(0.0, 0.0).0.abs() < 2.0 * mu);
        for (p, f) in [(0.1, 0.2), (-0.1, 0.2), (0.2, -0.1), (-0.1, -0.1)] {
            assert!(complementarity(p, f).0.abs() > 1e-3, "({p}, {f})");
        }
        let d = 1e-7;
        for (p, f) in [(0.3, -0.2), (-0.4, 0.1), (1e-3, 2e-3)] {
            let (_, dp, df) = complementarity(p, f);
            let fd_p = (complementarity(p + d, f).0 - complementarity(p - d, f).0) / (2.0 * d);
            let fd_f = (complementarity(p, f + d).0 - complementarity(p, f - d).0) / (2.0 * d);
            assert!((dp - fd_p).abs() < 1e-6 && (df - fd_f).abs() < 1e-6, "({p}, {f}): {dp} {fd_p}, {df} {fd_f}");
        }
    }

    /// One node with the residual F(P) = P - c (a spring pushed by c): the Reynolds
    /// condition's solution is P = max(c, 0), F = max(-c, 0). Newton on phi reaches it
    /// from either side and from the cavitated and the pressurised guess, to the
    /// smoothing's mu^2/|c|.
    #[test]
    fn semismooth_newton_on_one_node_finds_the_cavitated_and_the_pressurised_state() {
        for c in [0.5, -0.5, 1e-4, -1e-4] {
            for p0 in [-0.3, 0.0, 0.2, 1.0] {
                let mut p = p0;
                let mut v = f64::INFINITY;
                for _ in 0..50 {
                    let (phi, dp, df) = complementarity(p, p - c);
                    v = phi;
                    if v.abs() < 1e-15 {
                        break;
                    }
                    p -= v / (dp + df);
                }
                // The smoothed root: P (P - c) = mu^2, within mu^2/|c| of max(c, 0).
                let mu = COMPLEMENTARITY_SMOOTHING;
                assert!(v.abs() < 1e-15 && (p - c.max(0.0)).abs() <= 1.01 * mu * mu / c.abs(), "c = {c}, from {p0}: P = {p}");
            }
        }
    }

    /// The SUPG gate is 0 where the film cavitates, 1 where it is pressurised beyond the
    /// smoothing width, continuous with a continuous slope in between (so the residual that
    /// uses it stays C1 and Newton's Jacobian exact).
    #[test]
    fn the_pressurised_ramp_is_c1_from_0_to_1() {
        let g = |p: f64| pressurised(Dual::<1>::variable(p, 0));
        assert_eq!(g(-1e-3).v, 0.0);
        assert_eq!(g(0.0).v, 0.0);
        assert_eq!(g(PRESSURISED_RAMP).v, 1.0);
        assert_eq!(g(1.0).v, 1.0);
        assert!((g(0.5 * PRESSURISED_RAMP).v - 0.5).abs() < 1e-12);
        let d = 1e-9;
        for t in [1e-6, 0.2, 0.5, 0.9, 1.0 - 1e-6] {
            let p = t * PRESSURISED_RAMP;
            let fd = (g(p + d).v - g(p - d).v) / (2.0 * d);
            assert!((g(p).d[0] - fd).abs() < 1e-4 * (1.0 / PRESSURISED_RAMP), "at t = {t}: {} vs {fd}", g(p).d[0]);
        }
        // The slope vanishes at both ends: C1 joins to the constants.
        assert!(g(1e-9 * PRESSURISED_RAMP).d[0].abs() < 1e-3 && g((1.0 - 1e-9) * PRESSURISED_RAMP).d[0].abs() < 1e-3);
    }
}
