//! Discrete wavelet transforms for the toolchain's analyses of BRDF slices: the orthogonal Haar
//! and Daubechies-4 wavelets, 1D and separable 2D, one level or many, forward and inverse, with
//! periodic boundaries. The local-bandwidth estimator reads per-level, per-orientation details
//! from a [`Decomposition2`].
//!
//! # Conventions
//!
//! - **Filters as in PyWavelets.** [`Wavelet::D4`] is PyWavelets' `db2` (4 taps, two vanishing
//!   moments; PyWavelets' `db4` is the 8-tap filter) and [`Wavelet::Haar`] its `haar`, with the
//!   same `dec_lo`, `dec_hi`, `rec_lo`, `rec_hi` coefficients and signs. The only boundary mode
//!   is PyWavelets' `mode="periodization"`, so [`dwt`], [`idwt`], [`wavedec`], [`waverec`],
//!   [`dwt2`], [`idwt2`], [`wavedec2`] and [`waverec2`] return what the `pywt` functions of the
//!   same names return, element by element. In formulas, with `s = taps / 2 - 1`:
//!   `cA[k] = sum_j rec_lo[j] x[(2k - s + j) mod n]` and `cD[k]` the same with `rec_hi`.
//! - **Size rule.** A level halves the length and needs it even, so `levels` levels need a length
//!   (in 2D: width and height) divisible by `2^levels`; [`max_levels`] is the number of factors 2.
//!   Any such size works, not only powers of two (e.g. 24 allows 3 levels). Anything else, zero
//!   levels, empty input and NaN or infinite values are refused with an [`Error`] instead of
//!   PyWavelets' padding of odd lengths, which its inverse cannot undo.
//! - **Levels** are numbered `j = 1` (finest, half the input size) to `J` (coarsest).
//!   `details[j - 1]` is level `j` (finest first, the reverse of PyWavelets' lists); `approx` is
//!   the approximation after `J` levels.
//! - **2D layout.** An [`Image`] is row-major with `width` columns and `height` rows, like a
//!   numpy array of shape `(height, width)`: axis 0 is `y`, axis 1 is `x`. A level holds
//!   `[cH, cV, cD]` in PyWavelets' order ([`Orientation`]): `cH` is high-pass along axis 0 (rows
//!   change, horizontal edges), `cV` high-pass along axis 1, `cD` both. Coefficient `k` of level
//!   `j` sits over the pixels `2^j k .. 2^j (k + 1)` of its axis (centre
//!   [`coefficient_center`]); [`Wavelet::support`] gives every pixel it depends on.
//! - The transforms are orthogonal: energy is preserved and the inverse is the transpose.
//! - `levels` is always explicit. PyWavelets' default (`level=None`) is `pywt.dwt_max_level`,
//!   which stops once the length is below the filter length (8 levels for 1024 samples of `db2`);
//!   deeper levels, down to a single coefficient, are valid periodized transforms (PyWavelets
//!   warns but computes them) and match it too.
//!
//! The 2D transform filters the columns of the rows an output row depends on (contiguous
//! memory), writing the result's even and odd columns apart, then that row, whose taps are then
//! contiguous too: every inner loop runs over a row and vectorizes, and every coefficient is the
//! same sum in the same order as the plain filters' (bit for bit). One output row at a time, in
//! parallel over rows with rayon; it allocates nothing but its outputs, and [`Workspace2`] keeps
//! those between transforms of one size. The row loops are compiled for the best instruction set
//! the processor has (AVX-512 or AVX2, chosen at run time by `pulp`), the same operations in the
//! same order, so the same bits everywhere. Two variants serve analyses of part of an image:
//! [`Workspace2::wavedec2_where`] computes the details of chosen rows only, and
//! [`Workspace2::detail_energy`] sums each level's thresholded squares as the rows are made, of
//! an image given row by row ([`Rows`]), storing neither.
//!
//! The tests compare every function with golden vectors produced by PyWavelets
//! (`tests/golden/make_golden.py`) to 1e-12.

mod error;
mod image;
mod kernels;
mod transform1;
mod transform2;
mod wavelet;

pub use error::Error;
pub use image::Image;
pub use transform1::{Decomposition, dwt, idwt, wavedec, waverec};
pub use transform2::{Decomposition2, Orientation, Rows, Workspace2, dwt2, idwt2, wavedec2, waverec2};
pub use wavelet::Wavelet;

/// The most levels a signal of length `len` allows: the number of times it can be halved into
/// an even length, i.e. its number of factors 2 (0 for an odd or zero length). A 1024-long signal
/// allows 10 levels, a 24-long one 3.
pub fn max_levels(len: usize) -> usize {
    if len == 0 { 0 } else { len.trailing_zeros() as usize }
}

/// The most levels a `width` x `height` image allows: both sides must stay even.
pub fn max_levels2(width: usize, height: usize) -> usize {
    max_levels(width).min(max_levels(height))
}

/// The position, in samples (pixels) of the original signal along one axis, that coefficient
/// `k` of level `level` (1 = finest) is centred on: `2^level (k + 1/2) - 1/2`, the middle of the
/// block `2^level k .. 2^level (k + 1)`. It is the centre of [`Wavelet::support`] for both
/// wavelets, and the same for approximation and detail coefficients.
pub fn coefficient_center(level: usize, k: usize) -> f64 {
    let scale = (1u64 << level) as f64;
    scale * (k as f64 + 0.5) - 0.5
}

/// Runs `$body` with `$bank` bound to the filter bank of `$wavelet`, so the kernels are
/// monomorphized per filter length.
macro_rules! with_bank {
    ($wavelet:expr, $bank:ident => $body:expr) => {
        match $wavelet {
            Wavelet::Haar => {
                let $bank = &HAAR;
                $body
            }
            Wavelet::D4 => {
                let $bank = &D4;
                $body
            }
        }
    };
}
pub(crate) use with_bank;

fn check_levels(dim: &'static str, len: usize, levels: usize) -> Result<(), Error> {
    let max = max_levels(len);
    match levels {
        0 => Err(Error::ZeroLevels),
        _ if levels > max => Err(Error::TooManyLevels { dim, len, levels, max }),
        _ => Ok(()),
    }
}

/// Refuses NaN and infinities. Scans blocks with an integer test that vectorizes and only looks
/// for the position once a block fails, so the check costs a fraction of a transform.
fn check_finite(what: impl FnOnce() -> String, data: &[f64]) -> Result<(), Error> {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    const BLOCK: usize = 256;
    for (b, block) in data.chunks(BLOCK).enumerate() {
        let bad = block.iter().fold(0u64, |acc, v| acc | u64::from(v.to_bits() & EXPONENT == EXPONENT));
        if bad != 0 {
            let index = b * BLOCK + block.iter().position(|v| !v.is_finite()).expect("a non-finite value");
            return Err(Error::NonFinite { what: what(), index });
        }
    }
    Ok(())
}
