//! The converged estimate against the known answers and against the reference renderer.
//!
//! Tolerances come from the estimators' own spread: two estimates made independently (other
//! seeds, other bakes) differ by `sqrt(2)` times the noise of one, so the noise of the mean of
//! two is `|a1 - a2| / 2` (Euclidean norms over every covered value). Without bias the distance
//! between two such means is the root of the sum of their squared noises; we allow 3 times that:
//! the norms sum hundreds of pixels, whose errors are correlated (pixels of one slice share the
//! bake's samples) but far from a single degree of freedom, so the ratio stays well within 3.

use render::converged::converged;
use render::{Estimator, Image, Material, Settings, metrics};

use crate::support::{self, AlbedoCurve, L};

const SIZE: usize = 24;
const ROUNDS: u32 = 512;

/// The covered values of an image, in order.
fn covered(image: &Image) -> Vec<f32> {
    image.rgb.chunks_exact(3).zip(&image.covered).filter(|(_, c)| **c).flat_map(|(rgb, _)| rgb.to_vec()).collect()
}

fn mean(a: &[f32], b: &[f32]) -> Vec<f32> {
    a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect()
}

fn distance(a: &[f32], b: &[f32]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2)).sum::<f64>().sqrt()
}

/// Holds the converged estimate under a constant environment to `expected(theta_o)` where it is
/// known, whose values are off by at most `relative` of themselves plus `absolute` (albedo
/// units).
fn check_known_answer(material: &Material, expected: impl Fn(f64) -> Option<[f64; 3]>, relative: f64, absolute: f64) {
    let scene = support::sphere_scene(SIZE, SIZE);
    let [a, b] = [1, 2].map(|seed| {
        converged(&scene, material, &support::constant_lighting(), ROUNDS, seed).expect("valid inputs").rgb
    });
    let gbuffer = render::raster::rasterize(&scene.mesh, scene.camera.view_proj(1.0), SIZE, SIZE).expect("valid");
    let (mut kept_a, mut kept_b, mut answer) = (Vec::new(), Vec::new(), Vec::new());
    for (i, theta) in support::theta_o(&gbuffer, &scene.camera).iter().enumerate() {
        let Some(theta) = theta else { continue };
        let Some(albedo) = expected(*theta) else { continue };
        kept_a.extend_from_slice(&a[3 * i..3 * i + 3]);
        kept_b.extend_from_slice(&b[3 * i..3 * i + 3]);
        answer.extend((0..3).map(|c| (albedo[c] * f64::from(L[c])) as f32));
    }
    assert!(answer.len() > 3 * 200, "only {} values compared", answer.len());
    let (estimate, noise) = (mean(&kept_a, &kept_b), distance(&kept_a, &kept_b) / 2.0);
    let norm = distance(&answer, &vec![0.0; answer.len()]);
    // The norm of `absolute L` over every compared value.
    let radiance_norm =
        (answer.len() as f64 / 3.0).sqrt() * L.iter().map(|&l| f64::from(l).powi(2)).sum::<f64>().sqrt();
    let error = distance(&estimate, &answer);
    let bound = 3.0 * noise + relative * norm + absolute * radiance_norm;
    assert!(
        error <= bound,
        "relative error {:.2e} exceeds {:.2e} (noise {:.2e})",
        error / norm,
        bound / norm,
        noise / norm
    );
}

#[test]
fn lambertian_under_a_constant_environment_reflects_half() {
    // The table's albedo is 0.5 within 3e-5 (see known_answer).
    check_known_answer(support::lambertian(0), |_| Some([0.5; 3]), 1e-4, 0.0);
}

#[test]
fn phong_under_a_constant_environment_reflects_its_albedo() {
    let material = support::phong(0);
    let curve = AlbedoCurve::new(&material.table, 45);
    // The curve's quadrature (relative, see known_answer) and interpolation (absolute); beyond
    // its last node (88 degrees) the albedo falls to 0 within 2 degrees: not compared.
    let expected = |theta: f64| (theta <= curve.last_node()).then(|| curve.at(theta));
    check_known_answer(material, expected, 3e-3, curve.interpolation_error);
}

/// The converged estimate against the reference mode under the sky (sun included): the same
/// integral, by estimators that share nothing but the lookups.
fn check_sky(materials: [&Material; 2]) {
    let scene = support::sphere_scene(SIZE, SIZE);
    let lighting = support::sky_lighting();
    let [a, b] = [1, 2].map(|seed| covered(&converged(&scene, materials[0], &lighting, ROUNDS, seed).expect("valid")));
    let (estimate, estimate_noise) = (mean(&a, &b), distance(&a, &b) / 2.0);
    // Two bakes and two render seeds: the reference's noise includes its bake's own error.
    let [a, b] = [0, 1].map(|i| {
        let settings = Settings { estimator: Estimator::Reference, spp: 64, frames: 64, seed: i as u32 };
        covered(&render::render(&scene, materials[i], &lighting, &settings).expect("valid inputs"))
    });
    let (reference, reference_noise) = (mean(&a, &b), distance(&a, &b) / 2.0);
    let norm = distance(&reference, &vec![0.0; reference.len()]);
    let error = distance(&estimate, &reference);
    let bound = 3.0 * estimate_noise.hypot(reference_noise);
    assert!(
        error <= bound,
        "relative error {:.2e} exceeds {:.2e} (noise: converged {:.2e}, reference {:.2e})",
        error / norm,
        bound / norm,
        estimate_noise / norm,
        reference_noise / norm
    );
    // The bound stays meaningful: a few percent, not the size of the image.
    assert!(bound / norm < 0.1, "noise too large for a useful comparison: {:.2e}", bound / norm);
}

#[test]
fn lambertian_under_a_sky_agrees_with_the_reference() {
    check_sky([support::lambertian(0), support::lambertian(1)]);
}

#[test]
fn phong_under_a_sky_agrees_with_the_reference() {
    check_sky([support::phong(0), support::phong(1)]);
}

#[test]
fn background_is_the_environment() {
    let scene = support::sphere_scene(SIZE, SIZE);
    let lighting = support::sky_lighting();
    let image = converged(&scene, support::lambertian(0), &lighting, 1, 0).expect("valid inputs");
    let settings = Settings { estimator: Estimator::Reference, spp: 1, frames: 1, seed: 0 };
    let rendered = render::render(&scene, support::lambertian(0), &lighting, &settings).expect("valid inputs");
    assert_eq!(image.covered, rendered.covered);
    for (i, (a, b)) in image.rgb.chunks_exact(3).zip(rendered.rgb.chunks_exact(3)).enumerate() {
        if !image.covered[i] {
            assert_eq!(a, b, "background pixel {i}");
        }
    }
    assert!(metrics::mean_luminance(&image) > 0.0);
}
