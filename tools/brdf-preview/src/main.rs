//! `brdf-preview`: renders a bake on the GPU so that a person (or a script) can check it before
//! it ships; validates the GPU image against the CPU reference renderer. Argument parsing,
//! loading and printing around `bake::load`, `gpu::preview` and `render`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, ValueEnum};
use preview::{Brdf, Mode, Outcome, Request};

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
///                selection gives the view, blended, read by few samples; past the sharpest
///                layer the map itself (a mirror's lobe), and no layer sharper than a
///                sample's footprint
///
///   adaptive     bandwidth-driven multi-resolution shading (001 sections 2-3): the bake's
///                environment bandwidth and bandwidth atlas predict each pixel's image bandwidth and
///                variance; only the pixels the prediction asks for are shaded (reference
///                estimator) with a budget of --spp samples per pixel on average (--allocation),
///                the rest is up-sampled (crate render, module adaptive, is the specification)
///
///   adaptive-prefiltered
///                the same with the prefiltered estimator and eq. 10's variance (001 ASFPCS)
///
/// Small bright sources: fis and prefiltered filter only the environment's smooth part, the map
/// clamped at its mean luminance. The light above it (a sun, a softbox, a lit wall) is the
/// map's peaks, sampled from the unfiltered map by multiple importance sampling, so a small
/// bright source keeps its light and no filter spreads it. What the filter does to the smooth
/// part is an approximation, measured against Mitsuba 3 by cargo bench -p brdf-preview --bench
/// mitsuba (docs/benchmarks.md).
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
///   --brdf wavelet-brdf
///                evaluates the BRDF from its Haar wavelet encoding (brdf-wavelet), decoded per
///                sample on the GPU, renders the same image from the table, reports the PSNR and
///                relative error of the wavelet image against it and writes OUT-table.png
///
///   --compare-fit
///                renders the bake's glTF fit (brdf-bake --fit: the closest glTF material, as a
///                MERL table) with the same estimator, samples and camera, writes OUT-fit.png and
///                OUT-fit-difference.png (|material - fit| in 8-bit levels, with its scale), and
///                reports the PSNR of the fit against the material's render and of both against
///                the material's converged estimate (--converged N, 256 by default)
///
///   --sheet FILE writes a contact sheet of every picture in the bake
///
/// Exit status: 0 ok, 1 --min-psnr was not met, 2 error (including no GPU adapter).
#[derive(Debug, Parser)]
#[command(version, about, long_about, verbatim_doc_comment, allow_negative_numbers = true)]
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
    /// encoding (brdf-wavelet; Claustres et al. 2007), decoded on the GPU at --wavelet-brdf-lod.
    #[arg(long, value_enum, default_value_t = BrdfArg::Table)]
    brdf: BrdfArg,

    /// The wavelet-brdf asset for --brdf wavelet-brdf, made from the bake's material. Default: the
    /// bake's own (its manifest's wavelet-brdf output, which brdf-wavelet MATERIAL --out-dir BAKE
    /// and brdf-bake --wavelet-brdf-ratio R add).
    #[arg(long, value_name = "FILE")]
    wavelet_brdf: Option<PathBuf>,

    /// Level of detail of the wavelet reconstruction, from 0 (full resolution) to log2 of the
    /// grid side (the hemisphere's mean, at most 8); fractions blend two levels.
    #[arg(long, value_name = "L", default_value_t = 0.0, value_parser = parse_lod)]
    wavelet_brdf_lod: f64,

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
    /// mean samples per covered pixel (any number from 1; default 16, as fis and prefiltered).
    /// Within --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    spp: Option<u32>,

    /// Frames averaged, from 1; each pixel's frames walk through its own sequence of points (render
    /// crate docs, "Samples"). Default: for reference, as many as the bake's vectors hold samples
    /// at this spp (32 at 64 spp with the default bake: 2048 directions of each strategy); 8 for
    /// fis and prefiltered (whose footprints are sized for spp x frames samples: more frames,
    /// less blur); 8 for the adaptive modes, each frame planned from its own predictions with its
    /// own seed (crate render, module adaptive, "Frames"), adaptive-prefiltered's blocks sized
    /// for their samples x frames. Within --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    frames: Option<u32>,

    /// Adaptive modes: anti-aliasing by extra pyramid levels, 1, 4 or 16 render pixels per output
    /// pixel (001 section 4.3).
    #[arg(long, value_name = "1|4|16", default_value_t = 1, value_parser = parse_aa)]
    aa: usize,

    /// Adaptive modes: one prediction per block of 2^L x 2^L pixels, L from 0 (every pixel, as the
    /// paper; 2, the default, costs a sixteenth: cargo bench -p brdf-preview --bench adaptive); a
    /// level above the pyramid's top predicts at the top. A finer prediction catches a sun-lit
    /// rim's narrow ramp: gold-paint under quarry_01 at 512 x 512 (default camera), 14 pixels more
    /// than 20 levels from a converged estimate at 2, 2 at 1, 0 at 0, for 7% and 25% more time
    /// per frame on lavapipe.
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
    /// the bake picks for the view (each a lobe half as wide; the map itself past the sharpest
    /// at most), N from 0. The bake's pick suits 16 samples per pixel; a shaded block takes
    /// tens, and sharper layers blur less (crate render, module adaptive, "Shading": gold-paint
    /// under quarry 54.70 dB at 0, 55.26 at 1, 55.33 at 2).
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
    /// and write OUT-difference.png. For the adaptive modes, frame by frame: count the pixels the
    /// GPU predicted at another level than the CPU predicts (exit 1 over 2%), compare with the
    /// same frames (the GPU's predictions, the same plans) shaded on the CPU (reported as "cpu")
    /// and report psnr_db against the converged estimate (--converged N samples per strategy, 256
    /// by default) and, without anti-aliasing, ceiling_db: the PSNR of the same plans with their
    /// shaded blocks given the converged values, averaged (when psnr_db is near it, more --spp
    /// or --frames will not help; it is as exact as the converged estimate, whose noise it
    /// carries into the up-sampled pixels).
    #[arg(long)]
    validate: bool,

    /// Also render the independent converged estimate with N samples per strategy (from 1; three
    /// strategies); report PSNR and mean luminance against it and write OUT-converged.png. Within
    /// --max-samples.
    #[arg(long, value_name = "N", value_parser = cli::parse_count_u32)]
    converged: Option<u32>,

    /// Also render the bake's glTF fit (brdf-bake --fit) with the same estimator (reference or
    /// fis), write OUT-fit.png and OUT-fit-difference.png, and report the fit's PSNR against the
    /// material's render and against its converged estimate (--converged N, 256 by default).
    #[arg(long)]
    compare_fit: bool,

    /// Exit 1 when a reported PSNR (against the CPU, and against the converged estimate when
    /// asked for) is below this, in dB (a finite number).
    #[arg(long, value_name = "DB", allow_negative_numbers = true, value_parser = parse_psnr)]
    min_psnr: Option<f64>,

    /// The most samples this run may take, a limit against runaway work (a mistyped --frames or
    /// --converged): pixels x spp x frames on the GPU (once more with --brdf wavelet-brdf, once
    /// more with --compare-fit), the same again on the CPU with --validate, and pixels x 3 x N for
    /// the converged estimate (--converged N; --validate in the adaptive modes and --compare-fit
    /// take 256 without it). From 1; the default, 2^32, is about a minute
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

    /// With --window: once --frames frames are accumulated (1 for a debug view), save what the
    /// window shows (PNG) and exit. For scripts and CI (e.g. under xvfb-run).
    #[arg(long, value_name = "FILE.png", requires = "window")]
    window_screenshot: Option<PathBuf>,

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
    WaveletBrdf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum ModeArg {
    Reference,
    Fis,
    Prefiltered,
    Adaptive,
    AdaptivePrefiltered,
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
    let request = Request {
        bake: args.bake,
        out: args.out,
        material: args.material,
        brdf: match args.brdf {
            BrdfArg::Table => Brdf::Table,
            BrdfArg::WaveletBrdf => Brdf::WaveletBrdf,
        },
        wavelet_brdf: args.wavelet_brdf,
        wavelet_brdf_lod: args.wavelet_brdf_lod,
        mesh: args.mesh,
        mode: match args.mode {
            ModeArg::Reference => Mode::Reference,
            ModeArg::Fis => Mode::Fis,
            ModeArg::Prefiltered => Mode::Prefiltered,
            ModeArg::Adaptive => Mode::Adaptive,
            ModeArg::AdaptivePrefiltered => Mode::AdaptivePrefiltered,
        },
        spp: args.spp,
        frames: args.frames,
        aa: args.aa,
        predict_level: args.predict_level,
        allocation: match args.allocation {
            AllocationArg::Variance => render::adaptive::Allocation::Variance,
            AllocationArg::StdDev => render::adaptive::Allocation::StdDev,
            AllocationArg::Area => render::adaptive::Allocation::Area,
        },
        lobe_weight: args.lobe_weight,
        layer_shift: args.layer_shift,
        debug_views: args.debug_views,
        size: args.size,
        exposure: args.exposure,
        camera: args.camera,
        seed: args.seed,
        validate: args.validate,
        converged: args.converged,
        compare_fit: args.compare_fit,
        min_psnr: args.min_psnr,
        max_samples: args.max_samples,
        sheet: args.sheet,
        window: args.window,
        window_screenshot: args.window_screenshot,
    };
    let host = Host(cli::Progress::new(args.quiet || args.json));
    let outcome = preview::run(&request, &host);
    host.0.finish();
    let rendered = match outcome? {
        Outcome::Window(shown) => {
            if let Some(line) = shown {
                cli::outln!("{line}");
            }
            return Ok(ExitCode::SUCCESS);
        }
        Outcome::Rendered(rendered) => rendered,
    };
    // Every output is made; now write them, so that an error leaves none behind.
    for file in &rendered.files {
        asset::write_atomic(&file.path, &file.bytes).with_context(|| format!("writing {}", file.path.display()))?;
    }
    let written: Vec<String> = rendered.files.iter().map(|f| f.path.display().to_string()).collect();
    let mut value = rendered.json;
    value["files"] = rendered
        .files
        .iter()
        .map(|f| {
            let path = f.path.display().to_string();
            let output = asset::StageOutput::of_bytes(&path, asset::FileFormat::Png, f.role, &f.bytes)
                .expect("a PNG needs no header read");
            serde_json::to_value(output).expect("an output serializes")
        })
        .collect();
    Ok(cli::finish(args.json, &value, &rendered.report, &rendered.problems, &written))
}

/// The progress bar, and the GPU opened without the spurious line a headless run prints where
/// there is no Wayland session (`cli::without_stderr_lines`).
struct Host(cli::Progress);

impl preview::Host for Host {
    fn step(&self, what: String) {
        self.0.step(what);
    }

    fn work(&self, done: u64, total: u64) {
        self.0.work(done, total);
    }

    fn open_gpu(&self) -> Result<gpu::Gpu, gpu::GpuError> {
        cli::without_stderr_lines(cli::is_wayland_session_warning, gpu::Gpu::new)
    }
}
