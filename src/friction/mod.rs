//! Friction (docs/model.md section 7, the paper's Section 3): the shear stresses of the
//! lubricant film and the traction forces on the disc, computed on the converged pressure
//! and film thickness.
//! - [`shear`]: the per-point law (Ree-Eyring or Newtonian) across the film, PETSc-free.
//! - [`pass`]: the pass over the Reynolds rectangle, forces and friction coefficients.
pub mod pass;
pub mod shear;
