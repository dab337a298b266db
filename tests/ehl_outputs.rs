//! A lubricated run that converges end to end (light load, coarse mesh, default SUPG)
//! under 2 MPI ranks: the load balance
//! closes, and every output the user looks at is written: summary.json, the two profile
//! CSVs, the PNG maps and profiles, the contact-face VTU.
//! This checks the pipeline, not the film values (see docs/validation.md).
mod common;
use common::*;

#[test]
fn converged_lubricated_run_writes_all_outputs() {
    let dir = scratch("ehl-outputs");
    let scene = table2_ue2_with_mesh("contact_size = 0.5").replace("load = 1500.0", "load = 100.0");
    let path = write_scene(&dir, "scene.toml", &scene);
    let out_dir = dir.join("out");
    let out = mpirun(2, &[path.as_str(), "--output", out_dir.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    let s = summary(&out_dir);
    assert_eq!(s["converged"], true);
    // Load balance: integral of p equals the scene's 100 N (Newton converged to 1e-11).
    let err = s["pressure"]["load_error_rel"].as_f64().unwrap();
    assert!(err < 1e-6, "load error {err}");
    let (hc, hm) = (s["film"]["hc_m"].as_f64().unwrap(), s["film"]["hm_m"].as_f64().unwrap());
    assert!(hc > 0.0 && hm > 0.0 && hm <= hc, "hc {hc} hm {hm}");
    // The typed summary the readers use (restart, paper-findings) reads the same file.
    let typed = ehl_petsc::output::summary::Summary::read(&out_dir).unwrap();
    assert_eq!((typed.film.hc_m, typed.film.hm_m, typed.pressure.load_error_rel), (hc, hm, err));
    assert_eq!(typed.solver.path.len(), s["solver"]["path"].as_array().unwrap().len());
    for f in ["profile_x0.csv", "profile_z0.csv"] {
        let text = std::fs::read_to_string(out_dir.join(f)).unwrap();
        assert!(text.starts_with("x_m,z_m,p_pa,h_m\n"), "{f}");
        assert_eq!(text.lines().count(), 602, "{f}");
    }
    for f in ["pressure_map.png", "film_map.png", "film_map_contact.png", "profile_x0.png", "profile_z0.png"] {
        let bytes = std::fs::read(out_dir.join(f)).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{f} is not a PNG");
    }
    let vtu = std::fs::read(out_dir.join("contact_face.vtu")).unwrap();
    let head = String::from_utf8_lossy(&vtu[..vtu.len().min(4000)]).to_string();
    for name in ["p_pa", "h_m", "u2_m"] {
        assert!(head.contains(&format!("Name=\"{name}\"")), "VTU lacks {name}:\n{head}");
    }
    // No temporary files left behind.
    for e in std::fs::read_dir(&out_dir).unwrap() {
        let n = e.unwrap().file_name().to_string_lossy().to_string();
        assert!(!n.contains(".tmp"), "leftover {n}");
    }
}
