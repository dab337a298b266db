//! Hostile input and faults (issue 27): bad command lines, bad files, nonsense values,
//! misuses of the output folder and of --start-from, each run under `mpirun -n 2` and as a
//! single process (an MPI singleton, what `mpirun -n 1` starts), with a timeout. Each case
//! asserts the exit code, that the message names the field or option, that the error is
//! printed once and that nothing is left behind. Then SIGTERM/SIGINT sent to every rank
//! during each phase of a small lubricated run and of a dry run: exit 143/130, no result.
mod common;
use common::*;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Instant;

/// A hang is a failure: every run is killed after this long.
const TIMEOUT_S: u64 = 60;

fn case2() -> String {
    repo().join("cases/paper/case2.toml").display().to_string()
}

fn table2() -> String {
    repo().join("cases/paper/table2-ue2.toml").display().to_string()
}

/// One misuse: the arguments (the output folder is added unless `own_output`), the
/// expected exit code and the words the message must contain.
struct Case {
    name: &'static str,
    args: Vec<String>,
    code: i32,
    words: Vec<String>,
    env: Vec<(&'static str, String)>,
    /// The case names its own --output (or none is needed).
    own_output: bool,
}

fn case(name: &'static str, args: &[&str], code: i32, words: &[&str]) -> Case {
    Case {
        name,
        args: args.iter().map(|s| s.to_string()).collect(),
        code,
        words: words.iter().map(|s| s.to_string()).collect(),
        env: Vec::new(),
        own_output: false,
    }
}

/// A scene file in `dir` from text.
fn scene_file(dir: &Path, name: &str, text: &str) -> String {
    write_scene(dir, name, text)
}

/// An earlier run's folder for --start-from holding `summary` and a face_pressure.csv.
fn earlier_run(dir: &Path, name: &str, summary: serde_json::Value) -> String {
    let d = dir.join(name);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("summary.json"), serde_json::to_string(&summary).unwrap()).unwrap();
    std::fs::write(d.join("face_pressure.csv"), "x_m,z_m,p_pa\n").unwrap();
    d.display().to_string()
}

/// The stored scene of a summary.json: case2 as serde would write it, with `edit` applied.
fn stored_scene(edit: impl Fn(&mut serde_json::Value)) -> serde_json::Value {
    let scene = ehl_petsc::case::load_scene(&repo().join("cases/paper/table2-ue2.toml")).unwrap();
    let mut v = serde_json::to_value(&scene).unwrap();
    edit(&mut v);
    v
}

/// Every case; `dir` is a scratch folder holding the files they need (nothing else).
fn cases(dir: &Path) -> Vec<Case> {
    let good = std::fs::read_to_string(case2()).unwrap();
    let (c2, t2) = (case2(), table2());
    let fifo = dir.join("fifo.toml");
    let cpath = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    unsafe { libc::mkfifo(cpath.as_ptr(), 0o644) };
    let fifo = fifo.display().to_string();
    let big = scene_file(dir, "big.toml", &format!("{good}\n{}", "# padding\n".repeat(120_000)));
    let garbage = dir.join("garbage.toml");
    std::fs::write(&garbage, (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect::<Vec<u8>>()).unwrap();
    let garbage = garbage.display().to_string();
    let empty = scene_file(dir, "empty.toml", "");
    let dup = scene_file(dir, "dup.toml", &good.replacen("[operating]\n", "[operating]\nload = 1.0\n", 1));
    let list = |n: usize, a: f64, b: f64| (0..n).map(|k| format!("{}", a + (b - a) * k as f64 / n as f64)).collect::<Vec<_>>().join(", ");
    let sweep = scene_file(
        dir,
        "sweep.toml",
        &format!(
            "{good}\n[sweep]\nentrainment_speed = [{}]\ntilt_angle = [{}]\nslide_to_roll = [{}]\n",
            list(1000, 1.0, 3.0),
            list(1000, 10.0, 90.0),
            list(1000, -1.0, 1.0)
        ),
    );
    let small_sweep = scene_file(dir, "small-sweep.toml", &format!("{good}\n[sweep]\nslide_to_roll = [0.0, 0.1]\n"));
    let dry = repo().join("cases/dry-hertz.toml").display().to_string();
    let blocker = dir.join("a-file");
    std::fs::write(&blocker, "not a folder").unwrap();
    let locked = dir.join("locked");
    std::fs::create_dir_all(&locked).unwrap();
    // Process 1 (init) always exists: the lock is live.
    std::fs::write(locked.join(".ehl-petsc.lock"), format!("1 {}\n", hostname())).unwrap();
    let huge_cube = earlier_run(
        dir,
        "earlier-cube",
        serde_json::json!({ "converged": true, "film": { "hc_m": 3e-7 }, "scene": stored_scene(|s| s["mesh"]["cube_size"] = serde_json::json!(3000.0)) }),
    );
    let not_converged = earlier_run(
        dir,
        "earlier-failed",
        serde_json::json!({ "converged": false, "film": { "hc_m": 3e-7 }, "scene": stored_scene(|_| {}) }),
    );
    let bad_json = dir.join("earlier-json");
    std::fs::create_dir_all(&bad_json).unwrap();
    std::fs::write(bad_json.join("summary.json"), "{ not json").unwrap();
    let bad_json = bad_json.display().to_string();
    let s = |v: &str| v.to_string();
    let mut v = vec![
        // The command line.
        case("misspelt-option", &[&c2, "--sett", "operating.load=2"], 2, &["'--sett'", "--set"]),
        case("second-scene", &[&c2, &t2], 2, &["table2-ue2.toml", "one scene"]),
        case("second-scene-after-petsc-option", &[&c2, "-ksp_view", &t2], 2, &["table2-ue2.toml"]),
        case("stray-word", &[&c2, "please"], 2, &["'please'"]),
        case(
            "set-after-petsc-option",
            &[&c2, "-ksp_view", "--set", "operating.load=-1"],
            2,
            &["--set operating.load=-1", "operating.load"],
        ),
        case("flag-with-value", &[&c2, "--check=yes"], 2, &["'--check' takes no value"]),
        case("single-dash-only", &[&c2, "-"], 2, &["'-'"]),
        case("study-not-a-number", &[&c2, "--convergence-study", "many"], 2, &["--convergence-study"]),
        case("unknown-ladder", &[&c2, "--convergence-study", "3", "--ladder", "spiral"], 2, &["--ladder", "spiral"]),
        case("first-size-not-dyadic", &[&t2, "--convergence-study", "3", "--first-size", "0.3"], 2, &["--first-size"]),
        case("study-of-a-dry-scene", &[&dry, "--convergence-study", "2"], 2, &["--convergence-study", "effects.lubrication"]),
        case("sequence-without-study", &[&c2, "--sequence"], 2, &["--sequence"]),
        case("no-scene", &["--quiet"], 2, &["SCENE"]),
        case("options-file-missing", &[&c2, "-options_file", "/nonexistent/opts"], 2, &["-options_file", "/nonexistent/opts"]),
        case("start-from-missing", &[&t2, "--start-from", "/nonexistent/run"], 2, &["--start-from", "/nonexistent/run"]),
        case("start-from-with-sweep", &[&small_sweep, "--start-from", "/nonexistent/run"], 2, &["--start-from", "[sweep]"]),
        case("start-from-bad-json", &[&t2, "--start-from", &bad_json], 2, &["--start-from", "not valid JSON"]),
        case("start-from-stored-cube-3000", &[&t2, "--start-from", &huge_cube], 2, &["--start-from", "mesh.cube_size", "3000"]),
        case("start-from-not-converged", &[&t2, "--start-from", &not_converged], 2, &["--start-from", "converged"]),
        // The scene file.
        case("missing-file", &[&dir.join("does-not-exist.toml").display().to_string()], 2, &["does-not-exist.toml"]),
        case("folder-as-scene", &[&dir.display().to_string()], 2, &["a folder"]),
        case("fifo-as-scene", &[&fifo], 2, &["fifo.toml", "not a regular file"]),
        case("dev-zero-as-scene", &["/dev/zero"], 2, &["/dev/zero", "not a regular file"]),
        case("oversized-scene", &[&big], 2, &["big.toml", "limit"]),
        case("empty-scene", &[&empty], 2, &["empty.toml", "geometry"]),
        case("binary-garbage", &[&garbage], 2, &["garbage.toml"]),
        case("duplicate-key", &[&dup], 2, &["dup.toml", "load"]),
        case("sweep-of-1e9-points", &[&sweep], 2, &["[sweep]", "1000000000"]),
        // Values.
        case("load-1e308", &[&t2, "--set", "operating.load=1e308"], 2, &["operating.load", "a/R"]),
        case("load-negative", &[&t2, "--set", "operating.load=-1"], 2, &["--set operating.load=-1", "> 0"]),
        case("load-nan", &[&t2, "--set", "operating.load=nan"], 2, &["operating.load", "finite"]),
        case("load-inf", &[&t2, "--set", "operating.load=inf"], 2, &["operating.load", "finite"]),
        case("load-a-string", &[&t2, "--set", "operating.load=heavy"], 2, &["operating.load", "the string \"heavy\""]),
        case("young-modulus-tiny", &[&t2, "--set", "materials.ball.young_modulus=1e-300"], 2, &["a/R", "materials"]),
        case(
            "young-modulus-huge",
            &[&t2, "--set", "materials.disc.young_modulus=1e300", "--set", "materials.ball.young_modulus=1e300"],
            2,
            &["p_H", "materials"],
        ),
        case(
            "speed-tiny",
            &[&t2, "--set", "operating.entrainment_speed=1e-9"],
            2,
            &["Moes load parameter M", "operating.entrainment_speed"],
        ),
        case("viscosity-huge", &[&t2, "--set", "lubricant.viscosity=1e4"], 2, &["lubricant.viscosity"]),
        case("tilt-subnormal", &[&c2, "--set", "operating.tilt_angle=1e-320"], 2, &["spin", "operating.tilt_angle"]),
        case("tilt-tiny", &[&c2, "--set", "operating.tilt_angle=0.01"], 2, &["spin", "operating.tilt_angle", "checks.accept"]),
        case("alpha-huge", &[&t2, "--set", "lubricant.pressure_viscosity=1e-4"], 2, &["lubricant.pressure_viscosity"]),
        case(
            "roelands-index-derived-huge",
            &[&t2, "--set", "lubricant.pressure_viscosity=2e-7", "--set", "checks.accept=[\"moes_l\"]"],
            2,
            &["Roelands index", "lubricant.pressure_viscosity"],
        ),
        case("roelands-index-given-zero", &[&t2, "--set", "lubricant.roelands_exponent=0"], 2, &["lubricant.roelands_exponent"]),
        case("unknown-key", &[&t2, "--set", "opertaing.load=1"], 2, &["--set opertaing.load=1", "operating"]),
        case("section-set-to-a-number", &[&t2, "--set", "mesh=3"], 2, &["mesh", "table"]),
        case("override-without-equals", &[&t2, "--set", "operating.load"], 2, &["--set operating.load", "KEY=VALUE"]),
        case("accept-unknown-check", &[&t2, "--set", "checks.accept=[\"spn\"]"], 2, &["checks.accept[0]", "spin"]),
        // The mesh.
        case("contact-size-2", &[&t2, "--set", "mesh.contact_size=2"], 2, &["reynolds.x_min", "mesh.contact_size"]),
        case("cube-too-shallow", &[&t2, "--set", "mesh.cube_size=20"], 2, &["mesh.cube_size"]),
        case(
            "mesh-beyond-memory",
            &[&t2, "--set", "mesh.contact_size=0.015625", "--set", "mesh.ring_size=0", "--set", "mesh.core_size=0"],
            2,
            &["memory", "mesh.contact_size"],
        ),
        case("reynolds-outside-cube", &[&t2, "--set", "reynolds.x_max=40"], 2, &["reynolds.x_max", "mesh.cube_size"]),
    ];
    // Misuses of the output folder (these start MPI and PETSc: no --check).
    let mut last = case("option-without-value", &[&c2, "--check", "--output"], 2, &["'--output' needs a value"]);
    last.own_output = true;
    v.push(last);
    let mut no_value =
        case("option-without-value-before-another", &[&c2, "--output", "--check"], 2, &["'--output' needs a value", "'--check'"]);
    no_value.own_output = true;
    v.push(no_value);
    let mut out_file = case(
        "output-is-a-file",
        &[&t2, "--output", &blocker.join("sub").display().to_string(), "--set", "mesh.contact_size=1"],
        2,
        &["output folder"],
    );
    out_file.own_output = true;
    v.push(out_file);
    let mut lock = case(
        "output-folder-in-use",
        &[&t2, "--output", &locked.display().to_string(), "--set", "mesh.contact_size=1"],
        2,
        &["in use by another run", ".ehl-petsc.lock"],
    );
    lock.own_output = true;
    v.push(lock);
    let mut petsc_env = case("petsc-options-file-in-environment", &[&t2, "--set", "mesh.contact_size=1"], 3, &["PETSc could not start"]);
    petsc_env.env.push(("PETSC_OPTIONS", s("-options_file /nonexistent/opts")));
    v.push(petsc_env);
    // A PETSc option of the wrong type is read only when its solver is set up (here rank 0's
    // condensation): no --check, which starts no PETSc.
    let bad_value_out = dir.join("out-petsc-option-bad-value").display().to_string();
    let mut bad_value = case(
        "petsc-option-bad-value",
        &[&t2, "--set", "mesh.contact_size=1", "-elastic_mat_mumps_icntl_14", "abc", "--output", &bad_value_out],
        2,
        &["'-elastic_mat_mumps_icntl_14 abc'", "Input string abc"],
    );
    bad_value.own_output = true;
    v.push(bad_value);
    // The same value from PETSC_OPTIONS and from an options file: named too, from PETSc's
    // options database rather than the command line.
    let env_out = dir.join("out-petsc-option-bad-value-in-environment").display().to_string();
    let mut in_env = case(
        "petsc-option-bad-value-in-environment",
        &[&t2, "--set", "mesh.contact_size=1", "--output", &env_out],
        2,
        &["'-elastic_mat_mumps_icntl_14 abc'", "Input string abc"],
    );
    in_env.env.push(("PETSC_OPTIONS", s("-elastic_mat_mumps_icntl_14 abc")));
    in_env.own_output = true;
    v.push(in_env);
    let opts = dir.join("bad.opts");
    std::fs::write(&opts, "-elastic_mat_mumps_icntl_14 abc\n").unwrap();
    let file_out = dir.join("out-petsc-option-bad-value-in-file").display().to_string();
    let mut in_file = case(
        "petsc-option-bad-value-in-file",
        &[&t2, "--set", "mesh.contact_size=1", "-options_file", opts.to_str().unwrap(), "--output", &file_out],
        2,
        &["'-elastic_mat_mumps_icntl_14 abc'", "Input string abc"],
    );
    in_file.own_output = true;
    v.push(in_file);
    // The solver's own options are read after PETSc starts, on every rank alike.
    v.push(case(
        "ehl-option-not-a-number",
        &[&t2, "--set", "mesh.contact_size=1", "-ehl_supg_delta", "abc"],
        3,
        &["-ehl_supg_delta", "a real number", "abc"],
    ));
    v.push(case(
        "ehl-option-not-a-bool",
        &[&t2, "--set", "mesh.contact_size=1", "-ehl_monitor", "maybe"],
        3,
        &["-ehl_monitor", "true or false", "maybe"],
    ));
    v.push(case(
        "ehl-option-memory-not-positive",
        &[&t2, "--set", "mesh.contact_size=1", "-ehl_memory_per_rank", "-2"],
        3,
        &["-ehl_memory_per_rank = -2", "a positive number of GB"],
    ));
    v
}

fn hostname() -> String {
    let mut buf = [0u8; 256];
    unsafe { libc::gethostname(buf.as_mut_ptr() as *mut libc::c_char, buf.len()) };
    let end = buf.iter().position(|&b| b == 0).unwrap_or(0);
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

/// Runs the binary on `ranks` ranks (0: as a single process without mpirun), killed after
/// [`TIMEOUT_S`] (exit 124 then).
fn launch(ranks: usize, args: &[String], env: &[(&'static str, String)]) -> Output {
    let mut cmd = Command::new("timeout");
    cmd.args(["-k", "5", &TIMEOUT_S.to_string()]);
    if ranks > 0 {
        cmd.args(["mpirun", "-n", &ranks.to_string()]);
    }
    cmd.arg(binary()).args(args);
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OPENBLAS_NUM_THREADS", "1")
        .env("OMP_NUM_THREADS", "1");
    if args.iter().any(|a| a == "--check") {
        // --check runs no MPI: each rank checks alone and exits 2. Open MPI then waits a
        // second before killing the job (odls_base_sigkill_timeout); 0 saves it per case.
        cmd.env("OMPI_MCA_odls_base_sigkill_timeout", "0");
    }
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("timeout/mpirun")
}

/// All file names under `dir` (recursively), sorted.
fn tree(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            out.push(p.strip_prefix(dir).unwrap().display().to_string());
            if p.is_dir() && !p.is_symlink() {
                stack.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Runs the cases `pick` selects on `ranks`; returns their count and the failures.
fn run_all(ranks: usize, label: &str, pick: impl Fn(&Case) -> bool) -> (usize, Vec<String>) {
    let dir = scratch(&format!("hostile-{label}"));
    let all: Vec<Case> = cases(&dir).into_iter().filter(|c| pick(c)).collect();
    let before = tree(&dir);
    let mut failures = Vec::new();
    let t0 = Instant::now();
    for c in &all {
        let out_dir = dir.join(format!("out-{}", c.name));
        let mut args = c.args.clone();
        if !c.own_output {
            args.extend(["--output".to_string(), out_dir.display().to_string()]);
            // Value errors are found by --check as by a run: most cases use it (cheap).
            if c.code == 2 && !c.args.iter().any(|a| a == "--check") {
                args.push("--check".into());
            }
        }
        let started = Instant::now();
        let out = launch(ranks, &args, &c.env);
        let t = text(&out);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let mut why = Vec::new();
        if out.status.code() == Some(124) {
            why.push(format!("HANG (killed after {TIMEOUT_S} s)"));
        } else if out.status.code() != Some(c.code) {
            why.push(format!("exit {:?}, expected {}", out.status.code(), c.code));
        }
        for w in &c.words {
            if !t.contains(w.as_str()) {
                why.push(format!("message lacks '{w}'"));
            }
        }
        let errors = stderr.lines().filter(|l| l.starts_with("ehl-petsc: error") || l.starts_with("error:")).count();
        if errors != 1 {
            why.push(format!("{errors} error messages, expected 1"));
        }
        if t.contains("panicked") || t.contains("RUST_BACKTRACE") {
            why.push("a panic".into());
        }
        if out_dir.exists() {
            why.push(format!("left {} behind", out_dir.display()));
        }
        let after = tree(&dir);
        if after != before {
            why.push(format!("the scratch folder changed: {:?}", after.iter().filter(|f| !before.contains(f)).collect::<Vec<_>>()));
        }
        if !why.is_empty() {
            failures.push(format!(
                "[{label}] {} ({:.1} s): {}\n    args: {:?}\n    output: {}",
                c.name,
                started.elapsed().as_secs_f64(),
                why.join("; "),
                c.args,
                t.lines().take(6).collect::<Vec<_>>().join("\n            ")
            ));
        }
    }
    eprintln!("{} hostile cases on {label} in {:.1} s", all.len(), t0.elapsed().as_secs_f64());
    (all.len(), failures)
}

#[test]
fn hostile_inputs_on_two_ranks() {
    let (n, failures) = run_all(2, "mpirun-n2", |_| true);
    assert!(n >= 40, "only {n} cases");
    assert!(failures.is_empty(), "{} of {n} cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// Every case as a single process (an MPI singleton: what `mpirun -n 1` starts, without
/// mpirun's second of start-up per case).
#[test]
fn hostile_inputs_on_one_rank() {
    let (n, failures) = run_all(0, "singleton", |_| true);
    assert!(failures.is_empty(), "{} of {n} cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// The cases that start MPI and PETSc (the output folder, PETSc's start-up) and a few
/// usage errors, under `mpirun -n 1` itself.
#[test]
fn hostile_runs_under_mpirun_one_rank() {
    let (n, failures) = run_all(1, "mpirun-n1", |c| {
        c.own_output
            || !c.env.is_empty()
            || ["misspelt-option", "second-scene", "load-1e308", "contact-size-2", "fifo-as-scene"].contains(&c.name)
    });
    assert!(n >= 8, "only {n} cases");
    assert!(failures.is_empty(), "{} of {n} cases failed:\n{}", failures.len(), failures.join("\n"));
}

/// A small lubricated scene that converges in a few seconds on 2 ranks, with friction:
/// table2-ue2 at 300 N and 10 m/s (a thick film) on a plain 0.5a mesh of a 32a cube.
fn small_lubricated() -> Vec<String> {
    let mut a = vec![table2()];
    for s in [
        "mesh.contact_size=0.5",
        "mesh.ring_size=0",
        "mesh.core_size=0",
        "mesh.cube_size=32",
        "effects.friction=\"newtonian\"",
        "operating.slide_to_roll=0.5",
        "operating.load=300",
        "operating.entrainment_speed=10",
    ] {
        a.extend(["--set".to_string(), s.to_string()]);
    }
    a
}

/// Starts `mpirun -n 2` with `args`, waits for the first log line containing `wait_for`,
/// sends `sig` to both ranks; returns (exit code, stdout + stderr, whether the line came).
fn signal_at(args: &[String], out: &Path, wait_for: &str, sig: i32) -> (Option<i32>, String, bool) {
    let mut cmd = Command::new("timeout");
    cmd.args(["-k", "5", &TIMEOUT_S.to_string(), "mpirun", "-n", "2"]).arg(binary()).args(args).arg("--output").arg(out);
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OPENBLAS_NUM_THREADS", "1");
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let timeout_pid = child.id();
    let mut log = String::new();
    let mut seen = false;
    // The reader stays open until mpirun exits: mpirun aborts itself with SIGPIPE after ten
    // writes to a closed pipe, which the ranks may print before the signal reaches them.
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    for line in lines.by_ref() {
        let line = line.unwrap();
        log.push_str(&line);
        log.push('\n');
        if line.contains(wait_for) {
            seen = true;
            break;
        }
    }
    if seen {
        // timeout -> mpirun -> the two ranks.
        let mpirun = children(timeout_pid);
        let ranks: Vec<i32> = mpirun.iter().flat_map(|&p| children(p as u32)).collect();
        assert_eq!(ranks.len(), 2, "expected 2 ranks under mpirun, found {ranks:?}");
        for p in ranks {
            unsafe { libc::kill(p, sig) };
        }
    }
    for line in lines {
        log.push_str(&line.unwrap_or_default());
        log.push('\n');
    }
    let output = child.wait_with_output().unwrap();
    log.push_str(&String::from_utf8_lossy(&output.stdout));
    log.push_str(&String::from_utf8_lossy(&output.stderr));
    (output.status.code(), log, seen)
}

fn children(pid: u32) -> Vec<i32> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children")).unwrap_or_default();
    text.split_whitespace().filter_map(|s| s.parse().ok()).collect()
}

#[test]
fn signals_in_every_phase_leave_no_result() {
    let dir = scratch("hostile-signals");
    let lubricated = small_lubricated();
    let mut dry = vec![repo().join("cases/dry-hertz.toml").display().to_string()];
    dry.extend(["--set".into(), "mesh.contact_size=0.5".into()]);
    // (phase, arguments, the log line that starts the phase, signal)
    let phases: Vec<(&str, &Vec<String>, &str, i32)> = vec![
        ("mesh", &lubricated, "symmetry:", libc::SIGTERM),
        ("condensation", &lubricated, "coupling: condensed", libc::SIGTERM),
        ("Newton", &lubricated, "Newton from the Hertz start:", libc::SIGINT),
        ("friction", &lubricated, "result:", libc::SIGTERM),
        ("output", &lubricated, "friction (", libc::SIGTERM),
        ("dry assembly and solve", &dry, "mesh:", libc::SIGTERM),
    ];
    let mut failures = Vec::new();
    for (k, (phase, args, line, sig)) in phases.iter().enumerate() {
        let out = dir.join(format!("out-{k}"));
        let t0 = Instant::now();
        let (code, log, seen) = signal_at(args, &out, line, *sig);
        let expected = 128 + sig;
        let mut why = Vec::new();
        if !seen {
            why.push(format!("no '{line}' line"));
        }
        if code != Some(expected) {
            why.push(format!("exit {code:?}, expected {expected}"));
        }
        if !log.contains("interrupted by SIG") {
            why.push("no 'interrupted by' message".into());
        }
        if out.exists() {
            why.push(format!("left {:?} in {}", tree(&out), out.display()));
        }
        let said = log.lines().find(|l| l.contains("interrupted by")).unwrap_or("").to_string();
        eprintln!("signal during {phase}: exit {code:?} in {:.1} s: {said}", t0.elapsed().as_secs_f64());
        if !why.is_empty() {
            failures.push(format!("{phase}: {}\n{log}", why.join("; ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    // The same small scene, not interrupted, does write its result: the phases above were
    // stopped by the signal, not by a failing solve.
    let out = dir.join("out-complete");
    let full = launch(2, &[lubricated.clone(), vec!["--output".into(), out.display().to_string()]].concat(), &[]);
    assert_eq!(full.status.code(), Some(0), "{}", text(&full));
    assert!(out.join("summary.json").exists() && out.join("shear_profile.csv").exists());
    assert!(!out.join(".ehl-petsc.lock").exists(), "the lock file stayed: {:?}", tree(&out));
    assert!(tree(&out).iter().all(|f| !f.starts_with(".partial")), "{:?}", tree(&out));
}
