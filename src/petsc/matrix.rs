//! RAII wrapper of a distributed sparse PETSc matrix (AIJ) with exact preallocation.
use super::error::{rust_error, Result};
use super::ffi;
use crate::pcall;

/// A square distributed AIJ matrix (`MATAIJ`: SeqAIJ on one rank, MPIAIJ on several).
pub struct Matrix {
    pub(crate) raw: ffi::Mat,
}

impl Matrix {
    /// An AIJ matrix with `local_rows` rows on this rank, preallocated exactly:
    /// `d_nnz[i]` / `o_nnz[i]` = non-zeros of local row i inside / outside the diagonal block.
    /// A later insertion outside this pattern is an error (so the preallocation is verified).
    pub fn new_aij(comm: ffi::MPI_Comm, local_rows: usize, d_nnz: &[i32], o_nnz: &[i32]) -> Result<Matrix> {
        if d_nnz.len() != local_rows || o_nnz.len() != local_rows {
            return Err(rust_error("Matrix::new_aij: nnz arrays must have one entry per local row"));
        }
        let mut raw: ffi::Mat = std::ptr::null_mut();
        pcall!(ffi::MatCreate(comm, &mut raw))?;
        let m = Matrix { raw };
        let n = local_rows as ffi::PetscInt;
        pcall!(ffi::MatSetSizes(m.raw, n, n, ffi::PETSC_DETERMINE, ffi::PETSC_DETERMINE))?;
        pcall!(ffi::MatSetType(m.raw, ffi::MATAIJ.as_ptr() as *const _))?;
        pcall!(ffi::MatSeqAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr()))?;
        pcall!(ffi::MatMPIAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()))?;
        pcall!(ffi::MatSetOption(m.raw, ffi::MatOption_MAT_NEW_NONZERO_ALLOCATION_ERR, ffi::PetscBool_PETSC_TRUE))?;
        Ok(m)
    }

    /// Adds a dense block `vals` (row-major, rows.len() x cols.len()) at global indices.
    /// Negative indices are ignored by PETSc (used for eliminated Dirichlet dofs).
    pub fn add_values(&self, rows: &[i32], cols: &[i32], vals: &[f64]) -> Result<()> {
        if vals.len() != rows.len() * cols.len() {
            return Err(rust_error("Matrix::add_values: block size mismatch"));
        }
        pcall!(ffi::MatSetValues(
            self.raw,
            rows.len() as ffi::PetscInt,
            rows.as_ptr(),
            cols.len() as ffi::PetscInt,
            cols.as_ptr(),
            vals.as_ptr(),
            ffi::InsertMode_ADD_VALUES
        ))
    }

    /// Final assembly (communicates off-rank entries).
    pub fn assemble(&self) -> Result<()> {
        pcall!(ffi::MatAssemblyBegin(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY))?;
        pcall!(ffi::MatAssemblyEnd(self.raw, ffi::MatAssemblyType_MAT_FINAL_ASSEMBLY))
    }

    /// Sets all stored entries to zero, keeping the pattern.
    pub fn zero(&self) -> Result<()> {
        pcall!(ffi::MatZeroEntries(self.raw))
    }

    /// Marks the matrix symmetric (lets solvers exploit it).
    pub fn set_symmetric(&self, yes: bool) -> Result<()> {
        let b = if yes { ffi::PetscBool_PETSC_TRUE } else { ffi::PetscBool_PETSC_FALSE };
        pcall!(ffi::MatSetOption(self.raw, ffi::MatOption_MAT_SYMMETRIC, b))
    }

    /// y = A x.
    pub fn mult(&self, x: &super::Vector, y: &super::Vector) -> Result<()> {
        pcall!(ffi::MatMult(self.raw, x.raw, y.raw))
    }

    /// Global number of stored non-zeros.
    pub fn nonzeros(&self) -> Result<f64> {
        let mut info = ffi::MatInfo::default();
        pcall!(ffi::MatGetInfo(self.raw, ffi::MatInfoType_MAT_GLOBAL_SUM, &mut info))?;
        Ok(info.nz_used)
    }

    /// Raw handle for FFI calls.
    pub fn raw(&self) -> ffi::Mat {
        self.raw
    }
}

impl Drop for Matrix {
    fn drop(&mut self) {
        unsafe { ffi::MatDestroy(&mut self.raw) };
    }
}
