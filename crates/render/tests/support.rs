//! What the tests share: materials made from analytic tables, constant and synthetic
//! environments, the sphere scene, and the expected directional albedo of a table.

use std::sync::OnceLock;

use envmap::{EnvMap, MipChain};
use glam::DVec3;
use importance::Config;
use merl::albedo::{Quadrature, directional_albedo};
use merl::analytic::Analytic;
use merl::{Dims, Interp, MerlTable};
use render::raster::GBuffer;
use render::{Camera, Lighting, Material, Mesh, SampleSet, Scene};

/// The bakes: 16 vectors of 512 samples per slice, from `bake_seed` (the frames of a render walk
/// through the first 8192 points of each pixel's own sequence).
fn material(brdf: Analytic, bake_seed: u64) -> Material {
    let table = brdf.table(Dims::MERL);
    let config = Config { n_vectors: 16, n_samples: 512, seed: bake_seed, ..Config::default() };
    let tables = importance::build(&table, &config).expect("a valid config");
    Material::new(table, SampleSet::new(&tables), vec![0.0; 8])
}

/// Lambertian, albedo 0.5, baked with seed 0 or 1.
pub fn lambertian(bake_seed: u64) -> &'static Material {
    static MATERIALS: [OnceLock<Material>; 2] = [OnceLock::new(), OnceLock::new()];
    MATERIALS[bake_seed as usize].get_or_init(|| material(Analytic::Lambertian { albedo: [0.5; 3] }, bake_seed))
}

/// Normalized Phong, ks 1, n 100, baked with seed 0 or 1.
pub fn phong(bake_seed: u64) -> &'static Material {
    static MATERIALS: [OnceLock<Material>; 2] = [OnceLock::new(), OnceLock::new()];
    MATERIALS[bake_seed as usize]
        .get_or_init(|| material(Analytic::Phong { n: 100.0, ks: [1.0; 3], kd: [0.0; 3] }, bake_seed))
}

/// Radiance of the constant environments.
pub const L: [f32; 3] = [0.8, 1.0, 1.25];

/// A constant environment: every mip level and the one prefiltered layer are the constant too.
pub fn constant_lighting() -> Lighting {
    let map = EnvMap::constant(64, 32, L).expect("a 2:1 map");
    Lighting::new(MipChain::new(&map), vec![map], vec![1]).expect("a valid map")
}

/// A sky: a gradient from a bright zenith to a dim ground, and a sun disk (10 degrees across,
/// 10 times the sky around it: a third of the light on a surface facing it) at 36 degrees
/// elevation, on a 128 x 64 map.
pub fn sky_lighting() -> Lighting {
    let (w, h) = (128, 64);
    let sun = envmap::direction(0.1, 0.3);
    let mut rgb = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = ((x as f64 + 0.5) / w as f64, (y as f64 + 0.5) / h as f64);
            let d = envmap::direction(u, v);
            let sky = if d.z > 0.0 { [0.4 + 0.6 * d.z, 0.6 + 0.6 * d.z, 1.0 + 0.5 * d.z] } else { [0.25, 0.2, 0.15] };
            let boost = if d.dot(sun) > 5f64.to_radians().cos() { 10.0 } else { 1.0 };
            rgb.extend(sky.map(|c| (c * boost) as f32));
        }
    }
    let map = EnvMap::new(w, h, rgb).expect("finite, non-negative, 2:1");
    Lighting::new(MipChain::new(&map), vec![map], vec![1]).expect("a valid map")
}

/// A unit sphere in front of the default camera.
pub fn sphere_scene(width: usize, height: usize) -> Scene {
    Scene { mesh: Mesh::sphere(1.0, 32, 16), camera: Camera::default(), width, height }
}

/// `theta_o` at each pixel of a G-buffer, as the shading frame defines it (`None` where the
/// pixel is uncovered or black).
pub fn theta_o(gbuffer: &GBuffer, camera: &Camera) -> Vec<Option<f64>> {
    let eye = camera.eye().as_dvec3();
    gbuffer
        .hits
        .iter()
        .map(|hit| {
            let hit = hit.as_ref()?;
            let wo: DVec3 = (eye - hit.position).normalize();
            let cos_o = hit.normal.dot(wo);
            (cos_o > 0.0).then(|| (wo - cos_o * hit.normal).length().atan2(cos_o))
        })
        .collect()
}

/// The directional albedo of a table (nearest lookup) on a grid of `theta_o`, linearly
/// interpolated, with a bound on the interpolation error.
pub struct AlbedoCurve {
    step: f64,
    values: Vec<[f64; 3]>,
    /// `h^2 / 8` times the largest second difference quotient: the linear interpolation error
    /// of a function whose second derivative is that large.
    pub interpolation_error: f64,
}

impl AlbedoCurve {
    /// `nodes` values of `theta_o`, 2 degrees apart from 0. The quadrature (2 nodes per MERL
    /// cell, 360 in `phi_h`) is within 2e-3 relative of merl's default one on both test tables
    /// below 88 degrees (measured).
    pub fn new(table: &MerlTable, nodes: usize) -> AlbedoCurve {
        let step = 2f64.to_radians();
        let q = Quadrature { nodes_per_cell: 2, n_phi_h: 360 };
        let values: Vec<[f64; 3]> = (0..nodes)
            .map(|i| directional_albedo(|wi, wo| table.lookup(wi, wo, Interp::Nearest), i as f64 * step, q).rgb)
            .collect();
        let second = values
            .windows(3)
            .map(|w| (0..3).map(|c| (w[0][c] - 2.0 * w[1][c] + w[2][c]).abs()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        // The second difference is h^2 times the second derivative somewhere in the window.
        AlbedoCurve { step, values, interpolation_error: second / 8.0 }
    }

    /// The largest `theta_o` of the grid.
    pub fn last_node(&self) -> f64 {
        self.step * (self.values.len() - 1) as f64
    }

    pub fn at(&self, theta_o: f64) -> [f64; 3] {
        let x = (theta_o / self.step).clamp(0.0, (self.values.len() - 1) as f64);
        let i = (x as usize).min(self.values.len() - 2);
        let t = x - i as f64;
        std::array::from_fn(|c| self.values[i][c] * (1.0 - t) + self.values[i + 1][c] * t)
    }
}
