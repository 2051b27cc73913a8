use std::f64::consts::FRAC_1_SQRT_2;
use std::ops::Range;

/// An orthogonal wavelet, with the filters of PyWavelets' `pywt.Wavelet(name)` bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wavelet {
    /// Haar (`haar`, also `db1`): 2 taps, one vanishing moment.
    Haar,
    /// Daubechies' 4-tap wavelet with two vanishing moments, PyWavelets' `db2` (its `db4` is the
    /// 8-tap filter, not this one).
    D4,
}

// PyWavelets 1.9.0: pywt.Wavelet("db2").rec_lo and .rec_hi, printed with repr.
const D4_REC_LO: [f64; 4] = [0.48296291314453416, 0.8365163037378079, 0.2241438680420134, -0.12940952255126037];
const D4_REC_HI: [f64; 4] = [-0.12940952255126037, -0.2241438680420134, 0.8365163037378079, -0.48296291314453416];
const D4_DEC_LO: [f64; 4] = [-0.12940952255126037, 0.2241438680420134, 0.8365163037378079, 0.48296291314453416];
const D4_DEC_HI: [f64; 4] = [-0.48296291314453416, 0.8365163037378079, -0.2241438680420134, -0.12940952255126037];
const HAAR_REC_LO: [f64; 2] = [FRAC_1_SQRT_2, FRAC_1_SQRT_2];
const HAAR_REC_HI: [f64; 2] = [FRAC_1_SQRT_2, -FRAC_1_SQRT_2];
const HAAR_DEC_LO: [f64; 2] = [FRAC_1_SQRT_2, FRAC_1_SQRT_2];
const HAAR_DEC_HI: [f64; 2] = [-FRAC_1_SQRT_2, FRAC_1_SQRT_2];

/// The filters as the kernels use them. The transform is orthogonal, so the analysis is the
/// correlation with the reconstruction filters (the convolution with the reversed decomposition
/// filters) and the synthesis is its transpose: one pair of filters serves both directions.
#[derive(Debug)]
pub(crate) struct Bank<const F: usize> {
    pub(crate) lo: [f64; F],
    pub(crate) hi: [f64; F],
}

impl<const F: usize> Bank<F> {
    /// How far left of `2k` the window of coefficient `k` starts: PyWavelets' periodization
    /// makes `cA[k] = sum_j rec_lo[j] * x[(2k - SHIFT + j) mod n]` (1 for D4, 0 for Haar).
    pub(crate) const SHIFT: usize = F / 2 - 1;
}

pub(crate) const D4: Bank<4> = Bank { lo: D4_REC_LO, hi: D4_REC_HI };
pub(crate) const HAAR: Bank<2> = Bank { lo: HAAR_REC_LO, hi: HAAR_REC_HI };

impl Wavelet {
    /// The name PyWavelets knows this wavelet by.
    pub const fn pywt_name(self) -> &'static str {
        match self {
            Wavelet::Haar => "haar",
            Wavelet::D4 => "db2",
        }
    }

    /// Number of filter taps.
    pub const fn filter_len(self) -> usize {
        match self {
            Wavelet::Haar => 2,
            Wavelet::D4 => 4,
        }
    }

    /// PyWavelets' `dec_lo`: the analysis low-pass filter, in convolution order.
    pub const fn dec_lo(self) -> &'static [f64] {
        match self {
            Wavelet::Haar => &HAAR_DEC_LO,
            Wavelet::D4 => &D4_DEC_LO,
        }
    }

    /// PyWavelets' `dec_hi`: the analysis high-pass filter, in convolution order.
    pub const fn dec_hi(self) -> &'static [f64] {
        match self {
            Wavelet::Haar => &HAAR_DEC_HI,
            Wavelet::D4 => &D4_DEC_HI,
        }
    }

    /// PyWavelets' `rec_lo`: the synthesis low-pass filter (`dec_lo` reversed).
    pub const fn rec_lo(self) -> &'static [f64] {
        match self {
            Wavelet::Haar => &HAAR_REC_LO,
            Wavelet::D4 => &D4_REC_LO,
        }
    }

    /// PyWavelets' `rec_hi`: the synthesis high-pass filter (`dec_hi` reversed).
    pub const fn rec_hi(self) -> &'static [f64] {
        match self {
            Wavelet::Haar => &HAAR_REC_HI,
            Wavelet::D4 => &D4_REC_HI,
        }
    }

    /// The samples of the original signal (or, per axis, image) that coefficient `k` of level
    /// `level` (1 = finest) depends on, before wrapping them periodically into `0..len`.
    ///
    /// The range is `2^j k - s (2^j - 1) .. 2^j k - s (2^j - 1) + (taps - 1) (2^j - 1) + 1` with
    /// `s = taps / 2 - 1`; its centre is [`crate::coefficient_center`] for both wavelets. It is the
    /// same for the approximation and the detail coefficients. Panics when `level` is 0.
    pub fn support(self, level: usize, k: usize) -> Range<i64> {
        assert!(level > 0, "levels are numbered from 1");
        let span = (1i64 << level) - 1;
        let taps = self.filter_len() as i64;
        let start = (k as i64) << level;
        let start = start - (taps / 2 - 1) * span;
        start..start + (taps - 1) * span + 1
    }
}
