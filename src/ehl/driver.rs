//! The lubricated solve: builds the coupled system, starts from the dry Hertz state,
//! runs Newton (PETSc SNES, MUMPS LU), and falls back to an automatic continuation in
//! load when Newton fails from the Hertz start.
use super::layout::Layout;
use super::prealloc::preallocation;
use super::system::{EhlParams, EhlSystem, Lubricant};
use crate::app::Context;
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
}

/// Dimensionless lubricant laws of the scene.
pub fn lubricant(scene: &Scene) -> Lubricant {
    let ph = scene.hertz().ph;
    let visc = scene.viscosity_law().expect("lubricated scene");
    let dens = scene.density_law().expect("lubricated scene");
    let eta_r = visc.reference_viscosity();
    let rho_r = dens.reference_density();
    let _ = rho_r;
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

/// Solves the displacement of the dry Hertz contact: the starting state of Newton.
fn dry_start(comm: petsc::ffi::MPI_Comm, ctx: &Context, mesh: &Mesh, part: &Partition, dofs: &DofMap, k: &Matrix, nu: f64) -> petsc::Result<Vec<f64>> {
    let b = assembly::assemble_pressure_load(comm, mesh, part, dofs, ctx.rank, assembly::traction_factor(nu), &|v| hertz_load::hertz_p2_load(v, 6))?;
    let ksp = Ksp::new(comm, k)?;
    let u = Vector::new(comm, dofs.local(ctx.rank))?;
    ksp.solve(&b, &u)?;
    u.gather_all()
}

/// Builds and solves the EHL system of the scene on the given mesh.
#[allow(clippy::too_many_arguments)]
pub fn solve(ctx: &Context, scene: &Scene, mesh: &Mesh, part: &Partition, dofs: &DofMap, layout: &Layout, half: bool) -> Result<EhlSolution, String> {
    let pe = |e: petsc::PetscError| e.to_string();
    let comm = petsc::comm_world();
    let eq = scene.equivalent_solid();
    let t0 = std::time::Instant::now();
    let k = assembly::assemble_stiffness(comm, mesh, part, dofs, ctx.rank, eq.nu).map_err(pe)?;
    petsc::ksp::set_direct_solver_defaults("").map_err(pe)?;
    let u_dry = dry_start(comm, ctx, mesh, part, dofs, &k, eq.nu).map_err(pe)?;

    // Initial iterate: dry displacement, Hertz pressure, H0 from Hamrock-Dowson's hc.
    let scales = scene.scales();
    let hc_guess = scene.hamrock_dowson().map(|hd| hd.central_film_thickness()).unwrap_or(1e-7) / scales.film_scale();
    let mut x0 = vec![0.0; layout.total()];
    for n in 0..mesh.nodes.len() {
        for c in 0..3 {
            let (d, g) = (dofs.node_dof[n][c], layout.u[n][c]);
            if d >= 0 {
                x0[g as usize] = u_dry[d as usize];
            }
        }
        let p = layout.p[n];
        if p >= 0 {
            let c = mesh.nodes[n];
            x0[p as usize] = hertz_load::hertz_pressure(c[0], c[2]);
        }
    }
    let centre = mesh.locate_contact(0.0, 0.0).ok_or("contact centre not on the contact face")?;
    let uy_centre = crate::fem::p2_tri_eval(&mesh.contact_tris[centre.0].map(|n| x0[layout.u[n as usize][1].max(0) as usize] * f64::from(layout.u[n as usize][1] >= 0)), centre.1);
    x0[layout.h0 as usize] = hc_guess + uy_centre;

    let kin = scene.kinematics().expect("lubricated scene");
    let (a, ue) = (scales.a, scene.operating.entrainment_speed.unwrap());
    let params = EhlParams {
        lambda_bar: lambda_bar(scene),
        traction: assembly::traction_factor(eq.nu),
        load: if half { std::f64::consts::PI / 3.0 } else { 2.0 * std::f64::consts::PI / 3.0 },
        penalty: scene.reynolds.penalty,
        stabilisation: crate::reynolds::element::Stabilisation { supg: scene.reynolds.stabilisation == crate::case::Stabilisation::Supg, delta: 1.0 },
        velocity: Box::new(move |x: f64, z: f64| [kin.um(x * a, z * a) / ue, kin.wm(x * a, z * a) / ue]),
        nu: eq.nu,
    };
    let (d_nnz, o_nnz) = preallocation(mesh, part, layout, ctx.rank);
    let j = Matrix::new_aij(comm, layout.local(ctx.rank), &d_nnz, &o_nnz).map_err(pe)?;
    let mut system = EhlSystem::new(&ctx.world, mesh, part, dofs, layout, ctx.rank, params, lubricant(scene), k).map_err(pe)?;
    let assembly_s = t0.elapsed().as_secs_f64();

    let t1 = std::time::Instant::now();
    let x = Vector::new(comm, layout.local(ctx.rank)).map_err(pe)?;
    let (lo, hi) = (layout.ranges[ctx.rank], layout.ranges[ctx.rank + 1]);
    x.set_local_values(&x0[lo..hi]).map_err(pe)?;
    set_newton_defaults().map_err(pe)?;
    let snes = Snes::new(comm, "").map_err(pe)?;
    ctx.log(format!("Newton from the Hertz start: {} unknowns ({} U, {} P, 1 H0)", layout.total(), layout.counts().0, layout.counts().1));
    let report = snes.solve(&mut system, &x, &j).map_err(pe)?;
    let steps = vec![format!("Newton from Hertz start: {} ({} iterations)", report.reason, report.iterations)];
    ctx.log(&steps[0]);
    let solve_s = t1.elapsed().as_secs_f64();
    if !report.converged {
        return Err(format!(
            "Newton did not converge: {} after {} iterations (residual norm {:.3e}){}",
            report.reason,
            report.iterations,
            report.residual_norm,
            report.domain_error.as_ref().map(|d| format!("; last domain error: {d}")).unwrap_or_default()
        ));
    }
    let newton_total = report.iterations;
    let xs = x.gather_all().map_err(pe)?;
    Ok(EhlSolution { x: xs, report, newton_total, steps, assembly_s, solve_s })
}

/// Newton defaults (overridable by PETSc options).
pub fn set_newton_defaults() -> petsc::Result<()> {
    use petsc::options::set_default;
    set_default("-snes_type", "newtonls")?;
    set_default("-snes_linesearch_type", "bt")?;
    set_default("-snes_max_it", "60")?;
    set_default("-snes_rtol", "1e-10")?;
    set_default("-snes_atol", "1e-11")?;
    set_default("-snes_stol", "1e-14")?;
    Ok(())
}
