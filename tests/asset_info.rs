//! `asset-info` on the committed golden and damaged assets, and on an asset `merl-info` writes.

use std::path::PathBuf;

use serde_json::{Value, json};

use crate::support::{root, run, temp_dir, tool};

fn fixture(relative: &str) -> PathBuf {
    root().join("fixtures").join(relative)
}

fn asset_info(args: &[&std::ffi::OsStr]) -> crate::support::Run {
    let mut cmd = tool("asset-info");
    cmd.args(args);
    run(cmd, "")
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
    let r = asset_info(&[file.as_os_str(), "--json".as_ref()]).expect_code(0);
    let json = r.json();
    let expect = |pointer: &str, value: Value| {
        assert_eq!(json.pointer(pointer), Some(&value), "{pointer}\n{r}");
    };
    expect("/header/format_version", 1.into());
    expect("/header/kind", "material-info".into());
    expect("/header/kind_code", 1.into());
    expect("/checksum/ok", true.into());
    expect("/provenance/source_sha256", "47867bf448e306efd5b8b7f38d33d29deb6ebb53e29017f03a0d32d2b7406f00".into());
    expect("/provenance/parameters/0", json!(["interp", "nearest"]));
    expect("/payload/dims", json!([90, 90, 180]));
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
    let r = asset_info(&[file.as_os_str(), "--json".as_ref()]).expect_code(1);
    let json = r.json();
    assert!(
        json["checksum"]["ok"] == false && json["header"]["format_version"] == 1 && json["payload"].is_null(),
        "the JSON should show the header, a failed checksum and no payload\n{r}"
    );
}

#[test]
fn unreadable_assets_exit_2_with_one_line_naming_the_problem() {
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
            let mut args = vec![file.as_os_str()];
            if json {
                args.push("--json".as_ref());
            }
            let r = asset_info(&args).expect_code(2).expect_error(&file, needle);
            assert!(r.stdout.is_empty(), "nothing belongs on stdout\n{r}");
        }
    }
}

#[test]
fn help_explains_the_exit_status() {
    asset_info(&["--help".as_ref()]).expect_code(0).expect_stdout("Exit status: 0").expect_stdout("--json");
    asset_info(&[]).expect_code(2);
}

#[test]
fn merl_info_writes_an_asset_that_asset_info_verifies() {
    let dir = temp_dir();
    let table = dir.path().join("lambert.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["lambertian", "--albedo", "0.25,0.5,0.75", "--out"]).arg(&table);
    run(cmd, "").expect_code(0);
    let out = dir.path().join("lambert.info.asset");
    let mut cmd = tool("merl-info");
    cmd.arg(&table).arg("--asset").arg(&out);
    run(cmd, "").expect_code(0);

    let r = asset_info(&[out.as_os_str(), "--json".as_ref()]).expect_code(0);
    let json = r.json();
    let source_sha = asset::hex(&asset::sha256_file(&table).unwrap());
    assert_eq!(json["provenance"]["source_sha256"], source_sha.as_str(), "{r}");
    assert_eq!(json["provenance"]["source_name"], "lambert.binary", "{r}");
    assert_eq!(json["provenance"]["tool"], "merl-info", "{r}");
    let albedo = json["payload"]["albedo_rgb"].as_array().unwrap();
    assert_eq!(albedo.len(), 4, "{r}");
    for rgb in albedo {
        for (v, want) in rgb.as_array().unwrap().iter().zip([0.25, 0.5, 0.75]) {
            assert!((v.as_f64().unwrap() - want).abs() < 0.01 * want, "{rgb} vs {want}\n{r}");
        }
    }
    // No temporary file is left beside the outputs.
    let mut names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    names.sort();
    assert_eq!(names, ["lambert.binary", "lambert.info.asset"]);
}

#[test]
fn a_closed_stdout_ends_the_tool_quietly() {
    // `asset-info x --json | head -1`: the reader goes away; the tool must not panic.
    let file = fixture("assets/golden-v1-material-info.asset");
    let mut cmd = tool("asset-info");
    cmd.arg(&file).arg("--json").stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped());
    let mut child = cmd.spawn().unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
