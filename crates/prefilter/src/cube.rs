//! Cube maps: the six faces of a direction field, in the face order and orientation of Vulkan and
//! KTX2, resampled from a lat-long map.
//!
//! # Faces and texels
//!
//! Face `f` is `+X, -X, +Y, -Y, +Z, -Z` for `f = 0..6` (KTX2's and Vulkan's order). Texel `(i, j)`
//! of an `N x N` face (column `i` from the left, row `j` from the top, as stored) has its centre at
//! `s = (i + 1/2) / N`, `t = (j + 1/2) / N`; with `a = 2 s - 1`, `b = 2 t - 1` its direction in the
//! cube's frame is (Vulkan specification, "Cube Map Face Selection", inverted):
//!
//! | face | direction |
//! |------|-----------|
//! | `+X` | `( 1, -b, -a)` |
//! | `-X` | `(-1, -b,  a)` |
//! | `+Y` | `( a,  1,  b)` |
//! | `-Y` | `( a, -1, -b)` |
//! | `+Z` | `( a, -b,  1)` |
//! | `-Z` | `(-a, -b, -1)` |
//!
//! # The cube's frame and the world's
//!
//! The environment's world is `+z` up (the `envmap` crate); the engines that read cube maps
//! (three.js, Bevy, Filament, Godot, Unity) are `+Y` up. The cube's frame is the world turned so
//! that up is `+Y`: cube `(X, Y, Z)` = world `(x, z, -y)` ([`to_world`] is the inverse). The
//! world's zenith is the middle of the `+Y` face, world `+x` (the lat-long map's `u = 0` column)
//! the middle of `+X`, world `+y` the middle of `-Z`:
//!
//! ```text
//!            +----+
//!            | +Y |  zenith (world +z)
//!       +----+----+----+----+
//!       | -X | +Z | +X | -Z |   +X: world +x, -Z: world +y
//!       +----+----+----+----+
//!            | -Y |  nadir (world -z)
//!            +----+
//! ```
//!
//! three.js mirrors the `x` of every cube texture it did not render itself (`CubeTexture`'s
//! `flipEnvMap`); it samples these files with that flip, like any KTX2 cube map.
//!
//! # Resampling
//!
//! A face texel is the lat-long map's bilinear lookup (`envmap::EnvMap::lookup`) in its direction:
//! the cube holds the lat-long result at its texel centres, up to the lat-long grid's
//! interpolation error.

use envmap::{EnvMap, MipChain};
use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;
use crate::ktx::{self, Ktx2File, Shape, Storage};

/// The faces in storage order.
pub const FACES: [&str; 6] = ["+X", "-X", "+Y", "-Y", "+Z", "-Z"];

/// The direction (in the cube's frame, not normalized) of the point `(s, t)` in `[0, 1]^2` of
/// face `face` (module docs).
pub fn face_direction(face: usize, s: f64, t: f64) -> DVec3 {
    let (a, b) = (2.0 * s - 1.0, 2.0 * t - 1.0);
    match face {
        0 => DVec3::new(1.0, -b, -a),
        1 => DVec3::new(-1.0, -b, a),
        2 => DVec3::new(a, 1.0, b),
        3 => DVec3::new(a, -1.0, -b),
        4 => DVec3::new(a, -b, 1.0),
        5 => DVec3::new(-a, -b, -1.0),
        _ => panic!("a cube has faces 0 to 5, not {face}"),
    }
}

/// The world direction (`+z` up) of a direction in the cube's frame (`+Y` up): world `(x, y, z)`
/// = `(X, -Z, Y)`.
pub fn to_world(cube: DVec3) -> DVec3 {
    DVec3::new(cube.x, -cube.z, cube.y)
}

/// The world direction of the centre of texel `(i, j)` of face `face` of an `n x n` cube.
pub fn texel_direction(face: usize, i: usize, j: usize, n: usize) -> DVec3 {
    let s = (i as f64 + 0.5) / n as f64;
    let t = (j as f64 + 0.5) / n as f64;
    to_world(face_direction(face, s, t)).normalize()
}

/// The six `n x n` faces of `map` (interleaved RGB, rows top to bottom), each texel the map's
/// bilinear lookup at the texel centre's direction.
pub fn faces(map: &EnvMap, n: usize) -> Vec<Vec<f32>> {
    (0..6)
        .into_par_iter()
        .map(|face| (0..n * n).flat_map(|k| map.lookup(texel_direction(face, k % n, k / n, n))).collect::<Vec<f32>>())
        .collect()
}

/// The face side of the cube map made from a `width x height` lat-long map: `width / 4`, which
/// keeps the texel at the equator the same size (four faces around it), at least 1.
pub fn face_size(width: usize) -> usize {
    (width / 4).max(1)
}

/// The layers as one KTX2 cube-map array (`layerCount` = the number of layers, 6 faces each, one
/// level), faces of [`face_size`] of the layers' width.
pub fn encode_layers(layers: &[&EnvMap], storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
    let Some(first) = layers.first() else { return Err(Error::InvalidConfig("a cube array needs a layer".into())) };
    let n = face_size(first.width());
    let images: Vec<Vec<f32>> = layers.iter().flat_map(|layer| faces(layer, n)).collect();
    let level = images.iter().map(Vec::as_slice).collect();
    ktx::encode(Shape { width: n, height: n, layers: layers.len(), faces: 6 }, &[level], storage, writer)
}

/// A mip chain as one KTX2 cube map: level `l` has faces of `max(1, n >> l)` texels, `n` the
/// [`face_size`] of level 0's width, resampled from the chain's level `l`; as many levels as the
/// chain has, down to faces of one texel.
pub fn encode_mip_chain(chain: &MipChain, storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
    let n = face_size(chain.level(0).width());
    let levels: Vec<&EnvMap> = chain.levels().iter().take(n.ilog2() as usize + 1).collect();
    encode_levels(&levels, storage, writer)
}

/// Lat-long levels (each half the size of the one before) as one KTX2 cube map with a level
/// each: level `l` has faces of `max(1, n >> l)` texels, `n` the [`face_size`] of level 0's width.
/// At most `log2 n + 1` levels.
pub fn encode_levels(levels: &[&EnvMap], storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
    let Some(first) = levels.first() else { return Err(Error::InvalidConfig("a cube map needs a level".into())) };
    let n = face_size(first.width());
    let images: Vec<Vec<Vec<f32>>> =
        levels.iter().enumerate().map(|(l, level)| faces(level, (n >> l).max(1))).collect();
    let level_refs: Vec<Vec<&[f32]>> = images.iter().map(|faces| faces.iter().map(Vec::as_slice).collect()).collect();
    ktx::encode(Shape { width: n, height: n, layers: 0, faces: 6 }, &level_refs, storage, writer)
}
