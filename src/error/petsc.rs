//! The data of a PETSc error. Defined here, below every module, so that
//! [`crate::error::Error`] can carry it; [`crate::petsc::error`] turns PETSc's return codes
//! into it and re-exports it.

/// An error reported by PETSc (non-zero `PetscErrorCode`) or by the safe layer over it.
#[derive(Debug, Clone)]
pub struct PetscError {
    /// PETSc's error code (0 for errors raised by the Rust layer itself).
    pub code: i32,
    /// PETSc's messages, innermost first ("function (file:line): message").
    pub message: String,
}

impl std::fmt::Display for PetscError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.code == 0 {
            // Raised by the Rust layer (e.g. an interruption): its own message says it all.
            write!(f, "{}", self.message)
        } else {
            write!(f, "PETSc error {}: {}", self.code, self.message)
        }
    }
}
impl std::error::Error for PetscError {}
