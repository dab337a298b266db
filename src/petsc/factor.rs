//! Why a direct linear solve failed: the KSP's reason, the preconditioner's factorisation
//! error and, for MUMPS, its INFOG(1) and INFOG(2), with what each MUMPS code means.
//!
//! SNES reports only DIVERGED_LINEAR_SOLVE. The causes differ in what helps: a MUMPS
//! workspace that the analysis underestimated (delayed pivots fill more than predicted)
//! needs a larger ICNTL(14) and the same matrix factorises; a numerically singular matrix
//! does not, whatever the workspace.
use super::error::Result;
use super::ffi;
use crate::pcall;
use std::ffi::CStr;

/// What is known about the last failed linear solve of a KSP.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearFailure {
    /// The KSP's converged reason (e.g. `DIVERGED_PC_FAILED`).
    pub ksp_reason: String,
    /// The factorisation's error, when the preconditioner is a factorisation that failed.
    pub factor_error: Option<&'static str>,
    /// MUMPS's INFOG(1) and INFOG(2), when the factorisation is MUMPS's.
    pub mumps_infog: Option<(i64, i64)>,
    /// MUMPS's ICNTL(14) (percentage of workspace added to the analysis's estimate).
    pub mumps_icntl14: Option<i64>,
}

impl LinearFailure {
    /// True when MUMPS stopped because a workspace estimated by its analysis was too small:
    /// a larger ICNTL(14) lets the same matrix factorise.
    pub fn mumps_workspace_too_small(&self) -> bool {
        self.mumps_infog.is_some_and(|(i, _)| mumps_workspace_code(i))
    }
}

impl std::fmt::Display for LinearFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "KSP {}", self.ksp_reason)?;
        if let Some(e) = self.factor_error {
            write!(f, ", factorisation {e}")?;
        }
        if let Some((i1, i2)) = self.mumps_infog {
            write!(f, ", MUMPS INFOG(1) = {i1}, INFOG(2) = {i2}: {}", mumps_meaning(i1))?;
        }
        Ok(())
    }
}

/// MUMPS error codes (INFOG(1) < 0) that mean an internal workspace sized by the analysis
/// was too small: -8, -9 (factorisation), -11, -12, -14, -15 (solve, refinement), -17, -20
/// (communication buffers). The MUMPS user guide's remedy for each is a larger ICNTL(14).
pub fn mumps_workspace_code(infog1: i64) -> bool {
    matches!(infog1, -8 | -9 | -11 | -12 | -14 | -15 | -17 | -20)
}

/// ICNTL(14) a factorisation that failed for want of workspace is given: four times
/// MUMPS's default of 20 %, once. Where that is not enough the matrix itself is the
/// trouble: at M = 100, L = 20 on the 0.0625 a level the same Jacobian (alpha step, ninth
/// iteration) lacked 40, 64 and 257 million entries at 20, 80 and 320 %, and 1,280 % ran the
/// machine out of memory (the kernel killed the run, with no result).
pub const MUMPS_WORKSPACE_PERCENT: i64 = 80;

/// MUMPS error codes that mean the memory itself ran out: -13 (an allocation failed) and -19
/// (the limit ICNTL(23)). No other matrix of the same pattern factorises either.
pub fn mumps_memory_code(infog1: i64) -> bool {
    matches!(infog1, -13 | -19)
}

/// What a MUMPS INFOG(1) code means (MUMPS 5.5 user guide, section "Error diagnostics").
pub fn mumps_meaning(infog1: i64) -> &'static str {
    match infog1 {
        0 => "no error",
        -8 | -14 | -15 => "an integer workspace estimated by the analysis was too small",
        -9 | -11 | -12 => "the real workspace estimated by the analysis was too small (delayed pivots)",
        -10 => "the matrix is numerically singular",
        -13 => "a memory allocation failed (the machine's memory)",
        -17 | -20 => "a communication buffer estimated by the analysis was too small",
        -19 => "the memory limit ICNTL(23) is too small",
        i if i > 0 => "a warning",
        _ => "an error (see the MUMPS user guide)",
    }
}

/// The failure of the last solve of `ksp` (collective: every rank gets the same answer for
/// MUMPS, whose INFOG is global).
pub(crate) fn last_failure(ksp: ffi::KSP) -> Result<LinearFailure> {
    let mut reason: ffi::KSPConvergedReason = 0;
    pcall!(ffi::KSPGetConvergedReason(ksp, &mut reason))?;
    let mut s: *const std::os::raw::c_char = std::ptr::null();
    pcall!(ffi::KSPGetConvergedReasonString(ksp, &mut s))?;
    let ksp_reason = if s.is_null() { reason.to_string() } else { unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned() };
    let mut pc: ffi::PC = std::ptr::null_mut();
    pcall!(ffi::KSPGetPC(ksp, &mut pc))?;
    let mut failed: ffi::PCFailedReason = 0;
    pcall!(ffi::PCGetFailedReason(pc, &mut failed))?;
    let factor_error = match failed {
        ffi::PCFailedReason_PC_FACTOR_STRUCT_ZEROPIVOT => Some("structural zero pivot"),
        ffi::PCFailedReason_PC_FACTOR_NUMERIC_ZEROPIVOT => Some("numerical zero pivot"),
        ffi::PCFailedReason_PC_FACTOR_OUTMEMORY => Some("out of memory"),
        ffi::PCFailedReason_PC_FACTOR_OTHER => Some("failed"),
        _ => None,
    };
    let mut ty: ffi::PCType = std::ptr::null();
    pcall!(ffi::PCGetType(pc, &mut ty))?;
    let pc_type = if ty.is_null() { String::new() } else { unsafe { CStr::from_ptr(ty) }.to_string_lossy().into_owned() };
    let (mut mumps_infog, mut mumps_icntl14) = (None, None);
    if pc_type == "lu" || pc_type == "cholesky" {
        let mut f: ffi::Mat = std::ptr::null_mut();
        pcall!(ffi::PCFactorGetMatrix(pc, &mut f))?;
        let mut st: ffi::MatSolverType = std::ptr::null();
        if !f.is_null() {
            pcall!(ffi::MatFactorGetSolverType(f, &mut st))?;
        }
        if !st.is_null() && unsafe { CStr::from_ptr(st) }.to_bytes() == b"mumps" {
            let (mut i1, mut i2, mut c14): (ffi::PetscInt, ffi::PetscInt, ffi::PetscInt) = (0, 0, 0);
            pcall!(ffi::MatMumpsGetInfog(f, 1, &mut i1))?;
            pcall!(ffi::MatMumpsGetInfog(f, 2, &mut i2))?;
            pcall!(ffi::MatMumpsGetIcntl(f, 14, &mut c14))?;
            mumps_infog = Some((i1 as i64, i2 as i64));
            mumps_icntl14 = Some(c14 as i64);
        }
    }
    Ok(LinearFailure { ksp_reason, factor_error, mumps_infog, mumps_icntl14 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workspace_codes_are_told_from_singular_matrices_and_real_memory() {
        for c in [-8, -9, -11, -12, -14, -15, -17, -20] {
            assert!(mumps_workspace_code(c), "{c}");
        }
        for c in [0, 1, -10, -13, -19, -38] {
            assert!(!mumps_workspace_code(c), "{c}");
        }
        let f = LinearFailure {
            ksp_reason: "DIVERGED_PC_FAILED".into(),
            factor_error: Some("out of memory"),
            mumps_infog: Some((-9, 1234)),
            mumps_icntl14: Some(20),
        };
        assert!(f.mumps_workspace_too_small());
        assert!(f.to_string().contains("INFOG(1) = -9") && f.to_string().contains("delayed pivots"), "{f}");
        assert!(mumps_meaning(-10).contains("singular"));
        assert!(mumps_memory_code(-13) && mumps_memory_code(-19) && !mumps_memory_code(-9) && !mumps_memory_code(-10));
    }
}
