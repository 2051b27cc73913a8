//! Test 6: the windowed FFT reference on pure sinusoids.

use bandwidth::{Image, WindowedFftConfig, window_spread, windowed_fft_bandwidth};

use crate::sinusoid;

/// Every window of a sinusoid of period 3 to 16 pixels (1/3 to 1/16 cycle per pixel, 2 to 10
/// cycles in a 32-pixel window), at 0, 30 and 45 degrees, reads its frequency within 20%. The
/// radii lie on a grid of 1/64 cycle per pixel (2x zero padding), so a reading can be off by
/// half a step, 1/128, 12.5% of the lowest frequency here; the measured error is printed.
#[test]
fn sinusoids_read_their_frequency_within_twenty_percent() {
    let config = WindowedFftConfig::default();
    let mut worst = 0.0f64;
    for period in [3.0, 4.0, 6.0, 8.0, 11.0, 16.0] {
        for angle in [0.0, 30.0, 45.0] {
            let map = windowed_fft_bandwidth(&sinusoid(96, 80, period, angle, 0.3), &config).unwrap();
            assert_eq!((map.columns(), map.rows()), (9, 7));
            for f in map.frequency() {
                let error = (f * period - 1.0).abs();
                assert!(error <= 0.2, "period {period} at {angle} degrees reads {f:.4}");
                worst = worst.max(error);
            }
        }
    }
    println!("windowed fft: worst relative error on sinusoids {worst:.4}");
}

/// Without the window's spread subtracted, a line reads `f + spread` (to half a radius step,
/// 1/128): the spread is the window's own widening, not a fitted constant.
#[test]
fn the_window_spread_is_the_line_widening() {
    let spread = window_spread(32, 0.95);
    assert!((spread * 32.0 - 0.94).abs() < 0.02, "spread {spread}");
    let raw = WindowedFftConfig { subtract_window_spread: false, ..WindowedFftConfig::default() };
    let map = windowed_fft_bandwidth(&sinusoid(64, 64, 4.0, 0.0, 0.0), &raw).unwrap();
    for f in map.frequency() {
        assert!((f - 0.25 - spread).abs() <= 1.0 / 128.0 + 1e-12, "{f} vs {}", 0.25 + spread);
    }
}

/// Constant windows read 0, and the centres are where the map says.
#[test]
fn flat_windows_read_zero() {
    let map = windowed_fft_bandwidth(&Image::from_fn(64, 48, |_, _| 2.5), &WindowedFftConfig::default()).unwrap();
    assert_eq!((map.columns(), map.rows()), (5, 3));
    assert_eq!(map.centre(4, 2), (48, 32));
    assert!(map.frequency().iter().all(|f| *f == 0.0));
}
