//! The equal-quality benchmark of adaptive multi-resolution shading (a benchmark, not a
//! test): 3 real-derived materials x 2 real maps x 2 meshes (a sphere, and a torus, whose
//! curvature varies and changes sign), 512 x 512, the resolution of the paper's timings (`001`
//! Fig. 11; `--size N` for another), on the CPU renderer (crate `render`; the GPU renderer
//! equals it to rounding for the full-resolution modes) or with `--gpu` on the GPU (lavapipe on a
//! machine without one), as `make bench` runs it.
//!
//! For each case:
//!
//! 1. the brute-force reference mode at 1 to 256 samples per pixel: PSNR against the converged
//!    estimate (1024 samples per strategy; `--quick`: 256) and milliseconds;
//! 2. `adaptive` and `adaptive-prefiltered` at two budgets each, with the environment bandwidth
//!    read (a) as the paper does (`bandwidth::Reading::Paper`), (b) level-normalized, and (c)
//!    replaced by an oracle: the image bandwidth of a windowed FFT of the converged picture (32 x
//!    32 windows, as `001` Fig. 12), and (d) the paper's with `003`'s lobe weight in the
//!    up-sampling. For each: PSNR, the *ceiling* (the PSNR of the same plan with every shaded
//!    block given its converged value: the up-sampling's error alone, which no budget passes),
//!    milliseconds, shaded fraction, samples, and
//!    the time the brute force needs for the same PSNR (interpolated between its budgets, in
//!    log time) over the adaptive time: the speed-up at equal quality (`>` when the brute force
//!    never reaches the PSNR: a lower bound from its 256 spp; `~` when the PSNR is on the brute
//!    force's plateau, where the speed-up is the samples' luck: "The sun's plateau" below),
//!    summarized over all rows and over the rows off the plateau, per reading and for the rows of
//!    the reading each bake chose (`brdf-bake --env-reading auto`: level-normalized for chrome);
//! 3. Spearman's rank correlation of the predicted image bandwidth with the windowed FFT of the
//!    converged picture (windows wholly on the mesh), and of the predicted variance with the
//!    measured variance of the one-sample estimator (16 independent renders), per reading;
//! 4. 16x anti-aliasing against none: milliseconds and shaded blocks;
//! 5. where the adaptive frames' time goes (paper reading): G-buffer, prediction, pyramid and
//!    plan, shading and up-sampling, against the brute force's whole frame.
//!
//! # The brute force's plateau
//!
//! Where the brute force's curve flattens (its PSNR gains less than [`FLAT_DB_PER_DOUBLING`] per
//! doubling of its samples around an adaptive frame's PSNR, or it never reaches it but by less
//! than [`PLATEAU_DB`]), an equal-quality speed-up is the luck of the samples, and the report
//! marks the row `~` and summarizes the rows off the plateau apart. A brute force that finds a
//! small bright source only by chance flattens so (one that sampled the material alone would,
//! under quarry's sun); the reference mode samples the environment too (multiple importance
//! sampling) and converges there like anywhere.
//!
//! # On the GPU
//!
//! With `--gpu`, the brute force renders on the GPU (`gpu::preview`) and so do the adaptive
//! frames, whole (`Renderer::render_adaptive`, as `brdf-preview` runs them: one submission under
//! the area allocation, the default), timed without reading their buffers back and then rendered
//! once more with them for the ceiling. The G-buffer is then the camera's, made once before the
//! frames (`Renderer::adaptive_geometry`), as the brute force's raster pass is; on the CPU both
//! rasterize in every frame. On lavapipe the "GPU" is the machine's own cores: a frame's time is
//! its work, not its waits.
//!
//! # Running it
//!
//! `cargo bench -p brdf-preview --bench adaptive [-- --quick] [-- --gpu] [-- --seed S]`. Needs `../shared` (the maps, and
//! nbrdf2merl.py with numpy for the materials, made once under target/merl/). Bakes and
//! converged estimates are kept under target/bench-adaptive/ between runs. The report is printed
//! and written to target/bench-adaptive/report.md (report-gpu.md with `--gpu`).

use std::borrow::Cow;
use std::path::PathBuf;
use std::sync::Arc;

mod common;
use common::{Stamp, material_path, root, shared};
use std::time::Instant;

use bandwidth::Reading;
use render::adaptive::{self, Bandwidths, EnvBandwidth};
use render::{Camera, Estimator, Image, Lighting, Material, Scene, Settings, metrics};

const MATERIALS: [&str; 3] = ["gold-paint", "white-paint", "chrome"];
const ENVIRONMENTS: [&str; 2] = ["potsdamer_platz_1k", "quarry_01_1k"];
const MESHES: [&str; 2] = ["sphere", "torus"];
/// The summary's rows of the reading each bake chose (`brdf-bake --env-reading auto`, the
/// default: level-normalized for chrome, paper for the two paints).
const BAKE_CHOICE: &str = "the bake's (auto)";

/// The default render size (`--size N`): the paper's (`001` Fig. 11). The speed-ups depend on it:
/// a frame's fixed costs (prediction, plan, up-sampling) grow with the pixels as the brute
/// force's do, but the shaded pixels do not, as an image's bandwidth in cycles per pixel halves
/// when its width doubles, so the speed-ups grow with the size. `make bench` writes the report
/// at this size (`cargo bench -p brdf-preview --bench adaptive -- --gpu`) into
/// `docs/benchmarks.md`; `-- --size 256` measures a smaller one.
const SIZE: usize = 512;
const BRUTE_SPP: [u32; 9] = [1, 2, 4, 8, 16, 32, 64, 128, 256];

fn work() -> PathBuf {
    root().join("target/bench-adaptive")
}

fn environment_path(name: &str) -> PathBuf {
    shared().join("data/env").join(format!("{name}.hdr"))
}

/// The bake of a material under a map (incremental: a rerun reuses it). 128 importance vectors,
/// so that the brute force keeps improving up to its largest budget.
fn bake(material: &str, environment: &str) -> bake::Loaded {
    let dir = work().join(format!("{material}-{environment}"));
    let mut config = bake::BakeConfig::new(material_path(material), Some(environment_path(environment)), dir.clone());
    config.importance.n_vectors = 128;
    let program = bake::Program { name: "adaptive-bench", version: env!("CARGO_PKG_VERSION") };
    bake::run_bake(&config, &program, &|_| {}).unwrap_or_else(|e| panic!("baking {material} under {environment}: {e}"));
    bake::load(&dir, None).expect("loading the bake")
}

/// The environment's bandwidth read the given way, as the bake's stage computes it.
fn environment_bandwidth(environment: &str, reading: Reading) -> EnvBandwidth {
    let path = environment_path(environment);
    let map = envmap::load(&path).expect("loading the map");
    let mut settings = bake::stage::env_bandwidth::Settings::default();
    settings.config.reading = reading;
    let staged = bake::stage::env_bandwidth::run_on_map(&path, &map, &settings).expect("environment bandwidth");
    let exr = &staged.files.iter().find(|f| f.role == "environment-bandwidth").expect("the EXR").bytes;
    let image = envmap::read_image_from_memory(exr, &envmap::Limits::default()).expect("decoding the EXR");
    EnvBandwidth::new(image.width, image.height, image.rgb.chunks_exact(3).map(|t| t[0]).collect()).unwrap()
}

fn scene(mesh: &str, size: usize) -> Scene {
    let mesh = preview::mesh(mesh).expect("a named mesh");
    Scene {
        mesh,
        camera: Camera::orbit(glam::Vec3::ZERO, 3.2, 0.0, 0.5, 45f32.to_radians()).unwrap(),
        width: size,
        height: size,
    }
}

/// The converged estimate of a case, kept as raw little-endian `f32` RGB.
fn converged(name: &str, scene: &Scene, material: &Material, lighting: &Lighting, samples: u32) -> Image {
    let (width, height) = (scene.width, scene.height);
    let path = work().join(format!("{name}-{width}x{height}-converged-{samples}.f32"));
    let covered = render::raster::rasterize(&scene.mesh, scene.camera.view_proj(1.0), scene.width, scene.height)
        .expect("rasterizing")
        .hits
        .iter()
        .map(Option::is_some)
        .collect();
    if let Ok(bytes) = std::fs::read(&path)
        && bytes.len() == 12 * width * height
    {
        let rgb = bytes.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
        return Image { width, height, rgb, covered };
    }
    let start = Instant::now();
    let image = render::converged::converged(scene, material, lighting, samples, 1).expect("converged");
    eprintln!("{name}: converged estimate ({samples} per strategy) in {:.1} s", start.elapsed().as_secs_f64());
    std::fs::write(&path, image.rgb.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>()).expect("caching");
    image
}

/// An adaptive frame with what `hooks` gives (a function rather than a closure, whose one
/// lifetime would make every call's hooks borrow for the same span).
fn adaptive_frame(
    geometry: &adaptive::Geometry,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &Bandwidths,
    settings: &adaptive::Settings,
    hooks: adaptive::Hooks,
) -> adaptive::Adaptive {
    adaptive::render_with(geometry, material, lighting, bandwidths, settings, hooks).expect("adaptive render")
}

/// The best of `runs` wall times of `f`, in milliseconds, and its last result.
fn timed<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
        out = Some(value);
    }
    (best, out.expect("at least one run"))
}

/// Milliseconds as the tables print them: whole above 10 ms, else to 0.01 ms (a real GPU
/// renders these frames in a millisecond or two).
fn millis(ms: f64) -> String {
    if ms >= 10.0 { format!("{ms:.0}") } else { format!("{ms:.2}") }
}

/// Where an adaptive row's PSNR falls on the brute force's curve.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Match {
    /// Between two budgets (or below the first) of a curve that still converges there: the
    /// brute-force time at that PSNR, interpolated in log time.
    Measured(f64),
    /// Above the curve's best PSNR by [`PLATEAU_DB`] or more: the speed-up is at least the one
    /// over its largest budget's time.
    Beyond(f64),
    /// On the curve's plateau: between two budgets that gain less than [`FLAT_DB_PER_DOUBLING`]
    /// per doubling, or above its best by less than [`PLATEAU_DB`]. The speed-up is that of the
    /// interpolated time (or the largest budget's) as for the others, but which side of the
    /// plateau a frame lands on is the samples' luck (module docs, "The sun's plateau").
    Plateau(f64),
}

/// A brute-force curve that gains less than this per doubling of its samples is on its plateau;
/// an estimator whose variance falls as one over the samples gains 3 dB.
const FLAT_DB_PER_DOUBLING: f64 = 1.0;
/// An adaptive PSNR less than this above the brute force's best is within the seed's reach of
/// the plateau (module docs, "The sun's plateau").
const PLATEAU_DB: f64 = 1.0;

impl Match {
    fn ms(self) -> f64 {
        match self {
            Match::Measured(ms) | Match::Beyond(ms) | Match::Plateau(ms) => ms,
        }
    }

    /// The table's mark before a speed-up: `>` a lower bound, `~` on the plateau.
    fn mark(self) -> &'static str {
        match self {
            Match::Measured(_) => "",
            Match::Beyond(_) => ">",
            Match::Plateau(_) => "~",
        }
    }
}

/// Where `psnr` falls on the brute force's `curve` (PSNR and milliseconds at each of
/// [`BRUTE_SPP`], each twice the one before), on its running maximum.
fn brute_match(curve: &[(f64, f64)], psnr: f64) -> Match {
    let mut best = f64::NEG_INFINITY;
    let mut previous: Option<(usize, f64, f64)> = None;
    for (i, &(p, ms)) in curve.iter().enumerate() {
        if p <= best {
            continue;
        }
        if psnr <= p {
            let Some((i0, p0, ms0)) = previous else {
                return Match::Measured(ms);
            };
            let t = ((psnr - p0) / (p - p0)).clamp(0.0, 1.0);
            let ms = (ms0.ln() + t * (ms.ln() - ms0.ln())).exp();
            let gain = (p - p0) / (i - i0) as f64;
            return if gain < FLAT_DB_PER_DOUBLING { Match::Plateau(ms) } else { Match::Measured(ms) };
        }
        best = p;
        previous = Some((i, p, ms));
    }
    let ms = curve.last().expect("a brute-force curve").1;
    if psnr - best >= PLATEAU_DB { Match::Beyond(ms) } else { Match::Plateau(ms) }
}

/// The windowed FFT of a converged image as a person sees it: the tone-mapped luminance in
/// [0, 1], before 8-bit quantization (whose steps would read as detail everywhere), windows
/// whose RMS is below an 8-bit step's (1 / 255 / sqrt(12)) reading 0: detail the pictures the
/// PSNR compares cannot show. Per window centre, cycles per pixel.
fn picture_fft(image: &Image, preview: &envmap::ToneMapping) -> bandwidth::WindowedFftMap {
    let luminance: Vec<f64> = image
        .rgb
        .chunks_exact(3)
        .map(|p| color::luminance([p[0], p[1], p[2]].map(|v| envmap::tonemap(f64::from(v), preview))))
        .collect();
    let image = bandwidth::Image::new(image.width, image.height, luminance).unwrap();
    let config = bandwidth::WindowedFftConfig { noise_floor: 1.0 / 255.0 / 12f64.sqrt(), ..Default::default() };
    bandwidth::windowed_fft_bandwidth(&image, &config).expect("windowed FFT")
}

/// The oracle bandwidth of every pixel of a `size x size` image: the windowed FFT's value at the
/// nearest window centre.
fn oracle(fft: &bandwidth::WindowedFftMap, size: usize) -> Vec<f64> {
    let (half, stride) = (fft.window() / 2, fft.centre(1.min(fft.columns() - 1), 0).0 - fft.centre(0, 0).0);
    let nearest = |p: usize, n: usize| ((p.saturating_sub(half) + stride / 2) / stride.max(1)).min(n - 1);
    (0..size * size)
        .map(|i| fft.frequency_at(nearest(i % size, fft.columns()), nearest(i / size, fft.rows())))
        .collect()
}

struct Variant {
    name: &'static str,
    bandwidths: Bandwidths,
    oracle: Option<Vec<f64>>,
    lobe_weight: bool,
}

/// The command line (module docs, "Running it").
struct Options {
    /// `--quick`: the converged estimate at 256 samples per strategy instead of 1024.
    quick: bool,
    /// `--case SUBSTRING`: only the cases whose name contains it.
    only: Option<String>,
    /// `--predict-level L` (default 2, as brdf-preview).
    predict_level: usize,
    /// `--size N` (default [`SIZE`]): N x N pixels.
    size: usize,
    /// `--allocation variance|std-dev|area` (default area, as brdf-preview).
    allocation: adaptive::Allocation,
    /// The correlations and the anti-aliasing; `--no-extras` skips them.
    extras: bool,
    /// `--gpu`: the brute force and the adaptive frames on the GPU (lavapipe in CI), the adaptive
    /// frames' G-buffer made on the CPU once per camera, as brdf-preview runs them.
    gpu: bool,
    /// `--rescue-below W` (default 0).
    rescue_below: f64,
    /// `--seed S` (default 0): the adaptive frames' seed; the brute force's is S + 11. Under a small
    /// sun a frame's PSNR depends on which samples find it (module docs): other seeds show by how
    /// much.
    seed: u32,
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| args.iter().any(|a| a == name);
    let option = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    Options {
        quick: flag("--quick"),
        only: option("--case"),
        predict_level: option("--predict-level").map_or(2, |l| l.parse().expect("--predict-level L")),
        size: option("--size").map_or(SIZE, |n| n.parse().expect("--size N")),
        allocation: match option("--allocation").as_deref() {
            Some("variance") => adaptive::Allocation::Variance,
            Some("std-dev") => adaptive::Allocation::StdDev,
            None | Some("area") => adaptive::Allocation::Area,
            Some(other) => panic!("--allocation {other}: variance, std-dev or area"),
        },
        extras: !flag("--no-extras"),
        gpu: flag("--gpu"),
        rescue_below: option("--rescue-below").map_or(0.0, |v| v.parse().expect("--rescue-below W")),
        seed: option("--seed").map_or(0, |v| v.parse().expect("--seed S")),
    }
}

impl Options {
    fn converged_samples(&self) -> u32 {
        if self.quick { 256 } else { 1024 }
    }

    fn wanted(&self, case: &str) -> bool {
        self.only.as_ref().is_none_or(|o| case.contains(o.as_str()))
    }

    /// The brute force's frame at `spp`.
    fn brute_settings(&self, spp: u32) -> Settings {
        Settings { estimator: Estimator::Reference, spp, frames: 1, seed: self.seed.wrapping_add(11) }
    }

    /// An adaptive frame of the main table: `mode` at `spp` under `variant`.
    fn adaptive_settings(&self, mode: Estimator, spp: u32, variant: &Variant) -> adaptive::Settings {
        adaptive::Settings {
            predict_level: self.predict_level,
            allocation: self.allocation,
            lobe_weight: variant.lobe_weight,
            rescue_below: self.rescue_below,
            seed: self.seed,
            ..adaptive::Settings::new(mode, spp)
        }
    }
}

/// What every case is measured with: the options, and with `--gpu` the GPU.
struct Bench {
    options: Options,
    gpu: Option<gpu::Gpu>,
}

/// The report: each line printed as it is made (the main table's rows as their case is
/// measured) and kept for the file.
#[derive(Default)]
struct Report {
    text: String,
}

impl Report {
    fn line(&mut self, line: impl Into<String>) {
        let line = line.into();
        println!("{line}");
        self.text.push_str(&line);
        self.text.push('\n');
    }
}

fn case_name(material: &str, environment: &str, mesh: &str) -> String {
    format!("{material} / {environment} / {mesh}")
}

/// A map's environment bandwidth read both ways.
struct Readings {
    environment: &'static str,
    paper: EnvBandwidth,
    normalized: EnvBandwidth,
}

/// A material's bake under a map, and what its cases share.
struct Baked<'a> {
    material: &'static str,
    readings: &'a Readings,
    loaded: bake::Loaded,
    /// The reading the bake chose for the material (`brdf-bake --env-reading auto`): its rows make
    /// the summary's "bake's choice".
    bake_reading: &'static str,
    preview: envmap::ToneMapping,
}

impl<'a> Baked<'a> {
    fn new(material: &'static str, readings: &'a Readings) -> Baked<'a> {
        let env = readings.environment;
        let loaded = bake(material, env);
        let lighting = loaded.lighting.as_ref().expect("an environment");
        let bake_reading = match &loaded.bandwidths.as_ref().expect("bandwidths").environment {
            e if *e == readings.paper => "paper",
            e if *e == readings.normalized => "level-normalized",
            _ => panic!("{material} / {env}: the bake's environment bandwidth is neither reading's"),
        };
        let preview = metrics::auto_tone_mapping(lighting.mips.level(0));
        Baked { material, readings, loaded, bake_reading, preview }
    }

    fn material(&self) -> &Material {
        &self.loaded.material
    }

    fn lighting(&self) -> &Lighting {
        self.loaded.lighting.as_ref().expect("an environment")
    }

    /// The environment bandwidth's variants of the main table: (a) to (d) of the module docs.
    fn variants(&self, fft: &bandwidth::WindowedFftMap, size: usize) -> [Variant; 4] {
        let atlas = &self.loaded.bandwidths.as_ref().expect("bandwidths").brdf;
        let with = |environment: &EnvBandwidth| Bandwidths { environment: environment.clone(), brdf: atlas.clone() };
        let (paper, normalized) = (&self.readings.paper, &self.readings.normalized);
        [
            Variant { name: "paper", bandwidths: with(paper), oracle: None, lobe_weight: false },
            Variant { name: "level-normalized", bandwidths: with(normalized), oracle: None, lobe_weight: false },
            Variant {
                name: "oracle (FFT)",
                bandwidths: with(paper),
                oracle: Some(oracle(fft, size)),
                lobe_weight: false,
            },
            Variant { name: "paper + lobe weight", bandwidths: with(paper), oracle: None, lobe_weight: true },
        ]
    }
}

/// One case (a material under a map, on a mesh) and what its measurements share.
struct Case<'a> {
    name: String,
    baked: &'a Baked<'a>,
    scene: Scene,
    /// The converged estimate, and its picture (the PSNRs' reference).
    reference: Image,
    reference_picture: Vec<u8>,
    /// With `--gpu`, the renderer of the brute force and of the adaptive frames.
    renderer: Option<gpu::preview::Renderer>,
    /// The camera's G-buffer on the GPU (see [`Case::geometry`]).
    geometry: Option<Arc<adaptive::Geometry>>,
}

impl<'a> Case<'a> {
    fn new(bench: &Bench, baked: &'a Baked<'a>, mesh: &str) -> Case<'a> {
        let (material, env) = (baked.material, baked.readings.environment);
        let scene = scene(mesh, bench.options.size);
        let reference = converged(
            &format!("{material}-{env}-{mesh}"),
            &scene,
            baked.material(),
            baked.lighting(),
            bench.options.converged_samples(),
        );
        let reference_picture = metrics::tonemap(&reference, &baked.preview);
        let renderer = bench.gpu.as_ref().map(|g| {
            gpu::preview::Renderer::new(g, &scene, baked.material(), baked.lighting()).expect("the GPU renderer")
        });
        let geometry = renderer.as_ref().map(|r| r.adaptive_geometry(1).expect("the G-buffer"));
        Case { name: case_name(material, env, mesh), baked, scene, reference, reference_picture, renderer, geometry }
    }

    /// The camera's G-buffer. On the GPU it is made once per camera, as the raster pass the brute
    /// force reads is (at Renderer::new), and neither is in a frame's time; the CPU's brute force
    /// rasterizes in every frame, and so does its adaptive frame.
    fn geometry(&self) -> Cow<'_, adaptive::Geometry> {
        match &self.geometry {
            Some(g) => Cow::Borrowed(&**g),
            None => Cow::Owned(adaptive::Geometry::of_scene(&self.scene, 1).expect("the G-buffer")),
        }
    }

    fn psnr(&self, image: &Image) -> f64 {
        metrics::psnr_db(&metrics::tonemap(image, &self.baked.preview), &self.reference_picture)
    }

    /// The PSNR of `frame`'s plan with every shaded block given its converged value: the
    /// up-sampling's error alone, the PSNR no budget can pass.
    fn ceiling(&self, settings: &adaptive::Settings, variant: &Variant, frame: &adaptive::Adaptive) -> f64 {
        let ceiling = adaptive::ceiling(
            &self.geometry(),
            self.baked.material(),
            self.baked.lighting(),
            &variant.bandwidths,
            settings,
            &frame.details().predictions,
            &self.reference,
            variant.oracle.as_deref(),
        )
        .expect("the ceiling's frame");
        self.psnr(&ceiling.image)
    }
}

/// A row of the main table, for the speed-ups' summary.
struct Speedup {
    mode: &'static str,
    reading: &'static str,
    speedup: f64,
    brute: Match,
    /// The reading is the one the bake chose.
    bake_choice: bool,
}

/// A row of the correlations' table (item 3 of the module docs).
struct Correlation {
    case: String,
    reading: &'static str,
    bandwidth_rho: f64,
    windows: usize,
    variance_rho: f64,
}

/// A row of the anti-aliasing's table (item 4 of the module docs).
struct AntiAliasing {
    case: String,
    plain_ms: f64,
    aa_ms: f64,
    plain_shaded: usize,
    aa_shaded: usize,
}

/// A row of the frames' stages (item 5 of the module docs): a paper-reading frame of the main table.
struct Stages {
    case: String,
    mode: &'static str,
    spp: u32,
    timings: adaptive::Timings,
    ms: f64,
    brute_ms: f64,
}

/// What the report's sections after the main table are made from.
#[derive(Default)]
struct Results {
    speedups: Vec<Speedup>,
    correlations: Vec<Correlation>,
    anti_aliasing: Vec<AntiAliasing>,
    stages: Vec<Stages>,
}

fn main() {
    let options = options();
    let gpu = options.gpu.then(|| gpu::Gpu::new().expect("a GPU adapter (make setup-gpu)"));
    let bench = Bench { options, gpu };
    std::fs::create_dir_all(work()).expect("creating target/bench-adaptive");
    let mut report = Report::default();
    header(&mut report, &bench);
    let results = measure(&bench, &mut report);
    speedup_summary(&mut report, &results.speedups);
    correlation_table(&mut report, &results.correlations);
    anti_aliasing_table(&mut report, &results.anti_aliasing);
    stage_table(&mut report, &results.stages, bench.gpu.is_some());
    let file = work().join(if bench.gpu.is_some() { "report-gpu.md" } else { "report.md" });
    std::fs::write(&file, &report.text).expect("writing the report");
    eprintln!("report written to {}", file.display());
}

/// The report's title, what was measured and how, and the main table's header.
fn header(report: &mut Report, bench: &Bench) {
    let Options { size, predict_level, allocation, rescue_below, seed, .. } = bench.options;
    report.line(format!(
        "# Adaptive shading: equal-quality benchmark ({})",
        match &bench.gpu {
            Some(g) => format!("on {}, the G-buffer on the CPU once per camera", g.adapter_summary()),
            None => "CPU renderer".to_string(),
        }
    ));
    report.line("");
    report.line(format!("Measured at {}.", Stamp::now()));
    report.line("");
    report.line(format!(
        "{size} x {size}, converged estimate {} samples per strategy; brute force: the reference mode at 1 to 256 spp, one frame; \
         speed-up: brute-force time at the adaptive PSNR over the adaptive time (best of 3 runs each; `>`: the brute force never reaches it, \
         `~`: on its plateau, below); \
         ceiling: the PSNR of the plan with the converged values in its shaded blocks. Adaptive frames: prediction level {predict_level}, \
         allocation {}, rescue below {rescue_below}, seed {seed} (the brute force's {}).",
        bench.options.converged_samples(),
        allocation.name(),
        seed.wrapping_add(11)
    ));
    report.line("");
    report.line("| case | mode | env reading | budget spp | PSNR dB | ceiling dB | ms | shaded | samples | brute ms | speed-up |");
    report.line("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
}

/// Every wanted case, bake by bake: the main table's rows into `report` as they are measured,
/// the rest into the results.
fn measure(bench: &Bench, report: &mut Report) -> Results {
    let readings: Vec<Readings> = ENVIRONMENTS
        .into_iter()
        .map(|environment| Readings {
            environment,
            paper: environment_bandwidth(environment, Reading::Paper),
            normalized: environment_bandwidth(environment, Reading::LevelNormalized),
        })
        .collect();
    let mut results = Results::default();
    for material in MATERIALS {
        for readings in &readings {
            let wanted = |mesh: &str| bench.options.wanted(&case_name(material, readings.environment, mesh));
            if !MESHES.iter().any(|m| wanted(m)) {
                continue;
            }
            let baked = Baked::new(material, readings);
            for mesh in MESHES.into_iter().filter(|m| wanted(m)) {
                measure_case(bench, &mut Case::new(bench, &baked, mesh), report, &mut results);
            }
        }
    }
    results
}

/// One case: the brute force's curve, the main table's rows, and with the extras the
/// correlations and the anti-aliasing.
fn measure_case(bench: &Bench, case: &mut Case, report: &mut Report, results: &mut Results) {
    let curve = brute_force(bench, case);
    let fft = picture_fft(&case.reference, &case.baked.preview);
    let variants = case.baked.variants(&fft, bench.options.size);
    equal_quality(bench, case, &variants, &curve, report, results);
    if !bench.options.extras {
        return;
    }
    correlations(case, &variants[..2], &fft, &mut results.correlations);
    results.anti_aliasing.push(anti_aliasing(bench, case, &variants[0]));
}

/// The brute force's curve (item 1 of the module docs): PSNR and milliseconds at each of
/// [`BRUTE_SPP`], on the renderer the rest runs on.
fn brute_force(bench: &Bench, case: &mut Case) -> Vec<(f64, f64)> {
    let curve: Vec<(f64, f64)> = BRUTE_SPP
        .iter()
        .map(|&spp| {
            let settings = bench.options.brute_settings(spp);
            let (ms, image) = timed(if spp <= 32 { 3 } else { 1 }, || match case.renderer.as_mut() {
                Some(r) => r.render_frames(&settings).expect("render on the GPU"),
                None => render::render(&case.scene, case.baked.material(), case.baked.lighting(), &settings)
                    .expect("render"),
            });
            (case.psnr(&image), ms)
        })
        .collect();
    let brute: Vec<String> =
        BRUTE_SPP.iter().zip(&curve).map(|(s, (p, ms))| format!("{s}: {p:.2} dB {} ms", millis(*ms))).collect();
    eprintln!("{}: brute force {}", case.name, brute.join(", "));
    curve
}

/// The main table's rows of a case (item 2 of the module docs): each adaptive mode at its two
/// budgets under each variant, against the brute force's `curve`.
fn equal_quality(
    bench: &Bench,
    case: &mut Case,
    variants: &[Variant],
    curve: &[(f64, f64)],
    report: &mut Report,
    results: &mut Results,
) {
    for (mode, label, budgets) in
        [(Estimator::Reference, "adaptive", [4u32, 16]), (Estimator::Prefiltered, "adaptive-prefiltered", [2, 8])]
    {
        for variant in variants {
            if let Some(r) = case.renderer.as_mut() {
                r.set_bandwidths(&variant.bandwidths).expect("uploading the bandwidths");
            }
            for spp in budgets {
                let settings = bench.options.adaptive_settings(mode, spp, variant);
                let (ms, frame) = timed_adaptive(case, &settings, variant);
                let p = case.psnr(&frame.image);
                let ceiling = case.ceiling(&settings, variant, &frame);
                let brute = brute_match(curve, p);
                let speedup = brute.ms() / ms;
                report.line(format!(
                    "| {} | {label} | {} | {spp} | {p:.2} | {ceiling:.2} | {} | {:.3} | {} | {} | {}{speedup:.1} |",
                    case.name,
                    variant.name,
                    millis(ms),
                    frame.shaded_fraction(),
                    frame.samples,
                    millis(brute.ms()),
                    brute.mark()
                ));
                results.speedups.push(Speedup {
                    mode: label,
                    reading: variant.name,
                    speedup,
                    brute,
                    bake_choice: variant.name == case.baked.bake_reading,
                });
                if variant.name == "paper" {
                    let (timings, brute_ms) = (frame.timings, brute.ms());
                    results.stages.push(Stages { case: case.name.clone(), mode: label, spp, timings, ms, brute_ms });
                }
            }
        }
    }
}

/// An adaptive frame of the main table, in milliseconds (the best of 3), with the details its
/// ceiling reads. On the GPU the frame is timed without reading its buffers back, then rendered
/// once more (the same frame) with them.
fn timed_adaptive(case: &Case, settings: &adaptive::Settings, variant: &Variant) -> (f64, adaptive::Adaptive) {
    let (material, lighting) = (case.baked.material(), case.baked.lighting());
    let oracle = variant.oracle.as_deref();
    match case.renderer.as_ref() {
        Some(r) => {
            let frame = |details| {
                let options = gpu::preview::FrameOptions { oracle, details };
                r.render_adaptive(material, lighting, settings, options).expect("adaptive on the GPU")
            };
            (timed(3, || frame(false)).0, frame(true))
        }
        None => timed(3, || {
            let hooks = adaptive::Hooks { oracle, ..Default::default() };
            adaptive_frame(&case.geometry(), material, lighting, &variant.bandwidths, settings, hooks)
        }),
    }
}

/// Item 3 of the module docs, per reading in `readings` (on the CPU): Spearman's rank correlation
/// of the predicted image bandwidth with the windowed FFT of the converged picture (windows wholly
/// on the mesh), and of the predicted variance with the measured variance of the one-sample
/// estimator.
fn correlations(case: &Case, readings: &[Variant], fft: &bandwidth::WindowedFftMap, out: &mut Vec<Correlation>) {
    let size = case.scene.width;
    let measured_variance = one_sample_variance(case);
    for variant in readings {
        let settings = adaptive::Settings { predict_level: 0, ..adaptive::Settings::new(Estimator::Reference, 4) };
        let frame =
            adaptive::render(&case.scene, case.baked.material(), case.baked.lighting(), &variant.bandwidths, &settings)
                .expect("adaptive");
        let predictions = &frame.details().predictions;
        let (mut predicted, mut measured) = (Vec::new(), Vec::new());
        for j in 0..fft.rows() {
            for i in 0..fft.columns() {
                let (cx, cy) = fft.centre(i, j);
                let (x0, y0) = (cx - fft.window() / 2, cy - fft.window() / 2);
                let inside = (0..fft.window() * fft.window())
                    .all(|k| predictions[(y0 + k / fft.window()) * size + x0 + k % fft.window()].level >= 0);
                if inside {
                    predicted.push(predictions[cy * size + cx].bandwidth);
                    measured.push(fft.frequency_at(i, j));
                }
            }
        }
        let shadeable: Vec<usize> = (0..size * size).filter(|&i| predictions[i].level >= 0).collect();
        let pv: Vec<f64> = shadeable.iter().map(|&i| predictions[i].variance).collect();
        let mv: Vec<f64> = shadeable.iter().map(|&i| measured_variance[i]).collect();
        out.push(Correlation {
            case: case.name.clone(),
            reading: variant.name,
            bandwidth_rho: bandwidth::spearman(&predicted, &measured).unwrap_or(f64::NAN),
            windows: predicted.len(),
            variance_rho: bandwidth::spearman(&pv, &mv).unwrap_or(f64::NAN),
        });
    }
}

/// Per pixel, the variance of the luminance of 16 independent one-sample renders (the reference
/// mode, on the CPU).
fn one_sample_variance(case: &Case) -> Vec<f64> {
    let one_spp: Vec<Image> = (0..16)
        .map(|s| {
            let settings = Settings { estimator: Estimator::Reference, spp: 1, frames: 1, seed: 100 + s };
            render::render(&case.scene, case.baked.material(), case.baked.lighting(), &settings).expect("render")
        })
        .collect();
    let luminance = |img: &Image, i: usize| color::luminance([0, 1, 2].map(|c| f64::from(img.rgb[3 * i + c])));
    (0..case.scene.width * case.scene.height)
        .map(|i| {
            let v: Vec<f64> = one_spp.iter().map(|img| luminance(img, i)).collect();
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (v.len() - 1) as f64
        })
        .collect()
}

/// Item 4 of the module docs: the adaptive frame at 8 spp under `paper` with 16x anti-aliasing
/// against none, on the renderer the rest ran on.
fn anti_aliasing(bench: &Bench, case: &mut Case, paper: &Variant) -> AntiAliasing {
    let (material, lighting) = (case.baked.material(), case.baked.lighting());
    let aa_renderer = bench.gpu.as_ref().map(|g| {
        let big = Scene { width: case.scene.width * 4, height: case.scene.height * 4, ..case.scene.clone() };
        let mut r = gpu::preview::Renderer::new(g, &big, material, lighting).expect("the GPU renderer");
        r.set_bandwidths(&paper.bandwidths).expect("uploading the bandwidths");
        r
    });
    if let Some(r) = case.renderer.as_mut() {
        r.set_bandwidths(&paper.bandwidths).expect("uploading the bandwidths");
    }
    let frame = |supersample: usize, renderer: Option<&gpu::preview::Renderer>| {
        let settings = adaptive::Settings {
            supersample,
            predict_level: bench.options.predict_level,
            allocation: bench.options.allocation,
            ..adaptive::Settings::new(Estimator::Reference, 8)
        };
        match renderer {
            Some(r) => {
                r.render_adaptive(material, lighting, &settings, Default::default()).expect("adaptive on the GPU")
            }
            None => adaptive::render(&case.scene, material, lighting, &paper.bandwidths, &settings).expect("adaptive"),
        }
    };
    let (plain_ms, plain) = timed(3, || frame(1, case.renderer.as_ref()));
    let (aa_ms, aa) = timed(3, || frame(4, aa_renderer.as_ref()));
    let shaded = |f: &adaptive::Adaptive| f.shaded_per_level.iter().sum::<usize>();
    AntiAliasing { case: case.name.clone(), plain_ms, aa_ms, plain_shaded: shaded(&plain), aa_shaded: shaded(&aa) }
}

/// The speed-ups per mode and reading, over all rows and over the rows off the plateau.
fn speedup_summary(report: &mut Report, speedups: &[Speedup]) {
    report.line("");
    report.line("## Speed-up at equal quality, per mode and reading (over cases and budgets)");
    report.line("");
    report.line(format!(
        "All rows, then the rows off the brute force's plateau (`~` above: where its curve gains less than \
         {FLAT_DB_PER_DOUBLING} dB per doubling of its samples around the adaptive PSNR, or tops out less than {PLATEAU_DB} dB below it; \
         module docs, \"The sun's plateau\")."
    ));
    report.line("");
    report.line("| mode | env reading | rows | min | median | max | rows >= goal |");
    report.line("|---|---|---|---:|---:|---:|---:|");
    for label in ["adaptive", "adaptive-prefiltered"] {
        for reading in [BAKE_CHOICE, "paper", "level-normalized", "oracle (FFT)", "paper + lobe weight"] {
            for (rows, off_plateau) in [("all", false), ("off the plateau", true)] {
                let of_reading = |s: &Speedup| match reading {
                    BAKE_CHOICE => s.bake_choice,
                    _ => s.reading == reading,
                };
                let mut v: Vec<f64> = (speedups.iter())
                    .filter(|s| {
                        s.mode == label && of_reading(s) && !(off_plateau && matches!(s.brute, Match::Plateau(_)))
                    })
                    .map(|s| s.speedup)
                    .collect();
                v.sort_by(f64::total_cmp);
                if v.is_empty() {
                    continue;
                }
                let goal = if label == "adaptive" { 4.0 } else { 10.0 };
                let hit = v.iter().filter(|&&s| s >= goal).count();
                // Of an even count, the mean of the two middle rows.
                let middle = v.len() / 2;
                let median = if v.len() % 2 == 1 { v[middle] } else { (v[middle - 1] + v[middle]) / 2.0 };
                report.line(format!(
                    "| {label} | {reading} | {rows} | {:.1} | {median:.1} | {:.1} | {hit} of {} (goal {goal}x) |",
                    v[0],
                    v[v.len() - 1],
                    v.len()
                ));
            }
        }
    }
}

fn correlation_table(report: &mut Report, correlations: &[Correlation]) {
    report.line("");
    report.line("## Predictions against measurements (Spearman's rank correlation)");
    report.line("");
    report.line("| case | env reading | bandwidth vs windowed FFT | windows | variance vs measured |");
    report.line("|---|---|---:|---:|---:|");
    for c in correlations {
        let Correlation { case, reading, bandwidth_rho, windows, variance_rho } = c;
        report.line(format!("| {case} | {reading} | {bandwidth_rho:.3} | {windows} | {variance_rho:.3} |"));
    }
}

fn anti_aliasing_table(report: &mut Report, rows: &[AntiAliasing]) {
    report.line("");
    report.line("## 16x anti-aliasing (adaptive, 8 spp budget, paper reading)");
    report.line("");
    report.line("| case | ms 1x | ms 16x | time ratio | shaded blocks 1x | 16x |");
    report.line("|---|---:|---:|---:|---:|---:|");
    for AntiAliasing { case, plain_ms, aa_ms, plain_shaded, aa_shaded } in rows {
        let ratio = aa_ms / plain_ms;
        report.line(format!(
            "| {case} | {} | {} | {ratio:.2} | {plain_shaded} | {aa_shaded} |",
            millis(*plain_ms),
            millis(*aa_ms)
        ));
    }
}

/// Where the adaptive frames' time goes (item 5 of the module docs), `on_gpu` or on the CPU.
fn stage_table(report: &mut Report, stages: &[Stages], on_gpu: bool) {
    report.line("");
    report.line("## Where the adaptive frames' time goes (paper reading; ms)");
    report.line("");
    report.line(format!(
        "Stages of the frame whose PSNR the table above reports (its last run; `frame` is the best of 3). {}",
        if on_gpu {
            "On the GPU under the area allocation the frame is one submission: its stages on the GPU's clock \
             (timestamp queries; where the adapter has none, all of the frame in the last column), the samples \
             with the list of shaded blocks, and `frame` the wall time (recording, submission, the wait and the \
             image's read-back besides). Under the variance or std-dev allocation it is two submissions, wall \
             times: the first (prediction, pyramids, plan, and the list read back) in the prediction's column, the \
             allocation of the samples on the CPU in the next, the second with the image's read-back in the last. The G-buffer is the \
             camera's, made once on the CPU before its frames and not in `frame`, as the brute force's raster pass \
             is not in its time; the environment behind the mesh is drawn once per camera too, for both."
        } else {
            "The G-buffer is made in every frame, as the brute force rasterizes in every frame."
        }
    ));
    report.line("");
    report.line(if on_gpu {
        "| case | mode | budget spp | G-buffer | prediction | pyramids, plan, samples | shading, up-sampling, output | frame | brute force at equal PSNR |"
    } else {
        "| case | mode | budget spp | G-buffer | prediction | pyramids, plan, samples | shading, up-sampling, background | frame | brute force at equal PSNR |"
    });
    report.line("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for Stages { case, mode, spp, timings: t, ms, brute_ms } in stages {
        report.line(format!(
            "| {case} | {mode} | {spp} | {} | {} | {} | {} | {} | {} |",
            millis(t.gbuffer_ms),
            millis(t.predict_ms),
            millis(t.plan_ms),
            millis(t.shade_ms),
            millis(*ms),
            millis(*brute_ms)
        ));
    }
}
