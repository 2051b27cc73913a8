//! `brdf-preview`: renders a bake on the GPU so that a person (or a script) can check it before
//! it ships; validates the GPU image against the CPU reference renderer. Argument parsing,
//! loading and printing around `bake::load`, `gpu::preview` and `render`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, ValueEnum};
use picture::Canvas;
use render::{Camera, Mesh, Mode, Scene, Settings, metrics};
use serde_json::json;

mod adaptive;
mod window;

/// Render a baked material on a mesh under the bake's environment with wgpu (headless; --window
/// for an interactive view), by one of the estimators of the papers.
///
/// Modes (--mode):
///
///   reference    multiple importance sampling (balance heuristic) of the material's baked
///                importance tables (001 section 3.3) and the environment's own: unbiased; each
///                pixel draws its own directions, so its error is not its neighbours'
///
///   fis          filtered importance sampling (002): each of the material's samples reads the
///                environment's mip chain at the level of its footprint's solid angle
///
///   prefiltered  the Phong layers (001 sections 2.5 and 4.3) around the layer the bake's
///                selection gives the view, blended, read by few samples
///
///   adaptive     bandwidth-driven multi-resolution shading (001 sections 2-3): the bake's
///                environment bandwidth and BRDF atlas predict each pixel's image bandwidth and
///                variance; only the pixels the prediction asks for are shaded (reference
///                estimator) with a budget of --spp samples per pixel on average (--allocation),
///                the rest is up-sampled (crate render, module adaptive, is the specification)
///
///   adaptive-prefiltered
///                the same with the prefiltered estimator and eq. 10's variance (001 ASFPCS)
///
/// Small bright sources: fis and prefiltered filter only the environment's smooth part. Texels
/// brighter than 4 times its mean luminance (a sun, a softbox) are its peaks, sampled from the
/// unfiltered map by multiple importance sampling, so a small bright source keeps its light.
/// What the filter does to the smooth part is an approximation: within 2.5% of the converged
/// estimate's mean luminance on white-paint, gold-paint and chrome under quarry_01 and
/// studio_small_03 at the default settings (cargo bench -p brdf-preview --bench mitsuba); more
/// for a broad lobe under a sharp horizon (a Lambertian's broadest layer is read at
/// cosine-distributed directions: twice blurred).
///
/// Pictures: the environment is drawn behind the mesh, so its orientation can be checked.
/// Pictures are tone mapped: exposure 2^EV (by default the one that maps the environment's
/// log-average luminance to 0.18), Reinhard's x / (1 + x) per channel, then the sRGB transfer
/// function to 8 bits; a caption strip below the image says what was rendered.
///
/// Checks:
///
///   --validate   renders the same image on the CPU (crate render: the same estimator, the same
///                samples), reports the PSNR of the two 8-bit pictures and the relative error of
///                their linear radiance, and writes OUT-difference.png (|GPU - CPU| in tone-mapped
///                8-bit levels, with its scale)
///
///   --converged N
///                also renders an independent estimate (multiple importance sampling of the
///                environment, the cosine and the MERL grid's half vectors, N samples per
///                strategy, no baked table) and reports PSNR and the ratio of mean luminances
///
///   --brdf wavelet
///                evaluates the BRDF from its Haar wavelet encoding (brdf-wavelet), decoded per
///                sample on the GPU, renders the same image from the table, reports the PSNR and
///                relative error of the wavelet image against it and writes OUT-table.png
///
///   --sheet FILE writes a contact sheet of every picture in the bake
///
/// Exit status: 0 ok, 1 --min-psnr was not met, 2 error (including no GPU adapter).
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The bake's folder (made by brdf-bake, with --env for rendering).
    bake: PathBuf,

    /// The picture to write (PNG).
    #[arg(long, short, value_name = "FILE.png", required_unless_present_any = ["window", "sheet"])]
    out: Option<PathBuf>,

    /// The MERL table, when it is no longer where the bake read it (its sha256 must match).
    #[arg(long, value_name = "FILE")]
    material: Option<PathBuf>,

    /// Which BRDF the estimators evaluate: the MERL table (nearest lookup), or its Haar wavelet
    /// encoding (brdf-wavelet; Claustres et al. 2007), decoded on the GPU at --wavelet-lod.
    #[arg(long, value_enum, default_value_t = BrdfArg::Table)]
    brdf: BrdfArg,

    /// The wavelet-brdf asset for --brdf wavelet, made from the bake's material. Default: the
    /// bake's own (its manifest's wavelet-brdf output, which brdf-wavelet MATERIAL --out-dir BAKE
    /// and brdf-bake --wavelet-ratio R add).
    #[arg(long, value_name = "FILE")]
    wavelet: Option<PathBuf>,

    /// Level of detail of the wavelet reconstruction, from 0 (full resolution) to log2 of the
    /// grid side (the hemisphere's mean, at most 8); fractions blend two levels.
    #[arg(long, value_name = "L", default_value_t = 0.0, value_parser = parse_lod)]
    wavelet_lod: f64,

    /// The mesh: sphere, torus, or a Wavefront OBJ file (scaled to the unit sphere).
    #[arg(long, default_value = "sphere", value_name = "sphere|torus|FILE.obj")]
    mesh: String,

    /// The estimator.
    #[arg(long, value_enum, default_value_t = ModeArg::Reference)]
    mode: ModeArg,

    /// Samples per pixel and frame: a power of two from 1 up to the bake's samples per vector (256
    /// by default); in reference, fis and prefiltered each sample is a direction drawn from the
    /// material's tables and, where the mode samples a light, one drawn from the light. Default:
    /// 64 for reference, 16 for fis and prefiltered. For the adaptive modes, the frame's budget in
    /// mean samples per covered pixel (any number from 1; default 8 for adaptive, 4 for
    /// adaptive-prefiltered). Within --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    spp: Option<u32>,

    /// Frames averaged, from 1; each pixel's frames walk through its own sequence of points (render
    /// crate docs, "Samples"). Default: for reference, as many as the bake's vectors hold samples
    /// at this spp (32 at 64 spp with the default bake: 2048 directions of each strategy); 8 for
    /// fis and prefiltered (more frames average their noise away, not their bias). Within
    /// --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    frames: Option<u32>,

    /// Adaptive modes: anti-aliasing by extra pyramid levels, 1, 4 or 16 render pixels per output
    /// pixel (001 section 4.3).
    #[arg(long, value_name = "1|4|16", default_value_t = 1, value_parser = parse_aa)]
    aa: usize,

    /// Adaptive modes: one prediction per block of 2^L x 2^L pixels, L from 0 (every pixel, as the
    /// paper; 2, the default, costs a sixteenth: cargo bench -p brdf-preview --bench adaptive); a
    /// level above the pyramid's top predicts at the top.
    #[arg(long, value_name = "L", default_value_t = 2)]
    predict_level: usize,

    /// Adaptive modes: how the budget is shared among the shaded blocks: in proportion to the
    /// predicted variance (the paper: every pixel equally noisy), to sqrt(pixels x variance)
    /// (std-dev: the least total squared error for the budget), or to sqrt(pixels) (area, the
    /// default: the same with every pixel's variance taken equal; it wins the benchmark,
    /// cargo bench -p brdf-preview --bench adaptive).
    #[arg(long, value_enum, default_value_t = AllocationArg::Area)]
    allocation: AllocationArg,

    /// Adaptive modes: weight the up-sampling by how alike the specular lobes of the two pixels
    /// are (Tokuyoshi's spherical-Gaussian inner product, 003 eq. 4).
    #[arg(long)]
    lobe_weight: bool,

    /// adaptive-prefiltered: the shaded blocks read the Phong layer N layers sharper than the one
    /// the bake picks for the view (each a lobe half as wide; the sharpest at most), N from 0. The bake's
    /// pick suits 16 samples per pixel; a shaded block takes tens, and sharper layers blur less
    /// (crate render, module adaptive, "Shading": gold-paint under potsdamer 46.2 dB at 0, 50.5
    /// at 1; under quarry's sun sharper layers cost noise).
    #[arg(long, value_name = "N", default_value_t = render::adaptive::LAYER_SHIFT)]
    layer_shift: u32,

    /// Adaptive modes: also write OUT-debug.png, the frame's debug views (level each pixel was
    /// shaded at, samples per pixel, predicted bandwidth and variance).
    #[arg(long)]
    debug_views: bool,

    /// Image size, WIDTHxHEIGHT, each side from 1 to 8192. Within --max-samples.
    #[arg(long, value_name = "WxH", default_value = "256x256", value_parser = parse_size)]
    size: (usize, usize),

    /// Exposure in stops, from -64 to 64; default: the environment's log-average luminance maps to
    /// 0.18.
    #[arg(long, value_name = "EV", allow_negative_numbers = true, value_parser = parse_exposure)]
    exposure: Option<f32>,

    /// Camera azimuth and elevation in degrees, finite numbers (it orbits the mesh, looking at its
    /// centre; 0,0 looks from +x towards -x, horizontally).
    #[arg(long, value_name = "AZ,EL", default_value = "0,0", value_parser = parse_camera, allow_hyphen_values = true)]
    camera: (f32, f32),

    /// Mixed into every pixel's sample choice: any whole number from 0 to 4294967295.
    #[arg(long, default_value_t = 0)]
    seed: u32,

    /// Also render on the CPU with the same estimator and samples; report PSNR and relative error
    /// and write OUT-difference.png. For the adaptive modes, count the pixels the GPU predicted
    /// at another level than the CPU predicts (exit 1 over 2%), compare with the same frame
    /// (the GPU's predictions, the same plan) shaded on the CPU (reported as "cpu") and report
    /// psnr_db against the converged estimate
    /// (--converged N samples per strategy, 256 by default) and, without anti-aliasing,
    /// ceiling_db: the PSNR of the same plan with its shaded blocks given the converged values
    /// (when psnr_db is near it, more --spp will not help; it is as exact as the converged
    /// estimate, whose noise it carries into the up-sampled pixels).
    #[arg(long)]
    validate: bool,

    /// Also render the independent converged estimate with N samples per strategy (from 1; three
    /// strategies); report PSNR and mean luminance against it and write OUT-converged.png. Within
    /// --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    converged: Option<u32>,

    /// Exit 1 when a reported PSNR (against the CPU, and against the converged estimate when
    /// asked for) is below this, in dB (a finite number).
    #[arg(long, value_name = "DB", allow_negative_numbers = true, value_parser = parse_psnr)]
    min_psnr: Option<f64>,

    /// The most samples this run may take, a ceiling against runaway work (a mistyped --frames or
    /// --converged): pixels x spp x frames on the GPU (twice with --brdf wavelet), the same again
    /// on the CPU with --validate, and pixels x 3 x N for the converged estimate (--converged N;
    /// --validate in the adaptive modes takes 256). From 1; the default, 2^32, is about a minute
    /// of a GPU or an hour of CPU: raise it for a deliberate long run.
    #[arg(long, value_name = "N", default_value_t = 1 << 32, value_parser = parse_samples)]
    max_samples: u64,

    /// Write a contact sheet of every picture the bake holds (PNG).
    #[arg(long, value_name = "FILE.png")]
    sheet: Option<PathBuf>,

    /// Open an interactive window instead of rendering a file (needs a display): the render
    /// refines frame by frame; drag to orbit, scroll to zoom, 1/2/3 switch modes, D cycles the
    /// debug views (normals, prefiltered layer, sample slice), +/- exposure, R resets the camera,
    /// Esc or Q quits.
    #[arg(long)]
    window: bool,

    #[command(flatten)]
    window_options: window::Options,

    /// Print one JSON object (mode, psnr_db, relative_error, ms_per_frame, ... and the files
    /// written) on stdout; the report goes to stderr.
    #[arg(long)]
    json: bool,

    /// No progress bar (it shows on a terminal once a run takes a second, never with --json).
    #[arg(long)]
    quiet: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum BrdfArg {
    Table,
    Wavelet,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ModeArg {
    Reference,
    Fis,
    Prefiltered,
    Adaptive,
    AdaptivePrefiltered,
}

impl ModeArg {
    /// The estimator of the shaded pixels.
    fn estimator(self) -> Mode {
        match self {
            ModeArg::Reference | ModeArg::Adaptive => Mode::Reference,
            ModeArg::Fis => Mode::Fis,
            ModeArg::Prefiltered | ModeArg::AdaptivePrefiltered => Mode::Prefiltered,
        }
    }

    fn is_adaptive(self) -> bool {
        matches!(self, ModeArg::Adaptive | ModeArg::AdaptivePrefiltered)
    }

    /// The name on the command line and in JSON.
    fn name(self) -> &'static str {
        match self {
            ModeArg::Adaptive => "adaptive",
            ModeArg::AdaptivePrefiltered => "adaptive-prefiltered",
            other => other.estimator().name(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum AllocationArg {
    Variance,
    StdDev,
    Area,
}

fn parse_aa(text: &str) -> Result<usize, String> {
    match text.trim() {
        "1" => Ok(1),
        "4" => Ok(2),
        "16" => Ok(4),
        other => Err(format!("{other:?}: anti-aliasing is 1, 4 or 16 render pixels per pixel")),
    }
}

fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let (w, h) = cli::parse_size(text)?;
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(format!("{w}x{h}: each side must be between 1 and 8192"));
    }
    Ok((w, h))
}

fn parse_lod(text: &str) -> Result<f64, String> {
    cli::parse_finite(text, 0.0, f64::from(asset::MAX_WAVELET_SIDE.ilog2()))
}

fn parse_exposure(text: &str) -> Result<f32, String> {
    cli::parse_finite(text, -64.0, 64.0).map(|ev| ev as f32)
}

fn parse_psnr(text: &str) -> Result<f64, String> {
    cli::parse_finite(text, f64::MIN, f64::MAX).map_err(|_| "expected a finite number of dB".to_string())
}

fn parse_samples(text: &str) -> Result<u64, String> {
    match text.trim().parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err("expected a whole number of samples from 1".to_string()),
    }
}

fn parse_camera(text: &str) -> Result<(f32, f32), String> {
    let parse = |s: &str| match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("{s:?}: {v} degrees is not a finite angle")),
        Err(e) => Err(format!("{s:?}: {e}")),
    };
    let (a, e) = text.split_once(',').ok_or_else(|| format!("expected AZ,EL in degrees, got {text:?}"))?;
    Ok((parse(a)?, parse(e)?))
}

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    // Where the outputs go must exist before anything is rendered.
    for path in args.out.iter().chain(&args.sheet) {
        check_output_folder(path)?;
    }
    let mut loaded = bake::load(&args.bake, args.material.as_deref())?;
    if args.brdf == BrdfArg::Wavelet {
        let (path, brdf) = match &args.wavelet {
            Some(path) => (path.clone(), bake::load_wavelet(path, &loaded)?),
            None => bake::bake_wavelet(&loaded)?,
        };
        let levels = brdf.grid().levels() as f64;
        if !(0.0..=levels).contains(&args.wavelet_lod) {
            bail!("--wavelet-lod {} is outside 0 to {levels} (the levels of {})", args.wavelet_lod, path.display());
        }
        loaded.material.wavelet = Some(render::Wavelet { brdf, lod: args.wavelet_lod });
    } else if args.wavelet.is_some() {
        bail!("--wavelet names the asset for --brdf wavelet; add --brdf wavelet to render with it");
    }
    // (path, role, PNG bytes): every output is encoded before any is written.
    let mut files: Vec<(PathBuf, &'static str, Vec<u8>)> = Vec::new();
    let mut report = Vec::new();
    let mut value = json!({});
    if let Some(path) = &args.sheet {
        let sheet = contact_sheet(&loaded)?;
        files.push((path.clone(), "contact-sheet", png(&sheet.rgb, sheet.width, sheet.height)?));
    }
    let mut problems = Vec::new();
    let progress = cli::Progress::new(args.quiet || args.json);
    if args.out.is_some() || args.window {
        let Some(lighting) = &loaded.lighting else {
            bail!(
                "{}: the bake has no environment, nothing to light the material with: bake it with brdf-bake --env",
                args.bake.display()
            );
        };
        if args.mode.is_adaptive() {
            if args.window {
                bail!("--window renders the reference, fis and prefiltered modes; the adaptive modes render to a file");
            }
            let out = args.out.as_ref().expect("clap requires --out without --window");
            let step = render_adaptive(&args, &loaded, lighting, out, &progress)?;
            files.extend(step.files);
            report.extend(step.report);
            problems.extend(step.problems);
            value = step.value;
        } else {
            let mode = args.mode.estimator();
            let settings = Settings::previewer(mode, &loaded.material.samples, args.spp, args.frames, args.seed);
            let scene = scene(&args)?;
            let pixels = (scene.width * scene.height) as u128;
            let gpu_samples = pixels * u128::from(settings.spp) * u128::from(settings.frames);
            let renders = if loaded.material.wavelet.is_some() { 2 } else { 1 };
            check_work(
                &args,
                &[
                    ("on the GPU", renders * gpu_samples),
                    ("for --validate on the CPU", if args.validate { gpu_samples } else { 0 }),
                    ("for --converged on the CPU", pixels * 3 * u128::from(args.converged.unwrap_or(0))),
                ],
            )?;
            let preview = preview(&args, lighting);
            if args.window {
                return window::run(&loaded.material, lighting, &scene, &settings, &preview, &args.window_options);
            }
            let gpu = open_gpu()?;
            let out = args.out.as_ref().expect("clap requires --out without --window");
            let mut renderer = gpu::preview::Renderer::new(&gpu, &scene, &loaded.material, lighting)?;
            progress.step(format!("{} on the GPU", mode.name()));
            let start = Instant::now();
            let image = renderer.render_frames(&settings)?;
            check_finite(&args, &image.rgb, "the GPU render")?;
            let ms_per_frame = start.elapsed().as_secs_f64() * 1e3 / f64::from(settings.frames);
            let picture = metrics::tonemap(&image, &preview);
            let names = names(&loaded.manifest);
            let brdf = match &loaded.material.wavelet {
                Some(w) => format!("wavelet {}:1, lod {}", picture::format_number(w.brdf.ratio()), w.lod),
                None => "table".to_string(),
            };
            let caption = format!(
                "{} | {} | {brdf} | {} spp x {} frames | {}x{} | exposure {:+.2} EV",
                names,
                mode.name(),
                settings.spp,
                settings.frames,
                scene.width,
                scene.height,
                preview.exposure_ev
            );
            let captioned = with_caption(&picture, scene.width, scene.height, &caption);
            files.push((out.clone(), "preview", png(&captioned.rgb, captioned.width, captioned.height)?));
            report.push(format!(
                "{}: {} on {} ({}), {:.1} ms per frame",
                out.display(),
                mode.name(),
                gpu.adapter_summary(),
                args.mesh,
                ms_per_frame
            ));
            value = json!({
                "bake": args.bake.display().to_string(),
                "mode": mode.name(),
                "brdf": match args.brdf { BrdfArg::Table => "table", BrdfArg::Wavelet => "wavelet" },
                "spp": settings.spp,
                "frames": settings.frames,
                "width": scene.width,
                "height": scene.height,
                "exposure_ev": preview.exposure_ev,
                "adapter": gpu.adapter_summary(),
                "ms_per_frame": ms_per_frame,
                "mean_luminance": metrics::mean_luminance(&image),
            });

            if loaded.material.wavelet.is_some() {
                // What the compression costs: the same render from the table itself.
                let table_material = render::Material { wavelet: None, ..loaded.material.clone() };
                progress.step(format!("{} from the table on the GPU", mode.name()));
                let table =
                    gpu::preview::Renderer::new(&gpu, &scene, &table_material, lighting)?.render_frames(&settings)?;
                check_finite(&args, &table.rgb, "the GPU render from the table")?;
                let table_picture = metrics::tonemap(&table, &preview);
                let psnr = metrics::psnr_db(&picture, &table_picture);
                let relative = metrics::relative_error(&image.rgb, &table.rgb);
                files.push((sibling(out, "table"), "table", png(&table_picture, scene.width, scene.height)?));
                report.push(format!(
                "against the table (same estimator, same samples, the MERL table's nearest lookup): PSNR {} dB,                  relative error {relative:.3}",
                db(psnr)
            ));
                value["against_table"] = json!({ "psnr_db": json_db(psnr), "relative_error": relative });
            }
            if args.validate {
                progress.step(format!("{} on the CPU (--validate)", mode.name()));
                let cpu = render::render_with_progress(&scene, &loaded.material, lighting, &settings, &|done, all| {
                    progress.work(done, all)
                })?;
                check_finite(&args, &cpu.rgb, "the CPU render")?;
                let cpu_picture = metrics::tonemap(&cpu, &preview);
                let psnr = metrics::psnr_db(&picture, &cpu_picture);
                let relative = metrics::relative_error(&image.rgb, &cpu.rgb);
                let coverage = image.covered.iter().zip(&cpu.covered).filter(|(a, b)| a != b).count();
                let difference =
                    picture::layout::difference(&picture, &cpu_picture, scene.width, scene.height, "GPU - CPU");
                files.push((
                    sibling(out, "difference"),
                    "difference",
                    png(&difference.rgb, difference.width, difference.height)?,
                ));
                report.push(format!(
                "against the CPU (same estimator, same samples): PSNR {} dB, relative error {relative:.2e}, {coverage} \
                 pixels covered by one renderer only",
                db(psnr)
            ));
                value["psnr_db"] = json_db(psnr);
                value["relative_error"] = json!(relative);
                value["coverage_mismatches"] = json!(coverage);
                check_psnr(&args, "against the CPU", psnr, &mut problems);
            }
            if let Some(n) = args.converged {
                let Converged { image: converged, picture: converged_picture, psnr, relative } =
                    converged(&args, &scene, &loaded.material, lighting, n, (&image, &picture), &preview, &progress)?;
                let luminance_ratio = metrics::mean_luminance(&image) / metrics::mean_luminance(&converged);
                files.push((
                    sibling(out, "converged"),
                    "converged",
                    png(&converged_picture, scene.width, scene.height)?,
                ));
                report.push(format!(
                "against the converged estimate ({n} samples per strategy): PSNR {} dB, relative error {relative:.3}, \
                 mean luminance ratio {luminance_ratio:.4}",
                db(psnr)
            ));
                value["converged"] = json!({
                    "samples_per_strategy": n,
                    "psnr_db": json_db(psnr),
                    "relative_error": relative,
                    "mean_luminance_ratio": luminance_ratio,
                });
                check_psnr(&args, "against the converged estimate", psnr, &mut problems);
            }
        }
    }

    progress.finish();
    // Every output is made; now write them, so that an error leaves none behind.
    for (path, _, bytes) in &files {
        asset::write_atomic(path, bytes).with_context(|| format!("writing {}", path.display()))?;
    }
    let written: Vec<String> = files.iter().map(|(p, _, _)| p.display().to_string()).collect();
    value["files"] = files
        .iter()
        .map(|(path, role, bytes)| {
            json!({
                "path": path.display().to_string(),
                "format": "png",
                "role": role,
                "size_bytes": bytes.len(),
                "sha256": asset::hex(&asset::sha256(bytes)),
            })
        })
        .collect();
    Ok(cli::finish(args.json, &value, &report, &problems, &written))
}

/// What one rendering step made: files (path, role, PNG bytes), report lines, problems and the
/// JSON object.
struct Step {
    files: Vec<(PathBuf, &'static str, Vec<u8>)>,
    report: Vec<String>,
    problems: Vec<String>,
    value: serde_json::Value,
}

/// `--mode adaptive` and `--mode adaptive-prefiltered`: one frame on the GPU
/// (`gpu::preview::Renderer::render_adaptive`).
fn render_adaptive(
    args: &Args,
    loaded: &bake::Loaded,
    lighting: &render::Lighting,
    out: &Path,
    progress: &cli::Progress,
) -> Result<Step> {
    let bandwidths = loaded.bandwidths.as_ref().ok_or_else(|| {
        anyhow!(
            "{}: the bake has no environment bandwidth and atlas: bake it with brdf-bake --env",
            args.bake.display()
        )
    })?;
    let mode = args.mode.estimator();
    let settings = render::adaptive::Settings {
        supersample: args.aa,
        predict_level: args.predict_level,
        allocation: match args.allocation {
            AllocationArg::Variance => render::adaptive::Allocation::Variance,
            AllocationArg::StdDev => render::adaptive::Allocation::StdDev,
            AllocationArg::Area => render::adaptive::Allocation::Area,
        },
        lobe_weight: args.lobe_weight,
        layer_shift: args.layer_shift,
        seed: args.seed,
        ..render::adaptive::Settings::new(mode, args.spp.unwrap_or(if mode == Mode::Reference { 8 } else { 4 }))
    };
    let scene = scene(args)?;
    let ss = settings.supersample;
    let pixels = (scene.width * ss * scene.height * ss) as u128;
    let frame_samples = pixels * u128::from(settings.spp);
    let converged_samples = if args.validate || args.converged.is_some() {
        (scene.width * scene.height) as u128 * 3 * u128::from(args.converged.unwrap_or(256))
    } else {
        0
    };
    check_work(
        args,
        &[
            // A first frame compiles the pipelines, then the frame that is timed.
            ("on the GPU", 2 * frame_samples),
            ("for --validate on the CPU", if args.validate { frame_samples } else { 0 }),
            ("for the converged estimate on the CPU", converged_samples),
        ],
    )?;
    let preview = preview(args, lighting);
    let gpu = open_gpu()?;
    let render_scene = Scene { width: scene.width * ss, height: scene.height * ss, ..scene.clone() };
    let mut renderer = gpu::preview::Renderer::new(&gpu, &render_scene, &loaded.material, lighting)?;
    renderer.set_bandwidths(bandwidths)?;
    progress.step(format!("{} on the GPU", args.mode.name()));
    // A driver may compile a pipeline at its first dispatch (lavapipe does, tens of
    // milliseconds): a frame first, so that ms_per_frame times the frame. The G-buffer and its
    // upload are the camera's, made once for all its frames as the other modes' raster pass is.
    renderer.render_adaptive(&loaded.material, lighting, &settings, Default::default())?;
    let geometry = renderer.adaptive_geometry(ss)?;
    // The frame's buffers come back after its timings, for the views and the checks that read them.
    let details = args.debug_views || args.validate || args.converged.is_some();
    let options = gpu::preview::FrameOptions { details, ..Default::default() };
    let frame = renderer.render_adaptive(&loaded.material, lighting, &settings, options)?;
    check_finite(args, &frame.image.rgb, "the GPU's adaptive frame")?;
    let t = frame.timings;
    let ms_per_frame = t.total_ms;
    let picture = metrics::tonemap(&frame.image, &preview);
    let aa = settings.supersample * settings.supersample;
    // The pre-convolved estimator's layers, where they are not the bake's.
    let layers = match (mode, settings.layer_shift) {
        (Mode::Prefiltered, n) if n > 0 => format!(" ({n} layer{} sharper)", if n == 1 { "" } else { "s" }),
        _ => String::new(),
    };
    let caption = format!(
        "{} | {}{layers} | {} spp budget, {} samples | shaded fraction {:.3} | AA {aa}x | {}x{} | exposure {:+.2} EV",
        names(&loaded.manifest),
        args.mode.name(),
        settings.spp,
        frame.samples,
        frame.shaded_fraction(),
        scene.width,
        scene.height,
        preview.exposure_ev
    );
    let captioned = with_caption(&picture, scene.width, scene.height, &caption);
    let mut files = vec![(out.to_path_buf(), "preview", png(&captioned.rgb, captioned.width, captioned.height)?)];
    if args.debug_views {
        let sheet = adaptive::debug_views(
            &frame,
            settings.allocation,
            &picture,
            &format!("{}: {}", args.mode.name(), names(&loaded.manifest)),
        );
        files.push((sibling(out, "debug"), "debug-views", png(&sheet.rgb, sheet.width, sheet.height)?));
    }
    let steps = match (t.submissions, t.gpu_clock) {
        (1, true) => format!(
            "one submission; on the GPU's clock prediction {:.1}, pyramids, plan and samples {:.1}, shading, \
             up-sampling and output {:.1}",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
        (1, false) => "one submission".to_string(),
        _ => format!(
            "prediction, pyramids and plan {:.1} on the GPU, samples {:.1} on the CPU, shading, up-sampling and output \
             {:.1} on the GPU",
            t.predict_ms, t.plan_ms, t.shade_ms
        ),
    };
    let mut report = vec![format!(
        "{}: {} on {} ({}), {ms_per_frame:.1} ms ({steps}; the camera's G-buffer on the CPU before, once: {:.1}); \
         shaded fraction {:.4}, {} samples of a budget of {}",
        out.display(),
        args.mode.name(),
        gpu.adapter_summary(),
        args.mesh,
        t.gbuffer_ms,
        frame.shaded_fraction(),
        frame.samples,
        frame.budget
    )];
    let mut value = json!({
        "bake": args.bake.display().to_string(),
        "mode": args.mode.name(),
        "adapter": gpu.adapter_summary(),
        "spp": settings.spp,
        "aa": aa,
        "predict_level": settings.predict_level,
        "allocation": settings.allocation.name(),
        "lobe_weight": settings.lobe_weight,
        "layer_shift": settings.layer_shift,
        "width": scene.width,
        "height": scene.height,
        "exposure_ev": preview.exposure_ev,
        "ms_per_frame": ms_per_frame,
        "timings_ms": {
            "gbuffer": t.gbuffer_ms,
            "prediction": t.predict_ms,
            "plan_and_samples": t.plan_ms,
            "shading": t.shade_ms,
            "submissions": t.submissions,
            "gpu_clock": t.gpu_clock,
        },
        "shaded_fraction": frame.shaded_fraction(),
        "shaded_per_level": frame.shaded_per_level,
        "samples": frame.samples,
        "budget": frame.budget,
        "mean_luminance": metrics::mean_luminance(&frame.image),
    });
    let mut problems = Vec::new();
    if args.validate {
        // The CPU's own prediction: the levels equal but where a direction on the edge of a
        // nearest texel reads its neighbour in f32 (the tests hold 98% of them equal). Only the
        // predictions are read, so its blocks are not shaded.
        progress.step(format!("{} on the CPU (--validate)", args.mode.name()));
        let mut unshaded = |blocks: &[(u32, u32)]| Ok(vec![[0.0f32; 3]; blocks.len()]);
        let hooks = render::adaptive::Hooks { shader: Some(&mut unshaded), ..Default::default() };
        let own = render::adaptive::render_with(&geometry, &loaded.material, lighting, bandwidths, &settings, hooks)?;
        let predicted =
            frame.details().predictions.iter().zip(&own.details().predictions).filter(|(g, _)| g.level >= 0);
        let (pixels, differ) =
            predicted.fold((0usize, 0usize), |(n, d), (g, c)| (n + 1, d + usize::from(g.level != c.level)));
        // The same frame with the GPU's predictions on the CPU: the plan is the same (the weights
        // to f32 rounding: the GPU's are f32), the values equal to rounding.
        let mut replay = render::adaptive::replay_predictor(&frame.details().predictions);
        let hooks = render::adaptive::Hooks { predictor: Some(&mut replay), ..Default::default() };
        let cpu = render::adaptive::render_with(&geometry, &loaded.material, lighting, bandwidths, &settings, hooks)?;
        let cpu_picture = metrics::tonemap(&cpu.image, &preview);
        let psnr = metrics::psnr_db(&picture, &cpu_picture);
        let relative = metrics::relative_error(&frame.image.rgb, &cpu.image.rgb);
        let plan = frame.details().plan.compare(&cpu.details().plan, 1e-5);
        let same_plan = plan.is_ok();
        report.push(format!(
            "against the CPU: {differ} of {pixels} pixels predicted at another level than the CPU predicts; \
             with the GPU's predictions ({}): PSNR {} dB, relative error {relative:.2e}",
            match &plan {
                Ok(worst) => format!("the same plan, weights within {worst:.1e}"),
                Err(e) => format!("NOT the same plan: {e}"),
            },
            db(psnr)
        ));
        value["cpu"] = json!({
            "psnr_db": json_db(psnr),
            "relative_error": relative,
            "same_plan": same_plan,
            "prediction": { "pixels": pixels, "levels_differ": differ },
        });
        if !same_plan {
            problems.push(
                "the GPU's adaptive frame was planned differently from the CPU's with the same predictions".to_string(),
            );
        }
        if 50 * differ > pixels {
            problems.push(format!(
                "{differ} of {pixels} pixels were predicted at another level on the GPU than on the CPU"
            ));
        }
        check_psnr(args, "against the CPU", psnr, &mut problems);
    }
    if args.validate || args.converged.is_some() {
        let n = args.converged.unwrap_or(256);
        let Converged { image: converged, picture: converged_picture, psnr, relative } =
            converged(args, &scene, &loaded.material, lighting, n, (&frame.image, &picture), &preview, progress)?;
        files.push((sibling(out, "converged"), "converged", png(&converged_picture, scene.width, scene.height)?));
        report.push(format!(
            "against the converged estimate ({n} samples per strategy): PSNR {} dB, relative error {relative:.3}",
            db(psnr)
        ));
        value["psnr_db"] = json_db(psnr);
        value["relative_error"] = json!(relative);
        value["converged"] = json!({ "samples_per_strategy": n, "psnr_db": json_db(psnr), "relative_error": relative });
        check_psnr(args, "against the converged estimate", psnr, &mut problems);
        if ss == 1 {
            // The same plan with the converged values in its shaded blocks: the up-sampling's
            // error alone, the PSNR no budget can pass (render pixels are the converged
            // estimate's pixels only without anti-aliasing).
            let mut exact = render::adaptive::exact_shader(&converged);
            let mut replay = render::adaptive::replay_predictor(&frame.details().predictions);
            let hooks = render::adaptive::Hooks {
                predictor: Some(&mut replay),
                shader: Some(&mut exact),
                ..Default::default()
            };
            let ceiling =
                render::adaptive::render_with(&geometry, &loaded.material, lighting, bandwidths, &settings, hooks)?;
            let ceiling = metrics::psnr_db(&metrics::tonemap(&ceiling.image, &preview), &converged_picture);
            report.push(format!(
                "the plan's ceiling (its shaded blocks given the converged values, as exact as they are): PSNR {} dB; \
                 near it, more --spp does not help, the up-sampling is the error",
                db(ceiling)
            ));
            value["ceiling_db"] = json_db(ceiling);
        }
    }
    Ok(Step { files, report, problems, value })
}

/// The GPU, without the spurious line a headless run prints where there is no Wayland session
/// (`cli::without_stderr_lines`).
/// The independent converged estimate of a render, and how far the render is from it.
struct Converged {
    image: render::Image,
    /// Its tone-mapped picture.
    picture: Vec<u8>,
    /// PSNR of the render's picture against it.
    psnr: f64,
    /// Relative error of the render's radiance against it.
    relative: f64,
}

/// Renders the converged estimate with `n` samples per strategy and measures `rendered` (the
/// image and its picture) against it.
#[allow(clippy::too_many_arguments)]
fn converged(
    args: &Args,
    scene: &Scene,
    material: &render::Material,
    lighting: &render::Lighting,
    n: u32,
    (image, picture): (&render::Image, &[u8]),
    preview: &envmap::Preview,
    progress: &cli::Progress,
) -> Result<Converged> {
    progress.step(format!("converged estimate, {n} samples per strategy, on the CPU"));
    let converged = render::converged::converged_with_progress(
        scene,
        material,
        lighting,
        n,
        u64::from(args.seed),
        &|done, all| progress.work(done, all),
    )?;
    check_finite(args, &converged.rgb, "the converged estimate")?;
    let converged_picture = metrics::tonemap(&converged, preview);
    let psnr = metrics::psnr_db(picture, &converged_picture);
    let relative = metrics::relative_error(&image.rgb, &converged.rgb);
    Ok(Converged { image: converged, picture: converged_picture, psnr, relative })
}

fn open_gpu() -> Result<gpu::Gpu> {
    Ok(cli::without_stderr_lines(cli::is_wayland_session_warning, gpu::Gpu::new)?)
}

/// An output's folder must exist: found before the render rather than after it (nothing is
/// created; `asset::write_atomic`).
fn check_output_folder(path: &Path) -> Result<()> {
    let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        bail!("writing {}: the folder {} does not exist (create it first)", path.display(), folder.display());
    }
    Ok(())
}

/// The work the arguments ask for, `(what, samples)` by part, within --max-samples; otherwise an
/// error that gives the parts and how to lift the ceiling.
fn check_work(args: &Args, parts: &[(&str, u128)]) -> Result<()> {
    let total: u128 = parts.iter().map(|(_, n)| n).sum();
    if total <= u128::from(args.max_samples) {
        return Ok(());
    }
    let listed: Vec<String> = parts.iter().filter(|(_, n)| *n > 0).map(|(what, n)| format!("{n} {what}")).collect();
    bail!(
        "this run would take {total} samples ({}; --size, --spp, --frames and --converged set them), above the \
         ceiling of {} (--max-samples): ask for less, or raise --max-samples for a deliberate long run",
        listed.join(", "),
        args.max_samples
    )
}

/// A render with a pixel that is not a finite number is an error naming what it was rendered
/// from (a damaged or absurd asset can make a BRDF overflow), never a picture with exit 0.
fn check_finite(args: &Args, rgb: &[f32], what: &str) -> Result<()> {
    let bad = rgb.chunks_exact(3).filter(|p| p.iter().any(|v| !v.is_finite())).count();
    if bad == 0 {
        return Ok(());
    }
    let source = match (args.brdf, &args.wavelet) {
        (BrdfArg::Wavelet, Some(path)) => path.display().to_string(),
        (BrdfArg::Wavelet, None) => format!("the wavelet-brdf asset of {}", args.bake.display()),
        (BrdfArg::Table, _) => format!("the bake in {}", args.bake.display()),
    };
    bail!(
        "rendering {source}: {what} has {bad} of {} pixels that are not finite numbers (an asset's values overflow)",
        rgb.len() / 3
    )
}

/// How pictures are tone mapped: --exposure, or the environment's automatic exposure.
fn preview(args: &Args, lighting: &render::Lighting) -> envmap::Preview {
    match args.exposure {
        Some(ev) => envmap::Preview { exposure_ev: ev, tone_map: envmap::ToneMap::Reinhard },
        None => metrics::auto_preview(lighting.mips.level(0)),
    }
}

/// An 8-bit RGB picture as PNG bytes.
fn png(rgb: &[u8], width: usize, height: usize) -> Result<Vec<u8>> {
    Ok(envmap::encode_png_rgb8(width, height, rgb)?)
}

/// Every picture of the bake on one labelled page (`bake::sheet`).
fn contact_sheet(loaded: &bake::Loaded) -> Result<Canvas> {
    Ok(bake::sheet::contact_sheet(&loaded.dir, &loaded.manifest)?)
}

/// The scene the arguments describe.
fn scene(args: &Args) -> Result<Scene> {
    let mesh = match args.mesh.as_str() {
        "sphere" => Mesh::sphere(1.0, 128, 64),
        "torus" => Mesh::torus(0.7, 0.3, 128, 48),
        path => {
            // A regular file only (a FIFO or a device is refused without blocking), its size
            // checked against the mesh limit before it is read.
            let bytes = fsguard::read_regular(Path::new(path), Mesh::MAX_OBJ_BYTES as u64)
                .with_context(|| format!("reading {path}"))?;
            let text = String::from_utf8(bytes).map_err(|_| anyhow!("reading {path}: not utf-8 text (an obj file)"))?;
            Mesh::from_obj(&text).with_context(|| format!("reading {path}"))?
        }
    };
    let default = Camera::default();
    let (azimuth, elevation) = args.camera;
    let camera = Camera::orbit(
        default.target(),
        default.distance(),
        azimuth.to_radians(),
        elevation.to_radians(),
        default.fov_y(),
    )
    .map_err(|e| anyhow!("--camera: {e}"))?;
    Ok(Scene { mesh, camera, width: args.size.0, height: args.size.1 })
}

/// "material under environment", from the manifest.
fn names(manifest: &asset::BakeManifest) -> String {
    match &manifest.environment {
        Some(env) => format!("{} under {}", manifest.material.name, env.name),
        None => manifest.material.name.clone(),
    }
}

/// `out` with `-suffix` before its extension: preview.png -> preview-difference.png.
fn sibling(out: &Path, suffix: &str) -> PathBuf {
    let stem = out.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    out.with_file_name(format!("{stem}-{suffix}.png"))
}

fn db(psnr: f64) -> String {
    if psnr.is_finite() { format!("{psnr:.2}") } else { "infinite (identical)".to_string() }
}

/// PSNR in JSON: a number, or null for identical pictures (JSON has no infinity).
fn json_db(psnr: f64) -> serde_json::Value {
    if psnr.is_finite() { json!(psnr) } else { serde_json::Value::Null }
}

fn check_psnr(args: &Args, what: &str, psnr: f64, problems: &mut Vec<String>) {
    if let Some(min) = args.min_psnr
        && psnr < min
    {
        problems.push(format!("PSNR {what} is {psnr:.2} dB, below --min-psnr {min}"));
    }
}

/// The picture with a strip of text below it.
fn with_caption(rgb: &[u8], width: usize, height: usize, caption: &str) -> Canvas {
    let scale = if width >= 480 { 2 } else { 1 };
    let line = picture::font::LINE_HEIGHT * scale;
    let lines = wrap(caption, (width.saturating_sub(8)) / (picture::font::ADVANCE * scale));
    let mut canvas = Canvas::new(width, height + 8 + lines.len() * line, picture::BACKGROUND);
    canvas.blit_rgb8(width, height, rgb, 0, 0, 1);
    for (i, text) in lines.iter().enumerate() {
        canvas.text(4, (height + 5 + i * line) as isize, text, scale, picture::INK);
    }
    canvas
}

/// Breaks `text` at ` | ` separators (then anywhere) into lines of at most `columns` characters.
fn wrap(text: &str, columns: usize) -> Vec<String> {
    let columns = columns.max(8);
    let mut lines: Vec<String> = Vec::new();
    for part in text.split(" | ") {
        match lines.last_mut() {
            Some(last) if last.len() + 3 + part.len() <= columns => {
                last.push_str(" | ");
                last.push_str(part);
            }
            _ => {
                let mut rest = part;
                while rest.len() > columns {
                    let (head, tail) = rest.split_at(rest.floor_char_boundary(columns));
                    lines.push(head.to_string());
                    rest = tail;
                }
                lines.push(rest.to_string());
            }
        }
    }
    lines
}
