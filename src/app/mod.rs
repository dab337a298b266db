//! The program: reads the scene, starts PETSc, runs the simulation the scene asks for and
//! writes the results. `main.rs` only parses the command line and calls [`run`].
pub mod adapt;
pub mod cli;
pub mod dry;
mod estimate;
mod face_files;
mod first_level;
pub mod lubricated;
mod marking;
mod memory;
pub mod plots;
pub mod point;
pub mod restart;
mod sensitivity;
pub mod study;
pub mod subsurface;
pub mod sweep;

use crate::case::{Scene, SceneError, SceneErrorKind};
pub use crate::collective;
pub use crate::context::Context;
use crate::error::{Error, ResultExt};
use crate::petsc::Petsc;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use std::path::PathBuf;
use std::time::Instant;

/// What the command line asked for.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub scene: PathBuf,
    pub output: Option<PathBuf>,
    pub petsc_args: Vec<String>,
    pub check_only: bool,
    pub quiet: bool,
    /// `--convergence-study N`: solve the scene on N meshes (see [`study`]).
    pub study_levels: Option<usize>,
    /// `--ladder`: what the convergence study refines.
    pub ladder: study::Ladder,
    /// `--first-size`: the convergence study's first level size (default: the ladder's).
    pub first_size: Option<f64>,
    /// `--set KEY=VALUE` scene overrides, applied before validation.
    pub overrides: Vec<String>,
    /// `--sequence`: each convergence-study level starts from the previous level's pressure.
    pub study_sequence: bool,
    /// `--start-from DIR`: Newton starts from the converged pressure of an earlier run.
    pub start_from: Option<PathBuf>,
}

/// Runs the program on every rank; returns the process exit code. Errors are printed by
/// rank 0 (or by the rank that failed alone) on stderr.
pub fn run(world: SimpleCommunicator, opts: RunOptions) -> i32 {
    let rank = world.rank() as usize;
    let size = world.size() as usize;
    let start = Instant::now();
    // The scene, the ladder and the earlier run are read and checked on every rank: the
    // outcome is the same everywhere (exit 2, nothing written).
    let (scene, first_size, earlier) = match checked_inputs(&opts) {
        Ok(v) => v,
        Err(e) => {
            if rank == 0 {
                eprintln!("ehl-petsc: error: {e}");
            }
            return 2;
        }
    };
    if opts.check_only {
        if rank == 0 {
            println!("ehl-petsc: scene '{}' is valid", opts.scene.display());
        }
        return 0;
    }
    let out_dir = opts.output.clone().unwrap_or_else(|| PathBuf::from(&scene.output.dir));
    let mut petsc_argv = vec!["ehl-petsc".to_string()];
    petsc_argv.extend(opts.petsc_args.iter().cloned());
    let petsc = match Petsc::init(&petsc_argv) {
        Ok(p) => p,
        Err(e) => {
            // The other ranks may be waiting inside PetscInitialize (an options file read by
            // rank 0 only): no collective agreement is possible, so this rank ends the job.
            // Rank 0 prints at once; another rank waits a moment, so that when every rank
            // failed the message comes once, from rank 0, before the abort.
            if rank != 0 {
                std::thread::sleep(std::time::Duration::from_secs(2));
            }
            let who = if rank == 0 { String::new() } else { format!(" (rank {rank})") };
            // PETSc prints its own message from every rank at the same moment, a line in
            // several writes, so the ranks' lines interleave mid-line. One write (atomic on
            // a pipe below PIPE_BUF) that starts with a newline keeps this line whole and at
            // the start of a line whatever the other ranks are printing.
            let line = format!("\nehl-petsc: error{who}: PETSc could not start with the given PETSc options or PETSC_OPTIONS (PETSc error code {}; PETSc's own message is above); all ranks are stopped\n", e.code);
            let _ = std::io::Write::write_all(&mut std::io::stderr().lock(), line.as_bytes());
            // SAFETY: plain MPI_Abort on the world communicator; it does not return.
            unsafe { mpi::ffi::MPI_Abort(mpi::ffi::RSMPI_COMM_WORLD, 3) };
            return 3;
        }
    };
    crate::interrupt::install();
    // Every rank reads the same options and fails alike: rank 0 reports it, once.
    match collective::agree(&world, crate::ehl_options::read(crate::petsc::comm_world()).map_err(Error::from)) {
        Ok(o) => {
            if let Some(font) = &o.plot_font {
                crate::output::plot::set_font_file(font);
            }
        }
        Err(e) => {
            if rank == 0 {
                eprintln!("ehl-petsc: error: cannot read the -ehl_ options: {e}");
            }
            drop(petsc);
            return 3;
        }
    }
    // The output folder is claimed before any solve starts (rank 0, outcome shared): created
    // if needed, locked against another run using it.
    let claim = if rank == 0 { crate::output::claim_output_dir(&out_dir).map(Some) } else { Ok(None) };
    let claim = match collective::agree(&world, claim) {
        Ok(c) => c,
        Err(e) => {
            if rank == 0 {
                eprintln!("ehl-petsc: error: {e}");
            }
            drop(petsc);
            return 2;
        }
    };
    let ctx = Context { world, rank, size, out_dir, quiet: opts.quiet, start };
    ctx.log(format!("ehl-petsc {} on {} rank(s), {}; scene '{}'", env!("CARGO_PKG_VERSION"), size, petsc.version(), scene.name));
    let result = match opts.study_levels {
        Some(n) if scene.effects.lubrication == crate::case::LubricationModel::Reynolds => {
            study::run(&ctx, &scene, n, opts.ladder, first_size, opts.study_sequence).map(|()| Outcome::Done)
        }
        Some(_) => Err(Error::invalid("--convergence-study needs a lubricated scene (effects.lubrication = \"reynolds\")")),
        None => simulate(&ctx, &scene, earlier.as_ref()),
    };
    let failed_here = result.is_err();
    let code = match collective::agree(&ctx.world, result) {
        Ok(Outcome::Done) => 0,
        Ok(Outcome::ShortOfTarget(why)) => {
            if rank == 0 {
                eprintln!("ehl-petsc: warning: {why}");
            }
            4
        }
        Err(e) => failure_code(&ctx, &e, failed_here, &opts.petsc_args),
    };
    if let Some(c) = &claim {
        c.release(code == 0 || code == 4);
    }
    if rank == 0 {
        warn_unused_options();
    }
    drop(petsc);
    code
}

/// The exit code of a run that failed with `e` (`failed_here`: on this rank), after its
/// message: printed once by rank 0 when every rank failed, by the failing rank when it failed
/// alone. 2 for a PETSc option whose value PETSc rejected, 128 + the signal for an
/// interruption, 1 otherwise. Collective.
fn failure_code(ctx: &Context, e: &Error, failed_here: bool, petsc_args: &[String]) -> i32 {
    let all_failed = collective::all(&ctx.world, failed_here);
    // A value of one of the user's PETSc options that PETSc rejected when it read it
    // (a solver is set up only when it is first used): bad input, named.
    // The whole database: PETSC_OPTIONS and options files too, not only the command line.
    let given = crate::petsc::options::given().unwrap_or_else(|_| petsc_args.to_vec());
    let quoted = cli::options_quoted(&given, &e.to_string());
    // The rank that read the option may be alone with PETSc's message (rank 0's
    // condensation): every rank ends with the same code.
    let bad_option = !collective::all(&ctx.world, quoted.is_empty());
    if ctx.rank == 0 || (failed_here && !all_failed) {
        let who = if all_failed { String::new() } else { format!(" (rank {})", ctx.rank) };
        if quoted.is_empty() {
            eprintln!("ehl-petsc: error{who}: {e}");
        } else {
            eprintln!(
                "ehl-petsc: error{who}: PETSc rejects the value of the PETSc option '{}' (PETSc's message follows): {e}",
                quoted.join("', '")
            );
        }
    }
    match crate::interrupt::agreed() {
        0 if bad_option => 2,
        // A spent time budget that nothing turned into a labelled result.
        0 | crate::interrupt::DEADLINE => 1,
        sig => 128 + sig,
    }
}

/// -options_left style: warns of the user's PETSc options that nothing queried (misspelt,
/// or for a solver this run did not use). Rank 0.
fn warn_unused_options() {
    match crate::petsc::options::unused() {
        Ok(left) => {
            for (name, value) in left {
                let v = value.map(|v| format!(" {v}")).unwrap_or_default();
                eprintln!("ehl-petsc: warning: PETSc option '{name}{v}' was given but not used by this run (misspelt, or for a solver this run does not use)");
            }
        }
        Err(e) => eprintln!("ehl-petsc: warning: cannot list unused PETSc options: {e}"),
    }
}

/// `--check`: reads and checks everything [`run`] would check before solving (the scene
/// with its overrides, its physical plausibility and mesh, the ladder, the earlier run),
/// without MPI or PETSc; prints the outcome when `print` (the launcher's rank 0). Returns
/// the exit code (0 valid, 2 not).
pub fn check(opts: &RunOptions, print: bool) -> i32 {
    match checked_inputs(opts) {
        Ok((scene, _, _)) => {
            if print {
                for w in scene.warnings().into_iter().chain(scene.plausibility().unwrap_or_default()) {
                    println!("ehl-petsc: warning: {w}");
                }
                if !opts.petsc_args.is_empty() {
                    println!("ehl-petsc: warning: PETSc options are not used by --check: {}", opts.petsc_args.join(" "));
                }
                println!("ehl-petsc: scene '{}' is valid", opts.scene.display());
            }
            0
        }
        Err(e) => {
            if print {
                eprintln!("ehl-petsc: error: {e}");
            }
            2
        }
    }
}

/// What `run` checks before it touches the output folder: the scene (with its `--set`
/// overrides), a convergence study's ladder (its first size returned), and the earlier run
/// of `--start-from`.
fn checked_inputs(opts: &RunOptions) -> Result<(Scene, f64, Option<restart::EarlierRun>), Error> {
    let scene = crate::case::load_scene_with(&opts.scene, &opts.overrides)?;
    let file = opts.scene.display();
    scene.plausibility().context(file.to_string())?;
    check_mesh(&scene).context(file.to_string())?;
    let first_size = opts.first_size.unwrap_or(opts.ladder.default_first());
    if let Some(n) = opts.study_levels {
        if scene.effects.lubrication != crate::case::LubricationModel::Reynolds {
            return Err(Error::invalid("--convergence-study needs a lubricated scene (effects.lubrication = \"reynolds\")"));
        }
        if scene.is_sweep() {
            return Err(Error::invalid("--convergence-study solves one operating point: remove [sweep] from the scene"));
        }
        study::check_ladder(opts.ladder, first_size, n)?;
        for k in 0..n {
            let level = study::level_scene(&scene, opts.ladder, study::level_size(first_size, k));
            check_mesh(&level).context(format!("{file}: --convergence-study level {}", k + 1))?;
            level.plausibility().context(format!("{file}: --convergence-study level {}", k + 1))?;
        }
    }
    if opts.study_sequence && opts.study_levels.is_none() {
        return Err(Error::invalid("--sequence applies to --convergence-study N (a single solve takes --start-from DIR)"));
    }
    let earlier = match &opts.start_from {
        None => None,
        Some(_) if opts.study_levels.is_some() => {
            return Err(Error::invalid("--start-from applies to one solve, not to a --convergence-study"))
        }
        Some(_) if scene.is_sweep() => return Err(Error::invalid(
            "--start-from applies to one operating point: the scene has a [sweep] (each sweep point already starts from the previous one)",
        )),
        Some(_) if scene.effects.lubrication != crate::case::LubricationModel::Reynolds => {
            return Err(Error::invalid("--start-from needs a lubricated scene (effects.lubrication = \"reynolds\")"))
        }
        Some(dir) => Some(restart::EarlierRun::read(dir)?),
    };
    Ok((scene, first_size, earlier))
}

/// Checks that the mesher can build the scene's mesh (what it would refuse only after the
/// solve has started), with messages naming the scene keys.
pub fn check_mesh(scene: &Scene) -> Result<(), SceneError> {
    let half = scene.effects.lubrication == crate::case::LubricationModel::Reynolds && scene.uses_half_domain();
    let spec = dry::mesh_spec(scene, half);
    let h = crate::mesh::spec::dyadic_size(scene.mesh.contact_size);
    let r = &scene.reynolds;
    let mut edges = vec![("reynolds.x_min", r.x_min), ("reynolds.x_max", r.x_max), ("reynolds.z_min", r.z_min)];
    if !half {
        edges.push(("reynolds.z_max", r.z_max));
    }
    for (key, v) in edges {
        let on_grid = |size: f64| ((v / size) - (v / size).round()).abs() < 1e-9;
        if !on_grid(h) {
            // The largest size 16/2^k the edge is a multiple of.
            let fits = (0..=10).map(|k| 16.0 / f64::from(1u32 << k)).find(|&size| on_grid(size)).unwrap_or(crate::case::MIN_CONTACT_SIZE);
            return Err(SceneErrorKind::Conflict(format!(
                "{key} = {} is not a multiple of the contact element size {h} a (mesh.contact_size = {} rounded down to 16/2^k): the Reynolds rectangle's edges must lie on the contact grid (use mesh.contact_size <= {fits} or move the edge)",
                crate::case::spec::fmt_num(v),
                crate::case::spec::fmt_num(scene.mesh.contact_size),
            ))
            .into());
        }
    }
    if scene.effects.elasticity == crate::case::ElasticityModel::Rigid
        && scene.effects.lubrication == crate::case::LubricationModel::Reynolds
    {
        return Ok(());
    }
    spec.validate().map(|_| ()).map_err(|e| SceneErrorKind::Conflict(format!("the mesh of [mesh] and [reynolds] cannot be built ({}); check mesh.cube_size, mesh.contact_size and the reynolds.x_min/x_max/z_min/z_max rectangle", e.to_string().trim_start_matches("mesh spec: "))).into())
}

/// How a run that wrote its result ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Everything the scene asked for.
    Done,
    /// A labelled result short of its accuracy target (exit 4), and why.
    ShortOfTarget(String),
}

/// Dispatches on what the scene asks to simulate.
fn simulate(ctx: &Context, scene: &Scene, earlier: Option<&restart::EarlierRun>) -> Result<Outcome, Error> {
    for w in scene.warnings().into_iter().chain(scene.plausibility().unwrap_or_default()) {
        ctx.log(format!("warning: {w}"));
    }
    match scene.effects.lubrication {
        crate::case::LubricationModel::Dry => dry::run(ctx, scene).map(|()| Outcome::Done),
        crate::case::LubricationModel::Reynolds => lubricated::run(ctx, scene, earlier),
    }
}
