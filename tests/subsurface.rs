//! Subsurface stresses of the dry Hertz scene (cases/dry-hertz.toml, no mesh keys,
//! `output.subsurface = true`: the default mesh with the subsurface core box) against closed-form half-space solutions: Huber's field on
//! the axis of a frictionless contact, and Hamilton's (1983) sliding contact with a
//! tangential traction q = mu p. Tolerances are justified in docs/subsurface.md (the
//! measured errors on this mesh and their convergence under refinement).
mod common;
use common::*;
use ehl_petsc::solid::hertz_stress::{huber_axis, sliding_von_mises_max};

const NU: f64 = 0.3;

fn run_dry(name: &str, extra: &[&str]) -> (std::path::PathBuf, serde_json::Value) {
    let dir = scratch(name);
    let scene = repo().join("cases/dry-hertz.toml");
    let mut args = vec![
        scene.to_str().unwrap(),
        "--output",
        dir.to_str().unwrap(),
        "--set",
        "output.subsurface=true",
        "--set",
        "effects.friction=none",
    ];
    args.extend_from_slice(extra);
    let out = mpirun(1, &args);
    assert!(out.status.success(), "{name} failed:\n{}", text(&out));
    let s = summary(&dir);
    (dir, s)
}

/// Huber (Johnson Eq. 3.45) along the axis from the surface to 2 a: sigma_y (the normal
/// stress, Johnson's sigma_z) and sigma_x = sigma_z (Johnson's sigma_r) within 1 % of p_H,
/// surface point included (measured: sigma_y 0.65 %, sigma_r 0.12 %); the largest shear
/// stress (Tresca / 2) within 1 % of Huber's maximum (0.310 p_H; measured +0.1 %) and its
/// depth within 1 % of Huber's 0.481 a (measured 0.484 a).
#[test]
fn dry_hertz_subsurface_matches_huber() {
    let (dir, s) = run_dry("subsurface-huber", &[]);
    let (a, ph) = (num(&s, "hertz.a_m"), num(&s, "hertz.ph_pa"));
    let csv = std::fs::read_to_string(dir.join("subsurface_axis.csv")).unwrap();
    let (mut rows, mut worst_y, mut worst_r) = (0, 0.0f64, 0.0f64);
    for line in csv.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let d = v[0] / a;
        if d > 2.0 {
            break;
        }
        let (sz, sr) = huber_axis(d, NU);
        let tol = 0.01;
        let (sxx, syy, szz) = (v[1] / ph, v[2] / ph, v[3] / ph);
        assert!((syy - sz).abs() < tol, "depth {d:.3} a: sigma_y = {syy:.4} p_H, Huber {sz:.4}");
        assert!(
            (sxx - sr).abs() < tol && (szz - sr).abs() < tol,
            "depth {d:.3} a: sigma_x = {sxx:.4}, sigma_z = {szz:.4} p_H, Huber sigma_r {sr:.4}"
        );
        worst_y = worst_y.max((syy - sz).abs());
        worst_r = worst_r.max((sxx - sr).abs().max((szz - sr).abs()));
        rows += 1;
    }
    assert!(rows > 150, "only {rows} axis samples above 2a");
    eprintln!("axis to 2 a: largest error of sigma_y {:.3} %, of sigma_r {:.3} % of p_H", 100.0 * worst_y, 100.0 * worst_r);
    // Huber's maximum shear on the axis, by a fine search of the closed form.
    let (mut tmax, mut zmax) = (0.0, 0.0);
    for i in 1..20000 {
        let z = i as f64 * 1e-4;
        let (sz, sr) = huber_axis(z, NU);
        if 0.5 * (sr - sz).abs() > tmax {
            tmax = 0.5 * (sr - sz).abs();
            zmax = z;
        }
    }
    let tau = 0.5 * num(&s, "subsurface.tresca_max_pa") / ph;
    let depth = num(&s, "subsurface.tresca_max_depth_m") / a;
    eprintln!("max shear {tau:.4} p_H at depth {depth:.4} a; Huber {tmax:.4} p_H at {zmax:.4} a");
    assert!((tau / tmax - 1.0).abs() < 0.01, "max shear {tau:.4} p_H vs Huber {tmax:.4} p_H");
    assert!((depth / zmax - 1.0).abs() < 0.01, "max shear at depth {depth:.3} a vs Huber {zmax:.3} a");
    // The maximum lies on the axis (the load is axisymmetric).
    let r = num(&s, "subsurface.tresca_max_x_m").hypot(num(&s, "subsurface.tresca_max_z_m")) / a;
    assert!(r < 0.1, "max shear {r:.3} a off the axis");
    for f in [
        "subsurface.vtu",
        "subsurface_von_mises_xy.png",
        "subsurface_von_mises_zy.png",
        "subsurface_tau_xy_xy.png",
        "subsurface_tau_xy_zy.png",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    // One more right-hand side on the main factorisation: far cheaper than the solve.
    assert!(num(&s, "subsurface.solve.seconds") < 0.5 * num(&s, "timing.solve_s"));
}

/// Hamilton (1983) with q = mu p in +x: the von Mises maximum on the plane of symmetry,
/// value within 0.5 % (measured: 0.08 % for mu = 0.1, 0.05 % for mu = 0.3) and position
/// within 2 % of its distance from the centre. The maximum is flat (within 1 % of its value
/// over about +-0.17 a in x), so it is placed at the vertex of the quadratic fitted to the
/// field near it, not at the largest sample. The solver's frame maps Hamilton's (x, y, z)
/// to (x, z, -y).
fn check_hamilton(mu: f64) {
    let m = mu.to_string();
    let (_, s) = run_dry(
        &format!("subsurface-hamilton-{m}"),
        &[
            "--set",
            "effects.surface_traction=friction",
            "--set",
            &format!("operating.friction_coefficient={m}"),
            "--set",
            "output.png=false",
            "--set",
            "output.vtu=false",
        ],
    );
    let (a, ph) = (num(&s, "hertz.a_m"), num(&s, "hertz.ph_pa"));
    let (vref, xref, zref) = sliding_von_mises_max(NU, mu);
    let v = num(&s, "subsurface.von_mises_max_z0_pa") / ph;
    let (x, d) = (num(&s, "subsurface.von_mises_max_z0_x_m") / a, num(&s, "subsurface.von_mises_max_z0_depth_m") / a);
    eprintln!(
        "mu = {mu}: von Mises max {v:.4} p_H at x = {x:.4} a, depth {d:.4} a; Hamilton {vref:.4} at x = {xref:.4} a, depth {zref:.4} a"
    );
    assert!((v / vref - 1.0).abs() < 0.005, "mu = {mu}: von Mises max {v:.4} p_H vs Hamilton {vref:.4}");
    // The position within 2 % of its distance from the contact centre (0.0098 a at mu = 0.1,
    // 0.0107 a at mu = 0.3; measured 0.0027 a and 0.0044 a).
    let off = (x - xref).hypot(d - zref);
    assert!(
        off < 0.02 * xref.hypot(zref),
        "mu = {mu}: maximum at ({x:.4}, depth {d:.4}) a vs Hamilton ({xref:.4}, {zref:.4}) a: {off:.4} a apart"
    );
    // Over the whole region the maximum is the same (the plane of symmetry holds it).
    let v3 = num(&s, "subsurface.von_mises_max_pa") / ph;
    assert!((v3 / v - 1.0).abs() < 0.01, "3D maximum {v3:.4} vs plane {v:.4}");
}

#[test]
fn sliding_hertz_mu_0_1_matches_hamilton() {
    check_hamilton(0.1);
}

#[test]
fn sliding_hertz_mu_0_3_matches_hamilton() {
    check_hamilton(0.3);
}

/// The lubricated path on a small, lightly loaded scene (minimal.toml at L = 100 N, h_c =
/// 0.5 a, SRR = 5 %): the files, the pressure-only maxima next to the friction ones, and
/// the surface traction seen by the recovered field: the largest compression is the
/// largest film pressure (within 10 % on this coarse mesh: the P2 stress at the face) and
/// the friction traction (fx about 0.008) changes the von Mises maximum by less than 2 %.
#[test]
fn lubricated_subsurface_outputs() {
    let dir = scratch("subsurface-lubricated");
    let scene = repo().join("cases/examples/minimal.toml");
    let args = [
        scene.to_str().unwrap(),
        "--output",
        dir.to_str().unwrap(),
        "--set",
        "output.subsurface=true",
        "--set",
        "effects.surface_traction=friction",
        "--set",
        "mesh.contact_size=0.5",
        "--set",
        "operating.load=100",
        "--set",
        "operating.entrainment_speed=5",
        "--set",
        "operating.slide_to_roll=0.05",
    ];
    let out = mpirun(2, &args);
    assert!(out.status.success(), "lubricated subsurface run failed:\n{}", text(&out));
    let s = summary(&dir);
    for f in ["subsurface.vtu", "subsurface_axis.csv", "subsurface_von_mises_xy.png", "subsurface_tau_xy_zy.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let pmax = num(&s, "pressure.pmax_pa");
    let comp = num(&s, "subsurface.compression_max_pa");
    assert!((comp / pmax - 1.0).abs() < 0.1, "largest compression {comp:.4e} Pa vs pmax {pmax:.4e} Pa");
    let (vm, vm0) = (num(&s, "subsurface.von_mises_max_pa"), num(&s, "subsurface.pressure_only.von_mises_max_pa"));
    assert!(vm != vm0 && (vm / vm0 - 1.0).abs() < 0.02, "von Mises max {vm:.4e} with friction, {vm0:.4e} without");
    assert!(num(&s, "subsurface.solve.seconds") > 0.0 && num(&s, "subsurface.solve.mumps_factor_mb") > 0.0);
}
