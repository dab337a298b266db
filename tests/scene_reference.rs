//! docs/scene-reference.md is the text `ehl-petsc --scene-reference` prints from the schema
//! (src/case/schema.rs), so the documented keys, units, ranges and defaults are the ones the
//! validator applies.
mod common;
use common::*;

#[test]
fn scene_reference_doc_is_current() {
    let out = run_plain(&["--scene-reference"]);
    assert!(out.status.success());
    let generated = String::from_utf8(out.stdout).unwrap();
    let path = repo().join("docs/scene-reference.md");
    let doc = std::fs::read_to_string(&path).expect("docs/scene-reference.md");
    assert!(
        doc == generated,
        "docs/scene-reference.md is stale: regenerate it with \
         `target/release/ehl-petsc --scene-reference > docs/scene-reference.md`"
    );
}
