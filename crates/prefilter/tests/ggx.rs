//! The GGX lobe of the split-sum approximation: its normalization against a closed form, and
//! layers computed by the harmonics and the direct sum against the float64 brute force over every
//! source texel, on the shared real maps.

use std::f64::consts::PI;

use envmap::EnvMap;
use prefilter::ggx::{GgxLobe, alpha};
use prefilter::{Lobe, Method, Reference, convolve_lobes};
use rayon::prelude::*;

use crate::real_map;

/// `2 pi int_0^1 D((1 + t) / 2) t dt` in closed form: with `b = alpha^2 - 1`, `u = 1 + b x`,
/// `x = (1 + t) / 2`, the integral is `2 alpha^2 / b^2 [2 ln u + (2 + b) / u]` from `u = 1 + b /
/// 2` to `u = alpha^2` (times 2 pi / pi).
fn closed_form_norm(alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let b = a2 - 1.0;
    let f = |u: f64| 2.0 * u.ln() + (2.0 + b) / u;
    2.0 * PI / PI * 2.0 * a2 / (b * b) * (f(a2) - f(1.0 + 0.5 * b))
}

#[test]
fn the_lobe_integrates_to_one() {
    for a in [0.01, 0.05, 0.3, 0.7, 0.95] {
        let lobe = GgxLobe::new(a);
        // K(1) = D(1) / N: the peak gives N back.
        let norm = prefilter::ggx::distribution(a, 1.0) / lobe.peak();
        let expected = closed_form_norm(a);
        assert!((norm - expected).abs() < 1e-9 * expected, "alpha {a}: N {norm} against {expected}");
        assert!((lobe.legendre_coefficients(0)[0] - 1.0).abs() < 1e-12);
    }
    // alpha = 1: D = 1 / pi everywhere, K = t / pi, N = 1.
    let flat = GgxLobe::new(1.0);
    assert!((flat.peak() - 1.0 / PI).abs() < 1e-9, "{}", flat.peak());
    // The first Legendre coefficient is the lobe's mean cosine, 2 / 3 for K = t / pi.
    assert!((flat.legendre_coefficients(1)[1] - 2.0 / 3.0).abs() < 1e-9);
}

/// Relative RMSE `sqrt(sum |a - b|^2 / sum |b|^2)` over texels and channels.
fn relative_rmse(a: &[f32], b: &[[f64; 3]]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for (a, b) in a.chunks_exact(3).zip(b) {
        for c in 0..3 {
            num += (f64::from(a[c]) - b[c]).powi(2);
            den += b[c] * b[c];
        }
    }
    (num / den).sqrt()
}

fn brute_force(map: &EnvMap, lobe: &Lobe, width: usize, height: usize) -> Vec<[f64; 3]> {
    let reference = Reference::new(map);
    (0..width * height)
        .into_par_iter()
        .map(|k| {
            let (u, v) = envmap::geometry::texel_center_uv(k % width, k / width, width, height);
            reference.at_lobe(envmap::direction(u, v), lobe)
        })
        .collect()
}

#[test]
fn ggx_layers_match_the_brute_force_on_real_maps() {
    // Relative RMSE at most 1e-3 at 64 x 32 texel centres, roughness 0.05 to 1. The
    // methods sum the same texels as the reference; what differs is the harmonics' truncation
    // (the kink at the horizon of the widest lobes) and f32 rounding.
    let roughness = [0.05, 0.25, 0.5, 1.0];
    let lobes: Vec<Lobe> = roughness.iter().map(|&r| Lobe::Ggx(GgxLobe::new(alpha(r)))).collect();
    for name in ["quarry_01_1k.hdr", "potsdamer_platz_1k.hdr"] {
        let Some(map) = real_map(name) else { return };
        let sizes = vec![(64, 32); lobes.len()];
        let layers = convolve_lobes(&map, &lobes, &sizes, Method::Auto, &|_| {}).unwrap();
        for ((layer, lobe), r) in layers.iter().zip(&lobes).zip(roughness) {
            let reference = brute_force(&map, lobe, 64, 32);
            let error = relative_rmse(layer.map.rgb(), &reference);
            eprintln!("{name} roughness {r} ({}): {:?}, relative rmse {error:.2e}", lobe.name(), layer.method);
            assert!(error <= 1e-3, "{name} roughness {r}: relative rmse {error:.2e}");
        }
    }
}

#[test]
fn both_methods_agree_on_a_mid_roughness() {
    // The same lobe by the harmonics and by the direct sum: two computations of one sum.
    let Some(map) = real_map("potsdamer_platz_1k.hdr") else { return };
    let lobe = [Lobe::Ggx(GgxLobe::new(alpha(0.4)))];
    let by = |method| convolve_lobes(&map, &lobe, &[(32, 16)], method, &|_| {}).unwrap().remove(0);
    let (sh, window) = (by(Method::SphericalHarmonics), by(Method::Window));
    let reference: Vec<[f64; 3]> =
        window.map.rgb().chunks_exact(3).map(|t| [t[0], t[1], t[2]].map(f64::from)).collect();
    let error = relative_rmse(sh.map.rgb(), &reference);
    assert!(error < 1e-4, "harmonics against direct sum: {error:.2e}");
}

#[test]
fn a_chain_halves_its_levels_and_keeps_the_mean_radiance() {
    let Some(map) = real_map("potsdamer_platz_1k.hdr") else { return };
    let chain = prefilter::ggx::chain(&map, 64, 5, Method::Auto, &|_| {}).unwrap();
    assert_eq!(chain.roughness, [0.0, 0.25, 0.5, 0.75, 1.0]);
    let sizes: Vec<(usize, usize)> = chain.levels.iter().map(|l| (l.width(), l.height())).collect();
    assert_eq!(sizes, [(64, 32), (32, 16), (16, 8), (8, 4), (4, 2)]);
    // Level 0 is the mirror: the map box-filtered to 64 x 32.
    assert_eq!(chain.levels[0], envmap::MipChain::new(&map).levels()[4]);
    // Every lobe integrates to 1: every level keeps the source's solid-angle-weighted mean, up to
    // the midpoint quadrature of the level's own grid (measured: 1.4e-3 at 32 x 16, 4e-3 at 16 x 8,
    // 6% at 4 x 2, where eight texel centres stand for the sphere); checked down to 16 x 8.
    let source = map.mean_radiance();
    for (m, level) in chain.levels.iter().enumerate().take(3) {
        let mean = level.mean_radiance();
        for c in 0..3 {
            let error = (mean[c] - source[c]).abs() / source[c];
            eprintln!("level {m} channel {c}: relative error of the mean {error:.1e}");
            assert!(error < 1e-2, "level {m} channel {c}: mean {} against {}", mean[c], source[c]);
        }
    }
    assert!(prefilter::ggx::chain(&map, 64, 6, Method::Auto, &|_| {}).is_err(), "at most log2(64) - 1 levels");
}
