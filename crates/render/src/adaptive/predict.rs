//! The bandwidth buffer: each prediction pixel's image bandwidth and variance (module docs, "The
//! bandwidth buffer").

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;
use crate::raster::GBuffer;
use crate::shade::{brdf, slice_of};
use crate::{Estimator, Lighting, Material, pcg_hash};

use super::*;

/// The bandwidth buffer's entry of one pixel (module docs, "The bandwidth buffer").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Prediction {
    /// Image-space bandwidth, cycles per pixel (eq. 5-6).
    pub bandwidth: f64,
    /// The variance bound (eq. 9, or eq. 10 for the prefiltered estimator).
    pub variance: f64,
    /// The pyramid level the pixel may be shaded at (eq. 11); -1 when it is not shadeable.
    pub level: i32,
}

/// Where the bandwidth buffer is predicted: the render pixels predicted at (row-major order),
/// and for every render pixel the index in that list of the prediction it takes, `u32::MAX`
/// where it is not shadeable. With `l > 0` ([`Settings::prediction_level`]), one prediction per
/// `2^l x 2^l` block of render pixels, made at the block's pixel ([`Level::pixel`]), for blocks
/// of *inner* pixels: shadeable, and so are their four neighbours (those in the image). A block
/// that holds another pixel (at a silhouette, beside it, or at a hole) is split into its four
/// quarters, each predicted the same way, down to single pixels. So a shadeable pixel takes the
/// prediction of the largest block around it, of level at most `l`, whose pixels are all inner
/// (itself at level 0), and that block's pixel takes its own. The rim is where neighbouring
/// pixels are least alike (the view turns fastest there: `1 / cos theta_x` of the bandwidth at
/// the eye): predicted from a pixel one further in, the outermost pixels of a rim lit from
/// behind were shaded with that pixel in a 2 x 2 block, up to 15 levels dark against the
/// converged estimate at 128 x 128 (white-paint under quarry, the sun behind the sphere).
pub fn prediction_pixels(shadeable: &[bool], (width, height): (usize, usize), l: usize) -> (Vec<u32>, Vec<u32>) {
    // whole[k - 1]: per block of level k (row-major, partial blocks at the edges), whether every
    // pixel of it is inner.
    let inner = |i: usize| {
        let (x, y) = (i % width, i / width);
        shadeable[i]
            && (x == 0 || shadeable[i - 1])
            && (x + 1 == width || shadeable[i + 1])
            && (y == 0 || shadeable[i - width])
            && (y + 1 == height || shadeable[i + width])
    };
    let mut whole: Vec<(usize, Vec<bool>)> = Vec::with_capacity(l);
    for k in 1..=l {
        let (bw, bh) = (width.div_ceil(1 << k), height.div_ceil(1 << k));
        let finer = |x: usize, y: usize| match k {
            1 => x < width && y < height && !inner(y * width + x),
            _ => {
                let (fw, ref f) = whole[k - 2];
                x < fw && y < f.len() / fw && !f[y * fw + x]
            }
        };
        let blocks = (0..bw * bh)
            .map(|b| {
                let (bx, by) = (b % bw, b / bw);
                ![(0, 0), (1, 0), (0, 1), (1, 1)].iter().any(|&(dx, dy)| finer(2 * bx + dx, 2 * by + dy))
            })
            .collect();
        whole.push((bw, blocks));
    }
    let source = |i: usize| -> Option<usize> {
        if !shadeable[i] {
            return None;
        }
        let (x, y) = (i % width, i / width);
        let block = (1..=l)
            .rev()
            .find(|&k| {
                let (bw, ref blocks) = whole[k - 1];
                blocks[(y >> k) * bw + (x >> k)]
            })
            .map(|k| block_pixel(k, x >> k, y >> k, width, height));
        Some(block.map_or(i, |(bx, by)| by * width + bx))
    };
    let sources: Vec<Option<usize>> = (0..shadeable.len()).into_par_iter().map(source).collect();
    let mut index = vec![u32::MAX; shadeable.len()];
    let mut pixels = Vec::new();
    for (i, s) in sources.iter().enumerate() {
        if *s == Some(i) {
            index[i] = pixels.len() as u32;
            pixels.push(i as u32);
        }
    }
    let of_pixel = sources.iter().map(|s| s.map_or(u32::MAX, |s| index[s])).collect();
    (pixels, of_pixel)
}

/// The bandwidth buffer: one [`Prediction`] per render pixel, row-major, made at the
/// [`prediction_pixels`] by `predictor` (`(bandwidth, variance)` of each, in order) or here,
/// with eq. 11's level applied here either way.
pub(crate) fn predict(
    pixels: &[Option<Pixel>],
    (width, height): (usize, usize),
    frame: &Frame,
    predictor: Option<Predictor>,
) -> Result<Vec<Prediction>, Error> {
    let l = frame.settings.prediction_level(frame.top);
    let shadeable: Vec<bool> = pixels.iter().map(Option::is_some).collect();
    let (at, of_pixel) = prediction_pixels(&shadeable, (width, height), l);
    let values = match predictor {
        Some(predictor) => {
            let values = predictor(&at)?;
            if values.len() != at.len() {
                return Err(Error::Invalid(format!(
                    "the predictor returned {} predictions for {} pixels",
                    values.len(),
                    at.len()
                )));
            }
            if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.iter().all(|x| x.is_finite() && *x >= 0.0))
            {
                return Err(Error::Invalid(format!(
                    "the predictor's bandwidth and variance at render pixel {} are {} and {}: expected finite values >= 0",
                    at[i], v[0], v[1]
                )));
            }
            values
        }
        None => at
            .par_iter()
            .map(|&i| {
                predict_pixel(pixels[i as usize].as_ref().expect("a prediction pixel is shadeable"), i as usize, frame)
            })
            .collect(),
    };
    let predictions: Vec<Prediction> = values
        .iter()
        .map(|&[bandwidth, variance]| Prediction { bandwidth, variance, level: level_of(bandwidth, frame.top) })
        .collect();
    Ok(of_pixel
        .iter()
        .map(
            |&j| {
                if j == u32::MAX { Prediction { level: -1, ..Prediction::default() } } else { predictions[j as usize] }
            },
        )
        .collect())
}

/// What the prediction of a frame reads.
pub(crate) struct Frame<'a> {
    /// The render's G-buffer and the camera's eye.
    pub gbuffer: &'a GBuffer,
    pub eye: DVec3,
    pub material: &'a Material,
    pub lighting: &'a Lighting,
    pub bandwidths: &'a Bandwidths,
    pub settings: &'a Settings,
    /// Of the render, at the centre: `fov_y / height` (eq. 6).
    pub radians_per_pixel: f64,
    /// The pyramid's top level.
    pub top: usize,
}

/// The prediction of one shadeable pixel (module docs, "The bandwidth buffer"): its image
/// bandwidth (cycles per pixel) and variance.
fn predict_pixel(p: &Pixel, i: usize, frame: &Frame) -> [f64; 2] {
    let Frame { material, lighting, bandwidths, settings, radians_per_pixel, .. } = *frame;
    let shading = shading_frame(frame.gbuffer, frame.eye, i);
    let s = &material.samples;
    let level0 = lighting.mips.level(0);
    let n_b = settings.n_b.min(s.n_samples);
    let hashed_seed = pcg_hash(settings.seed ^ PREDICTION_SALT);
    let k = slice_of(shading.theta_o(), s.n_slices);
    let vector = pcg_hash(i as u32 ^ hashed_seed) as usize % s.n_vectors;
    let start = (k * s.n_vectors + vector) * s.n_samples;
    let (mut weight, mut weighted, mut variance) = (0.0, 0.0, 0.0);
    for texel in &s.texels[start..start + n_b] {
        let wi_local = DVec3::new(texel[0].into(), texel[1].into(), texel[2].into());
        let pdf = f64::from(texel[3]);
        if !(pdf > 0.0 && wi_local.z > 0.0) {
            continue;
        }
        let f = color::luminance(brdf(material, wi_local, shading.wo_local));
        let wi = shading.to_world(wi_local);
        // One map coordinate for the radiance and the bandwidth: the same texel grid.
        let (u, v) = envmap::uv(wi);
        let radiance = color::luminance(level0.lookup_uv(u, v).map(f64::from));
        let g = radiance * f * wi_local.z;
        let nu_env = bandwidths.environment.at_uv(u, v);
        let rho = f64::from(bandwidths.brdf.lookup(wi_local, shading.wo_local));
        let at_eye = bandwidth_at_eye(nu_env, rho, p.curvature, p.depth, shading.cos_o);
        weight += g / pdf;
        weighted += g / pdf * at_eye;
        variance += match settings.estimator {
            Estimator::Prefiltered => 2.0 * rho,
            _ => nu_env + rho,
        } * g
            * g
            / pdf;
    }
    let bandwidth = if weight > 0.0 { weighted / weight * radians_per_pixel } else { 0.0 };
    [bandwidth, variance / n_b as f64]
}

/// The angular bandwidth at the eye of the light from one incident direction (`001` eq. 3-4 with
/// the matrices of Fig. 4, as printed): a distant light's `[0, nu_env]` through `C_c`, `B_{0,rho}`,
/// `S`, `C_-c`, `P_x` and `T_d'` (`P_i` and `T_d` leave it unchanged); `|nu_a|` of the result,
/// in cycles per radian. `curvature` in 1 / length, `depth` in the same length.
pub fn bandwidth_at_eye(nu_env: f64, rho: f64, curvature: f64, depth: f64, cos_x: f64) -> f64 {
    type M = [[f64; 2]; 2];
    let apply = |m: M, v: [f64; 2]| [m[0][0] * v[0] + m[0][1] * v[1], m[1][0] * v[0] + m[1][1] * v[1]];
    let c = curvature;
    let mut nu = [0.0, nu_env];
    nu = apply([[1.0, c], [0.0, 1.0]], nu); // C_c
    nu = [nu[0], rho.min(nu[1])]; // B_{0, rho}
    nu = apply([[1.0, 0.0], [0.0, -1.0]], nu); // S
    nu = apply([[1.0, -c], [0.0, 1.0]], nu); // C_-c
    nu = apply([[1.0 / cos_x, 0.0], [0.0, 1.0]], nu); // P_x
    nu = apply([[1.0, 0.0], [-depth, 1.0]], nu); // T_d'
    nu[1].abs()
}

/// Samples per cycle of the predicted bandwidth that a pixel's level gives it (module docs, "The
/// bandwidth buffer"): twice the Nyquist rate, a power of two.
pub const SAMPLES_PER_CYCLE: f64 = 4.0;

/// Mixed into the seed of the prediction's choice of a vector per pixel (module docs, "The
/// bandwidth buffer"), so that it is not the shading's.
pub const PREDICTION_SALT: u32 = 0x9e37_79b9;

/// Eq. 11 at [`SAMPLES_PER_CYCLE`]: `floor(log2(1 / (4 bandwidth)))` clamped to `[0, top]`.
pub fn level_of(bandwidth: f64, top: usize) -> i32 {
    if bandwidth.is_nan() || bandwidth <= 0.0 {
        return top as i32;
    }
    (1.0 / (SAMPLES_PER_CYCLE * bandwidth)).log2().floor().clamp(0.0, top as f64) as i32
}
