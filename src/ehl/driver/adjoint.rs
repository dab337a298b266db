//! The adjoint of the converged system for a film value: which residuals move it, and by
//! how much (goal-oriented refinement, `app::adapt`).
//!
//! For a converged state x of F(x) = 0 and a film value J(x) = sum_n w_n H_n (nodal films
//! with weights summing to 1: the P2 interpolation at a point, or a mean over an area),
//! a perturbation r of the residual moves the state by -F'(x)^{-1} r and J by -z . r,
//! with z the solution of F'(x)^T z = dJ/dx. The Reynolds part of z is the sensitivity of
//! J to a mass flux injected at each pressure node: with the local Reynolds residual it
//! says where a discretisation error costs J. dJ/dx from H_n = H0 + (X^2 + Z^2)/2 - U_y:
//! 1 on H0 and -w_n on U_y of node n.
use super::problem::{ehl_params, lubricant};
use super::EhlSolver;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::prealloc::preallocation;
use crate::ehl::system::EhlSystem;
use crate::error::Error;
use crate::petsc::snes::Problem;
use crate::petsc::{self, Ksp, Matrix, Vector};
use crate::solid::assembly;

/// Options prefix of the adjoint's linear solver (`-adjoint_ksp_type`, ...).
pub const ADJOINT_PREFIX: &str = "adjoint_";

impl EhlSolver<'_> {
    /// The pressure part of the adjoint of each film value in `films` (nodal weights
    /// summing to 1), per mesh node (0 where a node has no pressure unknown), at the
    /// converged state `x` (monolithic layout, [`super::EhlSolution::x`]). One MUMPS LU of
    /// the monolithic Jacobian, one transposed solve per value. Collective.
    pub fn film_adjoints(&self, ctx: &Context, scene: &Scene, x: &[f64], films: &[Vec<(u32, f64)>]) -> Result<Vec<Vec<f64>>, Error> {
        let (mesh, layout) = (self.mesh, self.layout);
        let comm = petsc::comm_world();
        let eq = scene.equivalent_solid();
        let k = assembly::assemble_stiffness(comm, mesh, self.part, self.dofs, ctx.rank, eq.nu)?;
        let (d_nnz, o_nnz) = preallocation(mesh, self.part, layout, ctx.rank);
        let j = Matrix::new_aij(comm, layout.local(ctx.rank), &d_nnz, &o_nnz)?;
        let mut system = EhlSystem::new(
            &ctx.world,
            mesh,
            self.part,
            self.dofs,
            layout,
            ctx.rank,
            ehl_params(scene, eq.nu, self.half),
            lubricant(scene),
            k,
        )?;
        system.jacobian(x, &j)?;
        j.assemble()?;
        petsc::ksp::set_direct_solver_defaults(ADJOINT_PREFIX)?;
        petsc::options::set_default(&format!("-{ADJOINT_PREFIX}mat_mumps_icntl_7"), "4")?;
        let ksp = Ksp::with_prefix(comm, &j, ADJOINT_PREFIX)?;
        let (b, z) = (Vector::new(comm, layout.local(ctx.rank))?, Vector::new(comm, layout.local(ctx.rank))?);
        let mut out = Vec::with_capacity(films.len());
        for weights in films {
            b.set_all(0.0)?;
            if ctx.rank == 0 {
                let rows: Vec<i32> = weights.iter().map(|&(n, _)| layout.u[n as usize][1]).chain([layout.h0]).collect();
                let vals: Vec<f64> = weights.iter().map(|&(_, w)| -w).chain([1.0]).collect();
                b.set_values(&rows, &vals, true)?;
            }
            b.assemble()?;
            ksp.solve_transpose(&b, &z)?;
            let all = z.gather_all()?;
            out.push(layout.p.iter().map(|&d| if d >= 0 { all[d as usize] } else { 0.0 }).collect());
        }
        Ok(out)
    }
}
