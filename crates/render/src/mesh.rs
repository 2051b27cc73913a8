//! Triangle meshes: a UV sphere and a torus made here, and Wavefront OBJ files.

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::Vec3;

use crate::error::Error;

/// An indexed triangle mesh in world space: `indices` holds three vertex indices per triangle,
/// each vertex has a position and a unit normal (interpolated across triangles for smooth
/// shading). The fields are public; [`Mesh::validate`] checks what the renderers rely on.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Meshes with more vertices are refused (before allocating): far beyond what a preview
    /// needs, and it keeps every index within `u32`.
    pub const MAX_VERTICES: usize = 1 << 24;
    /// Meshes with more triangles are refused (before allocating).
    pub const MAX_TRIANGLES: usize = 1 << 24;
    /// OBJ text longer than this is refused before parsing.
    pub const MAX_OBJ_BYTES: usize = 1 << 30;

    /// A UV sphere centred at the origin, its axis along `z`: `segments` steps of longitude
    /// (at least 3) and `rings` of latitude (at least 2; smaller counts are raised to these), one
    /// vertex at each pole, normals exactly radial. Triangles wind counter-clockwise seen from
    /// outside.
    pub fn sphere(radius: f32, segments: usize, rings: usize) -> Mesh {
        let (segments, rings) = (segments.max(3), rings.max(2));
        let mut mesh = Mesh::default();
        let mut push = |normal: [f64; 3]| {
            mesh.normals.push(normal.map(|c| c as f32));
            mesh.positions.push(normal.map(|c| (c * f64::from(radius)) as f32));
        };
        push([0.0, 0.0, 1.0]);
        for i in 1..rings {
            let theta = PI * i as f64 / rings as f64;
            for j in 0..segments {
                let phi = 2.0 * PI * j as f64 / segments as f64;
                push([theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]);
            }
        }
        push([0.0, 0.0, -1.0]);
        let south = (mesh.positions.len() - 1) as u32;
        // Vertex j of ring i (1 ..= rings - 1).
        let ring = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
        for j in 0..segments {
            mesh.indices.extend([0, ring(1, j), ring(1, j + 1)]);
        }
        for i in 1..rings - 1 {
            for j in 0..segments {
                let (a, b, c, d) = (ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1));
                mesh.indices.extend([a, b, c, a, c, d]);
            }
        }
        for j in 0..segments {
            mesh.indices.extend([ring(rings - 1, j), south, ring(rings - 1, j + 1)]);
        }
        mesh
    }

    /// A torus around the `z` axis: the tube's centre circle has radius `major`, the tube radius
    /// `minor`; `segments` steps around the axis and `sides` around the tube (each at least 3).
    pub fn torus(major: f32, minor: f32, segments: usize, sides: usize) -> Mesh {
        let (segments, sides) = (segments.max(3), sides.max(3));
        let mut mesh = Mesh::default();
        for i in 0..segments {
            let phi = 2.0 * PI * i as f64 / segments as f64;
            for j in 0..sides {
                let psi = 2.0 * PI * j as f64 / sides as f64;
                let normal = [psi.cos() * phi.cos(), psi.cos() * phi.sin(), psi.sin()];
                let centre = [f64::from(major) * phi.cos(), f64::from(major) * phi.sin(), 0.0];
                mesh.normals.push(normal.map(|c| c as f32));
                mesh.positions.push(std::array::from_fn(|k| (centre[k] + f64::from(minor) * normal[k]) as f32));
            }
        }
        let vertex = |i: usize, j: usize| ((i % segments) * sides + j % sides) as u32;
        for i in 0..segments {
            for j in 0..sides {
                let (a, b, c, d) = (vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1));
                mesh.indices.extend([a, b, c, a, c, d]);
            }
        }
        mesh
    }

    /// Reads a Wavefront OBJ file (`v`, `vn` and `f` lines; texture coordinates, groups and
    /// materials are ignored). Polygons are triangulated as fans; the mesh is centred on its
    /// bounding box's centre and scaled so that its farthest vertex is at distance 1. Normals
    /// come from the file when every face vertex names one (normalized), else they are the
    /// area-weighted mean of the normals of the triangles around each position (vertices at the
    /// same position share it, so seams of texture coordinates stay smooth).
    ///
    /// Errors name the line: a face index of 0, beyond the vertices defined before it, or not an
    /// integer; NaN or infinite coordinates; a zero normal in the file; no triangle, or only
    /// triangles of zero area. Sizes are checked against [`Mesh::MAX_OBJ_BYTES`],
    /// [`Mesh::MAX_VERTICES`] and [`Mesh::MAX_TRIANGLES`] before anything is parsed.
    pub fn from_obj(text: &str) -> Result<Mesh, Error> {
        if text.len() > Mesh::MAX_OBJ_BYTES {
            return Err(Error::LimitExceeded(format!(
                "obj file of {} bytes, the limit is {}",
                text.len(),
                Mesh::MAX_OBJ_BYTES
            )));
        }
        let scan = scan_obj(text)?;
        if scan.triangles == 0 {
            return Err(Error::Invalid("obj: no faces with three or more vertices".into()));
        }
        let options =
            tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
        let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| {
            // Materials are not read: no file is opened, whatever `mtllib` names.
            Ok(Default::default())
        })
        .map_err(|e| Error::Invalid(format!("obj: {e}")))?;

        let mut mesh = Mesh::default();
        let mut file_normals = scan.all_have_normals;
        for model in &models {
            let m = &model.mesh;
            let base = mesh.positions.len();
            let n_vertices = m.positions.len() / 3;
            if base + n_vertices > Mesh::MAX_VERTICES {
                return Err(Error::LimitExceeded(format!("obj: more than {} vertices", Mesh::MAX_VERTICES)));
            }
            if m.normals.len() != m.positions.len() {
                file_normals = false;
            }
            for p in m.positions.chunks_exact(3) {
                let p = [p[0], p[1], p[2]];
                if !p.iter().all(|c| c.is_finite()) {
                    return Err(Error::Invalid(format!("obj: vertex position {p:?} is not finite")));
                }
                mesh.positions.push(p);
            }
            if file_normals {
                for n in m.normals.chunks_exact(3) {
                    let v = Vec3::new(n[0], n[1], n[2]);
                    if !v.is_finite() || v.length_squared() == 0.0 {
                        return Err(Error::Invalid(format!("obj: normal {v} is zero or not finite")));
                    }
                    mesh.normals.push(v.normalize().to_array());
                }
            }
            mesh.indices.extend(m.indices.iter().map(|&i| base as u32 + i));
        }
        if mesh.indices.is_empty() {
            return Err(Error::Invalid("obj: no triangles".into()));
        }
        normalize_placement(&mut mesh.positions)?;
        if !file_normals {
            mesh.normals = smooth_normals(&mesh.positions, &mesh.indices);
        }
        let any_area = mesh.indices.chunks_exact(3).any(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]));
            (b - a).cross(c - a).length_squared() > 0.0
        });
        if !any_area {
            return Err(Error::Invalid("obj: every triangle has zero area".into()));
        }
        mesh.validate()?;
        Ok(mesh)
    }

    /// The number of triangles.
    pub fn n_triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// Checks what the renderers rely on: as many normals as positions, whole triangles (at least
    /// one), every index in range, finite values, and the size limits.
    pub fn validate(&self) -> Result<(), Error> {
        if self.positions.len() > Mesh::MAX_VERTICES || self.indices.len() / 3 > Mesh::MAX_TRIANGLES {
            return Err(Error::LimitExceeded(format!(
                "mesh of {} vertices and {} triangles, the limits are {} and {}",
                self.positions.len(),
                self.indices.len() / 3,
                Mesh::MAX_VERTICES,
                Mesh::MAX_TRIANGLES
            )));
        }
        if self.normals.len() != self.positions.len() {
            return Err(Error::Invalid(format!(
                "mesh has {} positions but {} normals",
                self.positions.len(),
                self.normals.len()
            )));
        }
        if self.indices.is_empty() || !self.indices.len().is_multiple_of(3) {
            return Err(Error::Invalid(format!(
                "mesh has {} indices, expected a positive multiple of 3",
                self.indices.len()
            )));
        }
        if let Some(i) = self.indices.iter().position(|&i| i as usize >= self.positions.len()) {
            return Err(Error::Invalid(format!(
                "mesh index {} at position {i} is out of range for {} vertices",
                self.indices[i],
                self.positions.len()
            )));
        }
        for (what, values) in [("position", &self.positions), ("normal", &self.normals)] {
            if let Some(i) = values.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
                return Err(Error::Invalid(format!("mesh vertex {i} has a non-finite {what} {:?}", values[i])));
            }
        }
        Ok(())
    }
}

/// What a first pass over the OBJ text found.
struct ObjScan {
    triangles: usize,
    all_have_normals: bool,
}

/// Checks every face index against the vertices defined before it (as the format requires), so
/// that the parser never sees an index of 0 or one out of range (its index arithmetic would
/// overflow), and counts the triangles against the limit before anything is allocated. `f` and
/// `l` lines are checked alike: the parser reads both as faces.
fn scan_obj(text: &str) -> Result<ObjScan, Error> {
    // Positions, texture coordinates and normals defined so far.
    let mut counts = [0usize; 3];
    let mut triangles = 0usize;
    let mut all_have_normals = true;
    for (number, line) in text.lines().enumerate() {
        let number = number + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => counts[2] += 1,
            Some("f" | "l") => {
                let mut corners = 0;
                for word in words {
                    corners += 1;
                    let parts: Vec<&str> = word.split('/').collect();
                    if parts.len() > 3 {
                        return Err(Error::Invalid(format!("obj line {number}: bad face vertex {word:?}")));
                    }
                    if parts.get(2).is_none_or(|p| p.is_empty()) {
                        all_have_normals = false;
                    }
                    for (slot, part) in parts.iter().enumerate().filter(|(_, p)| !p.is_empty()) {
                        let what = ["vertex", "texture coordinate", "normal"][slot];
                        let index: i64 = part.parse().map_err(|_| {
                            Error::Invalid(format!("obj line {number}: {what} index {part:?} is not an integer"))
                        })?;
                        let defined = counts[slot];
                        let in_range = match index {
                            0 => false,
                            i if i > 0 => i as u64 <= defined as u64,
                            i => i.unsigned_abs() <= defined as u64,
                        };
                        if !in_range {
                            return Err(Error::Invalid(format!(
                                "obj line {number}: {what} index {index} is out of range, {defined} defined before it"
                            )));
                        }
                    }
                }
                // The parser reads an `l` line of three or more vertices as a polygon too.
                if corners >= 3 {
                    triangles += corners - 2;
                }
                if triangles > Mesh::MAX_TRIANGLES {
                    return Err(Error::LimitExceeded(format!("obj: more than {} triangles", Mesh::MAX_TRIANGLES)));
                }
            }
            _ => {}
        }
    }
    Ok(ObjScan { triangles, all_have_normals })
}

/// Moves the bounding box's centre to the origin and scales the farthest vertex to distance 1.
fn normalize_placement(positions: &mut [[f32; 3]]) -> Result<(), Error> {
    let (mut lo, mut hi) = (glam::DVec3::splat(f64::INFINITY), glam::DVec3::splat(f64::NEG_INFINITY));
    for p in positions.iter() {
        let p = Vec3::from(*p).as_dvec3();
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let centre = 0.5 * (lo + hi);
    let radius = positions.iter().map(|p| (Vec3::from(*p).as_dvec3() - centre).length()).fold(0.0, f64::max);
    if !(radius > 0.0 && radius.is_finite()) {
        return Err(Error::Invalid(format!("obj: the vertices span no volume (radius {radius})")));
    }
    for p in positions.iter_mut() {
        *p = ((Vec3::from(*p).as_dvec3() - centre) / radius).as_vec3().to_array();
    }
    Ok(())
}

/// Area-weighted vertex normals, shared by all vertices at the same position. A vertex that only
/// touches triangles of zero area (it can never cover a pixel) gets `+z`.
fn smooth_normals(positions: &[[f32; 3]], indices: &[u32]) -> Vec<[f32; 3]> {
    // `+ 0.0` turns -0 into +0, so the two zeros are one position.
    let key = |p: &[f32; 3]| p.map(|c| (c + 0.0).to_bits());
    let mut sums: HashMap<[u32; 3], glam::DVec3> = HashMap::new();
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(positions[t[k] as usize]).as_dvec3());
        // Twice the area times the unit normal: larger triangles weigh more.
        let n = (b - a).cross(c - a);
        for &i in t {
            *sums.entry(key(&positions[i as usize])).or_default() += n;
        }
    }
    positions
        .iter()
        .map(|p| {
            let n = sums.get(&key(p)).copied().unwrap_or_default();
            let n = if n.length_squared() > 0.0 { n.normalize() } else { glam::DVec3::Z };
            n.as_vec3().to_array()
        })
        .collect()
}
