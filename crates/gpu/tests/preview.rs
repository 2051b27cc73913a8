//! Holds the GPU renderer (`gpu::preview`) to the CPU renderer (`render::render`), which follows
//! the same specification in f64: the same coverage, and images that differ by rounding only.
//! Also an independent known answer (a Lambertian sphere under a constant sky), the orientation of
//! the background, determinism, and that a deliberately wrong render fails the comparison.
//!
//! Materials are analytic MERL tables with importance samples baked as `merl-importance` does;
//! the lighting is a synthetic sky with a sun, its mip chain and its Phong-prefiltered layers.
//! These tests run on whatever adapter `Gpu::new` finds (lavapipe in CI) and never skip.

use std::path::PathBuf;
use std::sync::OnceLock;

use envmap::{EnvMap, MipChain, ToneMapping};
use gpu::preview::Renderer;
use gpu::{Gpu, GpuError};
use merl::Dims;
use merl::analytic::Analytic;
use render::metrics::{psnr_db, relative_error, tonemap};
use render::{Camera, Estimator, Image, Lighting, Material, Mesh, SampleSet, Scene, Settings};

use crate::fixtures::bandwidths;
use crate::support::{gl_gpu, gpu, log};

/// PSNR of the tone-mapped GPU image against the CPU's, in dB, must reach this. The two differ by
/// f32 against f64 arithmetic (1e-6 relative, far below one 8-bit step) plus the rare sample that
/// rounding moves across a boundary where a nearest choice flips: a MERL cell, a slice (`theta_o`
/// goes through lavapipe's atan2, good to 3e-6 rad; Vulkan allows far worse), a pixel centre on a
/// triangle edge. Such a pixel changes by up to the noise of one sample in `spp`. Measured on
/// lavapipe: 80 dB and above (identical pictures for the Lambertian). The estimator's noise, a
/// wrong sample choice or a wrong lookup gives 20 to 36 dB.
const MIN_PSNR_DB: f64 = 45.0;

/// The relative error `|gpu - cpu| / |cpu|` of the linear images must stay below this: f32 alone
/// gives about 1e-6 (measured for the Lambertian, where no cell boundary matters), and the flips
/// above change a few pixels by a fraction of their value (measured: 2e-4 at most).
const MAX_RELATIVE_ERROR: f64 = 1e-3;

/// [`MAX_RELATIVE_ERROR`] for an adaptive frame: a sample flipped in a shaded block of few
/// samples reaches every pixel up-sampled from it. Measured on lavapipe: one block of the 2 x 2
/// anti-aliased frame at 4 spp, 29 output pixels up to 6% apart, 1.8e-3 over the image (70.6 dB).
const MAX_ADAPTIVE_RELATIVE_ERROR: f64 = 4e-3;

/// Pixel centres within rounding of a triangle edge may fall either way on the GPU and the CPU:
/// the CPU projects with glam's f32 arithmetic, the GPU may fuse multiply-adds, and a snapped
/// vertex moves by 1/256 pixel when its coordinate sits on a rounding boundary. A handful at most
/// in an image of thousands of edge pixels (measured: none); a wrong rule (culling, fill rule,
/// flipped y, the depth test) moves dozens to hundreds.
const MAX_COVERAGE_MISMATCHES: usize = 4;

const SIZE: usize = 64;

/// A bake of an analytic table: 90 slices of 8 vectors of 64 samples. The view-layer table picks
/// sharper layers at grazing views, where the lobe narrows, so every layer is read somewhere.
fn material(brdf: Analytic) -> Material {
    let table = brdf.table(Dims::MERL);
    let config = importance::Config { n_theta_o: 90, n_vectors: 8, n_samples: 64, ..Default::default() };
    let tables = importance::build(&table, &config).expect("a valid config");
    Material::new(table, SampleSet::new(&tables), vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0])
}

fn lambertian() -> &'static Material {
    static MATERIAL: OnceLock<Material> = OnceLock::new();
    MATERIAL.get_or_init(|| material(Analytic::Lambertian { albedo: [0.5, 0.4, 0.3] }))
}

fn phong() -> &'static Material {
    static MATERIAL: OnceLock<Material> = OnceLock::new();
    MATERIAL.get_or_init(|| material(Analytic::Phong { n: 50.0, ks: [0.9, 0.7, 0.5], kd: [0.0; 3] }))
}

/// Sharp enough that neighbouring MERL cells differ, so a wrong cell or frame shows.
fn ggx() -> &'static Material {
    static MATERIAL: OnceLock<Material> = OnceLock::new();
    MATERIAL.get_or_init(|| material(Analytic::Ggx { alpha: 0.15, f0: [0.9, 0.6, 0.3] }))
}

/// A 256 x 128 sky: a gradient from a bright zenith to a dim ground, and a sun disk (8 degrees
/// across, 30 times the zenith) at 40 degrees elevation, azimuth 30 degrees.
fn sky() -> &'static EnvMap {
    static MAP: OnceLock<EnvMap> = OnceLock::new();
    MAP.get_or_init(|| {
        let (w, h) = (256, 128);
        let sun = envmap::direction(30.0 / 360.0, 50.0 / 180.0);
        let mut rgb = Vec::with_capacity(3 * w * h);
        for y in 0..h {
            for x in 0..w {
                let d = envmap::direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
                let sky =
                    if d.z > 0.0 { [0.3 + 0.5 * d.z, 0.5 + 0.5 * d.z, 0.9 + 0.4 * d.z] } else { [0.2, 0.15, 0.1] };
                let boost = if d.dot(sun) > 4f64.to_radians().cos() { 30.0 } else { 1.0 };
                rgb.extend(sky.map(|c| (c * boost) as f32));
            }
        }
        EnvMap::new(w, h, rgb).expect("finite, non-negative, 2:1")
    })
}

/// The sky's mip chain and four Phong layers of 64 x 32 from `prefilter`.
fn sky_lighting() -> &'static Lighting {
    static LIGHTING: OnceLock<Lighting> = OnceLock::new();
    LIGHTING.get_or_init(|| {
        let exponents = vec![1, 8, 64, 512];
        let config = prefilter::Config { exponents: exponents.clone(), width: 64, height: 32, ..Default::default() };
        let prefiltered = prefilter::prefilter(sky(), &config).expect("a valid config");
        let layers = prefiltered.layers.into_iter().map(|layer| layer.map).collect();
        Lighting::new(MipChain::new(sky()), layers, exponents).expect("a valid map")
    })
}

/// A unit sphere before the default camera (from `+x`, horizontal): the sky's horizon crosses the
/// background's middle and the sun reflects in the sphere's upper half.
fn sphere_scene(size: usize) -> Scene {
    Scene { mesh: Mesh::sphere(1.0, 48, 24), camera: Camera::default(), width: size, height: size }
}

fn settings(mode: Estimator) -> Settings {
    Settings { estimator: mode, spp: 16, frames: 2, seed: 7 }
}

fn renderer(scene: &Scene, material: &Material, lighting: &Lighting) -> Renderer {
    renderer_on(gpu(), scene, material, lighting)
}

fn renderer_on(gpu: &Gpu, scene: &Scene, material: &Material, lighting: &Lighting) -> Renderer {
    Renderer::new(gpu, scene, material, lighting).unwrap_or_else(|e| panic!("setting up the renderer: {e}"))
}

fn render_gpu(renderer: &mut Renderer, settings: &Settings) -> Image {
    renderer.render_frames(settings).unwrap_or_else(|e| panic!("rendering on the gpu: {e}"))
}

fn render_cpu(scene: &Scene, material: &Material, lighting: &Lighting, settings: &Settings) -> Image {
    render::render(scene, material, lighting, settings).unwrap_or_else(|e| panic!("rendering on the cpu: {e}"))
}

/// The exposure every picture of a comparison shares: the sky's automatic one.
fn preview() -> ToneMapping {
    render::metrics::auto_tone_mapping(sky())
}

/// PSNR of the pictures and relative error of the linear values, GPU against CPU.
fn compare(gpu: &Image, cpu: &Image) -> (f64, f64) {
    let preview = preview();
    (psnr_db(&tonemap(gpu, &preview), &tonemap(cpu, &preview)), relative_error(&gpu.rgb, &cpu.rgb))
}

/// Writes the pictures of a failed comparison next to the test binary's scratch folder, so that
/// nobody has to run it again to see what differs.
fn write_pictures(name: &str, gpu: &Image, cpu: &Image) -> PathBuf {
    let folder = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("preview");
    let _ = std::fs::create_dir_all(&folder);
    let preview = preview();
    let (a, b) = (tonemap(gpu, &preview), tonemap(cpu, &preview));
    let pictures =
        [("actual", a.clone()), ("expected", b.clone()), ("difference", render::metrics::difference_rgb8(&a, &b))];
    for (kind, rgb8) in pictures {
        let _ = envmap::write_png_rgb8(&folder.join(format!("{name}-{kind}.png")), gpu.width, gpu.height, &rgb8);
    }
    folder
}

/// The pixels whose coverage differs, as `(x, y)`.
fn coverage_mismatches(a: &[bool], b: &[bool], width: usize) -> Vec<(usize, usize)> {
    a.iter().zip(b).enumerate().filter(|(_, (a, b))| a != b).map(|(i, _)| (i % width, i / width)).collect()
}

/// One GPU render against the CPU's with the same inputs.
fn check_against_cpu(name: &str, material: &Material, mode: Estimator) {
    check_against_cpu_on(gpu(), name, material, mode);
}

/// [`check_against_cpu`] on the device `on`.
fn check_against_cpu_on(on: &Gpu, name: &str, material: &Material, mode: Estimator) {
    let scene = sphere_scene(SIZE);
    let lighting = sky_lighting();
    let settings = settings(mode);
    let gpu = render_gpu(&mut renderer_on(on, &scene, material, lighting), &settings);
    let cpu = render_cpu(&scene, material, lighting, &settings);
    let mismatches = coverage_mismatches(&gpu.covered, &cpu.covered, SIZE);
    let (psnr, relative) = compare(&gpu, &cpu);
    log(&format!(
        "{name} {}: psnr {psnr:.1} dB, relative error {relative:.2e}, coverage mismatches {mismatches:?}",
        mode.name()
    ));
    let covered = cpu.covered.iter().filter(|c| **c).count();
    assert!(covered > SIZE * SIZE / 4, "{name}: the sphere covers only {covered} pixels");
    let ok = mismatches.len() <= MAX_COVERAGE_MISMATCHES && psnr >= MIN_PSNR_DB && relative < MAX_RELATIVE_ERROR;
    if !ok {
        let folder = write_pictures(&format!("{name}-{}", mode.name()), &gpu, &cpu);
        panic!(
            "{name} {}: psnr {psnr:.1} dB (at least {MIN_PSNR_DB}), relative error {relative:.2e} (below \
             {MAX_RELATIVE_ERROR:e}), coverage mismatches {mismatches:?} (at most {MAX_COVERAGE_MISMATCHES}); \
             pictures in {}",
            mode.name(),
            folder.display()
        );
    }
}

#[test]
fn lambertian_reference_matches_the_cpu() {
    check_against_cpu("lambertian", lambertian(), Estimator::Reference);
}

#[test]
fn lambertian_fis_matches_the_cpu() {
    check_against_cpu("lambertian", lambertian(), Estimator::Fis);
}

#[test]
fn lambertian_prefiltered_matches_the_cpu() {
    check_against_cpu("lambertian", lambertian(), Estimator::Prefiltered);
}

#[test]
fn phong_reference_matches_the_cpu() {
    check_against_cpu("phong", phong(), Estimator::Reference);
}

#[test]
fn phong_fis_matches_the_cpu() {
    check_against_cpu("phong", phong(), Estimator::Fis);
}

#[test]
fn phong_prefiltered_matches_the_cpu() {
    check_against_cpu("phong", phong(), Estimator::Prefiltered);
}

#[test]
fn ggx_reference_matches_the_cpu() {
    check_against_cpu("ggx", ggx(), Estimator::Reference);
}

#[test]
fn ggx_fis_matches_the_cpu() {
    check_against_cpu("ggx", ggx(), Estimator::Fis);
}

#[test]
fn ggx_prefiltered_matches_the_cpu() {
    check_against_cpu("ggx", ggx(), Estimator::Prefiltered);
}

/// The GGX material with its BRDF read from a Haar wavelet encoding of its table (16 x 16 grid,
/// 4:1, 8-bit codes) at a fractional level of detail, so that the WGSL decoder's every step
/// (bilinear cells, synthesis, level blend, dequantized codes) is held to `wavelet_brdf`.
fn ggx_wavelet() -> &'static Material {
    static MATERIAL: OnceLock<Material> = OnceLock::new();
    MATERIAL.get_or_init(|| {
        let material = ggx();
        let grid = wavelet_brdf::Grid::new(16).expect("a power of two");
        let resampled = wavelet_brdf::resample_table(grid, &material.table);
        let config = wavelet_brdf::Config { keep: wavelet_brdf::Keep::Ratio(4), quantize: true, ..Default::default() };
        let encoded = wavelet_brdf::encode(&resampled, config).expect("a valid config");
        let brdf = wavelet_brdf::Decoded::from_payload(&encoded.payload).expect("a valid payload");
        Material { wavelet_brdf: Some(render::WaveletBrdfLod { brdf, lod: 0.5 }), ..material.clone() }
    })
}

#[test]
fn wavelet_reference_matches_the_cpu() {
    check_against_cpu("ggx-wavelet", ggx_wavelet(), Estimator::Reference);
}

#[test]
fn wavelet_prefiltered_matches_the_cpu() {
    check_against_cpu("ggx-wavelet", ggx_wavelet(), Estimator::Prefiltered);
}

/// The wavelet render is not the table's: the comparison sees the encoding's error.
#[test]
fn a_wavelet_render_differs_from_the_table_render() {
    let scene = sphere_scene(SIZE);
    let settings = settings(Estimator::Reference);
    let wavelet = render_gpu(&mut renderer(&scene, ggx_wavelet(), sky_lighting()), &settings);
    let table = render_cpu(&scene, ggx(), sky_lighting(), &settings);
    let (psnr, relative) = compare(&wavelet, &table);
    log(&format!("ggx wavelet against the table: psnr {psnr:.1} dB, relative error {relative:.2e}"));
    assert!(psnr < MIN_PSNR_DB && relative > MAX_RELATIVE_ERROR, "psnr {psnr:.1} dB, relative error {relative:.2e}");
}

/// The comparison can fail: the same render with another seed draws other samples, and the
/// difference is the estimator's noise, far above the rounding the bar allows (one frame of 4
/// samples of each strategy: the reference's multiple importance sampling is quiet enough at the
/// other tests' 2 frames of 16 that two seeds would pass the bar less 5 dB, 42.5 dB apart).
#[test]
fn a_render_with_another_seed_fails_the_comparison() {
    let scene = sphere_scene(SIZE);
    let settings = Settings { spp: 4, frames: 1, ..settings(Estimator::Reference) };
    let gpu =
        render_gpu(&mut renderer(&scene, ggx(), sky_lighting()), &Settings { seed: settings.seed + 1, ..settings });
    let cpu = render_cpu(&scene, ggx(), sky_lighting(), &settings);
    let (psnr, relative) = compare(&gpu, &cpu);
    log(&format!("ggx reference, seeds 8 and 7: psnr {psnr:.1} dB, relative error {relative:.2e}"));
    assert!(psnr < MIN_PSNR_DB - 5.0, "psnr {psnr:.1} dB: the bar does not see noise");
    assert!(relative > 10.0 * MAX_RELATIVE_ERROR, "relative error {relative:.2e}: the bar does not see noise");
}

/// So does a render in another mode: FIS reads blurred levels where the reference reads level 0
/// (measured: 45.1 dB, relative error 4e-2; the comparison fails on either figure).
#[test]
fn a_render_in_another_mode_fails_the_comparison() {
    let scene = sphere_scene(SIZE);
    let gpu = render_gpu(&mut renderer(&scene, ggx(), sky_lighting()), &settings(Estimator::Fis));
    let cpu = render_cpu(&scene, ggx(), sky_lighting(), &settings(Estimator::Reference));
    let (psnr, relative) = compare(&gpu, &cpu);
    log(&format!("ggx fis against reference: psnr {psnr:.1} dB, relative error {relative:.2e}"));
    assert!(
        psnr < MIN_PSNR_DB || relative > 10.0 * MAX_RELATIVE_ERROR,
        "psnr {psnr:.1} dB, relative error {relative:.2e}"
    );
}

/// Moving the camera draws the G-buffer again: the image is the one a renderer set up with that
/// camera makes.
#[test]
fn moving_the_camera_is_setting_up_with_that_camera() {
    let scene = sphere_scene(SIZE);
    let camera = Camera::orbit(glam::Vec3::ZERO, 2.5, 1.0, 0.4, 50f32.to_radians()).expect("a valid camera");
    let settings = settings(Estimator::Prefiltered);
    let mut moved = renderer(&scene, phong(), sky_lighting());
    let before = render_gpu(&mut moved, &settings);
    moved.set_camera(&camera).expect("moving the camera");
    assert_eq!(moved.camera(), &camera);
    let after = render_gpu(&mut moved, &settings);
    let fresh = render_gpu(&mut renderer(&Scene { camera, ..scene.clone() }, phong(), sky_lighting()), &settings);
    assert!(after == fresh, "moving the camera differs from setting up with it");
    assert!(after != before, "the camera did not move");

    // The adaptive frames' G-buffer, made once per camera, is made again for the new one.
    let adaptive =
        render::adaptive::Settings { max_spp: 64, ..render::adaptive::Settings::new(Estimator::Reference, 4) };
    let frame = |r: &mut Renderer| {
        r.set_bandwidths(&bandwidths()).unwrap();
        r.render_adaptive(phong(), sky_lighting(), &adaptive, details()).unwrap()
    };
    moved.set_camera(&scene.camera).unwrap();
    let before = frame(&mut moved);
    moved.set_camera(&camera).unwrap();
    let after = frame(&mut moved);
    let fresh = frame(&mut renderer(&Scene { camera, ..scene.clone() }, phong(), sky_lighting()));
    assert!(
        after.image == fresh.image && after.details().plan.actions == fresh.details().plan.actions,
        "a stale adaptive G-buffer"
    );
    assert!(after.image != before.image, "the camera did not move");
}

#[test]
fn renders_are_deterministic() {
    let scene = sphere_scene(SIZE);
    let mut renderer = renderer(&scene, ggx(), sky_lighting());
    let settings = Settings { frames: 3, ..settings(Estimator::Fis) };
    let first = render_gpu(&mut renderer, &settings);
    let second = render_gpu(&mut renderer, &settings);
    let third = render_gpu(&mut self::renderer(&scene, ggx(), sky_lighting()), &settings);
    let bits = |image: &Image| image.rgb.iter().map(|v| v.to_bits()).collect::<Vec<u32>>();
    assert!(bits(&first) == bits(&second), "the same renderer gave two images");
    assert!(bits(&first) == bits(&third), "two renderers gave two images");
    assert_eq!(first.covered, third.covered);
}

/// Whether `render::raster` clips triangle `t` (a vertex outside `0 <= z <= w`,
/// `|x|, |y| <= GUARD_BAND w`) rather than drawing it whole.
fn clipped(mesh: &Mesh, view_proj: glam::Mat4, t: u32) -> bool {
    let g = render::raster::GUARD_BAND;
    mesh.indices[3 * t as usize..3 * t as usize + 3].iter().any(|&v| {
        let c = view_proj * glam::Vec3::from(mesh.positions[v as usize]).extend(1.0);
        !(c.z >= 0.0 && c.z <= c.w && c.x.abs() <= g * c.w && c.y.abs() <= g * c.w)
    })
}

/// The G-buffer against `render::raster`: coverage (the same rules), and where both cover a pixel,
/// the same triangle and the same interpolated position and normal.
///
/// On a triangle drawn whole both interpolate from the snapped vertices, so they agree to f32
/// rounding: 1e-5 on meshes of unit size (measured: 2e-7; the rasterizer's own interpolation was
/// off by 6e-4 at grazing pixels, a wrong triangle or barycentric is off by a pixel's footprint,
/// 1e-2). A triangle the CPU clips is interpolated on the GPU at the exact point where the pixel
/// ray meets it, on the CPU from the clipped polygon's snapped vertices: they differ by that
/// snapping (1/512 pixel) over sub-triangles that can be slivers, so 1e-4 (measured: 3e-5).
#[test]
fn the_gbuffer_matches_the_cpu_rasterizer() {
    let cameras = [
        Camera::default(),
        // Off-axis, close and wide: strong perspective.
        Camera::orbit(glam::Vec3::new(0.1, -0.2, 0.05), 1.6, 2.0, 0.7, 70f32.to_radians()).expect("a valid camera"),
        // Zoomed in: large triangles reach beyond the guard band, and the CPU clips them.
        Camera::orbit(glam::Vec3::ZERO, 1.5, 0.3, 0.2, 6f32.to_radians()).expect("a valid camera"),
        // Inside every mesh, wide: back faces everywhere, and many clipped triangles.
        Camera::orbit(glam::Vec3::ZERO, 0.62, 0.0, 0.1, 100f32.to_radians()).expect("a valid camera"),
    ];
    let meshes = [Mesh::sphere(1.0, 48, 24), Mesh::torus(0.7, 0.3, 40, 20), Mesh::sphere(1.0, 8, 4)];
    let mut clipped_pixels = 0;
    for (c, camera) in cameras.iter().enumerate() {
        for (m, mesh) in meshes.iter().enumerate() {
            // Not square, so that a swapped aspect or axis shows.
            let scene = Scene { mesh: mesh.clone(), camera: *camera, width: 96, height: 64 };
            let gbuffer = renderer(&scene, lambertian(), sky_lighting()).gbuffer().expect("reading the g-buffer");
            let view_proj = camera.view_proj(scene.width as f32 / scene.height as f32);
            let cpu =
                render::raster::rasterize(&scene.mesh, view_proj, scene.width, scene.height).expect("a valid scene");
            let cpu_covered: Vec<bool> = cpu.hits.iter().map(Option::is_some).collect();
            let mismatches = coverage_mismatches(&gbuffer.coverage(), &cpu_covered, scene.width);
            let mut other_triangle = Vec::new();
            // The largest position and normal errors, on triangles drawn whole and clipped.
            let mut worst = [[0.0f64; 2]; 2];
            // Where the largest position errors are: (x, y, triangle).
            let mut worst_at = [(0, 0, 0); 2];
            for (i, hit) in cpu.hits.iter().enumerate() {
                let (Some(hit), Some(triangle)) = (hit, gbuffer.triangle[i]) else { continue };
                if triangle != hit.triangle {
                    other_triangle.push((i % scene.width, i / scene.width, triangle, hit.triangle));
                    continue;
                }
                let position = glam::Vec3::from(gbuffer.position[i]).as_dvec3();
                let normal = glam::Vec3::from(gbuffer.normal[i]).as_dvec3();
                let kind = usize::from(clipped(mesh, view_proj, triangle));
                clipped_pixels += kind;
                let error = (position - hit.position).length();
                if error > worst[kind][0] {
                    worst_at[kind] = (i % scene.width, i / scene.width, triangle);
                }
                worst[kind][0] = worst[kind][0].max(error);
                worst[kind][1] = worst[kind][1].max((normal - hit.normal).length());
            }
            let covered = cpu_covered.iter().filter(|c| **c).count();
            log(&format!(
                "camera {c}, mesh {m}: {covered} pixels covered, coverage mismatches {mismatches:?}, other \
                 triangle {other_triangle:?}, largest position and normal errors {:.1e} {:.1e} at {:?} \
                 (clipped triangles: {:.1e} {:.1e} at {:?}; (x, y, triangle))",
                worst[0][0], worst[0][1], worst_at[0], worst[1][0], worst[1][1], worst_at[1]
            ));
            assert!(covered > 100, "camera {c}, mesh {m}: only {covered} pixels covered");
            assert!(
                mismatches.len() <= MAX_COVERAGE_MISMATCHES,
                "camera {c}, mesh {m}: coverage differs at {mismatches:?}"
            );
            assert!(
                other_triangle.len() <= MAX_COVERAGE_MISMATCHES,
                "camera {c}, mesh {m}: (x, y, gpu triangle, cpu triangle) {other_triangle:?}"
            );
            assert!(worst[0][0] < 1e-5 && worst[0][1] < 1e-5, "camera {c}, mesh {m}: errors {worst:?}");
            assert!(worst[1][0] < 1e-4 && worst[1][1] < 1e-4, "camera {c}, mesh {m}: errors {worst:?}");
        }
    }
    assert!(clipped_pixels > 1000, "only {clipped_pixels} pixels on clipped triangles");
}

/// An answer that owes nothing to the CPU renderer: under a constant environment `L` every mode
/// reads `L` (every mip level and every layer of a constant map is the constant), and a
/// Lambertian surface of albedo `a` reflects `a L` at every view. What remains is the estimator's
/// noise: the importance sampler's density is constant over a MERL cell where `f cos` is not.
/// Each pixel averages 16 frames of whole 64-sample vectors (measured: 1.1% at worst, 1e-6 on
/// the mean over the sphere), so 2.5% per pixel and 0.5% on the mean; a missing cosine (up to
/// 100%), a pdf in the wrong measure or a wrong BRDF scale (factors of pi) fail both.
#[test]
fn a_lambertian_sphere_under_a_constant_sky_reflects_its_albedo() {
    const L: [f32; 3] = [0.8, 1.0, 1.25];
    let map = EnvMap::constant(64, 32, L).expect("a 2:1 map");
    let lighting = Lighting::new(MipChain::new(&map), vec![map.clone(); 4], vec![1, 8, 64, 512]).expect("a valid map");
    let scene = sphere_scene(SIZE);
    let mut renderer = renderer(&scene, lambertian(), &lighting);
    let albedo = [0.5, 0.4, 0.3];
    for mode in Estimator::ALL {
        let image = render_gpu(&mut renderer, &Settings { estimator: mode, spp: 64, frames: 16, seed: 3 });
        let (mut worst, mut sum, mut shaded) = (0.0f64, 0.0f64, 0usize);
        for (rgb, covered) in image.rgb.chunks_exact(3).zip(&image.covered) {
            // Silhouette pixels whose interpolated normal faces away are black by the rules.
            if !covered || rgb == [0.0; 3] {
                continue;
            }
            shaded += 1;
            for c in 0..3 {
                let error = (f64::from(rgb[c]) / (albedo[c] * f64::from(L[c]))) - 1.0;
                worst = worst.max(error.abs());
                sum += error / 3.0;
            }
        }
        let mean = sum / shaded as f64;
        log(&format!(
            "lambertian under a constant sky, {}: {shaded} pixels, worst relative error {worst:.2e}, mean {mean:.2e}",
            mode.name()
        ));
        assert!(shaded > SIZE * SIZE / 4, "{}: only {shaded} shaded pixels", mode.name());
        assert!(worst < 0.025, "{}: a pixel is off by {worst:.3} of a L", mode.name());
        assert!(mean.abs() < 0.005, "{}: the pixels are off by {mean:.4} of a L on average", mode.name());
        // The background is the constant too, up to the f32 rounding of the bilinear weights and
        // of the sum over frames.
        for (rgb, covered) in image.rgb.chunks_exact(3).zip(&image.covered) {
            if !covered {
                assert!((0..3).all(|c| (rgb[c] - L[c]).abs() <= 1e-6 * L[c]), "{}: background {rgb:?}", mode.name());
            }
        }
    }
}

/// The background is the environment in the camera's orientation, checked on a map that is bright
/// above the horizon (`+z`) and dim below, and red where `y > 0`: the default camera sits on `+x`
/// looking towards `-x` with `+z` up, so the picture's top is sky, its bottom ground, and its
/// right (`+y`) red. A flipped row order or a mirrored azimuth swaps corners.
#[test]
fn the_background_shows_the_sky_up_and_the_camera_orientation() {
    let (w, h) = (64, 32);
    let mut rgb = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        for x in 0..w {
            let d = envmap::direction((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let up = if d.z > 0.0 { 1.0 } else { 0.1 };
            let red = if d.y > 0.0 { 1.0 } else { 0.0 };
            rgb.extend([up, up * (1.0 - red), up * (1.0 - red)]);
        }
    }
    let map = EnvMap::new(w, h, rgb).expect("a 2:1 map");
    let lighting = Lighting::new(MipChain::new(&map), vec![], vec![]).expect("a valid map");
    // A small sphere, so that the corners show the background.
    let scene = Scene { mesh: Mesh::sphere(0.3, 16, 8), camera: Camera::default(), width: 32, height: 32 };
    let image = render_gpu(&mut renderer(&scene, lambertian(), &lighting), &settings(Estimator::Reference));
    let pixel = |x: usize, y: usize| {
        let i = 3 * (y * scene.width + x);
        [image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]]
    };
    let (top_left, top_right, bottom_left) = (pixel(0, 0), pixel(31, 0), pixel(0, 31));
    assert!(!image.covered[0] && !image.covered[31] && !image.covered[31 * 32], "the corners are background");
    assert!(top_left[0] > 0.9 && top_left[1] > 0.9, "top left is white sky: {top_left:?}");
    assert!(top_right[0] > 0.9 && top_right[1] < 0.05, "top right is red sky: {top_right:?}");
    assert!(bottom_left[0] < 0.15 && bottom_left[0] > 0.05, "bottom left is ground: {bottom_left:?}");
}

#[test]
fn inconsistent_settings_are_rejected_like_the_cpu_rejects_them() {
    let scene = sphere_scene(16);
    let no_layers = Lighting { layers: vec![], exponents: vec![], ..sky_lighting().clone() };
    let mut renderer = renderer(&scene, lambertian(), &no_layers);
    let cases = [
        Settings { spp: 3, ..settings(Estimator::Reference) },
        Settings { spp: 128, ..settings(Estimator::Reference) },
        Settings { frames: 0, ..settings(Estimator::Fis) },
        settings(Estimator::Prefiltered),
    ];
    for case in cases {
        let cpu = render::render(&scene, lambertian(), &no_layers, &case).expect_err("the cpu rejects it");
        match renderer.render_frames(&case) {
            Err(GpuError::Scene(gpu)) => assert_eq!(gpu, cpu, "{case:?}"),
            other => panic!("{case:?}: expected the cpu's error {cpu}, got {other:?}"),
        }
    }
    let mut bad_samples = lambertian().clone();
    bad_samples.samples.texels.pop();
    let error = Renderer::new(gpu(), &scene, &bad_samples, &no_layers).expect_err("a short sample set");
    assert!(matches!(error, GpuError::Scene(_)), "{error}");
}

/// The bandwidth buffer predicted on the GPU (`Renderer::predict_blocks`) equals the
/// CPU's (`render::adaptive`) to f32 rounding, for both estimators' variances, with and without
/// anti-aliasing and per pixel or per block. Tolerance: the GPU works in f32 and reads the
/// environment bandwidth and the atlas at the nearest texel, so a direction on a texel's edge
/// may read the neighbour (a different value, by design of the fixture); so 98% of the
/// predictions within 1e-3 relative, and 98% of the levels (eq. 11, applied to both in f64)
/// equal.
#[test]
fn adaptive_predictions_on_the_gpu_equal_the_cpu() {
    let (material, lighting, bandwidths) = (phong(), sky_lighting(), bandwidths());
    let scene = sphere_scene(SIZE);
    for (mode, supersample, predict_level) in [
        (Estimator::Reference, 1, 0),
        (Estimator::Prefiltered, 1, 0),
        (Estimator::Reference, 2, 1),
        (Estimator::Reference, 1, 2),
    ] {
        let settings = render::adaptive::Settings {
            supersample,
            predict_level,
            max_spp: 64,
            ..render::adaptive::Settings::new(mode, 4)
        };
        let render_scene = Scene { width: SIZE * supersample, height: SIZE * supersample, ..scene.clone() };
        let mut renderer = renderer(&render_scene, material, lighting);
        renderer.set_bandwidths(&bandwidths).unwrap();
        let cpu = render::adaptive::render(&scene, material, lighting, &bandwidths, &settings).unwrap();
        let (w, h) = (render_scene.width, render_scene.height);
        let shadeable: Vec<bool> = cpu.details().predictions.iter().map(|p| p.level >= 0).collect();
        let top = render::adaptive::top_level(w, h, None);
        let (pixels, _) = render::adaptive::prediction_pixels(&shadeable, (w, h), settings.prediction_level(top));
        let gpu = renderer.predict_blocks(&settings, &pixels).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()).max(1e-12);
        let (mut near, mut same_level, mut worst) = (0, 0, 0.0f64);
        for (&i, &[bandwidth, variance]) in pixels.iter().zip(&gpu) {
            let p = cpu.details().predictions[i as usize];
            if close(bandwidth, p.bandwidth) && close(variance, p.variance) {
                near += 1;
            }
            if render::adaptive::level_of(bandwidth, top) == p.level {
                same_level += 1;
            }
            worst = worst.max((bandwidth - p.bandwidth).abs() / p.bandwidth.max(1e-12));
        }
        let n = pixels.len();
        log(&format!(
            "predictions {} {supersample}x{supersample} level {predict_level}: {n} pixels, {near} within 1e-3, \
             {same_level} at the same level, worst bandwidth difference {worst:.2e} relative",
            mode.name()
        ));
        assert!(n > 100 && 50 * near >= 49 * n && 50 * same_level >= 49 * n, "{near} and {same_level} of {n}");
    }
}

/// One adaptive frame's settings for [`check_adaptive_frame`].
struct AdaptiveCase {
    /// The sphere filling the image rather than the default view.
    filled: bool,
    mode: Estimator,
    supersample: usize,
    spp: u32,
    lobe_weight: bool,
    oracle: bool,
    allocation: render::adaptive::Allocation,
    max_spp: u32,
    /// The frames the picture averages (the prefiltered blocks' footprints).
    frames: u32,
}

/// A block cap of one vector's samples (the test material's 64).
const ONE_VECTOR: u32 = 64;

impl AdaptiveCase {
    fn new(mode: Estimator, spp: u32) -> AdaptiveCase {
        AdaptiveCase {
            filled: false,
            mode,
            supersample: 1,
            spp,
            lobe_weight: false,
            oracle: false,
            allocation: render::adaptive::Allocation::Area,
            max_spp: ONE_VECTOR,
            frames: 1,
        }
    }
}

/// Renders `case` on the GPU twice and on the CPU from the GPU's predictions, and holds them to
/// each other: the same plan (weights to f32 rounding), samples and image, stages within the wall
/// time (see [`adaptive_reference_frame_equals_the_cpu`] for what the cases cover).
fn check_adaptive_frame(case: AdaptiveCase) {
    check_adaptive_frame_on(gpu(), case);
}

/// [`check_adaptive_frame`] on the device `on`.
fn check_adaptive_frame_on(on: &Gpu, case: AdaptiveCase) {
    let (material, lighting, bandwidths) = (phong(), sky_lighting(), bandwidths());
    let whole = sphere_scene(SIZE);
    // From 1.5 radii away the sphere subtends 84 degrees; a 30 degree view sees only the sphere.
    let filled_camera = Camera::orbit(glam::Vec3::ZERO, 1.5, 0.3, 0.2, 30f32.to_radians()).unwrap();
    let scene = if case.filled { Scene { camera: filled_camera, ..whole.clone() } } else { whole };
    let AdaptiveCase { mode, supersample, spp, lobe_weight, oracle, allocation, max_spp, frames, .. } = case;
    let settings = render::adaptive::Settings {
        supersample,
        max_spp,
        lobe_weight,
        allocation,
        frames,
        ..render::adaptive::Settings::new(mode, spp)
    };
    let render_scene = Scene { width: SIZE * supersample, height: SIZE * supersample, ..scene.clone() };
    let (w, h) = (render_scene.width, render_scene.height);
    // An oracle that asks for every level somewhere: a ramp over the image.
    let ramp: Vec<f64> = (0..w * h).map(|i| 0.6 * ((i % w) as f64 / w as f64).powi(3)).collect();
    let mut renderer = renderer_on(on, &render_scene, material, lighting);
    renderer.set_bandwidths(&bandwidths).unwrap();
    let options = gpu::preview::FrameOptions { oracle: oracle.then_some(&ramp[..]), details: true };
    let gpu_frame = renderer
        .render_adaptive(material, lighting, &settings, options)
        .unwrap_or_else(|e| panic!("adaptive frame on the gpu: {e}"));
    // The same frame again on the same renderer: nothing of the first (the plan's counts per
    // level and per chunk, which it adds to) carries over.
    let again = renderer.render_adaptive(material, lighting, &settings, options).unwrap();
    assert!(again.image.rgb == gpu_frame.image.rgb && again.samples == gpu_frame.samples, "a second frame differs");
    let mut replay = render::adaptive::replay_predictor(&gpu_frame.details().predictions);
    let hooks = render::adaptive::Hooks {
        predictor: Some(&mut replay),
        oracle: oracle.then_some(&ramp[..]),
        ..Default::default()
    };
    let geometry = render::adaptive::Geometry::of_scene(&scene, settings.supersample).unwrap();
    if case.filled {
        assert!(geometry.pixels().iter().all(Option::is_some), "the sphere fills the image");
    }
    let cpu_frame =
        render::adaptive::render_with(&geometry, material, lighting, &bandwidths, &settings, hooks).unwrap();
    let worst = gpu_frame.details().plan.compare(&cpu_frame.details().plan, 1e-5).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(gpu_frame.shaded_per_level, cpu_frame.shaded_per_level);
    assert_eq!((gpu_frame.samples, gpu_frame.budget), (cpu_frame.samples, cpu_frame.budget));
    // One submission under the area allocation, its stages on the GPU's clock (where the
    // adapter has one) within the frame's wall time; two otherwise.
    let t = gpu_frame.timings;
    assert_eq!(t.submissions, if allocation == render::adaptive::Allocation::Area { 1 } else { 2 });
    // In two submissions the stages are differences of the wall clock's readings, and their
    // sum may pass the last reading by a rounding (seen: 62.97396800000001 against
    // 62.973968000000006).
    let stages = t.predict_ms + t.plan_ms + t.shade_ms;
    assert!(stages > 0.0 && stages <= t.total_ms * (1.0 + 1e-12), "stages {stages} ms of a frame of {} ms", t.total_ms);
    if t.gpu_clock {
        assert!(t.predict_ms > 0.0 && t.plan_ms > 0.0 && t.shade_ms > 0.0, "{t:?}");
    }
    let shaded: usize = cpu_frame.shaded_per_level.iter().sum();
    assert!(shaded > 0 && cpu_frame.shaded_fraction() < 1.0, "{shaded} shaded blocks");
    let most = (cpu_frame.details().plan.actions.iter().flatten())
        .filter_map(|a| match *a {
            render::adaptive::Action::Shade { samples, .. } => Some(samples),
            _ => None,
        })
        .max();
    if max_spp > ONE_VECTOR {
        assert!(most > Some(ONE_VECTOR), "the largest block has {most:?} samples");
    }
    let (psnr, relative) = compare(&gpu_frame.image, &cpu_frame.image);
    log(&format!(
        "adaptive {} {supersample}x{supersample} {spp} spp {}{}{}: {shaded} shaded blocks, levels {:?}, {} samples \
         (at most {most:?} a block), worst weight difference {worst:.1e}, PSNR {psnr:.2} dB, relative error \
         {relative:.2e}, {} submissions, stages {:.2} + {:.2} + {:.2} ms of {:.2} (GPU clock: {})",
        mode.name(),
        allocation.name(),
        if lobe_weight { " lobe weight" } else { "" },
        if oracle { " oracle" } else { "" },
        cpu_frame.shaded_per_level,
        cpu_frame.samples,
        t.submissions,
        t.predict_ms,
        t.plan_ms,
        t.shade_ms,
        t.total_ms,
        t.gpu_clock,
    ));
    assert!(psnr >= MIN_PSNR_DB && relative <= MAX_ADAPTIVE_RELATIVE_ERROR, "{psnr} dB, {relative}");
    if frames > 1 {
        // The frames reach the GPU's footprints: the same plan on the CPU sized for one frame is
        // far further from the GPU's than the CPU's own frame.
        let mut replay = render::adaptive::replay_predictor(&gpu_frame.details().predictions);
        let hooks = render::adaptive::Hooks { predictor: Some(&mut replay), ..Default::default() };
        let one = render::adaptive::Settings { frames: 1, ..settings };
        let one = render::adaptive::render_with(&geometry, material, lighting, &bandwidths, &one, hooks).unwrap();
        let apart = render::metrics::relative_error(&one.image.rgb, &cpu_frame.image.rgb);
        assert!(
            relative * 10.0 < apart,
            "GPU against CPU {relative:.2e}, one frame's footprints against {frames}: {apart:.2e}"
        );
    }
}

/// The cases below cover the reference and the prefiltered estimators, 2 x 2 anti-aliasing, the
/// lobe weight, the oracle's bandwidths, the allocations on the GPU (area) and on the host
/// (variance, standard deviation), blocks capped at one vector and blocks of several vectors (at
/// 256 spp parts of 128 samples, each across two vectors), and the sphere filling the image, so
/// that the blocks in its top-left corner, block 0 of their levels, are parents (the WGSL's
/// search for a parent already counted must not take its unwritten slots for block 0).
#[test]
fn adaptive_reference_frame_equals_the_cpu() {
    check_adaptive_frame(AdaptiveCase::new(Estimator::Reference, 8));
}

#[test]
fn adaptive_prefiltered_frame_equals_the_cpu() {
    // One frame of 8 averaged: the blocks' footprints are sized for 8 times their samples.
    check_adaptive_frame(AdaptiveCase { frames: 8, ..AdaptiveCase::new(Estimator::Prefiltered, 4) });
}

#[test]
fn adaptive_anti_aliased_frame_equals_the_cpu() {
    check_adaptive_frame(AdaptiveCase { supersample: 2, ..AdaptiveCase::new(Estimator::Reference, 4) });
}

#[test]
fn adaptive_frame_with_the_lobe_weight_and_the_variance_allocation_equals_the_cpu() {
    let allocation = render::adaptive::Allocation::Variance;
    check_adaptive_frame(AdaptiveCase { lobe_weight: true, allocation, ..AdaptiveCase::new(Estimator::Reference, 8) });
}

#[test]
fn adaptive_frame_with_the_oracle_equals_the_cpu() {
    check_adaptive_frame(AdaptiveCase { oracle: true, ..AdaptiveCase::new(Estimator::Reference, 8) });
}

#[test]
fn adaptive_frame_of_a_large_budget_equals_the_cpu() {
    check_adaptive_frame(AdaptiveCase::new(Estimator::Reference, 64));
}

#[test]
fn adaptive_prefiltered_frame_with_the_std_dev_allocation_equals_the_cpu() {
    let allocation = render::adaptive::Allocation::StdDev;
    check_adaptive_frame(AdaptiveCase { allocation, ..AdaptiveCase::new(Estimator::Prefiltered, 4) });
}

#[test]
fn adaptive_frame_of_blocks_across_vectors_equals_the_cpu() {
    let max_spp = render::adaptive::MAX_SPP;
    check_adaptive_frame(AdaptiveCase { max_spp, ..AdaptiveCase::new(Estimator::Reference, 256) });
}

#[test]
fn adaptive_prefiltered_frame_of_blocks_across_vectors_equals_the_cpu() {
    let (allocation, max_spp) = (render::adaptive::Allocation::StdDev, render::adaptive::MAX_SPP);
    check_adaptive_frame(AdaptiveCase { allocation, max_spp, ..AdaptiveCase::new(Estimator::Prefiltered, 32) });
}

#[test]
fn adaptive_frame_filling_the_image_equals_the_cpu() {
    check_adaptive_frame(AdaptiveCase { filled: true, oracle: true, ..AdaptiveCase::new(Estimator::Reference, 8) });
}

/// Every render pixel at level 0 (an oracle at the Nyquist rate) with 2 x 2 anti-aliasing shades
/// about 4 blocks per output pixel: 1 sample per output pixel cannot pay for them, the same error
/// whether the GPU allocates (area) or the host (variance).
#[test]
fn an_adaptive_budget_below_a_sample_per_block_is_an_error() {
    let (material, lighting, bandwidths) = (phong(), sky_lighting(), bandwidths());
    let render_scene = Scene { width: SIZE * 2, height: SIZE * 2, ..sphere_scene(SIZE) };
    let mut renderer = renderer(&render_scene, material, lighting);
    renderer.set_bandwidths(&bandwidths).unwrap();
    let nyquist = vec![0.5; 4 * SIZE * SIZE];
    for allocation in [render::adaptive::Allocation::Area, render::adaptive::Allocation::Variance] {
        let settings = render::adaptive::Settings {
            supersample: 2,
            max_spp: 64,
            allocation,
            ..render::adaptive::Settings::new(Estimator::Reference, 1)
        };
        let options = gpu::preview::FrameOptions { oracle: Some(&nyquist), details: false };
        let error = renderer.render_adaptive(material, lighting, &settings, options).expect_err("over budget");
        assert!(error.to_string().contains("less than one for each"), "{}: {error}", allocation.name());
    }
}

/// The prediction needs the bandwidths; without them the frame is an error that says so.
#[test]
fn an_adaptive_frame_without_bandwidths_is_an_error() {
    let (material, lighting) = (phong(), sky_lighting());
    let renderer = renderer(&sphere_scene(SIZE), material, lighting);
    let settings = render::adaptive::Settings::new(Estimator::Reference, 4);
    let error = renderer.render_adaptive(material, lighting, &settings, details()).expect_err("no bandwidths");
    assert!(error.to_string().contains("set_bandwidths"), "{error}");
}

/// Frame options that keep the frame's buffers.
fn details() -> gpu::preview::FrameOptions<'static> {
    gpu::preview::FrameOptions { details: true, ..Default::default() }
}

/// Mesa's GL (llvmpipe through EGL) binds 16 storage buffers per shader stage where lavapipe binds
/// more: every mode runs there, each pass's layout naming only the groups it reads, and equals the
/// CPU as it does on lavapipe.
#[test]
fn every_mode_on_mesa_gl_equals_the_cpu() {
    let gl = gl_gpu(&|limits| limits);
    for mode in [Estimator::Reference, Estimator::Fis, Estimator::Prefiltered] {
        check_against_cpu_on(&gl, "ggx on gl", ggx(), mode);
    }
    check_adaptive_frame_on(&gl, AdaptiveCase::new(Estimator::Reference, 8));
    check_adaptive_frame_on(&gl, AdaptiveCase::new(Estimator::Prefiltered, 4));
}

/// An adapter short of storage buffers per shader stage fails with one line that names the limit,
/// what the adapter has and what the work needs: the shading passes bind 8 (groups 0 to 2, their
/// buffers packed), so WebGPU's default of 8 runs the estimators, equal to the CPU as anywhere, and
/// an adaptive frame, whose passes bind 11, names the modes that run; at 7 no mode runs.
#[test]
fn an_adapter_short_of_storage_buffers_names_the_limit_and_the_modes_it_runs() {
    let capped =
        |n: u32| move |limits: wgpu::Limits| wgpu::Limits { max_storage_buffers_per_shader_stage: n, ..limits };
    let (scene, material, lighting) = (sphere_scene(SIZE), ggx(), sky_lighting());
    let seven = Gpu::with_backends(wgpu::Backends::all(), &capped(7)).unwrap();
    let error = Renderer::new(&seven, &scene, material, lighting).expect_err("7 storage buffers");
    let message = error.to_string();
    assert!(
        message.contains("max_storage_buffers_per_shader_stage is 7, shading (every mode) needs 8")
            && !message.contains('\n'),
        "{message}"
    );

    let webgpu_default = Gpu::with_backends(wgpu::Backends::all(), &capped(8)).unwrap();
    for mode in [Estimator::Reference, Estimator::Fis, Estimator::Prefiltered] {
        check_against_cpu_on(&webgpu_default, "ggx with 8 storage buffers", ggx(), mode);
    }
    let mut renderer = renderer_on(&webgpu_default, &scene, material, lighting);
    let error = renderer.set_bandwidths(&bandwidths()).expect_err("an adaptive frame needs 11");
    let message = error.to_string();
    assert!(
        message.contains(
            "max_storage_buffers_per_shader_stage is 8, an adaptive frame (reference, fis and prefiltered run on \
             this adapter) needs 11"
        ) && !message.contains('\n'),
        "{message}"
    );
}
