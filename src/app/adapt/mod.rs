//! Adaptive refinement to an accuracy target (`[accuracy] target`).
//!
//! 1. Solve on the scene's mesh (level 0).
//! 2. Mark the fewest contact triangles that carry the fraction `accuracy.marking` of the
//!    goal-oriented indicator: the mass-flux residual ([`crate::reynolds::estimate`])
//!    weighted by the adjoints of hc, hm and, with friction, fx and fz (how much a flux
//!    error in each triangle moves them); with `marking` 0, every
//!    triangle of the pressurised zone (a nodal pressure above 0.01 p_H). Halve their size
//!    (quarter it for those whose indicator is 16 times the smallest marked one, while an
//!    estimate is above 4 times the target, the target is 0.005 or more, Newton reached
//!    the level without a continuation and fz is no target: `marking::quarters`), keep
//!    the others'
//!    (a graded size field on the face, [`crate::mesh::size_field`]), and mesh the solid
//!    anew under it (conforming bisection). From level 1 on, a marking of fewer than 32
//!    triangles whose next level would have fewer than 1.5 times this level's contact
//!    triangles is widened to the next triangles by indicator until it has them
//!    (`widened`): that level may end the run, and a level made from so few triangles
//!    certifies itself only with that growth (`certifies`).
//! 3. Solve from the previous level's pressure, interpolated (mesh sequencing), and after a
//!    monolithic level from its displacement too.
//! 4. Estimate the error of hc and hm (and fx, fz with friction) from the change between
//!    the last two levels, e_k = |Q_k - Q_{k-1}| max(1, rho/(1 - rho)) with rho the observed
//!    ratio of the last two changes (capped at 0.8): for a sequence converging by a factor
//!    rho per level the remaining error is rho/(1 - rho) times the last change. A change
//!    below 1/8 of the one before it (1/64 on a level made by quartering) is a crossing of
//!    the limit, not convergence (see
//!    `estimate::estimate_scaled`). Stop when every estimate is below the target (from level 2 on, so
//!    that rho is measured).
//! 5. A next level above `accuracy.max_unknowns` (or the unknowns the time left or the
//!    memory a rank may reach holds: `marking::TimeLeft`, `memory::MemoryLeft`) refines
//!    only the marked triangles of largest indicator that fit (`marking::cut_count`), once per run; its
//!    estimate is the one before it less its change (`estimate_after_cut`), unless it
//!    keeps 90 % of the marked indicator: then it is estimated and gated as a full level
//!    (`Estimate::cut_worth_solving`).
//! 6. When the target cannot be reached (`accuracy.max_levels` levels solved, the next
//!    level above a budget with too little room for a cut, or every
//!    triangle at the smallest size), the
//!    last level's result is written with its estimated error, `accuracy.reached` is
//!    false and the run exits 4: a result, honestly labelled, rather than none.
//! 7. A level whose cavitation penalty's own error stands between it and the target
//!    (`estimate::penalty_in_the_way`), or alone keeps a level cut to the budget from it,
//!    has its mesh solved again as complementarity, as the next level, and the levels after
//!    it solve complementarity too. In the estimate's sequence that level takes the
//!    penalty level's place, the coarser levels counted less the penalty's error it
//!    measured (`estimate::sequence`). Where the two models' difference on that mesh alone
//!    then keeps it from the target (`Estimate::models_gap_in_the_way`), the mesh of the
//!    penalty level before it is solved again too, and the estimate's last change is
//!    between two complementarity films.
//!
//! This file holds the loop and steps 1, 2, 4, 6 and 7; `attempt` step 3 (a level's solve
//! and, when it fails, the remedy applied), `remedy` the choice of that remedy, `budget`
//! step 5 (the budgets and the level cut to them), `level` the record of each level and
//! summary.json's report, `end` the written result.
mod attempt;
mod budget;
mod end;
mod level;
mod remedy;

use super::estimate::{penalty_in_the_way, Estimate, PenaltyError, PenaltySlopes};
use super::first_level::{first_level_again, Onward, FIRST_LEVEL_RETRIES};
use super::lubricated::Setup;
use super::marking::{goal_mark, goals, longest_edges, quarters, widened_count, zone_mark, Goal, Marking, NextMesh};
use super::memory;
use super::point::PointResult;
use super::{Context, Outcome};
use crate::case::schema::Accuracy;
use crate::case::{CavitationModel, Scene};
use crate::collective;
use crate::ehl::driver::{EhlSolution, EhlSolver};
use crate::ehl::post::{FieldsOnFace, FilmStats};
use crate::error::{Error, Reached};
use crate::friction::pass::FrictionResult;
use end::{describe, finish, out_of_time, short_of};
pub use level::{replacement, written, Budget, Cut, Level};
use std::time::Instant;

/// Smallest element size adaptive refinement makes (units of a): 16/2^12.
pub const MIN_ADAPTIVE_SIZE: f64 = 16.0 / 4096.0;

/// How much a level's contact triangles must outnumber the level before's for its change to
/// certify it: a level that refined a small part of the face changes little whatever its
/// error. M = 100, L = 20 at target 0.01: level 1's marking took 7 of its 965 triangles
/// (the indicator's 90 % sat on the outlet spike), level 2 had 1,201, its hc changed by
/// -0.28 % and its estimate said 0.30 %, where its error against the quarter-target film
/// was +0.6 % (the next levels changed hc by -0.59 % and -0.01 %). On the Moes map the
/// last levels otherwise grow by 1.8 times or more (docs/accuracy.md, "The Moes map with
/// no mesh keys"). It holds for a level made from a marking of fewer than [`FEW_MARKED`]
/// triangles; such a marking is widened ([`widened`]), and the rule holds where that cannot
/// be done (no eligible triangle left).
const CERTIFYING_GROWTH: f64 = 1.5;

/// A marking of fewer triangles than this refines one feature a few elements wide (the
/// outlet spike at L = 20 and light load: 3-7 triangles; M = 200, L = 20: 22), and the
/// level made from it is held to [`CERTIFYING_GROWTH`]. A larger marking's level
/// certifies itself whatever its growth: on a fine face at high load Doerfler's set is a
/// small share of the triangles because the error sits in thin side lobes, and each level
/// grows the face by 1.33-1.39 times (cases/hard/heavy-3gpa: 94, 132 and 254 triangles
/// on levels 1-3). Widened to 1.5 times there, its levels reached the unknowns budget at
/// level 3 with estimates of 11 % and 7 %, where the levels as marked reach 0.01 at level
/// 4 with 540,644 unknowns (docs/accuracy.md, "Markings of a few triangles, widened").
const FEW_MARKED: usize = 32;

/// A widened marking aims at this many times [`CERTIFYING_GROWTH`], so that the power law
/// of [`widened_count`] lands above the growth from its first extrapolation.
const WIDENING_AIM: f64 = 1.1;

/// Meshes tried for a widened marking (each a fraction of a second at the sizes where
/// Doerfler's set is small).
const MAX_WIDENINGS: usize = 5;

/// A solved level kept for the next one: its setup, solution, dimensionless central film
/// and condensation time.
struct Solved {
    setup: Setup,
    sol: EhlSolution,
    hc: f64,
    condensation_s: Option<f64>,
    /// `speed_exponents` of summary.json, when the scene asks for them.
    exponents: Option<serde_json::Value>,
    /// The gradient-jump factor the level was solved with (it may be raised after it).
    gradient_jump: f64,
    /// The cavitation model the level was solved with (complementarity may take over after
    /// it).
    cavitation: CavitationModel,
    /// The marking of the next level (None on the last).
    marking: Option<Marking>,
    /// The size field the level was meshed with (None: the scene's mesh), for solving its
    /// mesh again.
    mesh_from: Option<NextMesh>,
    /// The level's friction pass, which the result's post-processing reports (a second
    /// pass on the same state gives the same numbers: on a 0.0078 a level of a thick film
    /// it took 66 s).
    friction: Option<FrictionResult>,
}

impl Solved {
    /// The next level's mesh from this level's marking with its quartered triangles halved
    /// (for a level over its budget, or one whose plain Newton failed on the quartered mesh).
    fn halved_marking(&mut self, growth: f64) -> Option<NextMesh> {
        let m = self.marking.as_mut()?;
        m.quarter = false;
        Some(NextMesh::marked(&self.setup.mesh, &longest_edges(&self.setup.mesh), m, None, growth))
    }
}

/// What an adaptive run wrote: its outcome, the last level's numbers and estimate, how many
/// levels it solved and the unknowns of the last.
pub struct Adapted {
    pub outcome: Outcome,
    pub point: PointResult,
    pub estimate: Option<Estimate>,
    pub levels: usize,
    pub unknowns: usize,
    /// Newton iterations of every level (the attempts that converged).
    pub newton_iterations: usize,
    /// pmax's relative change over the last level (`estimate::pmax_change`), not estimated.
    pub pmax_change: Option<f64>,
}

/// What one step of a level's try leads to.
enum Step<T> {
    /// On to the next step, with what this one made.
    On(T),
    /// The level is tried again: on another mesh, from another start or with a remedy.
    Again,
    /// The run ends: with its written result, or with the error that stopped it.
    Done(Box<Result<Adapted, Error>>),
}

impl<T> Step<T> {
    /// The run's end with `end`.
    fn end(end: Result<Adapted, Error>) -> Self {
        Step::Done(Box::new(end))
    }
}

/// The product of a [`Step`]; on [`Step::Again`] the loop's next pass, on [`Step::Done`]
/// the run's end.
macro_rules! step {
    ($step:expr) => {
        match $step {
            Step::On(v) => v,
            Step::Again => continue,
            Step::Done(end) => return *end,
        }
    };
}

/// Runs the adaptive loop of a lubricated single-point scene with `accuracy.target > 0`.
/// Collective. When the target cannot be reached (`max_levels`, `max_unknowns`, every
/// triangle at the smallest size) the last level's result is written with its estimated
/// error and the returned outcome is [`Outcome::ShortOfTarget`], saying why (exit 4).
///
/// Each pass of the loop is one try of a level, in the steps of the module documentation.
pub fn run(ctx: &Context, scene: &Scene, earlier: Option<&super::restart::EarlierRun>) -> Result<Adapted, Error> {
    let mut run = Loop::new(ctx, scene, earlier);
    loop {
        // The level's scene: the run's may change for the levels after it (the
        // gradient-jump factor raised, cavitation as complementarity).
        let scene = run.own.clone();
        let k = run.levels.len();
        let t0 = Instant::now();
        // Step 1: the scene's mesh, or the level before's marking refined.
        let setup = step!(run.mesh(&scene, k));
        // Step 5: within the budgets, or cut to them, or not begun.
        step!(run.within_budgets(&scene, &setup, k));
        // Steps 3, 4 and 2: solved (with the remedies when it fails), estimated, and the
        // next level marked.
        let solved = step!(run.solve(&scene, setup, k, t0));
        // Steps 6 and 7: the end at the target or a limit, the mesh again as
        // complementarity, or the next level's mesh.
        step!(run.after(&scene, solved, k));
    }
}

/// The adaptive loop's state from one try of a level to the next.
struct Loop<'c> {
    ctx: &'c Context,
    /// The earlier run whose state the first level goes on from (`--restart`).
    earlier: Option<&'c super::restart::EarlierRun>,
    acc: Accuracy,
    /// The scene as solved: the gradient-jump factor may be raised, and cavitation turned
    /// to complementarity, on the way.
    own: Scene,
    /// The levels solved, one per converged level (a retried first level stays 0).
    levels: Vec<Level>,
    /// The next level's size field with its halvings (None: the scene's own mesh).
    next: Option<NextMesh>,
    /// The last level solved.
    previous: Option<Solved>,
    /// Tries of the first level on a finer mesh after it failed on the scene's own.
    first_retries: usize,
    /// The level that may be meshed again with zone marking if it does not converge on its
    /// goal-oriented mesh.
    zone_retry: Option<usize>,
    /// The level solved again with the load and speed continuations and the Hertz start.
    full_ladder: Option<usize>,
    /// Seconds of the present level's attempts that did not converge: part of its time.
    tried_s: f64,
    /// Where a failed first level got, with its mesh: the retry goes on from there
    /// ([`super::first_level::onward`]).
    from: Option<Onward>,
    /// Where the continuation of a level that failed before the raise of the gradient-jump
    /// factor got, on the level's mesh: its solve with the factor raised goes on from there.
    raised_from: Option<Reached>,
    /// How the present level is cut when all its marked triangles would exceed a budget.
    cut: Option<Cut>,
    /// The meshes tried for the present level that were over the budget (count, unknowns).
    over: Vec<(usize, u64)>,
    /// The present level was made by quartering and its plain Newton failed: it is meshed
    /// again with the quartered triangles halved.
    halve_quartered: bool,
    /// The present level is the mesh of this level solved again as complementarity (the
    /// cavitation penalty's own error stood in the way of the last penalty level).
    again_of: Option<usize>,
    /// The penalty level whose mesh the present level solves again as complementarity,
    /// where it is not the last penalty level: that one's mesh solved again is then
    /// `previous` ([`Loop::switch_to_complementarity`]).
    back: Option<Solved>,
    /// The penalty level before the last penalty level: kept while cavitation is the
    /// penalty, for a switch to complementarity, and from the switch until the last
    /// penalty level's mesh solved again is judged, for solving its mesh again too.
    before: Option<Solved>,
}

/// What the record of a level leaves for its [`Solved`] and for the loop's decision.
struct LevelEnd {
    marking: Option<Marking>,
    friction: Option<FrictionResult>,
    exponents: Option<serde_json::Value>,
    edges: Vec<f64>,
    reached: bool,
}

/// A level solved and recorded, before the loop decides what follows it: its state, its
/// contact triangles' longest edges, and whether it reached the target.
struct Recorded {
    here: Solved,
    edges: Vec<f64>,
    reached: bool,
}

impl<'c> Loop<'c> {
    fn new(ctx: &'c Context, scene: &Scene, earlier: Option<&'c super::restart::EarlierRun>) -> Self {
        let acc = scene.accuracy;
        ctx.log(format!(
            "accuracy: target {} (relative error of hc and hm{}): adaptive refinement of the contact face, at most {} levels after the first and {} unknowns per level",
            acc.target,
            if scene.effects.friction == crate::case::FrictionModel::Off { "" } else { ", fx and fz" },
            acc.max_levels,
            acc.max_unknowns
        ));
        Loop {
            ctx,
            earlier,
            acc,
            own: scene.clone(),
            levels: Vec::new(),
            next: None,
            previous: None,
            first_retries: 0,
            zone_retry: None,
            full_ladder: None,
            tried_s: 0.0,
            from: None,
            raised_from: None,
            cut: None,
            over: Vec::new(),
            halve_quartered: false,
            again_of: None,
            back: None,
            before: None,
        }
    }

    /// After level `k` stopped with `e`: the last converged level's result when the time
    /// budget was spent, or the error ([`out_of_time`]).
    fn stopped(&self, scene: &Scene, k: usize, e: Error) -> Result<Adapted, Error> {
        out_of_time(self.ctx, scene, self.previous.as_ref(), k, &self.levels, e)
    }

    /// The run's end with the level before's result, short of the target because of `why`.
    fn short<T>(&self, scene: &Scene, prev: &Solved, why: &str) -> Step<T> {
        let why = short_of(self.acc.target, why, &self.levels);
        Step::end(finish(self.ctx, scene, prev, self.acc.target, &self.levels, Some(why)))
    }

    /// Step 1: the level's mesh, from the level before's marking (with its quartered
    /// triangles halved after a quartered try failed), or the scene's own.
    fn mesh(&mut self, scene: &Scene, k: usize) -> Step<Setup> {
        if std::mem::take(&mut self.halve_quartered) {
            if let Some(halved) = self.previous.as_mut().and_then(|p| p.halved_marking(scene.mesh.growth)) {
                self.next = Some(halved);
            }
        }
        match Setup::with_size_field(self.ctx, scene, self.next.as_ref().map(|m| m.field.clone())) {
            Ok(s) => Step::On(s),
            Err(e) => Step::end(self.stopped(scene, k, e)),
        }
    }

    /// Steps 3, 4 and 6 of a level: its solve from the level before (with the remedies
    /// when that fails), its record with the estimate, and the next level's marking.
    fn solve(&mut self, scene: &Scene, setup: Setup, k: usize, t0: Instant) -> Step<Recorded> {
        let ctx = self.ctx;
        // A level after one that plain Newton could not solve from its own coarser level
        // goes to the continuation at once (level 0 is not a guide: its start is the Hertz
        // pressure, not a coarser level's), unless that continuation was a load or speed
        // path: its ramp takes four or more solves where plain Newton takes one. M = 1000,
        // L = 0.01 with level 0 at 0.0625 a (the load path from L/5.2): level 1 failed plain
        // Newton, and levels 2-4 went through the load path at once, 63-87 iterations each,
        // where plain Newton from a finer coarser level took 20-25.
        let continued_near =
            self.previous.as_ref().is_some_and(|p| p.sol.continued && !p.sol.milder.as_ref().is_some_and(|m| m.last_resort));
        let plain = !(k >= 2 && continued_near);
        // From a coarser level's pressure, plain Newton's few steps do not pay back a
        // condensation; a continuation's many steps do, on the condensed coupling's cheaper
        // ones (M = 500, L = 15's level 2, 2,684 pressure unknowns: 16.2 s condensed, 36
        // iterations; 22.9 s monolithic, 42).
        let sequenced = (self.previous.is_some() && plain) || self.earlier.is_some();
        // The level's own peak memory, for its report and the next level's prediction.
        crate::output::restart_peak();
        let mut solver = match EhlSolver::new(ctx, scene, &setup.mesh, &setup.part, &setup.dofs, &setup.layout, setup.half, sequenced) {
            Ok(s) => s,
            Err(e) => return Step::end(self.stopped(scene, k, e)),
        };
        // The adjoint after the level solves on Newton's last factorisation.
        // The complementarity form has no penalty error to estimate.
        let penalised = scene.effects.cavitation == CavitationModel::Penalty;
        solver.keep_newton(self.acc.marking > 0.0 || scene.output.speed_exponents || penalised);
        // A staged penalty that stalls short of the scene's is judged by its error here.
        solver.accept_short_penalty(true);
        let sol = match self.attempt(scene, &setup, &solver, plain, k) {
            Ok(sol) => sol,
            Err(failed) => {
                drop(solver);
                return self.remedied(scene, setup, failed, k, t0);
            }
        };
        let fields = FieldsOnFace::new(&setup.mesh, &setup.layout, &sol.x);
        let st = fields.stats();
        let unphysical = ![st.hc, st.hm, st.pmax].iter().all(|v| v.is_finite()) || st.hm <= 0.0;
        // A first level whose film dips below zero between its nodes (the P2 film under a
        // spin pole or a side lobe narrower than its elements: cases/hard/spin-0.33deg at
        // 0.25 a) is refined and solved again like one that does not converge.
        if unphysical && self.previous.is_none() && self.earlier.is_none() && self.first_retries < FIRST_LEVEL_RETRIES {
            let why = format!(
                "converged to a film that is not positive everywhere (hm = {:.3e} at ({:.3}a, {:.3}a))",
                st.hm, st.hm_at[0], st.hm_at[1]
            );
            // Newton converged: the zone is halved, with no annulus and the gradient-jump term
            // kept (both answer a film closed during Newton at the side lobe). The dip lies
            // next to the spin pole, inside the Hertz circle, on the scenes where it was met:
            // spin-0.33deg's retry with an annulus at 0.0625 a around its radius had 166,728
            // unknowns and stopped at the budget one level earlier (fx 1.46 %, fz 1.37 %);
            // the halved zone has 92,600 and gets a level further (1.31 %, 1.03 %), with
            // the same films.
            self.next = Some(NextMesh::halving(first_level_again(ctx, &setup.mesh, scene.mesh.growth, &why, &[])));
            self.first_retries += 1;
            drop(fields);
            drop(solver);
            self.from = Some(Onward::Converged(setup, sol.x));
            return self.tried_again(t0);
        }
        if unphysical {
            return Step::end(Err(Error::numerical(format!(
                "accuracy: level {k} converged to an unphysical state (hc {}, hm {}); no result written",
                st.hc, st.hm
            ))));
        }
        match self.record(scene, &setup, &solver, &sol, &fields, t0) {
            Ok(LevelEnd { marking, friction, exponents, edges, reached }) => {
                let condensation_s = solver.condensation_s;
                drop(fields);
                drop(solver);
                let here = Solved {
                    setup,
                    sol,
                    hc: st.hc,
                    condensation_s,
                    exponents,
                    gradient_jump: scene.reynolds.gradient_jump,
                    cavitation: scene.effects.cavitation,
                    marking,
                    mesh_from: self.next.clone(),
                    friction,
                };
                Step::On(Recorded { here, edges, reached })
            }
            Err(e) => Step::end(Err(e)),
        }
    }

    /// Step 4, with the adjoints that serve step 2: the record of the level just solved
    /// (films, friction, peak memory), its estimate and log line, and the next level's
    /// marking unless it is the last.
    fn record(
        &mut self,
        scene: &Scene,
        setup: &Setup,
        solver: &EhlSolver<'_>,
        sol: &EhlSolution,
        fields: &FieldsOnFace,
        t0: Instant,
    ) -> Result<LevelEnd, Error> {
        let (ctx, acc, target) = (self.ctx, self.acc, self.acc.target);
        let k = self.levels.len();
        let st = fields.stats();
        let edges = longest_edges(&setup.mesh);
        // The pass's adapted rule is kept for the friction goals' gradient below.
        let friction = level_friction(ctx, scene, fields)?;
        let level = self.level_of(scene, setup, sol, &st, &edges, friction.as_ref(), t0);
        self.over.clear();
        self.levels.push(level);
        if k == 0 && acc.max_seconds > 0.0 {
            // The budget covers the levels after the first: a run always has a result.
            crate::interrupt::set_deadline(Some(ctx.start + std::time::Duration::from_secs_f64(acc.max_seconds)));
        }
        // A level cut to the budget is the last: the level after it would refine the rest of
        // its marking and more, over the budget, and would not be cut again.
        let cut_level = self.levels.last().is_some_and(|l| l.cut.is_some());
        // A coarser mesh solved again serves the estimate of the finer one's film: the run
        // refines that mesh, from its marking.
        let may_go_on = self.refined() < acc.max_levels as usize && !cut_level && self.back.is_none();
        // One adjoint LU serves the next level's marking, the speed exponents when asked for,
        // and the values' slopes in the cavitation penalty, which estimate the penalty's own
        // error: on every level that has an estimate (the second on), also the last, and on
        // the first when it marks anyway.
        let penalised = scene.effects.cavitation == CavitationModel::Penalty;
        let slopes_wanted = k >= 1 && penalised;
        // Without the penalty the estimate needs no slopes: a level it already takes below
        // the target is the last, and its marking is not needed.
        let certifies = certifies(&self.levels);
        let below = |est: Option<Estimate>| est.is_some_and(|e| e.values().iter().all(|&v| v < target));
        let settled = !penalised && self.refined() >= 2 && certifies && below(Estimate::of(&self.levels));
        let goal = may_go_on && acc.marking > 0.0 && !settled;
        let mut adjoint = (goal || slopes_wanted || scene.output.speed_exponents)
            .then(|| collective::agree(&ctx.world, solver.adjoint(ctx, scene, &sol.x)));
        let goals_of = match &adjoint {
            Some(Ok(a)) if goal || slopes_wanted => {
                Some(collective::agree(&ctx.world, goals(ctx, scene, a, fields, &st, friction.as_ref())))
            }
            Some(Err(e)) => Some(Err(Error::numerical(format!("the adjoint failed: {e}")))),
            _ => None,
        };
        let slopes = match (&mut adjoint, &goals_of) {
            (Some(Ok(a)), Some(Ok(g))) if penalised => collective::agree(&ctx.world, super::sensitivity::penalty_slopes(a, g)).map(Some),
            (_, Some(Err(e))) if penalised => Err(Error::numerical(e.to_string())),
            _ => Ok(None),
        };
        let slopes = slopes
            .map_err(|e| ctx.log(format!("accuracy: the films' slopes in the cavitation penalty were not computed ({e}); its part of the estimate is from the staged films alone, where there are two")))
            .ok()
            .flatten();
        self.levels.last_mut().expect("the level just pushed").penalty =
            penalty_of(setup, sol, [st.hc, st.hm], slopes, scene.reynolds.penalty);
        let est = Estimate::of(&self.levels);
        // A coarser mesh solved again estimates the film of the finer one: that level's
        // estimate is replaced.
        let (w, _) = written(&self.levels);
        self.levels[w].est = est;
        ctx.log(self.levels[k].log_line(k));
        if w != k {
            ctx.log(format!("accuracy: level {w}'s estimated error with level {k}: {}", describe(est)));
        }
        let reached = self.refined() >= 2 && certifies && below(est);
        let last = reached || !may_go_on;
        let exponents = match (&mut adjoint, scene.output.speed_exponents) {
            (Some(Ok(a)), true) => Some(collective::agree(&ctx.world, super::sensitivity::speed_exponents(ctx, a, fields, &st))),
            (Some(Err(e)), true) => Some(Err(Error::numerical(format!("the adjoint failed: {e}")))),
            _ => None,
        };
        let exponents = exponents.map(|got| super::sensitivity::report(ctx, got));
        let fz_target = friction.is_some() && !setup.half;
        let quarter = quarters(est.as_ref(), target, fz_target, sol.continued);
        let marking = if last { None } else { Some(self.next_marking(scene, fields, goals_of.filter(|_| goal), &edges, quarter)) };
        drop(adjoint);
        // A level's time includes its adjoint and the marking of the next one.
        let pushed = self.levels.last_mut().expect("the level just pushed");
        pushed.seconds = self.tried_s + t0.elapsed().as_secs_f64();
        pushed.marked = marking.as_ref().map(|m| m.count());
        self.tried_s = 0.0;
        Ok(LevelEnd { marking, friction, exponents, edges, reached })
    }

    /// The record of the level just solved, before its estimate: its mesh, Newton's work,
    /// films and friction, and where it stands in the ladder (a level solved again on an
    /// earlier mesh takes that level's cut and halvings).
    #[allow(clippy::too_many_arguments)]
    fn level_of(
        &mut self,
        scene: &Scene,
        setup: &Setup,
        sol: &EhlSolution,
        st: &FilmStats,
        edges: &[f64],
        friction: Option<&FrictionResult>,
        t0: Instant,
    ) -> Level {
        let k = self.levels.len();
        let (hs, ph) = (scene.scales().film_scale(), scene.hertz().ph);
        let min_size = edges.iter().cloned().fold(f64::INFINITY, f64::min) / std::f64::consts::SQRT_2;
        let replaced = self.again_of.and_then(|j| self.levels.get(j));
        let (elastic_unknowns, pressure_unknowns) = setup.layout.counts();
        Level {
            elastic_unknowns,
            pressure_unknowns,
            contact_triangles: setup.mesh.contact_tris.len(),
            min_size,
            newton_iterations: sol.newton_total,
            seconds: self.tried_s + t0.elapsed().as_secs_f64(),
            failed_seconds: self.tried_s,
            hc: st.hc * hs,
            hm: st.hm * hs,
            hm_at: st.hm_at,
            pmax: st.pmax * ph,
            pmax_at: st.pmax_at,
            friction: friction.map(|f| [f.fx, f.fz]),
            est: None,
            cut: replaced.map_or_else(|| self.cut.take(), |l| l.cut),
            halvings: match replaced {
                Some(l) => l.halvings,
                None if k == 0 => 1,
                None => self.next.as_ref().map_or(1, |m| m.halvings),
            },
            // Set by the caller, once the slopes are known.
            penalty: None,
            again_of: self.again_of.take(),
            marked: None,
            peak_memory_mb: collective::max_f64(&self.ctx.world, crate::output::peak_since_mb()),
        }
    }

    /// Step 2 for the level just recorded: the marking the next level refines, goal-oriented
    /// from the values' `goals` when there are some, the pressurised zone otherwise. A failed
    /// adjoint or goal costs this level's goal-oriented marking, not the run (an
    /// interruption is acted on at the check after the marking).
    fn next_marking(
        &mut self,
        scene: &Scene,
        fields: &FieldsOnFace,
        goals: Option<Result<Vec<Goal>, Error>>,
        edges: &[f64],
        quarter: bool,
    ) -> Marking {
        let k = self.levels.len() - 1;
        match goals {
            Some(Ok(goals)) => {
                self.zone_retry = Some(k + 1);
                goal_mark(self.ctx, scene, fields, &goals, edges, self.acc.marking, quarter)
            }
            Some(Err(e)) => {
                self.ctx.log(format!("accuracy: goal-oriented marking failed ({e}); level {} refines the pressurised zone", k + 1));
                Marking::unranked(zone_mark(fields, edges))
            }
            None => Marking::unranked(zone_mark(fields, edges)),
        }
    }

    /// Refinements so far: a level solved again on its mesh is none.
    fn refined(&self) -> usize {
        self.levels.len().saturating_sub(1) - self.levels.iter().filter(|l| l.again_of.is_some()).count()
    }

    /// Steps 4, 6 and 7 after a level: the run ends at the target or a limit, or the
    /// level's mesh is solved again as complementarity, or the next level's mesh is made
    /// from the marking (widened when too few triangles would make it).
    fn after(&mut self, scene: &Scene, recorded: Recorded, k: usize) -> Step<()> {
        let (ctx, acc, target) = (self.ctx, self.acc, self.acc.target);
        let Recorded { mut here, mut edges, reached } = recorded;
        // The mesh before the last penalty level's, solved again as complementarity, served
        // the estimate of the film of that level's mesh solved so (`previous`): the run
        // ends with that film or refines its mesh.
        if self.back.take().is_some() {
            here = self.previous.take().expect("the film the level before estimated");
            edges = longest_edges(&here.setup.mesh);
        }
        // The level whose film the run has: `k` but after such a level.
        let (w, _) = written(&self.levels);
        if reached {
            ctx.log(format!("accuracy: target {target} reached at level {w}"));
            return Step::end(finish(ctx, scene, &here, target, &self.levels, None));
        }
        // The mesh's refinement cannot take the penalty's own error below the target: a
        // penalty part above a quarter of it, once the mesh's part is below it, has this
        // level's mesh solved again, and the levels after it solved, with the Reynolds
        // condition as complementarity, which has no such part. In the estimate the level
        // solved again takes this one's place (docs/accuracy.md, "Complementarity where it
        // dominates").
        let in_the_way = self.levels[w].penalty.filter(|p| penalty_in_the_way(p, self.levels[w].est.as_ref(), target));
        if let Some(p) = in_the_way.filter(|_| self.own.effects.cavitation == CavitationModel::Penalty) {
            if let Err(e) = crate::interrupt::check("adaptive refinement") {
                return Step::end(out_of_time(ctx, scene, Some(&here), k + 1, &self.levels, e));
            }
            let why = format!(
                "the cavitation penalty's part of the estimate (hc {:.3} %, hm {:.3} %{}) is above a quarter of the target, the mesh's part below it",
                100.0 * p.hc,
                100.0 * p.hm,
                p.friction.map_or(String::new(), |[fx, fz]| format!(", fx {:.3} %, fz {:.3} %", 100.0 * fx, 100.0 * fz)),
            );
            let back = self.previous.replace(here);
            self.switch_to_complementarity(back, &why);
            return Step::Again;
        }
        // The last penalty level's mesh solved again, kept from the target by the two
        // models' difference on that mesh alone: the mesh of the penalty level before it
        // is solved again too, so that the estimate's last change is between two
        // complementarity films, with no such difference in it (docs/accuracy.md, "The two
        // cavitation models on one mesh").
        let blocked = self.levels[w].est.filter(|e| e.models_gap_in_the_way(target));
        if let (Some(e), Some(p)) = (blocked, self.levels[w].again_of) {
            if let Some(pen) = self.before.take() {
                let j = p - 1;
                if let Err(e) = crate::interrupt::check("adaptive refinement") {
                    return Step::end(out_of_time(ctx, scene, Some(&here), k + 1, &self.levels, e));
                }
                ctx.log(format!(
                    "accuracy: level {k}'s estimate ({}) is above the target by the two models' difference on its mesh alone; level {j}'s mesh is solved again as complementarity too, and the last change of the estimate is then between two complementarity films",
                    e.describe()
                ));
                self.next = pen.mesh_from.clone();
                self.again_of = Some(j);
                self.back = Some(pen);
                self.previous = Some(here);
                return Step::Again;
            }
        }
        let (refined, max_levels) = (self.refined(), acc.max_levels as usize);
        let short = |why: String| Step::end(finish(ctx, scene, &here, target, &self.levels, Some(short_of(target, &why, &self.levels))));
        if refined >= max_levels {
            return short(format!("accuracy.max_levels = {max_levels} refinement levels solved"));
        }
        // A level cut to the budget is the last (see `record`).
        if let Some(c) = self.levels[w].cut {
            return short(match c.by {
                Budget::Seconds => format!(
                    "level {w} was cut to the time left of accuracy.max_seconds = {} s: the level after it would not end in it",
                    acc.max_seconds
                ),
                Budget::Memory => format!("level {w} was cut to the memory a rank may reach: the level after it would need more"),
                Budget::Unknowns => {
                    format!("level {w} was cut to accuracy.max_unknowns = {}: the level after it would exceed it", acc.max_unknowns)
                }
            });
        }
        let marking = here.marking.as_ref().expect("marked when the loop goes on");
        if !marking.marked.iter().any(|&m| m) {
            return short(format!("every contact triangle is at the smallest size {MIN_ADAPTIVE_SIZE} a"));
        }
        let marked_next = NextMesh::marked(&here.setup.mesh, &edges, marking, None, scene.mesh.growth);
        // The next level may end the run (it is the second refinement or later): a marking
        // of a few triangles, too small for its change to certify it, is widened now, while
        // the level is one solve and not two ([`FEW_MARKED`]).
        if refined >= 1 {
            let marking = here.marking.as_mut().expect("marked when the loop goes on");
            match widened(ctx, scene, &here.setup.mesh, &edges, marking, marked_next, w) {
                Ok(wide) => self.next = Some(wide),
                Err(e) => return Step::end(out_of_time(ctx, scene, Some(&here), k + 1, &self.levels, e)),
            }
            self.levels[w].marked = Some(marking.count());
        } else {
            self.next = Some(marked_next);
        }
        if let Err(e) = crate::interrupt::check("adaptive refinement") {
            return Step::end(out_of_time(ctx, scene, Some(&here), k + 1, &self.levels, e));
        }
        // The level before is kept while the penalty may yet stand in the way; after the
        // switch it is no longer needed.
        let older = self.previous.replace(here);
        self.before = older.filter(|_| self.own.effects.cavitation == CavitationModel::Penalty);
        Step::On(())
    }

    /// Step 7: cavitation turns to complementarity because of `why`: the last level's mesh
    /// (`previous`) is solved again so, and the levels after it solve complementarity too.
    /// The level before it (`back`, where it was solved with the penalty) is kept as
    /// `before`: its mesh is solved again too when the two models' difference on the last
    /// one's alone keeps that from the target ([`Estimate::models_gap_in_the_way`]).
    fn switch_to_complementarity(&mut self, back: Option<Solved>, why: &str) {
        let last = self.levels.len() - 1;
        self.ctx.log(format!(
            "accuracy: {why}; level {last}'s mesh is solved again, and the levels after it solved, with cavitation as complementarity (effects.cavitation = \"complementarity\"), which has no such part"
        ));
        self.own.effects.cavitation = CavitationModel::Complementarity;
        self.next = self.previous.as_ref().expect("the last penalty level").mesh_from.clone();
        self.again_of = Some(last);
        self.before = back.filter(|b| b.cavitation == CavitationModel::Penalty && last >= 1);
    }
}

/// Whether the last of `levels` may end the run when its estimate is below the target: the
/// level before's marking had [`FEW_MARKED`] triangles or more, or the level refined enough
/// of the face over the level before ([`CERTIFYING_GROWTH`]), or it is that
/// level's mesh solved again as complementarity (whose estimate is the penalty level's
/// mesh part), or a level cut to the budget (whose estimate is the level before's less its
/// change).
fn certifies(levels: &[Level]) -> bool {
    let Some(last) = levels.last().filter(|_| levels.len() >= 2) else { return false };
    if last.again_of.is_some() || last.cut.is_some() {
        return true;
    }
    // The level before on the estimate's sequence: the one of the mesh before, as solved last.
    let before = levels.iter().enumerate().filter(|(_, l)| l.again_of.is_none()).rev().nth(1);
    before.map(|(i, l)| replacement(levels, i).map_or(l, |(_, r)| r)).is_some_and(|before| {
        before.marked.is_some_and(|m| m >= FEW_MARKED)
            || last.contact_triangles as f64 >= CERTIFYING_GROWTH * before.contact_triangles as f64
    })
}

/// The next level's mesh from level `k`'s `marking` on `mesh` (`edges`: its longest edges;
/// `marked`: the marking's own mesh, returned as it is when it needs no widening). A
/// marking of fewer than [`FEW_MARKED`] triangles that would give the next level fewer than
/// [`CERTIFYING_GROWTH`] times this level's contact triangles is widened: the next
/// triangles by indicator are taken ([`Marking::widen`]) until the next level has
/// [`WIDENING_AIM`] times that growth, the count found from the meshes tried
/// ([`widened_count`]), or until nothing is left to take. At L = 20 and light load (M = 20,
/// 50, 100) Doerfler's set on level 1 is 3-7 triangles of the outlet spike; the level made
/// from them changed the films little whatever their error, could not end the run, and
/// the levels after it were pre-asymptotic: M = 100, L = 20 then took 5 levels and 739 s,
/// widened 4 levels and 137 s, with its quarter-target film (docs/accuracy.md, "Markings
/// of a few triangles, widened").
fn widened(
    ctx: &Context,
    scene: &Scene,
    mesh: &crate::mesh::Mesh,
    edges: &[f64],
    marking: &mut Marking,
    marked: NextMesh,
    k: usize,
) -> Result<NextMesh, Error> {
    let before = mesh.contact_tris.len() as u64;
    let aim = CERTIFYING_GROWTH * before as f64;
    let doerfler = marking.count();
    if doerfler >= FEW_MARKED {
        return Ok(marked);
    }
    let mut tried: Vec<(usize, u64)> = Vec::new();
    let mut next = marked;
    let contact_triangles = |next: &NextMesh| -> Result<u64, Error> {
        Ok(super::lubricated::solid_mesh(scene, scene.uses_half_domain(), Some(next.field.clone()))?.contact_tris.len() as u64)
    };
    let mut tris = contact_triangles(&next)?;
    let first = tris;
    while (tris as f64) < aim && marking.widens() && tried.len() < MAX_WIDENINGS {
        tried.push((marking.count(), tris));
        ctx.log(format!("accuracy: level {k}'s marking of {} triangles gives level {} {tris} contact triangles", marking.count(), k + 1));
        marking.widen(widened_count(before, &tried, WIDENING_AIM * aim));
        next = NextMesh::marked(mesh, edges, marking, None, scene.mesh.growth);
        tris = contact_triangles(&next)?;
    }
    if tried.is_empty() {
        return Ok(next);
    }
    ctx.log(format!(
        "accuracy: level {k}'s marking of {doerfler} triangles would give level {} {first} contact triangles, fewer than {CERTIFYING_GROWTH} times its own {before}: widened to its {} triangles of largest indicator ({tris} contact triangles)",
        k + 1,
        marking.count(),
    ));
    Ok(next)
}

/// The cavitation penalty's estimated error on a level's films `films` (hc, hm), from its
/// state at the staged penalty where the penalty was staged, and from the values' slopes
/// in xi where the adjoints gave them (`slopes`; a scene's penalty `scene_xi` that was not
/// staged has them alone).
fn penalty_of(setup: &Setup, sol: &EhlSolution, films: [f64; 2], slopes: Option<PenaltySlopes>, scene_xi: f64) -> Option<PenaltyError> {
    let film = |x: &[f64]| {
        let st = FieldsOnFace::new(&setup.mesh, &setup.layout, x).stats();
        [st.hc, st.hm]
    };
    let Some(staged) = sol.penalty.as_ref() else { return PenaltyError::of(&[scene_xi], &[films], slopes, scene_xi) };
    let mut xis = vec![staged.base_xi];
    let mut at = vec![film(&staged.base_x)];
    if let Some((xi, x)) = staged.mid.as_ref().filter(|(xi, _)| *xi < staged.xi) {
        xis.push(*xi);
        at.push(film(x));
    }
    xis.push(staged.xi);
    at.push(films);
    PenaltyError::of(&xis, &at, slopes, staged.scene_xi)
}

/// The friction pass of a level, its triangles shared out over the ranks (every rank holds
/// the whole iterate and gets the whole result; collective), or None without friction.
fn level_friction(ctx: &Context, scene: &Scene, fields: &FieldsOnFace) -> Result<Option<FrictionResult>, Error> {
    let Some(fs) = super::lubricated::friction_setup(scene, fields.mesh.spec.contact) else { return Ok(None) };
    crate::friction::pass::friction_pass(fields, &fs, &super::lubricated::OverRanks(ctx)).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_that_refined_little_of_the_face_does_not_certify_itself() {
        let level = |contact_triangles: usize| Level {
            elastic_unknowns: 0,
            pressure_unknowns: 0,
            contact_triangles,
            min_size: 0.0625,
            newton_iterations: 0,
            seconds: 0.0,
            failed_seconds: 0.0,
            hc: 1.0,
            hm: 0.5,
            hm_at: [0.0, -0.9],
            pmax: 1.0,
            pmax_at: [0.0; 2],
            friction: None,
            est: None,
            cut: None,
            halvings: 1,
            penalty: None,
            again_of: None,
            marked: Some(7),
            peak_memory_mb: 0.0,
        };
        // M = 100, L = 20: 7 of level 1's 965 triangles marked, 1,201 on level 2.
        assert!(!certifies(&[level(720), level(965), level(1201)]));
        // heavy-3gpa: level 3's marking of 254 of its 17,216 triangles, 23,428 on level 4.
        assert!(certifies(&[level(12000), Level { marked: Some(254), ..level(17216) }, level(23428)]));
        // M = 20, L = 15, the smallest growth of the map's other last levels.
        assert!(certifies(&[level(720), level(869), level(1594)]));
        // The same mesh as complementarity, and a level cut to the budget, are judged by
        // their own estimates.
        assert!(certifies(&[level(965), Level { again_of: Some(0), ..level(965) }]));
        let cut = Cut { count: 10, share: 0.5, by: Budget::Unknowns };
        assert!(certifies(&[level(965), Level { cut: Some(cut), ..level(1000) }]));
        assert!(!certifies(&[level(720)]));
    }
}
