//! Convergence study (`--convergence-study N`): one scene solved on a ladder of N meshes,
//! each halving the element size over the contact zone, with the unknowns, Newton
//! iterations, time per phase and peak memory of each level, the converged values
//! estimated by Richardson extrapolation with the observed order, and the error each level
//! makes against them. Writes `level_K/` (the usual outputs), `study.csv`, `study.md` and
//! `study_error_vs_unknowns.png`, `study_error_vs_time.png`.
//!
//! Two ladders ([`Ladder`]):
//! - `core`: contact-zone sizes h (units of a) 0.5, 0.25 (plain meshes, `mesh.contact_size`),
//!   then 0.125, 0.0625, ... as a core over |X|, |Z| <= 1.25 on the 0.25a mesh (the paper
//!   scenes' construction). The scene's own `[mesh]` sizes are replaced.
//! - `ring`: the scene's own mesh with the ring `mesh.ring_inner <= r <= mesh.ring_outer`
//!   (around the Hertz circle, where the inlet build-up, the side lobes and the outlet
//!   spike sit) refined to h = 0.125, 0.0625, 0.03125, ...
use super::lubricated::Setup;
use super::point::{post_point, PointResult};
use super::{collective, Context};
use crate::case::Scene;
use crate::ehl::driver::EhlSolver;
use crate::error::Error;
use crate::output::plot::{line_plot, LineOpts, Series, Style};
use std::time::Instant;

/// Which part of the mesh a convergence study refines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ladder {
    /// The whole contact zone, then a core square over |X|, |Z| <= 1.25.
    Core,
    /// Only the ring around the Hertz circle, on the scene's own mesh.
    Ring,
}

impl std::str::FromStr for Ladder {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        match s {
            "core" => Ok(Ladder::Core),
            "ring" => Ok(Ladder::Ring),
            _ => Err(Error::invalid(format!("--ladder {s:?} is not allowed: use \"core\" or \"ring\""))),
        }
    }
}

impl Ladder {
    /// The first level's size when `--first-size` is not given (units of a).
    pub fn default_first(self) -> f64 {
        match self {
            Ladder::Core => 0.5,
            Ladder::Ring => 0.125,
        }
    }

    /// What the ladder's size refers to, for messages.
    fn sized(self) -> &'static str {
        match self {
            Ladder::Core => "contact-zone",
            Ladder::Ring => "ring",
        }
    }
}

/// Refined size of level k (units of a): the first level's size halved k times (core
/// ladder: 0.5, 0.25, ... by default; ring ladder: 0.125, 0.0625, ...).
pub fn level_size(first: f64, k: usize) -> f64 {
    first / (1u64 << k) as f64
}

/// Checks a ladder of `levels` levels from size `first`: at least 2 levels, a first size
/// the mesher can make exactly (16/2^k), and a finest level no finer than the mesher's
/// smallest size.
pub fn check_ladder(ladder: Ladder, first: f64, levels: usize) -> Result<(), Error> {
    // The core ladder refines the whole core square; the ring ladder only a band, which
    // the monolithic coupling solves one level finer (table2-ue2's narrow ring at
    // 0.0078 a).
    let min = match ladder {
        Ladder::Core => crate::case::MIN_CONTACT_SIZE,
        Ladder::Ring => crate::case::MIN_CONTACT_SIZE / 2.0,
    };
    if !(first.is_finite() && first > 0.0 && crate::mesh::spec::dyadic_size(first) == first && first <= 16.0) {
        return Err(Error::invalid(format!(
            "--first-size {first}: the first level's {} size must be 16/2^k a (0.5, 0.25, 0.125, ...), at most 16",
            ladder.sized()
        )));
    }
    let finest = level_size(first, levels.max(1) - 1);
    if levels < 2 || finest < min * (1.0 - 1e-12) {
        let max = (first / min).log2().round() as usize + 1;
        return Err(Error::invalid(format!(
            "--convergence-study {levels}: the number of levels must be in [2, {max}] for the {ladder:?} ladder from {first} a (the finest {} size allowed is {min} a)",
            ladder.sized()
        )));
    }
    Ok(())
}

/// The scene with the mesh of level size `h`.
pub fn level_scene(scene: &Scene, ladder: Ladder, h: f64) -> Scene {
    let mut s = scene.clone();
    // A study's levels are its meshes: no adaptive refinement inside a level.
    s.accuracy.target = 0.0;
    if ladder == Ladder::Ring {
        s.mesh.ring_size = h;
        return s;
    }
    s.mesh.ring_size = 0.0;
    if h >= 0.25 {
        s.mesh.contact_size = h;
        s.mesh.core_size = 0.0;
    } else {
        s.mesh.contact_size = 0.25;
        s.mesh.core_size = h;
        s.mesh.core_half_width = 1.25;
    }
    s
}

/// Richardson extrapolation of a sequence on meshes halving h: from the last three values,
/// the observed order p = log2(d1/d2) and q_inf = q3 + d2/(2^p - 1). None when the last two
/// differences do not shrink monotonically (no asymptotic range yet).
pub fn richardson(q: &[f64]) -> Option<(f64, f64)> {
    if q.len() < 3 {
        return None;
    }
    let n = q.len();
    let (d1, d2) = (q[n - 2] - q[n - 3], q[n - 1] - q[n - 2]);
    if d2 == 0.0 {
        return Some((q[n - 1], f64::INFINITY));
    }
    if d1 * d2 <= 0.0 || d2.abs() >= d1.abs() {
        return None;
    }
    let p = (d1 / d2).log2();
    Some((q[n - 1] + d2 / (2f64.powf(p) - 1.0), p))
}

/// How the last three values of a sequence on meshes halving h behave, after Stern,
/// Wilson, Coleman and Paterson (J. Fluids Eng. 123, 2001, "Comprehensive approach to
/// verification and validation of CFD simulations, part 1"), with the convergence ratio
/// R = (q3 - q2)/(q2 - q1) (q3 the finest):
/// 0 <= R < 1 monotone convergence (Richardson applies), -1 < R < 0 oscillatory convergence
/// (uncertainty half the range of the three values), |R| >= 1 divergence (no estimate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Convergence {
    Monotone { ratio: f64 },
    Oscillatory { ratio: f64, half_range: f64 },
    Diverging { ratio: f64 },
}

/// [`Convergence`] of the last three values of `q` (None for fewer than three values or two
/// equal coarser values).
pub fn convergence(q: &[f64]) -> Option<Convergence> {
    let n = q.len();
    if n < 3 || q[n - 2] == q[n - 3] {
        return None;
    }
    let ratio = (q[n - 1] - q[n - 2]) / (q[n - 2] - q[n - 3]);
    let last = &q[n - 3..];
    let (lo, hi) = last.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    Some(if ratio.abs() >= 1.0 {
        Convergence::Diverging { ratio }
    } else if ratio < 0.0 {
        Convergence::Oscillatory { ratio, half_range: 0.5 * (hi - lo) }
    } else {
        Convergence::Monotone { ratio }
    })
}

struct Level {
    /// Why the level failed (None: converged).
    failed: Option<Error>,
    h: f64,
    n_u: usize,
    n_p: usize,
    its: usize,
    mesh_s: f64,
    /// The elastic condensation (condensed coupling), or the stiffness assembly and the
    /// dry start (monolithic coupling).
    setup_s: f64,
    coupling: &'static str,
    newton_s: f64,
    total_s: f64,
    rss_mb: f64,
    r: PointResult,
}

/// Solves `scene` on `levels` levels of `ladder` from size `first`; the caller has checked
/// the ladder with [`check_ladder`] (app::run does, before any output is written).
/// With `sequence`, each level after the first starts from the last converged level's
/// pressure (mesh sequencing, see [`super::restart`]).
pub fn run(ctx: &Context, scene: &Scene, levels: usize, ladder: Ladder, first: f64, sequence: bool) -> Result<(), Error> {
    if scene.is_sweep() {
        return Err(Error::invalid("--convergence-study solves one operating point: remove [sweep] from the scene"));
    }
    let mut rows: Vec<Level> = Vec::new();
    let mut last_converged: Option<std::path::PathBuf> = None;
    for k in 0..levels {
        let h = level_size(first, k);
        let sc = level_scene(scene, ladder, h);
        ctx.log(format!("convergence study: level {} of {levels}, {} size {h} a", k + 1, ladder.sized()));
        let t0 = Instant::now();
        let dir = ctx.out_dir.join(format!("level_{}", k + 1));
        ctx.create_dir(&dir)?;
        let setup = Setup::new(ctx, &sc)?;
        let earlier = match (&last_converged, sequence) {
            (Some(d), true) => Some(super::restart::EarlierRun::read(d)?),
            _ => None,
        };
        let solver = EhlSolver::new(ctx, &sc, &setup.mesh, &setup.part, &setup.dofs, &setup.layout, setup.half, earlier.is_some())?;
        let (n_u, n_p) = setup.layout.counts();
        let solved = match &earlier {
            Some(e) => e.solve(ctx, &sc, &solver),
            None => solver.solve(ctx, &sc, None),
        }
        .and_then(|sol| {
            collective::agree(&ctx.world, post_point(ctx, &sc, &setup, &sol, solver.condensation_s, None, &dir)).map(|r| (sol, r))
        });
        let rss_mb = collective::max_f64(&ctx.world, crate::output::peak_rss_mb());
        let level = match solved {
            Ok((sol, r)) => Level {
                failed: None,
                h,
                n_u,
                n_p,
                its: sol.newton_total,
                mesh_s: setup.mesh_s,
                setup_s: solver.condensation_s.unwrap_or(sol.assembly_s),
                coupling: solver.coupling().name(),
                newton_s: sol.solve_s,
                total_s: t0.elapsed().as_secs_f64(),
                rss_mb,
                r,
            },
            Err(e) => {
                // A level too coarse for the load fails honestly: recorded, skipped, the
                // ladder goes on.
                ctx.log(format!("convergence study: level {} FAILED: {e}", k + 1));
                if ctx.rank == 0 {
                    let _ = std::fs::remove_dir_all(&dir);
                }
                if crate::interrupt::agreed() != 0 {
                    return Err(e);
                }
                Level {
                    failed: Some(e),
                    h,
                    n_u,
                    n_p,
                    its: 0,
                    mesh_s: setup.mesh_s,
                    setup_s: solver.condensation_s.unwrap_or(0.0),
                    coupling: solver.coupling().name(),
                    newton_s: 0.0,
                    total_s: t0.elapsed().as_secs_f64(),
                    rss_mb,
                    r: PointResult::default(),
                }
            }
        };
        if level.failed.is_none() {
            last_converged = Some(dir.clone());
        }
        rows.push(level);
    }
    let ok = rows.iter().filter(|r| r.failed.is_none()).count();
    if ok < 2 {
        return Err(Error::not_converged(format!("convergence study: only {ok} of {levels} levels converged; nothing to compare")));
    }
    if ctx.rank == 0 {
        write_outputs(ctx, scene, &rows, sequence)?;
    }
    Ok(())
}

fn write_outputs(ctx: &Context, scene: &Scene, all: &[Level], sequence: bool) -> Result<(), Error> {
    // Failed levels are listed, then left out of the estimates (the ladder still halves h
    // between the converged levels, which follow each other).
    let failed: Vec<String> =
        all.iter().enumerate().filter_map(|(k, r)| r.failed.as_ref().map(|e| format!("level {} (h = {} a): {e}", k + 1, r.h))).collect();
    let rows: Vec<&Level> = all.iter().filter(|r| r.failed.is_none()).collect();
    let level_no = |r: &Level| all.iter().position(|q| std::ptr::eq(q, r)).unwrap() + 1;
    let friction = rows.iter().all(|r| r.r.fx.is_some());
    let mut quantities: Vec<(&str, Vec<f64>)> = vec![
        ("hc", rows.iter().map(|r| r.r.hc).collect()),
        ("hm", rows.iter().map(|r| r.r.hm).collect()),
        ("pmax", rows.iter().map(|r| r.r.pmax).collect()),
    ];
    if friction {
        quantities.push(("fx", rows.iter().map(|r| r.r.fx.unwrap()).collect()));
        quantities.push(("fz", rows.iter().map(|r| r.r.fz.unwrap()).collect()));
    }
    // Reference: the Richardson estimate, or the finest level when there is none.
    let refs: Vec<(f64, Option<f64>)> =
        quantities.iter().map(|(_, q)| richardson(q).map(|(v, p)| (v, Some(p))).unwrap_or((*q.last().unwrap(), None))).collect();
    let err = |qi: usize, k: usize| (quantities[qi].1[k] - refs[qi].0).abs() / refs[qi].0.abs();
    // CSV
    let mut csv =
        String::from("level,h_a,dofs_elastic,dofs_reynolds,coupling,newton_iterations,mesh_s,setup_s,newton_s,total_s,peak_rss_mb");
    for (name, _) in &quantities {
        csv.push_str(&format!(",{name},{name}_rel_error"));
    }
    csv.push('\n');
    for (k, r) in rows.iter().enumerate() {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:.3},{:.3},{:.3},{:.3},{:.0}",
            level_no(r),
            r.h,
            r.n_u,
            r.n_p,
            r.coupling,
            r.its,
            r.mesh_s,
            r.setup_s,
            r.newton_s,
            r.total_s,
            r.rss_mb
        ));
        for (qi, (_, q)) in quantities.iter().enumerate() {
            csv.push_str(&format!(",{:e},{:e}", q[k], err(qi, k)));
        }
        csv.push('\n');
    }
    let path = ctx.out_dir.join("study.csv");
    crate::output::write_atomic(&path, csv.as_bytes()).map_err(Error::writing(&path))?;
    // Markdown
    let mut md = format!("# Convergence study: {} ({} ranks)\n\n| level | h (a) | elastic unknowns | pressure unknowns | coupling | Newton its | mesh + setup + Newton = total (s) | peak RSS/rank (MB) |", scene.name, ctx.size);
    for (name, _) in &quantities {
        md.push_str(&format!(" {name} | error |"));
    }
    md.push_str(&format!("\n|{}\n", "---|".repeat(8 + 2 * quantities.len())));
    for (k, r) in rows.iter().enumerate() {
        md.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {:.1} + {:.1} + {:.1} = {:.1} | {:.0} |",
            level_no(r),
            r.h,
            r.n_u,
            r.n_p,
            r.coupling,
            r.its,
            r.mesh_s,
            r.setup_s,
            r.newton_s,
            r.total_s,
            r.rss_mb
        ));
        for (qi, (_, q)) in quantities.iter().enumerate() {
            md.push_str(&format!(" {:.5e} | {:.2} % |", q[k], 100.0 * err(qi, k)));
        }
        md.push('\n');
    }
    for f in &failed {
        md.push_str(&format!("\nFailed: {f}\n"));
    }
    if sequence {
        md.push_str("\nLevels after the first started from the last converged level's pressure (--sequence): their Newton iterations and times are those of a refinement step, not of a solve from the Hertz start.\n");
    }
    md.push_str("\nReference values:\n\n");
    for (qi, (name, _)) in quantities.iter().enumerate() {
        match refs[qi].1 {
            Some(p) => md.push_str(&format!("- {name}: {:.5e} (Richardson, observed order {p:.2})\n", refs[qi].0)),
            None if rows.len() < 3 => md.push_str(&format!(
                "- {name}: {:.5e} = the finest level (fewer than three converged levels: no extrapolation)\n",
                refs[qi].0
            )),
            None => {
                let q = &quantities[qi].1;
                let why = match convergence(q) {
                    Some(Convergence::Oscillatory { ratio, half_range }) => format!(
                        "oscillatory convergence, R = {ratio:.2}: no extrapolation; uncertainty +-{:.2} % (half the range of the last three levels, Stern et al. 2001)",
                        100.0 * half_range / refs[qi].0.abs()
                    ),
                    Some(Convergence::Diverging { ratio }) => format!("the last differences grow, R = {ratio:.2}: not in the asymptotic range, no extrapolation"),
                    _ => "the last differences do not shrink: not in the asymptotic range, no extrapolation".into(),
                };
                md.push_str(&format!("- {name}: {:.5e} = the finest level ({why})\n", refs[qi].0))
            }
        }
    }
    // Against the finest level itself the error is zero by construction: with no
    // extrapolation only the coarser levels can be judged.
    let extrapolated = refs[0].1.is_some() && refs[1].1.is_some();
    let judged = if extrapolated { rows.len() } else { rows.len() - 1 };
    // The time a level costs: its own, or with --sequence the ladder's up to it (a
    // sequenced level needs the levels before it).
    let reach: Vec<f64> = rows
        .iter()
        .scan(0.0, |sum, r| {
            *sum = if sequence { *sum + r.total_s } else { r.total_s };
            Some(*sum)
        })
        .collect();
    let within = |tol: f64| {
        rows.iter()
            .take(judged)
            .enumerate()
            .find(|(k, _)| err(0, *k) < tol && err(1, *k) < tol)
            .map(|(k, r)| {
                format!("level {} ({:.1} s{})", level_no(r), reach[k], if sequence { " including the levels before it" } else { "" })
            })
            .unwrap_or_else(|| "no level".into())
    };
    md.push_str(&format!(
        "\nhc and hm within 1 % of the reference: {}; within 0.5 %: {}{}.\n",
        within(0.01),
        within(0.005),
        if extrapolated { "" } else { " (the reference is the finest level, which is not judged)" }
    ));
    let path = ctx.out_dir.join("study.md");
    crate::output::write_atomic(&path, md.as_bytes()).map_err(Error::writing(&path))?;
    ctx.log(format!("convergence study written: {} and study.csv\n{md}", path.display()));
    // Plots: relative error against unknowns and against wall time (levels with a nonzero
    // error: the finest is the reference when there is no extrapolation).
    for (name, xlabel, xs) in [
        ("study_error_vs_unknowns.png", "unknowns (elastic + pressure)", rows.iter().map(|r| (r.n_u + r.n_p) as f64).collect::<Vec<_>>()),
        ("study_error_vs_time.png", if sequence { "wall time to reach the level (s)" } else { "wall time per level (s)" }, reach.clone()),
    ] {
        let series: Vec<Series> = quantities
            .iter()
            .enumerate()
            .map(|(qi, (qn, _))| {
                let pts: Vec<(f64, f64)> = (0..rows.len()).map(|k| (xs[k], err(qi, k))).filter(|p| p.1 > 0.0).collect();
                Series::new(qn, pts.iter().map(|p| p.0).collect(), pts.iter().map(|p| p.1 * 100.0).collect(), Style::LinePoints)
            })
            .filter(|s| !s.x.is_empty())
            .collect();
        if series.is_empty() {
            continue;
        }
        let lo = LineOpts { log_x: true, log_y: true, ..LineOpts::default() };
        crate::output::write_atomic_with(&ctx.out_dir.join(name), |t| {
            line_plot(t, &format!("{}: error against the reference", scene.name), xlabel, "relative error (%)", &series, &lo)
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn richardson_recovers_a_second_order_sequence() {
        // q(h) = 1 + 3 h^2 at h = 0.5, 0.25, 0.125.
        let q: Vec<f64> = [0.5f64, 0.25, 0.125].iter().map(|h| 1.0 + 3.0 * h * h).collect();
        let (v, p) = richardson(&q).unwrap();
        assert!((v - 1.0).abs() < 1e-12 && (p - 2.0).abs() < 1e-12, "{v} {p}");
        // Oscillating or growing differences: no estimate.
        assert!(richardson(&[1.0, 1.1, 1.05]).is_none());
        assert!(richardson(&[1.0, 1.1, 1.3]).is_none());
    }

    #[test]
    fn convergence_is_classified_by_the_ratio_of_the_last_differences() {
        // Stern et al. (2001): R = (S1 - S2)/(S2 - S3), 1 the finest.
        let c = |q: &[f64]| convergence(q).unwrap();
        // q = 1 + 3 h^2: R = 1/4, monotone.
        assert!(matches!(c(&[1.75, 1.1875, 1.046875]), Convergence::Monotone { ratio } if (ratio - 0.25).abs() < 1e-12));
        // 1.0, 1.1, 1.05: R = -0.5, oscillatory; half range (1.1 - 1.0)/2.
        match c(&[1.0, 1.1, 1.05]) {
            Convergence::Oscillatory { ratio, half_range } => assert!((ratio + 0.5).abs() < 1e-12 && (half_range - 0.05).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        // Growing differences, either sign: diverging.
        assert!(matches!(c(&[1.0, 1.1, 1.3]), Convergence::Diverging { .. }));
        assert!(matches!(c(&[1.0, 1.1, 0.9]), Convergence::Diverging { .. }));
        // table2-ue2's hm on the narrow ring ladder (um): -0.12 %, then +0.96 %.
        assert!(matches!(c(&[0.13652, 0.13636, 0.13767]), Convergence::Diverging { ratio } if ratio < -1.0));
        assert!(convergence(&[1.0, 1.0, 2.0]).is_none() && convergence(&[1.0, 2.0]).is_none());
    }

    #[test]
    fn ladder_halves_the_contact_zone_size() {
        assert_eq!([0, 1, 2, 3].map(|k| level_size(Ladder::Core.default_first(), k)), [0.5, 0.25, 0.125, 0.0625]);
        assert_eq!([0, 1, 2].map(|k| level_size(Ladder::Ring.default_first(), k)), [0.125, 0.0625, 0.03125]);
        // The ladders' limits: 6 core levels from 0.5 a, 4 ring levels from 0.125 a, 3 from
        // 0.0625 a (the mesher's finest size is 1/64 a); a first size must be 16/2^k.
        assert!(check_ladder(Ladder::Core, 0.5, 6).is_ok());
        assert!(check_ladder(Ladder::Core, 0.5, 7).unwrap_err().to_string().contains("[2, 6]"));
        assert!(check_ladder(Ladder::Ring, 0.125, 4).is_ok());
        assert!(check_ladder(Ladder::Ring, 0.0625, 4).is_ok());
        assert!(check_ladder(Ladder::Ring, 0.0625, 5).unwrap_err().to_string().contains("[2, 4]"));
        assert!(check_ladder(Ladder::Ring, 0.0625, 1).is_err());
        assert!(check_ladder(Ladder::Ring, 0.1, 3).unwrap_err().to_string().contains("--first-size 0.1"));
        assert!(check_ladder(Ladder::Ring, -1.0, 3).is_err());
        assert_eq!("ring".parse::<Ladder>().unwrap(), Ladder::Ring);
        // The ring ladder keeps the scene's mesh and sets the ring; the core ladder drops it.
        let mut scene = crate::case::parse_scene(include_str!("../../cases/paper/table2-ue2.toml"), "x").unwrap();
        scene.mesh.ring_size = 0.03125;
        let r = level_scene(&scene, Ladder::Ring, 0.0625);
        assert_eq!((r.mesh.ring_size, r.mesh.core_size, r.mesh.contact_size), (0.0625, scene.mesh.core_size, scene.mesh.contact_size));
        let c = level_scene(&scene, Ladder::Core, 0.0625);
        assert_eq!((c.mesh.ring_size, c.mesh.core_size, c.mesh.contact_size), (0.0, 0.0625, 0.25));
        assert!("rings".parse::<Ladder>().unwrap_err().to_string().contains("\"core\" or \"ring\""));
    }
}
