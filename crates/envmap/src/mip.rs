//! A mip chain for filtered importance sampling (Colbert and Krivanek, "GPU-Based Importance
//! Sampling", GPU Gems 3, ch. 20, 2007): a sample that stands for a large solid angle reads a
//! coarser level, so few samples give a smooth result instead of noise.

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;
use crate::geometry;
use crate::map::EnvMap;

/// Level 0 is the map; each further level halves both sides with a 2x2 box filter weighted by
/// texel solid angle, so the solid-angle-weighted mean radiance ([`EnvMap::mean_radiance`]) is
/// the same at every level (up to `f32` rounding of the stored texels). A plain 2x2 average
/// would not keep it: the two rows of a block have different solid angles.
///
/// The chain stops at the first level whose height is odd (a 2:1 map's width is always even):
/// a `2^k m x 2^(k-1) m` map with `m` odd has `k` levels, the last `2m x m` (a `2^k x 2^(k-1)` map
/// ends at `2 x 1`). Halving an odd size would need a filter that straddles texels; the few
/// coarsest levels that a non-power-of-two map lacks matter only for very few samples.
#[derive(Clone, Debug)]
pub struct MipChain {
    levels: Vec<EnvMap>,
}

impl MipChain {
    pub fn new(map: &EnvMap) -> MipChain {
        let mut levels = vec![map.clone()];
        while let Some(next) = downsample(levels.last().expect("level 0 exists")) {
            levels.push(next);
        }
        MipChain { levels }
    }

    /// A chain made elsewhere, e.g. read back from a KTX2 file: at least one level, each half the
    /// size of the one before (rounded down), as [`MipChain::new`] makes them.
    pub fn from_levels(levels: Vec<EnvMap>) -> Result<MipChain, Error> {
        if levels.is_empty() {
            return Err(Error::Invalid("a mip chain needs at least one level".into()));
        }
        for (l, pair) in levels.windows(2).enumerate() {
            let (fine, coarse) = (&pair[0], &pair[1]);
            if (coarse.width(), coarse.height()) != (fine.width() / 2, fine.height() / 2) {
                return Err(Error::Invalid(format!(
                    "mip level {} is {} x {}, expected half of level {l} ({} x {})",
                    l + 1,
                    coarse.width(),
                    coarse.height(),
                    fine.width(),
                    fine.height()
                )));
            }
        }
        Ok(MipChain { levels })
    }

    /// The number of levels, at least 1.
    pub fn n_levels(&self) -> usize {
        self.levels.len()
    }

    /// Level `l`, 0 being the full-resolution map. Panics when `l >= n_levels()`, like indexing.
    pub fn level(&self, l: usize) -> &EnvMap {
        &self.levels[l]
    }

    pub fn levels(&self) -> &[EnvMap] {
        &self.levels
    }

    /// The level of detail for one of `n_samples` samples drawn with density `pdf_uv` over the unit
    /// square of map coordinates: `max(log4(width * height / (n_samples * pdf_uv)), 0)`, i.e. half
    /// the log2 of the ratio between the sample's share of the square, `1 / (n_samples pdf_uv)`,
    /// and one level-0 texel's, `1 / (width height)`. A pdf over solid angle converts with
    /// [`geometry::uv_jacobian`]: `pdf_uv = pdf_omega * uv_jacobian(v)`. Colbert and Krivanek add
    /// a bias of 1 level; callers that want it add it. Not clamped to the chain's last level (the
    /// lookups clamp); a zero or NaN pdf gives infinity or NaN, which the lookups treat as the
    /// last level or level 0.
    pub fn lod(&self, n_samples: usize, pdf_uv: f64) -> f64 {
        let level0 = &self.levels[0];
        let texels = (level0.width() * level0.height()) as f64;
        (0.5 * (texels / (n_samples as f64 * pdf_uv)).log2()).max(0.0)
    }

    /// The level of detail for one of `n_samples` samples drawn with density `pdf_omega` per unit
    /// solid angle, by the footprint's extent along `v` rather than its area in the map: the level
    /// [`MipChain::lod`] gives a footprint of that solid angle at the equator, wherever it lies,
    /// `max(log4(width * height / (n_samples * pdf_omega * 2 pi^2)), 0)`. Towards the poles a
    /// footprint of a given solid angle covers ever more of `u` and no more of `v`; a square
    /// level matched to its area there would blur it along `v` by `1 / sqrt(sin theta)`, mixing
    /// elevations the footprint does not reach (the zenith with the sky around a sun), where this
    /// level blurs it too little along `u` only: noise rather than bias.
    pub fn lod_solid_angle(&self, n_samples: usize, pdf_omega: f64) -> f64 {
        self.lod(n_samples, pdf_omega * 2.0 * std::f64::consts::PI * std::f64::consts::PI)
    }

    /// Trilinear lookup: bilinear ([`EnvMap::lookup_uv`]) in the two levels around `lod`, then
    /// linear between them. `lod` is clamped to `[0, n_levels() - 1]`; NaN reads level 0.
    pub fn lookup_uv(&self, u: f64, v: f64, lod: f64) -> [f32; 3] {
        let last = (self.levels.len() - 1) as f64;
        let lod = if lod > 0.0 { lod.min(last) } else { 0.0 };
        let l0 = lod.floor() as usize;
        let t = lod - l0 as f64;
        let a = self.levels[l0].lookup_uv(u, v);
        if t == 0.0 {
            return a;
        }
        let b = self.levels[l0 + 1].lookup_uv(u, v);
        std::array::from_fn(|i| (f64::from(a[i]) * (1.0 - t) + f64::from(b[i]) * t) as f32)
    }

    /// [`MipChain::lookup_uv`] in direction `wi` (need not be normalized).
    pub fn lookup(&self, wi: DVec3, lod: f64) -> [f32; 3] {
        let (u, v) = geometry::uv(wi);
        self.lookup_uv(u, v, lod)
    }
}

/// The next level, or `None` when the height is odd.
fn downsample(fine: &EnvMap) -> Option<EnvMap> {
    let (w, h) = (fine.width(), fine.height());
    if h % 2 == 1 {
        return None;
    }
    let (cw, ch) = (w / 2, h / 2);
    let texels = fine.texels();
    let mut rgb = vec![0.0f32; 3 * cw * ch];
    rgb.par_chunks_mut(3 * cw).enumerate().for_each(|(y, row)| {
        // Both fine rows have texels of width 2 pi / w, so their solid angles weigh as their
        // cosine differences; the common factor cancels in the normalization.
        let w0 = fine.texel_solid_angle(2 * y);
        let w1 = fine.texel_solid_angle(2 * y + 1);
        let norm = 2.0 * (w0 + w1);
        let (top, bottom) = (&texels[2 * y * w..(2 * y + 1) * w], &texels[(2 * y + 1) * w..(2 * y + 2) * w]);
        for (x, out) in row.chunks_exact_mut(3).enumerate() {
            for (c, value) in out.iter_mut().enumerate() {
                let sum_top = f64::from(top[2 * x][c]) + f64::from(top[2 * x + 1][c]);
                let sum_bottom = f64::from(bottom[2 * x][c]) + f64::from(bottom[2 * x + 1][c]);
                *value = ((w0 * sum_top + w1 * sum_bottom) / norm) as f32;
            }
        }
    });
    Some(EnvMap::from_checked(cw, ch, rgb))
}
