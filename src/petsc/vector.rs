//! RAII wrapper of a distributed PETSc `Vec`.
use super::error::{rust_error, Result};
use super::ffi;
use crate::pcall;

/// A distributed vector of `f64` (PETSc `Vec`, type from options, MPI by default).
pub struct Vector {
    pub(crate) raw: ffi::Vec,
}

impl Vector {
    /// A vector with `local` entries on this rank (rows owned contiguously, rank by rank).
    pub fn new(comm: ffi::MPI_Comm, local: usize) -> Result<Vector> {
        let mut raw: ffi::Vec = std::ptr::null_mut();
        pcall!(ffi::VecCreate(comm, &mut raw))?;
        let v = Vector { raw };
        pcall!(ffi::VecSetSizes(v.raw, local as ffi::PetscInt, ffi::PETSC_DETERMINE))?;
        pcall!(ffi::VecSetFromOptions(v.raw))?;
        Ok(v)
    }

    /// A new vector with the same layout (entries not copied).
    pub fn duplicate(&self) -> Result<Vector> {
        let mut raw: ffi::Vec = std::ptr::null_mut();
        pcall!(ffi::VecDuplicate(self.raw, &mut raw))?;
        Ok(Vector { raw })
    }

    /// Copies the entries of `self` into `other`.
    pub fn copy_to(&self, other: &Vector) -> Result<()> {
        pcall!(ffi::VecCopy(self.raw, other.raw))
    }

    /// Sets every entry to `value`.
    pub fn set_all(&self, value: f64) -> Result<()> {
        pcall!(ffi::VecSet(self.raw, value))
    }

    /// Adds (or inserts) values at global indices; call [`Vector::assemble`] afterwards.
    /// Negative indices (eliminated unknowns) are skipped.
    pub fn set_values(&self, idx: &[i32], vals: &[f64], add: bool) -> Result<()> {
        if idx.len() != vals.len() {
            return Err(rust_error("Vector::set_values: index and value lengths differ"));
        }
        if idx.iter().any(|&i| i < 0) {
            let (i, v): (Vec<i32>, Vec<f64>) = idx.iter().zip(vals).filter(|(&i, _)| i >= 0).map(|(&i, &v)| (i, v)).unzip();
            return self.set_values(&i, &v, add);
        }
        let mode = if add { ffi::InsertMode_ADD_VALUES } else { ffi::InsertMode_INSERT_VALUES };
        pcall!(ffi::VecSetValues(self.raw, idx.len() as ffi::PetscInt, idx.as_ptr(), vals.as_ptr(), mode))
    }

    /// Communicates off-rank contributions.
    pub fn assemble(&self) -> Result<()> {
        pcall!(ffi::VecAssemblyBegin(self.raw))?;
        pcall!(ffi::VecAssemblyEnd(self.raw))
    }

    /// Global size.
    pub fn size(&self) -> Result<usize> {
        let mut n: ffi::PetscInt = 0;
        pcall!(ffi::VecGetSize(self.raw, &mut n))?;
        Ok(n as usize)
    }

    /// Range `[lo, hi)` of global indices owned by this rank.
    pub fn ownership(&self) -> Result<(usize, usize)> {
        let (mut lo, mut hi): (ffi::PetscInt, ffi::PetscInt) = (0, 0);
        pcall!(ffi::VecGetOwnershipRange(self.raw, &mut lo, &mut hi))?;
        Ok((lo as usize, hi as usize))
    }

    /// Copy of the locally owned entries.
    pub fn local_values(&self) -> Result<Vec<f64>> {
        let (lo, hi) = self.ownership()?;
        let mut ptr: *const f64 = std::ptr::null();
        pcall!(ffi::VecGetArrayRead(self.raw, &mut ptr))?;
        let out = unsafe { std::slice::from_raw_parts(ptr, hi - lo) }.to_vec();
        pcall!(ffi::VecRestoreArrayRead(self.raw, &mut ptr))?;
        Ok(out)
    }

    /// Overwrites the locally owned entries.
    pub fn set_local_values(&self, values: &[f64]) -> Result<()> {
        let (lo, hi) = self.ownership()?;
        if values.len() != hi - lo {
            return Err(rust_error("Vector::set_local_values: wrong length"));
        }
        let mut ptr: *mut f64 = std::ptr::null_mut();
        pcall!(ffi::VecGetArray(self.raw, &mut ptr))?;
        unsafe { std::slice::from_raw_parts_mut(ptr, hi - lo) }.copy_from_slice(values);
        pcall!(ffi::VecRestoreArray(self.raw, &mut ptr))
    }

    /// All entries of the vector, gathered on every rank (collective).
    pub fn gather_all(&self) -> Result<Vec<f64>> {
        let mut scatter: ffi::VecScatter = std::ptr::null_mut();
        let mut all: ffi::Vec = std::ptr::null_mut();
        pcall!(ffi::VecScatterCreateToAll(self.raw, &mut scatter, &mut all))?;
        let all = Vector { raw: all };
        let r = (|| {
            pcall!(ffi::VecScatterBegin(scatter, self.raw, all.raw, ffi::InsertMode_INSERT_VALUES, ffi::ScatterMode_SCATTER_FORWARD))?;
            pcall!(ffi::VecScatterEnd(scatter, self.raw, all.raw, ffi::InsertMode_INSERT_VALUES, ffi::ScatterMode_SCATTER_FORWARD))?;
            let n = all.size()?;
            let mut ptr: *const f64 = std::ptr::null();
            pcall!(ffi::VecGetArrayRead(all.raw, &mut ptr))?;
            let out = unsafe { std::slice::from_raw_parts(ptr, n) }.to_vec();
            pcall!(ffi::VecRestoreArrayRead(all.raw, &mut ptr))?;
            Ok(out)
        })();
        unsafe { ffi::VecScatterDestroy(&mut scatter) };
        r
    }

    /// 2-norm (collective).
    pub fn norm2(&self) -> Result<f64> {
        let mut n = 0.0;
        pcall!(ffi::VecNorm(self.raw, ffi::NormType_NORM_2, &mut n))?;
        Ok(n)
    }

    /// Raw handle for FFI calls.
    pub fn raw(&self) -> ffi::Vec {
        self.raw
    }
}

impl Drop for Vector {
    fn drop(&mut self) {
        unsafe { ffi::VecDestroy(&mut self.raw) };
    }
}
