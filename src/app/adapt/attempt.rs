//! Step 3 of the adaptive loop: a level's attempt at its solve (from the level before's
//! state, an earlier run's or the first level's start), and what follows an attempt that
//! failed: the remedy [`super::remedy`] chooses, applied, or the run's end.
use super::end::out_of_time;
use super::level::written;
use super::remedy::{newton_failed, remedy, Failure, Remedy, Tried};
use super::{penalty_of, Loop, Recorded, Solved, Step};
use crate::app::estimate::SHORT_PENALTY_SHARE;
use crate::app::first_level::{
    closures, first_level_again, from_reached, onward, reached, without_gradient_jump, Onward, FIRST_LEVEL_RETRIES,
};
use crate::app::lubricated::Setup;
use crate::app::marking::{longest_edges, next_field, zone_mark, NextMesh};
use crate::app::Context;
use crate::case::schema::RAISED_GRADIENT_JUMP;
use crate::case::Scene;
use crate::collective;
use crate::ehl::driver::{Coarser, Coupling, EhlSolution, EhlSolver, Milder, RampLimits, Start, Tries};
use crate::ehl::post::FieldsOnFace;
use crate::error::{Error, Reached};
use std::sync::Arc;
use std::time::Instant;

/// How a level's solve failed, with what its remedy needs.
pub(super) enum Failed {
    /// The level before's mesh, solved again as complementarity from its solution.
    Again(Error),
    /// A refined level, and the remedy [`remedy`] chose for it.
    Refined(Error, Remedy),
    /// The first level.
    First(Error),
    /// The first level from an earlier run's state (`--restart`): not retried.
    Earlier(Error),
}

impl<'c> Loop<'c> {
    /// Step 3: the level's solve, from the level before's state (its own mesh solved again
    /// as complementarity, or a coarser level's pressure), an earlier run's, or the first
    /// level's start. Collective.
    pub(super) fn attempt<'s>(
        &mut self,
        scene: &Scene,
        setup: &'s Setup,
        solver: &EhlSolver<'s>,
        plain: bool,
        k: usize,
    ) -> Result<EhlSolution, Failed>
    where
        'c: 's,
    {
        let ctx = self.ctx;
        let target = self.acc.target;
        let Some(prev) = &self.previous else {
            return match self.earlier {
                Some(e) => {
                    collective::agree(&ctx.world, penalty_judged(ctx, setup, target, e.solve(ctx, scene, solver))).map_err(Failed::Earlier)
                }
                None => collective::agree(&ctx.world, penalty_judged(ctx, setup, target, onward(ctx, scene, solver, self.from.as_ref())))
                    .map_err(Failed::First),
            };
        };
        // The penalty level's mesh as complementarity, from its solution.
        if let Some(j) = self.again_of {
            let from = self.back.as_ref().unwrap_or(prev);
            return collective::agree(&ctx.world, solve_again(ctx, scene, solver, from, j)).map_err(Failed::Again);
        }
        let pf = FieldsOnFace::new(&prev.setup.mesh, &prev.setup.layout, &prev.sol.x);
        let p = |x: f64, z: f64| pf.at(x, z).map_or(0.0, |v| v.0);
        let label = format!("level {}'s pressure ({} contact triangles)", k - 1, prev.setup.mesh.contact_tris.len());
        // The previous level's state short of the scene, when it came through a
        // continuation: this level's continuation starts its milder problem there.
        let mf = prev.sol.milder.as_ref().map(|path| FieldsOnFace::new(&prev.setup.mesh, &prev.setup.layout, &path.x));
        let pm = |x: f64, z: f64| mf.as_ref().and_then(|f| f.at(x, z)).map_or(0.0, |v| v.0);
        let mild_label = format!("level {}'s state", k - 1);
        let milder = prev.sol.milder.as_ref().zip(mf.as_ref()).map(|(path, f)| Milder {
            parameter: path.parameter,
            ts: &path.ts,
            p: &pm,
            hc: f.stats().hc,
            label: &mild_label,
        });
        // While the gradient-jump factor can still be raised, a level that fails the
        // continuations nearest the scene is solved again with it raised (below)
        // before the load and speed continuations and the Hertz start: at M = 100,
        // L = 20 those cost 330 s on level 3 and never converged from a coarser
        // level's pressure. A failure the raise does not answer gets them after all.
        let raisable = scene.reynolds.gradient_jump > 0.0 && scene.reynolds.gradient_jump < RAISED_GRADIENT_JUMP;
        // A level made by quartering tries plain Newton alone: if that fails it is
        // meshed again halved (below), which converged by plain Newton where the
        // quartered level needed the continuation and the raise (a traction drive at
        // L = 22: 62 s to a tighter target against 638 s, docs/practice.md).
        let quartered = self.next.as_ref().is_some_and(|m| m.halvings == 2) && self.raised_from.is_none() && self.full_ladder != Some(k);
        let tries = match (plain, quartered) {
            (false, _) => Tries::Continuation,
            (true, true) => Tries::Plain,
            (true, false) => Tries::PlainThenContinuation,
        };
        let last_resorts = (!raisable || self.full_ladder == Some(k)) && tries != Tries::Plain;
        // A monolithic level after a monolithic one starts from its displacement.
        let coarser = (prev.sol.coupling == Coupling::Monolithic).then_some(Coarser {
            mesh: &prev.setup.mesh,
            layout: &prev.setup.layout,
            x: &prev.sol.x,
        });
        // While the factor can be raised, a ramp gives up at its second failed step:
        // the raised solve goes on from the furthest state the ramp converged at.
        // M = 40, L = 15's 0.03125 a level failed four ramp steps at c_J = 0.01
        // (alpha 25.6 -> 36.2 -> 39.5 GPa^-1 between its converged ones, 254 s),
        // then converged with c_J = 1 in 26 iterations (48 s). Once it is raised,
        // only the last resorts are left, and the ramp takes smaller steps before it
        // gives up ([`RampLimits::PATIENT`]); docs/accuracy.md, "The ramp's second
        // failure".
        let ramp = match (raisable, scene.reynolds.gradient_jump >= RAISED_GRADIENT_JUMP) {
            (true, _) => RampLimits::BEFORE_A_REMEDY,
            (false, true) => RampLimits::PATIENT,
            (false, false) => RampLimits::DEFAULT,
        };
        let start = Start::Pressure { p: &p, hc: prev.hc, label: &label, tries, milder, last_resorts, ramp, coarser };
        // After the raise: first from the failed try's furthest state (its milder
        // problem, on this same mesh), without the last resorts; if that fails, from
        // the coarser level's state as before. At M = 1000, L = 20 the try with
        // c_J = 0.01 got to alpha = 48.3 of 68.3 GPa^-1 on the 0.0156 a level, and
        // the raised solve spent 146 s getting there again from the coarser level's
        // alpha/4; at M = 20, L = 20 the raised ramp from the try's 44.3 GPa^-1
        // failed at 64.7 -> 68.3, where the one from the coarser level's alpha/2
        // converges (docs/accuracy.md).
        let onward_state = self.raised_from.take();
        let solved = match &onward_state {
            Some(r) => {
                let label = format!("level {k}'s state where its try before the raise stopped");
                from_reached(ctx, scene, solver, setup, r, &label, true)
            }
            None => solver.solve_from(ctx, scene, start),
        };
        collective::agree(&ctx.world, penalty_judged(ctx, setup, target, solved)).map_err(|e| {
            // What is tried next, in the order of [`remedy`].
            let tried = Tried {
                plain_alone: tries == Tries::Plain,
                raisable,
                from_try_state: onward_state.is_some(),
                last_resorts,
                zone_retry: self.zone_retry == Some(k),
            };
            let remedy = remedy(&Failure::of(ctx, &e), &tried);
            Failed::Refined(e, remedy)
        })
    }

    /// After a failed solve of level `k` on `setup`, begun at `t0`: what is tried next. The
    /// level again ([`Step::Again`], the failed try's time counted in it), or the run's end.
    pub(super) fn remedied(&mut self, scene: &Scene, setup: Setup, failed: Failed, k: usize, t0: Instant) -> Step<Recorded> {
        let ctx = self.ctx;
        match failed {
            Failed::Earlier(e) => Step::end(Err(e)),
            // Where the penalty level's mesh does not converge as complementarity, the
            // penalty level stays and the levels after it solve complementarity from its
            // pressure.
            Failed::Again(e) => {
                let prev = self.previous.as_ref().expect("a level solved again has one before it");
                if crate::interrupt::agreed() != 0 || !newton_failed(ctx, &e) {
                    return Step::end(out_of_time(ctx, scene, Some(prev), k, &self.levels, e));
                }
                let j = self.again_of.take().expect("set for a level solved again");
                self.before = None;
                let why = format!("level {j} did not converge as complementarity from its solution with the penalty ({})", reason(&e));
                // The mesh before: the film of the last mesh solved again keeps its estimate,
                // and the levels after it refine that mesh.
                let why = match self.back.take() {
                    Some(_) => format!("{why}; level {}'s estimate stands", written(&self.levels).0),
                    None => why,
                };
                match prev.marking.as_ref() {
                    Some(m) => {
                        ctx.log(format!("accuracy: {why}; the levels after it solve complementarity from its pressure"));
                        self.next = Some(NextMesh::marked(&prev.setup.mesh, &longest_edges(&prev.setup.mesh), m, None, scene.mesh.growth));
                        self.tried_again(t0)
                    }
                    // The penalty level was the last one the budget allows.
                    None => self.short(scene, prev, &why),
                }
            }
            Failed::Refined(e, remedy) => {
                let prev = self.previous.as_ref().expect("a refined level has one before it");
                match remedy {
                    Remedy::HalveQuartered => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge by plain Newton on its quartered mesh ({}); again with its {} quartered triangles halved",
                            reason(&e),
                            prev.marking.as_ref().map_or(0, |m| m.quartered())
                        ));
                        self.halve_quartered = true;
                    }
                    Remedy::Raise => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge ({}); again on the same mesh with the gradient-jump factor reynolds.gradient_jump raised from {} to {RAISED_GRADIENT_JUMP} for this level and the ones after",
                            reason(&e),
                            scene.reynolds.gradient_jump
                        ));
                        self.raised_from = reached(ctx, &e);
                        self.own.reynolds.gradient_jump = RAISED_GRADIENT_JUMP;
                    }
                    Remedy::FromCoarser => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge from its try's state ({}); again from level {}'s state",
                            reason(&e),
                            k - 1
                        ));
                    }
                    Remedy::FullLadder => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge ({}); again on the same mesh with the load and speed continuations and the Hertz start",
                            reason(&e)
                        ));
                        self.full_ladder = Some(k);
                    }
                    Remedy::ZoneMesh => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge on its goal-oriented mesh ({}); again with level {}'s pressurised zone refined",
                            reason(&e),
                            k - 1
                        ));
                        let pf = FieldsOnFace::new(&prev.setup.mesh, &prev.setup.layout, &prev.sol.x);
                        let edges = longest_edges(&prev.setup.mesh);
                        let marked = zone_mark(&pf, &edges);
                        self.next = Some(NextMesh::halving(Arc::new(next_field(&prev.setup.mesh, &edges, &marked, scene.mesh.growth))));
                        self.zone_retry = None;
                    }
                    Remedy::SpinPole => {
                        return Step::end(Err(Error::Context {
                            context: format!(
                                "accuracy: level {k} (level {} converged on its coarser mesh only, which does not resolve the spin pole; no result written)",
                                k - 1
                            ),
                            source: Box::new(e),
                        }));
                    }
                    Remedy::Short => return self.short(scene, prev, &format!("level {k} did not converge ({e})")),
                    Remedy::Stop => return Step::end(out_of_time(ctx, scene, Some(prev), k, &self.levels, e)),
                }
                self.tried_again(t0)
            }
            // A first mesh too coarse for the film (at low speed or high load the side
            // lobes and the outlet constriction are narrower than 0.25 a, and the film
            // closes there on it: cases/hard/slow, heavy-3gpa) is refined in the Hertz
            // zone and, finer, around the radii where the film closed, and solved again
            // without the gradient-jump term ([`without_gradient_jump`]); a film that
            // closes at a spin pole closes on any mesh.
            // Every rank decides the same: only Newton's own failure (the same on every
            // rank) is retried, not one rank's local fault.
            Failed::First(e) => {
                if !(crate::interrupt::agreed() == 0 && self.first_retries < FIRST_LEVEL_RETRIES && newton_failed(ctx, &e)) {
                    return Step::end(Err(e));
                }
                let why = format!("did not converge on its mesh ({})", reason(&e));
                let closed = closures(ctx, &e);
                self.next = Some(NextMesh::halving(first_level_again(ctx, &setup.mesh, scene.mesh.growth, &why, &closed)));
                if !closed.is_empty() {
                    without_gradient_jump(ctx, &mut self.own);
                }
                self.first_retries += 1;
                let further = |r: &Reached| !matches!(&self.from, Some(Onward::Reached(_, f)) if f.t >= r.t);
                if let Some(r) = reached(ctx, &e).filter(further) {
                    self.from = Some(Onward::Reached(setup, r));
                }
                self.tried_again(t0)
            }
        }
    }

    /// The level tried again after an attempt begun at `t0` that did not converge: its time
    /// is part of the level's.
    pub(super) fn tried_again<T>(&mut self, t0: Instant) -> Step<T> {
        self.tried_s += t0.elapsed().as_secs_f64();
        Step::Again
    }
}

/// Level `k`'s mesh solved again as complementarity (`scene`) from its solution with the
/// cavitation penalty, `prev`: plain Newton from the pressure and, after a monolithic
/// level, the displacement. The two differ by the penalty's error alone, a few tenths of a
/// per cent of the film, so no continuation is offered. Collective.
fn solve_again<'a>(ctx: &'a Context, scene: &Scene, solver: &EhlSolver<'a>, prev: &Solved, k: usize) -> Result<EhlSolution, Error> {
    let pf = FieldsOnFace::new(&prev.setup.mesh, &prev.setup.layout, &prev.sol.x);
    let p = |x: f64, z: f64| pf.at(x, z).map_or(0.0, |v| v.0);
    let label = format!("level {k}'s solution with the cavitation penalty");
    let coarser = (prev.sol.coupling == Coupling::Monolithic).then_some(Coarser {
        mesh: &prev.setup.mesh,
        layout: &prev.setup.layout,
        x: &prev.sol.x,
    });
    let start = Start::Pressure {
        p: &p,
        hc: prev.hc,
        label: &label,
        tries: Tries::Plain,
        milder: None,
        last_resorts: false,
        ramp: RampLimits::DEFAULT,
        coarser,
    };
    solver.solve_from(ctx, scene, start)
}

/// A solution whose staged cavitation penalty stalled short of the scene's
/// ([`EhlSolver::accept_short_penalty`]) is kept when the penalty's estimated error of hc
/// and hm is at most [`SHORT_PENALTY_SHARE`] of the target, and is Newton's failure
/// otherwise, as the stall was before. The same on every rank (the state is whole on each).
fn penalty_judged(ctx: &Context, setup: &Setup, target: f64, solved: Result<EhlSolution, Error>) -> Result<EhlSolution, Error> {
    let sol = solved?;
    let Some(staged) = sol.penalty.as_ref().filter(|p| p.short()) else { return Ok(sol) };
    let st = FieldsOnFace::new(&setup.mesh, &setup.layout, &sol.x).stats();
    let Some(e) = penalty_of(setup, &sol, [st.hc, st.hm], None, staged.scene_xi) else { return Ok(sol) };
    let what = format!(
        "the cavitation penalty's ramp stalled at xi = {:.3e} of the scene's {:e}, where its estimated error is hc {:.3} %, hm {:.3} %",
        staged.xi,
        staged.scene_xi,
        100.0 * e.hc,
        100.0 * e.hm
    );
    if e.hc.max(e.hm) <= SHORT_PENALTY_SHARE * target {
        ctx.log(format!("accuracy: {what}: within {SHORT_PENALTY_SHARE} of the target {target}, so the state there is kept and that error is part of the estimate"));
        Ok(sol)
    } else {
        Err(Error::not_converged(format!(
            "Newton did not converge: {what}, more than {SHORT_PENALTY_SHARE} of the target {target}; path: {}",
            sol.steps.join("; ")
        )))
    }
}

/// Why `e` stopped Newton, without the path of solves it lists, for the log.
fn reason(e: &Error) -> String {
    let why = e.to_string();
    why.split("; path:").next().unwrap_or(&why).to_string()
}
