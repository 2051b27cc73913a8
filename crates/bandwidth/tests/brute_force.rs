//! The separable sliding maximum against the definition, coefficient by coefficient: for every
//! pixel and level, the largest magnitude among all coefficients whose wrapped support covers
//! the pixel, then eq. 7. Exact agreement (the same f64 values are compared, no arithmetic
//! differs), on random images, both wavelets and all three modes.

use bandwidth::{
    BandwidthMap, Config, Image, Wavelet, latlong_bandwidth, local_bandwidth, local_bandwidth_zero_padded,
};
use dwt::wavedec2;
use rand::Rng;

use crate::rng;

/// Whether the wrapped `support` contains `p` on an axis of `n` pixels.
fn covers(support: std::ops::Range<i64>, p: usize, n: usize) -> bool {
    support.into_iter().any(|v| v.rem_euclid(n as i64) as usize == p)
}

/// `j*` (0 for none) of pixel `(px, py)` of `image`, by the definition.
fn reference_level(image: &Image, levels: usize, config: &Config, px: usize, py: usize) -> u8 {
    let (w, h) = (image.width(), image.height());
    let dec = wavedec2(image, config.wavelet, levels).unwrap();
    let mut lambda = vec![0.0f64; levels];
    for j in 1..=levels {
        for ky in 0..h >> j {
            if !covers(config.wavelet.support(j, ky), py, h) {
                continue;
            }
            for kx in 0..w >> j {
                if !covers(config.wavelet.support(j, kx), px, w) {
                    continue;
                }
                for o in 0..3 {
                    let v = dec.details[j - 1][o].get(kx, ky).abs();
                    if v >= config.noise_floor * (1u64 << j) as f64 {
                        lambda[j - 1] = lambda[j - 1].max(v);
                    }
                }
            }
        }
    }
    let max = lambda.iter().copied().fold(0.0, f64::max);
    let mut sum = 0.0;
    for (j, l) in lambda.iter().enumerate() {
        sum += l;
        if max > 0.0 && sum >= config.eps * max {
            return (j + 1) as u8;
        }
    }
    0
}

fn check(name: &str, extended: &Image, map: &BandwidthMap, config: &Config) {
    for y in 0..map.height() {
        for x in 0..map.width() {
            let want = reference_level(extended, map.levels(), config, x, y);
            assert_eq!(map.level()[y * map.width() + x], want, "{name}: pixel ({x}, {y})");
        }
    }
}

/// Random values with a few flat patches (so "no level" and the floor occur too).
fn random_image(seed: u64, w: usize, h: usize) -> Image {
    let mut r = rng(seed);
    Image::from_fn(w, h, |x, y| if (x / 4 + y / 4) % 3 == 0 { 0.25 } else { r.random_range(-1.0..1.0) })
}

#[test]
fn sliding_maximum_matches_the_definition() {
    for wavelet in [Wavelet::D4, Wavelet::Haar] {
        let config = Config { wavelet, noise_floor: 1e-3, ..Config::default() };
        // Periodic, 24 x 16: 3 levels, grids down to 3 x 2 (supports wrap more than once).
        let image = random_image(1, 24, 16);
        check("periodic", &image, &local_bandwidth(&image, &config).unwrap(), &config);
        // Zero padded, 11 x 6 with 3 levels: padded to 24 x 16.
        let image = random_image(2, 11, 6);
        let padded_config = Config { levels: Some(3), ..config };
        let mut padded = Image::zeros(24, 16);
        for y in 0..6 {
            for x in 0..11 {
                padded.data_mut()[y * 24 + x] = image.get(x, y);
            }
        }
        check("zero padded", &padded, &local_bandwidth_zero_padded(&image, &padded_config).unwrap(), &padded_config);
        // Lat-long, 16 x 8: the extension below is row 7 - i turned by half a turn.
        let image = random_image(3, 16, 8);
        let extended =
            Image::from_fn(16, 16, |x, y| if y < 8 { image.get(x, y) } else { image.get((x + 8) % 16, 15 - y) });
        let map = latlong_bandwidth(&image, &config).unwrap();
        check("lat-long", &extended, map.pixels(), &config);
    }
}
