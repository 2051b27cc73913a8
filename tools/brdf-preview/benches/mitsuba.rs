//! The outside referee: the CPU renderer (crate `render`) against Mitsuba 3 on the
//! same scene (a benchmark, not a test: it reports figures and asserts nothing).
//!
//! # What is compared
//!
//! Sixteen cases: a Lambertian (`merl-synth lambertian`'s table, albedo 0.5, made under
//! target/bench-mitsuba/), white-paint, gold-paint and chrome (real-derived MERL tables,
//! target/merl/) under quarry_01 (a small, very bright sun) and studio_small_03 (an indoor map of
//! softboxes), each seen by two cameras:
//! `sun`, in the direction of the map's brightest texel (the camera then sees that light's mirror
//! reflection at the sphere's centre), and `away`, at the opposite azimuth and the same elevation
//! (the light behind the sphere). The project's UV sphere of the previewer (`Mesh::sphere(1, 128,
//! 64)`), the previewer's camera (distance 3.2, 45 degrees vertically) and image size (128 x 128 by
//! default), the bake made with default settings (kept under target/bench-mitsuba/).
//!
//! Our images, as `brdf-preview` makes them by default: the converged estimate
//! (`render::converged`, 1024 samples per strategy), then `reference`, `fis` and `prefiltered` at
//! the previewer's defaults (`render::Settings::previewer`), and `adaptive` and
//! `adaptive-prefiltered` at theirs ([`ours`]: `render::adaptive::FRAMES` frames averaged). Mitsuba's: the `path` integrator, `max_depth` 2 (direct light only, which is what our
//! renderer computes; a convex sphere has no interreflection), 4096 spp, two seeds. Per case and
//! mode: the PSNR against Mitsuba's seed 0 on the 8-bit pictures (`render::metrics`, one exposure
//! for all: `metrics::auto_tone_mapping` of the map), over the whole picture (the background included,
//! as `metrics::psnr_db` takes it) and over the sphere alone; the ratio of the sphere's mean
//! luminance to Mitsuba's and the same per channel; and the structure of the difference, with the
//! noise averaged out (`metrics::windowed_bias`: the signed 8-bit difference averaged over the
//! sphere's pixels of a 7 x 7 window, its 99th percentile and maximum magnitude in levels), which
//! shows bands, blocks and shading errors where a PSNR mixes them with noise. Mitsuba's floor: its seed 1 against its seed
//! 0, the same figures. An image without error scores about 3 dB above the floor (it differs from
//! seed 0 by seed 0's noise alone, where two seeds differ by twice its variance); an image exactly
//! as noisy as Mitsuba's scores the floor. The floor's luminance ratio says how far Mitsuba's mean
//! can be trusted: where a light is reflected in chrome, a few pixels hundreds of times brighter
//! than the rest carry the sphere's mean luminance, and their noise moves it.
//!
//! Left out of every figure (and counted in the report): the pixels only one renderer covers, and
//! those seen at grazing angles ([`GRAZING_COS`]), where rounding decides whether a pixel is black.
//!
//! # The conventions matched, and how
//!
//! `mitsuba/render.py` (beside this file) renders a scene this benchmark exports under
//! target/bench-mitsuba/CASE/ (scene.json names the files):
//!
//! - the mesh as OBJ: our vertex positions and normals as `f32` written to round-trip, faces
//!   naming both, so Mitsuba interpolates the same normals;
//! - the camera: our eye (`f32`), target, `+z` up, vertical field of view, near and far planes;
//!   Mitsuba's `perspective` sensor generates the rays, but through the pixel centres ((x + 1/2) /
//!   W, (y + 1/2) / H, row 0 at the top), because our renderer shades one point per pixel and
//!   Mitsuba's film would average over the pixel. The script also writes which pixels the mesh
//!   covers; the report counts those that differ from our rasterizer's;
//! - the map: level 0 of the bake's mip chain, as our renderers read it (the bake's half floats),
//!   written as EXR; Mitsuba's `envmap` emitter with the rotation that turns its lat-long
//!   convention into `envmap`'s (the script's `ENV_TO_WORLD` says how). Checked on the
//!   background: Mitsuba's image of the map alone (no mesh, 1 spp: the background has no noise)
//!   against our renderer's background (level 0, bilinear, through `Camera::rays`), per map and
//!   camera, in the report's first table (the map's orientation, its rows and the camera: a
//!   wrong one shows as an image of another part of the map);
//! - the BRDF: a Python BSDF (`MerlNearest`) with the table's nearest lookup as BRDFRead.cpp and
//!   `merl::Dims::nearest_cell` index it, the same channel scales, 0 where a cell holds no data or
//!   below either horizon; its own sampling (a mixture of the cosine and a half-vector density
//!   made from the table), so nothing sampled is shared with ours. Held to crate merl's lookup on
//!   every run ([`lookup_pairs`], `render.py --check-lookup`), in the report's second table.
//!
//! Mitsuba's renders are kept beside the scene they were made from (a rerun reuses them when
//! the scene file, its inputs' SHA-256 and the script are the same, and the spp and seed; `--fresh`
//! renders them again); our images are made again on every run.
//!
//! # Running it
//!
//! `make setup-mitsuba` once (Mitsuba 3 from PyPI; libLLVM from Debian for its vectorized
//! `llvm_ad_rgb` variant, else the script falls back to `scalar_rgb`, one Python call per sample
//! and far slower), then
//!
//! `cargo bench -p brdf-preview --bench mitsuba [-- --cases SUBSTRINGS] [-- --spp N] [-- --size N]
//! [-- --converged N] [-- --python PYTHON] [-- --fresh]`
//!
//! `--cases` takes substrings separated by commas, matched against the case names
//! (`gold-paint / quarry_01 / sun`): `--cases chrome`, `--cases quarry_01/sun` does not match
//! (`--cases "quarry_01 / sun"` does). The table is printed and written, with the wall times,
//! the commit and the machine, to target/bench-mitsuba/report.md and report.json; each case's
//! pictures and differences (x4) to target/bench-mitsuba/CASE.png, each background check to
//! target/bench-mitsuba/background-MAP-CAMERA.png. Needs `../shared` (the maps, and nbrdf2merl.py
//! with numpy for the materials, made once under target/merl/).

mod common;
use common::{Stamp, material_path, root, shared};

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use envmap::EnvMap;
use picture::Canvas;
use picture::layout::Grid;
use render::{Camera, Estimator, Image, Lighting, Material, Mesh, Scene, Settings, adaptive, metrics};
use serde_json::{Value, json};

const MAPS: [&str; 2] = ["quarry_01", "studio_small_03"];
const MATERIALS: [&str; 4] = ["lambertian", "white-paint", "gold-paint", "chrome"];

/// A case's MERL table: `lambertian` is `merl-synth lambertian`'s (albedo 0.5), written under
/// target/bench-mitsuba/; the others are real-derived ([`material_path`]).
fn table_path(material: &str) -> PathBuf {
    if material != "lambertian" {
        return material_path(material);
    }
    let path = work().join("lambertian.binary");
    let table = merl::analytic::Analytic::Lambertian { albedo: [0.5; 3] }.table(merl::Dims::MERL);
    write(&path, &table.to_bytes());
    path
}
const VIEWS: [&str; 2] = ["sun", "away"];

fn work() -> PathBuf {
    root().join("target/bench-mitsuba")
}

fn script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/mitsuba/render.py")
}

struct Options {
    cases: Vec<String>,
    spp: u32,
    size: usize,
    converged: u32,
    python: String,
    fresh: bool,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut o =
        Options { cases: Vec::new(), spp: 4096, size: 128, converged: 1024, python: "python3".into(), fresh: false };
    let mut i = 0;
    while i < args.len() {
        let value = |i: usize| args.get(i + 1).unwrap_or_else(|| panic!("{} needs a value", args[i])).clone();
        let number = |i: usize| -> u64 {
            let v = value(i);
            v.parse().ok().filter(|&n| n > 0).unwrap_or_else(|| panic!("{} {v}: expected a positive integer", args[i]))
        };
        match args[i].as_str() {
            "--cases" => o.cases = value(i).split(',').map(|s| s.trim().to_string()).collect(),
            "--spp" => o.spp = number(i) as u32,
            "--size" => o.size = number(i) as usize,
            "--converged" => o.converged = number(i) as u32,
            "--python" => o.python = value(i),
            "--fresh" => {
                o.fresh = true;
                i += 1;
                continue;
            }
            // cargo bench passes --bench to every harness-less bench.
            "--bench" => {
                i += 1;
                continue;
            }
            other => panic!(
                "unknown argument {other:?}: --cases SUBSTRINGS, --spp N, --size N, --converged N, --python PYTHON, --fresh"
            ),
        }
        i += 2;
    }
    o
}

/// The bake of a material under a map with the default settings of every stage (a rerun reuses
/// it).
fn bake(material: &str, map: &str) -> bake::Loaded {
    let dir = work().join(format!("{material}-{map}"));
    let environment = shared().join("data/env").join(format!("{map}_1k.hdr"));
    let config = bake::BakeConfig::new(table_path(material), Some(environment), dir.clone());
    let program = bake::Program { name: "mitsuba-bench", version: env!("CARGO_PKG_VERSION") };
    bake::run_bake(&config, &program, &|_| {}).unwrap_or_else(|e| panic!("baking {material} under {map}: {e}"));
    bake::load(&dir, None).unwrap_or_else(|e| panic!("loading the bake {}: {e}", dir.display()))
}

/// The direction of the map's brightest texel (its centre).
fn brightest(map: &EnvMap) -> glam::DVec3 {
    let luminance = map.luminance();
    let i = (0..luminance.len()).max_by(|&a, &b| luminance[a].total_cmp(&luminance[b])).expect("a non-empty map");
    map.texel_direction(i % map.width(), i / map.width())
}

/// The camera's azimuth and elevation (radians) for a view of a map: `sun` in the direction of
/// its brightest texel, `away` at the opposite azimuth and the same elevation.
fn view_angles(map: &EnvMap, view: &str) -> (f32, f32) {
    let d = brightest(map);
    let azimuth = d.y.atan2(d.x) + if view == "away" { std::f64::consts::PI } else { 0.0 };
    (azimuth as f32, d.z.clamp(-1.0, 1.0).asin() as f32)
}

/// The scene as `brdf-preview --camera AZ,EL --size NxN` makes it (its `scene`): the default
/// sphere and the default camera's target, distance and field of view.
fn scene(azimuth: f32, elevation: f32, size: usize) -> Scene {
    let default = Camera::default();
    let camera = Camera::orbit(default.target(), default.distance(), azimuth, elevation, default.fov_y())
        .expect("a valid camera");
    Scene { mesh: preview::mesh("sphere").expect("the sphere"), camera, width: size, height: size }
}

/// Our images of a case, as `brdf-preview` renders them by default (its `run`): the converged
/// estimate, then each mode at its default samples and frames, then adaptive frames of each
/// estimator at `brdf-preview`'s defaults (its `--help`: 8 frames; 8 samples per pixel for `adaptive`, 4
/// for `adaptive-prefiltered`, `--predict-level 2`, the area allocation, no supersampling, the
/// default layer shift). The one place that builds `render`'s settings.
fn ours(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &adaptive::Bandwidths,
    converged: u32,
) -> Vec<(&'static str, Image, f64)> {
    let start = Instant::now();
    let image = render::converged::converged(scene, material, lighting, converged, 0).expect("the converged estimate");
    let mut images = vec![("converged", image, start.elapsed().as_secs_f64())];
    for mode in Estimator::ALL {
        let settings = Settings::previewer(mode, &material.samples, None, None, 0);
        let start = Instant::now();
        let image = render::render(scene, material, lighting, &settings)
            .unwrap_or_else(|e| panic!("rendering {}: {e}", mode.name()));
        images.push((mode.name(), image, start.elapsed().as_secs_f64()));
    }
    for (name, mode) in [("adaptive", Estimator::Reference), ("adaptive-prefiltered", Estimator::Prefiltered)] {
        let settings = adaptive::Settings {
            predict_level: 2,
            allocation: adaptive::Allocation::Area,
            frames: adaptive::FRAMES,
            ..adaptive::Settings::new(mode, adaptive::SPP)
        };
        let start = Instant::now();
        let image = adaptive::render_frames(scene, material, lighting, bandwidths, &settings)
            .unwrap_or_else(|e| panic!("rendering {name}: {e}"));
        images.push((name, image, start.elapsed().as_secs_f64()));
    }
    images
}

/// Our renderer's background: level 0, bilinear, along the ray through each pixel centre (crate
/// `render`'s documentation, the last paragraph of "The estimators").
fn background(scene: &Scene, level0: &EnvMap) -> Vec<f32> {
    let rays = scene.camera.rays(scene.width, scene.height);
    (0..scene.width * scene.height).flat_map(|i| level0.lookup(rays.ray(i % scene.width, i / scene.width))).collect()
}

/// Pixels whose shaded point is seen this close to edge-on (`cos theta_o` below it) are left out
/// of the figures on the sphere. There the view's cosine changes by more than this within a
/// thousandth of a pixel, so the two renderers' roundings (ours snaps the projected vertices to
/// 1/256 pixel and interpolates at the pixel centre; Mitsuba intersects the ray in `f32`) decide
/// how a pixel is shaded (ours bends a normal turned from the eye to `cos theta_o` = 1e-4, crate
/// `render`, "The shading frame"; Mitsuba's shading normal there is its own): one such pixel of
/// gold-paint (then ours black, Mitsuba's at `cos theta_o` = 7e-4 lit) took the whole picture's
/// PSNR of our converged estimate from 57 to 44 dB. At 128 x 128 about one pixel in a
/// thousand of the sphere's is left out; the report gives the count.
const GRAZING_COS: f64 = 0.02;

/// The pixels our rasterizer covers, and those of them seen at grazing angles ([`GRAZING_COS`]).
fn coverage(scene: &Scene) -> (Vec<bool>, Vec<bool>) {
    let aspect = scene.width as f32 / scene.height as f32;
    let gbuffer = render::raster::rasterize(&scene.mesh, scene.camera.view_proj(aspect), scene.width, scene.height)
        .expect("rasterizing");
    let eye = scene.camera.eye().as_dvec3();
    let covered = gbuffer.hits.iter().map(Option::is_some).collect();
    let grazing = (gbuffer.hits.iter())
        .map(|hit| hit.as_ref().is_some_and(|h| h.normal.dot((eye - h.position).normalize()) < GRAZING_COS))
        .collect();
    (covered, grazing)
}

/// A mesh as OBJ: positions and normals as `f32` (Rust prints the shortest text that reads back
/// to the same `f32`), faces naming both.
fn obj(mesh: &Mesh) -> String {
    let mut text = String::from("# the previewer's mesh, written by benches/mitsuba.rs\n");
    for p in &mesh.positions {
        writeln!(text, "v {} {} {}", p[0], p[1], p[2]).unwrap();
    }
    for n in &mesh.normals {
        writeln!(text, "vn {} {} {}", n[0], n[1], n[2]).unwrap();
    }
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
        writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}").unwrap();
    }
    text
}

fn sha256(path: &Path) -> String {
    asset::hex(&asset::sha256_file(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display())))
}

fn write(path: &Path, bytes: &[u8]) {
    asset::write_atomic(path, bytes).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
}

/// Writes a case's scene for `render.py` into `dir` (the mesh, the map and scene.json, whose
/// `inputs` hold the SHA-256 of every file it names and of the script) and returns scene.json's
/// path.
fn export(dir: &Path, scene: &Scene, level0: &EnvMap, material: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("creating {}: {e}", dir.display()));
    let (mesh, environment) = (dir.join("mesh.obj"), dir.join("environment.exr"));
    write(&mesh, obj(&scene.mesh).as_bytes());
    let exr = level0.encode_exr(envmap::SampleType::F32).expect("encoding the map");
    write(&environment, &exr);
    let material = std::fs::canonicalize(material).unwrap_or_else(|e| panic!("{}: {e}", material.display()));
    let camera = &scene.camera;
    let value = json!({
        "mesh": "mesh.obj",
        "environment": "environment.exr",
        "material": material,
        "camera": {
            "eye": camera.eye().to_array(),
            "target": camera.target().to_array(),
            "up": [0.0, 0.0, 1.0],
            "fov_y_deg": f64::from(camera.fov_y()).to_degrees(),
            "near": camera.near(),
            "far": camera.far(),
        },
        "width": scene.width,
        "height": scene.height,
        "inputs": {
            "mesh": sha256(&mesh),
            "environment": sha256(&environment),
            "material": sha256(&material),
            "script": sha256(&script()),
        },
    });
    let path = dir.join("scene.json");
    write(&path, serde_json::to_string_pretty(&value).expect("json").as_bytes());
    path
}

/// A Mitsuba render: linear RGB, which pixels the mesh covers, and what the script said (the
/// variant, the wall time).
struct Mitsuba {
    rgb: Vec<f32>,
    covered: Vec<bool>,
    info: Value,
    cached: bool,
}

/// `render.py SCENE` run by the chosen Python.
fn script_command(scene: &Path, options: &Options) -> Command {
    let mut command = Command::new(&options.python);
    command.arg(script()).arg(scene);
    command
}

/// Runs `render.py` and returns the JSON line it prints last; a failure prints the command, its
/// stdout and its stderr.
fn run_script(mut command: Command) -> Value {
    let output = command.output().unwrap_or_else(|e| panic!("running {command:?}: {e}"));
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        panic!(
            "{command:?} failed ({}; make setup-mitsuba installs Mitsuba)\nstdout:\n{stdout}\nstderr:\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        );
    }
    stdout
        .lines()
        .last()
        .and_then(|l| serde_json::from_str(l).ok())
        .unwrap_or_else(|| panic!("{command:?}: expected a JSON line on stdout, got {stdout:?}"))
}

/// Pairs of directions where the Python BSDF is held to crate merl's nearest lookup
/// (`render.py --check-lookup`): nine little-endian `f64` per pair, `wi`, `wo` and
/// `merl::MerlTable::lookup` (0 where the table holds no data). `wo` uniform over the upper
/// hemisphere; `wi` uniform too for half of the pairs, within about a degree of `wo`'s mirror
/// direction for the other half (where MERL's finest `theta_h` cells are). The directions are
/// rounded to `f32` before the lookup, as Mitsuba's llvm variant reads them, so that only the
/// arithmetic inside the two lookups differs. The numbers are `render::pcg_hash`'s.
fn lookup_pairs(table: &merl::MerlTable, n: usize) -> Vec<u8> {
    let mut counter = 0u32;
    let mut next = || {
        counter += 1;
        f64::from(render::pcg_hash(counter)) / 4_294_967_296.0
    };
    let mut bytes = Vec::with_capacity(72 * n);
    let mut pairs = 0;
    while pairs < n {
        let mut upper = || merl::spherical_dir(next().acos(), 2.0 * std::f64::consts::PI * next());
        let wo = upper();
        let wi = if pairs % 2 == 0 {
            upper()
        } else {
            let spread = 0.02 * next() * next();
            let jitter = glam::DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            (glam::DVec3::new(-wo.x, -wo.y, wo.z) + spread * jitter).normalize()
        };
        let (wi, wo) = (wi.as_vec3().as_dvec3(), wo.as_vec3().as_dvec3());
        if wi.z <= 0.0 || wo.z <= 0.0 {
            continue;
        }
        let f = table.lookup(wi, wo, merl::Interp::Nearest).unwrap_or([0.0; 3]);
        for v in [wi.x, wi.y, wi.z, wo.x, wo.y, wo.z, f[0], f[1], f[2]] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        pairs += 1;
    }
    bytes
}

/// The Python BSDF against crate merl's lookup on [`lookup_pairs`]: `(pairs, how many differ)`.
fn check_lookup(scene: &Path, table: &merl::MerlTable, options: &Options) -> (u64, u64) {
    let pairs = scene.with_file_name("lookup-pairs.bin");
    write(&pairs, &lookup_pairs(table, 100_000));
    let mut command = script_command(scene, options);
    command.arg("--check-lookup").arg(&pairs);
    let info = run_script(command);
    let count =
        |key: &str| info[key].as_u64().unwrap_or_else(|| panic!("render.py --check-lookup: no {key} in {info}"));
    (count("pairs"), count("differ"))
}

/// Mitsuba's image of `scene` (a scene.json) at `spp` and `seed` (`no_mesh`: the map alone), made
/// by `render.py` or reused when the same scene, inputs and script made it before.
fn mitsuba(scene: &Path, size: usize, spp: u32, seed: u32, no_mesh: bool, options: &Options) -> Mitsuba {
    let dir = scene.parent().expect("a folder");
    let stem = if no_mesh { format!("mitsuba-background-{spp}-{seed}") } else { format!("mitsuba-{spp}-{seed}") };
    let (out, coverage, sidecar) =
        (dir.join(format!("{stem}.exr")), dir.join(format!("{stem}-coverage.exr")), dir.join(format!("{stem}.json")));
    let scene_text = std::fs::read_to_string(scene).unwrap_or_else(|e| panic!("reading {}: {e}", scene.display()));
    let previous: Option<Value> = std::fs::read_to_string(&sidecar).ok().and_then(|t| serde_json::from_str(&t).ok());
    let reusable =
        !options.fresh && previous.as_ref().is_some_and(|p| p["scene"].as_str() == Some(scene_text.as_str()));
    let (info, cached) = if reusable {
        (previous.expect("checked")["info"].clone(), true)
    } else {
        let mut command = script_command(scene, options);
        command.arg("--out").arg(&out).arg("--coverage").arg(&coverage);
        command.args(["--spp", &spp.to_string(), "--seed", &seed.to_string()]);
        if no_mesh {
            command.arg("--no-mesh");
        }
        let info = run_script(command);
        let record = json!({ "scene": scene_text, "info": info });
        write(&sidecar, serde_json::to_string_pretty(&record).expect("json").as_bytes());
        (info, false)
    };
    let read = |path: &Path| {
        let image = envmap::read_image(path, &envmap::Limits::default())
            .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        assert!(
            image.width == size && image.height == size,
            "{}: {} x {}, expected {size} x {size}",
            path.display(),
            image.width,
            image.height
        );
        image.rgb
    };
    let rgb = read(&out);
    let covered = read(&coverage).chunks_exact(3).map(|y| y[0] > 0.5).collect();
    Mitsuba { rgb, covered, info, cached }
}

/// The pixels the figures take.
struct Compared {
    /// The whole picture but the pixels left out: those seen at grazing angles
    /// ([`GRAZING_COS`]) and those only one renderer covers.
    picture: Vec<bool>,
    /// The sphere's pixels among them (both renderers cover them).
    sphere: Vec<bool>,
    /// The pixels our rasterizer covers.
    covered: Vec<bool>,
    /// How many pixels only one renderer covers.
    coverage_differs: usize,
    /// How many of our pixels are seen at grazing angles.
    grazing: usize,
}

impl Compared {
    /// The pixels of `scene` the figures take, given those Mitsuba's render covers (`theirs`).
    fn new(scene: &Scene, theirs: &[bool]) -> Compared {
        let n = scene.width * scene.height;
        let (covered, grazing) = coverage(scene);
        Compared {
            picture: (0..n).map(|i| covered[i] == theirs[i] && !grazing[i]).collect(),
            sphere: (0..n).map(|i| covered[i] && theirs[i] && !grazing[i]).collect(),
            coverage_differs: covered.iter().zip(theirs).filter(|(a, b)| a != b).count(),
            grazing: grazing.iter().filter(|g| **g).count(),
            covered,
        }
    }
}

/// How an image compares with Mitsuba's.
#[derive(Clone, Copy, Debug)]
struct Figures {
    /// Over the compared pixels of the picture, the background included (`metrics::psnr_db`).
    psnr_db: f64,
    /// Over the compared pixels of the sphere.
    psnr_sphere_db: f64,
    /// Mean luminance over the compared pixels of the sphere, ours over Mitsuba's.
    luminance_ratio: f64,
    /// The same per channel.
    channel_ratio: [f64; 3],
    /// The 7 x 7 windowed bias over the compared pixels of the sphere, in 8-bit levels.
    bias: metrics::Bias,
}

impl Figures {
    fn json(&self) -> Value {
        json!({
            "psnr_db": db_json(self.psnr_db),
            "psnr_sphere_db": db_json(self.psnr_sphere_db),
            "luminance_ratio": self.luminance_ratio,
            "channel_ratio": self.channel_ratio,
            "bias_p99_levels": self.bias.p99,
            "bias_max_levels": self.bias.max,
            "bias_mean_levels": self.bias.mean,
        })
    }
}

/// PSNR as JSON: infinity (identical pictures) has no JSON number.
fn db_json(db: f64) -> Value {
    if db.is_finite() { json!(db) } else { json!("inf") }
}

/// `image` against `against` over the `compared` pixels: PSNR of the 8-bit pictures
/// (`render::metrics`, one exposure for both), and the ratios of the mean luminance and of each
/// channel's mean.
fn compare(image: &Image, against: &Image, compared: &Compared, preview: &envmap::ToneMapping) -> Figures {
    let (a, b) = (metrics::tonemap(image, preview), metrics::tonemap(against, preview));
    let only = |picture: &[u8], mask: &[bool]| -> Vec<u8> {
        picture.chunks_exact(3).zip(mask).filter(|(_, m)| **m).flat_map(|(p, _)| p.to_vec()).collect()
    };
    let psnr = |mask: &[bool]| metrics::psnr_db(&only(&a, mask), &only(&b, mask));
    let sphere = |img: &Image| Image { covered: compared.sphere.clone(), ..img.clone() };
    let channel_mean = |img: &Image, c: usize| {
        let values: Vec<f64> = (img.rgb.chunks_exact(3).zip(&compared.sphere))
            .filter(|(_, m)| **m)
            .map(|(p, _)| f64::from(p[c]))
            .collect();
        values.iter().sum::<f64>() / values.len().max(1) as f64
    };
    Figures {
        psnr_db: psnr(&compared.picture),
        psnr_sphere_db: psnr(&compared.sphere),
        luminance_ratio: metrics::mean_luminance(&sphere(image)) / metrics::mean_luminance(&sphere(against)),
        channel_ratio: std::array::from_fn(|c| channel_mean(image, c) / channel_mean(against, c)),
        bias: metrics::windowed_bias(&a, &b, image.width, image.height, &compared.sphere),
    }
}

/// A picture as a panel, doubled so that a person sees the pixels.
fn panel(picture: &[u8], size: usize) -> Canvas {
    let mut canvas = Canvas::new(2 * size, 2 * size, [0, 0, 0]);
    canvas.blit_rgb8(size, size, picture, 0, 0, 2);
    canvas
}

fn save_png(path: &Path, canvas: &Canvas) {
    let png = envmap::encode_png_rgb8(canvas.width, canvas.height, &canvas.rgb).expect("encoding a png");
    write(path, &png);
}

impl Options {
    fn wanted(&self, case: &str) -> bool {
        self.cases.is_empty() || self.cases.iter().any(|c| case.contains(c.as_str()))
    }
}

/// A material's bake under a map, and what its cases share.
struct Baked {
    material: &'static str,
    map: &'static str,
    loaded: bake::Loaded,
    /// The bake's wall time, seconds.
    seconds: f64,
    /// The one exposure of every picture of the map (`metrics::auto_tone_mapping`).
    preview: envmap::ToneMapping,
}

impl Baked {
    fn new(material: &'static str, map: &'static str) -> Baked {
        let start = Instant::now();
        let loaded = bake(material, map);
        let seconds = start.elapsed().as_secs_f64();
        let lighting = loaded.lighting.as_ref().expect("the bake has an environment");
        let preview = metrics::auto_tone_mapping(lighting.mips.level(0));
        Baked { material, map, loaded, seconds, preview }
    }

    fn lighting(&self) -> &Lighting {
        self.loaded.lighting.as_ref().expect("the bake has an environment")
    }

    fn level0(&self) -> &EnvMap {
        self.lighting().mips.level(0)
    }
}

/// The Python BSDF's check against crate merl's lookup of a material ([`check_lookup`]).
struct Lookup {
    material: &'static str,
    pairs: u64,
    /// The pairs whose values differ.
    differ: u64,
}

/// What a case measured: its rows of the report and its entries of report.json.
struct Measured {
    name: String,
    /// The camera's azimuth and elevation, radians.
    azimuth: f32,
    elevation: f32,
    /// Pixels only one renderer covers, and pixels left out as grazing ([`Compared`]).
    coverage_differs: usize,
    grazing: usize,
    /// Our background against Mitsuba's image of the map alone.
    background_psnr_db: f64,
    background_relative_error: f64,
    /// Mitsuba's renders at seeds 0 and 1, and their wall time, seconds (this process's).
    mitsuba: [Mitsuba; 2],
    mitsuba_s: f64,
    /// The wall time of our images, seconds.
    ours_s: f64,
    /// Mitsuba's seed 1 against its seed 0.
    floor: Figures,
    /// Each of our images against Mitsuba's seed 0: its mode, the figures, its seconds.
    ours: Vec<(&'static str, Figures, f64)>,
}

/// Everything the cases measured.
struct Measurements {
    cases: Vec<Measured>,
    /// The BSDF's check against crate merl, once per material.
    lookups: Vec<Lookup>,
    /// What our modes' settings were, for the report's header (the same for every case's bake).
    defaults: String,
}

fn main() {
    let options = options();
    let started = Instant::now();
    std::fs::create_dir_all(work()).expect("creating target/bench-mitsuba");
    let names: Vec<String> = MATERIALS
        .iter()
        .flat_map(|m| MAPS.iter().flat_map(move |e| VIEWS.iter().map(move |v| format!("{m} / {e} / {v}"))))
        .collect();
    if !names.iter().any(|n| options.wanted(n)) {
        panic!("--cases {:?} matches none of: {}", options.cases.join(","), names.join(", "));
    }
    let stamp = Stamp::now();
    let measurements = measure(&options);
    let wall_s = started.elapsed().as_secs_f64();
    let report = report(&options, &stamp, &measurements, wall_s);
    print!("{report}");
    std::fs::write(work().join("report.md"), &report).expect("writing report.md");
    let value = report_json(&options, &stamp, &measurements, wall_s);
    std::fs::write(work().join("report.json"), serde_json::to_string_pretty(&value).expect("json"))
        .expect("writing report.json");
    eprintln!("report written to {}", work().join("report.md").display());
}

/// Every wanted case, bake by bake.
fn measure(options: &Options) -> Measurements {
    let mut measurements = Measurements { cases: Vec::new(), lookups: Vec::new(), defaults: String::new() };
    for map in MAPS {
        for material in MATERIALS {
            if !VIEWS.iter().any(|v| options.wanted(&format!("{material} / {map} / {v}"))) {
                continue;
            }
            let baked = Baked::new(material, map);
            measurements.defaults = defaults(&baked.loaded.material);
            for view in VIEWS {
                if options.wanted(&format!("{material} / {map} / {view}")) {
                    let measured = measure_case(options, &baked, view, &mut measurements.lookups);
                    measurements.cases.push(measured);
                }
            }
        }
    }
    measurements
}

/// Our modes' settings as [`ours`] renders them, in words.
fn defaults(material: &Material) -> String {
    Estimator::ALL
        .iter()
        .map(|&mode| {
            let settings = Settings::previewer(mode, &material.samples, None, None, 0);
            format!("{} {} spp x {} frames", mode.name(), settings.spp, settings.frames)
        })
        .collect::<Vec<_>>()
        .join(", ")
        + &format!(
            ", adaptive and adaptive-prefiltered {} spp x {} frames (predict level 2, area allocation)",
            adaptive::SPP,
            adaptive::FRAMES
        )
}

/// One case: its scene exported, the BSDF's check (once per material), the background's check,
/// Mitsuba's two seeds and our images, compared; our images to CASE/ours-MODE.exr, the pictures
/// to CASE.png.
fn measure_case(options: &Options, baked: &Baked, view: &'static str, lookups: &mut Vec<Lookup>) -> Measured {
    let (material, map, size) = (baked.material, baked.map, options.size);
    let name = format!("{material} / {map} / {view}");
    let (azimuth, elevation) = view_angles(baked.level0(), view);
    let scene = scene(azimuth, elevation, size);
    let dir = work().join(format!("{material}-{map}-{view}-{size}"));
    let scene_file = export(&dir, &scene, baked.level0(), &table_path(material));
    if !lookups.iter().any(|l| l.material == material) {
        let (pairs, differ) = check_lookup(&scene_file, &baked.loaded.material.table, options);
        lookups.push(Lookup { material, pairs, differ });
    }
    let (background_psnr_db, background_relative_error) = background_check(options, baked, view, &scene, &scene_file);

    let start = Instant::now();
    let seeds = [0, 1].map(|seed| mitsuba(&scene_file, size, options.spp, seed, false, options));
    let mitsuba_s = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let bandwidths = baked.loaded.bandwidths.as_ref().expect("the bake has an environment");
    let images = ours(&scene, &baked.loaded.material, baked.lighting(), bandwidths, options.converged);
    let ours_s = start.elapsed().as_secs_f64();
    write_exrs(&dir, &images, size);

    let compared = Compared::new(&scene, &seeds[0].covered);
    let [m0, m1] = [0, 1].map(|i| Image {
        width: size,
        height: size,
        rgb: seeds[i].rgb.clone(),
        covered: compared.covered.clone(),
    });
    let floor = compare(&m1, &m0, &compared, &baked.preview);
    let ours: Vec<(&'static str, Figures, f64)> = (images.iter())
        .map(|(mode, image, seconds)| (*mode, compare(image, &m0, &compared, &baked.preview), *seconds))
        .collect();
    let grid = case_grid(&name, options.spp, [&m0, &m1], &images, floor, &ours, &baked.preview);
    save_png(&work().join(format!("{material}-{map}-{view}-{size}.png")), &grid.render());
    eprintln!(
        "{name}: bake {:.1} s, Mitsuba {mitsuba_s:.1} s{}, ours {ours_s:.1} s",
        baked.seconds,
        if seeds.iter().all(|s| s.cached) { " (reused)" } else { "" }
    );
    Measured {
        name,
        azimuth,
        elevation,
        coverage_differs: compared.coverage_differs,
        grazing: compared.grazing,
        background_psnr_db,
        background_relative_error,
        mitsuba: seeds,
        mitsuba_s,
        ours_s,
        floor,
        ours,
    }
}

/// The map's orientation and the camera: Mitsuba's image of the map alone against our renderer's
/// background, as PSNR and relative error; the pictures to background-MAP-VIEW-SIZE.png.
fn background_check(options: &Options, baked: &Baked, view: &str, scene: &Scene, scene_file: &Path) -> (f64, f64) {
    let size = options.size;
    let back = mitsuba(scene_file, size, 1, 0, true, options);
    let ours_back = background(scene, baked.level0());
    let full = |rgb: Vec<f32>| Image { width: size, height: size, rgb, covered: vec![true; size * size] };
    let (ours_back, their_back) = (full(ours_back), full(back.rgb));
    let (a, b) = (metrics::tonemap(&ours_back, &baked.preview), metrics::tonemap(&their_back, &baked.preview));
    let psnr = metrics::psnr_db(&a, &b);
    let relative = metrics::relative_error(&ours_back.rgb, &their_back.rgb);
    let mut grid = Grid::new(3);
    grid.title(format!("background, {} / {view}: our renderer against Mitsuba's envmap", baked.map));
    grid.add(panel(&a, size), "ours").add(panel(&b, size), "mitsuba");
    grid.add(panel(&metrics::difference_rgb8(&a, &b), size), format!("|diff| x4, {psnr:.1} dB"));
    save_png(&work().join(format!("background-{}-{view}-{size}.png", baked.map)), &grid.render());
    (psnr, relative)
}

/// Our images as EXR beside the case's scene: DIR/ours-MODE.exr.
fn write_exrs(dir: &Path, images: &[(&str, Image, f64)], size: usize) {
    for (mode, image, _) in images {
        let planes: [Vec<f32>; 3] = std::array::from_fn(|c| image.rgb.iter().skip(c).step_by(3).copied().collect());
        let channels = [("R", &planes[0][..]), ("G", &planes[1][..]), ("B", &planes[2][..])];
        let exr = envmap::encode_exr(size, size, &channels, envmap::SampleType::F32).expect("encoding an exr");
        write(&dir.join(format!("ours-{mode}.exr")), &exr);
    }
}

/// A case's pictures: Mitsuba's seed 0 and ours; below, each one's difference (x4) from seed 0,
/// seed 1's first, captioned with its PSNR (`floor`, `ours`).
fn case_grid(
    name: &str,
    spp: u32,
    [m0, m1]: [&Image; 2],
    images: &[(&str, Image, f64)],
    floor: Figures,
    ours: &[(&str, Figures, f64)],
    preview: &envmap::ToneMapping,
) -> Grid {
    let size = m0.width;
    let picture_m0 = metrics::tonemap(m0, preview);
    let mut grid = Grid::new(1 + images.len());
    grid.title(format!("{name}: Mitsuba ({spp} spp) and ours; below, |difference| x4 against Mitsuba's seed 0"));
    grid.add(panel(&picture_m0, size), "mitsuba seed 0");
    for (mode, image, _) in images {
        grid.add(panel(&metrics::tonemap(image, preview), size), *mode);
    }
    let picture_m1 = metrics::tonemap(m1, preview);
    grid.add(
        panel(&metrics::difference_rgb8(&picture_m1, &picture_m0), size),
        format!("seed 1: {:.1} dB", floor.psnr_db),
    );
    for ((_, image, _), (_, f, _)) in images.iter().zip(ours) {
        let picture = metrics::tonemap(image, preview);
        grid.add(panel(&metrics::difference_rgb8(&picture, &picture_m0), size), format!("{:.1} dB", f.psnr_db));
    }
    grid
}

/// The report (markdown): the header and the three tables.
fn report(options: &Options, stamp: &Stamp, measurements: &Measurements, wall_s: f64) -> String {
    let Stamp { commit, host, cores } = stamp;
    let size = options.size;
    let variant = (measurements.cases.last()).map_or("", |c| c.mitsuba[0].info["variant"].as_str().unwrap_or("?"));
    let mut lines = vec![
        "# Mitsuba 3 against the CPU renderer".to_string(),
        String::new(),
        format!(
            "Commit {commit}, {host} ({cores} cores); Mitsuba {variant}, path integrator (max_depth 2), {} spp; ours: converged {} per \
             strategy, each mode at brdf-preview's defaults (render::Settings::previewer: {}); {size} x {size}. Wall time {wall_s:.0} s.",
            options.spp, options.converged, measurements.defaults
        ),
        String::new(),
    ];
    lines.extend(background_table(&measurements.cases));
    lines.push(String::new());
    lines.extend(lookup_table(&measurements.lookups));
    lines.push(String::new());
    lines.extend(mitsuba_table(&measurements.cases));
    lines.iter().map(|l| format!("{l}\n")).collect()
}

/// Per case, the background's check and the pixels left out.
fn background_table(cases: &[Measured]) -> Vec<String> {
    let mut lines = vec![
        "## The map's orientation and the camera".to_string(),
        String::new(),
        format!(
            "Mitsuba's image of the map alone (1 spp through the pixel centres) against our renderer's background; pixels whose \
             coverage differs between our rasterizer and Mitsuba's ray casts; pixels of the sphere seen at grazing angles (cos \
             theta_o < {GRAZING_COS}). Both kinds are left out of the figures. The wall times of Mitsuba's two renders (as \
             its script measured them) and of our six images."
        ),
        String::new(),
        "| case | camera az, el (deg) | coverage differs | grazing pixels left out | background PSNR dB | background rel. error \
         | Mitsuba s (2 seeds) | ours s (6 images) |"
            .to_string(),
        "|---|---|---:|---:|---:|---:|---:|---:|".to_string(),
    ];
    for c in cases {
        let psnr = c.background_psnr_db;
        // The script's own time (the renders, not the start-up), or where they were reused.
        let mitsuba_s = match c.mitsuba.iter().map(|s| s.info["seconds"].as_f64()).sum::<Option<f64>>() {
            Some(t) if !c.mitsuba.iter().any(|s| s.cached) => format!("{t:.0}"),
            Some(t) => format!("{t:.0} (reused)"),
            None => "?".into(),
        };
        lines.push(format!(
            "| {} | {:.1}, {:.1} | {} | {} | {} | {:.2e} | {mitsuba_s} | {:.0} |",
            c.name,
            c.azimuth.to_degrees(),
            c.elevation.to_degrees(),
            c.coverage_differs,
            c.grazing,
            if psnr.is_finite() { format!("{psnr:.2}") } else { "identical".into() },
            c.background_relative_error,
            c.ours_s,
        ));
    }
    lines
}

/// Per material, the Python BSDF against crate merl's lookup.
fn lookup_table(lookups: &[Lookup]) -> Vec<String> {
    let mut lines = vec![
        "## The Python BSDF against crate merl's nearest lookup".to_string(),
        String::new(),
        "Direction pairs (half of them within a degree of the mirror configuration, all rounded to f32) where the BSDF's \
         value differs from crate merl's by more than 1e-3 in a channel: a different cell, which only rounding at a cell's edge \
         should cause."
            .to_string(),
        String::new(),
        "| material | pairs | differing |".to_string(),
        "|---|---:|---:|".to_string(),
    ];
    lines.extend(lookups.iter().map(|l| format!("| {} | {} | {} |", l.material, l.pairs, l.differ)));
    lines
}

/// Per case and mode, our image against Mitsuba's seed 0, beside the floor.
fn mitsuba_table(cases: &[Measured]) -> Vec<String> {
    let mut lines = vec![
        "## Against Mitsuba's seed 0".to_string(),
        String::new(),
        "PSNR on the 8-bit pictures (the whole picture, and the sphere alone, less the pixels left out); mean luminance and \
         per-channel means of the sphere's, ours over Mitsuba's; the floor is Mitsuba's seed 1 against its seed 0, the same \
         figures (an image without error scores about 3 dB above its PSNR; its luminance ratio is how far Mitsuba's own mean \
         can be trusted: a light reflected in chrome is a few pixels hundreds of times brighter than the rest, and carries the \
         mean). The 7x7 bias: the signed difference of the 8-bit pictures averaged over each sphere pixel's 7 x 7 window \
         (the sphere's pixels only), its 99th percentile and largest magnitude, in levels: structure, with the noise \
         averaged out."
            .to_string(),
        String::new(),
        "| case | mode | PSNR dB | sphere dB | luminance ratio | R G B ratio | 7x7 bias p99 / max | floor dB | floor sphere dB \
         | floor luminance | floor 7x7 bias p99 / max | ours s |"
            .to_string(),
        "|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|".to_string(),
    ];
    for c in cases {
        let floor = &c.floor;
        for (mode, f, seconds) in &c.ours {
            lines.push(format!(
                "| {} | {mode} | {:.2} | {:.2} | {:.4} | {:.3} {:.3} {:.3} | {:.2} / {:.2} | {:.2} | {:.2} | {:.4} | {:.2} / {:.2} | {seconds:.1} |",
                c.name,
                f.psnr_db,
                f.psnr_sphere_db,
                f.luminance_ratio,
                f.channel_ratio[0],
                f.channel_ratio[1],
                f.channel_ratio[2],
                f.bias.p99,
                f.bias.max,
                floor.psnr_db,
                floor.psnr_sphere_db,
                floor.luminance_ratio,
                floor.bias.p99,
                floor.bias.max,
            ));
        }
    }
    lines
}

/// report.json: what the report shows, with the figures at full precision and what Mitsuba's
/// script said.
fn report_json(options: &Options, stamp: &Stamp, measurements: &Measurements, wall_s: f64) -> Value {
    let camera_deg = |c: &Measured| [c.azimuth.to_degrees(), c.elevation.to_degrees()];
    let checks: Vec<Value> = (measurements.cases.iter())
        .map(|c| {
            json!({
                "case": c.name,
                "camera_deg": camera_deg(c),
                "coverage_differs": c.coverage_differs,
                "grazing_pixels_left_out": c.grazing,
                "background_psnr_db": db_json(c.background_psnr_db),
                "background_relative_error": c.background_relative_error,
            })
        })
        .collect();
    let cases: Vec<Value> = (measurements.cases.iter())
        .map(|c| {
            let ours: Vec<Value> = (c.ours.iter())
                .map(|(mode, f, seconds)| json!({ "mode": mode, "seconds": seconds, "against_mitsuba": f.json() }))
                .collect();
            json!({
                "case": c.name,
                "camera_deg": camera_deg(c),
                "mitsuba": c.mitsuba.iter().map(|s| json!({ "info": s.info, "reused": s.cached })).collect::<Vec<_>>(),
                "floor": c.floor.json(),
                "ours": ours,
                "seconds": { "mitsuba": c.mitsuba_s, "ours": c.ours_s },
            })
        })
        .collect();
    let lookup: Vec<Value> = (measurements.lookups.iter())
        .map(|l| json!({ "material": l.material, "pairs": l.pairs, "differ": l.differ }))
        .collect();
    json!({
        "commit": stamp.commit,
        "machine": { "host": stamp.host, "cores": stamp.cores },
        "size": options.size,
        "mitsuba_spp": options.spp,
        "converged_samples_per_strategy": options.converged,
        "wall_seconds": wall_s,
        "checks": checks,
        "lookup": lookup,
        "cases": cases,
    })
}
