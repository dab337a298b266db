//! Command line of ehl-petsc: `ehl-petsc [OPTIONS] SCENE.toml [PETSc options...]`; our
//! double-dash options may stand anywhere, PETSc's options take a single dash or follow
//! `--` (see [`ehl_petsc::app::cli`]).
use clap::{ArgAction, Parser};
use std::path::PathBuf;

const AFTER_HELP: &str = "\
Options of ehl-petsc take two dashes and may stand anywhere; an unknown one is an error.
PETSc options take one dash (or follow '--') and go to PETSc unchanged (PETSC_OPTIONS works too);
  options nobody used are listed as a warning at the end of the run:
  mpirun -n 2 ehl-petsc cases/dry-hertz.toml -ksp_view -log_view
  ehl-petsc cases/dry-hertz.toml -pc_type gamg -ksp_type cg -ksp_rtol 1e-10
Defaults: -ksp_type preonly -pc_type lu; MUMPS (-mat_mumps_icntl_7 4, PORD) for sparse matrices;
  the dense condensed EHL Jacobian: -pc_factor_mat_solver_type scalapack (2+ ranks) or petsc
  (LAPACK, 1 rank); -condensed_mat_type aij -pc_factor_mat_solver_type mumps returns to MUMPS.
Useful: -log_view, -ksp_view, -options_left (lists options nobody used), -mat_mumps_icntl_4 2;
  -mat_mumps_icntl_22 1 writes MUMPS's factors to disk (/tmp): a fifth less memory, a quarter more time.
The solver's own options (-ehl_monitor, -ehl_memory_per_rank GB, -ehl_supg_delta, ...) are listed
  with the others by -help after the scene.
Exit codes: 0 success, 1 solve failed or did not converge, 2 bad command line, scene or output folder
  (also an output folder in use by another run), 3 MPI or PETSc start-up (all ranks end),
  4 result written but its accuracy target not reached (summary.json: accuracy.reached = false,
  with the estimated error), 130/143 interrupted by SIGINT/SIGTERM (all ranks stop at the next check; no result of the
  interrupted solve is written).";

/// Full-system FEM solver for elastohydrodynamic lubrication (EHL) of circular contacts
/// under rolling, sliding and spinning, on PETSc and MPI.
#[derive(Parser, Debug)]
#[command(name = "ehl-petsc", version, override_usage = "ehl-petsc [OPTIONS] SCENE.toml [PETSc options: -name [value] ... or after --]", disable_help_flag = true, disable_version_flag = true, after_help = AFTER_HELP)]
struct Cli {
    /// Scene file (TOML): geometry, materials, lubricant, operating point, mesh, outputs
    #[arg(required_unless_present = "scene_reference")]
    scene: Option<PathBuf>,
    /// Output folder (default: the scene's output.dir)
    #[arg(long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Override a scene key before validation, e.g. --set mesh.core_size=0.0625
    /// --set operating.load=2000 (repeatable; the value is TOML, bare words are strings)
    #[arg(long = "set", value_name = "KEY=VALUE", action = ArgAction::Append)]
    set: Vec<String>,
    /// Start Newton from the converged pressure of an earlier run (its output folder:
    /// summary.json and face_pressure.csv), interpolated onto this mesh: mesh sequencing,
    /// e.g. a refined mesh from the coarse solution. Falls back to the Hertz start if
    /// Newton fails from it
    #[arg(long, value_name = "DIR")]
    start_from: Option<PathBuf>,
    /// Validate the scene file and exit without solving
    #[arg(long)]
    check: bool,
    /// Print only errors
    #[arg(long)]
    quiet: bool,
    /// Solve the scene on N meshes halving the contact-zone size (0.5a, 0.25a, then a
    /// 0.125a, 0.0625a, ... core), estimate converged values by Richardson extrapolation;
    /// writes study.csv, study.md and error plots
    #[arg(long, value_name = "N")]
    convergence_study: Option<usize>,
    /// What the convergence study refines: "core" (the whole contact zone, then a core
    /// square |X|, |Z| <= 1.25) or "ring" (only the ring mesh.ring_inner <= r <=
    /// mesh.ring_outer around the Hertz circle: 0.125a, 0.0625a, 0.03125a, ...)
    #[arg(long, value_name = "core|ring", default_value = "core")]
    ladder: ehl_petsc::app::study::Ladder,
    /// The convergence study's first level size in units of a, 16/2^k (default: 0.5 for the
    /// core ladder, 0.125 for the ring ladder); each level halves it
    #[arg(long, value_name = "H")]
    first_size: Option<f64>,
    /// With --convergence-study: each level starts from the last converged level's
    /// pressure (mesh sequencing, as --start-from) instead of the Hertz start
    #[arg(long)]
    sequence: bool,
    /// Print the scene-file reference (every key, unit, range, default) as Markdown and exit
    #[arg(long)]
    scene_reference: bool,
    /// Print help (PETSc's own help: -help after the scene)
    #[arg(long, action = ArgAction::Help)]
    help: Option<bool>,
    /// Print version
    #[arg(long, action = ArgAction::Version)]
    version: Option<bool>,
}

/// A usage error: printed once (by the launcher's rank 0), exit 2.
fn usage_error(rank0: bool, msg: &str) -> ! {
    if rank0 {
        eprintln!("ehl-petsc: error: {msg} (see ehl-petsc --help)");
    }
    exit_quietly(rank0, 2)
}

/// Ends a rank that runs without MPI (a usage error, --check). The other ranks wait a
/// moment so that rank 0, which prints the outcome, ends first: a launcher that tears the
/// job down at the first non-zero exit would otherwise cut its message.
fn exit_quietly(rank0: bool, code: i32) -> ! {
    if !rank0 && code != 0 {
        std::thread::sleep(std::time::Duration::from_millis(300));
    }
    std::process::exit(code)
}

fn main() {
    use ehl_petsc::app::cli;
    // The command line is checked before MPI starts: a usage error ends every rank the same
    // way, printed once.
    let rank0 = cli::launcher_rank() == 0;
    let args: Vec<String> = std::env::args_os()
        .skip(1)
        .map(|a| a.into_string().unwrap_or_else(|a| usage_error(rank0, &format!("argument {a:?} is not valid UTF-8"))))
        .collect();
    let split = cli::split(&args).unwrap_or_else(|e| usage_error(rank0, &e.to_string()));
    let cli = match Cli::try_parse_from(std::iter::once("ehl-petsc".to_string()).chain(split.ours)) {
        Ok(c) => c,
        Err(e) => {
            let code = match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => 0,
                _ => 2,
            };
            if rank0 {
                let _ = e.print();
            }
            exit_quietly(rank0, code);
        }
    };
    if cli.scene_reference {
        if rank0 {
            print!("{}", ehl_petsc::case::reference_markdown());
        }
        return;
    }
    if let Err(e) = cli::check_petsc_args(&split.petsc) {
        usage_error(rank0, &e.to_string());
    }
    let opts = ehl_petsc::app::RunOptions {
        scene: cli.scene.unwrap_or_else(|| usage_error(rank0, "no scene file given")),
        output: cli.output,
        petsc_args: split.petsc,
        check_only: cli.check,
        quiet: cli.quiet,
        study_levels: cli.convergence_study,
        ladder: cli.ladder,
        first_size: cli.first_size,
        overrides: cli.set,
        start_from: cli.start_from,
        study_sequence: cli.sequence,
    };
    if opts.check_only {
        // Validation only: no MPI, no PETSc, nothing written.
        exit_quietly(rank0, ehl_petsc::app::check(&opts, rank0));
    }
    let Some(universe) = mpi::initialize() else {
        if rank0 {
            eprintln!("ehl-petsc: error: MPI could not be initialised");
        }
        std::process::exit(3);
    };
    let world = universe.world();
    // A panic on one rank must not leave the others waiting: abort the whole job.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        default_hook(info);
        eprintln!("ehl-petsc: internal error, aborting all MPI ranks");
        unsafe { mpi::ffi::MPI_Abort(mpi::ffi::RSMPI_COMM_WORLD, 70) };
    }));
    let code = ehl_petsc::app::run(world, opts);
    drop(universe);
    std::process::exit(code);
}
