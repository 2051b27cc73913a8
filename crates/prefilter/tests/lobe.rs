//! The lobe on its own: its normalization, its Legendre spectrum, the truncation the harmonics
//! rely on, its bandwidth, and the bandwidth-to-layer mapping, each against an independent
//! computation (quadrature, the Legendre polynomials evaluated directly).

use std::f64::consts::PI;

use prefilter::lobe::{self, LayerMapping, legendre_coefficients, lobe, lobe_bandwidth};
use prefilter::{DEFAULT_EXPONENTS, KINK_DEGREE, sh_degree};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// `P_0(t) ..= P_{l_max}(t)` by Bonnet's recurrence.
fn legendre(t: f64, l_max: usize) -> Vec<f64> {
    let mut p = vec![1.0, t];
    for l in 1..l_max {
        let lf = l as f64;
        p.push(((2.0 * lf + 1.0) * t * p[l] - lf * p[l - 1]) / (lf + 1.0));
    }
    p.truncate(l_max + 1);
    p
}

/// The nodes and weights of the composite Gauss-Legendre rule of 5 points on `intervals` equal
/// pieces of `[a, b]` (exact for polynomials of degree 9 on each piece).
fn quadrature(a: f64, b: f64, intervals: usize) -> Vec<(f64, f64)> {
    const X: [f64; 5] =
        [0.0, -0.538_469_310_105_683_1, 0.538_469_310_105_683_1, -0.906_179_845_938_664, 0.906_179_845_938_664];
    const W: [f64; 5] = [
        0.568_888_888_888_888_9,
        0.478_628_670_499_366_5,
        0.478_628_670_499_366_5,
        0.236_926_885_056_189_1,
        0.236_926_885_056_189_1,
    ];
    let h = (b - a) / intervals as f64;
    (0..intervals)
        .flat_map(|i| {
            let mid = a + (i as f64 + 0.5) * h;
            X.iter().zip(W).map(move |(x, w)| (mid + 0.5 * h * x, 0.5 * h * w))
        })
        .collect()
}

fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, intervals: usize) -> f64 {
    quadrature(a, b, intervals).into_iter().map(|(x, w)| w * f(x)).sum()
}

/// `k_l = 2 pi int_0^1 K(t) P_l(t) dt`, `l = 0 ..= l_max`, for the lobe of (real) exponent `n`,
/// by quadrature.
fn spectrum_by_quadrature(n: f64, l_max: usize, intervals: usize) -> Vec<f64> {
    let mut k = vec![0.0; l_max + 1];
    for (t, w) in quadrature(0.0, 1.0, intervals) {
        let kernel = (n + 1.0) / (2.0 * PI) * t.powf(n);
        for (k, p) in k.iter_mut().zip(legendre(t, l_max)) {
            *k += 2.0 * PI * w * kernel * p;
        }
    }
    k
}

/// `(n + 1) / (2 pi)` normalizes `cos^n` over the hemisphere around `r`: with `max(0, .)` the lobe
/// integrates to 1 over the sphere. Without the clamp, `cos^n` over the whole sphere would give 0
/// (odd `n`) or 2 (even `n`) times that: the normalization is the hemisphere's.
#[test]
fn the_lobe_integrates_to_one_over_the_sphere() {
    for n in [1, 2, 3, 4, 16, 64, 256, 1024, 4096, 65536] {
        // d omega = 2 pi sin theta d theta; the integrand is smooth, the rule converges fast.
        let sphere = integrate(|theta| lobe(n, theta.cos()) * 2.0 * PI * theta.sin(), 0.0, PI, 20_000);
        assert!((sphere - 1.0).abs() < 1e-10, "n = {n}: the lobe integrates to {sphere}");
        let unclamped = integrate(
            |theta| lobe::normalization(n) * theta.cos().powi(n as i32) * 2.0 * PI * theta.sin(),
            0.0,
            PI,
            20_000,
        );
        let expected = if n % 2 == 1 { 0.0 } else { 2.0 };
        assert!((unclamped - expected).abs() < 1e-9, "n = {n}: unclamped cos^n integrates to {unclamped}");
    }
}

/// The closed-form recurrence of the Legendre coefficients against `k_l = 2 pi int K(t) P_l(t) dt`
/// by quadrature.
#[test]
fn legendre_coefficients_match_quadrature() {
    for n in [1, 2, 3, 4, 7, 16, 64, 256] {
        let l_max = 40;
        let k = legendre_coefficients(n, l_max);
        let quadrature = spectrum_by_quadrature(f64::from(n), l_max, 2_000);
        for l in 0..=l_max {
            let q = quadrature[l];
            assert!((k[l] - q).abs() < 1e-12, "n = {n}, l = {l}: recurrence {} vs quadrature {q}", k[l]);
        }
    }
}

/// Beyond [`sh_degree`] the truncated series stays within 1e-9 of the lobe's peak, checked at
/// random points, not on the grid `sh_degree` measured on (which may miss the largest error
/// between its angles by a few percent, hence 1.05e-9); for the kinked lobes the degree is
/// [`KINK_DEGREE`] and the error the one the crate documents (0.12% for `n = 1`).
#[test]
fn the_truncated_series_is_within_its_bound() {
    let mut rng = StdRng::seed_from_u64(0x1e6e);
    for n in DEFAULT_EXPONENTS {
        let degree = sh_degree(n);
        let k = legendre_coefficients(n, degree);
        let bound = if degree == KINK_DEGREE { 1.5e-3 } else { 1.05e-9 };
        let mut worst = 0.0f64;
        for _ in 0..2000 {
            let t: f64 = rng.random_range(-1.0..1.0);
            let p = legendre(t, degree);
            let series: f64 = (0..=degree).map(|l| (2 * l + 1) as f64 / (4.0 * PI) * k[l] * p[l]).sum();
            worst = worst.max((series - lobe(n, t)).abs() / lobe::normalization(n));
        }
        assert!(worst <= bound, "n = {n}, degree {degree}: truncation error {worst:e} > {bound:e}");
    }
    assert_eq!(sh_degree(1), KINK_DEGREE);
}

/// The frequency at which a lobe's spectrum falls to `e^{-1/2}`, where a Gaussian spectrum is one
/// standard deviation from 0: measured on the exact spectrum (quadrature, not the recurrence),
/// degree `l` at `sqrt(l (l + 1)) / (2 pi)` cycles per radian, linear between degrees.
fn measured_bandwidth(n: f64) -> f64 {
    let l_max = (3.0 * n.sqrt()) as usize + 8;
    let spectrum = spectrum_by_quadrature(n, l_max, 1_000);
    let level = (-0.5f64).exp();
    let l = spectrum.iter().position(|&k| k < level).expect("the spectrum falls below e^-1/2");
    let nu = |l: usize| ((l * (l + 1)) as f64).sqrt() / (2.0 * PI);
    let f = (spectrum[l - 1] - level) / (spectrum[l - 1] - spectrum[l]);
    nu(l - 1) + f * (nu(l) - nu(l - 1))
}

/// `sqrt(n + 2) / (2 pi)` against each lobe's measured spectral width: within 11% (the cosine
/// lobe, 0.90; the Gaussian approximation improves as `1 / n`: 0.94 at `n = 4`, 0.995 at
/// `n = 64`, within 1% from there).
#[test]
fn lobe_bandwidth_is_the_width_of_the_lobes_spectrum() {
    for n in DEFAULT_EXPONENTS.into_iter().take(6) {
        let measured = measured_bandwidth(f64::from(n));
        let ratio = measured / lobe_bandwidth(n);
        let tolerance = if n < 64 { 0.11 } else { 0.01 };
        assert!((ratio - 1.0).abs() <= tolerance, "n = {n}: measured {measured:.4}, formula {:.4}", lobe_bandwidth(n));
    }
}

/// The mapping on the Phong lobes themselves: each layer's lobe, by its measured bandwidth, is
/// served by its own layer; a lobe of an exponent between two layers (a factor `4^0.2` from one
/// of them) by the nearer one.
#[test]
fn phong_lobes_map_to_their_own_layer() {
    let exponents = &DEFAULT_EXPONENTS[..6];
    let mapping = LayerMapping::new(exponents);
    for (k, &n) in exponents.iter().enumerate() {
        for offset in [-0.2, 0.0, 0.2] {
            let m = f64::from(n) * 4f64.powf(offset);
            if m < 1.0 {
                continue;
            }
            let nu = measured_bandwidth(m);
            assert_eq!(
                mapping.layer(nu),
                k,
                "exponent {m:.2} (measured bandwidth {nu:.4}) should use layer {k} (n = {n})"
            );
        }
    }
}

/// One `check(nu, layer)` per case: thresholds at the geometric means, ties to the blurrier
/// layer, everything beyond the ends to the end layers, NaN to layer 0.
#[test]
fn layers_by_bandwidth() {
    let mapping = LayerMapping::new(&DEFAULT_EXPONENTS);
    let b = mapping.bandwidths().to_vec();
    let t = mapping.thresholds().to_vec();
    assert_eq!((b.len(), t.len()), (8, 7));
    for k in 0..7 {
        assert!(((t[k] * t[k]) / (b[k] * b[k + 1]) - 1.0).abs() < 1e-15, "threshold {k} is the geometric mean");
    }
    let check = |nu: f64, layer: usize| assert_eq!(mapping.layer(nu), layer, "bandwidth {nu}");
    check(0.0, 0);
    check(f64::NAN, 0);
    check(b[0] * 0.5, 0);
    for (k, &bandwidth) in b.iter().enumerate() {
        check(bandwidth, k);
    }
    for (k, &threshold) in t.iter().enumerate() {
        check(threshold, k);
        check(threshold * (1.0 + 1e-12), k + 1);
    }
    check(b[7] * 100.0, 7);
    check(f64::INFINITY, 7);
}

#[test]
fn layer_coordinates_interpolate_in_log_bandwidth() {
    let mapping = LayerMapping::new(&[1, 4, 16]);
    let b = mapping.bandwidths();
    let check = |nu: f64, expected: f64| {
        let s = mapping.layer_coordinate(nu);
        assert!((s - expected).abs() < 1e-12, "bandwidth {nu}: coordinate {s}, expected {expected}");
    };
    check(b[0] / 2.0, 0.0);
    check(f64::NAN, 0.0);
    check(b[0], 0.0);
    check(b[1], 1.0);
    check(b[2], 2.0);
    check(b[2] * 3.0, 2.0);
    check((b[0] * b[1]).sqrt(), 0.5);
    check((b[1] * b[2]).sqrt(), 1.5);
    check(b[1].powf(0.75) * b[2].powf(0.25), 1.25);
}

#[test]
fn exponent_for_bandwidth_inverts_lobe_bandwidth() {
    for n in [0, 1, 4, 100, 4096] {
        assert!((lobe::exponent_for_bandwidth(lobe_bandwidth(n)) - f64::from(n)).abs() < 1e-9 * f64::from(n + 1));
    }
}
