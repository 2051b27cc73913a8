use picture::colormap::{Scale, ScaleKind, false_colour_log, inferno, log_range, range_by_percentiles, viridis};

/// Rec. 709 luma of an sRGB byte triple: a monotone stand-in for perceived lightness.
fn luma(c: [u8; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// The anchors are matplotlib's end colours (inferno: #000004 and #fcffa4; viridis: #440154
/// and #fde725), and positions outside 0..=1 are clamped.
#[test]
fn colour_map_anchors() {
    assert_eq!(inferno(0.0), [0, 0, 4]);
    assert_eq!(inferno(1.0), [0xfc, 0xff, 0xa4]);
    assert_eq!(inferno(-1.0), inferno(0.0));
    assert_eq!(inferno(0.5), [0xbc, 0x37, 0x54]);
    assert_eq!(viridis(0.0), [68, 1, 84]);
    assert_eq!(viridis(1.0), [253, 231, 37]);
    assert_eq!(viridis(2.0), viridis(1.0));
    assert_eq!(viridis(0.5), [33, 144, 141]);
}

/// Both maps are dark to bright: a higher value is never darker, up to the rounding of each
/// channel to a byte (at most half a byte per channel at each end, so at most 1 in luma, whose
/// weights sum to 1); and over every tenth of the scale lightness rises by a clear margin.
#[test]
fn colour_maps_are_monotone_in_lightness() {
    for (name, map) in [("inferno", inferno as fn(f64) -> [u8; 3]), ("viridis", viridis)] {
        for i in 0..1000 {
            let (a, b) = (f64::from(i) / 1000.0, f64::from(i + 1) / 1000.0);
            assert!(luma(map(b)) >= luma(map(a)) - 1.0, "{name} at {a}");
        }
        for i in 0..10 {
            let (a, b) = (f64::from(i) / 10.0, f64::from(i + 1) / 10.0);
            assert!(luma(map(b)) > luma(map(a)) + 5.0, "{name} from {a} to {b}");
        }
    }
}

#[test]
fn false_colour_and_log_range() {
    let rgb = false_colour_log(&[0.0, 1.0, 100.0, f32::NAN], (1.0, 100.0));
    assert_eq!(rgb, [0, 0, 0, 68, 1, 84, 253, 231, 37, 0, 0, 0]);
    assert_eq!(log_range(&[0.0, 0.5, 20.0], 3.0), Some((0.5, 20.0)));
    let (lo, hi) = log_range(&[1e-9, 20.0], 3.0).unwrap();
    assert!((lo - 0.02).abs() < 1e-15 && hi == 20.0);
    assert_eq!(log_range(&[0.0], 3.0), None);
}

/// Positions against the closed forms; tolerance 1e-12: a few roundings of logarithms.
#[test]
fn scale_positions() {
    let log = Scale::log(0.01, 1e4);
    assert_eq!(log.kind(), ScaleKind::Log);
    for (v, t) in [(0.01, 0.0), (1.0, 1.0 / 3.0), (100.0, 2.0 / 3.0), (1e4, 1.0), (1e9, 1.0), (1e-3, 0.0)] {
        assert!((log.position(v) - t).abs() < 1e-12, "log {v}");
    }
    assert_eq!((log.position(0.0), log.position(-1.0), log.position(f64::NAN)), (0.0, 0.0, 0.0));
    let linear = Scale::linear(-2.0, 6.0);
    for (v, t) in [(-2.0, 0.0), (0.0, 0.25), (4.0, 0.75), (6.0, 1.0), (7.0, 1.0)] {
        assert!((linear.position(v) - t).abs() < 1e-12, "linear {v}");
    }
    for scale in [log, linear] {
        for i in 0..=10 {
            let t = f64::from(i) / 10.0;
            assert!((scale.position(scale.value(t)) - t).abs() < 1e-12);
        }
    }
}

/// Invalid ends are repaired, never NaN; nice ends are round numbers outside the data.
#[test]
fn scale_ends() {
    let ends = |s: Scale| (s.lo(), s.hi());
    assert_eq!(ends(Scale::linear(5.0, 1.0)), (1.0, 5.0));
    assert_eq!(ends(Scale::linear(2.0, 2.0)), (1.0, 3.0));
    assert_eq!(ends(Scale::linear(0.0, 0.0)), (-1.0, 1.0));
    assert_eq!(ends(Scale::linear(f64::NAN, 1.0)), (0.0, 1.0));
    assert_eq!(ends(Scale::log(0.0, 20.0)), (0.02, 20.0));
    assert_eq!(ends(Scale::log(-1.0, -1.0)), (1e-3, 1.0));
    let (lo, hi) = ends(Scale::log(4.0, 4.0));
    assert!((lo * hi - 16.0).abs() < 1e-12 && (hi / lo - 10.0).abs() < 1e-12);
    assert_eq!(ends(Scale::log(0.3173, 12.53).nice()), (0.2, 20.0));
    assert_eq!(ends(Scale::log(0.1, 5.0).nice()), (0.1, 5.0));
    assert_eq!(ends(Scale::log(0.0011, 0.999).nice()), (0.001, 1.0));
    // Linear: a step of 1, 2 or 5 times a power of ten for at most 5 intervals.
    assert_eq!(ends(Scale::linear(0.13, 0.87).nice()), (0.0, 1.0));
    assert_eq!(ends(Scale::linear(-3.7, 41.0).nice()), (-10.0, 50.0));
    assert_eq!(ends(Scale::linear(0.0, 1.0).nice()), (0.0, 1.0));
    assert_eq!(Scale::linear(0.0, 1.0).clipping(&[-0.1, 0.5, f64::INFINITY]), (true, false));
    assert_eq!(Scale::log(0.1, 1.0).clipping(&[0.0, -3.0, 0.5, 2.0]), (false, true));
}

/// A weighted percentile equals the plain percentile of the list in which each value is
/// repeated as often as its (integer) weight: the `p` quantile of `n` values is the one at
/// sorted index `ceil(p n) - 1`.
#[test]
fn weighted_percentiles_match_repetition() {
    let values: Vec<f64> = (0..40).map(|i| f64::from((i * 37) % 40) * 0.25 - 3.0).collect();
    let weights: Vec<f64> = (0..40).map(|i| f64::from(i % 5)).collect();
    let mut expanded: Vec<f64> = Vec::new();
    for (v, w) in values.iter().zip(&weights) {
        expanded.extend(std::iter::repeat_n(*v, *w as usize));
    }
    expanded.sort_by(f64::total_cmp);
    let n = expanded.len() as f64;
    let reference = |p: f64| expanded[((p * n).ceil() as usize).max(1) - 1];
    for (lo, hi) in [(0.0, 1.0), (0.05, 0.95), (0.01, 0.99), (0.5, 0.5), (0.3, 0.7)] {
        let range = range_by_percentiles(&values, Some(&weights), lo, hi);
        assert_eq!(range, Some((reference(lo), reference(hi))), "{lo} .. {hi}");
    }
}

/// A few huge outliers do not move a 1..99 % range; outliers that are many texels but little
/// weight (a lat-long map's pole rows) are ignored only when weighted. Non-finite values are
/// skipped.
#[test]
fn percentile_range_ignores_outliers() {
    let mut values: Vec<f64> = (0..1000).map(|i| 1.0 + f64::from(i) / 1000.0).collect();
    values.extend([1e6, 3e7, 1e9, f64::NAN, f64::INFINITY]);
    let (lo, hi) = range_by_percentiles(&values, None, 0.01, 0.99).unwrap();
    assert!((1.0..1.02).contains(&lo) && hi > 1.98 && hi < 2.0, "{lo} .. {hi}");

    // 20 % of the texels are outliers, but they cover 0.1 % of the weight.
    let n = 1000;
    let values: Vec<f64> = (0..n).map(|i| if i % 5 == 0 { 1e5 } else { f64::from(i % 97) }).collect();
    let weights: Vec<f64> = values.iter().map(|&v| if v == 1e5 { 1e-5 } else { 1.0 }).collect();
    let (_, hi) = range_by_percentiles(&values, Some(&weights), 0.01, 0.99).unwrap();
    assert!(hi <= 96.0, "weighted: {hi}");
    let (_, hi) = range_by_percentiles(&values, None, 0.01, 0.99).unwrap();
    assert_eq!(hi, 1e5, "unweighted");

    assert_eq!(range_by_percentiles(&[f64::NAN], None, 0.0, 1.0), None);
    assert_eq!(range_by_percentiles(&[1.0, 2.0], Some(&[0.0, 0.0]), 0.0, 1.0), None);
    assert_eq!(range_by_percentiles(&[], None, 0.0, 1.0), None);
    assert_eq!(range_by_percentiles(&[3.0, 1.0, 2.0], None, 1.0, 0.0), Some((1.0, 3.0)));
}
