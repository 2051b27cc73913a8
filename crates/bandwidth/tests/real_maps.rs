//! The estimator on the five real 1024 x 512 maps of `../shared/data/env`: a Gaussian blur of
//! the analysed image raises the estimate at no more than 1% of the pixels, and the windowed FFT
//! comparison, printed as a diagnostic.
//!
//! What is blurred: the analysed image, `ln(1 + Y)`, not the linear RGB. The property under test
//! is one of the estimator: a smoother input must not read a higher bandwidth. Blurring linear
//! radiance and then taking the logarithm is not a low-pass filter of what the estimator reads:
//! the tail of a blurred sun of luminance 86 500 is still about 30 (ln 31 = 3.4) four sigmas
//! away, so dark pixels beside bright ones gain new structure in `ln(1 + Y)` and some rightly
//! read higher. That variant is measured and printed too, not gated.

use bandwidth::{
    AngularBandwidthMap, Config, Image, WindowedFftConfig, compare_maps, latlong_bandwidth, log1p_luminance,
    wavelet_at_windows, windowed_fft_bandwidth,
};
use rayon::prelude::*;

/// The five 1024 x 512 maps (`../shared/data/env/README.md`).
const MAPS: [&str; 5] = [
    "quarry_01_1k.hdr",
    "potsdamer_platz_1k.hdr",
    "studio_small_03_1k.hdr",
    "piz_compressed.exr",
    "KernerEnvLatLong.exr",
];

/// The blur widths (sigma), in pixels.
const SIGMAS: [f64; 3] = [1.0, 2.0, 4.0];

/// A real map of `../shared/data/env`: its linear luminance and the analysed image `ln(1 + Y)`.
/// `None` when the calling test is to skip without them ([`crate::shared_data::shared_or_skip`]).
fn load(file: &str) -> Option<(Image, Image)> {
    let path = crate::shared_data::shared_or_skip(&["data/env"])?.join("data/env").join(file);
    let map = envmap::load(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let (w, h) = (map.width(), map.height());
    let y = map.texels().iter().map(|p| color::luminance(p.map(f64::from)).max(0.0)).collect();
    Some((Image::new(w, h, y).unwrap(), log1p_luminance(w, h, map.texels()).unwrap()))
}

/// Separable Gaussian blur of a lat-long image, the kernel cut at 4 sigma and normalized: rows
/// wrap (the map is periodic in `phi`), columns clamp at the top and bottom rows (the estimator
/// itself continues across the poles, which a clamped blur only approximates within 4 sigma of
/// them).
fn blur_latlong(image: &Image, sigma: f64) -> Image {
    let r = (4.0 * sigma).ceil() as i64;
    let kernel: Vec<f64> = (-r..=r).map(|i| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp()).collect();
    let sum: f64 = kernel.iter().sum();
    let kernel: Vec<f64> = kernel.iter().map(|k| k / sum).collect();
    let (w, h) = (image.width(), image.height());
    let mut rows = vec![0.0; w * h];
    rows.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let src = image.row(y);
        for (x, o) in out.iter_mut().enumerate() {
            *o = (-r..=r).zip(&kernel).map(|(i, k)| k * src[(x as i64 + i).rem_euclid(w as i64) as usize]).sum();
        }
    });
    let mut out = vec![0.0; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, dst)| {
        for (i, k) in (-r..=r).zip(&kernel) {
            let sy = (y as i64 + i).clamp(0, h as i64 - 1) as usize;
            for (d, s) in dst.iter_mut().zip(&rows[sy * w..(sy + 1) * w]) {
                *d += k * s;
            }
        }
    });
    Image::new(w, h, out).unwrap()
}

/// Fractions of pixels whose estimate went up and down from `before` to `after`.
fn raised_lowered(before: &AngularBandwidthMap, after: &AngularBandwidthMap) -> (f64, f64) {
    let (b, a) = (before.cycles_per_radian(), after.cycles_per_radian());
    let n = b.len() as f64;
    let raised = b.iter().zip(a).filter(|(b, a)| a > b).count() as f64 / n;
    let lowered = b.iter().zip(a).filter(|(b, a)| a < b).count() as f64 / n;
    (raised, lowered)
}

/// At most 1% of the pixels of each map may read higher after a blur of sigma 1, 2 or 4 pixels.
/// So that the test cannot pass on an estimate that ignores its input, the fraction that reads
/// lower must grow with sigma and reach 10% at sigma 4 (measured: 17% on the smooth overcast
/// potsdamer_platz, 30 to 41% on the others).
///
/// Why not 0%: the estimate is a maximum over the coefficients whose support covers a pixel, and
/// a blur widens structure by about 2 sigma, so a pixel just outside the reach of a level's
/// coefficients over an edge can come within reach of the blurred edge's coefficients at that
/// level (typically a coarse level, read where only a coarser one reached). Eq. 7 is also
/// relative to the pixel's largest `lambda_j`, which the blur lowers a little too. Both move a
/// few pixels near edges by one level; hence a bound of 1%, and the measured fractions are
/// printed (they are well below it).
#[test]
fn blurring_never_raises_the_estimate() {
    let config = Config::default();
    let mut report =
        String::from("map                       sigma   raised   lowered   (linear-RGB blur: raised  lowered)\n");
    let mut failures = Vec::new();
    for file in MAPS {
        let Some((linear, analysed)) = load(file) else { return };
        assert_eq!((analysed.width(), analysed.height()), (1024, 512), "{file}");
        let before = latlong_bandwidth(&analysed, &config).unwrap();
        let mut previous_lowered = 0.0;
        for sigma in SIGMAS {
            let after = latlong_bandwidth(&blur_latlong(&analysed, sigma), &config).unwrap();
            let (raised, lowered) = raised_lowered(&before, &after);
            let blurred_linear = blur_latlong(&linear, sigma);
            let data = blurred_linear.data().iter().map(|y| y.ln_1p()).collect();
            let after_linear = latlong_bandwidth(&Image::new(1024, 512, data).unwrap(), &config).unwrap();
            let (raised_linear, lowered_linear) = raised_lowered(&before, &after_linear);
            report += &format!(
                "{file:<25} {sigma:>5} {:>7.3}% {:>8.2}%   {:>22.3}% {:>7.2}%\n",
                100.0 * raised,
                100.0 * lowered,
                100.0 * raised_linear,
                100.0 * lowered_linear
            );
            if raised > 0.01 {
                failures.push(format!("{file}, sigma {sigma}: {:.3}% of the pixels read higher", 100.0 * raised));
            }
            if lowered <= previous_lowered || (sigma == 4.0 && lowered < 0.1) {
                failures.push(format!(
                    "{file}, sigma {sigma}: {:.2}% of the pixels read lower ({:.2}% at the previous sigma)",
                    100.0 * lowered,
                    100.0 * previous_lowered
                ));
            }
            previous_lowered = lowered;
        }
    }
    eprintln!("{report}");
    assert!(failures.is_empty(), "{}\n{report}", failures.join("\n"));
}

/// The windowed FFT against the wavelet estimate (both in cycles per pixel of the map) on each
/// real map: the distribution of `log2(wavelet / fft)` and Spearman's rank correlation, printed.
/// A diagnostic (crate docs, "Windowed FFT"); only sanity is asserted: the comparison covers
/// every window, most windows read positive on both sides, and the correlation is a number.
#[test]
fn windowed_fft_diagnostic() {
    let config = Config::default();
    let fft_config = WindowedFftConfig::default();
    let mut report = String::from(
        "map                       windows  one zero   log2(wavelet / fft) p5    p25    p50    p75    p95   spearman\n",
    );
    for file in MAPS {
        let Some((_, analysed)) = load(file) else { return };
        let wavelet = latlong_bandwidth(&analysed, &config).unwrap();
        let fft = windowed_fft_bandwidth(&analysed, &fft_config).unwrap();
        let c = compare_maps(&wavelet_at_windows(wavelet.pixels(), &fft), fft.frequency()).unwrap();
        let [p5, p25, p50, p75, p95] = c.log2_ratio;
        report += &format!(
            "{file:<25} {:>7} {:>9} {:>24.2} {p25:>6.2} {p50:>6.2} {p75:>6.2} {p95:>6.2} {:>10}\n",
            c.points,
            c.one_zero,
            p5,
            c.spearman.map_or("none".to_string(), |s| format!("{s:.3}"))
        );
        assert_eq!(c.points, fft.columns() * fft.rows(), "{file}");
        assert!(c.both_positive * 2 > c.points, "{file}: fewer than half the windows read positive on both sides");
        assert!(c.log2_ratio.iter().all(|r| r.is_finite()), "{file}: {:?}", c.log2_ratio);
        assert!(c.spearman.is_some_and(|s| (-1.0..=1.0).contains(&s)), "{file}: spearman {:?}", c.spearman);
    }
    eprintln!("{report}");
}
