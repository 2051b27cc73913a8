//! `envmap-prefilter` end to end on the shared real maps: every output is written, the asset
//! names them with their true hashes, the KTX2 files read back with the maintained `ktx2` reader
//! and hold the EXR layers and the mip chain to half-float rounding (`--verify`), and damaged or
//! awkward inputs give exit 2 and one line naming the file.

use std::path::{Path, PathBuf};

use asset::Payload;

use crate::support::{png_decode, run, shared, shared_or_skip, temp_dir, tool};

fn env_dir() -> PathBuf {
    shared().join("data").join("env")
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
}

/// `(vkFormat, width, height, layerCount, levelCount)` from a KTX2 header, by hand.
fn ktx2_header(path: &Path) -> (u32, u32, u32, u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    assert_eq!(
        &bytes[..12],
        &[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A],
        "{}",
        path.display()
    );
    (u32_at(&bytes, 12), u32_at(&bytes, 20), u32_at(&bytes, 24), u32_at(&bytes, 32), u32_at(&bytes, 40))
}

#[test]
fn writes_every_output_for_the_real_maps_and_they_verify() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    for name in ["quarry_01_1k.hdr", "potsdamer_platz_1k.hdr"] {
        let tmp = temp_dir();
        let out = tmp.path().join("prefiltered");
        let mut cmd = tool("envmap-prefilter");
        cmd.arg(env_dir().join(name)).arg("--out-dir").arg(&out).arg("--verify");
        let r = run(cmd, "")
            .expect_code(0)
            .expect_stdout("8 layers match the EXR layers within half-float rounding")
            .expect_stdout("10 mip levels match the source's mip chain within half-float rounding");
        assert!(!r.stdout.contains("problem"), "{r}");

        let asset = asset::read_file(&out.join("prefiltered.asset")).unwrap();
        assert_eq!(asset.provenance.source_name, name);
        assert_eq!(asset.provenance.source_sha256, asset::sha256_file(&env_dir().join(name)).unwrap());
        let Payload::PrefilteredEnvmap(p) = asset.payload else { panic!("{name}: not a prefiltered envmap") };
        assert_eq!(p.exponents, [1, 4, 16, 64, 256, 1024, 4096, 16384]);
        assert_eq!((p.source_size, p.layer_size, p.mip_levels), ([1024, 512], [512, 256], 10));
        assert_eq!(p.lobe_bandwidth.len(), 8);
        for (k, nu) in p.lobe_bandwidth.iter().enumerate() {
            let n = f64::from(p.exponents[k]);
            assert!((nu - (n + 2.0).sqrt() / (2.0 * std::f64::consts::PI)).abs() < 1e-12);
        }
        for (t, pair) in p.bandwidth_thresholds.iter().zip(p.lobe_bandwidth.windows(2)) {
            assert!((t - (pair[0] * pair[1]).sqrt()).abs() < 1e-12);
        }
        for (layer, source) in p.layer_mean_radiance.iter().map(|m| (m, p.source_mean_radiance)) {
            for c in 0..3 {
                assert!((layer[c] / source[c] - 1.0).abs() < 0.005, "{name}: layer mean {layer:?} vs {source:?}");
            }
        }
        let files = [&p.layers_ktx2, &p.mips_ktx2, &p.contact_sheet_png].into_iter().chain(&p.layer_exrs);
        for file in files {
            let path = out.join(&file.name);
            assert_eq!(asset::sha256_file(&path).unwrap(), file.sha256, "{}", path.display());
        }
        assert_eq!(p.contact_sheet_png.name, "layers.png");
        png_decode(&out.join("layers.png"));
        // The folder holds what the asset names and nothing else (no temporary file).
        let mut present: Vec<String> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        present.sort();
        let mut named: Vec<String> = [&p.layers_ktx2, &p.mips_ktx2, &p.contact_sheet_png]
            .into_iter()
            .chain(&p.layer_exrs)
            .map(|f| f.name.clone())
            .chain(["prefiltered.asset".to_string()])
            .collect();
        named.sort();
        assert_eq!(present, named);
        let names: Vec<&str> = p.layer_exrs.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "layer-n1.exr",
                "layer-n4.exr",
                "layer-n16.exr",
                "layer-n64.exr",
                "layer-n256.exr",
                "layer-n1024.exr",
                "layer-n4096.exr",
                "layer-n16384.exr"
            ]
        );
        // VK_FORMAT_R16G16B16A16_SFLOAT = 97; an array of 8 layers with one level, and a plain
        // 2D texture with 10 levels. Quarry's sun exceeds the largest half float: its mip chain is
        // stored as single floats (VK_FORMAT_R32G32B32A32_SFLOAT = 109), never at a hidden scale.
        assert_eq!(ktx2_header(&out.join(&p.layers_ktx2.name)), (97, 512, 256, 8, 1));
        let mips_format = if name.starts_with("quarry") { 109 } else { 97 };
        assert_eq!(ktx2_header(&out.join(&p.mips_ktx2.name)), (mips_format, 1024, 512, 0, 10));
        assert_eq!((p.layers_radiance_scale, p.mips_radiance_scale), (1.0, 1.0));

        let mut cmd = tool("asset-info");
        cmd.arg(out.join("prefiltered.asset"));
        run(cmd, "")
            .expect_code(0)
            .expect_stdout("kind             prefiltered-envmap (3)")
            .expect_stdout("payload: prefiltered envmap")
            .expect_stdout("layer exr        n = 16384: layer-n16384.exr");
        let mut cmd = tool("asset-info");
        cmd.arg(out.join("prefiltered.asset")).arg("--json");
        let json = run(cmd, "").expect_code(0).json();
        assert_eq!(json["payload"]["layers_ktx2"]["name"], "layers.ktx2");
        assert_eq!(json["payload"]["exponents"][7], 16384);
    }
}

/// Options: other exponents and sizes, and the method forced.
#[test]
fn exponents_size_and_method_are_honoured() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let tmp = temp_dir();
    let out = tmp.path().join("small");
    let mut cmd = tool("envmap-prefilter");
    cmd.arg(env_dir().join("studio_small_03_1k.hdr")).arg("--out-dir").arg(&out).args([
        "--exponents",
        "2,30,900",
        "--size",
        "64x32",
        "--method",
        "window",
        "--verify",
    ]);
    run(cmd, "").expect_code(0).expect_stdout("3 layers match");
    let Payload::PrefilteredEnvmap(p) = asset::read_file(&out.join("prefiltered.asset")).unwrap().payload else {
        panic!("not a prefiltered envmap")
    };
    assert_eq!((p.exponents.as_slice(), p.layer_size), (&[2, 30, 900][..], [64, 32]));
    assert_eq!(ktx2_header(&out.join("layers.ktx2")), (97, 64, 32, 3, 1));
    let provenance = asset::read_file(&out.join("prefiltered.asset")).unwrap().provenance;
    // The method each layer used is recorded, one ("layer", "n=N: METHOD") pair per layer.
    for n in [2, 30, 900] {
        let pair = ("layer".to_string(), format!("n={n}: window"));
        assert!(provenance.parameters.contains(&pair), "{provenance:?}");
    }
}

#[test]
fn bad_arguments_are_refused() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let cases: [(&[&str], &str); 3] = [
        (&["--exponents", "16,4"], "error: invalid arguments: exponents must increase strictly, found 16 then 4\n"),
        (&["--exponents", "0"], "error: invalid arguments: exponent 0 outside 1 ..= 16777216\n"),
        (
            &["--size", "100x100"],
            "error: invalid arguments: layer size 100 x 100: expected width = 2 x height, height 1 ..= 8192\n",
        ),
    ];
    let tmp = temp_dir();
    for (args, expected) in cases {
        let mut cmd = tool("envmap-prefilter");
        cmd.arg(env_dir().join("quarry_01_1k.hdr")).arg("--out-dir").arg(tmp.path().join("x")).args(args);
        let r = run(cmd, "").expect_code(2);
        assert_eq!(r.stderr, expected, "{r}");
        assert!(!tmp.path().join("x").exists(), "nothing is written\n{r}");
    }
    let mut cmd = tool("envmap-prefilter");
    cmd.arg(env_dir().join("quarry_01_1k.hdr")).arg("--out-dir").arg(tmp.path().join("x")).args(["--size", "256"]);
    run(cmd, "").expect_code(2);
}

/// Runs the tool on `path`, expects exit 2, one line `error: reading PATH: ...` holding
/// `problem`, nothing on stdout and nothing written.
fn check_refused(path: &Path, problem: &str) {
    let tmp = temp_dir();
    let out = tmp.path().join("out");
    let mut cmd = tool("envmap-prefilter");
    cmd.arg(path).arg("--out-dir").arg(&out);
    let r = run(cmd, "").expect_code(2).expect_error(path, problem);
    assert!(r.stdout.is_empty(), "nothing belongs on stdout\n{r}");
    assert!(!out.exists(), "nothing is written\n{r}");
}

/// The awkward files of `decoder/` decode (the `envmap` tests check their values) but none is a
/// 2:1 lat-long map: each is refused with the reason. The list must name every file there.
#[test]
fn awkward_decoder_files_are_refused_with_the_reason() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let cases = [
        ("imagers_old-rle.hdr", "not a lat-long map: 551 x 276, expected width = 2 x height"),
        ("imagers_rgbr4x4.hdr", "not a lat-long map: 4 x 4, expected width = 2 x height"),
        ("imagers_scale.hdr", "not a lat-long map: 256 x 8, expected width = 2 x height"),
        ("memorial.exr", "not a lat-long map: 512 x 768, expected width = 2 x height"),
    ];
    let dir = env_dir().join("decoder");
    let mut present: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    present.sort();
    assert_eq!(present, cases.map(|c| c.0), "every file in {} needs an expected outcome here", dir.display());
    for (file, problem) in cases {
        check_refused(&dir.join(file), problem);
    }
}

/// Damaged copies of real maps and files that are no map at all.
#[test]
fn damaged_inputs_are_refused_with_the_reason() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let tmp = temp_dir();
    let truncate = |name: &str, len: usize| {
        let bytes = std::fs::read(env_dir().join(name)).unwrap();
        let path = tmp.path().join(format!("truncated-{name}"));
        std::fs::write(&path, &bytes[..len]).unwrap();
        path
    };
    check_refused(&truncate("quarry_01_1k.hdr", 100_000), "radiance hdr: truncated: the file ends early");
    check_refused(&truncate("piz_compressed.exr", 100_000), "openexr: truncated: the file ends early");
    check_refused(&truncate("quarry_01_1k.hdr", 0), "empty file");
    let text = tmp.path().join("notes.hdr");
    std::fs::write(&text, "hello").unwrap();
    check_refused(&text, "unsupported: unknown file format (starts with 68 65 6c 6c)");
    check_refused(&tmp.path().join("missing.hdr"), "no such file or directory");
}

/// `asset-info` checks the files a prefiltered asset names: a missing or replaced file is exit 1
/// naming it (a killed rerun can leave `prefiltered.asset` naming a `layers.ktx2` whose sha256
/// no longer matches, which `asset-info` must say).
#[test]
fn asset_info_names_a_stale_or_missing_linked_file() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let tmp = temp_dir();
    let out = tmp.path().join("out");
    let mut cmd = tool("envmap-prefilter");
    cmd.arg(env_dir().join("studio_small_03_1k.hdr")).arg("--out-dir").arg(&out).args(["--size", "32x16"]);
    run(cmd, "").expect_code(0);
    let asset_path = out.join("prefiltered.asset");
    let check = |code: i32| {
        let mut cmd = tool("asset-info");
        cmd.arg(&asset_path);
        run(cmd, "").expect_code(code)
    };
    let r = check(0);
    assert!(r.stdout.contains("layers.ktx2            ok"), "{r}");
    std::fs::write(out.join("layers.ktx2"), b"another bake's layers").unwrap();
    std::fs::remove_file(out.join("layer-n4.exr")).unwrap();
    let r = check(1);
    assert_eq!(
        r.stderr.trim_end(),
        format!(
            "error: checking {}: linked file layers.ktx2 does not have the sha256 the asset records; layer-n4.exr is \
             missing",
            asset_path.display()
        ),
        "{r}"
    );
    let mut cmd = tool("asset-info");
    cmd.arg(&asset_path).arg("--json");
    let r = run(cmd, "").expect_code(1);
    let statuses: Vec<(String, String)> = r.json()["linked_files"]
        .as_array()
        .expect("linked_files")
        .iter()
        .map(|f| (f["name"].as_str().unwrap().to_string(), f["status"].as_str().unwrap().to_string()))
        .collect();
    assert!(statuses.contains(&("layers.ktx2".into(), "differs".into())), "{statuses:?}");
    assert!(statuses.contains(&("layer-n4.exr".into(), "missing".into())), "{statuses:?}");
    assert!(statuses.contains(&("mips.ktx2".into(), "ok".into())), "{statuses:?}");
}

/// Killed at 20 moments of its writing phase (from its first temporary file to its exit, at
/// seeded random fractions of the shortest phase measured so far), `envmap-prefilter` leaves
/// a folder that is consistent every time: where an asset is there, every file it names is there
/// with the recorded sha256 (`asset-info` exits 0); and the rerun leaves a complete folder with
/// no temporary file (the killed run's are removed).
#[test]
fn killed_while_writing_the_folder_stays_consistent() {
    use rand::{Rng, SeedableRng};
    use std::time::{Duration, Instant};

    let tmp = temp_dir();
    let out = tmp.path().join("out");
    // A small map keeps the 41 runs short (about 10 s in all in a debug build).
    let input = tmp.path().join("sky.exr");
    let mut cmd = tool("envmap-synth");
    cmd.args(["--size", "256x128", "--out"]).arg(&input);
    run(cmd, "").expect_code(0);
    let start = || {
        let mut cmd = tool("envmap-prefilter");
        cmd.arg(&input).arg("--out-dir").arg(&out).args(["--size", "256x128", "--quiet"]);
        cmd.stdout(std::process::Stdio::null()).stderr(std::process::Stdio::null());
        cmd.spawn().expect("start envmap-prefilter")
    };
    let writing = || {
        std::fs::read_dir(&out).is_ok_and(|d| d.flatten().any(|e| e.file_name().to_string_lossy().ends_with(".tmp")))
    };
    // Polls until the run starts writing; `None` if it ended first.
    let wait_for_writing = |child: &mut std::process::Child| loop {
        if writing() {
            return Some(Instant::now());
        }
        if child.try_wait().expect("poll").is_some() {
            return None;
        }
        std::thread::sleep(Duration::from_micros(200));
    };
    // The length of the writing phase: the shortest seen so far (every rerun is measured too, so
    // a first run slowed by a busy machine does not send the kills past the end).
    let measure = || {
        let mut child = start();
        let began = wait_for_writing(&mut child).expect("a full run writes");
        assert!(child.wait().expect("wait").success(), "a full run failed");
        began.elapsed()
    };
    let mut phase = measure();
    let asset_path = out.join("prefiltered.asset");
    let asset_info = |code: i32, what: &str| {
        let mut cmd = tool("asset-info");
        cmd.arg(&asset_path);
        let r = run(cmd, "");
        assert_eq!(r.code, Some(code), "{what}\n{r}");
    };
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    let (mut killed, mut with_asset) = (0, 0);
    for kill in 0..20 {
        let mut child = start();
        if wait_for_writing(&mut child).is_some() {
            std::thread::sleep(phase.mul_f64(rng.random_range(0.0..1.0)));
            killed += usize::from(child.try_wait().expect("poll").is_none());
            let _ = child.kill();
        }
        let _ = child.wait();
        if asset_path.exists() {
            // The asset is removed before any file it names is replaced, and lands last.
            with_asset += 1;
            asset_info(0, &format!("kill {kill}: asset-info on the killed state"));
        }
        phase = phase.min(measure());
        asset_info(0, &format!("kill {kill}: asset-info after the rerun"));
        let temporaries: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(temporaries.is_empty(), "kill {kill}: the rerun left {temporaries:?}");
    }
    println!(
        "writing takes {phase:?}; 20 runs stopped in it, {killed} killed before they ended, {with_asset} killed \
         states held an asset, every one consistent"
    );
    assert!(killed >= 5, "only {killed} of 20 kills landed while writing: the test no longer tests");
}

/// The KTX2 files as three.js reads them: `ktx-parse` (the parser of its KTX2Loader), run by
/// node on `tests/ktx-parse/check.mjs`, parses every file `--cube --ggx-levels --chain` writes, and finds the shape,
/// format, level sizes, descriptor and only the specification's keys; and Khronos' validator
/// `ktx2check` passes every file with warnings as errors. `make setup` installs both.
#[test]
fn ktx_parse_reads_the_lat_long_and_cube_files() {
    let Some(_) = shared_or_skip(&["data/env"]) else { return };
    let script = crate::support::root().join("tests").join("ktx-parse").join("check.mjs");
    let modules = crate::support::root().join("tests").join("ktx-parse").join("node_modules").join("ktx-parse");
    assert!(
        modules.is_dir(),
        "ktx-parse is not installed: run `make setup` (npm ci in tests/ktx-parse; needs node and npm)"
    );
    let tmp = temp_dir();
    let out = tmp.path().join("prefiltered");
    let mut cmd = tool("envmap-prefilter");
    cmd.arg(env_dir().join("quarry_01_1k.hdr")).arg("--out-dir").arg(&out);
    cmd.args(["--size", "64x32", "--exponents", "1,64", "--cube", "--ggx-levels", "5", "--chain", "--quiet"]);
    run(cmd, "").expect_code(0);
    let names = [
        "layers.ktx2",
        "mips.ktx2",
        "layers-cube.ktx2",
        "mips-cube.ktx2",
        "ggx.ktx2",
        "ggx-cube.ktx2",
        "dfg.ktx2",
        "phong-chain.ktx2",
        "phong-chain-cube.ktx2",
    ];
    let mut node = std::process::Command::new("node");
    node.arg(&script).args(names.map(|n| out.join(n)));
    let r = run(node, "").expect_code(0);
    let parsed: Vec<serde_json::Value> =
        r.stdout.lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}\n{r}"))).collect();
    assert_eq!(parsed.len(), names.len(), "{r}");
    // (faces, layers, width, height, levels) of each file.
    let shapes = [
        (1, 2, 64, 32, 1),
        (1, 0, 1024, 512, 10),
        (6, 2, 16, 16, 1),
        (6, 0, 256, 256, 9),
        (1, 0, 64, 32, 5),
        (6, 0, 16, 16, 5),
        (1, 0, 128, 128, 1),
        (1, 0, 64, 32, 2),
        (6, 0, 16, 16, 2),
    ];
    for (json, (name, (faces, layers, width, height, levels))) in parsed.iter().zip(names.iter().zip(shapes)) {
        let found = (&json["faceCount"], &json["layerCount"], &json["pixelWidth"], &json["pixelHeight"]);
        assert_eq!(found, (&faces.into(), &layers.into(), &width.into(), &height.into()), "{name}\n{r}");
        assert_eq!(json["levelCount"], levels, "{name}\n{r}");
        let format = json["vkFormat"].as_u64().unwrap();
        assert!(format == 97 || format == 109, "{name}: vkFormat {format}");
        let texel = if format == 97 { 8 } else { 16 };
        assert_eq!(json["bytesPlane0"], texel, "{name}\n{r}");
        for (l, bytes) in json["levelBytes"].as_array().unwrap().iter().enumerate() {
            let (w, h) = ((width >> l).max(1), (height >> l).max(1));
            assert_eq!(bytes.as_u64().unwrap(), (texel * w * h * faces * layers.max(1)) as u64, "{name} level {l}");
        }
        // Only keys the KTX2 specification defines: no custom key for a validator to warn about.
        for key in json["keys"].as_array().unwrap() {
            assert!(key.as_str().unwrap().starts_with("KTX"), "{name}: custom key {key}");
        }
        // RGBSDA, BT.709, linear.
        assert_eq!(
            (&json["colorModel"], &json["colorPrimaries"], &json["transferFunction"]),
            (&1.into(), &1.into(), &1.into())
        );
    }
    // Quarry's sun does not fit half floats: the lat-long mip chain is single floats.
    assert_eq!(parsed[1]["vkFormat"], 109, "{r}");

    // Khronos' own validator (ktx2check, KTX-Software 4.0), warnings counted as errors.
    let ktx2check = crate::support::root().join("target").join("ktx2check").join("ktx2check");
    assert!(
        ktx2check.is_file(),
        "ktx2check is not built: run `make setup` (make setup-ktx; needs cmake and a C++ compiler)"
    );
    let mut check = std::process::Command::new(&ktx2check);
    check.arg("--warn-as-error").args(names.map(|n| out.join(n)));
    let r = run(check, "");
    assert_eq!(r.code, Some(0), "ktx2check found problems\n{r}");
}
