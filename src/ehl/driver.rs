//! The lubricated solve: builds the coupled system, starts from the dry Hertz state,
//! runs Newton (PETSc SNES; a dense LU on the condensed system), and falls back to an
//! automatic continuation when Newton fails from the Hertz start.
//!
//! Developer diagnostics (environment variables, not part of the user interface):
//! `EHL_CHECK_JACOBIAN=1` prints a block-by-block finite-difference check of the Jacobian at
//! the start; `EHL_DEBUG=1` prints residual norms per block, the step limiter's binding node
//! and writes `debug_profile_z0.csv` after a failure; `EHL_START=zero` starts from P = 0,
//! U = 0; `EHL_NO_ROW_SCALING=1` and `EHL_NO_LIMIT=1` switch off the row scaling and the
//! film step limiter. `EHL_PTC=1` (with `EHL_PTC_DT0`) tries pseudo-transient
//! continuation before the load continuation; `EHL_SKIP_PLAIN=1` skips the plain Newton
//! attempt. `EHL_P1ISO=1` (condensed path) uses linear pressure on the P2 sub-triangles;
//! `EHL_SUPG_DELTA` scales the SUPG parameter tau (default 1).
//! With `EHL_DEBUG=1` the condensed path prints its worst residual rows and appends
//! the iterates' centre lines to /tmp/ehl_debug_lines.csv.
use super::layout::Layout;
use super::prealloc::preallocation;
use super::condensed::CondensedSystem;
use super::system::{EhlParams, EhlProblem, EhlSystem, Lubricant};
use crate::context::Context;
use crate::case::Scene;
use crate::mesh::{Mesh, Partition};
use crate::petsc::snes::{Snes, SolveReport};
use crate::petsc::{self, Ksp, Matrix, Vector};
use crate::solid::{assembly, dofmap::DofMap, hertz_load};

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
    /// "condensed", "monolithic" or "rigid" (see [`EhlSolver::coupling`]).
    pub coupling: &'static str,
}

/// Where Newton starts.
#[derive(Clone, Copy)]
pub enum Start<'s> {
    /// The dry Hertz pressure and its deflection, H0 from Hamrock-Dowson's central film.
    Hertz,
    /// A converged state of a neighbouring operating point on the same mesh (monolithic
    /// layout, as in [`EhlSolution::x`]).
    Previous(&'s [f64]),
    /// A pressure field P(X, Z) from another mesh (mesh sequencing: a coarser level's
    /// converged solution, interpolated), its deflection, and H0 so that the central film
    /// is `hc` (dimensionless). `label` names it in the log.
    Pressure { p: &'s dyn Fn(f64, f64) -> f64, hc: f64, label: &'s str },
}

impl<'s> Start<'s> {
    /// The starting pressure P(X, Z) and central film of a start that is not a previous
    /// state: the Hertz pressure with Hamrock-Dowson's hc, or the given field.
    fn pressure(&self, scene: &Scene) -> (&'s dyn Fn(f64, f64) -> f64, f64) {
        match *self {
            Start::Pressure { p, hc, .. } => (p, hc),
            _ => (&hertz_load::hertz_pressure, hc_guess(scene)),
        }
    }

    /// How Newton proceeds from this start; `reuse_lu`: the monolithic coupling may reuse
    /// its LU over Newton steps (see [`Policy::reuses_lu`]).
    fn policy(&self, reuse_lu: bool) -> Policy {
        Policy {
            // Only from the Hertz start: another start falls back to the Hertz start instead.
            continues: matches!(self, Start::Hertz),
            // From the Hertz start and from another mesh's pressure (its cavitation boundary
            // is the coarser mesh's), not from a previous state of the same mesh (a sweep).
            stages_penalty: !matches!(self, Start::Previous(_)),
            line_search: match self {
                Start::Pressure { .. } => "l2",
                _ => "bt",
            },
            reuses_lu: reuse_lu && !matches!(self, Start::Hertz),
        }
    }

    fn label(&self) -> &str {
        match self {
            Start::Hertz => "the Hertz start",
            Start::Previous(_) => "the previous operating point",
            Start::Pressure { label, .. } => label,
        }
    }
}

/// What Newton does from a start ([`Start::policy`]).
#[derive(Clone, Copy)]
struct Policy {
    /// Newton's failure leads to the automatic continuation.
    continues: bool,
    /// A stiff cavitation penalty (xi > 1e3) is reached through xi = 1e3.
    stages_penalty: bool,
    /// PETSc's line search (`-snes_linesearch_type` unless the user gave one). From another
    /// mesh's pressure "l2" (the step minimising the residual norm along the direction,
    /// from the norms at steps 1 and 1/2): there a full step overshoots at a few nodes of a
    /// thin side lobe, the backtracking "bt" then takes its smallest step (0.1) every
    /// iteration and Newton crawls (heavy-3gpa's annular patch 0.0039 a -> 0.002 a: 24
    /// iterations from residual 8e-2 to 1.3e-2, stopped; with l2, 13 + 7 iterations to
    /// convergence). From the Hertz start "bt": l2 stops there at once on a closed film
    /// (DIVERGED_FUNCTION_DOMAIN: it does not backtrack out of the film's domain), and on
    /// the Table 2 scenes it costs 0-2 iterations more.
    line_search: &'static str,
    /// The MUMPS LU is rebuilt every third Newton step, GMRES solving on it in between
    /// ([`set_newton_linear_solver`]); otherwise an LU at every step (exact Newton). Only
    /// on the monolithic coupling and from a start near the solution (another mesh's
    /// pressure, a previous operating point): from the Hertz start the inexact steps cost
    /// the hard scenes their convergence (spin-0.33deg: plain Newton ran out of its 30
    /// iterations at residual 5e-4, where exact Newton converges in 24, and every
    /// continuation after it failed; that run predates the tilt continuation on the
    /// monolithic coupling).
    reuses_lu: bool,
}

/// Dimensionless lubricant laws of the scene.
pub fn lubricant(scene: &Scene) -> Lubricant {
    let ph = scene.hertz().ph;
    let visc = scene.viscosity_law().expect("lubricated scene");
    let dens = scene.density_law().expect("lubricated scene");
    let eta_r = visc.reference_viscosity();
    Lubricant {
        eta: Box::new(move |p: f64| {
            let (e, de) = visc.viscosity_and_derivative(p * ph);
            (e / eta_r, de * ph / eta_r)
        }),
        rho: Box::new(move |p: f64| {
            let (r, dr) = dens.ratio_and_derivative(p * ph);
            (r, dr * ph)
        }),
        d2eta: Box::new(move |p: f64| visc.viscosity_second_derivative(p * ph) * ph * ph / eta_r),
        d2rho: Box::new(move |p: f64| dens.ratio_second_derivative(p * ph) * ph * ph),
    }
}

/// lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H).
pub fn lambda_bar(scene: &Scene) -> f64 {
    let h = scene.hertz();
    let eta_r = scene.lubricant.as_ref().expect("lubricated scene").viscosity;
    let ue = scene.operating.entrainment_speed.expect("lubricated scene");
    let r = scene.geometry.ball_radius;
    12.0 * eta_r * ue * r * r / (h.a.powi(3) * h.ph)
}

/// Solves the displacement under the pressure `p(X, Z)` (the Hertz pressure, or a coarser
/// level's) interpolated at the P2 nodes (the discrete pressure of the start, so the start
/// satisfies the elastic rows exactly and equals the condensed path's start): the starting
/// state of Newton.
#[allow(clippy::too_many_arguments)]
fn elastic_start(comm: petsc::ffi::MPI_Comm, ctx: &Context, mesh: &Mesh, part: &Partition, dofs: &DofMap, k: &Matrix, nu: f64, p: &dyn Fn(f64, f64) -> f64) -> petsc::Result<Vec<f64>> {
    let nodal = |v: &[[f64; 2]; 3]| -> [f64; 6] {
        let p = crate::fem::p2tri::p2_tri_node_coords(v).map(|q| p(q[0], q[1]));
        let m = super::system::p2_tri_mass(super::system::tri_area(v));
        std::array::from_fn(|i| (0..6).map(|j| m[i][j] * p[j]).sum())
    };
    let b = assembly::assemble_pressure_load(comm, mesh, part, dofs, ctx.rank, assembly::traction_factor(nu), &nodal)?;
    // K is symmetric positive definite (constrained dofs are eliminated): a MUMPS Cholesky
    // under its own prefix, so the Newton solver's flags (-ksp_type gmres, ...) do not reach it.
    for (k, v) in [("ksp_type", "preonly"), ("pc_type", "cholesky"), ("pc_factor_mat_solver_type", "mumps"), ("mat_mumps_icntl_7", "4")] {
        petsc::options::set_default(&format!("-{START_PREFIX}{k}"), v)?;
    }
    let ksp = Ksp::with_prefix(comm, k, START_PREFIX)?;
    let u = Vector::new(comm, dofs.local(ctx.rank))?;
    ksp.solve(&b, &u)?;
    u.gather_all()
}

/// Options prefix of the start's elastic solve (`-start_pc_type`, `-start_mat_mumps_icntl_7`).
const START_PREFIX: &str = "start_";

/// The scene's dimensionless entrainment velocity (Um, Wm)/Ue as a function of (X, Z).
fn velocity_field(scene: &Scene) -> Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync> {
    let kin = scene.kinematics().expect("lubricated scene");
    let (a, ue) = (scene.scales().a, scene.operating.entrainment_speed.unwrap());
    Box::new(move |x: f64, z: f64| [kin.um(x * a, z * a) / ue, kin.wm(x * a, z * a) / ue])
}

/// The scene's cavitation penalty xi (0 without the penalty model).
fn penalty(scene: &Scene) -> f64 {
    if scene.effects.cavitation == crate::case::CavitationModel::Penalty {
        scene.reynolds.penalty
    } else {
        0.0
    }
}

/// EHL parameters of the scene (dimensionless).
fn ehl_params(scene: &Scene, nu: f64, half: bool) -> EhlParams {
    let penalty = penalty(scene);
    EhlParams {
        lambda_bar: lambda_bar(scene),
        traction: assembly::traction_factor(nu),
        load: if half { std::f64::consts::PI / 3.0 } else { 2.0 * std::f64::consts::PI / 3.0 },
        penalty,
        stabilisation: stabilisation(scene, penalty),
        velocity: velocity_field(scene),
        nu,
    }
}

/// The Reynolds element's stabilisation for the scene's `reynolds.stabilisation`.
fn stabilisation(scene: &Scene, penalty: f64) -> crate::reynolds::element::Stabilisation {
    use crate::case::Stabilisation as S;
    use crate::reynolds::element::{Stabilisation, StrongResidual};
    let choice = scene.reynolds.stabilisation;
    Stabilisation {
        supg: choice != S::Off,
        delta: std::env::var("EHL_SUPG_DELTA").ok().and_then(|v| v.parse().ok()).unwrap_or(1.0),
        id: scene.reynolds.artificial_diffusion,
        cd: scene.reynolds.crosswind_diffusion,
        penalty,
        // An incompressible lubricant has no film Peclet number (d rho/dP = 0: the
        // pressure is not advected, the element falls back to |v|); with that larger tau
        // the diffusive part of the strong residual stalls Newton (measured on
        // cases/examples/barus-newtonian.toml), so "supg" keeps the Couette residual there.
        residual: match choice {
            S::SupgExact => StrongResidual::Full,
            S::SupgCouette => StrongResidual::Couette,
            _ if scene.effects.density == crate::case::DensityModel::Incompressible => StrongResidual::Couette,
            _ => StrongResidual::FrozenLubricant,
        },
        film_peclet: true,
    }
}

/// Estimated dimensionless central film (Hamrock-Dowson), at least 0.02.
fn hc_guess(scene: &Scene) -> f64 {
    (scene.hamrock_dowson().map(|hd| hd.central_film_thickness()).unwrap_or(0.0) / scene.scales().film_scale()).max(0.02)
}

/// H0 of the start: the central film `hc` (estimated, or a coarser level's) over the
/// starting deflection at the centre, raised if needed so that the starting film is
/// positive everywhere (a coarse mesh's dry deflection is not flat in the contact). `uy`
/// gives U_y at a contact node.
fn start_h0(hc: f64, mesh: &Mesh, uy: &dyn Fn(u32) -> f64) -> Result<f64, String> {
    let centre = mesh.locate_contact(0.0, 0.0).ok_or("contact centre not on the contact face")?;
    let uy_centre = crate::fem::p2_tri_eval(&mesh.contact_tris[centre.0].map(uy), centre.1);
    let min_gap = mesh.contact_nodes.iter().map(|&n| Layout::gap(mesh.nodes[n as usize]) - uy(n)).fold(f64::INFINITY, f64::min);
    Ok((hc + uy_centre).max(0.5 * hc - min_gap))
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
    /// Face compliance (condensed path; zero for rigid solids); None on the monolithic
    /// developer path.
    comp: Option<crate::solid::condense::Compliance>,
    /// Seconds spent condensing the elastic block (None: no condensation phase, i.e.
    /// rigid solids or the monolithic developer path).
    pub condensation_s: Option<f64>,
}

impl<'a> EhlSolver<'a> {
    /// Condenses the elastic block onto the contact face, unless the scene's
    /// `reynolds.coupling` (see [`monolithic`]) asks for the monolithic system. Collective.
    pub fn new(ctx: &Context, scene: &Scene, mesh: &'a Mesh, part: &'a Partition, dofs: &'a DofMap, layout: &'a Layout, half: bool) -> Result<Self, String> {
        set_newton_defaults().map_err(|e| e.to_string())?;
        let rigid = scene.effects.elasticity == crate::case::ElasticityModel::Rigid;
        let p_nodes = pressure_nodes(mesh, layout);
        let monolithic = !rigid && monolithic(scene.reynolds.coupling, p_nodes.len(), scene.is_sweep())?;
        if monolithic {
            ctx.log(format!("coupling: monolithic (reynolds.coupling = \"{}\", {} pressure unknowns): U, P and H0 in one sparse matrix, a MUMPS LU at every Newton step (every third step, GMRES in between, from a start near the solution)", scene.reynolds.coupling, p_nodes.len()));
            // The condensed path picks its solver by the Jacobian's type (see `solve_condensed`);
            // a convergence study may have run it before in this process.
            petsc::ksp::set_direct_solver_defaults("").map_err(|e| e.to_string())?;
            petsc::options::set_ours("-mat_mumps_icntl_7", "4").map_err(|e| e.to_string())?;
        } else {
            // The condensed Jacobian is dense: MUMPS's PORD ordering rejects it, AMD is fine.
            petsc::options::set_ours("-mat_mumps_icntl_7", "0").map_err(|e| e.to_string())?;
            // The condensation's 3D Cholesky has its own prefix and keeps PORD.
            petsc::options::set_default("-elastic_mat_mumps_icntl_7", "4").map_err(|e| e.to_string())?;
        }
        let t0 = std::time::Instant::now();
        let comp = if rigid {
            ctx.log(format!("rigid solids: no elastic unknowns, H = H0 + (X^2 + Z^2)/2; sparse Newton on {} pressure unknowns", p_nodes.len()));
            Some(crate::solid::condense::Compliance::rigid(mesh.contact_nodes.clone(), p_nodes))
        } else if monolithic {
            None
        } else {
            ctx.log(format!("coupling: condensed (reynolds.coupling = \"{}\", {} pressure unknowns): the elastic block eliminated onto the contact face, a dense LU at every Newton step", scene.reynolds.coupling, p_nodes.len()));
            let eq = scene.equivalent_solid();
            let comp = crate::solid::condense::face_compliance(&ctx.world, mesh, eq.nu, assembly::traction_factor(eq.nu), &p_nodes).map_err(|e| e.to_string())?;
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
        Ok(EhlSolver { mesh, part, dofs, layout, half, comp, condensation_s })
    }

    /// "condensed", "monolithic" or "rigid": the coupling this solver uses.
    pub fn coupling(&self) -> &'static str {
        match &self.comp {
            None => "monolithic",
            Some(c) if c.is_rigid() => "rigid",
            Some(_) => "condensed",
        }
    }

    /// Solves the scene's operating point. `start`: a converged state of a neighbouring
    /// operating point (monolithic layout, as in [`EhlSolution::x`]); when Newton fails
    /// from it, the solve starts over from the Hertz start. Collective.
    pub fn solve(&self, ctx: &Context, scene: &Scene, start: Option<&[f64]>) -> Result<EhlSolution, String> {
        self.solve_from(ctx, scene, start.map_or(Start::Hertz, Start::Previous))
    }

    /// Solves the scene's operating point from `start`; when Newton fails from a start
    /// other than the Hertz start, the solve starts over from the Hertz start (with its
    /// automatic continuation). Collective.
    ///
    /// On the monolithic coupling a start other than the Hertz start first reuses the LU
    /// over Newton steps ([`Policy::reuses_lu`]); if that fails, the same start is solved
    /// again with an LU at every step before the Hertz start is tried.
    pub fn solve_from(&self, ctx: &Context, scene: &Scene, start: Start) -> Result<EhlSolution, String> {
        let once = |start: Start, reuse_lu: bool| match &self.comp {
            None => solve_monolithic(ctx, scene, self.mesh, self.part, self.dofs, self.layout, self.half, start, reuse_lu),
            Some(comp) => solve_condensed(ctx, scene, self.mesh, self.layout, comp, self.half, start),
        };
        if !matches!(start, Start::Hertz) {
            let tries: &[bool] = if self.comp.is_none() { &[true, false] } else { &[false] };
            for (k, &reuse_lu) in tries.iter().enumerate() {
                match once(start, reuse_lu) {
                    Ok(s) => return Ok(s),
                    Err(e) if crate::interrupt::agreed() != 0 => return Err(e),
                    Err(e) if k + 1 < tries.len() => ctx.log(format!("Newton from {} with the LU reused over steps failed ({e}); again with an LU at every step", start.label())),
                    Err(e) => ctx.log(format!("Newton from {} failed ({e}); starting over from the Hertz start", start.label())),
                }
            }
        }
        once(Start::Hertz, false)
    }
}

/// Builds and solves the EHL system of the scene on the given mesh (one operating point).
#[allow(clippy::too_many_arguments)]
pub fn solve(ctx: &Context, scene: &Scene, mesh: &Mesh, part: &Partition, dofs: &DofMap, layout: &Layout, half: bool) -> Result<EhlSolution, String> {
    EhlSolver::new(ctx, scene, mesh, part, dofs, layout, half)?.solve(ctx, scene, None)
}

/// Whether `coupling` with `n_p` pressure unknowns (in a `sweep` or not) means the
/// monolithic system.
fn monolithic(coupling: crate::case::Coupling, n_p: usize, sweep: bool) -> Result<bool, String> {
    use crate::case::Coupling as C;
    match coupling {
        C::Monolithic => Ok(true),
        C::Condensed => Ok(false),
        C::Auto => Ok(n_p > if sweep { crate::case::AUTO_MONOLITHIC_ABOVE_SWEEP } else { crate::case::AUTO_MONOLITHIC_ABOVE }),
    }
}

/// The face nodes that carry a pressure unknown in the condensed system, in
/// `mesh.contact_nodes` order: every P2 node off the Dirichlet edges.
fn pressure_nodes(mesh: &Mesh, layout: &Layout) -> Vec<u32> {
    mesh.contact_nodes.iter().copied().filter(|&n| layout.p[n as usize] >= 0).collect()
}

/// Options prefix of the condensed Newton Jacobian (`-condensed_mat_type aij` with
/// `-pc_factor_mat_solver_type mumps` returns to the sparse-format MUMPS LU).
pub const CONDENSED_PREFIX: &std::ffi::CStr = c"condensed_";

/// The condensed path: Newton on (P, H0) with the face compliance `comp`, from the Hertz
/// start or from a previous state `start` (monolithic layout).
fn solve_condensed(ctx: &Context, scene: &Scene, mesh: &Mesh, layout: &Layout, comp: &crate::solid::condense::Compliance, half: bool, start: Start) -> Result<EhlSolution, String> {
    let pe = |e: petsc::PetscError| e.to_string();
    let comm = petsc::comm_world();
    let eq = scene.equivalent_solid();
    let t0 = std::time::Instant::now();
    let mut system = CondensedSystem::new(mesh, comp, ctx.size, ctx.rank, ehl_params(scene, eq.nu, half), lubricant(scene));
    let cl = system.layout.clone();
    system.debug_mesh = Some(mesh);
    let mut x0 = vec![0.0; cl.total()];
    let label = match start {
        Start::Previous(prev) => {
            for (j, &n) in comp.cols.iter().enumerate() {
                x0[j] = prev[layout.p[n as usize] as usize];
            }
            x0[cl.h0()] = prev[layout.h0 as usize];
            start.label()
        }
        Start::Hertz | Start::Pressure { .. } => {
            // The pressure and its (condensed) deflection.
            let (p, hc) = start.pressure(scene);
            for (j, &n) in comp.cols.iter().enumerate() {
                let c = mesh.nodes[n as usize];
                x0[j] = p(c[0], c[2]);
            }
            let uy0 = system.uy(&x0);
            x0[cl.h0()] = start_h0(hc, mesh, &|n| uy0[cl.face_index[n as usize] as usize])?;
            if comp.is_rigid() && matches!(start, Start::Hertz) {
                rigid_start(ctx, &mut system, &mut x0, (cl.ranges[ctx.rank], cl.ranges[ctx.rank + 1]), cl.local(ctx.rank))?;
                "the rigid start"
            } else {
                start.label()
            }
        }
    };
    let (d_nnz, o_nnz) = system.preallocation();
    let j = if comp.is_rigid() {
        Matrix::new_aij(comm, cl.local(ctx.rank), &d_nnz, &o_nnz).map_err(pe)?
    } else {
        let j = Matrix::new_dense(comm, cl.local(ctx.rank), CONDENSED_PREFIX, &d_nnz, &o_nnz).map_err(pe)?;
        let (rows, cols) = j.dense_fill_block(cl.total()).map_err(pe)?;
        system.set_fill_block(rows, cols);
        j
    };
    petsc::ksp::set_direct_solver_defaults_for("", &j).map_err(pe)?;
    let assembly_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let (lo, hi) = (cl.ranges[ctx.rank], cl.ranges[ctx.rank + 1]);
    ctx.log(format!("Newton from {label}: {} unknowns ({} P, 1 H0), {} Jacobian", cl.total(), cl.n_p, if comp.is_rigid() { "sparse" } else { "dense" }));
    let out = newton_with_continuation(ctx, scene, &mut system, &x0, label, start.policy(false), &j, (lo, hi), cl.local(ctx.rank))?;
    let solve_s = t1.elapsed().as_secs_f64();
    // Back to the monolithic layout for post-processing: P, H0 and U_y on the face.
    let uy = system.uy(&out.x);
    let mut x = vec![0.0; layout.total()];
    for (j, &n) in comp.cols.iter().enumerate() {
        x[layout.p[n as usize] as usize] = out.x[j];
    }
    for (i, &n) in comp.rows.iter().enumerate() {
        let d = layout.u[n as usize][1];
        if d >= 0 {
            x[d as usize] = uy[i];
        }
    }
    x[layout.h0 as usize] = out.x[cl.h0()];
    let coupling = if comp.is_rigid() { "rigid" } else { "condensed" };
    Ok(EhlSolution { x, report: out.report, newton_total: out.newton_total, steps: out.steps, assembly_s, solve_s, coupling })
}

/// A consistent start for rigid solids. The Hertz start is far from a rigid solution, and
/// at P = 0 the Reynolds rows do not depend on H0 (dR/dH0 = div(3 H^2 grad P) = 0), so
/// Newton on (P, H0) takes useless steps. Instead: solve the pressure of a frozen film
/// (P only), and adjust H0 until its load is within 2 % of the target, by a secant method
/// on log W(log H0) (the first step assumes W ~ 1/H0); each frozen-film solve starts from
/// the previous pressure scaled to the target load. The full Newton finishes from there.
fn rigid_start(ctx: &Context, system: &mut CondensedSystem, x0: &mut [f64], (lo, hi): (usize, usize), local: usize) -> Result<(), String> {
    let pe = |e: petsc::PetscError| e.to_string();
    let comm = petsc::comm_world();
    let n = x0.len();
    let np = n - 1;
    x0[..np].iter_mut().for_each(|p| *p = 0.0);
    let mut h0 = x0[np];
    let (d, o) = system.preallocation();
    let j = Matrix::new_aij(comm, local, &d, &o).map_err(pe)?;
    let x = Vector::new(comm, local).map_err(pe)?;
    // Its own options prefix: the frozen-film solves cross the cavitation penalty's kink
    // node by node and may need more iterations than the main Newton's default.
    for (k, v) in [("-rigid_start_snes_max_it", "200"), ("-rigid_start_snes_rtol", "1e-8"), ("-rigid_start_snes_stol", "0"), ("-rigid_start_snes_linesearch_type", "bt")] {
        petsc::options::set_default(k, v).map_err(pe)?;
    }
    petsc::ksp::set_direct_solver_defaults("rigid_start_").map_err(pe)?;
    let snes = Snes::new(comm, "rigid_start_").map_err(pe)?;
    let target = system.params.load;
    let mut prev: Option<(f64, f64)> = None;
    let mut result = Ok(());
    for it in 0..12 {
        system.fixed_h0 = Some(h0);
        x0[np] = h0;
        system.scale_rows(x0).map_err(pe)?;
        x.set_local_values(&x0[lo..hi]).map_err(pe)?;
        let r = snes.solve(system, &x, &j).map_err(pe)?;
        if !r.converged {
            if prev.is_none() && it < 4 {
                // A too thin first guess: the frozen film is much thinner than the
                // solution's, its pressure enormous. Start over from a thicker film.
                ctx.log(format!("rigid start {}: H0 = {h0:.5e}: {} ; trying a 4 times thicker film", it + 1, r.reason));
                h0 *= 4.0;
                x0[..np].iter_mut().for_each(|p| *p = 0.0);
                continue;
            }
            result = Err(format!("rigid start: the pressure of the film H0 = {h0:.4e} did not converge ({})", r.reason));
            break;
        }
        let xs = x.gather_all().map_err(pe)?;
        x0[..np].copy_from_slice(&xs[..np]);
        let w = system.load(x0);
        ctx.log(format!("rigid start {}: H0 = {h0:.5e}, load {:.4} of the target ({} iterations)", it + 1, w / target, r.iterations));
        if !(w > 0.0) || (w / target - 1.0).abs() < 0.02 {
            break;
        }
        // Slope of log W against log H0: secant once two points are known, else -1.
        let slope = match prev {
            Some((h_old, w_old)) if (h0 / h_old).ln().abs() > 1e-12 => ((w / w_old).ln() / (h0 / h_old).ln()).clamp(-4.0, -0.25),
            _ => -1.0,
        };
        prev = Some((h0, w));
        let factor = ((target / w).ln() / slope).clamp(-2.0, 2.0).exp();
        h0 *= factor;
        // The pressure scales roughly with the load: start the next solve from it.
        let s = target / w;
        x0[..np].iter_mut().for_each(|p| *p *= s);
    }
    system.fixed_h0 = None;
    x0[np] = h0;
    result
}

/// The monolithic path: U, P and H0 in one sparse system, from the Hertz start or from a
/// previous state `start` (same layout).
#[allow(clippy::too_many_arguments)]
fn solve_monolithic(ctx: &Context, scene: &Scene, mesh: &Mesh, part: &Partition, dofs: &DofMap, layout: &Layout, half: bool, start: Start, reuse_lu: bool) -> Result<EhlSolution, String> {
    let pe = |e: petsc::PetscError| e.to_string();
    let comm = petsc::comm_world();
    let eq = scene.equivalent_solid();
    let t0 = std::time::Instant::now();
    let k = assembly::assemble_stiffness(comm, mesh, part, dofs, ctx.rank, eq.nu).map_err(pe)?;
    let x0 = match start {
        Start::Previous(prev) => prev.to_vec(),
        Start::Hertz | Start::Pressure { .. } => {
            let (p, hc) = start.pressure(scene);
            let u_dry = elastic_start(comm, ctx, mesh, part, dofs, &k, eq.nu, p).map_err(pe)?;
            // Initial iterate: the start pressure, its displacement, H0 from the central film.
            let mut x0 = vec![0.0; layout.total()];
            for n in 0..mesh.nodes.len() {
                for c in 0..3 {
                    let (d, g) = (dofs.node_dof[n][c], layout.u[n][c]);
                    if d >= 0 {
                        x0[g as usize] = u_dry[d as usize];
                    }
                }
                let d = layout.p[n];
                if d >= 0 {
                    let c = mesh.nodes[n];
                    x0[d as usize] = p(c[0], c[2]);
                }
            }
            if std::env::var("EHL_START").as_deref() == Ok("zero") {
                for v in x0.iter_mut() {
                    *v = 0.0;
                }
            }
            x0[layout.h0 as usize] = start_h0(hc, mesh, &|n| layout.uy(&x0, n))?;
            x0
        }
    };
    let label = start.label();
    let (d_nnz, o_nnz) = preallocation(mesh, part, layout, ctx.rank);
    let j = Matrix::new_aij(comm, layout.local(ctx.rank), &d_nnz, &o_nnz).map_err(pe)?;
    let mut system = EhlSystem::new(&ctx.world, mesh, part, dofs, layout, ctx.rank, ehl_params(scene, eq.nu, half), lubricant(scene), k).map_err(pe)?;
    let assembly_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    ctx.log(format!("Newton from {label}: {} unknowns ({} U, {} P, 1 H0), sparse Jacobian", layout.total(), layout.counts().0, layout.counts().1));
    if std::env::var_os("EHL_CHECK_JACOBIAN").is_some() {
        if std::env::var_os("EHL_NO_ROW_SCALING").is_none() {
            system.scale_rows(&x0).map_err(pe)?;
        }
        for (r, c, e) in check_jacobian(&mut system, layout, ctx.rank, &x0, &j).map_err(pe)? {
            ctx.log(format!("Jacobian check: rows {r:2} cols {c:2}: max |J v - FD| / max |J v| = {e:.3e}"));
        }
    }
    let (lo, hi) = (layout.ranges[ctx.rank], layout.ranges[ctx.rank + 1]);
    let out = newton_with_continuation(ctx, scene, &mut system, &x0, label, start.policy(reuse_lu), &j, (lo, hi), layout.local(ctx.rank))?;
    let solve_s = t1.elapsed().as_secs_f64();
    Ok(EhlSolution { x: out.x, report: out.report, newton_total: out.newton_total, steps: out.steps, assembly_s, solve_s, coupling: "monolithic" })
}

/// Outcome of [`newton_with_continuation`].
struct NewtonOutcome {
    x: Vec<f64>,
    report: SolveReport,
    newton_total: usize,
    steps: Vec<String>,
}

/// A continuation parameter t in (0, 1]: `apply` sets the scene's problem at t (t = 1: the
/// scene itself; smaller t: milder).
struct Homotopy {
    name: &'static str,
    /// First factor on t when ramping to t = 1.
    ratio: f64,
    apply: SceneAt,
    show: Box<dyn Fn(f64) -> String>,
    /// The parameter changes the entrainment velocity field (tilt angle).
    kinematic: bool,
}

/// A homotopy that first searches a milder problem Newton solves from the Hertz start.
struct Search {
    h: Homotopy,
    /// First t tried from the start, halved down to `lowest` until Newton converges.
    start: f64,
    lowest: f64,
    /// The scene has this parameter to vary (alpha > 0; spin kinematics below 90 deg).
    applies: bool,
    /// A smaller t gives a thinner film (pressure-viscosity: hc grows about as alpha^0.5),
    /// so once a try ends with the film closed, the smaller t that follow would close it too
    /// and the search stops there.
    thins_film: bool,
}

/// Sets a scene's problem at continuation parameter t.
type SceneAt = Box<dyn Fn(&mut Scene, f64)>;

/// One Newton solve of a scene changed by a homotopy at t, from a start, with a label for
/// the path: the report and, if converged, the state.
type SolveAt<'a> = dyn Fn(&Scene, &Homotopy, f64, &mut dyn EhlProblem, &[f64], String) -> Result<(SolveReport, Option<Vec<f64>>), String> + 'a;

/// Newton from `x0` (described by `label`) at the scene's operating point. With
/// `stage_penalty` set, a stiff cavitation penalty (xi > 1e3) is solved at xi = 1e3 first;
/// with `continuation` set, if that fails, a continuation in the tilt angle (spin), then in pressure-viscosity, then
/// in load, then in speed, from a milder problem to the scene's (at xi = 1e3); and last the
/// penalty from 1e3 to the scene's xi. Each step is logged and kept in the path.
/// Returns the converged iterate (gathered) or an error naming the path taken.
#[allow(clippy::too_many_arguments)]
fn newton_with_continuation(ctx: &Context, scene: &Scene, system: &mut dyn EhlProblem, x0: &[f64], label: &str, policy: Policy, j: &Matrix, (lo, hi): (usize, usize), local: usize) -> Result<NewtonOutcome, String> {
    let pe = |e: petsc::PetscError| e.to_string();
    let Policy { continues: continuation, stages_penalty: stage_penalty, line_search, reuses_lu } = policy;
    petsc::options::set_ours("-snes_linesearch_type", line_search).map_err(pe)?;
    set_newton_linear_solver(reuses_lu).map_err(pe)?;
    let comm = petsc::comm_world();
    let x = Vector::new(comm, local).map_err(pe)?;
    let snes = Snes::new(comm, "").map_err(pe)?;
    let scaling = std::env::var_os("EHL_NO_ROW_SCALING").is_none();
    // Where the film closed, if the last solve stopped for that.
    let collapse: std::cell::Cell<Option<Collapse>> = std::cell::Cell::new(None);
    let solve_scene = |sc: &Scene, system: &mut dyn EhlProblem, start: &[f64]| -> Result<SolveReport, String> {
        system.set_operating(lambda_bar(sc), lubricant(sc), penalty(sc));
        x.set_local_values(&start[lo..hi]).map_err(pe)?;
        if scaling {
            system.scale_rows(start).map_err(pe)?;
        }
        system.take_collapse();
        collapse.set(None);
        let mut r = snes.solve(system, &x, j).map_err(pe)?;
        if let (false, Some(c)) = (r.converged, system.take_collapse()) {
            r.reason = format!("{}: film closed at ({:.3}, {:.3})a", r.reason, c[0], c[1]);
            collapse.set(Some(Collapse { at: c, pole: sc.spin_pole_over_a() }));
        }
        Ok(r)
    };
    // The problem solved first. A stiff cavitation penalty (xi > 1e3) is reached last, from
    // the solution at xi = 1e3: on fine rings Newton crawls at xi = 1e4 from the Hertz start
    // (each step flips nodes across the penalty's kink; 30 iterations wasted on table2-ue2
    // with the ring halved), while from the xi = 1e3 solution the cavitated set is already
    // right. Every other continuation runs at xi = 1e3 too, where Newton converges from the
    // Hertz start on every mesh measured (README "The cavitation penalty and the finer ring").
    // A pressure from another mesh is staged the same way, a previous state of the same mesh
    // (a sweep) goes straight to the scene's xi ([`Start::stages_penalty`]).
    let target = scene.operating.load;
    let xi = penalty(scene);
    let staged = stage_penalty && xi > PENALTY_START;
    let mut base = scene.clone();
    if staged {
        base.reynolds.penalty = PENALTY_START;
    }
    // 1. Plain Newton from the Hertz start at the base problem.
    let report = if std::env::var_os("EHL_SKIP_PLAIN").is_some() {
        SolveReport { converged: false, reason: "SKIPPED".into(), reason_code: 0, iterations: 0, linear_iterations: 0, residual_norm: f64::NAN, domain_error: None }
    } else {
        solve_scene(&base, system, x0)?
    };
    let at_xi = if staged { format!(", xi = {PENALTY_START:e}") } else { String::new() };
    // The path taken: every Newton solve, logged as it ends.
    let steps = std::cell::RefCell::new(Vec::new());
    let note = |s: String| {
        ctx.log(&s);
        steps.borrow_mut().push(s);
    };
    note(format!("Newton from {label} at L = {target} N{at_xi}: {} ({} iterations)", report.reason, report.iterations));
    let newton_total = std::cell::Cell::new(report.iterations);
    let mut last = report;
    // The converged state of the base problem.
    let mut state: Option<Vec<f64>> = if last.converged { Some(x.gather_all().map_err(pe)?) } else { None };
    // One Newton solve of `sc0` changed by homotopy `h` at t, from `start`; the step is
    // logged and kept in the path. Returns the report and, if converged, the state.
    let solve_h = |sc0: &Scene, h: &Homotopy, t: f64, system: &mut dyn EhlProblem, start: &[f64], what: String| -> Result<(SolveReport, Option<Vec<f64>>), String> {
        crate::interrupt::check("the continuation")?;
        let mut sc = sc0.clone();
        (h.apply)(&mut sc, t);
        if h.kinematic {
            system.set_velocity(velocity_field(&sc));
        }
        let r = solve_scene(&sc, system, start)?;
        newton_total.set(newton_total.get() + r.iterations);
        note(format!("{} continuation: {what}{}: {} ({} iterations)", h.name, (h.show)(t), r.reason, r.iterations));
        let xs = if r.converged { Some(x.gather_all().map_err(pe)?) } else { None };
        Ok((r, xs))
    };
    // Ramps `h` from t (where `state` is converged) to the scene's problem at t = 1,
    // multiplying t by `h.ratio`, by its square root after each failure, and giving up below
    // a ratio of 1.05. Returns whether t = 1 converged, the last report and the last
    // converged state.
    let ramp = |solve_h: &SolveAt,
                sc0: &Scene,
                h: &Homotopy,
                mut t: f64,
                mut state: Vec<f64>,
                system: &mut dyn EhlProblem|
     -> Result<(bool, Option<SolveReport>, Vec<f64>), String> {
        let mut ratio = h.ratio;
        let mut last = None;
        while t < 1.0 {
            // Within round-off of the end is the end (heavy-3gpa's load ramp by factors of
            // 2^(1/4) ended at t = 1 - 1e-16, then solved t = 1 again in 0 iterations).
            let next = if t * ratio > 1.0 - 1e-9 { 1.0 } else { t * ratio };
            let (r, xs) = solve_h(sc0, h, next, system, &state, String::new())?;
            match xs {
                Some(xs) => {
                    state = xs;
                    t = next;
                }
                None => {
                    ratio = ratio.sqrt();
                    if ratio < 1.05 {
                        return Ok((false, Some(r), state));
                    }
                }
            }
            last = Some(r);
        }
        Ok((true, last, state))
    };
    // 3. If it failed: continuation, first (spin kinematics, lambda < 90 deg) in the tilt
    //    angle, then in pressure-viscosity, then in load, then in speed. Each is a milder
    //    problem at one end (a larger tilt: weaker spin; a smaller alpha: a less steep
    //    viscosity at the same Hertz geometry, so the Hertz start stays good; a lighter
    //    load in Hertz units: smaller M and alpha p_H; a higher speed: a thicker film) and
    //    the base problem at the other; each converged state starts the next. Pressure-viscosity
    //    goes before load: on the hard suite it is the one that converges (alpha30 on the
    //    paper mesh: load continuation fails from every Hertz start down to L/64, alpha/2 ->
    //    alpha converges in 23 + 8 iterations); the tilt only applies to spin scenes.
    if state.is_none() && continuation {
        let alpha = scene.lubricant.as_ref().and_then(|l| l.pressure_viscosity).unwrap_or(0.0);
        let z = scene.lubricant.as_ref().and_then(|l| l.roelands_exponent);
        let ue = scene.operating.entrainment_speed.unwrap_or(0.0);
        let tilt = scene.operating.tilt_angle;
        // A small tilt angle (strong spin) is milder at a larger one; only with spin kinematics.
        let spin = scene.effects.kinematics == crate::case::KinematicsModel::Spin && tilt < 90.0;
        let searches: Vec<Search> = vec![
            Search {
                h: Homotopy {
                    name: "tilt",
                    ratio: 2.0,
                    apply: Box::new(move |sc: &mut Scene, t| sc.operating.tilt_angle = (tilt / t).min(90.0)),
                    show: Box::new(move |t| format!("lambda = {:.4} deg", (tilt / t).min(90.0))),
                    kinematic: true,
                },
                start: 0.5,
                lowest: 1.0 / 64.0,
                applies: spin,
                thins_film: false,
            },
            Search {
                h: Homotopy {
                    name: "pressure-viscosity",
                    ratio: 2.0,
                    apply: Box::new(move |sc: &mut Scene, t| {
                        if let Some(l) = sc.lubricant.as_mut() {
                            l.pressure_viscosity = l.pressure_viscosity.map(|_| alpha * t);
                            l.roelands_exponent = z.map(|z| z * t);
                        }
                    }),
                    show: Box::new(move |t| format!("alpha = {:.4} GPa^-1", alpha * t * 1e9)),
                    kinematic: false,
                },
                start: 0.5,
                lowest: 0.125,
                applies: alpha > 0.0,
                thins_film: true,
            },
            Search {
                h: Homotopy { name: "load", ratio: 2.0, apply: Box::new(move |sc: &mut Scene, t| sc.operating.load = target * t), show: Box::new(move |t| format!("L = {:.4} N", target * t)), kinematic: false },
                start: 1.0 / 8.0,
                lowest: 1.0 / 64.0,
                applies: true,
                thins_film: false,
            },
            Search {
                h: Homotopy { name: "speed", ratio: 2.0, apply: Box::new(move |sc: &mut Scene, t| sc.operating.entrainment_speed = Some(ue / t)), show: Box::new(move |t| format!("Ue = {:.4} m/s", ue / t)), kinematic: false },
                start: 0.25,
                lowest: 1.0 / 64.0,
                applies: true,
                thins_film: false,
            },
        ];
        for Search { h, start, lowest, applies, thins_film } in &searches {
            let (start, lowest) = (*start, *lowest);
            // A kinematic parameter also needs a problem whose velocity field can change.
            if !applies || (h.kinematic && !system.set_velocity(velocity_field(scene))) {
                continue;
            }
            // Find a milder problem Newton solves from the start.
            let mut t = start;
            let mut found: Option<Vec<f64>> = None;
            while t >= lowest {
                let (_, xs) = solve_h(&base, h, t, system, x0, format!("{label} at "))?;
                if xs.is_some() {
                    found = xs;
                    break;
                }
                // heavy-3gpa: the film closed at alpha/2, alpha/4 and alpha/8 alike (4 min of
                // the 10 on its patch mesh); no try after a closed film has converged.
                if *thins_film && collapse.get().is_some() {
                    break;
                }
                t /= 2.0;
            }
            let Some(from) = found else {
                if t >= lowest {
                    note(format!("{} continuation: the film closed at {}; a smaller value gives a thinner film, so the search stops", h.name, (h.show)(t)));
                } else {
                    note(format!("{} continuation: no milder problem converged down to {}", h.name, (h.show)(lowest)));
                }
                continue;
            };
            let (done, r, xs) = ramp(&solve_h, &base, h, t, from, system)?;
            if let Some(r) = r {
                last = r;
            }
            if done {
                state = Some(xs);
                break;
            }
            if h.kinematic {
                // Back to the scene's own velocity field for what follows.
                system.set_velocity(velocity_field(scene));
                // The film closed at the spin pole on the way to the scene's tilt: every
                // other continuation ends at the same problem, with the pole at the same place.
                if let Some(why) = collapse.get().and_then(|c| c.at_pole()) {
                    note(format!("{}: {why}; the other continuations end at the same tilt, so they are not tried", h.name));
                    break;
                }
            }
        }
    }
    // 4. The stiff penalty: from the base solution, xi goes to the scene's in one step (its
    //    square root, and so on, on failure). table2-ue2 with the ring halved, xi = 1e4: 11
    //    iterations at 1e3, then 7 to 1e4 (135 s); by factors of sqrt(10): 6 + 5 (162 s);
    //    plain Newton at 1e4 from the Hertz start: DIVERGED_MAX_IT after 30.
    if let Some(from) = state.take_if(|_| staged) {
        let h = Homotopy {
            name: "penalty",
            ratio: xi / PENALTY_START,
            apply: Box::new(move |sc: &mut Scene, t| sc.reynolds.penalty = xi * t),
            show: Box::new(move |t| format!("xi = {:.4e}", xi * t)),
            kinematic: false,
        };
        let (done, r, xs) = ramp(&solve_h, scene, &h, PENALTY_START / xi, from, system)?;
        if let Some(r) = r {
            last = r;
        }
        state = if done { Some(xs) } else { None };
    }
    let Some(xs) = state else {
        return Err(format!(
            "Newton did not converge: {} after {} iterations (residual norm {:.3e}){}{}; path: {}",
            last.reason,
            last.iterations,
            last.residual_norm,
            last.domain_error.as_ref().map(|d| format!("; last domain error: {d}")).unwrap_or_default(),
            collapse.get().and_then(|c| c.at_pole()).map(|w| format!("; {w}")).unwrap_or_default(),
            steps.borrow().join("; ")
        ));
    };
    Ok(NewtonOutcome { x: xs, report: last, newton_total: newton_total.get(), steps: steps.into_inner() })
}

/// A Newton solve stopped because the film closed.
#[derive(Clone, Copy, Debug)]
struct Collapse {
    /// Where (X, Z in units of a).
    at: [f64; 2],
    /// Z of the solved problem's spin pole (units of a), with spin kinematics.
    pole: Option<f64>,
}

impl Collapse {
    /// If the film closed within 0.25 a of a spin pole inside the Hertz circle: why, in
    /// words. At the pole the mean surface velocity vanishes, so the isothermal Reynolds
    /// equation has no entrainment there to carry a film (README "Strong spin").
    fn at_pole(&self) -> Option<String> {
        let zc = self.pole?;
        let [x, z] = self.at;
        (zc.abs() < 1.0 && x.hypot(z - zc) <= 0.25).then(|| {
            format!("the film closes at ({x:.3}, {z:.3})a, next to the spin pole (0, {zc:.3})a inside the Hertz circle, where the mean surface velocity vanishes: the isothermal Reynolds equation has no entrainment there to carry a film (README \"Strong spin\")")
        })
    }
}

/// The cavitation penalty the penalty continuation starts from (Newton converges from the
/// Hertz start with it on every mesh measured; README "The cavitation penalty and the finer
/// ring").
const PENALTY_START: f64 = 1e3;

/// Newton defaults (overridable by PETSc options).
pub fn set_newton_defaults() -> petsc::Result<()> {
    use petsc::options::set_default;
    set_default("-snes_type", "newtonls")?;
    set_default("-snes_linesearch_type", "bt")?;
    set_default("-snes_max_it", "30")?;
    set_default("-snes_rtol", "1e-10")?;
    set_default("-snes_atol", "1e-11")?;
    // A tiny step is not convergence: only the residual norm decides.
    set_default("-snes_stol", "0")?;
    Ok(())
}

/// The linear solve of a Newton step (each overridable by PETSc options).
///
/// `reuse_lu` (the monolithic coupling from a start near the solution, see
/// [`Policy::reuses_lu`]): the MUMPS LU of the sparse Jacobian is rebuilt every third Newton step and
/// GMRES solves on the last one, to the Eisenstat-Walker tolerance (inexact Newton: loose
/// while the residual is large, tight near the solution). The LU is 87 % of a monolithic
/// step (table2-ue2, narrow ring 0.015625 a: 5.1 s per factorisation, 0.16 s per
/// triangular solve); from level 1's pressure this took 10-11 iterations and 41-42 s
/// instead of 9 and 66-71 s, to the same film (README "Solver options"). From the Hertz
/// start it took 17 iterations and 59 s instead of 13 and 102 s there, but it made
/// spin-0.33deg fail, so the Hertz start keeps exact Newton (the user can ask for the
/// reuse everywhere: `-snes_lag_preconditioner 3 -ksp_type gmres -snes_ksp_ew`, and for
/// exact Newton everywhere: `-snes_lag_preconditioner 1 -ksp_type preonly -snes_ksp_ew false`).
///
/// Otherwise a fresh LU every step and one back-substitution: the condensed coupling (the
/// ScaLAPACK LU of the Table 2 scenes is 0.4 s, about what a stale LU costs in GMRES
/// iterations) and the Hertz start.
///
/// Set with `set_ours` before every solve, so that each solve of a process gets its own,
/// while the user's flags stay.
pub fn set_newton_linear_solver(reuse_lu: bool) -> petsc::Result<()> {
    use petsc::options::set_ours;
    let settings: &[(&str, &str)] = if reuse_lu {
        &[("-ksp_type", "gmres"), ("-ksp_gmres_restart", "100"), ("-snes_lag_preconditioner", "3"), ("-snes_ksp_ew", "true")]
    } else {
        &[("-ksp_type", "preonly"), ("-snes_lag_preconditioner", "1"), ("-snes_ksp_ew", "false")]
    };
    for (k, v) in settings {
        set_ours(k, v)?;
    }
    Ok(())
}

/// Directional finite-difference check of the exact Jacobian, block by block:
/// for a random direction v restricted to one column block (U, P or H0), compares J v with
/// (F(x + d v) - F(x - d v)) / (2 d) on each row block. Returns (row block, column block,
/// relative error) for the 9 pairs. Collective.
pub fn check_jacobian(system: &mut EhlSystem, layout: &Layout, rank: usize, x0: &[f64], j: &Matrix) -> petsc::Result<Vec<(String, String, f64)>> {
    use crate::petsc::snes::Problem;
    let comm = petsc::comm_world();
    let n = layout.total();
    let block_of = |i: usize| -> usize {
        if i as i32 == layout.h0 {
            return 2;
        }
        let r = layout.ranges.partition_point(|&s| s <= i) - 1;
        if i - layout.ranges[r] < layout.n_u[r] { 0 } else { 1 }
    };
    let names = ["U", "P", "H0"];
    // A generic point near the start: the Hertz start has P = 0 exactly at every node
    // outside the Hertz circle, on the kink of the cavitation penalty (pen'' jumps from
    // 1/delta to 0), where central differences straddle the kink and are wrong by
    // xi h / (4 delta). A P-perturbation of 1e-3 >> the FD step moves every node off it
    // (and puts some inside the penalty's quadratic zone, so that is checked too).
    // Deterministic pseudo-random numbers in [-0.5, 0.5) for the point and the direction.
    let mut seed: u64 = 12345;
    let mut rnd = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let x0: Vec<f64> = x0.iter().enumerate().map(|(i, &v)| v + if block_of(i) == 1 { 2e-3 * rnd() } else { 0.0 }).collect();
    let x0 = &x0[..];
    system.jacobian(x0, j)?;
    j.assemble()?;
    let (lo, hi) = (layout.ranges[rank], layout.ranges[rank + 1]);
    let mut out = Vec::new();
    let dir_all: Vec<f64> = (0..n).map(|_| rnd()).collect();
    for cb in 0..3 {
        let v: Vec<f64> = (0..n).map(|i| if block_of(i) == cb { dir_all[i] } else { 0.0 }).collect();
        let vmax = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let d = 1e-7 / vmax.max(1e-300);
        let vv = Vector::new(comm, layout.local(rank))?;
        vv.set_local_values(&v[lo..hi])?;
        let jv = vv.duplicate()?;
        j.mult(&vv, &jv)?;
        let jv = jv.gather_all()?;
        let eval = |s: &mut EhlSystem, xs: &[f64]| -> petsc::Result<Vec<f64>> {
            let f = Vector::new(comm, layout.local(rank))?;
            f.set_all(0.0)?;
            s.residual(xs, &f)?;
            f.assemble()?;
            f.gather_all()
        };
        let xp: Vec<f64> = x0.iter().zip(&v).map(|(a, b)| a + d * b).collect();
        let xm: Vec<f64> = x0.iter().zip(&v).map(|(a, b)| a - d * b).collect();
        let (fp, fm) = (eval(system, &xp)?, eval(system, &xm)?);
        for rb in 0..3 {
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for i in 0..n {
                if block_of(i) != rb {
                    continue;
                }
                let fd = (fp[i] - fm[i]) / (2.0 * d);
                num = num.max((fd - jv[i]).abs());
                den = den.max(jv[i].abs().max(fd.abs()));
            }
            out.push((names[rb].to_string(), names[cb].to_string(), if den > 0.0 { num / den } else { 0.0 }));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::Collapse;

    #[test]
    fn a_collapse_is_blamed_on_the_spin_pole_only_next_to_a_pole_inside_the_contact() {
        // The strong-spin scene at lambda = 0.297 deg: pole at Z = -0.871 (kinematics test),
        // the film closed at the node (0, -0.906).
        let c = Collapse { at: [0.0, -0.906], pole: Some(-0.871) };
        assert!(c.at_pole().unwrap().contains("spin pole (0, -0.871)a"));
        // Far from the pole, the pole outside the Hertz circle, or no spin: no such claim.
        assert!(Collapse { at: [0.6, -0.5], pole: Some(-0.871) }.at_pole().is_none());
        assert!(Collapse { at: [0.0, -0.95], pole: Some(-1.2) }.at_pole().is_none());
        assert!(Collapse { at: [0.0, -0.9], pole: None }.at_pole().is_none());
    }

    #[test]
    fn auto_coupling_switches_to_monolithic_above_the_measured_crossover() {
        use crate::case::{Coupling, AUTO_MONOLITHIC_ABOVE as N, AUTO_MONOLITHIC_ABOVE_SWEEP as NS};
        assert!(!super::monolithic(Coupling::Auto, N, false).unwrap());
        assert!(super::monolithic(Coupling::Auto, N + 1, false).unwrap());
        assert!(!super::monolithic(Coupling::Auto, N + 1, true).unwrap());
        assert!(super::monolithic(Coupling::Auto, NS + 1, true).unwrap());
        assert!(!super::monolithic(Coupling::Condensed, 100 * N, false).unwrap());
        assert!(super::monolithic(Coupling::Monolithic, 10, true).unwrap());
    }
}
