//! The documentation's shape: README.md stays a front door (at most 300 lines) that links
//! every file in docs/, and no document points outside the repository (neither by a
//! relative link above its root nor to the project's shared folder).
use std::path::{Component, Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn docs() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo().join("docs"))
        .expect("docs/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    files.sort();
    files
}

/// The targets of the Markdown links `](target)` in `text`, without their #anchor.
fn link_targets(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(i, _)| {
            let rest = &text[i + 2..];
            let end = rest.find(')')?;
            Some(rest[..end].split('#').next().unwrap_or(""))
        })
        .filter(|t| !t.is_empty() && !t.contains("://"))
        .collect()
}

#[test]
fn readme_is_short_and_links_every_doc() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 300, "README.md has {lines} lines; move reference text to docs/");
    let links = link_targets(&readme);
    for f in docs() {
        let name = format!("docs/{}", f.file_name().unwrap().to_str().unwrap());
        assert!(links.contains(&name.as_str()), "README.md does not link {name}");
    }
}

#[test]
fn documents_stay_inside_the_repository() {
    let root = repo();
    let mut files = vec![root.join("README.md"), root.join("CHANGELOG.md")];
    files.extend(docs());
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for outside in ["../shared", "/work/shared"] {
            assert!(!text.contains(outside), "{} refers to {outside}, outside the repository", f.display());
        }
        for target in link_targets(&text) {
            // Resolve the link against the file's folder without touching the disk: a link
            // may name a document another branch adds, but never a path above the root.
            let mut depth = f.parent().unwrap().strip_prefix(&root).unwrap().components().count();
            for c in Path::new(target).components() {
                match c {
                    Component::ParentDir => {
                        assert!(depth > 0, "{}: link {target} leaves the repository", f.display());
                        depth -= 1;
                    }
                    Component::Normal(_) => depth += 1,
                    Component::RootDir | Component::Prefix(_) => {
                        panic!("{}: absolute link {target}", f.display())
                    }
                    Component::CurDir => {}
                }
            }
        }
    }
}
