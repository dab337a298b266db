//! The convergence-study command end to end (2 ranks, the three coarse levels of the
//! ladder, about 40 s): one row per converged level with growing unknowns, failed levels
//! (the 0.5a mesh is too coarse for Table 2's load and says so) listed, tables and plots.
//! Richardson extrapolation itself is unit-tested (src/app/study.rs).
mod common;
use common::*;

#[test]
fn convergence_study_writes_its_table_and_plots() {
    let dir = scratch("study");
    let scene = std::fs::read_to_string(repo().join("cases/paper/table2-ue2.toml")).unwrap();
    let path = write_scene(&dir, "scene.toml", &scene);
    let out_dir = dir.join("out");
    let out = mpirun(2, &["--convergence-study", "3", path.as_str(), "--output", out_dir.to_str().unwrap()]);
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    let csv = std::fs::read_to_string(out_dir.join("study.csv")).unwrap();
    let rows: Vec<Vec<String>> = csv.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect()).collect();
    let md = std::fs::read_to_string(out_dir.join("study.md")).unwrap();
    let failed = md.matches("\nFailed: level").count();
    assert_eq!(rows.len() + failed, 3, "{csv}\n{md}");
    assert!(rows.len() >= 2, "{md}");
    let col = |name: &str| csv.lines().next().unwrap().split(',').position(|c| c == name).unwrap();
    let (h, np, hc) = (col("h_a"), col("dofs_reynolds"), col("hc"));
    let hs: Vec<f64> = rows.iter().map(|r| r[h].parse().unwrap()).collect();
    assert_eq!(*hs.last().unwrap(), 0.125);
    let n: Vec<f64> = rows.iter().map(|r| r[np].parse().unwrap()).collect();
    assert!(n.windows(2).all(|w| w[1] > 1.5 * w[0]), "refining must add pressure unknowns: {n:?}");
    // Both levels converge to a film of the right size (Table 2: 0.40 um).
    for r in &rows {
        let v: f64 = r[hc].parse().unwrap();
        assert!(v > 0.3e-6 && v < 0.45e-6, "hc {v}");
    }
    assert!(md.contains("Reference values"), "{md}");
    for f in ["study_error_vs_unknowns.png", "study_error_vs_time.png", "level_3/summary.json"] {
        assert!(out_dir.join(f).exists(), "{f} missing");
    }
    // A bad level count is refused with the option named.
    let bad = mpirun(2, &["--convergence-study", "9", path.as_str(), "--output", dir.join("bad").to_str().unwrap()]);
    assert_eq!(bad.status.code(), Some(2), "{}", text(&bad));
    assert!(text(&bad).contains("--convergence-study 9"), "{}", text(&bad));
    assert!(!dir.join("bad").exists(), "a refused study must not create its output folder");
    // So is a first size the mesher cannot make.
    let bad = mpirun(
        2,
        &[
            "--convergence-study",
            "3",
            "--ladder",
            "ring",
            "--first-size",
            "0.1",
            path.as_str(),
            "--output",
            dir.join("bad").to_str().unwrap(),
        ],
    );
    assert_eq!(bad.status.code(), Some(2), "{}", text(&bad));
    assert!(text(&bad).contains("--first-size 0.1"), "{}", text(&bad));
}

/// A ring ladder whose second level crosses `reynolds.coupling = "auto"`'s switch (2,720
/// then 4,824 pressure unknowns: condensed, then monolithic) in one process, each level
/// from the previous one's pressure (`--sequence`). The condensed level's solver defaults
/// (ScaLAPACK) must not leak into the monolithic level, and both films must match the
/// runs of the same meshes from the Hertz start (docs/performance.md's narrow-ring ladder,
/// 2 ranks).
#[test]
fn sequenced_ring_ladder_switches_coupling() {
    let dir = scratch("study-sequence");
    let scene = std::fs::read_to_string(repo().join("cases/paper/table2-ue2.toml")).unwrap();
    let path = write_scene(&dir, "scene.toml", &scene);
    let out_dir = dir.join("out");
    let out = mpirun(
        2,
        &[
            "--convergence-study",
            "2",
            "--ladder",
            "ring",
            "--first-size",
            "0.0625",
            "--sequence",
            path.as_str(),
            "--set",
            "mesh.ring_inner=0.92",
            "--set",
            "mesh.ring_outer=1.02",
            "--output",
            out_dir.to_str().unwrap(),
        ],
    );
    let t = text(&out);
    assert_eq!(out.status.code(), Some(0), "{t}");
    assert!(t.contains("coupling: condensed") && t.contains("coupling: monolithic"), "{t}");
    assert!(t.contains("Newton from the pressure of"), "{t}");
    let md = std::fs::read_to_string(out_dir.join("study.md")).unwrap();
    assert!(md.contains("--sequence"), "{md}");
    // hc, hm of the two meshes from the Hertz start (docs/performance.md "Ladders":
    // 0.36427 / 0.13652 and 0.36301 / 0.13636 um): the same discrete problems, so they
    // agree to the 5 printed digits.
    for (level, hc, hm) in [(1, 0.36427e-6, 0.13652e-6), (2, 0.36301e-6, 0.13636e-6)] {
        let s = summary(&out_dir.join(format!("level_{level}")));
        let (h, m) = (num(&s, "film.hc_m"), num(&s, "film.hm_m"));
        // Half a unit of the 5th printed digit (0.5e-5 um), plus round-off.
        assert!((h - hc).abs() < 0.51e-11 && (m - hm).abs() < 0.51e-11, "level {level}: hc {h}, hm {m}");
    }
}
