//! Test 3: Gaussian-blurred white noise, whose bandwidth is proportional to `1 / sigma`.

use bandwidth::{Config, Image, local_bandwidth};
use rand::Rng;

use crate::{blur, median, rng, slope};

/// The median estimate over the image follows `1 / sigma`: the least-squares slope of
/// `log2(median)` against `log2(sigma)`, sigma from 2 to 8 pixels in quarter octaves, is
/// `-1 +- 0.2`. The estimate moves in whole octaves, so a median of 9 steps over 2 octaves is a
/// staircase; 0.2 is what a staircase whose steps fall anywhere relative to the samples can
/// deviate from its line (measured: -0.93, and -0.89 for the geometric mean).
#[test]
fn median_follows_one_over_sigma() {
    let n = 256;
    let mut rng = rng(7);
    let noise = Image::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    let config = Config::default();
    let (mut log_sigma, mut log_median, mut log_geomean) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=8 {
        let sigma = 2.0 * (i as f64 / 4.0).exp2();
        let map = local_bandwidth(&blur(&noise, sigma), &config).unwrap();
        assert!(map.frequency().iter().all(|f| *f > 0.0), "sigma {sigma}: a pixel of blurred noise reads flat");
        log_sigma.push(sigma.log2());
        log_median.push(median(map.frequency()).log2());
        log_geomean.push(map.frequency().iter().map(|f| f.log2()).sum::<f64>() / (n * n) as f64);
    }
    let (s, g) = (slope(&log_sigma, &log_median), slope(&log_sigma, &log_geomean));
    println!("blurred noise: slope of the median {s:.3}, of the geometric mean {g:.3}; log2 medians {log_median:?}");
    assert!((s + 1.0).abs() <= 0.2, "slope {s:.3}");
}
