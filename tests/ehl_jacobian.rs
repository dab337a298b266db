//! The assembled Jacobian of the coupled EHL system (U, P, H0) against finite differences,
//! block by block, on a small mesh of the Table 2 (Ue = 2 m/s) scene, under 2 MPI ranks.
mod common;
use common::*;

#[test]
fn ehl_jacobian_matches_finite_differences() {
    let dir = scratch("ehl-jacobian");
    let scene = table2_ue2_with_mesh("contact_size = 1.0\ngrowth = 2.0");
    let path = write_scene(&dir, "scene.toml", &scene);
    let mut cmd = std::process::Command::new("mpirun");
    cmd.args(["-n", "2"]).arg(binary()).args([
        path.as_str(),
        "--set",
        "reynolds.coupling=monolithic",
        "--output",
        dir.join("out").to_str().unwrap(),
        "-snes_max_it",
        "0",
        "-ehl_check_jacobian",
    ]);
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1").env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1").env("OPENBLAS_NUM_THREADS", "1");
    let out = cmd.output().unwrap();
    let t = text(&out);
    assert!(t.contains("coupling: monolithic"), "{t}");
    let lines: Vec<&str> = t.lines().filter(|l| l.contains("Jacobian check")).collect();
    assert_eq!(lines.len(), 9, "expected 9 block checks:\n{t}");
    for l in &lines {
        let err: f64 = l.rsplit('=').next().unwrap().trim().parse().unwrap();
        // Central differences with step 1e-7 of the direction's size: truncation and
        // round-off together stay below ~1e-6 for an exact Jacobian; a wrong coupling term
        // gives O(1).
        assert!(err < 1e-5, "Jacobian block mismatch: {l}");
    }
    // Zero Newton iterations cannot converge: the run must say so and fail, with no summary.
    assert_eq!(out.status.code(), Some(1), "{t}");
    assert!(t.contains("did not converge"), "{t}");
    assert!(!dir.join("out").join("summary.json").exists());
}

/// The condensed system's dense Jacobian (dR/dP + dR/dH C and the load row) against PETSc's
/// finite-difference Jacobian (`-snes_test_jacobian`) at the Hertz start.
#[test]
fn condensed_jacobian_matches_finite_differences() {
    let dir = scratch("condensed-jacobian-p2");
    let scene = table2_ue2_with_mesh("contact_size = 1.0\ngrowth = 2.0");
    let path = write_scene(&dir, "scene.toml", &scene);
    let mut cmd = std::process::Command::new("mpirun");
    cmd.args(["-n", "2"]).arg(binary()).args([
        path.as_str(),
        "--output",
        dir.join("out").to_str().unwrap(),
        "-snes_max_it",
        "1",
        "-snes_test_jacobian",
    ]);
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1").env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1").env("OPENBLAS_NUM_THREADS", "1");
    let out = cmd.output().unwrap();
    let t = text(&out);
    let first = t.lines().find(|l| l.contains("||J - Jfd||_F/||J||_F =")).unwrap_or_else(|| panic!("no Jacobian test printed:\n{t}"));
    let ratio: f64 = first.split('=').nth(1).unwrap().split(',').next().unwrap().trim().parse().unwrap();
    // PETSc's forward differences (relative step ~1.5e-8) give ~1e-7 for an exact
    // Jacobian (measured 1.5e-7); a wrong or missing coupling term (the compliance) gives
    // 1e-3 or more.
    assert!(ratio < 1e-5, "condensed Jacobian mismatch: {first}");
    assert!(t.contains("66 P"), "expected 66 P unknowns on the coarse face:\n{t}");
}

/// Runs the coarse Table 2 scene for a few Newton iterations and returns the SNES residual
/// norms it printed (the whole continuation path).
fn newton_norms(tag: &str, monolithic: bool) -> Vec<f64> {
    newton_norms_on(tag, monolithic, 2)
}

fn newton_norms_on(tag: &str, monolithic: bool, ranks: usize) -> Vec<f64> {
    let dir = scratch(tag);
    let scene = table2_ue2_with_mesh("contact_size = 1.0\ngrowth = 2.0");
    let path = write_scene(&dir, "scene.toml", &scene);
    let mut cmd = std::process::Command::new("mpirun");
    let coupling = if monolithic { "reynolds.coupling=monolithic" } else { "reynolds.coupling=condensed" };
    cmd.args(["-n", &ranks.to_string()]).arg(binary()).args([
        path.as_str(),
        "--set",
        coupling,
        "--output",
        dir.join("out").to_str().unwrap(),
        "-snes_max_it",
        "3",
        "-snes_monitor",
        // The backtracking line search throughout: it only shortens the same Newton step on
        // both couplings. (Given by the user, it also keeps plain Newton from going on with
        // "l2" when bt gives out: l2 minimises the norm of the whole residual, whose elastic
        // rows only the monolithic system has, so its steps differ between the couplings.)
        "-snes_linesearch_type",
        "bt",
    ]);
    if monolithic {
        // Exact Newton, as the monolithic coupling takes from the Hertz start by default
        // (from a start near the solution it reuses the LU over three steps with GMRES to
        // the Eisenstat-Walker tolerance, whose iterates differ from exact Newton's by that
        // tolerance); the comparison is of the discrete problem, so both take exact steps.
        cmd.args(["-snes_lag_preconditioner", "1", "-ksp_type", "preonly", "-snes_ksp_ew", "false"]);
    }
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OPENBLAS_NUM_THREADS", "1");
    let out = cmd.output().unwrap();
    let t = text(&out);
    let used = if monolithic { "coupling: monolithic" } else { "coupling: condensed" };
    assert!(t.contains(used), "the run did not use the requested coupling ({used}):\n{t}");
    t.lines()
        .filter(|l| l.contains("SNES Function norm"))
        .map(|l| l.rsplit(' ').find(|w| !w.is_empty()).unwrap().parse().unwrap())
        .collect()
}

/// The condensed system (elastic block eliminated onto the contact face through MUMPS's
/// Schur complement) is the same discrete problem as the monolithic one: Newton from the
/// same start must produce the same residual norms, iteration by iteration, up to
/// round-off of the different elimination order.
#[test]
fn condensed_newton_matches_monolithic_newton() {
    let c = newton_norms("ehl-condensed", false);
    let m = newton_norms("ehl-monolithic", true);
    assert!(c.len() >= 4, "too few Newton iterations printed: {c:?}");
    // The first solve (start + 3 Newton steps) is deterministic up to round-off; later
    // solves may take different line-search branches, so only the first 4 norms count.
    for k in 0..4 {
        let rel = (c[k] - m[k]).abs() / m[k].abs();
        assert!(rel < 1e-6, "iteration {k}: condensed {} vs monolithic {} (rel {rel:.2e})\n{c:?}\n{m:?}", c[k], m[k]);
    }
}

/// The dense condensed Jacobian is filled block by block where it is stored: all of it on
/// 1 rank (LAPACK LU), column blocks on 2 ranks (a 1 x 2 ScaLAPACK grid), row and column
/// blocks on 4 (2 x 2). A block filled wrongly changes the Newton steps: the residual
/// history from the same start must agree to round-off at 1, 2 and 4 ranks.
#[test]
fn condensed_newton_history_is_rank_invariant() {
    let one = newton_norms_on("ehl-condensed-1", false, 1);
    assert!(one.len() >= 4, "too few Newton iterations printed: {one:?}");
    for ranks in [2, 4] {
        let other = newton_norms_on(&format!("ehl-condensed-{ranks}"), false, ranks);
        for k in 0..4 {
            let rel = (other[k] - one[k]).abs() / one[k].abs();
            assert!(rel < 1e-8, "{ranks} ranks, iteration {k}: {} vs {} on 1 rank (rel {rel:.2e})\n{other:?}\n{one:?}", other[k], one[k]);
        }
    }
}
