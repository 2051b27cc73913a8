//! The renderer: the G-buffer of [`crate::raster`], the shading frame and the per-frame estimators
//! of the crate documentation, and the environment behind uncovered pixels.

use std::f64::consts::FRAC_PI_2;

use envmap::{EnvMap, MipChain};
use glam::DVec3;
use merl::Interp;
use rayon::prelude::*;

use crate::error::Error;
use crate::raster::{self, GBuffer, Hit};
use crate::{
    Camera, Estimator, Lighting, Material, Mesh, Rays, SampleSet, Scene, Settings, pixel_sequences, point,
    sample_range, view_layer,
};

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
    render_with_progress(scene, material, lighting, settings, &|_, _| {})
}

/// [`render`], calling `progress(rows done, rows)` as rows finish (a progress bar's hook; from any
/// thread, in no particular order of rows).
pub fn render_with_progress(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    settings: &Settings,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<Image, Error> {
    check_inputs(material, lighting)?;
    check_settings(settings, material.samples.n_samples, lighting.layers.len(), &material.view_layers)?;
    let gbuffer = visibility(scene)?;
    let width = scene.width;
    Ok(shade_rows(scene, &gbuffer, lighting.mips.level(0), progress, |frame, x, y| {
        shade(frame, (y * width + x) as u32, material, lighting, settings, BlockFilter::NONE)
    }))
}

/// The image of `scene`: `pixel(frame, x, y)` where a triangle of `gbuffer` covers the pixel and
/// has a shading frame, black where its normal interpolates to zero, the environment (`level0`) where
/// none covers it. In parallel over rows, calling `progress(rows done, rows)` as they finish.
pub(crate) fn shade_rows(
    scene: &Scene,
    gbuffer: &GBuffer,
    level0: &EnvMap,
    progress: &(dyn Fn(u64, u64) + Sync),
    pixel: impl Fn(&ShadingFrame, usize, usize) -> [f64; 3] + Sync,
) -> Image {
    let eye = scene.camera.eye().as_dvec3();
    let rays = scene.camera.rays(scene.width, scene.height);
    let (width, height) = (scene.width, scene.height);
    let done = std::sync::atomic::AtomicU64::new(0);
    let mut rgb = vec![0.0f32; 3 * width * height];
    rgb.par_chunks_mut(3 * width).enumerate().for_each(|(y, row)| {
        for (x, out) in row.chunks_exact_mut(3).enumerate() {
            let value = match gbuffer.hit(x, y) {
                Some(hit) => match ShadingFrame::new(hit, eye) {
                    Some(frame) => pixel(&frame, x, y),
                    None => [0.0; 3],
                },
                None => background(&rays, level0, x, y),
            };
            out.copy_from_slice(&value.map(|v| v as f32));
        }
        progress(done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1, height as u64);
    });
    Image { width, height, rgb, covered: gbuffer.hits.iter().map(Option::is_some).collect() }
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
    /// `None` where the pixel is black: the normal interpolated to zero (or not a number). A
    /// normal that turns away from the eye, or nearly, is bent towards it ([`bend_towards`]).
    pub fn new(hit: &Hit, eye: DVec3) -> Option<ShadingFrame> {
        let n = hit.normal;
        if n == DVec3::ZERO {
            return None;
        }
        let wo = (eye - hit.position).normalize();
        let cos_o = n.dot(wo);
        if cos_o.is_nan() {
            return None;
        }
        let (n, cos_o) = if cos_o < COS_O_MIN {
            let bent = bend_towards(n, wo, cos_o);
            (bent, bent.dot(wo))
        } else {
            (n, cos_o)
        };
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

/// The least `cos theta_o` a shading frame has: a normal that turns further from the eye is bent
/// towards it until `n . wo` is this (crate documentation, "The shading frame"). Filament's
/// `MIN_N_DOT_V`.
pub const COS_O_MIN: f64 = 1e-4;

/// The unit normal `n` (with `cos_o = n . wo < COS_O_MIN`) rotated towards `wo` in the plane of
/// the two until `n . wo = COS_O_MIN`: `COS_O_MIN wo + sqrt(1 - COS_O_MIN^2) p`, `p` the part of
/// `n` across `wo` normalized (the first tangent of Duff et al.'s basis for `wo` where `n` is
/// `-wo`, so that the two renderers agree).
pub(crate) fn bend_towards(n: DVec3, wo: DVec3, cos_o: f64) -> DVec3 {
    let across = n - cos_o * wo;
    let length = across.length();
    let p = if length < 1e-6 { duff_tangent(wo) } else { across / length };
    COS_O_MIN * wo + (1.0 - COS_O_MIN * COS_O_MIN).sqrt() * p
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
    match &material.wavelet_brdf {
        Some(w) => w.brdf.eval(wi_local, wo_local, w.lod),
        None => material.table.lookup(wi_local, wo_local, Interp::Nearest).unwrap_or([0.0; 3]),
    }
}

/// Where a mode reads `L`.
#[derive(Clone, Copy)]
enum Source<'a> {
    /// The Phong layers at the view's layer coordinate, or the sample's footprint's where that
    /// is broader, blended: `(1 - t)` of layer `k` and `t` of layer `k + 1`, `k + t` the
    /// coordinate; layer `len` is the smooth map itself.
    Layers(f64),
    /// Trilinear in the mip chain at the sample's level of detail (filtered importance sampling).
    Mips(&'a MipChain),
}

/// How an adaptive frame's shaded block filters (`adaptive::Settings::layer_shift` and
/// `frames`): the prefiltered estimator reads the layer `layer_shift` layers sharper than the
/// view's (the smooth map at most) and sizes its footprints for the block's samples times
/// `frames`, the frames the picture averages. [`BlockFilter::NONE`] for [`render`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockFilter {
    pub layer_shift: u32,
    pub frames: u32,
}

impl BlockFilter {
    pub const NONE: BlockFilter = BlockFilter { layer_shift: 0, frames: 1 };
}

/// The estimate of one covered pixel, averaged over the frames, filtered as `block` says.
pub(crate) fn shade(
    frame: &ShadingFrame,
    pixel: u32,
    material: &Material,
    lighting: &Lighting,
    settings: &Settings,
    block: BlockFilter,
) -> [f64; 3] {
    let s: &SampleSet = &material.samples;
    let (n_vectors, n_samples, spp) = (s.n_vectors as u32, s.n_samples as u32, settings.spp);
    let table = &s.tables[slice_of(frame.theta_o(), s.n_slices)];
    let [brdf_points, env_points] = pixel_sequences(pixel, settings.seed);
    let filter_samples = settings.filter_samples() as usize * block.frames as usize;
    // The light a filtered estimator reads (`Some` in fis and prefiltered) and the light that
    // multiple importance sampling of the BRDF's and a light's strategy takes: level 0 whole in
    // the reference mode, the peaks in the filtered modes (crate documentation).
    let filtered = match settings.estimator {
        Estimator::Reference => None,
        Estimator::Fis => Some(Source::Mips(lighting.smooth_mips())),
        Estimator::Prefiltered => {
            let past = lighting.smooth_layers().len() as f64;
            Some(Source::Layers(
                (view_layer(&material.view_layers, frame.cos_o) + f64::from(block.layer_shift)).min(past),
            ))
        }
    };
    let sampled = match (settings.estimator, &lighting.peaks) {
        (Estimator::Reference, _) => Some((&lighting.environment, lighting.mips.level(0))),
        (_, Some(peaks)) => Some((&peaks.sampling, &peaks.map)),
        (_, None) => None,
    };
    let (diffuse, diffuse_radiance) = diffuse_term(frame, material, lighting, settings.estimator);
    let mut total = [0.0f64; 3];
    let mut add = |f: [f64; 3], radiance: [f32; 3], weight: f64| {
        for c in 0..3 {
            total[c] += f[c] * f64::from(radiance[c]) * weight;
        }
    };
    for f in 0..settings.frames {
        let (v, first) = sample_range(pixel, f, settings.seed, n_vectors, n_samples, spp);
        let base = v * n_samples + first;
        for index in base..base + spp {
            // The BRDF's strategy: the slice's table at the pixel's own point.
            let sample = table.sample(point(&brdf_points, index));
            let wi_local = sample.wi;
            if sample.pdf > 0.0 && wi_local.z > 0.0 {
                let f = brdf(material, wi_local, frame.wo_local);
                let rest: [f64; 3] = std::array::from_fn(|c| f[c] - diffuse[c]);
                if f != [0.0; 3] || rest != [0.0; 3] {
                    let wi = frame.to_world(wi_local);
                    let (u, v) = envmap::uv(wi);
                    match filtered {
                        Some(Source::Layers(x_view)) => {
                            let x = x_view.min(footprint_layer(&lighting.exponents, filter_samples, sample.pdf));
                            add(rest, layers_lookup(lighting, x, u, v), wi_local.z / sample.pdf);
                        }
                        Some(Source::Mips(mips)) => {
                            let lod = mips.lod_solid_angle(filter_samples, sample.pdf) + crate::FIS_LOD_BIAS;
                            add(rest, mips.lookup_uv(u, v, lod), wi_local.z / sample.pdf);
                        }
                        None => {}
                    }
                    if let Some((light, map)) = sampled {
                        let weight = mis_weight(sample.pdf, light.pdf([u, v]));
                        add(f, map.lookup_uv(u, v), wi_local.z * weight / sample.pdf);
                    }
                }
            }
            // The light's strategy: its distribution at the pixel's other point.
            let Some((light, map)) = sampled else { continue };
            let drawn = light.sample(point(&env_points, index));
            let [u, v] = drawn.uv;
            let wi_local = frame.to_local(envmap::direction(u, v));
            if drawn.pdf > 0.0 && wi_local.z > 0.0 {
                let f = brdf(material, wi_local, frame.wo_local);
                if f != [0.0; 3] {
                    let weight = mis_weight(drawn.pdf, table.pdf(wi_local));
                    add(f, map.lookup_uv(u, v), wi_local.z * weight / drawn.pdf);
                }
            }
        }
    }
    let samples = f64::from(spp) * f64::from(settings.frames);
    std::array::from_fn(|c| total[c] / samples + diffuse_radiance[c])
}

/// The diffuse part the filtered estimators take out of the BRDF, and its integral against the
/// smooth light, `pi f_d L_1(n)` (crate documentation, "The estimators"): `(f_d, radiance)`, both
/// 0 in the reference mode. A diffuse part is never 0 without a cosine layer to read.
fn diffuse_term(
    frame: &ShadingFrame,
    material: &Material,
    lighting: &Lighting,
    mode: Estimator,
) -> ([f64; 3], [f64; 3]) {
    let diffuse = match mode {
        Estimator::Reference => return ([0.0; 3], [0.0; 3]),
        Estimator::Fis | Estimator::Prefiltered => crate::diffuse_split(material, lighting).map(f64::from),
    };
    if diffuse == [0.0; 3] {
        return (diffuse, [0.0; 3]);
    }
    let (u, v) = envmap::uv(frame.n);
    let l_1 = lighting.smooth_layers()[0].lookup_uv(u, v);
    (diffuse, std::array::from_fn(|c| std::f64::consts::PI * diffuse[c] * f64::from(l_1[c])))
}

/// The layer coordinate of the footprint of one of `n` samples of solid-angle density `pdf`:
/// the Phong lobe of the same solid angle `1 / (n pdf)`, whose exponent is `2 pi n pdf - 1`
/// (the normalized lobe's peak is `(e + 1) / (2 pi)`), [`crate::PREFILTERED_FOOTPRINT_LAYERS`]
/// sharper.
pub(crate) fn footprint_layer(exponents: &[u32], n: usize, pdf: f64) -> f64 {
    let exponent = 2.0 * std::f64::consts::PI * n as f64 * pdf - 1.0;
    crate::exponent_layer(exponents, exponent) + crate::PREFILTERED_FOOTPRINT_LAYERS
}

/// The smooth part's layers at coordinate `x` (clamped to `[0, layers]`) in direction `(u, v)`:
/// `(1 - t)` of layer `k` and `t` of layer `k + 1`, each bilinear, the smooth part's level 0
/// past the sharpest.
fn layers_lookup(lighting: &Lighting, x: f64, u: f64, v: f64) -> [f32; 3] {
    let layers = lighting.smooth_layers();
    let x = x.clamp(0.0, layers.len() as f64);
    let k = x.floor() as usize;
    let t = x - k as f64;
    let layer = |k: usize| layers.get(k).unwrap_or_else(|| lighting.smooth_mips().level(0));
    if t > 0.0 { blend(layer(k).lookup_uv(u, v), layer(k + 1).lookup_uv(u, v), t) } else { layer(k).lookup_uv(u, v) }
}

/// `(1 - t) a + t b`.
fn blend(a: [f32; 3], b: [f32; 3], t: f64) -> [f32; 3] {
    std::array::from_fn(|c| (f64::from(a[c]) * (1.0 - t) + f64::from(b[c]) * t) as f32)
}

/// The weight of a sample drawn with density `p` by one of two strategies that each draw one
/// direction per sample, `q` the other's density at it: the balance heuristic `p / (p + q)`
/// (crate documentation, "The estimators").
pub(crate) fn mis_weight(p: f64, q: f64) -> f64 {
    p / (p + q)
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
    view_layers: &[f32],
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
    if settings.estimator == Estimator::Prefiltered {
        if n_layers == 0 {
            return Err(Error::Invalid("prefiltered mode needs at least one prefiltered layer".into()));
        }
        if view_layers.is_empty() {
            return Err(Error::Invalid("prefiltered mode needs at least one view-layer entry".into()));
        }
        if let Some(&bad) = view_layers.iter().find(|&&l| !(l >= 0.0 && l as f64 <= n_layers as f64)) {
            return Err(Error::Invalid(format!(
                "view layer coordinate {bad} is outside 0 to {n_layers} (the smooth map past the {n_layers} prefiltered layers)"
            )));
        }
    }
    Ok(())
}
