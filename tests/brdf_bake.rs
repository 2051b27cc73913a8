//! `brdf-bake` end to end on a small but real case (a GGX table and a 1024 x 512 environment
//! map): the folder and its manifest agree with each other and with the manifest's JSON Schema;
//! a rerun writes nothing; outputs do not depend on the number of threads; a changed parameter
//! rebakes and removes the files it no longer writes; a bake killed at any moment leaves no
//! manifest naming a missing or stale file and no truncated output; and bad inputs are refused
//! with one line.
//!
//! The bake is made once per run (`support::reference_bake`); each test works on a copy.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant, SystemTime};

use rand::{Rng, SeedableRng};
use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::support::{
    BAKE_ENV, ReferenceBake, bake_command, bake_env, copy_dir, ggx_copper, png_decode, reference_bake, root, run,
    shared_or_skip, temp_dir, tool,
};

pub(crate) const MANIFEST: &str = "manifest.json";

/// The files `brdf-bake --help` says a bake with an environment writes, besides the Phong layers'
/// EXRs (one per exponent) and the manifest.
const DOCUMENTED: [&str; 11] = [
    "importance.asset",
    "importance.png",
    "bandwidth-atlas.asset",
    "bandwidth-atlas.exr",
    "bandwidth-atlas.png",
    "env-bandwidth.exr",
    "env-bandwidth.png",
    "prefiltered.asset",
    "layers.ktx2",
    "mips.ktx2",
    "layers.png",
];

pub(crate) fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(".tmp")
}

/// Every file of a (flat) folder: its bytes and modification time, by name.
fn snapshot(dir: &Path) -> BTreeMap<String, (Vec<u8>, SystemTime)> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("listing {}: {e}", dir.display()))
        .map(|entry| {
            let entry = entry.expect("a folder entry");
            let name = entry.file_name().to_string_lossy().into_owned();
            let path = entry.path();
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
            let modified = entry.metadata().and_then(|m| m.modified()).expect("a modification time");
            (name, (bytes, modified))
        })
        .collect()
}

/// Just the bytes of [`snapshot`].
pub(crate) fn contents(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    snapshot(dir).into_iter().map(|(name, (bytes, _))| (name, bytes)).collect()
}

fn schema() -> &'static jsonschema::Validator {
    static VALIDATOR: std::sync::OnceLock<jsonschema::Validator> = std::sync::OnceLock::new();
    VALIDATOR.get_or_init(|| {
        let path = root().join("data-schema").join("bake-manifest.schema.json");
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let schema: Value = serde_json::from_str(&text).expect("the schema is JSON");
        jsonschema::draft202012::new(&schema)
            .unwrap_or_else(|e| panic!("{} is not a valid schema: {e}", path.display()))
    })
}

/// The manifest in `dir`, after checking that it passes the JSON Schema, that the asset crate
/// reads it, and that every output it lists is in `dir` with its size and SHA-256 (computed here
/// with `sha2`, not with the tool's helper).
fn checked_manifest(dir: &Path) -> Value {
    let path = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let manifest: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()));
    let errors: Vec<String> =
        schema().iter_errors(&manifest).map(|e| format!("{e} at {}", e.instance_path())).collect();
    assert!(errors.is_empty(), "{} fails the schema:\n{}", path.display(), errors.join("\n"));
    asset::BakeManifest::from_json(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    for output in outputs(&manifest) {
        let file = dir.join(output["path"].as_str().unwrap());
        let bytes = std::fs::read(&file).unwrap_or_else(|e| panic!("the manifest names {}: {e}", file.display()));
        assert_eq!(Some(bytes.len() as u64), output["size_bytes"].as_u64(), "size of {}", file.display());
        assert_eq!(Some(sha256_hex(&bytes).as_str()), output["sha256"].as_str(), "sha256 of {}", file.display());
    }
    manifest
}

pub(crate) fn outputs(manifest: &Value) -> impl Iterator<Item = &Value> {
    manifest["stages"].as_array().expect("stages").iter().flat_map(|s| s["outputs"].as_array().expect("outputs"))
}

fn output_paths(manifest: &Value) -> BTreeSet<String> {
    outputs(manifest).map(|o| o["path"].as_str().unwrap().to_string()).collect()
}

/// Every picture decodes whole and every asset reads back (magic, version, checksum, payload).
fn check_decodable(dir: &Path, name: &str) {
    let path = dir.join(name);
    if name.ends_with(".png") {
        png_decode(&path);
    } else if name.ends_with(".asset") {
        asset::read_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// A finished bake: its manifest is valid and lists every file of the folder (the manifest
/// aside), and nothing else is there: no temporary file, no file of an earlier bake.
pub(crate) fn check_complete(dir: &Path) -> Value {
    check_complete_but(dir, None)
}

/// [`check_complete`] with one more file in the folder, `extra`, which the manifest does not list.
fn check_complete_but(dir: &Path, extra: Option<&str>) -> Value {
    let manifest = checked_manifest(dir);
    let listed = output_paths(&manifest);
    let present: BTreeSet<String> =
        contents(dir).into_keys().filter(|n| n != MANIFEST && Some(n.as_str()) != extra).collect();
    assert!(present.iter().all(|n| !is_temporary(n)), "temporary files remain in {}: {present:?}", dir.display());
    assert_eq!(present, listed, "the files of {} are those its manifest lists", dir.display());
    for name in &present {
        check_decodable(dir, name);
    }
    manifest
}

/// A copy of the reference bake in a fresh folder.
fn copy_of_reference(tmp: &tempfile::TempDir) -> (&'static ReferenceBake, std::path::PathBuf) {
    let reference = reference_bake();
    let dir = tmp.path().join("bake");
    copy_dir(&reference.dir, &dir);
    (reference, dir)
}

#[test]
fn a_bake_lists_every_file_with_its_hash_in_a_valid_manifest() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let reference = reference_bake();
    let dir = &reference.dir;
    let manifest = check_complete(dir);

    // Everything --help promises, one EXR per Phong exponent, and the inputs by their hashes.
    let listed = output_paths(&manifest);
    let exponents = manifest["parameters"]["prefilter"]["exponents"].as_array().expect("the exponents");
    let layers = exponents.iter().map(|n| format!("layer-n{n}.exr"));
    for name in DOCUMENTED.into_iter().map(String::from).chain(layers) {
        assert!(listed.contains(&name), "{name} is missing from the bake: {listed:?}");
    }
    let material = std::fs::read(ggx_copper()).unwrap();
    let environment = std::fs::read(bake_env()).unwrap();
    assert_eq!(manifest["material"]["source_sha256"].as_str(), Some(sha256_hex(&material).as_str()));
    assert_eq!(manifest["environment"]["source_sha256"].as_str(), Some(sha256_hex(&environment).as_str()));
    let importance = asset::read_file(&dir.join("importance.asset")).unwrap();
    assert_eq!(asset::hex(&importance.provenance.source_sha256), sha256_hex(&material));

    // The --json object holds the manifest as written and the files as written.
    let json = reference.run.json_object();
    assert_eq!(json["up_to_date"], false, "{}", reference.run);
    assert_eq!(json["manifest"], manifest, "the printed manifest is the file's\n{}", reference.run);
    // Each file as every tool lists it: path, format, role, size and hash.
    let printed: BTreeSet<String> =
        json["files"].as_array().unwrap().iter().map(|f| f["path"].as_str().unwrap().to_string()).collect();
    for file in json["files"].as_array().unwrap() {
        let path = PathBuf::from(file["path"].as_str().unwrap());
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(file["sha256"].as_str(), Some(sha256_hex(&bytes).as_str()), "{}", path.display());
        assert_eq!(file["size_bytes"].as_u64(), Some(bytes.len() as u64), "{}", path.display());
    }
    let expected: BTreeSet<String> =
        listed.iter().chain([&MANIFEST.to_string()]).map(|n| dir.join(n).display().to_string()).collect();
    assert_eq!(printed, expected, "{}", reference.run);
}

#[test]
fn a_rerun_is_up_to_date_and_writes_nothing() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let (_, dir) = copy_of_reference(&tmp);
    let before = snapshot(&dir);
    let r = run(bake_command(&dir, &[]), "").expect_code(0).expect_stdout("up to date");
    assert!(snapshot(&dir) == before, "a rerun changed the folder\n{r}");
    let r = run(bake_command(&dir, &["--json"]), "").expect_code(0);
    let json = r.json_object();
    assert_eq!((&json["up_to_date"], &json["files"]), (&Value::Bool(true), &serde_json::json!([])), "{r}");
    assert!(r.stderr.contains("up to date"), "{r}");
    assert!(snapshot(&dir) == before, "a rerun with --json changed the folder\n{r}");
}

/// The up-to-date check does only the work this bake's own files ask for: a manifest that also
/// lists a file no stage writes (or a Phong layer under another spelling of its exponent), whole
/// and matching its hash, is another bake's, so the rerun bakes again rather than hash it. The
/// rebake then removes the extra file only where its name has a stage's pattern (`layer-n<N>.exr`,
/// data-schema "Bake folders", step 5); a file of the user's stays.
#[test]
fn files_no_stage_writes_make_a_manifest_another_bakes() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    for extra in ["notes.bin", "layer-n016.exr"] {
        let tmp = temp_dir();
        let (_, dir) = copy_of_reference(&tmp);
        let bytes = b"a file of the user's";
        std::fs::write(dir.join(extra), bytes).unwrap();
        let path = dir.join(MANIFEST);
        let mut manifest: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let outputs = manifest["stages"][0]["outputs"].as_array_mut().unwrap();
        let mut listed = outputs.iter().find(|o| o["format"] == "png").expect("a picture").clone();
        listed["path"] = Value::from(extra);
        listed["size_bytes"] = Value::from(bytes.len());
        listed["sha256"] = Value::from(sha256_hex(bytes));
        outputs.push(listed);
        std::fs::write(&path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
        let r = run(bake_command(&dir, &[]), "").expect_code(0);
        assert!(!r.stdout.contains("up to date"), "{extra}: {r}");
        check_complete_but(&dir, Some(extra));
        let kept = std::fs::read(dir.join(extra)).ok();
        assert_eq!(kept.as_deref(), (extra == "notes.bin").then_some(&bytes[..]), "{extra}");
    }
}

#[test]
fn force_on_one_thread_gives_the_same_bytes() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let (reference, dir) = copy_of_reference(&tmp);
    let mut cmd = bake_command(&dir, &["--force"]);
    cmd.env("RAYON_NUM_THREADS", "1");
    let r = run(cmd, "").expect_code(0);
    assert!(!r.stdout.contains("up to date"), "--force bakes\n{r}");
    let (expected, baked) = (contents(&reference.dir), contents(&dir));
    assert_eq!(expected.keys().collect::<Vec<_>>(), baked.keys().collect::<Vec<_>>(), "{r}");
    for (name, bytes) in &expected {
        assert!(&baked[name] == bytes, "{name} differs between the bake on all threads and on one\n{r}");
    }
}

#[test]
fn a_changed_parameter_rebakes_and_removes_the_files_it_no_longer_writes() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let (reference, dir) = copy_of_reference(&tmp);
    // What an interrupted write leaves: the next bake removes it.
    std::fs::write(dir.join(".bandwidth-atlas.asset.Xy12Ab.tmp"), b"half an atlas").unwrap();

    let r = run(bake_command(&dir, &["--pca-max-error", "0.05"]), "").expect_code(0);
    assert!(!r.stdout.contains("up to date"), "a new parameter rebakes\n{r}");
    let manifest = check_complete(&dir);
    assert_eq!(manifest["parameters"]["pca_max_error"], 0.05, "{r}");
    let listed = output_paths(&manifest);
    assert!(listed.contains("bandwidth-pca.asset") && listed.contains("bandwidth-pca.png"), "{listed:?}");
    let Ok(asset::Asset { payload: asset::Payload::BandwidthPca(model), .. }) =
        asset::read_file(&dir.join("bandwidth-pca.asset"))
    else {
        panic!("bandwidth-pca.asset is not a PCA model")
    };
    assert!(model.n_components >= 1, "{r}");
    // The stages the parameter does not reach write the same bytes.
    let expected = contents(&reference.dir);
    for name in ["importance.asset", "bandwidth-atlas.asset", "prefiltered.asset", "layers.ktx2"] {
        assert!(std::fs::read(dir.join(name)).unwrap() == expected[name], "{name} changed with --pca-max-error\n{r}");
    }

    // Back to the reference's parameters: the PCA files go, and the folder is the reference's,
    // byte for byte (the manifest included).
    let r = run(bake_command(&dir, &[]), "").expect_code(0);
    assert!(!r.stdout.contains("up to date"), "dropping a parameter rebakes\n{r}");
    check_complete(&dir);
    assert!(!dir.join("bandwidth-pca.asset").exists() && !dir.join("bandwidth-pca.png").exists(), "{r}");
    assert!(contents(&dir) == expected, "the folder differs from the reference bake\n{r}");
}

/// Ten rebakes with `--force` killed (SIGKILL) after seeded random delays spread over the
/// reference bake's duration. After each, once the switch it may have interrupted is recovered
/// (`asset::recover_switch`, as the next bake or reader does): any file with an output's name is
/// whole (the bake is deterministic, so whole means equal to the reference's; pictures decode and
/// assets read back as well), and the old bake or the new one is listed: a manifest that names
/// only files that are there with its sizes and hashes. Temporary files may remain; the next bake
/// cleans them and finishes.
#[test]
fn killed_bakes_leave_no_stale_manifest_and_no_truncated_file() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let (reference, dir) = copy_of_reference(&tmp);
    let expected = contents(&reference.dir);
    let mut rng = rand::rngs::StdRng::seed_from_u64(20_240_601);
    let (mut interrupted, mut in_switch, mut with_temporaries) = (0, 0, 0);
    let kills = 10;
    // The reference bake ran beside other tests: when a bake here finishes before its kill, its
    // own duration is the better estimate.
    let mut duration = reference.duration;
    for k in 0..kills {
        // One delay in each tenth of the bake's duration.
        let delay = duration.mul_f64((k as f64 + rng.random::<f64>()) / kills as f64);
        let mut cmd = bake_command(&dir, &["--force", "--quiet"]);
        let mut child = cmd.stdout(Stdio::null()).stderr(Stdio::null()).spawn().expect("starting brdf-bake");
        let start = Instant::now();
        let mut finished = child.try_wait().expect("polling brdf-bake").is_some();
        while start.elapsed() < delay && !finished {
            std::thread::sleep(Duration::from_millis(5));
            finished = child.try_wait().expect("polling brdf-bake").is_some();
        }
        if finished {
            duration = start.elapsed();
        } else {
            interrupted += 1;
            child.kill().expect("killing brdf-bake");
        }
        child.wait().expect("waiting for brdf-bake");

        // A kill inside the switch leaves its journal; the next holder of the folder (a bake, or
        // a reader where none holds it) recovers the switch from it first, as here.
        let journal = dir.join(asset::SWITCH_JOURNAL).exists();
        let folder = fsguard::Folder::open(&dir).unwrap();
        let recovery = asset::recover_switch(&folder).unwrap();
        assert_eq!(journal, recovery != asset::Recovery::None, "kill {k} after {delay:?}: {recovery:?}");
        in_switch += usize::from(journal);
        let names: Vec<String> = contents(&dir).into_keys().collect();
        let mut temporaries = 0;
        for name in &names {
            if is_temporary(name) {
                temporaries += 1;
                continue;
            }
            let bytes = std::fs::read(dir.join(name)).unwrap();
            let reference_bytes =
                expected.get(name).unwrap_or_else(|| panic!("kill {k} after {delay:?}: unexpected file {name}"));
            assert!(&bytes == reference_bytes, "kill {k} after {delay:?}: {name} is not whole");
            check_decodable(&dir, name);
        }
        // The old bake or the new one (the same bytes) whole and listed.
        assert!(names.iter().any(|n| n == MANIFEST), "kill {k} after {delay:?}: no manifest");
        checked_manifest(&dir);
        with_temporaries += usize::from(temporaries > 0);
    }
    eprintln!(
        "{interrupted} of {kills} bakes killed while running; {in_switch} inside the switch; {with_temporaries} left \
         temporary files"
    );
    assert!(interrupted >= kills / 2, "most kills must land while the bake runs");

    let r = run(bake_command(&dir, &[]), "").expect_code(0);
    check_complete(&dir);
    assert!(contents(&dir) == expected, "after the interruptions the bake differs from the reference\n{r}");
}

/// Each refusal: exit 2, nothing on stdout, one line `error: ...` naming the file or the option,
/// and no manifest.
#[test]
fn bad_inputs_and_settings_exit_2_with_one_line() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let out = tmp.path().join("bake");
    let missing = tmp.path().join("missing.binary");
    let mut cmd = crate::support::tool("brdf-bake");
    cmd.arg(&missing).arg("--env").arg(bake_env()).arg("--out-dir").arg(&out);
    let r = run(cmd, "").expect_code(2).expect_error(&missing, "no such file");
    assert!(r.stdout.is_empty(), "{r}");

    // A damaged environment map: a real one cut short.
    let truncated = tmp.path().join("truncated.hdr");
    std::fs::write(&truncated, &std::fs::read(bake_env()).unwrap()[..100_000]).unwrap();
    let mut cmd = crate::support::tool("brdf-bake");
    cmd.arg(ggx_copper()).arg("--env").arg(&truncated).arg("--out-dir").arg(&out).arg("--json");
    let r = run(cmd, "").expect_code(2).expect_error(&truncated, "truncated");
    assert!(r.stdout.is_empty(), "{r}");

    for value in ["2", "0", "NaN"] {
        let r = run(bake_command(&out, &["--pca-max-error", value]), "").expect_code(2);
        let line = r.stderr.strip_suffix('\n').unwrap_or(&r.stderr);
        assert!(line.starts_with("error: ") && !line.contains('\n'), "one error line\n{r}");
        assert!(line.contains("--pca-max-error"), "the error names the option\n{r}");
        assert!(r.stdout.is_empty(), "{r}");
    }
    assert!(!out.join(MANIFEST).exists());
}

/// A bake whose validation found a problem (here: at 64 x 64 most of the GGX's lobes reach the
/// analysis grid's limit) exits 1, records the problem in its manifest, and a rerun that finds it
/// up to date reports the same problem and exits 1 again: a pipeline sees the same status either
/// way.
#[test]
fn validation_problems_survive_an_up_to_date_rerun() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = tmp.path().join("bake");
    let command = || {
        let mut cmd = tool("brdf-bake");
        cmd.arg(ggx_copper()).arg("--env").arg(bake_env()).arg("--out-dir").arg(&dir);
        cmd.args(["--analysis-size", "64"]);
        cmd
    };
    let first = run(command(), "").expect_code(1);
    assert!(first.stdout.contains("problem: bandwidth-atlas:") && first.stdout.contains("grid's limit"), "{first}");
    let manifest = checked_manifest(&dir);
    let atlas = manifest["stages"].as_array().unwrap().iter().find(|s| s["name"] == "bandwidth-atlas").unwrap();
    assert_eq!(atlas["figures"]["problems"].as_array().map(Vec::len), Some(1), "{manifest:#}");
    let before = snapshot(&dir);
    let again = run(command(), "").expect_code(1);
    assert!(again.stdout.contains("up to date"), "{again}");
    assert!(again.stdout.contains("problem: bandwidth-atlas:"), "{again}");
    assert_eq!(snapshot(&dir), before, "an up-to-date rerun wrote something");
}

/// A table whose values no material has (one cell reflecting hundreds of times the light it
/// receives, which the albedo at merl-info's four elevations misses; every cell at 1e30; every
/// cell at an albedo of 31) is a validation problem: exit 1, the problem with its figures, nothing
/// written, the previous bake kept.
#[test]
fn an_unphysical_table_is_refused_before_anything_is_baked() {
    let tmp = temp_dir();
    let dir = tmp.path().join("bake");
    let command = |table: &Path| {
        let mut cmd = tool("brdf-bake");
        cmd.arg(table).arg("--out-dir").arg(&dir).args(["--analysis-size", "128"]);
        cmd
    };
    let good = run(command(ggx_copper()), "").expect_code(0);
    let before = snapshot(&dir);
    let table = merl::MerlTable::parse(&std::fs::read(ggx_copper()).unwrap()).unwrap();
    let dims = table.dims();
    let cell = dims.index(merl::Cell { theta_h: 0, theta_d: 68, phi_d: 105 });
    let mut one_cell = table.raw().to_vec();
    (0..3).for_each(|c| one_cell[c * dims.cells() + cell] = 1e15);
    // Every cell at 1e30: each reflects more than it receives, found by the cells' pass. Every
    // cell at 10 / sr: an albedo of about 31, each cell's share 0.013 (a Lambertian's 4.2e-4 per
    // unit albedo), found by the importance stage's quadrature, before anything is written.
    let all = vec![1e30; table.raw().len()];
    let bright: Vec<f64> = (0..table.raw().len()).map(|i| 10.0 / merl::SCALE[i / dims.cells()]).collect();
    let cases = [
        ("one-cell", one_cell, "on its own it reflects"),
        ("all", all, "on its own it reflects"),
        ("bright", bright, "albedo above 2 at theta_o 0 deg"),
    ];
    for (name, raw, expect) in cases {
        let path = tmp.path().join(format!("{name}.binary"));
        std::fs::write(&path, merl::MerlTable::from_raw(dims, raw).unwrap().to_bytes()).unwrap();
        let mut cmd = command(&path);
        cmd.arg("--json");
        let r = run(cmd, "").expect_code(1);
        let json: Value = serde_json::from_str(&r.stdout).unwrap_or_else(|e| panic!("{e}: {r}"));
        let problems = json["problems"].as_array().unwrap();
        assert!(problems.iter().any(|p| p.as_str().unwrap().contains(expect)), "{name}: {r}");
        assert_eq!(json["files"].as_array().map(Vec::len), Some(0), "{name}: {r}");
        assert!(r.stderr.contains("not a physical material, nothing baked"), "{name}: {r}");
        assert_eq!(snapshot(&dir), before, "{name}: the previous bake changed ({good})");
    }
}

/// `--env-reading auto` (the default) reads the environment's bandwidth level-normalized exactly
/// when the layer selection's figures say every view's lobe is at least as sharp as the sharpest
/// layer's, and a fixed reading is kept; either way `env-bandwidth.exr` is what `envmap-bandwidth
/// --reading` of that reading writes for the map.
#[test]
fn the_environment_bandwidth_reading_follows_the_material() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let reference = reference_bake();
    let stage = |manifest: &Value, name: &str| -> Value {
        manifest["stages"].as_array().unwrap().iter().find(|s| s["name"] == name).cloned().expect(name)
    };
    let manifest = checked_manifest(&reference.dir);
    assert_eq!(manifest["parameters"]["environment_bandwidth"]["reading"], "auto", "{manifest:#}");
    let selection = stage(&manifest, "layer-selection");
    let numbers = |key: &str| -> Vec<f64> {
        selection["figures"][key].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
    };
    let sharpest = *numbers("layer_bandwidth").last().unwrap();
    let mirror_like = numbers("view_bandwidth").iter().all(|&b| b >= sharpest);
    let (chosen, other) = if mirror_like { ("level-normalized", "paper") } else { ("paper", "level-normalized") };
    assert_eq!(stage(&manifest, "environment-bandwidth")["parameters"]["reading"], chosen, "{manifest:#}");

    let tmp = temp_dir();
    let fixed = tmp.path().join("fixed");
    run(bake_command(&fixed, &["--env-reading", other]), "").expect_code(0);
    let fixed_manifest = checked_manifest(&fixed);
    assert_eq!(fixed_manifest["parameters"]["environment_bandwidth"]["reading"], other);
    assert_eq!(stage(&fixed_manifest, "environment-bandwidth")["parameters"]["reading"], other);
    for (reading, dir) in [(chosen, &reference.dir), (other, &fixed)] {
        let alone = tmp.path().join(reading);
        let mut cmd = tool("envmap-bandwidth");
        cmd.arg(bake_env()).arg("--out-dir").arg(&alone).args(["--reading", reading]);
        run(cmd, "").expect_code(0);
        let read = |d: &Path| std::fs::read(d.join("env-bandwidth.exr")).expect("env-bandwidth.exr");
        assert!(read(dir) == read(&alone), "{reading}: the bake's env-bandwidth.exr differs from envmap-bandwidth's");
    }
}
