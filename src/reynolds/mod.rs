//! Reynolds equation on the contact face: P2 element residual, exact Jacobian, SUPG.
//!
//! Pure Rust, no PETSc: the caller (assembly, Newton driver) owns the mesh and the global
//! vectors and calls [`reynolds_element`] on each triangle.
//!
//! # Equation (docs/model.md section 5, dimensionless)
//! X = x/a, Z = z/a, P = p/p_H, H = h R/a^2, rho_bar = rho/rho_R, eta_bar = eta/eta_R,
//! v = (u_bar, w_bar) = (Um, Wm)/Ue. On the rectangle Omega, with P = 0 on its boundary:
//!
//! ```text
//!   -div( eps grad P ) + div( rho_bar H v ) = 0,
//!   eps = rho_bar H^3 / (eta_bar lambda_bar),   lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H).
//! ```
//! v is affine in (X, Z) (rigid-body motions) and divergence-free; it is given per element
//! by its values at the three vertices.
//!
//! # Discretisation
//! Straight P2 triangles ([`crate::fem::p2tri::P2Triangle`]), local nodes v0, v1, v2, mid(0,1), mid(1,2), mid(2,0);
//! P and H are both P2 fields given by nodal values (H = H0 + (X^2+Z^2)/2 - U_y is exactly
//! P2 when U_y is; the caller computes the nodal H).
//!
//! Galerkin residual for the test function N_i (Couette term integrated by parts; the
//! boundary term vanishes because the caller keeps only nodes where N_i = 0 on dOmega):
//! ```text
//!   R_i = int_T [ eps grad P . grad N_i - rho_bar H (v . grad N_i) - f N_i ]
//! ```
//! (f = 0 for the physical problem; [`reynolds_element_with_source`] takes an f(X, Z) for
//! manufactured solutions.)
//!
//! Element and quadrature from [`crate::fem`]: the straight P2 triangle
//! ([`crate::fem::p2tri::P2Triangle`]) and Dunavant's 12-point degree-6 rule
//! ([`crate::fem::quadrature::DUNAVANT6`]), all weights positive, points interior.
//!
//! # SUPG stabilisation (consistent, residual based)
//! When [`Stabilisation::supg`] is set, each element adds
//! ```text
//!   sum_q w_q |T| tau (v . grad N_i) (r_strong - f),
//!   r_strong = -div(eps grad P) + div(rho_bar H v)
//!            = -[ eps Lap P + grad eps . grad P ] + v . grad(rho_bar H) + rho_bar H div v,
//!   grad eps = eps_P grad P + eps_H grad H,
//!   eps_P = d eps/dP = eps (rho_bar'/rho_bar - eta_bar'/eta_bar),   eps_H = d eps/dH = 3 eps/H,
//!   grad(rho_bar H) = rho_bar' H grad P + rho_bar grad H,
//! ```
//! evaluated from the P2 fields inside the element (Lap P is constant on a straight P2
//! triangle, so r_strong is exact for the discrete fields; div v = 0 for rigid-body
//! entrainment but the term is kept so the formula holds for any affine v). The exact
//! solution satisfies r_strong = f, so the term is consistent and keeps the P2 order
//! (verified by the manufactured-solution tests).
//!
//! ```text
//!   tau = delta h_e / (2 |v|) xi(Pe),   Pe = |v| h_e / (2 eps),   xi(Pe) = coth(Pe) - 1/Pe,
//!   h_e = 2 |v| / sum_k |v . grad L_k|   (L_k: barycentric coordinates)
//! ```
//! h_e is the length of the triangle in the stream direction (Tezduyar's h_UGN), see
//! [`streamline_length`]; tau, v and h_e are evaluated at each quadrature point.
//! For P2 elements part of the literature uses the node spacing h_e/2 instead: that is
//! delta = 0.5 here. On the boundary-layer test (eps = 1e-6, 16x16 mesh) delta = 1 gives a
//! monotone centre line with max P = 0.97 < 1, while delta = 0.5 is sharper but shows a
//! small wiggle inside the outflow layer (max P = 1.07); hence the default delta = 1.
//! xi ~ Pe/3 for small Pe (then tau ~ delta h_e^2 / (12 eps), SUPG fades out where
//! diffusion dominates) and xi -> 1 for large Pe (tau -> delta h_e / (2|v|)).
//! delta (default 1) scales tau.
//!
//! ## Variants used by the EHL solver ([`element::StrongResidual`], `film_peclet`)
//! - `film_peclet`: Pe = |beta| h_e / (2 eps) with Habchi's beta = (d rho_bar/dP) H v (the
//!   convection velocity of P in the Couette term), tau = delta h_e/(2|v|) xi(Pe): SUPG acts
//!   only where the Couette term dominates (an incompressible lubricant falls back to |v|).
//! - `StrongResidual::FrozenLubricant` (the solver's default) drops (d eps/dP) |grad P|^2
//!   from r_strong. Its linearisation is a streamline anti-diffusion at the outlet (grad P
//!   against v) about 20 times the physical diffusion on the default mesh, and Newton
//!   stalls with it; without it the manufactured-solution order is 2 instead of 3.
//! - `StrongResidual::Couette` keeps only div(rho_bar H v) (and the penalty): first order.
//! - The cavitation penalty xi pen(P) enters r_strong when [`Stabilisation::penalty`] > 0.
//!
//! # Exact Jacobian
//! The residual is computed once over [`dual::Dual`]`<12>` numbers seeded with the 12
//! element unknowns (P_0..P_5, then H_0..H_5), giving dR_i/dP_j and dR_i/dH_j exactly,
//! including the derivative of tau through eps (tau is *not* frozen) and of the strong
//! residual. The lubricant laws enter through [`Dual::chain`] with their value and
//! derivative; eps_P is itself differentiated, which needs d^2 eta_bar/dP^2 and
//! d^2 rho_bar/dP^2: [`Fluid`] carries them as two extra closures (`d2eta`, `d2rho`; only
//! evaluated when SUPG is on). Verified against central finite differences in the tests.
//!
//! Not included here (the caller's business): the cavitation penalty, the load balance
//! (use [`crate::fem::p2tri::P2Triangle::load_weights`] for int P), the elastic coupling H(U_y).

// Index loops mirror the formulas (N_i, dR_i/dP_j) in this numeric code.
#![allow(clippy::needless_range_loop)]

pub mod cavitation;
pub mod dual;
pub mod element;
pub mod estimate;
pub mod jump;
pub mod multiplier;

#[cfg(test)]
mod tests;

pub use dual::Dual;
pub use element::{reynolds_element, reynolds_element_with_source, streamline_length, xi, ElementOut, Fluid, Stabilisation};

/// The 4 sub-triangles of a P2 triangle (local nodes v0, v1, v2, m01, m12, m20), same
/// orientation as the parent.
pub const P2_SUB_TRIANGLES: [[usize; 3]; 4] = [[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]];
