//! Helpers of the end-to-end tests: build and run the tools, report failures in full, and
//! find or make the test data.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::{Mutex, OnceLock};

mod shared_data;
pub use shared_data::{shared, shared_or_skip};

/// The workspace root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Builds every tool once per test run (so the tests never run a stale binary) and returns the
/// folder that holds them. With `--tests`, as `make test` builds them: the tools are then resolved
/// with the tests' dev-dependencies' features, so `cargo test` has already built them and this
/// checks only; without it cargo would resolve the features again without them and rebuild wgpu
/// and a hundred other crates for the tools alone.
fn bin_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        // The test binary lives in target/<profile>/deps/.
        let exe = std::env::current_exe().expect("current_exe");
        let dir = exe.parent().and_then(Path::parent).expect("target/<profile>").to_path_buf();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        let mut cmd = Command::new(cargo);
        cmd.current_dir(root()).args(["build", "--quiet", "--workspace", "--bins", "--tests"]);
        if dir.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let status = cmd.status().expect("running cargo build");
        assert!(status.success(), "cargo build --workspace --bins --tests failed");
        dir
    })
}

/// A command running one of the workspace's tools.
pub fn tool(name: &str) -> Command {
    let path = bin_dir().join(name);
    assert!(path.exists(), "{} was not built", path.display());
    let mut cmd = Command::new(path);
    cmd.current_dir(root());
    // The Vulkan loader complains on stderr when XDG_RUNTIME_DIR is unset (as it is under a bare
    // `cargo test`); `make test` sets it, and so does this, to a private folder.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = root().join("target").join("xdg-runtime");
        std::fs::create_dir_all(&dir).expect("creating target/xdg-runtime");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).expect("chmod 0700");
        }
        cmd.env("XDG_RUNTIME_DIR", dir);
    }
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

    /// stdout is exactly one JSON object and nothing else (white space aside): what every tool
    /// prints with `--json`.
    pub fn json_object(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut values = serde_json::Deserializer::from_str(&self.stdout).into_iter::<serde_json::Value>();
        let first = match values.next() {
            Some(Ok(serde_json::Value::Object(map))) => map,
            Some(Ok(other)) => panic!("stdout is JSON but not an object: {other}\n{self}"),
            Some(Err(e)) => panic!("stdout is not JSON: {e}\n{self}"),
            None => panic!("stdout is empty\n{self}"),
        };
        assert!(values.next().is_none(), "stdout holds more than one JSON value\n{self}");
        first
    }

    /// Exit 2, stderr exactly one line `error: ...` containing `needle`, nothing on stdout, and no
    /// panic: how every tool refuses what it cannot do.
    pub fn expect_one_error_line(self, needle: &str) -> Run {
        let line = self.stderr.strip_suffix('\n').unwrap_or(&self.stderr);
        let one = self.code == Some(2) && line.starts_with("error: ") && !line.contains('\n');
        assert!(one && self.stdout.is_empty(), "expected exit 2 and one line `error: ...`\n{self}");
        assert!(line.contains(needle), "expected the error to say {needle:?}\n{self}");
        assert!(!line.contains("panicked") && !line.ends_with('.'), "{self}");
        self
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

/// Runs a command (stdin empty) like [`run`], but fails the test, with what the command printed so
/// far, when it has not ended within `limit` (it is killed): for commands that must not block.
/// Returns how long it ran.
pub fn run_within(mut cmd: Command, limit: std::time::Duration) -> (Run, std::time::Duration) {
    use std::io::Read;
    let command = format!("{cmd:?}");
    let start = std::time::Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("spawning {command}: {e}"));
    let reader = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            String::from_utf8_lossy(&bytes).into_owned()
        })
    };
    let stdout = reader(Box::new(child.stdout.take().expect("stdout")));
    let stderr = reader(Box::new(child.stderr.take().expect("stderr")));
    let status = loop {
        if let Some(status) = child.try_wait().expect("polling the tool") {
            break Some(status);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    };
    let elapsed = start.elapsed();
    let r = Run {
        command,
        code: status.and_then(|s| s.code()),
        stdout: stdout.join().expect("stdout reader"),
        stderr: stderr.join().expect("stderr reader"),
    };
    assert!(status.is_some(), "still running after {limit:?}, killed\n{r}");
    (r, elapsed)
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

/// What [`nbrdf_table`] reads in `../shared` (with `tools/nbrdf2merl.py`), for [`shared_or_skip`].
pub const NBRDF: &str = "data/nbrdf";

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
/// A PSNR a tool reported in JSON under `key` of `object`: `null` is an infinite one (identical
/// pictures, which JSON cannot write as a number); a missing key fails the test, so that a report
/// that lost its figure cannot pass a bar.
pub fn reported_psnr(object: &serde_json::Value, key: &str) -> f64 {
    match object.get(key) {
        Some(serde_json::Value::Null) => f64::INFINITY,
        Some(value) => value.as_f64().unwrap_or_else(|| panic!("{key} is not a number in {object}")),
        None => panic!("no {key} in {object}"),
    }
}

pub fn temp_dir() -> tempfile::TempDir {
    let base = root().join("target").join("test-tmp");
    std::fs::create_dir_all(&base).expect("creating target/test-tmp");
    tempfile::tempdir_in(base).expect("creating a temporary folder")
}

/// Decodes the whole of a PNG (every row and checksum, so a truncated file fails) and returns its
/// width and height; panics naming the file otherwise.
pub fn png_decode(path: &Path) -> (usize, usize) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{} is not a PNG", path.display());
    let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes))
        .read_info()
        .unwrap_or_else(|e| panic!("decoding {}: {e}", path.display()));
    let mut buffer = vec![0; reader.output_buffer_size().expect("a PNG that fits in memory")];
    let info = reader.next_frame(&mut buffer).unwrap_or_else(|e| panic!("decoding {}: {e}", path.display()));
    (info.width as usize, info.height as usize)
}

/// Width and height from an OpenEXR header's `dataWindow` (a box2i: x_min, y_min, x_max, y_max),
/// and the channel list's names: enough to check the file without an EXR decoder.
pub fn exr_header(path: &Path) -> ((usize, usize), Vec<String>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    assert_eq!(&bytes[..4], [0x76, 0x2f, 0x31, 0x01], "{} is not OpenEXR", path.display());
    let mut at = 8;
    let cstr = |at: &mut usize| {
        let end = *at + bytes[*at..].iter().position(|b| *b == 0).expect("a terminated name");
        let s = String::from_utf8_lossy(&bytes[*at..end]).into_owned();
        *at = end + 1;
        s
    };
    let i32_at = |i: usize| i32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    let (mut size, mut channels) = (None, Vec::new());
    loop {
        let name = cstr(&mut at);
        if name.is_empty() {
            break;
        }
        let _kind = cstr(&mut at);
        let len = i32_at(at) as usize;
        let value = at + 4;
        if name == "dataWindow" {
            let [x0, y0, x1, y1] = [0, 4, 8, 12].map(|o| i32_at(value + o));
            size = Some(((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize));
        }
        if name == "channels" {
            // name, then pixel type, pLinear + reserved, x and y sampling: 16 bytes per channel.
            let mut c = value;
            while bytes[c] != 0 {
                channels.push(cstr(&mut c));
                assert_eq!(i32_at(c), 2, "channel {:?} is not 32-bit float", channels.last());
                c += 16;
            }
        }
        at = value + len;
    }
    (size.expect("a dataWindow"), channels)
}

/// A GGX table with a copper-like Fresnel (`merl-synth ggx --alpha 0.2 --f0 0.95,0.64,0.54`),
/// written once per test run at target/test-tmp/ggx-copper.binary: a small but real material for
/// the bake tests.
pub fn ggx_copper() -> &'static Path {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = root().join("target").join("test-tmp");
        std::fs::create_dir_all(&dir).expect("creating target/test-tmp");
        let path = dir.join("ggx-copper.binary");
        let mut cmd = tool("merl-synth");
        cmd.args(["ggx", "--alpha", "0.2", "--f0", "0.95,0.64,0.54", "--out"]).arg(&path);
        run(cmd, "").expect_code(0);
        path
    })
}

/// The environment of the bake tests, in `../shared`: the smallest shared map that works
/// (1024 x 512, a smooth overcast street). The tests that use [`bake_env`], [`reference_bake`] or
/// [`bake_command`] name it to [`shared_or_skip`].
pub const BAKE_ENV: &str = "data/env/potsdamer_platz_1k.hdr";

/// [`BAKE_ENV`] in `../shared`.
pub fn bake_env() -> PathBuf {
    shared().join(BAKE_ENV)
}

/// A finished bake of [`ggx_copper`] in [`bake_env`], made once per test run (with `--force`,
/// so never a leftover) at target/test-tmp/reference-bake; tests copy it rather than bake again.
#[derive(Debug)]
pub struct ReferenceBake {
    pub dir: PathBuf,
    /// The `--json` run that made it.
    pub run: Run,
    /// How long that bake took.
    pub duration: std::time::Duration,
}

pub fn reference_bake() -> &'static ReferenceBake {
    static BAKE: OnceLock<ReferenceBake> = OnceLock::new();
    BAKE.get_or_init(|| {
        let dir = root().join("target").join("test-tmp").join("reference-bake");
        match std::fs::remove_dir_all(&dir) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => panic!("removing {}: {e}", dir.display()),
        }
        let start = std::time::Instant::now();
        let run = run(bake_command(&dir, &["--force", "--json"]), "").expect_code(0);
        ReferenceBake { dir, run, duration: start.elapsed() }
    })
}

/// `brdf-bake` of [`ggx_copper`] in [`bake_env`] into `dir`, with `args`. The lobes are analysed
/// at 128 x 128 rather than the default 1024 x 1024: what these tests check does not depend on it,
/// and the bake takes a fraction of the time (at 64 x 64 most of this GGX's lobes would reach the
/// grid's limit, a validation problem that exits 1).
pub fn bake_command(dir: &Path, args: &[&str]) -> Command {
    let mut cmd = tool("brdf-bake");
    cmd.arg(ggx_copper()).arg("--env").arg(bake_env()).arg("--out-dir").arg(dir);
    cmd.args(["--analysis-size", "128"]).args(args);
    cmd
}

/// Copies the files of `from` (a flat folder) into a new folder `to`.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap_or_else(|e| panic!("creating {}: {e}", to.display()));
    for entry in std::fs::read_dir(from).unwrap_or_else(|e| panic!("listing {}: {e}", from.display())) {
        let entry = entry.expect("a folder entry");
        std::fs::copy(entry.path(), to.join(entry.file_name()))
            .unwrap_or_else(|e| panic!("copying {}: {e}", entry.path().display()));
    }
}
