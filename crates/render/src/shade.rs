//! The renderer: the G-buffer of [`crate::raster`], the shading frame and the per-frame estimators
//! of the crate documentation, and the environment behind uncovered pixels.

use std::f64::consts::FRAC_PI_2;

use envmap::{EnvMap, MipChain};
use glam::DVec3;
use merl::Interp;
use rayon::prelude::*;

use crate::error::Error;
use crate::raster::{self, GBuffer, Hit};
use crate::{Camera, Lighting, Material, Mesh, Mode, Rays, SampleSet, Scene, Settings, sample_range};

/// A rendered image: linear RGB radiance, interleaved, row-major with row 0 at the top, and
/// which pixels a triangle covers (the others show the environment).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<f32>,
    pub covered: Vec<bool>,
}

/// Renders `scene` with `settings.mode` (see the crate documentation for every step). Runs in
/// parallel over rows; the result does not depend on the number of threads.
pub fn render(scene: &Scene, material: &Material, lighting: &Lighting, settings: &Settings) -> Result<Image, Error> {
    check_inputs(material, lighting)?;
    check_settings(settings, material.samples.n_samples, lighting.layers.len(), &material.view_layers)?;
    let gbuffer = visibility(scene)?;
    let eye = scene.camera.eye().as_dvec3();
    let level0 = lighting.mips.level(0);
    let rays = scene.camera.rays(scene.width, scene.height);
    let width = scene.width;
    let mut rgb = vec![0.0f32; 3 * width * scene.height];
    rgb.par_chunks_mut(3 * width).enumerate().for_each(|(y, row)| {
        for (x, out) in row.chunks_exact_mut(3).enumerate() {
            let value = match gbuffer.hit(x, y) {
                Some(hit) => match ShadingFrame::new(hit, eye) {
                    Some(frame) => shade(&frame, (y * width + x) as u32, material, lighting, settings, 0),
                    None => [0.0; 3],
                },
                None => background(&rays, level0, x, y),
            };
            out.copy_from_slice(&value.map(|v| v as f32));
        }
    });
    Ok(Image { width, height: scene.height, rgb, covered: gbuffer.hits.iter().map(Option::is_some).collect() })
}

/// The G-buffer of a scene, after checking it.
pub(crate) fn visibility(scene: &Scene) -> Result<GBuffer, Error> {
    visibility_of(&scene.mesh, &scene.camera, scene.width, scene.height)
}

/// The G-buffer of `mesh` seen from `camera` at `width x height`, after checking the size.
pub(crate) fn visibility_of(mesh: &Mesh, camera: &Camera, width: usize, height: usize) -> Result<GBuffer, Error> {
    raster::check_size(width, height)?;
    if (width * height) as u64 > u64::from(u32::MAX) {
        return Err(Error::LimitExceeded(format!("{width} x {height} pixels do not fit a u32 index")));
    }
    raster::rasterize(mesh, camera.view_proj(width as f32 / height as f32), width, height)
}

/// The environment behind pixel `(x, y)`: level 0, bilinear, along the ray through its centre.
pub(crate) fn background(rays: &Rays, level0: &EnvMap, x: usize, y: usize) -> [f64; 3] {
    level0.lookup(rays.ray(x, y)).map(f64::from)
}

/// The shading frame at a covered pixel (crate documentation, "The shading frame").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ShadingFrame {
    pub t: DVec3,
    pub b: DVec3,
    pub n: DVec3,
    pub cos_o: f64,
    /// `wo` in the frame: `(sin theta_o, 0, cos theta_o)`.
    pub wo_local: DVec3,
}

impl ShadingFrame {
    /// `None` where the pixel is black: the normal interpolated to zero or faces away from the eye.
    pub fn new(hit: &Hit, eye: DVec3) -> Option<ShadingFrame> {
        let n = hit.normal;
        if n == DVec3::ZERO {
            return None;
        }
        let wo = (eye - hit.position).normalize();
        let cos_o = n.dot(wo);
        if cos_o.is_nan() || cos_o <= 0.0 {
            return None;
        }
        let tangent = wo - cos_o * n;
        let sin_o = tangent.length();
        let t = if sin_o < 1e-6 { duff_tangent(n) } else { tangent / sin_o };
        let b = n.cross(t);
        let wo_local = DVec3::new(sin_o, 0.0, cos_o).normalize();
        Some(ShadingFrame { t, b, n, cos_o, wo_local })
    }

    pub fn to_world(self, local: DVec3) -> DVec3 {
        local.x * self.t + local.y * self.b + local.z * self.n
    }

    pub fn to_local(self, world: DVec3) -> DVec3 {
        DVec3::new(world.dot(self.t), world.dot(self.b), world.dot(self.n))
    }

    /// `theta_o = atan2(wo_local.x, wo_local.z)`.
    pub fn theta_o(&self) -> f64 {
        self.wo_local.x.atan2(self.wo_local.z)
    }
}

/// The first tangent of the branchless orthonormal basis of Duff et al. 2017 ("Building an
/// Orthonormal Basis, Revisited"): with `s = copysign(1, n.z)` and `a = -1 / (s + n.z)`,
/// `(1 + s n.x^2 a, s n.x n.y a, -s n.x)`.
pub(crate) fn duff_tangent(n: DVec3) -> DVec3 {
    let s = 1f64.copysign(n.z);
    let a = -1.0 / (s + n.z);
    DVec3::new(1.0 + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x)
}

/// The slice of a pixel: `min(floor(theta_o / (pi / 2) S + 1/2), S - 1)`.
pub(crate) fn slice_of(theta_o: f64, n_slices: usize) -> usize {
    ((theta_o / FRAC_PI_2 * n_slices as f64 + 0.5).floor().max(0.0) as usize).min(n_slices - 1)
}

/// `f(wi, wo)`: the wavelet reconstruction when the material has one, else the table's nearest
/// lookup, 0 where it holds no data.
pub(crate) fn brdf(material: &Material, wi_local: DVec3, wo_local: DVec3) -> [f64; 3] {
    match &material.wavelet {
        Some(w) => w.brdf.eval(wi_local, wo_local, w.lod),
        None => material.table.lookup(wi_local, wo_local, Interp::Nearest).unwrap_or([0.0; 3]),
    }
}

/// Where a mode reads `L`.
#[derive(Clone, Copy)]
enum Source<'a> {
    /// Bilinear in one map: level 0 (reference) or a prefiltered layer.
    Map(&'a EnvMap),
    /// Trilinear in the mip chain at the sample's level of detail (filtered importance sampling).
    Mips(&'a MipChain),
}

/// The estimate of one covered pixel, averaged over the frames; the prefiltered estimator reads
/// the layer `layer_shift` layers sharper than the view's (the sharpest at most: an adaptive
/// frame's shaded blocks, `adaptive::Settings::layer_shift`; 0 for [`render`]).
pub(crate) fn shade(
    frame: &ShadingFrame,
    pixel: u32,
    material: &Material,
    lighting: &Lighting,
    settings: &Settings,
    layer_shift: u32,
) -> [f64; 3] {
    let s: &SampleSet = &material.samples;
    let (n_vectors, n_samples, spp) = (s.n_vectors as u32, s.n_samples as u32, settings.spp);
    let k = slice_of(frame.theta_o(), s.n_slices);
    let source = match settings.mode {
        Mode::Reference => Source::Map(lighting.mips.level(0)),
        Mode::Fis => Source::Mips(&lighting.mips),
        Mode::Prefiltered => {
            let rows = material.view_layers.len();
            let r = (((1.0 - frame.cos_o) * rows as f64).floor().max(0.0) as usize).min(rows - 1);
            let layer = (material.view_layers[r] as usize).saturating_add(layer_shift as usize);
            Source::Map(&lighting.layers[layer.min(lighting.layers.len() - 1)])
        }
    };
    let mut total = [0.0f64; 3];
    for f in 0..settings.frames {
        let (v, first) = sample_range(pixel, f, settings.seed, n_vectors, n_samples, spp);
        let start = (k * s.n_vectors + v as usize) * s.n_samples + first as usize;
        let mut sum = [0.0f64; 3];
        for texel in &s.texels[start..start + spp as usize] {
            let wi_local = DVec3::new(texel[0].into(), texel[1].into(), texel[2].into());
            let pdf = f64::from(texel[3]);
            if !(pdf > 0.0 && wi_local.z > 0.0) {
                continue;
            }
            let f = brdf(material, wi_local, frame.wo_local);
            if f == [0.0; 3] {
                continue;
            }
            let wi = frame.to_world(wi_local);
            let radiance = match source {
                Source::Map(map) => map.lookup(wi),
                Source::Mips(mips) => {
                    let (u, v) = envmap::uv(wi);
                    let pdf_uv = pdf * envmap::geometry::uv_jacobian(v);
                    mips.lookup_uv(u, v, mips.lod(spp as usize, pdf_uv))
                }
            };
            let weight = wi_local.z / pdf;
            for c in 0..3 {
                sum[c] += f[c] * f64::from(radiance[c]) * weight;
            }
        }
        for c in 0..3 {
            total[c] += sum[c] / f64::from(spp);
        }
    }
    total.map(|t| t / f64::from(settings.frames))
}

/// The checks [`render`] makes on its inputs before it reads them: the sample set is whole and
/// finite, the lighting has an exponent per layer. The GPU renderer makes the same checks through
/// this function.
pub fn check_inputs(material: &Material, lighting: &Lighting) -> Result<(), Error> {
    let s = &material.samples;
    if s.n_slices == 0 || s.n_vectors == 0 || s.n_samples == 0 {
        return Err(Error::Invalid(format!(
            "the sample set has {} slices, {} vectors and {} samples per vector, need at least one of each",
            s.n_slices, s.n_vectors, s.n_samples
        )));
    }
    if !s.n_samples.is_power_of_two() || s.n_samples > u32::MAX as usize || s.n_vectors > u32::MAX as usize {
        return Err(Error::Invalid(format!(
            "{} samples per vector and {} vectors: the samples must be a power of two and both fit a u32",
            s.n_samples, s.n_vectors
        )));
    }
    let expected = s.n_slices.checked_mul(s.n_vectors).and_then(|n| n.checked_mul(s.n_samples));
    if expected != Some(s.texels.len()) {
        return Err(Error::Invalid(format!(
            "the sample set has {} texels, expected {} slices x {} vectors x {} samples",
            s.texels.len(),
            s.n_slices,
            s.n_vectors,
            s.n_samples
        )));
    }
    // Millions of texels, checked on every call: in parallel chunks, then the first bad one.
    let finite = |t: &[f32; 4]| t.iter().all(|v| v.is_finite());
    if !s.texels.par_chunks(1 << 16).all(|chunk| chunk.iter().all(finite))
        && let Some(i) = s.texels.iter().position(|t| !finite(t))
    {
        return Err(Error::Invalid(format!("sample texel {i} is not finite: {:?}", s.texels[i])));
    }
    if lighting.exponents.len() != lighting.layers.len() {
        return Err(Error::Invalid(format!(
            "{} prefiltered layers but {} exponents",
            lighting.layers.len(),
            lighting.exponents.len()
        )));
    }
    Ok(())
}

/// The checks [`render`] makes on the settings against inputs with `n_samples` samples per vector,
/// `n_layers` Phong layers and `view_layers` (the GPU renderer keeps only these after its upload).
pub fn check_settings(
    settings: &Settings,
    n_samples: usize,
    n_layers: usize,
    view_layers: &[u32],
) -> Result<(), Error> {
    let spp = settings.spp as usize;
    if !settings.spp.is_power_of_two() || !n_samples.is_multiple_of(spp) {
        return Err(Error::Invalid(format!(
            "spp {} must be a power of two dividing the {n_samples} samples per vector",
            settings.spp
        )));
    }
    if settings.frames == 0 {
        return Err(Error::Invalid("frames must be at least 1".into()));
    }
    if settings.mode == Mode::Prefiltered {
        if n_layers == 0 {
            return Err(Error::Invalid("prefiltered mode needs at least one prefiltered layer".into()));
        }
        if view_layers.is_empty() {
            return Err(Error::Invalid("prefiltered mode needs at least one view-layer entry".into()));
        }
        if let Some(&bad) = view_layers.iter().find(|&&l| l as usize >= n_layers) {
            return Err(Error::Invalid(format!("view layer {bad} is out of range for {n_layers} prefiltered layers")));
        }
    }
    Ok(())
}
