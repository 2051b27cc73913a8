//! Known answers under a constant environment `L`: the value of a covered pixel is the table's
//! directional albedo at the pixel's `theta_o` times `L` (Lambertian: exactly 0.5 L), and the
//! background is `L` itself, in every mode. Fis and prefiltered give the same image (every mip
//! level and layer of a constant map is the constant, and a constant map has no peaks; both read
//! the diffuse part from the cosine layer at the normal); the reference mode samples the
//! environment too, a different estimator of the same value.

use std::f64::consts::{E, FRAC_PI_2, PI};

use color::luminance;
use merl::Interp;
use merl::albedo::{Quadrature, hemisphere_integral};
use render::{Estimator, Image, Material, Settings, raster};

use crate::support::{self, AlbedoCurve, L};

const SIZE: usize = 32;
const SPP: u32 = 64;
const FRAMES: u32 = 16;

/// The relative standard deviation of one round of a mode's estimate (one direction from each of
/// its strategies) in each slice, at the slice's own `wo`, for `g = Y(f) cos theta_i`: by
/// quadrature of the table's density `p_b` (the slice's own), not by the renderer. The BRDF's
/// strategy alone (fis, prefiltered: no peaks) has the variance `int g^2 / p_b - mu^2`; the
/// reference's balance heuristic draws one direction `x_b` from `p_b` and one `x_e` from the
/// environment's `p_e`, `X = g(x_b) / (p_b + p_e) + g(x_e) / (p_b + p_e)`, whose parts are
/// independent: `Var X = sum_s (int g^2 p_s / (p_b + p_e)^2 - (int g p_s / (p_b + p_e))^2)`. A
/// constant map's `p_e` is `1 / (4 pi)` within 1% away from the poles (texels weighted by
/// `sin theta` at their row centres).
fn round_spread(material: &Material, mode: Estimator) -> Vec<f64> {
    let p_e = 1.0 / (4.0 * PI);
    material
        .samples
        .tables
        .iter()
        .map(|slice| {
            let wo = slice.wo();
            let g = |wi: glam::DVec3| material.table.lookup(wi, wo, Interp::Nearest).map_or(0.0, luminance) * wi.z;
            let [mu, second, mean_b, second_b, mean_e, second_e] = hemisphere_integral(
                |wi| {
                    let (g, p_b) = (g(wi), slice.pdf(wi));
                    let p = p_b + p_e;
                    let only_b = if p_b > 0.0 { g * g / p_b } else { 0.0 };
                    [g, only_b, g * p_b / p, g * g * p_b / (p * p), g * p_e / p, g * g * p_e / (p * p)]
                },
                wo,
                // A sixteenth of the default nodes: a standard deviation for a tolerance, which
                // this moves by 4% at most on these tables (measured against the default).
                Quadrature { nodes_per_cell: 2, n_phi_h: 360 },
            );
            let variance = match mode {
                Estimator::Reference => second_b - mean_b * mean_b + second_e - mean_e * mean_e,
                Estimator::Fis | Estimator::Prefiltered => second - mu * mu,
            };
            variance.max(0.0).sqrt() / mu
        })
        .collect()
}

/// The slice the renderers pick for `theta_o` (crate documentation, "Samples").
fn slice_of(theta_o: f64, n_slices: usize) -> usize {
    ((theta_o / FRAC_PI_2 * n_slices as f64 + 0.5).floor() as usize).min(n_slices - 1)
}

/// The relative tolerance of a pixel of slice spread `spread`: five standard deviations of its
/// estimate, `SPP x FRAMES` rounds of the pixel's own Owen-scrambled Sobol' points, whose variance
/// is at most `e` times that of as many independent rounds (Owen 1997, for (0, m, 2)-nets in
/// base 2). Pixels draw independent scrambles, so nothing else is shared between them.
fn noise_tolerance(spread: f64) -> f64 {
    5.0 * E.sqrt() * spread / f64::from(SPP * FRAMES).sqrt()
}

/// Holds every covered pixel of `image` (rendered in `mode`) to `expected(theta_o)`, per pixel
/// and on average; checks that uncovered pixels are `L` exactly and that black pixels are black.
fn check(
    image: &Image,
    mode: Estimator,
    material: &Material,
    expected: impl Fn(f64) -> Option<[f64; 3]>,
    systematic: f64,
) {
    let scene = support::sphere_scene(SIZE, SIZE);
    let gbuffer = raster::rasterize(&scene.mesh, scene.camera.view_proj(1.0), SIZE, SIZE).expect("valid scene");
    let theta_o = support::theta_o(&gbuffer, &scene.camera);
    let spread = round_spread(material, mode);
    let max_spread = spread.iter().copied().fold(0.0, f64::max);
    let (mut sum, mut count) = (0.0, 0);
    for (i, rgb) in image.rgb.chunks_exact(3).enumerate() {
        assert_eq!(image.covered[i], gbuffer.hits[i].is_some(), "pixel {i}");
        if !image.covered[i] {
            assert_eq!(rgb, L, "background pixel {i} must be the constant");
            continue;
        }
        let Some(theta) = theta_o[i] else {
            assert_eq!(rgb, [0.0; 3], "pixel {i} faces away and must be black");
            continue;
        };
        let Some(expected) = expected(theta) else { continue };
        let k = slice_of(theta, material.samples.n_slices);
        let tolerance = noise_tolerance(spread[k]) + systematic;
        for c in 0..3 {
            let relative = f64::from(rgb[c]) / (expected[c] * f64::from(L[c])) - 1.0;
            assert!(
                relative.abs() <= tolerance,
                "{}: pixel {i} (theta_o {:.2} deg, slice {k}), channel {c}: {} vs {}, relative error {relative:.2e} > {tolerance:.2e}",
                mode.name(),
                theta.to_degrees(),
                rgb[c],
                expected[c] * f64::from(L[c]),
            );
            sum += relative;
            count += 1;
        }
    }
    assert!(count > 3 * 300, "only {count} values checked");
    // Independent pixels: the mean's noise falls with their number (the channels of a pixel
    // share its directions, so a third of the values count).
    let mean = sum / count as f64;
    let bound = noise_tolerance(max_spread) / ((count / 3) as f64).sqrt() + systematic;
    println!("{}: mean relative error {mean:.2e}, bound {bound:.2e}", mode.name());
    assert!(mean.abs() <= bound, "{}: mean relative error {mean:.2e} exceeds {bound:.2e}", mode.name());
}

/// Renders every mode under the constant map and holds each to `expected`.
fn check_all_modes(material: &Material, expected: impl Fn(f64) -> Option<[f64; 3]> + Copy, systematic: f64) {
    let scene = support::sphere_scene(SIZE, SIZE);
    let lighting = support::constant_lighting();
    let render = |mode| {
        let settings = Settings { estimator: mode, spp: SPP, frames: FRAMES, seed: 7 };
        render::render(&scene, material, &lighting, &settings).expect("valid inputs")
    };
    let (fis, prefiltered) = (render(Estimator::Fis), render(Estimator::Prefiltered));
    // Every lookup of a constant map returns the constant: the filtered modes cannot differ, both
    // reading the diffuse part from the cosine layer at the normal and the rest in the lookups.
    assert_eq!(fis, prefiltered, "prefiltered differs from fis under a constant map");
    check(&fis, Estimator::Fis, material, expected, systematic);
    check(&render(Estimator::Reference), Estimator::Reference, material, expected, systematic);
}

#[test]
fn lambertian_under_a_constant_environment_reflects_half() {
    let material = support::lambertian(0);
    // The table's directional albedo (nearest lookup) is 0.5 within 3e-5 at every theta_o below
    // 88 degrees (measured by merl's quadrature, default and finer): the horizon's cells hold
    // data in a table of a Lambertian. 1e-4 covers it.
    check_all_modes(material, |_| Some([0.5; 3]), 1e-4);
}

#[test]
fn phong_under_a_constant_environment_reflects_its_albedo() {
    let material = support::phong(0);
    let curve = AlbedoCurve::new(&material.table, 45);
    // Systematic part: the curve's quadrature (within 2e-3 of merl's default quadrature on this
    // table, measured, which is itself within 1e-3 of a 16 times finer one), and the linear
    // interpolation between nodes 2 degrees apart, relative to the smallest albedo compared.
    let systematic = 3e-3 + curve.interpolation_error / curve.at(curve.last_node())[1];
    // Beyond the last node (88 degrees) the albedo falls to 0 within 2 degrees: not compared.
    let last = curve.last_node();
    check_all_modes(material, |theta| (theta <= last).then(|| curve.at(theta)), systematic);
}
