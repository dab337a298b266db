//! Scenes simulate only the effects they ask for (issue 5): each switch changes what is
//! computed (unknowns, phases in "timing"), not only the numbers.
mod common;
use common::*;

/// Table 2 (Ue = 2 m/s) on the plain 0.25a mesh: uniform kinematics, so the scene is
/// symmetric about z = 0 and is solved on the half domain unless symmetry is off. The
/// two solutions must agree (the half domain is exact for a symmetric scene: the mirror of
/// a solution is a solution); 0.5 % is the bar, the measured gap is ~1e-5.
#[test]
fn half_domain_matches_full_domain_with_half_the_unknowns() {
    let dir = scratch("effects-symmetry");
    let base = table2_ue2_with_mesh("contact_size = 0.25");
    let half_scene = write_scene(&dir, "half.toml", &base);
    let full_scene = write_scene(&dir, "full.toml", &base.replace("friction = \"none\"", "friction = \"none\"\nsymmetry = \"off\""));
    let (half_out, full_out) = (dir.join("half"), dir.join("full"));
    for (scene, out_dir) in [(&half_scene, &half_out), (&full_scene, &full_out)] {
        let out = mpirun(2, &[scene.as_str(), "--output", out_dir.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    }
    let (h, f) = (summary(&half_out), summary(&full_out));
    assert_eq!(h["effects"]["symmetry"], "half domain z <= 0");
    assert_eq!(f["effects"]["symmetry"], "full domain");
    for key in ["film.hc_m", "film.hm_m", "pressure.pmax_pa"] {
        let (a, b) = (num(&h, key), num(&f, key));
        assert!((a - b).abs() / b < 5e-3, "{key}: half {a} vs full {b}");
    }
    let (np_h, np_f) = (num(&h, "solver.dofs_reynolds"), num(&f, "solver.dofs_reynolds"));
    let (nu_h, nu_f) = (num(&h, "solver.dofs_elastic"), num(&f, "solver.dofs_elastic"));
    assert!(np_h < 0.55 * np_f && nu_h < 0.55 * nu_f, "unknowns: half ({nu_h}, {np_h}) vs full ({nu_f}, {np_f})");
    assert!(num(&h, "pressure.load_error_rel") < 1e-6);
    // The mirrored outputs cover the whole rectangle: the x = 0 profile spans z in [-3a, 3a]
    // and is symmetric.
    let prof = std::fs::read_to_string(half_out.join("profile_x0.csv")).unwrap();
    let rows: Vec<Vec<f64>> = prof.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    let n = rows.len();
    assert_eq!(n, 601);
    for i in 0..n / 2 {
        let (a, b) = (&rows[i], &rows[n - 1 - i]);
        assert!((a[1] + b[1]).abs() < 1e-12 && (a[3] - b[3]).abs() <= 1e-12 * a[3].abs().max(1e-9), "profile not mirrored at row {i}");
    }
    // No friction asked for: no friction phase, no friction block.
    assert!(h.get("friction").is_none() && h["timing"].get("friction_s").is_none());
}
