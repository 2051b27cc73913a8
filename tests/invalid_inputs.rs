//! Every damaged input gives exit 2 and a one-line error naming the file and the problem, never
//! a panic. Small damaged files are committed in fixtures/invalid/; those that must be full size
//! (NaN in the payload, trailing bytes) are made here.

use std::path::Path;

use crate::support::{root, run, shared_or_skip, temp_dir, tool};

/// Runs `tool FILE`, expects exit `code` and a single `error: reading FILE: ...` line holding
/// `problem`.
fn check(tool_name: &str, path: &Path, code: i32, problem: &str) {
    let mut cmd = tool(tool_name);
    cmd.arg(path);
    let r = run(cmd, "").expect_code(code).expect_error(path, problem);
    assert!(r.stdout.is_empty(), "nothing belongs on stdout\n{r}");
}

#[test]
fn damaged_merl_files_are_rejected() {
    let dir = root().join("fixtures").join("invalid");
    let cases = [
        ("merl-empty.binary", "truncated header: expected 12 bytes, found 0"),
        ("merl-truncated-header.binary", "truncated header: expected 12 bytes, found 8"),
        ("merl-truncated-payload.binary", "truncated payload: a 90 x 90 x 180 table is 34992012 bytes, found 1212"),
        ("merl-wrong-dims.binary", "unsupported dimensions 90 x 90 x 90"),
        ("merl-negative-dims.binary", "not a MERL table: unsupported dimensions -90 x 90 x 180"),
        ("merl-huge-header.binary", "not a MERL table: unsupported dimensions 2048 x 1024 x 1024"),
        ("merl-size-mismatch.binary", "truncated payload: a 90 x 90 x 360 table is 69984012 bytes, found 1212"),
    ];
    for (file, problem) in cases {
        check("merl-info", &dir.join(file), 2, problem);
    }
    check("merl-info", &dir.join("does-not-exist.binary"), 2, "no such file or directory");
    // A table of another size is a MERL table this build does not support, not something else.
    let mut cmd = tool("merl-info");
    cmd.arg(dir.join("merl-wrong-dims.binary"));
    let r = run(cmd, "").expect_code(2);
    assert!(!r.stderr.contains("not a MERL table"), "{r}");
}

/// A file that is no MERL table at all (text) is called that, with the header it read, rather
/// than a table of odd dimensions; by the tool that reads tables and by the bake.
#[test]
fn a_text_file_is_not_a_merl_table() {
    let readme = root().join("README.md");
    let problem = "not a MERL table: unsupported dimensions ";
    check("merl-info", &readme, 2, problem);
    let tmp = temp_dir();
    let out = tmp.path().join("bake");
    let mut cmd = tool("brdf-bake");
    cmd.arg(&readme).arg("--out-dir").arg(&out);
    let r = run(cmd, "").expect_code(2).expect_error(&readme, problem);
    assert!(r.stdout.is_empty(), "nothing belongs on stdout\n{r}");
    assert!(!out.join("manifest.json").exists(), "{r}");
}

#[test]
fn full_size_damaged_merl_files_are_rejected() {
    let tmp = temp_dir();
    let table = merl::analytic::Analytic::Lambertian { albedo: [0.5; 3] }.table(merl::Dims::MERL);
    let mut bytes = table.to_bytes();

    let trailing = tmp.path().join("trailing.binary");
    let mut longer = bytes.clone();
    longer.extend_from_slice(&[0; 8]);
    std::fs::write(&trailing, &longer).unwrap();
    check("merl-info", &trailing, 2, "trailing bytes: a 90 x 90 x 180 table is 34992012 bytes, found 34992020");

    // A NaN in the blue channel at cell (2, 3, 4).
    let at = 12 + 8 * (2 * 1_458_000 + (2 * 90 + 3) * 180 + 4);
    bytes[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    let nan = tmp.path().join("nan.binary");
    std::fs::write(&nan, &bytes).unwrap();
    check("merl-info", &nan, 2, "NaN value in the blue channel at cell (theta_h 2, theta_d 3, phi_d 4)");

    bytes[at..at + 8].copy_from_slice(&f64::NEG_INFINITY.to_le_bytes());
    std::fs::write(&nan, &bytes).unwrap();
    check("merl-info", &nan, 2, "infinite value in the blue channel");
}

/// Count options take a whole number from 1 up and say so: zero (`bandwidth-pca --components 0`
/// was accepted) and negative numbers (clap read `-1` as an unknown flag, "unexpected argument
/// '-1' found") are errors that name the option and what it accepts, before any input is read.
#[test]
fn count_options_say_what_they_accept() {
    let missing = Path::new("no-such-input");
    for (name, option) in [
        ("bandwidth-pca", "--components"),
        ("brdf-bandwidth", "--lobes"),
        ("brdf-bandwidth", "--analysis-size"),
        ("merl-importance", "--samples"),
        ("merl-importance", "--theta-o"),
        ("brdf-bake", "--vectors"),
        ("envmap-bandwidth", "--levels"),
    ] {
        for value in ["0", "-1", "2.5"] {
            let mut cmd = tool(name);
            cmd.arg(missing).args([option, value, "--out-dir", "unused"]);
            let r = run(cmd, "").expect_code(2);
            let says = format!("invalid value '{value}' for '{option}");
            assert!(
                r.stderr.contains(&says) && r.stderr.contains("expected a whole number from 1 up"),
                "{name} {option} {value}: {r}"
            );
        }
    }
}

/// A 98 KB old-RLE Radiance file declaring 16384 x 8192 (exactly the size limit) made the
/// environment tools decode it and then abort on a 1.4 GB (prefilter) or 0.5 GB (bandwidth)
/// allocation under a 4 GB address-space limit. Now each tool estimates its need from the header
/// and refuses it over the budget (4 GiB by default), in one line, with exit 2 and no output;
/// with the budget raised past what the system gives (`ulimit -v`), the estimate cannot be
/// reserved, which is the same kind of error, not an abort.
#[test]
fn a_small_file_declaring_a_huge_map_is_refused_within_the_memory_budget() {
    let Some(shared) = shared_or_skip(&["data/env", "data/hostile"]) else { return };
    let hostile = shared.join("data/hostile/repro-oldrle-16384x8192-abort.hdr");
    let tmp = temp_dir();
    for (name, need) in [("envmap-prefilter", "needs about 7.5 GiB"), ("envmap-bandwidth", "needs about 10 GiB")] {
        let out = tmp.path().join(name);
        let mut cmd = tool(name);
        cmd.arg(&hostile).arg("--out-dir").arg(&out);
        run(cmd, "").expect_code(2).expect_error(&hostile, need).expect_error(&hostile, "memory budget of 4 GiB");
        assert!(!out.exists(), "{name} wrote {}", out.display());
    }
    let mut cmd = std::process::Command::new("sh");
    let prefilter = tool("envmap-prefilter");
    cmd.arg("-c").arg(r#"ulimit -v 4000000 && exec "$0" "$@""#).arg(prefilter.get_program()).arg(&hostile);
    cmd.args(["--max-memory", "64G", "--out-dir"]).arg(tmp.path().join("raised"));
    run(cmd, "").expect_code(2).expect_error(&hostile, "the system cannot provide it");
    // The budget applies to small maps too, and --max-memory says what it accepts.
    let map = shared.join("data/env/quarry_01_1k.hdr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&map).args(["--max-memory", "16M", "--out-dir"]).arg(tmp.path().join("small"));
    run(cmd, "").expect_code(2).expect_error(&map, "a 1024 x 512 map needs about 40 MiB for this job");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&map).args(["--max-memory", "lots", "--out-dir"]).arg(tmp.path().join("small"));
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("expected a size such as 4G, 512M"), "{r}");
}
