//! Visibility: which triangle covers each pixel centre, and the world position and normal there
//! (a G-buffer), by the rules of the crate documentation, which are Vulkan's:
//!
//! 1. Vertices are projected in `f32`: `clip = view_proj * (p, 1)`.
//! 2. A triangle with a vertex outside the clip volume `0 <= z <= w`, `|x|, |y| <= G w` (with the
//!    guard band `G` = [`GUARD_BAND`]) is clipped against those planes (Sutherland-Hodgman, in
//!    `f32` clip space) and the polygon fanned from its first vertex; every new vertex carries
//!    its barycentric coordinates in the original triangle. Only `z >= 0` (the near plane) and
//!    `z <= w` change what is visible; the guard band only keeps the fixed-point coordinates
//!    small. The default camera clips nothing within the unit sphere.
//! 3. Viewport transform (wgpu's: y flipped, depth range `[0, 1]`), in `f32`:
//!    `x_f = (W / 2) (x / w) + W / 2`, `y_f = (-H / 2) (y / w) + H / 2`, `z_f = z / w`; then
//!    `x_f` and `y_f` are snapped to 1/256 pixel: `X = round_ties_even(256 x_f)` as an integer.
//! 4. Coverage of the pixel centre `(256 x + 128, 256 y + 128)` by the integer edge functions
//!    `E_ab(p) = (b.x - a.x)(p.y - a.y) - (b.y - a.y)(p.x - a.x)` (exact in `i64`), after
//!    ordering the vertices so the area is positive (back faces are kept): covered when every
//!    `E > 0`, or `E = 0` on a top edge (horizontal, `dx > 0` in that order) or a left edge
//!    (`dy < 0`). Zero-area triangles cover nothing.
//! 5. Screen-space barycentrics `b_i = E_i / area` (exact ratios of integers); depth
//!    `z = sum b_i z_f,i`, rounded to `f32`, passes when it is less than the stored depth
//!    (cleared to 1): the nearest wins, ties go to the triangle drawn first.
//! 6. Perspective-correct weights `l_i = (b_i / w_i) / sum_j (b_j / w_j)` interpolate the
//!    vertices' world positions and normals (in `f64`); the normal is then normalized (a normal
//!    that interpolates to zero stays zero; such a pixel is black).

use std::ops::Range;

use glam::{DVec3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

use crate::error::Error;
use crate::mesh::Mesh;

/// Sub-pixel precision of the snapped viewport coordinates: 8 bits, 1/256 pixel, as lavapipe.
pub const SUBPIXEL_BITS: u32 = 8;
/// Clip planes `|x|, |y| <= G w`: coordinates within `G` times the viewport's half size of its
/// centre, so snapped values stay far below where the `i64` edge functions could overflow.
pub const GUARD_BAND: f32 = 4.0;
/// Images wider or taller than this are refused.
pub const MAX_SIZE: usize = 16384;

const ONE: i64 = 1 << SUBPIXEL_BITS;
const HALF: i64 = ONE / 2;
/// Rows per parallel band.
const BAND: usize = 16;

/// What covers one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// World position at the pixel centre.
    pub position: DVec3,
    /// The interpolated vertex normal, normalized; zero when it interpolates to zero.
    pub normal: DVec3,
    /// The index of the triangle in the mesh.
    pub triangle: u32,
    /// The depth that won the depth test, in `[0, 1]`.
    pub depth: f32,
}

/// The visible surface at every pixel centre, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct GBuffer {
    pub width: usize,
    pub height: usize,
    pub hits: Vec<Option<Hit>>,
}

impl GBuffer {
    pub fn hit(&self, x: usize, y: usize) -> Option<&Hit> {
        self.hits[y * self.width + x].as_ref()
    }
}

/// Checks an image size against [`MAX_SIZE`] and for emptiness.
pub fn check_size(width: usize, height: usize) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::Invalid(format!("empty image: {width} x {height}")));
    }
    if width > MAX_SIZE || height > MAX_SIZE {
        return Err(Error::LimitExceeded(format!("image of {width} x {height}, the limit is {MAX_SIZE} a side")));
    }
    Ok(())
}

/// Rasterizes `mesh` into a `width x height` G-buffer with `view_proj` (see the module
/// documentation). Deterministic whatever the number of threads: bands of rows are independent
/// and each draws the triangles in mesh order.
pub fn rasterize(mesh: &Mesh, view_proj: Mat4, width: usize, height: usize) -> Result<GBuffer, Error> {
    mesh.validate()?;
    check_size(width, height)?;
    let clip = project(&mesh.positions, view_proj);
    let subs: Vec<SubTriangle> = mesh
        .indices
        .par_chunks_exact(3)
        .enumerate()
        .flat_map_iter(|(t, idx)| {
            let vertices = [0, 1, 2].map(|k| clip[idx[k] as usize]);
            setup(t as u32, vertices, width, height)
        })
        .collect();

    let n_bands = height.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    for (i, sub) in subs.iter().enumerate() {
        if let Some(rows) = sub.rows(height) {
            for bin in &mut bins[rows.start / BAND..=(rows.end - 1) / BAND] {
                bin.push(i as u32);
            }
        }
    }

    let mut hits = vec![None; width * height];
    hits.par_chunks_mut(width * BAND).zip(bins.par_iter()).enumerate().for_each(|(band, (out, bin))| {
        let rows = band * BAND..(band * BAND + BAND).min(height);
        let mut depth = vec![1.0f32; out.len()];
        for &i in bin {
            let sub = &subs[i as usize];
            for_each_covered(sub.v, width, rows.clone(), |x, y, b| {
                let z = (b[0] * sub.z[0] + b[1] * sub.z[1] + b[2] * sub.z[2]) as f32;
                let at = (y - rows.start) * width + x;
                if z < depth[at] {
                    depth[at] = z;
                    out[at] = Some(sub.hit(mesh, b, z));
                }
            });
        }
    });
    Ok(GBuffer { width, height, hits })
}

/// Step 1: the vertices' clip-space positions, `view_proj * (p, 1)` in `f32`. A GPU that
/// projects for itself may fuse the multiply-adds and round differently, which moves a snapped
/// vertex by a sub-pixel step where it lies near a rounding tie: `gpu::preview` draws with these.
pub fn project(positions: &[[f32; 3]], view_proj: Mat4) -> Vec<Vec4> {
    positions.par_iter().map(|p| view_proj * Vec3::from(*p).extend(1.0)).collect()
}

/// The viewport coordinates `(x_f, y_f, z_f)` of a clip-space position (step 3, before snapping).
pub fn to_viewport(clip: Vec4, width: usize, height: usize) -> Vec3 {
    let (half_w, half_h) = (width as f32 * 0.5, height as f32 * 0.5);
    let ndc = clip.truncate() / clip.w;
    Vec3::new(half_w * ndc.x + half_w, -half_h * ndc.y + half_h, ndc.z)
}

/// The snapped viewport `x` and `y` (steps 3 and 4) of a vertex inside the clip volume, `None`
/// outside it (where the triangle is clipped first).
pub fn snapped(clip: Vec4, width: usize, height: usize) -> Option<[i64; 2]> {
    plane_distances(clip).iter().all(|d| *d >= 0.0).then(|| {
        let v = to_viewport(clip, width, height);
        [snap(v.x), snap(v.y)]
    })
}

/// A viewport coordinate snapped to 1/256 pixel, as an integer count of 1/256 pixels.
pub fn snap(coordinate: f32) -> i64 {
    (coordinate * ONE as f32).round_ties_even() as i64
}

/// Calls `f(x, y, b)` for every pixel in `rows` (and within `0..width`) whose centre the
/// triangle with snapped vertices `v` covers (step 4), with `b` its screen-space barycentrics
/// (weights of `v[0]`, `v[1]`, `v[2]`, summing to 1). Pixels come row by row, left to right.
/// Coordinates must stay within `2^30` (1/256 pixels) for the `i64` edge functions to be exact;
/// the guard band keeps the rasterizer's within `2^24`.
pub fn for_each_covered(v: [[i64; 2]; 3], width: usize, rows: Range<usize>, mut f: impl FnMut(usize, usize, [f64; 3])) {
    let edge = |a: [i64; 2], b: [i64; 2], p: [i64; 2]| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let area = edge(v[0], v[1], v[2]);
    if area == 0 {
        return;
    }
    // Order the vertices so the area is positive; `order[k]` is the caller's index of vertex k.
    let order = if area > 0 { [0, 1, 2] } else { [0, 2, 1] };
    let w = order.map(|k| v[k]);
    let area = area.abs();
    // Edge k is opposite vertex k: from w[k + 1] to w[k + 2]; its function is vertex k's weight.
    let ends = [(w[1], w[2]), (w[2], w[0]), (w[0], w[1])];
    // Off the top-left edges a zero edge function is outside: require E >= 1 there.
    let bias = ends.map(|(a, b)| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        if dy < 0 || (dy == 0 && dx > 0) { 0 } else { 1 }
    });

    let min = |c: usize| w.iter().map(|p| p[c]).min().expect("three vertices");
    let max = |c: usize| w.iter().map(|p| p[c]).max().expect("three vertices");
    // The first and last pixel whose centre 256 i + 128 lies within [min, max].
    let first = |lo: i64| -((HALF - lo).div_euclid(ONE));
    let last = |hi: i64| (hi - HALF).div_euclid(ONE);
    let x0 = first(min(0)).max(0);
    let x1 = last(max(0)).min(width as i64 - 1);
    let y0 = first(min(1)).max(rows.start as i64);
    let y1 = last(max(1)).min(rows.end as i64 - 1);
    if x0 > x1 || y0 > y1 {
        return;
    }
    for y in y0..=y1 {
        let py = ONE * y + HALF;
        let mut e = ends.map(|(a, b)| edge(a, b, [ONE * x0 + HALF, py]));
        // Moving one pixel right changes E_ab by -(b.y - a.y) 256.
        let step = ends.map(|(a, b)| -(b[1] - a[1]) * ONE);
        for x in x0..=x1 {
            if (0..3).all(|k| e[k] >= bias[k]) {
                let mut b = [0.0; 3];
                for k in 0..3 {
                    b[order[k]] = e[k] as f64 / area as f64;
                }
                f(x as usize, y as usize, b);
            }
            for k in 0..3 {
                e[k] += step[k];
            }
        }
    }
}

/// A triangle after clipping, ready to rasterize.
#[derive(Clone, Copy, Debug)]
struct SubTriangle {
    triangle: u32,
    /// Snapped viewport coordinates.
    v: [[i64; 2]; 3],
    z: [f64; 3],
    inv_w: [f64; 3],
    /// The barycentric coordinates of each vertex in the original triangle.
    bary: [DVec3; 3],
}

impl SubTriangle {
    /// The rows its bounding box spans within the image, if any.
    fn rows(&self, height: usize) -> Option<Range<usize>> {
        let lo = self.v.iter().map(|p| p[1]).min().expect("three vertices");
        let hi = self.v.iter().map(|p| p[1]).max().expect("three vertices");
        let y0 = (-((HALF - lo).div_euclid(ONE))).max(0);
        let y1 = ((hi - HALF).div_euclid(ONE)).min(height as i64 - 1);
        (y0 <= y1).then(|| y0 as usize..y1 as usize + 1)
    }

    /// Step 6 at screen-space barycentrics `b`.
    fn hit(&self, mesh: &Mesh, b: [f64; 3], depth: f32) -> Hit {
        let q = [0, 1, 2].map(|k| b[k] * self.inv_w[k]);
        let sum = q[0] + q[1] + q[2];
        let weights = (q[0] * self.bary[0] + q[1] * self.bary[1] + q[2] * self.bary[2]) / sum;
        let idx = &mesh.indices[3 * self.triangle as usize..3 * self.triangle as usize + 3];
        let (mut position, mut normal) = (DVec3::ZERO, DVec3::ZERO);
        for (k, &i) in idx.iter().enumerate() {
            position += weights[k] * Vec3::from(mesh.positions[i as usize]).as_dvec3();
            normal += weights[k] * Vec3::from(mesh.normals[i as usize]).as_dvec3();
        }
        Hit { position, normal: normal.normalize_or_zero(), triangle: self.triangle, depth }
    }
}

/// The distances of a clip-space point to the clip planes of step 2 (inside where all `>= 0`).
fn plane_distances(c: Vec4) -> [f32; 6] {
    let g = GUARD_BAND * c.w;
    [c.z, c.w - c.z, c.x + g, g - c.x, c.y + g, g - c.y]
}

/// Clips (where needed) and snaps one triangle: none, one or several sub-triangles.
fn setup(triangle: u32, clip: [Vec4; 3], width: usize, height: usize) -> Vec<SubTriangle> {
    let mut polygon: Vec<(Vec4, DVec3)> = vec![(clip[0], DVec3::X), (clip[1], DVec3::Y), (clip[2], DVec3::Z)];
    if !clip.iter().all(|c| plane_distances(*c).iter().all(|d| *d >= 0.0)) {
        for plane in 0..6 {
            polygon = clip_polygon(&polygon, plane);
            if polygon.len() < 3 {
                return Vec::new();
            }
        }
    }
    let screen: Vec<([i64; 2], f64, f64, DVec3)> = polygon
        .iter()
        .map(|&(c, bary)| {
            let v = to_viewport(c, width, height);
            ([snap(v.x), snap(v.y)], f64::from(v.z), 1.0 / f64::from(c.w), bary)
        })
        .collect();
    (1..screen.len() - 1)
        .map(|i| {
            let corners = [screen[0], screen[i], screen[i + 1]];
            SubTriangle {
                triangle,
                v: corners.map(|c| c.0),
                z: corners.map(|c| c.1),
                inv_w: corners.map(|c| c.2),
                bary: corners.map(|c| c.3),
            }
        })
        .collect()
}

/// One Sutherland-Hodgman step: the part of `polygon` on the inner side of `plane`.
fn clip_polygon(polygon: &[(Vec4, DVec3)], plane: usize) -> Vec<(Vec4, DVec3)> {
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (i, &(a, bary_a)) in polygon.iter().enumerate() {
        let (b, bary_b) = polygon[(i + 1) % polygon.len()];
        let (da, db) = (plane_distances(a)[plane], plane_distances(b)[plane]);
        if da >= 0.0 {
            out.push((a, bary_a));
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push((a + t * (b - a), bary_a + f64::from(t) * (bary_b - bary_a)));
        }
    }
    out
}
