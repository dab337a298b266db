//! Adaptive refinement to an accuracy target (`[accuracy] target`).
//!
//! 1. Solve on the scene's mesh (level 0).
//! 2. Mark the fewest contact triangles that carry the fraction `accuracy.marking` of the
//!    goal-oriented indicator: the mass-flux residual ([`crate::reynolds::estimate`])
//!    weighted by the adjoints of hc, hm and, with friction, fx and fz (how much a flux
//!    error in each triangle moves them); with `marking` 0, every
//!    triangle of the pressurised zone (a nodal pressure above 0.01 p_H). Halve their size,
//!    keep the others' (a graded size field on the face, [`crate::mesh::size_field`]), and
//!    mesh the solid anew under it (conforming bisection).
//! 3. Solve from the previous level's pressure, interpolated (mesh sequencing).
//! 4. Estimate the error of hc and hm (and fx, fz with friction) from the change between
//!    the last two levels, e_k = |Q_k - Q_{k-1}| max(1, rho/(1 - rho)) with rho the observed
//!    ratio of the last two changes (capped at 0.8): for a sequence converging by a factor
//!    rho per level the remaining error is rho/(1 - rho) times the last change. A change
//!    below 1/8 of the one before it is a crossing of the limit, not convergence (see
//!    [`estimate`]). Stop when every estimate is below the target (from level 2 on, so
//!    that rho is measured).
//! 5. When the target cannot be reached (`accuracy.max_levels` levels solved, the next
//!    level above `accuracy.max_unknowns`, or every triangle at the smallest size), the
//!    last level's result is written with its estimated error, `accuracy.reached` is
//!    false and the run exits 4: a result, honestly labelled, rather than none.
use super::first_level::{closures, first_level_again, onward, reached, without_gradient_jump, Onward, FIRST_LEVEL_RETRIES};
use super::lubricated::{post_point, Setup};
use super::marking::{goal_mark, goals, longest_edges, next_field, zone_mark};
use super::{Context, Outcome};
use crate::case::schema::RAISED_GRADIENT_JUMP;
use crate::case::Scene;
use crate::collective;
use crate::ehl::driver::{EhlSolution, EhlSolver, Milder, Start};
use crate::ehl::post::FieldsOnFace;
use crate::error::{Error, Reached};
use crate::mesh::size_field::SizeField;
use serde_json::json;
use std::sync::Arc;
use std::time::Instant;

/// Smallest element size adaptive refinement makes (units of a): 16/2^12.
pub const MIN_ADAPTIVE_SIZE: f64 = 16.0 / 4096.0;

/// The ratio of successive changes is capped here: beyond it the sequence is not
/// converging in a way an estimate can trust, and the factor rho/(1 - rho) stays at 4.
const RHO_CAP: f64 = 0.8;

/// The smallest ratio of successive changes a converging level sequence can show: a
/// P2 discretisation converges at most at third order in the element size (hc and hm:
/// observed orders 1.2-3.5, docs/accuracy.md), 2^-3 per halving. A smaller ratio is a
/// change that crossed the limit by chance.
const FASTEST_CONTRACTION: f64 = 0.125;

/// One level of the adaptive loop.
#[derive(Debug, Clone)]
pub struct Level {
    pub elastic_unknowns: usize,
    pub pressure_unknowns: usize,
    pub contact_triangles: usize,
    pub min_size: f64,
    /// Newton iterations of the attempt that converged.
    pub newton_iterations: usize,
    /// Wall time of the level: every attempt, its adjoint and the next level's marking.
    pub seconds: f64,
    /// The part of `seconds` spent in attempts that did not converge (the level solved
    /// again on the same or another mesh).
    pub failed_seconds: f64,
    /// hc, hm (m), pmax (Pa).
    pub hc: f64,
    pub hm: f64,
    /// Where hm lies (units of a): on a full domain the minimum can move from one side
    /// lobe to the other between levels.
    pub hm_at: [f64; 2],
    pub pmax: f64,
    /// Friction coefficients fx, fz (scenes with friction).
    pub friction: Option<[f64; 2]>,
    /// Estimated errors (None on level 0).
    pub est: Option<Estimate>,
}

/// The estimated relative errors of a level's target quantities: hc and hm, and with
/// friction fx and fz, each relative to the magnitude of the friction coefficient
/// sqrt(fx^2 + fz^2) (fz vanishes by symmetry without spin, so its own size is no scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    pub hc: f64,
    pub hm: f64,
    pub friction: Option<[f64; 2]>,
}

impl Estimate {
    /// The estimate of the last level of `levels`, None before the second level.
    fn of(levels: &[Level]) -> Option<Estimate> {
        let series = |f: &dyn Fn(&Level) -> f64| levels.iter().map(f).collect::<Vec<f64>>();
        let hc = estimate(&series(&|l| l.hc))?;
        let hm = estimate(&series(&|l| l.hm))?;
        let friction = levels.iter().map(|l| l.friction).collect::<Option<Vec<[f64; 2]>>>().and_then(|f| {
            let last = f.last()?;
            let scale = last[0].hypot(last[1]);
            let fx: Vec<f64> = f.iter().map(|v| v[0]).collect();
            let fz: Vec<f64> = f.iter().map(|v| v[1]).collect();
            Some([estimate_scaled(&fx, scale)?, estimate_scaled(&fz, scale)?])
        });
        Some(Estimate { hc, hm, friction })
    }

    /// Every estimated error.
    fn values(&self) -> Vec<f64> {
        let mut v = vec![self.hc, self.hm];
        v.extend(self.friction.iter().flatten());
        v
    }

    /// "hc x %, hm y %" (and fx, fz).
    fn describe(&self) -> String {
        let mut s = format!("hc {:.2} %, hm {:.2} %", 100.0 * self.hc, 100.0 * self.hm);
        if let Some([fx, fz]) = self.friction {
            s.push_str(&format!(", fx {:.2} %, fz {:.2} %", 100.0 * fx, 100.0 * fz));
        }
        s
    }

    fn json(&self) -> serde_json::Value {
        let mut v = json!({ "hc": self.hc, "hm": self.hm });
        if let Some([fx, fz]) = self.friction {
            v["fx"] = json!(fx);
            v["fz"] = json!(fz);
        }
        v
    }
}

/// The estimated relative error of the last value of `q` (see the module documentation).
pub fn estimate(q: &[f64]) -> Option<f64> {
    estimate_scaled(q, q.last()?.abs())
}

/// The estimated error of the last value of `q` relative to `scale`.
///
/// With changes d_i = q_i - q_{i-1}, the last one d_k and rho = |d_k / d_{k-1}|:
/// e = max(1, rho/(1 - rho)) |d_k|. Two guards make a coincidence visible:
/// - a change smaller than [`FASTEST_CONTRACTION`] times the one before it is faster than
///   the discretisation converges; it is a crossing of the limit, not convergence. So the
///   estimate is at least [`FASTEST_CONTRACTION`] |d_{k-1}| (the next change of a
///   sequence converging at that rate). The change from the first level counts too: a
///   large one says the first level was far off, and the next change can be small by
///   chance (cases/hard/slow without the gradient-jump term: a side lobe narrower than
///   the elements held hm within 0.66 % over one halving and moved it by 4.1 % over the
///   next);
/// - the ratio after such a crossing is measured over two changes, rho = sqrt|d_k / d_{k-2}|,
///   not against the crossing.
fn estimate_scaled(q: &[f64], scale: f64) -> Option<f64> {
    let n = q.len();
    if n < 2 {
        return None;
    }
    let d: Vec<f64> = q.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let k = d.len() - 1;
    let crossing = |i: usize| i >= 1 && d[i] < FASTEST_CONTRACTION * d[i - 1];
    let mut e = d[k];
    if k >= 1 {
        let rho = if crossing(k - 1) {
            (d[k] / d[k - 2]).sqrt()
        } else if d[k - 1] > 0.0 {
            d[k] / d[k - 1]
        } else {
            RHO_CAP
        };
        let rho = if rho.is_finite() { rho.min(RHO_CAP) } else { RHO_CAP };
        e = (e * (rho / (1.0 - rho)).max(1.0)).max(FASTEST_CONTRACTION * d[k - 1]);
    }
    Some(e / scale)
}

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
}

/// Runs the adaptive loop of a lubricated single-point scene with `accuracy.target > 0`.
/// Collective. When the target cannot be reached (`max_levels`, `max_unknowns`, every
/// triangle at the smallest size) the last level's result is written with its estimated
/// error and the returned [`Outcome::ShortOfTarget`] says why (exit 4).
pub fn run(ctx: &Context, scene: &Scene, earlier: Option<&super::restart::EarlierRun>) -> Result<Outcome, Error> {
    // The scene as solved: the gradient-jump factor may be raised on the way (below).
    let mut own = scene.clone();
    let acc = scene.accuracy;
    let target = acc.target;
    let max_levels = acc.max_levels as usize;
    ctx.log(format!(
        "accuracy: target {target} (relative error of hc and hm{}): adaptive refinement of the contact face, at most {max_levels} levels after the first and {} unknowns per level",
        if scene.effects.friction == crate::case::FrictionModel::Off { "" } else { ", fx and fz" },
        acc.max_unknowns
    ));
    let mut levels: Vec<Level> = Vec::new();
    let mut field: Option<Arc<SizeField>> = None;
    let mut previous: Option<Solved> = None;
    let growth = scene.mesh.growth;
    // Tries of the first level on a finer mesh after it failed on the scene's own.
    let mut first_retries = 0;
    // The level that may be meshed again with zone marking if it does not converge on its
    // goal-oriented mesh.
    let mut zone_retry: Option<usize> = None;
    // The level solved again with the load and speed continuations and the Hertz start.
    let mut full_ladder: Option<usize> = None;
    // Seconds of the present level's attempts that did not converge: part of its time.
    let mut tried_s = 0.0;
    // Where a failed first level got, with its mesh: the retry goes on from there ([`onward`]).
    let mut from: Option<Onward> = None;
    loop {
        let scene = &own;
        // The level being solved: one per converged level (a retried first level stays 0).
        let k = levels.len();
        let t0 = Instant::now();
        let setup = match Setup::with_size_field(ctx, scene, field.clone()) {
            Ok(s) => s,
            Err(e) => return out_of_time(ctx, scene, previous.as_ref(), k, &levels, e),
        };
        let (n_u, n_p) = setup.layout.counts();
        if let (Some(prev), true) = (&previous, (n_u + n_p + 1) as u64 > acc.max_unknowns) {
            let why = format!("level {k} would have {} unknowns, above accuracy.max_unknowns = {}", n_u + n_p + 1, acc.max_unknowns);
            let why = short_of(target, &why, k - 1, levels.last().and_then(|l| l.est));
            return finish(ctx, scene, prev, target, &levels, Some(why));
        }
        let solver = match EhlSolver::new(ctx, scene, &setup.mesh, &setup.part, &setup.dofs, &setup.layout, setup.half) {
            Ok(s) => s,
            Err(e) => return out_of_time(ctx, scene, previous.as_ref(), k, &levels, e),
        };
        let sol = match (&previous, earlier) {
            (Some(prev), _) => {
                let pf = FieldsOnFace::new(&prev.setup.mesh, &prev.setup.layout, &prev.sol.x);
                let p = |x: f64, z: f64| pf.at(x, z).map_or(0.0, |v| v.0);
                // A level after one that plain Newton could not solve from its own coarser
                // level goes to the continuation at once (level 0 is not a guide: its start
                // is the Hertz pressure, not a coarser level's).
                let plain = !(k >= 2 && prev.sol.continued);
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
                let last_resorts = !raisable || full_ladder == Some(k);
                let solved = collective::agree(
                    &ctx.world,
                    solver.solve_from(ctx, scene, Start::Pressure { p: &p, hc: prev.hc, label: &label, plain, milder, last_resorts }),
                );
                match solved {
                    Ok(sol) => sol,
                    // A level that does not converge with a small gradient-jump factor is
                    // solved again on the same mesh with it raised, for it and the levels
                    // after: at M = 100, L = 20 the outlet spike is one element wide on the
                    // 0.0625 and 0.03125 a levels, Newton moves it from node to node, and
                    // the alpha ramp stops at 55-63 of 68.3 GPa^-1; with c_J = 1 every level
                    // converges and hc, hm move by 0.1 %, 0.3 % (docs/accuracy.md, "Newton
                    // on fine levels at high M and L").
                    Err(e) if crate::interrupt::agreed() == 0 && raisable && newton_failed(ctx, &e) => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge ({}); again on the same mesh with the gradient-jump factor reynolds.gradient_jump raised from {} to {RAISED_GRADIENT_JUMP} for this level and the ones after",
                            reason(&e),
                            scene.reynolds.gradient_jump
                        ));
                        drop(solver);
                        own.reynolds.gradient_jump = RAISED_GRADIENT_JUMP;
                        tried_s += t0.elapsed().as_secs_f64();
                        continue;
                    }
                    Err(e) if crate::interrupt::agreed() == 0 && !last_resorts => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge ({}); again on the same mesh with the load and speed continuations and the Hertz start",
                            reason(&e)
                        ));
                        drop(solver);
                        full_ladder = Some(k);
                        tried_s += t0.elapsed().as_secs_f64();
                        continue;
                    }
                    // A goal-oriented level that does not converge is meshed again with the
                    // previous level's whole pressurised zone refined, once: at M = 100,
                    // L = 20 the continuation stalled at alpha 62.6 of 68.3 GPa^-1 on the
                    // goal-oriented 0.125 a level and converged on the zone's.
                    Err(e) if crate::interrupt::agreed() == 0 && zone_retry == Some(k) => {
                        ctx.log(format!(
                            "accuracy: level {k} did not converge on its goal-oriented mesh ({}); again with level {}'s pressurised zone refined",
                            reason(&e),
                            k - 1
                        ));
                        let edges = longest_edges(&prev.setup.mesh);
                        let marked = zone_mark(&pf, &edges);
                        field = Some(Arc::new(next_field(&prev.setup.mesh, &edges, &marked, growth)));
                        zone_retry = None;
                        tried_s += t0.elapsed().as_secs_f64();
                        continue;
                    }
                    // A level that does not converge leaves the last converged one as the
                    // result, labelled as short of its target (an interruption stops).
                    Err(e) if crate::interrupt::agreed() == 0 => {
                        let why = short_of(target, &format!("level {k} did not converge ({e})"), k - 1, levels.last().and_then(|l| l.est));
                        drop(solver);
                        return finish(ctx, scene, prev, target, &levels, Some(why));
                    }
                    Err(e) => {
                        drop(solver);
                        return out_of_time(ctx, scene, Some(prev), k, &levels, e);
                    }
                }
            }
            (None, Some(e)) => e.solve(ctx, scene, &solver)?,
            (None, None) => match collective::agree(&ctx.world, onward(ctx, scene, &solver, from.as_ref())) {
                Ok(sol) => sol,
                // A first mesh too coarse for the film (at low speed or high load the side
                // lobes and the outlet constriction are narrower than 0.25 a, and the film
                // closes there on it: cases/hard/slow, heavy-3gpa) is refined in the Hertz
                // zone and, finer, around the radii where the film closed, and solved again
                // without the gradient-jump term ([`without_gradient_jump`]); a film that
                // closes at a spin pole closes on any mesh.
                // Every rank decides the same: only Newton's own failure (the same on every
                // rank) is retried, not one rank's local fault.
                Err(e) if crate::interrupt::agreed() == 0 && first_retries < FIRST_LEVEL_RETRIES && newton_failed(ctx, &e) => {
                    let why = format!("did not converge on its mesh ({})", reason(&e));
                    let closed = closures(ctx, &e);
                    field = Some(first_level_again(ctx, &setup.mesh, growth, &why, &closed));
                    if !closed.is_empty() {
                        without_gradient_jump(ctx, &mut own);
                    }
                    first_retries += 1;
                    tried_s += t0.elapsed().as_secs_f64();
                    drop(solver);
                    let further = |r: &Reached| !matches!(&from, Some(Onward::Reached(_, f)) if f.t >= r.t);
                    if let Some(r) = reached(ctx, &e).filter(further) {
                        from = Some(Onward::Reached(setup, r));
                    }
                    continue;
                }
                Err(e) => return Err(e),
            },
        };
        let fields = FieldsOnFace::new(&setup.mesh, &setup.layout, &sol.x);
        let st = fields.stats();
        let unphysical = ![st.hc, st.hm, st.pmax].iter().all(|v| v.is_finite()) || st.hm <= 0.0;
        // A first level whose film dips below zero between its nodes (the P2 film under a
        // spin pole or a side lobe narrower than its elements: cases/hard/spin-0.33deg at
        // 0.25 a) is refined and solved again like one that does not converge.
        if unphysical && previous.is_none() && earlier.is_none() && first_retries < FIRST_LEVEL_RETRIES {
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
            field = Some(first_level_again(ctx, &setup.mesh, growth, &why, &[]));
            first_retries += 1;
            tried_s += t0.elapsed().as_secs_f64();
            drop(solver);
            from = Some(Onward::Converged(setup, sol.x));
            continue;
        }
        if unphysical {
            return Err(Error::numerical(format!(
                "accuracy: level {k} converged to an unphysical state (hc {}, hm {}); no result written",
                st.hc, st.hm
            )));
        }
        let (hs, ph) = (scene.scales().film_scale(), scene.hertz().ph);
        let edges = longest_edges(&setup.mesh);
        let min_size = edges.iter().cloned().fold(f64::INFINITY, f64::min) / std::f64::consts::SQRT_2;
        let level = Level {
            elastic_unknowns: n_u,
            pressure_unknowns: n_p,
            contact_triangles: setup.mesh.contact_tris.len(),
            min_size,
            newton_iterations: sol.newton_total,
            seconds: tried_s + t0.elapsed().as_secs_f64(),
            failed_seconds: tried_s,
            hc: st.hc * hs,
            hm: st.hm * hs,
            hm_at: st.hm_at,
            pmax: st.pmax * ph,
            friction: level_friction(scene, &fields)?,
            est: None,
        };
        levels.push(level);
        if k == 0 && acc.max_seconds > 0.0 {
            // The budget covers the levels after the first: a run always has a result.
            crate::interrupt::set_deadline(Some(ctx.start + std::time::Duration::from_secs_f64(acc.max_seconds)));
        }
        let est = Estimate::of(&levels);
        let level = levels.last_mut().expect("the level just pushed");
        level.est = est;
        ctx.log(format!(
            "accuracy: level {k}: {} contact triangles (smallest {:.4} a), {} unknowns, {} Newton its, {:.1} s{}: hc = {:.5e} m, hm = {:.5e} m at ({:.3}a, {:.3}a), pmax = {:.4e} Pa{}; estimated error {}",
            level.contact_triangles,
            level.min_size,
            n_u + n_p + 1,
            level.newton_iterations,
            level.seconds,
            if level.failed_seconds > 0.0 { format!(" ({:.1} s of them in attempts that failed)", level.failed_seconds) } else { String::new() },
            level.hc,
            level.hm,
            level.hm_at[0],
            level.hm_at[1],
            level.pmax,
            level.friction.map_or(String::new(), |f| format!(", fx = {:.5e}, fz = {:.5e}", f[0], f[1])),
            level.est.map_or("- (first level)".to_string(), |e| e.describe())
        ));
        let reached = k >= 2 && est.is_some_and(|e| e.values().iter().all(|&v| v < target));
        // The next level's marking, while this level's fields are at hand (not when it is the
        // last), and the speed exponents when asked for: both from one adjoint LU.
        let goal = !reached && k < max_levels && acc.marking > 0.0;
        let mut adjoint = (goal || scene.output.speed_exponents).then(|| collective::agree(&ctx.world, solver.adjoint(ctx, scene, &sol.x)));
        let exponents = match (&mut adjoint, scene.output.speed_exponents) {
            (Some(Ok(a)), true) => Some(collective::agree(&ctx.world, super::sensitivity::speed_exponents(ctx, a, &fields, &st))),
            (Some(Err(e)), true) => Some(Err(Error::numerical(format!("the adjoint failed: {e}")))),
            _ => None,
        };
        let exponents = exponents.map(|got| super::sensitivity::report(ctx, got));
        let marked = if !reached && k < max_levels {
            Some(match adjoint.as_ref().filter(|_| goal) {
                // A failed adjoint costs this level's goal-oriented marking, not the run (an
                // interruption is acted on at the check after the marking).
                Some(Ok(a)) => {
                    match collective::agree(&ctx.world, goals(ctx, scene, a, &fields, &st, levels.last().and_then(|l| l.friction)))
                        .map(|goals| goal_mark(ctx, scene, &fields, &goals, &edges, acc.marking))
                    {
                        Ok(m) => {
                            zone_retry = Some(k + 1);
                            m
                        }
                        Err(e) => {
                            ctx.log(format!("accuracy: goal-oriented marking failed ({e}); level {} refines the pressurised zone", k + 1));
                            zone_mark(&fields, &edges)
                        }
                    }
                }
                Some(Err(e)) => {
                    ctx.log(format!("accuracy: the adjoint failed ({e}); level {} refines the pressurised zone", k + 1));
                    zone_mark(&fields, &edges)
                }
                None => zone_mark(&fields, &edges),
            })
        } else {
            None
        };
        drop(adjoint);
        // A level's time includes its adjoint and the marking of the next one.
        levels.last_mut().expect("the level just pushed").seconds = tried_s + t0.elapsed().as_secs_f64();
        tried_s = 0.0;
        let condensation_s = solver.condensation_s;
        drop(fields);
        drop(solver);
        let here = Solved { setup, sol, hc: st.hc, condensation_s, exponents, gradient_jump: scene.reynolds.gradient_jump };
        if reached {
            ctx.log(format!("accuracy: target {target} reached at level {k}"));
            return finish(ctx, scene, &here, target, &levels, None);
        }
        if k == max_levels {
            let why = short_of(target, &format!("accuracy.max_levels = {max_levels} refinement levels solved"), k, est);
            return finish(ctx, scene, &here, target, &levels, Some(why));
        }
        let marked = marked.expect("marked when the loop goes on");
        if !marked.iter().any(|&m| m) {
            let why = short_of(target, &format!("every contact triangle is at the smallest size {MIN_ADAPTIVE_SIZE} a"), k, est);
            return finish(ctx, scene, &here, target, &levels, Some(why));
        }
        field = Some(Arc::new(next_field(&here.setup.mesh, &edges, &marked, growth)));
        if let Err(e) = crate::interrupt::check("adaptive refinement") {
            return out_of_time(ctx, scene, Some(&here), k + 1, &levels, e);
        }
        previous = Some(here);
    }
}

/// Whether `e` is Newton's own failure, the same on every rank (not one rank's local
/// fault), and not a film closing at a spin pole (which closes on any mesh): the failures
/// after which a level is solved again. Collective.
fn newton_failed(ctx: &Context, e: &Error) -> bool {
    collective::all(
        &ctx.world,
        matches!(e.root(), Error::NotConverged(_) | Error::FilmClosed { .. }) && !e.to_string().contains(crate::ehl::driver::POLE_COLLAPSE),
    )
}

/// Why `e` stopped Newton, without the path of solves it lists, for the log.
fn reason(e: &Error) -> String {
    let why = e.to_string();
    why.split("; path:").next().unwrap_or(&why).to_string()
}

/// After level `k` stopped with `e`: when the time budget was spent (and a level converged
/// before), the last converged level's result, labelled as short of its target; any other
/// error (a signal, a failure outside Newton) stops the run.
fn out_of_time(ctx: &Context, scene: &Scene, prev: Option<&Solved>, k: usize, levels: &[Level], e: Error) -> Result<Outcome, Error> {
    match prev {
        // (`finish` clears the spent budget before it writes.)
        Some(prev) if crate::interrupt::agreed() == crate::interrupt::DEADLINE => {
            let acc = scene.accuracy;
            let why = format!("the time budget accuracy.max_seconds = {} s was spent during level {k}", acc.max_seconds);
            let why = short_of(acc.target, &why, k - 1, levels.last().and_then(|l| l.est));
            finish(ctx, scene, prev, acc.target, levels, Some(why))
        }
        _ => Err(e),
    }
}

/// The message of a run that stops short of `target`: why, and which level's result is
/// written with which estimate.
fn short_of(target: f64, why: &str, level: usize, est: Option<Estimate>) -> String {
    format!(
        "accuracy: target {target} not reached: {why}; the result of level {level} is written with its estimated error ({})",
        describe(est)
    )
}

/// The estimate, or "none: a single level" without one.
fn describe(est: Option<Estimate>) -> String {
    est.map_or("none: a single level".to_string(), |e| e.describe())
}

/// The friction coefficients fx, fz of a level (every rank holds the whole iterate), or
/// None without friction.
fn level_friction(scene: &Scene, fields: &FieldsOnFace) -> Result<Option<[f64; 2]>, Error> {
    let Some(fs) = super::lubricated::friction_setup(scene, fields.mesh.spec.contact) else { return Ok(None) };
    let f = crate::friction::pass::friction_pass(fields, &fs)?;
    Ok(Some([f.fx, f.fz]))
}

/// Writes the result of `done` (the last level solved) with the accuracy report; with a
/// `shortfall` the report says the target was not reached and the run exits 4.
fn finish(ctx: &Context, scene: &Scene, done: &Solved, target: f64, levels: &[Level], shortfall: Option<String>) -> Result<Outcome, Error> {
    // The budget bounds the refinement, not the writing of its result.
    crate::interrupt::clear_deadline();
    crate::interrupt::check("the Newton solve")?;
    // The scene written with the result is the one its level was solved with.
    let mut scene = scene.clone();
    scene.reynolds.gradient_jump = done.gradient_jump;
    let scene = &scene;
    ctx.write_results(|dir| {
        post_point(ctx, scene, &done.setup, &done.sol, done.condensation_s, dir)?;
        ctx.amend_summary(dir, |summary| {
            summary["accuracy"] = accuracy_report(target, levels, shortfall.as_deref());
            if let Some(e) = &done.exponents {
                summary["speed_exponents"] = e.clone();
            }
        })
    })?;
    Ok(match shortfall {
        Some(why) => {
            ctx.log(&why);
            Outcome::ShortOfTarget(why)
        }
        None => Outcome::Done,
    })
}

/// The `accuracy` object of summary.json: target, estimates, levels.
fn accuracy_report(target: f64, levels: &[Level], shortfall: Option<&str>) -> serde_json::Value {
    let last = levels.last().expect("a level");
    let mut report = json!({
        "target": target,
        "reached": shortfall.is_none(),
        "estimator": "change between the last two levels times max(1, rho/(1-rho)), rho the ratio of the last two changes (capped at 0.8; over two changes after a change below 1/8 of the one before it), and at least 1/8 of the change before the last",
        "levels": levels.iter().enumerate().map(|(k, l)| {
            let mut v = json!({
                "level": k, "elastic_unknowns": l.elastic_unknowns, "pressure_unknowns": l.pressure_unknowns,
                "contact_triangles": l.contact_triangles, "smallest_size_a": l.min_size,
                "newton_iterations": l.newton_iterations, "seconds": l.seconds, "failed_attempts_seconds": l.failed_seconds,
                "hc_m": l.hc, "hm_m": l.hm, "hm_at_a": l.hm_at, "pmax_pa": l.pmax,
            });
            // The first level has no estimate: the key is left out (summary.json holds no null).
            if let Some(e) = l.est {
                v["estimated_error"] = e.json();
            }
            if let Some([fx, fz]) = l.friction {
                v["fx"] = json!(fx);
                v["fz"] = json!(fz);
            }
            v
        }).collect::<Vec<_>>(),
    });
    if let Some(e) = last.est {
        report["estimated_error"] = e.json();
    }
    if let Some(why) = shortfall {
        report["not_reached_because"] = json!(why);
    }
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_of_a_geometric_sequence_bounds_its_error() {
        // q_k = 1 + 0.1 rho^k converges to 1; the estimate of the last value's relative
        // error is rho/(1-rho) times the last change: exact for a geometric sequence.
        for rho in [0.25, 0.5, 0.7] {
            let q: Vec<f64> = (0..5).map(|k| 1.0 + 0.1 * f64::powi(rho, k)).collect();
            let e = estimate(&q).unwrap();
            let true_err = (q[4] - 1.0) / q[4];
            let factor = (rho / (1.0 - rho)).max(1.0);
            assert!((e - factor * (q[4] - q[3]).abs() / q[4]).abs() < 1e-15);
            assert!(e >= true_err * (1.0 - 1e-12), "rho {rho}: estimate {e} below the error {true_err}");
        }
        assert_eq!(estimate(&[1.0]), None);
        // Two values: the change itself.
        assert!((estimate(&[1.0, 1.01]).unwrap() - 0.01 / 1.01).abs() < 1e-15);
    }

    #[test]
    fn a_change_that_crosses_the_limit_by_chance_is_not_trusted() {
        // hm of table2-ue2 with only a target (um, levels 0-4 at 0.25 a down to 0.0156 a):
        // the third change (+0.22 %) is a crossing; level 4 shows hm was still 0.96 % off.
        let hm = [0.145152, 0.152788, 0.136198, 0.136493, 0.137811];
        let error_of_level_3 = (hm[4] - hm[3]) / hm[4];
        let e3 = estimate(&hm[..4]).unwrap();
        assert!(e3 >= error_of_level_3, "level 3: estimate {e3} below the error {error_of_level_3}");
        assert!((e3 - 0.125 * (hm[2] - hm[1]).abs() / hm[3]).abs() < 1e-15, "{e3}");
        // After the crossing the ratio is taken over two changes (sqrt(0.97/10.9) = 0.3):
        // the estimate is the last change itself, not 4 times it.
        let e4 = estimate(&hm).unwrap();
        assert!((e4 - (hm[4] - hm[3]).abs() / hm[4]).abs() < 1e-15, "{e4}");
        // cases/hard/slow: after level 0's one-node dip of hm the next change is held to an
        // eighth of it too; the level after it decides.
        let hm = [2.34073e-9, 1.02892e-8, 1.01946e-8];
        let e = estimate(&hm).unwrap();
        assert!((e - 0.125 * (hm[1] - hm[0]).abs() / hm[2]).abs() < 1e-15, "{e}");
        // A sequence converging at third order keeps its plain estimate.
        let q: Vec<f64> = (0..5).map(|k| 1.0 + 0.1 * f64::powi(0.125, k)).collect();
        assert!((estimate(&q).unwrap() - (q[4] - q[3]).abs() / q[4]).abs() < 1e-15);
    }

    #[test]
    fn friction_errors_are_relative_to_the_friction_coefficient_and_join_the_targets() {
        let level = |hc: f64, f: Option<[f64; 2]>| Level {
            elastic_unknowns: 0,
            pressure_unknowns: 0,
            contact_triangles: 0,
            min_size: 0.25,
            newton_iterations: 0,
            seconds: 0.0,
            failed_seconds: 0.0,
            hc,
            hm: 1.0,
            hm_at: [0.0, -0.9],
            pmax: 1.0,
            friction: f,
            est: None,
        };
        // fz is zero up to round-off (no spin): its change is measured against |f|, not |fz|.
        let levels = [level(1.0, Some([0.03, 1e-12])), level(1.0, Some([0.0303, 3e-12]))];
        let e = Estimate::of(&levels).unwrap();
        let [fx, fz] = e.friction.unwrap();
        assert!((fx - 0.0003 / 0.0303).abs() < 1e-12 && fz < 1e-9, "{e:?}");
        assert_eq!(e.values().len(), 4);
        assert!(e.describe().contains("fx 0.99 %"), "{}", e.describe());
        // Without friction only hc and hm.
        let e = Estimate::of(&[level(1.0, None), level(1.02, None)]).unwrap();
        assert_eq!((e.values().len(), e.friction), (2, None));
        assert!(Estimate::of(&[level(1.0, None)]).is_none());
    }
}
