//! PETSc through our own bindgen FFI: raw bindings ([`ffi`]) and a safe RAII layer.
//! No physics lives here.
pub mod error;
pub mod factor;
pub mod ffi;
pub mod ksp;
pub mod matrix;
pub mod options;
pub mod session;
pub mod snes;
pub mod vector;

pub use error::{PetscError, Result};
pub use ksp::Ksp;
pub use matrix::Matrix;
pub use session::{comm_world, Petsc};
pub use vector::Vector;
