//! What the previewer's benchmarks share: where the project and the shared data are, the
//! real-derived MERL tables, made once under target/merl/, and the stamp of a report.

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

/// What a report was measured on: the commit (`(modified)` with uncommitted changes to tracked
/// files), the machine's name and its cores.
pub struct Stamp {
    pub commit: String,
    pub host: String,
    pub cores: usize,
}

impl Stamp {
    pub fn now() -> Stamp {
        let modified = !git(&["status", "--porcelain", "--untracked-files=no"]).is_empty();
        Stamp {
            commit: format!("{}{}", git(&["rev-parse", "--short", "HEAD"]), if modified { " (modified)" } else { "" }),
            host: std::fs::read_to_string("/etc/hostname").map_or_else(|_| "unknown".into(), |h| h.trim().to_string()),
            cores: std::thread::available_parallelism().map_or(0, |n| n.get()),
        }
    }
}

impl std::fmt::Display for Stamp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "commit {}, {} ({} cores)", self.commit, self.host, self.cores)
    }
}

/// `git ARGS` in the project's folder, its output trimmed; "unknown" where git fails.
fn git(args: &[&str]) -> String {
    std::process::Command::new("git")
        .args(args)
        .current_dir(root())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map_or_else(|| "unknown".into(), |o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}
