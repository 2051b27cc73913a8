//! The previewer's renderer, on the CPU: a triangle mesh under a distant environment, shaded with a
//! measured BRDF and the assets of a bake, by the estimators of the papers (`001` sections 2.5
//! and 3.3, `002`). It is the reference the GPU renderer (`gpu::preview`) is held to: both follow
//! this specification step for step, with the same samples, so that their images agree to
//! rounding and a difference measures a bug rather than noise. A second, independent estimator
//! ([`converged`]) uses no baked table at all, so a bug shared by the two renderers shows too.
//!
//! No IO: `bake::load` turns a bake folder into a [`Material`] and a [`Lighting`].
//!
//! # Conventions
//!
//! World space is the environment's: `+z` up, directions looked up in the lat-long maps with
//! `envmap`'s orientation (`envmap::geometry::uv`). `wi` and `wo` point away from the surface.
//! Radiance is linear RGB, in the environment map's units.
//!
//! # Visibility ([`raster`])
//!
//! The camera ([`Camera`]) gives one `f32` view-projection matrix (right-handed view, depth in
//! `[0, 1]` as wgpu wants it; near and far planes at `distance / 100` and `100 distance`) and the
//! eye position in `f32`. Pixel `(x, y)` (row 0 at the top) is covered by the triangle whose
//! coverage test passes at the pixel centre under the Vulkan rasterization rules: vertices
//! projected in `f32`, viewport coordinates snapped to 1/256 pixel (8 sub-pixel bits, as
//! lavapipe does; ties round to even), integer edge functions, the top-left fill rule, the nearest
//! depth winning (depth cleared to 1, compared as `f32` with "less": ties go to the first triangle
//! drawn). Both renderers then use the perspective-correct interpolation of the vertices' world
//! positions and normals at the pixel centre. Back faces are not culled. Triangles that cross the
//! near or far plane are clipped there; the [`raster`] module documentation has every step, the
//! clipping included (a clipper's rounding is the one place the two renderers may differ by more
//! than rounding; the default camera clips nothing within the unit sphere).
//!
//! # The shading frame
//!
//! At a covered pixel with interpolated position `p` and normal `n` (normalized after
//! interpolation): `wo = normalize(eye - p)`, `cos_o = n . wo`. If `cos_o <= 0` the pixel is black
//! (the interpolated normal faces away, at silhouettes), and so is a pixel whose normal
//! interpolates to zero. Otherwise `t = wo - cos_o n`; if `|t| < 1e-6` (`wo` along the normal)
//! `t` is the first tangent of the branchless basis of Duff et al. 2017 for `n`
//! (`s = copysign(1, n.z)`, `a = -1 / (s + n.z)`, `t = (1 + s n.x^2 a, s n.x n.y a, -s n.x)`),
//! else `t / |t|`; `b = n x t`. In this frame `wo` is
//! `wo_local = (|wo - cos_o n|, 0, cos_o)` (normalized), the frame of the baked samples (`phi_o =
//! 0`), and a local direction `(x, y, z)` is `x t + y b + z n` in world space.
//!
//! # Samples ([`SampleSet`], [`sample_range`])
//!
//! The baked importance samples come in `S` slices (slice `k` for `theta_o = k / S * pi / 2`), `V`
//! vectors per slice and `N` samples per vector, each `(wi_local, pdf)` with `pdf` per unit solid
//! angle (`data-schema/README.md`, kind 2). A pixel uses the slice nearest its `theta_o =
//! atan2(wo_local.x, wo_local.z)`: `k = min(floor(theta_o / (pi / 2) * S + 1/2), S - 1)`.
//!
//! With `spp` samples per pixel and frame (a power of two dividing `N`), a slice holds
//! `C = V N / spp` chunks of `spp` consecutive samples: chunk `c` is vector `c / (N / spp)`,
//! samples from `(c % (N / spp)) spp`. Pixel `i = y * width + x` draws one random word
//! `h = pcg_hash(i ^ pcg_hash(seed))` ([`pcg_hash`]: Jarzynski and Olano 2020, wrapping `u32`
//! arithmetic, so both renderers draw the same word; the seed is hashed so that neighbouring seeds
//! give unrelated words) and in frame `f` takes chunk `c = (h % C + f % C) % C`: the frames walk
//! through the slice's chunks from a random start, each chunk once per `C` frames. Each vector is
//! an Owen-scrambled Sobol' sequence, so every aligned block of a power-of-two length is itself
//! stratified (`001` section 3.3: "we read N_p samples randomly, from multiple pre-computed
//! vectors"). After `C` frames a pixel has used every baked sample of its slice exactly once: the
//! image is then the estimator's expectation over the sample choice, exactly, and more frames only
//! repeat it (a render that wants less noise than the bake's `V N` samples allow needs a bake
//! with more samples).
//!
//! # The estimators ([`Mode`])
//!
//! Every mode computes, per frame,
//!
//! ```text
//! L_o = 1 / spp * sum_j f(wi_j, wo) L(wi_j) cos(theta_j) / pdf_j
//! ```
//!
//! over the pixel's `spp` samples, where a sample with `pdf <= 0` or `wi_local.z <= 0`
//! contributes 0, `f` is the BRDF at `(wi_local, wo_local)` and `cos(theta_j) = wi_local.z`. The
//! BRDF is the table's nearest lookup (`merl::MerlTable::lookup` with `Interp::Nearest`, the
//! lookup the WGSL ports), 0 where the table holds no data; or, when the material carries a
//! [`Wavelet`], its reconstruction at the wavelet's level of detail
//! (`haar_brdf::WaveletBrdf::eval`: bilinear over the 4 x 4 surrounding cell pairs of the sphere
//! grid, Haar synthesis of each, in the log domain; the WGSL `brdf_wavelet.wgsl` ports it). The
//! modes differ in `L`:
//!
//! - [`Mode::Reference`]: the environment's level 0, bilinear (`envmap::EnvMap::lookup`).
//! - [`Mode::Fis`] (filtered importance sampling, `002`): the mip chain, trilinear
//!   (`envmap::MipChain::lookup`) at `lod = max(log4(w h / (spp p_uv)), 0)`, `w x h` the level-0
//!   size, `p_uv = pdf * envmap::geometry::uv_jacobian(v)` the sample's density over the map's
//!   unit square (`envmap::MipChain::lod`), `v` the world direction's map coordinate. No bias.
//! - [`Mode::Prefiltered`] (`001` section 2.5, "ASFPCS"): the Phong-lobe layer the material's
//!   [`Material::view_layers`] picks for the pixel's view direction, bilinear. Row
//!   `r = min(floor((1 - cos_o) * R), R - 1)` of the `R` entries (the rows of the bandwidth atlas,
//!   equal steps of `cos theta`). An adaptive frame's shaded blocks read a sharper layer
//!   (`adaptive::Settings::layer_shift`, module `adaptive`, "Shading").
//!
//! A frame's estimate is averaged over `frames` frames (`f = 0 .. frames`): the image converges to
//! the mode's expectation as frames grow. That expectation is over the choice of vector and chunk
//! only: with the bake fixed it is the mean over the slice's `V N` samples, which is off the
//! integral by the bake's own Monte Carlo error (it shrinks as `1 / sqrt(V N)`, not with frames).
//!
//! Pixels no triangle covers show the environment behind them: level 0, bilinear, in the
//! direction of the ray through the pixel centre ([`Camera::ray`]: built from the camera's basis in
//! `f64`, not by inverting the matrix), in every mode, so that a person can check the
//! environment's orientation.
//!
//! # Pictures and figures ([`metrics`])
//!
//! Linear radiance becomes 8-bit sRGB by `envmap::tonemap_rgb8` (exposure `2^ev`, Reinhard's
//! `x / (1 + x)` per channel, the sRGB transfer function). PSNR is taken on those 8-bit images
//! over all pixels and channels; the relative error is `|a - b| / |b|` (Euclidean norms over all
//! linear values). Every picture of a comparison shares one exposure, by default the environment's
//! ([`metrics::auto_preview`], `envmap::Preview::auto`: its solid-angle-weighted log-average
//! luminance maps to 0.18, as on `envmap-prefilter`'s contact sheet); the difference picture is `|a - b|` of the 8-bit
//! values times 4, clamped.
//!
//! # The converged estimate ([`converged`])
//!
//! An estimator that shares nothing baked with the two renderers: multiple importance sampling
//! (balance heuristic, one sample from each strategy per round) of three strategies, none of which
//! reads the importance tables: the environment's level 0 by its luminance times `sin theta`
//! (a `sampling::Distribution2D` over the texels), the cosine over the hemisphere, and the half
//! vector drawn uniformly over the cells of the MERL grid (uniform in `sqrt(theta_h / (pi / 2))`
//! and `phi_h`: dense near the normal, where mirror-like tables keep their energy, whatever the
//! material). Same BRDF lookup, same visibility and frame, and the same `L` as
//! [`Mode::Reference`] (level 0, bilinear) for every strategy, so it estimates exactly the
//! reference mode's expectation; the environment's density is evaluated exactly for every
//! direction, so reading `L` bilinearly costs no bias (the texel weights are the luminance of the
//! bilinear reconstruction averaged over each texel, which keeps that density positive wherever
//! the lookup is; the [`converged`] module documentation has the details). Many samples, drawn
//! from Owen-scrambled Sobol' sequences seeded per pixel: deterministic.

pub mod adaptive;
pub mod converged;
pub mod metrics;
pub mod raster;

mod camera;
mod error;
mod mesh;
mod shade;

pub use camera::{Camera, Rays};
pub use error::Error;
pub use mesh::Mesh;
pub use shade::{Image, check_inputs, check_settings, render};

use envmap::{EnvMap, MipChain};
use merl::MerlTable;

/// What the previewer looks at: one mesh, a camera and an image size.
#[derive(Clone, Debug)]
pub struct Scene {
    pub mesh: Mesh,
    pub camera: Camera,
    pub width: usize,
    pub height: usize,
}

/// The baked importance samples of a material (asset kind 2), as the renderers read them.
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSet {
    /// `S`: slice `k` is for `theta_o = k / S * pi / 2`.
    pub n_slices: usize,
    /// `V`.
    pub n_vectors: usize,
    /// `N`, a power of two.
    pub n_samples: usize,
    /// `S * V * N` texels `(wi.x, wi.y, wi.z, pdf)`, slice-major, then vector, then sample.
    pub texels: Vec<[f32; 4]>,
}

/// A measured material with what a bake made of it.
#[derive(Clone, Debug)]
pub struct Material {
    pub table: MerlTable,
    pub samples: SampleSet,
    /// For [`Mode::Prefiltered`]: the Phong layer (an index into [`Lighting::layers`]) for each
    /// of `R` view elevations in equal steps of `cos theta_o` (row `r` covers
    /// `1 - cos theta_o` in `[r / R, (r + 1) / R)`).
    pub view_layers: Vec<u32>,
    /// When set, the renderers evaluate `f` from this wavelet encoding of the table instead of
    /// the table (`brdf-preview --brdf wavelet`): see "The BRDF" in the crate docs.
    pub wavelet: Option<Wavelet>,
}

/// A wavelet encoding of the material (asset kind `wavelet-brdf`, crate `haar_brdf`) and the
/// level of detail it is read at.
#[derive(Clone, Debug)]
pub struct Wavelet {
    pub brdf: haar_brdf::WaveletBrdf,
    /// In `[0, log2 n]`: 0 is full resolution (`haar_brdf::WaveletBrdf::eval`).
    pub lod: f64,
}

/// A distant environment with what a bake made of it.
#[derive(Clone, Debug)]
pub struct Lighting {
    /// The environment's mip chain; level 0 is the map itself.
    pub mips: MipChain,
    /// The map convolved with normalized Phong lobes, one layer per exponent, all the same size.
    pub layers: Vec<EnvMap>,
    /// The exponent of each layer.
    pub exponents: Vec<u32>,
}

/// Which estimator shades the covered pixels (see the crate documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    Reference,
    Fis,
    Prefiltered,
}

impl Mode {
    pub const ALL: [Mode; 3] = [Mode::Reference, Mode::Fis, Mode::Prefiltered];

    /// The name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Reference => "reference",
            Mode::Fis => "fis",
            Mode::Prefiltered => "prefiltered",
        }
    }
}

/// How many samples a render takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    pub mode: Mode,
    /// Samples per pixel and frame: a power of two that divides [`SampleSet::n_samples`].
    pub spp: u32,
    /// Frames averaged.
    pub frames: u32,
    /// Mixed into every pixel's random word; renders with different seeds are independent.
    pub seed: u32,
}

/// The random word of the sample choice: Jarzynski and Olano's PCG hash ("Hash functions for GPU
/// rendering", JCGT 2020), wrapping `u32` arithmetic. The WGSL copy must match it bit for bit.
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The samples pixel `pixel` uses in frame `frame`: `(vector, first sample)` within its slice
/// (see the crate documentation). `spp` must be a power of two dividing `n_samples`, and
/// `n_vectors * n_samples / spp` must fit a `u32`.
pub fn sample_range(pixel: u32, frame: u32, seed: u32, n_vectors: u32, n_samples: u32, spp: u32) -> (u32, u32) {
    let per_vector = n_samples / spp;
    let chunks = n_vectors * per_vector;
    let h = pcg_hash(pixel ^ pcg_hash(seed));
    let chunk = (h % chunks + frame % chunks) % chunks;
    (chunk / per_vector, (chunk % per_vector) * spp)
}

/// The frames after which a pixel has used every sample of its slice once ([`sample_range`]):
/// `n_vectors * n_samples / spp`.
pub fn frames_to_exhaust(n_vectors: usize, n_samples: usize, spp: u32) -> u32 {
    (n_vectors * n_samples / spp as usize) as u32
}
