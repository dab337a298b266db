//! Spin kinematics, the friction pass and sweeps end to end (2 MPI ranks, coarse mesh,
//! light load so that it runs in seconds): a two-point tilt sweep at SRR = 5 %.
//! Checks against numbers from outside the code: the kinematics of docs/model.md section 3
//! by hand, the sign convention of section 7 (SRR > 0 drags the disc towards +x), and the
//! paper's findings 4 and 5 (spin lowers fx; |fz| is far below fx). The friction values
//! themselves are checked in the unit tests of the shear law (uniform-film and Newtonian
//! limits) and, on the paper's mesh, by `paper-findings` (docs/paper.md).
mod common;
use common::*;

fn sweep_scene() -> String {
    table2_ue2_with_mesh("contact_size = 0.5")
        .replace("load = 1500.0", "load = 100.0")
        .replace("kinematics = \"uniform\"", "kinematics = \"spin\"")
        .replace("friction = \"none\"", "friction = \"ree-eyring\"")
        .replace("slide_to_roll = 0.0", "slide_to_roll = 0.05")
        + "\n[sweep]\ntilt_angle = [90.0, 2.0]\n"
}

#[test]
fn tilt_sweep_with_friction() {
    let dir = scratch("sweep-friction");
    let path = write_scene(&dir, "scene.toml", &sweep_scene());
    let out_dir = dir.join("out");
    let out = mpirun(2, &[path.as_str(), "--output", out_dir.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    assert!(t.contains("sweep point 2 of 2"), "no progress lines:\n{t}");
    let table = std::fs::read_to_string(out_dir.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{table}");
    assert!(rows.iter().all(|r| r.contains(",converged,")), "{table}");
    let (s90, s2) = (summary(&out_dir.join("point_001")), summary(&out_dir.join("point_002")));
    // Kinematics by hand (docs/model.md section 3): U_BO = Ue (1 + SRR/2) = 2.05 m/s,
    // U_DO = 1.95 m/s, omega_B = U_BO / (R_B sin lambda), omega_D = U_DO / R_D.
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs();
    assert!(rel(num(&s90, "kinematics.U_BO_m_s"), 2.05) < 1e-12);
    assert!(rel(num(&s90, "kinematics.U_DO_m_s"), 1.95) < 1e-12);
    assert!(rel(num(&s90, "kinematics.omega_B_rad_s"), 2.05 / 0.08) < 1e-12);
    assert!(rel(num(&s2, "kinematics.omega_B_rad_s"), 2.05 / (0.08 * 2f64.to_radians().sin())) < 1e-12);
    assert!(rel(num(&s2, "kinematics.omega_D_rad_s"), 1.95 / 0.04) < 1e-12);
    let (fx90, fz90, fx2) = (num(&s90, "friction.fx"), num(&s90, "friction.fz"), num(&s2, "friction.fx"));
    // SRR > 0 (ball faster) drags the disc towards +x; Fx = fx L.
    assert!(fx90 > 0.0 && fx2 > 0.0, "fx {fx90} {fx2}");
    assert!(rel(num(&s90, "friction.Fx_n"), fx90 * 100.0) < 1e-12);
    // Paper finding 4: spin (lambda = 2 deg) lowers fx at SRR = 5 %.
    assert!(fx2 < fx90, "fx(2 deg) = {fx2} >= fx(90 deg) = {fx90}");
    // Paper finding 5: |fz| is orders of magnitude below fx.
    assert!(fz90.abs() < 0.1 * fx90, "fz {fz90} fx {fx90}");
    for f in [
        "shear_x_map.png",
        "shear_z_map.png",
        "shear_profile.png",
        "velocity_ball.png",
        "velocity_disc.png",
        "velocity_sliding.png",
        "velocity_mean.png",
    ] {
        let bytes = std::fs::read(out_dir.join("point_002").join(f)).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{f}");
    }
    for f in ["sweep_film_vs_tilt.png", "sweep_fx_vs_tilt.png", "sweep_film_ratio_vs_tilt.png"] {
        assert!(out_dir.join(f).exists(), "{f} missing");
    }
    let prof = std::fs::read_to_string(out_dir.join("point_002").join("shear_profile.csv")).unwrap();
    assert!(prof.starts_with("x_m,z_m,p_pa,h_m,tau_yx_pa,tau_yz_pa\n"));
    // A sweep point started from its neighbour's state is the operating point's own
    // solution: the same scene at lambda = 2 deg alone, from the Hertz start, on the same
    // mesh. Both Newton solves stop at a residual of 1e-11, so their films agree to about
    // 1e-10 (measured: every number of summary.json within 1e-9); a velocity field, penalty
    // or row scaling left over from the point before would show far above 1e-8.
    let single = write_scene(&dir, "single.toml", sweep_scene().split("\n[sweep]").next().unwrap());
    let single_dir = dir.join("single");
    let out = mpirun(2, &[single.as_str(), "--output", single_dir.to_str().unwrap(), "--set", "operating.tilt_angle=2.0"]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let alone = summary(&single_dir);
    for key in ["film.hc_m", "film.hm_m", "pressure.pmax_pa", "friction.fx", "friction.fz"] {
        let (a, b) = (num(&s2, key), num(&alone, key));
        assert!((a - b).abs() <= 1e-8 * b.abs(), "{key}: sweep point {a} against the point alone {b}");
    }
}

#[test]
fn failed_sweep_point_is_reported_and_the_sweep_goes_on() {
    let dir = scratch("sweep-failure");
    let scene = sweep_scene().replace("tilt_angle = [90.0, 2.0]", "tilt_angle = [90.0, 45.0, 30.0]");
    let path = write_scene(&dir, "scene.toml", &scene);
    let out_dir = dir.join("out");
    let out = mpirun(2, &[path.as_str(), "--output", out_dir.to_str().unwrap(), "-ehl_fail_point", "2"]);
    let t = text(&out);
    assert_ne!(out.status.code(), Some(0), "a failed point must end the run non-zero:\n{t}");
    assert!(t.contains("1 of 3 sweep points failed"), "{t}");
    let table = std::fs::read_to_string(out_dir.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = table.lines().skip(1).collect();
    assert!(rows[0].contains(",converged,") && rows[1].contains(",failed,") && rows[2].contains(",converged,"), "{table}");
    assert!(rows[1].contains("injected failure"), "{table}");
    // Only converged points keep a folder.
    assert!(out_dir.join("point_001/summary.json").exists() && out_dir.join("point_003/summary.json").exists());
    assert!(!out_dir.join("point_002").exists());
}
