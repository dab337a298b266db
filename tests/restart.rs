//! Mesh sequencing (`--start-from DIR`), end to end on 2 ranks: table2-ue2 solved on the
//! plain 0.25a mesh, then on the 0.125a-core mesh from that solution and from the Hertz
//! start. Both fine solves are the same discrete problem, so they must agree to Newton's
//! tolerance; the sequenced one must take fewer Newton iterations (that is its purpose).
//! Bad earlier runs are refused before anything is written.
mod common;
use common::*;

fn iterations(dir: &std::path::Path) -> f64 {
    num(&summary(dir), "solver.newton_iterations")
}

#[test]
fn a_finer_mesh_starts_from_a_coarser_solution() {
    let dir = scratch("restart");
    let coarse = write_scene(&dir, "coarse.toml", &table2_ue2_with_mesh("contact_size = 0.25"));
    let fine = write_scene(&dir, "fine.toml", &table2_ue2_with_mesh("contact_size = 0.25\ncore_size = 0.125"));
    let (c_out, f_hertz, f_seq) = (dir.join("coarse"), dir.join("fine-hertz"), dir.join("fine-seq"));
    let out = mpirun(2, &[coarse.as_str(), "--output", c_out.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let csv = std::fs::read_to_string(c_out.join("face_pressure.csv")).unwrap();
    assert!(csv.starts_with("x_m,z_m,p_pa\n") && csv.lines().count() > 1000, "{}", &csv[..200.min(csv.len())]);

    let out = mpirun(2, &[fine.as_str(), "--output", f_hertz.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out));
    let out = mpirun(2, &[fine.as_str(), "--start-from", c_out.to_str().unwrap(), "--output", f_seq.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    assert!(t.contains("Newton from the pressure of"), "{t}");
    assert!(!t.contains("starting over from the Hertz start"), "{t}");
    let (a, b) = (summary(&f_hertz), summary(&f_seq));
    for key in ["film.hc_m", "film.hm_m", "pressure.pmax_pa", "film.h0_m"] {
        let (x, y) = (num(&a, key), num(&b, key));
        // Newton stops at a residual of 1e-8 or below; the two solutions of the same
        // discrete problem agree far below 1e-6 (condensed against monolithic: 1e-12).
        assert!((x - y).abs() <= 1e-6 * x.abs(), "{key}: from Hertz {x}, from the coarse mesh {y}");
    }
    let (n_hertz, n_seq) = (iterations(&f_hertz), iterations(&f_seq));
    assert!(n_seq < n_hertz, "sequenced Newton took {n_seq} iterations, from the Hertz start {n_hertz}");

    // A folder without a run, and a pressure file that does not match the earlier mesh,
    // are refused before the output folder is created.
    let bad = dir.join("bad");
    let out = mpirun(2, &[fine.as_str(), "--start-from", dir.join("nothing").to_str().unwrap(), "--output", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("--start-from") && text(&out).contains("summary.json"), "{}", text(&out));
    assert!(!bad.exists());
    let cut: String = csv.lines().take(csv.lines().count() - 1).map(|l| format!("{l}\n")).collect();
    std::fs::write(c_out.join("face_pressure.csv"), cut).unwrap();
    let out = mpirun(2, &[fine.as_str(), "--start-from", c_out.to_str().unwrap(), "--output", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("face_pressure.csv has"), "{}", text(&out));
    assert!(!bad.exists());

    // An adaptively refined run (more than one level in its accuracy report): its last
    // level's mesh is not rebuilt from the scene, so it is refused with that reason.
    std::fs::write(c_out.join("face_pressure.csv"), &csv).unwrap();
    let mut s = summary(&c_out);
    s["accuracy"] = serde_json::json!({"target": 0.01, "reached": true, "levels": [{}, {}, {}]});
    std::fs::write(c_out.join("summary.json"), serde_json::to_string_pretty(&s).unwrap()).unwrap();
    let out = mpirun(2, &[fine.as_str(), "--start-from", c_out.to_str().unwrap(), "--output", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("refined adaptively (3 levels)"), "{}", text(&out));
    assert!(!bad.exists());
}
