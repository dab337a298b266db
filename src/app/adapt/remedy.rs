//! What a refined level that did not converge is tried with next.
use crate::app::Context;
use crate::collective;
use crate::error::Error;

/// How a refined level's solve failed, the same on every rank.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Failure {
    /// A signal or the spent time budget stopped it.
    pub(super) interrupted: bool,
    /// Newton's own failure, not at a spin pole ([`newton_failed`]).
    pub(super) newton: bool,
    /// The film closed next to a spin pole inside the Hertz circle ([`at_spin_pole`]).
    pub(super) at_pole: bool,
}

impl Failure {
    /// Collective.
    pub(super) fn of(ctx: &Context, e: &Error) -> Self {
        if crate::interrupt::agreed() != 0 {
            return Failure { interrupted: true, ..Failure::default() };
        }
        Failure { interrupted: false, newton: newton_failed(ctx, e), at_pole: at_spin_pole(ctx, e) }
    }
}

/// What the failed solve of a refined level had tried, and what is left for it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Tried {
    /// Plain Newton alone, on a mesh made by quartering.
    pub(super) plain_alone: bool,
    /// The gradient-jump factor can still be raised.
    pub(super) raisable: bool,
    /// The solve went on from the furthest state of the try before the raise.
    pub(super) from_try_state: bool,
    /// The load and speed continuations and the Hertz start were among its tries.
    pub(super) last_resorts: bool,
    /// The level is goal-oriented and may be meshed again with the pressurised zone.
    pub(super) zone_retry: bool,
}

/// What a refined level that did not converge is tried with next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Remedy {
    /// The level meshed again with its quartered triangles halved, which converged by
    /// plain Newton where the quartered level needed the continuation and the raise (a
    /// traction drive at L = 22: 62 s to a tighter target against 638 s, docs/practice.md).
    HalveQuartered,
    /// The same mesh with the gradient-jump factor raised, for it and the levels after: at
    /// M = 100, L = 20 the outlet spike is one element wide on the 0.0625 and 0.03125 a
    /// levels, Newton moves it from node to node, and the alpha ramp stops at 55-63 of
    /// 68.3 GPa^-1; with c_J = 1 every level converges and hc, hm move by 0.1 %, 0.3 %
    /// (docs/accuracy.md, "Newton on fine levels at high M and L").
    Raise,
    /// The raised solve from the try's furthest state failed: again from the coarser
    /// level's state.
    FromCoarser,
    /// A film that closes next to a spin pole inside the Hertz circle closes on every finer
    /// mesh: the coarser level converged only because its elements do not resolve the
    /// pole, so its film is no result (no retry, nothing written). The full ladder after
    /// such a failure spent 500 s and more closing the film at the same node
    /// (docs/accuracy.md, "The loop", step 1).
    SpinPole,
    /// The same mesh with the load and speed continuations and the Hertz start.
    FullLadder,
    /// A goal-oriented level meshed again with the coarser level's whole pressurised zone
    /// refined, once: at M = 100, L = 20 the continuation stalled at alpha 62.6 of
    /// 68.3 GPa^-1 on the goal-oriented 0.125 a level and converged on the zone's.
    ZoneMesh,
    /// Nothing is left: the last converged level is the result, labelled as short of its
    /// target.
    Short,
    /// An interruption: the run stops (with the last converged level when the time budget
    /// was spent).
    Stop,
}

/// The remedy for a failed refined level, in order: the halved mesh for a quartered one,
/// the raised gradient-jump factor while it can be raised, the coarser level's state after
/// a raised solve from the try's state, then (for any failure but a spin pole's) the last
/// resorts, the zone's mesh, and the last converged level. The raise comes before the last
/// resorts: at M = 100, L = 20 those cost 330 s on level 3 and never converged from a
/// coarser level's pressure.
pub(super) fn remedy(failed: &Failure, tried: &Tried) -> Remedy {
    match *failed {
        Failure { interrupted: true, .. } => Remedy::Stop,
        Failure { newton: true, .. } if tried.plain_alone => Remedy::HalveQuartered,
        Failure { newton: true, .. } if tried.raisable => Remedy::Raise,
        Failure { newton: true, .. } if tried.from_try_state => Remedy::FromCoarser,
        Failure { at_pole: true, .. } => Remedy::SpinPole,
        _ if !tried.last_resorts => Remedy::FullLadder,
        _ if tried.zone_retry => Remedy::ZoneMesh,
        _ => Remedy::Short,
    }
}

/// Whether `e` is Newton's own failure, the same on every rank (not one rank's local
/// fault), and not a film closing at a spin pole (which closes on any mesh): the failures
/// after which a level is solved again. Collective.
pub(super) fn newton_failed(ctx: &Context, e: &Error) -> bool {
    collective::all(&ctx.world, newton_failure(e) && !closed_at_spin_pole(e))
}

/// Whether Newton failed on every rank because the film closed next to a spin pole inside
/// the Hertz circle, where the model has no film on any mesh. Collective.
fn at_spin_pole(ctx: &Context, e: &Error) -> bool {
    collective::all(&ctx.world, closed_at_spin_pole(e))
}

/// Whether `e` is Newton's own failure (not converged, or the film closed on the way).
fn newton_failure(e: &Error) -> bool {
    matches!(e.root(), Error::NotConverged { .. } | Error::FilmClosed { .. })
}

/// Whether `e` is Newton's failure with the film closed next to a spin pole inside the
/// Hertz circle (the driver's diagnosis, in its message).
fn closed_at_spin_pole(e: &Error) -> bool {
    newton_failure(e) && e.to_string().contains(crate::ehl::driver::POLE_COLLAPSE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ehl::driver::POLE_COLLAPSE;

    fn closed(message: String) -> Error {
        Error::FilmClosed { message, closed: vec![[0.0, -0.75]], reached: None }
    }

    #[test]
    fn a_failed_level_gets_the_cheapest_remedy_left() {
        let newton = Failure { newton: true, ..Failure::default() };
        let everything = Tried { plain_alone: true, raisable: true, from_try_state: true, last_resorts: false, zone_retry: true };
        assert_eq!(remedy(&newton, &everything), Remedy::HalveQuartered);
        let raisable = Tried { plain_alone: false, ..everything };
        assert_eq!(remedy(&newton, &raisable), Remedy::Raise);
        let raised = Tried { raisable: false, ..raisable };
        assert_eq!(remedy(&newton, &raised), Remedy::FromCoarser);
        let from_coarser = Tried { from_try_state: false, ..raised };
        assert_eq!(remedy(&newton, &from_coarser), Remedy::FullLadder);
        let ladder_tried = Tried { last_resorts: true, ..from_coarser };
        assert_eq!(remedy(&newton, &ladder_tried), Remedy::ZoneMesh);
        assert_eq!(remedy(&newton, &Tried { zone_retry: false, ..ladder_tried }), Remedy::Short);
        // A film closed at a spin pole is no Newton failure to retry: no raise, no ladder.
        let pole = Failure { at_pole: true, ..Failure::default() };
        assert_eq!(remedy(&pole, &everything), Remedy::SpinPole);
        // A failure outside Newton gets only the last resorts and the zone's mesh.
        let other = Failure::default();
        assert_eq!(remedy(&other, &everything), Remedy::FullLadder);
        assert_eq!(remedy(&other, &ladder_tried), Remedy::ZoneMesh);
        // An interruption is never retried.
        let stopped = Failure { interrupted: true, newton: true, at_pole: false };
        assert_eq!(remedy(&stopped, &everything), Remedy::Stop);
    }

    #[test]
    fn only_newtons_failure_at_a_spin_pole_stops_the_refinement() {
        // The driver's diagnosis of a film closed next to a pole inside the Hertz circle,
        // bare and as a level's context adds it.
        let pole = closed(format!("film closed at (0.000, -0.750)a; the film closes at (0.000, -0.750)a, {POLE_COLLAPSE} (0, -0.633)a"));
        assert!(closed_at_spin_pole(&pole) && newton_failure(&pole));
        let wrapped = Error::Context { context: "level 1".into(), source: Box::new(pole) };
        assert!(closed_at_spin_pole(&wrapped));
        // A film closed at a side lobe is refined and solved again.
        let lobe = closed("film closed at (0.250, -0.875)a after 7 iterations".into());
        assert!(newton_failure(&lobe) && !closed_at_spin_pole(&lobe));
        // Words alone are not Newton's failure.
        assert!(!closed_at_spin_pole(&Error::Numerical(format!("{POLE_COLLAPSE} (0, -0.6)a"))));
    }
}
