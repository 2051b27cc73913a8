//! `brdf-fit` end to end: on tables `merl-synth` writes, the files, the JSON, the known answers,
//! the Khronos glTF validator's verdict, and the refusals; and `brdf-bake --fit`, which writes
//! the same files as a stage of the bake.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::brdf_bake::sha256_hex;
use crate::support::{
    BAKE_ENV, Run, bake_command, bake_env, ggx_copper, png_decode, reference_bake, root, run, shared_or_skip, temp_dir,
    tool,
};

fn synth(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let mut cmd = tool("merl-synth");
    cmd.args(args).arg("--out").arg(&out);
    run(cmd, "").expect_code(0);
    out
}

fn schema() -> jsonschema::Validator {
    let path = root().join("data-schema").join("brdf-fit.schema.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let schema: Value = serde_json::from_str(&text).expect("the schema is JSON");
    jsonschema::draft202012::new(&schema).unwrap_or_else(|e| panic!("{} is not a valid schema: {e}", path.display()))
}

/// The Khronos glTF validator's report of each file (`tests/gltf-validator/check.mjs`, run by
/// node). `make setup` installs it; without it the test fails and says so.
fn validate_gltf(files: &[PathBuf]) -> Vec<Value> {
    let dir = root().join("tests").join("gltf-validator");
    assert!(
        dir.join("node_modules").join("gltf-validator").is_dir(),
        "gltf-validator is not installed: run `make setup` (npm ci in tests/gltf-validator; needs node and npm)"
    );
    let mut node = std::process::Command::new("node");
    node.arg(dir.join("check.mjs")).args(files);
    let r = run(node, "").expect_code(0);
    r.stdout.lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}\n{r}"))).collect()
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

/// Runs the tool with `--json` and checks what every run must hold: one JSON object on stdout
/// whose `fit` is fit.json, which passes the schema; the files it lists, with their sizes and
/// SHA-256; a glTF whose factors are fit.json's; a MERL table that the `merl` crate reads.
fn fit(table: &Path, out: &Path) -> Value {
    let mut cmd = tool("brdf-fit");
    cmd.arg(table).arg("--out-dir").arg(out).arg("--json");
    let r = run(cmd, "").expect_code(0);
    let object = Value::Object(r.json_object());
    let text = std::fs::read_to_string(out.join("fit.json")).expect("fit.json");
    let record: Value = serde_json::from_str(&text).expect("fit.json is JSON");
    assert_eq!(record, object["fit"], "stdout's fit is fit.json\n{r}");
    let errors: Vec<String> = schema().iter_errors(&record).map(|e| format!("{e} at {}", e.instance_path())).collect();
    assert!(errors.is_empty(), "fit.json fails the schema:\n{}", errors.join("\n"));
    let names: Vec<String> =
        object["files"].as_array().unwrap().iter().map(|f| f["path"].as_str().unwrap().to_string()).collect();
    let expected: Vec<String> = ["material.bin", "fit.binary", "material.gltf", "fit.json"]
        .iter()
        .map(|n| out.join(n).display().to_string())
        .collect();
    assert_eq!(names, expected, "{r}");
    for file in object["files"].as_array().unwrap() {
        let bytes = std::fs::read(file["path"].as_str().unwrap()).unwrap();
        assert_eq!(file["size_bytes"].as_u64(), Some(bytes.len() as u64), "{file}");
        assert_eq!(file["sha256"].as_str(), Some(sha256_hex(&bytes).as_str()), "{file}");
    }
    let source = std::fs::read(table).unwrap();
    assert_eq!(record["provenance"]["source"]["name"], table.file_name().unwrap().to_str().unwrap());
    assert_eq!(record["provenance"]["source"]["size_bytes"].as_u64(), Some(source.len() as u64));

    // The glTF's factors are fit.json's, exactly.
    let gltf: Value = serde_json::from_str(&std::fs::read_to_string(out.join("material.gltf")).unwrap()).unwrap();
    let (m, pbr) = (&record["material"], &gltf["materials"][0]["pbrMetallicRoughness"]);
    let mut base = f64s(&m["baseColorFactor"]);
    base.push(1.0);
    assert_eq!(f64s(&pbr["baseColorFactor"]), base);
    assert_eq!(pbr["metallicFactor"], m["metallicFactor"]);
    assert_eq!(pbr["roughnessFactor"], m["roughnessFactor"]);
    let listed = &record["model"]["extensions"];
    let uses = |name: &str| listed.as_array().unwrap().iter().any(|e| e == name);
    let extensions = &gltf["materials"][0]["extensions"];
    if listed.as_array().unwrap().is_empty() {
        assert!(extensions.is_null() && gltf.get("extensionsUsed").is_none(), "{gltf:#}");
    } else {
        assert_eq!(&gltf["extensionsUsed"], listed, "{gltf:#}");
    }
    let specular = &extensions["KHR_materials_specular"];
    if uses("KHR_materials_specular") {
        assert_eq!(specular["specularFactor"], m["specularFactor"]);
        assert_eq!(specular["specularColorFactor"], m["specularColorFactor"]);
    } else {
        assert!(specular.is_null(), "{gltf:#}");
    }
    let coat = &extensions["KHR_materials_clearcoat"];
    if uses("KHR_materials_clearcoat") {
        assert_eq!(coat["clearcoatFactor"], m["clearcoatFactor"]);
        assert_eq!(coat["clearcoatRoughnessFactor"], m["clearcoatRoughnessFactor"]);
    } else {
        assert!(coat.is_null() && m["clearcoatFactor"] == 0.0, "{gltf:#}");
    }
    merl::read_file(&out.join("fit.binary")).unwrap_or_else(|e| panic!("fit.binary: {e}"));
    record
}

/// A GGX metal (`merl-synth ggx`, known width and F0) comes back: the table is the model's own,
/// sampled where the fit reads it, so only the optimizer's convergence separates them (2e-3 in
/// each factor; the library's tests hold the same), fit.binary equals the input table to 1e-6
/// relative in every cell, the albedo errors are 0 to 1e-6, and the validator passes the sphere
/// with no error, warning or info.
#[test]
fn brdf_fit_recovers_a_ggx_metal_and_writes_a_valid_gltf() {
    let dir = temp_dir();
    let table = synth(dir.path(), "copper.binary", &["ggx", "--alpha", "0.1", "--f0", "0.95,0.64,0.54"]);
    let out = dir.path().join("fit");
    let record = fit(&table, &out);
    assert_eq!(record["variant"], "core", "{record:#}");
    let m = &record["material"];
    let close = |got: f64, want: f64| (got - want).abs() <= 2e-3;
    assert!(close(m["metallicFactor"].as_f64().unwrap(), 1.0), "{record:#}");
    assert!(close(m["roughnessFactor"].as_f64().unwrap(), 0.1_f64.sqrt()), "{record:#}");
    for (got, want) in f64s(&m["baseColorFactor"]).into_iter().zip([0.95, 0.64, 0.54]) {
        assert!(close(got, want), "{record:#}");
    }
    for row in record["albedo"].as_array().unwrap() {
        assert!(row["relative_error"].as_f64().unwrap().abs() < 1e-6, "{row}");
    }
    let (input, fitted) = (merl::read_file(&table).unwrap(), merl::read_file(&out.join("fit.binary")).unwrap());
    for (a, b) in input.raw().iter().zip(fitted.raw()) {
        assert!((a - b).abs() <= 1e-6 * a.abs().max(1e-9), "{a} {b}");
    }

    let reports = validate_gltf(&[out.join("material.gltf")]);
    let report = &reports[0];
    assert_eq!(
        (report["errors"].as_u64(), report["warnings"].as_u64(), report["infos"].as_u64()),
        (Some(0), Some(0), Some(0)),
        "{report:#}"
    );
    assert_eq!(report["resources"], serde_json::json!(["material.bin"]), "{report:#}");
}

/// A Lambertian needs `KHR_materials_specular` (`specularFactor` 0): the extension is used,
/// listed, and passes the validator; a damaged buffer does not (the validator is not vacuous).
#[test]
fn brdf_fit_uses_the_specular_extension_for_a_lambertian() {
    let dir = temp_dir();
    let table = synth(dir.path(), "matte.binary", &["lambertian", "--albedo", "0.5,0.3,0.1"]);
    let out = dir.path().join("fit");
    let record = fit(&table, &out);
    assert_eq!(record["variant"], "specular", "{record:#}");
    assert_eq!(record["model"]["extensions"], serde_json::json!(["KHR_materials_specular"]));
    // Tolerances as in the library's test: the model holds a Lambertian exactly.
    for (got, want) in f64s(&record["material"]["baseColorFactor"]).into_iter().zip([0.5, 0.3, 0.1]) {
        assert!((got - want).abs() < 2e-3, "{record:#}");
    }
    assert!(record["material"]["specularFactor"].as_f64().unwrap() < 2e-3, "{record:#}");

    let damaged = dir.path().join("damaged");
    std::fs::create_dir(&damaged).unwrap();
    std::fs::copy(out.join("material.gltf"), damaged.join("material.gltf")).unwrap();
    std::fs::write(damaged.join("material.bin"), &std::fs::read(out.join("material.bin")).unwrap()[..1000]).unwrap();
    let reports = validate_gltf(&[out.join("material.gltf"), damaged.join("material.gltf")]);
    assert_eq!(reports[0]["errors"].as_u64(), Some(0), "{:#}", reports[0]);
    assert_eq!(reports[0]["warnings"].as_u64(), Some(0), "{:#}", reports[0]);
    assert_eq!(reports[0]["extensionsUsed"], serde_json::json!(["KHR_materials_specular"]));
    assert!(reports[1]["errors"].as_u64().unwrap() > 0, "{:#}", reports[1]);
}

/// A coated metal's table (a sharp colourless lobe over a broad dark metal: the library's
/// `recovers_a_coated_metal`, whose tolerances these are) comes back with
/// `KHR_materials_clearcoat`, which the validator passes with no error or warning.
#[test]
fn brdf_fit_uses_the_clearcoat_extension_for_a_coated_metal() {
    let dir = temp_dir();
    let coated = gltf_fit::Material {
        clearcoat: 0.9,
        clearcoat_roughness: 0.1,
        ..gltf_fit::Material::core([0.1, 0.06, 0.03], 1.0, 0.6)
    };
    let table = dir.path().join("coated.binary");
    let bytes = gltf_fit::fitted_table(&coated, gltf_fit::Masking::HeightCorrelated, merl::Dims::MERL).to_bytes();
    std::fs::write(&table, bytes).unwrap();
    let out = dir.path().join("fit");
    let record = fit(&table, &out);
    assert_eq!(record["variant"], "clearcoat", "{record:#}");
    assert_eq!(record["model"]["extensions"], serde_json::json!(["KHR_materials_clearcoat"]));
    let m = &record["material"];
    let factor = |k: &str| m[k].as_f64().unwrap();
    assert!((factor("clearcoatRoughnessFactor") - 0.1).abs() <= 1e-2, "{record:#}");
    assert!((factor("roughnessFactor") - 0.6).abs() <= 1e-2, "{record:#}");
    assert!((factor("clearcoatFactor") - 0.9).abs() <= 0.1, "{record:#}");
    let report = &validate_gltf(&[out.join("material.gltf")])[0];
    assert_eq!((report["errors"].as_u64(), report["warnings"].as_u64()), (Some(0), Some(0)), "{report:#}");
    assert_eq!(report["extensionsUsed"], serde_json::json!(["KHR_materials_clearcoat"]), "{report:#}");
}

/// `brdf-bake --fit` writes brdf-fit's four files as its stage `fit`, each listed by role and
/// format with its hash, and they are brdf-fit's bytes on the same table but for the name of the
/// tool that wrote them (fit.json's provenance, the glTF's generator).
#[test]
fn brdf_bake_fit_writes_brdf_fits_files_as_a_stage() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let dir = temp_dir();
    let bake = dir.path().join("bake");
    run(bake_command(&bake, &["--fit"]), "").expect_code(0);
    let manifest: Value = serde_json::from_str(&std::fs::read_to_string(bake.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["parameters"]["fit"]["objective"], "log-cosine", "{manifest:#}");
    let stage = manifest["stages"].as_array().unwrap().iter().find(|s| s["name"] == "fit").expect("a fit stage");
    let listed: Vec<(String, String, String)> = stage["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| {
            let bytes = std::fs::read(bake.join(o["path"].as_str().unwrap())).unwrap();
            assert_eq!(o["sha256"].as_str(), Some(sha256_hex(&bytes).as_str()), "{o}");
            [&o["path"], &o["role"], &o["format"]].map(|v| v.as_str().unwrap().to_string()).into()
        })
        .collect();
    let expected = [
        ("material.bin", "fit-gltf-buffer", "bin"),
        ("fit.binary", "fit-table", "merl"),
        ("material.gltf", "fit-gltf", "gltf"),
        ("fit.json", "fit-record", "json"),
    ]
    .map(|(a, b, c)| (a.to_string(), b.to_string(), c.to_string()));
    assert_eq!(listed, expected);

    let alone = dir.path().join("alone");
    fit(ggx_copper(), &alone);
    let read = |d: &Path, n: &str| std::fs::read(d.join(n)).unwrap();
    for name in ["material.bin", "fit.binary"] {
        assert!(read(&bake, name) == read(&alone, name), "{name} differs between brdf-bake and brdf-fit");
    }
    let json = |d: &Path, n: &str| -> Value { serde_json::from_slice(&read(d, n)).unwrap() };
    let (mut baked, alone_record) = (json(&bake, "fit.json"), json(&alone, "fit.json"));
    let errors: Vec<String> = schema().iter_errors(&baked).map(|e| format!("{e} at {}", e.instance_path())).collect();
    assert!(errors.is_empty(), "the bake's fit.json fails the schema:\n{}", errors.join("\n"));
    assert_eq!(baked["provenance"]["tool"]["name"], "brdf-bake");
    baked["provenance"]["tool"] = alone_record["provenance"]["tool"].clone();
    assert_eq!(baked, alone_record);
    let (mut baked, alone_gltf) = (json(&bake, "material.gltf"), json(&alone, "material.gltf"));
    assert!(baked["asset"]["generator"].as_str().unwrap().starts_with("brdf-bake "), "{baked:#}");
    baked["asset"]["generator"] = alone_gltf["asset"]["generator"].clone();
    assert_eq!(baked, alone_gltf);
}

/// A small valid table for the refusals that are not about the table.
fn table_of(dir: &Path) -> PathBuf {
    synth(dir, "lambert.binary", &["lambertian"])
}

/// Refusals: a file that is not a MERL table and a missing one name the file (exit 2, one line,
/// nothing written); a bake folder is refused as the output, and an output folder whose parent
/// is missing before the fit runs.
#[test]
fn brdf_fit_refuses_bad_inputs() {
    let dir = temp_dir();
    let text = dir.path().join("notes.binary");
    std::fs::write(&text, "these are not the droids you are looking for\n".repeat(10)).unwrap();
    let out = dir.path().join("out");
    let mut cmd = tool("brdf-fit");
    cmd.arg(&text).arg("--out-dir").arg(&out);
    run(cmd, "").expect_code(2).expect_error(&text, "not a MERL table");
    assert!(!out.exists(), "nothing is written for a refused input");

    let missing = dir.path().join("missing.binary");
    let mut cmd = tool("brdf-fit");
    cmd.arg(&missing).arg("--out-dir").arg(&out);
    run(cmd, "").expect_code(2).expect_error(&missing, "no such file");

    let bake = dir.path().join("bake");
    std::fs::create_dir(&bake).unwrap();
    std::fs::write(bake.join("manifest.json"), "{}").unwrap();
    let mut cmd = tool("brdf-fit");
    cmd.arg(&text).arg("--out-dir").arg(&bake);
    run(cmd, "").expect_one_error_line("is a bake folder");

    let orphan = dir.path().join("no-such-folder").join("out");
    let mut cmd = tool("brdf-fit");
    cmd.arg(table_of(dir.path())).arg("--out-dir").arg(&orphan);
    run(cmd, "").expect_one_error_line("does not exist");

    let mut cmd = tool("brdf-fit");
    cmd.arg(&text).arg("--out-dir").arg(&out).args(["--masking", "ggx"]);
    run(cmd, "").expect_one_error_line("--masking");
}

/// `brdf-preview --compare-fit` draws the bake's glTF fit with the material's estimator, samples
/// and camera beside the material: the fit's picture and the difference with its scale, the fit's
/// PSNR and relative error against the material's render, and its PSNR against the converged
/// estimate. Known answers at both ends: GGX copper is glTF's own BRDF, which the fit recovers to
/// the last digits (objective 1e-33), so the two renders are the same numbers; a Lewis Phong lobe
/// (n 10, ks 0.2, kd 0.8: `merl-synth phong`) is no GGX lobe, so the fit's render differs from
/// the material's by more than noise and lies farther from the converged estimate. The modes
/// that read the material's layer selection, and a bake without a fit, are refused in one line.
#[test]
fn brdf_preview_compare_fit_draws_the_fit_beside_the_material() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let dir = temp_dir();
    let phong = synth(dir.path(), "lewis.binary", &["phong", "-n", "10", "--ks", "0.2", "--kd", "0.8"]);
    let out = dir.path().join("preview.png");
    let compare = |table: &Path, mode: &str| -> (Run, PathBuf) {
        let bake = dir.path().join(table.file_stem().unwrap());
        let mut cmd = tool("brdf-bake");
        cmd.arg(table).arg("--env").arg(bake_env()).arg("--out-dir").arg(&bake);
        cmd.args(["--analysis-size", "128", "--fit", "--quiet"]);
        run(cmd, "").expect_code(0);
        let mut cmd = tool("brdf-preview");
        cmd.arg(&bake).arg("--out").arg(&out).args(["--size", "64x64", "--converged", "16", "--json", "--compare-fit"]);
        cmd.args(["--mode", mode]);
        (run(cmd, ""), bake)
    };
    let figures = |r: &Run| {
        let json = Value::Object(r.json_object());
        let fit = &json["fit"];
        let relative = fit["relative_error"].as_f64().expect("a relative error");
        let (fitted, material) =
            (&fit["against_converged"]["fit_psnr_db"], &fit["against_converged"]["material_psnr_db"]);
        eprintln!(
            "relative error {relative:.2e}, PSNR {}; against the converged estimate {fitted} dB (the material's {material})",
            fit["psnr_db"]
        );
        (relative, fitted.as_f64().expect("a finite PSNR"), material.as_f64().expect("a finite PSNR"))
    };

    let (r, copper) = compare(ggx_copper(), "reference");
    let r = r.expect_code(0);
    let (relative, fitted, material) = figures(&r);
    assert!(relative < 1e-6 && fitted == material, "GGX copper's exact fit renders as the material\n{r}");
    let (r, _) = compare(&phong, "fis");
    let r = r.expect_code(0);
    let (relative, fitted, material) = figures(&r);
    assert!(relative > 0.01 && fitted < material, "the Phong lobe's GGX fit renders as the material\n{r}");
    // The fit's picture with its caption below; the difference with its legend and caption.
    for name in ["preview-fit.png", "preview-fit-difference.png"] {
        let (width, height) = png_decode(&dir.path().join(name));
        assert!(width >= 64 && height > 64, "{name}: {width} x {height}");
    }

    let mut cmd = tool("brdf-preview");
    cmd.arg(&copper).arg("--out").arg(&out).args(["--compare-fit", "--mode", "prefiltered"]);
    let r = run(cmd, "").expect_code(2);
    assert!(
        r.stderr.contains("--compare-fit renders the reference and fis modes") && r.stderr.lines().count() == 1,
        "{r}"
    );
    let mut cmd = tool("brdf-preview");
    cmd.arg(&reference_bake().dir).arg("--out").arg(&out).arg("--compare-fit");
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("has no fit-table output: bake it again with brdf-bake --fit"), "{r}");
}
