//! The split-sum table against two deterministic quadratures of the same integral, and its
//! mirror limit.

use std::f64::consts::PI;

use glam::DVec3;
use merl::analytic::{ggx_d, smith_lambda};
use prefilter::dfg::{dfg, table};
use prefilter::ggx::alpha;
use rayon::prelude::*;

/// `f(l, v) (n . l)` of GGX with height-correlated Smith masking, without the Fresnel factor, and
/// the Fresnel weight `Fc = (1 - v . h)^5`: `A` integrates `(1 - Fc)` times it, `B` `Fc` times it.
fn integrand(l: DVec3, v: DVec3, a: f64) -> Option<(f64, f64)> {
    if l.z <= 0.0 {
        return None;
    }
    let h = (l + v).normalize();
    let g2 = 1.0 / (1.0 + smith_lambda(a, v.z) + smith_lambda(a, l.z));
    let f = ggx_d(a, h.z) * g2 / (4.0 * l.z * v.z) * l.z;
    Some((f, (1.0 - v.dot(h)).powi(5)))
}

/// Quadrature over the half vector: the GGX inverse CDF in `theta_h` (`tan^2 theta_h = a^2 xi /
/// (1 - xi)`, graded midpoints in `xi`) and, for each `theta_h`, the midpoint rule over the interval of
/// `phi` where `l` stays above the horizon and `v . h > 0`, found in closed form: the integrand
/// is smooth there, so the rule converges fast instead of stepping over the horizon's edge.
/// `dl = 4 (v . h) dh`, the density of `h` is `D cos theta_h`. Nothing of the table's sampling.
fn by_half_vectors(mu: f64, a: f64) -> [f64; 2] {
    let sin_v = (1.0 - mu * mu).sqrt();
    let v = DVec3::new(sin_v, 0.0, mu);
    let (nx, np) = (1024, 512);
    let (mut sa, mut sb) = (0.0, 0.0);
    for i in 0..nx {
        // xi = 1 - (1 - s)^4, midpoint in s: dense near xi = 1 (h near the horizon), where the
        // integrand grows like 1 / cos theta_h before the horizon cuts it off.
        let s_mid = (i as f64 + 0.5) / nx as f64;
        let xi = 1.0 - (1.0 - s_mid).powi(4);
        let dxi = 4.0 * (1.0 - s_mid).powi(3);
        let tan2 = a * a * xi / (1.0 - xi);
        let cos_h = 1.0 / (1.0 + tan2).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).sqrt();
        let pdf_h = ggx_d(a, cos_h) * cos_h;
        // l.z = 2 (v . h) cos_h - mu > 0 and v . h > 0, with v . h = sin_v sin_h cos(phi) + mu cos_h:
        // cos(phi) above both thresholds.
        let s = sin_v * sin_h;
        let threshold = if s > 0.0 {
            ((mu - 2.0 * mu * cos_h * cos_h) / (2.0 * s * cos_h)).max(-mu * cos_h / s)
        } else if mu * (2.0 * cos_h * cos_h - 1.0) > 0.0 {
            -1.0
        } else {
            1.0
        };
        if threshold >= 1.0 {
            continue;
        }
        let phi_max = threshold.max(-1.0).acos();
        for j in 0..np {
            let phi = phi_max * (2.0 * (j as f64 + 0.5) / np as f64 - 1.0);
            let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
            let vh = v.dot(h);
            let l = 2.0 * vh * h - v;
            if let Some((f, fc)) = integrand(l, v, a) {
                // xi and phi cells: 1 / nx and 2 phi_max / np of the (xi, phi / (2 pi)) square.
                let weight = f * 4.0 * vh / pdf_h * dxi / nx as f64 * (2.0 * phi_max / np as f64) / (2.0 * PI);
                sa += (1.0 - fc) * weight;
                sb += fc * weight;
            }
        }
    }
    [sa, sb]
}

/// Midpoint quadrature over `l` itself, uniform in `cos theta_l` and `phi_l`: nothing of GGX's
/// sampling; good for lobes several cells wide.
fn by_directions(mu: f64, a: f64) -> [f64; 2] {
    let v = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
    let (nz, np) = (1000, 1000);
    let (mut sa, mut sb) = (0.0, 0.0);
    for i in 0..nz {
        let z = (i as f64 + 0.5) / nz as f64;
        let r = (1.0 - z * z).sqrt();
        for j in 0..np {
            let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
            if let Some((f, fc)) = integrand(DVec3::new(r * phi.cos(), r * phi.sin(), z), v, a) {
                let weight = f * 2.0 * PI / (nz * np) as f64;
                sa += (1.0 - fc) * weight;
                sb += fc * weight;
            }
        }
    }
    [sa, sb]
}

#[test]
fn the_table_matches_quadrature_over_half_vectors() {
    // Within 1e-3 absolute. Every texel centre of a 16 x 16 table.
    let size = 16;
    let t = table(size);
    let worst = (0..size * size)
        .into_par_iter()
        .map(|k| {
            let (mu, rho) = (((k % size) as f64 + 0.5) / size as f64, ((k / size) as f64 + 0.5) / size as f64);
            let expected = by_half_vectors(mu, alpha(rho));
            let got = t[k];
            let error = (0..2).map(|c| (f64::from(got[c]) - expected[c]).abs()).fold(0.0, f64::max);
            assert!(error < 1e-3, "mu {mu} rho {rho}: {got:?} against {expected:?}");
            error
        })
        .reduce(|| 0.0, f64::max);
    eprintln!("dfg against half-vector quadrature: largest difference {worst:.1e}");
}

#[test]
fn the_table_matches_quadrature_over_directions_where_the_lobe_is_wide() {
    for (mu, rho) in [(0.1, 0.5), (0.5, 0.5), (0.9, 0.7), (0.3, 1.0), (0.95, 0.95)] {
        let (got, expected) = (dfg(mu, alpha(rho)), by_directions(mu, alpha(rho)));
        for c in 0..2 {
            assert!((got[c] - expected[c]).abs() < 1e-3, "mu {mu} rho {rho}: {got:?} against {expected:?}");
        }
    }
}

#[test]
fn a_mirror_reflects_everything_with_schlicks_fresnel() {
    // alpha -> 0: G2 -> 1 and every sample is the mirror direction, so A + B = 1 and B = (1 - mu)^5.
    for mu in [0.05, 0.3, 0.8, 1.0] {
        let [a, b] = dfg(mu, 1e-4);
        assert!((a + b - 1.0).abs() < 1e-3 && (b - (1.0 - mu).powi(5)).abs() < 1e-3, "mu {mu}: {a} {b}");
    }
}

#[test]
fn the_embedded_table_is_the_computed_one() {
    // The default size is embedded (module docs): held to the computation on a spread of texels
    // (every 61st, all rows and columns reached). Exact on the machine that wrote it; another
    // libm may round a sample's last bit differently, which moves an f32 by at most an ulp.
    let size = prefilter::dfg::DFG_SIZE;
    let embedded = table(size);
    assert_eq!(embedded.len(), size * size);
    for k in (0..size * size).step_by(61) {
        let mu = ((k % size) as f64 + 0.5) / size as f64;
        let alpha = alpha(((k / size) as f64 + 0.5) / size as f64).max(prefilter::ggx::MIN_ALPHA);
        let computed = dfg(mu, alpha).map(|x| x as f32);
        for (e, c) in embedded[k].iter().zip(computed) {
            assert!((e - c).abs() <= 2.0 * f32::EPSILON * c.abs().max(1e-3), "texel {k}: embedded {e}, computed {c}");
        }
    }
}
