//! The tilt continuation on both couplings: a spin scene solved through the tilt
//! continuation (plain Newton skipped, `-ehl_skip_plain`) with the condensed and with the
//! monolithic coupling. Both are the same discrete problem on the same path, so they must
//! take the path and reach the same film. Before 2026-11-25 the monolithic system could not
//! change its velocity field, skipped the tilt continuation, and a spin scene above 4,000
//! pressure unknowns lost it.
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
