//! Pearson's chi-square goodness-of-fit test of a sampler against a density, the way Mitsuba's
//! and pbrt's sampler tests do it: bin the domain into a histogram, take expected counts from
//! the integral of the density over each bin, pool bins expecting fewer than 5 samples (below
//! that the chi-square approximation of Pearson's statistic is poor), and read the p-value from
//! the chi-square distribution. A sample in a bin of zero expected count fails outright.
//!
//! It lives in the library rather than in one crate's tests because every sampler built on
//! these distributions (importance tables, environment sampling) is held to it.

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The p-value a correct sampler must beat. With fixed seeds every test is deterministic; this
/// is the significance a fresh seed would need, 1 false alarm in 100.
pub const ACCEPT: f64 = 0.01;
/// The p-value a wrong sampler must fall below: far from anything a correct one produces.
pub const REJECT: f64 = 1e-6;
/// Cells expecting fewer samples than this are pooled.
const MIN_EXPECTED: f64 = 5.0;

#[derive(Debug)]
pub struct Chi2 {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
}

/// Tests `observed` counts against `expected` counts (same total).
///
/// # Panics
/// If the two slices differ in length or their totals differ by more than 1e-9 relative: that
/// is a bug in the calling test, not a failed fit.
pub fn chi2_test(observed: &[u64], expected: &[f64]) -> Chi2 {
    assert_eq!(observed.len(), expected.len());
    let n_observed = observed.iter().sum::<u64>() as f64;
    let n_expected: f64 = expected.iter().sum();
    assert!((n_observed - n_expected).abs() <= 1e-9 * n_observed, "{n_observed} samples but {n_expected} expected");
    if observed.iter().zip(expected).any(|(&o, &e)| o > 0 && e <= 0.0) {
        return Chi2 { statistic: f64::INFINITY, dof: 0, p_value: 0.0 };
    }
    let mut cells: Vec<(f64, f64)> =
        observed.iter().zip(expected).filter(|&(_, &e)| e > 0.0).map(|(&o, &e)| (o as f64, e)).collect();
    cells.sort_by(|a, b| a.1.total_cmp(&b.1));
    // Smallest cells first: they pool with each other until a pool expects MIN_EXPECTED; what is
    // left short at the end joins the last pool.
    let mut pools: Vec<(f64, f64)> = Vec::new();
    let mut pool = (0.0, 0.0);
    for (o, e) in cells {
        pool = (pool.0 + o, pool.1 + e);
        if pool.1 >= MIN_EXPECTED {
            pools.push(pool);
            pool = (0.0, 0.0);
        }
    }
    if pool.1 > 0.0 {
        match pools.last_mut() {
            Some(last) => *last = (last.0 + pool.0, last.1 + pool.1),
            None => pools.push(pool),
        }
    }
    let statistic: f64 = pools.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    // The counts sum to the number of samples: one constraint.
    let dof = pools.len() - 1;
    let p_value = if dof == 0 { 1.0 } else { ChiSquared::new(dof as f64).unwrap().sf(statistic) };
    Chi2 { statistic, dof, p_value }
}
