use crate::{Error, ONE_MINUS_EPSILON};

/// A piecewise-constant distribution over `[0, 1)` with `n` equal bins, sampled by inverting its
/// CDF table. See the crate documentation for the conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    func: Vec<f64>,
    cdf: Vec<f64>,
    integral: f64,
}

/// What [`Distribution1D::sample`] returns: the point `x` in `[0, 1)`, its pdf, and the bin it
/// lies in (`func[index] > 0` always, unless the function is all zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample1D {
    pub x: f64,
    pub pdf: f64,
    pub index: usize,
}

impl Distribution1D {
    /// Builds the distribution proportional to `func`, `n >= 1` values each finite and `>= 0`.
    /// An all-zero `func` gives the uniform distribution (see the crate documentation).
    pub fn new(func: &[f64]) -> Result<Self, Error> {
        if func.is_empty() {
            return Err(Error::Empty);
        }
        check_values(func)?;
        let mut cdf = vec![0.0; func.len() + 1];
        let integral = build_cdf(func, &mut cdf);
        Ok(Self { func: func.to_vec(), cdf, integral })
    }

    /// The distribution whose CDF table is `cdf` as it is (`n + 1 >= 2` values, `cdf[0] = 0`,
    /// `cdf[n] = 1`, finite and non-decreasing), bin `i` of value `(cdf[i + 1] - cdf[i]) n`: the
    /// distribution a renderer samples when it reads a stored table, such as one rounded to
    /// `f32` for a GPU, where rebuilding the CDF from the values could move a bin edge by a
    /// rounding. Its integral is 1.
    pub fn from_cdf(cdf: &[f64]) -> Result<Self, Error> {
        let func = func_of_cdf(cdf)?;
        Ok(Self { func, cdf: cdf.to_vec(), integral: 1.0 })
    }

    /// Maps `u` in `[0, 1)` to `x` in `[0, 1)` distributed with density `pdf(x)`. Linear within
    /// a bin, so `x` is a continuous, non-decreasing function of `u`.
    pub fn sample(&self, u: f64) -> Sample1D {
        self.view().sample(u)
    }

    /// The density at `x` that [`sample`](Self::sample) draws from; 0 outside `[0, 1]`.
    pub fn pdf(&self, x: f64) -> f64 {
        self.view().pdf(x)
    }

    /// The `u` that [`sample`](Self::sample) maps to `x`, i.e. the CDF at `x`; `x` is clamped
    /// to `[0, 1]`. A bin of zero probability maps entirely to its CDF value.
    pub fn invert(&self, x: f64) -> f64 {
        self.view().invert(x)
    }

    /// The function values as given.
    pub fn func(&self) -> &[f64] {
        &self.func
    }

    /// The CDF at the bin edges: `n + 1` values, `cdf[0] = 0`, `cdf[n] = 1`.
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }

    /// The integral of the function over `[0, 1)`, the mean of `func`; 0 for an all-zero
    /// function even though that one is sampled uniformly.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The number of bins.
    #[expect(clippy::len_without_is_empty, reason = "a distribution has at least one bin")]
    pub fn len(&self) -> usize {
        self.func.len()
    }

    pub(crate) fn view(&self) -> Piecewise<'_> {
        Piecewise { func: &self.func, cdf: &self.cdf, integral: self.integral }
    }
}

/// `x` clamped to `[0, hi]`, NaN read as 0 so that no NaN reaches a table lookup.
pub(crate) fn clamp_unit(x: f64, hi: f64) -> f64 {
    if x.is_nan() { 0.0 } else { x.clamp(0.0, hi) }
}

/// The first value that is NaN, infinite or negative, as an error.
pub(crate) fn check_values(func: &[f64]) -> Result<(), Error> {
    match func.iter().position(|&f| !(f.is_finite() && f >= 0.0)) {
        Some(index) => Err(Error::InvalidValue { index, value: func[index] }),
        None => Ok(()),
    }
}

/// The bin values `(cdf[i + 1] - cdf[i]) n` of a CDF table, after checking that it is one: at
/// least two entries, the first 0, the last 1, finite and non-decreasing.
pub(crate) fn func_of_cdf(cdf: &[f64]) -> Result<Vec<f64>, Error> {
    let n = cdf.len().checked_sub(1).filter(|&n| n > 0).ok_or(Error::Empty)?;
    if cdf[0] != 0.0 {
        return Err(Error::InvalidCdf { index: 0, value: cdf[0] });
    }
    if cdf[n] != 1.0 {
        return Err(Error::InvalidCdf { index: n, value: cdf[n] });
    }
    if let Some(i) = (0..n).find(|&i| !(cdf[i + 1] >= cdf[i] && cdf[i + 1].is_finite())) {
        return Err(Error::InvalidCdf { index: i + 1, value: cdf[i + 1] });
    }
    Ok(cdf.windows(2).map(|w| (w[1] - w[0]) * n as f64).collect())
}

/// Fills `cdf` (`func.len() + 1` entries) and returns the integral, the mean of `func`. Values
/// must be finite and `>= 0`. A function whose integral is 0, all zero or so small that its mean
/// underflows, gets the uniform CDF.
pub(crate) fn build_cdf(func: &[f64], cdf: &mut [f64]) -> f64 {
    let n = func.len();
    debug_assert_eq!(cdf.len(), n + 1);
    cdf[0] = 0.0;
    for i in 0..n {
        cdf[i + 1] = cdf[i] + func[i];
    }
    let mut integral = cdf[n] / n as f64;
    if !cdf[n].is_finite() {
        // Values near f64::MAX overflow the sum; summing func / max keeps it within n. Not the
        // default because dividing rounds, and plain sums keep simple tables exact.
        let max = func.iter().fold(0.0_f64, |m, &f| m.max(f));
        for i in 0..n {
            cdf[i + 1] = cdf[i] + func[i] / max;
        }
        // The integral cannot exceed the largest value; min guards against rounding past it.
        integral = (max * (cdf[n] / n as f64)).min(max);
    }
    if integral == 0.0 {
        for (i, c) in cdf.iter_mut().enumerate() {
            *c = i as f64 / n as f64;
        }
        return 0.0;
    }
    // Zero bins keep zero width through the normalization (adding 0 and dividing by the same sum
    // repeat a value exactly), which is what keeps samples out of them; in particular the sums
    // past the last nonzero bin equal the total and normalize to exactly 1.
    let sum = cdf[n];
    for c in &mut cdf[1..] {
        *c /= sum;
    }
    integral
}

/// A borrowed 1D distribution: [`Distribution1D`] and each row of a
/// [`Distribution2D`](crate::Distribution2D) share this code, so both follow the same rules.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piecewise<'a> {
    pub func: &'a [f64],
    pub cdf: &'a [f64],
    pub integral: f64,
}

impl Piecewise<'_> {
    fn n(&self) -> usize {
        self.func.len()
    }

    /// The bin holding `x`, for `x` in `[0, 1]`; an edge belongs to the upper bin, 1 to the last.
    pub fn bin(&self, x: f64) -> usize {
        // `as usize` saturates, so a negative x (or NaN) reads as bin 0.
        ((x * self.n() as f64) as usize).min(self.n() - 1)
    }

    pub fn bin_pdf(&self, i: usize) -> f64 {
        if self.integral > 0.0 { self.func[i] / self.integral } else { 1.0 }
    }

    pub fn sample(&self, u: f64) -> Sample1D {
        let n = self.n();
        let u = clamp_unit(u, ONE_MINUS_EPSILON);
        // cdf[0] = 0 <= u < 1 = cdf[n], so the bin with cdf[index] <= u < cdf[index + 1] exists
        // and has positive width: func[index] > 0 (or the function is all zero).
        let index = self.cdf.partition_point(|&c| c <= u) - 1;
        let (c0, c1) = (self.cdf[index], self.cdf[index + 1]);
        let t = ((u - c0) / (c1 - c0)).min(ONE_MINUS_EPSILON);
        let mut x = ((index as f64 + t) / n as f64).min(ONE_MINUS_EPSILON);
        // Rounding may carry x an ulp across a bin edge; pdf(x) must find the bin reported here.
        while self.bin(x) > index {
            x = x.next_down();
        }
        while self.bin(x) < index {
            x = x.next_up();
        }
        Sample1D { x, pdf: self.bin_pdf(index), index }
    }

    pub fn pdf(&self, x: f64) -> f64 {
        if (0.0..=1.0).contains(&x) { self.bin_pdf(self.bin(x)) } else { 0.0 }
    }

    pub fn invert(&self, x: f64) -> f64 {
        let x = clamp_unit(x, 1.0);
        let i = self.bin(x);
        // One rounding instead of two: invert(sample(u).x) loses no more than x itself carries.
        let t = x.mul_add(self.n() as f64, -(i as f64)).clamp(0.0, 1.0);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        t.mul_add(c1 - c0, c0).min(1.0)
    }
}
