//! Helpers of the end-to-end tests: build and run the tools, report failures in full, and
//! find or make the test data.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::{Mutex, OnceLock};

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Builds every tool once per test run (so the tests never run a stale binary) and returns the
/// folder that holds them.
fn bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // The test binary lives in target/<profile>/deps/.
        let exe = std::env::current_exe().expect("current_exe");
        let dir = exe.parent().and_then(Path::parent).expect("target/<profile>").to_path_buf();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(root()).args(["build", "--quiet", "--workspace", "--bins"]);
        if dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let status = cmd.status().expect("running cargo build");
        assert!(status.success(), "cargo build --workspace --bins failed");
        dir
    })
}

/// A command running one of the workspace's tools.
pub fn tool(name: &str) -> Command {
    let path = bin_dir().join(name);
    assert!(path.exists(), "{} was not built", path.display());
    let mut cmd = Command::new(path);
    cmd.current_dir(root());
    cmd
}

/// What a tool run printed, with the command for the failure messages.
#[derive(Debug)]
pub struct Run {
    pub command: String,
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// Panics with the command and everything it printed unless it exited with `code`.
    pub fn expect_code(self, code: i32) -> Run {
        assert!(self.code == Some(code), "expected exit {code}\n{self}");
        self
    }

    pub fn expect_stdout(self, needle: &str) -> Run {
        assert!(self.stdout.contains(needle), "stdout lacks {needle:?}\n{self}");
        self
    }

    /// stdout parsed as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.stdout).unwrap_or_else(|e| panic!("stdout is not JSON: {e}\n{self}"))
    }

    /// stderr is exactly one line `error: reading FILE: problem`, the problem in lower case,
    /// without a trailing period, and containing `needle`; and nothing panicked.
    pub fn expect_error(self, file: &Path, needle: &str) -> Run {
        let prefix = format!("error: reading {}: ", file.display());
        let problem = self.stderr.strip_suffix('\n').and_then(|s| s.strip_prefix(&prefix));
        let Some(problem) = problem else { panic!("stderr is not one line starting with {prefix:?}\n{self}") };
        assert!(!problem.contains('\n'), "expected a one-line error\n{self}");
        assert!(problem.contains(needle), "expected the error to say {needle:?}\n{self}");
        assert!(!problem.ends_with('.'), "no trailing period\n{self}");
        assert!(!problem.starts_with(|c: char| c.is_uppercase()) || problem.starts_with("NaN"), "lower case\n{self}");
        self
    }
}

impl std::fmt::Display for Run {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "command: {}\nexit: {:?}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.command, self.code, self.stdout, self.stderr
        )
    }
}

/// Runs a command, feeding `stdin`, and captures what it printed.
pub fn run(mut cmd: Command, stdin: &str) -> Run {
    use std::io::Write;
    let command = format!("{cmd:?}");
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("spawning {command}: {e}"));
    let mut input = child.stdin.take().expect("stdin");
    let data = stdin.to_string();
    let writer = std::thread::spawn(move || input.write_all(data.as_bytes()));
    let Output { status, stdout, stderr } = child.wait_with_output().expect("waiting for the tool");
    writer.join().expect("stdin writer").expect("writing stdin");
    Run {
        command,
        code: status.code(),
        stdout: String::from_utf8_lossy(&stdout).into_owned(),
        stderr: String::from_utf8_lossy(&stderr).into_owned(),
    }
}

/// `../shared` beside the checkout, which holds the real test data; fails with a clear message
/// if it is missing (CI always has it).
pub fn shared() -> PathBuf {
    let dir = root().join("..").join("shared");
    assert!(
        dir.join("data").is_dir(),
        "the shared test data is missing: expected it at {} (a checkout of the project's shared/ folder beside this repository)",
        dir.display()
    );
    dir
}

/// The 20 materials of `../shared/data/nbrdf/merl-dev.json`.
pub const MATERIALS: [&str; 20] = [
    "color-changing-paint3",
    "gold-paint",
    "red-metallic-paint",
    "green-metallic-paint",
    "blue-rubber",
    "white-marble",
    "white-paint",
    "chrome",
    "nickel",
    "pink-fabric",
    "brass",
    "blue-acrylic",
    "gray-plastic",
    "yellow-paint",
    "steel",
    "alum-bronze",
    "black-obsidian",
    "cherry-235",
    "teflon",
    "silver-metallic-paint",
];

/// A MERL table rebuilt from the shared neural fits, made once under target/merl/ with
/// `nbrdf2merl.py` (needs python3 with numpy).
pub fn nbrdf_table(name: &str) -> PathBuf {
    static LOCK: Mutex<()> = Mutex::new(());
    let _guard = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let out = root().join("target").join("merl");
    let path = out.join(format!("{name}.binary"));
    if std::fs::metadata(&path).is_ok_and(|m| m.len() == merl::Dims::MERL.file_bytes()) {
        return path;
    }
    let script = shared().join("tools").join("nbrdf2merl.py");
    let r = run(
        {
            let mut c = Command::new("python3");
            c.arg(&script).arg("--out").arg(&out).arg(name);
            c
        },
        "",
    );
    assert!(
        r.code == Some(0),
        "making {name} with nbrdf2merl.py failed (it needs python3 with numpy: pip install numpy)\n{r}"
    );
    path
}

/// A temporary folder under target/, removed when dropped.
pub fn temp_dir() -> tempfile::TempDir {
    let base = root().join("target").join("test-tmp");
    std::fs::create_dir_all(&base).expect("creating target/test-tmp");
    tempfile::tempdir_in(base).expect("creating a temporary folder")
}

/// Width and height from a PNG's IHDR chunk (right after the 8-byte signature).
pub fn png_size(path: &Path) -> (usize, usize) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{} is not a PNG", path.display());
    assert_eq!(&bytes[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    (be(16), be(20))
}
