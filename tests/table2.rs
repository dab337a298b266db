//! Table 2 of the paper (pure rolling, Ue = 2 m/s, L = 1500 N) on the scene's mesh (0.25 a,
//! core of 0.125 a over |X|, |Z| <= 1.25, ring of 0.0625 a on 0.85 <= r <= 1.15) under 2 MPI
//! ranks (about 1 minute): Newton converges from the Hertz start with the default SUPG, the
//! load balance closes, and hc, hm land near the paper's FEM values.
//!
//! Tolerances: the acceptance bands around the paper's FEM values (hc 0.40 um
//! within 12 %, hm 0.16 um within 20 %). The paper's hc sits on Hamrock-Dowson, which
//! overestimates heavily loaded contacts; converged multigrid solutions of this problem lie
//! roughly a tenth below it, so the bands are about as tight as the physics allows.
mod common;
use common::*;

#[test]
fn table2_ue2_converges_near_the_paper() {
    let dir = scratch("table2-ue2");
    let out_dir = dir.join("out");
    let scene = repo().join("cases/paper/table2-ue2.toml");
    let out = mpirun(2, &[scene.to_str().unwrap(), "--output", out_dir.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    let s = summary(&out_dir);
    assert_eq!(s["converged"], true);
    assert!(s["solver"]["snes_reason"].as_str().unwrap().starts_with("CONVERGED"), "{}", s["solver"]);
    let err = s["pressure"]["load_error_rel"].as_f64().unwrap();
    assert!(err < 1e-6, "load error {err}");
    let hc = s["film"]["hc_m"].as_f64().unwrap();
    let hm = s["film"]["hm_m"].as_f64().unwrap();
    println!("hc = {hc:.4e} m (paper 0.40e-6), hm = {hm:.4e} m (paper 0.16e-6)");
    assert!((hc / 0.40e-6 - 1.0).abs() < 0.12, "hc = {hc:.4e} m, paper 0.40 um");
    assert!((hm / 0.16e-6 - 1.0).abs() < 0.20, "hm = {hm:.4e} m, paper 0.16 um");
    assert!(hm < hc, "hm {hm} hc {hc}");
}
