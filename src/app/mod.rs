//! The program: reads the scene, starts PETSc, runs the simulation the scene asks for and
//! writes the results. `main.rs` only parses the command line and calls [`run`].
pub mod adapt;
pub mod dry;
pub mod lubricated;
pub mod plots;
pub mod restart;
pub mod study;
pub mod subsurface;
pub mod sweep;

pub use crate::collective;
pub use crate::context::Context;
use crate::case::Scene;
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
    // The output folder is checked before any solve starts (by rank 0, outcome shared).
    let ready = if rank == 0 { crate::output::prepare_output_dir(&out_dir) } else { Ok(()) };
    if let Err(e) = collective::agree(&world, ready) {
        if rank == 0 {
            eprintln!("ehl-petsc: error: {e}");
        }
        return 2;
    }
    let mut petsc_argv = vec!["ehl-petsc".to_string()];
    petsc_argv.extend(opts.petsc_args.iter().cloned());
    let petsc = match Petsc::init(&petsc_argv) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("ehl-petsc: error: cannot initialise PETSc: {e}");
            return 3;
        }
    };
    crate::interrupt::install();
    match crate::ehl_options::read(crate::petsc::comm_world()) {
        Ok(o) => {
            if let Some(font) = &o.plot_font {
                crate::output::plot::set_font_file(font);
            }
        }
        Err(e) => {
            eprintln!("ehl-petsc: error: cannot read the -ehl_ options: {e}");
            return 3;
        }
    }
    let ctx = Context { world, rank, size, out_dir, quiet: opts.quiet, start };
    ctx.log(format!("ehl-petsc {} on {} rank(s), {}; scene '{}'", env!("CARGO_PKG_VERSION"), size, petsc.version(), scene.name));
    let result = match opts.study_levels {
        Some(n) if scene.effects.lubrication == crate::case::LubricationModel::Reynolds => study::run(&ctx, &scene, n, opts.ladder, first_size, opts.study_sequence),
        Some(_) => Err("--convergence-study needs a lubricated scene (effects.lubrication = \"reynolds\")".into()),
        None => simulate(&ctx, &scene, earlier.as_ref()),
    };
    let failed_here = result.is_err();
    let code = match collective::agree(&ctx.world, result) {
        Ok(()) => 0,
        Err(e) => {
            // A failure every rank shares (Newton, an interruption) is printed once, by
            // rank 0; a rank that failed alone prints its own message.
            let all_failed = collective::all(&ctx.world, failed_here);
            if rank == 0 || (failed_here && !all_failed) {
                eprintln!("ehl-petsc: error{}: {e}", if all_failed { String::new() } else { format!(" (rank {rank})") });
            }
            match crate::interrupt::agreed() {
                0 => 1,
                sig => 128 + sig,
            }
        }
    };
    drop(petsc);
    code
}

/// What `run` checks before it touches the output folder: the scene (with its `--set`
/// overrides), a convergence study's ladder (its first size returned), and the earlier run
/// of `--start-from`.
fn checked_inputs(opts: &RunOptions) -> Result<(Scene, f64, Option<restart::EarlierRun>), String> {
    let scene = crate::case::load_scene_with(&opts.scene, &opts.overrides).map_err(|e| e.to_string())?;
    let first_size = opts.first_size.unwrap_or(opts.ladder.default_first());
    if let Some(n) = opts.study_levels {
        study::check_ladder(opts.ladder, first_size, n)?;
    }
    if opts.study_sequence && opts.study_levels.is_none() {
        return Err("--sequence applies to --convergence-study N (a single solve takes --start-from DIR)".into());
    }
    let earlier = match &opts.start_from {
        None => None,
        Some(_) if opts.study_levels.is_some() => return Err("--start-from applies to one solve, not to a --convergence-study".into()),
        Some(_) if scene.is_sweep() => return Err("--start-from applies to one operating point: the scene has a [sweep] (each sweep point already starts from the previous one)".into()),
        Some(_) if scene.effects.lubrication != crate::case::LubricationModel::Reynolds => return Err("--start-from needs a lubricated scene (effects.lubrication = \"reynolds\")".into()),
        Some(dir) => Some(restart::EarlierRun::read(dir)?),
    };
    Ok((scene, first_size, earlier))
}

/// Dispatches on what the scene asks to simulate.
fn simulate(ctx: &Context, scene: &Scene, earlier: Option<&restart::EarlierRun>) -> Result<(), String> {
    for w in scene.warnings() {
        ctx.log(format!("warning: {w}"));
    }
    match scene.effects.lubrication {
        crate::case::LubricationModel::Dry => dry::run(ctx, scene),
        crate::case::LubricationModel::Reynolds => lubricated::run(ctx, scene, earlier),
    }
}
