use crate::kernels::{analyze, synthesize};
use crate::wavelet::{D4, HAAR};
use crate::{Error, Wavelet, check_finite, check_levels, with_bank};

/// A multi-level 1D decomposition: the approximation after `levels()` steps and the detail
/// coefficients of every level, finest first.
///
/// `details[j - 1]` is level `j` (1 = finest, of length `n / 2`; `levels()` = coarsest, of the
/// same length as `approx`). PyWavelets' `wavedec` lists the same arrays coarsest first:
/// `[approx, details[J-1], ..., details[0]]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition {
    pub wavelet: Wavelet,
    pub approx: Vec<f64>,
    pub details: Vec<Vec<f64>>,
}

impl Decomposition {
    /// Number of levels `J`.
    pub fn levels(&self) -> usize {
        self.details.len()
    }

    /// The detail coefficients of level `level` (1 = finest). Panics unless `1 <= level <= J`.
    pub fn detail(&self, level: usize) -> &[f64] {
        assert!((1..=self.levels()).contains(&level), "level {level} is not in 1..={}", self.levels());
        &self.details[level - 1]
    }

    /// Sum of squares of all coefficients; equals the signal's energy.
    pub fn energy(&self) -> f64 {
        self.details.iter().chain([&self.approx]).flatten().map(|v| v * v).sum()
    }
}

/// One level of the forward transform: `(cA, cD)` of `pywt.dwt(x, w, mode="periodization")`.
/// The length must be even.
pub fn dwt(x: &[f64], wavelet: Wavelet) -> Result<(Vec<f64>, Vec<f64>), Error> {
    check_signal(x, 1)?;
    let mut a = vec![0.0; x.len() / 2];
    let mut d = vec![0.0; x.len() / 2];
    with_bank!(wavelet, bank => analyze(bank, x, &mut a, &mut d));
    Ok((a, d))
}

/// One level of the inverse transform: `pywt.idwt(approx, detail, w, mode="periodization")`, a
/// signal twice as long as the (equally long) coefficient arrays.
pub fn idwt(approx: &[f64], detail: &[f64], wavelet: Wavelet) -> Result<Vec<f64>, Error> {
    if approx.is_empty() {
        return Err(Error::Empty { what: "approximation" });
    }
    if detail.len() != approx.len() {
        return Err(Error::ShapeMismatch(format!(
            "approximation has {} coefficients, detail has {}",
            approx.len(),
            detail.len()
        )));
    }
    check_finite(|| "approximation".to_owned(), approx)?;
    check_finite(|| "detail".to_owned(), detail)?;
    let mut x = vec![0.0; 2 * approx.len()];
    with_bank!(wavelet, bank => synthesize(bank, approx, detail, &mut x));
    Ok(x)
}

/// The forward transform over `levels` levels: `pywt.wavedec(x, w, mode="periodization",
/// level=levels)`. The length must be divisible by `2^levels` ([`crate::max_levels`]).
pub fn wavedec(x: &[f64], wavelet: Wavelet, levels: usize) -> Result<Decomposition, Error> {
    check_signal(x, levels)?;
    let mut approx = Vec::new();
    let mut details = Vec::with_capacity(levels);
    for _ in 0..levels {
        let finer = if approx.is_empty() { x } else { &approx };
        let mut a = vec![0.0; finer.len() / 2];
        let mut d = vec![0.0; finer.len() / 2];
        with_bank!(wavelet, bank => analyze(bank, finer, &mut a, &mut d));
        approx = a;
        details.push(d);
    }
    Ok(Decomposition { wavelet, approx, details })
}

/// The inverse of [`wavedec`]: `pywt.waverec(coeffs, w, mode="periodization")` with `coeffs` in
/// PyWavelets' order. Fails unless level `j` holds `2^(J-j)` times as many coefficients as
/// `approx` and every value is finite.
pub fn waverec(decomposition: &Decomposition) -> Result<Vec<f64>, Error> {
    let Decomposition { wavelet, approx, details } = decomposition;
    if details.is_empty() {
        return Err(Error::ZeroLevels);
    }
    if approx.is_empty() {
        return Err(Error::Empty { what: "approximation" });
    }
    check_finite(|| "approximation".to_owned(), approx)?;
    let mut expected = approx.len();
    for (j, d) in details.iter().enumerate().rev() {
        if d.len() != expected {
            return Err(Error::ShapeMismatch(format!(
                "level {} detail has {} coefficients, expected {expected}",
                j + 1,
                d.len()
            )));
        }
        check_finite(|| format!("level {} detail", j + 1), d)?;
        expected *= 2;
    }
    let mut x = Vec::new();
    for d in details.iter().rev() {
        let coarser = if x.is_empty() { approx } else { &x };
        let mut finer = vec![0.0; 2 * d.len()];
        with_bank!(*wavelet, bank => synthesize(bank, coarser, d, &mut finer));
        x = finer;
    }
    Ok(x)
}

fn check_signal(x: &[f64], levels: usize) -> Result<(), Error> {
    if x.is_empty() {
        return Err(Error::Empty { what: "signal" });
    }
    check_levels("length", x.len(), levels)?;
    check_finite(|| "signal".to_owned(), x)
}
