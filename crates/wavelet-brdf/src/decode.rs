//! Reading a `wavelet-brdf` payload back: the value of any direction pair at any level of detail
//! (sections 5.3-5.4), by the same steps the WGSL decoder (`gpu`, `wavelet_brdf.wgsl`) takes.

use glam::DVec3;

use crate::Error;
use crate::grid::Grid;
use crate::transform;

/// A decoded `wavelet-brdf` asset, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct Decoded {
    grid: Grid,
    epsilon: f64,
    channel_mean: [f64; 3],
    /// Per coefficient position: its slice in `slices`, 0 for the zero slice.
    map: Vec<u32>,
    /// `K + 1` slices of `n^2 x 3` values, slice 0 all zeros (section 5.2's shared zero slice),
    /// quantized codes already turned into values.
    slices: Vec<f32>,
}

impl Decoded {
    /// Checks the payload (as the asset reader does) and lays its slices out behind a zero slice.
    pub fn from_payload(payload: &asset::WaveletBrdf) -> Result<Decoded, Error> {
        payload.check().map_err(Error::Invalid)?;
        let grid = Grid::new(payload.side as usize)?;
        let slice_len = grid.cells() * 3;
        let mut slices = vec![0.0f32; slice_len];
        match &payload.coefficients {
            asset::WaveletCoefficients::Float(values) => slices.extend_from_slice(values),
            asset::WaveletCoefficients::Quantized { offset, step, codes } => {
                slices.extend(codes.iter().enumerate().map(|(k, &q)| {
                    let range = k / slice_len * 3 + k % 3;
                    offset[range] + f32::from(q) * step[range]
                }));
            }
        }
        Ok(Decoded {
            grid,
            epsilon: payload.epsilon,
            channel_mean: payload.channel_mean,
            map: payload.map.clone(),
            slices,
        })
    }

    pub fn grid(&self) -> Grid {
        self.grid
    }

    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    pub fn channel_mean(&self) -> [f64; 3] {
        self.channel_mean
    }

    /// Coefficient positions per stored slice: the compression ratio `r_c`.
    pub fn ratio(&self) -> f64 {
        self.map.len() as f64 / self.map.iter().filter(|&&m| m != 0).count().max(1) as f64
    }

    /// Per coefficient position, its slice in [`Decoded::slices`] (0: the zero slice).
    pub fn map(&self) -> &[u32] {
        &self.map
    }

    /// The zero slice and the `K` stored slices, `n^2 x 3` values each (outgoing cell, then
    /// channel): what a GPU uploads.
    pub fn slices(&self) -> &[f32] {
        &self.slices
    }

    /// Where coefficient position `p` of outgoing cell `o` starts in `slices` (3 channels).
    fn coefficient_at(&self, p: usize, o: usize) -> usize {
        (self.map[p] as usize * self.grid.cells() + o) * 3
    }

    /// Coefficient position `p` of outgoing cell `o`.
    fn coefficient(&self, p: usize, o: usize) -> [f64; 3] {
        let at = self.coefficient_at(p, o);
        [0, 1, 2].map(|c| f64::from(self.slices[at + c]))
    }

    /// The log-encoded value at outgoing cell `o` and incoming cell `i` at the integer level of
    /// detail `lod` (`0..=J`), by point synthesis (`transform::synthesis`).
    pub fn log_value(&self, o: usize, i: usize, lod: usize) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for (p, weight) in transform::synthesis(self.grid, i, lod) {
            let c = self.coefficient(p, o);
            for k in 0..3 {
                sum[k] += weight * c[k];
            }
        }
        sum
    }

    /// `eps mu` per channel: below it the log encoding's precision is relative to `eps mu`
    /// rather than to `f` (`errors`).
    pub fn floor(&self) -> [f64; 3] {
        self.channel_mean.map(|m| self.epsilon * m)
    }

    /// `f = mu (exp(value) - eps)`, clamped at 0: the log encoding undone.
    pub fn from_log(&self, log: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|c| (self.channel_mean[c] * (log[c].exp() - self.epsilon)).max(0.0))
    }

    /// `f(wi, wo)` in 1/sr at level of detail `lod` in `[0, J]` (`0` is full resolution), 0 when
    /// either direction is below the horizon:
    ///
    /// 1. the four outgoing cells around `wo` and the four incoming cells around `wi`, with their
    ///    bilinear weights ([`Grid::bilinear`]; section 5.4.2's magnification, in both
    ///    directions);
    /// 2. the log-encoded value of each of the 16 cell pairs at the integer levels `floor(lod)`
    ///    and `floor(lod) + 1` (up to `J`), blended by the fraction of `lod` (section 5.4.1);
    /// 3. the bilinear sum of those values, in the log domain, and [`Decoded::from_log`].
    pub fn eval(&self, wi: DVec3, wo: DVec3, lod: f64) -> [f64; 3] {
        let (Some(outgoing), Some(incoming)) = (self.grid.bilinear(wo), self.grid.bilinear(wi)) else {
            return [0.0; 3];
        };
        let lod = lod.clamp(0.0, self.grid.levels() as f64);
        let coarse = lod.floor() as usize;
        let blend = lod - coarse as f64;
        let mut sum = [0.0; 3];
        for (o, wo_weight) in outgoing {
            for (i, wi_weight) in incoming {
                let mut add = |value: [f64; 3], weight: f64| {
                    for c in 0..3 {
                        sum[c] += wo_weight * wi_weight * weight * value[c];
                    }
                };
                add(self.log_value(o, i, coarse), 1.0 - blend);
                if blend > 0.0 {
                    add(self.log_value(o, i, coarse + 1), blend);
                }
            }
        }
        self.from_log(sum)
    }

    /// Every log-encoded value at the integer level of detail `lod`, by the inverse transform of
    /// whole slices (`dwt::waverec2`: independent of [`Decoded::log_value`]'s point
    /// synthesis), in the layout of `Resampled::log_encoded`.
    pub fn decode_log(&self, lod: usize) -> Vec<f64> {
        let cells = self.grid.cells();
        transform::map_slices(
            self.grid,
            |o, c, p| f64::from(self.slices[self.coefficient_at(p, o) + c]),
            |layout| transform::inverse(self.grid, layout, lod),
            |o, c, i| (o * cells + i) * 3 + c,
        )
    }

    /// Every value in 1/sr at the integer level of detail `lod`, in the layout of
    /// `Resampled::values`.
    pub fn decode(&self, lod: usize) -> Vec<[f64; 3]> {
        self.decode_log(lod).chunks_exact(3).map(|v| self.from_log([v[0], v[1], v[2]])).collect()
    }
}
