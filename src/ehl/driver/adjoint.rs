//! The adjoint of the converged system for a film value: which residuals move it, and by
//! how much (goal-oriented refinement, `app::adapt`), and what a change of the speed
//! parameter (`output.speed_exponents`) or of the cavitation penalty (the penalty's own
//! error in the adaptive loop's estimate) does to it.
//!
//! For a converged state x of F(x) = 0 and a film value J(x) = sum_n w_n H_n (nodal films
//! with weights summing to 1: the P2 interpolation at a point, or a mean over an area),
//! a perturbation r of the residual moves the state by -F'(x)^{-1} r and J by -z . r,
//! with z the solution of F'(x)^T z = dJ/dx. The Reynolds part of z is the sensitivity of
//! J to a mass flux injected at each pressure node: with the local Reynolds residual it
//! says where a discretisation error costs J. dJ/dx from H_n = H0 + (X^2 + Z^2)/2 - U_y:
//! 1 on H0 and -w_n on U_y of node n.
//!
//! A parameter s of the residual ([`Parameter`]) moves J by dJ/ds = -z . dF/ds. For
//! s = ln lambda_bar (lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H): the only place the
//! entrainment speed and the reference viscosity enter the dimensionless system, the scales
//! a and p_H do not depend on them) that is the film's exponent in eta_R Ue times J, the
//! discrete counterpart of the 0.67 of Hamrock and Dowson's formula; for s = ln xi it is
//! the slope from which the penalty's error is estimated. dF/ds is a central difference of
//! the residual in s on the same mesh and state.
use super::problem::{ehl_params, lubricant};
use super::EhlSolver;
use super::Kept;
use crate::case::Scene;
use crate::context::Context;
use crate::ehl::condensed::CondensedSystem;
use crate::ehl::layout::Layout;
use crate::ehl::prealloc::preallocation;
use crate::ehl::system::{EhlParams, EhlSystem};
use crate::error::Error;
use crate::petsc::snes::{Eval, Problem};
use crate::petsc::{self, Ksp, Matrix, Vector};
use crate::solid::assembly;
use crate::solid::condense::Compliance;

/// Options prefix of the adjoint's linear solver (`-adjoint_ksp_type`, ...).
pub const ADJOINT_PREFIX: &str = "adjoint_";

/// Relative step of the central difference of the residual in a parameter. The residual is
/// smooth in lambda_bar (a power of it in the Poiseuille and stabilisation terms) and in the
/// penalty xi (linear in the penalty rows, smooth in their stabilisation), so the difference
/// is exact to O(1e-8) and the roundoff of F(x) ~ 0 stays near 1e-12 of dF/ds.
const PARAMETER_STEP: f64 = 1e-4;

/// The adjoints of film values at a converged state, from one factorisation. Collective in every
/// method. An adjoint z is in the layout of the system it was solved on (monolithic, or
/// condensed: P and H0); [`Adjoint::pressure_part`] reads it per mesh node, and
/// [`film_derivative`] pairs it with [`Adjoint::residual_derivative`] of the same
/// system.
pub struct Adjoint<'a> {
    form: Form<'a>,
    local: usize,
}

/// Relative tolerance of the adjoint's GMRES on Newton's last factorisation: the adjoint
/// to about the precision of a direct solve.
const KRYLOV_RTOL: f64 = 1e-10;

/// GMRES iterations allowed on Newton's last factorisation before a new LU is made
/// instead (measured: 3-6 on the adaptive levels of table2-ue2).
const KRYLOV_MAX_IT: usize = 50;

/// The system an adjoint is solved on.
enum Form<'a> {
    /// U, P and H0 on a new transposed MUMPS LU of the sparse Jacobian.
    Monolithic {
        system: EhlSystem<'a>,
        layout: &'a Layout,
        x: &'a [f64],
        // Declared before the matrix: the solver holds a reference to it.
        ksp: Ksp,
        _jacobian: Matrix,
    },
    /// U, P and H0 on the converged solve's own Newton solver: its Jacobian made again at
    /// the solution, GMRES on the transposed system preconditioned by the LU Newton made
    /// last (at most two steps before, with the LU reused over steps). The system's
    /// Reynolds rows are scaled (by D): the solve gives y with J^T D y = g, so z = D y, and
    /// the residual's derivative is unscaled the same way.
    Newton { kept: Kept<'a>, layout: &'a Layout, x: &'a [f64], ksp: Ksp },
    /// The elastic block condensed onto the face (the level was solved so): the dense
    /// Jacobian in (P, H0), transposed and factorised. Eliminating U from J^T z = g gives
    /// J_c^T (z_P, z_H0) = (g_P + C^T g_Uy, g_H0) with C the face compliance: the same
    /// pressure and H0 parts as the monolithic adjoint, without the elastic LU. The
    /// displacement part is not formed: nothing reads it (the residual's speed derivative
    /// and the marking live in the Reynolds rows).
    Condensed {
        system: CondensedSystem<'a>,
        comp: &'a Compliance,
        x: Vec<f64>,
        // Declared before the matrix: the solver holds a reference to it.
        ksp: Ksp,
        _transposed: Matrix,
    },
}

impl EhlSolver<'_> {
    /// The adjoint machinery at the converged state `x` (monolithic layout,
    /// [`super::EhlSolution::x`]), on the coupling the level was solved with: the condensed
    /// Jacobian transposed and factorised; on the monolithic coupling Newton's own solver
    /// when it was kept ([`EhlSolver::keep_newton`]), else the Jacobian factorised (prefix
    /// `adjoint_`). Collective.
    pub fn adjoint<'s>(&'s self, ctx: &'s Context, scene: &Scene, x: &'s [f64]) -> Result<Adjoint<'s>, Error> {
        let (mesh, layout) = (self.mesh, self.layout);
        let comm = petsc::comm_world();
        let eq = scene.equivalent_solid();
        let params = ehl_params(scene, eq.nu, self.half);
        if let Some(comp) = &self.comp {
            let mut system = CondensedSystem::new(mesh, comp, ctx.size, ctx.rank, params, lubricant(scene));
            let xc = super::condensed_state(comp, &system.layout, layout, x);
            let local = system.layout.local(ctx.rank);
            let j = super::condensed_jacobian(&mut system, ctx.rank)?;
            system.jacobian(&xc, &j)?;
            j.assemble()?;
            // ScaLAPACK's LU has no transposed solve: the transpose is factorised instead.
            let jt = j.transposed()?;
            drop(j);
            petsc::ksp::set_direct_solver_defaults_for(ADJOINT_PREFIX, &jt)?;
            let ksp = Ksp::with_prefix(comm, &jt, ADJOINT_PREFIX)?;
            let form = Form::Condensed { system, comp, x: xc, ksp, _transposed: jt };
            return Ok(Adjoint { form, local });
        }
        let local = layout.local(ctx.rank);
        if let Some(mut kept) = self.kept.borrow_mut().take() {
            let solved = (|| -> Result<Ksp, Error> {
                kept.system.jacobian(x, &kept.jacobian)?;
                kept.jacobian.assemble()?;
                let ksp = kept.snes.ksp()?;
                ksp.krylov_on_present_factor(KRYLOV_RTOL, KRYLOV_MAX_IT)?;
                // A trial solve (the adjoint of H0): a factorisation too far from the
                // solution to converge on is replaced by a new LU now, not in the middle
                // of the marking.
                let (b, z) = (Vector::new(comm, local)?, Vector::new(comm, local)?);
                b.set_all(0.0)?;
                if ctx.rank == 0 {
                    b.set_values(&[layout.h0], &[1.0], false)?;
                }
                b.assemble()?;
                ksp.solve_transpose(&b, &z)?;
                Ok(ksp)
            })();
            match solved {
                Ok(ksp) => return Ok(Adjoint { form: Form::Newton { kept, layout, x, ksp }, local }),
                Err(e) => ctx.log(format!("adjoint: Newton's factorisation could not be used ({e}); a new LU instead")),
            }
        }
        let k = assembly::assemble_stiffness(comm, mesh, self.part, self.dofs, ctx.rank, eq.nu)?;
        let (d_nnz, o_nnz) = preallocation(mesh, self.part, layout, ctx.rank, params.stabilisation.jump > 0.0);
        let j = Matrix::new_aij(comm, local, &d_nnz, &o_nnz)?;
        let mut system = EhlSystem::new(&ctx.world, mesh, self.part, self.dofs, layout, ctx.rank, params, lubricant(scene), k)?;
        system.jacobian(x, &j)?;
        j.assemble()?;
        petsc::ksp::set_direct_solver_defaults(ADJOINT_PREFIX)?;
        petsc::options::set_default(&format!("-{ADJOINT_PREFIX}mat_mumps_icntl_7"), "4")?;
        let ksp = Ksp::with_prefix(comm, &j, ADJOINT_PREFIX)?;
        Ok(Adjoint { form: Form::Monolithic { system, layout, x, ksp, _jacobian: j }, local })
    }
}

impl Adjoint<'_> {
    /// The adjoint z of the film value with nodal weights `weights` (summing to 1), whole,
    /// on every rank.
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
            let (rows, vals): (Vec<i32>, Vec<f64>) = match &self.form {
                Form::Monolithic { layout, .. } | Form::Newton { layout, .. } => dh
                    .iter()
                    .map(|&(n, w)| (layout.u[n as usize][1], -w))
                    .chain([(layout.h0, h0)])
                    .chain(dp.iter().map(|&(n, w)| (layout.p[n as usize], w)))
                    .unzip(),
                Form::Condensed { system, comp, .. } => {
                    let cl = &system.layout;
                    // g_P + C^T g_Uy, with g_Uy = -dh on the face rows.
                    let mut g = vec![0.0; cl.total()];
                    for &(n, w) in dp {
                        if let Some(&j) = cl.p_index.get(n as usize).filter(|&&j| j >= 0) {
                            g[j as usize] += w;
                        }
                    }
                    if !comp.is_rigid() {
                        let ncols = comp.cols.len();
                        for &(n, w) in dh {
                            let i = cl.face_index[n as usize];
                            if i >= 0 {
                                let row = &comp.c[i as usize * ncols..(i as usize + 1) * ncols];
                                for (gj, c) in g.iter_mut().zip(row) {
                                    *gj -= w * c;
                                }
                            }
                        }
                    }
                    g[cl.h0()] += h0;
                    g.iter().enumerate().map(|(i, &v)| (i as i32, v)).unzip()
                }
            };
            // Added, so that a repeated row sums; the rows of nodes without a pressure
            // unknown (negative) are dropped.
            b.set_values(&rows, &vals, true)?;
        }
        b.assemble()?;
        match &self.form {
            Form::Monolithic { ksp, .. } => ksp.solve_transpose(&b, &z)?,
            Form::Condensed { ksp, .. } => ksp.solve(&b, &z).map(|_| ())?,
            Form::Newton { kept, ksp, .. } => {
                ksp.solve_transpose(&b, &z)?;
                if crate::ehl_options::get().monitor && ctx.rank == 0 {
                    eprintln!("ehl_monitor: adjoint on Newton's factorisation: {} GMRES iterations", ksp.iterations()?);
                }
                let mut z = z.gather_all()?;
                for (d, s) in kept.system.row_scales() {
                    z[d] *= s;
                }
                return Ok(z);
            }
        }
        Ok(z.gather_all()?)
    }

    /// The pressure part of an adjoint `z`, per mesh node (0 where a node has no pressure
    /// unknown).
    pub fn pressure_part(&self, z: &[f64]) -> Vec<f64> {
        let index: &[i32] = match &self.form {
            Form::Monolithic { layout, .. } | Form::Newton { layout, .. } => &layout.p,
            Form::Condensed { system, .. } => &system.layout.p_index,
        };
        index.iter().map(|&d| if d >= 0 { z[d as usize] } else { 0.0 }).collect()
    }

    /// dF/d(ln s) at the converged state for the parameter s = `param`, whole, on every
    /// rank, in the layout of the adjoints.
    pub fn residual_derivative(&mut self, param: Parameter) -> Result<Vec<f64>, Error> {
        let local = self.local;
        match &mut self.form {
            Form::Monolithic { system, x, .. } => parameter_derivative(system, |s| &mut s.params, x, local, param),
            Form::Condensed { system, x, .. } => parameter_derivative(system, |s| &mut s.params, x, local, param),
            Form::Newton { kept, x, .. } => {
                let mut df = parameter_derivative(&mut kept.system, |s| &mut s.params, x, local, param)?;
                for (d, s) in kept.system.row_scales() {
                    df[d] /= s;
                }
                Ok(df)
            }
        }
    }
}

/// A parameter of the residual whose derivative [`Adjoint::residual_derivative`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameter {
    /// lambda_bar: the entrainment speed times the reference viscosity.
    Speed,
    /// The cavitation penalty xi (the penalty rows and their stabilisation).
    Penalty,
}

/// dF/d(ln s) of `system` at `x` by a central difference (`params` reaches the system's
/// parameters), whole, on every rank.
fn parameter_derivative<S: Problem>(
    system: &mut S,
    params: fn(&mut S) -> &mut EhlParams,
    x: &[f64],
    local: usize,
    param: Parameter,
) -> Result<Vec<f64>, Error> {
    let (lambda, penalty, exact) = (params(system).lambda_bar, params(system).penalty, params(system).stabilisation.complementarity);
    let mut at = |step: f64| -> Result<Vec<f64>, Error> {
        let factor = step.exp();
        match param {
            Parameter::Speed => params(system).set_operating(lambda * factor, penalty, exact),
            Parameter::Penalty => params(system).set_operating(lambda, penalty * factor, exact),
        }
        let f = Vector::new(petsc::comm_world(), local)?;
        f.set_all(0.0)?;
        let eval = system.residual(x, &f)?;
        f.assemble()?;
        match eval {
            Eval::Ok => Ok(f.gather_all()?),
            Eval::Domain(why) => Err(Error::numerical(format!("the residual's derivative in {param:?} left the film's domain: {why}"))),
        }
    };
    let (plus, minus) = (at(PARAMETER_STEP), at(-PARAMETER_STEP));
    params(system).set_operating(lambda, penalty, exact);
    let (plus, minus) = (plus?, minus?);
    Ok(plus.iter().zip(&minus).map(|(p, m)| (p - m) / (2.0 * PARAMETER_STEP)).collect())
}

/// dJ/ds = -z . dF/ds for an adjoint `z` and a residual derivative `df` (both whole).
pub fn film_derivative(z: &[f64], df: &[f64]) -> f64 {
    -z.iter().zip(df).map(|(a, b)| a * b).sum::<f64>()
}
