//! The tilt continuation on both couplings: a spin scene solved through the tilt
//! continuation (plain Newton skipped, `-ehl_skip_plain`) with the condensed and with the
//! monolithic coupling. Both are the same discrete problem on the same path, so they must
//! take the path and reach the same film. Before 2026-11-25 the monolithic system could not
//! change its velocity field, skipped the tilt continuation, and a spin scene above 4,000
//! pressure unknowns lost it.
//!
//! And a continuation after a failed tilt continuation solves the scene's own spin: a heavy
//! Moes point (M = 100, L = 20) with spin at lambda = 20 deg on a 0.25 a face fails plain
//! Newton and every tilt from the Hertz start, and reaches the scene through the
//! pressure-viscosity continuation. Before 2026-12-01 a tilt search that found nothing left
//! the last tried tilt's velocity field (lambda = 90 deg) in the system, and that run wrote
//! the pure-rolling film as the lambda = 20 deg result.
mod common;
use common::*;

fn solve(coupling: &str) -> (String, serde_json::Value) {
    let dir = scratch(&format!("tilt-{coupling}"));
    let scene = repo().join("cases/paper/case2.toml");
    let out_dir = dir.join("out");
    let set = format!("reynolds.coupling={coupling}");
    let args = [
        scene.to_str().unwrap(),
        "--set",
        "operating.load=300",
        "--set",
        "mesh.core_size=0",
        "--set",
        "mesh.ring_size=0",
        "--set",
        "mesh.growth=0.5",
        "--set",
        "mesh.contact_size=0.5",
        "--set",
        "operating.tilt_angle=1.0",
        "--set",
        "effects.friction=none",
        "--set",
        &set,
        "--output",
        out_dir.to_str().unwrap(),
        "-ehl_skip_plain",
    ];
    let out = mpirun(2, &args);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    (t, summary(&out_dir))
}

#[test]
fn the_tilt_continuation_runs_on_both_couplings_to_the_same_film() {
    let (tc, c) = solve("condensed");
    let (tm, m) = solve("monolithic");
    assert!(tm.contains("coupling: monolithic"), "{tm}");
    for t in [&tc, &tm] {
        // lambda = 2 deg from the Hertz start, then the scene's 1 deg.
        assert!(t.contains("tilt continuation: the Hertz start at lambda = 2.0000 deg: CONVERGED"), "{t}");
        assert!(t.contains("tilt continuation: lambda = 1.0000 deg: CONVERGED"), "{t}");
    }
    for key in ["film.hc_m", "film.hm_m", "pressure.pmax_pa", "film.h0_m"] {
        let (x, y) = (num(&c, key), num(&m, key));
        // Newton stops at a residual of 1e-10: two eliminations of one discrete problem
        // agree far below 1e-6.
        assert!((x - y).abs() <= 1e-6 * x.abs(), "{key}: condensed {x}, monolithic {y}");
    }
}

/// The heavy spin point of the module's second check (lambda = 20 deg), written into `dir` as
/// `name`.toml with `extra` appended.
fn heavy_spin(dir: &std::path::Path, name: &str, extra: &str) -> String {
    // Moes M = 100, L = 20 (steel, R = 0.08 m, eta = 0.012 Pa.s, Ue = 2 m/s), as ci/moes-map writes it.
    let scene = format!(
        r#"name = "{name}"
[effects]
viscosity = "barus"
density = "incompressible"
kinematics = "spin"
friction = "none"
[geometry]
ball_radius = 0.08
disc_track_radius = 0.04
[materials.ball]
young_modulus = 210e9
poisson_ratio = 0.3
[materials.disc]
young_modulus = 210e9
poisson_ratio = 0.3
[lubricant]
viscosity = 0.012
pressure_viscosity = 6.82511e-08
[operating]
load = 302.404
entrainment_speed = 2.0
slide_to_roll = 0.0
tilt_angle = 20.0
[mesh]
contact_size = 0.25
growth = 1.0
{extra}"#
    );
    write_scene(dir, &format!("{name}.toml"), &scene)
}

#[test]
fn a_continuation_after_a_failed_tilt_search_solves_the_scene_s_spin() {
    let dir = scratch("tilt-search-fails");
    // Path 1: plain Newton and every tilt fail from the Hertz start; alpha/2 -> alpha.
    let single = heavy_spin(&dir, "single", "");
    let out_single = dir.join("single-out");
    let out = mpirun(2, &[&single, "--output", out_single.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    assert!(t.contains("tilt continuation: no milder problem converged"), "{t}");
    assert!(t.contains("pressure-viscosity continuation: alpha = 68.2511 GPa^-1: CONVERGED"), "{t}");
    // Path 2: a sweep to the same point from the pure-rolling solution on the same mesh,
    // by plain Newton from the previous point's state.
    let sweep = heavy_spin(&dir, "sweep", "[sweep]\ntilt_angle = [90.0, 20.0]\n");
    let out_sweep = dir.join("sweep-out");
    let out = mpirun(2, &[&sweep, "--output", out_sweep.to_str().unwrap()]);
    let ts = text(&out);
    assert_eq!(out.status.code(), Some(0), "{ts}");
    assert!(ts.contains("Newton from the previous operating point at L = 302.404 N: CONVERGED"), "{ts}");
    let (s, rolling, spin) = (summary(&out_single), summary(&out_sweep.join("point_001")), summary(&out_sweep.join("point_002")));
    for key in ["film.hc_m", "film.hm_m", "pressure.pmax_pa"] {
        let (x, y) = (num(&s, key), num(&spin, key));
        // One discrete problem, two paths, each converged to a residual of 1e-10: they
        // agree far below 1e-6.
        assert!((x - y).abs() <= 1e-6 * y.abs(), "{key}: continuation {x}, sweep {y}");
    }
    // The spin moves hm by 0.28 % from pure rolling on this mesh: a run that solved the
    // pure-rolling problem instead would fail the comparison above by far more than its
    // tolerance.
    let (hm, hm0) = (num(&s, "film.hm_m"), num(&rolling, "film.hm_m"));
    assert!((hm - hm0).abs() > 1e-3 * hm0, "lambda = 20 deg: hm {hm}, pure rolling {hm0}");
}
