//! The lubricated solve: builds the coupled system, starts Newton (PETSc SNES) from the dry
//! Hertz state or a given start, and falls back to an automatic continuation when Newton
//! fails from the Hertz start. The parts, each in its own file:
//! - `problem`: the scene as a dimensionless problem (lambda_bar, lubricant laws,
//!   velocity field, penalty, stabilisation);
//! - `start`: where Newton starts;
//! - `continuation`: the path of one Newton with continuation, as a recipe (plain Newton,
//!   the continuations, the stiff penalty, complementarity);
//! - `newton`: the Newton solver the path's solves share (retries, the exact finish, the
//!   line search's hand-over, one homotopy's search and ramp);
//! - `homotopy`: the homotopies (scene parameter, ramp) and how a ramp steps;
//! - `policy`: the coupling ([`Coupling`]) and the PETSc options each solve sets;
//! - `diagnostics`: why the film closed, the finite-difference Jacobian check.
//!
//! Developer options (`-ehl_...`, listed by `-help`) are read by [`crate::ehl_options`].
mod adjoint;
mod continuation;
mod diagnostics;
mod homotopy;
mod newton;
mod policy;
mod problem;
mod start;

use crate::error::Error;
pub use adjoint::{film_derivative, Adjoint, Parameter};
pub use diagnostics::{check_jacobian, POLE_COLLAPSE};
use policy::Attempt;
pub use policy::{set_newton_defaults, set_newton_linear_solver, Coupling, CONDENSED_PREFIX};
pub use problem::{lambda_bar, lubricant, stabilisation, velocity_field};
pub use start::{Coarser, Milder, RampLimits, Start, Tries};

use super::condensed::CondensedSystem;
use super::layout::Layout;
use super::prealloc::preallocation;
use super::system::{EhlProblem, EhlSystem};
use crate::case::Scene;
use crate::context::Context;
use crate::mesh::{Mesh, Partition};
use crate::petsc::snes::SolveReport;
use crate::petsc::{self, Matrix};
use crate::solid::{assembly, dofmap::DofMap};
pub use continuation::{complementarity_start_penalty, ContinuationPath, StagedPenalty};
use continuation::{newton_with_continuation, MilderStart};
use policy::Policy;
use problem::ehl_params;
use start::{coarser_displacement, elastic_start, rigid_start, start_h0};

/// Result of a converged lubricated solve (dimensionless state gathered on every rank).
pub struct EhlSolution {
    pub x: Vec<f64>,
    pub report: SolveReport,
    /// Newton iterations summed over all continuation steps.
    pub newton_total: usize,
    /// Continuation steps taken (1 = plain Newton from the Hertz start).
    pub steps: Vec<String>,
    pub assembly_s: f64,
    pub solve_s: f64,
    /// The coupling solved (see [`EhlSolver::coupling`]).
    pub coupling: Coupling,
    /// Plain Newton from the start failed and a continuation found the state.
    pub continued: bool,
    /// The path of the continuation that found the state (monolithic layout). A finer
    /// level starts its continuation there ([`Milder`]).
    pub milder: Option<ContinuationPath>,
    /// The staged cavitation penalty's state at xi = 1e3 (monolithic layout) and the xi the
    /// solution is at, when the penalty was staged for a solver told to accept a short one
    /// ([`EhlSolver::accept_short_penalty`]).
    pub penalty: Option<StagedPenalty>,
}

/// The lubricated solver of one mesh: the parts that do not depend on the operating
/// point (the elastic block condensed onto the contact face) are built once by
/// [`EhlSolver::new`]; [`EhlSolver::solve`] then solves any operating point of the same
/// geometry and materials (a sweep), optionally from a previous converged state.
pub struct EhlSolver<'a> {
    mesh: &'a Mesh,
    part: &'a Partition,
    dofs: &'a DofMap,
    layout: &'a Layout,
    half: bool,
    coupling: Coupling,
    /// Face compliance (condensed coupling; zero for rigid solids); None on the monolithic
    /// coupling.
    comp: Option<crate::solid::condense::Compliance>,
    /// Seconds spent condensing the elastic block (None: no condensation phase, i.e.
    /// rigid solids or the monolithic coupling).
    pub condensation_s: Option<f64>,
    /// Keep the last monolithic Newton solver for [`EhlSolver::adjoint`] ([`EhlSolver::keep_newton`]).
    keep: bool,
    kept: std::cell::RefCell<Option<Kept<'a>>>,
    /// A staged penalty's stalled ramp keeps its state ([`EhlSolver::accept_short_penalty`]).
    short_penalty: bool,
}

/// A converged monolithic solve's Newton solver, its Jacobian matrix and its system (with
/// the row scaling the solver's factorisation was made with): the adjoint solves on that
/// factorisation instead of a new LU.
pub(super) struct Kept<'a> {
    pub(super) snes: crate::petsc::snes::Snes,
    pub(super) jacobian: Matrix,
    pub(super) system: EhlSystem<'a>,
}

impl<'a> EhlSolver<'a> {
    /// Condenses the elastic block onto the contact face, unless the scene's
    /// `reynolds.coupling` (see [`Coupling::of_scene`]) asks for the monolithic system;
    /// `sequenced`: the solves start from a coarser mesh's pressure. Collective.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        mesh: &'a Mesh,
        part: &'a Partition,
        dofs: &'a DofMap,
        layout: &'a Layout,
        half: bool,
        sequenced: bool,
    ) -> Result<Self, Error> {
        set_newton_defaults(scene.accuracy.target)?;
        let p_nodes = pressure_nodes(mesh, layout);
        let coupling = Coupling::of_scene(scene, p_nodes.len(), sequenced);
        let (rigid, monolithic) = (coupling == Coupling::Rigid, coupling == Coupling::Monolithic);
        if monolithic {
            ctx.log(format!("coupling: monolithic (reynolds.coupling = \"{}\", {} pressure unknowns): U, P and H0 in one sparse matrix, a MUMPS LU at every Newton step (every third step, GMRES in between, from a start near the solution)", scene.reynolds.coupling, p_nodes.len()));
            // The condensed path picks its solver by the Jacobian's type (see `solve_condensed`);
            // a convergence study may have run it before in this process.
            petsc::ksp::set_direct_solver_defaults("")?;
            petsc::options::set_ours("-mat_mumps_icntl_7", "4")?;
        } else {
            // The condensed Jacobian is dense: MUMPS's PORD ordering rejects it, AMD is fine.
            petsc::options::set_ours("-mat_mumps_icntl_7", "0")?;
            // The condensation's 3D Cholesky has its own prefix and keeps PORD.
            petsc::options::set_default("-elastic_mat_mumps_icntl_7", "4")?;
        }
        let t0 = std::time::Instant::now();
        let comp = if rigid {
            ctx.log(format!(
                "rigid solids: no elastic unknowns, H = H0 + (X^2 + Z^2)/2; sparse Newton on {} pressure unknowns",
                p_nodes.len()
            ));
            Some(crate::solid::condense::Compliance::rigid(mesh.contact_nodes.clone(), p_nodes))
        } else if monolithic {
            None
        } else {
            ctx.log(format!("coupling: condensed (reynolds.coupling = \"{}\", {} pressure unknowns): the elastic block eliminated onto the contact face, a dense LU at every Newton step", scene.reynolds.coupling, p_nodes.len()));
            let eq = scene.equivalent_solid();
            let comp = crate::solid::condense::face_compliance(&ctx.world, mesh, eq.nu, assembly::traction_factor(eq.nu), &p_nodes)?;
            ctx.log(format!(
                "elastic block condensed onto the contact face: {} elastic unknowns -> {} face nodes x {} pressure nodes ({:.2} s)",
                comp.elastic_unknowns,
                comp.rows.len(),
                comp.cols.len(),
                comp.seconds
            ));
            Some(comp)
        };
        let condensation_s = (!rigid && !monolithic).then(|| t0.elapsed().as_secs_f64());
        crate::interrupt::check("the elastic condensation")?;
        Ok(EhlSolver {
            mesh,
            part,
            dofs,
            layout,
            half,
            coupling,
            comp,
            condensation_s,
            keep: false,
            kept: Default::default(),
            short_penalty: false,
        })
    }

    /// Keep the Newton solver of each converged monolithic solve until the next solve or
    /// [`EhlSolver::adjoint`], which then solves on its factorisation (one MUMPS LU fewer
    /// per level; the factorisation's memory stays in use meanwhile). Off by default.
    pub fn keep_newton(&mut self, yes: bool) {
        self.keep = yes;
    }

    /// A staged cavitation penalty whose ramp stalls above xi = 1e3 returns the state it
    /// converged at (solved to the scene's tolerance) instead of failing, with
    /// [`EhlSolution::penalty`] saying how far it got: for a caller that estimates the
    /// penalty's error and judges it against an accuracy target. Off by default.
    pub fn accept_short_penalty(&mut self, yes: bool) {
        self.short_penalty = yes;
    }

    /// Releases a kept Newton solver (its factorisation's memory), if any.
    pub fn release_newton(&self) {
        self.kept.borrow_mut().take();
    }

    /// The coupling this solver uses.
    pub fn coupling(&self) -> Coupling {
        self.coupling
    }

    /// Solves the scene's operating point. `start`: a converged state of a neighbouring
    /// operating point (monolithic layout, as in [`EhlSolution::x`]); when Newton fails
    /// from it, the solve starts over from the Hertz start. Collective.
    pub fn solve(&self, ctx: &'a Context, scene: &Scene, start: Option<&[f64]>) -> Result<EhlSolution, Error> {
        self.solve_from(ctx, scene, start.map_or(Start::Hertz, Start::Previous))
    }

    /// Solves the scene's operating point from `start`: the attempts of
    /// [`Attempt::ladder`] in order (plain Newton, the monolithic LU reused; from another
    /// mesh's pressure then the continuation from that pressure), then the Hertz start with
    /// its automatic continuation (not after a start without its last resorts: its last
    /// failure is returned). Collective.
    pub fn solve_from(&self, ctx: &'a Context, scene: &Scene, start: Start) -> Result<EhlSolution, Error> {
        // A solver kept from the solve before: its memory is freed before this one factorises.
        self.release_newton();
        let once = |start: Start, attempt: Attempt| match &self.comp {
            None => {
                solve_monolithic(ctx, scene, self.mesh, self.part, self.dofs, self.layout, self.half, start, attempt, self.short_penalty)
                    .map(|(s, kept)| {
                        if self.keep {
                            *self.kept.borrow_mut() = Some(kept);
                        }
                        s
                    })
            }
            Some(comp) => solve_condensed(ctx, scene, self.mesh, self.layout, comp, self.half, start, attempt, self.short_penalty),
        };
        if !matches!(start, Start::Hertz) {
            let ladder = Attempt::ladder(&start, self.comp.is_none());
            for (k, attempt) in ladder.iter().enumerate() {
                match once(start, *attempt) {
                    Ok(s) => return Ok(s),
                    Err(e) if crate::interrupt::agreed() != 0 => return Err(e),
                    Err(e) if k + 1 == ladder.len() && !start.last_resorts() => return Err(e),
                    Err(e) => {
                        let next = ladder.get(k + 1).map_or("the Hertz start", |a| a.describe());
                        ctx.log(format!("from {}: {} failed ({e}); now {next}", start.label(), attempt.describe()));
                    }
                }
            }
        }
        once(Start::Hertz, Attempt::PLAIN)
    }
}

/// Builds and solves the EHL system of the scene on the given mesh (one operating point).
#[allow(clippy::too_many_arguments)]
pub fn solve(
    ctx: &Context,
    scene: &Scene,
    mesh: &Mesh,
    part: &Partition,
    dofs: &DofMap,
    layout: &Layout,
    half: bool,
) -> Result<EhlSolution, Error> {
    EhlSolver::new(ctx, scene, mesh, part, dofs, layout, half, false)?.solve(ctx, scene, None)
}

/// The face nodes that carry a pressure unknown in the condensed system, in
/// `mesh.contact_nodes` order: every P2 node off the Dirichlet edges.
fn pressure_nodes(mesh: &Mesh, layout: &Layout) -> Vec<u32> {
    mesh.contact_nodes.iter().copied().filter(|&n| layout.p[n as usize] >= 0).collect()
}

/// The condensed path: Newton on (P, H0) with the face compliance `comp`, from the Hertz
/// start or from a previous state `start` (monolithic layout).
#[allow(clippy::too_many_arguments)]
fn solve_condensed(
    ctx: &Context,
    scene: &Scene,
    mesh: &Mesh,
    layout: &Layout,
    comp: &crate::solid::condense::Compliance,
    half: bool,
    start: Start,
    attempt: Attempt,
    short_penalty: bool,
) -> Result<EhlSolution, Error> {
    let eq = scene.equivalent_solid();
    let t0 = std::time::Instant::now();
    let mut system = CondensedSystem::new(mesh, comp, ctx.size, ctx.rank, ehl_params(scene, eq.nu, half), lubricant(scene));
    let cl = system.layout.clone();
    system.debug_mesh = Some(mesh);
    // The condensed state of a pressure field and central film: the pressure at the
    // nodes and H0 over its deflection.
    let state_of = |system: &CondensedSystem, p: &dyn Fn(f64, f64) -> f64, hc: f64| -> Result<Vec<f64>, Error> {
        let mut x0 = vec![0.0; cl.total()];
        for (j, &n) in comp.cols.iter().enumerate() {
            let c = mesh.nodes[n as usize];
            x0[j] = p(c[0], c[2]);
        }
        let uy0 = system.uy(&x0);
        x0[cl.h0()] = start_h0(hc, mesh, &|n| uy0[cl.face_index[n as usize] as usize])?;
        Ok(x0)
    };
    let mut x0 = vec![0.0; cl.total()];
    let label = match start {
        Start::Previous(prev) => {
            x0 = condensed_state(comp, &cl, layout, prev);
            start.label()
        }
        Start::Hertz | Start::Pressure { .. } => {
            // The pressure and its (condensed) deflection.
            let (p, hc) = start.pressure(scene);
            x0 = state_of(&system, p, hc)?;
            if comp.is_rigid() && matches!(start, Start::Hertz) {
                // Under complementarity the frozen-film solves cross from P = 0 everywhere
                // with the penalty that starts the complementarity solve (as the Hertz
                // start does), not with the complementarity form itself.
                let complementarity = system.params.stabilisation.complementarity;
                let (lambda_bar, penalty) = (system.params.lambda_bar, system.params.penalty);
                if complementarity {
                    system.set_operating(lambda_bar, lubricant(scene), continuation::complementarity_start_penalty(scene), false);
                }
                let started = rigid_start(ctx, &mut system, &mut x0, (cl.ranges[ctx.rank], cl.ranges[ctx.rank + 1]), cl.local(ctx.rank));
                system.set_operating(lambda_bar, lubricant(scene), penalty, complementarity);
                started?;
                "the rigid start"
            } else {
                start.label()
            }
        }
    };
    let j = condensed_jacobian(&mut system, ctx.rank)?;
    petsc::ksp::set_direct_solver_defaults_for("", &j)?;
    let assembly_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let (lo, hi) = (cl.ranges[ctx.rank], cl.ranges[ctx.rank + 1]);
    ctx.log(format!(
        "Newton from {label}: {} unknowns ({} P, 1 H0), {} Jacobian",
        cl.total(),
        cl.n_p,
        if comp.is_rigid() { "sparse" } else { "dense" }
    ));
    let policy = Policy { accepts_short_penalty: short_penalty, ..Policy::for_start(&start, attempt) };
    let milder = match start.milder().filter(|_| policy.continues) {
        Some(m) => Some((m, state_of(&system, m.p, m.hc)?)),
        None => None,
    };
    let out = newton_with_continuation(
        ctx,
        scene,
        &mut system,
        &x0,
        label,
        policy,
        &j,
        (lo, hi),
        cl.local(ctx.rank),
        milder.as_ref().map(|(m, x)| MilderStart { parameter: m.parameter, ts: m.ts, x, label: m.label }),
    );
    let solve_s = t1.elapsed().as_secs_f64();
    // Back to the monolithic layout for post-processing: P, H0 and U_y on the face.
    let monolithic = |xc: &[f64]| {
        let uy = system.uy(xc);
        let mut x = vec![0.0; layout.total()];
        for (j, &n) in comp.cols.iter().enumerate() {
            x[layout.p[n as usize] as usize] = xc[j];
        }
        for (i, &n) in comp.rows.iter().enumerate() {
            let d = layout.u[n as usize][1];
            if d >= 0 {
                x[d as usize] = uy[i];
            }
        }
        x[layout.h0 as usize] = xc[cl.h0()];
        x
    };
    // A failure's furthest state is reported in the monolithic layout too.
    let out = out.map_err(|mut e| {
        if let Error::FilmClosed { reached: Some(r), .. } | Error::NotConverged { reached: Some(r), .. } = &mut e {
            r.x = monolithic(&r.x);
        }
        e
    })?;
    let x = monolithic(&out.x);
    let milder = out.milder.map(|path| ContinuationPath { x: monolithic(&path.x), ..path });
    let penalty =
        out.penalty.map(|st| StagedPenalty { base_x: monolithic(&st.base_x), mid: st.mid.map(|(xi, x)| (xi, monolithic(&x))), ..st });
    let coupling = if comp.is_rigid() { Coupling::Rigid } else { Coupling::Condensed };
    Ok(EhlSolution {
        x,
        report: out.report,
        newton_total: out.newton_total,
        steps: out.steps,
        assembly_s,
        solve_s,
        coupling,
        continued: out.continued,
        milder,
        penalty,
    })
}

/// The condensed state (P in `comp.cols` order, then H0) of a monolithic state `x`.
fn condensed_state(
    comp: &crate::solid::condense::Compliance,
    cl: &super::condensed::CondensedLayout,
    layout: &Layout,
    x: &[f64],
) -> Vec<f64> {
    let mut xc = vec![0.0; cl.total()];
    for (j, &n) in comp.cols.iter().enumerate() {
        xc[j] = x[layout.p[n as usize] as usize];
    }
    xc[cl.h0()] = x[layout.h0 as usize];
    xc
}

/// The matrix of the condensed Jacobian of `system` on this rank: dense (the block of it
/// this rank fills is set on the system), or sparse with rigid solids.
fn condensed_jacobian(system: &mut CondensedSystem, rank: usize) -> Result<Matrix, Error> {
    let comm = petsc::comm_world();
    let (d_nnz, o_nnz) = system.preallocation();
    let local = system.layout.local(rank);
    if system.comp.is_rigid() {
        return Ok(Matrix::new_aij(comm, local, &d_nnz, &o_nnz)?);
    }
    let j = Matrix::new_dense(comm, local, CONDENSED_PREFIX, &d_nnz, &o_nnz)?;
    let (rows, cols) = j.dense_fill_block(system.layout.total())?;
    system.set_fill_block(rows, cols);
    Ok(j)
}

/// The monolithic path: U, P and H0 in one sparse system, from the Hertz start or from a
/// previous state `start` (same layout). Returns the solution and its Newton solver.
#[allow(clippy::too_many_arguments)]
fn solve_monolithic<'a>(
    ctx: &'a Context,
    scene: &Scene,
    mesh: &'a Mesh,
    part: &'a Partition,
    dofs: &'a DofMap,
    layout: &'a Layout,
    half: bool,
    start: Start,
    attempt: Attempt,
    short_penalty: bool,
) -> Result<(EhlSolution, Kept<'a>), Error> {
    let comm = petsc::comm_world();
    let eq = scene.equivalent_solid();
    let t0 = std::time::Instant::now();
    let k = assembly::assemble_stiffness(comm, mesh, part, dofs, ctx.rank, eq.nu)?;
    // Initial iterate of a pressure field and central film: the pressure, its displacement
    // (the coarser level's `u`, interpolated, when given; else solved under the pressure),
    // H0 from the central film.
    let state_of = |p: &dyn Fn(f64, f64) -> f64, hc: f64, u: Option<Vec<[f64; 3]>>| -> Result<Vec<f64>, Error> {
        let u_at: Box<dyn Fn(usize, usize) -> f64> = match u {
            Some(u) => Box::new(move |n, c| u[n][c]),
            None => {
                let u_dry = elastic_start(comm, ctx, mesh, part, dofs, &k, eq.nu, p)?;
                Box::new(move |n, c| {
                    let d = dofs.node_dof[n][c];
                    if d >= 0 {
                        u_dry[d as usize]
                    } else {
                        0.0
                    }
                })
            }
        };
        let mut x0 = vec![0.0; layout.total()];
        for n in 0..mesh.nodes.len() {
            for c in 0..3 {
                let g = layout.u[n][c];
                if g >= 0 {
                    x0[g as usize] = u_at(n, c);
                }
            }
            let d = layout.p[n];
            if d >= 0 {
                let c = mesh.nodes[n];
                x0[d as usize] = p(c[0], c[2]);
            }
        }
        x0[layout.h0 as usize] = start_h0(hc, mesh, &|n| layout.uy(&x0, n))?;
        Ok(x0)
    };
    let x0 = match start {
        Start::Previous(prev) => prev.to_vec(),
        Start::Hertz | Start::Pressure { .. } => {
            let (p, hc) = start.pressure(scene);
            state_of(p, hc, start.coarser().and_then(|c| coarser_displacement(&c, mesh)))?
        }
    };
    let policy = Policy { accepts_short_penalty: short_penalty, ..Policy::for_start(&start, attempt) };
    let milder = match start.milder().filter(|_| policy.continues) {
        Some(m) => Some((m, state_of(m.p, m.hc, None)?)),
        None => None,
    };
    let label = start.label();
    let params = ehl_params(scene, eq.nu, half);
    let (d_nnz, o_nnz) = preallocation(mesh, part, layout, ctx.rank, params.stabilisation.jump > 0.0);
    let j = Matrix::new_aij(comm, layout.local(ctx.rank), &d_nnz, &o_nnz)?;
    let mut system = EhlSystem::new(&ctx.world, mesh, part, dofs, layout, ctx.rank, params, lubricant(scene), k)?;
    let assembly_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    ctx.log(format!(
        "Newton from {label}: {} unknowns ({} U, {} P, 1 H0), sparse Jacobian",
        layout.total(),
        layout.counts().0,
        layout.counts().1
    ));
    if crate::ehl_options::get().check_jacobian {
        if crate::ehl_options::get().row_scaling {
            system.scale_rows(&x0)?;
        }
        for (r, c, e) in check_jacobian(&mut system, layout, ctx.rank, &x0, &j)? {
            ctx.log(format!("Jacobian check: rows {r:2} cols {c:2}: max |J v - FD| / max |J v| = {e:.3e}"));
        }
    }
    let (lo, hi) = (layout.ranges[ctx.rank], layout.ranges[ctx.rank + 1]);
    let out = newton_with_continuation(
        ctx,
        scene,
        &mut system,
        &x0,
        label,
        policy,
        &j,
        (lo, hi),
        layout.local(ctx.rank),
        milder.as_ref().map(|(m, x)| MilderStart { parameter: m.parameter, ts: m.ts, x, label: m.label }),
    )?;
    let solve_s = t1.elapsed().as_secs_f64();
    let solution = EhlSolution {
        x: out.x,
        report: out.report,
        newton_total: out.newton_total,
        steps: out.steps,
        assembly_s,
        solve_s,
        coupling: Coupling::Monolithic,
        continued: out.continued,
        milder: out.milder,
        penalty: out.penalty,
    };
    Ok((solution, Kept { snes: out.snes, jacobian: j, system }))
}
