//! Histograms for `sampling::chi2`, the library's goodness-of-fit test, and tests of that test.
//!
//! The pdfs tested here are piecewise constant on an `nu` x `nv` grid, so the cell integrals are
//! exact sums of pdf times overlap area; the histogram grids are deliberately not aligned with
//! the distribution grids, so cells straddle bin edges and see the sampling within a bin too.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
pub use sampling::chi2::{ACCEPT, Chi2, REJECT, chi2_test};

/// For each of `n_cells` equal cells of `[0, 1)`, the bins of an `n_bins` grid it overlaps and the
/// length of the overlap.
fn overlaps(n_cells: usize, n_bins: usize) -> Vec<Vec<(usize, f64)>> {
    (0..n_cells)
        .map(|c| {
            let (a, b) = (c as f64 / n_cells as f64, (c + 1) as f64 / n_cells as f64);
            (0..n_bins)
                .filter_map(|j| {
                    let (lo, hi) = (j as f64 / n_bins as f64, (j + 1) as f64 / n_bins as f64);
                    let len = hi.min(b) - lo.max(a);
                    (len > 0.0).then_some((j, len))
                })
                .collect()
        })
        .collect()
}

fn cell(x: f64, n_cells: usize) -> usize {
    assert!((0.0..1.0).contains(&x), "sample {x} outside [0, 1)");
    ((x * n_cells as f64) as usize).min(n_cells - 1)
}

/// Draws `n_samples` points with `sample(u)`, `u` uniform from a fixed seed, and tests them
/// against `pdf`, a density constant on each cell of an `n_bins[0]` x `n_bins[1]` grid, with a
/// histogram of `n_cells[0]` x `n_cells[1]` cells.
pub fn chi2_2d(
    mut sample: impl FnMut([f64; 2]) -> [f64; 2],
    pdf: impl Fn([f64; 2]) -> f64,
    n_bins: [usize; 2],
    n_cells: [usize; 2],
    n_samples: usize,
    seed: u64,
) -> Chi2 {
    let [nu, nv] = n_bins;
    let [hu, hv] = n_cells;
    let bin_pdf: Vec<f64> =
        (0..nu * nv).map(|k| pdf([((k % nu) as f64 + 0.5) / nu as f64, ((k / nu) as f64 + 0.5) / nv as f64])).collect();
    let (over_u, over_v) = (overlaps(hu, nu), overlaps(hv, nv));
    let mut expected = vec![0.0; hu * hv];
    for (cv, ov) in over_v.iter().enumerate() {
        for (cu, ou) in over_u.iter().enumerate() {
            let bin_pdf = &bin_pdf;
            let mass: f64 =
                ov.iter().flat_map(|&(jv, lv)| ou.iter().map(move |&(ju, lu)| lv * lu * bin_pdf[jv * nu + ju])).sum();
            expected[cv * hu + cu] = mass * n_samples as f64;
        }
    }
    let mut rng = StdRng::seed_from_u64(seed);
    let mut observed = vec![0u64; hu * hv];
    for _ in 0..n_samples {
        let p = sample([rng.random(), rng.random()]);
        observed[cell(p[1], hv) * hu + cell(p[0], hu)] += 1;
    }
    chi2_test(&observed, &expected)
}

/// [`chi2_2d`] for a sampler of `[0, 1)`.
pub fn chi2_1d(
    mut sample: impl FnMut(f64) -> f64,
    pdf: impl Fn(f64) -> f64,
    n_bins: usize,
    n_cells: usize,
    n_samples: usize,
    seed: u64,
) -> Chi2 {
    chi2_2d(|u| [sample(u[0]), 0.5], |p| pdf(p[0]), [n_bins, 1], [n_cells, 1], n_samples, seed)
}

#[track_caller]
pub fn assert_accepts(result: Chi2, what: &str) {
    assert!(result.p_value > ACCEPT, "{what}: correct sampler rejected: {result:?}");
}

#[track_caller]
pub fn assert_rejects(result: Chi2, what: &str) {
    assert!(result.p_value < REJECT, "{what}: wrong sampler accepted: {result:?}");
}

// The test itself, on counts whose answer is known.

#[test]
fn chi2_matches_exact_counts_with_p_one() {
    let result = chi2_test(&[10, 20, 30], &[10.0, 20.0, 30.0]);
    assert_eq!((result.statistic, result.dof, result.p_value), (0.0, 2, 1.0));
}

#[test]
fn chi2_known_statistic_and_p_value() {
    // (30-20)^2/20 + (10-20)^2/20 = 10 with 1 degree of freedom: p = erfc(sqrt(5)) = 0.0015654.
    let result = chi2_test(&[30, 10], &[20.0, 20.0]);
    assert_eq!((result.statistic, result.dof), (10.0, 1));
    assert!((result.p_value - 0.001_565_402_258).abs() < 1e-9, "{result:?}");
}

#[test]
fn chi2_fails_a_sample_in_a_zero_cell() {
    assert_eq!(chi2_test(&[99, 1], &[100.0, 0.0]).p_value, 0.0);
}

#[test]
fn chi2_pools_cells_expecting_fewer_than_five() {
    // The three small cells pool into one expecting 5 and observing 5: no contribution, where
    // unpooled they would add (3-2)^2/2 + (0-2)^2/2 + (2-1)^2/1 = 3.5.
    let result = chi2_test(&[3, 0, 2, 92], &[2.0, 2.0, 1.0, 92.0]);
    assert_eq!((result.statistic, result.dof), (0.0, 1));
}
