//! Finite-element building blocks (pure Rust, PETSc-free): quadrature, reference P2
//! elements, affine geometry and element kernels for the equivalent elastic solid.
//!
//! Conventions
//! - P2 tetrahedron, 10 nodes in VTK quadratic-tet order: `v0, v1, v2, v3, mid(0,1),
//!   mid(1,2), mid(0,2), mid(0,3), mid(1,3), mid(2,3)`; straight-sided (affine map from the
//!   4 vertices). Positive orientation is expected, volumes use `|det J|`.
//! - P2 triangle, 6 nodes: `v0, v1, v2, mid(0,1), mid(1,2), mid(2,0)`, in the 2D
//!   coordinates `(x, z)` of the contact plane.
//! - Vector-field element DOFs are node-major: `[u_x0, u_y0, u_z0, u_x1, ...]` (30 per tet).
//!
//! Submodules
//! - [`quadrature`]: symmetric positive rules on the reference tet/triangle, collapsed Gauss;
//!   the degree-6 triangle rule also in barycentric form ([`quadrature::DUNAVANT6`]).
//! - [`p2tet`], [`p2tri`]: P2 shape functions, gradients, evaluation; the physical P2
//!   triangle of the contact face ([`p2tri::P2Triangle`]), its mass matrix and area.
//! - [`geometry`]: affine maps (`J`, `det J`, `J^{-T}`, physical gradients).
//! - [`elasticity`]: Lamé parameters and the isotropic elasticity stiffness kernel.
//! - [`loads`]: body-force and contact-pressure load vectors.
//! - [`norms`]: element contributions to L2 / H1-seminorm errors.
//! - [`testmesh`]: structured Kuhn-cube P2 mesh for tests.
#![allow(clippy::needless_range_loop, clippy::excessive_precision)]
pub mod elasticity;
pub mod geometry;
pub mod loads;
pub mod norms;
pub mod p2tet;
pub mod p2tri;
pub mod quadrature;
pub mod testmesh;

#[cfg(test)]
mod convergence_tests;

pub use elasticity::{elasticity_apply, elasticity_stiffness, elasticity_stiffness_flat, lame, stress_from_grad};
pub use geometry::{tet_signed_volume, AffineTet, AffineTri};
pub use loads::{body_force_load, tri_normal_load};
pub use norms::{h1_seminorm_error_sq, l2_error_sq};
pub use p2tet::{p2_tet_basis, p2_tet_eval, p2_tet_eval_scalar, p2_tet_ref_grads};
pub use p2tri::{p2_tri_basis, p2_tri_eval, p2_tri_eval_grad, p2_tri_ref_grads};
pub use quadrature::{tet_rule, tri_rule, QuadRule, TetRule, TriRule};
pub use testmesh::kuhn_box_mesh;
