//! The local bandwidth of an environment map (`envmap-bandwidth`; `000` Appendix A, `001`
//! section 2.3): per pixel, cycles per radian on the sphere (or, for textures and area lights,
//! cycles per pixel), as a single-channel float EXR and a false-colour picture with a legend,
//! with summary statistics and an optional windowed-FFT diagnostic.

mod picture;

use std::path::Path;

use bandwidth::{
    BandwidthMap, Config, Image, Reading, WindowedFftConfig, compare_maps, latlong_bandwidth, local_bandwidth,
    local_bandwidth_zero_padded, log1p_luminance, wavelet_at_windows, windowed_fft_bandwidth,
};
use bandwidth_atlas::view::ViewLayers;
use serde_json::json;

use crate::{Error, OutFile, Staged, object};

pub const EXR: &str = "env-bandwidth.exr";
pub const PICTURE: &str = "env-bandwidth.png";

/// What is estimated and in which unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// A 2:1 lat-long environment map, cycles per radian.
    Angular,
    /// A tiling texture, cycles per pixel.
    SpatialPeriodic,
    /// An image of finite extent, zero outside (an area light), cycles per pixel.
    SpatialPadded,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Angular => "angular",
            Mode::SpatialPeriodic => "spatial-periodic",
            Mode::SpatialPadded => "spatial-padded",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Mode::Angular => "cycles per radian",
            Mode::SpatialPeriodic | Mode::SpatialPadded => "cycles per pixel",
        }
    }
}

/// The settings of the stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub mode: Mode,
    pub config: Config,
    /// Also run the windowed FFT and compare.
    pub fft_diagnostic: bool,
    /// The memory budget, in bytes: a map whose estimated need ([`BYTES_PER_TEXEL`]) exceeds it
    /// is refused from its header.
    pub max_memory: u64,
}

/// Which reading of eq. 7 a bake's environment bandwidth takes (crate `bandwidth`, "Readings"):
/// one the user fixed, or [`ReadingChoice::Auto`], chosen by the material.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ReadingChoice {
    /// The level-normalized reading for a mirror-like material ([`mirror_like`]), the paper's
    /// for every other. The adaptive frames read the map as the bandwidth of the light a pixel
    /// reflects (`render::adaptive`, "The bandwidth buffer"). A glossy lobe blurs the fine detail
    /// that the paper's reading lets a strong edge mask, so the paper's plans hold for it; a
    /// mirror-like lobe shows that detail, and the paper's reading then plans blocks across it.
    /// Measured on chrome under studio_small_03_1k at 512 x 512, brdf-preview's defaults, against
    /// a converged estimate of 256 samples per strategy: `adaptive` leaves 1708 covered pixels more
    /// than 20 levels off with the paper's reading (shading 8% of the pixels), 14 with the
    /// level-normalized one (44%) (`brdf-bake --env-reading paper` or `auto`, then `brdf-preview
    /// --mode adaptive --size 512x512 --json` and a count against `--converged 256`); gold-paint, whose lobes are wider than the sharpest layer's,
    /// keeps the paper's plans (`cargo bench -p brdf-preview --bench adaptive` has both readings
    /// per case).
    #[default]
    Auto,
    Fixed(Reading),
}

impl ReadingChoice {
    /// The name on command lines and in manifests: `auto` or the reading's.
    pub fn name(self) -> &'static str {
        match self {
            ReadingChoice::Auto => "auto",
            ReadingChoice::Fixed(reading) => reading.name(),
        }
    }

    /// The reading for the material whose layer selection is `selection`.
    pub fn resolve(self, selection: &ViewLayers) -> Reading {
        match self {
            ReadingChoice::Fixed(reading) => reading,
            ReadingChoice::Auto if mirror_like(selection) => Reading::LevelNormalized,
            ReadingChoice::Auto => Reading::Paper,
        }
    }
}

impl std::str::FromStr for ReadingChoice {
    type Err = String;

    fn from_str(text: &str) -> Result<ReadingChoice, String> {
        match text.trim() {
            "auto" => Ok(ReadingChoice::Auto),
            other => Reading::from_name(other)
                .map(ReadingChoice::Fixed)
                .ok_or_else(|| format!("{text:?}: the readings are auto, paper and level-normalized")),
        }
    }
}

/// A material is mirror-like when its lobe at every view is at least as sharp as the sharpest
/// Phong layer's (`selection`'s measured bandwidths, the same analysis for both): no layer blurs
/// it, so the light's finest detail reaches the picture. Of the 20 shared materials, under the
/// default bake: black-obsidian, blue-acrylic, brass, chrome and steel (least view bandwidth
/// 17.3 to 21.8 cycles per radian against the sharpest layer's 13.4); red-metallic-paint (9.8)
/// and white-marble (8.4) are not.
pub fn mirror_like(selection: &ViewLayers) -> bool {
    let Some(&sharpest) = selection.layer_bandwidth.last() else { return false };
    !selection.view_bandwidth.is_empty() && selection.view_bandwidth.iter().all(|&b| b >= sharpest)
}

/// The peak memory of this stage per texel of the map, in bytes, reading included: measured 68
/// (the maximum resident size on 2048 x 1024 and 4096 x 2048 maps, the difference over the
/// difference in texels: the image, `ln(1 + Y)` in `f64`, the wavelet decomposition and the
/// estimate), with room to spare.
pub const BYTES_PER_TEXEL: u64 = 80;

impl Default for Settings {
    fn default() -> Self {
        Settings {
            mode: Mode::Angular,
            config: Config::default(),
            fft_diagnostic: false,
            max_memory: envmap::DEFAULT_MAX_MEMORY,
        }
    }
}

/// Reads `input` and estimates its bandwidth. Angular mode loads it as an environment map (2:1,
/// finite, non-negative); the spatial modes take any image.
pub fn run(input: &Path, settings: &Settings) -> Result<Staged, Error> {
    let limits = envmap::Limits::for_job(BYTES_PER_TEXEL, settings.max_memory);
    let (width, height, image) = read(input, settings.mode, &limits).map_err(|e| Error::read(input, e))?;
    run_on(input, width, height, image, settings)
}

/// [`run`] on a map already in memory (`brdf-bake` loads the map once for every stage).
pub fn run_on_map(input: &Path, map: &envmap::EnvMap, settings: &Settings) -> Result<Staged, Error> {
    let image = log1p_luminance(map.width(), map.height(), map.texels()).map_err(|e| Error::read(input, e))?;
    run_on(input, map.width(), map.height(), image, settings)
}

fn run_on(input: &Path, width: usize, height: usize, image: Image, settings: &Settings) -> Result<Staged, Error> {
    let mode = settings.mode;
    let analysis = analyse(image, mode, &settings.config).map_err(|e| Error::analyse(input, e))?;
    let values32: Vec<f32> = analysis.values.iter().map(|&v| v as f32).collect();
    let exr = envmap::encode_exr(width, height, &[("Y", &values32)], envmap::SampleType::F32)
        .map_err(|e| Error::Internal(format!("encoding {EXR}: {e}")))?;
    let name = input.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let pic = picture::render(&picture::Input {
        name: &name,
        width,
        height,
        values: &analysis.values,
        levels: analysis.pixels.level(),
        unit: mode.unit(),
        latlong: mode == Mode::Angular,
        reading: settings.config.reading,
    });
    let png = envmap::encode_png_rgb8(pic.width, pic.height, &pic.rgb)
        .map_err(|e| Error::Internal(format!("encoding {PICTURE}: {e}")))?;
    let stats = stats(&analysis);
    let fft = if settings.fft_diagnostic {
        Some(fft_diagnostic(&analysis).map_err(|e| Error::analyse(input, e))?)
    } else {
        None
    };
    Ok(Staged {
        name: "environment-bandwidth",
        parameters: object([
            ("mode", json!(mode.name())),
            ("eps", json!(settings.config.eps)),
            ("c", json!(settings.config.c)),
            ("levels", json!(analysis.pixels.levels())),
            ("reading", json!(settings.config.reading.name())),
        ]),
        figures: figures(mode, &analysis, &stats, fft.as_ref()),
        files: vec![
            OutFile { name: EXR.into(), format: asset::FileFormat::Exr, role: "environment-bandwidth", bytes: exr },
            OutFile {
                name: PICTURE.into(),
                format: asset::FileFormat::Png,
                role: "environment-bandwidth-picture",
                bytes: png,
            },
        ],
        report: report(input, mode, &settings.config, &analysis, &stats, fft.as_ref()),
        problems: Vec::new(),
    })
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

/// Reads the input and returns its size and the image the estimator reads, ln(1 + Y).
fn read(
    path: &Path,
    mode: Mode,
    limits: &envmap::Limits,
) -> Result<(usize, usize, Image), Box<dyn std::error::Error + Send + Sync>> {
    Ok(if mode == Mode::Angular {
        let map = envmap::load_with_limits(path, limits)?;
        (map.width(), map.height(), log1p_luminance(map.width(), map.height(), map.texels())?)
    } else {
        let image = envmap::read_image(path, limits)?;
        (image.width, image.height, log1p_luminance(image.width, image.height, image.rgb.as_chunks::<3>().0)?)
    })
}

fn analyse(image: Image, mode: Mode, config: &Config) -> Result<Analysis, bandwidth::Error> {
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

fn fft_diagnostic(analysis: &Analysis) -> Result<bandwidth::Comparison, bandwidth::Error> {
    let fft = windowed_fft_bandwidth(&analysis.image, &WindowedFftConfig::default())?;
    compare_maps(&wavelet_at_windows(&analysis.pixels, &fft), fft.frequency())
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
) -> Vec<String> {
    let (w, h) = (analysis.pixels.width(), analysis.pixels.height());
    let mut lines = vec![
        format!("{}: {w} x {h}, {} bandwidth in {}", input.display(), mode.name(), mode.unit()),
        format!("  levels {}, eps {}, c {}", analysis.pixels.levels(), config.eps, sig(config.c)),
    ];
    lines.push(match stats.spread {
        Some([min, median, p95, max]) => {
            format!("  min {}  median {}  p95 {}  max {}", sig(min), sig(median), sig(p95), sig(max))
        }
        None => "  min -  median -  p95 -  max -  (every pixel is flat)".to_string(),
    });
    let percent = |n: usize| 100.0 * n as f64 / stats.pixels as f64;
    lines.push(format!(
        "  at the Nyquist limit {:.2}% of pixels (their true bandwidth may be higher)",
        percent(stats.nyquist)
    ));
    lines.push(format!("  flat {:.2}% of pixels (no significant detail)", percent(stats.flat)));
    if let Some(c) = fft {
        let [p5, p25, p50, p75, p95] = c.log2_ratio;
        lines.push(format!(
            "fft diagnostic (cycles per pixel): {} windows, {} positive on both sides, {} zero on one side only",
            c.points, c.both_positive, c.one_zero
        ));
        lines.push(format!("  log2(wavelet / fft) p5 {p5:.2}  p25 {p25:.2}  p50 {p50:.2}  p75 {p75:.2}  p95 {p95:.2}"));
        lines.push(format!(
            "  spearman {}",
            c.spearman.map_or("undefined (a constant map)".to_string(), |s| format!("{s:.3}"))
        ));
    }
    lines
}

fn figures(
    mode: Mode,
    analysis: &Analysis,
    stats: &Stats,
    fft: Option<&bandwidth::Comparison>,
) -> serde_json::Map<String, serde_json::Value> {
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
    object([
        ("unit", json!(mode.unit())),
        ("width", json!(analysis.pixels.width())),
        ("height", json!(analysis.pixels.height())),
        ("pixels", json!(stats.pixels)),
        ("min", json!(spread(0))),
        ("median", json!(spread(1))),
        ("p95", json!(spread(2))),
        ("max", json!(spread(3))),
        ("nyquist_fraction", json!(fraction(stats.nyquist))),
        ("flat_fraction", json!(fraction(stats.flat))),
        ("fft_diagnostic", json!(fft)),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn selection(view_bandwidth: Vec<f64>) -> ViewLayers {
        ViewLayers {
            reduction: bandwidth_atlas::view::ViewReduction::BandQuantile(0.99),
            exponents: vec![16, 256, 4096],
            layer_bandwidth: vec![0.45, 1.7, 6.8],
            view_layer: vec![2; view_bandwidth.len()],
            view_bandwidth,
        }
    }

    #[test]
    fn auto_reads_level_normalized_only_where_every_view_is_as_sharp_as_the_sharpest_layer() {
        let mirror = selection(vec![6.8, 9.0, 25.0]);
        // One view below the sharpest layer (the view layer would still be the sharpest by the
        // nearest bandwidth on a log scale) is not mirror-like.
        let glossy = selection(vec![6.7, 9.0, 25.0]);
        assert!(mirror_like(&mirror) && !mirror_like(&glossy));
        assert!(!mirror_like(&selection(Vec::new())));
        assert_eq!(ReadingChoice::Auto.resolve(&mirror), Reading::LevelNormalized);
        assert_eq!(ReadingChoice::Auto.resolve(&glossy), Reading::Paper);
        for reading in [Reading::Paper, Reading::LevelNormalized] {
            for s in [&mirror, &glossy] {
                assert_eq!(ReadingChoice::Fixed(reading).resolve(s), reading);
            }
        }
    }

    #[test]
    fn reading_choices_parse_their_names() {
        for choice in
            [ReadingChoice::Auto, ReadingChoice::Fixed(Reading::Paper), ReadingChoice::Fixed(Reading::LevelNormalized)]
        {
            assert_eq!(choice.name().parse::<ReadingChoice>(), Ok(choice));
        }
        let error = "mirror".parse::<ReadingChoice>().unwrap_err();
        assert!(error.contains("auto, paper and level-normalized"), "{error}");
    }

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
