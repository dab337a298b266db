//! The lubricated scene: the full EHL system (elasticity + Reynolds + load balance) solved
//! by Newton, then film and pressure results written to the output folder.
use super::{collective, Context};
use crate::case::Scene;
use crate::ehl::{driver, layout::Layout, post::FieldsOnFace};
use crate::mesh;
use crate::solid::dofmap::DofMap;
use serde_json::json;
use std::time::Instant;

pub fn run(ctx: &Context, scene: &Scene) -> Result<(), String> {
    let hertz = scene.hertz();
    let scales = scene.scales();
    ctx.log(format!("Hertz: a = {:.5e} m, p_H = {:.5e} Pa; lambda_bar = {:.4e}", hertz.a, hertz.ph, driver::lambda_bar(scene)));
    let t0 = Instant::now();
    let half = false;
    let mesh = super::dry::build_mesh(scene, half)?;
    let part = mesh::partition(&mesh, ctx.size);
    let quality = mesh::quality(&mesh);
    let dofs = DofMap::new(&mesh, &part, ctx.size);
    let layout = Layout::new(&mesh, &part, &dofs, &mesh.spec.contact, half, ctx.size);
    let mesh_s = t0.elapsed().as_secs_f64();
    let (n_u, n_p) = layout.counts();
    ctx.log(format!(
        "mesh: {} P2 tetrahedra, {} nodes, h_c = {} a, {} contact triangles; unknowns: {} elastic + {} pressure + h0 = {}",
        mesh.tets.len(), mesh.nodes.len(), mesh.contact_size, mesh.contact_tris.len(), n_u, n_p, layout.total()
    ));
    let sol = driver::solve(ctx, scene, &mesh, &part, &dofs, &layout, half)?;
    let t_post = Instant::now();
    let fields = FieldsOnFace::new(&mesh, &layout, &sol.x);
    let st = fields.stats();
    let target = if half { std::f64::consts::PI / 3.0 } else { 2.0 * std::f64::consts::PI / 3.0 };
    let load_error = (st.load - target).abs() / target;
    let hs = scales.film_scale();
    let (a, ph) = (hertz.a, hertz.ph);
    ctx.log(format!(
        "result: hc = {:.4e} m, hm = {:.4e} m at ({:.3}a, {:.3}a), pmax = {:.4e} Pa, load error {:.2e}",
        st.hc * hs, st.hm * hs, st.hm_at[0], st.hm_at[1], st.pmax * ph, load_error
    ));
    let peak = collective::max_f64(&ctx.world, crate::output::peak_rss_mb());
    if ctx.rank == 0 {
        let r = &mesh.spec.contact;
        let prof_x0: Vec<Vec<f64>> = fields.profile([0.0, r.z0], [0.0, r.z1], 601).iter().map(|s| vec![s[0] * a, s[1] * a, s[2] * ph, s[3] * hs]).collect();
        let prof_z0: Vec<Vec<f64>> = fields.profile([r.x0, 0.0], [r.x1, 0.0], 601).iter().map(|s| vec![s[0] * a, s[1] * a, s[2] * ph, s[3] * hs]).collect();
        write_profiles(ctx, "profile_x0.csv", &prof_x0)?;
        write_profiles(ctx, "profile_z0.csv", &prof_z0)?;
        if scene.output.png {
            write_plots(ctx, &fields, a, ph, hs, &prof_x0, &prof_z0)?;
        }
        if scene.output.vtu {
            write_face_vtu(ctx, &fields, a, ph, hs)?;
        }
        let hd = scene.hamrock_dowson();
        let summary = json!({
            "case": scene.name,
            "ranks": ctx.size,
            "converged": sol.report.converged,
            "hertz": { "a_m": a, "ph_pa": ph, "e_prime_pa": hertz.e_prime },
            "mesh": {
                "elements": mesh.tets.len(), "nodes": mesh.nodes.len(), "dofs_total": layout.total(),
                "contact_triangles": mesh.contact_tris.len(), "contact_size_a": mesh.contact_size,
                "worst_quality": quality.min_dihedral_deg, "worst_quality_measure": "minimum dihedral angle (degrees)",
            },
            "film": {
                "hc_m": st.hc * hs, "hm_m": st.hm * hs, "hm_x_m": st.hm_at[0] * a, "hm_z_m": st.hm_at[1] * a, "h0_m": st.h0 * hs,
                "hc_hamrock_dowson_m": hd.map(|h| h.central_film_thickness()),
                "hm_hamrock_dowson_m": hd.map(|h| h.minimum_film_thickness()),
            },
            "pressure": { "pmax_pa": st.pmax * ph, "pmax_x_m": st.pmax_at[0] * a, "pmax_z_m": st.pmax_at[1] * a, "pmin_pa": st.pmin * ph, "load_error_rel": load_error },
            "solver": {
                "newton_iterations": sol.newton_total, "snes_reason": sol.report.reason,
                "residual_norm": sol.report.residual_norm,
                "dofs_elastic": n_u, "dofs_reynolds": n_p, "path": sol.steps,
                "penalty": scene.reynolds.penalty, "stabilisation": scene.reynolds.stabilisation.as_str(),
            },
            "timing": { "mesh_s": mesh_s, "assembly_s": sol.assembly_s, "solve_s": sol.solve_s, "post_s": t_post.elapsed().as_secs_f64(), "total_s": ctx.start.elapsed().as_secs_f64() },
            "peak_rss_mb": peak,
            "scene": scene,
        });
        ctx.write_summary(&summary)?;
    }
    Ok(())
}

fn write_profiles(ctx: &Context, name: &str, rows: &[Vec<f64>]) -> Result<(), String> {
    let mut text = String::from("x_m,z_m,p_pa,h_m\n");
    for r in rows {
        text.push_str(&format!("{:e},{:e},{:e},{:e}\n", r[0], r[1], r[2], r[3]));
    }
    let path = ctx.out_dir.join(name);
    crate::output::write_atomic(&path, text.as_bytes()).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// PNG maps of p and h on the Reynolds rectangle and PNG plots of the two centre-line
/// profiles (rank 0). Each P2 triangle is drawn as its 4 linear sub-triangles.
fn write_plots(ctx: &Context, fields: &FieldsOnFace, a: f64, ph: f64, hs: f64, prof_x0: &[Vec<f64>], prof_z0: &[Vec<f64>]) -> Result<(), String> {
    let mesh = fields.mesh;
    use crate::output::plot::{line_plot, map_plot, LineOpts, MapOpts, Series, Style};
    let mut tris = Vec::new();
    let (mut pv, mut hv) = (Vec::new(), Vec::new());
    for tri in &mesh.contact_tris {
        let xz = tri.map(|n| {
            let c = mesh.nodes[n as usize];
            [c[0], c[2]]
        });
        let p = tri.map(|n| fields.p_node(n) * ph * 1e-9);
        let h = tri.map(|n| fields.h_node(n) * hs * 1e6);
        for s in crate::reynolds::P2_SUB_TRIANGLES {
            tris.push(s.map(|k| xz[k]));
            pv.push(s.map(|k| p[k]));
            hv.push(s.map(|k| h[k]));
        }
    }
    // The film grows to tens of um at the rectangle's corners: colours and the profile's
    // film axis stop at 4 hc so the contact's film shape stays visible.
    let h_top = 4.0 * fields.stats().hc * hs * 1e6;
    let opts = |label: &str, range: Option<(f64, f64)>| MapOpts { circle: Some((0.0, 0.0, 1.0)), colorbar_label: label.to_string(), range, ..MapOpts::default() };
    for (name, title, vals, label, range) in [
        ("pressure_map.png", "pressure", &pv, "p (GPa)", None),
        ("film_map.png", "film thickness (colours saturate at 4 hc)", &hv, "h (um)", Some((0.0, h_top))),
    ] {
        let path = ctx.out_dir.join(name);
        crate::output::write_atomic_with(&path, |t| map_plot(t, title, "x / a", "z / a", &tris, vals, &opts(label, range)))?;
    }
    for (name, title, rows, col, xl) in [
        ("profile_z0.png", "centre line z = 0 (rolling direction)", prof_z0, 0usize, "x / a"),
        ("profile_x0.png", "centre line x = 0 (transverse)", prof_x0, 1usize, "z / a"),
    ] {
        let x: Vec<f64> = rows.iter().map(|r| r[col] / a).collect();
        let p = Series::new("p (GPa)", x.clone(), rows.iter().map(|r| r[2] * 1e-9).collect(), Style::Line);
        let h = Series::new("h (um)", x, rows.iter().map(|r| r[3] * 1e6).collect(), Style::Line).on_secondary();
        let lo = LineOpts { y2label: "h (um)".into(), y2_range: Some((0.0, h_top)), ..LineOpts::default() };
        let path = ctx.out_dir.join(name);
        crate::output::write_atomic_with(&path, |t| line_plot(t, title, xl, "p (GPa)", &[p, h], &lo))?;
    }
    Ok(())
}

/// VTU of the contact face (P2 triangles, coordinates in m): p, h and the normal
/// displacement u2, for ParaView.
fn write_face_vtu(ctx: &Context, fields: &FieldsOnFace, a: f64, ph: f64, hs: f64) -> Result<(), String> {
    let mesh = fields.mesh;
    let mut id = vec![u32::MAX; mesh.nodes.len()];
    let mut points = Vec::new();
    let (mut p, mut h, mut u2) = (Vec::new(), Vec::new(), Vec::new());
    for &n in &mesh.contact_nodes {
        id[n as usize] = points.len() as u32;
        let c = mesh.nodes[n as usize];
        points.push([c[0] * a, 0.0, c[2] * a]);
        p.push(fields.p_node(n) * ph);
        h.push(fields.h_node(n) * hs);
        u2.push(fields.layout.uy(fields.x, n) * hs);
    }
    let conn: Vec<u32> = mesh.contact_tris.iter().flat_map(|t| t.map(|n| id[n as usize])).collect();
    use crate::output::vtu::{write_vtu_single_type, Field};
    let path = ctx.out_dir.join("contact_face.vtu");
    crate::output::write_atomic_with(&path, |t| {
        write_vtu_single_type(t, &points, 22, &conn, &[Field { name: "p_pa", components: 1, values: &p }, Field { name: "h_m", components: 1, values: &h }, Field { name: "u2_m", components: 1, values: &u2 }], &[])
            .map_err(|e| format!("cannot write {}: {e}", t.display()))
    })
}
