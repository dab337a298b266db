//! ehl-petsc: full-system finite-element solver for elastohydrodynamic lubrication (EHL)
//! of circular contacts under rolling, sliding and spinning.
//!
//! Layout (one folder per concern):
//! - [`case`]: the scene file (schema, units, validation).
//! - [`physics`]: Hertz theory, equivalent solid, lubricant laws, as small pure functions.
//! - [`mesh`]: graded P2 tetrahedral mesh of the equivalent cube, contact face, partition.
//! - [`fem`]: quadrature, reference elements and element kernels (pure, PETSc-free).
//! - [`petsc`]: FFI bindings and safe RAII wrappers; no physics.
//! - [`output`]: summary.json and other result files.
//! - [`context`], [`collective`]: the run's shared state (rank, log, output folder) and
//!   making an outcome agreed by every rank.
//! - [`interrupt`]: SIGINT/SIGTERM, stopping every rank together.
//! - [`error`]: the project's error type [`Error`], below every other module.
//! - [`regress`]: summary.json comparison (regression runner) and the hard suite's checks.
// `!(x > 0.0)` is written on purpose throughout: it rejects NaN as well as x <= 0.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// `pcall!` wraps its argument, a PETSc FFI call, in `unsafe` by design (petsc/error.rs).
#![allow(clippy::macro_metavars_in_unsafe)]
pub mod app;
pub mod case;
pub mod collective;
pub mod context;
pub mod ehl;
pub mod ehl_options;
pub mod error;
pub mod fem;
pub mod friction;
pub mod interrupt;
pub mod mesh;
pub mod output;
pub mod petsc;
pub mod physics;
pub mod regress;
pub mod reynolds;
pub mod solid;

pub use error::Error;
