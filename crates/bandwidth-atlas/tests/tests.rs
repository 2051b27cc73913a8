//! Integration tests of the `bandwidth-atlas` crate, one binary with a module per topic. Every test
//! with a tolerance states it and why; measured numbers are printed (`--nocapture`).

mod atlas;
mod flat;
mod pca;
mod phong;
mod view;

use merl::analytic::Analytic;
use merl::{Dims, MerlTable};

/// A MERL table of energy-normalized Phong of exponent `n`.
pub fn phong(n: f64) -> MerlTable {
    Analytic::Phong { n, ks: [1.0; 3], kd: [0.0; 3] }.table(Dims::MERL)
}

/// Least-squares slope of `ys` against `xs`.
pub fn slope(xs: &[f64], ys: &[f64]) -> f64 {
    let n = xs.len() as f64;
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}
