//! `brdf-bandwidth`: the angular-bandwidth atlas of a MERL BRDF (`000` section 2.4): for every
//! incident direction of a grid, the outgoing lobe as an image, its local bandwidth by wavelets,
//! reduced to a tile of the atlas. A thin layer over the `brdf-atlas` crate.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use brdf_atlas::{Atlas, AtlasBuild, Config, build_atlas};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Build the angular-bandwidth atlas of a MERL BRDF: for each incident direction of a
/// lobes x lobes grid (rows in equal steps of cos theta_i, columns in phi_i), the BRDF's
/// outgoing lobe (luminance) as an image in the frame of its plane of incidence, its local
/// bandwidth from a D4 wavelet decomposition (eps 0.01, c = 2^-2.5) in cycles per radian,
/// reduced to a tile x tile tile by taking the maximum over the pixels of the hemisphere each
/// texel covers. A MERL table is isotropic: the lobes of a row are one image, analysed once.
/// Reports how many lobes reach the analysis grid's limit. Writes, in DIR:
/// bandwidth-atlas.exr (one float channel Y), bandwidth-atlas.png (false colour, log scale) and
/// bandwidth-atlas.asset (the atlas for bandwidth-pca). Parameterizations and layout:
/// data-schema/brdf-atlas.md.
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The folder to write the atlas into (created if missing).
    #[arg(long, short, value_name = "DIR")]
    out: PathBuf,

    /// Incident directions per side of the grid.
    #[arg(long, value_name = "N", default_value_t = Config::default().lobes)]
    lobes: usize,

    /// Texels per side of each lobe's tile (a power of two).
    #[arg(long, value_name = "T", default_value_t = Config::default().tile)]
    tile: usize,

    /// Pixels per side of the image each lobe is analysed on (a power of two from 16, >= the
    /// tile); the highest bandwidth it resolves grows with it.
    #[arg(long = "analysis-size", value_name = "N", default_value_t = Config::default().analysis_size)]
    analysis_size: usize,
}

/// The file names written into `--out`.
const EXR: &str = "bandwidth-atlas.exr";
const PNG: &str = "bandwidth-atlas.png";
const BIN: &str = "bandwidth-atlas.asset";

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()))
}

fn run(args: Args) -> Result<ExitCode> {
    let start = Instant::now();
    let config = Config { lobes: args.lobes, tile: args.tile, analysis_size: args.analysis_size, ..Config::default() };
    config.check()?;
    let table = merl::read_file(&args.material).with_context(|| format!("reading {}", args.material.display()))?;
    let read = start.elapsed();

    let build = with_progress((config.lobes * config.lobes) as u64, |tick| build_atlas(&table, &config, tick))?;
    let built = start.elapsed() - read;

    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let atlas = &build.atlas;
    let (exr, png, bin) = (args.out.join(EXR), args.out.join(PNG), args.out.join(BIN));
    envmap::write_exr(&exr, atlas.width(), atlas.height(), &[("Y", &atlas.data)], envmap::SampleType::F32)
        .with_context(|| format!("writing {}", exr.display()))?;
    let range = envmap::colormap::log_range(&atlas.data, 3.0).unwrap_or((1.0, 1.0));
    let rgb = envmap::colormap::false_colour_log(&atlas.data, range);
    envmap::write_png_rgb8(&png, atlas.width(), atlas.height(), &rgb)
        .with_context(|| format!("writing {}", png.display()))?;
    write_atlas(&bin, atlas, &args.material, &config).with_context(|| format!("writing {}", bin.display()))?;

    report(&args, &config, &build, range);
    cli::outln!(
        "time          {:.2} s: reading {:.2} s, lobes {:.2} s, writing {:.2} s",
        start.elapsed().as_secs_f64(),
        read.as_secs_f64(),
        built.as_secs_f64(),
        (start.elapsed() - read - built).as_secs_f64()
    );
    eprintln!("wrote {}, {} and {}", exr.display(), png.display(), bin.display());
    Ok(ExitCode::SUCCESS)
}

/// Runs `work` with a progress bar on stderr that appears only once the work has taken a second
/// (and only on a terminal). `work` gets the function to call with each number of lobes done.
fn with_progress<T>(len: u64, work: impl FnOnce(&(dyn Fn(usize) + Sync)) -> T) -> T {
    let start = Instant::now();
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
    bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} lobes, {eta} left").expect("a valid template"));
    let shown = AtomicBool::new(false);
    let tick = |n: usize| {
        bar.inc(n as u64);
        if start.elapsed() > Duration::from_secs(1) && !shown.swap(true, Ordering::Relaxed) {
            bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    };
    let out = work(&tick);
    bar.finish_and_clear();
    out
}

fn report(args: &Args, config: &Config, build: &AtlasBuild, range: (f64, f64)) {
    let atlas = &build.atlas;
    let stats = &build.stats;
    let mut sorted: Vec<f32> = atlas.data.clone();
    sorted.sort_by(f32::total_cmp);
    let quantile = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
    let n_lobes = atlas.n_lobes();
    cli::outln!("material      {}", args.material.display());
    cli::outln!(
        "atlas         {} x {} lobes of {} x {} texels ({} x {}), each lobe analysed at {} x {}",
        atlas.lobes_x,
        atlas.lobes_y,
        atlas.tile,
        atlas.tile,
        atlas.width(),
        atlas.height(),
        config.analysis_size,
        config.analysis_size
    );
    cli::outln!(
        "bandwidth     cycles per radian: median {:.3}, 90% {:.3}, 99% {:.3}, max {:.3}; {} of {} texels flat (0)",
        quantile(0.5),
        quantile(0.9),
        quantile(0.99),
        quantile(1.0),
        sorted.iter().filter(|v| **v == 0.0).count(),
        sorted.len()
    );
    let nyquist = stats.nyquist_lobes();
    cli::outln!(
        "nyquist       {nyquist} of {n_lobes} lobes reach the analysis grid's limit ({} texels): {}",
        stats.nyquist_texels,
        if nyquist == 0 {
            "every bandwidth is resolved".to_string()
        } else {
            format!(
                "their bandwidth is a lower bound ({:.2} cycles per radian at a lobe's centre); a larger --analysis-size resolves more",
                config.c / 2.0 * config.analysis_size as f64 / std::f64::consts::PI
            )
        }
    );
    if stats.filled_pixels > 0 {
        cli::outln!(
            "filled        {} lobe pixels had no table data around them: filled from their neighbours",
            stats.filled_pixels
        );
    }
    cli::outln!(
        "png           log colour scale from {:.3} (dark violet) to {:.3} (yellow) cycles per radian, black 0",
        range.0,
        range.1
    );
}

/// Writes the atlas as a `bandwidth-atlas` asset (data-schema/README.md), the input of
/// `bandwidth-pca`.
fn write_atlas(path: &Path, atlas: &Atlas, source: &Path, config: &Config) -> Result<()> {
    let payload = asset::BandwidthAtlas {
        lobes_x: atlas.lobes_x as u32,
        lobes_y: atlas.lobes_y as u32,
        tile: atlas.tile as u32,
        analysis: asset::BandwidthAnalysis {
            parameterization: atlas.parameterization.name().to_string(),
            analysis_size: atlas.analysis_size as u32,
            eps: atlas.eps,
            c: atlas.c,
        },
        data: atlas.data.clone(),
    };
    let provenance = asset::Provenance::of_source(
        source,
        env!("CARGO_PKG_NAME"),
        env!("CARGO_PKG_VERSION"),
        vec![
            ("lobes".to_string(), config.lobes.to_string()),
            ("tile".to_string(), config.tile.to_string()),
            ("analysis_size".to_string(), config.analysis_size.to_string()),
        ],
    )
    .with_context(|| format!("hashing {}", source.display()))?;
    asset::write_file(path, &asset::Asset { provenance, payload: payload.into() })?;
    Ok(())
}
