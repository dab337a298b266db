//! Bad scenes: a clear error naming the field, a non-zero exit, and no summary.json.
mod common;
use common::*;

const GOOD: &str = include_str!("../cases/dry-hertz.toml");

/// Runs a scene on 2 ranks and checks it fails with `expect` in the message, exit code 2,
/// and leaves no summary.json.
fn rejects(name: &str, scene: &str, expect: &[&str]) {
    let dir = scratch(&format!("bad-{name}"));
    let out_dir = dir.join("out");
    let path = write_scene(&dir, "scene.toml", scene);
    let out = mpirun(2, &[&path, "--output", out_dir.to_str().unwrap()]);
    let msg = text(&out);
    assert_eq!(out.status.code(), Some(2), "{name}: expected exit code 2, got {:?}\n{msg}", out.status.code());
    for e in expect {
        assert!(msg.contains(e), "{name}: message should contain '{e}':\n{msg}");
    }
    assert!(!out_dir.join("summary.json").exists(), "{name}: a summary.json was left behind");
}

#[test]
fn missing_field_is_named() {
    rejects("missing", &GOOD.replace("load = 1500.0", ""), &["operating.load"]);
}

#[test]
fn negative_radius_is_rejected() {
    rejects("radius", &GOOD.replace("ball_radius = 0.08", "ball_radius = -0.08"), &["geometry.ball_radius", "-0.08"]);
}

#[test]
fn poisson_ratio_at_half_is_rejected() {
    rejects("nu", &GOOD.replacen("poisson_ratio = 0.3", "poisson_ratio = 0.5", 1), &["materials.ball.poisson_ratio", "0.5"]);
}

#[test]
fn unknown_key_gets_a_suggestion() {
    rejects("unknown", &GOOD.replace("load = 1500.0", "lod = 1500.0"), &["operating.lod", "load"]);
}

#[test]
fn unreadable_file_is_reported() {
    let dir = scratch("bad-unreadable");
    let missing = dir.join("does-not-exist.toml");
    let out = mpirun(2, &[missing.to_str().unwrap(), "--output", dir.join("out").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("does-not-exist.toml"), "{}", text(&out));
    assert!(!dir.join("out").join("summary.json").exists());
}

#[test]
fn unwritable_output_folder_is_reported_before_solving() {
    let dir = scratch("bad-output");
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"not a folder").unwrap();
    let path = write_scene(&dir, "scene.toml", GOOD);
    let out = mpirun(2, &[&path, "--output", blocker.join("sub").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("output folder"), "{}", text(&out));
    assert!(!text(&out).contains("solve:"), "a solve started before the output check:\n{}", text(&out));
}

#[test]
fn help_documents_petsc_options() {
    let out = run_plain(&["--help"]);
    assert!(out.status.success());
    let t = text(&out);
    assert!(t.contains("PETSC_OPTIONS") && t.contains("-ksp_view") && t.contains("--output"), "{t}");
}

/// Every scene the repository ships (cases/**/*.toml) passes validation: a scene key renamed
/// or a range tightened must not leave a shipped scene behind.
#[test]
fn every_shipped_scene_is_valid() {
    let mut scenes = Vec::new();
    let mut dirs = vec![repo().join("cases")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "toml") {
                scenes.push(p);
            }
        }
    }
    assert!(scenes.len() >= 20, "found only {} scenes", scenes.len());
    for s in &scenes {
        let out = run_plain(&["--check", s.to_str().unwrap()]);
        assert!(out.status.success(), "{} does not validate:\n{}", s.display(), text(&out));
    }
}
