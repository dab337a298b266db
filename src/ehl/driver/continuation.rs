//! Newton with continuation. Plain Newton runs first at the base problem (the scene, with
//! a stiff cavitation penalty lowered to [`PENALTY_START`]); if it fails from the Hertz
//! start, the homotopies of [`homotopies`] are tried in order, each a scene parameter and
//! a ramp: find a milder problem Newton solves from the start, then ramp the parameter back
//! to the scene's value, each converged state starting the next solve. Last, a staged
//! penalty is ramped from [`PENALTY_START`] to the scene's, or, with cavitation as
//! complementarity, the complementarity form is solved from the penalty solution. Every
//! Newton solve is logged and kept in the path.
use super::diagnostics::Collapse;
use super::policy::{newton_atol, set_newton_linear_solver, Policy, INTERMEDIATE_ATOL};
use super::problem::{complementarity, hc_guess, lambda_bar, lubricant, penalty, velocity_field};
use super::start::RampLimits;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::system::EhlProblem;
use crate::error::{Error, Reached};
use crate::petsc::factor::MUMPS_WORKSPACE_PERCENT;
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

/// Newton's line search `ls` ("bt" or "l2"), unless the user chose one. "l2" extrapolates
/// past the full step when the residual falls along it, and so past the film limiter's
/// fraction to the boundary: on M = 1323's 0.25 a first level it went to 4.7 times the
/// limited step and closed the film. Its largest step is the full one (PETSc's "maxstep" is
/// a lambda for "l2" and a step length for "bt", whose default, no limit, it keeps).
fn set_line_search(ls: &str) -> Result<(), Error> {
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
fn bt_gave_out(r: &SolveReport, closed: bool) -> bool {
    let crawled = r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT
        && !r.stalled
        && r.residual_norm < CRAWL * r.initial_residual_norm;
    let refused = r.reason_code == petsc::ffi::SNESConvergedReason_SNES_DIVERGED_LINE_SEARCH && !closed;
    r.domain_error.is_none() && (crawled || refused)
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

/// A scene parameter a continuation varies, with the scene's value: at t = 1 the scene
/// itself, at smaller t a milder problem.
#[derive(Clone, Copy, Debug)]
enum Parameter {
    /// The tilt angle lambda (deg) becomes min(lambda / t, 90): weaker spin.
    Tilt(f64),
    /// The pressure-viscosity coefficient alpha (1/Pa) and the Roelands exponent z are
    /// scaled by t: a less steep viscosity at the same Hertz geometry.
    PressureViscosity { alpha: f64, z: Option<f64> },
    /// The load (N) is scaled by t: smaller M and alpha p_H.
    Load(f64),
    /// The entrainment speed (m/s) becomes Ue / t: a thicker film.
    Speed(f64),
    /// The cavitation penalty xi is scaled by t.
    Penalty(f64),
}

impl Parameter {
    fn name(self) -> &'static str {
        match self {
            Parameter::Tilt(_) => "tilt",
            Parameter::PressureViscosity { .. } => "pressure-viscosity",
            Parameter::Load(_) => "load",
            Parameter::Speed(_) => "speed",
            Parameter::Penalty(_) => "penalty",
        }
    }

    /// Sets the parameter of `sc` at t.
    fn apply(self, sc: &mut Scene, t: f64) {
        match self {
            Parameter::Tilt(tilt) => sc.operating.tilt_angle = (tilt / t).min(90.0),
            Parameter::PressureViscosity { alpha, z } => {
                if let Some(l) = sc.lubricant.as_mut() {
                    l.pressure_viscosity = l.pressure_viscosity.map(|_| alpha * t);
                    l.roelands_exponent = z.map(|z| z * t);
                }
            }
            Parameter::Load(load) => sc.operating.load = load * t,
            Parameter::Speed(ue) => sc.operating.entrainment_speed = Some(ue / t),
            Parameter::Penalty(xi) => sc.reynolds.penalty = xi * t,
        }
    }

    /// The parameter's value at t, for the log.
    fn show(self, t: f64) -> String {
        match self {
            Parameter::Tilt(tilt) => format!("lambda = {:.4} deg", (tilt / t).min(90.0)),
            Parameter::PressureViscosity { alpha, .. } => format!("alpha = {:.4} GPa^-1", alpha * t * 1e9),
            Parameter::Load(load) => format!("L = {:.4} N", load * t),
            Parameter::Speed(ue) => format!("Ue = {:.4} m/s", ue / t),
            Parameter::Penalty(xi) => format!("xi = {:.4e}", xi * t),
        }
    }

    /// Load and speed: continuations that change the film's whole shape, tried after the
    /// ones nearest the scene (tilt, pressure-viscosity) failed. Their search from a
    /// coarser level's pressure has not converged on any level measured (M = 100, L = 20 at
    /// 0.0625 a and 0.03125 a: L/8 to L/64 and 2 Ue to 32 Ue all fail, 210 s, measured
    /// before a milder problem's start had its own film, [`film_gain`]).
    fn last_resort(self) -> bool {
        matches!(self, Parameter::Load(_) | Parameter::Speed(_))
    }

    /// The parameter changes the entrainment velocity field.
    fn kinematic(self) -> bool {
        matches!(self, Parameter::Tilt(_))
    }

    /// The parameter changes the film in the units of its own Hertz contact (X = x/a,
    /// H = h R/a^2): a lighter load has a smaller a, so the same film is a thicker H; a
    /// faster speed has a thicker film. The dimensionless Hertz pressure and its deflection
    /// are the same at every load, so only H0 of a start is wrong for another value.
    fn moves_film(self) -> bool {
        matches!(self, Parameter::Load(_) | Parameter::Speed(_))
    }

    /// A smaller t gives a thinner film (pressure-viscosity: hc grows about as alpha^0.5),
    /// so once a try ends with the film closed, the smaller t that follow would close it too.
    fn thins_film(self) -> bool {
        matches!(self, Parameter::PressureViscosity { .. })
    }
}

/// How much a start of `from` at `p = from_t` raises its H0 for a solve at `p = t`: the
/// estimated central film's gain ([`hc_guess`]) where the film at t is the thicker. At L/8
/// the Hertz start's H0, the scene's film, is about a fifth of the milder problem's own.
/// A thinner film is not imposed: a start whose film is too thick only needs the load
/// balance to lower H0, one too thin can close the film at its first step.
fn film_gain(from: &Scene, p: Parameter, from_t: f64, t: f64) -> f64 {
    if !p.moves_film() {
        return 0.0;
    }
    let at = |t: f64| {
        let mut sc = from.clone();
        p.apply(&mut sc, t);
        hc_guess(&sc)
    };
    (at(t) - at(from_t)).max(0.0)
}

/// The viscosity rise over the contact, ln(eta(p_H)/eta_R), below which a smaller alpha is
/// not a milder problem from the Hertz start (a factor 1.65 in the viscosity; the
/// isoviscous-elastic points measured had 2e-4 to 0.07).
const MILD_VISCOSITY_RISE: f64 = 0.5;

/// How t moves: the search for a milder problem tries `first`, halving down to `lowest`;
/// the ramp back to t = 1 multiplies t by `ratio` (by its square root after a failure).
#[derive(Clone, Copy, Debug)]
struct Ramp {
    first: f64,
    lowest: f64,
    ratio: f64,
}

/// One continuation: a parameter and its ramp.
#[derive(Clone, Copy, Debug)]
struct Homotopy {
    parameter: Parameter,
    ramp: Ramp,
}

/// The continuations tried, in order, when Newton fails from the Hertz start: first (spin
/// kinematics, lambda < 90 deg) the tilt angle, then pressure-viscosity (alpha > 0), then
/// load, then speed. Pressure-viscosity goes before load: on the hard suite it is the one
/// that converges (alpha30 on the paper mesh: load continuation fails from every Hertz
/// start down to L/64, alpha/2 -> alpha converges in 23 + 8 iterations).
///
/// From the Hertz start (`from_hertz`) the pressure-viscosity continuation is left out where
/// the viscosity barely rises over the contact (ln(eta(p_H)/eta_R) below
/// [`MILD_VISCOSITY_RISE`]): a smaller alpha is then the same problem, and it failed as
/// plain Newton did on every isoviscous-elastic point measured (a steel ball on PDMS, the
/// Moes points at L = 0.01 from M = 10 to 1000; at M = 1000 its three tries took 180 s of a
/// retry at 83,937 unknowns). From a coarser level's pressure it stays: there its first
/// step, solved with the bt line search, is what converges (docs/practice.md, "Soft EHL").
fn homotopies(scene: &Scene, from_hertz: bool) -> Vec<Homotopy> {
    let alpha = scene.lubricant.as_ref().and_then(|l| l.pressure_viscosity).unwrap_or(0.0);
    let mild = from_hertz && scene.viscosity_rise().unwrap_or(0.0) < MILD_VISCOSITY_RISE;
    let alpha = if mild { 0.0 } else { alpha };
    let z = scene.lubricant.as_ref().and_then(|l| l.roelands_exponent);
    let ue = scene.operating.entrainment_speed.unwrap_or(0.0);
    let tilt = scene.operating.tilt_angle;
    // A small tilt angle (strong spin) is milder at a larger one; only with spin kinematics.
    let spin = scene.effects.kinematics == crate::case::KinematicsModel::Spin && tilt < 90.0;
    let halving = |first: f64, lowest: f64| Ramp { first, lowest, ratio: 2.0 };
    let mut list = Vec::new();
    if spin {
        list.push(Homotopy { parameter: Parameter::Tilt(tilt), ramp: halving(0.5, 1.0 / 64.0) });
    }
    if alpha > 0.0 {
        list.push(Homotopy { parameter: Parameter::PressureViscosity { alpha, z }, ramp: halving(0.5, 0.125) });
    }
    list.push(Homotopy { parameter: Parameter::Load(scene.operating.load), ramp: halving(1.0 / 8.0, 1.0 / 64.0) });
    list.push(Homotopy { parameter: Parameter::Speed(ue), ramp: halving(0.25, 1.0 / 64.0) });
    list
}

/// The Newton solver shared by every solve of the path, and the path so far.
struct Newton<'a> {
    ctx: &'a Context,
    snes: Snes,
    /// The iterate (distributed).
    x: Vector,
    j: &'a Matrix,
    /// This rank's rows.
    owned: (usize, usize),
    row_scaling: bool,
    /// Where the film closed, if the last solve stopped for that.
    collapse: Option<Collapse>,
    /// Every place the film closed on the path, in the order met (places within
    /// [`SAME_PLACE`] of one met before are not repeated).
    closed: Vec<[f64; 2]>,
    /// Every Newton solve, logged as it ends.
    steps: Vec<String>,
    /// Newton iterations over the path.
    iterations: usize,
    /// The Jacobian's LU is reused over Newton steps ([`Policy::reuses_lu`]).
    reuses_lu: bool,
    /// A continuation step stopped at the film's domain is solved again with the "bt"
    /// line search ([`Policy::bt_after_domain_error`]).
    bt_after_domain: bool,
    /// The scene's cavitation penalty: a solve below it (the staged xi = 1e3) is short of
    /// the scene.
    scene_penalty: f64,
    /// When set, every state a ramp converges at, with its t (the penalty's ramp, for its
    /// error estimate).
    trail: Option<Vec<(f64, Vec<f64>)>>,
    /// The absolute tolerance of a solve short of the scene (with an accuracy target,
    /// [`INTERMEDIATE_ATOL`]), and of the scene's own solve.
    short_atol: Option<f64>,
    atol: f64,
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
    fn note(&mut self, s: String) {
        self.ctx.log(&s);
        self.steps.push(s);
    }

    /// One Newton solve of the scene `sc` from `start`; `short`: `sc` is short of the
    /// scene (a continuation step below t = 1, the staged penalty), solved to
    /// `short_atol` when there is one.
    fn solve(&mut self, sc: &Scene, system: &mut dyn EhlProblem, start: &[f64], short: bool) -> Result<SolveReport, Error> {
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
    fn solve_with_line_search(
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
    fn on_with_l2(&mut self, sc: &Scene, system: &mut dyn EhlProblem, short: bool, failed: &SolveReport) -> Result<SolveReport, Error> {
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
    fn solution(&self) -> Result<Vec<f64>, Error> {
        Ok(self.x.gather_all()?)
    }

    /// One Newton solve of `from` with `p` at t, from `start`, a state at `p = from_t`
    /// (its H0 raised by [`film_gain`]); the step is logged (`what` before the parameter's
    /// value) and kept in the path. Returns the report and, if converged, the state.
    fn solve_at(
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
    fn search(
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
    fn ramp(
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

/// The steps of a continuation's ramp towards t = 1: t times the ratio (the last step cut
/// at t = 1), or a value of the schedule (where a coarser level's ramp converged) between
/// t and that.
struct RampSteps<'s> {
    ratio: f64,
    schedule: &'s [f64],
    /// The failed steps left before the ramp gives up (None: no such limit).
    failures_left: Option<usize>,
    /// A ramp gives up when a failed step would be followed by a ratio below this.
    smallest_ratio: f64,
}

impl<'s> RampSteps<'s> {
    /// Steps by `ratio` through `schedule`, within `limits`.
    fn new(ratio: f64, schedule: &'s [f64], limits: RampLimits) -> RampSteps<'s> {
        RampSteps { ratio, schedule, failures_left: limits.failures, smallest_ratio: limits.smallest_ratio }
    }

    /// The value to try from t, and whether it is a value of the schedule.
    fn next(&self, t: f64) -> (f64, bool) {
        // Within round-off of the end is the end (heavy-3gpa's load ramp by factors of
        // 2^(1/4) ended at t = 1 - 1e-16, then solved t = 1 again in 0 iterations).
        let next = if t * self.ratio > 1.0 - 1e-9 { 1.0 } else { t * self.ratio };
        match self.schedule.iter().copied().find(|&s| s > t * (1.0 + 1e-9)).filter(|&s| s < next) {
            Some(s) => (s, true),
            None => (next, false),
        }
    }

    /// After the step from t to `tried` failed: the ratio becomes the square root of the
    /// step tried (a step cut at t = 1 is halved in log t from its own size, so the same
    /// failing solve is not repeated: from a scheduled alpha/1.41 with the ratio still 2,
    /// the step to alpha failed, and the square root of 2 gave alpha again). A failed
    /// scheduled step drops the schedule, and the ramp goes on by its own ratio from there;
    /// such a step may be below the smallest ratio once (the coarser level's path had small
    /// steps). Returns false when the ramp gives up: its ratio too small, or its failures
    /// spent.
    fn failed(&mut self, t: f64, tried: f64, planned: bool) -> bool {
        self.ratio = (tried / t).sqrt();
        if let Some(left) = self.failures_left.as_mut() {
            *left = left.saturating_sub(1);
            if *left == 0 {
                return false;
            }
        }
        if planned {
            self.schedule = &[];
            true
        } else {
            self.ratio >= self.smallest_ratio
        }
    }
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

/// Newton's solver, with the stall test of `-ehl_newton_stall` ([`crate::ehl_options::NEWTON_STALL`]).
fn new_snes(comm: petsc::ffi::MPI_Comm) -> Result<Snes, Error> {
    let mut snes = Snes::new(comm, "")?;
    snes.set_stall_test(crate::ehl_options::get().newton_stall, crate::ehl_options::NEWTON_STALL_FACTOR)?;
    Ok(snes)
}

#[cfg(test)]
mod tests {
    use super::{bt_gave_out, homotopies, Parameter, RampLimits, RampSteps};
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

    /// The values a ramp from t0 tries when a step from t to t' converges iff `ok(t, t')`.
    fn tried(t0: f64, ratio: f64, schedule: &[f64], ok: impl Fn(f64, f64) -> bool) -> (bool, Vec<f64>) {
        tried_with(t0, ratio, schedule, RampLimits::DEFAULT, ok)
    }

    /// The same, with the ramp's `limits`.
    fn tried_with(t0: f64, ratio: f64, schedule: &[f64], limits: RampLimits, ok: impl Fn(f64, f64) -> bool) -> (bool, Vec<f64>) {
        let (mut steps, mut t, mut out) = (RampSteps::new(ratio, schedule, limits), t0, Vec::new());
        while t < 1.0 {
            let (next, planned) = steps.next(t);
            out.push(next);
            if ok(t, next) {
                t = next;
            } else if !steps.failed(t, next, planned) {
                return (false, out);
            }
        }
        (true, out)
    }

    #[test]
    fn a_ramp_halves_a_failed_step_and_never_repeats_it() {
        let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let (r2, r4) = (2f64.sqrt(), 2f64.powf(0.25));
        // By factors of 2 from 1/2, converging only by steps up to 1.3: 1 fails, 1/sqrt(2)
        // fails, then steps of 2^(1/4) reach 1.
        let (done, t) = tried(0.5, 2.0, &[], |t, n| n / t <= 1.3);
        assert!(done && close(&t, &[1.0, 0.5 * r2, 0.5 * r4, 0.5 * r2, 0.5 * r2 * r4, 1.0]), "{t:?}");
        // A problem that converges only up to t = 0.9, from the scheduled 1/sqrt(2) with the
        // ratio still 2: the step to 1 is cut to sqrt(2) and fails; the next try is
        // 2^(1/4) from there, not 1 again.
        let (done, t) = tried(0.5, 2.0, &[0.5f64.sqrt()], |_, n| n <= 0.9);
        assert!(!done && close(&t, &[0.5 * r2, 1.0, 0.5 * r2 * r4, 1.0, 0.5 * r2 * r4 * 2f64.powf(0.125)]), "{t:?}");
        assert!(t.windows(2).all(|w| w[0] != w[1]), "a failed step was tried again: {t:?}");
        // A step cut at t = 1 whose square root is below the smallest ratio: no retry.
        assert_eq!(tried(0.96, 2.0, &[], |_, _| false), (false, vec![1.0]));
        // Steps of 2, 2^(1/2), 2^(1/4), 2^(1/8) and then the ramp gives up.
        let (done, t) = tried(0.5, 2.0, &[], |_, _| false);
        assert!(!done && t.len() == 4, "{t:?}");
    }

    #[test]
    fn a_ramp_with_a_failure_limit_gives_up_at_it() {
        let r2 = 2f64.sqrt();
        // Converging only by steps up to 1.3 from 1/2: the second failure ends the ramp.
        let (done, t) = tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |t, n| n / t <= 1.3);
        assert!(!done && t.len() == 2 && (t[1] - 0.5 * r2).abs() < 1e-12, "{t:?}");
        // Failures between converged steps count too: 1 fails, 1/sqrt(2) converges, 1 fails.
        let (done, t) = tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |_, n| n < 0.8);
        assert!(!done && t == vec![1.0, 0.5 * r2, 1.0], "{t:?}");
        // One failure and then convergence: the limit does not bind.
        assert_eq!(tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |t, n| n / t <= 1.5), (true, vec![1.0, 0.5 * r2, 1.0]));
        // Without the limit the same ramp as before.
        assert_eq!(tried_with(0.5, 2.0, &[], RampLimits::DEFAULT, |t, n| n / t <= 1.3), tried(0.5, 2.0, &[], |t, n| n / t <= 1.3));
    }

    #[test]
    fn a_patient_ramp_takes_smaller_steps_before_it_gives_up() {
        // M = 20, L = 20 with c_J = 1: from alpha 62.59 of 68.25 GPa^-1 the step to alpha
        // fails and only a step of at most 1.05 converges.
        let (t0, r) = (62.59 / 68.25, (68.25f64 / 62.59).sqrt());
        let ok = |t: f64, n: f64| n / t <= 1.05;
        assert_eq!(tried_with(t0, 2.0, &[], RampLimits::DEFAULT, ok), (false, vec![1.0]));
        let (done, t) = tried_with(t0, 2.0, &[], RampLimits::PATIENT, ok);
        assert!(done && t.len() == 3 && (t[1] - t0 * r).abs() < 1e-12, "{t:?}");
    }

    /// A milder load's start gets its own film: Hamrock-Dowson's hc goes as W^-0.067 and
    /// the Hertz radius a as W^(1/3), so the dimensionless film H = h R/a^2 of L/8 is
    /// 8^(2/3 + 0.067) = 4.6 times the scene's. The pressure-viscosity continuation keeps
    /// its start, and no step thins a start's film.
    #[test]
    fn a_lighter_load_starts_from_its_own_thicker_film() {
        use super::{film_gain, hc_guess};
        let scene = crate::case::parse_scene(include_str!("../../../cases/paper/table2-ue2.toml"), "table2-ue2").unwrap();
        let load = Parameter::Load(scene.operating.load);
        let h = hc_guess(&scene);
        let ratio = 1.0 + film_gain(&scene, load, 1.0, 0.125) / h;
        assert!((ratio / 8f64.powf(2.0 / 3.0 + 0.067) - 1.0).abs() < 1e-3, "{ratio}");
        let (g, g8, g4) = (film_gain(&scene, load, 0.25, 0.125), film_gain(&scene, load, 1.0, 0.125), film_gain(&scene, load, 1.0, 0.25));
        assert!((g - (g8 - g4)).abs() < 1e-12 * g8, "{g} against {}", g8 - g4);
        // A heavier load or a slower speed: the start keeps its thicker film.
        assert_eq!(film_gain(&scene, load, 0.125, 1.0), 0.0);
        let ue = scene.operating.entrainment_speed.unwrap();
        assert_eq!(film_gain(&scene, Parameter::Speed(ue), 0.25, 1.0), 0.0);
        // Four times the speed: hc as Ue^0.67 at the same a.
        let ratio = 1.0 + film_gain(&scene, Parameter::Speed(ue), 1.0, 0.25) / h;
        assert!((ratio / 4f64.powf(0.67) - 1.0).abs() < 1e-3, "{ratio}");
        let pv = Parameter::PressureViscosity { alpha: 2e-8, z: None };
        assert_eq!(film_gain(&scene, pv, 1.0, 0.5), 0.0);
    }

    #[test]
    fn the_homotopies_reach_the_scene_at_t_equal_1_and_are_milder_below() {
        let scene = crate::case::parse_scene(include_str!("../../../cases/paper/table2-ue2.toml"), "table2-ue2").unwrap();
        let list = homotopies(&scene, true);
        let names: Vec<&str> = list.iter().map(|h| h.parameter.name()).collect();
        // Table 2 has alpha > 0 and rolls without spin: no tilt continuation.
        assert_eq!(names, ["pressure-viscosity", "load", "speed"]);
        // Barus with alpha 400 times smaller: the viscosity rises by e^0.05 over the
        // contact. From the Hertz start a smaller alpha is no milder problem, from a coarser
        // level's pressure the continuation stays.
        let mut iso = scene.clone();
        iso.effects.viscosity = crate::case::ViscosityModel::Barus;
        iso.lubricant.as_mut().unwrap().pressure_viscosity = Some(23e-9 / 400.0);
        let names = |from_hertz| homotopies(&iso, from_hertz).iter().map(|h| h.parameter.name()).collect::<Vec<_>>();
        assert_eq!(names(true), ["load", "speed"]);
        assert_eq!(names(false), ["pressure-viscosity", "load", "speed"]);
        // Without the last resorts only the continuations nearest the scene remain.
        let last: Vec<bool> = list.iter().map(|h| h.parameter.last_resort()).collect();
        assert_eq!(last, [false, true, true]);
        assert!(!Parameter::Tilt(0.5).last_resort());
        for h in &list {
            let mut sc = scene.clone();
            h.parameter.apply(&mut sc, 1.0);
            assert_eq!(sc.operating, scene.operating, "{}", h.parameter.name());
            assert_eq!(sc.lubricant, scene.lubricant, "{}", h.parameter.name());
        }
        // At t = 1/2: half the load, twice the speed (a thicker film), half of alpha.
        let mut sc = scene.clone();
        Parameter::Load(scene.operating.load).apply(&mut sc, 0.5);
        Parameter::Speed(scene.operating.entrainment_speed.unwrap()).apply(&mut sc, 0.5);
        assert_eq!(sc.operating.load, 0.5 * scene.operating.load);
        assert_eq!(sc.operating.entrainment_speed, Some(2.0 * scene.operating.entrainment_speed.unwrap()));
    }
}
