//! One frame: the stages in order, the hooks that check them, and what the frame made (module
//! docs, "Shading" and "Anti-aliasing").

use rayon::prelude::*;

use crate::error::Error;
use crate::raster::GBuffer;
use crate::shade::{BlockFilter, background, shade};
use crate::{Image, Lighting, Material, Scene};

use super::*;

/// What an adaptive frame made: the picture, its figures, and (where kept) everything the debug
/// views and the checks read.
#[derive(Clone, Debug)]
pub struct Adaptive {
    /// The output image (the render averaged over `supersample^2` pixels).
    pub image: Image,
    /// The render size (the output size times `supersample`).
    pub width: usize,
    pub height: usize,
    /// Shadeable render pixels.
    pub shadeable: usize,
    /// The blocks shaded at each level, level 0 first.
    pub shaded_per_level: Vec<usize>,
    /// The samples the frame spent, and its budget.
    pub samples: u64,
    pub budget: u64,
    /// Wall time of the steps, in milliseconds: G-buffer (made once per camera: the
    /// [`Geometry`]'s), bandwidth buffer (prediction), pyramid and plan, shading and
    /// up-sampling.
    pub timings: Timings,
    /// The frame's buffers: always here from [`render_with`]; a renderer that keeps them where
    /// it computed them (`gpu::preview`) reads them back only when asked.
    pub details: Option<Details>,
}

/// An adaptive frame's buffers, per render pixel and per block.
#[derive(Clone, Debug)]
pub struct Details {
    /// The bandwidth buffer, per render pixel.
    pub predictions: Vec<Prediction>,
    pub plan: Plan,
    /// Per render pixel: the level of the block whose shading its value comes from (through
    /// its own ancestors), -1 where it is not shadeable.
    pub shaded_level: Vec<i32>,
    /// Per render pixel: the samples of that block over its area in render pixels.
    pub samples_per_pixel: Vec<f32>,
}

impl Details {
    /// The per-pixel views of `plan` over a `width`-wide render: for each render pixel, the
    /// level its value comes from (through the up-sampling's first parents, the same block
    /// [`render_with`] follows) and that block's samples over its area; -1 and 0 where the
    /// pixel is not shadeable.
    pub fn origins(plan: &Plan) -> (Vec<i32>, Vec<f32>) {
        let top = plan.levels.len() - 1;
        let mut origin: Vec<(i32, f32)> = Vec::new();
        for k in (0..=top).rev() {
            let level = &plan.levels[k];
            let coarser = origin;
            origin = plan.actions[k]
                .iter()
                .enumerate()
                .map(|(b, action)| match *action {
                    Action::Skip => (-1, 0.0),
                    Action::Shade { samples, .. } => (k as i32, samples as f32 / (1u64 << (2 * k)) as f32),
                    Action::Upsample { .. } => {
                        coarser[(b / level.width / 2) * plan.levels[k + 1].width + (b % level.width) / 2]
                    }
                })
                .collect();
        }
        origin.into_iter().unzip()
    }
}

/// Wall time of an adaptive frame's steps, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// The [`Geometry`]'s, made once per camera: not part of the frame's time when its camera
    /// made frames before.
    pub gbuffer_ms: f64,
    /// The prediction: [`render_with`]'s, or `gpu::preview`'s in one submission (the area
    /// allocation) on the GPU's clock (0 on an adapter without timestamp queries); in two (the
    /// variance and std-dev allocations): the first submission's wall time (the prediction,
    /// the pyramids and the plan, and the list of shaded blocks read back).
    pub predict_ms: f64,
    /// The pyramids and the plan with its samples: [`render_with`]'s, or `gpu::preview`'s in
    /// one submission on the GPU's clock (with the list of shaded blocks; 0 without
    /// timestamps); in two: the allocation of the samples on the CPU.
    pub plan_ms: f64,
    /// [`render_with`]: shading, up-sampling and the background; `gpu::preview` in one
    /// submission: the shading, up-sampling and output on the GPU's clock (without timestamps:
    /// the whole frame); in two: the second's wall time (the same, and the image read back).
    pub shade_ms: f64,
    /// The frame's wall time: the steps and, on the GPU, what lies between and around them
    /// (recording, submission, waiting, read-back). Not the G-buffer's.
    pub total_ms: f64,
    /// The GPU submissions of the frame (`gpu::preview`: 1 or 2; [`render_with`]: 0), and
    /// whether the steps were timed on the GPU's clock.
    pub submissions: u32,
    pub gpu_clock: bool,
}

impl Adaptive {
    /// Shaded blocks over shadeable render pixels: 1 when every pixel is shaded on its own.
    pub fn shaded_fraction(&self) -> f64 {
        let shaded: usize = self.shaded_per_level.iter().sum();
        if self.shadeable == 0 { 0.0 } else { shaded as f64 / self.shadeable as f64 }
    }

    /// The frame's buffers ([`Adaptive::details`]). Panics where the renderer was not asked to
    /// keep them: a caller that reads them asks.
    pub fn details(&self) -> &Details {
        self.details.as_ref().expect("an adaptive frame rendered without its details")
    }
}

/// Renders one adaptive frame of `scene` (module docs for every step), its [`Geometry`]
/// included. The settings are checked before the scene is rasterized.
pub fn render(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &Bandwidths,
    settings: &Settings,
) -> Result<Adaptive, Error> {
    check_settings(settings, material, lighting)?;
    let geometry = Geometry::of_scene(scene, settings.supersample)?;
    render_with(&geometry, material, lighting, bandwidths, settings, Hooks::default())
}

/// Frames a previewer averages by default (module docs, "Frames").
pub const FRAMES: u32 = 8;

/// The budget a previewer gives a frame by default ([`Settings::spp`], module docs, "Frames"):
/// the filtered modes' 16 samples per pixel and frame, 128 per covered pixel over [`FRAMES`]
/// frames, for either estimator. The frames' noise is spread over the shaded blocks' areas,
/// which a 7x7 average of the picture does not remove: against the converged estimate on the
/// Mitsuba bench's cases (128 x 128; Lambertian, white-paint and gold-paint under `quarry_01`
/// and `studio_small_03`, the light before and behind the sphere), the largest 7x7 bias p99 was
/// 1.77 levels for `adaptive` at 8 and 2.50 for `adaptive-prefiltered` at 4 (gold-paint under
/// the studio with the light behind: noise, not structure), 1.36 and 1.35 at 16 (white-paint
/// under quarry, the light behind).
pub const SPP: u32 = 16;

/// The seed of frame `frame` of frames started with `seed` (module docs, "Frames"): `seed`
/// itself for the first, so that one frame is [`render`]'s; then a hash of both, so that two
/// seeds' frames do not repeat each other's.
pub fn frame_seed(seed: u32, frame: u32) -> u32 {
    if frame == 0 { seed } else { crate::pcg_hash(seed ^ crate::pcg_hash(frame)) }
}

/// The mean of [`Settings::frames`] adaptive frames of `scene` (module docs, "Frames"): frame `f`
/// rendered with [`frame_seed`]`(settings.seed, f)`, the [`Geometry`] made once.
pub fn render_frames(
    scene: &Scene,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &Bandwidths,
    settings: &Settings,
) -> Result<Image, Error> {
    check_settings(settings, material, lighting)?;
    let geometry = Geometry::of_scene(scene, settings.supersample)?;
    let mut mean = FrameMean::default();
    for f in 0..settings.frames {
        let settings = Settings { seed: frame_seed(settings.seed, f), ..*settings };
        mean.add(&render_with(&geometry, material, lighting, bandwidths, &settings, Hooks::default())?.image);
    }
    mean.mean().ok_or_else(|| Error::Invalid("adaptive frames: expected at least one frame".into()))
}

/// The mean of images of one size and coverage, added one at a time (in `f64`).
#[derive(Clone, Debug, Default)]
pub struct FrameMean {
    first: Option<Image>,
    sum: Vec<f64>,
    count: u32,
}

impl FrameMean {
    /// Adds `image`. Panics if its size differs from the first image's.
    pub fn add(&mut self, image: &Image) {
        if self.first.is_none() {
            self.first = Some(image.clone());
            self.sum = vec![0.0; image.rgb.len()];
        }
        assert_eq!(self.sum.len(), image.rgb.len(), "frames of different sizes");
        for (s, &v) in self.sum.iter_mut().zip(&image.rgb) {
            *s += f64::from(v);
        }
        self.count += 1;
    }

    /// The frames added so far.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// The mean image, `None` before the first.
    pub fn mean(self) -> Option<Image> {
        let n = f64::from(self.count);
        let first = self.first?;
        Some(Image { rgb: self.sum.iter().map(|s| (s / n) as f32).collect(), ..first })
    }
}

/// What [`render_with`] may take from elsewhere instead of computing it here; the default takes
/// nothing.
#[derive(Default)]
pub struct Hooks<'a> {
    /// The image bandwidth of every render pixel (cycles per pixel, row-major) given instead of
    /// predicted: the benchmark's oracle, a windowed FFT of the converged image (`001` Fig.
    /// 12); the variance is predicted as usual.
    pub oracle: Option<&'a [f64]>,
    /// The predictions made elsewhere ([`replay_predictor`]: an earlier frame's, such as the
    /// GPU's).
    pub predictor: Option<Predictor<'a>>,
    /// The shaded blocks shaded elsewhere ([`exact_shader`]: a reference image's values).
    pub shader: Option<Shader<'a>>,
}

impl std::fmt::Debug for Hooks<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("oracle", &self.oracle.map(<[f64]>::len))
            .field("predictor", &self.predictor.is_some())
            .field("shader", &self.shader.is_some())
            .finish()
    }
}

/// A predictor of the bandwidth buffer (see [`Hooks`]): the [`prediction_pixels`] in (row-major
/// indices at the render size), each one's `(bandwidth, variance)` out, as the module docs
/// specify them for `settings` (eq. 11's level is applied by the caller).
pub type Predictor<'a> = &'a mut dyn FnMut(&[u32]) -> Predicted;

/// What a [`Predictor`] returns: each pixel's image bandwidth (cycles per pixel) and variance.
pub type Predicted = Result<Vec<[f64; 2]>, Error>;

/// A [`Predictor`] that gives back the predictions of an earlier frame (at the same render size),
/// so that [`render_with`] makes its plan again: the previewer checks a frame the GPU planned
/// with the CPU's shading this way.
pub fn replay_predictor(predictions: &[Prediction]) -> impl FnMut(&[u32]) -> Predicted + '_ {
    |pixels| {
        pixels
            .iter()
            .map(|&i| match predictions.get(i as usize) {
                Some(p) if p.level >= 0 => Ok([p.bandwidth, p.variance]),
                _ => Err(Error::Invalid(format!("render pixel {i} has no prediction to replay"))),
            })
            .collect()
    }
}

/// A shader of shaded blocks (see [`render_with`]): `(render pixel, samples)` in, each block's
/// estimate out.
pub type Shader<'a> = &'a mut dyn FnMut(&[(u32, u32)]) -> Estimates;

/// What a [`Shader`] returns: each block's estimate (linear RGB), in the order given.
pub type Estimates = Result<Vec<[f32; 3]>, Error>;

/// A [`Shader`] that gives every shaded block `reference`'s value at its pixel, so that
/// [`render_with`] makes the frame whose only error is the up-sampling's: the plan's *ceiling*,
/// the quality no budget passes. `reference` is at the render size (no supersampling).
pub fn exact_shader(reference: &Image) -> impl FnMut(&[(u32, u32)]) -> Estimates + '_ {
    |blocks| {
        blocks
            .iter()
            .map(|&(i, _)| {
                let i = i as usize;
                reference.rgb.get(3 * i..3 * i + 3).map(|v| [v[0], v[1], v[2]]).ok_or_else(|| {
                    Error::Invalid(format!(
                        "block pixel {i} is outside the reference image of {} x {}",
                        reference.width, reference.height
                    ))
                })
            })
            .collect()
    }
}

/// The plan's ceiling: the frame planned again from `predictions` (an earlier frame's, such as
/// the GPU's) with every shaded block given its value in `reference` (a converged estimate at the
/// render's size), so that its error against `reference` is the up-sampling's alone, the quality
/// no budget can pass. `oracle` as in [`Hooks`].
#[allow(clippy::too_many_arguments)]
pub fn ceiling(
    geometry: &Geometry,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &Bandwidths,
    settings: &Settings,
    predictions: &[Prediction],
    reference: &Image,
    oracle: Option<&[f64]>,
) -> Result<Adaptive, Error> {
    let hooks = Hooks {
        oracle,
        predictor: Some(&mut replay_predictor(predictions)),
        shader: Some(&mut exact_shader(reference)),
    };
    render_with(geometry, material, lighting, bandwidths, settings, hooks)
}

/// [`render`] from the `geometry` of the frame's camera (made for `settings.supersample`),
/// with what `hooks` gives instead of computing it here. `oracle` replaces the predicted
/// bandwidths (the prediction still runs, for the variance). `predictor`: given the
/// [`prediction_pixels`], it returns their predictions. `shader`: given every shaded block's
/// render pixel (row-major index at the render size) and samples, it returns each one's
/// estimate in frame 0 with that many samples by `settings.mode`'s estimator, as
/// [`crate::render`] computes it. Everything else (pyramid, plan, up-sampling, the environment
/// behind the mesh) runs here, and the timings include the hooks'; [`Timings::gbuffer_ms`] is
/// the geometry's.
pub fn render_with(
    geometry: &Geometry,
    material: &Material,
    lighting: &Lighting,
    bandwidths: &Bandwidths,
    settings: &Settings,
    hooks: Hooks,
) -> Result<Adaptive, Error> {
    let Hooks { oracle, predictor, shader } = hooks;
    crate::check_inputs(material, lighting)?;
    let settings = &check_settings(settings, material, lighting)?;
    if settings.supersample != geometry.supersample {
        return Err(Error::Invalid(format!(
            "a frame supersampled {} times from a geometry made for {}",
            settings.supersample, geometry.supersample
        )));
    }
    let (width, height) = geometry.render_size();
    let (gbuffer, pixels) = (&geometry.gbuffer, &geometry.pixels);
    let clock = std::time::Instant::now();
    let lap = || clock.elapsed().as_secs_f64() * 1e3;
    let top = top_level(width, height, settings.max_level);
    let radians_per_pixel = f64::from(geometry.camera.fov_y()) / height as f64;
    let frame = Frame {
        gbuffer,
        eye: geometry.camera.eye().as_dvec3(),
        material,
        lighting,
        bandwidths,
        settings,
        radians_per_pixel,
        top,
    };
    let mut predictions = predict(pixels, (width, height), &frame, predictor)?;
    if let Some(oracle) = oracle {
        apply_oracle(&mut predictions, oracle, top, (width, height))?;
    }
    grade_levels(&mut predictions, width, height);
    let predict_ms = lap();
    let levels = pyramid(&predictions, width, height, top);
    let covered_output = geometry.covered.iter().filter(|&&c| c).count() as u64;
    // The lobe weight's sharpness per view row: the exponent at the row's layer coordinate.
    let sharpness: Option<Vec<f64>> = settings
        .lobe_weight
        .then(|| material.view_layers.iter().map(|&x| crate::layer_exponent(&lighting.exponents, x)).collect());
    let plan = plan(
        levels,
        pixels,
        (width, height),
        u64::from(settings.spp) * covered_output,
        settings,
        sharpness.as_deref(),
    )?;
    let plan_ms = lap();
    let shaded = shade_blocks(&plan, &frame, shader)?;
    let values = upsample(&plan, &shaded);
    let image = compose(geometry, lighting, &values);
    let shade_ms = lap();
    let timings = Timings {
        gbuffer_ms: geometry.millis,
        predict_ms,
        plan_ms: plan_ms - predict_ms,
        shade_ms: shade_ms - plan_ms,
        total_ms: shade_ms,
        submissions: 0,
        gpu_clock: false,
    };
    let (shaded_level, samples_per_pixel) = Details::origins(&plan);
    Ok(Adaptive {
        timings,
        image,
        width,
        height,
        shadeable: pixels.iter().filter(|p| p.is_some()).count(),
        shaded_per_level: plan.shaded_per_level(),
        samples: plan.samples(),
        budget: plan.budget,
        details: Some(Details { predictions, plan, shaded_level, samples_per_pixel }),
    })
}

/// Replaces the predicted bandwidths of the shadeable pixels by `oracle`'s (one per render pixel
/// of `width x height`), and their levels by eq. 11's for them.
fn apply_oracle(
    predictions: &mut [Prediction],
    oracle: &[f64],
    top: usize,
    (width, height): (usize, usize),
) -> Result<(), Error> {
    if oracle.len() != predictions.len() {
        return Err(Error::Invalid(format!(
            "an oracle of {} values for {width} x {height} render pixels",
            oracle.len()
        )));
    }
    for (p, &bandwidth) in predictions.iter_mut().zip(oracle) {
        if p.level >= 0 {
            *p = Prediction { bandwidth, level: level_of(bandwidth, top), ..*p };
        }
    }
    Ok(())
}

/// The estimates of a plan's shaded blocks.
struct Shaded {
    /// One per shaded block, in the plan's order.
    estimates: Vec<[f32; 3]>,
    /// Per level and block, the index of its estimate (`u32::MAX` where it is not shaded).
    slots: Vec<Vec<u32>>,
}

/// The estimates of the plan's shaded blocks, by `shader` or here (module docs, "Shading").
/// Shading does not depend on up-sampling: every shaded block at once.
fn shade_blocks(plan: &Plan, frame: &Frame, shader: Option<Shader>) -> Result<Shaded, Error> {
    let Frame { gbuffer, material, lighting, settings, .. } = *frame;
    let (width, height) = (gbuffer.width, gbuffer.height);
    let mut shaded: Vec<(u32, u32)> = Vec::new();
    let slots = plan
        .actions
        .iter()
        .zip(&plan.levels)
        .map(|(actions, level)| {
            actions
                .iter()
                .enumerate()
                .map(|(b, action)| match *action {
                    Action::Shade { samples, .. } => {
                        let (x, y) = level.pixel(b % level.width, b / level.width, width, height);
                        shaded.push(((y * width + x) as u32, samples));
                        (shaded.len() - 1) as u32
                    }
                    _ => u32::MAX,
                })
                .collect()
        })
        .collect();
    // A block's samples come a vector's worth at most per frame.
    let n_samples = material.samples.n_samples as u32;
    let estimates = match shader {
        Some(shader) => shader(&shaded)?,
        None => shaded
            .par_iter()
            .map(|&(pixel, samples)| {
                let local = shading_frame(gbuffer, frame.eye, pixel as usize);
                let spp = samples.min(n_samples);
                let shading =
                    crate::Settings { estimator: settings.estimator, spp, frames: samples / spp, seed: settings.seed };
                let block = BlockFilter { layer_shift: settings.layer_shift, frames: settings.frames };
                shade(&local, pixel, material, lighting, &shading, block).map(|v| v as f32)
            })
            .collect(),
    };
    if estimates.len() != shaded.len() {
        return Err(Error::Invalid(format!(
            "the shader returned {} estimates for {} blocks",
            estimates.len(),
            shaded.len()
        )));
    }
    Ok(Shaded { estimates, slots })
}

/// Every level's block values, coarse to fine: a shaded block's estimate, an up-sampled block's
/// weighted parents (module docs, "Coarse to fine").
fn upsample(plan: &Plan, shaded: &Shaded) -> Vec<Vec<[f32; 3]>> {
    let Shaded { estimates, slots } = shaded;
    let top = plan.levels.len() - 1;
    let mut values: Vec<Vec<[f32; 3]>> = vec![Vec::new(); top + 1];
    for k in (0..=top).rev() {
        let coarser = if k < top { &values[k + 1] } else { &Vec::new() };
        values[k] = plan.actions[k]
            .par_iter()
            .enumerate()
            .map(|(b, action)| match *action {
                Action::Skip => [0.0; 3],
                Action::Shade { .. } => estimates[slots[k][b] as usize],
                Action::Upsample { parents, count } => {
                    let mut value = [0.0f32; 3];
                    for &(i, w) in &parents[..count as usize] {
                        for c in 0..3 {
                            value[c] += w * coarser[i as usize][c];
                        }
                    }
                    value
                }
            })
            .collect();
    }
    values
}

/// The output image: level 0's values where a pixel is shadeable, black where a triangle covers
/// it without a shading frame, the environment behind the mesh elsewhere, averaged over each
/// output pixel's `supersample x supersample` render pixels.
fn compose(geometry: &Geometry, lighting: &Lighting, values: &[Vec<[f32; 3]>]) -> Image {
    let (width, height) = geometry.render_size();
    let (level0, rays) = (lighting.mips.level(0), geometry.camera.rays(width, height));
    let render_rgb: Vec<[f32; 3]> = (0..width * height)
        .into_par_iter()
        .map(|i| match (&geometry.gbuffer.hits[i], &geometry.pixels[i]) {
            (None, _) => background(&rays, level0, i % width, i / width).map(|v| v as f32),
            (Some(_), None) => [0.0; 3],
            (Some(_), Some(_)) => values[0][i],
        })
        .collect();
    let (output_width, output_height) = geometry.size;
    downsample(&render_rgb, geometry.covered.clone(), output_width, output_height, geometry.supersample)
}

/// Per output pixel: whether a triangle covers any of its `ss x ss` render pixels.
pub(super) fn output_coverage(gbuffer: &GBuffer, width: usize, height: usize, ss: usize) -> Vec<bool> {
    (0..width * height)
        .map(|i| {
            let (x, y) = (i % width * ss, i / width * ss);
            (0..ss * ss).any(|j| gbuffer.hits[(y + j / ss) * gbuffer.width + x + j % ss].is_some())
        })
        .collect()
}

/// The output image: the mean of each `ss x ss` block of render pixels, with its coverage.
fn downsample(rgb: &[[f32; 3]], covered: Vec<bool>, width: usize, height: usize, ss: usize) -> Image {
    let render_width = width * ss;
    let mut out = Vec::with_capacity(3 * width * height);
    for y in 0..height {
        for x in 0..width {
            let mut sum = [0.0f64; 3];
            for j in 0..ss * ss {
                let i = (y * ss + j / ss) * render_width + x * ss + j % ss;
                for c in 0..3 {
                    sum[c] += f64::from(rgb[i][c]);
                }
            }
            out.extend(sum.map(|v| (v / (ss * ss) as f64) as f32));
        }
    }
    Image { width, height, rgb: out, covered }
}
