//! `brdf-bandwidth` and `bandwidth-pca` end to end: the outputs and their sizes, the
//! count of lobes at the analysis grid's limit on sharp and broad Phong lobes, a flat atlas for
//! a Lambertian material, one-line errors on bad input, and the PCA table of the 20 shared
//! real-derived materials.

use std::path::{Path, PathBuf};

use merl::Dims;
use merl::analytic::Analytic;

use crate::support::{
    MATERIALS, NBRDF, Run, exr_header, nbrdf_table, png_decode, root, run, shared_or_skip, temp_dir, tool,
};

/// Writes a MERL table of `brdf` into `dir`.
fn write_table(dir: &Path, name: &str, brdf: Analytic) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, brdf.table(Dims::MERL).to_bytes()).unwrap();
    path
}

fn brdf_bandwidth(material: &Path, out: &Path, args: &[&str]) -> Run {
    let mut cmd = tool("brdf-bandwidth");
    cmd.arg(material).arg("--out-dir").arg(out).args(args);
    run(cmd, "")
}

fn bandwidth_pca(atlas: &Path, out: &Path, args: &[&str]) -> Run {
    let mut cmd = tool("bandwidth-pca");
    cmd.arg(atlas).arg("--out-dir").arg(out).args(args);
    run(cmd, "")
}

/// The payload of an asset file, which must be of the expected kind: a MERL table's atlas is
/// isotropic, so `brdf-bandwidth` stores it once per row (kind 7).
fn read_rows(path: &Path) -> asset::BandwidthRows {
    match asset::read_file(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display())).payload {
        asset::Payload::BandwidthRows(r) => r,
        other => panic!("{} holds {}, expected bandwidth rows", path.display(), other.kind()),
    }
}

/// The full atlas texture the rows stand for, as `data-schema/bandwidth-atlas.md` tells a renderer to
/// expand it: texel `(x, y)` is texel `(x mod tile, y mod tile)` of row `y / tile`'s tile.
fn expand(rows: &asset::BandwidthRows) -> Vec<f32> {
    let (t, width) = (rows.tile as usize, (rows.lobes_x * rows.tile) as usize);
    let height = (rows.lobes_y * rows.tile) as usize;
    (0..width * height)
        .map(|k| (k % width, k / width))
        .map(|(x, y)| rows.data[(y / t) * t * t + (y % t) * t + x % t])
        .collect()
}

fn read_model(path: &Path) -> asset::BandwidthPca {
    match asset::read_file(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display())).payload {
        asset::Payload::BandwidthPca(m) => m,
        other => panic!("{} holds {}, expected a bandwidth pca", path.display(), other.kind()),
    }
}

/// A figure of a tool's `--json` object.
fn figure(r: &Run, name: &str) -> serde_json::Value {
    let json = r.json_object();
    json["figures"].get(name).cloned().unwrap_or_else(|| panic!("no figure {name:?}\n{r}"))
}

/// The number of lobes that reach the analysis grid's limit, from brdf-bandwidth's `--json`.
fn lobes_at_limit(r: &Run) -> u64 {
    figure(r, "lobes_at_limit").as_u64().unwrap_or_else(|| panic!("lobes_at_limit is not a count\n{r}"))
}

#[test]
fn tools_end_to_end() {
    let tmp = temp_dir();
    let material =
        write_table(tmp.path(), "phong30.binary", Analytic::Phong { n: 30.0, ks: [0.9, 0.6, 0.3], kd: [0.0; 3] });
    let out = tmp.path().join("atlas");
    let r = brdf_bandwidth(&material, &out, &["--lobes", "8", "--json"]).expect_code(0);
    assert!(r.stderr.contains("8 x 8 lobes of 16 x 16") && r.stderr.contains("kind 7 (bandwidth-rows)"), "{r}");

    // An 8 x 8 grid of 16 x 16 tiles: 128 x 128 texels in the EXR (the renderers' texture), the
    // 8 row tiles in the asset, which expand to the EXR's texels exactly. (The picture's layout
    // belongs to the picture code: it must decode.)
    let exr = out.join("bandwidth-atlas.exr");
    assert_eq!(exr_header(&exr), ((128, 128), vec!["Y".to_string()]), "{r}");
    png_decode(&out.join("bandwidth-atlas.png"));
    let rows = read_rows(&out.join("bandwidth-atlas.asset"));
    assert_eq!((rows.lobes_x, rows.lobes_y, rows.tile), (8, 8, 16));
    assert_eq!(rows.data.len(), 8 * 16 * 16);
    let texels = expand(&rows);
    let image = envmap::read_image(&exr, &envmap::Limits::default()).unwrap();
    let exr_texels: Vec<f32> = image.rgb.iter().step_by(3).copied().collect();
    assert!(texels == exr_texels, "the rows expanded differ from the EXR\n{r}");
    assert!(texels.iter().all(|v| v.is_finite() && *v >= 0.0) && texels.iter().any(|v| *v > 0.0), "{r}");
    assert_eq!(figure(&r, "stored_kind"), "bandwidth-rows", "{r}");

    // PCA with every component reproduces it. The model is fitted on the 8 row tiles: one
    // column, one set of coefficients per row.
    let bin = out.join("bandwidth-atlas.asset");
    let model_dir = tmp.path().join("model");
    let model = model_dir.join("bandwidth-pca.asset");
    let r = bandwidth_pca(&bin, &model_dir, &["--components", "256", "--json"]).expect_code(0);
    assert_eq!(figure(&r, "components"), 256);
    assert_eq!(figure(&r, "distinct_tiles"), 8);
    assert!(figure(&r, "relative_rmse").as_f64().unwrap() <= 1e-6, "{r}");
    let m = read_model(&model);
    assert_eq!((m.lobes_x, m.lobes_y, m.n_components), (1, 8, 256));
    assert_eq!((m.mean.len(), m.components.len(), m.coefficients.len()), (256, 256 * 256, 8 * 256));
    png_decode(&model_dir.join("bandwidth-pca.png"));

    // Fewer components: a smaller model, and the report says how far off it is, against the
    // distinct tiles (8 x 256 floats) and against the full grid (64 x 256 floats), 8 times less.
    let r = bandwidth_pca(&bin, &model_dir, &["--components", "4", "--json"]).expect_code(0);
    assert!(r.stderr.contains("components      4") && r.stderr.contains("relative rmse"), "{r}");
    assert!(r.stderr.contains("of the distinct tiles") && r.stderr.contains("against the full 8 x 8 grid"), "{r}");
    let m = read_model(&model);
    assert_eq!((m.mean.len(), m.components.len(), m.coefficients.len()), (256, 4 * 256, 8 * 4));
    let stored = (256 + 4 * 256 + 8 * 4) as f64;
    let (ratio, ratio_full) =
        (figure(&r, "size_ratio").as_f64().unwrap(), figure(&r, "size_ratio_full_grid").as_f64().unwrap());
    assert!((ratio - stored / (8.0 * 256.0)).abs() < 1e-12 && (ratio_full - stored / (64.0 * 256.0)).abs() < 1e-12);
}

#[test]
fn the_report_names_the_lobes_at_the_grid_limit() {
    // Phong of exponent 1000 is 2 pixels wide at a 64 x 64 analysis: every lobe reaches the
    // limit; exponent 6 (19 pixels wide) is resolved everywhere.
    let tmp = temp_dir();
    let sharp = write_table(tmp.path(), "sharp.binary", Analytic::Phong { n: 1000.0, ks: [1.0; 3], kd: [0.0; 3] });
    let args = ["--lobes", "8", "--analysis-size", "64", "--json"];
    // Most lobes at the limit is a validation problem (exit 1) that says what to do; the atlas is
    // still written.
    let r = brdf_bandwidth(&sharp, &tmp.path().join("sharp"), &args).expect_code(1);
    assert_eq!(lobes_at_limit(&r), 64, "{r}");
    // With --json the report goes to stderr, and it says what the count means.
    assert!(r.stderr.contains("lower bound"), "{r}");
    let problems = r.json()["problems"].to_string();
    assert!(problems.contains("64 of 64 lobes") && problems.contains("--analysis-size"), "{r}");
    assert!(tmp.path().join("sharp/bandwidth-atlas.asset").exists(), "{r}");
    let broad = write_table(tmp.path(), "broad.binary", Analytic::Phong { n: 6.0, ks: [1.0; 3], kd: [0.0; 3] });
    let r = brdf_bandwidth(&broad, &tmp.path().join("broad"), &args).expect_code(0);
    assert_eq!(lobes_at_limit(&r), 0, "{r}");
}

/// With the defaults (1024 x 1024), no lobe of a `merl-synth` table of Phong n = 1000
/// reaches the analysis grid's limit (the `bandwidth-atlas` test `phong_1000_is_resolved_at_the_default_size`
/// says what read it before: 192 lobes at 512, 64 at 1024 before the table's cells below the
/// horizon were continued).
#[test]
fn the_default_analysis_resolves_phong_1000() {
    let tmp = temp_dir();
    let table = write_table(tmp.path(), "phong1000.binary", Analytic::Phong { n: 1000.0, ks: [1.0; 3], kd: [0.0; 3] });
    let r = brdf_bandwidth(&table, &tmp.path().join("atlas"), &["--json"]).expect_code(0);
    assert_eq!(lobes_at_limit(&r), 0, "{r}");
    assert_eq!(figure(&r, "texels_at_limit"), 0, "{r}");
}

#[test]
fn a_lambertian_atlas_is_flat() {
    let tmp = temp_dir();
    let material = write_table(tmp.path(), "lambertian.binary", Analytic::Lambertian { albedo: [0.5; 3] });
    let out = tmp.path().join("atlas");
    let r = brdf_bandwidth(&material, &out, &["--lobes", "8", "--json"]).expect_code(0);
    assert_eq!(lobes_at_limit(&r), 0, "{r}");
    let texels = read_rows(&out.join("bandwidth-atlas.asset")).data;
    let nonzero = texels.iter().filter(|v| **v != 0.0).count();
    assert_eq!(nonzero, 0, "{nonzero} texels of a Lambertian atlas read a frequency\n{r}");
    assert_eq!(figure(&r, "flat_texels"), 128 * 128, "the figures agree with the asset\n{r}");
}

#[test]
fn bad_inputs_exit_2_naming_the_file() {
    let tmp = temp_dir();
    let out = tmp.path().join("out");
    let invalid = root().join("fixtures").join("invalid");
    let missing = tmp.path().join("missing.binary");
    brdf_bandwidth(&missing, &out, &[]).expect_code(2).expect_error(&missing, "no such file");
    let truncated = invalid.join("merl-truncated-header.binary");
    brdf_bandwidth(&truncated, &out, &[]).expect_code(2).expect_error(&truncated, "truncated header");
    assert!(!out.exists(), "nothing is written for a bad input");

    // A file that is not an atlas, and an atlas cut short.
    let model = tmp.path().join("model");
    bandwidth_pca(&truncated, &model, &["--components", "1"])
        .expect_code(2)
        .expect_error(&truncated, "not an asset file");
    let golden = root().join("fixtures").join("assets").join("golden-v1-material-info.asset");
    bandwidth_pca(&golden, &model, &["--components", "1"]).expect_code(2).expect_error(
        &golden,
        "expected a bandwidth-atlas or bandwidth-rows asset (from brdf-bandwidth), found material-info",
    );
    let material = write_table(tmp.path(), "phong.binary", Analytic::Phong { n: 10.0, ks: [1.0; 3], kd: [0.0; 3] });
    brdf_bandwidth(&material, &out, &["--lobes", "2"]).expect_code(0);
    let mut bytes = std::fs::read(out.join("bandwidth-atlas.asset")).unwrap();
    bytes.truncate(bytes.len() - 4);
    let cut = tmp.path().join("cut.asset");
    std::fs::write(&cut, &bytes).unwrap();
    bandwidth_pca(&cut, &model, &["--components", "1"]).expect_code(2).expect_error(&cut, "truncated");
    let missing_atlas = tmp.path().join("missing.asset");
    bandwidth_pca(&missing_atlas, &model, &["--components", "1"])
        .expect_code(2)
        .expect_error(&missing_atlas, "no such file");
    assert!(!model.exists());

    // A bad setting is an error too, one line, before anything is read.
    let r = brdf_bandwidth(&material, &out, &["--tile", "12"]).expect_code(2);
    assert_eq!(r.stderr.lines().count(), 1, "{r}");
    assert!(r.stderr.starts_with("error: invalid configuration: tile size 12"), "{r}");
}

#[test]
fn pca_of_the_shared_materials() {
    let Some(_) = shared_or_skip(&[NBRDF]) else { return };
    // For each material, the atlas (64 x 64 lobes of 16 x 16, analysed at 64 x 64; stored as its
    // 64 row tiles) and the fewest PCA components whose relative RMSE is at most 2%. Asserted:
    // such a K exists and its measured error is within 2%. The table is printed: the model's size
    // against the 64 distinct tiles and against the full 64 x 64 grid (64 times less).
    let tmp = temp_dir();
    let mut table = String::from(
        "material                    K   rel. rmse   max error (cycles/rad)   model/rows   compression   vs full grid\n",
    );
    let mut failures = Vec::new();
    for name in MATERIALS {
        let material = nbrdf_table(name);
        let out = tmp.path().join(name);
        // The table is made at an analysis size of 64 x 64, where every lobe of these materials
        // reaches the limit, which the tool reports as a problem (exit 1); the atlas is still
        // written.
        brdf_bandwidth(&material, &out, &["--analysis-size", "64"]).expect_code(1);
        let r =
            bandwidth_pca(&out.join("bandwidth-atlas.asset"), &out, &["--max-error", "0.02", "--json"]).expect_code(0);
        let (k, rmse, max_error, ratio, ratio_full) = (
            figure(&r, "components").as_u64().unwrap(),
            figure(&r, "relative_rmse").as_f64().unwrap(),
            figure(&r, "max_abs_error").as_f64().unwrap(),
            figure(&r, "size_ratio").as_f64().unwrap(),
            figure(&r, "size_ratio_full_grid").as_f64().unwrap(),
        );
        table += &format!(
            "{name:<24} {k:>5} {:>10.3}% {max_error:>18.3} {:>13.1}% {:>12.2}:1 {:>12.1}:1\n",
            100.0 * rmse,
            100.0 * ratio,
            1.0 / ratio,
            1.0 / ratio_full
        );
        if !(k <= 256 && rmse <= 0.02) {
            failures.push(format!("{name}: K {k}, relative rmse {rmse}"));
        }
    }
    eprintln!("{table}");
    assert!(failures.is_empty(), "{}\n{table}", failures.join("\n"));
}
