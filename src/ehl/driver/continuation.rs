//! Newton with continuation. Plain Newton runs first at the base problem (the scene, with
//! a stiff cavitation penalty lowered to [`PENALTY_START`]); if it fails from the Hertz
//! start, the homotopies of [`homotopies`] are tried in order, each a scene parameter and
//! a ramp: find a milder problem Newton solves from the start, then ramp the parameter back
//! to the scene's value, each converged state starting the next solve. Last, a staged
//! penalty is ramped from [`PENALTY_START`] to the scene's, or, with cavitation as
//! complementarity, the complementarity form is solved from the penalty solution. Every
//! Newton solve is logged and kept in the path. The solves are [`Newton`]'s
//! ([`super::newton`]), the homotopies [`super::homotopy`]'s.
use super::homotopy::{homotopies, Homotopy, Parameter, Ramp, RampSteps};
use super::newton::{bt_gave_out, new_snes, set_line_search, Newton};
use super::policy::{newton_atol, set_newton_linear_solver, Policy, INTERMEDIATE_ATOL};
use super::problem::{complementarity, penalty, velocity_field};
use super::start::RampLimits;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::system::EhlProblem;
use crate::error::{Error, Reached};
use crate::petsc::snes::{Snes, SolveReport};
use crate::petsc::{self, Matrix, Vector};

/// The cavitation penalty the penalty continuation starts from (Newton converges from the
/// Hertz start with it on every mesh measured; README "The cavitation penalty and the finer
/// ring").
const PENALTY_START: f64 = 1e3;

/// The penalty xi of the penalty problem from whose solution the complementarity form of
/// cavitation is solved: the scene's, at most [`PENALTY_START`].
pub fn complementarity_start_penalty(scene: &Scene) -> f64 {
    scene.reynolds.penalty.min(PENALTY_START)
}

/// Outcome of [`newton_with_continuation`].
pub(super) struct NewtonOutcome {
    pub(super) x: Vec<f64>,
    pub(super) report: SolveReport,
    pub(super) newton_total: usize,
    pub(super) steps: Vec<String>,
    /// The state came from a continuation (plain Newton from the start did not converge).
    pub(super) continued: bool,
    /// The path of the continuation that reached the scene, the state in the system's
    /// layout. A finer mesh's continuation starts there and ramps through the same values
    /// ([`MilderStart`]).
    pub(super) milder: Option<ContinuationPath>,
    /// The solver of the last Newton solve, with the factorisation it last made: the
    /// monolithic adjoint solves on it ([`super::Kept`]).
    pub(super) snes: Snes,
    /// The staged cavitation penalty's states, when it was staged for a caller that
    /// estimates its error ([`Policy::accepts_short_penalty`]).
    pub(super) penalty: Option<StagedPenalty>,
}

/// A cavitation penalty reached through a staged one: the state converged at `base_xi`
/// (1e3), in the system's layout, and the penalty `xi` the solution was solved at: the
/// scene's, or less when its ramp stalled and the solver was told to accept that
/// ([`Policy::accepts_short_penalty`]); with that, also the last state the ramp converged
/// at below `xi` (`mid`, with its xi), if any. The films of these states give the penalty's
/// own error (`app::estimate::penalty_error`).
#[derive(Debug, Clone)]
pub struct StagedPenalty {
    pub base_xi: f64,
    pub base_x: Vec<f64>,
    pub mid: Option<(f64, Vec<f64>)>,
    pub xi: f64,
    pub scene_xi: f64,
}

impl StagedPenalty {
    /// The solution is at a penalty below the scene's.
    pub fn short(&self) -> bool {
        self.xi < self.scene_xi
    }
}

/// The path of a continuation that reached the scene: the continuation's name, the values
/// of t < 1 its ramp converged at (ascending), and the state at the first of them (the
/// milder problem found).
#[derive(Debug, Clone)]
pub struct ContinuationPath {
    pub parameter: &'static str,
    pub ts: Vec<f64>,
    pub x: Vec<f64>,
    /// The parameter is a last resort (load, speed): a path that changes the film's whole
    /// shape, several steps long.
    pub last_resort: bool,
}

/// A milder problem's state to start a continuation from: a coarser level's converged state
/// at `ts[0]` of the continuation named `parameter`, interpolated onto this mesh (`x`, the
/// system's layout), described by `label`; `ts` are the values of t < 1 the coarser
/// level's ramp converged at. The milder problem is solved from it instead of from the
/// scene's start: from the scene's film a milder problem's first step can cross H = 0 (a
/// smaller alpha's film is thinner), while the coarser level's state is that problem's own
/// solution. The ramp then steps through `ts`, where the coarser level's steps converged.
pub(super) struct MilderStart<'a> {
    pub(super) parameter: &'static str,
    pub(super) ts: &'a [f64],
    pub(super) x: &'a [f64],
    pub(super) label: &'a str,
}

/// Newton from `x0` (described by `label`) at the scene's operating point, as the policy
/// says: with `stages_penalty`, a stiff cavitation penalty (xi > 1e3) is solved at xi = 1e3
/// first; with `continues`, if that fails, the [`homotopies`] from a milder problem to the
/// scene's (at xi = 1e3); last the penalty from 1e3 to the scene's xi. With cavitation as
/// complementarity the Hertz start and the continuations solve the penalty problem at
/// xi = 1e3 and then the complementarity form from its solution; another start solves the
/// complementarity form at once. Returns the converged iterate (gathered) or an error
/// naming the path taken.
#[allow(clippy::too_many_arguments)]
pub(super) fn newton_with_continuation(
    ctx: &Context,
    scene: &Scene,
    system: &mut dyn EhlProblem,
    x0: &[f64],
    label: &str,
    policy: Policy,
    j: &Matrix,
    owned: (usize, usize),
    local: usize,
    milder: Option<MilderStart>,
) -> Result<NewtonOutcome, Error> {
    let mut path = Path::new(ctx, scene, policy, j, owned, local)?;
    path.plain(system, x0, label)?;
    path.continuations(system, x0, label, milder)?;
    path.stiff_penalty(system)?;
    path.complementarity(system)?;
    path.outcome()
}

/// The path of one [`newton_with_continuation`]: the problems it solves, in order, and what
/// it has reached. Each step starts from the state the step before left, and does nothing
/// when that step left none (or, for the last two, when its problem is not staged).
struct Path<'a> {
    nw: Newton<'a>,
    scene: &'a Scene,
    policy: Policy,
    /// The problem plain Newton and the continuations solve: the scene, or its penalty
    /// problem at [`PENALTY_START`] when the penalty is staged or the complementarity form
    /// waits for a penalty solution (`relaxed`).
    base: Scene,
    /// With cavitation as complementarity, the scene's penalty problem at
    /// [`complementarity_start_penalty`].
    relaxed: Scene,
    /// A stiff penalty (xi > [`PENALTY_START`]) is reached last, from the state at
    /// [`PENALTY_START`].
    staged: bool,
    /// The state found is the penalty problem's, and the complementarity form is solved
    /// from it.
    from_relaxed: bool,
    /// The last solve's report; none when plain Newton is skipped and no continuation step
    /// gets to a solve.
    last: Option<SolveReport>,
    /// The converged state of the path's last problem, if it converged.
    state: Option<Vec<f64>>,
    /// Plain Newton did not converge (or was skipped): the state is a continuation's.
    continued: bool,
    /// The continuation that reached the scene.
    reached_from: Option<ContinuationPath>,
    /// The furthest a continuation that failed got (largest t), for the error.
    furthest: Option<Reached>,
    /// The staged penalty's states, for a caller that estimates its error.
    staged_penalty: Option<StagedPenalty>,
}

impl<'a> Path<'a> {
    /// The solver and the problems of the path, nothing solved yet.
    ///
    /// A stiff cavitation penalty (xi > 1e3) is reached last, from the solution at
    /// xi = 1e3: on fine rings Newton crawls at xi = 1e4 from the Hertz start (each step
    /// flips nodes across the penalty's kink; 30 iterations wasted on table2-ue2 with the
    /// ring halved), while from the xi = 1e3 solution the cavitated set is already right.
    /// Every other continuation runs at xi = 1e3 too, where Newton converges from the Hertz
    /// start on every mesh measured. A pressure from another mesh is staged the same way, a
    /// previous state of the same mesh (a sweep) goes straight to the scene's xi
    /// ([`Policy::stages_penalty`]).
    ///
    /// The complementarity form of cavitation is solved from a converged state only: a
    /// coarser level's pressure, or this level's penalty solution at xi = 1e3 (its xi does
    /// not reach the result, so the penalty is not staged). From the Hertz start Newton on
    /// it closed the film on table2-ue2's first level, where the penalty converges in 8
    /// iterations (docs/numerics.md "Cavitation as complementarity").
    fn new(
        ctx: &'a Context,
        scene: &'a Scene,
        policy: Policy,
        j: &'a Matrix,
        owned: (usize, usize),
        local: usize,
    ) -> Result<Path<'a>, Error> {
        set_line_search(policy.line_search)?;
        set_newton_linear_solver(policy.reuses_lu)?;
        let comm = petsc::comm_world();
        let opts = crate::ehl_options::get();
        let exact = complementarity(scene);
        let nw = Newton {
            ctx,
            snes: new_snes(comm)?,
            x: Vector::new(comm, local)?,
            j,
            owned,
            row_scaling: opts.row_scaling,
            collapse: None,
            closed: Vec::new(),
            steps: Vec::new(),
            iterations: 0,
            bt_after_domain: policy.bt_after_domain_error(),
            reuses_lu: policy.reuses_lu,
            // With complementarity every penalty problem is short of the scene's.
            scene_penalty: if exact { f64::INFINITY } else { penalty(scene) },
            trail: None,
            short_atol: (scene.accuracy.target > 0.0).then_some(INTERMEDIATE_ATOL.max(newton_atol(scene.accuracy.target))),
            atol: newton_atol(scene.accuracy.target),
        };
        let mut relaxed = scene.clone();
        if exact {
            relaxed.effects.cavitation = crate::case::CavitationModel::Penalty;
            relaxed.reynolds.penalty = complementarity_start_penalty(scene);
        }
        let staged = !exact && policy.stages_penalty && penalty(scene) > PENALTY_START;
        let from_relaxed = exact && policy.from_hertz;
        let mut base = if from_relaxed { relaxed.clone() } else { scene.clone() };
        if staged {
            base.reynolds.penalty = PENALTY_START;
        }
        Ok(Path {
            nw,
            scene,
            policy,
            base,
            relaxed,
            staged,
            from_relaxed,
            last: None,
            state: None,
            continued: true,
            reached_from: None,
            furthest: None,
            staged_penalty: None,
        })
    }

    /// A solve at the base problem is short of the scene.
    fn base_short(&self) -> bool {
        self.staged || self.from_relaxed
    }

    /// 1. Plain Newton from the start at the base problem (unless the policy or
    ///    `-ehl_skip_plain` skips it); a "bt" line search that gave out goes on with "l2".
    fn plain(&mut self, system: &mut dyn EhlProblem, x0: &[f64], label: &str) -> Result<(), Error> {
        if !self.policy.plain_first || crate::ehl_options::get().skip_plain {
            return Ok(());
        }
        let short = self.base_short();
        let mut report = self.nw.solve(&self.base, system, x0, short)?;
        let at_xi = if self.staged { format!(", xi = {PENALTY_START:e}") } else { String::new() };
        let load = self.scene.operating.load;
        self.nw.note(format!("Newton from {label} at L = {load} N{at_xi}: {} ({} iterations)", report.reason, report.iterations));
        // The solve's own count adds to what it already counted: the iterations with the LU
        // reused before an exact finish, a try before a new linear solver.
        self.nw.iterations += report.iterations;
        if self.policy.line_search == "bt"
            && bt_gave_out(&report, self.nw.collapse.is_some())
            && !petsc::options::user_set("-snes_linesearch_type")?
        {
            report = self.nw.on_with_l2(&self.base, system, short, &report)?;
        }
        if self.settle(report)? {
            self.continued = false;
        }
        Ok(())
    }

    /// 2. If plain Newton did not converge: the continuations, each from a milder problem
    ///    back to the base one, on the penalty problem. The continuation a coarser mesh's
    ///    path went through is tried first, even when it is a last resort: that path shows
    ///    it gets somewhere from this start.
    fn continuations(&mut self, system: &mut dyn EhlProblem, x0: &[f64], label: &str, milder: Option<MilderStart>) -> Result<(), Error> {
        if self.state.is_some() || !self.policy.continues {
            return Ok(());
        }
        if complementarity(self.scene) {
            self.base = self.relaxed.clone();
            self.from_relaxed = true;
        }
        let leads = |h: &Homotopy| milder.as_ref().is_some_and(|m| m.parameter == h.parameter.name());
        let mut list: Vec<Homotopy> = homotopies(self.scene, self.policy.from_hertz)
            .into_iter()
            .filter(|h| self.policy.last_resorts || !h.parameter.last_resort() || leads(h))
            .collect();
        list.sort_by_key(|h| !leads(h));
        for h in list {
            // A kinematic parameter also needs a problem whose velocity field can change.
            if h.parameter.kinematic() && !system.set_velocity(velocity_field(self.scene)) {
                continue;
            }
            let from_coarser = milder.as_ref().filter(|m| m.parameter == h.parameter.name() && !m.ts.is_empty());
            if self.continuation(&h, system, x0, label, from_coarser)? {
                return Ok(());
            }
            if h.parameter.kinematic() {
                // Back to the scene's own velocity field for what follows.
                system.set_velocity(velocity_field(self.scene));
                // The film closed at the spin pole on the way to the scene's tilt: every
                // other continuation ends at the same problem, with the pole at the same place.
                if let Some(why) = self.nw.collapse.and_then(|c| c.at_pole()) {
                    self.nw.note(format!(
                        "{}: {why}; the other continuations end at the same tilt, so they are not tried",
                        h.parameter.name()
                    ));
                    return Ok(());
                }
            }
        }
        Ok(())
    }

    /// One continuation `h`: its milder problem, solved from a coarser level's state of it
    /// (`from_coarser`, whose ramp's values are then the schedule) or searched from `x0`,
    /// then the ramp to the base problem. Returns whether it reached it; if not, the
    /// furthest state it converged at is kept when it got further than the ones before.
    fn continuation(
        &mut self,
        h: &Homotopy,
        system: &mut dyn EhlProblem,
        x0: &[f64],
        label: &str,
        from_coarser: Option<&MilderStart>,
    ) -> Result<bool, Error> {
        let mut found = None;
        let mut schedule: &[f64] = &[];
        if let Some(m) = from_coarser {
            if let (_, Some(xs)) =
                self.nw.solve_at(&self.base, h.parameter, (m.ts[0], m.ts[0]), system, m.x, &format!("{} at ", m.label))?
            {
                found = Some((m.ts[0], xs));
                schedule = m.ts;
            }
        }
        if found.is_none() {
            found = self.nw.search(&self.base, h, system, x0, label)?;
        }
        let Some((t, from)) = found else { return Ok(false) };
        let first = from.clone();
        let steps = RampSteps::new(h.ramp.ratio, schedule, self.policy.ramp);
        let (done, r, xs, below) = self.nw.ramp(&self.base, h, t, from, system, steps)?;
        if r.is_some() {
            self.last = r;
        }
        if done {
            self.state = Some(xs);
            self.reached_from =
                Some(ContinuationPath { parameter: h.parameter.name(), ts: below, x: first, last_resort: h.parameter.last_resort() });
            return Ok(true);
        }
        let t_last = below.last().copied().unwrap_or(t);
        if self.furthest.as_ref().map_or(true, |f| t_last > f.t) {
            self.furthest = Some(Reached { parameter: h.parameter.name(), t: t_last, x: xs });
        }
        Ok(false)
    }

    /// 3. The staged penalty: from the base solution, xi goes to the scene's in one step
    ///    (its square root, and so on, on failure). table2-ue2 with the ring halved,
    ///    xi = 1e4: 11 iterations at 1e3, then 7 to 1e4 (135 s); by factors of sqrt(10):
    ///    6 + 5 (162 s); plain Newton at 1e4 from the Hertz start: DIVERGED_MAX_IT after 30.
    ///    A ramp that stalls above 1e3 ends the solve, unless the caller accepts a penalty
    ///    short of the scene's: then the state it converged at is solved to the scene's
    ///    tolerance and kept. At M = 10, L = 20 on a 0.0625 a level every try stalled
    ///    between xi = 2.4e3 and 3e3, cycling on a one-element outlet spike, while the films
    ///    moved by 0.1 % between 1e3 and 2.4e3 (docs/accuracy.md, "A penalty ramp that
    ///    stalls").
    fn stiff_penalty(&mut self, system: &mut dyn EhlProblem) -> Result<(), Error> {
        let staged = self.staged;
        let Some(from) = self.state.take_if(|_| staged) else { return Ok(()) };
        let xi = penalty(self.scene);
        let first = PENALTY_START / xi;
        let h = Homotopy { parameter: Parameter::Penalty(xi), ramp: Ramp { first, lowest: first, ratio: xi / PENALTY_START } };
        // For a caller that estimates the penalty's error the states the ramp converges at
        // on the way are kept: with a stalled ramp, its last two and the one at 1e3 show
        // the order at which the films converge in xi (docs/accuracy.md). The state at 1e3
        // is kept only for such a caller.
        let estimates = self.policy.accepts_short_penalty;
        if estimates {
            self.nw.trail = Some(Vec::new());
        }
        let base_x = estimates.then(|| from.clone());
        let steps = RampSteps::new(h.ramp.ratio, &[], RampLimits::DEFAULT);
        let (done, r, xs, below) = self.nw.ramp(self.scene, &h, first, from, system, steps)?;
        if r.is_some() {
            self.last = r;
        }
        let t = if done { 1.0 } else { below.last().copied().unwrap_or(first) };
        if done {
            self.state = Some(xs);
        } else if estimates && t > first {
            let mut at = self.scene.clone();
            at.reynolds.penalty = xi * t;
            let r = self.nw.solve(&at, system, &xs, false)?;
            self.nw.iterations += r.iterations;
            self.nw.note(format!(
                "penalty continuation: kept the state at xi = {:.3e} of {xi:e}, solved to the scene's tolerance: {} ({} iterations)",
                xi * t,
                r.reason,
                r.iterations
            ));
            self.settle(r)?;
        }
        self.staged_penalty = base_x.map(|base_x| {
            let mid = self.nw.trail.take().unwrap_or_default().into_iter().rfind(|(s, _)| *s < t).map(|(s, x)| (xi * s, x));
            StagedPenalty { base_xi: PENALTY_START, base_x, mid, xi: xi * t, scene_xi: xi }
        });
        Ok(())
    }

    /// 4. The complementarity form, from the penalty problem's solution, with the "l2" line
    ///    search (unless the user set one): "bt" refused every full step on table2-ue2's
    ///    0.25 a first level and crawled at its smallest step for 30 iterations, as from
    ///    another mesh's pressure ([`Policy::line_search`]).
    fn complementarity(&mut self, system: &mut dyn EhlProblem) -> Result<(), Error> {
        let from_relaxed = self.from_relaxed;
        let Some(from) = self.state.take_if(|_| from_relaxed) else { return Ok(()) };
        let ls = if petsc::options::user_set("-snes_linesearch_type")? { self.policy.line_search } else { "l2" };
        let r = self.nw.solve_with_line_search((ls, self.policy.line_search), self.scene, system, &from, false)?;
        self.nw.iterations += r.iterations;
        self.nw.note(format!(
            "cavitation as complementarity, from the penalty solution at xi = {:e}: {} ({} iterations)",
            self.relaxed.reynolds.penalty, r.reason, r.iterations
        ));
        self.settle(r)?;
        Ok(())
    }

    /// A solve's report becomes the path's last, and its solution the path's state when it
    /// converged; returns whether it did.
    fn settle(&mut self, report: SolveReport) -> Result<bool, Error> {
        let converged = report.converged;
        if converged {
            self.state = Some(self.nw.solution()?);
        }
        self.last = Some(report);
        Ok(converged)
    }

    /// The converged state with the path that reached it, or the error naming the path
    /// (the film closed on it, or Newton did not converge) with the furthest state a
    /// continuation reached.
    fn outcome(self) -> Result<NewtonOutcome, Error> {
        let nw = self.nw;
        let (Some(x), Some(report)) = (self.state, self.last.clone()) else {
            let end = match &self.last {
                Some(r) => format!(
                    "{} after {} iterations (residual norm {:.3e}){}",
                    r.reason,
                    r.iterations,
                    r.residual_norm,
                    r.domain_error.as_ref().map(|d| format!("; last domain error: {d}")).unwrap_or_default()
                ),
                None => "no continuation step reached a solve".into(),
            };
            let message = format!(
                "Newton did not converge: {end}{}; path: {}",
                nw.collapse.and_then(|c| c.at_pole()).map(|w| format!("; {w}")).unwrap_or_default(),
                nw.steps.join("; ")
            );
            let reached = self.furthest.map(Box::new);
            return Err(match nw.closed.is_empty() {
                true => Error::NotConverged { message, reached },
                false => Error::FilmClosed { message, closed: nw.closed, reached },
            });
        };
        Ok(NewtonOutcome {
            x,
            report,
            newton_total: nw.iterations,
            steps: nw.steps,
            continued: self.continued,
            milder: self.reached_from,
            snes: nw.snes,
            penalty: self.staged_penalty,
        })
    }
}
