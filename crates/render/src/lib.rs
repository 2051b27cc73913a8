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
//! interpolation): `wo = normalize(eye - p)`, `cos_o = n . wo`. A pixel whose normal interpolates
//! to zero is black. Where `cos_o <` [`COS_O_MIN`] (`1e-4`, Filament's `MIN_N_DOT_V`) the
//! interpolated normal turns away from the eye, or nearly: at a silhouette, the pixel centre falls
//! on a triangle whose vertex normals lie beyond it. Such a normal is bent towards the eye, as
//! engines do: rotated in the plane of `n` and `wo` until `n . wo = COS_O_MIN`, `n = COS_O_MIN wo +
//! sqrt(1 - COS_O_MIN^2) p` with `p` the part of `n` across `wo`, normalized (where `n = -wo`, Duff
//! et al.'s first tangent for `wo`, below), and `cos_o = n . wo` computed again. Every estimator,
//! the converged one included, shades the bent frame, so the silhouette has no black pixels and the
//! estimators still agree there. Then `t = wo - cos_o n`; if `|t| < 1e-6` (`wo` along the normal)
//! `t` is the first tangent of the branchless basis of Duff et al. 2017 for `n`
//! (`s = copysign(1, n.z)`, `a = -1 / (s + n.z)`, `t = (1 + s n.x^2 a, s n.x n.y a, -s n.x)`),
//! else `t / |t|`; `b = n x t`. In this frame `wo` is
//! `wo_local = (|wo - cos_o n|, 0, cos_o)` (normalized), the frame of the baked samples (`phi_o =
//! 0`), and a local direction `(x, y, z)` is `x t + y b + z n` in world space.
//!
//! # Samples ([`SampleSet`], [`sample_range`], [`pixel_sequences`])
//!
//! The bake's importance tables come in `S` slices (slice `k` for `theta_o = k / S * pi / 2`):
//! per slice a piecewise-constant distribution over the half vector, MERL's `theta_h` rows by
//! sectors of `phi_h`, uniform in the solid angle of `h` within a cell (`importance`'s crate
//! docs), held as the asset's `f32` CDF tables and sampled as stored
//! (`sampling::Distribution2D::from_cdfs`, [`SampleSet::tables`]; `data-schema/README.md`, kind
//! 2). A pixel uses the slice nearest its `theta_o = atan2(wo_local.x, wo_local.z)`:
//! `k = min(floor(theta_o / (pi / 2) * S + 1/2), S - 1)`.
//!
//! Every pixel draws its own directions. Pixel `i = y * width + x` has two Owen-scrambled Sobol'
//! (0,2)-sequences ([`pixel_sequences`]: `sampling::OwenSobol2D` scrambled by words of
//! [`pcg_hash`], Jarzynski and Olano 2020, `w0 = pcg_hash(i ^ pcg_hash(seed ^ 0x6a09e667))`,
//! each next word the hash of the one before; wrapping `u32` arithmetic, so both renderers draw
//! the same points), one for the BRDF's directions and one for the light's. A point is read as the
//! top 24 bits of each coordinate ([`point`]: exact in `f32`), and the slice's table maps it to a
//! direction and its density (`importance::Slice::sample`: `u1` picks the row through the
//! marginal CDF, `u0` the sector through that row's conditional, linear within both).
//!
//! Which points: with `spp` samples per pixel and frame (a power of two dividing the bake's `N`
//! samples per vector), the first `V N` points of a sequence hold `C = V N / spp` chunks of `spp`
//! consecutive points, chunk `c` starting at point `c spp` (as vector `c / (N / spp)`, sample
//! `(c % (N / spp)) spp` of the bake's layout: [`sample_range`]). The pixel draws one more word
//! `h = pcg_hash(i ^ pcg_hash(seed))` and in frame `f` takes chunk `c = (h % C + f % C) % C`: the
//! frames walk through its points from a random start, each chunk once per `C` frames, and every
//! aligned chunk of a power-of-two length is itself stratified (a (0, m, 2)-net).
//!
//! Why each pixel has its own points. The papers' renderer reads precomputed vectors of samples
//! (`001` section 3.3), the same for every pixel of a slice: after `C` frames every pixel of the
//! slice has averaged the same `V N` directions, so it shares their Monte Carlo error, which under
//! a sun is whether those few directions happen to hit it. That error is constant along the
//! circles of equal `theta_o`, and a sphere shows rings. Rotating a pixel's baked directions about
//! the normal by a random azimuth does not help: a view's lobe depends on `phi_i - phi_o`, so
//! rotating `wi` with `wo` fixed moves the samples out of the lobe, another distribution (the same
//! one only for `wo = n`). What keeps the distribution: nested uniform scrambling makes every
//! point of a scrambled sequence uniform on `[0, 1)^2` whatever the scramble (Owen 1995), so the
//! table maps each pixel's points to directions of exactly the table's density, and the density
//! the estimators divide by is that of the direction drawn: unbiased, pixel by pixel. Pixels
//! with unrelated scrambles have unrelated errors, so the error carries no structure from pixel
//! to pixel. The scrambles come from a hash rather than independent draws; the tests hold one
//! point of many pixels to the table's density by chi-square and measure the correlation of
//! neighbouring pixels' errors. The bake's own sample texels ([`SampleSet::texels`], the
//! papers' vectors) stay in the asset: the adaptive prediction reads one vector's first samples
//! (module [`adaptive`]), and `merl-importance` shows them. The price is a table lookup per
//! sample in place of a texel read: two binary searches, over 91 row edges and 129 sector edges.
//!
//! # The estimators ([`Estimator`])
//!
//! Every mode sums, per frame, over the pixel's `spp` points: point `n` gives one direction from
//! the BRDF's strategy (`wi_b` of density `p_b`, the slice's table) and, where the mode samples
//! a light, one from the light's (`wi_l` of density `p_l`, a `sampling::LatLong` of a map):
//!
//! ```text
//! L_o = 1 / spp * sum_n [ f(wi_b) cos_b (F(wi_b) / p_b + M(wi_b) / (p_b(wi_b) + p_l(wi_b)))
//!                         + f(wi_l) cos_l M(wi_l) / (p_b(wi_l) + p_l(wi_l)) ]
//! ```
//!
//! `F` is the light a filtered mode reads, `M` the light multiple importance sampling takes,
//! with the balance heuristic (each strategy's weight is its density over the sum of the two, one
//! direction of each per point). A direction with a density of 0 or
//! `wi_local.z <= 0` contributes 0, `f` is the BRDF at `(wi_local, wo_local)` and `cos =
//! wi_local.z`. `p_b` of a light's direction is the slice's table density at it
//! (`importance::Slice::pdf`, from the cell it falls in), `p_l` of a BRDF direction the light's
//! at its map coordinates (`sampling::LatLong::pdf`): both exact for every direction, so the
//! weights sum to 1 wherever either density is positive. The table's density is positive over
//! the whole upper hemisphere (its defensive share), so `M` is integrated without bias. The BRDF
//! is the table's nearest lookup (`merl::MerlTable::lookup` with `Interp::Nearest`, the lookup
//! the WGSL ports), 0 where the table holds no data; or, when the material carries a [`WaveletBrdfLod`],
//! its reconstruction at the wavelet's level of detail (`wavelet_brdf::Decoded::eval`: bilinear
//! over the 4 x 4 surrounding cell pairs of the sphere grid, Haar synthesis of each, in the log
//! domain; the WGSL `wavelet_brdf.wgsl` ports it). The modes differ in `F` and `M`:
//!
//! - [`Estimator::Reference`]: `F = 0`, `M` the environment's level 0, bilinear
//!   (`envmap::EnvMap::lookup`), `p_l` its importance sampling ([`Lighting::environment`]: texels
//!   by the luminance of their bilinear reconstruction times `sin theta`). Unbiased: it estimates
//!   `int f L cos` with level 0 as the renderers read it, the converged estimate's integral.
//! - [`Estimator::Fis`] (filtered importance sampling, `002`): `F` the mip chain of the environment's
//!   smooth part ([`Lighting::smooth_mips`]), trilinear at `lod = max(log4(w h / (N p_b 2 pi^2))
//!   + FIS_LOD_BIAS, 0)` (`envmap::MipChain::lod_solid_angle`, `w x h` the level-0 size: the
//!   level a footprint of solid angle `1 / (N p_b)` gets at the equator, wherever it lies;
//!   "Small bright sources" says why; [`FIS_LOD_BIAS`] says why a level finer than the
//!   footprint's); `N` the samples the picture averages, `spp` times the frames
//!   ([`Settings::filter_samples`]): the frames draw other points of the sample set, so each
//!   sample stands for `1 / N` of the integral, not `1 / spp`. A frame alone is then filtered
//!   for more samples than it holds, and only the average is free of aliasing. Sized by `spp`
//!   alone, the footprints of 8 frames of 16 samples were 1.5 levels wider, and the filter's
//!   bias showed: chrome's reflection of a dark wall brightened by its lit surroundings, 7x7
//!   bias p99 10.5 levels against Mitsuba 3 under the studio map, 4.6 sized by `N`; gold-paint
//!   2.3 to 0.4 under quarry (`cargo bench -p brdf-preview --bench mitsuba`). `M` the
//!   environment's peaks, `p_l` theirs ([`Peaks`]). The BRDF split as in the
//!   prefiltered mode (below): the diffuse part read from the cosine layer at the normal, the rest
//!   `f - f_d` in the `F` term.
//! - [`Estimator::Prefiltered`] (`001` section 2.5, "ASFPCS"), with the BRDF split in two: its
//!   diffuse part `f_d` ([`diffuse_split`]: the table's least value within 60 degrees of the
//!   normal, [`diffuse_part`],
//!   where the first layer is the cosine lobe `n = 1`; else 0) and the rest. The diffuse part's
//!   integral against the smooth part is a layer: `int f_d L_s cos = pi f_d L_1(n)`, `L_1` the
//!   cosine layer (`(1 / pi) max(0, w . n)`) read at the normal, added once per pixel and
//!   without noise. Read in the BRDF samples' directions instead, as the rest is, a broad
//!   layer blurs the light around each direction, and a diffuse lobe's directions reach the
//!   horizon: the light of the ground wrapped over a Lambertian sphere's lower half (9.5 levels
//!   of 8-bit bias). The rest, `f - f_d` in the `F` term (the `M` term keeps `f`): `F` the
//!   smooth part's Phong layers
//!   ([`Lighting::smooth_layers`]) blended at the sample's layer coordinate `x`: `(1 - t)` of
//!   layer `k` and `t` of layer `k + 1`, `k + t = x`, each bilinear, where layer `K` (one past
//!   the sharpest of `K`) is the smooth part's level 0 itself. `x` is the pixel's
//!   [`view_layer`]`(cos_o)` (the material's [`Material::view_layers`], one per row of the
//!   bandwidth atlas, interpolated between the rows' centres) `+ layer_shift`, at most `K`, and
//!   at most the sample's footprint's ([`PREFILTERED_FOOTPRINT_LAYERS`]: the lobe of solid
//!   angle `1 / (N p_b)`, one layer sharper). Blending by a coordinate that moves continuously
//!   with the view leaves no seam where the chosen layer changes. A mirror-like lobe (chrome,
//!   whose views measure 18 to 27 cycles per radian, twice that wanted, against the sharpest
//!   default layer's 13.4 at 512 x 256) reads level 0, which a 1024 x 512 map resolves to
//!   about 80; its tail's samples, rare and far from the mirror direction, read the broad
//!   layers of their footprint instead of sharp light, which left sparkles (chrome under
//!   `studio_small_03`: 7x7 bias max 3.47 levels with every sample at the sharpest layer, 1.47
//!   with both). An adaptive frame's shaded blocks read sharper layers
//!   (`adaptive::Settings::layer_shift`, module `adaptive`, "Shading"). `M` and `p_l` as fis.
//!
//! Where the environment has no peaks, the filtered modes take no light's directions (`M = 0`).
//! A frame's estimate is averaged over `frames` frames (`f = 0 .. frames`): the image converges
//! to the mode's expectation, the integral for the reference mode and the filtered
//! approximation for the others, as the frames grow.
//!
//! # Small bright sources ([`Lighting::peaks`])
//!
//! The filtered modes read light that is already averaged, fis over a mip texel the size of the
//! sample's footprint, prefiltered over a Phong lobe: the estimate is `int L (f cos * K)` for a
//! kernel `K`, a bias wherever the BRDF times the cosine changes within the kernel. Under a small
//! bright source it was large: the sun's light spread over a footprint reaches directions below a
//! surface's horizon and beyond a lobe (mean luminance -7% to +31% against the converged estimate
//! under quarry's sun, +64% in a band with the sun behind the sphere). So level 0 is split in two
//! ([`Peaks`]): a texel whose luminance `Y` exceeds [`PEAK_CONTRAST`] (1) times the map's mean
//! luminance (by solid angle) keeps `T / Y` of itself, `T` that threshold, and gives the rest to
//! the peaks. The peaks' light is integrated without a filter, by multiple importance sampling of
//! the BRDF's directions and the peaks' own importance sampling; the filters read the smooth rest,
//! the map clamped at its mean. Filtering is linear, so the smooth part's chain and layers are the
//! bake's minus the peaks' own (made with the code that made the bake's, `envmap::MipChain::new`
//! and `prefilter::prefilter`, once per map when the lighting is made). A lower contrast moves
//! more light into the unbiased part, with more noise at few samples; a higher one more into the
//! filter, whose bias shows on a narrow lobe: a studio's lit walls, below 4 times its mean,
//! blurred into chrome's reflection of the dark ones. Against the converged estimate (128 x 128,
//! brdf-preview's defaults, the Mitsuba bench's cases and cameras), 7x7 bias p99 of fis (with a
//! level-of-detail bias of 0) and prefiltered on chrome under `studio_small_03`, the light before
//! and behind the sphere:
//!
//! | contrast | fis | prefiltered | Lambertian / quarry / sun, prefiltered PSNR (sphere) |
//! |---:|---|---|---:|
//! | 4 | 4.45, 2.54 | 2.13, 4.98 | 46.30 dB |
//! | 2 | 2.77, 1.77 | 1.66, 2.73 | 45.92 dB |
//! | 1 | 1.70, 1.41 | 1.30, 1.58 | 45.50 dB |
//! | 0.5 | 1.13, 1.29 | 1.07, 1.15 | 44.61 dB |
//!
//! From 4 to 1, no other case's p99 grew by more than 0.07 levels, and gold-paint's under the
//! studio with the light behind fell from 0.94 to 0.56 (prefiltered); what a lower contrast
//! costs is noise under a sun, where a broad lobe takes ever more of the light by sampling. 1
//! keeps the Lambertian's prefiltered picture above 48 dB against Mitsuba 3.
//!
//! A second bias was fis's own on a lat-long chain: a footprint of a given solid angle covers ever
//! more of `u` towards the poles and no more of `v`, and a square level matched to its area there
//! blurs it along `v` by `1 / sqrt(sin theta)`. With the sun behind the sphere that mixed the
//! zenith with the bright sky around the sun, 3% too bright on gold-paint; the level a footprint
//! of that solid angle gets at the equator blurs too little along `u` instead (noise, not bias).
//!
//! What remains is the filters' bias on the smooth part: a gradient of soft light across a
//! footprint or a lobe. `cargo bench -p brdf-preview --bench mitsuba` measures every mode against
//! the converged estimate and Mitsuba 3.
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
//! ([`metrics::auto_tone_mapping`], `envmap::ToneMapping::auto`: its solid-angle-weighted log-average
//! luminance maps to 0.18, as on `envmap-prefilter`'s contact sheet); the difference picture is `|a - b|` of the 8-bit
//! values times 4, clamped.
//!
//! # The converged estimate ([`converged`])
//!
//! An estimator that shares nothing baked with the two renderers: multiple importance sampling
//! (balance heuristic, one sample from each strategy per round) of three strategies, none of which
//! reads the importance tables: the environment's level 0 ([`Lighting::environment`], made from
//! the map rather than baked; the reference mode samples it too), the cosine over the hemisphere,
//! and the half
//! vector drawn uniformly over the cells of the MERL grid (uniform in `sqrt(theta_h / (pi / 2))`
//! and `phi_h`: dense near the normal, where mirror-like tables keep their energy, whatever the
//! material). Same BRDF lookup, same visibility and frame, and the same `L` as
//! [`Estimator::Reference`] (level 0, bilinear) for every strategy, so it estimates exactly the
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
mod diffuse;
mod error;
mod lighting;
mod mesh;
mod shade;

pub use camera::{Camera, Rays};
pub use diffuse::{DIFFUSE_MIN_COS, diffuse_part, diffuse_split};
pub use error::Error;
pub use lighting::{Lighting, PEAK_CONTRAST, Peaks};
pub use mesh::Mesh;
pub use shade::{COS_O_MIN, Image, check_inputs, check_settings, render, render_with_progress};

use merl::MerlTable;
use sampling::OwenSobol2D;

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
    /// The tables the samples were drawn from, one per slice (the asset's `f32` CDFs as they are
    /// stored): the estimators draw each pixel's own directions from them (crate documentation,
    /// "Samples").
    pub tables: Vec<importance::Slice>,
}

impl SampleSet {
    /// The sample set of importance tables built in memory, as the renderers read it from their
    /// asset (`importance::Slice::as_stored`): what `bake::load` makes of the asset of `tables`.
    pub fn new(tables: &importance::ImportanceTables) -> SampleSet {
        let c = tables.config();
        SampleSet {
            n_slices: c.n_theta_o,
            n_vectors: c.n_vectors,
            n_samples: c.n_samples,
            texels: tables.sample_texels(),
            tables: tables.slices().iter().map(importance::Slice::as_stored).collect(),
        }
    }
}

/// A measured material with what a bake made of it.
#[derive(Clone, Debug)]
pub struct Material {
    pub table: MerlTable,
    pub samples: SampleSet,
    /// For [`Estimator::Prefiltered`]: where each of `R` view elevations, in equal steps of
    /// `cos theta_o`, falls among the Phong layers of [`Lighting::layers`], as a layer coordinate
    /// (`bandwidth_atlas::view::view_coordinates`: the layer of twice the view's bandwidth, `k + t`
    /// blending layer `k` and `k + 1` by `t`, up to the number of layers: the smooth map itself
    /// past the sharpest). Row
    /// `r` is for `1 - cos theta_o = (r + 1/2) / R`; a pixel interpolates the rows around it
    /// ([`view_layer`]).
    pub view_layers: Vec<f32>,
    /// The table's diffuse part `f_d` (1/sr per channel, [`diffuse_part`]), which the filtered
    /// modes ([`Estimator::Fis`], [`Estimator::Prefiltered`]) read from the cosine layer at the normal
    /// (crate documentation, "The estimators").
    pub diffuse: [f32; 3],
    /// When set, the renderers evaluate `f` from this wavelet encoding of the table instead of
    /// the table (`brdf-preview --brdf wavelet-brdf`): see "The BRDF" in the crate docs.
    pub wavelet_brdf: Option<WaveletBrdfLod>,
}

impl Material {
    /// The material of a table, its sample set and view layers, with the table's diffuse part
    /// ([`diffuse_part`]) and no wavelet encoding.
    pub fn new(table: MerlTable, samples: SampleSet, view_layers: Vec<f32>) -> Material {
        let diffuse = diffuse_part(&table);
        Material { table, samples, view_layers, diffuse, wavelet_brdf: None }
    }
}

/// A wavelet encoding of the material (asset kind `wavelet-brdf`, crate `wavelet_brdf`) and the
/// level of detail it is read at.
#[derive(Clone, Debug)]
pub struct WaveletBrdfLod {
    pub brdf: wavelet_brdf::Decoded,
    /// In `[0, log2 n]`: 0 is full resolution (`wavelet_brdf::Decoded::eval`).
    pub lod: f64,
}

/// Which estimator shades the covered pixels (see the crate documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Estimator {
    Reference,
    Fis,
    Prefiltered,
}

impl Estimator {
    pub const ALL: [Estimator; 3] = [Estimator::Reference, Estimator::Fis, Estimator::Prefiltered];

    /// The name on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Reference => "reference",
            Estimator::Fis => "fis",
            Estimator::Prefiltered => "prefiltered",
        }
    }
}

/// How many samples a render takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    pub estimator: Estimator,
    /// Samples per pixel and frame: a power of two that divides [`SampleSet::n_samples`].
    pub spp: u32,
    /// Frames averaged.
    pub frames: u32,
    /// Mixed into every pixel's random word; renders with different seeds are independent.
    pub seed: u32,
}

impl Settings {
    /// The previewer's settings for `estimator` where a user sets nothing: `spp` samples per pixel
    /// and frame (default 64 for the reference estimator, 16 for the filtered ones) and `frames` frames
    /// (default: for the reference estimator enough to use every point of a pixel's `V N` once,
    /// [`frames_to_exhaust`]; for the filtered estimators 8, which average prefiltered's noise, not
    /// its bias, and narrow fis's footprints, [`Settings::filter_samples`]). `spp` must not be 0
    /// where `frames` is left to the default of the reference estimator.
    pub fn previewer(
        estimator: Estimator,
        samples: &SampleSet,
        spp: Option<u32>,
        frames: Option<u32>,
        seed: u32,
    ) -> Settings {
        let spp = spp.unwrap_or(if estimator == Estimator::Reference { 64 } else { 16 });
        let frames = frames.unwrap_or_else(|| match estimator {
            Estimator::Reference => frames_to_exhaust(samples.n_vectors, samples.n_samples, spp),
            Estimator::Fis | Estimator::Prefiltered => 8,
        });
        Settings { estimator, spp, frames, seed }
    }

    /// The samples a picture averages, `spp` times `frames` (at most `u32::MAX`): the fis
    /// estimator sizes each sample's footprint for them (crate documentation, "The
    /// estimators"). The GPU renderer passes the same count.
    pub fn filter_samples(&self) -> u32 {
        self.spp.saturating_mul(self.frames)
    }
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

/// The Phong layer coordinate of a view with `cos theta_o = cos_o` among rows of layer coordinates
/// `view_layers` (see [`Material::view_layers`]): linear in `1 - cos theta_o` between the two
/// rows' centres around it, the first or last row's own beyond their centres. Continuous in the
/// view, so the layer blend leaves no seam where rows meet. `view_layers` must not be empty.
pub fn view_layer(view_layers: &[f32], cos_o: f64) -> f64 {
    let rows = view_layers.len();
    let s = ((1.0 - cos_o) * rows as f64 - 0.5).clamp(0.0, (rows - 1) as f64);
    let r = (s.floor() as usize).min(rows - 1);
    let t = s - r as f64;
    let a = f64::from(view_layers[r]);
    if t > 0.0 { a + (f64::from(view_layers[r + 1]) - a) * t } else { a }
}

/// The Phong exponent at layer coordinate `x` among layers of `exponents` (increasing): geometric
/// between the two layers it blends (`n_k^(1 - t) n_(k+1)^t`), as the lobes' widths are. Index
/// `exponents.len()` is the layer past the sharpest, the smooth map itself, which the
/// pre-filtered estimator reads where the sharpest layer is too broad (crate documentation, "The
/// estimators"); it stands at the exponents' last step continued ([`past_exponent`]). `x` is
/// clamped to `[0, exponents.len()]`; `exponents` must not be empty.
pub fn layer_exponent(exponents: &[u32], x: f32) -> f64 {
    let n = |k: usize| exponents.get(k).map_or_else(|| past_exponent(exponents), |&e| f64::from(e));
    let x = f64::from(x).clamp(0.0, exponents.len() as f64);
    let k = x.floor() as usize;
    let t = x - k as f64;
    if t > 0.0 { n(k).powf(1.0 - t) * n(k + 1).powf(t) } else { n(k) }
}

/// The exponent the layer past the sharpest stands at: the last one's times the last step's
/// ratio (4 between the default layers, as between every two of them), 4 times it where there
/// is one layer.
pub fn past_exponent(exponents: &[u32]) -> f64 {
    let last = f64::from(exponents[exponents.len() - 1]);
    let step = match exponents {
        [.., a, b] if *a > 0 => f64::from(*b) / f64::from(*a),
        _ => 4.0,
    };
    last * step
}

/// The layer coordinate of Phong exponent `n` among layers of `exponents` (increasing), the
/// inverse of [`layer_exponent`]: linear in `ln n` between the layers around it, 0 at or below
/// the broadest, `exponents.len()` (the smooth map itself) at or above [`past_exponent`].
pub fn exponent_layer(exponents: &[u32], n: f64) -> f64 {
    let past = past_exponent(exponents);
    // NaN (no footprint) reads the broadest layer.
    if n.is_nan() || n <= f64::from(exponents[0]) {
        return 0.0;
    }
    if n >= past {
        return exponents.len() as f64;
    }
    let e = |k: usize| exponents.get(k).map_or(past, |&e| f64::from(e));
    let k = exponents.partition_point(|&e| f64::from(e) <= n) - 1;
    k as f64 + (n.ln() - e(k).ln()) / (e(k + 1).ln() - e(k).ln())
}

/// Layers added to the pre-filtered estimator's footprint coordinate (crate documentation, "The
/// estimators"): a sample of density `p` among `N` reads at most the layer whose lobe is one
/// layer sharper than its footprint of solid angle `1 / (N p)`, as fis reads one mip level finer
/// ([`FIS_LOD_BIAS`]). Against Mitsuba 3 (the Mitsuba bench's cases, 128 x 128, brdf-preview's
/// defaults), chrome under `studio_small_03`, the only cases it moves by more than 0.05 levels:
/// 7x7 bias p99 / max 1.00 / 1.87 and 1.57 / 2.73 (light before and behind the sphere) without
/// the cap, 1.57 / 2.37 and 1.53 / 2.06 at 0 layers, 0.94 / 1.47 and 0.96 / 1.51 at 1.
pub const PREFILTERED_FOOTPRINT_LAYERS: f64 = 1.0;

/// The point sequences of pixel `pixel`: `[brdf, environment]`, Owen-scrambled Sobol' sequences
/// scrambled by words of [`pcg_hash`] (crate documentation, "Samples"), so both renderers draw
/// the same points and neighbouring pixels unrelated ones.
pub fn pixel_sequences(pixel: u32, seed: u32) -> [OwenSobol2D; 2] {
    let w0 = pcg_hash(pixel ^ pcg_hash(seed ^ SEQUENCE_SALT));
    let w1 = pcg_hash(w0);
    let w2 = pcg_hash(w1);
    let w3 = pcg_hash(w2);
    [OwenSobol2D::from_words([w0, w1]), OwenSobol2D::from_words([w2, w3])]
}

/// Levels added to fis's level of detail (crate documentation, "The estimators"): the footprint
/// of solid angle `1 / (N p_b)` is read one level finer than its size. A trilinear read's
/// bilinear tent at level `l` spans two texels of that level along each axis, twice the width of
/// the footprint that chose `l`; one level finer, its support is the footprint. What the wider
/// read costs is bias where the smooth light changes within it: against the converged estimate
/// (the Mitsuba bench's cases, 128 x 128, brdf-preview's defaults), chrome under
/// `studio_small_03` had a 7x7 bias p99 of 1.70 and 1.41 levels (light before and behind the
/// sphere) at 0, 0.92 and 1.01 at -1, for 0.1 and 1.6 dB more noise; no other case's p99 moved
/// by more than 0.05 levels. Colbert and Krivanek's +1 hides the aliasing of a few samples; the picture's
/// `N` is `spp` times the frames, 128 by default.
pub const FIS_LOD_BIAS: f64 = -1.0;

/// Mixed into the seed of [`pixel_sequences`], so that its words are not [`sample_range`]'s.
pub const SEQUENCE_SALT: u32 = 0x6a09_e667;

/// Point `index` of `sequence` as the renderers read it: the top 24 bits of each coordinate,
/// exact in `f32`, in `[0, 1 - 2^-24]`.
pub fn point(sequence: &OwenSobol2D, index: u32) -> [f64; 2] {
    sequence.point_bits(index).map(|bits| f64::from(bits >> 8) / 16_777_216.0)
}

/// The frames after which a pixel has used every sample of its slice once ([`sample_range`]):
/// `n_vectors * n_samples / spp`.
pub fn frames_to_exhaust(n_vectors: usize, n_samples: usize, spp: u32) -> u32 {
    (n_vectors * n_samples / spp as usize) as u32
}
