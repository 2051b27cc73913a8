//! Test 1 and the calibration of `c`: pure sinusoids of known frequency.

use bandwidth::{Config, DEFAULT_C, local_bandwidth};

use crate::{fraction_within, median, octaves, sinusoid};

const N: usize = 256;
/// Periods from 8 to 64 pixels (1/8 to 1/64 cycle per pixel), dyadic and not.
const PERIODS: [f64; 7] = [8.0, 11.0, 16.0, 23.0, 32.0, 45.0, 64.0];
const ANGLES_DEG: [f64; 3] = [0.0, 30.0, 45.0];
/// Periods that do not divide 256, and every slanted wave, meet themselves with a jump at the
/// periodic seam. The jump can only make a level finer than `j*` significant, and only at pixels
/// covered by a coefficient of that level straddling the seam. For periods up to 64, `j* <= 4`,
/// so the levels in question are 1 to 3, whose D4 supports are at most 3 * 8 - 2 = 22 pixels:
/// a margin of 24 pixels leaves only pixels no such coefficient reaches. (Measured: no pixel
/// beyond 6 pixels from the border is off by more than an octave.)
const MARGIN: usize = 24;

/// `log2(estimate / f)` over the pixels at least `MARGIN` from the border.
fn ratios(period: f64, angle_deg: f64, phase: f64, config: &Config) -> Vec<f64> {
    let map = local_bandwidth(&sinusoid(N, N, period, angle_deg, phase), config).unwrap();
    let mut out = Vec::new();
    for y in MARGIN..N - MARGIN {
        for x in MARGIN..N - MARGIN {
            out.push(octaves(map.frequency_at(x, y), 1.0 / period));
        }
    }
    out
}

/// Test 1: within one octave on at least 95% of the pixels away from the border, for every
/// period, angle and two phases. One octave is the resolution of the estimate itself (`c 2^-j*`
/// moves in octaves), and 95% leaves room for the few pixels where the level changes.
#[test]
fn sinusoids_read_their_frequency_within_an_octave() {
    let config = Config::default();
    let mut worst = (f64::INFINITY, 0.0, 0.0);
    for period in PERIODS {
        for angle in ANGLES_DEG {
            for phase in [0.3, 2.0] {
                let within = fraction_within(&ratios(period, angle, phase, &config), 1.0);
                assert!(
                    within >= 0.95,
                    "period {period} at {angle} degrees, phase {phase}: {within:.3} within an octave"
                );
                if within < worst.0 {
                    worst = (within, period, angle);
                }
            }
        }
    }
    println!("sinusoids: worst fraction within an octave {:.4} (period {}, {} degrees)", worst.0, worst.1, worst.2);
}

/// The calibration: with `c = 1` (a level read as its band's upper edge) the median of
/// `log2(estimate / f)` over every test pixel is the overshoot `c` must undo, and
/// [`DEFAULT_C`] must be `2^-median` within a quarter octave (half the spacing of the levels'
/// half-octave offsets the non-dyadic periods produce).
#[test]
fn c_is_the_calibrated_constant() {
    let config = Config { c: 1.0, ..Config::default() };
    let mut all = Vec::new();
    for period in PERIODS {
        for angle in ANGLES_DEG {
            all.extend(ratios(period, angle, 0.3, &config));
        }
    }
    let overshoot = median(&all);
    let (lo, hi) = all.iter().fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
    println!("calibration: with c = 1 the estimate overshoots by {lo:.2} to {hi:.2} octaves, median {overshoot:.3}");
    assert!(
        (DEFAULT_C.log2() + overshoot).abs() <= 0.25,
        "c = 2^{:.3}, calibration says 2^{:.3}",
        DEFAULT_C.log2(),
        -overshoot
    );
    assert!((DEFAULT_C - 2f64.powf(-2.5)).abs() < 1e-15);
}

/// The map's bookkeeping: frequency `c 2^-j*`, 0 exactly where no level is significant, and the
/// Nyquist flag exactly where `j* = 1`.
#[test]
fn frequency_level_and_nyquist_flag_agree() {
    let config = Config::default();
    let map = local_bandwidth(&sinusoid(64, 32, 5.0, 20.0, 0.0), &config).unwrap();
    assert_eq!((map.width(), map.height(), map.levels()), (64, 32, 5));
    for y in 0..32 {
        for x in 0..64 {
            let f = map.frequency_at(x, y);
            match map.level_at(x, y) {
                Some(j) => assert_eq!(f, DEFAULT_C * 0.5f64.powi(j as i32)),
                None => assert_eq!(f, 0.0),
            }
            assert_eq!(map.at_nyquist(x, y), map.level_at(x, y) == Some(1));
        }
    }
    // A period of 5 pixels is above what the estimate can hold: every pixel is at the limit.
    assert_eq!(map.nyquist_count(), 64 * 32);
    assert_eq!(map.max_frequency(), DEFAULT_C / 2.0);
}
