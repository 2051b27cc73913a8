//! `envmap-bandwidth` end to end on the real maps of `../shared/data/env`: the outputs, their
//! sizes, the printed and JSON statistics, the FFT diagnostic, and the errors (a file that is not
//! 2:1, bad arguments), and that the EXR holds exactly the `bandwidth` crate's estimate in each
//! mode.

use std::path::Path;

use bandwidth::{Config, latlong_bandwidth, local_bandwidth, local_bandwidth_zero_padded, log1p_luminance};

use crate::support::{png_size, run, shared, temp_dir, tool};

/// The legend strip below the map in the picture (`tools/envmap-bandwidth/src/picture.rs`).
const LEGEND_HEIGHT: usize = 144;

/// Width and height from an OpenEXR header's `dataWindow` (a box2i: x_min, y_min, x_max, y_max),
/// and the channel list's names: enough to check the file without an EXR decoder.
fn exr_header(path: &Path) -> ((usize, usize), Vec<String>) {
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

#[test]
fn quarry_end_to_end() {
    let dir = temp_dir();
    let (out, json) = (dir.path().join("quarry-bw.exr"), dir.path().join("quarry.json"));
    let input = shared().join("data/env/quarry_01_1k.hdr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&input).arg("--out").arg(&out).arg("--json").arg(&json);
    let r = run(cmd, "").expect_code(0).expect_stdout("cycles per radian").expect_stdout("median");
    assert!(
        r.stderr.contains("estimated the angular bandwidth") && r.stderr.contains("wrote"),
        "no progress message\n{r}"
    );
    assert!(!r.stdout.contains("spearman"), "the fft diagnostic ran without --fft-diagnostic\n{r}");

    assert_eq!(exr_header(&out), ((1024, 512), vec!["Y".to_string()]));
    // The picture defaults to --out with the extension .png: the map at one pixel per pixel above
    // the legend.
    assert_eq!(png_size(&out.with_extension("png")), (1024, 512 + LEGEND_HEIGHT));

    let text = std::fs::read_to_string(&json).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(v["mode"], "angular");
    assert_eq!(v["unit"], "cycles per radian");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64(), v["pixels"].as_u64()),
        (Some(1024), Some(512), Some(524288))
    );
    assert_eq!((v["levels"].as_u64(), v["eps"].as_f64()), (Some(10), Some(0.01)));
    assert!(v["input"].as_str().unwrap().ends_with("quarry_01_1k.hdr"), "{v}");
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
fn fft_diagnostic_and_explicit_png() {
    let dir = temp_dir();
    let (out, png, json) = (dir.path().join("bw.exr"), dir.path().join("picture.png"), dir.path().join("s.json"));
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(shared().join("data/env/potsdamer_platz_1k.hdr"))
        .args(["--fft-diagnostic", "--out"])
        .arg(&out)
        .arg("--png")
        .arg(&png)
        .arg("--json")
        .arg(&json);
    let r = run(cmd, "").expect_code(0).expect_stdout("log2(wavelet / fft)").expect_stdout("spearman");
    assert!(!out.with_extension("png").exists(), "a default picture was written beside --png\n{r}");
    assert_eq!(png_size(&png), (1024, 512 + LEGEND_HEIGHT));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
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
    let dir = temp_dir();
    let input = shared().join("data/env/decoder/memorial.exr");
    let out = dir.path().join("m.exr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&input).arg("--out").arg(&out);
    run(cmd, "").expect_code(2).expect_error(&input, "not a lat-long map: 512 x 768");
    assert!(!out.exists());

    for flags in [&["--spatial"][..], &["--spatial", "--pad"]] {
        let json = dir.path().join("m.json");
        let mut cmd = tool("envmap-bandwidth");
        cmd.arg(&input).args(flags).arg("--out").arg(&out).arg("--json").arg(&json);
        run(cmd, "").expect_code(0).expect_stdout("cycles per pixel");
        assert_eq!(exr_header(&out).0, (512, 768));
        // 512 x 768 fits 512 pixels: drawn at one pixel per pixel on a canvas at least 640 wide.
        assert_eq!(png_size(&out.with_extension("png")), (640, 768 + LEGEND_HEIGHT));
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let mode = if flags.len() == 2 { "spatial-padded" } else { "spatial-periodic" };
        assert_eq!((v["mode"].as_str(), v["unit"].as_str()), (Some(mode), Some("cycles per pixel")), "{v}");
        // Cycles per pixel never exceed the estimator's ceiling, c / 2.
        assert!(v["max"].as_f64().unwrap() <= v["c"].as_f64().unwrap() / 2.0 + 1e-12, "{v}");
    }
}

/// A tiny texture (4 x 4) is enlarged in the picture so that it stays visible.
#[test]
fn tiny_texture() {
    let dir = temp_dir();
    let out = dir.path().join("t.exr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(shared().join("data/env/decoder/imagers_rgbr4x4.hdr")).args(["--spatial", "--pad", "--out"]).arg(&out);
    run(cmd, "").expect_code(0);
    assert_eq!(exr_header(&out).0, (4, 4));
    assert_eq!(png_size(&out.with_extension("png")), (640, 512 + LEGEND_HEIGHT));
}

#[test]
fn input_errors_name_the_file() {
    let dir = temp_dir();
    let out = dir.path().join("x.exr");
    let missing = dir.path().join("missing.hdr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&missing).arg("--out").arg(&out);
    run(cmd, "").expect_code(2).expect_error(&missing, "no such file");

    let not_an_image = dir.path().join("notes.hdr");
    std::fs::write(&not_an_image, "hello").unwrap();
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&not_an_image).arg("--out").arg(&out);
    run(cmd, "").expect_code(2).expect_error(&not_an_image, "unknown file format");
    assert!(!out.exists());
}

/// Usage errors exit 2 (clap's status) and say what was wrong; values that only the estimator
/// refuses exit 2 with one line; the picture may not overwrite the map.
#[test]
fn bad_arguments() {
    let input = shared().join("data/env/quarry_01_1k.hdr");
    let dir = temp_dir();
    let out = dir.path().join("bw.exr");
    let usage: [(&[&str], &str); 6] = [
        (&[], "--out"),
        (&["--pad", "--out", "x.exr"], "--spatial"),
        (&["--out", "x.exr", "--frobnicate"], "--frobnicate"),
        (&["--out", "x.exr", "--levels", "many"], "--levels"),
        (&["--out", "x.exr", "--eps", "2"], "2 is not in (0, 1]"),
        (&["--out", "x.exr", "--eps", "NaN"], "NaN is not in (0, 1]"),
    ];
    for (args, needle) in usage {
        let mut cmd = tool("envmap-bandwidth");
        cmd.arg(&input).args(args);
        let r = run(cmd, "").expect_code(2);
        assert!(r.stderr.contains(needle), "stderr should mention {needle}\n{r}");
    }
    // Values that only the estimator refuses: one line naming the file.
    for levels in ["0", "11"] {
        let mut cmd = tool("envmap-bandwidth");
        cmd.arg(&input).arg("--out").arg(&out).args(["--levels", levels]);
        let r = run(cmd, "").expect_code(2);
        let prefix = format!("error: analysing {}: ", input.display());
        assert!(r.stderr.starts_with(&prefix) && r.stderr.lines().count() == 1, "{r}");
    }
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(&input).arg("--out").arg(dir.path().join("same.png"));
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("--png") && r.stderr.lines().count() == 1, "{r}");
    assert!(!out.exists() && !dir.path().join("same.png").exists());

    let mut cmd = tool("envmap-bandwidth");
    cmd.arg("--help");
    run(cmd, "").expect_code(0).expect_stdout("--spatial").expect_stdout("--fft-diagnostic").expect_stdout("JSON");
}

// The EXR is the library's estimate.

/// Runs the tool with `args` and the outputs in a fresh folder; returns the EXR it wrote, read
/// back (`Y` comes back as `R = G = B`).
fn run_tool(input: &Path, extra: &[&str]) -> envmap::HdrImage {
    let dir = temp_dir();
    let out = dir.path().join("bw.exr");
    let mut cmd = tool("envmap-bandwidth");
    cmd.arg(input).arg("--out").arg(&out).args(extra);
    run(cmd, "").expect_code(0);
    envmap::read_image(&out, &envmap::Limits::default()).unwrap()
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
    let path = shared().join("data/env/quarry_01_1k.hdr");
    let map = envmap::load(&path).unwrap();
    let image = log1p_luminance(map.width(), map.height(), map.texels()).unwrap();
    let expected = latlong_bandwidth(&image, &Config::default()).unwrap();
    assert!(expected.cycles_per_radian().iter().any(|v| *v > 0.0));
    assert_equal(&run_tool(&path, &[]), 1024, 512, expected.cycles_per_radian(), "quarry, angular");
}

/// A 512 x 768 file (not 2:1) in both spatial modes, and the options reach the library.
#[test]
fn spatial_maps_equal_the_library_estimate() {
    let path = shared().join("data/env/decoder/memorial.exr");
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
