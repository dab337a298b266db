//! The adjoint of the converged system for a film value: which residuals move it, and by
//! how much (goal-oriented refinement, `app::adapt`), and what a change of the speed
//! parameter does to it (`output.speed_exponents`).
//!
//! For a converged state x of F(x) = 0 and a film value J(x) = sum_n w_n H_n (nodal films
//! with weights summing to 1: the P2 interpolation at a point, or a mean over an area),
//! a perturbation r of the residual moves the state by -F'(x)^{-1} r and J by -z . r,
//! with z the solution of F'(x)^T z = dJ/dx. The Reynolds part of z is the sensitivity of
//! J to a mass flux injected at each pressure node: with the local Reynolds residual it
//! says where a discretisation error costs J. dJ/dx from H_n = H0 + (X^2 + Z^2)/2 - U_y:
//! 1 on H0 and -w_n on U_y of node n.
//!
//! A parameter s of the residual moves J by dJ/ds = -z . dF/ds. For s = ln lambda_bar
//! (lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H): the only place the entrainment speed and the
//! reference viscosity enter the dimensionless system, the scales a and p_H do not depend
//! on them) that is the film's exponent in eta_R Ue times J, the discrete counterpart of
//! the 0.67 of Hamrock and Dowson's formula. dF/ds is a central difference of the residual
//! in s on the same mesh and state.
use super::problem::{ehl_params, lubricant};
use super::EhlSolver;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::layout::Layout;
use crate::ehl::prealloc::preallocation;
use crate::ehl::system::EhlSystem;
use crate::error::Error;
use crate::petsc::snes::{Eval, Problem};
use crate::petsc::{self, Ksp, Matrix, Vector};
use crate::solid::assembly;

/// Options prefix of the adjoint's linear solver (`-adjoint_ksp_type`, ...).
pub const ADJOINT_PREFIX: &str = "adjoint_";

/// Relative step of the central difference of the residual in lambda_bar. The residual is
/// smooth in lambda_bar (a power of it in the Poiseuille and stabilisation terms), so the
/// difference is exact to O(1e-8) and the roundoff of F(x) ~ 0 stays near 1e-12 of dF/ds.
const SPEED_STEP: f64 = 1e-4;

/// The transposed LU of the monolithic Jacobian at a converged state: adjoints of film
/// values. Collective in every method.
pub struct Adjoint<'a> {
    system: EhlSystem<'a>,
    layout: &'a Layout,
    x: &'a [f64],
    // Declared before the matrix: the solver holds a reference to it.
    ksp: Ksp,
    _jacobian: Matrix,
    local: usize,
}

impl EhlSolver<'_> {
    /// The adjoint machinery at the converged state `x` (monolithic layout,
    /// [`super::EhlSolution::x`], whatever coupling solved it): the Jacobian assembled and
    /// factorised once (MUMPS, prefix `adjoint_`). Collective.
    pub fn adjoint<'s>(&'s self, ctx: &'s Context, scene: &Scene, x: &'s [f64]) -> Result<Adjoint<'s>, Error> {
        let (mesh, layout) = (self.mesh, self.layout);
        let comm = petsc::comm_world();
        let eq = scene.equivalent_solid();
        let k = assembly::assemble_stiffness(comm, mesh, self.part, self.dofs, ctx.rank, eq.nu)?;
        let params = ehl_params(scene, eq.nu, self.half);
        let (d_nnz, o_nnz) = preallocation(mesh, self.part, layout, ctx.rank, params.stabilisation.jump > 0.0);
        let local = layout.local(ctx.rank);
        let j = Matrix::new_aij(comm, local, &d_nnz, &o_nnz)?;
        let mut system = EhlSystem::new(&ctx.world, mesh, self.part, self.dofs, layout, ctx.rank, params, lubricant(scene), k)?;
        system.jacobian(x, &j)?;
        j.assemble()?;
        petsc::ksp::set_direct_solver_defaults(ADJOINT_PREFIX)?;
        petsc::options::set_default(&format!("-{ADJOINT_PREFIX}mat_mumps_icntl_7"), "4")?;
        let ksp = Ksp::with_prefix(comm, &j, ADJOINT_PREFIX)?;
        Ok(Adjoint { system, layout, x, ksp, _jacobian: j, local })
    }
}

impl Adjoint<'_> {
    /// The adjoint z of the film value with nodal weights `weights` (summing to 1), whole,
    /// on every rank (monolithic layout).
    pub fn film(&self, ctx: &Context, weights: &[(u32, f64)]) -> Result<Vec<f64>, Error> {
        self.functional(ctx, weights, &[])
    }

    /// The adjoint z of a value J with dJ/dH_n = `dh` and dJ/dP_n = `dp` (nodal film and
    /// pressure; nodes without a pressure unknown are skipped), whole, on every rank.
    /// Through H_n = H0 + (X^2 + Z^2)/2 - U_y: dJ/dU_y of node n is -dJ/dH_n, and dJ/dH0
    /// their sum.
    pub fn functional(&self, ctx: &Context, dh: &[(u32, f64)], dp: &[(u32, f64)]) -> Result<Vec<f64>, Error> {
        let comm = petsc::comm_world();
        let (b, z) = (Vector::new(comm, self.local)?, Vector::new(comm, self.local)?);
        b.set_all(0.0)?;
        if ctx.rank == 0 {
            let h0: f64 = dh.iter().map(|&(_, w)| w).sum();
            let rows: Vec<i32> = dh
                .iter()
                .map(|&(n, _)| self.layout.u[n as usize][1])
                .chain([self.layout.h0])
                .chain(dp.iter().map(|&(n, _)| self.layout.p[n as usize]))
                .collect();
            let vals: Vec<f64> = dh.iter().map(|&(_, w)| -w).chain([h0]).chain(dp.iter().map(|&(_, w)| w)).collect();
            // Added, so that a repeated row sums; the rows of nodes without a pressure
            // unknown (negative) are dropped.
            b.set_values(&rows, &vals, true)?;
        }
        b.assemble()?;
        self.ksp.solve_transpose(&b, &z)?;
        Ok(z.gather_all()?)
    }

    /// The pressure part of an adjoint `z`, per mesh node (0 where a node has no pressure
    /// unknown).
    pub fn pressure_part(&self, z: &[f64]) -> Vec<f64> {
        self.layout.p.iter().map(|&d| if d >= 0 { z[d as usize] } else { 0.0 }).collect()
    }

    /// dF/d(ln lambda_bar) at the converged state, whole, on every rank.
    pub fn residual_speed_derivative(&mut self) -> Result<Vec<f64>, Error> {
        let lambda = self.system.params.lambda_bar;
        let penalty = self.system.params.penalty;
        let mut at = |s: f64| -> Result<Vec<f64>, Error> {
            self.system.params.set_operating(lambda * s.exp(), penalty);
            let f = Vector::new(petsc::comm_world(), self.local)?;
            f.set_all(0.0)?;
            let eval = self.system.residual(self.x, &f)?;
            f.assemble()?;
            match eval {
                Eval::Ok => Ok(f.gather_all()?),
                Eval::Domain(why) => Err(Error::numerical(format!("the speed derivative left the film's domain: {why}"))),
            }
        };
        let (plus, minus) = (at(SPEED_STEP), at(-SPEED_STEP));
        self.system.params.set_operating(lambda, penalty);
        let (plus, minus) = (plus?, minus?);
        Ok(plus.iter().zip(&minus).map(|(p, m)| (p - m) / (2.0 * SPEED_STEP)).collect())
    }
}

/// dJ/ds = -z . dF/ds for an adjoint `z` and a residual derivative `df` (both whole).
pub fn film_derivative(z: &[f64], df: &[f64]) -> f64 {
    -z.iter().zip(df).map(|(a, b)| a * b).sum::<f64>()
}
