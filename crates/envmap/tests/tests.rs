//! All integration tests of the `envmap` crate, one module per topic, in one binary.

mod decoder;
mod geometry;
mod invalid;
mod lookup;
mod mip;
mod real_maps;
mod write;

/// Finds `../shared`, or skips a test without it where the run allows.
#[path = "../../../tests/support/shared_data.rs"]
mod shared_data;

use std::path::{Path, PathBuf};

/// `../shared/data/env` next to the workspace: real maps that are never committed. `None` when the
/// calling test is to skip without them ([`shared_data::shared_or_skip`]).
pub fn shared_env() -> Option<PathBuf> {
    shared_data::shared_or_skip(&["data/env"]).map(|shared| shared.join("data/env"))
}

/// The damaged files committed with the crate.
pub fn invalid_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/invalid/envmap")
}

/// `|a - b| <= rel * max(|a|, |b|)`, with a message naming what differs.
#[track_caller]
pub fn assert_close(a: f64, b: f64, rel: f64, what: &str) {
    let scale = a.abs().max(b.abs());
    assert!((a - b).abs() <= rel * scale, "{what}: {a} vs {b}, relative difference {} > {rel}", (a - b).abs() / scale);
}

/// The kind of an error, for tables of expected outcomes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Invalid,
    Unsupported,
    Limit,
    Io,
}

pub fn kind(error: &envmap::Error) -> Kind {
    match error {
        envmap::Error::Invalid(_) => Kind::Invalid,
        envmap::Error::Unsupported(_) => Kind::Unsupported,
        envmap::Error::LimitExceeded(_) => Kind::Limit,
        envmap::Error::Io(_) => Kind::Io,
    }
}

/// The names of the files in `dir`, sorted, leaving out `skip`.
pub fn file_names(dir: &Path, skip: &[&str]) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("listing {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").file_name().to_string_lossy().into_owned())
        .filter(|name| !skip.contains(&name.as_str()))
        .collect();
    names.sort();
    names
}

/// Runs `f`, turning a panic into a failure that names `what`.
#[track_caller]
pub fn no_panic<T>(what: &str, f: impl FnOnce() -> T + std::panic::UnwindSafe) -> T {
    std::panic::catch_unwind(f).unwrap_or_else(|_| panic!("{what}: the reader panicked instead of returning an error"))
}
