//! The interactive previewer's GPU side: progressive accumulation (`Renderer::accumulate`) against
//! one render of as many frames, the present pass (`Presenter`) against `envmap::tonemap_rgb8`
//! on the CPU, and the debug views against the G-buffer and the specification's formulas
//! evaluated on the CPU in f64.

use std::f64::consts::FRAC_PI_2;
use std::sync::OnceLock;

use envmap::{EnvMap, MipChain, ToneMap, ToneMapping};
use gpu::preview::{Presenter, Renderer, View};
use merl::Dims;
use merl::analytic::Analytic;
use render::{Camera, Estimator, Image, Lighting, Material, Mesh, SampleSet, Scene, Settings};

use crate::support::{gpu, log};

const SIZE: usize = 48;

/// A GGX bake, small (16 slices of 4 vectors of 64 samples), with a view-layer table that reads
/// every layer: the renderers' agreement is `preview.rs`'s business, not this file's.
fn material() -> &'static Material {
    static MATERIAL: OnceLock<Material> = OnceLock::new();
    MATERIAL.get_or_init(|| {
        let table = Analytic::Ggx { alpha: 0.2, f0: [0.95, 0.64, 0.54] }.table(Dims::MERL);
        let config = importance::Config { n_theta_o: 16, n_vectors: 4, n_samples: 64, ..Default::default() };
        let tables = importance::build(&table, &config).expect("a valid config");
        let samples = SampleSet::new(&tables);
        Material::new(table, samples, vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0])
    })
}

/// A 64 x 32 sky with a bright sun (tone mapping reaches the top of its curve there), its mip
/// chain and three Phong layers.
fn lighting() -> &'static Lighting {
    static LIGHTING: OnceLock<Lighting> = OnceLock::new();
    LIGHTING.get_or_init(|| {
        let (w, h) = (64, 32);
        let sun = envmap::direction(0.1, 0.3);
        let mut rgb = Vec::with_capacity(3 * w * h);
        for y in 0..h {
            for x in 0..w {
                let d = envmap::direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let sky =
                    if d.z > 0.0 { [0.3 + 0.5 * d.z, 0.5 + 0.5 * d.z, 0.9 + 0.4 * d.z] } else { [0.2, 0.15, 0.1] };
                let boost = if d.dot(sun) > 0.97 { 50.0 } else { 1.0 };
                rgb.extend(sky.map(|c| (c * boost) as f32));
            }
        }
        let map = EnvMap::new(w, h, rgb).expect("finite, non-negative, 2:1");
        let exponents = vec![1, 16, 256];
        let config = prefilter::Config { exponents: exponents.clone(), width: 32, height: 16, ..Default::default() };
        let layers = prefilter::prefilter(&map, &config).expect("a valid config").layers;
        Lighting::new(MipChain::new(&map), layers.into_iter().map(|l| l.map).collect(), exponents).expect("a valid map")
    })
}

fn renderer() -> Renderer {
    let scene = Scene { mesh: Mesh::sphere(1.0, 32, 16), camera: Camera::default(), width: SIZE, height: SIZE };
    Renderer::new(gpu(), &scene, material(), lighting()).unwrap_or_else(|e| panic!("setting up the renderer: {e}"))
}

fn settings(frames: u32) -> Settings {
    Settings { estimator: Estimator::Reference, spp: 16, frames, seed: 3 }
}

fn bits(image: &Image) -> Vec<u32> {
    image.rgb.iter().map(|v| v.to_bits()).collect()
}

/// Frames added one call at a time are frames `0, 1, 2`: the sums are those of one render of
/// three frames, bit for bit (the same additions in the same order). A change of settings or
/// view, `restart` and a camera change start again from frame 0.
#[test]
fn accumulating_frame_by_frame_is_one_render_of_as_many_frames() {
    let mut renderer = renderer();
    for expected in 1..=3 {
        let frames = renderer.accumulate(&settings(3), View::Shaded, 1).expect("accumulating");
        assert_eq!(frames, expected);
    }
    let progressive = renderer.accumulated_image().expect("reading back");
    let whole = renderer.render_frames(&settings(3)).expect("rendering");
    assert!(bits(&progressive) == bits(&whole), "three single frames differ from one render of three");
    assert_eq!(progressive.covered, whole.covered);
    // And the three frames are not one frame thrice.
    let first = renderer.render_frames(&settings(1)).expect("rendering");
    assert!(bits(&first) != bits(&whole), "frames 1 and 2 added nothing new");

    // render_frames leaves its frames to go on from, for the same picture.
    assert_eq!(renderer.frames_accumulated(), 1);
    assert_eq!(renderer.accumulate(&settings(1), View::Shaded, 2).expect("accumulating"), 3);
    assert_eq!(renderer.accumulate(&settings(2), View::Shaded, 1).expect("accumulating"), 1, "another picture goes on");
    let other_seed = Settings { seed: 4, ..settings(2) };
    assert_eq!(renderer.accumulate(&other_seed, View::Shaded, 1).expect("accumulating"), 1, "a new seed goes on");
    assert_eq!(renderer.accumulate(&other_seed, View::Normal, 1).expect("accumulating"), 1, "a new view goes on");
    renderer.restart();
    assert_eq!(renderer.frames_accumulated(), 0);
    assert!(renderer.accumulated_image().is_err(), "an empty accumulation read back");
    renderer.accumulate(&settings(2), View::Shaded, 2).expect("accumulating");
    let camera = Camera::orbit(glam::Vec3::ZERO, 3.0, 0.5, 0.3, 45f32.to_radians()).expect("a valid camera");
    renderer.set_camera(&camera).expect("moving the camera");
    assert_eq!(renderer.frames_accumulated(), 0, "a camera change kept the accumulation");
    let invalid = Settings { spp: 3, ..settings(1) };
    assert!(renderer.accumulate(&invalid, View::Shaded, 1).is_err(), "spp 3 accepted");
}

/// The present pass at the image's size is `envmap::tonemap_rgb8` of the image
/// `render_frames` reads back, for plain and sRGB targets in both byte orders, at two exposures.
/// Tolerance for plain targets: one 8-bit step, and only for a value whose exact level (`255`
/// times the tone-mapped value, in f64) lies within a quarter step of a rounding boundary.
/// Vulkan lets the conversion to 8 bits give either neighbour and only recommends rounding to
/// nearest; the curve in f32 at WGSL's accuracy moves a level by some 5e-4 of a step. Measured:
/// lavapipe rounds to nearest (no value differs); an NVIDIA H200 differs in 2% of the values, all
/// within 0.061 of a step from a boundary. For sRGB targets: one step anywhere, because the pass
/// decodes and the hardware encodes again, rounding its own way (lavapipe differs in about 13% of
/// the values). A wrong curve, exposure or channel order is off by tens of steps in most values;
/// an exposure off by 1% moves mid-tone levels by about half a step (measured: 40% of the values
/// differ, up to 0.47 of a step from a boundary).
#[test]
fn the_present_pass_tone_maps_like_the_pictures() {
    let mut renderer = renderer();
    let image = renderer.render_frames(&settings(2)).expect("rendering");
    let auto = render::metrics::auto_tone_mapping(lighting().mips.level(0)).exposure_ev;
    for format in [
        wgpu::TextureFormat::Rgba8Unorm,
        wgpu::TextureFormat::Bgra8Unorm,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Bgra8UnormSrgb,
    ] {
        let presenter = Presenter::new(gpu(), format).expect("a presenter");
        for exposure_ev in [auto, auto + 3.0] {
            let expected = envmap::tonemap_rgb8(&image.rgb, &ToneMapping { exposure_ev, tone_map: ToneMap::Reinhard });
            let drawn = presenter.draw_rgb8(&renderer, (SIZE as u32, SIZE as u32), exposure_ev).expect("presenting");
            assert_eq!(drawn.len(), expected.len());
            let differences: Vec<u8> = drawn.iter().zip(&expected).map(|(a, b)| a.abs_diff(*b)).collect();
            let largest = differences.iter().copied().max().unwrap_or(0);
            let differing = differences.iter().filter(|&&d| d > 0).count();
            // How far the exact level of each differing value is from a rounding boundary.
            let preview = ToneMapping { exposure_ev, tone_map: ToneMap::Reinhard };
            let from_boundary = |j: usize| {
                let level = 255.0 * envmap::tonemap(f64::from(image.rgb[j]), &preview);
                (level - level.floor() - 0.5).abs()
            };
            let furthest = (0..drawn.len()).filter(|&j| differences[j] > 0).map(from_boundary).fold(0.0, f64::max);
            log(&format!(
                "present {format:?} at {exposure_ev:+.2} EV: {differing} of {} values differ, by {largest} at most, \
                 {furthest:.2e} of a step from a rounding boundary at most",
                drawn.len()
            ));
            assert!(largest <= 1, "{format:?}: a value differs by {largest} steps");
            if !format.is_srgb() {
                assert!(
                    furthest < 0.25,
                    "{format:?}: a value {furthest} of a step from a rounding boundary differs ({differing} differ)"
                );
            }
        }
    }
}

/// In a wider target the image is drawn at its own scale in the middle, the margins in the
/// background grey (0.125 encoded: 32).
#[test]
fn the_present_pass_centres_the_image() {
    let mut renderer = renderer();
    renderer.render_frames(&settings(1)).expect("rendering");
    let presenter = Presenter::new(gpu(), wgpu::TextureFormat::Rgba8Unorm).expect("a presenter");
    let exposure_ev = 0.0;
    let own = presenter.draw_rgb8(&renderer, (SIZE as u32, SIZE as u32), exposure_ev).expect("presenting");
    let (width, margin) = (2 * SIZE, SIZE / 2);
    let wide = presenter.draw_rgb8(&renderer, (width as u32, SIZE as u32), exposure_ev).expect("presenting");
    for y in 0..SIZE {
        let row = &wide[3 * y * width..3 * (y + 1) * width];
        assert!(row[..3 * margin].iter().all(|&v| v == 32), "left margin of row {y}");
        assert!(row[3 * (margin + SIZE)..].iter().all(|&v| v == 32), "right margin of row {y}");
        assert_eq!(&row[3 * margin..3 * (margin + SIZE)], &own[3 * y * SIZE..3 * (y + 1) * SIZE], "row {y}");
    }
}

/// The debug views hold what the specification says the estimators read, evaluated on the CPU
/// in f64 from the G-buffer's interpolated position and normal: the normal itself (exactly: the
/// same interpolation), the layer coordinate `render::view_layer` (to 1e-5: f32 arithmetic on
/// coordinates below 3) and the slice `min(floor(theta_o / (pi / 2) S + 1/2), S - 1)`. A pixel
/// whose `theta_o` lies within f32 rounding of a slice boundary may fall either way: a few in an
/// image of hundreds of boundary-free pixels (measured: none), where a wrong slice formula moves
/// whole bands, and a wrong interpolation of the rows whole rings.
#[test]
fn debug_views_show_what_the_estimators_read() {
    let mut renderer = renderer();
    let gbuffer = renderer.gbuffer().expect("the g-buffer");
    let eye = renderer.camera().eye().as_dvec3();
    let material = material();
    let slices = material.samples.n_slices;

    renderer.accumulate(&settings(1), View::Normal, 1).expect("accumulating normals");
    let normals = renderer.accumulated_image().expect("reading back");
    renderer.accumulate(&settings(1), View::Layer, 1).expect("accumulating layers");
    let layers = renderer.accumulated_image().expect("reading back");
    renderer.accumulate(&settings(1), View::Slice, 1).expect("accumulating slices");
    let slice_view = renderer.accumulated_image().expect("reading back");

    let (mut mismatches, mut covered, mut seen_layers, mut seen_slices) = (0, 0, Vec::new(), Vec::new());
    for i in 0..SIZE * SIZE {
        if gbuffer.triangle[i].is_none() {
            continue;
        }
        covered += 1;
        let value = |image: &Image| [image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]];
        assert_eq!(value(&normals), gbuffer.normal[i], "normal at pixel {i}");
        let n = glam::Vec3::from(gbuffer.normal[i]).as_dvec3();
        let wo = (eye - glam::Vec3::from(gbuffer.position[i]).as_dvec3()).normalize();
        let cos_o = n.dot(wo);
        if cos_o <= 0.0 {
            assert_eq!(value(&layers), [0.0; 3], "layer at pixel {i}, facing away");
            assert_eq!(value(&slice_view), [0.0; 3], "slice at pixel {i}, facing away");
            continue;
        }
        let layer = render::view_layer(&material.view_layers, cos_o) as f32;
        let theta_o = (wo - cos_o * n).length().atan2(cos_o);
        let slice = ((theta_o / FRAC_PI_2 * slices as f64 + 0.5).floor() as usize).min(slices - 1) as f32;
        let [shown, one, zero] = value(&layers);
        if (shown - layer).abs() > 1e-5 || [one, zero] != [1.0, 0.0] || value(&slice_view) != [slice, 1.0, 0.0] {
            mismatches += 1;
        }
        seen_layers.push(layer.round() as u32);
        seen_slices.push(slice as u32);
    }
    seen_layers.sort_unstable();
    seen_layers.dedup();
    seen_slices.sort_unstable();
    seen_slices.dedup();
    log(&format!(
        "debug views: {covered} covered pixels, {mismatches} with another layer or slice; layers {seen_layers:?}, {} slices",
        seen_slices.len()
    ));
    assert!(mismatches <= 3, "{mismatches} pixels show another layer or slice");
    // The views are not trivially right: every layer and most slices appear.
    assert_eq!(seen_layers, vec![0, 1, 2]);
    assert!(seen_slices.len() >= slices / 2, "slices {seen_slices:?}");
}

/// Pixels no triangle covers show the environment in a debug view too: the same radiance as in
/// the shaded view.
#[test]
fn debug_views_keep_the_environment_behind_the_mesh() {
    let mut renderer = renderer();
    let shaded = renderer.render_frames(&settings(1)).expect("rendering");
    renderer.accumulate(&settings(1), View::Slice, 1).expect("accumulating slices");
    let slices = renderer.accumulated_image().expect("reading back");
    let mut background = 0;
    for (i, covered) in shaded.covered.iter().enumerate() {
        if !covered {
            background += 1;
            assert_eq!(&slices.rgb[3 * i..3 * i + 3], &shaded.rgb[3 * i..3 * i + 3], "pixel {i}");
        }
    }
    assert!(background > SIZE * SIZE / 4, "only {background} background pixels");
}
