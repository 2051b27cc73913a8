//! A bake in three.js (`engines/three`), in a real browser: `brdf-bake --engine-textures` writes
//! the textures the estimators read (every one valid to Khronos' `ktx2check` and to `ktx-parse`,
//! the parser three.js uses, and holding the bake's numbers), and the three.js material renders
//! brdf-preview's sphere in headless Chromium (WebGL 2 on SwiftShader, driven by puppeteer-core:
//! `engines/three/test/render.mjs`) as brdf-preview renders it on the GPU: the same estimator
//! with the same samples, so the two pictures differ by the port alone.
//!
//! Two ways to draw. `exact`: the mesh rasterized at brdf-preview's sub-pixel precision
//! (`exactCoverage` in `engines/three/src/index.js`: a G-buffer at 16 times the size, then the
//! material's estimators as a full-screen pass), so that every pixel covers what it covers in
//! brdf-preview; `forward`: the material on the mesh, as a scene draws it, where SwiftShader's
//! coarser sub-pixel grid (1/16 pixel, against lavapipe's and `render::raster`'s 1/256) covers
//! about a dozen rim pixels of a 128 x 128 sphere differently.
//!
//! Needs Chromium (`/usr/bin/chromium`, Debian's `chromium`, or `CHROMIUM`), node and
//! `npm ci` in engines/three (`make setup`); fails saying so when one is missing.
//!
//! `make three-cases` runs the six cases (white-paint, gold-paint and chrome under quarry_01 and
//! potsdamer_platz, 128 x 128) at brdf-preview's default samples
//! ([`three_js_equals_brdf_preview_on_the_six_cases`], ignored in `make test`: about 10 minutes
//! on 2 cores, most of it SwiftShader's reference renders).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::support::{NBRDF, nbrdf_table, root, run, shared, shared_or_skip, tool};

/// The PSNR both modes must reach against brdf-preview drawn exactly: 60 dB, above the 40 dB the
/// GPU renderer is held to against the CPU's (`tests/preview.rs`), because the same estimator
/// with the same samples and the same coverage leaves f32 rounding alone, one 8-bit step at a few
/// hundred pixels, above 60 dB (measured on the six cases: 62.1 to 73.8 dB).
const MIN_EXACT_PSNR_DB: f64 = 60.0;

/// Drawn forward, the pictures differ in two ways, both from where the mesh falls on the pixel
/// grid. The rim: pixels whose centre lies within 1/32 pixel of a silhouette edge, which
/// SwiftShader's 1/16-pixel vertex grid covers otherwise than brdf-preview's 1/256 (measured: 11
/// to 15 pixels per case, 35.4 to 46.7 dB over all pixels). And a pixel just inside the rim,
/// where the normal turns fastest across the image: the vertices' snapping moves the interpolated
/// normal a fraction of a pixel's turn, and a metal's grazing reflection changes by tens of levels
/// per pixel there (steel and chrome under studio_small_03: the pixel 1.17 pixels inside the rim
/// at (16, 49), 8 and 10 levels off, between its neighbours' 111 and 235). So a forward drawing is
/// held to this: every pixel beyond [`FAR_STEPS`] lies within [`RIM_PX`] of the sphere's
/// silhouette circle or between the least and greatest of brdf-preview's 3 x 3 pixels around it
/// (each channel, widened by [`FAR_STEPS`]), and the others reach this PSNR (measured 56.5 to
/// 67.2 dB).
const MIN_FORWARD_OFF_RIM_PSNR_DB: f64 = 50.0;

/// A difference of more than this many 8-bit steps is not rounding.
const FAR_STEPS: u8 = 8;

/// How close to the silhouette circle a rim pixel's centre lies (measured: 0.07 pixel at most).
const RIM_PX: f64 = 0.5;

/// The test bakes: brdf-bake's defaults but the smallest analysis (the atlas enters neither mode).
fn bake(material: &str, environment: &str) -> PathBuf {
    let dir = root().join("target/test-tmp/three-bakes").join(format!("{material}-{environment}"));
    std::fs::create_dir_all(dir.parent().unwrap()).expect("creating target/test-tmp/three-bakes");
    let mut cmd = tool("brdf-bake");
    cmd.arg(nbrdf_table(material))
        .arg("--env")
        .arg(shared().join("data/env").join(format!("{environment}.hdr")))
        .arg("--out-dir")
        .arg(&dir)
        .args(["--engine-textures", "--analysis-size", "64", "--quiet"]);
    // At 64 x 64 most lobes reach the analysis grid's limit, a validation problem (exit 1).
    let r = run(cmd, "");
    assert!(matches!(r.code, Some(0 | 1)), "the bake failed\n{r}");
    dir
}

/// The figures of the bake's engine-textures stage.
fn figures(dir: &Path) -> serde_json::Value {
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    let stage = manifest["stages"].as_array().unwrap().iter().find(|s| s["name"] == "engine-textures");
    stage.expect("an engine-textures stage").clone()
}

const ENGINE_TEXTURES: [&str; 7] = [
    "engine-merl.ktx2",
    "engine-brdf-tables.ktx2",
    "engine-view-layers.ktx2",
    "engine-environment.ktx2",
    "engine-light-tables.ktx2",
    "engine-layers.ktx2",
    "engine-full-layers.ktx2",
];

fn read_data(path: &Path) -> prefilter::ktx::Ktx2Data {
    prefilter::ktx::decode_data(&std::fs::read(path).unwrap()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every engine texture is listed in the manifest with its role, passes `ktx2check
/// --warn-as-error` and `ktx-parse`, has the shape `data-schema/engine-textures.md` gives it, and
/// holds the bake's numbers: the MERL table's values exactly, level 0 as the bake's `mips.ktx2`
/// holds it, peaks that are a share of level 0, CDF rows that rise from 0 to 1, layer coordinates
/// among the layers, the whole environment's layers as the bake's `layers.ktx2` holds them and
/// the smooth part's below them.
#[test]
fn engine_textures_are_valid_ktx2_holding_the_bakes_numbers() {
    let Some(shared) = shared_or_skip(&["data/env", NBRDF]) else { return };
    let dir = bake("white-paint", "potsdamer_platz_1k");
    // A valid manifest (data-schema's JSON schema) listing every file of the folder.
    crate::brdf_bake::check_complete(&dir);
    let stage = figures(&dir);
    let roles: Vec<(&str, &str)> = stage["outputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| (o["path"].as_str().unwrap(), o["role"].as_str().unwrap()))
        .collect();
    let expected_roles: Vec<(&str, String)> =
        ENGINE_TEXTURES.iter().map(|n| (*n, n.trim_end_matches(".ktx2").to_string())).collect();
    assert_eq!(roles, expected_roles.iter().map(|(n, r)| (*n, r.as_str())).collect::<Vec<_>>());
    let paths: Vec<PathBuf> = ENGINE_TEXTURES.iter().map(|n| dir.join(n)).collect();

    // Deterministic: the same bytes baked on one thread.
    let tmp = crate::support::temp_dir();
    let mut cmd = tool("brdf-bake");
    cmd.arg(nbrdf_table("white-paint"))
        .arg("--env")
        .arg(shared.join("data/env/potsdamer_platz_1k.hdr"))
        .arg("--out-dir")
        .arg(tmp.path().join("bake"))
        .args(["--engine-textures", "--analysis-size", "64", "--quiet"])
        .env("RAYON_NUM_THREADS", "1");
    let r = run(cmd, "");
    assert!(matches!(r.code, Some(0 | 1)), "the bake failed\n{r}");
    for (name, path) in ENGINE_TEXTURES.iter().zip(&paths) {
        let again = std::fs::read(tmp.path().join("bake").join(name)).unwrap();
        assert!(std::fs::read(path).unwrap() == again, "{name} differs when baked on one thread");
    }

    let ktx2check = root().join("target/ktx2check/ktx2check");
    assert!(
        ktx2check.is_file(),
        "ktx2check is not built: run `make setup` (make setup-ktx; needs cmake and a C++ compiler)"
    );
    let mut check = Command::new(&ktx2check);
    check.arg("--warn-as-error").args(&paths);
    let r = run(check, "");
    assert_eq!(r.code, Some(0), "ktx2check found problems\n{r}");

    let modules = root().join("tests/ktx-parse/node_modules/ktx-parse");
    assert!(
        modules.is_dir(),
        "ktx-parse is not installed: run `make setup` (npm ci in tests/ktx-parse; needs node and npm)"
    );
    let mut node = Command::new("node");
    node.arg(root().join("tests/ktx-parse/check.mjs")).args(&paths);
    let r = run(node, "").expect_code(0);
    let parsed: Vec<serde_json::Value> = r.stdout.lines().map(|l| serde_json::from_str(l).unwrap()).collect();

    let f = &stage["figures"];
    let n = |v: &serde_json::Value| v.as_u64().unwrap() as usize;
    let (rows, sectors, slices) = (n(&f["rows"]), n(&f["sectors"]), n(&f["slices"]));
    let (w, h) = (n(&f["environment_size"][0]), n(&f["environment_size"][1]));
    let layers = f["exponents"].as_array().unwrap().len();
    // (vkFormat, width, height, depth, layers) of each file, from the figures.
    let shapes = [
        (109, n(&f["merl_size"][0]), n(&f["merl_size"][1]), n(&f["merl_size"][2]), 0),
        (100, rows.max(sectors) + 1, rows + 2, 0, slices),
        (100, n(&f["view_rows"]), 1, 0, 0),
        (109, w, h, 0, 2),
        (100, w.max(h) + 1, h + 1, 0, 2),
        (109, n(&f["layers_size"][0]), n(&f["layers_size"][1]), 0, layers),
        (109, n(&f["layers_size"][0]), n(&f["layers_size"][1]), 0, layers),
    ];
    for ((json, path), shape) in parsed.iter().zip(&paths).zip(shapes) {
        let found = (
            n(&json["vkFormat"]),
            n(&json["pixelWidth"]),
            n(&json["pixelHeight"]),
            n(&json["pixelDepth"]),
            n(&json["layerCount"]),
        );
        assert_eq!(found, shape, "{}\n{r}", path.display());
        assert_eq!((n(&json["levelCount"]), n(&json["faceCount"])), (1, 1), "{}", path.display());
        let decoded = read_data(path);
        let ds = decoded.shape;
        assert_eq!((ds.width, ds.height, ds.depth, ds.layers), (shape.1, shape.2, shape.3, shape.4));
    }

    // The MERL table, cell for cell: (phi_d, theta_d, theta_h), RGB in 1/sr, 0 without data.
    let table = merl::MerlTable::parse(&std::fs::read(nbrdf_table("white-paint")).unwrap()).unwrap();
    let merl_texels = read_data(&paths[0]).values;
    for cell in 0..table.dims().cells() {
        let expected = match table.cell_value(cell) {
            Some(rgb) => [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, 1.0],
            None => [0.0; 4],
        };
        assert_eq!(merl_texels[4 * cell..4 * cell + 4], expected, "cell {cell}");
    }

    // Each slice: the row edges rise from 0 to at most 2 (t = 1 - cos theta_h), every CDF row from
    // 0 to 1.
    let tables = read_data(&paths[1]).values;
    let width = rows.max(sectors) + 1;
    let rising = |values: &[f32], what: &str| {
        assert_eq!(values[0], 0.0, "{what} starts at 0");
        assert!(values.windows(2).all(|p| p[0] <= p[1]), "{what} does not rise");
    };
    for (k, layer) in tables.chunks_exact(width * (rows + 2)).enumerate() {
        rising(&layer[..=rows], &format!("slice {k}'s row edges"));
        assert!(layer[rows] <= 2.0);
        for row in 1..rows + 2 {
            let len = if row == 1 { rows + 1 } else { sectors + 1 };
            let cdf = &layer[row * width..row * width + len];
            rising(cdf, &format!("slice {k}, row {row}"));
            assert!((cdf[len - 1] - 1.0).abs() < 1e-6, "slice {k}, row {row} ends at {}", cdf[len - 1]);
        }
    }

    let view_layers = read_data(&paths[2]).values;
    assert!(view_layers.iter().all(|&x| (0.0..=layers as f32).contains(&x)), "{view_layers:?}");

    // Level 0 is the bake's mips.ktx2 level 0; the peaks take a share of each texel.
    let mips = prefilter::ktx::decode(&std::fs::read(dir.join("mips.ktx2")).unwrap()).unwrap();
    let environment = read_data(&paths[3]).values;
    let (level0, peaks) = environment.split_at(4 * w * h);
    for (i, (rgb, stored)) in mips.levels[0][0].chunks_exact(3).zip(level0.chunks_exact(4)).enumerate() {
        assert_eq!(rgb, &stored[..3], "texel {i}");
        let peak = &peaks[4 * i..4 * i + 3];
        assert!(peak.iter().zip(rgb).all(|(p, l)| *p >= 0.0 && *p <= *l), "texel {i}: peak {peak:?} of {rgb:?}");
    }
    assert_eq!(f["peaks"], peaks.iter().any(|&v| v > 0.0));

    let light = read_data(&paths[4]).values;
    let light_width = w.max(h) + 1;
    for (d, layer) in light.chunks_exact(light_width * (h + 1)).enumerate() {
        for row in 0..=h {
            let len = if row == 0 { h + 1 } else { w + 1 };
            let cdf = &layer[row * light_width..row * light_width + len];
            rising(cdf, &format!("distribution {d}, row {row}"));
            assert!((cdf[len - 1] - 1.0).abs() < 1e-6, "distribution {d}, row {row} ends at {}", cdf[len - 1]);
        }
    }

    // The whole environment's layers are the bake's layers.ktx2, texel for texel; the smooth
    // part's lie at or below them (they are the bake's less the peaks' own, clamped at 0).
    let baked = prefilter::ktx::decode(&std::fs::read(dir.join("layers.ktx2")).unwrap()).unwrap();
    let full = read_data(&paths[6]).values;
    let smooth = read_data(&paths[5]).values;
    let texels = full.len() / 4 / layers;
    for (k, image) in baked.levels[0].iter().enumerate() {
        for (i, rgb) in image.chunks_exact(3).enumerate() {
            let at = 4 * (k * texels + i);
            assert_eq!(rgb, &full[at..at + 3], "layer {k}, texel {i}");
            assert!((0..3).all(|c| smooth[at + c] <= full[at + c]), "layer {k}, texel {i}: smooth above the whole");
        }
    }
}

/// A bake whose engine-textures stage lists fewer files than the stage now writes (one made before
/// it wrote `engine-full-layers.ktx2`) is not up to date: the rerun bakes it again, with the file.
#[test]
fn a_bake_missing_an_engine_texture_is_baked_again() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let tmp = crate::support::temp_dir();
    let dir = tmp.path().join("bake");
    let bake = || {
        let mut cmd = tool("brdf-bake");
        cmd.arg(crate::support::ggx_copper())
            .arg("--env")
            .arg(shared.join("data/env/quarry_01_1k.hdr"))
            .arg("--out-dir")
            .arg(&dir)
            .args(["--engine-textures", "--analysis-size", "64", "--json"]);
        let r = run(cmd, "");
        assert!(matches!(r.code, Some(0 | 1)), "the bake failed\n{r}");
        r.json_object()["up_to_date"].clone()
    };
    assert_eq!(bake(), serde_json::Value::Bool(false));
    assert_eq!(bake(), serde_json::Value::Bool(true), "a rerun of the same bake is up to date");
    // The manifest as an older brdf-bake wrote it: no engine-full-layers.
    let path = dir.join("manifest.json");
    let mut manifest: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for stage in manifest["stages"].as_array_mut().unwrap() {
        if stage["name"] == "engine-textures" {
            stage["outputs"].as_array_mut().unwrap().retain(|o| o["path"] != "engine-full-layers.ktx2");
        }
    }
    std::fs::write(&path, serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    std::fs::remove_file(dir.join("engine-full-layers.ktx2")).unwrap();
    assert_eq!(bake(), serde_json::Value::Bool(false), "the older bake was taken as up to date");
    assert!(dir.join("engine-full-layers.ktx2").is_file());
    crate::brdf_bake::check_complete(&dir);
}

/// The engine textures hold the lighting: without an environment the bake refuses to start.
#[test]
fn engine_textures_need_an_environment() {
    let tmp = crate::support::temp_dir();
    let mut cmd = tool("brdf-bake");
    cmd.arg(crate::support::ggx_copper()).arg("--engine-textures").arg("--out-dir").arg(tmp.path().join("bake"));
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("--env"), "{r}");
    assert!(!tmp.path().join("bake").exists(), "{r}");
}

/// The material in a three.js scene as its users build one (`engines/three/test/scene.mjs`:
/// +y up, the bake's map as `scene.environment` and `scene.background`, the material's default
/// orientation), chrome under quarry_01 at 128 x 128; the pictures are written to
/// target/test-tmp/three-scene, three.js's drawing beside the bake's.
/// - The bake's background equals three's `scene.background` of the same map, unturned and under a
///   `backgroundRotation` about every axis: at least 45 dB (measured 51.9 and 48.8: three turns the
///   map into a cube map and filters it, the bake reads it bilinearly; the map mirrored, as the
///   material read it before, or turned the wrong way scores 14.7).
/// - A `MeshStandardMaterial` mirror ball lit by `scene.environment` and the bake's near-mirror
///   material reflect the horizon on the same row of the ball's centre column, within one pixel
///   (measured: the same row).
/// - A sphere squashed by its mesh's scale is drawn as the same shape made in its geometry: at
///   least 60 dB (measured 92.0; with normals turned by the model matrix instead of its inverse
///   transpose, 22.6). Likewise an `InstancedMesh` of 100 against 100 meshes (measured 90.3-92.0)
///   and a sphere skinned to a bone against a mesh moved as the bone (88.1-89.0), a `BatchedMesh`
///   of 9 spheres of two sizes against 9 meshes, and the bake's sphere cutting through one of
///   three's drawn by a renderer with a logarithmic depth buffer against one without (which
///   sphere covers the other where they meet is the depth the material writes).
/// - An orthographic camera draws as a perspective one 4000 units away (rays parallel within
///   3e-4 radians): at least 50 dB (measured 58.4; with the eye at the camera's position, as for
///   a perspective camera, 30.0).
/// - `scene.environmentRotation` turns the environment the material reads: a turn about +y against
///   the unturned scene seen by a camera turned back by as much, at least 60 dB (measured 88.1;
///   the picture without the turn puts the sun's reflection elsewhere).
/// - Three's morph and clipping chunks: a sphere morphed into a squashed one (a morph target of
///   influence 1) against the squashed shape in its geometry, and a sphere under a clipping plane
///   through its centre against its lower half made in its geometry: at least 60 dB each
///   (measured: identical pictures, an infinite PSNR, null in the JSON).
/// - The live mode (`Accumulator`): without its split first frame, eight calls, one frame each,
///   average to one draw of the same eight frames within 1e-5 relatively (measured: equal), and a
///   moved camera starts again at one frame; with it (the default), nine calls average to the
///   split material's frame weighted 4 and those eight frames weighted 1 each, within 1e-5.
/// - On the canvas under `ACESFilmicToneMapping` and `NoToneMapping`, the material writes three's
///   pipeline (its tone mapping formula, exposure 1.7, sRGB) applied to its linear radiance read
///   back as floats, within one 8-bit level (measured: 1 and 0).
#[test]
fn the_material_is_at_home_in_a_y_up_three_js_scene() {
    let Some(_) = shared_or_skip(&["data/env", NBRDF]) else { return };
    let dir = bake("chrome", "quarry_01_1k");
    let out = root().join("target/test-tmp/three-scene");
    assert!(
        root().join("engines/three/node_modules/puppeteer-core").is_dir(),
        "puppeteer-core is not installed: run `make setup` (npm ci in engines/three; needs node and npm)"
    );
    let mut node = Command::new("node");
    node.arg(root().join("engines/three/test/scene.mjs")).arg("--bake").arg(&dir).arg("--out-dir").arg(&out);
    let r = run(node, "");
    assert_eq!(r.code, Some(0), "the scenes failed (Chromium: apt-get install chromium, or set CHROMIUM)\n{r}");
    let figures: serde_json::Value = serde_json::from_str(r.stdout.trim()).unwrap();
    println!("{figures}");
    let where_ = format!("pictures in {}", out.display());
    for (i, psnr) in figures["background_psnr_db"].as_array().unwrap().iter().enumerate() {
        let psnr = psnr.as_f64().unwrap();
        assert!(psnr >= 45.0, "background {i}: {psnr:.2} dB against three's scene.background; {where_}");
    }
    let rows = &figures["mirror_horizon_rows"];
    let (three, ours) = (rows["three"].as_i64().unwrap(), rows["bake"].as_i64().unwrap());
    assert!(three > 0 && (three - ours).abs() <= 1, "reflected horizon on row {ours}, three's on {three}; {where_}");
    for (what, key) in [
        ("mesh scale against geometry scale", "scale_psnr_db"),
        ("an InstancedMesh against separate meshes", "instances_psnr_db"),
        ("a SkinnedMesh against a moved mesh", "skinning_psnr_db"),
        ("a BatchedMesh against separate meshes", "batched_psnr_db"),
        ("a logarithmic depth buffer against a linear one", "logarithmic_depth_psnr_db"),
        ("scene.environmentRotation against a camera turned back", "environment_rotation_psnr_db"),
        ("a morph target against the same shape in its geometry", "morph_psnr_db"),
        ("a clipping plane against the half made in its geometry", "clipping_psnr_db"),
    ] {
        // Identical pictures have an infinite PSNR, null in JSON.
        let value = figures.get(key).unwrap_or_else(|| panic!("the scenes gave no {key}; {where_}"));
        let psnr = if value.is_null() { f64::INFINITY } else { value.as_f64().unwrap() };
        assert!(psnr >= 60.0, "{what}: {psnr:.2} dB; {where_}");
    }
    let live = figures["live_largest_relative_difference"].as_f64().unwrap();
    assert!(live <= 1e-5, "the live mode's mean of 8 calls against 8 frames drawn at once: {live:e}; {where_}");
    let frames = (figures["live_frames"].as_u64(), figures["live_frames_after_moving"].as_u64());
    assert_eq!(frames, (Some(8), Some(1)), "the live mode's frames, then after the camera moved");
    let split = figures["live_split_largest_relative_difference"].as_f64().unwrap();
    assert!(
        split <= 1e-5,
        "the live mode with its split first frame against that frame and 8 frames, weighted 4 and 1: {split:e}; {where_}"
    );
    let weights = (figures["live_split_frames"].as_u64(), figures["live_split_weight"].as_u64());
    assert_eq!(weights, (Some(9), Some(12)), "the live mode's frames and weight with its split first frame");
    let orthographic = figures["orthographic_psnr_db"].as_f64().unwrap();
    assert!(orthographic >= 50.0, "an orthographic camera against a distant perspective one: {orthographic:.2} dB");
    for (mapping, found) in figures["tone_mapping_levels"].as_object().unwrap() {
        let max = found["max"].as_u64().unwrap();
        assert!(max <= 1, "{mapping} tone mapping: {max} levels from three's pipeline; {where_}");
    }
}

/// The loader refuses what a hostile bake can give (`node --test` on
/// `engines/three/test/loader.test.mjs`, a synthetic bake behind a fake fetch): manifest paths
/// that leave the folder, figures of the wrong type or out of range, textures of the wrong format
/// or shape or with values outside their role's range, outputs missing, listed twice or with
/// sizes and hashes that are no file's, bodies longer than listed (an endless one stops at the
/// limit), a file that is not the one listed, with WebCrypto or without: each a BakeError
/// naming the file.
#[test]
fn the_loader_refuses_what_a_hostile_bake_gives() {
    node_test("loader.test.mjs");
}

/// What the split estimator derives at load time (`node --test` on
/// `engines/three/test/split.test.mjs`) against analytic answers: a Lambertian table's albedo
/// (within 1%, 2% at the two most grazing views), a Phong lobe's albedo (3%) and its weight on
/// its own layer (above 0.85), the mixture's kernels, the peak lights' corrections (none where
/// the mixture is the table, within 5% of the lobe's peak; the layers' share below the horizon),
/// peak lights' powers (radiance times solid angle) and directions, a sun kept apart from a lamp,
/// no power lost when sources merge, and level 0 averaged down.
#[test]
fn the_split_estimator_derives_its_inputs_as_analytic_answers_say() {
    node_test("split.test.mjs");
}

/// `node --test` on `engines/three/test/FILE`, which must pass.
fn node_test(file: &str) {
    assert!(
        root().join("engines/three/node_modules/three").is_dir(),
        "three is not installed: run `make setup` (npm ci in engines/three; needs node and npm)"
    );
    let mut node = Command::new("node");
    node.arg("--test").arg(root().join("engines/three/test").join(file));
    run(node, "").expect_code(0);
}

/// An 8-bit RGB picture: the first `height` rows of a PNG (brdf-preview's has a caption below).
fn picture(path: &Path, width: usize, height: usize) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::Cursor::new(&bytes)).read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buffer).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb, "{}", path.display());
    assert!(info.width as usize == width && info.height as usize >= height, "{}", path.display());
    buffer.truncate(3 * width * height);
    buffer
}

/// `10 log10(255^2 / MSE)` over every pixel and channel (`render::metrics::psnr_db`).
fn psnr_db(a: &[u8], b: &[u8]) -> f64 {
    let squared: u64 = a.iter().zip(b).map(|(&x, &y)| u64::from(x.abs_diff(y)).pow(2)).sum();
    10.0 * (255.0f64 * 255.0 / (squared as f64 / a.len() as f64)).log10()
}

/// Writes an 8-bit RGB PNG.
fn write_png(path: &Path, rgb: &[u8], width: usize, height: usize) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header().unwrap().write_image_data(rgb).unwrap();
}

/// One comparison: brdf-preview and three.js on the same bake, mode, samples and size.
struct Case {
    psnr_db: f64,
    /// Pixels with a channel more than [`FAR_STEPS`] apart.
    far_pixels: usize,
    /// Of those, the ones farther than [`RIM_PX`] from the silhouette circle and outside the range
    /// of brdf-preview's 3 x 3 pixels around them ([`MIN_FORWARD_OFF_RIM_PSNR_DB`]).
    unexplained: usize,
    /// The PSNR over the other pixels.
    psnr_without_far_db: f64,
    three_ms: f64,
    preview: serde_json::Value,
}

/// The radius in pixels of the unit sphere's silhouette at brdf-preview's default camera (3.2 from
/// the centre, 45 degrees vertical field of view) in an image `height` pixels high, centred.
fn silhouette_radius(height: usize) -> f64 {
    (1.0f64 / 3.2).asin().tan() / 22.5f64.to_radians().tan() * height as f64 / 2.0
}

/// Renders `dir` with `mode` (and `extra` brdf-preview arguments: `--converged`; `frames` for
/// both) by brdf-preview and by three.js in Chromium (drawn `coverage`: exact or forward) at
/// 128 x 128 into `out`, and compares them; writes
/// `NAME-actual.png` (three.js), `NAME-expected.png` and `NAME-difference.png` (|a - b| times 4)
/// there when the comparison fails ([`problem`]).
fn compare(
    dir: &Path,
    out: &Path,
    name: &str,
    (mode, coverage): (&str, &str),
    frames: Option<u32>,
    extra: &[&str],
) -> Case {
    let (width, height) = (128, 128);
    std::fs::create_dir_all(out).unwrap();
    let preview_png = out.join(format!("{name}-preview.png"));
    let mut cmd = tool("brdf-preview");
    cmd.arg(dir).arg("--out").arg(&preview_png).args(["--mode", mode, "--size", "128x128", "--json"]).args(extra);
    if let Some(frames) = frames {
        cmd.args(["--frames", &frames.to_string()]);
    }
    let r = run(cmd, "").expect_code(0);
    let preview = r.json();
    let spp = preview["spp"].as_u64().unwrap().to_string();
    let frames = preview["frames"].as_u64().unwrap().to_string();

    let three_png = out.join(format!("{name}-three.png"));
    let script = root().join("engines/three/test/render.mjs");
    assert!(
        root().join("engines/three/node_modules/puppeteer-core").is_dir(),
        "puppeteer-core is not installed: run `make setup` (npm ci in engines/three; needs node and npm)"
    );
    let mut node = Command::new("node");
    node.arg(&script).arg("--bake").arg(dir).arg("--out").arg(&three_png);
    node.args(["--mode", mode, "--size", "128x128", "--spp", &spp, "--frames", &frames, "--coverage", coverage]);
    let r = run(node, "");
    assert_eq!(
        r.code,
        Some(0),
        "the three.js render failed (Chromium: apt-get install chromium, or set CHROMIUM)\n{r}"
    );
    let three: serde_json::Value = serde_json::from_str(r.stdout.trim()).unwrap();

    let a = picture(&three_png, width, height);
    let b = picture(&preview_png, width, height);
    let psnr = psnr_db(&a, &b);
    let (mut far_pixels, mut unexplained) = (0, 0);
    let (mut near_a, mut near_b) = (Vec::new(), Vec::new());
    for (i, (p, q)) in a.chunks_exact(3).zip(b.chunks_exact(3)).enumerate() {
        if p.iter().zip(q).any(|(x, y)| x.abs_diff(*y) > FAR_STEPS) {
            far_pixels += 1;
            let (x, y) = (i % width, i / width);
            let r = (x as f64 + 0.5 - width as f64 / 2.0).hypot(y as f64 + 0.5 - height as f64 / 2.0);
            let on_rim = (r - silhouette_radius(height)).abs() <= RIM_PX;
            if !on_rim && !between_neighbours(&b, width, height, (x, y), p) {
                unexplained += 1;
            }
        } else {
            near_a.extend_from_slice(p);
            near_b.extend_from_slice(q);
        }
    }
    let psnr_without_far_db = psnr_db(&near_a, &near_b);
    let case = Case {
        psnr_db: psnr,
        far_pixels,
        unexplained,
        psnr_without_far_db,
        three_ms: three["render_ms"].as_f64().unwrap(),
        preview,
    };
    if problem(&case, coverage).is_some() {
        let difference: Vec<u8> =
            a.iter().zip(&b).map(|(x, y)| (u32::from(x.abs_diff(*y)) * 4).min(255) as u8).collect();
        write_png(&out.join(format!("{name}-actual.png")), &a, width, height);
        write_png(&out.join(format!("{name}-expected.png")), &b, width, height);
        write_png(&out.join(format!("{name}-difference.png")), &difference, width, height);
    }
    case
}

/// Whether each channel of `value` lies between the least and greatest of `expected`'s pixels in
/// the 3 x 3 around `(x, y)` (clipped at the border), widened by [`FAR_STEPS`]: what a sub-pixel
/// shift of the image there could give.
fn between_neighbours(expected: &[u8], width: usize, height: usize, (x, y): (usize, usize), value: &[u8]) -> bool {
    (0..3).all(|c| {
        let around = (y.saturating_sub(1)..(y + 2).min(height))
            .flat_map(|v| (x.saturating_sub(1)..(x + 2).min(width)).map(move |u| (u, v)))
            .map(|(u, v)| expected[3 * (v * width + u) + c]);
        let (lo, hi) = around.fold((u8::MAX, 0), |(lo, hi), e| (lo.min(e), hi.max(e)));
        (lo.saturating_sub(FAR_STEPS)..=hi.saturating_add(FAR_STEPS)).contains(&value[c])
    })
}

/// What is wrong with a comparison drawn `coverage`, if anything (see [`MIN_EXACT_PSNR_DB`] and
/// [`MIN_FORWARD_OFF_RIM_PSNR_DB`]).
fn problem(case: &Case, coverage: &str) -> Option<String> {
    match coverage {
        "exact" if case.psnr_db < MIN_EXACT_PSNR_DB => {
            Some(format!("{:.2} dB, below {MIN_EXACT_PSNR_DB} dB", case.psnr_db))
        }
        "forward" if case.unexplained > 0 => Some(format!(
            "{} of {} pixels beyond {FAR_STEPS} steps lie off the silhouette and outside their neighbours' range",
            case.unexplained, case.far_pixels
        )),
        "forward" if case.psnr_without_far_db < MIN_FORWARD_OFF_RIM_PSNR_DB => {
            Some(format!("{:.2} dB off the rim, below {MIN_FORWARD_OFF_RIM_PSNR_DB} dB", case.psnr_without_far_db))
        }
        _ => None,
    }
}

/// The CI cases: gold-paint under quarry_01 (a sun: the peaks and their sampling tables in use) in
/// both modes drawn exactly, the prefiltered mode at brdf-preview's defaults (8 frames of 16
/// samples), the reference mode at 4 of its 32 frames of 64 samples (the same samples as
/// brdf-preview's first 4 frames, to keep make test short); and the prefiltered mode drawn
/// forward, as a scene draws the material, there and on steel under studio_small_03, a metal's
/// grazing reflection of an indoor map's lamps, where the image changes fastest inside the rim.
#[test]
fn three_js_renders_a_bake_as_brdf_preview_does() {
    let Some(_) = shared_or_skip(&["data/env", NBRDF]) else { return };
    let out = root().join("target/test-tmp/three");
    let cases = [
        ("gold-paint", "quarry_01_1k", "prefiltered", "exact", None),
        ("gold-paint", "quarry_01_1k", "reference", "exact", Some(4)),
        ("gold-paint", "quarry_01_1k", "prefiltered", "forward", None),
        ("steel", "studio_small_03_1k", "prefiltered", "forward", None),
    ];
    let mut bakes = std::collections::HashMap::new();
    for (material, environment, mode, coverage, frames) in cases {
        let dir = bakes.entry((material, environment)).or_insert_with(|| bake(material, environment));
        let name = format!("{material}-{}-{mode}-{coverage}", environment.trim_end_matches("_1k"));
        let case = compare(dir, &out, &name, (mode, coverage), frames, &[]);
        println!(
            "{material} under {environment}, {mode} drawn {coverage}: {:.2} dB, {} pixels beyond {FAR_STEPS} steps \
             ({} unexplained), {:.2} dB without them",
            case.psnr_db, case.far_pixels, case.unexplained, case.psnr_without_far_db
        );
        if let Some(problem) = problem(&case, coverage) {
            panic!("{name}: three.js against brdf-preview: {problem}; pictures in {}", out.display());
        }
    }
}

/// The six cases (white-paint, gold-paint and chrome under quarry_01 and
/// potsdamer_platz, 128 x 128) at brdf-preview's default samples in both modes drawn exactly,
/// each at [`MIN_EXACT_PSNR_DB`] or more, and the prefiltered mode drawn forward, different only
/// on the rim; and against the converged estimate, three.js's exact prefiltered picture within
/// 1 dB of brdf-preview's. Prints the table. `make three-cases`.
#[test]
#[ignore = "about 10 minutes on 2 cores: make three-cases"]
fn three_js_equals_brdf_preview_on_the_six_cases() {
    let Some(_) = shared_or_skip(&["data/env", NBRDF]) else { return };
    let out = root().join("target/three-cases");
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for material in ["white-paint", "gold-paint", "chrome"] {
        for environment in ["quarry_01_1k", "potsdamer_platz_1k"] {
            let dir = bake(material, environment);
            let name = format!("{material}-{}", environment.trim_end_matches("_1k"));
            let reference = compare(&dir, &out, &format!("{name}-reference"), ("reference", "exact"), None, &[]);
            let prefiltered = compare(
                &dir,
                &out,
                &format!("{name}-prefiltered"),
                ("prefiltered", "exact"),
                None,
                &["--converged", "1024"],
            );
            let forward = compare(&dir, &out, &format!("{name}-forward"), ("prefiltered", "forward"), None, &[]);
            // Both pictures against brdf-preview's converged estimate.
            let converged = picture(&out.join(format!("{name}-prefiltered-preview-converged.png")), 128, 128);
            let three = picture(&out.join(format!("{name}-prefiltered-three.png")), 128, 128);
            let three_converged = psnr_db(&three, &converged);
            let preview_converged = prefiltered.preview["converged"]["psnr_db"].as_f64().unwrap();
            rows.push(format!(
                "| {material} | {} | {:.2} | {:.2} | {:.2} ({} px beyond 8 steps; {:.2} without) | {:.2} | {:.2} | {:+.2} | {:.0} \
                 | {:.0} |",
                environment.trim_end_matches("_1k"),
                reference.psnr_db,
                prefiltered.psnr_db,
                forward.psnr_db,
                forward.far_pixels,
                forward.psnr_without_far_db,
                preview_converged,
                three_converged,
                three_converged - preview_converged,
                reference.three_ms,
                prefiltered.three_ms,
            ));
            let cases = [
                ("reference", &reference, "exact"),
                ("prefiltered", &prefiltered, "exact"),
                ("prefiltered", &forward, "forward"),
            ];
            for (mode, case, coverage) in cases {
                if let Some(problem) = problem(case, coverage) {
                    failures.push(format!("{name} {mode} drawn {coverage}: {problem}"));
                }
            }
            if (three_converged - preview_converged).abs() > 1.0 {
                failures.push(format!(
                    "{name}: against the converged estimate three.js {three_converged:.2} dB, brdf-preview \
                     {preview_converged:.2} dB"
                ));
            }
        }
    }
    println!(
        "three.js in Chromium (SwiftShader) against brdf-preview (same bake, mode and samples, 128 x 128; PSNR in \
         dB over all pixels; drawn exactly, and the prefiltered mode drawn forward with its pixels beyond 8 steps), \
         and the exact prefiltered pictures against brdf-preview's converged estimate (1024 samples per strategy); \
         the render's milliseconds in Chromium"
    );
    println!(
        "| material | environment | reference dB | prefiltered dB | prefiltered forward dB | preview vs converged | \
         three.js vs converged | difference | reference ms | prefiltered ms |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for row in &rows {
        println!("{row}");
    }
    assert!(failures.is_empty(), "{failures:?}; pictures in {}", out.display());
}
