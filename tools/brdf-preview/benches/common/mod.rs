//! What the previewer's benchmarks share: where the project and the shared data are, and the
//! real-derived MERL tables, made once under target/merl/.

use std::path::PathBuf;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn shared() -> PathBuf {
    let dir = root().join("../shared");
    assert!(dir.join("data").is_dir(), "the shared data is missing: expected it at {}", dir.display());
    dir
}

/// A real-derived MERL table's path, made once under target/merl/ by nbrdf2merl.py.
pub fn material_path(name: &str) -> PathBuf {
    let path = root().join("target/merl").join(format!("{name}.binary"));
    if !path.exists() {
        let status = std::process::Command::new("python3")
            .arg(shared().join("tools/nbrdf2merl.py"))
            .arg("--out")
            .arg(root().join("target/merl"))
            .arg(name)
            .status()
            .expect("running python3");
        assert!(status.success(), "nbrdf2merl.py {name} failed (it needs numpy)");
    }
    path
}
