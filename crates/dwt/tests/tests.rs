//! Integration tests of the `dwt` crate, one binary with a module per topic.

mod errors;
mod golden;
mod known_answers;
mod roundtrip;

use dwt::Image;
use rand::{Rng, SeedableRng, rngs::StdRng};

/// Uniform values in [-1, 1): the magnitude the absolute tolerances are stated for.
pub fn random_signal(rng: &mut StdRng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

pub fn random_image(rng: &mut StdRng, width: usize, height: usize) -> Image {
    Image::new(width, height, random_signal(rng, width * height)).unwrap()
}

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// Largest absolute difference; panics on different lengths so a short result cannot pass.
pub fn max_abs_diff(got: &[f64], want: &[f64]) -> f64 {
    assert_eq!(got.len(), want.len(), "lengths differ");
    got.iter().zip(want).map(|(g, w)| (g - w).abs()).fold(0.0, f64::max)
}
