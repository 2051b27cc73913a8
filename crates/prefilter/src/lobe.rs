//! The normalized Phong lobe `K_n(w . r) = (n + 1) / (2 pi) max(0, w . r)^n`, its Legendre
//! spectrum, its angular bandwidth, and the mapping from a BRDF's bandwidth to a layer.

use std::f64::consts::PI;

use rayon::prelude::*;

use crate::ggx::GgxLobe;

/// `(n + 1) / (2 pi)`: the lobe's value at its peak, and the factor that makes it integrate to 1
/// over the sphere. Only the hemisphere around `r` contributes (the `max(0, .)`), and there
/// `int cos^n theta d omega = 2 pi int_0^1 t^n dt = 2 pi / (n + 1)`.
pub fn normalization(n: u32) -> f64 {
    (f64::from(n) + 1.0) / (2.0 * PI)
}

/// The normalized Phong lobe at cosine `cos_angle = w . r`: `(n + 1) / (2 pi) max(0, cos)^n`.
pub fn lobe(n: u32, cos_angle: f64) -> f64 {
    if cos_angle <= 0.0 { 0.0 } else { normalization(n) * pow_n(cos_angle, n) }
}

/// `t^n` by squaring, the same in every module (and in the brute-force reference), so that the
/// methods differ only where they are meant to.
#[inline]
pub(crate) fn pow_n(t: f64, n: u32) -> f64 {
    let (mut result, mut base, mut e) = (1.0, t, n);
    while e > 0 {
        if e & 1 == 1 {
            result *= base;
        }
        base *= base;
        e >>= 1;
    }
    result
}

/// The Legendre coefficients `k_0 ..= k_{l_max}` of the lobe as a function of `t = w . r`:
/// `K_n(t) = sum_l (2l + 1) / (4 pi) k_l P_l(t)`, `k_l = 2 pi int_{-1}^{1} K_n(t) P_l(t) dt`. By
/// the Funk-Hecke theorem, convolving a function with the lobe multiplies its spherical-harmonic
/// coefficients of degree `l` by `k_l`.
///
/// Exact, by the recurrence `k_0 = 1` (the lobe integrates to 1), `k_1 = (n + 1) / (n + 2)`,
/// `k_{l+2} = k_l (n - l) / (n + l + 3)`, which follows from the closed form of
/// `int_0^1 t^n P_l(t) dt` (a ratio of gamma functions). For `l > n` with `l - n` even, `k_l = 0`;
/// for large `n`, `k_l ~ exp(-l (l + 1) / (2 n))`.
pub fn legendre_coefficients(n: u32, l_max: usize) -> Vec<f64> {
    let n = f64::from(n);
    let mut k = vec![0.0; l_max + 1];
    k[0] = 1.0;
    if l_max >= 1 {
        k[1] = (n + 1.0) / (n + 2.0);
    }
    for l in 0..l_max.saturating_sub(1) {
        let lf = l as f64;
        k[l + 2] = k[l] * (n - lf) / (n + lf + 3.0);
    }
    k
}

/// `e[L]`, `L = 0 ..= l_top`: the largest difference between the lobe and its Legendre series
/// truncated at degree `L`, relative to the lobe's peak `(n + 1) / (2 pi)`, over `8 l_top + 8`
/// angles spread evenly over `[0, pi]` (every `P_l`, `l <= l_top`, sampled at least 8 times per
/// oscillation, so the largest error between samples is missed by a few percent at most).
pub fn truncation_errors(n: u32, l_top: usize) -> Vec<f64> {
    Lobe::Phong(n).truncation_errors(l_top)
}

/// A zonal lobe the map is convolved with: a function of `t = w . r` alone that integrates to 1
/// over the sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lobe {
    /// The normalized Phong lobe of exponent `n` ([`lobe`]).
    Phong(u32),
    /// The GGX lobe of the split-sum approximation ([`crate::ggx`]).
    Ggx(GgxLobe),
}

impl Lobe {
    /// The lobe at `t = w . r`.
    pub fn eval(&self, t: f64) -> f64 {
        match self {
            Lobe::Phong(n) => lobe(*n, t),
            Lobe::Ggx(g) => g.eval(t),
        }
    }

    /// Its value at `t = 1`, the largest.
    pub fn peak(&self) -> f64 {
        match self {
            Lobe::Phong(n) => normalization(*n),
            Lobe::Ggx(g) => g.peak(),
        }
    }

    /// `k_0 ..= k_{l_max}`: the Legendre coefficients (see [`legendre_coefficients`]).
    pub fn legendre_coefficients(&self, l_max: usize) -> Vec<f64> {
        match self {
            Lobe::Phong(n) => legendre_coefficients(*n, l_max),
            Lobe::Ggx(g) => g.legendre_coefficients(l_max),
        }
    }

    /// A name for reports: `phong n 64`, `ggx alpha 0.25`.
    pub fn name(&self) -> String {
        match self {
            Lobe::Phong(n) => format!("phong n {n}"),
            Lobe::Ggx(g) => format!("ggx alpha {}", g.alpha),
        }
    }

    /// [`truncation_errors`] of this lobe.
    pub fn truncation_errors(&self, l_top: usize) -> Vec<f64> {
        self.truncation_errors_of(&self.legendre_coefficients(l_top))
    }

    /// [`Lobe::truncation_errors`] from this lobe's coefficients `k_0 ..= k_{l_top}`, computed
    /// once by the caller.
    pub fn truncation_errors_of(&self, k: &[f64]) -> Vec<f64> {
        let l_top = k.len() - 1;
        let c: Vec<f64> = k.iter().enumerate().map(|(l, k)| (2 * l + 1) as f64 / (4.0 * PI) * k).collect();
        let peak = self.peak();
        let n = *self;
        let lobe = move |t: f64| n.eval(t);
        let n_angles = 8 * l_top + 8;
        let max = |a: Vec<f64>, b: Vec<f64>| a.iter().zip(&b).map(|(a, b)| a.max(*b)).collect::<Vec<f64>>();
        (0..n_angles)
            .into_par_iter()
            .fold(
                || vec![0.0f64; l_top + 1],
                |mut errors, i| {
                    let t = (PI * (i as f64 + 0.5) / n_angles as f64).cos();
                    let exact = lobe(t);
                    let (mut p0, mut p1) = (1.0, t);
                    let mut sum = c[0];
                    errors[0] = errors[0].max((exact - sum).abs() / peak);
                    for l in 1..=l_top {
                        sum += c[l] * p1;
                        errors[l] = errors[l].max((exact - sum).abs() / peak);
                        let lf = l as f64;
                        let p2 = ((2.0 * lf + 1.0) * t * p1 - lf * p0) / (lf + 1.0);
                        p0 = p1;
                        p1 = p2;
                    }
                    errors
                },
            )
            .reduce(|| vec![0.0f64; l_top + 1], max)
    }
}

/// The angular bandwidth of the lobe of exponent `n`, in cycles per radian (the units of
/// `envmap-bandwidth`: a sinusoid `cos(k a)` of the angle has `k / (2 pi)`): the standard
/// deviation of its spectrum, `sqrt(n + 2) / (2 pi)`.
///
/// Derivation. Near its peak `cos^n a = exp(-n a^2 / 2 - n a^4 / 12 - ...)`: nearly a Gaussian of
/// standard deviation `s = 1 / sqrt(n)` radians, whose Fourier transform is a Gaussian
/// `exp(-nu^2 / (2 sigma^2))` of standard deviation `sigma = 1 / (2 pi s) = sqrt(n) / (2 pi)`
/// cycles per radian. The `+ 2` is exact rather than asymptotic: on the sphere the spectrum is
/// the Legendre coefficients `k_l` ([`legendre_coefficients`]) at frequencies
/// `nu_l = sqrt(l (l + 1)) / (2 pi)` (a degree-`l` harmonic oscillates locally like
/// `cos((l + 1/2) a)`), and a Gaussian spectrum starts as `1 - nu^2 / (2 sigma^2)`; matching its
/// curvature at zero frequency to `1 - k_1 = 1 / (n + 2)` (`k_1 = (n + 1) / (n + 2)` is the
/// lobe's mean cosine) gives `sigma^2 = (n + 2) / (2 pi)^2`. Equivalently, `1 / (n + 2) =
/// E[1 - cos a] ~ E[a^2] / 2` is the lobe's angular variance per axis. For the cosine lobe
/// (`n = 1`) the `+ 2` matters: its spectrum falls to `e^{-1/2}` at 0.249 cycles per radian
/// (0.90 of `sqrt(3) / (2 pi)`), where `sqrt(n) / (2 pi) = 0.159` would place it nearer the
/// `n = 4` lobe than its own.
pub fn lobe_bandwidth(n: u32) -> f64 {
    (f64::from(n) + 2.0).sqrt() / (2.0 * PI)
}

/// The Phong exponent whose lobe has bandwidth `nu` (cycles per radian): `(2 pi nu)^2 - 2`, the
/// inverse of [`lobe_bandwidth`]. Negative below `sqrt(2) / (2 pi)`, the bandwidth of `n = 0`
/// (the uniform hemisphere): no Phong lobe is that wide.
pub fn exponent_for_bandwidth(nu: f64) -> f64 {
    (2.0 * PI * nu).powi(2) - 2.0
}

/// Which layer of a prefiltered array serves a BRDF of a given angular bandwidth: the layer
/// whose lobe bandwidth ([`lobe_bandwidth`]) is nearest on a logarithmic scale, so the
/// thresholds between neighbours are the geometric means of their bandwidths,
/// `t_k = sqrt(nu_k nu_{k+1}) = ((n_k + 2) (n_{k+1} + 2))^(1/4) / (2 pi)`.
///
/// A BRDF of bandwidth `nu` is matched by the Phong lobe of exponent `(2 pi nu)^2 - 2`; a layer
/// blurs by its lobe, so a layer of lower bandwidth than the BRDF's blurs detail the BRDF would
/// have shown, and one of higher bandwidth leaves aliasing for the renderer's few samples to
/// show. On a logarithmic scale both mistakes weigh alike, hence the geometric means.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerMapping {
    bandwidths: Vec<f64>,
    thresholds: Vec<f64>,
}

impl LayerMapping {
    /// The mapping for layers of these exponents, which must be non-empty and strictly
    /// increasing (as [`crate::Config`] requires). Panics otherwise.
    pub fn new(exponents: &[u32]) -> LayerMapping {
        assert!(
            !exponents.is_empty() && exponents.windows(2).all(|w| w[0] < w[1]),
            "exponents must be non-empty and strictly increasing, got {exponents:?}"
        );
        let bandwidths: Vec<f64> = exponents.iter().map(|&n| lobe_bandwidth(n)).collect();
        let thresholds = bandwidths.windows(2).map(|w| (w[0] * w[1]).sqrt()).collect();
        LayerMapping { bandwidths, thresholds }
    }

    /// The lobe bandwidth of each layer, cycles per radian, increasing.
    pub fn bandwidths(&self) -> &[f64] {
        &self.bandwidths
    }

    /// The `layers - 1` thresholds: bandwidth `nu` goes to layer `k` when
    /// `thresholds[k - 1] < nu <= thresholds[k]`.
    pub fn thresholds(&self) -> &[f64] {
        &self.thresholds
    }

    /// The layer for a BRDF of angular bandwidth `nu` (cycles per radian): the number of
    /// thresholds below `nu`. A bandwidth exactly on a threshold takes the blurrier layer;
    /// bandwidths beyond the first or last layer take that layer; NaN takes layer 0.
    pub fn layer(&self, nu: f64) -> usize {
        self.thresholds.iter().take_while(|&&t| t < nu).count()
    }

    /// A continuous layer coordinate for blending two neighbouring layers: `k + f` where `nu`
    /// lies between the bandwidths of layers `k` and `k + 1`, `f` linear in `ln nu` between them;
    /// clamped to `[0, layers - 1]`.
    /// Rounding it gives [`LayerMapping::layer`] (up to ties). NaN gives 0.
    pub fn layer_coordinate(&self, nu: f64) -> f64 {
        let b = &self.bandwidths;
        if nu.is_nan() || nu <= b[0] {
            return 0.0;
        }
        let last = b.len() - 1;
        if nu >= b[last] {
            return last as f64;
        }
        let k = b.iter().take_while(|&&bk| bk <= nu).count() - 1;
        k as f64 + (nu / b[k]).ln() / (b[k + 1] / b[k]).ln()
    }
}
