//! Runs the built `asset-info` on the committed golden and damaged assets and checks its
//! output and exit status. A failure prints the command, its stdout and its stderr.

use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::Value;

fn fixture(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures").join(relative)
}

struct Run {
    command: String,
    output: Output,
}

impl Run {
    fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }
    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }
    /// Panics with everything a reader needs to see why, without running it again.
    fn fail(&self, why: &str) -> ! {
        panic!(
            "{why}\ncommand: {}\nstatus: {}\n--- stdout\n{}--- stderr\n{}",
            self.command,
            self.output.status,
            self.stdout(),
            self.stderr()
        )
    }
    fn expect_code(&self, code: i32) -> &Run {
        if self.output.status.code() != Some(code) {
            self.fail(&format!("expected exit status {code}"));
        }
        self
    }
    fn expect_stdout(&self, needle: &str) -> &Run {
        if !self.stdout().contains(needle) {
            self.fail(&format!("stdout lacks {needle:?}"));
        }
        self
    }
    fn json(&self) -> Value {
        serde_json::from_str(&self.stdout()).unwrap_or_else(|e| self.fail(&format!("stdout is not json: {e}")))
    }
    /// stderr is exactly one line `error: reading FILE: problem`, the problem lower case and
    /// containing `needle`.
    fn expect_error(&self, file: &std::path::Path, needle: &str) -> &Run {
        let stderr = self.stderr();
        let prefix = format!("error: reading {}: ", file.display());
        let Some(problem) = stderr.strip_suffix('\n').and_then(|s| s.strip_prefix(&prefix)) else {
            self.fail(&format!("stderr is not one line starting with {prefix:?}"));
        };
        if problem.contains('\n') || !problem.contains(needle) || problem.ends_with('.') {
            self.fail(&format!("expected one line naming {needle:?}, no trailing period"));
        }
        if problem.starts_with(|c: char| c.is_uppercase()) {
            self.fail("the message should start in lower case");
        }
        self
    }
}

fn asset_info(args: &[&std::ffi::OsStr]) -> Run {
    let exe = env!("CARGO_BIN_EXE_asset-info");
    let output = Command::new(exe).args(args).output().expect("running asset-info");
    let command = std::iter::once(exe.to_owned())
        .chain(args.iter().map(|a| a.to_string_lossy().into_owned()))
        .collect::<Vec<_>>()
        .join(" ");
    Run { command, output }
}

#[test]
fn the_golden_file_is_shown_in_full() {
    let file = fixture("assets/golden-v1-material-info.asset");
    asset_info(&[file.as_os_str()])
        .expect_code(0)
        .expect_stdout("magic            BRDFASET (ok)")
        .expect_stdout("format version   1")
        .expect_stdout("kind             material-info (1)")
        .expect_stdout("checksum           ok")
        .expect_stdout("source           golden-lambert-0.5.binary")
        .expect_stdout("source sha256    47867bf448e306efd5b8b7f38d33d29deb6ebb53e29017f03a0d32d2b7406f00")
        .expect_stdout("tool             merl-info 0.1.0")
        .expect_stdout("quadrature = 64x128")
        .expect_stdout("dims             90 x 90 x 180")
        // 80 degrees, its albedo and its no-data fraction (1/64).
        .expect_stdout("80.00   0.250000   0.375000   0.125000     1.56%");
}

#[test]
fn the_golden_file_as_json() {
    let file = fixture("assets/golden-v1-material-info.asset");
    let run = asset_info(&[file.as_os_str(), "--json".as_ref()]);
    let json = run.expect_code(0).json();
    let expect = |pointer: &str, value: Value| {
        if json.pointer(pointer) != Some(&value) {
            run.fail(&format!("{pointer} should be {value}"));
        }
    };
    expect("/header/format_version", 1.into());
    expect("/header/kind", "material-info".into());
    expect("/header/kind_code", 1.into());
    expect("/checksum/ok", true.into());
    expect("/provenance/source_sha256", "47867bf448e306efd5b8b7f38d33d29deb6ebb53e29017f03a0d32d2b7406f00".into());
    expect("/provenance/parameters/0", serde_json::json!(["interp", "nearest"]));
    expect("/payload/dims", serde_json::json!([90, 90, 180]));
    expect("/payload/albedo_theta_o/1", std::f64::consts::FRAC_PI_6.into());
}

#[test]
fn a_checksum_mismatch_shows_the_header_and_exits_1() {
    let file = fixture("invalid/asset-bad-checksum.asset");
    asset_info(&[file.as_os_str()])
        .expect_code(1)
        .expect_stdout("kind             material-info (1)")
        .expect_stdout("checksum           MISMATCH")
        .expect_error(&file, "checksum mismatch");
    let run = asset_info(&[file.as_os_str(), "--json".as_ref()]);
    let json = run.expect_code(1).json();
    if json["checksum"]["ok"] != false || json["header"]["format_version"] != 1 || !json["payload"].is_null() {
        run.fail("json should show the header, a failed checksum and no payload");
    }
}

#[test]
fn unreadable_files_exit_2_with_one_line_naming_the_problem() {
    let cases = [
        ("invalid/asset-bad-magic.asset", "expected magic \"BRDFASET\""),
        ("invalid/asset-future-version.asset", "unsupported format version 7: this build reads version 1"),
        ("invalid/asset-truncated.asset", "truncated: header declares"),
        ("invalid/asset-huge-length.asset", "payload length 1152921504606846976 bytes exceeds the limit"),
        ("invalid/no-such-file.asset", "no such file"),
    ];
    for (relative, needle) in cases {
        let file = fixture(relative);
        for json in [false, true] {
            let args: Vec<&std::ffi::OsStr> =
                if json { vec![file.as_os_str(), "--json".as_ref()] } else { vec![file.as_os_str()] };
            let run = asset_info(&args);
            run.expect_code(2).expect_error(&file, needle);
            if !run.stdout().is_empty() {
                run.fail("nothing should be printed on stdout");
            }
        }
    }
}

#[test]
fn help_explains_the_exit_status() {
    asset_info(&["--help".as_ref()]).expect_code(0).expect_stdout("Exit status: 0").expect_stdout("--json");
}

#[test]
fn a_missing_argument_is_a_usage_error() {
    asset_info(&[]).expect_code(2);
}
