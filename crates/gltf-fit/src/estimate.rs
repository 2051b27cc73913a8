//! The initial estimate of the microfacet distribution from the table's backscattering (Dupuy et
//! al. 2015, "Extracting microfacet-based BRDF parameters from arbitrary materials with power
//! iterations"), and its conversion to a GGX width.
//!
//! At retro-reflection (`wi = wo = k`, so `h = k` and `v.h = 1`) a microfacet BRDF is
//! `f(k, k) = F(1) D(k) G2(k, k) / (4 cos^2 theta_k)`. Smith's masking writes itself through the
//! distribution's projected area `sigma(k) = integral <k, m>+ D(m) dm` (`G1(k) = cos theta_k /
//! sigma(k)`, `Lambda(k) = sigma(k) / cos theta_k - 1`), so `D(k)` is proportional to
//! `f(k, k) cos^2 theta_k / G2(k, k)`, a function of `D` itself through `sigma`: the fixed point
//! of `D <- normalize(f(k, k) cos^2 theta_k / G2(k, k; sigma[D]))`, found by iterating from a
//! constant `D`. With the paper's `G2(k, k) = G1(k)` this is `D <- f cos theta sigma`, an
//! eigenvector found by power iteration (the paper's Eq. 9); with the fit's masking
//! (`crate::Masking`) it is `f cos theta (2 sigma - cos theta)` (height-correlated,
//! `G2 = 1 / (1 + 2 Lambda)`) or `f sigma^2` (separable, `G1^2`), so that a GGX table is a fixed
//! point. `D` is normalized so that `integral D(m) cos theta_m dm = 1`; `F(1)` cancels.
//!
//! For an isotropic material `D` depends on `theta` alone and `sigma(k)` is a 1D integral whose
//! azimuthal part is closed-form ([`azimuthal_projection`]). The nodes are midpoints in
//! `u = sqrt(theta / (pi/2))` (MERL's spacing, dense near the normal where the narrow lobes are);
//! the backscattering is read from the table's `theta_d = 0` cells by the trilinear lookup.
//!
//! The conversion to GGX: the width `alpha` minimizing the projected-area-weighted squared
//! difference `integral (D_est - D_ggx(alpha))^2 cos theta dm` (golden-section search over
//! `ln alpha` in `[1e-3, 1]`). The diffuse part of a material adds a constant to `f(k, k)` and so
//! widens the estimate; the least squares afterwards corrects it.

use std::f64::consts::PI;

use merl::{HalfDiff, Interp, MerlTable};

use crate::model::{Masking, ggx_d};

/// Quadrature nodes of the distribution (midpoints in `u`, 4 per MERL `theta_h` cell).
pub const NODES: usize = 360;

/// What the power iteration found.
#[derive(Debug, Clone, PartialEq)]
pub struct NdfEstimate {
    /// `theta` of each node.
    pub theta: Vec<f64>,
    /// The estimated distribution at each node, normalized (`integral D cos theta dm = 1`).
    pub d: Vec<f64>,
    /// Iterations run.
    pub iterations: usize,
    /// The GGX width closest to `d` ([`ggx_alpha`]).
    pub alpha: f64,
}

/// `integral_0^{2 pi} max(0, cos a cos b + sin a sin b cos phi) dphi`, the azimuthal part of
/// the projected area of facets at elevation `b` seen from elevation `a`.
pub fn azimuthal_projection(theta_a: f64, theta_b: f64) -> f64 {
    let (p, q) = (theta_a.cos() * theta_b.cos(), theta_a.sin() * theta_b.sin());
    if p >= q {
        2.0 * PI * p
    } else if p <= -q {
        0.0
    } else {
        let phi0 = (-p / q).acos();
        2.0 * (p * phi0 + q * phi0.sin())
    }
}

/// The nodes' `theta` and their weights `w` such that `integral g(theta) sin theta dtheta
/// ~= sum g(theta_j) w_j` (one azimuthal turn not included).
fn nodes() -> (Vec<f64>, Vec<f64>) {
    (0..NODES).map(|j| merl::albedo::sqrt_spaced_node(j, NODES)).unzip()
}

/// The luminance of the table's backscattering `f(k, k)` at elevation `theta` (`None` where
/// the table holds no data).
fn backscattering(table: &MerlTable, theta: f64) -> Option<f64> {
    let hd = HalfDiff { theta_h: theta, phi_h: 0.0, theta_d: 0.0, phi_d: 0.0 };
    table.lookup_half_diff(&hd, Interp::Trilinear).map(color::luminance)
}

/// The power iteration on the table's backscattering, then [`ggx_alpha`]. Iterates until the
/// distribution changes by less than 1e-10 (relative, in the max norm) or 200 times.
pub fn estimate_ndf(table: &MerlTable, masking: Masking) -> NdfEstimate {
    let (theta, w) = nodes();
    let f: Vec<f64> = theta.iter().map(|&t| backscattering(table, t).unwrap_or(0.0).max(0.0)).collect();
    // The azimuthal kernel is the same every iteration.
    let kernel: Vec<Vec<f64>> = theta
        .iter()
        .map(|&tk| theta.iter().zip(&w).map(|(&tm, &wm)| azimuthal_projection(tk, tm) * wm).collect())
        .collect();
    let normalize = |d: &mut Vec<f64>| {
        let total: f64 = d.iter().zip(&theta).zip(&w).map(|((d, t), w)| d * t.cos() * w).sum::<f64>() * 2.0 * PI;
        if total > 0.0 {
            d.iter_mut().for_each(|x| *x /= total);
        }
    };
    let mut d = vec![1.0; NODES];
    normalize(&mut d);
    let mut iterations = 0;
    while iterations < 200 {
        iterations += 1;
        let mut next: Vec<f64> = (0..NODES)
            .map(|k| {
                let sigma: f64 = kernel[k].iter().zip(&d).map(|(a, d)| a * d).sum();
                let c = theta[k].cos();
                let inverse_g2 = match masking {
                    Masking::HeightCorrelated => (2.0 * sigma - c) / c,
                    Masking::Separable => sigma * sigma / (c * c),
                };
                f[k] * c * c * inverse_g2
            })
            .collect();
        normalize(&mut next);
        let peak = next.iter().copied().fold(0.0, f64::max);
        let change = next.iter().zip(&d).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        d = next;
        if peak == 0.0 || change <= 1e-10 * peak {
            break;
        }
    }
    let alpha = ggx_alpha(&theta, &w, &d);
    NdfEstimate { theta, d, iterations, alpha }
}

/// The GGX width whose distribution is closest to `d` at the nodes `theta` (weights `w`) in
/// the projected-area measure: `argmin sum (d_j - D_ggx(theta_j))^2 cos theta_j w_j` over
/// `alpha` in `[1e-3, 1]`, by golden-section search on `ln alpha` (the error is unimodal in
/// practice: one lobe against another of varying width).
pub fn ggx_alpha(theta: &[f64], w: &[f64], d: &[f64]) -> f64 {
    let error = |ln_alpha: f64| {
        let alpha = ln_alpha.exp();
        theta.iter().zip(w).zip(d).map(|((t, w), d)| (d - ggx_d(alpha, t.cos())).powi(2) * t.cos() * w).sum::<f64>()
    };
    let (mut a, mut b) = (1e-3_f64.ln(), 0.0);
    let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut e1, mut e2) = (error(x1), error(x2));
    for _ in 0..80 {
        if e1 < e2 {
            b = x2;
            (x2, e2) = (x1, e1);
            x1 = b - ratio * (b - a);
            e1 = error(x1);
        } else {
            a = x1;
            (x1, e1) = (x2, e2);
            x2 = a + ratio * (b - a);
            e2 = error(x2);
        }
    }
    ((a + b) / 2.0).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use merl::Dims;
    use merl::analytic::Analytic;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn azimuthal_projection_known_values() {
        // Seen from the normal, every facet projects its cosine over the whole turn.
        assert!((azimuthal_projection(0.0, 0.7) - 2.0 * PI * 0.7_f64.cos()).abs() < 1e-12);
        // Two grazing directions: half the turn sees the facet, with mean |cos phi| = 2 / pi.
        assert!((azimuthal_projection(FRAC_PI_2, FRAC_PI_2) - 2.0).abs() < 1e-12);
        // A brute-force sum agrees elsewhere (1e-6: 100 000 midpoints on a kinked integrand).
        let (ta, tb) = (1.1_f64, 0.9_f64);
        let n = 100_000;
        let brute: f64 = (0..n)
            .map(|i| {
                let phi = (i as f64 + 0.5) / n as f64 * 2.0 * PI;
                (ta.cos() * tb.cos() + ta.sin() * tb.sin() * phi.cos()).max(0.0)
            })
            .sum::<f64>()
            * 2.0
            * PI
            / n as f64;
        assert!((azimuthal_projection(ta, tb) - brute).abs() < 1e-6, "{brute}");
    }

    /// The projected area of a GGX distribution seen from the normal is 1 (its normalization),
    /// and the nodes integrate it to 1e-4 for the widths the fit meets.
    #[test]
    fn nodes_integrate_a_ggx_distribution() {
        let (theta, w) = nodes();
        for alpha in [0.02, 0.1, 0.5, 1.0] {
            let total: f64 =
                theta.iter().zip(&w).map(|(t, w)| ggx_d(alpha, t.cos()) * t.cos() * w).sum::<f64>() * 2.0 * PI;
            assert!((total - 1.0).abs() < 1e-4, "alpha {alpha}: {total}");
        }
    }

    /// On a GGX table the iteration's fixed point is GGX itself, so the width comes back. The
    /// tolerance, 3% of alpha, covers the table's trilinear reading of the backscattering between
    /// samples (largest for the narrowest lobe, a few cells wide) and the nodes' quadrature.
    #[test]
    fn recovers_the_width_of_a_ggx_table() {
        for masking in [Masking::HeightCorrelated, Masking::Separable] {
            for alpha in [0.05_f64, 0.15, 0.4, 0.8] {
                let metal = crate::Material::core([0.9, 0.6, 0.3], 1.0, alpha.sqrt());
                let table = crate::fitted_table(&metal, masking, Dims::MERL);
                let e = estimate_ndf(&table, masking);
                assert!(
                    (e.alpha - alpha).abs() < 0.03 * alpha,
                    "{masking:?} alpha {alpha}: {} after {}",
                    e.alpha,
                    e.iterations
                );
            }
        }
        // The merl crate's own table (height-correlated): the same.
        let table = Analytic::Ggx { alpha: 0.2, f0: [0.5; 3] }.table(Dims::MERL);
        let e = estimate_ndf(&table, Masking::HeightCorrelated);
        assert!((e.alpha - 0.2).abs() < 0.006, "{}", e.alpha);
    }
}
