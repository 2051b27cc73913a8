//! The comparison of two maps, and the diagnostic report of the wavelet estimate against the
//! windowed FFT (reported, not gated).

use bandwidth::{
    Config, Image, WindowedFftConfig, compare_maps, local_bandwidth, wavelet_at_windows, windowed_fft_bandwidth,
};
use rand::Rng;

use crate::{blur, rng, sinusoid};

/// Known answers: ratios of exact powers of two, so the percentiles are exact; ties share ranks.
#[test]
fn percentiles_and_rank_correlation() {
    let reference = [1.0, 2.0, 4.0, 8.0, 16.0];
    let estimate = [2.0, 4.0, 8.0, 16.0, 32.0];
    let c = compare_maps(&estimate, &reference).unwrap();
    assert_eq!((c.points, c.both_positive, c.one_zero), (5, 5, 0));
    assert_eq!(c.log2_ratio, [1.0; 5]);
    assert_eq!(c.spearman, Some(1.0));
    let reversed: Vec<f64> = estimate.iter().rev().copied().collect();
    assert!((compare_maps(&reversed, &reference).unwrap().spearman.unwrap() + 1.0).abs() < 1e-12);
    // log2 ratios 0, 1, 2, 3, 4 (numpy: percentile([0, 1, 2, 3, 4], [5, 25, 50, 75, 95])).
    let spread = [1.0, 4.0, 16.0, 64.0, 256.0];
    let c = compare_maps(&spread, &reference).unwrap();
    assert_eq!(c.log2_ratio, [0.2, 1.0, 2.0, 3.0, 3.8]);
    // Ties: ranks [1.5, 1.5, 3] against [1, 2, 3] -> 0.866.
    let c = compare_maps(&[1.0, 1.0, 2.0], &[1.0, 2.0, 3.0]).unwrap();
    assert!((c.spearman.unwrap() - 0.75f64.sqrt()).abs() < 1e-12);
    // A zero on one side is counted, not logged; a constant map has no rank correlation.
    let c = compare_maps(&[0.0, 1.0, 1.0], &[1.0, 1.0, 1.0]).unwrap();
    assert_eq!((c.both_positive, c.one_zero, c.spearman), (2, 1, None));
    assert!(compare_maps(&[1.0], &[1.0, 2.0]).is_err());
    assert!(compare_maps(&[f64::NAN], &[1.0]).is_err());
}

/// The report: the wavelet estimate against the windowed FFT on a sinusoid, on blurred noise of
/// several widths side by side (a case where both should rank regions alike), and on white
/// noise with a step (where they measure different things). Printed, not gated, except that
/// the sinusoid's ratio is the calibration's (within an octave, as test 1).
#[test]
fn report_wavelet_against_windowed_fft() {
    let config = Config::default();
    let fft_config = WindowedFftConfig::default();
    let mut r = rng(11);
    let noise = Image::from_fn(256, 256, |_, _| r.random_range(-1.0..1.0));
    let (fine, middle, coarse) = (blur(&noise, 1.5), blur(&noise, 3.0), blur(&noise, 6.0));
    let mixed =
        Image::from_fn(256, 256, |x, y| [fine.get(x, y), coarse.get(x, y) * 4.0, middle.get(x, y) * 2.0, 0.0][x / 64]);
    let step = Image::from_fn(256, 256, |x, y| noise.get(x, y) * 0.05 + if x < 128 { 0.0 } else { 1.0 });
    for (name, image) in [
        ("sinusoid period 11", sinusoid(256, 256, 11.0, 30.0, 0.3)),
        ("blurred noise bands", mixed),
        ("noise and a step", step),
    ] {
        let wavelet = local_bandwidth(&image, &config).unwrap();
        let fft = windowed_fft_bandwidth(&image, &fft_config).unwrap();
        let c = compare_maps(&wavelet_at_windows(&wavelet, &fft), fft.frequency()).unwrap();
        println!(
            "wavelet vs windowed fft, {name}: log2 ratio p5 {:+.2} p25 {:+.2} p50 {:+.2} p75 {:+.2} p95 {:+.2}; spearman {:?}; {} of {} windows zero on one side",
            c.log2_ratio[0],
            c.log2_ratio[1],
            c.log2_ratio[2],
            c.log2_ratio[3],
            c.log2_ratio[4],
            c.spearman.map(|s| (s * 1000.0).round() / 1000.0),
            c.one_zero,
            c.points
        );
        if name.starts_with("sinusoid") {
            assert!(c.log2_ratio[0] >= -1.0 && c.log2_ratio[4] <= 1.0, "{c:?}");
        }
    }
}
