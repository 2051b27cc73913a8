//! Known answers under a constant environment `L`: the value of a covered pixel is the table's
//! directional albedo at the pixel's `theta_o` times `L` (Lambertian: exactly 0.5 L), the
//! background is `L` itself, and the three modes give the same image (every mip level and
//! layer of a constant map is the constant).

use std::f64::consts::{E, FRAC_PI_2};

use glam::DVec3;
use merl::{Interp, luminance};
use render::{Image, Material, Mode, Settings, raster};

use crate::support::{self, AlbedoCurve, L};

const SIZE: usize = 32;
const SPP: u32 = 64;
const FRAMES: u32 = 16;

/// The relative standard deviation of one sample's weight `Y(f) cos theta_i / pdf` in each slice,
/// over all its `V N` baked samples, at the slice's own `wo`. Computed from the texels here, not
/// by the renderer.
fn slice_spread(material: &Material) -> Vec<f64> {
    let s = &material.samples;
    let per_slice = s.n_vectors * s.n_samples;
    (0..s.n_slices)
        .map(|k| {
            let wo = merl::spherical_dir(k as f64 / s.n_slices as f64 * FRAC_PI_2, 0.0);
            let weights: Vec<f64> = s.texels[k * per_slice..(k + 1) * per_slice]
                .iter()
                .map(|t| {
                    let wi = DVec3::new(t[0].into(), t[1].into(), t[2].into());
                    if t[3] > 0.0 && wi.z > 0.0 {
                        let f = material.table.lookup(wi, wo, Interp::Nearest).map_or(0.0, luminance);
                        f * wi.z / f64::from(t[3])
                    } else {
                        0.0
                    }
                })
                .collect();
            let mean = weights.iter().sum::<f64>() / per_slice as f64;
            let variance = weights.iter().map(|w| (w - mean).powi(2)).sum::<f64>() / (per_slice - 1) as f64;
            variance.sqrt() / mean
        })
        .collect()
}

/// The slice the renderers pick for `theta_o` (crate documentation, "Samples").
fn slice_of(theta_o: f64, n_slices: usize) -> usize {
    ((theta_o / FRAC_PI_2 * n_slices as f64 + 0.5).floor() as usize).min(n_slices - 1)
}

/// The relative tolerance of a pixel in slice `k`: five standard deviations of the two parts of
/// its error. (1) The frames: each takes `spp` consecutive samples of an Owen-scrambled Sobol'
/// vector, an estimate whose variance is at most `e` times that of `spp` independent samples
/// (Owen 1997, for (0, m, 2)-nets in base 2), and the frames choose independently. (2) The
/// bake: the renderer's expectation is the mean over the slice's `V N` samples, itself off the
/// integral by about `sigma / sqrt(V N)`.
fn noise_tolerance(spread: f64, material: &Material) -> f64 {
    let s = &material.samples;
    5.0 * (E.sqrt() * spread / f64::from(SPP * FRAMES).sqrt() + spread / ((s.n_vectors * s.n_samples) as f64).sqrt())
}

/// Holds every covered pixel of `image` to `expected(theta_o)`, per pixel and on average; checks
/// that uncovered pixels are `L` exactly and that black pixels are black.
fn check(image: &Image, material: &Material, expected: impl Fn(f64) -> Option<[f64; 3]>, systematic: f64) {
    let scene = support::sphere_scene(SIZE, SIZE);
    let gbuffer = raster::rasterize(&scene.mesh, scene.camera.view_proj(1.0), SIZE, SIZE).expect("valid scene");
    let theta_o = support::theta_o(&gbuffer, &scene.camera);
    let spread = slice_spread(material);
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
        let tolerance = noise_tolerance(spread[k], material) + systematic;
        for c in 0..3 {
            let relative = f64::from(rgb[c]) / (expected[c] * f64::from(L[c])) - 1.0;
            assert!(
                relative.abs() <= tolerance,
                "pixel {i} (theta_o {:.2} deg, slice {k}), channel {c}: {} vs {}, relative error {relative:.2e} > {tolerance:.2e}",
                theta.to_degrees(),
                rgb[c],
                expected[c] * f64::from(L[c]),
            );
            sum += relative;
            count += 1;
        }
    }
    assert!(count > 3 * 300, "only {count} values checked");
    // The mean over pixels still carries the bake's error in full (pixels share its samples),
    // but no longer the frames'.
    let mean = sum / count as f64;
    let s = &material.samples;
    let bound = 5.0 * max_spread / ((s.n_vectors * s.n_samples) as f64).sqrt() + systematic;
    assert!(mean.abs() <= bound, "mean relative error {mean:.2e} exceeds {bound:.2e}");
}

fn render_all_modes(material: &Material) -> Image {
    let scene = support::sphere_scene(SIZE, SIZE);
    let lighting = support::constant_lighting();
    let images: Vec<Image> = Mode::ALL
        .iter()
        .map(|&mode| {
            let settings = Settings { mode, spp: SPP, frames: FRAMES, seed: 7 };
            render::render(&scene, material, &lighting, &settings).expect("valid inputs")
        })
        .collect();
    // Every lookup of a constant map returns the constant: the modes cannot differ.
    assert_eq!(images[0], images[1], "fis differs from the reference under a constant map");
    assert_eq!(images[0], images[2], "prefiltered differs from the reference under a constant map");
    images.into_iter().next().expect("three modes")
}

#[test]
fn lambertian_under_a_constant_environment_reflects_half() {
    let material = support::lambertian(0);
    let image = render_all_modes(material);
    // The table's directional albedo (nearest lookup) is 0.5 within 3e-5 at every theta_o below
    // 88 degrees (measured by merl's quadrature, default and finer): the horizon's cells hold
    // data in a table of a Lambertian. 1e-4 covers it.
    check(&image, material, |_| Some([0.5; 3]), 1e-4);
}

#[test]
fn phong_under_a_constant_environment_reflects_its_albedo() {
    let material = support::phong(0);
    let image = render_all_modes(material);
    let curve = AlbedoCurve::new(&material.table, 45);
    // Systematic part: the curve's quadrature (within 2e-3 of merl's default quadrature on this
    // table, measured, which is itself within 1e-3 of a 16 times finer one), and the linear
    // interpolation between nodes 2 degrees apart, relative to the smallest albedo compared.
    let systematic = 3e-3 + curve.interpolation_error / curve.at(curve.last_node())[1];
    // Beyond the last node (88 degrees) the albedo falls to 0 within 2 degrees: not compared.
    check(&image, material, |theta| (theta <= curve.last_node()).then(|| curve.at(theta)), systematic);
}
