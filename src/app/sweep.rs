//! Sweeps: one scene, several operating points (`[sweep]` lists of Ue, lambda, SRR). The
//! mesh and the condensed elastic block are built once; each point starts from the
//! previous converged state (and from the Hertz start when that fails). A point that fails
//! is recorded with its reason and the sweep goes on; the run then ends non-zero.
//!
//! Output: `point_NNN/` per converged point (summary.json, profiles, plots, as for a single
//! scene), `sweep.csv` (rewritten after every point, so a long sweep can be watched) and
//! PNG plots of the film and the friction against the swept parameters.
use super::lubricated::{post_point, PointResult, Setup};
use super::{collective, Context};
use crate::case::Scene;
use crate::ehl::driver::EhlSolver;
use crate::error::Error;
use crate::output::plot::{line_plot, LineOpts, Series, Style};
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
                    post_point(ctx, p, setup, &sol, solver.condensation_s.map(|c| if k == 0 { c } else { 0.0 }), &dir),
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
        rows.push(SweepRow {
            ue: p.operating.entrainment_speed.unwrap_or(f64::NAN),
            lambda_deg: p.operating.tilt_angle,
            srr: p.operating.slide_to_roll,
            result,
            newton_iterations: its,
            wall_s,
        });
        if ctx.rank == 0 {
            write_table(ctx, &rows)?;
        }
    }
    if ctx.rank == 0 && scene.output.png {
        sweep_plots(ctx, scene, &rows)?;
    }
    let failed: Vec<String> = rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.result.is_err())
        .map(|(i, r)| format!("point {} ({})", i + 1, format_args!("Ue = {}, lambda = {}, SRR = {}", r.ue, r.lambda_deg, r.srr)))
        .collect();
    let total: f64 = rows.iter().map(|r| r.wall_s).sum();
    ctx.log(format!(
        "sweep done: {} of {} points converged, {:.1} s of solves ({:.1} s per point); table {}",
        n - failed.len(),
        n,
        total,
        total / n as f64,
        ctx.out_dir.join("sweep.csv").display()
    ));
    if failed.is_empty() {
        Ok(())
    } else {
        Err(Error::not_converged(format!("{} of {} sweep points failed: {} (reasons in sweep.csv)", failed.len(), n, failed.join(", "))))
    }
}

/// `sweep.csv`: one row per point, in sweep order.
fn write_table(ctx: &Context, rows: &[SweepRow]) -> Result<(), Error> {
    let mut t = String::from(
        "point,ue_m_s,tilt_angle_deg,slide_to_roll,status,hc_m,hm_m,pmax_pa,load_error_rel,fx,fz,newton_iterations,wall_s,reason\n",
    );
    let opt = |v: Option<f64>| v.map(|x| format!("{x:e}")).unwrap_or_default();
    for (i, r) in rows.iter().enumerate() {
        let head = format!("{},{},{},{}", i + 1, r.ue, r.lambda_deg, r.srr);
        match &r.result {
            Ok(p) => t.push_str(&format!(
                "{head},converged,{:e},{:e},{:e},{:e},{},{},{},{:.2},\n",
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
                "{head},failed,,,,,,,{},{:.2},\"{}\"\n",
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
