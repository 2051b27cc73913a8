//! `envmap-bandwidth`: the local bandwidth of an environment map (cycles per radian) or of a
//! texture or area light (cycles per pixel), as a float map, a false-colour picture with a
//! legend, and summary statistics. A thin layer over the `bandwidth` crate: reading, one
//! estimate, reporting.

mod font;
mod picture;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use bandwidth::{
    BandwidthMap, Config, Image, WindowedFftConfig, compare_maps, latlong_bandwidth, local_bandwidth,
    local_bandwidth_zero_padded, log1p_luminance, wavelet_at_windows, windowed_fft_bandwidth,
};
use clap::Parser;
use serde_json::json;

/// Estimate the local angular bandwidth of a lat-long environment map: per pixel, the highest
/// frequency that carries significant energy around it, in cycles per radian of arc on the
/// sphere (the wavelet estimator of the bandwidth crate on ln(1 + luminance), converted through
/// the lat-long mapping). With --spatial, the spatial bandwidth of an image of any shape (a
/// texture, an area light) in cycles per pixel.
///
/// Writes the map as a single-channel (Y) 32-bit float OpenEXR of the input's size; a
/// false-colour PNG (log scale; cyan: at the grid's Nyquist limit, the true bandwidth may be
/// higher; grey: flat, no significant detail) with a legend below the map; and prints the
/// statistics. Pixel fractions count pixels, not solid angle.
///
/// JSON (--json): input, mode ("angular", "spatial-periodic" or "spatial-padded"), unit, width,
/// height, levels, eps, c, pixels, min, median, p95, max (over the pixels that are not flat; null
/// when all are), nyquist_fraction, flat_fraction, and fft_diagnostic (null unless
/// --fft-diagnostic: windows, both_positive, one_zero, log2_ratio {p5, p25, p50, p75, p95} of
/// wavelet / fft, spearman).
///
/// Exit status: 0 ok, 2 error (unreadable input, a map that is not 2:1 without --spatial, a size
/// the estimator cannot analyse, bad arguments).
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    /// The map: OpenEXR or Radiance HDR (told apart by their first bytes). Without --spatial it
    /// must be a 2:1 lat-long map.
    input: PathBuf,

    /// The bandwidth map to write: OpenEXR, one 32-bit float channel Y, the input's size.
    #[arg(long, short, value_name = "BW.exr")]
    out: PathBuf,

    /// The false-colour picture; defaults to --out with the extension .png.
    #[arg(long, value_name = "BW.png")]
    png: Option<PathBuf>,

    /// Also write the statistics as JSON to this file.
    #[arg(long, value_name = "STATS.json")]
    json: Option<PathBuf>,

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

    /// Number of wavelet levels; by default as many as the size allows.
    #[arg(long)]
    levels: Option<usize>,
}

/// `--eps`: checked here because `latlong_bandwidth` does not check its configuration.
fn parse_eps(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(eps) if eps > 0.0 && eps <= 1.0 => Ok(eps),
        Ok(_) => Err(format!("{text} is not in (0, 1]")),
        Err(e) => Err(e.to_string()),
    }
}

/// What is estimated and in which unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Angular,
    SpatialPeriodic,
    SpatialPadded,
}

impl Mode {
    fn name(self) -> &'static str {
        match self {
            Mode::Angular => "angular",
            Mode::SpatialPeriodic => "spatial-periodic",
            Mode::SpatialPadded => "spatial-padded",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Mode::Angular => "cycles per radian",
            Mode::SpatialPeriodic | Mode::SpatialPadded => "cycles per pixel",
        }
    }
}

/// The estimate of one image.
#[derive(Debug)]
struct Analysis {
    /// The image the estimator read, ln(1 + Y).
    image: Image,
    /// The estimate in cycles per pixel: levels and Nyquist flags.
    pixels: BandwidthMap,
    /// Per pixel in the mode's unit, row-major.
    values: Vec<f64>,
}

/// Summary statistics of a map, in its unit.
#[derive(Debug, PartialEq)]
struct Stats {
    pixels: usize,
    flat: usize,
    nyquist: usize,
    /// `[min, median, p95, max]` over the pixels that are not flat; `None` when all are.
    spread: Option<[f64; 4]>,
}

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()))
}

fn run(args: Args) -> Result<ExitCode> {
    let mode = match (args.spatial, args.pad) {
        (false, _) => Mode::Angular,
        (true, false) => Mode::SpatialPeriodic,
        (true, true) => Mode::SpatialPadded,
    };
    let png = args.png.clone().unwrap_or_else(|| args.out.with_extension("png"));
    if png == args.out {
        bail!("--out {} and the picture would be the same file: name the picture with --png", args.out.display());
    }
    let config = Config { eps: args.eps, levels: args.levels, ..Config::default() };
    let input = &args.input;

    // Progress goes to stderr once a stage has succeeded, so that an input error is the only
    // line a failing run prints.
    let start = Instant::now();
    let (width, height, image) = read(input, mode).with_context(|| format!("reading {}", input.display()))?;
    let analysis = analyse(image, mode, &config).with_context(|| format!("analysing {}", input.display()))?;
    let estimated = start.elapsed();
    eprintln!(
        "estimated the {} bandwidth of {} ({width} x {height}, {} levels) in {:.0} ms (reading included)",
        if mode == Mode::Angular { "angular" } else { "spatial" },
        input.display(),
        analysis.pixels.levels(),
        estimated.as_secs_f64() * 1e3
    );

    let values32: Vec<f32> = analysis.values.iter().map(|&v| v as f32).collect();
    envmap::write_exr(&args.out, width, height, &[("Y", &values32)], envmap::SampleType::F32)
        .with_context(|| format!("writing {}", args.out.display()))?;
    let picture = picture::render(&picture::Input {
        width,
        height,
        values: &analysis.values,
        levels: analysis.pixels.level(),
        unit: mode.unit(),
    });
    envmap::write_png_rgb8(&png, picture.width, picture.height, &picture.rgb)
        .with_context(|| format!("writing {}", png.display()))?;

    let stats = stats(&analysis);
    let fft = if args.fft_diagnostic {
        let start = Instant::now();
        let comparison = fft_diagnostic(&analysis).with_context(|| format!("fft diagnostic of {}", input.display()))?;
        eprintln!("ran the windowed fft in {:.0} ms", start.elapsed().as_secs_f64() * 1e3);
        Some(comparison)
    } else {
        None
    };
    report(input, mode, &config, &analysis, &stats, fft.as_ref());
    if let Some(path) = &args.json {
        let json = summary_json(input, mode, &config, &analysis, &stats, fft.as_ref());
        let text = serde_json::to_string_pretty(&json)? + "\n";
        asset::write_atomic(path, text.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
    }
    let written: Vec<String> = [Some(&args.out), Some(&png), args.json.as_ref()]
        .into_iter()
        .flatten()
        .map(|p| p.display().to_string())
        .collect();
    eprintln!("wrote {}", written.join(", "));
    Ok(ExitCode::SUCCESS)
}

/// Reads the input and returns its size and the image the estimator reads, ln(1 + Y).
fn read(path: &Path, mode: Mode) -> Result<(usize, usize, Image)> {
    let (width, height, image) = if mode == Mode::Angular {
        let map = envmap::load(path)?;
        (map.width(), map.height(), log1p_luminance(map.width(), map.height(), map.texels())?)
    } else {
        let image = envmap::read_image(path, &envmap::Limits::default())?;
        (image.width, image.height, log1p_luminance(image.width, image.height, image.rgb.as_chunks::<3>().0)?)
    };
    Ok((width, height, image))
}

fn analyse(image: Image, mode: Mode, config: &Config) -> Result<Analysis> {
    Ok(match mode {
        Mode::Angular => {
            let map = latlong_bandwidth(&image, config)?;
            Analysis { values: map.cycles_per_radian().to_vec(), pixels: map.pixels().clone(), image }
        }
        Mode::SpatialPeriodic => {
            let pixels = local_bandwidth(&image, config)?;
            Analysis { values: pixels.frequency().to_vec(), pixels, image }
        }
        Mode::SpatialPadded => {
            let pixels = local_bandwidth_zero_padded(&image, config)?;
            Analysis { values: pixels.frequency().to_vec(), pixels, image }
        }
    })
}

fn stats(analysis: &Analysis) -> Stats {
    let levels = analysis.pixels.level();
    let mut positive: Vec<f64> =
        analysis.values.iter().zip(levels).filter(|(_, j)| **j != 0).map(|(v, _)| *v).collect();
    positive.sort_by(f64::total_cmp);
    let spread = (!positive.is_empty())
        .then(|| [positive[0], percentile(&positive, 50.0), percentile(&positive, 95.0), positive[positive.len() - 1]]);
    Stats {
        pixels: levels.len(),
        flat: levels.iter().filter(|j| **j == 0).count(),
        nyquist: analysis.pixels.nyquist_count(),
        spread,
    }
}

/// Percentile `p` (0..=100) of sorted, non-empty values, interpolated linearly between order
/// statistics (numpy's default).
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let pos = p / 100.0 * (sorted.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
}

fn fft_diagnostic(analysis: &Analysis) -> Result<bandwidth::Comparison> {
    let fft = windowed_fft_bandwidth(&analysis.image, &WindowedFftConfig::default())?;
    Ok(compare_maps(&wavelet_at_windows(&analysis.pixels, &fft), fft.frequency())?)
}

/// Four significant digits, without an exponent for the values bandwidths take.
fn sig(v: f64) -> String {
    if v == 0.0 || !(1e-4..1e6).contains(&v.abs()) {
        return format!("{v:.3e}");
    }
    let decimals = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}")
}

fn report(
    input: &Path,
    mode: Mode,
    config: &Config,
    analysis: &Analysis,
    stats: &Stats,
    fft: Option<&bandwidth::Comparison>,
) {
    let (w, h) = (analysis.pixels.width(), analysis.pixels.height());
    cli::outln!("{}: {w} x {h}, {} bandwidth in {}", input.display(), mode.name(), mode.unit());
    cli::outln!("  levels {}, eps {}, c {}", analysis.pixels.levels(), config.eps, sig(config.c));
    match stats.spread {
        Some([min, median, p95, max]) => {
            cli::outln!("  min {}  median {}  p95 {}  max {}", sig(min), sig(median), sig(p95), sig(max))
        }
        None => cli::outln!("  min -  median -  p95 -  max -  (every pixel is flat)"),
    }
    let percent = |n: usize| 100.0 * n as f64 / stats.pixels as f64;
    cli::outln!("  at the Nyquist limit {:.2}% of pixels (their true bandwidth may be higher)", percent(stats.nyquist));
    cli::outln!("  flat {:.2}% of pixels (no significant detail)", percent(stats.flat));
    if let Some(c) = fft {
        let [p5, p25, p50, p75, p95] = c.log2_ratio;
        cli::outln!(
            "fft diagnostic (cycles per pixel): {} windows, {} positive on both sides, {} zero on one side only",
            c.points,
            c.both_positive,
            c.one_zero
        );
        cli::outln!("  log2(wavelet / fft) p5 {p5:.2}  p25 {p25:.2}  p50 {p50:.2}  p75 {p75:.2}  p95 {p95:.2}");
        cli::outln!(
            "  spearman {}",
            c.spearman.map_or("undefined (a constant map)".to_string(), |s| format!("{s:.3}"))
        );
    }
}

fn summary_json(
    input: &Path,
    mode: Mode,
    config: &Config,
    analysis: &Analysis,
    stats: &Stats,
    fft: Option<&bandwidth::Comparison>,
) -> serde_json::Value {
    let spread = |i: usize| stats.spread.map(|s| s[i]);
    let fraction = |n: usize| n as f64 / stats.pixels as f64;
    let fft = fft.map(|c| {
        let [p5, p25, p50, p75, p95] = c.log2_ratio;
        json!({
            "windows": c.points,
            "both_positive": c.both_positive,
            "one_zero": c.one_zero,
            "log2_ratio": { "p5": p5, "p25": p25, "p50": p50, "p75": p75, "p95": p95 },
            "spearman": c.spearman,
        })
    });
    json!({
        "input": input.display().to_string(),
        "mode": mode.name(),
        "unit": mode.unit(),
        "width": analysis.pixels.width(),
        "height": analysis.pixels.height(),
        "levels": analysis.pixels.levels(),
        "eps": config.eps,
        "c": config.c,
        "pixels": stats.pixels,
        "min": spread(0),
        "median": spread(1),
        "p95": spread(2),
        "max": spread(3),
        "nyquist_fraction": fraction(stats.nyquist),
        "flat_fraction": fraction(stats.flat),
        "fft_diagnostic": fft,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_interpolate_like_numpy() {
        // numpy.percentile([1, 2, 3, 4, 10], [0, 50, 95, 100]) = [1, 3, 8.8, 10] (to rounding)
        let v = [1.0, 2.0, 3.0, 4.0, 10.0];
        let p = [0.0, 50.0, 95.0, 100.0].map(|p| percentile(&v, p));
        assert_eq!([p[0], p[1], p[3]], [1.0, 3.0, 10.0]);
        assert!((p[2] - 8.8).abs() < 1e-12, "{}", p[2]);
    }

    #[test]
    fn four_significant_digits() {
        assert_eq!(sig(0.028_13), "0.02813");
        assert_eq!(sig(1.234_56), "1.235");
        assert_eq!(sig(4712.9), "4713");
        assert_eq!(sig(0.0), "0.000e0");
        assert_eq!(sig(2.5e7), "2.500e7");
    }

    /// Flat pixels count in the fraction and stay out of the spread; Nyquist pixels are level 1.
    #[test]
    fn statistics_leave_flat_pixels_out() {
        let image = Image::from_fn(64, 64, |x, _| if x < 32 { 0.0 } else { ((x * 7 % 5) as f64).sin() });
        let analysis = analyse(image, Mode::SpatialPeriodic, &Config::default()).unwrap();
        let s = stats(&analysis);
        let levels = analysis.pixels.level();
        assert_eq!(s.pixels, 64 * 64);
        assert_eq!(s.flat, levels.iter().filter(|j| **j == 0).count());
        assert_eq!(s.nyquist, levels.iter().filter(|j| **j == 1).count());
        let [min, median, p95, max] = s.spread.unwrap();
        assert!(min > 0.0 && min <= median && median <= p95 && p95 <= max, "{:?}", s.spread);
        assert_eq!(max, analysis.values.iter().copied().fold(0.0, f64::max));
        let flat = analyse(Image::zeros(64, 64), Mode::SpatialPeriodic, &Config::default()).unwrap();
        assert_eq!(stats(&flat), Stats { pixels: 4096, flat: 4096, nyquist: 0, spread: None });
    }
}
