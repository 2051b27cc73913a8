//! Comparing two bandwidth maps: the distribution of their log2 ratios and their rank
//! correlation. A diagnostic that reports; it sets no threshold.

use crate::Error;
use crate::estimate::BandwidthMap;
use crate::fft::WindowedFftMap;

/// The percentiles [`Comparison::log2_ratio`] holds.
pub const PERCENTILES: [f64; 5] = [5.0, 25.0, 50.0, 75.0, 95.0];

/// How two maps of the same points compare.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Number of points compared.
    pub points: usize,
    /// Points where both maps are positive: the log2 ratios are taken over these.
    pub both_positive: usize,
    /// Points where exactly one map is 0 (a flat reading on one side only).
    pub one_zero: usize,
    /// `log2(estimate / reference)` at [`PERCENTILES`] (linear interpolation between order
    /// statistics, as numpy's default); NaN when no point has both positive.
    pub log2_ratio: [f64; 5],
    /// Spearman's rank correlation over all points (tied values share their mean rank); `None`
    /// when either map is constant.
    pub spearman: Option<f64>,
}

/// Compares `estimate` with `reference`, point by point.
pub fn compare_maps(estimate: &[f64], reference: &[f64]) -> Result<Comparison, Error> {
    if estimate.len() != reference.len() {
        return Err(Error::LengthMismatch(estimate.len(), reference.len()));
    }
    if let Some(index) = estimate.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { what: "estimate", index });
    }
    if let Some(index) = reference.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { what: "reference", index });
    }
    let mut ratios: Vec<f64> =
        estimate.iter().zip(reference).filter(|(e, r)| **e > 0.0 && **r > 0.0).map(|(e, r)| (e / r).log2()).collect();
    ratios.sort_by(f64::total_cmp);
    let one_zero = estimate.iter().zip(reference).filter(|(e, r)| (**e > 0.0) != (**r > 0.0)).count();
    Ok(Comparison {
        points: estimate.len(),
        both_positive: ratios.len(),
        one_zero,
        log2_ratio: PERCENTILES.map(|p| percentile(&ratios, p)),
        spearman: spearman(estimate, reference),
    })
}

/// The wavelet map read at the windowed FFT's windows, for [`compare_maps`]: the largest
/// frequency over the central half of each window (the `window / 2` square around its centre,
/// where the Hann weight exceeds 1/2). The maximum because both measures are upper edges: the
/// 95% radius is set by the highest-frequency content that carries energy anywhere in the window.
pub fn wavelet_at_windows(map: &BandwidthMap, fft: &WindowedFftMap) -> Vec<f64> {
    let half = fft.window() / 4;
    let mut out = Vec::with_capacity(fft.columns() * fft.rows());
    for j in 0..fft.rows() {
        for i in 0..fft.columns() {
            let (cx, cy) = fft.centre(i, j);
            let mut best = 0.0f64;
            for y in cy - half..(cy + half).min(map.height()) {
                for x in cx - half..(cx + half).min(map.width()) {
                    best = best.max(map.frequency_at(x, y));
                }
            }
            out.push(best);
        }
    }
    out
}

/// Percentile `p` (0..=100) of sorted values with linear interpolation; NaN when empty.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        n => {
            let pos = p / 100.0 * (n - 1) as f64;
            let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
            sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64)
        }
    }
}

/// Ranks from 1, ties sharing their mean rank.
fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut start = 0;
    while start < order.len() {
        let mut end = start + 1;
        while end < order.len() && values[order[end]] == values[order[start]] {
            end += 1;
        }
        let mean = (start + end + 1) as f64 / 2.0;
        for &i in &order[start..end] {
            ranks[i] = mean;
        }
        start = end;
    }
    ranks
}

/// Spearman's rank correlation of two equally long samples (ties share their mean rank);
/// `None` when either is constant.
pub fn spearman(a: &[f64], b: &[f64]) -> Option<f64> {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in ra.iter().zip(&rb) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    (saa > 0.0 && sbb > 0.0).then(|| sab / (saa * sbb).sqrt())
}
