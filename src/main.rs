//! Command line of ehl-petsc: `ehl-petsc [OPTIONS] SCENE.toml [PETSc options...]`.
use clap::{ArgAction, Parser};
use std::path::PathBuf;

const AFTER_HELP: &str = "\
PETSc options follow the scene file and go to PETSc unchanged (PETSC_OPTIONS works too):
  mpirun -n 2 ehl-petsc cases/dry-hertz.toml -ksp_view -log_view
  ehl-petsc cases/dry-hertz.toml -pc_type gamg -ksp_type cg -ksp_rtol 1e-10
Defaults: -ksp_type preonly -pc_type lu; MUMPS (-mat_mumps_icntl_7 4, PORD) for sparse matrices;
  the dense condensed EHL Jacobian: -pc_factor_mat_solver_type scalapack (2+ ranks) or petsc
  (LAPACK, 1 rank); -condensed_mat_type aij -pc_factor_mat_solver_type mumps returns to MUMPS.
Useful: -log_view, -ksp_view, -options_left (lists options nobody used), -mat_mumps_icntl_4 2.
The solver's own options (-ehl_monitor, -ehl_check_jacobian, -ehl_supg_delta, ...) are listed
  with the others by -help after the scene.
Exit codes: 0 success, 1 solve failed or did not converge, 2 bad scene or output folder, 3 PETSc start-up,
  130/143 interrupted by SIGINT/SIGTERM (all ranks stop at the next check; no result of the
  interrupted solve is written).";

/// Full-system FEM solver for elastohydrodynamic lubrication (EHL) of circular contacts
/// under rolling, sliding and spinning, on PETSc and MPI.
#[derive(Parser, Debug)]
#[command(name = "ehl-petsc", version, disable_help_flag = true, disable_version_flag = true, after_help = AFTER_HELP, trailing_var_arg = true)]
struct Cli {
    /// Scene file (TOML): geometry, materials, lubricant, operating point, mesh, outputs
    #[arg(required_unless_present = "scene_reference")]
    scene: Option<PathBuf>,
    /// PETSc options, e.g. -ksp_view -log_view -snes_monitor (single dash, after the scene)
    #[arg(allow_hyphen_values = true, value_name = "PETSC_OPTIONS")]
    petsc_args: Vec<String>,
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

fn main() {
    let cli = Cli::parse();
    if cli.scene_reference {
        print!("{}", ehl_petsc::case::reference_markdown());
        return;
    }
    let Some(universe) = mpi::initialize() else {
        eprintln!("ehl-petsc: error: MPI could not be initialised");
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
    let opts = ehl_petsc::app::RunOptions {
        scene: cli.scene.expect("clap requires the scene"),
        output: cli.output,
        petsc_args: cli.petsc_args,
        check_only: cli.check,
        quiet: cli.quiet,
        study_levels: cli.convergence_study,
        ladder: cli.ladder,
        first_size: cli.first_size,
        overrides: cli.set,
        start_from: cli.start_from,
        study_sequence: cli.sequence,
    };
    let code = ehl_petsc::app::run(world, opts);
    drop(universe);
    std::process::exit(code);
}
