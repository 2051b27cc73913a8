//! Bandwidth-driven multi-resolution shading (`000` section 3, `001` sections 2-3): predict, per
//! pixel, how finely the image must be sampled and how many samples its integral needs; shade
//! only the pixels of a pyramid whose level the prediction asks for, with a fixed total budget
//! of samples spread by the predicted variance; up-sample the rest from coarser shaded pixels.
//!
//! Everything here is a specification as much as code. `gpu::preview::Renderer::render_adaptive`
//! runs the whole frame on the GPU, step for step, from this module's G-buffer ([`Geometry`])
//! and with its allocation of the samples ([`allocation`]), in `f32`; it is held to this module
//! by planning a frame again from the GPU's predictions ([`render_with`]'s [`Hooks`]:
//! [`replay_predictor`]), the plans compared by [`Plan::compare`]. The hooks also give the
//! checks an oracle's bandwidths and exact shading ([`exact_shader`]: the plan's ceiling).
//!
//! # The G-buffer
//!
//! [`crate::raster`]'s hits (position, normal) at the render resolution (the output size times
//! `supersample`), and per pixel: the distance to the eye (`depth`), the surface's curvature `c`
//! (radians of normal turn per unit of length: `|n(x+1) - n(x-1)| / |p(x+1) - p(x-1)|` over
//! the covered neighbours, one-sided at the edges, the larger of the two screen axes; 1 / R on
//! a sphere of radius R, 0 on a plane), and the material (one per scene: covered or not). A
//! pixel is *shadeable* when it is covered and has a shading frame (crate docs). It depends on
//! the camera alone: [`Geometry`] holds it, made once per camera and shared by that camera's
//! frames, as a renderer draws its G-buffer once for the frames of a camera that does not move
//! (`gpu::preview::Renderer` does both).
//!
//! # The bandwidth buffer (`001` eq. 3-6, 9-11)
//!
//! For each shadeable pixel (or, with [`Settings::predict_level`] `l`, once per block of `2^l x
//! 2^l` output pixels, at the block's pixel, copied to its pixels, a block that holds a pixel
//! at or beside a silhouette split into its quarters ([`prediction_pixels`]): the prediction
//! costs as much as shading `n_b` samples, and a block's pixels are alike), `n_b` incident
//! directions (default 16): the first `n_b` samples of one baked vector of the pixel's slice
//! (the vector `pcg_hash(pixel ^ pcg_hash(seed ^ PREDICTION_SALT)) % V`; the prefix of an
//! Owen-scrambled Sobol' vector is stratified), each with its pdf. For each `wi`:
//!
//! - the light's bandwidth `nu_l = [0, nu_env(wi)]`, `nu_env` the bake's environment bandwidth
//!   (cycles per radian, nearest texel; [`EnvBandwidth`]; read level-normalized for a
//!   mirror-like material, whose pictures show the fine detail the paper's reading lets a strong
//!   edge mask: crate `bake`, `stage::env_bandwidth::ReadingChoice`); a distant light has no spatial
//!   bandwidth, so the transport from it (`T_d`) and `P_i` leave it unchanged;
//! - the reflection operator of eq. 3, `R = P_x C_-c S B_{t,rho} C_c P_i`, with the matrices of
//!   Fig. 4 exactly as printed: `C_c` shears `[0, nu_a]` to `[c nu_a, nu_a]`; `B` keeps the
//!   spatial part (`t = 0`: no texture) and limits the angular one to `m = min(rho, nu_a)`,
//!   `rho` the BRDF's bandwidth for `(wi, wo)` from the atlas ([`bandwidth_atlas::Atlas::lookup`]);
//!   `S`, `C_-c` and `P_x = diag(1 / cos theta_x, 1)` follow; `c` is the G-buffer's curvature
//!   (its magnitude: the sign of the shear is lost with it, the conservative side);
//! - the transport to the eye `T_d'` with `d'` the pixel's depth. The angular bandwidth at the
//!   eye is then `|nu_a| = m + d' c (nu_env + m) / cos theta_x`.
//!
//! Eq. 5 averages them with the weights `lambda_i = L(wi) f(wi, wo) cos theta_i` (luminances;
//! `L` the environment's level 0), each divided by the sample's pdf so that the average
//! estimates the integral it stands for whatever the sampling. Eq. 6 turns the result into
//! cycles per pixel with the radians per pixel of the render, `fov_y / height`.
//!
//! The pixel's level (eq. 11): its sampling rate is [`SAMPLES_PER_CYCLE`] (4) times its
//! bandwidth, `s = 4 nu` samples per pixel, and its level `floor(log2(1 / s))` clamped to `[0,
//! K]`, `K` the pyramid's top (`floor(log2(min(w, h)))`, or less when asked); a pixel with no
//! bandwidth sits at `K`. (The paper writes `log2(1 / b_p)` with `b_p` the bandwidth; read
//! literally it samples at the bandwidth, half the Nyquist rate, and its "floor ensures that
//! the Nyquist sampling rate is respected" would not hold.) Twice the Nyquist rate, because the
//! up-sampling is bilinear, not the ideal low-pass Nyquist's theorem reconstructs with: at the
//! Nyquist rate a bilinear reconstruction leaves square blocks and staircase contours wherever
//! the image is at its predicted bandwidth (a highlight under a sun). Measured against Mitsuba 3
//! (`cargo bench -p brdf-preview --bench mitsuba`, 7x7 bias p99, [`FRAMES`] frames):
//! gold-paint under quarry's sun 2.06 levels at the Nyquist rate, 1.18 at twice it, 1.47 at
//! four times (the budget then spreads over more blocks: noise); chrome, whose predicted
//! bandwidth the paper's reading of the environment made low, 5.6, 3.0 and 1.0 (the bakes now
//! read chrome's environment level-normalized: see "The bandwidth buffer").
//!
//! The predicted variance (eq. 9) is `sum_i (nu_env(wi) + rho_i) g_i^2 / pdf_i / n_b` with
//! `g_i = L(wi) f(wi, wo) cos theta_i` the integrand, the angular bandwidths of the light and
//! the BRDF at `wi` bounding the spectrum of their product; for the prefiltered estimator
//! (eq. 10) `sum_i 2 rho_i g_i^2 / pdf_i / n_b`: the layer holds no detail beyond the BRDF's.
//!
//! # Grading
//!
//! One prediction per block of `2^l x 2^l` pixels samples the image's bandwidth sparsely: an
//! edge that a block's pixel does not see (the rim of a softbox reflected in chrome, a sun's
//! highlight) is left to a coarse level beside a block that saw it, and the up-sampling draws
//! it in steps. The levels are therefore graded before the pyramid ([`grade_levels`]): a
//! shadeable pixel's level is at most [`GRADE_SLACK`] (1) more than the finest level among the
//! shadeable pixels within [`GRADE_RADIUS`] (4 render pixels, a prediction block at the default
//! level). Against Mitsuba 3 (`cargo bench -p brdf-preview --bench mitsuba`, 7x7 bias max in
//! levels; ungraded, graded, and graded with the blocks beside a finer region shaded rather than
//! extrapolated, "Coarse to fine"): chrome under `studio_small_03`, `adaptive` 4.20, 3.22 and
//! 2.61 with the light before the sphere, 3.82, 2.18 and 2.18 behind it; `adaptive-prefiltered`
//! 4.24, 3.10 and 3.14, and 3.61, 2.63 and 2.63; a Lambertian under quarry's sun 1.90, 1.48 and
//! 1.14. Grading moved PSNR by -0.3 to +1.0 dB: the few pixels it refines take little of the
//! budget. Taking the finest level within the radius instead (a slack of 0) cleared chrome's
//! blocks as well (max 2.06 and 2.10) but refined so much that every case lost 1 to 4 dB to
//! noise.
//!
//! # The pyramid (`001` section 3.1)
//!
//! Level `k` has blocks of `2^k x 2^k` pixels (partial at the right and bottom edges). The
//! *min* pyramid: `m_0` is a pixel's level (or "none" when it is not shadeable), `m_k` of a
//! block the least `m` of its children, "none" when any child has none: a block that holds
//! background or a silhouette is never shaded whole. A block is *valid* at level `k` when
//! `m_k >= k`: all its pixels may be sampled that coarsely. The *max* pyramid of the variance
//! gives a shaded block the largest variance of its pixels. Since a block's `m` is at most its
//! children's, a valid block's children are valid: the pyramid is conservative.
//!
//! # Coarse to fine (`001` section 3.2)
//!
//! From the top level down, each valid block is either *shaded* (its parent is not valid, or it
//! is the top level) or *up-sampled* from the valid blocks among the 2 x 2 parents of bilinear
//! interpolation at the next coarser level, with the weights `w_i = g_z g_a alpha_i` normalized
//! to sum to 1:
//!
//! - `alpha_i`: bilinear, from the blocks' centres (block `b` of level `k` sits at pixel
//!   `b 2^k + floor(2^k / 2)` and is shaded with that pixel's G-buffer: "we always shade with
//!   depth and normal values picked at the finest level");
//! - `g_z = exp(-(z - z_i)^2 / (2 (sigma z)^2))`, `sigma` relative ([`Settings::depth_sigma`],
//!   0.02): parents at another depth do not count;
//! - `g_a = exp(-v^T M v)`, `v` the offset to the parent in units of the parent spacing,
//!   `M = R^T diag(1 / cos^2 theta_x, 1) R` in the frame of the screen-projected normal: the
//!   weight falls faster across the foreshortened direction (the paper's `R_phi` leaves which
//!   axis takes `1 / cos^2` to its figure; foreshortening compresses the surface along the
//!   projected normal, so that is the axis), `cos theta_x` clamped at 0.1.
//!
//! - with [`Settings::lobe_weight`], also `003`'s lobe weight: the inner product of the two
//!   pixels' specular lobes as normalized spherical Gaussians ([`lobe_similarity`]), each
//!   around its mirror direction with the sharpness of the Phong layer the bake's layer
//!   selection picks for its view (`exp(n (cos - 1))` is the SG of `cos^n`): parents whose
//!   reflections point elsewhere, relative to the lobe's width, count less.
//!
//! A parent whose weight `w_i` is below [`MIN_WEIGHT`] (`2^-100`) does not count: the weights
//! are products of exponentials, which underflow at another depth in `f32` (`g_z` at a 26% depth
//! difference) long before they do in `f64` (76%), and a renderer that weights in `f32` must
//! count the same parents. A block is shaded instead (*rescued*) when one of its bilinear parents
//! is not valid, when its weights all vanish (every parent at another depth), or when they sum to
//! at most [`Settings::rescue_below`] before normalization. Every pixel therefore ends shaded at
//! its level or up-sampled from shaded parents, and the plan is fixed by the G-buffer alone,
//! before any shading.
//!
//! A parent that is not valid lies where the image needs a finer level, or holds a silhouette:
//! the remaining parents, renormalized, would extrapolate across it, drawing a coarse block's
//! value over pixels beside a finer region, a step along every boundary between levels (a
//! sun-lit rim's steep ramp on white-paint came out 20 levels dark in a column one pixel wide).
//! Shading such blocks costs 35 to 45% more shaded blocks of the same budget and gains 0 to
//! 1.3 dB; measured at 512 x 512, brdf-preview's defaults, against the converged estimate of 256
//! samples per strategy (PSNR; covered pixels more than 20 levels off), extrapolating and not:
//! white-paint under quarry_01 (default camera) `adaptive` 54.29 dB (14) and 55.55 (1),
//! `adaptive-prefiltered` 54.34 (13) and 55.62 (0); gold-paint 55.26 (0) and 56.42 (0); under
//! quarry's sun (camera -144, 10) 50.98 (0) and 51.01 (0); chrome under studio_small_03
//! 47.49 (14) and 47.73 (1), `adaptive-prefiltered` 46.77 (16) and 46.74 (1). In the adaptive
//! benchmark (`cargo bench -p brdf-preview --bench adaptive -- --gpu`, paper reading) the plans'
//! ceilings rose by 1 to 5 dB (gold-paint under quarry_01 55.28 to 57.10 dB on the sphere, 55.68
//! to 59.90 on the torus), and the frames gained up to 2.6 dB at 8 and 16 spp but lost 0.5 to 1.5
//! dB at 2 and 4, where the same budget spread over more blocks is noisier: the median speed-up
//! at equal PSNR fell from 6.2x to 5.1x (`adaptive`) and from 8.6x to 6.8x
//! (`adaptive-prefiltered`).
//!
//! # Samples
//!
//! The frame's budget is `spp` times the covered pixels of the output image. Each shaded block
//! gets at least 1 sample and the rest in proportion to a weight ([`Allocation`]):
//!
//! - its predicted variance `V_b` ([`Allocation::Variance`], the paper: every block, hence
//!   every pixel, equally noisy);
//! - `sqrt(A_b V_b)`, `A_b = 4^k` the pixels a block of level `k` stands for
//!   ([`Allocation::StdDev`]): the least total squared error over the pixels, which is what a
//!   PSNR measures. A block's noise `V_b / N_b` reaches every pixel up-sampled from it, whose
//!   weights sum to `A_b` over the pixels, so the error is `sum_b A_b V_b / N_b`; minimizing
//!   it under `sum_b N_b = B` gives `N_b ~ sqrt(A_b V_b)`;
//! - `sqrt(A_b)` ([`Allocation::Area`]): the same with every pixel's variance taken equal, the
//!   prediction's variance not used. At the budgets of the benchmark (`cargo bench -p
//!   brdf-preview --bench adaptive`, which measures the three) it is the best: eq. 9's bound
//!   ranks the pixels' noise moderately well but not its size, and weighting by it (or, tried
//!   and dropped, by it in display space or by the sample variance of the `n_b` directions)
//!   did not beat the area alone. Every block of a level then has the same share, so the
//!   samples follow from the shaded blocks per level alone: [`area_allocation`] computes them
//!   in exact integers (as `gpu::preview` does on the GPU, without a sort);
//!
//! at most the cap (what a capped block cannot
//! take goes to the others), rounded down to a power of two (a pixel's points are read in
//! aligned chunks: crate docs, "Samples"); what rounding leaves is handed out by doubling the
//! blocks furthest below their share, while it fits. The total never exceeds the budget; a
//! budget below one sample per shaded block is an error. The cap is [`Settings::max_spp`]
//! within a slice's `V N` points ([`Settings::block_cap`]): by default ([`MAX_SPP`]) a block may
//! read all of them (see "Shading"), so that the budget is spent. (A cap of one vector
//! left it unspent wherever the plan shades few blocks: on the benchmark's sphere at 512 x 512,
//! whose plans shade 2% of the pixels, every block reached 256 samples, and a 16 spp budget
//! spent 584704 of 2076672 samples.)
//!
//! # Shading
//!
//! A shaded block is shaded by the chosen estimator at its pixel: up to `N` samples (a baked
//! vector's worth) with its count as `spp` and one frame (the random chunk of that pixel's
//! points); a block of more samples (a power of two, so a multiple of `N`) with `spp = N` and
//! `count / N` frames, the first `count / N` vectors' worth of its pixel's walk through its
//! `V N` points (crate docs, "Samples"): all distinct, as the cap keeps `count <= V N`.
//! The prefiltered estimator sizes the block's footprints for `count` times
//! [`Settings::frames`], the frames the picture averages, as the full-resolution mode sizes
//! them for `spp` times its frames: each frame's block draws other points. Measured against the
//! converged estimate (chrome under studio_small_03, the Mitsuba benchmark's camera 82.8, 43.1,
//! 128 x 128, 8 frames), footprints for `count` alone left the picture 0.21 levels too bright on
//! average (7x7 bias p99 1.88) where those for `8 count` leave it 0.05 (p99 0.88).
//!
//! The prefiltered estimator (`001` section 2.5: samples of the illumination "pre-filtered
//! ... at the level given by the maximum frequency of the BRDF") reads the Phong layers
//! [`Settings::layer_shift`] layers sharper than the coordinate the bake's selection gives the
//! view ([`Material::view_layers`], crate docs "The estimators"), the map itself past the
//! sharpest at most, and no layer sharper than a sample's footprint among the block's. That
//! selection was chosen for the full-resolution pre-filtered mode at 16 samples per pixel (crate
//! `bake`, `stage::layer_selection`), where a sharper layer's noise costs about what its blur saves. A
//! shaded block takes tens to hundreds of samples, the budget of the pixels it stands for, and
//! there the blur dominates: the default shift is one layer ([`LAYER_SHIFT`]). Measured at
//! 512 x 512, brdf-preview's defaults and default camera, PSNR of the whole picture against
//! the converged estimate of 256 samples per strategy, shifts 0, 1 and 2: gold-paint under
//! quarry_01 54.70, 55.26 and 55.33 dB; white-paint 54.32, 54.34 and 54.34; chrome under
//! studio_small_03 46.77 at every shift (its views already read the map itself).
//!
//! # Frames
//!
//! A frame is planned from its own predictions, so its up-sampled pixels carry the noise of the
//! shaded blocks they come from: noise spread over a block's area, which no local average of the
//! picture removes. A previewer averages [`FRAMES`] frames ([`render_frames`]), each with its own
//! seed ([`frame_seed`]): other prediction directions, so a slightly different plan, and other
//! samples. Against Mitsuba 3 (`cargo bench -p brdf-preview --bench mitsuba`, 7x7 bias p99 at
//! brdf-preview's defaults, at the Nyquist rate): a Lambertian under quarry's sun 2.45 levels
//! with one frame, 1.74 with 8; gold-paint 3.61 and 2.06. Each frame's budget is [`SPP`]
//! samples per covered pixel by default, the filtered modes' 16.
//!
//! # Anti-aliasing (`001` section 4.3)
//!
//! `supersample = s` renders at `s` times the output size in each axis: the pyramid gets
//! `log2(s)` more levels, and smooth regions are shaded as coarsely as before, so the shading
//! grows with the edges, not with `s^2`; the prediction stays at the output's resolution (its
//! blocks are `s` times larger in render pixels); the G-buffer is the render's. The output pixel
//! is the mean of its `s x s` render pixels.

use crate::error::Error;
use crate::{Estimator, Lighting, Material, SampleSet};

mod frame;
mod geometry;
mod plan;
mod predict;
mod samples;
#[cfg(test)]
mod tests;

pub use frame::*;
pub use geometry::*;
pub use plan::*;
pub use predict::*;
pub use samples::*;

/// The environment's local angular bandwidth, in cycles per radian, on the environment's
/// lat-long grid (`envmap`'s orientation): the bake's `env-bandwidth.exr`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvBandwidth {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

impl EnvBandwidth {
    /// Checks the sizes (a 2:1 lat-long grid) and that every value is finite and non-negative.
    pub fn new(width: usize, height: usize, values: Vec<f32>) -> Result<Self, Error> {
        if width == 0 || width != 2 * height || width.checked_mul(height) != Some(values.len()) {
            return Err(Error::Invalid(format!(
                "an environment bandwidth map of {width} x {height} with {} values: expected a 2:1 lat-long grid",
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(Error::Invalid(format!(
                "environment bandwidth texel ({}, {}) is {}: expected a finite bandwidth >= 0",
                i % width,
                i / width,
                values[i]
            )));
        }
        Ok(Self { width, height, values })
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The texels, row-major.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The bandwidth at the map coordinates `(u, v)` of a direction (`envmap::uv`): the nearest
    /// texel.
    pub fn at_uv(&self, u: f64, v: f64) -> f64 {
        let x = ((u * self.width as f64) as usize).min(self.width - 1);
        let y = ((v * self.height as f64) as usize).min(self.height - 1);
        f64::from(self.values[y * self.width + x])
    }
}

/// What the prediction reads besides the material and the lighting.
#[derive(Clone, Debug)]
pub struct Bandwidths {
    pub environment: EnvBandwidth,
    /// The material's bandwidth atlas (the full grid; `bake` expands stored rows).
    pub brdf: bandwidth_atlas::Atlas,
}

/// How an adaptive frame is rendered (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The estimator of the shaded pixels: [`Estimator::Reference`] (`adaptive`) or
    /// [`Estimator::Prefiltered`] (`adaptive-prefiltered`, eq. 10 for the variance).
    pub estimator: Estimator,
    /// The budget: mean samples per covered pixel of the output image.
    pub spp: u32,
    /// The most samples one shaded block gets: a power of two. A block with more samples than
    /// a baked vector holds reads several vectors' worth of points (module docs, "Shading"); a
    /// frame reads at most a slice's `V N`, so the cap it applies is [`Settings::block_cap`].
    /// Default [`MAX_SPP`].
    pub max_spp: u32,
    /// Incident directions per pixel for the prediction (`n_b`).
    pub n_b: usize,
    pub seed: u32,
    /// Render pixels per output pixel along each axis: 1, 2 or 4 (anti-aliasing 1x, 4x, 16x).
    pub supersample: usize,
    /// The pyramid's top level; `None`: `floor(log2(min(w, h)))` of the render size (eq. 11).
    pub max_level: Option<usize>,
    /// `sigma` of the depth weight, relative to the child's depth.
    pub depth_sigma: f64,
    /// One prediction per `2^l x 2^l` block of output pixels (0: every pixel, as the paper);
    /// with anti-aliasing the blocks are `supersample` times larger in render pixels; at most
    /// the pyramid's top level (a larger value means the top).
    pub predict_level: usize,
    /// How the budget is shared among the shaded blocks.
    pub allocation: Allocation,
    /// Multiply the up-sampling weights by the similarity of the two pixels' specular lobes
    /// (`003` eq. 4, module docs).
    pub lobe_weight: bool,
    /// Shade a block instead of up-sampling it when the sum of its weights before
    /// normalization (at most 1) is at most this: `003`'s "recomputing the pixel values
    /// adaptively" where the weights say the parents do not represent it. 0: only when they
    /// all vanish.
    pub rescue_below: f64,
    /// [`Estimator::Prefiltered`]: the shaded blocks read the Phong layer this many layers sharper
    /// than the one [`Material::view_layers`] picks for their view (each layer a lobe half as
    /// wide), the map itself past the sharpest layer at most (module docs, "Shading"). Default
    /// [`LAYER_SHIFT`].
    pub layer_shift: u32,
    /// The frames the picture averages, each planned and shaded with its own seed
    /// ([`render_frames`] renders and averages them; a previewer may loop over [`render`]):
    /// the prefiltered estimator sizes a shaded block's footprints for its samples times
    /// these, as [`crate::Settings::filter_samples`] counts `spp` times the frames (module docs,
    /// "Shading"). From 1; default 1.
    pub frames: u32,
}

/// [`Settings::layer_shift`]'s default (module docs, "Shading").
pub const LAYER_SHIFT: u32 = 1;

/// [`Settings::max_spp`]'s default: no cap below a slice's samples for any bake up to 2^16 of
/// them, the most the GPU's allocation takes (`gpu::preview`).
pub const MAX_SPP: u32 = 1 << 16;

/// How a frame's samples are shared among its shaded blocks (module docs, "Samples").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Allocation {
    /// In proportion to the predicted variance: every pixel's estimate equally noisy (`001`
    /// section 2.4: "keep the variance of the shading globally constant").
    Variance,
    /// In proportion to `sqrt(A_b V_b)`, `A_b = 4^k` the pixels a block of level `k` stands
    /// for: the least total squared error over the pixels for the budget (module docs,
    /// "Samples").
    StdDev,
    /// In proportion to `sqrt(A_b)`: the least total squared error with every pixel's variance
    /// taken equal (the predicted variance not used).
    Area,
}

impl Allocation {
    pub fn name(self) -> &'static str {
        match self {
            Allocation::Variance => "variance",
            Allocation::StdDev => "std-dev",
            Allocation::Area => "area",
        }
    }
}

impl Settings {
    /// [`Settings::predict_level`] in render pixels, as [`prediction_pixels`] takes it: `l +
    /// log2(supersample)`, at most the pyramid's `top` (a block no larger than the image, and a
    /// shift that fits).
    pub fn prediction_level(&self, top: usize) -> usize {
        self.predict_level.saturating_add(self.supersample.trailing_zeros() as usize).min(top)
    }

    /// The most samples a block gets with `samples`: [`Settings::max_spp`], at most the largest
    /// power of two within a slice's `V N` (beyond them a block would read a point twice). A
    /// frame applies this cap ([`check_settings`] gives its settings).
    pub fn block_cap(&self, samples: &SampleSet) -> u32 {
        let slice = (samples.n_vectors as u64).saturating_mul(samples.n_samples as u64).max(1);
        let slice = 1u64 << (63 - slice.leading_zeros());
        u64::from(self.max_spp).min(slice) as u32
    }

    /// The defaults for an estimator and a budget: `n_b` 16, no anti-aliasing, the full pyramid,
    /// `max_spp` [`MAX_SPP`], depth sigma 0.02, seed 0, a prediction per pixel, samples in
    /// proportion to the variance (the paper's choices where it makes one).
    pub fn new(estimator: Estimator, spp: u32) -> Self {
        Settings {
            estimator,
            spp,
            max_spp: MAX_SPP,
            n_b: 16,
            seed: 0,
            supersample: 1,
            max_level: None,
            depth_sigma: 0.02,
            predict_level: 0,
            allocation: Allocation::Variance,
            lobe_weight: false,
            rescue_below: 0.0,
            layer_shift: LAYER_SHIFT,
            frames: 1,
        }
    }
}

/// The checks [`render`] makes on its settings, and the settings a frame of `material` runs
/// with: these with [`Settings::max_spp`] lowered to the block cap ([`Settings::block_cap`]).
/// Both renderers take their frame's settings from here.
pub fn check_settings(settings: &Settings, material: &Material, lighting: &Lighting) -> Result<Settings, Error> {
    if !matches!(settings.estimator, Estimator::Reference | Estimator::Prefiltered) {
        return Err(Error::Invalid(format!(
            "adaptive shading uses the reference or the prefiltered estimator, not {}",
            settings.estimator.name()
        )));
    }
    if !settings.max_spp.is_power_of_two() {
        return Err(Error::Invalid(format!("max_spp {} must be a power of two", settings.max_spp)));
    }
    // A block's samples are read a vector's worth (at most) at a time: the chunks' check.
    let n_samples = material.samples.n_samples;
    let per_frame = settings.max_spp.min(u32::try_from(n_samples).unwrap_or(u32::MAX));
    let base = crate::Settings { estimator: settings.estimator, spp: per_frame, frames: 1, seed: settings.seed };
    crate::check_settings(&base, n_samples, lighting.layers.len(), &material.view_layers)?;
    if settings.spp == 0 || settings.n_b == 0 || settings.frames == 0 || !matches!(settings.supersample, 1 | 2 | 4) {
        return Err(Error::Invalid(format!(
            "spp {}, n_b {} and frames {} must be at least 1 and supersample ({}) 1, 2 or 4",
            settings.spp, settings.n_b, settings.frames, settings.supersample
        )));
    }
    if settings.lobe_weight
        && (material.view_layers.is_empty()
            || material.view_layers.iter().any(|&l| !(l >= 0.0 && f64::from(l) <= lighting.exponents.len() as f64)))
    {
        return Err(Error::Invalid(
            "the lobe weight reads the bake's layer selection, which is missing or out of range".into(),
        ));
    }
    if !(settings.depth_sigma > 0.0 && settings.depth_sigma.is_finite()) {
        return Err(Error::Invalid(format!("depth sigma {} must be positive", settings.depth_sigma)));
    }
    Ok(Settings { max_spp: settings.block_cap(&material.samples), ..*settings })
}

/// The pyramid's top level for a render of `width x height`: eq. 11's `floor(log2(min(w, h)))`,
/// at most `max_level`.
pub fn top_level(width: usize, height: usize, max_level: Option<usize>) -> usize {
    let full = (usize::BITS - 1 - width.min(height).max(1).leading_zeros()) as usize;
    max_level.map_or(full, |m| m.min(full))
}
