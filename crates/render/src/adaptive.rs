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
//! 2^l` output pixels, at the block's pixel, copied to its shadeable pixels, a block whose pixel
//! is not shadeable split into its quarters: the prediction costs as much as shading `n_b`
//! samples, and a block's pixels are alike), `n_b` incident
//! directions (default 16): the first `n_b` samples of one baked vector of the pixel's slice
//! (the vector `pcg_hash(pixel ^ pcg_hash(seed ^ 0x9e37_79b9)) % V`; the prefix of an
//! Owen-scrambled Sobol' vector is stratified), each with its pdf. For each `wi`:
//!
//! - the light's bandwidth `nu_l = [0, nu_env(wi)]`, `nu_env` the bake's environment bandwidth
//!   (cycles per radian, nearest texel; [`EnvBandwidth`]); a distant light has no spatial
//!   bandwidth, so the transport from it (`T_d`) and `P_i` leave it unchanged;
//! - the reflection operator of eq. 3, `R = P_x C_-c S B_{t,rho} C_c P_i`, with the matrices of
//!   Fig. 4 exactly as printed: `C_c` shears `[0, nu_a]` to `[c nu_a, nu_a]`; `B` keeps the
//!   spatial part (`t = 0`: no texture) and limits the angular one to `m = min(rho, nu_a)`,
//!   `rho` the BRDF's bandwidth for `(wi, wo)` from the atlas ([`brdf_atlas::Atlas::lookup`]);
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
//! The pixel's level (eq. 11): its sampling rate is twice its bandwidth (Nyquist), `s = 2 nu`
//! samples per pixel, and its level `floor(log2(1 / s))` clamped to `[0, K]`, `K` the pyramid's
//! top (`floor(log2(min(w, h)))`, or less when asked); a pixel with no bandwidth sits at `K`.
//! (The paper writes `log2(1 / b_p)` with `b_p` the bandwidth; read literally it samples at
//! the bandwidth, half the Nyquist rate, and its "floor ensures that the Nyquist sampling rate
//! is respected" would not hold.)
//!
//! The predicted variance (eq. 9) is `sum_i (nu_env(wi) + rho_i) g_i^2 / pdf_i / n_b` with
//! `g_i = L(wi) f(wi, wo) cos theta_i` the integrand, the angular bandwidths of the light and
//! the BRDF at `wi` bounding the spectrum of their product; for the pre-convolved estimator
//! (eq. 10) `sum_i 2 rho_i g_i^2 / pdf_i / n_b`: the layer holds no detail beyond the BRDF's.
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
//! count the same parents. A block whose weights all vanish (every parent at another depth), or
//! sum to at most [`Settings::rescue_below`] before normalization, is shaded instead
//! (*rescued*). Every pixel therefore ends shaded at its level or up-sampled from shaded
//! parents, and the plan is fixed by the G-buffer alone, before any shading.
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
//!
//! The pre-convolved estimator (`001` section 2.5: samples of the illumination "pre-filtered
//! ... at the level given by the maximum frequency of the BRDF") reads the Phong layers
//! [`Settings::layer_shift`] layers sharper than the coordinate the bake's selection gives the
//! view ([`Material::view_layers`], crate docs "The estimators"), the sharpest at most. That
//! selection was chosen for the full-resolution pre-filtered mode at 16 samples per pixel (crate
//! `bake`, `stage::layers`), where a sharper layer's noise costs about what its blur saves. A
//! shaded block takes tens to hundreds of samples, the budget of the pixels it stands for, and
//! there the blur dominates: the default shift is one layer ([`LAYER_SHIFT`]). It was measured
//! (the adaptive benchmark with the shift set by hand: 0 to 3 layers) when the estimator read
//! one layer per view row and filtered the sun with the sky; with the layers blended and the
//! peaks sampled unfiltered it has not been measured again.
//!
//! # Anti-aliasing (`001` section 4.3)
//!
//! `supersample = s` renders at `s` times the output size in each axis: the pyramid gets
//! `log2(s)` more levels, and smooth regions are shaded as coarsely as before, so the shading
//! grows with the edges, not with `s^2`; the prediction stays at the output's resolution (its
//! blocks are `s` times larger in render pixels); the G-buffer is the render's. The output pixel
//! is the mean of its `s x s` render pixels.

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;
use crate::raster::GBuffer;
use crate::shade::{ShadingFrame, background, brdf, shade, slice_of, visibility_of};
use crate::{Camera, Image, Lighting, Material, Mesh, Mode, SampleSet, Scene, pcg_hash};

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
    pub brdf: brdf_atlas::Atlas,
}

/// How an adaptive frame is rendered (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The estimator of the shaded pixels: [`Mode::Reference`] (`adaptive`) or
    /// [`Mode::Prefiltered`] (`adaptive-prefiltered`, eq. 10 for the variance).
    pub mode: Mode,
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
    /// [`Mode::Prefiltered`]: the shaded blocks read the Phong layer this many layers sharper
    /// than the one [`Material::view_layers`] picks for their view (each layer a lobe half as
    /// wide), the sharpest layer at most (module docs, "Shading"). Default [`LAYER_SHIFT`].
    pub layer_shift: u32,
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

    /// The defaults for a mode and a budget: `n_b` 16, no anti-aliasing, the full pyramid,
    /// `max_spp` [`MAX_SPP`], depth sigma 0.02, seed 0, a prediction per pixel, samples in
    /// proportion to the variance (the paper's choices where it makes one).
    pub fn new(mode: Mode, spp: u32) -> Self {
        Settings {
            mode,
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
        }
    }
}

/// A shadeable pixel's G-buffer (module docs, "The G-buffer"), what the plan reads; its shading
/// frame is made again where a pixel is shaded or predicted (`shading_frame`). Kept small: a
/// frame allocates one per render pixel, and fresh memory costs more than the arithmetic.
#[derive(Clone, Copy, Debug)]
pub struct Pixel {
    /// `cos theta_o` of the shading frame.
    pub cos_o: f64,
    pub depth: f64,
    pub curvature: f64,
    /// The normal projected on the screen (x right, y down), unit, or zero when it faces the
    /// eye.
    pub screen_normal: [f64; 2],
    /// The mirror direction of the view about the normal: the axis of a specular lobe.
    pub mirror: DVec3,
}

/// What a camera sees, for its adaptive frames (module docs, "The G-buffer"): the G-buffer of
/// the render (the output's size times the supersampling) and its pixels' quantities. Made once
/// per camera; every frame of that camera and supersampling reads it.
#[derive(Clone)]
pub struct Geometry {
    camera: Camera,
    /// The output's size.
    size: (usize, usize),
    supersample: usize,
    gbuffer: GBuffer,
    pixels: Vec<Option<Pixel>>,
    /// Per output pixel: whether a triangle covers any of its render pixels.
    covered: Vec<bool>,
    /// Wall time it took to make, in milliseconds.
    millis: f64,
}

impl Geometry {
    /// `mesh` seen from `camera` by an output image of `width x height` rendered at
    /// `supersample` (1, 2 or 4) times that size along each axis.
    pub fn new(
        mesh: &Mesh,
        camera: &Camera,
        (width, height): (usize, usize),
        supersample: usize,
    ) -> Result<Geometry, Error> {
        if !matches!(supersample, 1 | 2 | 4) {
            return Err(Error::Invalid(format!("supersample {supersample} must be 1, 2 or 4")));
        }
        let clock = std::time::Instant::now();
        let (render_width, render_height) = (width * supersample, height * supersample);
        let gbuffer = visibility_of(mesh, camera, render_width, render_height)?;
        let pixels = pixels(camera, &gbuffer);
        let covered = output_coverage(&gbuffer, width, height, supersample);
        let millis = clock.elapsed().as_secs_f64() * 1e3;
        Ok(Geometry { camera: *camera, size: (width, height), supersample, gbuffer, pixels, covered, millis })
    }

    /// The geometry of `scene` rendered at `supersample` times its size.
    pub fn of_scene(scene: &Scene, supersample: usize) -> Result<Geometry, Error> {
        Geometry::new(&scene.mesh, &scene.camera, (scene.width, scene.height), supersample)
    }

    pub fn supersample(&self) -> usize {
        self.supersample
    }

    /// The output's size.
    pub fn size(&self) -> (usize, usize) {
        self.size
    }

    /// Per render pixel, row-major: its G-buffer, `None` where it is not shadeable.
    pub fn pixels(&self) -> &[Option<Pixel>] {
        &self.pixels
    }

    /// Whether a triangle covers render pixel `i` (shadeable or not).
    pub fn covers(&self, i: usize) -> bool {
        self.gbuffer.hits[i].is_some()
    }

    /// Per output pixel: whether a triangle covers any of its render pixels.
    pub fn output_coverage(&self) -> &[bool] {
        &self.covered
    }

    /// Wall time it took to make, in milliseconds.
    pub fn millis(&self) -> f64 {
        self.millis
    }

    /// The render's size: the output's times the supersampling.
    pub fn render_size(&self) -> (usize, usize) {
        (self.gbuffer.width, self.gbuffer.height)
    }
}

impl std::fmt::Debug for Geometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Geometry")
            .field("size", &self.size)
            .field("supersample", &self.supersample)
            .field("shadeable", &self.pixels.iter().filter(|p| p.is_some()).count())
            .field("millis", &self.millis)
            .finish_non_exhaustive()
    }
}

/// The G-buffer's pixels, `None` where a pixel is not shadeable.
fn pixels(camera: &Camera, gbuffer: &GBuffer) -> Vec<Option<Pixel>> {
    let eye = camera.eye().as_dvec3();
    let [_, right, up] = camera.basis();
    let (w, h) = (gbuffer.width, gbuffer.height);
    let shadeable: Vec<bool> = gbuffer
        .hits
        .par_iter()
        .map(|hit| hit.as_ref().is_some_and(|hit| ShadingFrame::new(hit, eye).is_some()))
        .collect();
    let at = |x: usize, y: usize| gbuffer.hits[y * w + x].as_ref().filter(|_| shadeable[y * w + x]);
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let hit = gbuffer.hits[i].as_ref()?;
            let frame = ShadingFrame::new(hit, eye)?;
            // The curvature along one axis from the neighbours that are there (module docs).
            let axis = |a: Option<&crate::raster::Hit>, b: Option<&crate::raster::Hit>| {
                let (a, b) = (a.unwrap_or(hit), b.unwrap_or(hit));
                let dp = (a.position - b.position).length();
                if dp > 0.0 { (a.normal - b.normal).length() / dp } else { 0.0 }
            };
            let horizontal = axis((x > 0).then(|| at(x - 1, y)).flatten(), (x + 1 < w).then(|| at(x + 1, y)).flatten());
            let vertical = axis((y > 0).then(|| at(x, y - 1)).flatten(), (y + 1 < h).then(|| at(x, y + 1)).flatten());
            let n = frame.n;
            let projected = [n.dot(right), -n.dot(up)];
            let length = projected[0].hypot(projected[1]);
            let screen_normal = if length > 1e-9 { [projected[0] / length, projected[1] / length] } else { [0.0; 2] };
            let wo = (eye - hit.position).normalize();
            Some(Pixel {
                cos_o: frame.cos_o,
                mirror: 2.0 * frame.n.dot(wo) * frame.n - wo,
                depth: (eye - hit.position).length(),
                curvature: horizontal.max(vertical),
                screen_normal,
            })
        })
        .collect()
}

/// The shading frame of render pixel `i`, which [`pixels`] found shadeable, seen from `eye`.
fn shading_frame(gbuffer: &GBuffer, eye: DVec3, i: usize) -> ShadingFrame {
    gbuffer.hits[i].as_ref().and_then(|hit| ShadingFrame::new(hit, eye)).expect("a shadeable pixel has a shading frame")
}

/// The bandwidth buffer's entry of one pixel (module docs, "The bandwidth buffer").
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Prediction {
    /// Image-space bandwidth, cycles per pixel (eq. 5-6).
    pub bandwidth: f64,
    /// The variance bound (eq. 9, or eq. 10 for the pre-convolved estimator).
    pub variance: f64,
    /// The pyramid level the pixel may be shaded at (eq. 11); -1 when it is not shadeable.
    pub level: i32,
}

/// Where the bandwidth buffer is predicted: the render pixels predicted at (row-major order),
/// and for every render pixel the index in that list of the prediction it takes, `u32::MAX`
/// where it is not shadeable. With `l > 0` ([`Settings::prediction_level`]), one prediction per
/// `2^l x 2^l` block of render pixels, made at the block's pixel
/// ([`Level::pixel`]); a block whose pixel is not shadeable (at a silhouette, or over a hole) is
/// split into its four quarters, each predicted the same way, down to single pixels. So a
/// shadeable pixel takes the prediction of the largest block around it, of level at most `l`,
/// whose pixel is shadeable (itself at level 0), and that pixel takes its own.
pub fn prediction_pixels(shadeable: &[bool], (width, height): (usize, usize), l: usize) -> (Vec<u32>, Vec<u32>) {
    let source = |i: usize| -> Option<usize> {
        if !shadeable[i] {
            return None;
        }
        let (x, y) = (i % width, i / width);
        let block = (1..=l)
            .rev()
            .map(|k| block_pixel(k, x >> k, y >> k, width, height))
            .find(|&(bx, by)| shadeable[by * width + bx]);
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
    let hashed_seed = pcg_hash(settings.seed ^ 0x9e37_79b9);
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
        let f = merl::luminance(brdf(material, wi_local, shading.wo_local));
        let wi = shading.to_world(wi_local);
        // One map coordinate for the radiance and the bandwidth: the same texel grid.
        let (u, v) = envmap::uv(wi);
        let radiance = envmap::luminance(level0.lookup_uv(u, v).map(f64::from));
        let g = radiance * f * wi_local.z;
        let nu_env = bandwidths.environment.at_uv(u, v);
        let rho = f64::from(bandwidths.brdf.lookup(wi_local, shading.wo_local));
        let at_eye = bandwidth_at_eye(nu_env, rho, p.curvature, p.depth, shading.cos_o);
        weight += g / pdf;
        weighted += g / pdf * at_eye;
        variance += match settings.mode {
            Mode::Prefiltered => 2.0 * rho,
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

/// Eq. 11 with the Nyquist rate: `floor(log2(1 / (2 bandwidth)))` clamped to `[0, top]`.
pub fn level_of(bandwidth: f64, top: usize) -> i32 {
    if bandwidth.is_nan() || bandwidth <= 0.0 {
        return top as i32;
    }
    (1.0 / (2.0 * bandwidth)).log2().floor().clamp(0.0, top as f64) as i32
}

/// One level of the pyramid: `width x height` blocks of `2^level` pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub level: usize,
    pub width: usize,
    pub height: usize,
    /// The min pyramid: the least level of the block's pixels, -1 when one is not shadeable.
    pub min_level: Vec<i32>,
    /// The max pyramid of the predicted variance.
    pub max_variance: Vec<f64>,
}

impl Level {
    /// Whether block `b` may be shaded at this level or coarser (module docs).
    pub fn valid(&self, b: usize) -> bool {
        self.min_level[b] >= self.level as i32
    }

    /// The render pixel block `(bx, by)` is shaded with: `b 2^k + floor(2^k / 2)` per axis,
    /// clamped to the image.
    pub fn pixel(&self, bx: usize, by: usize, width: usize, height: usize) -> (usize, usize) {
        block_pixel(self.level, bx, by, width, height)
    }
}

/// The render pixel block `(bx, by)` of level `level` stands for: `b 2^k + floor(2^k / 2)` per
/// axis, clamped to the `width x height` image.
fn block_pixel(level: usize, bx: usize, by: usize, width: usize, height: usize) -> (usize, usize) {
    let (size, half) = (1usize << level, (1usize << level) / 2);
    ((bx * size + half).min(width - 1), (by * size + half).min(height - 1))
}

/// The min and max pyramids of a bandwidth buffer of `width x height` pixels, levels `0..=top`.
pub fn pyramid(predictions: &[Prediction], width: usize, height: usize, top: usize) -> Vec<Level> {
    let mut levels = vec![Level {
        level: 0,
        width,
        height,
        min_level: predictions.iter().map(|p| p.level).collect(),
        max_variance: predictions.iter().map(|p| p.variance).collect(),
    }];
    for k in 1..=top {
        let child = &levels[k - 1];
        let (w, h) = (child.width.div_ceil(2), child.height.div_ceil(2));
        let mut min_level = vec![i32::MAX; w * h];
        let mut max_variance = vec![0.0f64; w * h];
        for cy in 0..child.height {
            for cx in 0..child.width {
                let (c, b) = (cy * child.width + cx, (cy / 2) * w + cx / 2);
                min_level[b] = min_level[b].min(child.min_level[c]);
                max_variance[b] = max_variance[b].max(child.max_variance[c]);
            }
        }
        levels.push(Level { level: k, width: w, height: h, min_level, max_variance });
    }
    levels
}

/// What happens to a block (module docs, "Coarse to fine").
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Not computed at this level (not valid).
    Skip,
    /// Shaded with this many samples; `rescued` when its parents' weights all vanished.
    Shade { samples: u32, rescued: bool },
    /// The weighted mean of `count` blocks of the next coarser level: `(index, weight)`, the
    /// weights summing to 1.
    Upsample { parents: [(u32, f32); 4], count: u8 },
}

/// The plan of a frame: every level's actions, fixed by the G-buffer before any shading.
#[derive(Clone, Debug)]
pub struct Plan {
    pub levels: Vec<Level>,
    pub actions: Vec<Vec<Action>>,
    /// The frame's budget of samples.
    pub budget: u64,
}

impl Plan {
    /// The blocks shaded at each level.
    pub fn shaded_per_level(&self) -> Vec<usize> {
        self.actions.iter().map(|a| a.iter().filter(|a| matches!(a, Action::Shade { .. })).count()).collect()
    }

    /// Checks that `other` is this plan to `f32` rounding: the same pyramid, every block the same
    /// action with the same parents and samples, the weights within `tolerance` of each other
    /// (`gpu::preview` plans in `f32`). Returns the largest weight difference, or the first
    /// difference in words.
    pub fn compare(&self, other: &Plan, tolerance: f32) -> Result<f32, String> {
        if self.levels != other.levels {
            return Err("the pyramids differ".into());
        }
        let mut worst = 0.0f32;
        for (k, (a, b)) in self.actions.iter().zip(&other.actions).enumerate() {
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                let same = match (x, y) {
                    (Action::Upsample { parents: p, count: m }, Action::Upsample { parents: q, count: n }) => {
                        worst = p.iter().zip(q).fold(worst, |w, (u, v)| w.max((u.1 - v.1).abs()));
                        m == n && p.iter().zip(q).all(|(u, v)| u.0 == v.0)
                    }
                    _ => x == y,
                };
                if !same {
                    return Err(format!("level {k} block {i}: {x:?} against {y:?}"));
                }
            }
        }
        if worst > tolerance {
            return Err(format!("up-sampling weights differ by {worst:e}"));
        }
        Ok(worst)
    }

    /// The samples the plan spends.
    pub fn samples(&self) -> u64 {
        self.actions
            .iter()
            .flatten()
            .map(|a| match a {
                Action::Shade { samples, .. } => u64::from(*samples),
                _ => 0,
            })
            .sum()
    }
}

/// The least weight a parent counts with (module docs, "Coarse to fine"): `2^-100`, far above
/// the underflow of `f32` (`2^-126`), so that a renderer weighting in `f32` counts the same
/// parents as this one in `f64`.
pub const MIN_WEIGHT: f64 = 7.888609052210118e-31;

/// The up-sampling weights of block `(bx, by)` of `child` from the valid blocks of `parent`
/// (module docs); `None` when they all vanish.
fn upsample_weights(
    child: &Level,
    parent: &Level,
    (bx, by): (usize, usize),
    pixels: &[Option<Pixel>],
    (width, height): (usize, usize),
    settings: &Settings,
    sharpness: Option<&[f64]>,
) -> Option<([(u32, f32); 4], u8)> {
    let (depth_sigma, rescue_below) = (settings.depth_sigma, settings.rescue_below);
    let (cx, cy) = child.pixel(bx, by, width, height);
    let me = pixels[cy * width + cx].as_ref()?;
    let spacing = (1usize << parent.level) as f64;
    let centre = |b: usize, level: usize| (b * (1 << level) + (1 << level) / 2) as f64 + 0.5;
    // Bilinear neighbours along one axis: (first parent, fraction towards the second).
    let axis = |b: usize, n: usize| -> (usize, f64) {
        if n == 1 {
            return (0, 0.0);
        }
        let offset = centre(0, parent.level);
        let t = ((centre(b, child.level) - offset) / spacing).clamp(0.0, (n - 1) as f64);
        let first = (t.floor() as usize).min(n - 2);
        (first, t - first as f64)
    };
    let (x0, fx) = axis(bx, parent.width);
    let (y0, fy) = axis(by, parent.height);
    let cos_x = me.cos_o.max(0.1);
    let mut out = [(0u32, 0f32); 4];
    let (mut count, mut total) = (0u8, 0.0f64);
    let mut weights = [0.0f64; 4];
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let alpha = (if dx == 0 { 1.0 - fx } else { fx }) * (if dy == 0 { 1.0 - fy } else { fy });
        let (px, py) = ((x0 + dx).min(parent.width - 1), (y0 + dy).min(parent.height - 1));
        let b = py * parent.width + px;
        if alpha <= 0.0 || !parent.valid(b) || out[..count as usize].iter().any(|(i, _)| *i as usize == b) {
            continue;
        }
        let (rx, ry) = parent.pixel(px, py, width, height);
        let Some(them) = pixels[ry * width + rx].as_ref() else { continue };
        let dz = (me.depth - them.depth) / (depth_sigma * me.depth);
        let g_z = (-0.5 * dz * dz).exp();
        let v = [
            (centre(px, parent.level) - centre(bx, child.level)) / spacing,
            (centre(py, parent.level) - centre(by, child.level)) / spacing,
        ];
        // A normal facing the eye has no screen direction: M is then the identity.
        let [nx, ny] = if me.screen_normal == [0.0; 2] { [1.0, 0.0] } else { me.screen_normal };
        let along = v[0] * nx + v[1] * ny;
        let across = -v[0] * ny + v[1] * nx;
        let g_a = (-(along * along / (cos_x * cos_x) + across * across)).exp();
        let g_lobe = sharpness.map_or(1.0, |rows| {
            let lambda = |p: &Pixel| rows[(((1.0 - p.cos_o) * rows.len() as f64) as usize).min(rows.len() - 1)];
            lobe_similarity(me.mirror, lambda(me), them.mirror, lambda(them))
        });
        let w = g_z * g_a * alpha * g_lobe;
        if w >= MIN_WEIGHT {
            out[count as usize] = (b as u32, 0.0);
            weights[count as usize] = w;
            total += w;
            count += 1;
        }
    }
    if count == 0 || total.is_nan() || total <= rescue_below {
        return None;
    }
    for j in 0..count as usize {
        out[j].1 = (weights[j] / total) as f32;
    }
    Some((out, count))
}

/// The plan of a frame (module docs): which blocks are shaded, with how many samples, and the
/// up-sampling weights of the others. `budget` samples in all.
pub(crate) fn plan(
    levels: Vec<Level>,
    pixels: &[Option<Pixel>],
    (width, height): (usize, usize),
    budget: u64,
    settings: &Settings,
    sharpness: Option<&[f64]>,
) -> Result<Plan, Error> {
    let top = levels.len() - 1;
    let mut actions: Vec<Vec<Action>> = Vec::with_capacity(levels.len());
    for k in (0..=top).rev() {
        let level = &levels[k];
        let row: Vec<Action> = (0..level.width * level.height)
            .into_par_iter()
            .map(|b| {
                if !level.valid(b) {
                    return Action::Skip;
                }
                let (bx, by) = (b % level.width, b / level.width);
                if k < top && levels[k + 1].valid((by / 2) * levels[k + 1].width + bx / 2) {
                    match upsample_weights(
                        level,
                        &levels[k + 1],
                        (bx, by),
                        pixels,
                        (width, height),
                        settings,
                        sharpness,
                    ) {
                        Some((parents, count)) => Action::Upsample { parents, count },
                        None => Action::Shade { samples: 0, rescued: true },
                    }
                } else {
                    Action::Shade { samples: 0, rescued: false }
                }
            })
            .collect();
        actions.push(row);
    }
    actions.reverse();
    allocate(&levels, &mut actions, budget, settings)?;
    Ok(Plan { levels, actions, budget })
}

/// Splits `budget` among blocks of the given variances: each at least 1 and at most `cap`, the
/// rest in proportion to the variance, what a capped block cannot take going to the others
/// (water filling). The shares sum to `min(budget, cap * n)`.
fn shares(variance: &[f64], budget: f64, cap: f64) -> Vec<f64> {
    let mut share = vec![1.0; variance.len()];
    let mut open: Vec<usize> = (0..variance.len()).collect();
    let mut spare = budget - variance.len() as f64;
    while spare > 0.0 && !open.is_empty() {
        let total: f64 = open.iter().map(|&i| variance[i]).sum();
        let portion = |i: usize| if total > 0.0 { spare * variance[i] / total } else { spare / open.len() as f64 };
        let full: Vec<usize> = open.iter().copied().filter(|&i| share[i] + portion(i) >= cap).collect();
        if full.is_empty() {
            for &i in &open {
                share[i] += portion(i);
            }
            break;
        }
        for &i in &full {
            spare -= cap - share[i];
            share[i] = cap;
        }
        open.retain(|&i| share[i] < cap);
    }
    share
}

/// Gives every shaded block its samples (module docs, "Samples").
fn allocate(levels: &[Level], actions: &mut [Vec<Action>], budget: u64, settings: &Settings) -> Result<(), Error> {
    // (level, block, variance)
    let shaded: Vec<(usize, usize, f64)> = actions
        .iter()
        .enumerate()
        .flat_map(|(k, row)| {
            row.iter()
                .enumerate()
                .filter(|(_, a)| matches!(a, Action::Shade { .. }))
                .map(move |(b, _)| (k, b, levels[k].max_variance[b]))
        })
        .collect();
    let blocks: Vec<(usize, f64)> = shaded.iter().map(|&(k, _, variance)| (k, variance)).collect();
    let samples = allocation(&blocks, budget, settings)?;
    for ((k, b, _), n) in shaded.into_iter().zip(samples) {
        if let Action::Shade { samples, .. } = &mut actions[k][b] {
            *samples = n;
        }
    }
    Ok(())
}

/// The samples of each shaded block (module docs, "Samples"), given as `(level, max variance)`
/// in the plan's order: by level, finest first, then by block index. `budget` samples in all.
/// A renderer that plans elsewhere (`gpu::preview`) allocates with this, or with
/// [`area_allocation`], so that its blocks get exactly the samples the CPU's plan gives them.
pub fn allocation(blocks: &[(usize, f64)], budget: u64, settings: &Settings) -> Result<Vec<u32>, Error> {
    let max_spp = settings.max_spp;
    if settings.allocation == Allocation::Area {
        let top = blocks.iter().map(|&(k, _)| k).max().unwrap_or(0);
        let mut counts = vec![0u64; top + 1];
        for &(k, _) in blocks {
            counts[k] += 1;
        }
        let per_level = area_allocation(&counts, budget, max_spp)?;
        // Each block's rank in its level, in the plan's order.
        let mut rank = vec![0u64; top + 1];
        return Ok(blocks
            .iter()
            .map(|&(k, _)| {
                let LevelSamples { samples, doubled } = per_level[k];
                rank[k] += 1;
                if rank[k] <= doubled { 2 * samples } else { samples }
            })
            .collect());
    }
    check_budget(blocks.len() as u64, budget)?;
    let weights: Vec<f64> = blocks
        .iter()
        .map(|&(k, variance)| match settings.allocation {
            Allocation::Variance => variance,
            Allocation::StdDev => ((1u64 << (2 * k)) as f64 * variance).sqrt(),
            Allocation::Area => unreachable!("allocated per level above"),
        })
        .collect();
    Ok(weighted_allocation(&weights, budget, max_spp))
}

/// A frame's budget must give every shaded block a sample.
pub fn check_budget(shaded: u64, budget: u64) -> Result<(), Error> {
    if shaded > budget {
        return Err(Error::Invalid(format!(
            "a budget of {budget} samples is less than one for each of the {shaded} shaded pixels: raise spp"
        )));
    }
    Ok(())
}

/// The samples of blocks of the given weights (module docs, "Samples"): the water-filled
/// shares, each rounded down to a power of two, then the rest handed out by doubling the blocks
/// furthest below their share, in order, while it fits.
fn weighted_allocation(weights: &[f64], budget: u64, max_spp: u32) -> Vec<u32> {
    let ideal = shares(weights, budget as f64, f64::from(max_spp));
    let floor_pow2 = |x: f64| -> u32 {
        let x = x.min(f64::from(max_spp)).max(1.0);
        1u32 << (x.log2().floor() as u32)
    };
    let mut samples: Vec<u32> = ideal.iter().map(|&x| floor_pow2(x)).collect();
    let mut left = budget - samples.iter().map(|&n| u64::from(n)).sum::<u64>();
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| {
        (ideal[b] / f64::from(samples[b])).total_cmp(&(ideal[a] / f64::from(samples[a]))).then(a.cmp(&b))
    });
    for i in order {
        if samples[i] < max_spp && u64::from(samples[i]) <= left {
            left -= u64::from(samples[i]);
            samples[i] *= 2;
        }
    }
    samples
}

/// The samples of one level's shaded blocks under [`Allocation::Area`]: the first `doubled`
/// blocks of the level, in the plan's order, get `2 samples`, the others `samples`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelSamples {
    pub samples: u32,
    pub doubled: u64,
}

/// [`Allocation::Area`]'s samples from the count of shaded blocks per level alone (level 0
/// first), in exact integer arithmetic: every block of a level has the same weight `2^k`, so the
/// same share, the same power of two below it, and the blocks that double are the first of
/// their level that fit (module docs, "Samples"). The water filling: a level is full when
/// `1 + spare 2^k / W >= max_spp` (`W` the open levels' `sum n_k 2^k`), that is when
/// `spare 2^k >= (max_spp - 1) W`; full levels take `max_spp` and leave the rest to the others
/// until none is full; a level's samples are then the largest power of two `2^m <= max_spp`
/// with `2^m W <= W + spare 2^k`, and the levels below their share double, furthest below
/// first (the least level first among equals), while their samples fit what is left.
/// `gpu::preview` computes the same in `preview_adaptive.wgsl`'s `adaptive_allocate`, with
/// 64-bit sums of shifts for the products (every factor but the counts a power of two).
/// `max_spp` is a power of two ([`check_settings`]).
pub fn area_allocation(counts: &[u64], budget: u64, max_spp: u32) -> Result<Vec<LevelSamples>, Error> {
    debug_assert!(max_spp.is_power_of_two());
    check_budget(counts.iter().sum(), budget)?;
    let cap = u128::from(max_spp);
    let weight = |k: usize| u128::from(counts[k]) << k;
    let mut capped = vec![false; counts.len()];
    let open = |capped: &[bool]| -> Vec<usize> { (0..counts.len()).filter(|&k| counts[k] > 0 && !capped[k]).collect() };
    let mut spare = u128::from(budget - counts.iter().sum::<u64>());
    // The last round's spare and W, where it shared among open levels.
    let mut shared = None;
    loop {
        let open = open(&capped);
        let total: u128 = open.iter().map(|&k| weight(k)).sum();
        if spare == 0 || total == 0 {
            break;
        }
        let full: Vec<usize> = open.into_iter().filter(|&k| spare << k >= (cap - 1) * total).collect();
        if full.is_empty() {
            shared = Some((spare, total));
            break;
        }
        for k in full {
            spare -= u128::from(counts[k]) * (cap - 1);
            capped[k] = true;
        }
    }
    // Each level's ideal share as a fraction, and its power of two.
    let ideal = |k: usize| -> (u128, u128) {
        match shared {
            _ if capped[k] => (cap, 1),
            Some((spare, total)) => (total + (spare << k), total),
            None => (1, 1),
        }
    };
    let mut levels: Vec<LevelSamples> = (0..counts.len())
        .map(|k| {
            let (num, den) = ideal(k);
            let mut samples = 1u128;
            while 2 * samples <= cap && 2 * samples * den <= num {
                samples *= 2;
            }
            LevelSamples { samples: samples as u32, doubled: 0 }
        })
        .collect();
    let mut left = budget - (0..counts.len()).map(|k| counts[k] * u64::from(levels[k].samples)).sum::<u64>();
    // Furthest below the share first: ideal / samples descending, the lesser level first.
    let mut order: Vec<usize> = (0..counts.len()).filter(|&k| counts[k] > 0).collect();
    let below = |k: usize| {
        let (num, den) = ideal(k);
        (num, den * u128::from(levels[k].samples))
    };
    order.sort_by(|&a, &b| {
        let ((na, da), (nb, db)) = (below(a), below(b));
        (nb * da).cmp(&(na * db)).then(a.cmp(&b))
    });
    for k in order {
        let samples = u64::from(levels[k].samples);
        if levels[k].samples < max_spp {
            let doubled = counts[k].min(left / samples);
            left -= doubled * samples;
            levels[k].doubled = doubled;
        }
    }
    Ok(levels)
}

/// The inner product of two normalized spherical Gaussians `exp(lambda (xi . w - 1))` (`003`
/// eq. 4): 1 for equal lobes, towards 0 as their axes part relative to their widths.
/// `4 sqrt(a_i a_j) sinh(d) / (exp(lambda_i + lambda_j) d)`, `d = |lambda_i xi_i + lambda_j
/// xi_j|`, `a = lambda / (1 - exp(-4 lambda))`, evaluated as `exp(d - l_i - l_j)` terms so
/// that sharp lobes do not overflow.
pub fn lobe_similarity(xi_i: DVec3, lambda_i: f64, xi_j: DVec3, lambda_j: f64) -> f64 {
    let alpha = |l: f64| if l < 1e-9 { 0.25 } else { l / -(-4.0 * l).exp_m1() };
    let sum = lambda_i + lambda_j;
    let d = (lambda_i * xi_i + lambda_j * xi_j).length();
    let sinh_over = if d < 1e-9 { (-sum).exp() } else { ((d - sum).exp() - (-d - sum).exp()) / (2.0 * d) };
    4.0 * (alpha(lambda_i) * alpha(lambda_j)).sqrt() * sinh_over
}

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

/// The checks [`render`] makes on its settings, and the settings a frame of `material` runs
/// with: these with [`Settings::max_spp`] lowered to the block cap ([`Settings::block_cap`]).
/// Both renderers take their frame's settings from here.
pub fn check_settings(settings: &Settings, material: &Material, lighting: &Lighting) -> Result<Settings, Error> {
    if !matches!(settings.mode, Mode::Reference | Mode::Prefiltered) {
        return Err(Error::Invalid(format!(
            "adaptive shading uses the reference or the prefiltered estimator, not {}",
            settings.mode.name()
        )));
    }
    if !settings.max_spp.is_power_of_two() {
        return Err(Error::Invalid(format!("max_spp {} must be a power of two", settings.max_spp)));
    }
    // A block's samples are read a vector's worth (at most) at a time: the chunks' check.
    let n_samples = material.samples.n_samples;
    let per_frame = settings.max_spp.min(u32::try_from(n_samples).unwrap_or(u32::MAX));
    let base = crate::Settings { mode: settings.mode, spp: per_frame, frames: 1, seed: settings.seed };
    crate::check_settings(&base, n_samples, lighting.layers.len(), &material.view_layers)?;
    if settings.spp == 0 || settings.n_b == 0 || !matches!(settings.supersample, 1 | 2 | 4) {
        return Err(Error::Invalid(format!(
            "spp {} and n_b {} must be at least 1 and supersample ({}) 1, 2 or 4",
            settings.spp, settings.n_b, settings.supersample
        )));
    }
    if settings.lobe_weight
        && (material.view_layers.is_empty()
            || material.view_layers.iter().any(|&l| !(l >= 0.0 && (l as usize) < lighting.exponents.len())))
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
    let (ss, (output_width, output_height)) = (geometry.supersample, geometry.size);
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
    }
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

    // Shading does not depend on up-sampling: every shaded block at once, then coarse to fine.
    // A block's samples come a vector's worth at most per frame (module docs, "Shading").
    let n_samples = material.samples.n_samples as u32;
    let mut shaded: Vec<(u32, u32)> = Vec::new();
    let mut slot: Vec<Vec<u32>> = vec![Vec::new(); top + 1];
    for (k, actions) in plan.actions.iter().enumerate() {
        let level = &plan.levels[k];
        slot[k] = actions
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
            .collect();
    }
    let estimates = match shader {
        Some(shader) => shader(&shaded)?,
        None => shaded
            .par_iter()
            .map(|&(pixel, samples)| {
                let local = shading_frame(gbuffer, frame.eye, pixel as usize);
                let spp = samples.min(n_samples);
                let shading = crate::Settings { mode: settings.mode, spp, frames: samples / spp, seed: settings.seed };
                shade(&local, pixel, material, lighting, &shading, settings.layer_shift).map(|v| v as f32)
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
    let mut values: Vec<Vec<[f32; 3]>> = vec![Vec::new(); top + 1];
    for k in (0..=top).rev() {
        let coarser = if k < top { &values[k + 1] } else { &Vec::new() };
        values[k] = plan.actions[k]
            .par_iter()
            .enumerate()
            .map(|(b, action)| match *action {
                Action::Skip => [0.0; 3],
                Action::Shade { .. } => estimates[slot[k][b] as usize],
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

    let (level0, rays) = (lighting.mips.level(0), geometry.camera.rays(width, height));
    let render_rgb: Vec<[f32; 3]> = (0..width * height)
        .into_par_iter()
        .map(|i| match (&gbuffer.hits[i], &pixels[i]) {
            (None, _) => background(&rays, level0, i % width, i / width).map(|v| v as f32),
            (Some(_), None) => [0.0; 3],
            (Some(_), Some(_)) => values[0][i],
        })
        .collect();
    let image = downsample(&render_rgb, geometry.covered.clone(), output_width, output_height, ss);
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

/// Per output pixel: whether a triangle covers any of its `ss x ss` render pixels.
fn output_coverage(gbuffer: &GBuffer, width: usize, height: usize, ss: usize) -> Vec<bool> {
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

#[cfg(test)]
mod tests {
    use super::{
        Action, Allocation, Level, LevelSamples, Pixel, Settings, allocate, allocation, area_allocation,
        lobe_similarity, pixels, shares, upsample_weights, weighted_allocation,
    };
    use crate::Mode;
    use crate::shade::visibility;
    use crate::{Camera, Mesh, Scene};
    use glam::DVec3;

    #[test]
    fn the_curvature_of_a_sphere_is_one_over_its_radius() {
        // Interpolated vertex normals of a finely tessellated sphere: the median over the
        // pixels is within 2% of 1 / R (the tessellation's flat spans and the one-sided
        // differences at the silhouette are the rest).
        for radius in [1.0f32, 0.5] {
            let scene =
                Scene { mesh: Mesh::sphere(radius, 256, 128), camera: Camera::default(), width: 96, height: 96 };
            let gbuffer = visibility(&scene).unwrap();
            let mut curvature: Vec<f64> =
                pixels(&scene.camera, &gbuffer).iter().flatten().map(|p| p.curvature).collect();
            curvature.sort_by(f64::total_cmp);
            let median = curvature[curvature.len() / 2];
            let expect = 1.0 / f64::from(radius);
            assert!((median / expect - 1.0).abs() < 0.02, "radius {radius}: median curvature {median}");
        }
    }

    #[test]
    fn the_lobe_similarity_is_a_normalized_inner_product() {
        let z = DVec3::Z;
        for lambda in [0.0, 0.5, 4.0, 100.0, 4096.0] {
            assert!((lobe_similarity(z, lambda, z, lambda) - 1.0).abs() < 1e-9, "lambda {lambda}");
        }
        let tilted = DVec3::new(0.2f64.sin(), 0.0, 0.2f64.cos());
        let mut previous = 1.0;
        for lambda in [1.0, 10.0, 100.0, 1000.0] {
            let w = lobe_similarity(z, lambda, tilted, lambda);
            assert!(w > 0.0 && w < previous, "lambda {lambda}: {w} (sharper lobes 0.2 rad apart are less alike)");
            // Symmetric, and at most 1 (Cauchy-Schwarz) for different sharpness too.
            assert!((w - lobe_similarity(tilted, lambda, z, lambda)).abs() < 1e-12);
            assert!(lobe_similarity(z, lambda, tilted, 3.0 * lambda) <= 1.0);
            previous = w;
        }
        // Equal sharp lobes at an angle a: d = 2 lambda cos(a / 2) and sinh(d) ~ exp(d) / 2, so
        // the weight is exp(2 lambda (cos(a / 2) - 1)) / cos(a / 2) (~ exp(-lambda a^2 / 4)).
        let (lambda, a) = (1000.0f64, 0.2f64);
        let expect = (2.0 * lambda * ((a / 2.0).cos() - 1.0)).exp() / (a / 2.0).cos();
        let w = lobe_similarity(z, lambda, tilted, lambda);
        assert!((w / expect - 1.0).abs() < 1e-9, "{w} vs {expect}");
    }

    #[test]
    fn a_coarse_block_gets_samples_for_the_pixels_it_stands_for() {
        // One shaded block at level 0 and one at level 2 (16 pixels), the same variance; 10
        // samples. Variance: equal ideal shares, 5 and 5, rounded to 4 and 4. StdDev and Area:
        // weights 1 and sqrt(16) = 4, ideal shares 1 + 8 / 5 = 2.6 and 1 + 32 / 5 = 7.4, rounded
        // to 2 and 4, and the 4 left double the block furthest below its share (7.4 / 4): 2 and 8.
        let level = |k: usize, variance: f64| Level {
            level: k,
            width: 1,
            height: 1,
            min_level: vec![k as i32],
            max_variance: vec![variance],
        };
        for (allocation, variance_2, expect) in [
            (Allocation::Variance, 3.0, [4, 4]),
            (Allocation::StdDev, 3.0, [2, 8]),
            (Allocation::Area, 3.0, [2, 8]),
            // StdDev follows the variance too; Area does not: sqrt(16 * 3 / 48) = 1.
            (Allocation::StdDev, 3.0 / 16.0, [4, 4]),
            (Allocation::Area, 3.0 / 16.0, [2, 8]),
        ] {
            let levels = [level(0, 3.0), level(1, 0.0), level(2, variance_2)];
            let shade = Action::Shade { samples: 0, rescued: false };
            let mut actions = vec![vec![shade], vec![Action::Skip], vec![shade]];
            let settings = Settings { allocation, ..Settings::new(Mode::Reference, 1) };
            allocate(&levels, &mut actions, 10, &settings).unwrap();
            let got = [0, 2].map(|k| match actions[k][0] {
                Action::Shade { samples, .. } => samples,
                _ => unreachable!(),
            });
            assert_eq!(got, expect, "{} with variances 3 and {variance_2}", allocation.name());
        }
    }

    #[test]
    fn the_area_allocation_per_level_is_the_water_filling_of_every_block() {
        // Independent reference: `weighted_allocation` over every block with the weight 2^k, in
        // f64, against `allocation`'s Area path (per level, in integers); random levels, counts,
        // budgets (at most 300 samples per block) and caps, with empty levels and budgets at
        // exactly one sample per block among them.
        let mut state = 7u32;
        let mut next = |n: u32| {
            state = crate::pcg_hash(state);
            state % n
        };
        let (mut doubled, mut capped) = (0, 0);
        for case in 0..2000 {
            let levels = 1 + next(7) as usize;
            let counts: Vec<u64> = (0..levels).map(|_| u64::from(next(4).min(1) * next(40))).collect();
            let n: u64 = counts.iter().sum();
            if n == 0 {
                continue;
            }
            let budget = if case % 10 == 0 { n } else { n + u64::from(next(300)) * n / u64::from(1 + next(8)) };
            let max_spp = 1 << next(9);
            let blocks: Vec<(usize, f64)> =
                counts.iter().enumerate().flat_map(|(k, &c)| (0..c).map(move |_| (k, 0.0))).collect();
            let weights: Vec<f64> = blocks.iter().map(|&(k, _)| (1u64 << k) as f64).collect();
            let expect = weighted_allocation(&weights, budget, max_spp);
            let settings = Settings { allocation: Allocation::Area, max_spp, ..Settings::new(Mode::Reference, 1) };
            let got = allocation(&blocks, budget, &settings).unwrap();
            assert_eq!(got, expect, "counts {counts:?}, budget {budget}, max_spp {max_spp}");
            assert!(got.iter().map(|&s| u64::from(s)).sum::<u64>() <= budget);
            let per_level = area_allocation(&counts, budget, max_spp).unwrap();
            doubled += usize::from(per_level.iter().any(|l| l.doubled > 0));
            capped += usize::from(per_level.iter().any(|l| l.samples == max_spp && max_spp > 1));
        }
        // The cases reach both the doubling and the cap.
        assert!(doubled > 500 && capped > 100, "{doubled} cases doubled, {capped} capped");
        // Levels 0 and 2 tie (ideal over samples 3 / 2: shares 1.5, 2, 3 of 13 samples, W = 14,
        // spare 7): the lesser level doubles first, both its blocks, and the 1 sample left
        // doubles neither of level 2's (taking level 2 first would double one of each).
        let tie = area_allocation(&[2, 2, 2], 13, 8).unwrap();
        let expect = [(1, 2), (2, 0), (2, 0)].map(|(samples, doubled)| LevelSamples { samples, doubled });
        assert_eq!(tie, expect);
        let weights = [1.0, 1.0, 2.0, 2.0, 4.0, 4.0];
        assert_eq!(weighted_allocation(&weights, 13, 8), [2, 2, 2, 2, 2, 2]);
        // A budget below a sample per block is the same error either way.
        let error = area_allocation(&[3, 1], 3, 4).unwrap_err().to_string();
        assert!(error.contains("less than one for each of the 4 shaded"), "{error}");
    }

    #[test]
    fn a_parent_weighted_below_the_least_weight_does_not_count() {
        // A 2 x 1 child level under a 1 x 1 parent: the child block (0, 0) up-samples from the
        // one parent with g_z = exp(-dz^2 / 2), dz = depth difference / (sigma depth). At a
        // difference of 0.25 (dz 12.5: g_z about 1e-34, below 2^-100 though f64 holds it) the
        // parent does not count and the block is rescued; at 0.2 (dz 10: g_z about 2e-22) it
        // counts, with weight 1.
        let pixel = |depth: f64| Pixel { cos_o: 1.0, depth, curvature: 0.0, screen_normal: [0.0; 2], mirror: DVec3::Z };
        let level = |k: usize, width: usize| Level {
            level: k,
            width,
            height: 1,
            min_level: vec![1; width],
            max_variance: vec![0.0; width],
        };
        let (child, parent) = (level(0, 2), level(1, 1));
        let settings = Settings::new(Mode::Reference, 1);
        for (difference, counts) in [(0.25, false), (0.2, true)] {
            // The child block's pixel is (0, 0); the parent's is (1, 0).
            let pixels = [Some(pixel(1.0)), Some(pixel(1.0 + difference))];
            let weights = upsample_weights(&child, &parent, (0, 0), &pixels, (2, 1), &settings, None);
            assert_eq!(weights.is_some(), counts, "depth difference {difference}");
            if let Some((parents, count)) = weights {
                assert_eq!((count, parents[0]), (1, (0, 1.0)));
            }
        }
    }

    #[test]
    fn water_filling_respects_the_budget_the_cap_and_the_proportions() {
        let weights = [0.0, 1.0, 2.0, 4.0, 100.0, 0.5];
        for (budget, cap) in [(6.0, 256.0), (50.0, 256.0), (50.0, 16.0), (1000.0, 16.0), (10_000.0, 1e9)] {
            let s = shares(&weights, budget, cap);
            let total: f64 = s.iter().sum();
            assert!((total - f64::min(budget, cap * weights.len() as f64)).abs() < 1e-9, "{budget} {cap}: {s:?}");
            assert!(s.iter().all(|&x| (1.0..=cap + 1e-9).contains(&x)), "{budget} {cap}: {s:?}");
            // Below the cap, every share is 1 plus the same multiple of its weight.
            let open: Vec<usize> = (0..weights.len()).filter(|&i| s[i] < cap - 1e-9 && weights[i] > 0.0).collect();
            for pair in open.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let (ra, rb) = ((s[a] - 1.0) / weights[a], (s[b] - 1.0) / weights[b]);
                assert!((ra - rb).abs() <= 1e-9 * ra.max(rb), "{budget} {cap}: {s:?}");
            }
        }
        // No variance anywhere: equal shares.
        assert_eq!(shares(&[0.0; 4], 40.0, 256.0), vec![10.0; 4]);
    }
}
