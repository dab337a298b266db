//! The files of a lubricated point's contact face: the centre-line profiles (CSV), the
//! maps of p and h and the profile plots (PNG), and the face's fields (VTU).
use crate::ehl::post::FieldsOnFace;
use crate::error::Error;
use crate::friction::pass::FrictionResult;
use std::path::Path;

/// A centre-line profile as CSV: x, z, p, h (and the disc's shear stresses with friction)
/// in SI units, one row per sample.
pub(super) fn write_profiles(dir: &Path, name: &str, rows: &[Vec<f64>], with_tau: bool) -> Result<(), Error> {
    let mut text = String::from(if with_tau { "x_m,z_m,p_pa,h_m,tau_yx_pa,tau_yz_pa\n" } else { "x_m,z_m,p_pa,h_m\n" });
    for r in rows {
        text.push_str(&r.iter().map(|v| format!("{v:e}")).collect::<Vec<_>>().join(","));
        text.push('\n');
    }
    let path = dir.join(name);
    crate::output::write_atomic(&path, text.as_bytes()).map_err(Error::writing(&path))
}

/// PNG maps of p and h on the Reynolds rectangle and PNG plots of the two centre-line
/// profiles (rank 0). Each P2 triangle is drawn as its 4 linear sub-triangles.
pub(super) fn write_plots(
    dir: &Path,
    fields: &FieldsOnFace,
    a: f64,
    ph: f64,
    hs: f64,
    prof_x0: &[Vec<f64>],
    prof_z0: &[Vec<f64>],
) -> Result<(), Error> {
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
    if fields.half() {
        // The mirror image z -> -z of the half domain.
        for i in 0..tris.len() {
            let t: [[f64; 2]; 3] = tris[i];
            tris.push(t.map(|q| [q[0], -q[1]]));
            pv.push(pv[i]);
            hv.push(hv[i]);
        }
    }
    // The film grows to tens of um at the rectangle's corners: colours and the profile's
    // film axis stop at 4 hc so the contact's film shape stays visible.
    let st = fields.stats();
    let hc_um = st.hc * hs * 1e6;
    let h_top = 4.0 * hc_um;
    // The places summary.json gives for hm and pmax, marked on the maps of h and p.
    let (hm, pmax) = ((st.hm_at, "hm"), (st.pmax_at, "pmax"));
    let opts = |label: &str, range: Option<(f64, f64)>, (at, name): ([f64; 2], &str)| MapOpts {
        circle: Some((0.0, 0.0, 1.0)),
        colorbar_label: label.to_string(),
        range,
        markers: vec![(at, name.to_string())],
        ..MapOpts::default()
    };
    for (name, title, vals, label, range, marker) in [
        ("pressure_map.png", "pressure", &pv, "p (GPa)", None, pmax),
        ("film_map.png", "film thickness (colours saturate at 4 hc)", &hv, "h (um)", Some((0.0, h_top)), hm),
    ] {
        let path = dir.join(name);
        crate::output::write_atomic_with(&path, |t| map_plot(t, title, "x / a", "z / a", &tris, vals, &opts(label, range, marker)))?;
    }
    // The contact itself: |x|, |z| <= 1.3 a, colours up to 1.5 hc, so the side lobes, the
    // outlet constriction and the minimum film stand out.
    let zoom = MapOpts { x_range: Some((-1.3, 1.3)), y_range: Some((-1.3, 1.3)), ..opts("h (um)", Some((0.0, 1.5 * hc_um)), hm) };
    // The face mesh the film was solved on (an adaptive run's last level) over the film.
    let mut edges: Vec<[[f64; 2]; 2]> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for tri in &mesh.contact_tris {
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            if seen.insert((a.min(b), a.max(b))) {
                let (pa, pb) = (mesh.nodes[a as usize], mesh.nodes[b as usize]);
                edges.push([[pa[0], pa[2]], [pb[0], pb[2]]]);
                if fields.half() {
                    edges.push([[pa[0], -pa[2]], [pb[0], -pb[2]]]);
                }
            }
        }
    }
    let with_mesh = MapOpts { edges, ..opts("h (um)", Some((0.0, h_top)), hm) };
    let path = dir.join("film_mesh.png");
    crate::output::write_atomic_with(&path, |t| {
        map_plot(t, "contact-face mesh over the film (colours saturate at 4 hc)", "x / a", "z / a", &tris, &hv, &with_mesh)
    })?;
    let path = dir.join("film_map_contact.png");
    crate::output::write_atomic_with(&path, |t| {
        map_plot(t, "film thickness in the contact (colours saturate at 1.5 hc)", "x / a", "z / a", &tris, &hv, &zoom)
    })?;
    for (name, title, rows, col, xl) in [
        ("profile_z0.png", "centre line z = 0 (rolling direction)", prof_z0, 0usize, "x / a"),
        ("profile_x0.png", "centre line x = 0 (transverse)", prof_x0, 1usize, "z / a"),
    ] {
        let x: Vec<f64> = rows.iter().map(|r| r[col] / a).collect();
        let p = Series::new("p (GPa)", x.clone(), rows.iter().map(|r| r[2] * 1e-9).collect(), Style::Line);
        let h = Series::new("h (um)", x, rows.iter().map(|r| r[3] * 1e6).collect(), Style::Line).on_secondary();
        let lo = LineOpts { y2label: "h (um)".into(), y2_range: Some((0.0, h_top)), ..LineOpts::default() };
        let path = dir.join(name);
        crate::output::write_atomic_with(&path, |t| line_plot(t, title, xl, "p (GPa)", &[p, h], &lo))?;
    }
    Ok(())
}

/// VTU of the contact face (P2 triangles, coordinates in m): p, h, the normal
/// displacement u2 and, with friction, the disc shear stress (averaged over the
/// triangles sharing a node), for ParaView.
pub(super) fn write_face_vtu(
    dir: &Path,
    fields: &FieldsOnFace,
    a: f64,
    ph: f64,
    hs: f64,
    friction: Option<&FrictionResult>,
) -> Result<(), Error> {
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
    let mut tau = vec![0.0; 3 * points.len()];
    if let Some(f) = friction {
        let mut count = vec![0.0; points.len()];
        for (t, vals) in &f.nodal {
            for (k, &n) in mesh.contact_tris[*t].iter().enumerate() {
                let i = id[n as usize] as usize;
                tau[3 * i] += vals[k][0];
                tau[3 * i + 2] += vals[k][1];
                count[i] += 1.0;
            }
        }
        for (i, c) in count.iter().enumerate() {
            if *c > 0.0 {
                tau[3 * i] /= c;
                tau[3 * i + 2] /= c;
            }
        }
    }
    let conn: Vec<u32> = mesh.contact_tris.iter().flat_map(|t| t.map(|n| id[n as usize])).collect();
    use crate::output::vtu::{write_vtu_single_type, Field};
    let mut vtu_fields = vec![
        Field { name: "p_pa", components: 1, values: &p },
        Field { name: "h_m", components: 1, values: &h },
        Field { name: "u2_m", components: 1, values: &u2 },
    ];
    if friction.is_some() {
        vtu_fields.push(Field { name: "tau_disc_pa", components: 3, values: &tau });
    }
    let path = dir.join("contact_face.vtu");
    crate::output::write_atomic_with(&path, |t| write_vtu_single_type(t, &points, 22, &conn, &vtu_fields, &[]).map_err(Error::writing(t)))
}
