use crate::distribution1d::{Piecewise, build_cdf, check_values, clamp_unit, func_of_cdf};
use crate::{Distribution1D, Error};

/// A piecewise-constant distribution over `[0, 1)^2` on an `nu` x `nv` grid, sampled as pbrt's
/// `PiecewiseConstant2D`: a marginal distribution over rows `p(v)` and one conditional
/// distribution per row `p(u | v)`. See the crate documentation for the conventions.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D {
    nu: usize,
    nv: usize,
    func: Vec<f64>,
    conditional_cdf: Vec<f64>,
    marginal: Distribution1D,
}

/// What [`Distribution2D::sample`] returns: the point `p = [u, v]` in `[0, 1)^2`, its pdf, and
/// the cell `[iu, iv]` it lies in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample2D {
    pub p: [f64; 2],
    pub pdf: f64,
    pub index: [usize; 2],
}

impl Distribution2D {
    /// Builds the distribution proportional to `func`, row-major with `nv` rows of `nu` values
    /// (`func[iv * nu + iu]`), each finite and `>= 0`.
    pub fn new(func: &[f64], nu: usize, nv: usize) -> Result<Self, Error> {
        if nu == 0 || nv == 0 {
            return Err(Error::EmptyGrid { nu, nv });
        }
        if nu.checked_mul(nv) != Some(func.len()) {
            return Err(Error::WrongSize { len: func.len(), nu, nv });
        }
        check_values(func)?;
        let mut conditional_cdf = vec![0.0; nv * (nu + 1)];
        let row_integrals: Vec<f64> = func
            .chunks_exact(nu)
            .zip(conditional_cdf.chunks_exact_mut(nu + 1))
            .map(|(row, cdf)| build_cdf(row, cdf))
            .collect();
        let marginal = Distribution1D::new(&row_integrals)?;
        Ok(Self { nu, nv, func: func.to_vec(), conditional_cdf, marginal })
    }

    /// The distribution whose tables are `marginal_cdf` (`nv + 1` values over the rows) and
    /// `conditional_cdf` (`nv` rows of `nu + 1`) as they are, each a CDF table as
    /// [`Distribution1D::from_cdf`] takes it: what a renderer samples when it reads stored
    /// tables. Cell `(iu, iv)` has the value `marginal bin iv x conditional bin iu` of those
    /// tables' differences, so `pdf` is the product of the two tables' bin widths times `nu nv`.
    pub fn from_cdfs(marginal_cdf: &[f64], conditional_cdf: &[f64], nu: usize, nv: usize) -> Result<Self, Error> {
        if nu == 0 || nv == 0 {
            return Err(Error::EmptyGrid { nu, nv });
        }
        if marginal_cdf.len() != nv + 1 || nv.checked_mul(nu + 1) != Some(conditional_cdf.len()) {
            return Err(Error::WrongSize { len: conditional_cdf.len(), nu: nu + 1, nv });
        }
        let marginal = Distribution1D::from_cdf(marginal_cdf)?;
        let mut func = Vec::with_capacity(nu * nv);
        for (iv, cdf) in conditional_cdf.chunks_exact(nu + 1).enumerate() {
            let row = func_of_cdf(cdf).map_err(|e| match e {
                Error::InvalidCdf { index, value } => Error::InvalidCdf { index: iv * (nu + 1) + index, value },
                other => other,
            })?;
            func.extend(row.iter().map(|c| c * marginal.func()[iv]));
        }
        Ok(Self { nu, nv, func, conditional_cdf: conditional_cdf.to_vec(), marginal })
    }

    /// The same distribution with its CDF tables rounded to `f32` ([`Distribution2D::from_cdfs`]
    /// of the rounded tables): the one a GPU that reads them as `f32` samples. Rounding keeps
    /// every table non-decreasing from 0 to 1; a bin narrower than the rounding may close
    /// (never sampled, pdf 0) or open up to a rounding's width.
    pub fn rounded_to_f32(&self) -> Distribution2D {
        let round = |t: &[f64]| t.iter().map(|&c| f64::from(c as f32)).collect::<Vec<f64>>();
        Distribution2D::from_cdfs(&round(self.marginal.cdf()), &round(&self.conditional_cdf), self.nu, self.nv)
            .expect("rounding to f32 keeps a CDF table a CDF table")
    }

    /// Maps `u` in `[0, 1)^2` to `p` in `[0, 1)^2` distributed with density `pdf(p)`: `u[1]`
    /// picks `p[1]` from the marginal, `u[0]` picks `p[0]` from that row's conditional.
    pub fn sample(&self, u: [f64; 2]) -> Sample2D {
        let sv = self.marginal.sample(u[1]);
        let su = self.conditional(sv.index).sample(u[0]);
        Sample2D { p: [su.x, sv.x], pdf: su.pdf * sv.pdf, index: [su.index, sv.index] }
    }

    /// The density at `p` that [`sample`](Self::sample) draws from, `func[iv][iu] / integral`
    /// computed as marginal times conditional; 0 outside `[0, 1]^2`.
    pub fn pdf(&self, p: [f64; 2]) -> f64 {
        if !((0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1])) {
            return 0.0;
        }
        let marginal = self.marginal.view();
        marginal.pdf(p[1]) * self.conditional(marginal.bin(p[1])).pdf(p[0])
    }

    /// The `u` that [`sample`](Self::sample) maps to `p`; `p` is clamped to `[0, 1]^2`.
    pub fn invert(&self, p: [f64; 2]) -> [f64; 2] {
        let marginal = self.marginal.view();
        let iv = marginal.bin(clamp_unit(p[1], 1.0));
        [self.conditional(iv).invert(p[0]), marginal.invert(p[1])]
    }

    /// Columns: values per row.
    pub fn nu(&self) -> usize {
        self.nu
    }

    /// Rows.
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// The function values as given, row-major.
    pub fn func(&self) -> &[f64] {
        &self.func
    }

    /// The integral of the function over `[0, 1)^2`, the mean of `func`; 0 for an all-zero
    /// function even though that one is sampled uniformly.
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// The marginal distribution over rows: its `func` holds the row integrals (`nv` values), its
    /// `cdf` has `nv + 1` entries.
    pub fn marginal(&self) -> &Distribution1D {
        &self.marginal
    }

    /// The conditional CDFs of all rows, row-major: `nv` rows of `nu + 1` entries, row `iv` at
    /// `iv * (nu + 1)`, each running from 0 to 1. A row's integral is `marginal().func()[iv]`.
    pub fn conditional_cdf(&self) -> &[f64] {
        &self.conditional_cdf
    }

    fn conditional(&self, iv: usize) -> Piecewise<'_> {
        Piecewise {
            func: &self.func[iv * self.nu..(iv + 1) * self.nu],
            cdf: &self.conditional_cdf[iv * (self.nu + 1)..(iv + 1) * (self.nu + 1)],
            integral: self.marginal.func()[iv],
        }
    }
}
