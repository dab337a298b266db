//! README.md stays true: its scene-file reference is the one the binary prints.
mod common;
use common::*;

#[test]
fn readme_scene_reference_is_current() {
    let out = run_plain(&["--scene-reference"]);
    assert!(out.status.success());
    let generated = String::from_utf8(out.stdout).unwrap();
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let start = readme.find("<!-- scene-reference:start -->\n").expect("start marker") + "<!-- scene-reference:start -->\n".len();
    let end = readme.find("<!-- scene-reference:end -->").expect("end marker");
    assert_eq!(&readme[start..end], generated, "README scene reference is stale: regenerate it with `ehl-petsc --scene-reference`");
}
