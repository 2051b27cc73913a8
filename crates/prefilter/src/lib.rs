//! Prefiltered environment maps for real-time shading of measured materials (Bagher et al.
//! 2013, sections 2.5 and 4.3: "pre-convolve the environment map with Phong lobes of various
//! exponents and assemble them into an array of textures"): for each exponent `n`, the map
//! convolved with the normalized Phong lobe around every direction `r`,
//!
//! ```text
//! f_n(r) = int L(w) (n + 1) / (2 pi) max(0, w . r)^n dw,
//! ```
//!
//! on a lat-long grid; the mapping from a BRDF's angular bandwidth to the layer that serves it;
//! a KTX2 writer for the layers and for the source's mip chain (filtered importance sampling,
//! Colbert and Krivanek 2007); a contact sheet; and the brute-force reference the method is held
//! to. No IO: the tool `envmap-prefilter` reads and writes the files.
//!
//! # The lobe
//!
//! `(n + 1) / (2 pi)` normalizes `cos^n` over the hemisphere around `r`
//! (`int cos^n theta dw = 2 pi / (n + 1)` there), so with the `max(0, .)` the lobe integrates to 1
//! over the sphere (without it, `cos^n` would integrate to 0 or twice that) and every layer keeps
//! the source's solid-angle-weighted mean radiance ([`lobe::normalization`]; checked by
//! quadrature in `tests/lobe.rs`).
//!
//! # Method
//!
//! The integral is what the reference ([`Reference`]) sums: `L_j K_n(w_j . r) omega_j` over the
//! source texel centres `w_j`, exact texel solid angles. Two methods compute it without visiting
//! every source texel for every layer texel:
//!
//! - **Spherical harmonics** ([`Method::SphericalHarmonics`]). With the lobe's Legendre
//!   coefficients `k_l` (exact, by a recurrence: [`lobe::legendre_coefficients`]) and the
//!   addition theorem, `f_n(r) = sum_lm k_l a_lm Y_lm(r)`, where `a_lm` is the same discrete sum
//!   over the texel centres as the reference: nothing is projected or assumed band-limited, the
//!   only error is truncating the lobe's series at degree `L`. [`sh_degree`] picks the smallest
//!   `L` beyond which the truncated lobe stays within `1e-9` of its peak everywhere (`L = 205`
//!   for `n = 1024`, about `6.4 sqrt(n)`), or [`KINK_DEGREE`] = 256 for the lobes whose kink at
//!   the horizon (`max(0, t)^n`, small `n`) makes the series converge slowly: the `n = 1` lobe
//!   truncated at 256 is within 0.12% of its peak everywhere. FFTs over the map's rows and the
//!   associated Legendre recurrence over its rows (north and south together) give all `a_lm` for
//!   all layers at once; the layers are summed back the same way at their own rows. Cost
//!   `O(W H log W + L^2 (H + H_layer))`, independent of the layer count but for the last term.
//! - **Direct summation over the lobe's extent** ([`Method::Window`]): only the source texels in
//!   the cap where `cos^n` exceeds `1e-9` of its peak, found row by row as a `phi` interval. The
//!   cost per layer texel is the number of texels in the cap, about `1.6 W H / n` (more near the
//!   poles, where texels are slivers): bounded, and small for narrow lobes.
//!
//! [`Method::Auto`] takes, per layer, the one with fewer steps (a recurrence step for a row pair
//! and a texel visit cost about the same): harmonics for every default layer on 1024 x 512 maps
//! (the `n = 4096` cap still holds 86 million texel visits for 256 x 128 layers, the harmonics 27
//! million steps), direct summation for the lobes narrower than the source's texels can carry
//! harmonics for (`L > 1000`) or whose cap is small. The source's mip chain is not used for the
//! convolution: a coarse texel moves a small bright source (the quarry sun, 46% of the energy in
//! 9 texels) to its centre, which for a lobe a few coarse texels wide shifts the highlight by a
//! large fraction of its width; both methods keep every texel where it is.
//!
//! # Accuracy
//!
//! Against the reference at every texel of 64 x 32 layers of the 1024 x 512 quarry (sun) and
//! potsdamer (overcast) maps (`tests/accuracy.rs`), both methods: relative RMSE below `5e-7` and
//! 99th-percentile per-texel relative error below `2e-7` on every layer (`f32` rounding), except
//! the harmonics of `n = 1`: RMSE `1e-4`, 99th percentile `1e-3`, largest `6e-3` (quarry; its kink
//! truncated at degree 256). A point source gives the lobe itself and a constant map itself
//! (`tests/accuracy.rs`); the solid-angle-weighted mean of every default layer equals the
//! source's within 0.5% (`layer_means_equal_the_source_mean`). The layers are `f32`; the KTX2
//! textures round them to half floats (relative error at most `2^-11`).
//!
//! # Bandwidth to layer
//!
//! A lobe of exponent `n` has angular bandwidth `sqrt(n + 2) / (2 pi)` cycles per radian (the
//! units of `envmap-bandwidth`; a sinusoid `cos(k a)` has `k / (2 pi)`): the standard deviation of
//! its spectrum, `sqrt(n) / (2 pi)` for the Gaussian `exp(-n a^2 / 2)` it resembles near its peak,
//! exactly `sqrt(n + 2)` when matched to the lobe's first Legendre coefficient
//! ([`lobe::lobe_bandwidth`] has the derivation). A BRDF of bandwidth `nu` is served by the layer
//! whose lobe bandwidth is nearest on a log scale: thresholds at the geometric means of
//! neighbouring bandwidths ([`LayerMapping`]). Tested on the Phong lobes themselves: the measured
//! width of each lobe's spectrum is within 10% of the formula, and every layer's lobe maps to its
//! own layer.
//!
//! # Cost
//!
//! Time: `cargo bench -p prefilter --bench prefilter` times real 1024 x 512 maps, the 7
//! exponents to `n = 4096` and 256 x 128 layers, against the brute-force reference (its last report is in
//! `docs/benchmarks.md`). Memory: the row spectra and coefficients, a few tens of megabytes at
//! `L = 411`.

pub mod cube;
pub mod dfg;
mod error;
pub mod ggx;
pub mod ktx;
pub mod lobe;
pub mod reference;
mod sh;
mod sheet;
mod window;

use std::sync::atomic::{AtomicU64, Ordering};

use envmap::EnvMap;
use rayon::prelude::*;

pub use error::Error;
pub use lobe::{LayerMapping, Lobe, legendre_coefficients, lobe, lobe_bandwidth};
pub use reference::Reference;
pub use sheet::{COLUMNS, ContactSheet, MIN_PANEL_WIDTH, contact_sheet, panel_titles, signed};

/// The exponents of the default layers: lobes from a cosine (`n = 1`, diffuse-like) to
/// about a texel of the default 512 x 256 layers (`n = 16384`, standard deviation 0.45 degrees,
/// a texel 0.7: the sharpest light the layers hold), a factor 4 apart (a factor 2 in bandwidth).
/// With 7 exponents to `n = 4096` (0.9 degrees) on 256 x 128 layers (1.4 degrees), a mirror-like
/// material read light blurred past its lobe: chrome against Mitsuba 3, 7x7 bias p99 / max,
/// quarry 1.29 / 3.38 levels, studio 4.39 / 11.88; with these layers 0.63 / 1.23 and 2.20 / 4.93
/// (`cargo bench -p brdf-preview --bench mitsuba`, docs/benchmarks.md has every case).
pub const DEFAULT_EXPONENTS: [u32; 8] = [1, 4, 16, 64, 256, 1024, 4096, 16384];

/// The largest exponent accepted: its lobe (standard deviation 0.06 degrees) is narrower than a
/// texel of any map within `envmap`'s limits.
pub const MAX_EXPONENT: u32 = 1 << 24;

/// The largest layer height accepted (layers are `2 h x h`).
pub const MAX_LAYER_HEIGHT: usize = 8192;

/// The largest degree of the spherical harmonics (beyond it, rows near the poles could no longer
/// be skipped safely); narrower lobes, `n` above about 15 000, are summed directly.
pub const MAX_SH_DEGREE: usize = sh::MAX_DEGREE;

/// The truncation degree of the lobes with a kink at the horizon (`n <= 3`), whose Legendre
/// series converge slowly; see the crate documentation.
pub const KINK_DEGREE: usize = 256;

/// The truncation error allowed in the spherical-harmonic series: the largest difference
/// between the lobe and its truncated Legendre series, as a fraction of the lobe's peak value.
const SH_EPSILON: f64 = 1e-9;

/// How a layer is computed (see the crate documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Per layer, the cheaper of the two for its lobe and the map's size.
    #[default]
    Auto,
    SphericalHarmonics,
    Window,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::SphericalHarmonics => "spherical-harmonics",
            Method::Window => "window",
        }
    }
}

/// What to compute.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Phong exponents, one layer each: at least one, each in `1 ..= MAX_EXPONENT`, strictly
    /// increasing (the layer mapping needs the order).
    pub exponents: Vec<u32>,
    /// Layer width and height: `width == 2 * height`, `1 <= height <= MAX_LAYER_HEIGHT`.
    pub width: usize,
    pub height: usize,
    pub method: Method,
    /// How the KTX2 files store radiance (no effect on the layers themselves).
    pub storage: ktx::Storage,
    /// Also write the layers and the mip chain as KTX2 cube maps ([`cube`]).
    pub cube: bool,
    /// Also compute a GGX chain of this many levels from a `width x height` level 0 ([`ggx`]); 0
    /// for none.
    pub ggx_levels: usize,
    /// Also compute the exponents as one mip chain ([`phong_chain`]).
    pub chain: bool,
}

impl Default for Config {
    /// The 8 default exponents, 512 x 256 layers, [`Method::Auto`], [`ktx::Storage::Auto`].
    fn default() -> Self {
        Config {
            exponents: DEFAULT_EXPONENTS.to_vec(),
            width: 512,
            height: 256,
            method: Method::Auto,
            storage: ktx::Storage::Auto,
            cube: false,
            ggx_levels: 0,
            chain: false,
        }
    }
}

impl Config {
    /// Checks the exponents and the layer size.
    pub fn check(&self) -> Result<(), Error> {
        let invalid = |message: String| Err(Error::InvalidConfig(message));
        if self.exponents.is_empty() {
            return invalid("no exponents".into());
        }
        if let Some(&n) = self.exponents.iter().find(|&&n| n == 0 || n > MAX_EXPONENT) {
            return invalid(format!("exponent {n} outside 1 ..= {MAX_EXPONENT}"));
        }
        if let Some(pair) = self.exponents.windows(2).find(|w| w[0] >= w[1]) {
            return invalid(format!("exponents must increase strictly, found {} then {}", pair[0], pair[1]));
        }
        if self.height == 0 || self.height > MAX_LAYER_HEIGHT || self.width != 2 * self.height {
            return invalid(format!(
                "layer size {} x {}: expected width = 2 x height, height 1 ..= {MAX_LAYER_HEIGHT}",
                self.width, self.height
            ));
        }
        if self.chain {
            self.check_chain()?;
        }
        if self.ggx_levels != 0 && !(2..=ggx::max_levels(self.width)).contains(&self.ggx_levels) {
            return invalid(format!(
                "{} ggx levels from a {} x {} level 0: 2 to {}",
                self.ggx_levels,
                self.width,
                self.height,
                ggx::max_levels(self.width)
            ));
        }
        Ok(())
    }
}

impl Config {
    /// The exponents fit one mip chain from the layers' size ([`phong_chain`]).
    pub fn check_chain(&self) -> Result<(), Error> {
        if self.exponents.len() > ggx::max_levels(self.width) {
            return Err(Error::InvalidConfig(format!(
                "a chain of {} exponents from a {} x {} level 0: at most {} levels",
                self.exponents.len(),
                self.width,
                self.height,
                ggx::max_levels(self.width)
            )));
        }
        Ok(())
    }
}

/// One layer: the source convolved with the lobe of `exponent`, as a lat-long map in the
/// source's orientation.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub exponent: u32,
    /// The method that computed it (never `Auto`).
    pub method: Method,
    /// The truncation degree, for [`Method::SphericalHarmonics`].
    pub degree: Option<usize>,
    pub map: EnvMap,
}

/// The layers, in the order of [`Config::exponents`].
#[derive(Clone, Debug, PartialEq)]
pub struct Prefiltered {
    pub layers: Vec<Layer>,
    pub mapping: LayerMapping,
}

/// How far the computation has come, in units of work of roughly equal cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    pub done: u64,
    pub total: u64,
}

/// The layers of `map` for `config`. See [`prefilter_with_progress`].
pub fn prefilter(map: &EnvMap, config: &Config) -> Result<Prefiltered, Error> {
    prefilter_with_progress(map, config, &|_| {})
}

/// The layers of `map` for `config`, calling `progress` (from any thread) as work gets done.
/// Fails only on an invalid config, or when a layer value does not fit in `f32`. (The chains the
/// config may ask for are [`prefilter_all`]'s.)
pub fn prefilter_with_progress(
    map: &EnvMap,
    config: &Config,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Prefiltered, Error> {
    let array_only = Config { chain: false, ggx_levels: 0, ..config.clone() };
    Ok(convolve_all(map, &array_only, progress)?.prefiltered)
}

/// Everything a [`Config`] asks for: the layers, and the chains of [`Config::chain`] and
/// [`Config::ggx_levels`] when set.
#[derive(Clone, Debug, PartialEq)]
pub struct All {
    pub prefiltered: Prefiltered,
    /// [`phong_chain`]'s levels.
    pub phong_chain: Option<Vec<(u32, EnvMap)>>,
    pub ggx: Option<ggx::Chain>,
}

/// [`prefilter_with_progress`], [`phong_chain`] and [`ggx::chain`] as `config` asks, in one
/// [`convolve_lobes`]: the map's harmonics are analysed once for all of them, and a chain level
/// that is an array layer (the sharpest exponent at the layers' size) is computed once. `mips` is
/// the map's mip chain (`envmap::MipChain::new(map)`), which the GGX chain's level 0 is taken
/// from: a caller that needs the chain itself (a bake writes it) makes it once for both.
pub fn prefilter_all(
    map: &EnvMap,
    mips: &envmap::MipChain,
    config: &Config,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<All, Error> {
    let Convolutions { prefiltered, phong_chain, ggx } = convolve_all(map, config, progress)?;
    let ggx = ggx.map(|(roughness, convolved)| ggx::assemble(map, mips, config.width, roughness, convolved));
    Ok(All { prefiltered, phong_chain, ggx })
}

/// [`prefilter_all`]'s convolutions: the GGX chain is its roughness and its levels 1 and up,
/// before its level 0 joins them.
struct Convolutions {
    prefiltered: Prefiltered,
    phong_chain: Option<Vec<(u32, EnvMap)>>,
    ggx: Option<(Vec<f64>, Vec<Convolved>)>,
}

fn convolve_all(map: &EnvMap, config: &Config, progress: &(dyn Fn(Progress) + Sync)) -> Result<Convolutions, Error> {
    config.check()?;
    let mut lobes: Vec<Lobe> = config.exponents.iter().map(|&n| Lobe::Phong(n)).collect();
    let mut sizes = vec![(config.width, config.height); lobes.len()];
    let chain_exponents = config.chain.then(|| phong_chain_lobes(config, &mut lobes, &mut sizes));
    let ggx_roughness = (config.ggx_levels > 0)
        .then(|| ggx::chain_lobes(config.width, config.ggx_levels, &mut lobes, &mut sizes))
        .transpose()?;
    let mut convolved = convolve_lobes(map, &lobes, &sizes, config.method, progress)?.into_iter();
    let layers = convolved
        .by_ref()
        .take(config.exponents.len())
        .zip(&config.exponents)
        .map(|(c, &exponent)| Layer { exponent, method: c.method, degree: c.degree, map: c.map })
        .collect();
    let prefiltered = Prefiltered { layers, mapping: LayerMapping::new(&config.exponents) };
    let phong_chain = chain_exponents.map(|exponents| {
        let levels: Vec<EnvMap> = convolved.by_ref().take(exponents.len()).map(|c| c.map).collect();
        exponents.into_iter().zip(levels).collect()
    });
    let ggx = ggx_roughness.map(|roughness| (roughness, convolved.collect()));
    Ok(Convolutions { prefiltered, phong_chain, ggx })
}

/// The exponents as one mip chain, the layout engines read (cmft's): level `m` holds the `m`-th
/// largest exponent on a `(width >> m) x (height >> m)` grid, so the sharpest lobe gets the finest
/// level and every factor 4 in exponent (a factor 2 in lobe width) costs a level (half the
/// resolution): the default exponents give cmft's `4096, 1024, ..., 1` from `width x height` down,
/// the texels per lobe width about constant. Returns `(exponent, level)` pairs, level 0 first.
pub fn phong_chain(
    map: &EnvMap,
    config: &Config,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<(u32, EnvMap)>, Error> {
    config.check()?;
    config.check_chain()?;
    let (mut lobes, mut sizes) = (Vec::new(), Vec::new());
    let exponents = phong_chain_lobes(config, &mut lobes, &mut sizes);
    let levels = convolve_lobes(map, &lobes, &sizes, config.method, progress)?;
    Ok(exponents.into_iter().zip(levels.into_iter().map(|c| c.map)).collect())
}

/// Appends the lobes and sizes of [`phong_chain`]'s levels; returns their exponents.
fn phong_chain_lobes(config: &Config, lobes: &mut Vec<Lobe>, sizes: &mut Vec<(usize, usize)>) -> Vec<u32> {
    let exponents: Vec<u32> = config.exponents.iter().rev().copied().collect();
    for (m, &n) in exponents.iter().enumerate() {
        lobes.push(Lobe::Phong(n));
        sizes.push((config.width >> m, config.height >> m));
    }
    exponents
}

/// One convolution of [`convolve_lobes`].
#[derive(Clone, Debug, PartialEq)]
pub struct Convolved {
    /// The method that computed it (never `Auto`).
    pub method: Method,
    /// The truncation degree, for [`Method::SphericalHarmonics`].
    pub degree: Option<usize>,
    pub map: EnvMap,
}

/// `map` convolved with each lobe, layer `k` on a lat-long grid of `sizes[k]` (`width = 2
/// height`), by `method` (per layer the cheaper one for `Auto`). The map's harmonics are analysed
/// once for every layer that uses them.
pub fn convolve_lobes(
    map: &EnvMap,
    lobes: &[Lobe],
    sizes: &[(usize, usize)],
    method: Method,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Convolved>, Error> {
    assert_eq!(lobes.len(), sizes.len(), "one size per lobe");
    // A (lobe, size) pair asked for twice is computed once.
    let first = |k: usize| (0..k).find(|&j| lobes[j] == lobes[k] && sizes[j] == sizes[k]).unwrap_or(k);
    let unique: Vec<usize> = (0..lobes.len()).filter(|&k| first(k) == k).collect();
    if unique.len() < lobes.len() {
        let pick = |k: &usize| (lobes[*k], sizes[*k]);
        let (unique_lobes, unique_sizes): (Vec<Lobe>, Vec<(usize, usize)>) = unique.iter().map(pick).unzip();
        let computed = convolve_lobes(map, &unique_lobes, &unique_sizes, method, progress)?;
        let at = |k: usize| unique.iter().position(|&u| u == first(k)).expect("a first occurrence");
        return Ok((0..lobes.len()).map(|k| computed[at(k)].clone()).collect());
    }
    // Per layer its method and, for harmonics, its degree and Legendre coefficients (GGX's come
    // from a quadrature: computed once, for the degree search, and kept).
    let plan: Vec<Plan> = lobes
        .par_iter()
        .zip(sizes)
        .map(|(lobe, &size)| plan_layer(lobe, map, size, method))
        .collect::<Result<_, _>>()?;
    let sh_degree = plan.iter().filter_map(|(_, sh)| sh.as_ref().map(|(degree, _)| *degree)).max();
    let rows = |k: usize| sizes[k].1 as u64;
    let sh_rows: u64 = (0..plan.len()).filter(|&k| plan[k].1.is_some()).map(rows).sum();
    let window_rows: u64 = (0..plan.len()).filter(|&k| plan[k].0 == Method::Window).map(rows).sum();
    let total = sh_degree.map_or(0, |l| 2 * (l as u64 + 1) + sh_rows) + window_rows;
    let done = AtomicU64::new(0);
    let tick = || {
        let done = done.fetch_add(1, Ordering::Relaxed) + 1;
        progress(Progress { done, total });
    };

    let mut rgb: Vec<Option<Vec<f32>>> = vec![None; plan.len()];
    if let Some(l_max) = sh_degree {
        let coefficients = sh::analyse(map, l_max, &tick);
        // The layers of one size share the synthesis's recurrence: one pass per size.
        let mut by_size: Vec<((usize, usize), Vec<usize>)> = Vec::new();
        for (k, (_, sh)) in plan.iter().enumerate() {
            if sh.is_some() {
                match by_size.iter_mut().find(|(size, _)| *size == sizes[k]) {
                    Some((_, ks)) => ks.push(k),
                    None => by_size.push((sizes[k], vec![k])),
                }
            }
        }
        for ((width, height), ks) in by_size {
            let specs: Vec<sh::LayerSpec> =
                ks.iter().map(|&k| sh::LayerSpec { k: plan[k].1.as_ref().expect("harmonics").1.clone() }).collect();
            for (k, layer) in ks.into_iter().zip(sh::synthesize(&coefficients, &specs, width, height, &tick)) {
                rgb[k] = Some(layer);
            }
        }
    }
    for (k, (method, _)) in plan.iter().enumerate() {
        if *method == Method::Window {
            let (width, height) = sizes[k];
            rgb[k] = Some(window::convolve(map, &lobes[k], width, height, &tick));
        }
    }
    rgb.into_iter()
        .zip(plan)
        .zip(lobes.iter().zip(sizes))
        .map(|((rgb, (method, sh)), (lobe, &(width, height)))| {
            let degree = sh.map(|(degree, _)| degree);
            let rgb = rgb.expect("every layer was computed");
            let map = EnvMap::new(width, height, rgb)
                .map_err(|e| Error::Overflow(format!("layer of the {}: {e}", lobe.name())))?;
            Ok(Convolved { method, degree, map })
        })
        .collect()
}

/// A layer's method and, for harmonics, its degree and coefficients `k_0 ..= k_degree`.
type Plan = (Method, Option<(usize, Vec<f64>)>);

/// The [`Plan`] of a layer of `lobe` of `(width, height)`.
fn plan_layer(lobe: &Lobe, map: &EnvMap, (width, height): (usize, usize), method: Method) -> Result<Plan, Error> {
    let (degree, coefficients) = degree_and_coefficients(lobe);
    let harmonics = move || {
        let k = coefficients.unwrap_or_else(|| lobe.legendre_coefficients(degree));
        Some((degree, k))
    };
    match method {
        Method::Auto => {
            // One step of the recurrence for one row pair costs about what one texel visit of the
            // direct sum does (about 3 ns each on 2 cores, measured for n = 4096 on quarry).
            let steps = sh::steps(degree, map.height(), height);
            if degree > sh::MAX_DEGREE || window::visits(lobe, map.width(), map.height(), width, height) < steps {
                Ok((Method::Window, None))
            } else {
                Ok((Method::SphericalHarmonics, harmonics()))
            }
        }
        Method::SphericalHarmonics if degree > sh::MAX_DEGREE => Err(Error::InvalidConfig(format!(
            "the {} needs spherical harmonics of degree {degree}, above the limit of {}",
            lobe.name(),
            sh::MAX_DEGREE
        ))),
        Method::SphericalHarmonics => Ok((Method::SphericalHarmonics, harmonics())),
        Method::Window => Ok((Method::Window, None)),
    }
}

/// The truncation degree of the lobe of exponent `n` for [`Method::SphericalHarmonics`]: the
/// smallest `L` beyond which the truncated series `K_L(t) = sum_{l <= L} (2l + 1) / (4 pi) k_l
/// P_l(t)` stays within `SH_EPSILON` of the lobe's peak value everywhere (measured on a grid of
/// `8 l_top` angles, `l_top` the largest degree tried); [`KINK_DEGREE`] for the lobes that get
/// there only far beyond it (the kink of `max(0, t)^n` at the horizon slows the series for small
/// `n`). Above [`MAX_SH_DEGREE`] when the lobe is too narrow for harmonics.
pub fn sh_degree(n: u32) -> usize {
    lobe_degree(&Lobe::Phong(n))
}

/// [`sh_degree`] for any lobe. A Phong lobe's coefficients fall like `exp(-l^2 / (2 n))`: below
/// 1e-13 beyond `8 sqrt(n)`. GGX's tails fall like `t^-4` in angle, so its spectrum falls only
/// exponentially, like `exp(-2 alpha l)` roughly: below 1e-9 of its peak beyond about `12 /
/// alpha`.
pub fn lobe_degree(lobe: &Lobe) -> usize {
    degree_and_coefficients(lobe).0
}

/// [`lobe_degree`], and the coefficients `k_0 ..= k_degree` when the search computed them (not
/// for a lobe too narrow for harmonics).
fn degree_and_coefficients(lobe: &Lobe) -> (usize, Option<Vec<f64>>) {
    let wanted = match lobe {
        Lobe::Phong(n) => (8.0 * f64::from(*n).sqrt()).ceil() as usize + 16,
        Lobe::Ggx(g) => (12.0 / g.alpha).ceil() as usize + 16,
    };
    if wanted > sh::MAX_DEGREE {
        return (wanted, None);
    }
    let l_top = wanted.max(KINK_DEGREE);
    let mut k = lobe.legendre_coefficients(l_top);
    let errors = lobe.truncation_errors_of(&k);
    let degree = errors.iter().rposition(|&e| e > SH_EPSILON).map_or(0, |l| (l + 1).min(l_top));
    k.truncate(degree + 1);
    (degree, Some(k))
}
