//! The Newton solver every solve of a continuation's path shares ([`Newton`]): one solve of
//! a scene with the linear-solver retries, the exact finish after a stale LU and the line
//! search's hand-over, and the search and ramp of one homotopy built on it. The path that
//! orders the solves is [`super::continuation`]'s.
use super::diagnostics::Collapse;
use super::homotopy::{film_gain, Homotopy, Parameter, RampSteps};
use super::policy::set_newton_linear_solver;
use super::problem::{complementarity, lambda_bar, lubricant, penalty, velocity_field};
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::system::EhlProblem;
use crate::error::Error;
use crate::petsc::factor::MUMPS_WORKSPACE_PERCENT;
use crate::petsc::snes::{Snes, SolveReport};
use crate::petsc::{self, Matrix, Vector};

/// Newton's line search `ls` ("bt" or "l2"), unless the user chose one. "l2" extrapolates
/// past the full step when the residual falls along it, and so past the film limiter's
/// fraction to the boundary: on M = 1323's 0.25 a first level it went to 4.7 times the
/// limited step and closed the film. Its largest step is the full one (PETSc's "maxstep" is
/// a lambda for "l2" and a step length for "bt", whose default, no limit, it keeps).
pub(super) fn set_line_search(ls: &str) -> Result<(), Error> {
    petsc::options::set_ours("-snes_linesearch_type", ls)?;
    petsc::options::set_ours("-snes_linesearch_maxstep", if ls == "l2" { "1" } else { "1e8" })?;
    Ok(())
}

/// A Newton solve with the LU reused that ran out of iterations with its residual below this
/// fraction of the starting one is near the solution: exact Newton finishes it.
const NEAR_SOLUTION: f64 = 1e-4;

/// Places where the film closed closer than this (units of a) are one place.
const SAME_PLACE: f64 = 0.05;

/// A solve that ran out of iterations (not stalled, not at the film's domain) with its
/// residual below this fraction of the starting one crawled: it made steady progress, at
/// the line search's smallest steps ([`bt_gave_out`]).
const CRAWL: f64 = 0.1;

/// The "bt" line search, not Newton, failed the solve: it refused every full step and
/// either crawled (the step at its smallest fraction, 0.1, every iteration, the residual
/// falling by about 10 % per iteration until the iterations ran out) or gave up on a step
/// (DIVERGED_LINE_SEARCH) where the film had not closed. At light, nearly isoviscous
/// points the residual norm rises for a step or two on the way to the solution, which
/// bt's sufficient-decrease test does not allow, and every milder problem of the
/// continuation fails the same way: from the Hertz start a steel ball on PDMS (M = 32,
/// L = 2e-4, 0.5 a mesh) crawls from 0.67 to 5.5e-2 in 30 iterations, and "l2" finishes
/// in 6 more. (With Hamrock-Dowson's film as the start's, Moes M = 5, L = 2 crawled the
/// same way and M = 3, L = 1 gave up at its first step; from the isoviscous film they
/// converge by bt.)
pub(super) fn bt_gave_out(r: &SolveReport, closed: bool) -> bool {
    let crawled = r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT
        && !r.stalled
        && r.residual_norm < CRAWL * r.initial_residual_norm;
    let refused = r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_LINE_SEARCH && !closed;
    r.domain_error.is_none() && (crawled || refused)
}

/// The Newton solver shared by every solve of the path, and the path so far.
pub(super) struct Newton<'a> {
    pub(super) ctx: &'a Context,
    pub(super) snes: Snes,
    /// The iterate (distributed).
    pub(super) x: Vector,
    pub(super) j: &'a Matrix,
    /// This rank's rows.
    pub(super) owned: (usize, usize),
    pub(super) row_scaling: bool,
    /// Where the film closed, if the last solve stopped for that.
    pub(super) collapse: Option<Collapse>,
    /// Every place the film closed on the path, in the order met (places within
    /// [`SAME_PLACE`] of one met before are not repeated).
    pub(super) closed: Vec<[f64; 2]>,
    /// Every Newton solve, logged as it ends.
    pub(super) steps: Vec<String>,
    /// Newton iterations over the path.
    pub(super) iterations: usize,
    /// The Jacobian's LU is reused over Newton steps ([`super::policy::Policy::reuses_lu`]).
    pub(super) reuses_lu: bool,
    /// A continuation step stopped at the film's domain is solved again with the "bt"
    /// line search ([`super::policy::Policy::bt_after_domain_error`]).
    pub(super) bt_after_domain: bool,
    /// The scene's cavitation penalty: a solve below it (the staged xi = 1e3) is short of
    /// the scene.
    pub(super) scene_penalty: f64,
    /// When set, every state a ramp converges at, with its t (the penalty's ramp, for its
    /// error estimate).
    pub(super) trail: Option<Vec<(f64, Vec<f64>)>>,
    /// The absolute tolerance of a solve short of the scene (with an accuracy target,
    /// [`super::policy::INTERMEDIATE_ATOL`]), and of the scene's own solve.
    pub(super) short_atol: Option<f64>,
    pub(super) atol: f64,
}

/// After a MUMPS failure for want of workspace, sets `-mat_mumps_icntl_14` (percentage added
/// to the analysis's estimate) to [`MUMPS_WORKSPACE_PERCENT`] for the factorisations that
/// follow, unless the user chose it or it is there already; says what it did, for the log.
fn more_mumps_workspace(why: &petsc::factor::LinearFailure) -> petsc::Result<String> {
    const KEY: &str = "-mat_mumps_icntl_14";
    let (true, Some(now)) = (why.mumps_workspace_too_small(), why.mumps_icntl14) else {
        return Ok(String::new());
    };
    if petsc::options::user_set(KEY)? {
        return Ok(format!(" (your {KEY} {now} kept)"));
    }
    if now >= MUMPS_WORKSPACE_PERCENT {
        return Ok(format!(" ({KEY} stays {now}: more workspace did not help this matrix where it was measured)"));
    }
    petsc::options::set_ours(KEY, &MUMPS_WORKSPACE_PERCENT.to_string())?;
    Ok(format!(" and MUMPS workspace {KEY} {MUMPS_WORKSPACE_PERCENT}"))
}

impl Newton<'_> {
    pub(super) fn note(&mut self, s: String) {
        self.ctx.log(&s);
        self.steps.push(s);
    }

    /// One Newton solve of the scene `sc` from `start`; `short`: `sc` is short of the
    /// scene (a continuation step below t = 1, the staged penalty), solved to
    /// `short_atol` when there is one.
    pub(super) fn solve(&mut self, sc: &Scene, system: &mut dyn EhlProblem, start: &[f64], short: bool) -> Result<SolveReport, Error> {
        let loose = self.short_atol.filter(|_| short);
        if let Some(atol) = loose {
            petsc::options::set_ours("-snes_atol", &format!("{atol:e}"))?;
        }
        let r = self.solve_to_tolerance(sc, system, start);
        if loose.is_some() {
            petsc::options::set_ours("-snes_atol", &format!("{:e}", self.atol))?;
        }
        r
    }

    /// [`Newton::solve`] at the tolerance set: the linear-solver retries and the exact
    /// finish after a stale LU included.
    fn solve_to_tolerance(&mut self, sc: &Scene, system: &mut dyn EhlProblem, start: &[f64]) -> Result<SolveReport, Error> {
        let (lo, hi) = self.owned;
        system.set_operating(lambda_bar(sc), lubricant(sc), penalty(sc), complementarity(sc));
        self.x.set_local_values(&start[lo..hi])?;
        if self.row_scaling {
            system.scale_rows(start)?;
        }
        system.take_collapse();
        self.collapse = None;
        let mut r = self.snes.solve(system, &self.x, self.j)?;
        if r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_LINEAR_SOLVE {
            // A failed factorisation leaves the solver failing every later solve at its
            // first step (M = 100, L = 20 at 0.0625 a: nine continuation steps in a row
            // with DIVERGED_LINEAR_SOLVE after 0 iterations): a fresh SNES, KSP and LU,
            // and the same solve once more. When MUMPS's analysis underestimated a
            // workspace (delayed pivots of the exp(alpha p) rows), a fresh LU with the
            // same estimate fails again: the new one gets a larger ICNTL(14).
            let why = self.snes.linear_failure()?;
            let more = more_mumps_workspace(&why)?;
            self.note(format!("Newton: {} after {} iterations ({why}); again with a new linear solver{more}", r.reason, r.iterations));
            self.iterations += r.iterations;
            self.snes = new_snes(petsc::comm_world())?;
            self.x.set_local_values(&start[lo..hi])?;
            system.take_collapse();
            r = self.snes.solve(system, &self.x, self.j)?;
            if r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_LINEAR_SOLVE {
                // Out of the machine's memory or of the user's MUMPS memory limit: no milder
                // problem has a smaller factorisation, so the continuation would only repeat it.
                let why = self.snes.linear_failure()?;
                if why.mumps_infog.is_some_and(|(i, _)| petsc::factor::mumps_memory_code(i)) {
                    return Err(Error::not_converged(format!("the linear solver cannot factorise the Jacobian: {why}")));
                }
            }
        }
        if self.reuses_lu
            && r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT
            && r.residual_norm < NEAR_SOLUTION * r.initial_residual_norm
        {
            // Near the solution a stale LU only slows Newton down (GMRES on it converges
            // linearly): exact Newton finishes from the last iterate. Cases/hard/heavy-3gpa,
            // level 1 from level 0's pressure: the residual at 3.6e-8 after 30 iterations
            // with the LU reused; without the finish the level went to the continuation.
            let from = self.solution()?;
            self.note(format!(
                "Newton: {} after {} iterations with the LU reused, the residual down from {:.3e} to {:.3e}; exact Newton from there",
                r.reason, r.iterations, r.initial_residual_norm, r.residual_norm
            ));
            self.iterations += r.iterations;
            set_newton_linear_solver(false)?;
            self.x.set_local_values(&from[lo..hi])?;
            system.take_collapse();
            let again = self.snes.solve(system, &self.x, self.j);
            set_newton_linear_solver(true)?;
            r = again?;
        }
        if let (false, Some(c)) = (r.converged, system.take_collapse()) {
            r.reason = format!("{}: film closed at ({:.3}, {:.3})a", r.reason, c[0], c[1]);
            self.collapse = Some(Collapse { at: c, pole: sc.spin_pole_over_a() });
            if !self.closed.iter().any(|d| (d[0] - c[0]).hypot(d[1] - c[1]) < SAME_PLACE) {
                self.closed.push(c);
            }
        }
        Ok(r)
    }

    /// [`Newton::solve`] with the line search `ls.0`, the policy's `ls.1` set back after it
    /// (a user's `-snes_linesearch_type` stays in force throughout).
    pub(super) fn solve_with_line_search(
        &mut self,
        ls: (&str, &str),
        sc: &Scene,
        system: &mut dyn EhlProblem,
        start: &[f64],
        short: bool,
    ) -> Result<SolveReport, Error> {
        set_line_search(ls.0)?;
        let r = self.solve(sc, system, start, short);
        set_line_search(ls.1)?;
        r
    }

    /// Newton again from the last iterate of `failed` (a solve that [`bt_gave_out`]) with the
    /// "l2" line search, which takes the steps "bt" refused; the solve is logged and counted.
    pub(super) fn on_with_l2(
        &mut self,
        sc: &Scene,
        system: &mut dyn EhlProblem,
        short: bool,
        failed: &SolveReport,
    ) -> Result<SolveReport, Error> {
        let from = self.solution()?;
        let r = self.solve_with_line_search(("l2", "bt"), sc, system, &from, short)?;
        self.iterations += r.iterations;
        self.note(format!(
            "Newton: the bt line search gave out (residual {:.3e} -> {:.3e} in {} iterations); on from there with l2: {} ({} iterations)",
            failed.initial_residual_norm, failed.residual_norm, failed.iterations, r.reason, r.iterations
        ));
        Ok(r)
    }

    /// The converged iterate of the last solve, gathered.
    pub(super) fn solution(&self) -> Result<Vec<f64>, Error> {
        Ok(self.x.gather_all()?)
    }

    /// One Newton solve of `from` with `p` at t, from `start`, a state at `p = from_t`
    /// (its H0 raised by [`film_gain`]); the step is logged (`what` before the parameter's
    /// value) and kept in the path. Returns the report and, if converged, the state.
    pub(super) fn solve_at(
        &mut self,
        from: &Scene,
        p: Parameter,
        (from_t, t): (f64, f64),
        system: &mut dyn EhlProblem,
        start: &[f64],
        what: &str,
    ) -> Result<(SolveReport, Option<Vec<f64>>), Error> {
        crate::interrupt::check("the continuation")?;
        let gain = film_gain(from, p, from_t, t);
        let raised;
        let start = if gain > 0.0 {
            let mut x = start.to_vec();
            x[system.h0_index()] += gain;
            raised = x;
            &raised[..]
        } else {
            start
        };
        let what = if gain > 0.0 { format!("{what}(H0 + {gain:.3e}, its film) ") } else { what.to_string() };
        let what = what.as_str();
        let mut sc = from.clone();
        p.apply(&mut sc, t);
        if p.kinematic() {
            system.set_velocity(velocity_field(&sc));
        }
        let short = t < 1.0 || penalty(&sc) < self.scene_penalty;
        let mut r = self.solve(&sc, system, start, short)?;
        if self.bt_after_domain && r.reason.starts_with("DIVERGED_FUNCTION_DOMAIN") {
            self.iterations += r.iterations;
            self.note(format!(
                "{} continuation: {what}{}: {} ({} iterations); again with the bt line search",
                p.name(),
                p.show(t),
                r.reason,
                r.iterations
            ));
            r = self.solve_with_line_search(("bt", "l2"), &sc, system, start, short)?;
        }
        self.iterations += r.iterations;
        self.note(format!("{} continuation: {what}{}: {} ({} iterations)", p.name(), p.show(t), r.reason, r.iterations));
        let xs = if r.converged { Some(self.solution()?) } else { None };
        Ok((r, xs))
    }

    /// Searches a milder problem Newton solves from `x0` (described by `label`): t from
    /// the ramp's first value, halved down to its lowest. Returns t and the converged state,
    /// or None (logged) if none converged.
    pub(super) fn search(
        &mut self,
        from: &Scene,
        h: &Homotopy,
        system: &mut dyn EhlProblem,
        x0: &[f64],
        label: &str,
    ) -> Result<Option<(f64, Vec<f64>)>, Error> {
        let (p, lowest) = (h.parameter, h.ramp.lowest);
        let mut t = h.ramp.first;
        while t >= lowest {
            if let (_, Some(xs)) = self.solve_at(from, p, (1.0, t), system, x0, &format!("{label} at "))? {
                return Ok(Some((t, xs)));
            }
            // heavy-3gpa: the film closed at alpha/2, alpha/4 and alpha/8 alike (4 min of
            // the 10 on its patch mesh); no try after a closed film has converged.
            if p.thins_film() && self.collapse.is_some() {
                break;
            }
            t /= 2.0;
        }
        if t >= lowest {
            self.note(format!(
                "{} continuation: the film closed at {}; a smaller value gives a thinner film, so the search stops",
                p.name(),
                p.show(t)
            ));
        } else {
            self.note(format!("{} continuation: no milder problem converged down to {}", p.name(), p.show(lowest)));
        }
        Ok(None)
    }

    /// Ramps `h` from t (where `state` is converged) to the scene's problem at t = 1 by the
    /// `steps` ([`RampSteps`]). Returns whether t = 1 converged, the last report, the last
    /// converged state, and the values of t < 1 converged at (from the first t on).
    #[allow(clippy::type_complexity)]
    pub(super) fn ramp(
        &mut self,
        from: &Scene,
        h: &Homotopy,
        mut t: f64,
        mut state: Vec<f64>,
        system: &mut dyn EhlProblem,
        mut steps: RampSteps,
    ) -> Result<(bool, Option<SolveReport>, Vec<f64>, Vec<f64>), Error> {
        let failures = steps.failures_left;
        let mut last = None;
        let mut below = vec![t];
        while t < 1.0 {
            let (next, planned) = steps.next(t);
            let (r, xs) = self.solve_at(from, h.parameter, (t, next), system, &state, "")?;
            let converged = xs.is_some();
            if let Some(xs) = xs {
                if next < 1.0 {
                    below.push(next);
                }
                if let Some(trail) = self.trail.as_mut() {
                    trail.push((next, xs.clone()));
                }
                state = xs;
                t = next;
            }
            last = Some(r);
            if !converged && !steps.failed(t, next, planned) {
                if steps.failures_left == Some(0) {
                    self.note(format!(
                        "{} continuation: {} failed steps, the most this solve allows (a cheaper remedy follows)",
                        h.parameter.name(),
                        failures.unwrap_or_default()
                    ));
                }
                return Ok((false, last, state, below));
            }
        }
        Ok((true, last, state, below))
    }
}

/// Newton's solver, with the stall test of `-ehl_newton_stall` ([`crate::ehl_options::NEWTON_STALL`]).
pub(super) fn new_snes(comm: petsc::ffi::MPI_Comm) -> Result<Snes, Error> {
    let mut snes = Snes::new(comm, "")?;
    snes.set_stall_test(crate::ehl_options::get().newton_stall, crate::ehl_options::NEWTON_STALL_FACTOR)?;
    Ok(snes)
}

#[cfg(test)]
mod tests {
    use super::bt_gave_out;
    use crate::petsc::ffi;
    use crate::petsc::snes::SolveReport;

    fn report(code: i32, reason: &str, initial: f64, last: f64, domain: bool) -> SolveReport {
        SolveReport {
            converged: false,
            stalled: reason.contains("stalled"),
            reason: reason.into(),
            reason_code: code,
            iterations: 30,
            linear_iterations: 30,
            residual_norm: last,
            initial_residual_norm: initial,
            domain_error: domain.then(|| "H < 0".into()),
        }
    }

    /// The line search gave out (a crawl, a refused step where the film is open); Newton
    /// itself failed (a stall, no progress, a closed film, the film's domain).
    #[test]
    fn only_a_line_search_that_gave_out_is_handed_to_l2() {
        let (max_it, ls) = (ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT, ffi::SNESConvergedReason_SNES_DIVERGED_LINE_SEARCH);
        // M = 5, L = 2 from the Hertz start: 0.72 -> 3.5e-2 in 30 iterations.
        assert!(bt_gave_out(&report(max_it, "DIVERGED_MAX_IT", 0.72, 3.5e-2, false), false));
        // M = 3, L = 1: the first step refused.
        assert!(bt_gave_out(&report(ls, "DIVERGED_LINE_SEARCH", 0.71, 0.71, false), false));
        // Out of iterations with little progress, or stalled: Newton's failure.
        assert!(!bt_gave_out(&report(max_it, "DIVERGED_MAX_IT", 1.0, 0.5, false), false));
        assert!(!bt_gave_out(&report(max_it, "DIVERGED_MAX_IT: stalled (...)", 1.0, 0.05, false), false));
        // The film closed, or the step left the film's domain: the continuation's job.
        assert!(!bt_gave_out(&report(ls, "DIVERGED_LINE_SEARCH", 0.71, 0.71, false), true));
        assert!(!bt_gave_out(&report(ls, "DIVERGED_LINE_SEARCH", 0.71, 0.71, true), false));
    }
}
