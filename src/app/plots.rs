//! PNG plots of the friction pass and of the kinematics (paper Figs. 9-11): shear-stress
//! maps and profile on the disc, and the surface velocity fields of ball and disc.
use crate::ehl::post::FieldsOnFace;
use crate::error::Error;
use crate::friction::pass::FrictionResult;
use crate::mesh::Rect;
use crate::output::plot::{line_plot, map_plot, quiver_plot, LineOpts, MapOpts, QuiverOpts, Series, Style};
use crate::output::write_atomic_with;
use crate::physics::Kinematics;
use std::path::Path;

/// Maps of tau_yx and tau_yz on the disc (MPa, diverging colours) over the Hertz zone
/// and its surroundings, and the profile of both along the line z = `z_line` (m), whose
/// rows are (x, z, p, h, tau_yx, tau_yz) in SI units.
pub fn friction_plots(dir: &Path, fields: &FieldsOnFace, f: &FrictionResult, a: f64, z_line: f64, line: &[Vec<f64>]) -> Result<(), Error> {
    let mesh = fields.mesh;
    let (mut tris, mut tx, mut tz) = (Vec::new(), Vec::new(), Vec::new());
    for (t, vals) in &f.nodal {
        let xz = mesh.contact_tris[*t].map(|n| {
            let c = mesh.nodes[n as usize];
            [c[0], c[2]]
        });
        for s in crate::reynolds::P2_SUB_TRIANGLES {
            tris.push(s.map(|k| xz[k]));
            tx.push(s.map(|k| vals[k][0] * 1e-6));
            tz.push(s.map(|k| vals[k][1] * 1e-6));
        }
    }
    if fields.half() {
        // Mirror image of the half domain: tau_yx even in z, tau_yz odd.
        for i in 0..tris.len() {
            let t: [[f64; 2]; 3] = tris[i];
            tris.push(t.map(|q| [q[0], -q[1]]));
            tx.push(tx[i]);
            tz.push(tz[i].map(|v| -v));
        }
    }
    let opts = |label: &str| MapOpts {
        circle: Some((0.0, 0.0, 1.0)),
        colorbar_label: label.to_string(),
        diverging: true,
        x_range: Some((-1.5, 1.5)),
        y_range: Some((-1.5, 1.5)),
        ..MapOpts::default()
    };
    for (name, title, vals, label) in [
        ("shear_x_map.png", "shear stress tau_yx on the disc", &tx, "tau_yx (MPa)"),
        ("shear_z_map.png", "shear stress tau_yz on the disc", &tz, "tau_yz (MPa)"),
    ] {
        write_atomic_with(&dir.join(name), |t| map_plot(t, title, "x / a", "z / a", &tris, vals, &opts(label)))?;
    }
    if line.is_empty() || line[0].len() < 6 {
        return Ok(());
    }
    let x: Vec<f64> = line.iter().map(|r| r[0] * 1e3).collect();
    let series = [
        Series::new("tau_yx (MPa)", x.clone(), line.iter().map(|r| r[4] * 1e-6).collect(), Style::Line),
        Series::new("tau_yz (MPa)", x.clone(), line.iter().map(|r| r[5] * 1e-6).collect(), Style::Line),
        Series::new("p / 100 (MPa)", x, line.iter().map(|r| r[2] * 1e-8).collect(), Style::Line),
    ];
    let lo = LineOpts { x_range: Some((-1.5 * a * 1e3, 1.5 * a * 1e3)), ..LineOpts::default() };
    let title = format!("shear stresses on the disc along z = {:.3} mm", z_line * 1e3);
    write_atomic_with(&dir.join("shear_profile.png"), |t| line_plot(t, &title, "x (mm)", "stress (MPa)", &series, &lo))
}

/// Arrow maps of the ball and disc surface velocities and of the sliding velocity
/// (U_B - U_D, W_B - W_D) over the Hertz zone (paper Fig. 9).
pub fn velocity_plots(dir: &Path, k: &Kinematics, a: f64, _rect: &Rect) -> Result<(), Error> {
    const N: usize = 13;
    let grid = |f: &dyn Fn(f64, f64) -> [f64; 2]| -> Vec<[f64; 4]> {
        let mut out = Vec::new();
        for i in 0..N {
            for j in 0..N {
                let (x, z) = (-1.5 + 3.0 * i as f64 / (N - 1) as f64, -1.5 + 3.0 * j as f64 / (N - 1) as f64);
                let v = f(x * a, z * a);
                out.push([x, z, v[0], v[1]]);
            }
        }
        out
    };
    let opts = QuiverOpts { circle: Some((0.0, 0.0, 1.0)), unit: "m/s".into(), ..QuiverOpts::default() };
    let ball = grid(&|x, z| [k.u_b(x, z), k.w_b(x, z)]);
    let disc = grid(&|x, z| [k.u_d(x, z), k.w_d(x, z)]);
    let slide = grid(&|x, z| [k.du(x, z), k.dw(x, z)]);
    let mean = grid(&|x, z| [k.um(x, z), k.wm(x, z)]);
    // The mean velocity carries the lubricant; with spin it turns about the spin pole.
    let mean_title = match k.spin_centre() {
        Some(zc) => format!("mean velocity (Um, Wm): turns about the spin pole (0, {:.3} a)", zc / a),
        None => "mean velocity (Um, Wm)".to_string(),
    };
    for (name, title, arrows) in [
        ("velocity_ball.png", "ball surface velocity (U_B, W_B)", &ball),
        ("velocity_disc.png", "disc surface velocity (U_D, W_D)", &disc),
        ("velocity_sliding.png", "sliding velocity (U_B - U_D, W_B - W_D)", &slide),
        ("velocity_mean.png", mean_title.as_str(), &mean),
    ] {
        write_atomic_with(&dir.join(name), |t| quiver_plot(t, title, "x / a", "z / a", arrows, &opts))?;
    }
    Ok(())
}
