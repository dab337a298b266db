//! RAII wrapper of PETSc's nonlinear solver (SNES) driving a Rust [`Problem`].
//!
//! In the callbacks the current iterate is gathered on every rank (the meshes are
//! replicated), the problem adds its own elements' contributions to the distributed
//! residual or Jacobian, and PETSc assembles them. A Rust error inside a callback becomes a
//! PETSc error code (never a panic across the FFI boundary); an unphysical iterate (for
//! example a negative film) is reported to SNES as a domain error so the line search
//! backtracks.
use super::error::{check, rust_error, PetscError, Result};
use super::{ffi, Matrix, Vector};
use crate::pcall;
use std::ffi::CStr;
use std::os::raw::c_void;

/// Outcome of a residual evaluation.
pub enum Eval {
    /// The residual was assembled.
    Ok,
    /// The iterate is outside the physical domain (e.g. negative film thickness).
    Domain(String),
}

/// A nonlinear system F(x) = 0 with its exact Jacobian.
pub trait Problem {
    /// Adds this rank's contributions to `f` (zeroed beforehand); `x` is the whole iterate.
    fn residual(&mut self, x: &[f64], f: &Vector) -> Result<Eval>;
    /// Fills `j` (this rank's contributions; the problem decides what to zero); `x` is the whole iterate.
    fn jacobian(&mut self, x: &[f64], j: &Matrix) -> Result<()>;
    /// Step limiter called before each line search with the iterate `x` and the Newton
    /// direction `y` (the update is x - lambda y): returns a factor in (0, 1] that scales
    /// y, e.g. to keep a physical quantity positive (fraction to the boundary).
    fn limit_step(&mut self, _x: &[f64], _y: &[f64]) -> Result<f64> {
        Ok(1.0)
    }
    /// Component-wise change of the Newton direction `y`, called before [`Problem::limit_step`]
    /// (e.g. clipping one unknown's update at a bound); returns how many components changed.
    /// Every rank gets the same whole `x` and `y` and must change `y` the same way.
    fn clip_step(&mut self, _x: &[f64], _y: &mut [f64]) -> Result<usize> {
        Ok(0)
    }
}

struct Context<'a> {
    problem: &'a mut dyn Problem,
    domain_error: Option<String>,
    error: Option<PetscError>,
}

/// Outcome of a nonlinear solve.
#[derive(Debug, Clone)]
pub struct SolveReport {
    pub converged: bool,
    pub reason: String,
    pub reason_code: i32,
    pub iterations: usize,
    pub linear_iterations: usize,
    pub residual_norm: f64,
    /// The residual norm at the start (before the first step).
    pub initial_residual_norm: f64,
    pub domain_error: Option<String>,
    /// The stall test stopped the solve ([`Snes::set_stall_test`]; the reason is then
    /// DIVERGED_MAX_IT with "stalled" in its text).
    pub stalled: bool,
}

/// A PETSc SNES (Newton with line search by default; everything overridable by options).
pub struct Snes {
    raw: ffi::SNES,
    /// The residual norms of the last solve (PETSc writes them here while it solves), and
    /// their linear iteration counts.
    history: Vec<ffi::PetscReal>,
    history_its: Vec<ffi::PetscInt>,
    /// The stall test's state (boxed: PETSc holds its address), when one is set.
    stall: Option<Box<StallTest>>,
}

/// A solve stops as stalled when its smallest residual norm over the last `window`
/// iterations is above `factor` times the smallest before them ([`stalled`]).
struct StallTest {
    window: usize,
    factor: f64,
    norms: Vec<f64>,
    stalled: bool,
}

/// Whether the residual norms `norms` (one per iteration, the start first) have stalled:
/// the smallest of the last `window` is above `factor` times the smallest before them.
pub fn stalled(norms: &[f64], window: usize, factor: f64) -> bool {
    let n = norms.len();
    if window == 0 || n <= window {
        return false;
    }
    let least = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    least(&norms[n - window..]) > factor * least(&norms[..n - window])
}

/// PETSc's default convergence test, then the stall test of [`stalled`].
unsafe extern "C" fn converged_or_stalled(
    snes: ffi::SNES,
    it: ffi::PetscInt,
    xnorm: ffi::PetscReal,
    snorm: ffi::PetscReal,
    fnorm: ffi::PetscReal,
    reason: *mut ffi::SNESConvergedReason,
    ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    let code = ffi::SNESConvergedDefault(snes, it, xnorm, snorm, fnorm, reason, std::ptr::null_mut());
    if code != 0 {
        return code;
    }
    let t = &mut *(ctx as *mut StallTest);
    if it == 0 {
        t.norms.clear();
        t.stalled = false;
    }
    t.norms.push(fnorm);
    if *reason == ffi::SNESConvergedReason_SNES_CONVERGED_ITERATING && stalled(&t.norms, t.window, t.factor) {
        // Out of useful iterations, as at the iteration budget: callers treat both alike.
        *reason = ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT;
        t.stalled = true;
    }
    0
}

/// Residual norms kept of one solve (more than any Newton iteration budget used).
const HISTORY: usize = 1000;

unsafe extern "C" fn form_function(snes: ffi::SNES, x: ffi::Vec, f: ffi::Vec, ctx: *mut c_void) -> ffi::PetscErrorCode {
    let ctx = &mut *(ctx as *mut Context);
    // Every rank evaluates the residual together: the place to stop on SIGINT/SIGTERM.
    let sig = crate::interrupt::collective_signal();
    if sig != 0 {
        ctx.error = Some(rust_error(crate::interrupt::message(sig, "the Newton solve")));
        return ffi::PETSC_ERR_LIB as ffi::PetscErrorCode;
    }
    let run = || -> Result<Eval> {
        let xv = std::mem::ManuallyDrop::new(Vector { raw: x });
        let fv = std::mem::ManuallyDrop::new(Vector { raw: f });
        let all = xv.gather_all()?;
        fv.set_all(0.0)?;
        let r = ctx.problem.residual(&all, &fv)?;
        fv.assemble()?;
        Ok(r)
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(Ok(Eval::Ok)) => 0,
        Ok(Ok(Eval::Domain(msg))) => {
            ctx.domain_error = Some(msg);
            ffi::SNESSetFunctionDomainError(snes)
        }
        Ok(Err(e)) => {
            ctx.error = Some(e);
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
        Err(_) => {
            ctx.error = Some(rust_error("panic in residual evaluation"));
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
    }
}

unsafe extern "C" fn form_jacobian(_snes: ffi::SNES, x: ffi::Vec, j: ffi::Mat, _p: ffi::Mat, ctx: *mut c_void) -> ffi::PetscErrorCode {
    let ctx = &mut *(ctx as *mut Context);
    let run = || -> Result<()> {
        let xv = std::mem::ManuallyDrop::new(Vector { raw: x });
        let jm = std::mem::ManuallyDrop::new(Matrix { raw: j });
        let all = xv.gather_all()?;
        ctx.problem.jacobian(&all, &jm)?;
        jm.assemble()
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(Ok(())) => 0,
        Ok(Err(e)) => {
            ctx.error = Some(e);
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
        Err(_) => {
            ctx.error = Some(rust_error("panic in Jacobian evaluation"));
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
    }
}

unsafe extern "C" fn precheck(
    _ls: ffi::SNESLineSearch,
    x: ffi::Vec,
    y: ffi::Vec,
    changed: *mut ffi::PetscBool,
    ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    let ctx = &mut *(ctx as *mut Context);
    let run = || -> Result<bool> {
        let xv = std::mem::ManuallyDrop::new(Vector { raw: x });
        let yv = std::mem::ManuallyDrop::new(Vector { raw: y });
        let (xa, mut ya) = (xv.gather_all()?, yv.gather_all()?);
        let clipped = ctx.problem.clip_step(&xa, &mut ya)?;
        if clipped > 0 {
            let (lo, hi) = yv.ownership()?;
            yv.set_local_values(&ya[lo..hi])?;
        }
        let s = ctx.problem.limit_step(&xa, &ya)?;
        if s < 1.0 {
            pcall!(ffi::VecScale(y, s))?;
        }
        Ok(clipped > 0 || s < 1.0)
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(run)) {
        Ok(Ok(ch)) => {
            *changed = if ch { ffi::PetscBool_PETSC_TRUE } else { ffi::PetscBool_PETSC_FALSE };
            0
        }
        Ok(Err(e)) => {
            ctx.error = Some(e);
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
        Err(_) => {
            ctx.error = Some(rust_error("panic in the step limiter"));
            ffi::PETSC_ERR_LIB as ffi::PetscErrorCode
        }
    }
}

impl Snes {
    /// A SNES configured from the options database (with `prefix`, e.g. "" or "ehl_").
    pub fn new(comm: ffi::MPI_Comm, prefix: &str) -> Result<Snes> {
        let mut raw: ffi::SNES = std::ptr::null_mut();
        pcall!(ffi::SNESCreate(comm, &mut raw))?;
        let mut s = Snes { raw, history: vec![0.0; HISTORY], history_its: vec![0; HISTORY], stall: None };
        // The buffers live as long as the SNES, which writes into them on every solve.
        pcall!(ffi::SNESSetConvergenceHistory(
            s.raw,
            s.history.as_mut_ptr(),
            s.history_its.as_mut_ptr(),
            HISTORY as ffi::PetscInt,
            ffi::PetscBool_PETSC_TRUE
        ))?;
        if !prefix.is_empty() {
            let p = std::ffi::CString::new(prefix).unwrap();
            pcall!(ffi::SNESSetOptionsPrefix(s.raw, p.as_ptr()))?;
        }
        Ok(s)
    }

    /// Stops a solve as stalled (reason DIVERGED_MAX_IT, "stalled" in its report) when its
    /// smallest residual norm over the last `window` iterations is above `factor` times the
    /// smallest before them ([`stalled`]); `window` 0 removes the test.
    pub fn set_stall_test(&mut self, window: usize, factor: f64) -> Result<()> {
        if window == 0 {
            pcall!(ffi::SNESSetConvergenceTest(self.raw, Some(ffi::SNESConvergedDefault), std::ptr::null_mut(), None))?;
            self.stall = None;
            return Ok(());
        }
        let mut t = Box::new(StallTest { window, factor, norms: Vec::new(), stalled: false });
        let ctx = t.as_mut() as *mut StallTest as *mut c_void;
        pcall!(ffi::SNESSetConvergenceTest(self.raw, Some(converged_or_stalled), ctx, None))?;
        self.stall = Some(t);
        Ok(())
    }

    /// Solves F(x) = 0 from the initial guess in `x`, with Jacobian storage `j`.
    /// Options are read here (so defaults set before this call apply).
    pub fn solve(&self, problem: &mut dyn Problem, x: &Vector, j: &Matrix) -> Result<SolveReport> {
        let r = x.duplicate()?;
        let mut ctx = Context { problem, domain_error: None, error: None };
        let ctxp = &mut ctx as *mut Context as *mut c_void;
        pcall!(ffi::SNESSetFunction(self.raw, r.raw, Some(form_function), ctxp))?;
        pcall!(ffi::SNESSetJacobian(self.raw, j.raw, j.raw, Some(form_jacobian), ctxp))?;
        pcall!(ffi::SNESSetFromOptions(self.raw))?;
        let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
        pcall!(ffi::SNESGetLineSearch(self.raw, &mut ls))?;
        pcall!(ffi::SNESLineSearchSetPreCheck(ls, Some(precheck), ctxp))?;
        let code = unsafe { ffi::SNESSolve(self.raw, std::ptr::null_mut(), x.raw) };
        // Detach the callbacks' context before it goes out of scope.
        let _ = unsafe { ffi::SNESSetFunction(self.raw, r.raw, None, std::ptr::null_mut()) };
        let _ = unsafe { ffi::SNESLineSearchSetPreCheck(ls, None, std::ptr::null_mut()) };
        if let Some(e) = ctx.error.take() {
            let _ = check(code);
            return Err(e);
        }
        check(code)?;
        let mut reason: ffi::SNESConvergedReason = 0;
        pcall!(ffi::SNESGetConvergedReason(self.raw, &mut reason))?;
        let mut s: *const std::os::raw::c_char = std::ptr::null();
        pcall!(ffi::SNESGetConvergedReasonString(self.raw, &mut s))?;
        let mut reason_name = if s.is_null() { reason.to_string() } else { unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned() };
        let stalled = self.stall.as_ref().is_some_and(|t| t.stalled);
        if let Some(t) = self.stall.as_ref().filter(|t| t.stalled) {
            reason_name = format!(
                "{reason_name}: stalled (the residual norm fell by less than {:.0} % in {} iterations)",
                100.0 * (1.0 - t.factor),
                t.window
            );
        }
        let (mut its, mut lits): (ffi::PetscInt, ffi::PetscInt) = (0, 0);
        pcall!(ffi::SNESGetIterationNumber(self.raw, &mut its))?;
        pcall!(ffi::SNESGetLinearSolveIterations(self.raw, &mut lits))?;
        let mut norm = 0.0;
        pcall!(ffi::SNESGetFunctionNorm(self.raw, &mut norm))?;
        let (mut kept, mut kept_its, mut n_kept): (*mut ffi::PetscReal, *mut ffi::PetscInt, ffi::PetscInt) =
            (std::ptr::null_mut(), std::ptr::null_mut(), 0);
        pcall!(ffi::SNESGetConvergenceHistory(self.raw, &mut kept, &mut kept_its, &mut n_kept))?;
        let initial = if n_kept > 0 { self.history[0] } else { norm };
        Ok(SolveReport {
            converged: reason > 0,
            reason: reason_name,
            reason_code: reason,
            iterations: its as usize,
            linear_iterations: lits as usize,
            residual_norm: norm,
            initial_residual_norm: initial,
            domain_error: ctx.domain_error.take(),
            stalled,
        })
    }

    /// Why the last linear solve failed (after a DIVERGED_LINEAR_SOLVE).
    pub fn linear_failure(&self) -> Result<super::factor::LinearFailure> {
        let mut ksp: ffi::KSP = std::ptr::null_mut();
        pcall!(ffi::SNESGetKSP(self.raw, &mut ksp))?;
        super::factor::last_failure(ksp)
    }

    /// The Krylov solver of the Newton steps, with the factorisation it last made (a new
    /// reference: it outlives this SNES if kept).
    pub fn ksp(&self) -> Result<super::Ksp> {
        let mut ksp: ffi::KSP = std::ptr::null_mut();
        pcall!(ffi::SNESGetKSP(self.raw, &mut ksp))?;
        pcall!(ffi::PetscObjectReference(ksp as ffi::PetscObject))?;
        Ok(super::Ksp::from_raw(ksp))
    }

    /// Raw handle for FFI calls.
    pub fn raw(&self) -> ffi::SNES {
        self.raw
    }
}

impl Drop for Snes {
    fn drop(&mut self) {
        unsafe { ffi::SNESDestroy(&mut self.raw) };
    }
}

#[cfg(test)]
mod tests {
    use super::stalled;

    #[test]
    fn a_plateau_stalls_and_a_slow_descent_does_not() {
        // M = 1000, L = 10 at 0.0078 a: the alpha step that failed after 30 iterations
        // (its first 14 residual norms) stalls at iteration 13; the step that converged in
        // 21 iterations on the level before never does.
        let failed = [0.2258, 0.1802, 0.1774, 0.1489, 0.1507, 0.1511, 0.1459, 0.1740, 0.1787, 0.1806, 0.1752, 0.1720, 0.1632, 0.2150];
        let first = (1..=failed.len()).find(|&n| stalled(&failed[..n], 10, 0.9));
        assert_eq!(first, Some(14));
        let slow = [
            0.2660, 0.2410, 0.2189, 0.2143, 0.1577, 0.1483, 0.1341, 0.1006, 0.0936, 0.0906, 0.0683, 0.0535, 0.0450, 0.0234, 0.0162, 0.0126,
            1.97e-3, 1.36e-3, 8.75e-4, 5.67e-5, 6.68e-6, 1.24e-7,
        ];
        assert!((1..=slow.len()).all(|n| !stalled(&slow[..n], 10, 0.9)));
        // Too few iterations to judge, or the test off.
        assert!(!stalled(&failed[..10], 10, 0.9) && !stalled(&failed, 0, 0.9));
    }
}
