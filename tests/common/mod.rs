//! Helpers for integration tests: run the real binary, under mpirun, in a scratch folder.
#![allow(dead_code)]
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The ehl-petsc binary cargo built for these tests.
pub fn binary() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ehl-petsc"))
}

/// The repository root (for cases/).
pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh empty scratch folder under target/test-scratch/<name>.
pub fn scratch(name: &str) -> PathBuf {
    let dir = repo().join("target").join("test-scratch").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn mpi_env(cmd: &mut Command) {
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OPENBLAS_NUM_THREADS", "1")
        .env("OMP_NUM_THREADS", "1");
}

/// Runs `mpirun -n ranks ehl-petsc args...` and returns its output.
pub fn mpirun(ranks: usize, args: &[&str]) -> Output {
    let mut cmd = Command::new("mpirun");
    cmd.arg("-n").arg(ranks.to_string()).arg(binary()).args(args);
    mpi_env(&mut cmd);
    cmd.output().expect("mpirun could not be started (is openmpi-bin installed? run ci/setup)")
}

/// Runs `mpirun -n ranks ehl-petsc args...` with extra environment variables.
pub fn mpirun_env(ranks: usize, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new("mpirun");
    cmd.arg("-n").arg(ranks.to_string()).arg(binary()).args(args);
    mpi_env(&mut cmd);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("mpirun could not be started (is openmpi-bin installed? run ci/setup)")
}

/// Runs the binary directly (MPI singleton), for command-line checks.
pub fn run_plain(args: &[&str]) -> Output {
    let mut cmd = Command::new(binary());
    cmd.args(args);
    mpi_env(&mut cmd);
    cmd.output().expect("binary could not be started")
}

/// stdout + stderr as one string (for assertion messages).
pub fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// Reads a summary.json. A lubricated run's summary (one with `film`) must also be read by
/// the typed reader that `--start-from` and paper-findings use, so every test that reads one
/// checks that the two agree on what the file holds.
pub fn summary(dir: &Path) -> serde_json::Value {
    let path = dir.join("summary.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    if v.get("film").is_some() {
        let typed =
            ehl_petsc::output::summary::Summary::from_json(&text).unwrap_or_else(|e| panic!("{}: typed reader: {e}", path.display()));
        let same = |a: f64, b: Option<f64>| b.is_some_and(|b| a == b || (a.is_nan() && b.is_nan()));
        assert!(
            same(typed.film.hc_m, v["film"]["hc_m"].as_f64()),
            "{}: typed film.hc_m {} against the file",
            path.display(),
            typed.film.hc_m
        );
        assert!(
            same(typed.film.hm_m, v["film"]["hm_m"].as_f64()),
            "{}: typed film.hm_m {} against the file",
            path.display(),
            typed.film.hm_m
        );
    }
    v
}

/// Writes a scene file into `dir` and returns its path as a String.
pub fn write_scene(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

/// Writes into `dir` the M = 10, L = 6 reference scene (cases/references) as a sweep over
/// Ue = 2 and 4 m/s, and returns its path.
pub fn moes_m10_speed_sweep(dir: &Path) -> String {
    let text = std::fs::read_to_string(repo().join("cases/references/moes-m10-l6.toml")).unwrap();
    write_scene(dir, "sweep.toml", &format!("{text}\n[sweep]\nentrainment_speed = [2.0, 4.0]\n"))
}

/// A number from a JSON path like "elastic.u2_center_m".
pub fn num(v: &serde_json::Value, path: &str) -> f64 {
    let mut cur = v;
    for key in path.split('.') {
        cur = &cur[key];
    }
    cur.as_f64().unwrap_or_else(|| panic!("{path} is not a number in {v}"))
}

/// The Table 2 (Ue = 2 m/s) paper scene with its `[mesh]` section replaced by `mesh`
/// (the TOML lines of the new section, without the header).
pub fn table2_ue2_with_mesh(mesh: &str) -> String {
    let base = std::fs::read_to_string(repo().join("cases/paper/table2-ue2.toml")).unwrap();
    let start = base.find("[mesh]\n").expect("table2-ue2 has a [mesh] section");
    let end = start + base[start..].find("\n\n").expect("[mesh] section ends with a blank line");
    format!("{}[mesh]\n{}{}", &base[..start], mesh, &base[end..])
}
