//! Sweeps: one scene, several operating points (`[sweep]` lists of Ue, lambda, SRR).
//!
//! - Without an accuracy target ([`run`]) the mesh and the condensed elastic block are
//!   built once; each point starts from the previous converged state (and from the Hertz
//!   start when that fails).
//! - With `accuracy.target` ([`run_adaptive`]) every point is refined adaptively by itself,
//!   as a single-point scene would be: the film's thin features move with the operating
//!   point (the side lobes and the outlet with the speed, the spin pole with the tilt), so
//!   one mesh cannot hold a target across a sweep. Each point has its own levels, estimate
//!   and time budget.
//!
//! A point that fails is recorded with its reason and the sweep goes on; the run then ends
//! non-zero (exit 4 when every point has a result but some are short of the target).
//!
//! Output: `point_NNN/` per converged point (summary.json, profiles, plots, as for a single
//! scene), `sweep.csv` (rewritten after every point, so a long sweep can be watched) and
//! PNG plots of the film and the friction against the swept parameters.
use super::adapt::Adapted;
use super::estimate::Estimate;
use super::lubricated::Setup;
use super::point::{post_point, PointResult};
use super::{collective, Context, Outcome};
use crate::case::Scene;
use crate::ehl::driver::EhlSolver;
use crate::error::Error;
use crate::output::plot::{line_plot, LineOpts, Series, Style};
use mpi::traits::Communicator;
use std::time::Instant;

/// One row of the sweep table.
#[derive(Debug)]
pub struct SweepRow {
    pub ue: f64,
    pub lambda_deg: f64,
    pub srr: f64,
    /// The point's numbers, or the reason it failed.
    pub result: Result<PointResult, Error>,
    pub newton_iterations: usize,
    pub wall_s: f64,
    /// A point refined to an accuracy target: whether it reached it, its estimate, levels
    /// and last level's unknowns.
    pub adaptive: Option<AdaptiveRow>,
}

impl SweepRow {
    fn of(p: &Scene, result: Result<PointResult, Error>, newton_iterations: usize, wall_s: f64, adaptive: Option<AdaptiveRow>) -> SweepRow {
        SweepRow {
            ue: p.operating.entrainment_speed.unwrap_or(f64::NAN),
            lambda_deg: p.operating.tilt_angle,
            srr: p.operating.slide_to_roll,
            result,
            newton_iterations,
            wall_s,
            adaptive,
        }
    }

    /// A point refined to a target that ended short of it (`short_of_target` in sweep.csv).
    fn short_of_target(&self) -> bool {
        self.adaptive.as_ref().is_some_and(|a| !a.reached)
    }
}

/// Adds a point's row and rewrites `sweep.csv` (rank 0), so a long sweep can be watched.
fn record(ctx: &Context, rows: &mut Vec<SweepRow>, row: SweepRow) -> Result<(), Error> {
    rows.push(row);
    if ctx.rank == 0 {
        write_table(ctx, rows)?;
    }
    Ok(())
}

/// What an adaptively refined sweep point reports in `sweep.csv`.
#[derive(Debug, Clone)]
pub struct AdaptiveRow {
    pub reached: bool,
    pub estimate: Option<Estimate>,
    pub levels: usize,
    pub unknowns: usize,
    /// pmax's relative change over the last level (not a target, not estimated).
    pub pmax_change: Option<f64>,
}

fn point_label(p: &Scene) -> String {
    format!(
        "Ue = {} m/s, lambda = {} deg, SRR = {}",
        p.operating.entrainment_speed.unwrap_or(f64::NAN),
        p.operating.tilt_angle,
        p.operating.slide_to_roll
    )
}

pub fn run<'a>(ctx: &'a Context, scene: &Scene, setup: &Setup, solver: &EhlSolver<'a>) -> Result<(), Error> {
    let points = scene.points();
    let n = points.len();
    ctx.log(format!("sweep: {n} operating points on one mesh"));
    let mut rows: Vec<SweepRow> = Vec::new();
    let mut prev: Option<Vec<f64>> = None;
    for (k, p) in points.iter().enumerate() {
        let t0 = Instant::now();
        ctx.log(format!("sweep point {} of {}: {}", k + 1, n, point_label(p)));
        let dir = ctx.out_dir.join(format!("point_{:03}", k + 1));
        ctx.create_dir(&dir)?;
        let mut its = 0;
        // Test hook (fault injection): -ehl_fail_point k makes point k fail as a
        // non-converged Newton would, to test that the sweep goes on and ends non-zero.
        let injected = crate::ehl_options::get().fail_point == Some(k + 1);
        let solved =
            if injected { Err(Error::not_converged("injected failure (-ehl_fail_point)")) } else { solver.solve(ctx, p, prev.as_deref()) };
        let result = match solved {
            Ok(sol) => {
                its = sol.newton_total;
                let r = collective::agree(
                    &ctx.world,
                    post_point(ctx, p, setup, &sol, solver.condensation_s.map(|c| if k == 0 { c } else { 0.0 }), None, &dir),
                );
                if r.is_ok() {
                    prev = Some(sol.x);
                }
                r
            }
            Err(e) => Err(e),
        };
        let wall_s = t0.elapsed().as_secs_f64();
        match &result {
            Ok(_) => ctx.log(format!("sweep point {} of {} converged ({} Newton iterations, {:.1} s)", k + 1, n, its, wall_s)),
            Err(e) => {
                ctx.log(format!("sweep point {} of {} FAILED ({:.1} s): {e}", k + 1, n, wall_s));
                if ctx.rank == 0 {
                    // Only converged points keep a folder: no partial output.
                    let _ = std::fs::remove_dir_all(&dir);
                }
                if crate::interrupt::agreed() != 0 {
                    // Interrupted: the completed points keep their folders and sweep.csv.
                    return result.map(|_| ());
                }
            }
        }
        record(ctx, &mut rows, SweepRow::of(p, result, its, wall_s, None))?;
    }
    finish(ctx, scene, &rows).map(|_| ())
}

/// A sweep with an accuracy target: each point through the adaptive loop
/// ([`super::adapt::run`]) from the scene's first mesh and the Hertz start, written into its
/// `point_NNN/` as a single-point run would be. The point's log lines count its own time;
/// its time budget (`accuracy.max_seconds`) is its own. Collective.
pub fn run_adaptive(ctx: &Context, scene: &Scene) -> Result<Outcome, Error> {
    let points = scene.points();
    let n = points.len();
    ctx.log(format!("sweep: {n} operating points, each refined adaptively to accuracy.target = {}", scene.accuracy.target));
    let mut rows: Vec<SweepRow> = Vec::new();
    for (k, p) in points.iter().enumerate() {
        crate::interrupt::check("the sweep")?;
        let t0 = Instant::now();
        ctx.log(format!("sweep point {} of {}: {}", k + 1, n, point_label(p)));
        // The point's folder appears with its results (through the staging folder).
        let dir = ctx.out_dir.join(format!("point_{:03}", k + 1));
        let point_ctx =
            Context { world: ctx.world.duplicate(), rank: ctx.rank, size: ctx.size, out_dir: dir.clone(), quiet: ctx.quiet, start: t0 };
        let injected = crate::ehl_options::get().fail_point == Some(k + 1);
        let adapted =
            if injected { Err(Error::not_converged("injected failure (-ehl_fail_point)")) } else { super::adapt::run(&point_ctx, p, None) };
        // A point whose levels outran its own budget without a level to fall back on
        // failed; the next point has a budget of its own.
        if crate::interrupt::agreed() == crate::interrupt::DEADLINE {
            crate::interrupt::clear_deadline();
        }
        let wall_s = t0.elapsed().as_secs_f64();
        let (result, its, adaptive) = match adapted {
            Ok(Adapted { outcome, point, estimate, levels, unknowns, newton_iterations, pmax_change }) => {
                let reached = matches!(outcome, Outcome::Done);
                let how = if reached { "reached the target" } else { "SHORT of the target" };
                ctx.log(format!("sweep point {} of {} {how} ({levels} levels, {unknowns} unknowns, {wall_s:.1} s)", k + 1, n));
                (Ok(point), newton_iterations, Some(AdaptiveRow { reached, estimate, levels, unknowns, pmax_change }))
            }
            Err(e) => {
                ctx.log(format!("sweep point {} of {} FAILED ({wall_s:.1} s): {e}", k + 1, n));
                if ctx.rank == 0 {
                    // Only points with a result keep a folder: no partial output.
                    let _ = std::fs::remove_dir_all(&dir);
                }
                if crate::interrupt::agreed() != 0 {
                    return Err(e);
                }
                (Err(e), 0, None)
            }
        };
        record(ctx, &mut rows, SweepRow::of(p, result, its, wall_s, adaptive))?;
    }
    finish(ctx, scene, &rows)
}

/// The end of a sweep: its plots and last log line; an error naming the failed points,
/// or the points short of their target (exit 4).
fn finish(ctx: &Context, scene: &Scene, rows: &[SweepRow]) -> Result<Outcome, Error> {
    let n = rows.len();
    if ctx.rank == 0 && scene.output.png {
        sweep_plots(ctx, scene, rows)?;
    }
    let label = |i: usize, r: &SweepRow| format!("point {} (Ue = {}, lambda = {}, SRR = {})", i + 1, r.ue, r.lambda_deg, r.srr);
    let failed: Vec<String> = rows.iter().enumerate().filter(|(_, r)| r.result.is_err()).map(|(i, r)| label(i, r)).collect();
    let short: Vec<String> = rows.iter().enumerate().filter(|(_, r)| r.short_of_target()).map(|(i, r)| label(i, r)).collect();
    let total: f64 = rows.iter().map(|r| r.wall_s).sum();
    ctx.log(format!(
        "sweep done: {} of {} points converged, {:.1} s of solves ({:.1} s per point); table {}",
        n - failed.len(),
        n,
        total,
        total / n as f64,
        ctx.out_dir.join("sweep.csv").display()
    ));
    if !failed.is_empty() {
        return Err(Error::not_converged(format!(
            "{} of {} sweep points failed: {} (reasons in sweep.csv)",
            failed.len(),
            n,
            failed.join(", ")
        )));
    }
    if !short.is_empty() {
        return Ok(Outcome::ShortOfTarget(format!(
            "{} of {} sweep points short of accuracy.target = {}: {} (their estimates in sweep.csv)",
            short.len(),
            n,
            scene.accuracy.target,
            short.join(", ")
        )));
    }
    Ok(Outcome::Done)
}

/// `sweep.csv`: one row per point, in sweep order.
fn write_table(ctx: &Context, rows: &[SweepRow]) -> Result<(), Error> {
    let mut t = String::from(
        "point,ue_m_s,tilt_angle_deg,slide_to_roll,status,hc_m,hm_m,pmax_pa,load_error_rel,fx,fz,newton_iterations,wall_s,levels,unknowns,est_hc,est_hm,est_fx,est_fz,pmax_change,reason\n",
    );
    let opt = |v: Option<f64>| v.map(|x| format!("{x:e}")).unwrap_or_default();
    for (i, r) in rows.iter().enumerate() {
        let head = format!("{},{},{},{}", i + 1, r.ue, r.lambda_deg, r.srr);
        // An adaptive point's levels, unknowns and estimated errors (empty on one mesh).
        let adaptive = match &r.adaptive {
            Some(a) => {
                let e = a.estimate;
                format!(
                    "{},{},{},{},{},{},{}",
                    a.levels,
                    a.unknowns,
                    opt(e.map(|e| e.hc)),
                    opt(e.map(|e| e.hm)),
                    opt(e.and_then(|e| e.friction).map(|f| f[0])),
                    opt(e.and_then(|e| e.friction).map(|f| f[1])),
                    opt(a.pmax_change)
                )
            }
            None => ",,,,,,".to_string(),
        };
        let status = if r.short_of_target() { "short_of_target" } else { "converged" };
        match &r.result {
            Ok(p) => t.push_str(&format!(
                "{head},{status},{:e},{:e},{:e},{:e},{},{},{},{:.2},{adaptive},\n",
                p.hc,
                p.hm,
                p.pmax,
                p.load_error,
                opt(p.fx),
                opt(p.fz),
                r.newton_iterations,
                r.wall_s
            )),
            Err(e) => t.push_str(&format!(
                "{head},failed,,,,,,,{},{:.2},{adaptive},\"{}\"\n",
                r.newton_iterations,
                r.wall_s,
                e.to_string().replace('"', "'")
            )),
        }
    }
    let path = ctx.out_dir.join("sweep.csv");
    crate::output::write_atomic(&path, t.as_bytes()).map_err(Error::writing(&path))
}

/// Which operating parameter a plot runs along.
#[derive(Clone, Copy, PartialEq)]
enum Axis {
    Speed,
    Tilt,
    Srr,
}

impl Axis {
    fn of(self, r: &SweepRow) -> f64 {
        match self {
            Axis::Speed => r.ue,
            Axis::Tilt => r.lambda_deg,
            Axis::Srr => r.srr,
        }
    }
    fn label(self) -> &'static str {
        match self {
            Axis::Speed => "Ue (m/s)",
            Axis::Tilt => "tilt angle lambda (deg)",
            Axis::Srr => "SRR (%)",
        }
    }
    fn scale(self) -> f64 {
        if self == Axis::Srr {
            100.0
        } else {
            1.0
        }
    }
    fn legend(self, r: &SweepRow) -> String {
        match self {
            Axis::Speed => format!("Ue {} m/s", r.ue),
            Axis::Tilt => format!("lambda {} deg", r.lambda_deg),
            Axis::Srr => format!("SRR {} %", r.srr * 100.0),
        }
    }
}

/// Series of `y` against `axis`, one per combination of the other swept parameters
/// (converged points only).
fn series_along(
    rows: &[SweepRow],
    axis: Axis,
    others: &[Axis],
    name: &str,
    y: &dyn Fn(&SweepRow, &PointResult) -> Option<f64>,
) -> Vec<Series> {
    let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for r in rows {
        let Ok(p) = &r.result else { continue };
        let Some(v) = y(r, p) else { continue };
        let key = others.iter().map(|o| o.legend(r)).collect::<Vec<_>>().join(", ");
        let key = if key.is_empty() { name.to_string() } else { format!("{name}, {key}") };
        let pt = (axis.of(r) * axis.scale(), v);
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(pt),
            None => groups.push((key, vec![pt])),
        }
    }
    groups
        .into_iter()
        .map(|(k, mut pts)| {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series::new(&k, pts.iter().map(|p| p.0).collect(), pts.iter().map(|p| p.1).collect(), Style::LinePoints)
        })
        .collect()
}

/// The sweep's PNG plots: film against each swept parameter with more than one value,
/// h_lambda/h_90 when lambda = 90 deg is in the sweep, and fx, fz against SRR.
fn sweep_plots(ctx: &Context, scene: &Scene, rows: &[SweepRow]) -> Result<(), Error> {
    let sw = scene.sweep.clone().unwrap_or_default();
    let varied: Vec<Axis> =
        [(Axis::Speed, sw.entrainment_speed.as_ref()), (Axis::Tilt, sw.tilt_angle.as_ref()), (Axis::Srr, sw.slide_to_roll.as_ref())]
            .into_iter()
            .filter(|(_, l)| l.map_or(0, |v| v.len()) > 1)
            .map(|(a, _)| a)
            .collect();
    let write = |name: &str, title: &str, xlabel: &str, ylabel: &str, series: Vec<Series>, log_x: bool| -> Result<(), Error> {
        if series.is_empty() {
            return Ok(());
        }
        let lo = LineOpts { log_x, legend: crate::output::plot::Legend::LowerRight, ..LineOpts::default() };
        crate::output::write_atomic_with(&ctx.out_dir.join(name), |t| line_plot(t, title, xlabel, ylabel, &series, &lo))
    };
    for &axis in &varied {
        let others: Vec<Axis> = varied.iter().copied().filter(|&o| o != axis).collect();
        let log_x = axis == Axis::Tilt;
        let tag = match axis {
            Axis::Speed => "speed",
            Axis::Tilt => "tilt",
            Axis::Srr => "srr",
        };
        let mut film = series_along(rows, axis, &others, "hc", &|_, p| Some(p.hc * 1e6));
        film.extend(series_along(rows, axis, &others, "hm", &|_, p| Some(p.hm * 1e6)));
        write(
            &format!("sweep_film_vs_{tag}.png"),
            &format!("film thickness against {}", axis.label()),
            axis.label(),
            "h (um)",
            film,
            log_x,
        )?;
        let fx = series_along(rows, axis, &others, "fx", &|_, p| p.fx);
        write(
            &format!("sweep_fx_vs_{tag}.png"),
            &format!("friction coefficient fx against {}", axis.label()),
            axis.label(),
            "fx",
            fx,
            log_x,
        )?;
        let fz = series_along(rows, axis, &others, "fz", &|_, p| p.fz);
        write(
            &format!("sweep_fz_vs_{tag}.png"),
            &format!("transverse friction coefficient fz against {}", axis.label()),
            axis.label(),
            "fz",
            fz,
            log_x,
        )?;
        if axis == Axis::Tilt {
            // h_lambda / h_90 of the same (Ue, SRR).
            let base = |r: &SweepRow, f: &dyn Fn(&PointResult) -> f64| -> Option<f64> {
                rows.iter().find(|q| q.lambda_deg == 90.0 && q.ue == r.ue && q.srr == r.srr).and_then(|q| q.result.as_ref().ok()).map(f)
            };
            let mut ratio = series_along(rows, axis, &others, "hc/hc90", &|r, p| base(r, &|q| q.hc).map(|b| p.hc / b));
            ratio.extend(series_along(rows, axis, &others, "hm/hm90", &|r, p| base(r, &|q| q.hm).map(|b| p.hm / b)));
            write(
                "sweep_film_ratio_vs_tilt.png",
                "film thickness relative to lambda = 90 deg",
                axis.label(),
                "h_lambda / h_90",
                ratio,
                true,
            )?;
            profiles_by_tilt(ctx, rows)?;
        }
    }
    Ok(())
}

/// Film profiles along x = 0 (paper Fig. 6): one plot per (Ue, SRR) with one curve per
/// tilt angle, `sweep_profile_x0_ue<Ue>_srr<SRR>.png`.
fn profiles_by_tilt(ctx: &Context, rows: &[SweepRow]) -> Result<(), Error> {
    let mut groups: Vec<(f64, f64)> = Vec::new();
    for r in rows {
        if !groups.contains(&(r.ue, r.srr)) {
            groups.push((r.ue, r.srr));
        }
    }
    for (ue, srr) in groups {
        let mut series = Vec::new();
        let mut hmax: f64 = 0.0;
        for r in rows.iter().filter(|r| r.ue == ue && r.srr == srr) {
            let Ok(p) = &r.result else { continue };
            let pts: Vec<&[f64; 2]> = p.profile_x0.iter().filter(|q| q[0].abs() <= 1.5).collect();
            hmax = hmax.max(2.0 * p.hc * 1e6);
            series.push(Series::new(
                &format!("lambda {} deg", r.lambda_deg),
                pts.iter().map(|q| q[0]).collect(),
                pts.iter().map(|q| q[1] * 1e6).collect(),
                Style::Line,
            ));
        }
        if series.is_empty() {
            continue;
        }
        let lo = LineOpts { y_range: Some((0.0, hmax)), legend: crate::output::plot::Legend::UpperRight, ..LineOpts::default() };
        let name = format!("sweep_profile_x0_ue{ue}_srr{srr}.png");
        let title = format!("film on x = 0, Ue = {ue} m/s, SRR = {srr}");
        crate::output::write_atomic_with(&ctx.out_dir.join(name), |t| line_plot(t, &title, "z / a", "h (um)", &series, &lo))?;
    }
    Ok(())
}
