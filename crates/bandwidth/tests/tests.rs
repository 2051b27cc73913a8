//! Integration tests of the `bandwidth` crate, one binary with a module per topic. Every test
//! with a tolerance states it and why; the measured numbers are printed (`--nocapture`).

mod angular;
mod blurred_noise;
mod brute_force;
mod compare;
mod errors;
mod flat;
mod readings;
mod real_maps;
mod sinusoids;
mod split;
mod windowed_fft;
mod zero_padding;

/// Finds `../shared`, or skips a test without it where the run allows.
#[path = "../../../tests/support/shared_data.rs"]
mod shared_data;

use std::f64::consts::TAU;

use bandwidth::Image;
use rand::{SeedableRng, rngs::StdRng};

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// `cos(2 pi (x cos a + y sin a) / period + phase)`: a plane wave of `1 / period` cycles per
/// pixel running at `angle_deg` from the `x` axis.
pub fn sinusoid(width: usize, height: usize, period: f64, angle_deg: f64, phase: f64) -> Image {
    let a = angle_deg.to_radians();
    Image::from_fn(width, height, |x, y| (TAU / period * (x as f64 * a.cos() + y as f64 * a.sin()) + phase).cos())
}

/// Periodic separable Gaussian blur, the kernel cut at 4 sigma and normalized.
pub fn blur(image: &Image, sigma: f64) -> Image {
    let r = (4.0 * sigma).ceil() as i64;
    let kernel: Vec<f64> = (-r..=r).map(|i| (-((i * i) as f64) / (2.0 * sigma * sigma)).exp()).collect();
    let sum: f64 = kernel.iter().sum();
    let (w, h) = (image.width() as i64, image.height() as i64);
    let pass = |src: &Image, along_x: bool| {
        Image::from_fn(w as usize, h as usize, |x, y| {
            let mut acc = 0.0;
            for (i, k) in (-r..=r).zip(&kernel) {
                let (sx, sy) = if along_x {
                    ((x as i64 + i).rem_euclid(w), y as i64)
                } else {
                    (x as i64, (y as i64 + i).rem_euclid(h))
                };
                acc += k * src.get(sx as usize, sy as usize);
            }
            acc / sum
        })
    };
    pass(&pass(image, true), false)
}

/// `log2(estimate / truth)`; `-inf` for an estimate of 0, so a flat reading is never "close".
pub fn octaves(estimate: f64, truth: f64) -> f64 {
    (estimate / truth).log2()
}

/// The fraction of `values` within `limit` octaves of 0.
pub fn fraction_within(values: &[f64], limit: f64) -> f64 {
    values.iter().filter(|v| v.abs() <= limit).count() as f64 / values.len() as f64
}

/// Least-squares slope of `ys` against `xs`.
pub fn slope(xs: &[f64], ys: &[f64]) -> f64 {
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
