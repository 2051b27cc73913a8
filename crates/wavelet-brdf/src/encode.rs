//! From a BRDF to the payload of a `wavelet-brdf` asset: resampling (section 4.1), the log
//! encoding (5.1), the per-slice transform (4.2), the choice of kept positions (4.3), the
//! compression map and the quantisation (5.1-5.2).

use glam::DVec3;
use merl::{Interp, MerlTable};
use rayon::prelude::*;

use crate::Error;
use crate::grid::Grid;
use crate::transform;

/// The default bias of the log encoding (section 5.1: `eps` keeps the logarithm finite where
/// `f = 0`).
pub const DEFAULT_EPSILON: f64 = 0.01;

/// The default grid: 32 x 32 directions per hemisphere, the paper's `(32 x 32)^2`.
pub const DEFAULT_SIDE: usize = 32;

/// A BRDF sampled at the cell centres of a grid, for every pair of cells.
#[derive(Clone, Debug)]
pub struct Resampled {
    pub grid: Grid,
    /// `n^2 x n^2` RGB values in 1/sr, outgoing cell major: `values[o n^2 + i]`.
    pub values: Vec<[f64; 3]>,
    /// Samples where the source held no data, stored as 0.
    pub no_data: usize,
}

/// Samples `brdf(wi, wo)` at every pair of cell centres (`None`, no data, becomes 0 and is
/// counted).
pub fn resample(grid: Grid, brdf: impl Fn(DVec3, DVec3) -> Option<[f64; 3]> + Sync) -> Resampled {
    let cells = grid.cells();
    let rows: Vec<(Vec<[f64; 3]>, usize)> = (0..cells)
        .into_par_iter()
        .map(|o| {
            let wo = grid.direction(o);
            let mut missing = 0;
            let row = (0..cells)
                .map(|i| {
                    brdf(grid.direction(i), wo).unwrap_or_else(|| {
                        missing += 1;
                        [0.0; 3]
                    })
                })
                .collect();
            (row, missing)
        })
        .collect();
    let no_data = rows.iter().map(|(_, m)| m).sum();
    Resampled { grid, values: rows.into_iter().flat_map(|(row, _)| row).collect(), no_data }
}

/// [`resample`] of a MERL table, read by its trilinear lookup (`merl::Interp::Trilinear`): the
/// grid's samples fall between the table's, and the nearest lookup would copy its steps into
/// the wavelets.
pub fn resample_table(grid: Grid, table: &MerlTable) -> Resampled {
    resample(grid, |wi, wo| table.lookup(wi, wo, Interp::Trilinear))
}

impl Resampled {
    /// `mu` per channel, the mean of all samples (section 5.1), or 1 for a channel that is 0
    /// everywhere (any positive `mu` encodes it exactly).
    pub fn channel_mean(&self) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for v in &self.values {
            for c in 0..3 {
                sum[c] += v[c];
            }
        }
        sum.map(|s| if s > 0.0 { s / self.values.len() as f64 } else { 1.0 })
    }

    /// The log-encoded values `log((f + eps mu) / mu)`, in the layout of `values`, channel
    /// innermost.
    pub fn log_encoded(&self, epsilon: f64) -> Vec<f64> {
        let mean = self.channel_mean();
        self.values.iter().flat_map(|v| [0, 1, 2].map(|c| ((v[c] + epsilon * mean[c]) / mean[c]).ln())).collect()
    }
}

/// The transform of every slice of a log-encoded BRDF, before any coefficient is dropped.
#[derive(Clone, Debug)]
pub struct Coefficients {
    pub grid: Grid,
    pub epsilon: f64,
    pub channel_mean: [f64; 3],
    /// Position-major: coefficient position `p` of outgoing cell `o`, channel `c` is
    /// `values[(p n^2 + o) 3 + c]`, the layout of the asset's slices.
    pub values: Vec<f64>,
}

/// Log-encodes `resampled` and transforms each slice (one outgoing cell, one channel).
pub fn coefficients(resampled: &Resampled, epsilon: f64) -> Result<Coefficients, Error> {
    check_epsilon(epsilon)?;
    let grid = resampled.grid;
    let cells = grid.cells();
    let log = resampled.log_encoded(epsilon);
    // Slice (o, c) holds the incoming cells in the table's layout; its coefficients go
    // position-major.
    let values = transform::map_slices(
        grid,
        |o, c, i| log[(o * cells + i) * 3 + c],
        |slice| transform::forward(grid, slice),
        |o, c, p| (p * cells + o) * 3 + c,
    );
    Ok(Coefficients { grid, epsilon, channel_mean: resampled.channel_mean(), values })
}

/// Which coefficient positions to keep (section 4.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Keep {
    /// Every position: the transform alone, exact up to `f32`.
    All,
    /// `n^2 / ratio` positions, those of the largest energy: `ratio` must divide `n^2`, so that
    /// exactly `1 / ratio` of the coefficients are kept.
    Ratio(u32),
    /// The positions whose root-mean-square coefficient (over the outgoing cells and channels,
    /// in log units) is at least this.
    Threshold(f64),
}

/// Refuses a log-encoding bias outside [`asset::WAVELET_EPSILON_RANGE`] (what an asset may hold).
pub(crate) fn check_epsilon(epsilon: f64) -> Result<(), Error> {
    let range = asset::WAVELET_EPSILON_RANGE;
    if !range.contains(&epsilon) {
        return Err(Error::Invalid(format!(
            "the log encoding's epsilon must be a number from {:e} to {}, found {epsilon:?}",
            range.start(),
            range.end()
        )));
    }
    Ok(())
}

impl Keep {
    /// Refuses a setting no grid of this side can honour: a ratio that does not divide its `n^2`
    /// coefficient positions, a threshold that is not a number `>= 0`.
    pub fn check(self, grid: Grid) -> Result<(), Error> {
        let positions = grid.cells();
        match self {
            Keep::Ratio(ratio) if ratio == 0 || !positions.is_multiple_of(ratio as usize) => {
                Err(Error::Invalid(format!(
                    "a ratio of {ratio}:1 does not divide the {positions} coefficient positions of a {0} x {0} grid: \
                     use a power of two up to {positions}",
                    grid.side()
                )))
            }
            Keep::Threshold(t) if !(t.is_finite() && t >= 0.0) => {
                Err(Error::Invalid(format!("the threshold must be a number >= 0, found {t}")))
            }
            _ => Ok(()),
        }
    }
}

impl Coefficients {
    /// The energy (sum of squares) of each position's vector of `n^2 x 3` coefficients.
    pub fn position_energy(&self) -> Vec<f64> {
        self.values.chunks_exact(self.grid.cells() * 3).map(|v| v.iter().map(|x| x * x).sum()).collect()
    }

    /// The positions to keep, as a flag per position. Ties in energy keep the lower position.
    pub fn select(&self, keep: Keep) -> Result<Vec<bool>, Error> {
        keep.check(self.grid)?;
        let positions = self.grid.cells();
        let energy = self.position_energy();
        match keep {
            Keep::All => Ok(vec![true; positions]),
            Keep::Ratio(ratio) => {
                let mut order: Vec<usize> = (0..positions).collect();
                order.sort_by(|&a, &b| energy[b].total_cmp(&energy[a]).then(a.cmp(&b)));
                let mut kept = vec![false; positions];
                for &p in &order[..positions / ratio as usize] {
                    kept[p] = true;
                }
                Ok(kept)
            }
            Keep::Threshold(t) => {
                let entries = (self.grid.cells() * 3) as f64;
                Ok(energy.iter().map(|e| (e / entries).sqrt() >= t).collect())
            }
        }
    }

    /// The payload that keeps the positions flagged in `kept`, as `f32` or 8-bit codes.
    pub fn to_payload(&self, kept: &[bool], quantize: bool) -> asset::WaveletBrdf {
        let slice_len = self.grid.cells() * 3;
        let mut map = Vec::with_capacity(kept.len());
        let mut stored: Vec<&[f64]> = Vec::new();
        for (p, slice) in self.values.chunks_exact(slice_len).enumerate() {
            if kept[p] {
                stored.push(slice);
                map.push(stored.len() as u32);
            } else {
                map.push(0);
            }
        }
        let coefficients = if quantize {
            quantize_slices(&stored)
        } else {
            asset::WaveletCoefficients::Float(stored.iter().flat_map(|s| s.iter().map(|&v| v as f32)).collect())
        };
        asset::WaveletBrdf {
            side: self.grid.side() as u32,
            epsilon: self.epsilon,
            channel_mean: self.channel_mean,
            map,
            coefficients,
        }
    }
}

/// 8-bit codes per slice and channel: the channel's range in the slice cut into 255 steps, each
/// value rounded to the nearest step.
fn quantize_slices(slices: &[&[f64]]) -> asset::WaveletCoefficients {
    let (mut offset, mut step, mut codes) = (Vec::new(), Vec::new(), Vec::new());
    for slice in slices {
        let mut ranges = [(f64::INFINITY, f64::NEG_INFINITY); 3];
        for (k, v) in slice.iter().enumerate() {
            let r = &mut ranges[k % 3];
            *r = (r.0.min(*v), r.1.max(*v));
        }
        // The offset and step are stored as f32: quantize against the stored ones, so that the
        // reader's `offset + code step` is the value the code was chosen for.
        let stored = ranges.map(|(lo, hi)| (lo as f32, ((hi - lo) / 255.0) as f32));
        for (k, v) in slice.iter().enumerate() {
            let (lo, s) = stored[k % 3];
            let code = if s > 0.0 { ((v - f64::from(lo)) / f64::from(s)).round().clamp(0.0, 255.0) } else { 0.0 };
            codes.push(code as u8);
        }
        offset.extend(stored.map(|s| s.0));
        step.extend(stored.map(|s| s.1));
    }
    asset::WaveletCoefficients::Quantized { offset, step, codes }
}
