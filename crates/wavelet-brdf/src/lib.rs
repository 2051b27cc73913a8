//! Haar wavelet encoding of measured BRDFs for real-time rendering (Claustres, Barthe and Paulin,
//! *Wavelet encoding of BRDFs for real-time rendering*, Graphics Interface 2007, sections 4-5):
//! the tool `brdf-wavelet` and the previewer's `--brdf wavelet-brdf`.
//!
//! # The steps, and the choices the paper leaves open
//!
//! 1. **Resampling** ([`resample`], section 4.1). Directions use the paper's parameterization
//!    `(sin phi cos theta, cos phi, sin theta sin phi)`, `theta, phi` in `[0, pi]`: the upper
//!    hemisphere with its poles on the local `y` axis, in the tangent plane ([`grid`]). An
//!    `n x n` grid of cells (default `n = 32`, the paper's `(32 x 32)^2`) is sampled at its cell
//!    centres, for `wo` (one slice per outgoing cell) and `wi` (within a slice): `n^4` RGB values.
//!    A MERL table is read by its trilinear lookup ([`resample_table`]); where it holds no data
//!    the sample is 0 (counted and reported).
//! 2. **Log encoding** (section 5.1). `f~ = log((f + eps mu) / mu)` per channel, `mu` the
//!    channel's mean over all samples, `eps = 0.01` by default.
//! 3. **Transform** (section 4.2). Each slice and channel (`n x n` values over `wi`) gets the 2D
//!    non-standard orthonormal Haar transform over all `log2 n` levels, laid out in place
//!    ([`transform`] gives the layout and the synthesis formula).
//! 4. **Compression** (section 4.3). The paper "views a set of hemispherical wavelet coefficients
//!    as a vector" and drops the vectors of small magnitude, which can be read two ways. We take a
//!    vector to be one coefficient *position* of the slice transform taken across all `n^2`
//!    outgoing slices and the 3 channels (`3 n^2` values), and drop whole positions by energy
//!    ([`Keep`]). The reading is chosen by the paper's own Table 1: on the Lewis-like material
//!    (`kd 0.8, ks 0.2, n 10`) it gives mean relative errors at or below Table 1's Lewis row at
//!    4:1, 16:1 and 32:1 (tested), where dropping whole outgoing slices gives errors several
//!    times larger. It is also the reading under which section 5.2's storage works as written: a
//!    dropped position is one slice of the 3D texture (indexed by position, holding the outgoing
//!    hemisphere), so the **compression map** gives each position its slice, `0` being a shared
//!    slice of zeros (section 5.2). A ratio `r` keeps exactly `n^2 / r` positions, so exactly
//!    `1 / r` of the coefficients.
//! 5. **Quantisation** (section 5.1, optional). Each stored slice and channel keeps its range
//!    (`offset`, `step`, as `f32`) and 8-bit codes `round((c - offset) / step)`, `step = range /
//!    255`: the error of a coefficient is at most `step / 2`.
//! 6. **Reconstruction** ([`Decoded::eval`], sections 5.3-5.4). Level of detail `lod` in
//!    `[0, log2 n]` leaves out the finest `floor(lod)` levels and blends linearly to the next
//!    (section 5.4.1; `0` is full resolution). Magnification (section 5.4.2) is bilinear between
//!    cell centres over `wi` and over `wo`, on the log-encoded values: by linearity this is the
//!    paper's interpolation of the coefficients, computed exactly from the 16 surrounding cell
//!    pairs rather than through texture filtering of the coefficient layout (whose bands do not
//!    line up with the cells). Then `f = mu (exp(f~) - eps)`, clamped at 0. Beyond the outermost
//!    cell centres the grid clamps; directions below the horizon give 0.
//!
//! # Errors ([`errors`])
//!
//! As in the paper's Table 1, over the resampled samples (all pairs of cell centres and all three
//! channels): `rms`, the root mean square of `f - f'` in 1/sr, and `mean_relative_error`, the
//! mean of `|f - f'| / f` over the samples with `f > 0`, as a fraction. Tables with values many
//! decades below their mean (mirror-like materials, or real-derived tables whose fits reach
//! `1e-15`) make the second unbounded: the log encoding is relative to `f + eps mu`, so a value far
//! below `eps mu` comes back as a value near `eps mu`. `mean_relative_error_above_floor` takes the
//! same mean over the samples with `f >= eps mu` only, where the encoding is relative to `f`.
//!
//! Without compression or quantisation the only loss is the `f32` storage of coefficients: the
//! log-encoded values are exact to about `1e-7` of the coefficients' size, so `|f - f'|` stays
//! below `1e-5 (f + eps mu)` (the encoding is relative to `f + eps mu`, not to `f`). The
//! log-domain squared error of a compressed asset equals the energy of the dropped positions
//! (Parseval, the transform being orthonormal).

pub mod grid;
pub mod transform;

mod decode;
mod encode;

pub use decode::Decoded;
pub use encode::{
    Coefficients, DEFAULT_EPSILON, DEFAULT_SIDE, Keep, Resampled, coefficients, resample, resample_table,
};
pub use grid::Grid;

/// A setting or a payload this crate cannot use.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("{0}")]
    Invalid(String),
}

/// What to encode and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    pub epsilon: f64,
    pub keep: Keep,
    pub quantize: bool,
}

impl Config {
    /// Refuses settings that cannot encode a table on `grid` (the checks [`encode`] makes), so
    /// that a caller can refuse them before reading anything.
    pub fn check(&self, grid: Grid) -> Result<(), Error> {
        encode::check_epsilon(self.epsilon)?;
        self.keep.check(grid)
    }
}

impl Default for Config {
    fn default() -> Config {
        Config { epsilon: DEFAULT_EPSILON, keep: Keep::Ratio(4), quantize: false }
    }
}

/// An encoded BRDF and what the encoding kept.
#[derive(Clone, Debug)]
pub struct Encoded {
    pub payload: asset::WaveletBrdf,
    /// Coefficient positions kept, of `n^2`.
    pub kept_positions: usize,
    /// Coefficients kept (`3 n^2` per kept position), of `3 n^4`.
    pub kept_coefficients: usize,
    pub total_coefficients: usize,
    /// The sum of squares of the dropped coefficients (log units): the log-domain squared error
    /// before quantisation.
    pub dropped_energy: f64,
}

impl Encoded {
    /// `total / kept` coefficients, the paper's `r_c`.
    pub fn ratio(&self) -> f64 {
        self.total_coefficients as f64 / self.kept_coefficients.max(1) as f64
    }
}

/// Log-encodes, transforms and compresses `resampled` (steps 2-5 of the crate docs).
pub fn encode(resampled: &Resampled, config: Config) -> Result<Encoded, Error> {
    let coefficients = coefficients(resampled, config.epsilon)?;
    let kept = coefficients.select(config.keep)?;
    let energy = coefficients.position_energy();
    let kept_positions = kept.iter().filter(|k| **k).count();
    if kept_positions == 0 {
        return Err(Error::Invalid(format!(
            "the threshold keeps no coefficient position (the largest RMS coefficient is {})",
            energy.iter().fold(0.0f64, |m, e| m.max(*e)).sqrt() / ((resampled.grid.cells() * 3) as f64).sqrt()
        )));
    }
    let per_position = resampled.grid.cells() * 3;
    Ok(Encoded {
        payload: coefficients.to_payload(&kept, config.quantize),
        kept_positions,
        kept_coefficients: kept_positions * per_position,
        total_coefficients: kept.len() * per_position,
        dropped_energy: energy.iter().zip(&kept).filter(|(_, k)| !**k).map(|(e, _)| e).sum(),
    })
}

/// The reconstruction errors of Table 1 (crate docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// Root mean square of `f - f'` over all samples and channels, 1/sr.
    pub rms: f64,
    /// Mean of `|f - f'| / f` over the samples and channels with `f > 0`, a fraction.
    pub mean_relative_error: f64,
    /// Largest `|f - f'| / f` over the same.
    pub max_relative_error: f64,
    /// Mean of `f` over all samples and channels (Table 1's "mean value").
    pub mean_value: f64,
    /// Samples and channels with `f > 0`, of which the relative errors are taken.
    pub positive: usize,
    /// Mean of `|f - f'| / f` over the samples and channels with `f >= floor` (`floor` =
    /// `eps mu`, 1% of the channel's mean by default): where the log encoding is relative to
    /// `f`. Below it the encoding is relative to `eps mu` instead, and a value of `1e-15` read
    /// back as `1e-4` is a relative error of `1e11` that says nothing about the picture.
    pub mean_relative_error_above_floor: f64,
    /// Samples and channels with `f >= floor`.
    pub above_floor: usize,
}

/// The errors of `decoded` against `original` (same layout); `floor` per channel is usually
/// `eps mu` ([`Decoded::floor`]).
pub fn errors(original: &[[f64; 3]], decoded: &[[f64; 3]], floor: [f64; 3]) -> Errors {
    assert_eq!(original.len(), decoded.len(), "two tables of one grid");
    let (mut squares, mut sum, mut relative, mut max_relative, mut positive) = (0.0, 0.0, 0.0, 0.0f64, 0usize);
    let (mut relative_above, mut above) = (0.0, 0usize);
    for (f, g) in original.iter().zip(decoded) {
        for c in 0..3 {
            let d = f[c] - g[c];
            squares += d * d;
            sum += f[c];
            if f[c] > 0.0 {
                let r = d.abs() / f[c];
                relative += r;
                max_relative = max_relative.max(r);
                positive += 1;
                if f[c] >= floor[c] {
                    relative_above += r;
                    above += 1;
                }
            }
        }
    }
    let n = (3 * original.len()).max(1) as f64;
    Errors {
        rms: (squares / n).sqrt(),
        mean_relative_error: relative / positive.max(1) as f64,
        max_relative_error: max_relative,
        mean_value: sum / n,
        positive,
        mean_relative_error_above_floor: relative_above / above.max(1) as f64,
        above_floor: above,
    }
}
