//! `envmap-bandwidth`: the local bandwidth of an environment map (cycles per radian) or of a
//! texture or area light (cycles per pixel). Argument parsing and printing around
//! `bake::stage::env_bandwidth`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use bake::stage::env_bandwidth::{Mode, Settings};
use bandwidth::Config;
use clap::Parser;

/// Estimate the local angular bandwidth of a lat-long environment map: per pixel, the highest
/// frequency that carries significant energy around it, in cycles per radian of arc on the
/// sphere (the wavelet estimator of the bandwidth crate on ln(1 + luminance), converted through
/// the lat-long mapping). With --spatial, the spatial bandwidth of an image of any shape (a
/// texture, an area light) in cycles per pixel.
///
/// Writes, in DIR: env-bandwidth.exr (the map, one 32-bit float channel Y, the input's size) and
/// env-bandwidth.png (false colour, log scale; cyan: at the grid's Nyquist limit, the true
/// bandwidth may be higher; grey: flat, no significant detail; a legend below the map), and prints
/// the statistics. Pixel fractions count pixels, not solid angle.
///
/// JSON (--json): parameters (mode, eps, c, levels), figures (unit, width, height, pixels, min,
/// median, p95, max over the pixels that are not flat, null when all are, nyquist_fraction,
/// flat_fraction, fft_diagnostic: null unless --fft-diagnostic, else windows, both_positive,
/// one_zero, log2_ratio {p5, p25, p50, p75, p95} of wavelet / fft, spearman) and the files
/// written.
///
/// Exit status: 0 ok, 2 error (unreadable input, a map that is not 2:1 without --spatial, a size
/// the estimator cannot analyse, bad arguments).
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The map: OpenEXR or Radiance HDR (told apart by their first bytes). Without --spatial it
    /// must be a 2:1 lat-long map.
    input: PathBuf,

    /// The folder to write into (created if missing).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Print one JSON object (parameters, figures, files written) on stdout; the report goes to
    /// stderr.
    #[arg(long)]
    json: bool,

    /// Spatial bandwidth in cycles per pixel, for textures and area lights of any shape. The
    /// image is taken as periodic (a tiling texture): both sides must divide by 2^levels;
    /// otherwise use --pad.
    #[arg(long)]
    spatial: bool,

    /// With --spatial: the image has finite extent, zero outside (an area light, a texture on a
    /// finite patch): zero padding to twice the size, estimate, crop (paper 001, section 2.3).
    /// Any size works.
    #[arg(long, requires = "spatial")]
    pad: bool,

    /// Also run the windowed FFT reference (32 x 32 Hann windows, stride 8, 95% energy radius)
    /// and print how the estimate compares: percentiles of log2(wavelet / fft) and Spearman's
    /// rank correlation, in cycles per pixel. A diagnostic: slower, and it measures something
    /// else on real images (see the bandwidth crate docs).
    #[arg(long)]
    fft_diagnostic: bool,

    /// The relative threshold of the estimator (eq. 7), in (0, 1]: a level counts when it and
    /// the finer ones reach eps times the pixel's largest level.
    #[arg(long, default_value_t = Config::default().eps, value_parser = parse_eps)]
    eps: f64,

    /// Number of wavelet levels, 1 to 30 (and no more than the size allows); by default as many as
    /// the size allows.
    #[arg(long, value_parser = cli::parse_count)]
    levels: Option<usize>,

    /// How eq. 7 compares the levels: paper (Appendix A as printed: a strong edge's coarse
    /// coefficients set the bar, which masks fine detail beside it) or level-normalized (each
    /// level in units of the amplitude it answers). The paper's reading is the default: it won
    /// the previewer's equal-quality benchmark (cargo bench -p brdf-preview --bench adaptive).
    #[arg(long, value_name = "paper|level-normalized", default_value = "paper")]
    reading: bandwidth::Reading,

    /// Memory budget (4G, 512M, ...; from 1 byte to 16 EiB): a map whose estimated need (80 bytes
    /// per texel) is larger is refused from its header, before decoding.
    #[arg(long, value_name = "SIZE", default_value = "4G", value_parser = cli::parse_bytes)]
    max_memory: u64,
}

/// `--eps`: checked here because `latlong_bandwidth` does not check its configuration.
fn parse_eps(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(eps) if eps > 0.0 && eps <= 1.0 => Ok(eps),
        Ok(_) => Err(format!("{text} is not in (0, 1]")),
        Err(e) => Err(e.to_string()),
    }
}

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let mode = match (args.spatial, args.pad) {
        (false, _) => Mode::Angular,
        (true, false) => Mode::SpatialPeriodic,
        (true, true) => Mode::SpatialPadded,
    };
    let settings = Settings {
        mode,
        config: Config { eps: args.eps, levels: args.levels, reading: args.reading, ..Config::default() },
        fft_diagnostic: args.fft_diagnostic,
        max_memory: args.max_memory,
    };
    let staged = bake::stage::env_bandwidth::run(&args.input, &settings)?;
    let dir = &args.out_dir;
    staged.write(dir)?;
    Ok(cli::finish(args.json, &staged.json(dir)?, &staged.report, &staged.problems, &staged.written(dir)))
}
