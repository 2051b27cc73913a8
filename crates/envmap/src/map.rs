//! The map in memory: validated radiance, texel geometry, bilinear lookups and means.

use glam::DVec3;

use crate::error::Error;
use crate::geometry::{self, texel_solid_angle};

/// A lat-long environment map: linear RGB radiance in `f32`, `width x height` texels, row-major,
/// row 0 at the `+z` pole (see the crate documentation for the orientation).
///
/// Every `EnvMap` holds at least one texel, has `width == 2 * height`, and every value is finite
/// and non-negative: constructors check, so the methods cannot fail.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    width: usize,
    height: usize,
    /// Three values (R, G, B) per texel, row-major.
    rgb: Vec<f32>,
}

impl EnvMap {
    /// A map from interleaved RGB values, three per texel, row-major. Rejects (as
    /// [`Error::Invalid`]) an empty map, a map that is not 2:1, a buffer of the wrong length, and
    /// NaN, infinite or negative values (the message names the first bad texel).
    pub fn new(width: usize, height: usize, rgb: Vec<f32>) -> Result<EnvMap, Error> {
        check_latlong_shape(width, height)?;
        if Some(rgb.len()) != width.checked_mul(height).and_then(|n| n.checked_mul(3)) {
            return Err(Error::Invalid(format!(
                "{width} x {height} map needs {} rgb values, got {}",
                3 * width * height,
                rgb.len()
            )));
        }
        check_radiance(width, &["R", "G", "B"], &rgb)?;
        Ok(EnvMap { width, height, rgb })
    }

    /// A map with the same radiance everywhere.
    pub fn constant(width: usize, height: usize, radiance: [f32; 3]) -> Result<EnvMap, Error> {
        check_latlong_shape(width, height)?;
        EnvMap::new(width, height, radiance.repeat(width * height))
    }

    /// Already checked by the caller (the readers and the mip chain).
    pub(crate) fn from_checked(width: usize, height: usize, rgb: Vec<f32>) -> EnvMap {
        debug_assert!(width == 2 * height && height > 0 && rgb.len() == 3 * width * height);
        EnvMap { width, height, rgb }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The texels, row-major.
    pub fn texels(&self) -> &[[f32; 3]] {
        self.rgb.as_chunks::<3>().0
    }

    /// The texels as interleaved RGB values, three per texel, row-major (what a GPU upload wants).
    pub fn rgb(&self) -> &[f32] {
        &self.rgb
    }

    pub fn into_rgb(self) -> Vec<f32> {
        self.rgb
    }

    /// The radiance of texel `(x, y)`. Panics when `x >= width` or `y >= height`, like indexing.
    pub fn texel(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(x < self.width && y < self.height, "texel ({x}, {y}) outside a {} x {} map", self.width, self.height);
        self.texels()[y * self.width + x]
    }

    /// The solid angle of each texel in row `y` (see [`geometry::texel_solid_angle`]).
    pub fn texel_solid_angle(&self, y: usize) -> f64 {
        texel_solid_angle(y, self.width, self.height)
    }

    /// The direction through the centre of texel `(x, y)`.
    pub fn texel_direction(&self, x: usize, y: usize) -> DVec3 {
        let (u, v) = geometry::texel_center_uv(x, y, self.width, self.height);
        geometry::direction(u, v)
    }

    /// Bilinear interpolation of the texels at map coordinates `(u, v)`, with texel `(x, y)` at
    /// its centre `((x + 0.5) / width, (y + 0.5) / height)`, so a lookup at a centre returns the
    /// texel exactly.
    ///
    /// `u` wraps (the `phi = 0` seam is continuous); `v` is clamped to the centres of the first
    /// and last rows, as a GPU sampler with repeat in `u` and clamp-to-edge in `v` does. Within
    /// half a texel of a pole the value therefore no longer changes with `v`, and at the pole itself
    /// it still depends on `u`: a lat-long map has no single value there.
    pub fn lookup_uv(&self, u: f64, v: f64) -> [f32; 3] {
        let (w, h) = (self.width, self.height);
        let s = u * w as f64 - 0.5;
        let t = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let s0 = s.floor();
        let (fx, fy) = (s - s0, t - t.floor());
        // `as` saturates on huge and maps NaN to 0; the result is then NaN, never a panic.
        let x0 = (s0 as i64).rem_euclid(w as i64) as usize;
        let x1 = if x0 + 1 == w { 0 } else { x0 + 1 };
        let y0 = (t as usize).min(h - 1);
        let y1 = (y0 + 1).min(h - 1);
        let texels = self.texels();
        let (a, b, c, d) = (texels[y0 * w + x0], texels[y0 * w + x1], texels[y1 * w + x0], texels[y1 * w + x1]);
        std::array::from_fn(|i| {
            let top = f64::from(a[i]) * (1.0 - fx) + f64::from(b[i]) * fx;
            let bottom = f64::from(c[i]) * (1.0 - fx) + f64::from(d[i]) * fx;
            (top * (1.0 - fy) + bottom * fy) as f32
        })
    }

    /// Bilinear lookup in direction `wi` (need not be normalized); see [`EnvMap::lookup_uv`].
    pub fn lookup(&self, wi: DVec3) -> [f32; 3] {
        let (u, v) = geometry::uv(wi);
        self.lookup_uv(u, v)
    }

    /// `exp(sum omega ln(1e-4 + Y) / (4 pi))`: the geometric mean of the luminance over directions,
    /// weighted by solid angle (the small offset keeps black texels finite).
    pub fn log_average_luminance(&self) -> f64 {
        let luminance = self.luminance();
        let mut sum = 0.0;
        for (y, row) in luminance.chunks_exact(self.width).enumerate() {
            let omega = self.texel_solid_angle(y);
            sum += omega * row.iter().map(|&v| (1e-4 + f64::from(v)).ln()).sum::<f64>();
        }
        (sum / (4.0 * std::f64::consts::PI)).exp()
    }

    /// The solid-angle-weighted mean radiance per channel, `sum(L omega) / (4 pi)`: the average
    /// over all directions (a plain mean over texels would over-weight the poles).
    pub fn mean_radiance(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for (y, row) in self.texels().chunks_exact(self.width).enumerate() {
            let omega = self.texel_solid_angle(y);
            let mut row_sum = [0.0f64; 3];
            for texel in row {
                for (s, &value) in row_sum.iter_mut().zip(texel) {
                    *s += f64::from(value);
                }
            }
            for (s, r) in sum.iter_mut().zip(row_sum) {
                *s += omega * r;
            }
        }
        sum.map(|s| s / (4.0 * std::f64::consts::PI))
    }

    /// The solid-angle-weighted mean of the Rec. 709 luminance.
    pub fn mean_luminance(&self) -> f64 {
        color::luminance(self.mean_radiance())
    }

    /// The Rec. 709 luminance of every texel, row-major.
    pub fn luminance(&self) -> Vec<f32> {
        self.texels().iter().map(|&rgb| color::luminance(rgb.map(f64::from)) as f32).collect()
    }

    /// Per texel, the luminance of the bilinear reconstruction ([`EnvMap::lookup_uv`]) averaged
    /// over the texel: the luminances filtered by `[1, 6, 1] / 8` along each axis (the mean over
    /// a texel of the linear interpolation between texel centres is 1/8 of each neighbour and 3/4
    /// of itself), wrapping in `u`, the edge rows repeated in `v` (the lookup clamps to their
    /// centres). Positive wherever the lookup is, half a texel around a bright texel included:
    /// the weights of an importance sampler that must find every direction the lookup lights.
    pub fn bilinear_luminance(&self) -> Vec<f64> {
        let (w, h) = (self.width, self.height);
        let luminance = self.luminance();
        let mut along_u = vec![0.0f64; w * h];
        for y in 0..h {
            let at = |x: usize| f64::from(luminance[y * w + x]);
            for x in 0..w {
                along_u[y * w + x] = (at((x + w - 1) % w) + 6.0 * at(x) + at((x + 1) % w)) / 8.0;
            }
        }
        (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let (up, down) = (y.saturating_sub(1), (y + 1).min(h - 1));
                // Luminance of non-negative radiance with positive weights: finite and >= 0.
                ((along_u[up * w + x] + 6.0 * along_u[i] + along_u[down * w + x]) / 8.0).max(0.0)
            })
            .collect()
    }
}

/// Rejects an empty map, then one that is not 2:1.
pub(crate) fn check_latlong_shape(width: usize, height: usize) -> Result<(), Error> {
    check_not_empty(width, height)?;
    if Some(width) != height.checked_mul(2) {
        return Err(Error::Invalid(format!("not a lat-long map: {width} x {height}, expected width = 2 x height")));
    }
    Ok(())
}

pub(crate) fn check_not_empty(width: usize, height: usize) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::Invalid(format!("empty map: {width} x {height}")));
    }
    Ok(())
}

/// Rejects NaN, infinities and negative values; `values` interleaves `names.len()` channels per
/// texel, row-major. The message names the first bad texel in that order.
pub(crate) fn check_radiance(width: usize, names: &[&str], values: &[f32]) -> Result<(), Error> {
    let Some(index) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) else {
        return Ok(());
    };
    let value = values[index];
    let texel = index / names.len();
    let (x, y, channel) = (texel % width, texel / width, names[index % names.len()]);
    let what = if value.is_finite() { "negative radiance" } else { "non-finite radiance" };
    Err(Error::Invalid(format!("{what} {value} at x {x}, y {y}, channel {channel}")))
}
