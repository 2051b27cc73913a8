//! The workspace's own settings: a library or tool whose manifest says it has no unit tests
//! (`test = false`) or no doc examples (`doctest = false`) must not have any, or `cargo test`
//! would skip them without a word. The settings save `make test` the harnesses it would build
//! and run for nothing (19 unit-test binaries and 14 doc-test runs).

use std::path::{Path, PathBuf};

use crate::support::root;

/// The `.rs` files under `dir`, recursively.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("reading {}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files
}

/// The keys set to `false` in the manifest's `[lib]` and `[[bin]]` sections (a line-based reading
/// of the workspace's own simple manifests).
fn disabled(manifest: &str) -> Vec<&str> {
    let mut section = "";
    let mut keys = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            section = line;
        } else if matches!(section, "[lib]" | "[[bin]]")
            && let Some((key, value)) = line.split_once('=')
            && value.trim() == "false"
        {
            keys.push(key.trim());
        }
    }
    keys
}

/// Unit tests in a file: the attributes that make `cargo test` build a harness worth running.
fn has_unit_tests(source: &str) -> bool {
    source.contains("#[test]") || source.contains("#[cfg(test)]")
}

/// Doc examples rustdoc would run: a fence in a doc comment whose info string is empty or Rust's.
fn has_doc_examples(source: &str) -> bool {
    let mut open = false;
    for line in source.lines().map(str::trim_start) {
        let Some(doc) = line.strip_prefix("///").or_else(|| line.strip_prefix("//!")) else { continue };
        let Some(info) = doc.trim_start().strip_prefix("```") else { continue };
        if !open {
            let info = info.trim();
            if info.is_empty()
                || info.split(',').any(|t| matches!(t.trim(), "rust" | "no_run" | "should_panic" | "compile_fail"))
            {
                return true;
            }
        }
        open = !open;
    }
    false
}

#[test]
fn packages_without_unit_tests_or_doc_examples_have_none() {
    let mut checked = 0;
    let mut problems = Vec::new();
    for group in ["crates", "tools"] {
        for entry in std::fs::read_dir(root().join(group)).unwrap() {
            let dir = entry.unwrap().path();
            let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap_or_default();
            let keys = disabled(&manifest);
            for file in sources(&dir.join("src")) {
                let source = std::fs::read_to_string(&file).unwrap();
                if keys.contains(&"test") && has_unit_tests(&source) {
                    problems.push(format!("{}: unit tests in a target with test = false", file.display()));
                }
                if keys.contains(&"doctest") && has_doc_examples(&source) {
                    problems.push(format!("{}: doc examples in a library with doctest = false", file.display()));
                }
            }
            checked += usize::from(!keys.is_empty());
        }
    }
    // The readers themselves, on what they must tell apart.
    assert_eq!(
        disabled("[package]\ntest = false\n[lib]\ndoctest = false\n[[bin]]\ntest = false\n"),
        ["doctest", "test"]
    );
    assert!(has_doc_examples("/// ```\n/// let x = 1;\n/// ```\n"));
    assert!(!has_doc_examples("//! ```text\n//! a -> b\n//! ```\n"));
    assert!(has_unit_tests("#[cfg(test)]\nmod tests {}\n"));
    assert_eq!(checked, 25, "the packages that turn a harness off");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
