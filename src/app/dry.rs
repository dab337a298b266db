//! The dry Hertz scene: the Hertzian pressure applied as a traction on the contact face of
//! the equivalent solid, one linear elastic solve, and the surface deflection compared with
//! the half-space solution (docs/model.md sections 2 and 6).
use super::{collective, Context};
use crate::case::Scene;
use crate::error::{Error, ResultExt};
use crate::mesh::{self, Mesh};
use crate::petsc::{self, Ksp, Vector};
use crate::solid::{assembly, dofmap::DofMap, hertz_load};
use serde_json::json;
use std::time::Instant;

/// Depth of the recursive splitting of contact triangles cut by the Hertz circle.
const HERTZ_SPLIT_DEPTH: u32 = 6;

/// Builds the mesh described by the scene (every rank builds the same mesh).
pub fn build_mesh(scene: &Scene, half_z: bool) -> Result<Mesh, Error> {
    mesh::generate(&mesh_spec(scene, half_z)).context("mesh")
}

/// The mesh specification of the scene.
pub fn mesh_spec(scene: &Scene, half_z: bool) -> mesh::MeshSpec {
    mesh::MeshSpec {
        cube_edge: scene.mesh.cube_size,
        depth: scene.mesh.cube_size,
        half_z,
        contact: mesh::Rect {
            x0: scene.reynolds.x_min,
            x1: scene.reynolds.x_max,
            z0: scene.reynolds.z_min,
            z1: if half_z { 0.0 } else { scene.reynolds.z_max },
        },
        contact_size: scene.mesh.contact_size,
        growth: scene.mesh.growth,
        core: (scene.mesh.core_size > 0.0).then(|| {
            let w = scene.mesh.core_half_width;
            (mesh::Rect { x0: -w, x1: w, z0: -w, z1: if half_z { 0.0 } else { w } }, scene.mesh.core_size)
        }),
        core_depth: scene.mesh.core_depth,
        ring: (scene.mesh.ring_size > 0.0).then_some(mesh::Ring {
            inner: scene.mesh.ring_inner,
            outer: scene.mesh.ring_outer,
            size: scene.mesh.ring_size,
        }),
        patch: (scene.mesh.patch_size > 0.0).then(|| {
            let m = &scene.mesh;
            (mesh::Rect { x0: m.patch_x_min, x1: m.patch_x_max, z0: m.patch_z_min, z1: m.patch_z_max }, m.patch_size)
        }),
        patch_radii: (scene.mesh.patch_size > 0.0 && scene.mesh.patch_r_max > 0.0)
            .then_some((scene.mesh.patch_r_min, scene.mesh.patch_r_max)),
        size_field: None,
    }
}

/// Value of the y displacement (dimensionless U) at (x, z) on the contact face.
pub fn contact_uy(mesh: &Mesh, dofs: &DofMap, sol: &[f64], x: f64, z: f64) -> Result<f64, Error> {
    let (tri, bary) = mesh.locate_contact(x, z).ok_or_else(|| Error::other(format!("point ({x}, {z}) is not on the contact face")))?;
    let nodes = mesh.contact_tris[tri];
    let vals = nodes.map(|n| {
        let d = dofs.node_dof[n as usize][1];
        if d < 0 {
            0.0
        } else {
            sol[d as usize]
        }
    });
    Ok(crate::fem::p2_tri_eval(&vals, bary))
}

/// The subsurface stresses of the dry scene (`output.subsurface`): the disc under the Hertz
/// pressure and, with `effects.surface_traction = "friction"`, the traction q = mu p in +x.
/// With equal Poisson ratios of the disc and the equivalent solid the factorisation of the
/// main solve is reused (one more right-hand side); otherwise rank 0 solves the disc's own
/// elastic problem. Collective; the JSON object is returned on rank 0.
#[allow(clippy::too_many_arguments)]
fn subsurface_stresses(
    ctx: &Context,
    scene: &Scene,
    mesh: &Mesh,
    part: &mesh::Partition,
    dofs: &DofMap,
    ksp: &Ksp,
    main_solve_s: f64,
    dir: &std::path::Path,
) -> Result<Option<serde_json::Value>, Error> {
    use super::subsurface as sub;
    let t0 = Instant::now();
    let disc = scene.disc_material();
    let mu = match scene.effects.surface_traction {
        crate::case::SurfaceTraction::Friction => scene.operating.friction_coefficient,
        crate::case::SurfaceTraction::Off => 0.0,
    };
    let load = |t: usize| {
        let tri = mesh.contact_tris[t];
        let v = [0, 1, 2].map(|i| {
            let p = mesh.nodes[tri[i] as usize];
            [p[0], p[2]]
        });
        hertz_load::hertz_p2_load(&v, HERTZ_SPLIT_DEPTH).map(|f| [mu * f, -f, 0.0])
    };
    let reuse = (disc.nu - scene.equivalent_solid().nu).abs() < 1e-12;
    let (u, cost) = if reuse {
        let rss0 = sub::current_rss_mb();
        let comm = petsc::comm_world();
        let b = sub::assemble_face_traction(comm, mesh, part, dofs, ctx.rank, &load)?;
        let x = Vector::new(comm, dofs.local(ctx.rank))?;
        ksp.solve(&b, &x)?;
        let sol = x.gather_all()?;
        let cost = sub::SolveCost {
            seconds: t0.elapsed().as_secs_f64(),
            rss_increase_mb: sub::current_rss_mb() - rss0,
            factor_mb: ksp.mumps_factor_mb(),
            unknowns: dofs.total(),
        };
        (Some(sub::node_displacements(dofs, &sol, 1.0)), cost)
    } else if ctx.rank == 0 {
        let (mut u, c) = sub::solve_alone(mesh, disc.nu, &[&load])?;
        (u.pop(), c)
    } else {
        (None, sub::SolveCost::default())
    };
    let Some(u) = u else { return Ok(None) };
    if ctx.rank != 0 {
        return Ok(None);
    }
    let hertz = scene.hertz();
    let traction = if mu > 0.0 { format!("Hertz pressure and q = {mu} p in +x") } else { "Hertz pressure".to_string() };
    let params = sub::Params {
        nu: disc.nu,
        e: disc.e,
        a: hertz.a,
        ph: hertz.ph,
        rect: mesh::Rect { x0: scene.reynolds.x_min, x1: scene.reynolds.x_max, z0: scene.reynolds.z_min, z1: scene.reynolds.z_max },
        half: false,
        png: scene.output.png,
        vtu: scene.output.vtu,
        traction: &traction,
        method: scene.output.subsurface_recovery,
    };
    let log = |m: String| ctx.log(m);
    let mut obj = sub::recover_and_write(mesh, &u, &params, dir, &log)?;
    obj["friction_coefficient"] = json!(mu);
    obj["solve"] = json!({
        "kind": if reuse { "the main solve's factorisation, one more right-hand side" } else { "rank 0: the disc's own elastic problem (MUMPS Cholesky)" },
        "seconds": cost.seconds, "rss_increase_mb": cost.rss_increase_mb, "mumps_factor_mb": cost.factor_mb, "unknowns": cost.unknowns,
        "main_solve_s": main_solve_s,
    });
    obj["total_s"] = json!(t0.elapsed().as_secs_f64());
    ctx.log(format!("subsurface: {:.2} s (solve {:.2} s, main solve {:.2} s)", t0.elapsed().as_secs_f64(), cost.seconds, main_solve_s));
    Ok(Some(obj))
}

pub fn run(ctx: &Context, scene: &Scene) -> Result<(), Error> {
    let hertz = scene.hertz();
    let eq = scene.equivalent_solid();
    let comm = petsc::comm_world();
    ctx.log(format!("Hertz: a = {:.5e} m, p_H = {:.5e} Pa; equivalent solid E = {:.4e} Pa, nu = {:.4}", hertz.a, hertz.ph, eq.e, eq.nu));

    let t0 = Instant::now();
    let mesh = build_mesh(scene, false)?;
    let part = mesh::partition(&mesh, ctx.size);
    let quality = mesh::quality(&mesh);
    let dofs = DofMap::new(&mesh, &part, ctx.size);
    let mesh_s = t0.elapsed().as_secs_f64();
    crate::interrupt::check("the mesh")?;
    ctx.log(format!(
        "mesh: {} P2 tetrahedra, {} nodes, {} contact triangles, h_c = {} a, {} displacement unknowns, worst dihedral {:.1} deg",
        mesh.tets.len(),
        mesh.nodes.len(),
        mesh.contact_tris.len(),
        mesh.contact_size,
        dofs.total(),
        quality.min_dihedral_deg
    ));

    let t1 = Instant::now();
    let k = assembly::assemble_stiffness(comm, &mesh, &part, &dofs, ctx.rank, eq.nu)?;
    let factor = assembly::traction_factor(eq.nu);
    let b = assembly::assemble_pressure_load(comm, &mesh, &part, &dofs, ctx.rank, factor, &|v| {
        hertz_load::hertz_p2_load(v, HERTZ_SPLIT_DEPTH)
    })?;
    let assembly_s = t1.elapsed().as_secs_f64();
    crate::interrupt::check("the assembly")?;
    // Load check: the assembled traction sums to -factor * integral of P = -factor * 2 pi / 3.
    let load_num = {
        let local = b.local_values()?;
        collective::sum_f64(&ctx.world, local.iter().sum::<f64>())
    };
    let load_exact = -factor * 2.0 * std::f64::consts::PI / 3.0;
    let load_error_rel = (load_num - load_exact).abs() / load_exact.abs();
    ctx.log(format!("assembly: {:.2} s, {:.0} non-zeros; traction load error {:.2e}", assembly_s, k.nonzeros()?, load_error_rel));

    let t2 = Instant::now();
    petsc::ksp::set_direct_solver_defaults("")?;
    let ksp = Ksp::new(comm, &k)?;
    let x = Vector::new(comm, dofs.local(ctx.rank))?;
    let its = ksp.solve(&b, &x)?;
    let solve_s = t2.elapsed().as_secs_f64();
    crate::interrupt::check("the elastic solve")?;
    ctx.log(format!("solve: {:.2} s ({} KSP iteration(s))", solve_s, its));

    let sol = x.gather_all()?;
    let scale = hertz.a * hertz.a / scene.geometry.ball_radius; // U -> metres
    let u_c = contact_uy(&mesh, &dofs, &sol, 0.0, 0.0)?;
    let u_a = contact_uy(&mesh, &dofs, &sol, 1.0, 0.0)?;
    ctx.log(format!("deflection: U(0) = {:.5} (half-space -1), U(0) - U(a) = {:.5} (half-space -0.5)", u_c, u_c - u_a));
    let peak = collective::max_f64(&ctx.world, crate::output::peak_rss_mb());
    let peak_total = collective::sum_f64(&ctx.world, crate::output::peak_rss_mb());
    let total_s = ctx.start.elapsed().as_secs_f64();
    ctx.write_results(|dir| {
        let subsurface =
            if scene.output.subsurface { Some(subsurface_stresses(ctx, scene, &mesh, &part, &dofs, &ksp, solve_s, dir)?) } else { None };
        if ctx.rank != 0 {
            return Ok(());
        }
        use crate::output::summary::*;
        let summary = DrySummary {
            case: scene.name.clone(),
            ranks: ctx.size,
            converged: true,
            hertz: HertzSummary { a_m: hertz.a, ph_pa: hertz.ph, e_prime_pa: hertz.e_prime },
            equivalent_solid: EquivalentSolidSummary { e_pa: eq.e, nu: eq.nu },
            mesh: MeshSummary {
                elements: mesh.tets.len(),
                nodes: mesh.nodes.len(),
                dofs_total: dofs.total(),
                contact_triangles: mesh.contact_tris.len(),
                contact_size_a: mesh.contact_size,
                worst_quality: Some(quality.min_dihedral_deg),
                worst_quality_measure: "minimum dihedral angle (degrees)".into(),
                max_aspect_ratio: Some(quality.max_aspect_ratio),
            },
            elastic: ElasticSummary {
                u2_center_m: u_c * scale,
                u2_edge_m: u_a * scale,
                u2_center_halfspace_m: -scale,
                u2_difference_halfspace_m: -0.5 * scale,
                traction_load_error_rel: load_error_rel,
            },
            timing: Timing { mesh_s, assembly_s, solve_s, post_s: None, total_s, condensation_s: None, friction_s: None },
            peak_rss_mb: peak,
            peak_rss_mb_all_ranks: peak_total,
            scene: scene.clone(),
        };
        let mut summary = to_json(&summary)?;
        if let Some(Some(s)) = subsurface {
            summary["subsurface"] = s;
        }
        ctx.write_summary_to(dir, &summary)
    })
}
