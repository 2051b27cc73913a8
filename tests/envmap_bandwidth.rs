//! `envmap-bandwidth` end to end on the real maps of `../shared/data/env`: the outputs, their
//! sizes, the printed and JSON statistics (`--json` on stdout, the report on stderr), the FFT
//! diagnostic, and the errors (a file that is not 2:1, bad arguments), and that the EXR holds
//! exactly the `bandwidth` crate's estimate in each mode.

use std::path::Path;

use bandwidth::{Config, latlong_bandwidth, local_bandwidth, local_bandwidth_zero_padded, log1p_luminance};

use crate::support::{Run, exr_header, png_decode, run, shared_or_skip, temp_dir, tool};

/// Runs envmap-bandwidth on `input` into `out_dir` with `args`.
fn envmap_bandwidth(input: &Path, out_dir: &Path, args: &[&str]) -> Run {
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(input).arg("--out-dir").arg(out_dir).args(args);
    run(cmd, "")
}

/// The figures of a `--json` run, after checking that its `files` are the two outputs in
/// `out_dir` as they are on disk.
fn figures(r: &Run, out_dir: &Path) -> serde_json::Value {
    let json = r.json_object();
    let paths: Vec<&str> = json["files"].as_array().unwrap().iter().map(|f| f["path"].as_str().unwrap()).collect();
    let expected = [out_dir.join("env-bandwidth.exr"), out_dir.join("env-bandwidth.png")];
    assert_eq!(paths, expected.iter().map(|p| p.to_str().unwrap()).collect::<Vec<_>>(), "{r}");
    for (file, path) in json["files"].as_array().unwrap().iter().zip(&expected) {
        let len = std::fs::metadata(path).unwrap().len();
        assert_eq!(file["size_bytes"].as_u64(), Some(len), "{}\n{r}", path.display());
    }
    json["figures"].clone()
}

#[test]
fn quarry_end_to_end() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let dir = temp_dir();
    let out = dir.path().join("quarry");
    let input = shared.join("data/env/quarry_01_1k.hdr");
    let r =
        envmap_bandwidth(&input, &out, &[]).expect_code(0).expect_stdout("cycles per radian").expect_stdout("median");
    assert!(r.stdout.contains(&input.display().to_string()), "the report names its input\n{r}");
    assert!(r.stderr.contains("wrote"), "no message about the files written\n{r}");
    assert!(!r.stdout.contains("spearman"), "the fft diagnostic ran without --fft-diagnostic\n{r}");

    assert_eq!(exr_header(&out.join("env-bandwidth.exr")), ((1024, 512), vec!["Y".to_string()]));
    png_decode(&out.join("env-bandwidth.png"));

    // The same run with --json: one object on stdout, the report on stderr.
    let r_json = envmap_bandwidth(&input, &out, &["--json"]).expect_code(0);
    assert!(r_json.stderr.contains("median"), "the report goes to stderr\n{r_json}");
    let json = r_json.json_object();
    let v = figures(&r_json, &out);
    assert_eq!(json["parameters"]["mode"], "angular");
    assert_eq!(v["unit"], "cycles per radian");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64(), v["pixels"].as_u64()),
        (Some(1024), Some(512), Some(524288))
    );
    assert_eq!((json["parameters"]["levels"].as_u64(), json["parameters"]["eps"].as_f64()), (Some(10), Some(0.01)));
    let stat = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("{k} missing or not a number\n{v}"));
    let (min, median, p95, max) = (stat("min"), stat("median"), stat("p95"), stat("max"));
    assert!(0.0 < min && min <= median && median <= p95 && p95 <= max, "{v}");
    // The sun (about 50 pixels of a 86 500 peak) is at the Nyquist limit; little else is.
    let (nyquist, flat) = (stat("nyquist_fraction"), stat("flat_fraction"));
    assert!(nyquist > 0.0 && nyquist < 0.01 && (0.0..=1.0).contains(&flat), "{v}");
    assert!(v["fft_diagnostic"].is_null(), "{v}");
    // The printed Nyquist fraction is the JSON's.
    assert!(r.stdout.contains(&format!("at the Nyquist limit {:.2}%", 100.0 * nyquist)), "{r}");
}

#[test]
fn fft_diagnostic() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let dir = temp_dir();
    let out = dir.path().join("potsdamer");
    let input = shared.join("data/env/potsdamer_platz_1k.hdr");
    let r =
        envmap_bandwidth(&input, &out, &["--fft-diagnostic", "--json"]).expect_code(0).expect_stdout("fft_diagnostic");
    assert!(r.stderr.contains("log2(wavelet / fft)") && r.stderr.contains("spearman"), "{r}");
    png_decode(&out.join("env-bandwidth.png"));
    let v = figures(&r, &out);
    let fft = &v["fft_diagnostic"];
    // 32 x 32 windows every 8 pixels, wholly inside 1024 x 512: 125 x 61.
    assert_eq!(fft["windows"].as_u64(), Some(125 * 61), "{v}");
    assert!(fft["both_positive"].as_u64().is_some() && fft["one_zero"].as_u64().is_some(), "{v}");
    let ratio: Vec<f64> =
        ["p5", "p25", "p50", "p75", "p95"].iter().map(|k| fft["log2_ratio"][k].as_f64().unwrap()).collect();
    assert!(ratio.windows(2).all(|w| w[0] <= w[1]), "{v}");
    assert!(fft["spearman"].as_f64().is_some_and(|s| (-1.0..=1.0).contains(&s)), "{v}");
}

/// A file that is not 2:1 is refused as an environment map, with one line naming it; the
/// spatial modes take it.
#[test]
fn not_two_to_one() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let dir = temp_dir();
    let input = shared.join("data/env/decoder/memorial.exr");
    let out = dir.path().join("m");
    envmap_bandwidth(&input, &out, &[]).expect_code(2).expect_error(&input, "not a lat-long map: 512 x 768");
    assert!(!out.exists());

    for flags in [&["--spatial", "--json"][..], &["--spatial", "--pad", "--json"]] {
        let r = envmap_bandwidth(&input, &out, flags).expect_code(0);
        assert!(r.stderr.contains("cycles per pixel"), "{r}");
        assert_eq!(exr_header(&out.join("env-bandwidth.exr")).0, (512, 768));
        png_decode(&out.join("env-bandwidth.png"));
        let json = r.json_object();
        let v = figures(&r, &out);
        let mode = if flags.contains(&"--pad") { "spatial-padded" } else { "spatial-periodic" };
        assert_eq!(
            (json["parameters"]["mode"].as_str(), v["unit"].as_str()),
            (Some(mode), Some("cycles per pixel")),
            "{r}"
        );
        // Cycles per pixel never exceed the estimator's ceiling, c / 2.
        assert!(v["max"].as_f64().unwrap() <= json["parameters"]["c"].as_f64().unwrap() / 2.0 + 1e-12, "{r}");
    }
}

/// A tiny texture (4 x 4) is enlarged in the picture so that it stays visible.
#[test]
fn tiny_texture() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let dir = temp_dir();
    let out = dir.path().join("t");
    envmap_bandwidth(&shared.join("data/env/decoder/imagers_rgbr4x4.hdr"), &out, &["--spatial", "--pad"])
        .expect_code(0);
    assert_eq!(exr_header(&out.join("env-bandwidth.exr")).0, (4, 4));
    // Enlarged: at 4 x 4 picture pixels the map would be invisible; 64 is a generous floor
    // whatever the legend's layout.
    let (width, height) = png_decode(&out.join("env-bandwidth.png"));
    assert!(width >= 64 && height >= 64, "a {width} x {height} picture of a 4 x 4 texture");
}

#[test]
fn input_errors_name_the_file() {
    let dir = temp_dir();
    let out = dir.path().join("x");
    let missing = dir.path().join("missing.hdr");
    envmap_bandwidth(&missing, &out, &[]).expect_code(2).expect_error(&missing, "no such file");

    let not_an_image = dir.path().join("notes.hdr");
    std::fs::write(&not_an_image, "hello").unwrap();
    envmap_bandwidth(&not_an_image, &out, &["--json"])
        .expect_code(2)
        .expect_error(&not_an_image, "unknown file format");
    assert!(!out.exists());
}

/// Usage errors exit 2 and say what was wrong in one line, as every other error does (clap's own
/// message spans several lines, with the usage); values that only the estimator refuses exit 2
/// with one line.
#[test]
fn bad_arguments() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let input = shared.join("data/env/quarry_01_1k.hdr");
    let dir = temp_dir();
    let out = dir.path().join("bw");
    let usage: [(&[&str], &str); 8] = [
        (&[], "--out-dir"),
        (&["--pad", "--out-dir", "x"], "--spatial"),
        (&["--out-dir", "x", "--frobnicate"], "--frobnicate"),
        (&["--out-dir", "x", "--levels", "many"], "--levels"),
        (&["--out-dir", "x", "--eps", "2"], "2 is not in (0, 1]"),
        (&["--out-dir", "x", "--levels", "0"], "expected a whole number from 1 up"),
        (&["--out-dir", "x", "--eps", "NaN"], "NaN is not in (0, 1]"),
        // `--png` is not an option (the picture is one of the files of `--out-dir`): refused, not
        // ignored.
        (&["--out-dir", "x", "--png", "x.png"], "--png"),
    ];
    for (args, needle) in usage {
        let mut cmd = tool("envmap-bandwidth");
        cmd.arg(&input).args(args);
        let r = run(cmd, "").expect_code(2);
        assert!(r.stderr.contains(needle), "stderr should mention {needle}\n{r}");
        assert!(r.stderr.starts_with("error: ") && r.stderr.lines().count() == 1, "one line\n{r}");
        assert!(r.stdout.is_empty(), "{r}");
    }
    // A value that only the estimator refuses: one line naming the file. (`--levels 0` is a
    // usage error: a count takes a whole number from 1 up.)
    let r = envmap_bandwidth(&input, &out, &["--levels", "11"]).expect_code(2);
    let names_the_file = r.stderr.contains(&input.display().to_string());
    assert!(r.stderr.starts_with("error: ") && names_the_file && r.stderr.lines().count() == 1, "{r}");
    assert!(!out.exists() && !dir.path().join("x").exists());

    let mut cmd = tool("envmap-bandwidth");
    cmd.arg("--help");
    run(cmd, "").expect_code(0).expect_stdout("--spatial").expect_stdout("--fft-diagnostic").expect_stdout("JSON");
}

// The EXR is the library's estimate.

/// Runs the tool with `args` and the outputs in a fresh folder; returns the EXR it wrote, read
/// back (`Y` comes back as `R = G = B`).
fn run_tool(input: &Path, extra: &[&str]) -> envmap::HdrImage {
    let dir = temp_dir();
    envmap_bandwidth(input, dir.path(), extra).expect_code(0);
    envmap::read_image(&dir.path().join("env-bandwidth.exr"), &envmap::Limits::default()).unwrap()
}

/// Every texel of `image` is exactly `expected` as `f32` (the EXR stores `f32`, so equality is
/// exact: the tool and this test run the same deterministic code on the same input).
fn assert_equal(image: &envmap::HdrImage, width: usize, height: usize, expected: &[f64], what: &str) {
    assert_eq!((image.width, image.height), (width, height), "{what}");
    for (i, (texel, e)) in image.rgb.chunks_exact(3).zip(expected).enumerate() {
        assert_eq!(texel, [*e as f32; 3], "{what}: pixel ({}, {})", i % width, i / width);
    }
}

#[test]
fn angular_map_equals_the_library_estimate() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let path = shared.join("data/env/quarry_01_1k.hdr");
    let map = envmap::load(&path).unwrap();
    let image = log1p_luminance(map.width(), map.height(), map.texels()).unwrap();
    let expected = latlong_bandwidth(&image, &Config::default()).unwrap();
    assert!(expected.cycles_per_radian().iter().any(|v| *v > 0.0));
    assert_equal(&run_tool(&path, &[]), 1024, 512, expected.cycles_per_radian(), "quarry, angular");
}

/// A 512 x 768 file (not 2:1) in both spatial modes, and the options reach the library.
#[test]
fn spatial_maps_equal_the_library_estimate() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let path = shared.join("data/env/decoder/memorial.exr");
    let file = envmap::read_image(&path, &envmap::Limits::default()).unwrap();
    let image = log1p_luminance(file.width, file.height, file.rgb.as_chunks::<3>().0).unwrap();
    let padded = local_bandwidth_zero_padded(&image, &Config::default()).unwrap();
    assert_equal(&run_tool(&path, &["--spatial", "--pad"]), 512, 768, padded.frequency(), "memorial, padded");
    let periodic = local_bandwidth(&image, &Config::default()).unwrap();
    assert_ne!(periodic.frequency(), padded.frequency());
    assert_equal(&run_tool(&path, &["--spatial"]), 512, 768, periodic.frequency(), "memorial, periodic");
    let config = Config { eps: 0.05, levels: Some(6), ..Config::default() };
    let custom = local_bandwidth(&image, &config).unwrap();
    assert_ne!(custom.frequency(), periodic.frequency());
    let run = run_tool(&path, &["--spatial", "--eps", "0.05", "--levels", "6"]);
    assert_equal(&run, 512, 768, custom.frequency(), "memorial, periodic, eps 0.05, 6 levels");
}

/// `--reading level-normalized`: recorded in the JSON parameters, and never reads a
/// coarser level than the paper's reading, so its median and 95th percentile are at least the
/// paper's; on quarry it reads the fine texture the paper's reading masks (its median is higher).
#[test]
fn the_level_normalized_reading_reads_finer() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let dir = temp_dir();
    let input = shared.join("data/env/quarry_01_1k.hdr");
    let (paper_dir, normalized_dir) = (dir.path().join("paper"), dir.path().join("normalized"));
    let paper = envmap_bandwidth(&input, &paper_dir, &["--json"]).expect_code(0);
    let normalized =
        envmap_bandwidth(&input, &normalized_dir, &["--json", "--reading", "level-normalized"]).expect_code(0);
    assert_eq!(paper.json_object()["parameters"]["reading"], "paper", "{paper}");
    assert_eq!(normalized.json_object()["parameters"]["reading"], "level-normalized", "{normalized}");
    let (p, n) = (figures(&paper, &paper_dir), figures(&normalized, &normalized_dir));
    let stat = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
    println!("median {} -> {}, p95 {} -> {}", stat(&p, "median"), stat(&n, "median"), stat(&p, "p95"), stat(&n, "p95"));
    assert!(stat(&n, "median") > stat(&p, "median"), "{p}\n{n}");
    assert!(stat(&n, "p95") >= stat(&p, "p95"), "{p}\n{n}");
}
