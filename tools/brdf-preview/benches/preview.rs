//! The previewer's benchmark (a benchmark, not a test): over six cases (white-paint,
//! gold-paint and chrome under potsdamer_platz and quarry_01, a 128 x 128 sphere),
//!
//! 1. the layer selection's calibration: the prefiltered mode's PSNR against the converged
//!    estimate for each analysis size and per-view reduction (CPU renders, which equal the GPU's
//!    to rounding), the figures that chose the bake's defaults;
//! 2. each mode against the converged estimate at equal sample counts, with the GPU's
//!    milliseconds per frame (lavapipe in CI; a real GPU elsewhere);
//! 3. the reference mode's expectation over the sample choice (every sample of a pixel's slice
//!    once) against the converged estimate: the image's mean luminance ratio, with the 128
//!    importance vectors the end-to-end tests bake. The tests check the estimator under the map
//!    without a sun at 64 x 64 (0.5%); what the bake's finite sample set leaves under quarry's
//!    sun is measured here, not tested (as a test, about 7 minutes of `make test` on 2 cores).
//!
//! `cargo bench -p brdf-preview --bench preview [-- --quick] [-- --no-calibration]`. Needs
//! `../shared` (the maps, and nbrdf2merl.py with numpy for the materials, made once under
//! target/merl/) and a GPU adapter (lavapipe: `make setup-gpu`).

mod common;
use common::shared;
use std::time::Instant;

use bandwidth_atlas::view::{ViewReduction, select_layers_of_table, view_coordinates};
use render::{Camera, Estimator, Lighting, Material, Scene, Settings, metrics};

const MATERIALS: [&str; 3] = ["white-paint", "gold-paint", "chrome"];
const ENVIRONMENTS: [&str; 2] = ["potsdamer_platz_1k.hdr", "quarry_01_1k.hdr"];
const SIZE: usize = 128;

/// A real-derived MERL table, made once under target/merl/ by nbrdf2merl.py.
fn material(name: &str) -> merl::MerlTable {
    let path = common::material_path(name);
    merl::read_file(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

struct Case {
    name: String,
    table: merl::MerlTable,
    samples: render::SampleSet,
    lighting: Lighting,
    preview: envmap::ToneMapping,
    converged: render::Image,
    converged_picture: Vec<u8>,
}

fn scene() -> Scene {
    Scene { mesh: preview::mesh("sphere").expect("the sphere"), camera: Camera::default(), width: SIZE, height: SIZE }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let calibrate = !args.iter().any(|a| a == "--no-calibration");
    let converged_samples: u32 = if quick { 256 } else { 1024 };
    let scene = scene();
    let exponents = prefilter::DEFAULT_EXPONENTS.to_vec();

    let mut environments = Vec::new();
    for env in ENVIRONMENTS {
        let map = envmap::load(&shared().join("data/env").join(env)).expect("loading the map");
        let config = prefilter::Config { exponents: exponents.clone(), ..prefilter::Config::default() };
        let layers =
            prefilter::prefilter(&map, &config).expect("prefiltering").layers.into_iter().map(|l| l.map).collect();
        let preview = metrics::auto_tone_mapping(&map);
        let lighting = Lighting::new(envmap::MipChain::new(&map), layers, exponents.clone()).expect("a valid map");
        environments.push((env.trim_end_matches(".hdr").to_string(), lighting, preview));
    }
    let mut cases = Vec::new();
    for name in MATERIALS {
        let table = material(name);
        let tables = importance::build(&table, &importance::Config::default()).expect("importance tables");
        let samples = render::SampleSet::new(&tables);
        for (env, lighting, preview) in &environments {
            let start = Instant::now();
            let material = Material::new(table.clone(), samples.clone(), vec![0.0]);
            let converged =
                render::converged::converged(&scene, &material, lighting, converged_samples, 1).expect("converged");
            let converged_picture = metrics::tonemap(&converged, preview);
            eprintln!(
                "{name} under {env}: converged estimate ({converged_samples} per strategy) in {:.1} s",
                start.elapsed().as_secs_f64()
            );
            cases.push(Case {
                name: format!("{name} / {env}"),
                table: table.clone(),
                samples: samples.clone(),
                lighting: lighting.clone(),
                preview: *preview,
                converged,
                converged_picture,
            });
        }
    }

    println!("Measured at {}.", common::Stamp::now());
    if calibrate {
        calibration(&cases, &scene, &exponents, quick);
    }
    // One adapter for both GPU tables.
    let gpu = gpu::Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    modes(&gpu, &cases, &scene, &exponents);
    expectation(&gpu, &cases, &scene);
}

/// Table 1: the prefiltered mode's PSNR against the converged estimate per analysis size and
/// reduction.
fn calibration(cases: &[Case], scene: &Scene, exponents: &[u32], quick: bool) {
    let sizes: &[usize] = if quick { &[64, 256] } else { &[64, 128, 256, 512] };
    let reductions = [
        ViewReduction::Max,
        ViewReduction::BandQuantile(0.9),
        ViewReduction::BandQuantile(0.95),
        ViewReduction::BandQuantile(0.99),
    ];
    println!("\nLayer selection: prefiltered mode (16 spp, 1 frame) against the converged estimate, PSNR in dB");
    print!("{:<14} {:<10}", "analysis", "reduction");
    for case in cases {
        print!(" {:>24}", case.name);
    }
    println!(" {:>8}", "mean");
    for &size in sizes {
        let config = bandwidth_atlas::Config { analysis_size: size, ..bandwidth_atlas::Config::default() };
        // One atlas per material and size, shared by its two environments and every reduction.
        let mut selections: Vec<Vec<Vec<f32>>> = Vec::new();
        for pair in cases.chunks(ENVIRONMENTS.len()) {
            let build = bandwidth_atlas::build_atlas(&pair[0].table, &config, &|_| {}).expect("atlas");
            selections.push(
                reductions
                    .iter()
                    .map(|&r| {
                        let selection =
                            bandwidth_atlas::view::select_layers(&build, &config, exponents, r).expect("selection");
                        view_coordinates(&selection.view_bandwidth, &selection.layer_bandwidth)
                    })
                    .collect(),
            );
        }
        for (r, reduction) in reductions.iter().enumerate() {
            print!("{:<14} {:<10}", format!("{size} x {size}"), reduction.name());
            let mut sum = 0.0;
            for (c, case) in cases.iter().enumerate() {
                let view_layers = selections[c / ENVIRONMENTS.len()][r].clone();
                let psnr = psnr_of(case, scene, view_layers, Estimator::Prefiltered, 16, 1);
                sum += psnr;
                print!(" {psnr:>24.2}");
            }
            println!(" {:>8.2}", sum / cases.len() as f64);
        }
    }
}

/// PSNR of one CPU render against the case's converged estimate.
fn psnr_of(case: &Case, scene: &Scene, view_layers: Vec<f32>, mode: Estimator, spp: u32, frames: u32) -> f64 {
    let material = Material::new(case.table.clone(), case.samples.clone(), view_layers);
    let image = render::render(scene, &material, &case.lighting, &Settings { estimator: mode, spp, frames, seed: 0 })
        .expect("render");
    metrics::psnr_db(&metrics::tonemap(&image, &case.preview), &case.converged_picture)
}

/// Table 2: every mode against the converged estimate at equal sample counts, timed on the GPU.
fn modes(gpu: &gpu::Gpu, cases: &[Case], scene: &Scene, exponents: &[u32]) {
    println!("\nModes against the converged estimate on {} (128 x 128 sphere)", gpu.adapter_summary());
    println!(
        "{:<32} {:<12} {:>5} {:>7} {:>9} {:>10} {:>12} {:>10}",
        "case", "mode", "spp", "frames", "PSNR dB", "rel. error", "mean lum.", "ms/frame"
    );
    let config = bandwidth_atlas::Config::default();
    for pair in cases.chunks(ENVIRONMENTS.len()) {
        let selection =
            select_layers_of_table(&pair[0].table, &config, exponents, bake::stage::layer_selection::DEFAULT_REDUCTION)
                .expect("selection");
        for case in pair {
            let material = Material::new(
                case.table.clone(),
                case.samples.clone(),
                view_coordinates(&selection.view_bandwidth, &selection.layer_bandwidth),
            );
            let mut renderer = gpu::preview::Renderer::new(gpu, scene, &material, &case.lighting).expect("renderer");
            let runs = [
                (Estimator::Reference, 16, 1),
                (Estimator::Fis, 16, 1),
                (Estimator::Prefiltered, 16, 1),
                (Estimator::Reference, 64, 16),
                (Estimator::Fis, 64, 1),
                (Estimator::Prefiltered, 64, 1),
            ];
            for (mode, spp, frames) in runs {
                let settings = Settings { estimator: mode, spp, frames, seed: 0 };
                renderer.render_frames(&Settings { frames: 1, ..settings }).expect("warm-up");
                let repeats = (16 / frames).max(1);
                let start = Instant::now();
                let mut image = renderer.render_frames(&settings).expect("render");
                for _ in 1..repeats {
                    image = renderer.render_frames(&settings).expect("render");
                }
                let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(frames * repeats);
                let picture = metrics::tonemap(&image, &case.preview);
                let psnr = metrics::psnr_db(&picture, &case.converged_picture);
                let relative = metrics::relative_error(&image.rgb, &case.converged.rgb);
                let luminance = metrics::mean_luminance(&image) / metrics::mean_luminance(&case.converged);
                println!(
                    "{:<32} {:<12} {spp:>5} {frames:>7} {psnr:>9.2} {relative:>10.4} {luminance:>12.4} {ms:>10.1}",
                    case.name,
                    mode.name()
                );
            }
        }
    }
}

/// Table 3: the reference mode's expectation (256 spp, as many frames as use every sample of a
/// pixel's slice once) against the converged estimate, with 128 importance vectors of 256
/// samples, the end-to-end tests' bake.
fn expectation(gpu: &gpu::Gpu, cases: &[Case], scene: &Scene) {
    let config = importance::Config { n_vectors: 128, ..importance::Config::default() };
    println!(
        "\nThe reference mode's expectation (every baked sample once, {} vectors) against the converged estimate",
        config.n_vectors
    );
    println!("{:<32} {:>7} {:>12} {:>9} {:>10}", "case", "frames", "mean lum.", "PSNR dB", "ms/frame");
    for pair in cases.chunks(ENVIRONMENTS.len()) {
        let tables = importance::build(&pair[0].table, &config).expect("importance tables");
        let samples = render::SampleSet::new(&tables);
        for case in pair {
            let material = Material::new(case.table.clone(), samples.clone(), vec![0.0]);
            let mut renderer = gpu::preview::Renderer::new(gpu, scene, &material, &case.lighting).expect("renderer");
            let spp = 256;
            let frames = render::frames_to_exhaust(samples.n_vectors, samples.n_samples, spp);
            let start = Instant::now();
            let image = renderer
                .render_frames(&Settings { estimator: Estimator::Reference, spp, frames, seed: 0 })
                .expect("render");
            let ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(frames);
            let psnr = metrics::psnr_db(&metrics::tonemap(&image, &case.preview), &case.converged_picture);
            let luminance = metrics::mean_luminance(&image) / metrics::mean_luminance(&case.converged);
            println!("{:<32} {frames:>7} {luminance:>12.4} {psnr:>9.2} {ms:>10.1}", case.name);
        }
    }
}
