//! The default scene that `ci/quickstart` runs (cases/default.toml: Table 2 at Ue = 2 m/s,
//! 5 % sliding, Ree-Eyring friction) on 2 ranks: it converges without a warning line, and
//! its summary carries the film, the pressure and the friction a newcomer looks at, with
//! the plots next to it.
//!
//! Tolerances: the film is checked against the paper's Table 2 FEM values at the same load
//! and speed (hc 0.40 um within 12 %, hm 0.16 um within 20 %, as tests/table2.rs): the
//! isothermal Reynolds equation sees only the mean surface velocity, which sliding leaves
//! at Ue, so 5 % sliding does not move the film. At Moes M ~ 500 the contact is heavily
//! loaded and the pressure is close to Hertz's: pmax within 10 % of p_H. Friction: SRR > 0 (ball faster) drags the
//! disc towards +x, so fx > 0; uniform entrainment is symmetric about z = 0, so fz = 0;
//! and fx lies in the range of EHL traction coefficients at moderate sliding, 0.02-0.1
//! (the paper's Fig. 7 reads about 0.05 at SRR = 5 %, lambda = 90 deg).
mod common;
use common::*;

#[test]
fn default_scene_shows_film_pressure_and_friction_without_warning() {
    let dir = scratch("default-scene");
    let out_dir = dir.join("out");
    let scene = repo().join("cases/default.toml");
    let out = mpirun(2, &[scene.to_str().unwrap(), "--output", out_dir.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    assert!(!t.to_lowercase().contains("warning"), "the default scene prints a warning:\n{t}");
    let s = summary(&out_dir);
    assert_eq!(s["converged"], true);
    assert!(s["solver"]["half_domain"].as_bool().unwrap(), "{}", s["solver"]);
    let err = num(&s, "pressure.load_error_rel");
    assert!(err < 1e-6, "load error {err}");
    let (hc, hm) = (num(&s, "film.hc_m"), num(&s, "film.hm_m"));
    assert!((hc / 0.40e-6 - 1.0).abs() < 0.12, "hc = {hc:.4e} m, paper 0.40 um");
    assert!((hm / 0.16e-6 - 1.0).abs() < 0.20, "hm = {hm:.4e} m, paper 0.16 um");
    let pmax = num(&s, "pressure.pmax_pa");
    let ph = num(&s, "hertz.ph_pa");
    assert!((pmax / ph - 1.0).abs() < 0.1, "pmax {pmax:.4e} Pa, p_H {ph:.4e} Pa");
    let (fx, fz) = (num(&s, "friction.fx"), num(&s, "friction.fz"));
    assert!(fx > 0.02 && fx < 0.1, "fx = {fx}");
    assert_eq!(fz, 0.0, "fz on a symmetric scene");
    for png in ["pressure_map.png", "film_map_contact.png", "shear_x_map.png", "profile_x0.png"] {
        assert!(out_dir.join(png).is_file(), "{png} missing");
    }
}
