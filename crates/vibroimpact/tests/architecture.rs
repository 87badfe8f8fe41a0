//! The house as `docs/architecture.md` describes it: every path the page
//! names exists, the folders are the module tree (no path attribute on a
//! module anywhere in the workspace), and every folder of the library opens its
//! `mod.rs` with a map that names each of its files and folders.

use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every file under `dir` (recursively) whose name ends with `ext`.
fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, ext, out);
        } else if path.to_string_lossy().ends_with(ext) {
            out.push(path);
        }
    }
}

/// The backquoted words of `text` that name a file or folder: they hold a
/// `/` or end in a source or document extension (`a.rs::item` names
/// `a.rs`).
fn named_paths(text: &str) -> Vec<String> {
    let mut names = Vec::new();
    for (k, piece) in text.split('`').enumerate() {
        if k % 2 == 0 || piece.contains(' ') || piece.contains('\'') {
            continue;
        }
        let name = piece.split("::").next().unwrap_or(piece);
        let file = [".rs", ".md", ".py", ".pyi", ".toml", ".sh"]
            .iter()
            .any(|e| name.ends_with(e));
        if file || (name.contains('/') && !name.starts_with("--")) {
            names.push(name.to_string());
        }
    }
    names
}

#[test]
fn architecture_page_names_existing_paths() {
    let root = root();
    let page = fs::read_to_string(root.join("docs/architecture.md")).unwrap();
    // Where a short name may stand: the repository, the library's source,
    // the CLI's, the binding's and the package's.
    let bases = [
        "",
        "crates/vibroimpact/src",
        "crates/vibroimpact-cli/src",
        "crates/vibroimpact-py",
        "crates/vibroimpact-py/src",
        "crates/vibroimpact-py/python/vibroimpact",
    ];
    let mut all = Vec::new();
    files(&root.join("crates"), "", &mut all);
    let names = named_paths(&page);
    assert!(names.len() > 40, "only {} paths read", names.len());
    let missing: Vec<&String> = names
        .iter()
        .filter(|name| {
            let trimmed = name.trim_end_matches('/');
            let found = bases.iter().any(|b| root.join(b).join(trimmed).exists());
            // A bare file name (`mod.rs`, `tests.rs`) stands for any file
            // of that name.
            let bare = !trimmed.contains('/')
                && all.iter().any(|p| {
                    p.file_name()
                        .is_some_and(|f| f == trimmed.as_ref() as &std::ffi::OsStr)
                        || p.parent()
                            .and_then(|d| d.file_name())
                            .is_some_and(|d| d == trimmed)
                });
            !found && !bare
        })
        .collect();
    assert!(missing.is_empty(), "docs/architecture.md names {missing:?}");
}

#[test]
fn no_path_attributes() {
    let root = root();
    let mut sources = Vec::new();
    files(&root.join("crates"), ".rs", &mut sources);
    files(&root.join("bench/src"), ".rs", &mut sources);
    let marker = ["#[", "path"].concat();
    let with: Vec<_> = sources
        .iter()
        .filter(|p| fs::read_to_string(p).unwrap().contains(&marker))
        .collect();
    assert!(with.is_empty(), "{with:?}");
}

#[test]
fn every_folder_opens_with_a_map_of_its_files() {
    let src = root().join("crates/vibroimpact/src");
    let mut mods = Vec::new();
    files(&src, "mod.rs", &mut mods);
    assert!(mods.len() > 20, "{} folders", mods.len());
    let mut unnamed = Vec::new();
    for m in &mods {
        let text = fs::read_to_string(m).unwrap();
        let doc: String = text
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .collect::<Vec<_>>()
            .join("\n");
        let dir = m.parent().unwrap();
        for entry in fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            let shown = if path.is_dir() {
                format!("`{name}/`")
            } else {
                format!("`{name}`")
            };
            if name != "mod.rs" && !doc.contains(&shown) {
                unnamed.push(format!("{}: {shown}", dir.display()));
            }
        }
    }
    assert!(unnamed.is_empty(), "{unnamed:#?}");
}
