//! The solver's own PETSc-style options (`-ehl_...`): developer diagnostics and the few
//! numerical knobs that are not scene keys. They are read once per run through PETSc's
//! options database (so `-help` lists them and `-options_left` knows them) and kept here
//! for every module; before they are read (unit tests), the defaults hold.
use crate::petsc;
use std::sync::OnceLock;

/// Values of the `-ehl_...` options.
#[derive(Debug, Clone)]
pub struct EhlOptions {
    /// `-ehl_monitor`: per-iteration diagnostics on stderr (residual norms per block, the
    /// worst residual rows, the film step limiter and its binding node, clipped pressure
    /// steps, the condensation's phases, the iterate's central and minimum film).
    pub monitor: bool,
    /// `-ehl_check_jacobian`: a block-by-block finite-difference check of the monolithic
    /// Jacobian at the start (the condensed coupling: `-snes_test_jacobian`).
    pub check_jacobian: bool,
    /// `-ehl_supg_delta`: factor on the SUPG parameter tau.
    pub supg_delta: f64,
    /// `-ehl_pressure_step_floor`: the floor of a Newton step's nodal pressure
    /// ([`crate::reynolds::cavitation::PRESSURE_STEP_FLOOR`]); None with
    /// `-ehl_pressure_step_clip false`.
    pub pressure_step_floor: Option<f64>,
    /// `-ehl_film_limiter`: the fraction-to-the-boundary limit on the film in each step.
    pub film_limiter: bool,
    /// `-ehl_row_scaling`: each Reynolds row scaled by its diagonal at the start of a solve.
    pub row_scaling: bool,
    /// `-ehl_skip_plain`: skip plain Newton from the start and go to the continuation
    /// (tests of the continuation).
    pub skip_plain: bool,
    /// `-ehl_fail_point K`: the K-th operating point of a sweep fails (fault injection for
    /// the sweep's error handling).
    pub fail_point: Option<usize>,
    /// `-ehl_plot_font FILE`: TrueType font for the plots.
    pub plot_font: Option<String>,
    /// `-ehl_newton_stall N`: a Newton solve whose smallest residual norm over its last N
    /// iterations stays above [`NEWTON_STALL_FACTOR`] times the smallest before them stops
    /// as stalled (0: never).
    pub newton_stall: usize,
    /// `-ehl_memory_per_rank GB`: the resident memory a rank may reach, which bounds the
    /// levels of an adaptive run (`app::memory`); None: what the node has free, shared
    /// among this run's ranks on it.
    pub memory_per_rank_gb: Option<f64>,
}

impl Default for EhlOptions {
    fn default() -> Self {
        EhlOptions {
            monitor: false,
            check_jacobian: false,
            supg_delta: 1.0,
            pressure_step_floor: Some(crate::reynolds::cavitation::PRESSURE_STEP_FLOOR),
            film_limiter: true,
            row_scaling: true,
            skip_plain: false,
            fail_point: None,
            plot_font: None,
            newton_stall: NEWTON_STALL,
            memory_per_rank_gb: None,
        }
    }
}

/// Iterations over which Newton's smallest residual norm must fall by 10 %, or the solve
/// stops as stalled (the default of `-ehl_newton_stall`). On M = 1000, L = 10 at 0.0078 a an
/// alpha step plateaued at a residual of 0.15-0.2 from its third iteration and failed after
/// 30 (347 s, 11.5 s per iteration); the test stops it after 13. Every solve that converged
/// on that run (23, up to 21 iterations, the slow ones gaining 10-30 % per iteration while
/// the line search damps the steps) passes it.
pub const NEWTON_STALL: usize = 10;

/// The least decrease of Newton's smallest residual norm over the iterations of
/// `-ehl_newton_stall` before a solve stops as stalled: its norm must fall below this
/// factor times the smallest before them.
pub const NEWTON_STALL_FACTOR: f64 = 0.9;

static OPTIONS: OnceLock<EhlOptions> = OnceLock::new();

/// Reads the `-ehl_...` options from PETSc's database (after PETSc is initialised; once per
/// process, later calls keep the first values). Collective.
pub fn read(comm: petsc::ffi::MPI_Comm) -> petsc::Result<&'static EhlOptions> {
    if let Some(o) = OPTIONS.get() {
        return Ok(o);
    }
    let d = EhlOptions::default();
    let mut g = petsc::options::Group::begin(comm, "EHL solver options", "EHL")?;
    let monitor = g.bool(
        "-ehl_monitor",
        "Print Newton diagnostics per iteration (block residual norms, worst rows, film limiter, the iterate's hc and hm)",
        d.monitor,
    )?;
    let check_jacobian = g.bool(
        "-ehl_check_jacobian",
        "Check the monolithic Jacobian block by block against finite differences at the start",
        d.check_jacobian,
    )?;
    let supg_delta =
        g.real("-ehl_supg_delta", "Factor on the SUPG parameter tau of the Reynolds element", d.supg_delta)?.unwrap_or(d.supg_delta);
    let floor_default = crate::reynolds::cavitation::PRESSURE_STEP_FLOOR;
    let clip = g.bool("-ehl_pressure_step_clip", "Clip a Newton step's nodal pressure at -ehl_pressure_step_floor", true)?;
    let floor = g
        .real("-ehl_pressure_step_floor", "Lowest nodal pressure a Newton step may reach (dimensionless, P/p_H)", floor_default)?
        .unwrap_or(floor_default);
    let film_limiter = g.bool(
        "-ehl_film_limiter",
        "Limit each Newton step so that the film keeps a fifth of its thickness at every node",
        d.film_limiter,
    )?;
    let row_scaling = g.bool("-ehl_row_scaling", "Scale each Reynolds row by its diagonal at the start of a solve", d.row_scaling)?;
    let skip_plain = g.bool("-ehl_skip_plain", "Skip plain Newton from the start and go to the continuation (for tests)", d.skip_plain)?;
    let fail_point = g
        .int("-ehl_fail_point", "Make the K-th operating point of a sweep fail (fault injection, for tests)", 0)?
        .filter(|&k| k > 0)
        .map(|k| k as usize);
    let newton_stall = g
        .int(
            "-ehl_newton_stall",
            &format!(
                "Stop a Newton solve whose smallest residual norm fell by less than {:.0} % over its last N iterations (0: never)",
                100.0 * (1.0 - NEWTON_STALL_FACTOR)
            ),
            d.newton_stall as i32,
        )?
        .map_or(d.newton_stall, |n| n.max(0) as usize);
    let memory_per_rank_gb = g.real(
        "-ehl_memory_per_rank",
        "Resident memory (GB) a rank may reach: an adaptive run solves no level predicted to need more (default: the node's free memory shared among the run's ranks on it)",
        0.0,
    )?;
    let plot_font = g.string("-ehl_plot_font", "TrueType font file for the plots", crate::output::plot::FONT_PATH)?;
    g.end()?;
    if let Some(v) = memory_per_rank_gb.filter(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(petsc::PetscError {
            code: petsc::ffi::PETSC_ERR_ARG_OUTOFRANGE as i32,
            message: format!("-ehl_memory_per_rank = {v}: the memory a rank may use must be a positive number of GB"),
        });
    }
    let o = EhlOptions {
        monitor,
        check_jacobian,
        supg_delta,
        pressure_step_floor: clip.then_some(floor),
        film_limiter,
        row_scaling,
        skip_plain,
        fail_point,
        plot_font,
        newton_stall,
        memory_per_rank_gb,
    };
    Ok(OPTIONS.get_or_init(|| o))
}

/// The options read by [`read`], or the defaults if they were not read.
pub fn get() -> &'static EhlOptions {
    static DEFAULTS: OnceLock<EhlOptions> = OnceLock::new();
    OPTIONS.get().unwrap_or_else(|| DEFAULTS.get_or_init(EhlOptions::default))
}
