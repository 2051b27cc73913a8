//! A piecewise-constant distribution over the directions of the sphere in the latitude-longitude
//! parameterization: an environment map's importance sampling.

use std::f64::consts::PI;

use crate::{Distribution2D, Error};

/// A distribution over the sphere through the lat-long parameterization `(u, v)` in `[0, 1)^2`,
/// `theta = pi v` from the pole of row 0 and `phi = 2 pi u` (the azimuth's origin and direction
/// are the caller's: densities do not depend on them). Texel `(x, y)` of a `width x height` grid
/// has the probability of its `weight` times `sin theta` at the row's centre, and within a texel
/// `(u, v)` is uniform. Since `dw = 2 pi^2 sin(theta) du dv`, the density per unit solid angle of
/// the point `(u, v)` is `pdf_uv / (2 pi^2 sin(pi v))`: it follows the weight times the texel's
/// solid angle, and within the texel it varies as `sin(theta_row) / sin(theta)` (exactly the
/// density of the points drawn, not an approximation of it).
///
/// The CDF tables are rounded to `f32` ([`Distribution2D::rounded_to_f32`]) so that a GPU that
/// reads them samples exactly this distribution, bin for bin.
#[derive(Debug, Clone, PartialEq)]
pub struct LatLong {
    dist: Distribution2D,
}

/// What [`LatLong::sample`] returns: the point `uv` and its density per unit solid angle (0 only
/// on a pole, where `sin theta` is 0 and no direction is drawn in the limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatLongSample {
    pub uv: [f64; 2],
    pub pdf: f64,
}

impl LatLong {
    /// The distribution of texels weighted by `weights` (row-major, `height` rows of `width`,
    /// row 0 at `v = 0`, finite and `>= 0`) times `sin theta` at their row centres. All-zero
    /// weights give the uniform distribution over `(u, v)` ([`Distribution2D::new`]).
    pub fn new(weights: &[f64], width: usize, height: usize) -> Result<LatLong, Error> {
        if width == 0 || height == 0 {
            return Err(Error::EmptyGrid { nu: width, nv: height });
        }
        if width.checked_mul(height) != Some(weights.len()) {
            return Err(Error::WrongSize { len: weights.len(), nu: width, nv: height });
        }
        crate::distribution1d::check_values(weights)?;
        let func: Vec<f64> = weights
            .chunks_exact(width)
            .enumerate()
            .flat_map(|(y, row)| {
                let sin_theta = (PI * (y as f64 + 0.5) / height as f64).sin();
                row.iter().map(move |w| w * sin_theta)
            })
            .collect();
        Ok(LatLong { dist: Distribution2D::new(&func, width, height)?.rounded_to_f32() })
    }

    /// Draws `uv` from `u` in `[0, 1)^2`.
    pub fn sample(&self, u: [f64; 2]) -> LatLongSample {
        let s = self.dist.sample(u);
        LatLongSample { uv: s.p, pdf: solid_angle_density(s.pdf, s.p[1]) }
    }

    /// The density per unit solid angle that [`LatLong::sample`] draws the point `uv` with (0
    /// outside `[0, 1]^2` and on the poles).
    pub fn pdf(&self, uv: [f64; 2]) -> f64 {
        solid_angle_density(self.dist.pdf(uv), uv[1])
    }

    /// The `u` that [`LatLong::sample`] maps to `uv`.
    pub fn invert(&self, uv: [f64; 2]) -> [f64; 2] {
        self.dist.invert(uv)
    }

    /// The distribution over `(u, v)`: its `f32` tables are what a GPU uploads.
    pub fn distribution(&self) -> &Distribution2D {
        &self.dist
    }
}

/// `pdf_uv / (2 pi^2 sin(pi v))`, 0 where `sin(pi v)` is not positive.
fn solid_angle_density(pdf_uv: f64, v: f64) -> f64 {
    let sin_theta = (PI * v).sin();
    if sin_theta > 0.0 && pdf_uv > 0.0 { pdf_uv / (2.0 * PI * PI * sin_theta) } else { 0.0 }
}
