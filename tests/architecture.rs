//! ARCHITECTURE.md's dependency statements held to `cargo metadata`: the list of each package's
//! workspace dependencies, the order that makes them point one way, and the outside crates that
//! belong to named packages. A statement that becomes false fails here.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

type Graph = BTreeMap<String, BTreeSet<String>>;

/// The `text` blocks of ARCHITECTURE.md's "Dependencies" section, in order.
fn dependency_blocks() -> Vec<String> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("ARCHITECTURE.md");
    let text = std::fs::read_to_string(&path).expect("ARCHITECTURE.md is readable");
    let start = text.find("\n## Dependencies\n").expect("ARCHITECTURE.md has a Dependencies section");
    let section = &text[start + 1..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let mut blocks = Vec::new();
    let mut rest = section;
    while let Some(open) = rest.find("```text\n") {
        let body = &rest[open + 8..];
        let close = body.find("```").expect("a closed code block");
        blocks.push(body[..close].to_string());
        rest = &body[close + 3..];
    }
    blocks
}

/// `name -> a b c` lines, in their order.
fn parse_lines(block: &str, separator: &str) -> Vec<(String, BTreeSet<String>)> {
    block
        .lines()
        .filter(|line| !line.trim().is_empty())
        .map(|line| {
            let (name, rest) = line.split_once(separator).unwrap_or_else(|| panic!("no '{separator}' in {line:?}"));
            (name.trim().to_string(), rest.split_whitespace().map(str::to_string).collect())
        })
        .collect()
}

/// Each workspace package's normal dependencies: on workspace packages, and on outside crates.
fn metadata() -> (Graph, Graph) {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo runs");
    assert!(output.status.success(), "cargo metadata failed: {}", String::from_utf8_lossy(&output.stderr));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("cargo metadata prints JSON");
    let packages = json["packages"].as_array().expect("a package list");
    let members: BTreeSet<String> = packages.iter().map(|p| p["name"].as_str().unwrap().to_string()).collect();
    let (mut inside, mut outside) = (Graph::new(), Graph::new());
    for package in packages {
        let name = package["name"].as_str().unwrap().to_string();
        if name == env!("CARGO_PKG_NAME") {
            continue; // the workspace root holds only the end-to-end tests
        }
        let normal = package["dependencies"].as_array().unwrap().iter().filter(|d| d["kind"].is_null());
        for dependency in normal {
            let dependency = dependency["name"].as_str().unwrap().to_string();
            let graph = if members.contains(&dependency) { &mut inside } else { &mut outside };
            graph.entry(name.clone()).or_default().insert(dependency);
        }
        inside.entry(name).or_default();
    }
    (inside, outside)
}

#[test]
fn architecture_states_every_workspace_dependency_and_they_point_one_way() {
    let blocks = dependency_blocks();
    assert_eq!(blocks.len(), 2, "the Dependencies section holds the package list and the outside crates");
    let listed = parse_lines(&blocks[0], "->");
    let (inside, _) = metadata();

    let mut seen = BTreeSet::new();
    for (name, dependencies) in &listed {
        let actual =
            inside.get(name).unwrap_or_else(|| panic!("ARCHITECTURE.md lists {name}, not a workspace package"));
        assert_eq!(dependencies, actual, "ARCHITECTURE.md: {name}'s workspace dependencies (listed, then actual)");
        let later: Vec<_> = dependencies.difference(&seen).collect();
        assert!(later.is_empty(), "ARCHITECTURE.md: {name} depends on {later:?}, listed below it");
        assert!(seen.insert(name.clone()), "ARCHITECTURE.md lists {name} twice");
    }
    let unlisted: Vec<_> = inside.keys().filter(|name| !seen.contains(*name)).collect();
    assert!(unlisted.is_empty(), "ARCHITECTURE.md's dependency list misses {unlisted:?}");
}

#[test]
fn architecture_names_every_package_that_uses_a_confined_outside_crate() {
    let blocks = dependency_blocks();
    let (_, outside) = metadata();
    for (krate, owners) in parse_lines(&blocks[1], ":") {
        let actual: BTreeSet<String> =
            outside.iter().filter(|(_, deps)| deps.contains(&krate)).map(|(name, _)| name.clone()).collect();
        assert!(!actual.is_empty(), "ARCHITECTURE.md confines {krate}, which no package uses");
        assert_eq!(owners, actual, "ARCHITECTURE.md: the packages that depend on {krate} (listed, then actual)");
    }
}
