//! The solver-option policy: which coupling a scene gets, and the PETSc options (Newton,
//! line search, linear solver) each solve sets as overridable defaults.
use super::start::{Start, Tries};
use crate::case::Scene;
use crate::petsc;

/// How the elastic unknowns enter Newton.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coupling {
    /// The elastic block condensed onto the contact face (a dense face compliance): Newton
    /// on (P, H0) with a dense Jacobian.
    Condensed,
    /// U, P and H0 in one sparse system.
    Monolithic,
    /// Rigid solids: no elastic unknowns, H = H0 + (X^2 + Z^2)/2; sparse Newton on (P, H0).
    Rigid,
}

impl Coupling {
    /// The coupling for `scene` with `n_p` pressure unknowns, solved from a coarser mesh's
    /// pressure or not (`sequenced`): rigid solids are rigid, else the scene's
    /// `reynolds.coupling` (`monolithic`).
    pub fn of_scene(scene: &Scene, n_p: usize, sequenced: bool) -> Coupling {
        if scene.effects.elasticity == crate::case::ElasticityModel::Rigid {
            Coupling::Rigid
        } else if monolithic(scene.reynolds.coupling, n_p, scene.is_sweep(), sequenced) {
            Coupling::Monolithic
        } else {
            Coupling::Condensed
        }
    }

    /// "condensed", "monolithic" or "rigid" (the name in summary.json and the study tables).
    pub fn name(self) -> &'static str {
        match self {
            Coupling::Condensed => "condensed",
            Coupling::Monolithic => "monolithic",
            Coupling::Rigid => "rigid",
        }
    }
}

/// Whether `coupling` with `n_p` pressure unknowns (in a `sweep` or not, solved from a
/// coarser mesh's pressure or not) means the monolithic system.
pub(super) fn monolithic(coupling: crate::case::Coupling, n_p: usize, sweep: bool, sequenced: bool) -> bool {
    use crate::case::{Coupling as C, AUTO_MONOLITHIC_ABOVE, AUTO_MONOLITHIC_ABOVE_SEQUENCED, AUTO_MONOLITHIC_ABOVE_SWEEP};
    let above = match (sweep, sequenced) {
        (true, _) => AUTO_MONOLITHIC_ABOVE_SWEEP,
        (false, true) => AUTO_MONOLITHIC_ABOVE_SEQUENCED,
        (false, false) => AUTO_MONOLITHIC_ABOVE,
    };
    match coupling {
        C::Monolithic => true,
        C::Condensed => false,
        C::Auto => n_p > above,
    }
}

/// What Newton does from a start ([`Policy::for_start`]).
#[derive(Clone, Copy)]
pub(super) struct Policy {
    /// Newton's failure leads to the automatic continuation.
    pub(super) continues: bool,
    /// A stiff cavitation penalty (xi > 1e3) is reached through xi = 1e3.
    pub(super) stages_penalty: bool,
    /// PETSc's line search (`-snes_linesearch_type` unless the user gave one). From another
    /// mesh's pressure "l2" (the step minimising the residual norm along the direction,
    /// from the norms at steps 1 and 1/2): there a full step overshoots at a few nodes of a
    /// thin side lobe, the backtracking "bt" then takes its smallest step (0.1) every
    /// iteration and Newton crawls (heavy-3gpa's annular patch 0.0039 a -> 0.002 a: 24
    /// iterations from residual 8e-2 to 1.3e-2, stopped; with l2, 13 + 7 iterations to
    /// convergence). From the Hertz start "bt": l2 stops there at once on a closed film
    /// (DIVERGED_FUNCTION_DOMAIN: it does not backtrack out of the film's domain), and on
    /// the Table 2 scenes it costs 0-2 iterations more; a plain Newton whose "bt" gave out
    /// on an open film goes on with "l2" (`bt_gave_out` in the continuation).
    pub(super) line_search: &'static str,
    /// The MUMPS LU is rebuilt every third Newton step, GMRES solving on it in between
    /// ([`set_newton_linear_solver`]); otherwise an LU at every step (exact Newton). Only
    /// on the monolithic coupling and from a start near the solution (another mesh's
    /// pressure, in plain Newton and in the continuation from it; a previous operating
    /// point). In the continuation at M = 1000, L = 10 it took more iterations (levels 3-5:
    /// 46, 42, 79 against 29, 31, 37) but fewer LUs: the levels cost 42, 117 and 617 s
    /// against 58, 195 and 727 s (the run 820 s against 1,030 s), to the same films. From the Hertz start the inexact steps cost
    /// the hard scenes their convergence (spin-0.33deg: plain Newton ran out of its 30
    /// iterations at residual 5e-4, where exact Newton converges in 24, and every
    /// continuation after it failed; that run predates the tilt continuation on the
    /// monolithic coupling).
    pub(super) reuses_lu: bool,
    /// Plain Newton at the scene's problem comes first (the continuation only after it).
    pub(super) plain_first: bool,
    /// The load and speed continuations follow the tilt and pressure-viscosity ones
    /// ([`Start::last_resorts`]).
    pub(super) last_resorts: bool,
    /// When a continuation's ramp gives up ([`Start::ramp`]).
    pub(super) ramp: super::start::RampLimits,
    /// The start is the Hertz start (some continuations are no milder problem from there).
    pub(super) from_hertz: bool,
    /// The caller estimates a staged penalty's error: the solve returns its states
    /// ([`super::StagedPenalty`]), and a ramp that stalls above xi = 1e3 keeps the state it
    /// converged at (solved again to the scene's tolerance) instead of failing, for the
    /// caller to judge. Off unless the solver is told
    /// ([`super::EhlSolver::accept_short_penalty`]).
    pub(super) accepts_short_penalty: bool,
}

impl Policy {
    /// A continuation step with the "l2" line search that stops at the film's domain
    /// (DIVERGED_FUNCTION_DOMAIN: a milder problem's film is thinner, the first step
    /// crosses H = 0 at some nodes, and "l2" does not backtrack out of the domain) is
    /// solved again with "bt", which does (M = 100, L = 20, 0.0625 a, at alpha/4).
    pub(super) fn bt_after_domain_error(&self) -> bool {
        self.continues && self.line_search == "l2"
    }

    /// How Newton proceeds from `start` in the given attempt ([`Attempt`]).
    pub(super) fn for_start(start: &Start, attempt: Attempt) -> Policy {
        let hertz = matches!(start, Start::Hertz);
        let coarse = matches!(start, Start::Pressure { .. });
        Policy {
            // From the Hertz start always; from another start only in the attempt that
            // continues (before it, a failure moves on to the next attempt).
            continues: hertz || attempt.continues,
            // From the Hertz start and from another mesh's pressure (its cavitation boundary
            // is the coarser mesh's), not from a previous state of the same mesh (a sweep).
            stages_penalty: !matches!(start, Start::Previous(_)),
            // "l2" from another mesh's pressure, in the continuation from it too: on the
            // alpha ramp of M = 100, L = 20 (0.125 a) "l2" converged where "bt" stalled at
            // 62.6 of 68.3 GPa^-1. A continuation step that "l2" stops at the film's domain
            // is solved again with "bt" ([`Policy::bt_after_domain_error`]).
            line_search: if coarse { "l2" } else { "bt" },
            reuses_lu: attempt.reuse_lu && !hertz,
            // The continuation attempt follows plain Newton from the same start, which
            // failed: it goes straight to the continuation.
            plain_first: hertz || !attempt.continues,
            last_resorts: start.last_resorts(),
            ramp: start.ramp(),
            from_hertz: hertz,
            accepts_short_penalty: false,
        }
    }
}

/// Newton iterations of one solve (`-snes_max_it` unless the user gave it). Plain Newton
/// from a coarser mesh's pressure converges in 6-14 on the adaptive ladders measured, but in
/// 25-27 on the hard cases' hand-made refinements (docs/hard-cases.md), so it keeps 30.
pub(super) const MAX_IT: usize = 30;

/// One way of solving from a start: [`super::EhlSolver::solve_from`] tries the attempts of
/// [`Attempt::ladder`] in order and then the Hertz start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Attempt {
    /// The monolithic LU is reused over Newton steps ([`Policy::reuses_lu`]).
    pub(super) reuse_lu: bool,
    /// Plain Newton is skipped (it failed in the attempt before) and the continuation
    /// runs from this start.
    pub(super) continues: bool,
}

impl Attempt {
    /// Exact Newton, no continuation: the Hertz start's first solve.
    pub(super) const PLAIN: Attempt = Attempt { reuse_lu: false, continues: false };

    /// The attempts from a start other than the Hertz start, in order, on the monolithic
    /// coupling (`monolithic`) or the condensed one.
    ///
    /// - Plain Newton, with the monolithic LU reused over steps (cheapest near the solution).
    /// - A previous operating point (a sweep) on the monolithic coupling: exact Newton.
    /// - Another mesh's pressure (a coarser level): the continuation from that pressure
    ///   (pressure-viscosity first: alpha/2, then alpha), with the LU reused on the
    ///   monolithic coupling as in plain Newton ([`Policy::reuses_lu`]). At M = 1000, L = 10 from 0.125 a
    ///   to 0.0625 a, plain Newton failed with the LU reused (18 iterations), exact (30)
    ///   and with both step safeguards off (30), and the continuation from the coarse
    ///   pressure converged in 9 + 11 + 7 iterations; the Hertz start on a fine level
    ///   redoes the whole ramp from far away and stalls short of the scene's alpha
    ///   (M = 100, L = 20).
    /// - A coarser level that itself needed the continuation ([`Tries::Continuation`]): the
    ///   continuation at once. Plain Newton failed on every level after the first at
    ///   M = 1000, L = 10 and M = 100, L = 20 (levels 1-3), and on the 449k-unknown level it
    ///   cost 540 s before the continuation started. Its milder problem starts from the
    ///   coarser level's own state of that problem when the start carries one
    ///   ([`super::Milder`]).
    pub(super) fn ladder(start: &Start, monolithic: bool) -> Vec<Attempt> {
        let first = Attempt { reuse_lu: monolithic, ..Attempt::PLAIN };
        match start {
            Start::Hertz => vec![Attempt::PLAIN],
            Start::Previous(_) if monolithic => vec![first, Attempt::PLAIN],
            Start::Previous(_) => vec![first],
            Start::Pressure { tries: Tries::PlainThenContinuation, .. } => vec![first, Attempt { continues: true, ..first }],
            Start::Pressure { tries: Tries::Plain, .. } => vec![first],
            Start::Pressure { tries: Tries::Continuation, .. } => vec![Attempt { continues: true, ..first }],
        }
    }

    /// What the attempt is, for the log.
    pub(super) fn describe(&self) -> &'static str {
        match (self.reuse_lu, self.continues) {
            (true, false) => "plain Newton with the LU reused over steps",
            (false, false) => "exact plain Newton",
            (true, true) => "the continuation with the LU reused over steps",
            (false, true) => "the continuation",
        }
    }
}

/// Options prefix of the condensed Newton Jacobian (`-condensed_mat_type aij` with
/// `-pc_factor_mat_solver_type mumps` returns to the sparse-format MUMPS LU).
pub const CONDENSED_PREFIX: &std::ffi::CStr = c"condensed_";

/// Newton's absolute tolerance on the residual norm without an accuracy target: the
/// converged numbers agree to 1e-8 whatever the start.
pub const NEWTON_ATOL: f64 = 1e-11;

/// Newton's absolute tolerance per unit of `accuracy.target`. The Reynolds rows are scaled
/// by their diagonal, so their residual is a nodal pressure correction in units of p_H;
/// 1e-6 of the target leaves a film error orders of magnitude below the target even at
/// H ~ 5e-3 (the heaviest scenes), and Newton, quadratic there, ends one step earlier than
/// at [`NEWTON_ATOL`]: on table2-ue2 at target 0.01 every level's hc, hm and pmax are the
/// same to 6 digits, and the monolithic levels save their last LU (103 s against 118 s).
pub const NEWTON_ATOL_PER_TARGET: f64 = 1e-6;

/// Newton's absolute tolerance, with an accuracy target, on a problem short of the scene's
/// (a continuation step below t = 1, the staged penalty's xi = 1e3). Its state only starts
/// the next solve, whose own change (the parameter's step) puts the residual back at
/// 1e-3..1e-1: converging it below 1e-6 costs Newton steps and changes nothing.
pub const INTERMEDIATE_ATOL: f64 = 1e-6;

/// Newton's absolute tolerance for a scene with accuracy target `target` (0: none).
pub fn newton_atol(target: f64) -> f64 {
    if target > 0.0 {
        (NEWTON_ATOL_PER_TARGET * target).max(NEWTON_ATOL)
    } else {
        NEWTON_ATOL
    }
}

/// Newton defaults (overridable by PETSc options); `target` is the scene's accuracy target
/// (0: none), which sets the absolute tolerance ([`newton_atol`]).
pub fn set_newton_defaults(target: f64) -> petsc::Result<()> {
    use petsc::options::{set_default, set_ours};
    set_default("-snes_type", "newtonls")?;
    set_default("-snes_linesearch_type", "bt")?;
    set_default("-snes_max_it", &MAX_IT.to_string())?;
    set_default("-snes_rtol", "1e-10")?;
    set_ours("-snes_atol", &format!("{:e}", newton_atol(target)))?;
    // A tiny step is not convergence: only the residual norm decides.
    set_default("-snes_stol", "0")?;
    Ok(())
}

/// MUMPS's block low-rank dropping parameter (`-mat_mumps_cntl_7`) of the monolithic LU that
/// GMRES is preconditioned with. The low-rank blocks of the fronts are compressed to this
/// relative accuracy: the factorisation is cheaper and smaller, and GMRES, which corrects a
/// three-step-old LU anyway, takes the same Newton steps or one more per level. table2-ue2
/// at target 0.005 (2 ranks, the same films and estimates to 6 digits): 148 s and 4.3 GB
/// per rank against 187 s and 5.3 GB with the full-rank LU (medians of 3). Single runs of
/// other values: 1e-6 164 s (1e-5: 138 s); 1e-4 142 s, 3.8 GB, one Newton step more on
/// level 3; 1e-3 146 s, two more on level 4. docs/performance.md, "Block low-rank LU under
/// GMRES".
pub const BLR_DROPPING: &str = "1e-5";

/// The linear solve of a Newton step (each overridable by PETSc options).
///
/// `reuse_lu` (the monolithic coupling from a start near the solution, see
/// `Policy::reuses_lu`): the MUMPS LU of the sparse Jacobian is rebuilt every third Newton step and
/// GMRES solves on the last one, to the Eisenstat-Walker tolerance (inexact Newton: loose
/// while the residual is large, tight near the solution). The LU is 87 % of a monolithic
/// step (table2-ue2, narrow ring 0.015625 a: 5.1 s per factorisation, 0.16 s per
/// triangular solve); from level 1's pressure this took 10-11 iterations and 41-42 s
/// instead of 9 and 66-71 s, to the same film (README "Solver options"). From the Hertz
/// start it took 17 iterations and 59 s instead of 13 and 102 s there, but it made
/// spin-0.33deg fail, so the Hertz start keeps exact Newton (the user can ask for the
/// reuse everywhere: `-snes_lag_preconditioner 3 -ksp_type gmres -snes_ksp_ew`, and for
/// exact Newton everywhere: `-snes_lag_preconditioner 1 -ksp_type preonly -snes_ksp_ew false`).
///
/// Otherwise a fresh LU every step and one back-substitution: the condensed coupling (the
/// ScaLAPACK LU of the Table 2 scenes is 0.4 s, about what a stale LU costs in GMRES
/// iterations) and the Hertz start.
///
/// Where GMRES corrects the LU anyway (`reuse_lu`), the LU is MUMPS's block low-rank one
/// ([`BLR_DROPPING`]); a back-substitution alone (`preonly`) keeps the full-rank LU.
///
/// Set with `set_ours` before every solve, so that each solve of a process gets its own,
/// while the user's flags stay.
pub fn set_newton_linear_solver(reuse_lu: bool) -> petsc::Result<()> {
    use petsc::options::set_ours;
    let settings: &[(&str, &str)] = if reuse_lu {
        &[
            ("-ksp_type", "gmres"),
            ("-ksp_gmres_restart", "100"),
            ("-snes_lag_preconditioner", "3"),
            ("-snes_ksp_ew", "true"),
            ("-mat_mumps_icntl_35", "1"),
            ("-mat_mumps_cntl_7", BLR_DROPPING),
        ]
    } else {
        &[("-ksp_type", "preonly"), ("-snes_lag_preconditioner", "1"), ("-snes_ksp_ew", "false"), ("-mat_mumps_icntl_35", "0")]
    };
    for (k, v) in settings {
        set_ours(k, v)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{Attempt, Policy, Start, Tries};

    #[test]
    fn another_meshs_pressure_continues_from_itself_after_a_short_plain_newton() {
        let p = |_: f64, _: f64| 0.0;
        let coarse = Start::from_pressure(&p, 0.5, "level 0");
        for monolithic in [true, false] {
            let ladder = Attempt::ladder(&coarse, monolithic);
            assert_eq!(ladder.len(), 2);
            assert_eq!(ladder[0].reuse_lu, monolithic);
            let (plain, cont) = (Policy::for_start(&coarse, ladder[0]), Policy::for_start(&coarse, ladder[1]));
            assert!(plain.plain_first && !plain.continues);
            assert!(!cont.plain_first && cont.continues);
            assert_eq!(cont.reuses_lu, monolithic);
            assert_eq!((plain.line_search, cont.line_search), ("l2", "l2"));
            assert!(cont.bt_after_domain_error() && !plain.bt_after_domain_error());
        }
        // After a coarser level that needed the continuation: the continuation at once.
        let hard = Start::Pressure {
            p: &p,
            hc: 0.5,
            label: "level 1",
            tries: Tries::Continuation,
            milder: None,
            last_resorts: true,
            ramp: crate::ehl::driver::RampLimits::DEFAULT,
            coarser: None,
        };
        assert_eq!(Attempt::ladder(&hard, true), vec![Attempt { reuse_lu: true, continues: true }]);
        assert_eq!(Attempt::ladder(&hard, false), vec![Attempt { reuse_lu: false, continues: true }]);
        // A quartered level: plain Newton alone (its caller halves the level instead).
        let quartered = Start::Pressure {
            p: &p,
            hc: 0.5,
            label: "level 3",
            tries: Tries::Plain,
            milder: None,
            last_resorts: false,
            ramp: crate::ehl::driver::RampLimits::BEFORE_A_REMEDY,
            coarser: None,
        };
        assert_eq!(Attempt::ladder(&quartered, true), vec![Attempt { reuse_lu: true, continues: false }]);
        assert!(!quartered.last_resorts());
        // A sweep's previous point: the LU reuse on the monolithic coupling, then exact Newton.
        let x = [0.0; 4];
        assert_eq!(Attempt::ladder(&Start::Previous(&x), true).len(), 2);
        assert_eq!(Attempt::ladder(&Start::Previous(&x), false), vec![Attempt::PLAIN]);
        assert!(!Policy::for_start(&Start::Previous(&x), Attempt::PLAIN).continues);
        let hertz = Policy::for_start(&Start::Hertz, Attempt::PLAIN);
        assert!(hertz.continues && hertz.plain_first && !hertz.reuses_lu && hertz.last_resorts);
        // A caller with a remedy of its own: the continuation without the last resorts.
        let own = Start::Pressure {
            p: &p,
            hc: 0.5,
            label: "level 2",
            tries: Tries::Continuation,
            milder: None,
            last_resorts: false,
            ramp: crate::ehl::driver::RampLimits::DEFAULT,
            coarser: None,
        };
        let ladder = Attempt::ladder(&own, true);
        assert!(ladder.iter().all(|a| !Policy::for_start(&own, *a).last_resorts));
        assert!(!own.last_resorts() && hard.last_resorts());
    }

    #[test]
    fn auto_coupling_switches_to_monolithic_above_the_measured_crossover() {
        use crate::case::{Coupling, AUTO_MONOLITHIC_ABOVE as N, AUTO_MONOLITHIC_ABOVE_SEQUENCED as NQ, AUTO_MONOLITHIC_ABOVE_SWEEP as NS};
        assert!(!super::monolithic(Coupling::Auto, N, false, false));
        assert!(super::monolithic(Coupling::Auto, N + 1, false, false));
        assert!(!super::monolithic(Coupling::Auto, N + 1, true, false));
        assert!(super::monolithic(Coupling::Auto, NS + 1, true, false));
        // From a coarser mesh's pressure the condensation is not paid back as early.
        const { assert!(NQ < N) };
        assert!(!super::monolithic(Coupling::Auto, NQ, false, true));
        assert!(super::monolithic(Coupling::Auto, NQ + 1, false, true));
        assert!(!super::monolithic(Coupling::Auto, NQ + 1, true, true));
        assert!(!super::monolithic(Coupling::Condensed, 100 * N, false, true));
        assert!(super::monolithic(Coupling::Monolithic, 10, true, false));
    }
}
