//! `../shared` beside the checkout: the project's real test data (environment maps, the neural
//! fits the MERL tables are made from, hostile files), never committed. One file for the
//! end-to-end tests (`tests/support`) and the crates' own tests, which include it by path.
//!
//! A test that reads `../shared` begins with [`shared_or_skip`], naming what it reads. Absent
//! data is a failure that says where it was expected, except in a run that allows skipping: when
//! `BRDF_TESTS_WITHOUT_SHARED=1` (which `make test` sets when `../shared` is absent) and the whole
//! folder is absent, the test is listed in `target/tests-skipped.txt` and returns. Data that is
//! there but incomplete always fails: CI always has it.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Set to 1 by `make test` when `../shared` is absent.
const WITHOUT_SHARED: &str = "BRDF_TESTS_WITHOUT_SHARED";

/// Where the skipped tests are listed, in the workspace's `target/`: `make test` empties it first
/// and prints it last.
const SKIPPED: &str = "tests-skipped.txt";

/// The workspace root: the nearest folder above this package that holds `Cargo.lock`.
fn workspace_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .find(|dir| dir.join("Cargo.lock").is_file())
        .expect("a Cargo.lock above the package: the workspace root")
}

/// `../shared`; fails, saying where it was expected, when it is missing. For the helpers of tests
/// that began with [`shared_or_skip`].
#[track_caller]
pub fn shared() -> PathBuf {
    let dir = workspace_root().join("..").join("shared");
    assert!(
        dir.join("data").is_dir(),
        "the shared test data is missing: expected it at {} (a checkout of the project's shared/ folder beside \
         this repository; `make test` runs without it, listing the tests it skips)",
        dir.display()
    );
    dir
}

/// `../shared`, for a test that reads `needs` in it (paths inside it: `data/env`), each checked.
/// `None` only when the whole folder is absent and the run allows it: the calling test is listed,
/// with what it needed, in `target/tests-skipped.txt` and on stderr, and returns.
#[track_caller]
pub fn shared_or_skip(needs: &[&str]) -> Option<PathBuf> {
    let absent = std::fs::symlink_metadata(workspace_root().join("..").join("shared")).is_err();
    if absent && std::env::var_os(WITHOUT_SHARED).is_some_and(|v| v == "1") {
        record_skip(needs);
        return None;
    }
    let dir = shared();
    for need in needs {
        let path = dir.join(need);
        assert!(path.exists(), "the shared test data is incomplete: expected {}", path.display());
    }
    Some(dir)
}

/// Appends `<package> <test>: needs ../shared/<need>, ...` to the list, in one write (tests run
/// on parallel threads), and prints it. The test harness names each test's thread after it.
fn record_skip(needs: &[&str]) {
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("a test on an unnamed thread");
    let needs: Vec<String> = needs.iter().map(|need| format!("../shared/{need}")).collect();
    let line = format!("{} {test}: needs {}\n", env!("CARGO_PKG_NAME"), needs.join(", "));
    eprint!("skipped {line}");
    let target = workspace_root().join("target");
    std::fs::create_dir_all(&target).unwrap_or_else(|e| panic!("creating {}: {e}", target.display()));
    let path = target.join(SKIPPED);
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .and_then(|mut file| file.write_all(line.as_bytes()))
        .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
}
