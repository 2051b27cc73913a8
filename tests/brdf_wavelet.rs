//! `brdf-wavelet` end to end: the paper's Lewis-like material through `merl-synth`
//! and the tool meets Table 1, the asset reads back in `asset-info`, bad settings and damaged
//! assets are refused with the file and the problem, and `brdf-preview --brdf wavelet-brdf` renders
//! from it and measures it against the table.

use std::path::Path;

use crate::support::{BAKE_ENV, reference_bake, reported_psnr, run, shared_or_skip, temp_dir, tool};

/// `merl-synth phong -n 10 --ks 0.2 --kd 0.8` (Claustres et al. 2007, Table 1's Lewis row).
fn lewis(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("lewis.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["phong", "-n", "10", "--ks", "0.2", "--kd", "0.8", "--out"]).arg(&path);
    run(cmd, "").expect_code(0);
    path
}

fn encode(material: &Path, out: &Path, args: &[&str]) -> crate::support::Run {
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(material).arg("--out-dir").arg(out).args(args);
    run(cmd, "")
}

#[test]
fn the_lewis_material_meets_table_1_through_the_tools() {
    // Through the MERL table (read trilinearly) rather than the analytic BRDF of the crate's
    // test: the same bounds hold. Table 1, Lewis: 1.74%, 2.90%, 3.73%.
    let tmp = temp_dir();
    let material = lewis(tmp.path());
    for (ratio, paper) in [("4", 0.0174), ("16", 0.0290), ("32", 0.0373)] {
        let out = tmp.path().join(format!("r{ratio}"));
        let r = encode(&material, &out, &["--ratio", ratio, "--json"]).expect_code(0);
        let json = r.json();
        let figures = &json["figures"];
        let relative = figures["mean_relative_error"].as_f64().unwrap();
        assert!(relative <= paper, "{ratio}:1: mean relative error {relative} above {paper}\n{r}");
        assert_eq!(figures["ratio"].as_f64(), Some(ratio.parse().unwrap()), "{r}");
        let (kept, total) =
            (figures["kept_coefficients"].as_u64().unwrap(), figures["total_coefficients"].as_u64().unwrap());
        assert_eq!(kept * ratio.parse::<u64>().unwrap(), total, "{r}");
        assert!(figures["bytes"].as_u64().unwrap() < 4 * total / ratio.parse::<u64>().unwrap() + 10_000, "{r}");
        assert!(r.stderr.contains("relative error    mean"), "{r}");
    }
    // 8-bit codes: a quarter of the bytes, a larger error.
    let out = tmp.path().join("q");
    let q = encode(&material, &out, &["--ratio", "16", "--quantize", "8", "--json"]).expect_code(0).json();
    let f = encode(&material, &tmp.path().join("f"), &["--ratio", "16", "--json"]).expect_code(0).json();
    let bytes = |j: &serde_json::Value| j["figures"]["bytes"].as_f64().unwrap();
    assert!(bytes(&q) < 0.3 * bytes(&f), "{} against {}", bytes(&q), bytes(&f));
    let error = |j: &serde_json::Value| j["figures"]["mean_relative_error"].as_f64().unwrap();
    assert!(error(&q) > error(&f) && error(&q) < 0.1, "{} against {}", error(&q), error(&f));
    // asset-info reads it.
    let mut cmd = tool("asset-info");
    cmd.arg(out.join("wavelet-brdf.asset")).arg("--json");
    let info = run(cmd, "").expect_code(0).json();
    assert_eq!(info["header"]["kind"], "wavelet-brdf");
    assert_eq!(info["payload"]["kept_positions"], 64);
    assert_eq!(info["payload"]["quantized"], true);
}

#[test]
fn bad_settings_and_damaged_assets_are_refused() {
    let tmp = temp_dir();
    let material = lewis(tmp.path());
    let out = tmp.path().join("out");
    let r = encode(&material, &out, &["--side", "8", "--ratio", "3"]).expect_code(2);
    assert!(r.stderr.contains("does not divide"), "{r}");
    let r = encode(&material, &out, &["--quantize", "4"]).expect_code(2);
    assert!(r.stderr.contains("8 bits only"), "{r}");
    let r = encode(&material, &out, &["--side", "12"]).expect_code(2);
    assert!(r.stderr.contains("power of two"), "{r}");
    assert!(!out.exists(), "a refused run writes nothing");

    // Truncated or flipped, the asset is an error naming the file, never a crash.
    encode(&material, &out, &["--side", "4", "--ratio", "4"]).expect_code(0);
    let asset = out.join("wavelet-brdf.asset");
    let bytes = std::fs::read(&asset).unwrap();
    let damaged = tmp.path().join("damaged.asset");
    for cut in [10, 64, bytes.len() / 2, bytes.len() - 1] {
        std::fs::write(&damaged, &bytes[..cut]).unwrap();
        let mut cmd = tool("asset-info");
        cmd.arg(&damaged);
        let r = run(cmd, "");
        assert!(r.code == Some(1) || r.code == Some(2), "cut at {cut}: {r}");
        assert!(r.stderr.contains("damaged.asset"), "cut at {cut}: {r}");
    }
}

#[test]
fn the_previewer_renders_from_the_wavelet_and_measures_it_against_the_table() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let material = crate::support::ggx_copper();
    // brdf-wavelet into a copy of the bake: the previewer finds the asset there by default.
    let bake = tmp.path().join("bake");
    crate::support::copy_dir(&reference_bake().dir, &bake);
    encode(material, &bake, &["--side", "16", "--ratio", "4"]).expect_code(0);
    let picture = tmp.path().join("preview.png");
    let mut cmd = tool("brdf-preview");
    cmd.arg(&bake).arg("--out").arg(&picture).args(["--brdf", "wavelet-brdf"]);
    cmd.args(["--size", "48x48", "--frames", "2", "--spp", "16", "--validate", "--json"]);
    let r = run(cmd, "").expect_code(0);
    let json = r.json();
    assert_eq!(json["brdf"], "wavelet-brdf", "{r}");
    // The GPU decoder agrees with the CPU's (the gpu crate's tests hold it to rounding).
    assert!(reported_psnr(&json, "psnr_db") > 45.0, "{r}");
    // The table render differs by the encoding's error: finite, well below the CPU agreement.
    let against = json["against_table"]["psnr_db"].as_f64().unwrap();
    assert!(against > 15.0 && against < 60.0, "{r}");
    assert!(tmp.path().join("preview-table.png").exists(), "{r}");

    // An asset of another material is refused, naming the file.
    let other = tmp.path().join("other");
    encode(&lewis(tmp.path()), &other, &["--side", "4"]).expect_code(0);
    let mut cmd = tool("brdf-preview");
    cmd.arg(&bake).arg("--out").arg(&picture).args(["--brdf", "wavelet-brdf", "--wavelet-brdf"]);
    cmd.arg(other.join("wavelet-brdf.asset")).args(["--size", "16x16"]);
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("not from the bake's material") && r.stderr.contains("wavelet-brdf.asset"), "{r}");
}

#[test]
fn brdf_bake_encodes_the_wavelet_with_the_other_material_stages() {
    let tmp = temp_dir();
    let out = tmp.path().join("bake");
    let mut cmd = tool("brdf-bake");
    cmd.arg(crate::support::ggx_copper()).arg("--out-dir").arg(&out);
    cmd.args(["--analysis-size", "64", "--wavelet-brdf-ratio", "16", "--wavelet-brdf-quantize", "--json", "--quiet"]);
    let r = run(cmd, "");
    assert!(r.code == Some(0) || r.code == Some(1), "{r}");
    let json = r.json();
    let stage = json["manifest"]["stages"].as_array().unwrap().iter().find(|s| s["name"] == "wavelet-brdf");
    let stage = stage.unwrap_or_else(|| panic!("no wavelet stage\n{r}"));
    assert_eq!(stage["parameters"]["keep"], "ratio 16", "{r}");
    assert_eq!(stage["parameters"]["quantize"], true, "{r}");
    assert_eq!(stage["figures"]["ratio"], 16.0, "{r}");
    let roles: Vec<&str> = stage["outputs"].as_array().unwrap().iter().map(|o| o["role"].as_str().unwrap()).collect();
    assert_eq!(roles, ["wavelet-brdf", "wavelet-brdf-picture"], "{r}");
    assert!(out.join("wavelet-brdf.asset").exists());
    // A ratio that does not divide the grid is refused before anything is written.
    let refused = tmp.path().join("refused");
    let mut cmd = tool("brdf-bake");
    cmd.arg(crate::support::ggx_copper()).arg("--out-dir").arg(&refused).args(["--wavelet-brdf-ratio", "3"]);
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("does not divide") && !refused.exists(), "{r}");
}
