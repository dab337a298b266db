//! RAII wrapper of a PETSc linear solver (KSP), MUMPS LU by default.
use super::error::{rust_error, Result};
use super::{ffi, options, Matrix, Vector};
use crate::pcall;
use std::ffi::CStr;

/// Solver defaults ehl-petsc sets unless the user gave the option: a direct MUMPS LU
/// solve with the PORD ordering (the fastest of Debian's built-in MUMPS orderings for 3D
/// elasticity on this kind of machine).
pub fn set_direct_solver_defaults(prefix: &str) -> Result<()> {
    options::set_default(&format!("-{prefix}ksp_type"), "preonly")?;
    options::set_default(&format!("-{prefix}pc_type"), "lu")?;
    options::set_ours(&format!("-{prefix}pc_factor_mat_solver_type"), "mumps")?;
    options::set_default("-mat_mumps_icntl_7", "4")?;
    Ok(())
}

/// Direct-solver defaults for the matrix `a`, by its type: PETSc's own LAPACK LU for a
/// sequential dense matrix, ScaLAPACK for `MATSCALAPACK`, MUMPS otherwise. The user's
/// flags override each of them.
pub fn set_direct_solver_defaults_for(prefix: &str, a: &Matrix) -> Result<()> {
    options::set_default(&format!("-{prefix}ksp_type"), "preonly")?;
    options::set_default(&format!("-{prefix}pc_type"), "lu")?;
    let solver = match a.type_name()?.as_str() {
        "seqdense" => "petsc",
        "scalapack" => "scalapack",
        _ => "mumps",
    };
    options::set_ours(&format!("-{prefix}pc_factor_mat_solver_type"), solver)
}

/// A Krylov solver context (any KSP/PC through PETSc options).
pub struct Ksp {
    raw: ffi::KSP,
}

impl Ksp {
    /// Wraps a solver the caller holds a reference to (released on drop).
    pub(super) fn from_raw(raw: ffi::KSP) -> Ksp {
        Ksp { raw }
    }

    /// Creates a solver for operator `a`, configured from the options database.
    pub fn new(comm: ffi::MPI_Comm, a: &Matrix) -> Result<Ksp> {
        Ksp::with_prefix(comm, a, "")
    }

    /// Creates a solver for operator `a` that reads its options under `prefix`
    /// (`-{prefix}ksp_type`, `-{prefix}mat_mumps_icntl_7`, ...).
    pub fn with_prefix(comm: ffi::MPI_Comm, a: &Matrix, prefix: &str) -> Result<Ksp> {
        let mut raw: ffi::KSP = std::ptr::null_mut();
        pcall!(ffi::KSPCreate(comm, &mut raw))?;
        let k = Ksp { raw };
        if !prefix.is_empty() {
            let c = std::ffi::CString::new(prefix).map_err(|_| rust_error(format!("options prefix {prefix:?} contains a NUL byte")))?;
            pcall!(ffi::KSPSetOptionsPrefix(k.raw, c.as_ptr()))?;
        }
        pcall!(ffi::KSPSetOperators(k.raw, a.raw, a.raw))?;
        pcall!(ffi::KSPSetFromOptions(k.raw))?;
        Ok(k)
    }

    /// Solves A x = b and checks the converged reason (a failed solve is an error).
    pub fn solve(&self, b: &Vector, x: &Vector) -> Result<usize> {
        pcall!(ffi::KSPSolve(self.raw, b.raw, x.raw))?;
        self.outcome("linear solve")
    }

    /// The iterations of the last solve, or an error naming why it failed (the KSP reason
    /// and the factorisation's own cause, MUMPS's INFOG, when there is one).
    fn outcome(&self, what: &str) -> Result<usize> {
        let mut reason: ffi::KSPConvergedReason = 0;
        pcall!(ffi::KSPGetConvergedReason(self.raw, &mut reason))?;
        let mut its: ffi::PetscInt = 0;
        pcall!(ffi::KSPGetIterationNumber(self.raw, &mut its))?;
        if reason < 0 {
            let why = super::factor::last_failure(self.raw).map_or_else(|_| reason.to_string(), |f| f.to_string());
            return Err(rust_error(format!("{what} failed: {why} after {its} iterations")));
        }
        Ok(its as usize)
    }

    /// Solves A x = b once with a fresh solver for `a` under `prefix`; when MUMPS stops
    /// because a workspace its analysis estimated was too small (INFOG(1) = -9 and the like:
    /// it happens to an elastic Cholesky on some graded meshes), once more with
    /// `-{prefix}mat_mumps_icntl_14` at [`super::factor::MUMPS_WORKSPACE_PERCENT`], unless
    /// the user chose that option.
    pub fn solve_once_more_with_workspace(comm: ffi::MPI_Comm, a: &Matrix, prefix: &str, b: &Vector, x: &Vector) -> Result<()> {
        let ksp = Ksp::with_prefix(comm, a, prefix)?;
        let Err(e) = ksp.solve(b, x) else { return Ok(()) };
        let key = format!("-{prefix}mat_mumps_icntl_14");
        if !super::factor::last_failure(ksp.raw)?.mumps_workspace_too_small() || options::user_set(&key)? {
            return Err(e);
        }
        drop(ksp);
        options::set_ours(&key, &super::factor::MUMPS_WORKSPACE_PERCENT.to_string())?;
        Ksp::with_prefix(comm, a, prefix)?.solve(b, x).map(|_| ())
    }

    /// Solves A^T x = b (the adjoint; MUMPS solves it with the same factors) and checks
    /// the converged reason.
    pub fn solve_transpose(&self, b: &Vector, x: &Vector) -> Result<()> {
        pcall!(ffi::KSPSolveTranspose(self.raw, b.raw, x.raw))?;
        self.outcome("transposed linear solve").map(|_| ())
    }

    /// Makes this solver GMRES to the relative tolerance `rtol` (at most `max_it`
    /// iterations) on its operator, preconditioned by the factorisation it holds, which is
    /// not made again when the operator's values change: solves with a matrix near the one
    /// factorised.
    pub fn krylov_on_present_factor(&self, rtol: f64, max_it: usize) -> Result<()> {
        pcall!(ffi::KSPSetType(self.raw, ffi::KSPGMRES.as_ptr() as *const _))?;
        pcall!(ffi::KSPSetReusePreconditioner(self.raw, ffi::PetscBool_PETSC_TRUE))?;
        // A Newton solver's KSP carries SNES's Eisenstat-Walker hooks, which would reset
        // the tolerance below to the forcing term of its last step.
        pcall!(ffi::KSPSetPreSolve(self.raw, None, std::ptr::null_mut()))?;
        pcall!(ffi::KSPSetPostSolve(self.raw, None, std::ptr::null_mut()))?;
        let default = ffi::PETSC_DEFAULT as f64;
        pcall!(ffi::KSPSetTolerances(self.raw, rtol, default, default, max_it as ffi::PetscInt))
    }

    /// The iterations of the last solve.
    pub fn iterations(&self) -> Result<usize> {
        let mut its: ffi::PetscInt = 0;
        pcall!(ffi::KSPGetIterationNumber(self.raw, &mut its))?;
        Ok(its as usize)
    }

    /// Memory MUMPS used for the factorisation (MB, summed over the ranks: INFOG(22)),
    /// after a solve; None when the preconditioner is not a MUMPS factorisation.
    pub fn mumps_factor_mb(&self) -> Option<f64> {
        let mut pc: ffi::PC = std::ptr::null_mut();
        pcall!(ffi::KSPGetPC(self.raw, &mut pc)).ok()?;
        let mut f: ffi::Mat = std::ptr::null_mut();
        pcall!(ffi::PCFactorGetMatrix(pc, &mut f)).ok()?;
        let mut mtype: ffi::MatSolverType = std::ptr::null();
        pcall!(ffi::MatFactorGetSolverType(f, &mut mtype)).ok()?;
        if mtype.is_null() || unsafe { CStr::from_ptr(mtype) }.to_bytes() != b"mumps" {
            return None;
        }
        let mut v: ffi::PetscInt = 0;
        pcall!(ffi::MatMumpsGetInfog(f, 22, &mut v)).ok()?;
        Some(v as f64)
    }
}

impl Drop for Ksp {
    fn drop(&mut self) {
        unsafe { ffi::KSPDestroy(&mut self.raw) };
    }
}
