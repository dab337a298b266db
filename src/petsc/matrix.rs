//! RAII wrapper of a distributed sparse PETSc matrix (AIJ) with exact preallocation.
use super::error::{rust_error, Result};
use super::ffi;
use crate::pcall;
use std::ffi::CStr;

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

    /// A square dense matrix with `local_rows` rows on this rank, for a Jacobian that is
    /// dense by nature (the condensed EHL system). One rank: `MATSEQDENSE`, factorised by
    /// LAPACK (PETSc's own LU); several: `MATSCALAPACK` (2D block-cyclic, factorised by
    /// ScaLAPACK; entries set off the rank that stores them travel through the stash at
    /// assembly, see [`Matrix::dense_fill_block`]).
    /// `MatSetFromOptions` with the prefix `prefix` lets the user pick another type
    /// (`-{prefix}mat_type aij` and a sparse direct solver); for a sparse type the
    /// preallocation `d_nnz`, `o_nnz` applies.
    pub fn new_dense(comm: ffi::MPI_Comm, local_rows: usize, prefix: &CStr, d_nnz: &[i32], o_nnz: &[i32]) -> Result<Matrix> {
        let mut size = 0;
        unsafe { mpi::ffi::MPI_Comm_size(comm, &mut size) };
        let mut raw: ffi::Mat = std::ptr::null_mut();
        pcall!(ffi::MatCreate(comm, &mut raw))?;
        let m = Matrix { raw };
        let n = local_rows as ffi::PetscInt;
        pcall!(ffi::MatSetSizes(m.raw, n, n, ffi::PETSC_DETERMINE, ffi::PETSC_DETERMINE))?;
        let ty = if size > 1 { ffi::MATSCALAPACK.as_ptr() } else { ffi::MATSEQDENSE.as_ptr() };
        pcall!(ffi::MatSetType(m.raw, ty as *const _))?;
        pcall!(ffi::MatSetOptionsPrefix(m.raw, prefix.as_ptr()))?;
        pcall!(ffi::MatSetFromOptions(m.raw))?;
        // Ignored by the dense types; exact for AIJ.
        pcall!(ffi::MatSeqAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr()))?;
        pcall!(ffi::MatMPIAIJSetPreallocation(m.raw, 0, d_nnz.as_ptr(), 0, o_nnz.as_ptr()))?;
        pcall!(ffi::MatSetUp(m.raw))?;
        Ok(m)
    }

    /// The matrix type name (`seqdense`, `scalapack`, `mpiaij`, ...).
    pub fn type_name(&self) -> Result<String> {
        let mut t: ffi::MatType = std::ptr::null();
        pcall!(ffi::MatGetType(self.raw, &mut t))?;
        Ok(unsafe { CStr::from_ptr(t) }.to_string_lossy().into_owned())
    }

    /// Adds a dense block `vals` (row-major, rows.len() x cols.len()) at global indices.
    /// Negative indices are ignored by PETSc (used for eliminated Dirichlet dofs).
    pub fn add_values(&self, rows: &[i32], cols: &[i32], vals: &[f64]) -> Result<()> {
        self.put_values(rows, cols, vals, ffi::InsertMode_ADD_VALUES, "add_values")
    }

    /// Sets (overwrites) a dense block `vals` (row-major, rows.len() x cols.len()).
    pub fn set_values(&self, rows: &[i32], cols: &[i32], vals: &[f64]) -> Result<()> {
        self.put_values(rows, cols, vals, ffi::InsertMode_INSERT_VALUES, "set_values")
    }

    fn put_values(&self, rows: &[i32], cols: &[i32], vals: &[f64], mode: ffi::InsertMode, what: &str) -> Result<()> {
        if vals.len() != rows.len() * cols.len() {
            return Err(rust_error(format!("Matrix::{what}: block size mismatch")));
        }
        pcall!(ffi::MatSetValues(
            self.raw,
            rows.len() as ffi::PetscInt,
            rows.as_ptr(),
            cols.len() as ffi::PetscInt,
            cols.as_ptr(),
            vals.as_ptr(),
            mode
        ))
    }

    /// The (rows, columns) block of a dense matrix whose entries this rank stores: for
    /// `MATSCALAPACK` its share of the 2D block-cyclic distribution (filling exactly that
    /// block sends nothing at assembly); for every other type the owned rows and all
    /// `n` columns.
    pub fn dense_fill_block(&self, n: usize) -> Result<(Vec<usize>, Vec<usize>)> {
        let all: Vec<usize> = (0..n).collect();
        if self.type_name()? != "scalapack" {
            let (mut lo, mut hi) = (0, 0);
            pcall!(ffi::MatGetOwnershipRange(self.raw, &mut lo, &mut hi))?;
            return Ok(((lo as usize..hi as usize).collect(), all));
        }
        let (mut ris, mut cis): (ffi::IS, ffi::IS) = (std::ptr::null_mut(), std::ptr::null_mut());
        pcall!(ffi::MatGetOwnershipIS(self.raw, &mut ris, &mut cis))?;
        let read = |is: ffi::IS| -> Result<Vec<usize>> {
            let mut len: ffi::PetscInt = 0;
            pcall!(ffi::ISGetLocalSize(is, &mut len))?;
            let mut p: *const ffi::PetscInt = std::ptr::null();
            pcall!(ffi::ISGetIndices(is, &mut p))?;
            let v = unsafe { std::slice::from_raw_parts(p, len as usize) }.iter().map(|&i| i as usize).collect();
            pcall!(ffi::ISRestoreIndices(is, &mut p))?;
            Ok(v)
        };
        let out = read(ris).and_then(|r| Ok((r, read(cis)?)));
        unsafe {
            ffi::ISDestroy(&mut ris);
            ffi::ISDestroy(&mut cis);
        }
        out
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

    /// A new matrix holding the transpose (`MatTranspose`), of the same type: for a
    /// transposed solve with a factorisation that has none (ScaLAPACK's LU).
    pub fn transposed(&self) -> Result<Matrix> {
        let mut raw: ffi::Mat = std::ptr::null_mut();
        pcall!(ffi::MatTranspose(self.raw, ffi::MatReuse_MAT_INITIAL_MATRIX, &mut raw))?;
        Ok(Matrix { raw })
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
