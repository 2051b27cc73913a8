//! PCA of the atlas (`000` Fig. 8): every lobe's tile is one vector of `tile^2` values; the
//! model is their mean, the first `K` principal components and each lobe's `K` coefficients, and
//! a tile is reconstructed as `mean + sum_k coefficient_k component_k`.

use nalgebra::{DMatrix, SymmetricEigen};

use crate::atlas::{Atlas, Parameterization};
use crate::error::Error;

/// How many components to keep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Components {
    /// Exactly this many (at most the tile's length).
    Count(usize),
    /// The fewest whose reconstruction has a relative RMSE ([`PcaReport::relative_rmse`]) of at
    /// most this value.
    MaxRelativeRmse(f64),
}

/// A PCA model of an atlas. `f32` like the atlas; the atlas's layout and parameterization are
/// kept so that the model stands for the atlas on its own.
#[derive(Clone, Debug, PartialEq)]
pub struct PcaModel {
    pub lobes_x: usize,
    pub lobes_y: usize,
    pub tile: usize,
    /// Values per tile, `tile^2`.
    pub tile_len: usize,
    /// `K`, the number of components.
    pub n_components: usize,
    /// The mean tile, `tile_len` values (cycles per radian).
    pub mean: Vec<f32>,
    /// `K x tile_len`, row `k` is component `k` (unit length), by decreasing variance.
    pub components: Vec<f32>,
    /// `n_lobes x K`, row `l` holds lobe `l`'s coefficients (row-major lobe index, as
    /// [`Atlas::lobe_index`]).
    pub coefficients: Vec<f32>,
    pub parameterization: Parameterization,
    pub analysis_size: usize,
    pub eps: f64,
    pub c: f64,
}

impl PcaModel {
    pub fn n_lobes(&self) -> usize {
        self.lobes_x * self.lobes_y
    }

    /// Checks that the sizes agree with each other and every value is finite.
    pub fn check(&self) -> Result<(), Error> {
        let n_lobes = self.lobes_x.checked_mul(self.lobes_y);
        let expect = [
            ("tile length", self.tile.checked_mul(self.tile), self.tile_len),
            ("mean", Some(self.tile_len), self.mean.len()),
            ("components", self.n_components.checked_mul(self.tile_len), self.components.len()),
            ("coefficients", n_lobes.and_then(|n| n.checked_mul(self.n_components)), self.coefficients.len()),
        ];
        for (what, expected, found) in expect {
            if expected != Some(found) {
                return Err(Error::Invalid(format!("pca model {what} holds {found} values, expected {expected:?}")));
            }
        }
        if self.n_components > self.tile_len {
            return Err(Error::Invalid(format!(
                "pca model has {} components for tiles of {} values",
                self.n_components, self.tile_len
            )));
        }
        let values = self.mean.iter().chain(&self.components).chain(&self.coefficients);
        if values.into_iter().any(|v| !v.is_finite()) {
            return Err(Error::Invalid("pca model holds a non-finite value".into()));
        }
        Ok(())
    }

    /// The reconstructed tile of lobe `lobe` (row-major lobe index), `tile_len` values.
    pub fn reconstruct(&self, lobe: usize) -> Vec<f32> {
        let mut out = vec![0.0; self.tile_len];
        self.reconstruct_into(lobe, &mut out);
        out
    }

    /// [`Self::reconstruct`] into `out` (summed in `f64`).
    pub fn reconstruct_into(&self, lobe: usize, out: &mut [f32]) {
        let k = self.n_components;
        let coefficients = &self.coefficients[lobe * k..(lobe + 1) * k];
        for (t, out) in out.iter_mut().enumerate() {
            let mut v = f64::from(self.mean[t]);
            for (c, component) in coefficients.iter().zip(self.components.chunks_exact(self.tile_len)) {
                v += f64::from(*c) * f64::from(component[t]);
            }
            *out = v as f32;
        }
    }

    /// The atlas the model stands for.
    pub fn reconstruct_atlas(&self) -> Atlas {
        let mut atlas = Atlas {
            lobes_x: self.lobes_x,
            lobes_y: self.lobes_y,
            tile: self.tile,
            data: vec![0.0; self.n_lobes() * self.tile_len],
            parameterization: self.parameterization,
            analysis_size: self.analysis_size,
            eps: self.eps,
            c: self.c,
        };
        let mut tile = vec![0.0; self.tile_len];
        for lobe in 0..self.n_lobes() {
            self.reconstruct_into(lobe, &mut tile);
            atlas.set_tile(lobe, &tile);
        }
        atlas
    }

    /// Floats the model stores (mean, components, coefficients).
    pub fn stored_values(&self) -> usize {
        self.mean.len() + self.components.len() + self.coefficients.len()
    }
}

/// A fitted model and what the fit predicts for every `K`.
#[derive(Clone, Debug, PartialEq)]
pub struct PcaFit {
    pub model: PcaModel,
    /// The relative RMSE the first `K` components leave, for `K = 0 ..= tile_len`, from the
    /// eigenvalues (exact arithmetic; the `f32` model may differ by rounding).
    pub predicted_relative_rmse: Vec<f64>,
}

/// How well a model reproduces an atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct PcaReport {
    pub n_components: usize,
    /// `|reconstruction - atlas|` over all texels (Frobenius norm) divided by `|atlas|`.
    pub relative_rmse: f64,
    /// The largest `|reconstruction - atlas|` of a texel, cycles per radian.
    pub max_abs_error: f64,
    /// The largest texel of the atlas, cycles per radian.
    pub max_value: f64,
    /// Floats stored by the model over floats in the atlas.
    pub size_ratio: f64,
    /// `|reconstruction - atlas|` per texel, in the atlas's layout.
    pub errors: Vec<f32>,
}

/// Fits a PCA model to the atlas's tiles: mean, then the eigenvectors of the covariance of the
/// centred tiles (a `tile_len x tile_len` symmetric eigenproblem, in `f64`), by decreasing
/// eigenvalue. With [`Components::MaxRelativeRmse`], `K` is the smallest the eigenvalues
/// predict, raised while the `f32` model misses the bound.
pub fn fit(atlas: &Atlas, components: Components) -> Result<PcaFit, Error> {
    atlas.check()?;
    let (n, d) = (atlas.n_lobes(), atlas.tile_len());
    match components {
        Components::Count(k) if k > d => {
            return Err(Error::Config(format!("{k} components requested: tiles hold {d} values")));
        }
        Components::MaxRelativeRmse(e) if !(e >= 0.0 && e.is_finite()) => {
            return Err(Error::Config(format!("maximum relative rmse {e} is not a finite number >= 0")));
        }
        _ => {}
    }

    let mut tile = vec![0.0f32; d];
    let mut x = DMatrix::<f64>::zeros(n, d);
    for lobe in 0..n {
        atlas.copy_tile(lobe, &mut tile);
        for (t, v) in tile.iter().enumerate() {
            x[(lobe, t)] = f64::from(*v);
        }
    }
    let total: f64 = x.iter().map(|v| v * v).sum();
    let mean: Vec<f64> = (0..d).map(|t| x.column(t).sum() / n as f64).collect();
    for (t, m) in mean.iter().enumerate() {
        x.column_mut(t).add_scalar_mut(-m);
    }
    let covariance = x.tr_mul(&x);
    let eigen = SymmetricEigen::new(covariance);
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&a, &b| eigen.eigenvalues[b].total_cmp(&eigen.eigenvalues[a]));

    // Residual energy after K components: the centred energy not captured, i.e. the sum of the
    // remaining eigenvalues (negative rounding clamped to 0).
    let mut predicted = vec![0.0; d + 1];
    let mut residual: f64 = order.iter().map(|&k| eigen.eigenvalues[k].max(0.0)).sum();
    for (k, p) in predicted.iter_mut().enumerate() {
        *p = if total > 0.0 { (residual.max(0.0) / total).sqrt() } else { 0.0 };
        if k < d {
            residual -= eigen.eigenvalues[order[k]].max(0.0);
        }
    }

    let model_with = |k: usize| -> PcaModel {
        let mut components = Vec::with_capacity(k * d);
        for &c in &order[..k] {
            components.extend(eigen.eigenvectors.column(c).iter().map(|v| *v as f32));
        }
        let mut coefficients = vec![0.0f32; n * k];
        for (slot, &c) in order[..k].iter().enumerate() {
            let projected = &x * eigen.eigenvectors.column(c);
            for lobe in 0..n {
                coefficients[lobe * k + slot] = projected[lobe] as f32;
            }
        }
        PcaModel {
            lobes_x: atlas.lobes_x,
            lobes_y: atlas.lobes_y,
            tile: atlas.tile,
            tile_len: d,
            n_components: k,
            mean: mean.iter().map(|v| *v as f32).collect(),
            components,
            coefficients,
            parameterization: atlas.parameterization,
            analysis_size: atlas.analysis_size,
            eps: atlas.eps,
            c: atlas.c,
        }
    };

    let model = match components {
        Components::Count(k) => model_with(k),
        Components::MaxRelativeRmse(bound) => {
            let mut k = predicted.iter().position(|p| *p <= bound).unwrap_or(d);
            loop {
                let model = model_with(k);
                if k == d || evaluate(atlas, &model).relative_rmse <= bound {
                    break model;
                }
                k += 1;
            }
        }
    };
    Ok(PcaFit { model, predicted_relative_rmse: predicted })
}

/// Compares a model's reconstruction with the atlas. The two must have the same layout.
pub fn evaluate(atlas: &Atlas, model: &PcaModel) -> PcaReport {
    assert_eq!(
        (atlas.lobes_x, atlas.lobes_y, atlas.tile),
        (model.lobes_x, model.lobes_y, model.tile),
        "the model was fitted to an atlas of another layout"
    );
    let reconstructed = model.reconstruct_atlas();
    let mut errors = Vec::with_capacity(atlas.data.len());
    let (mut sum_err, mut sum_ref, mut max_err, mut max_value) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (a, r) in atlas.data.iter().zip(&reconstructed.data) {
        let (a, r) = (f64::from(*a), f64::from(*r));
        let e = (r - a).abs();
        sum_err += e * e;
        sum_ref += a * a;
        max_err = max_err.max(e);
        max_value = max_value.max(a.abs());
        errors.push(e as f32);
    }
    PcaReport {
        n_components: model.n_components,
        relative_rmse: if sum_ref > 0.0 { (sum_err / sum_ref).sqrt() } else { sum_err.sqrt() },
        max_abs_error: max_err,
        max_value,
        size_ratio: model.stored_values() as f64 / atlas.data.len() as f64,
        errors,
    }
}
