//! petsc
