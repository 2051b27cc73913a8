//! Bake folders that cannot be turned against their user: hostile folders (manifests
//! naming files outside, links, FIFOs) make no tool touch or read anything outside the folder and
//! no tool block; two bakes of one folder at once leave a manifest that tells the truth; a rebake
//! that fails keeps the previous bake listed; `brdf-wavelet` into a bake goes through the bake's
//! protocol; every path option refuses a FIFO and a device without blocking; numeric options have
//! ranges; and the messages a newcomer meets say what to do.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use rand::{Rng, SeedableRng};

use crate::brdf_bake::{MANIFEST, check_complete, contents, sha256_hex};
use crate::support::{
    BAKE_ENV, bake_command, copy_dir, ggx_copper, reference_bake, root, run, run_within, shared_or_skip, temp_dir, tool,
};

/// Longer than any of these runs takes on a loaded machine, far shorter than forever: a run that
/// blocks (on a FIFO, on `/dev/zero`) is killed and fails the test.
const NO_HANG: Duration = Duration::from_secs(60);

/// A copy of the reference bake in `tmp/name`.
fn copy_of_reference(tmp: &Path, name: &str) -> PathBuf {
    let dir = tmp.join(name);
    copy_dir(&reference_bake().dir, &dir);
    dir
}

/// Every entry under `dir` (links not followed), with the bytes of each file: what must not
/// change outside a bake.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("listing {}: {e}", dir.display())) {
        let path = entry.expect("an entry").path();
        let meta = std::fs::symlink_metadata(&path).expect("metadata");
        if meta.is_dir() {
            out.extend(tree(&path));
        } else {
            out.insert(path.clone(), meta.is_file().then(|| std::fs::read(&path).expect("reading")));
        }
    }
    out
}

/// A small preview of the bake in `dir` (16 x 16, one frame of 16 samples).
fn preview_command(dir: &Path, out: &Path) -> Command {
    let mut cmd = tool("brdf-preview");
    cmd.arg(dir).arg("--out").arg(out).args(["--spp", "16", "--frames", "1", "--size", "16x16"]);
    cmd
}

/// A second material for the bakes here: `merl-synth phong -n 50` in `dir`.
fn phong(dir: &Path) -> PathBuf {
    let path = dir.join("phong.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["phong", "-n", "50", "--out"]).arg(&path);
    run(cmd, "").expect_code(0);
    path
}

fn mkfifo(path: &Path) {
    let status = Command::new("mkfifo").arg(path).status().expect("running mkfifo");
    assert!(status.success(), "mkfifo {}", path.display());
}

/// `make-hostile-bakes.sh` (`../shared/data/hostile/bake/`) on a copy of the reference bake, and
/// one more case: a manifest that lists a file of the user's inside the folder, with its true
/// size and hash. `brdf-bake` and `brdf-preview` run on every folder: each ends within the limit,
/// with exit 2 and one line or with success; `outside/` is byte for byte as it was, and the
/// user's file is still there. The previewer refuses the link and the FIFO by name; the bake
/// rebakes each folder (`--force`) and lists no file outside it.
#[test]
fn hostile_bake_folders_touch_nothing_outside_and_never_block() {
    let Some(shared) = shared_or_skip(&["data/hostile", BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let good = copy_of_reference(tmp.path(), "good");
    let dir = tmp.path().join("hostile");
    let script = shared.join("data/hostile/bake/make-hostile-bakes.sh");
    let mut cmd = Command::new("bash");
    cmd.arg(&script).arg(&good).arg(&dir);
    run(cmd, "").expect_code(0);

    // A file of the user's in the folder, listed by a manifest as if the bake had written it.
    let user = copy_of_reference(&dir, "lists-a-user-file");
    std::fs::write(user.join("notes.txt"), b"the user's notes").unwrap();
    let text = std::fs::read_to_string(user.join(MANIFEST)).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
    manifest["stages"][0]["outputs"].as_array_mut().unwrap().push(serde_json::json!({
        "path": "notes.txt", "format": "png", "role": "extra", "size_bytes": 16,
        "sha256": sha256_hex(b"the user's notes"),
    }));
    std::fs::write(user.join(MANIFEST), serde_json::to_string_pretty(&manifest).unwrap()).unwrap();

    let outside = tree(&dir.join("outside"));
    assert!(outside.len() >= 4, "{outside:?}");
    let cases = ["v1-outside", "v2-symlinked-folder", "symlinked-file", "fifo-manifest", "lists-a-user-file"];
    // What the previewer must say (exit 2), or None where it may succeed without following anything.
    let preview_refusal = |case: &str| match case {
        "v1-outside" => Some("expected a relative path inside the folder"),
        "symlinked-file" => Some("\"importance.asset\" is a symbolic link, which is not followed"),
        "fifo-manifest" => Some("a fifo (named pipe), not a regular file"),
        _ => None,
    };
    for case in cases {
        let folder = dir.join(case);
        let out = tmp.path().join(format!("{case}.png"));
        let (r, _) = run_within(preview_command(&folder, &out), NO_HANG);
        match preview_refusal(case) {
            Some(needle) => {
                r.expect_one_error_line(needle);
            }
            None => {
                r.expect_code(0);
            }
        }
        assert!(tree(&dir.join("outside")) == outside, "brdf-preview on {case} changed outside/");

        // --force: a manifest that matches its files would otherwise be up to date.
        let (r, _) = run_within(bake_command(&folder, &["--force", "--quiet"]), NO_HANG);
        let r = r.expect_code(0);
        assert!(tree(&dir.join("outside")) == outside, "brdf-bake on {case} changed outside/\n{r}");
        let listed = check_manifest_inside(&folder);
        assert!(listed.iter().all(|p| !p.contains('/')), "{case}: {listed:?}\n{r}");
        // The rebaked folder is the reference bake's again, and previews.
        for (name, bytes) in contents(&reference_bake().dir) {
            assert!(std::fs::read(folder.join(&name)).unwrap() == bytes, "{case}: {name} differs\n{r}");
        }
        let (r, _) = run_within(preview_command(&folder, &out), NO_HANG);
        r.expect_code(0);
    }
    assert_eq!(std::fs::read(user.join("notes.txt")).unwrap(), b"the user's notes", "the user's file was removed");
    // The links are left where they were, their targets untouched.
    assert!(dir.join("v2-symlinked-folder/link").is_symlink());
    assert!(!std::fs::symlink_metadata(dir.join("symlinked-file/importance.asset")).unwrap().is_symlink());
}

/// The paths the manifest in `dir` lists, after checking each is a regular file inside `dir` with
/// its size and hash.
fn check_manifest_inside(dir: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(dir.join(MANIFEST)).expect("a manifest");
    let manifest: serde_json::Value = serde_json::from_str(&text).expect("json");
    let mut paths = Vec::new();
    for output in crate::brdf_bake::outputs(&manifest) {
        let path = output["path"].as_str().unwrap().to_string();
        let meta = std::fs::symlink_metadata(dir.join(&path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        assert!(meta.is_file(), "{path} is not a regular file");
        let bytes = std::fs::read(dir.join(&path)).unwrap();
        assert_eq!(Some(sha256_hex(&bytes).as_str()), output["sha256"].as_str(), "{path}");
        paths.push(path);
    }
    paths
}

/// Pairs of bakes of two materials into one folder, the second started at a seeded random offset
/// within the first half of the first one's duration. Afterwards the folder is one complete bake
/// (every file its manifest lists there with its size and hash, nothing else of ours), of one of
/// the two materials; a run that overlapped the other ended at once with exit 2 and one line saying that
/// another bake holds the folder.
#[test]
fn concurrent_bakes_into_one_folder_leave_a_manifest_that_tells_the_truth() {
    let tmp = temp_dir();
    let materials = [ggx_copper().to_path_buf(), phong(tmp.path())];
    let hashes: Vec<String> = materials.iter().map(|m| sha256_hex(&std::fs::read(m).unwrap())).collect();
    let bake = |material: &Path, dir: &Path| {
        let mut cmd = tool("brdf-bake");
        // --force: a bake of the material the folder holds would be up to date and end at once.
        cmd.arg(material).arg("--out-dir").arg(dir).args(["--analysis-size", "128", "--force", "--quiet"]);
        cmd
    };
    // The duration of one bake, measured here.
    let dir = tmp.path().join("bake");
    let start = std::time::Instant::now();
    run(bake(&materials[0], &dir), "").expect_code(0);
    let duration = start.elapsed();

    let mut rng = rand::rngs::StdRng::seed_from_u64(32);
    let mut refused = 0;
    for pair in 0..3 {
        // Within the first half of the first bake: they overlap.
        let offset = duration.mul_f64(rng.random_range(0.0..0.5));
        let (first, second) = if pair % 2 == 0 { (0, 1) } else { (1, 0) };
        let a = std::thread::spawn({
            let cmd = bake(&materials[first], &dir);
            move || run_within(cmd, NO_HANG)
        });
        std::thread::sleep(offset);
        let b = run_within(bake(&materials[second], &dir), NO_HANG).0;
        let (a, a_took) = a.join().expect("the first bake");
        // The second started well before the first ended (reading its inputs takes a fraction of
        // a second before it asks for the folder): one of them must have been refused.
        if offset + Duration::from_secs(1) < a_took {
            assert!(a.code == Some(2) || b.code == Some(2), "pair {pair}: both baked at once\n{a}\n{b}");
        }
        for r in [&a, &b] {
            if r.code == Some(2) {
                refused += 1;
                let line = r.stderr.trim_end();
                assert!(line.contains("another bake is writing this folder"), "pair {pair}: {r}");
                assert!(line.contains(&dir.display().to_string()) && !line.contains('\n'), "{r}");
            } else {
                assert_eq!(r.code, Some(0), "pair {pair}, offset {offset:?}\n{r}");
            }
        }
        assert!(a.code == Some(0) || b.code == Some(0), "pair {pair}: neither bake ran\n{a}\n{b}");
        let manifest = check_complete(&dir);
        let material = manifest["material"]["source_sha256"].as_str().unwrap();
        assert!(hashes.iter().any(|h| h == material), "pair {pair}: {material}");
        for asset in ["importance.asset", "bandwidth-atlas.asset"] {
            let read = asset::read_file(&dir.join(asset)).unwrap();
            assert_eq!(asset::hex(&read.provenance.source_sha256), material, "pair {pair}: {asset} is the other's");
        }
    }
    eprintln!("3 pairs, {refused} runs refused (the folder was another bake's)");
    assert!(refused >= 1, "the pairs overlapped, yet no run was refused");
}

/// A rebake that fails while it writes (here: files are limited to 4 MiB, `ulimit -f 8192`, and
/// the mip chain is 5.6 MB; a full disk fails the same way) exits 2 with one line and leaves the
/// previous bake as it was: its manifest, every file it lists, no temporary file; it still
/// previews, and `asset-info` passes every asset.
#[test]
fn a_rebake_that_fails_keeps_the_previous_bake_listed() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = copy_of_reference(tmp.path(), "bake");
    let before = contents(&dir);
    // A parameter changed, so that it rebakes: fewer vectors make a smaller importance asset, so
    // that the failure comes late, with many new files written.
    let bake = bake_command(&dir, &["--vectors", "1", "--quiet"]);
    let mut cmd = Command::new("sh");
    // SIGXFSZ ignored: a write past the limit fails with EFBIG instead of killing the process.
    cmd.arg("-c").arg("trap '' XFSZ; ulimit -f 8192 && exec \"$@\"").arg("sh");
    cmd.arg(bake.get_program()).args(bake.get_args());
    cmd.current_dir(root());
    let (r, _) = run_within(cmd, NO_HANG);
    r.expect_one_error_line("file too large");
    assert!(contents(&dir) == before, "the failed rebake changed the folder");
    check_complete(&dir);

    let (r, _) = run_within(preview_command(&dir, &tmp.path().join("p.png")), NO_HANG);
    r.expect_code(0);
    for name in before.keys().filter(|n| n.ends_with(".asset")) {
        let mut cmd = tool("asset-info");
        cmd.arg(dir.join(name));
        run(cmd, "").expect_code(0);
    }
}

/// `make-cases.sh` (`../shared/data/hostile/bake2/`) on a copy of the reference bake, case
/// `switch-blocked`: a non-empty folder where a rebake with `--cube` writes `layers-cube.ktx2`; and
/// the same with `--engine-textures` and a non-empty `engine-merl.ktx2/`. Each rebake exits 2 with
/// one line naming the folder in the way and changes nothing: the previous manifest and every file
/// it lists, with its checksum, the folder in the way with its note, no temporary file (a switch
/// that renamed new files over the old ones until it met the folder, then undid by deleting the
/// new files, would leave 3 of 21 files and no manifest).
#[test]
fn a_rebake_blocked_by_a_folder_at_a_name_it_writes_keeps_the_previous_bake() {
    let Some(shared) = shared_or_skip(&["data/hostile", BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let good = copy_of_reference(tmp.path(), "good");
    let cases = tmp.path().join("cases");
    let mut cmd = Command::new("bash");
    cmd.arg(shared.join("data/hostile/bake2/make-cases.sh")).arg(&good).arg(&cases);
    run(cmd, "").expect_code(0);
    let engine = copy_of_reference(tmp.path(), "engine-blocked");
    std::fs::create_dir(engine.join("engine-merl.ktx2")).unwrap();
    std::fs::write(engine.join("engine-merl.ktx2/note"), b"keep\n").unwrap();

    let before = contents(&good);
    for (dir, flag, name) in [
        (cases.join("switch-blocked"), "--cube", "layers-cube.ktx2"),
        (engine, "--engine-textures", "engine-merl.ktx2"),
    ] {
        let (r, _) = run_within(bake_command(&dir, &[flag, "--quiet"]), NO_HANG);
        let r = r.expect_one_error_line(&format!("{}: refusing to replace a folder", dir.join(name).display()));
        let mut names: Vec<String> =
            std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
        names.sort();
        let mut expected: Vec<String> = before.keys().cloned().chain([name.to_string()]).collect();
        expected.sort();
        assert_eq!(
            names, expected,
            "{flag}: the folder holds the previous bake, the folder in the way, nothing else\n{r}"
        );
        for (file, bytes) in &before {
            assert!(std::fs::read(dir.join(file)).unwrap() == *bytes, "{flag}: {file} changed\n{r}");
        }
        let listed = check_manifest_inside(&dir);
        assert_eq!(listed.len() + 1, before.len(), "{flag}: every file but the manifest is listed");
        assert_eq!(std::fs::read(dir.join(name).join("note")).unwrap(), b"keep\n", "{flag}\n{r}");
    }
}

/// `make-cases.sh`'s `duplicate-1000` (the manifest lists `importance.png` 1000 more times) and a
/// 100 000-entry one made here (compact JSON, under the 16 MiB limit): every reader (a preview,
/// `--sheet`, `brdf-wavelet` adding its stage) refuses the manifest at once with one line naming
/// it and the path listed twice, instead of hashing or drawing every copy (measured: 29 s for
/// 3 000 copies, an allocation failure for 100 000); `brdf-bake` counts it as no manifest and
/// bakes again, hashing nothing it lists.
#[test]
fn a_manifest_listing_a_path_twice_is_refused_by_every_reader() {
    let Some(shared) = shared_or_skip(&["data/hostile", BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let good = copy_of_reference(tmp.path(), "good");
    let cases = tmp.path().join("cases");
    let mut cmd = Command::new("bash");
    cmd.arg(shared.join("data/hostile/bake2/make-cases.sh")).arg(&good).arg(&cases);
    run(cmd, "").expect_code(0);
    let large = copy_of_reference(tmp.path(), "duplicate-100000");
    let text = std::fs::read_to_string(large.join(MANIFEST)).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
    let outputs = manifest["stages"][0]["outputs"].as_array_mut().unwrap();
    let copy = outputs.iter().find(|o| o["path"] == "importance.png").unwrap().clone();
    outputs.extend(std::iter::repeat_n(copy, 100_000));
    let text = serde_json::to_string(&manifest).unwrap();
    assert!(text.len() < 16 << 20, "{} bytes: the size limit would refuse it first", text.len());
    std::fs::write(large.join(MANIFEST), text).unwrap();

    let quick = Duration::from_secs(10);
    for dir in [cases.join("duplicate-1000"), large] {
        let needle = format!(
            "reading {}: invalid bake manifest: output \"importance.png\" is listed twice",
            dir.join(MANIFEST).display()
        );
        let png = tmp.path().join("p.png");
        let mut sheet = tool("brdf-preview");
        sheet.arg(&dir).arg("--sheet").arg(&png);
        let mut wavelet = tool("brdf-wavelet");
        wavelet.arg(ggx_copper()).arg("--out-dir").arg(&dir).args(["--side", "8"]);
        for cmd in [preview_command(&dir, &png), sheet, wavelet] {
            let (r, took) = run_within(cmd, NO_HANG);
            r.expect_one_error_line(&needle);
            assert!(took < quick, "{took:?}");
        }
        assert!(!png.exists());
    }
    let (r, took) = run_within(bake_command(&tmp.path().join("duplicate-100000"), &["--quiet"]), NO_HANG);
    r.expect_code(0);
    check_complete(&tmp.path().join("duplicate-100000"));
    eprintln!("brdf-bake over a manifest of 100 001 entries: {took:?} (a whole bake)");
}

/// `make-cases.sh`'s `control-chars` (an output path holding a newline and ANSI colour codes that
/// forge a second, green `error: none, the bake is fine` line), the same in the material's
/// `source_path` and in an asset's provenance: every message is one line, the name in it with its
/// control characters escaped, and no raw control character reaches the terminal.
#[test]
fn names_from_a_file_cannot_forge_messages() {
    let Some(shared) = shared_or_skip(&["data/hostile", BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let good = copy_of_reference(tmp.path(), "good");
    let cases = tmp.path().join("cases");
    let mut cmd = Command::new("bash");
    cmd.arg(shared.join("data/hostile/bake2/make-cases.sh")).arg(&good).arg(&cases);
    run(cmd, "").expect_code(0);
    let dir = cases.join("control-chars");
    let forged = "\n\u{1b}[32merror: none, the bake is fine\u{1b}[0m";
    let shown = "\\n\\u{1b}[32merror: none, the bake is fine\\u{1b}[0m";
    let source = copy_of_reference(tmp.path(), "source-path");
    let text = std::fs::read_to_string(source.join(MANIFEST)).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
    manifest["material"]["source_path"] = format!("gold{forged}.binary").into();
    std::fs::write(source.join(MANIFEST), serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    let good_asset = asset::read_file(&good.join("importance.asset")).unwrap();
    let mut provenance = good_asset.provenance.clone();
    provenance.source_name = format!("gold{forged}");
    provenance.parameters.push((format!("seed{forged}"), format!("7{forged}")));
    let forged_asset = tmp.path().join("provenance.asset");
    std::fs::write(&forged_asset, asset::encode(&asset::Asset { provenance, payload: good_asset.payload })).unwrap();

    let no_raw_controls = |r: &crate::support::Run| {
        let raw = r.stderr.chars().chain(r.stdout.chars()).any(|c| c.is_control() && c != '\n');
        assert!(!raw, "a raw control character was printed\n{r}");
    };
    let png = tmp.path().join("p.png");
    let mut sheet = tool("brdf-preview");
    sheet.arg(&dir).arg("--sheet").arg(&png);
    let refusals = [
        (
            preview_command(&dir, &png),
            format!("{}: no such file", dir.join(format!("importance{shown}.asset")).display()),
        ),
        (sheet, format!("importance{shown}.asset")),
        (preview_command(&source, &png), format!("reading gold{shown}.binary: no such file")),
    ];
    for (cmd, needle) in refusals {
        let (r, _) = run_within(cmd, NO_HANG);
        no_raw_controls(&r.expect_one_error_line(&needle));
    }
    let mut cmd = tool("asset-info");
    cmd.arg(&forged_asset);
    let r = run(cmd, "").expect_code(0);
    assert!(r.stdout.contains(&format!("gold{shown}")) && r.stdout.contains(&format!("seed{shown} = 7{shown}")), "{r}");
    no_raw_controls(&r);
    // The bake itself prints no name of the manifest's: it rebakes quietly.
    let (r, _) = run_within(bake_command(&dir, &["--quiet"]), NO_HANG);
    no_raw_controls(&r.expect_code(0));
}

/// Tools that write one file (`merl-info --asset`, `brdf-preview --out`) into a bake folder: a
/// name the manifest lists (or the manifest) is refused with one line, the bake left as it was;
/// while a bake holds the folder's lock (taken here by `flock(1)`, as a bake takes it) any name is
/// refused at once; an unlisted name is written when no bake runs (so neither tool writes into a
/// folder during a bake, and `merl-info --asset BAKE/importance.asset` cannot overwrite a listed
/// file).
#[test]
fn tools_that_write_one_file_leave_a_bake_alone() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = copy_of_reference(tmp.path(), "bake");
    let before = contents(&dir);
    let merl_info = |name: &str| {
        let mut cmd = tool("merl-info");
        cmd.arg(ggx_copper()).arg("--asset").arg(dir.join(name));
        cmd
    };
    let preview = |name: &str| preview_command(&dir, &dir.join(name));
    let listed = |name: &str| format!("{name} is a file of the bake in {} (its manifest lists it)", dir.display());
    for (cmd, name) in
        [(merl_info("importance.asset"), "importance.asset"), (preview("importance.png"), "importance.png")]
    {
        let (r, _) = run_within(cmd, NO_HANG);
        r.expect_one_error_line(&listed(name));
    }
    let (r, _) = run_within(merl_info(MANIFEST), NO_HANG);
    r.expect_one_error_line(&listed(MANIFEST));
    assert!(contents(&dir) == before, "a refused tool changed the bake");
    check_complete(&dir);

    let mut lock = Command::new("flock");
    lock.arg("--close").arg(&dir).args(["sleep", "60"]);
    let mut lock = lock.spawn().expect("running flock");
    let held =
        || !Command::new("flock").args(["--nonblock", "--shared"]).arg(&dir).arg("true").status().unwrap().success();
    let start = std::time::Instant::now();
    while !held() {
        assert!(start.elapsed() < NO_HANG, "flock took no lock");
        std::thread::sleep(Duration::from_millis(20));
    }
    for cmd in [merl_info("material-info.asset"), preview("preview.png")] {
        let (r, _) = run_within(cmd, NO_HANG);
        r.expect_one_error_line("a bake is writing this folder (it holds the folder's lock)");
    }
    lock.kill().expect("ending flock");
    lock.wait().expect("flock ended");
    assert!(contents(&dir) == before, "a tool wrote into a folder a bake held");
    for cmd in [merl_info("material-info.asset"), preview("preview.png")] {
        run_within(cmd, NO_HANG).0.expect_code(0);
    }
    check_manifest_inside(&dir);
}

/// A bake whose manifest is just under the readers' 16 MiB limit (a stage's figures padded):
/// `brdf-wavelet` adding its stage would write a manifest over it, which every reader refuses; it
/// exits 2 with one line instead and leaves the bake as it was, rather than exit 0 with a 24 MB
/// manifest that no reader would read.
#[test]
fn a_writer_refuses_a_manifest_its_readers_would_refuse() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = copy_of_reference(tmp.path(), "bake");
    let text = std::fs::read_to_string(dir.join(MANIFEST)).unwrap();
    let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
    let pretty = |m: &serde_json::Value| serde_json::to_string_pretty(m).unwrap() + "\n";
    let limit = 16 << 20;
    manifest["stages"][0]["figures"]["padding"] = "".into();
    let room = limit - pretty(&manifest).len() - 300;
    manifest["stages"][0]["figures"]["padding"] = "x".repeat(room).into();
    let text = pretty(&manifest);
    assert!(text.len() <= limit);
    std::fs::write(dir.join(MANIFEST), &text).unwrap();
    let before = contents(&dir);
    let out = tmp.path().join("p.png");
    run_within(preview_command(&dir, &out), NO_HANG).0.expect_code(0);

    let mut cmd = tool("brdf-wavelet");
    cmd.arg(ggx_copper()).arg("--out-dir").arg(&dir).args(["--side", "8"]);
    let (r, _) = run_within(cmd, NO_HANG);
    r.expect_one_error_line(&format!(
        "writing {}: the new manifest would be refused by its readers (manifest length",
        dir.join(MANIFEST).display()
    ));
    assert!(contents(&dir) == before, "the refused stage changed the bake");
}

/// A folder moved while a bake runs (`mv D D.old; mkdir D`), and a second bake into the new `D`
/// at once, at seeded random offsets into the first: each folder ends one complete bake (its
/// manifest lists exactly the files there, each with its size and hash); where both ran, the first
/// landed in `D.old` and the second in `D` (were the staging, the manifest's removal and the
/// renames done by path, `D` could end with the first bake's files, or one manifest and 14
/// unlisted files, and the moved folder's manifest name files the bake had deleted).
#[test]
fn a_folder_moved_during_a_bake_keeps_both_bakes_whole() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    // The first bake changes a setting (so that it rebakes); the second bakes the reference's.
    let first_bake = |dir: &Path| bake_command(dir, &["--vectors", "1", "--quiet"]);
    let measure = copy_of_reference(tmp.path(), "measure");
    let start = std::time::Instant::now();
    run(first_bake(&measure), "").expect_code(0);
    let duration = start.elapsed();
    let vectors = |m: &serde_json::Value| m["parameters"]["importance"]["vectors"].as_u64();

    let mut rng = rand::rngs::StdRng::seed_from_u64(42);
    let mut both_ran = 0;
    for case in 0..4 {
        let dir = copy_of_reference(tmp.path(), &format!("d{case}"));
        let moved = tmp.path().join(format!("d{case}.old"));
        let offset = duration.mul_f64(rng.random_range(0.2..0.9));
        let first = std::thread::spawn({
            let cmd = first_bake(&dir);
            move || run_within(cmd, NO_HANG).0
        });
        std::thread::sleep(offset);
        std::fs::rename(&dir, &moved).unwrap();
        // The first bake may have created the path again if it had not opened its folder yet.
        let _ = std::fs::create_dir(&dir);
        let second = run_within(bake_command(&dir, &["--quiet"]), NO_HANG).0;
        let first = first.join().expect("the first bake");
        for r in [&first, &second] {
            match r.code {
                Some(0) => {}
                Some(2) => assert!(r.stderr.contains("another bake is writing this folder"), "case {case}\n{r}"),
                _ => panic!("case {case}, offset {offset:?}\n{r}"),
            }
        }
        let (old, new) = (check_complete(&moved), check_complete(&dir));
        if first.code == Some(0) && second.code == Some(0) {
            both_ran += 1;
            assert_eq!(vectors(&old), Some(1), "case {case}: the first bake is not in the moved folder\n{first}");
            assert_ne!(vectors(&new), Some(1), "case {case}: the second bake is not in the new folder\n{second}");
        }
    }
    assert!(both_ran >= 2, "{both_ran} of 4 cases moved the folder while the first bake held it");
}

/// `brdf-wavelet` into a bake folder adds its stage as `brdf-bake --wavelet-brdf-ratio` would, through
/// the bake's protocol: the manifest lists the files with their hashes and the settings, the
/// previewer renders from it by default, and a rebake without the wavelet removes them again.
/// Another material is refused; so is a single-stage tool that cannot update a manifest.
#[test]
fn brdf_wavelet_adds_its_stage_to_a_bake_and_other_tools_refuse_one() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = copy_of_reference(tmp.path(), "bake");
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(ggx_copper()).arg("--out-dir").arg(&dir).args(["--side", "8", "--ratio", "4"]);
    let r = run(cmd, "").expect_code(0);
    assert!(r.stdout.contains("added to the bake"), "{r}");
    let manifest = check_complete(&dir);
    let names: Vec<&str> = manifest["stages"].as_array().unwrap().iter().map(|s| s["name"].as_str().unwrap()).collect();
    let at = |n: &str| names.iter().position(|s| *s == n).unwrap_or_else(|| panic!("{n} in {names:?}"));
    assert!(at("bandwidth-atlas") < at("wavelet-brdf") && at("wavelet-brdf") < at("environment-bandwidth"));
    assert_eq!(manifest["parameters"]["wavelet_brdf"]["side"], 8, "{manifest:#}");

    let out = tmp.path().join("w.png");
    let mut cmd = preview_command(&dir, &out);
    cmd.args(["--brdf", "wavelet-brdf"]);
    run(cmd, "").expect_code(0);

    // The bake's own command line does not ask for the wavelet: it rebakes without it.
    let r = run(bake_command(&dir, &["--quiet"]), "").expect_code(0);
    check_complete(&dir);
    assert!(!dir.join("wavelet-brdf.asset").exists(), "{r}");
    assert!(contents(&dir) == contents(&reference_bake().dir), "{r}");

    let phong = phong(tmp.path());
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(&phong).arg("--out-dir").arg(&dir).args(["--side", "8"]);
    run(cmd, "").expect_one_error_line("is a bake of ggx-copper");
    let mut cmd = tool("merl-importance");
    cmd.arg(&phong).arg("--out-dir").arg(&dir).args(["--theta-o", "2", "--vectors", "1", "--samples", "16"]);
    run(cmd, "").expect_one_error_line("is a bake folder (it has a manifest.json)");
    assert!(contents(&dir) == contents(&reference_bake().dir));
}

/// Every path option of every tool, given a FIFO (nobody writes to it) and `/dev/zero`: each run
/// ends within the limit with exit 2 and one line that says what the path is. Outputs that are a
/// FIFO are not replaced either.
#[test]
fn path_options_refuse_fifos_and_devices_without_blocking() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let bake = copy_of_reference(tmp.path(), "bake");
    let fifo = tmp.path().join("fifo");
    mkfifo(&fifo);
    let material = ggx_copper().to_path_buf();
    let out = tmp.path().join("out");
    let png = tmp.path().join("p.png");
    // The reading tools: the path under test first, then these arguments.
    let readers: [(&str, &[&str]); 9] = [
        ("merl-info", &[]),
        ("asset-info", &[]),
        ("merl-importance", &["--out-dir"]),
        ("brdf-bandwidth", &["--out-dir"]),
        ("bandwidth-pca", &["--components", "1", "--out-dir"]),
        ("envmap-bandwidth", &["--out-dir"]),
        ("envmap-prefilter", &["--out-dir"]),
        ("brdf-wavelet", &["--out-dir"]),
        ("brdf-bake", &["--out-dir"]),
    ];
    let mut runs = 0;
    for bad in [fifo.as_path(), Path::new("/dev/zero")] {
        let what = if bad == fifo { "a fifo (named pipe), not a regular file" } else { "a character device" };
        for (name, flags) in readers {
            let mut cmd = tool(name);
            cmd.arg(bad).args(flags);
            if flags.last() == Some(&"--out-dir") {
                cmd.arg(&out);
            }
            run_within(cmd, NO_HANG).0.expect_one_error_line(what);
            runs += 1;
        }
        let preview = |extra: &[&std::ffi::OsStr]| {
            let mut cmd = tool("brdf-preview");
            cmd.arg(&bake).arg("--out").arg(&png).args(extra);
            cmd
        };
        let mut bake_env_cmd = tool("brdf-bake");
        bake_env_cmd.arg(&material).arg("--env").arg(bad).arg("--out-dir").arg(&out);
        for cmd in [
            bake_env_cmd,
            preview(&["--material".as_ref(), bad.as_os_str()]),
            preview(&["--brdf".as_ref(), "wavelet-brdf".as_ref(), "--wavelet-brdf".as_ref(), bad.as_os_str()]),
            preview(&["--mesh".as_ref(), bad.as_os_str()]),
        ] {
            run_within(cmd, NO_HANG).0.expect_one_error_line(what);
            runs += 1;
        }
        // A bake folder or an output folder that is not a folder.
        let mut cmd = tool("brdf-preview");
        cmd.arg(bad).arg("--out").arg(&png);
        run_within(cmd, NO_HANG).0.expect_one_error_line("not a folder");
        let mut cmd = tool("brdf-bake");
        cmd.arg(&material).arg("--out-dir").arg(bad);
        run_within(cmd, NO_HANG).0.expect_one_error_line("not a folder");
        runs += 2;
    }
    // Outputs: a FIFO is not renamed away (nor would a device be).
    let fifo = fifo.as_os_str();
    let outputs: [(&str, Vec<&std::ffi::OsStr>); 5] = [
        ("brdf-preview", vec![bake.as_os_str(), "--out".as_ref(), fifo, "--size".as_ref(), "16x16".as_ref()]),
        ("brdf-preview", vec![bake.as_os_str(), "--sheet".as_ref(), fifo]),
        ("merl-synth", vec!["lambertian".as_ref(), "--out".as_ref(), fifo]),
        ("envmap-synth", vec!["--size".as_ref(), "16x8".as_ref(), "--out".as_ref(), fifo]),
        ("merl-info", vec![material.as_os_str(), "--asset".as_ref(), fifo]),
    ];
    for (name, args) in outputs {
        let mut cmd = tool(name);
        cmd.args(&args);
        run_within(cmd, NO_HANG).0.expect_one_error_line("refusing to replace");
        runs += 1;
    }
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::symlink_metadata(fifo).unwrap().file_type().is_fifo());
    eprintln!("{runs} runs, none blocked");
}
