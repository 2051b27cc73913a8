//! Directional albedo `a(wo) = integral f(wi, wo) cos theta_i dwi` by a deterministic quadrature
//! over the half vector.
//!
//! A uniform grid over `wi` misses mirror-like peaks (chrome is off by tens of percent even at
//! one-degree spacing), so the integral is taken over `h` instead, with `wi` the reflection of
//! `wo` about `h`: `dwi = 4 (wo . h) dwh`. `theta_h` is parameterized like MERL,
//! `theta_h = u^2 pi / 2`, so `dtheta_h = pi u du`; the `u` nodes are midpoints of
//! `nodes_per_cell` equal parts of each of the 90 MERL `theta_h` cells, and `phi_h` uses
//! `n_phi_h` midpoints over `[0, 2 pi)`. Half vectors whose reflection falls below the horizon
//! contribute nothing.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use rayon::prelude::*;

use crate::coords::spherical_dir;

/// Resolution of the quadrature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quadrature {
    /// Nodes in `u = sqrt(theta_h / (pi/2))` per MERL `theta_h` cell (90 cells).
    pub nodes_per_cell: usize,
    /// Nodes in `phi_h` over `[0, 2 pi)`.
    pub n_phi_h: usize,
}

impl Default for Quadrature {
    /// Refining to 32 nodes per cell and 5760 in `phi_h` changes the albedo of the real-derived
    /// chrome and white-paint tables by at most 2e-4 relative (measured); the `converges` test
    /// checks the same on a sharp analytic table.
    fn default() -> Self {
        Quadrature { nodes_per_cell: 8, n_phi_h: 1440 }
    }
}

/// The result of [`directional_albedo`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Albedo {
    pub rgb: [f64; 3],
    /// Share of the cosine-weighted hemisphere of `wi` (out of `pi`) at which the BRDF held no
    /// data and so contributed nothing.
    pub no_data_fraction: f64,
}

/// Directional albedo at outgoing elevation `theta_o` (`phi_o = 0`; the BRDF is isotropic).
/// `brdf(wi, wo)` returns the BRDF in 1/sr, or `None` where it holds no data.
pub fn directional_albedo(
    brdf: impl Fn(DVec3, DVec3) -> Option<[f64; 3]> + Sync,
    theta_o: f64,
    q: Quadrature,
) -> Albedo {
    let wo = spherical_dir(theta_o, 0.0);
    // The fourth component measures, cosine-weighted, where the BRDF holds no data.
    let [r, g, b, no_data] = hemisphere_integral(
        |wi| match brdf(wi, wo) {
            Some(f) => [f[0] * wi.z, f[1] * wi.z, f[2] * wi.z, 0.0],
            None => [0.0, 0.0, 0.0, wi.z],
        },
        wo,
        q,
    );
    Albedo { rgb: [r, g, b], no_data_fraction: no_data / PI }
}

/// Node `i` of `n` of the quadrature in `theta` over `[0, pi / 2]` at MERL's square-root spacing
/// (`theta = u^2 pi / 2`, `u` the node's midpoint in `[0, 1]`): `(theta, w)` such that
/// `integral g(theta) sin theta dtheta ~= sum g(theta_i) w_i` (`dtheta = pi u du`), dense near
/// 0 where peaked lobes are. The rows of [`hemisphere_integral`]'s half vectors.
pub fn sqrt_spaced_node(i: usize, n: usize) -> (f64, f64) {
    let du = 1.0 / n as f64;
    let u = (i as f64 + 0.5) * du;
    let theta = u * u * FRAC_PI_2;
    (theta, theta.sin() * PI * u * du)
}

/// `integral g(wi) dwi` over the upper hemisphere (`wi.z > 0`), by the half-vector quadrature
/// about `wo` described in the module docs: the nodes are dense where `wi` is near the mirror
/// direction of `wo`, so peaked integrands (BRDF lobes, importance-sampling densities) converge.
/// Deterministic: the same bits whatever the number of threads.
pub fn hemisphere_integral<const N: usize>(g: impl Fn(DVec3) -> [f64; N] + Sync, wo: DVec3, q: Quadrature) -> [f64; N] {
    let n_u = 90 * q.nodes_per_cell;
    let dphi = 2.0 * PI / q.n_phi_h as f64;
    (0..n_u)
        .into_par_iter()
        .map(|iu| {
            let (theta_h, weight) = sqrt_spaced_node(iu, n_u);
            let row_weight = weight * dphi;
            let mut sum = [0.0; N];
            for ip in 0..q.n_phi_h {
                let h = spherical_dir(theta_h, (ip as f64 + 0.5) * dphi);
                let wo_h = wo.dot(h);
                if wo_h <= 0.0 {
                    continue;
                }
                let wi = 2.0 * wo_h * h - wo;
                if wi.z <= 0.0 {
                    continue;
                }
                let w = 4.0 * wo_h * row_weight;
                for (s, v) in sum.iter_mut().zip(g(wi)) {
                    *s += v * w;
                }
            }
            sum
        })
        // Rows are summed in order, not by rayon's reduce, whose grouping follows the thread
        // count: the result is then the same bits on every machine and run (bakes are compared by
        // their bytes).
        .collect::<Vec<[f64; N]>>()
        .into_iter()
        .fold([0.0; N], |mut a, b| {
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
            a
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Interp;
    use crate::analytic::Analytic;

    #[test]
    fn lambertian_known_answer() {
        // The quadrature alone, on the continuous BRDF: the albedo is exactly 0.5 at every angle.
        let lambert = Analytic::Lambertian { albedo: [0.5; 3] };
        for theta_o_deg in [0.0, 30.0, 60.0, 80.0, 89.0_f64] {
            let a = directional_albedo(
                |wi, wo| Some(lambert.eval(wi, wo)),
                theta_o_deg.to_radians(),
                Quadrature::default(),
            );
            assert!((a.rgb[0] - 0.5).abs() < 5e-4, "theta_o {theta_o_deg}: {:?}", a.rgb);
            assert_eq!(a.no_data_fraction, 0.0);
        }
    }

    #[test]
    fn hemisphere_has_solid_angle_two_pi() {
        for theta_o_deg in [0.0, 45.0, 85.0_f64] {
            let wo = crate::spherical_dir(theta_o_deg.to_radians(), 0.0);
            let [area, projected] = hemisphere_integral(|wi| [1.0, wi.z], wo, Quadrature::default());
            // Midpoint nodes straddle the horizon, where a constant integrand does not vanish:
            // first-order error, measured 7e-4 at theta_o = 0. A cosine-weighted integrand
            // vanishes there and converges far better (1e-4 below).
            assert!((area - 2.0 * PI).abs() < 1.5e-3 * 2.0 * PI, "theta_o {theta_o_deg}: {area}");
            assert!((projected - PI).abs() < 1e-4 * PI, "theta_o {theta_o_deg}: {projected}");
        }
    }

    #[test]
    fn converges_on_a_sharp_table() {
        // GGX alpha 0.02: a lobe a few MERL cells wide, sharper than any shared material.
        let table = Analytic::Ggx { alpha: 0.02, f0: [1.0; 3] }.table(crate::Dims::MERL);
        let fine = Quadrature { nodes_per_cell: 32, n_phi_h: 5760 };
        for theta_o_deg in [0.0, 45.0, 80.0_f64] {
            let a = |q| directional_albedo(|wi, wo| table.lookup(wi, wo, Interp::Nearest), theta_o_deg.to_radians(), q);
            let (coarse, fine) = (a(Quadrature::default()).rgb[0], a(fine).rgb[0]);
            assert!((coarse - fine).abs() < 1e-3 * fine, "theta_o {theta_o_deg}: {coarse} vs {fine}");
        }
    }

    #[test]
    fn phong_known_answer_at_normal_incidence() {
        // Energy-normalized Phong reflects exactly ks at normal incidence, however sharp.
        for n in [10.0, 1000.0, 100_000.0] {
            let phong = Analytic::Phong { n, ks: [1.0; 3], kd: [0.0; 3] };
            let a = directional_albedo(|wi, wo| Some(phong.eval(wi, wo)), 0.0, Quadrature::default());
            assert!((a.rgb[0] - 1.0).abs() < 2e-3, "n {n}: {:?}", a.rgb);
        }
    }
}
