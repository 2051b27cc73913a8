//! Inputs that make no sense are errors, never panics.

use glam::Vec3;
use render::converged::converged;
use render::{Camera, Error, Estimator, Lighting, Material, Mesh, SampleSet, Scene, Settings};

use crate::support;

fn settings(mode: Estimator, spp: u32, frames: u32) -> Settings {
    Settings { estimator: mode, spp, frames, seed: 0 }
}

fn expect_invalid(result: Result<render::Image, Error>, says: &str) {
    match result {
        Err(Error::Invalid(message)) => assert!(message.contains(says), "{message:?} does not say {says:?}"),
        other => panic!("expected an error saying {says:?}, got {:?}", other.map(|i| i.width)),
    }
}

#[test]
fn settings_must_fit_the_samples() {
    let scene = support::sphere_scene(8, 8);
    let lighting = support::constant_lighting();
    let material = support::lambertian(0);
    let render = |s: Settings| render::render(&scene, material, &lighting, &s);
    expect_invalid(render(settings(Estimator::Reference, 3, 1)), "spp 3 must be a power of two");
    expect_invalid(render(settings(Estimator::Reference, 0, 1)), "spp 0");
    expect_invalid(render(settings(Estimator::Reference, 1024, 1)), "dividing the 512 samples");
    expect_invalid(render(settings(Estimator::Fis, 4, 0)), "frames must be at least 1");
    assert!(render(settings(Estimator::Reference, 512, 1)).is_ok());
}

fn with_samples(material: &Material, samples: SampleSet) -> Material {
    Material { samples, ..material.clone() }
}

#[test]
fn sample_sets_must_be_consistent() {
    let scene = support::sphere_scene(8, 8);
    let lighting = support::constant_lighting();
    let material = support::lambertian(0);
    let s = &material.samples;
    let render = |m: &Material| render::render(&scene, m, &lighting, &settings(Estimator::Reference, 4, 1));
    let short = SampleSet { texels: s.texels[1..].to_vec(), ..s.clone() };
    expect_invalid(render(&with_samples(material, short)), "texels, expected");
    let odd = SampleSet { n_samples: 384, n_vectors: s.n_vectors * 4 / 3, ..s.clone() };
    expect_invalid(render(&with_samples(material, odd)), "must be a power of two");
    let none = SampleSet { n_slices: 0, texels: Vec::new(), ..s.clone() };
    expect_invalid(render(&with_samples(material, none)), "at least one of each");
    let mut nan = s.clone();
    nan.texels[5][3] = f32::NAN;
    expect_invalid(render(&with_samples(material, nan)), "sample texel 5 is not finite");
}

#[test]
fn prefiltered_mode_needs_layers() {
    let scene = support::sphere_scene(8, 8);
    let material = support::lambertian(0);
    let lighting = support::constant_lighting();
    let prefiltered = settings(Estimator::Prefiltered, 4, 1);
    let no_layers = Lighting { layers: Vec::new(), exponents: Vec::new(), ..lighting.clone() };
    expect_invalid(render::render(&scene, material, &no_layers, &prefiltered), "at least one prefiltered layer");
    // Other modes do not read the layers.
    assert!(render::render(&scene, material, &no_layers, &settings(Estimator::Fis, 4, 1)).is_ok());
    let mismatch = Lighting { exponents: vec![1, 4], ..lighting.clone() };
    expect_invalid(render::render(&scene, material, &mismatch, &prefiltered), "1 prefiltered layers but 2 exponents");
    let no_rows = Material { view_layers: Vec::new(), ..material.clone() };
    expect_invalid(render::render(&scene, &no_rows, &lighting, &prefiltered), "at least one view-layer entry");
    // Coordinate 1 of one layer is the smooth map past it; 1.5 is nothing.
    let past = Material { view_layers: vec![0.0, 1.0], ..material.clone() };
    assert!(render::render(&scene, &past, &lighting, &prefiltered).is_ok());
    let out_of_range = Material { view_layers: vec![0.0, 1.5], ..material.clone() };
    expect_invalid(
        render::render(&scene, &out_of_range, &lighting, &prefiltered),
        "view layer coordinate 1.5 is outside 0 to 1",
    );
}

#[test]
fn scenes_must_be_valid() {
    let material = support::lambertian(0);
    let lighting = support::constant_lighting();
    let s = settings(Estimator::Reference, 4, 1);
    let scene = support::sphere_scene(8, 8);
    let render = |scene: &Scene| render::render(scene, material, &lighting, &s);
    expect_invalid(render(&Scene { width: 0, ..scene.clone() }), "empty image");
    assert!(matches!(render(&Scene { width: 100_000, ..scene.clone() }), Err(Error::LimitExceeded(_))));
    let mut bad_index = scene.clone();
    bad_index.mesh.indices[4] = 1_000_000;
    expect_invalid(render(&bad_index), "out of range");
    let mut nan = scene.clone();
    nan.mesh.positions[3][1] = f32::NAN;
    expect_invalid(render(&nan), "non-finite position");
    let mut normals = scene.clone();
    normals.mesh.normals.pop();
    expect_invalid(render(&normals), "normals");
    let empty = Scene { mesh: Mesh::default(), ..scene.clone() };
    expect_invalid(render(&empty), "positive multiple of 3");
    expect_invalid(converged(&scene, material, &lighting, 0, 0), "at least one sample");
    expect_invalid(converged(&bad_index, material, &lighting, 4, 0), "out of range");
}

#[test]
fn cameras_must_be_valid() {
    assert!(Camera::orbit(Vec3::ZERO, 0.0, 0.0, 0.0, 1.0).is_err());
    assert!(Camera::orbit(Vec3::ZERO, f32::NAN, 0.0, 0.0, 1.0).is_err());
    assert!(Camera::orbit(Vec3::ZERO, 2.0, f32::INFINITY, 0.0, 1.0).is_err());
    assert!(Camera::orbit(Vec3::ZERO, 2.0, 0.0, 0.0, 0.0).is_err());
    assert!(Camera::orbit(Vec3::ZERO, 2.0, 0.0, 0.0, 3.2).is_err());
    assert!(Camera::orbit(Vec3::new(f32::NAN, 0.0, 0.0), 2.0, 0.0, 0.0, 1.0).is_err());
    // Elevations are kept off the poles.
    let top = Camera::orbit(Vec3::ZERO, 2.0, 0.0, 2.0, 1.0).expect("clamped");
    assert_eq!(top.elevation(), Camera::MAX_ELEVATION);
    assert!(top.view_proj(1.0).is_finite());
}
