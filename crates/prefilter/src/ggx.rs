//! The GGX (Trowbridge-Reitz) lobe of the split-sum approximation (Karis 2013, as Filament's
//! `cmgen`, cmft and glTF-IBL-Sampler use it): the environment pre-filtered for a view along the
//! normal, `n = v = r`, which engines then read along the reflection vector.
//!
//! # The lobe, and why the Phong machinery applies
//!
//! The estimator engines use draws half vectors `h` from `D(h) (n . h)`, reflects `v` about them
//! into `l`, and averages `L(l)` weighted by `n . l`. With `v = n` the density of `l` is
//! `D(h) / 4` (`p(l) = D (n . h) / (4 v . h)` and `v . h = n . h`), so its expectation is
//!
//! ```text
//! f(r) = int L(l) K(l . r) dl,   K(t) = D(cos^2 theta_h = (1 + t) / 2) max(t, 0) / N,
//! ```
//!
//! with `t = l . r` (`l` makes the angle `2 theta_h` with `r = n`, so `cos^2 theta_h = (1 + t) /
//! 2`), `D(c) = alpha^2 / (pi (c (alpha^2 - 1) + 1)^2)` and `N = 2 pi int_0^1 D((1 + t) / 2) t dt`
//! making `K` integrate to 1. `K` depends on `l . r` alone: a zonal lobe around `r`, like the Phong
//! lobe, so the same two methods compute it exactly (module `sh` with its Legendre coefficients,
//! module `window` over its cap), and the same brute-force sum is its reference.
//!
//! # Legendre coefficients
//!
//! No closed form: `k_l = 2 pi int_0^{pi/2} K(cos a) P_l(cos a) sin a da` by Gauss-Legendre
//! quadrature, 8 nodes on each of `max(1024, 8 l_max)` panels of `s` in `[0, 1]` with `a = (pi / 2)
//! s^2`: the substitution puts a quarter of the nodes within `a < 0.1` for the sharp lobes, and
//! every `P_l` oscillation up to `l_max` gets at least 16 nodes. `N` is the same quadrature of
//! `k_0` on 65 536 panels; it is checked in the tests against a closed form.
//!
//! # Roughness
//!
//! Engines index GGX by perceptual roughness `rho` in `[0, 1]` with `alpha = rho^2` (Burley 2012;
//! Filament, three.js, Bevy, Unity's HDRP). A chain of `M` levels holds `rho_m = m / (M - 1)`:
//! level 0 (`rho = 0`) is the mirror, the map itself.

use std::f64::consts::PI;

use rayon::prelude::*;

/// Panels of the quadrature of the normalization `N` (module docs): 65 536, enough for the
/// sharpest lobe accepted (at `MIN_ALPHA` the lobe spans about 20 of them).
const NORM_PANELS: usize = 65_536;

/// The fewest panels of the quadrature of the Legendre coefficients: harmonics serve only lobes
/// with `alpha >= 0.012` (degree 1000 and below), which span 120 panels or more.
const COEFFICIENT_PANELS: usize = 1024;

/// The smallest GGX width the lobe accepts: below it the lobe is far narrower than any map's
/// texel (`alpha = 1e-4` is 0.01 degrees wide) and a level is the map itself.
pub const MIN_ALPHA: f64 = 1e-4;

/// `alpha = rho^2` for perceptual roughness `rho` (module docs).
pub fn alpha(roughness: f64) -> f64 {
    roughness * roughness
}

/// The GGX normal distribution `D` at `c = cos^2 theta_h` (`merl::analytic::ggx_d`, the one the
/// toolchain's GGX tables use).
pub fn distribution(alpha: f64, cos2: f64) -> f64 {
    merl::analytic::ggx_d(alpha, cos2.sqrt())
}

/// The GGX lobe of one width, normalized (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GgxLobe {
    pub alpha: f64,
    /// `N`: the integral of the unnormalized lobe over the sphere.
    norm: f64,
}

impl GgxLobe {
    /// The lobe of width `alpha` in `[MIN_ALPHA, 1]`; panics outside (the config checks first).
    pub fn new(alpha: f64) -> GgxLobe {
        assert!((MIN_ALPHA..=1.0).contains(&alpha), "ggx alpha {alpha} outside [{MIN_ALPHA}, 1]");
        // k_0 alone is cheap: many panels, for the sharpest lobes.
        let norm = legendre_unnormalized(alpha, 0, NORM_PANELS)[0];
        GgxLobe { alpha, norm }
    }

    /// `K(t)`, `t = l . r`.
    pub fn eval(&self, t: f64) -> f64 {
        if t <= 0.0 { 0.0 } else { distribution(self.alpha, 0.5 * (1.0 + t)) * t / self.norm }
    }

    /// The lobe's largest value, at `t = 1`.
    pub fn peak(&self) -> f64 {
        self.eval(1.0)
    }

    /// `k_0 ..= k_{l_max}` (module docs), `k_0 = 1`.
    pub fn legendre_coefficients(&self, l_max: usize) -> Vec<f64> {
        let panels = (8 * l_max).max(COEFFICIENT_PANELS);
        legendre_unnormalized(self.alpha, l_max, panels).into_iter().map(|k| k / self.norm).collect()
    }

    /// The cosine below which the lobe is under `eps` of its peak: it increases with `t` (for
    /// `alpha <= 1`, `D` grows towards the peak), so bisection finds it.
    pub(crate) fn cap_cos(&self, eps: f64) -> f64 {
        let target = eps * self.peak();
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if self.eval(mid) < target { lo = mid } else { hi = mid }
        }
        lo
    }
}

/// `2 pi int_0^{pi/2} K'(cos a) P_l(cos a) sin a da` for `l = 0 ..= l_max`, `K'` the unnormalized
/// lobe (module docs).
fn legendre_unnormalized(alpha: f64, l_max: usize, panels: usize) -> Vec<f64> {
    let (nodes, weights) = gauss_legendre_8();
    let panel_sums: Vec<Vec<f64>> = (0..panels)
        .into_par_iter()
        .map(|p| {
            let mut sums = vec![0.0; l_max + 1];
            for (x, w) in nodes.iter().zip(weights) {
                let s = (p as f64 + 0.5 + 0.5 * x) / panels as f64;
                let a = 0.5 * PI * s * s;
                let (sin_a, t) = a.sin_cos();
                // da = pi s ds, ds = 1 / (2 panels) per unit of the node coordinate.
                let weight = w * 0.5 / panels as f64 * PI * s * sin_a * 2.0 * PI;
                let k = distribution(alpha, 0.5 * (1.0 + t)) * t * weight;
                let (mut p0, mut p1) = (1.0, t);
                sums[0] += k;
                for (l, sum) in sums.iter_mut().enumerate().skip(1) {
                    *sum += k * p1;
                    let lf = l as f64;
                    let p2 = ((2.0 * lf + 1.0) * t * p1 - lf * p0) / (lf + 1.0);
                    p0 = p1;
                    p1 = p2;
                }
            }
            sums
        })
        .collect();
    (0..=l_max).map(|l| panel_sums.iter().map(|s| s[l]).sum()).collect()
}

/// The 8-point Gauss-Legendre rule on `[-1, 1]`.
fn gauss_legendre_8() -> ([f64; 8], [f64; 8]) {
    let x = [0.183_434_642_495_649_8, 0.525_532_409_916_329, 0.796_666_477_413_626_7, 0.960_289_856_497_536_3];
    let w = [0.362_683_783_378_362, 0.313_706_645_877_887_3, 0.222_381_034_453_374_5, 0.101_228_536_290_376_3];
    ([-x[3], -x[2], -x[1], -x[0], x[0], x[1], x[2], x[3]], [w[3], w[2], w[1], w[0], w[0], w[1], w[2], w[3]])
}

/// A GGX pre-filtered chain: level `m` is the map convolved with the GGX lobe of perceptual
/// roughness `roughness[m] = m / (M - 1)` on a lat-long grid of `(width >> m) x (height >> m)`
/// (module docs). Level 0, roughness 0, is the mirror: the map itself, box-filtered to the
/// level's size (`envmap::MipChain`) when the map's width is `width` times a power of two, else
/// its bilinear lookup at the level's texel centres.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    pub roughness: Vec<f64>,
    pub levels: Vec<envmap::EnvMap>,
    /// The method of each level from 1 on.
    pub methods: Vec<crate::Method>,
}

/// The most levels a chain of level-0 width `width` may have: `log2(width) - 1`, so that its
/// cube map (faces of `width / 4`) ends at faces of one texel and its lat-long grid at 4 x 2.
pub fn max_levels(width: usize) -> usize {
    if width < 4 { 0 } else { width.ilog2() as usize - 1 }
}

/// The GGX chain of `map` with `levels` levels from a `width x width / 2` level 0 (`levels` in
/// `2..=max_levels(width)`, `width` even).
pub fn chain(
    map: &envmap::EnvMap,
    width: usize,
    levels: usize,
    method: crate::Method,
    progress: &(dyn Fn(crate::Progress) + Sync),
) -> Result<Chain, crate::Error> {
    let (mut lobes, mut sizes) = (Vec::new(), Vec::new());
    let roughness = chain_lobes(width, levels, &mut lobes, &mut sizes)?;
    let convolved = crate::convolve_lobes(map, &lobes, &sizes, method, progress)?;
    Ok(assemble(map, &envmap::MipChain::new(map), width, roughness, convolved))
}

/// Appends the lobes and sizes of a chain's levels 1 and up ([`chain`]); returns every level's
/// roughness.
pub(crate) fn chain_lobes(
    width: usize,
    levels: usize,
    lobes: &mut Vec<crate::Lobe>,
    sizes: &mut Vec<(usize, usize)>,
) -> Result<Vec<f64>, crate::Error> {
    if width < 2 || !width.is_multiple_of(2) || !(2..=max_levels(width)).contains(&levels) {
        return Err(crate::Error::InvalidConfig(format!(
            "a ggx chain of {levels} levels from a {width} x {} level 0: need an even width and 2 to {} levels",
            width / 2,
            max_levels(width)
        )));
    }
    let roughness: Vec<f64> = (0..levels).map(|m| m as f64 / (levels - 1) as f64).collect();
    for (m, &r) in roughness.iter().enumerate().skip(1) {
        lobes.push(crate::Lobe::Ggx(GgxLobe::new(alpha(r).max(MIN_ALPHA))));
        sizes.push((width >> m, (width / 2) >> m));
    }
    Ok(roughness)
}

/// The chain from its levels 1 and up, convolved, and the mirror level, from `mips` (`map`'s mip
/// chain) or `map`.
pub(crate) fn assemble(
    map: &envmap::EnvMap,
    mips: &envmap::MipChain,
    width: usize,
    roughness: Vec<f64>,
    convolved: Vec<crate::Convolved>,
) -> Chain {
    let mirror = mirror_level(map, mips, width);
    let methods = convolved.iter().map(|c| c.method).collect();
    let levels = std::iter::once(mirror).chain(convolved.into_iter().map(|c| c.map)).collect();
    Chain { roughness, levels, methods }
}

/// The map at `width x width / 2` (see [`Chain`]).
fn mirror_level(map: &envmap::EnvMap, mips: &envmap::MipChain, width: usize) -> envmap::EnvMap {
    if let Some(level) = mips.levels().iter().find(|l| l.width() == width) {
        return level.clone();
    }
    let height = width / 2;
    let rgb = (0..width * height)
        .flat_map(|k| {
            let (u, v) = envmap::geometry::texel_center_uv(k % width, k / width, width, height);
            map.lookup_uv(u, v)
        })
        .collect();
    envmap::EnvMap::new(width, height, rgb).expect("bilinear lookups of a valid map are valid")
}
