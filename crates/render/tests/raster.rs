//! The rasterizer against brute-force ray casting of the same triangles, the area of projected
//! quads, and the fill rule on triangles that share edges.

use glam::{DMat4, DVec2, DVec3, DVec4, Mat4, Vec3};
use rand::{Rng, SeedableRng, rngs::StdRng};
use render::raster::{self, GBuffer};
use render::{Camera, Mesh};

/// Pixels whose centre lies within this many pixels of a projected edge are not compared:
/// snapping to 1/256 pixel moves a vertex by up to `sqrt(2) / 512 = 2.8e-3` pixels, and an edge
/// with it; 1/256 adds a margin for the `f32` projection.
const EDGE_MARGIN: f64 = 1.0 / 256.0;

fn merge(meshes: &[Mesh]) -> Mesh {
    let mut out = Mesh::default();
    for m in meshes {
        let base = out.positions.len() as u32;
        out.positions.extend_from_slice(&m.positions);
        out.normals.extend_from_slice(&m.normals);
        out.indices.extend(m.indices.iter().map(|i| base + i));
    }
    out
}

/// A square of half-size `half` in the plane `z = height`, normal `+z`.
fn floor(half: f32, height: f32) -> Mesh {
    let corners = [[-half, -half], [half, -half], [half, half], [-half, half]];
    Mesh {
        positions: corners.iter().map(|c| [c[0], c[1], height]).collect(),
        normals: vec![[0.0, 0.0, 1.0]; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

fn transformed(mesh: &Mesh, translate: Vec3, scale: f32) -> Mesh {
    let mut m = mesh.clone();
    for p in &mut m.positions {
        *p = (Vec3::from(*p) * scale + translate).to_array();
    }
    m
}

/// The nearest intersection of the ray `o + t d` (`t >= 0`) with the triangles, by
/// Moller-Trumbore in `f64`: `(t, triangle, barycentrics)`.
fn cast(mesh: &Mesh, o: DVec3, d: DVec3) -> Option<(f64, usize, [f64; 3])> {
    let mut best: Option<(f64, usize, [f64; 3])> = None;
    for (t_index, tri) in mesh.indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize]).as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-300 {
            continue;
        }
        let s = o - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let t = e2.dot(q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= 0.0 && best.is_none_or(|b| t < b.0) {
            best = Some((t, t_index, [1.0 - u - v, u, v]));
        }
    }
    best
}

/// The part of a triangle in front of the near plane, projected to pixel coordinates (`f64`).
fn projected_polygon(corners: [DVec3; 3], view_proj: DMat4, view: DMat4, near: f64, size: [usize; 2]) -> Vec<DVec2> {
    // Clip in view space against z_view <= -near (the camera looks down -z).
    let depth = |p: DVec3| -view.transform_point3(p).z - near;
    let mut polygon = Vec::new();
    for i in 0..3 {
        let (a, b) = (corners[i], corners[(i + 1) % 3]);
        let (da, db) = (depth(a), depth(b));
        if da >= 0.0 {
            polygon.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            polygon.push(a + (b - a) * (da / (da - db)));
        }
    }
    polygon
        .iter()
        .map(|p| {
            let c = view_proj * p.extend(1.0);
            let ndc = c.truncate() / c.w;
            DVec2::new((ndc.x + 1.0) * 0.5 * size[0] as f64, (1.0 - ndc.y) * 0.5 * size[1] as f64)
        })
        .collect()
}

fn segment_distance(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    (p - (a + t * ab)).length()
}

/// Compares the G-buffer of `mesh` with ray casting at every pixel whose centre is farther than
/// [`EDGE_MARGIN`] from every projected edge; returns the number of pixels compared.
fn compare_with_ray_casting(mesh: &Mesh, camera: &Camera, width: usize, height: usize) -> usize {
    let aspect = width as f32 / height as f32;
    let view_proj_f32: Mat4 = camera.view_proj(aspect);
    let gbuffer: GBuffer = raster::rasterize(mesh, view_proj_f32, width, height).expect("valid mesh");
    let view_proj = view_proj_f32.as_dmat4();
    let inverse = view_proj.inverse();
    let view = camera.view().as_dmat4();
    let polygons: Vec<Vec<DVec2>> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let corners = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]).as_dvec3());
            projected_polygon(corners, view_proj, view, f64::from(camera.near()), [width, height])
        })
        .collect();
    let mut compared = 0;
    for y in 0..height {
        for x in 0..width {
            let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
            let near_edge = polygons.iter().any(|poly| {
                (0..poly.len()).any(|i| segment_distance(centre, poly[i], poly[(i + 1) % poly.len()]) <= EDGE_MARGIN)
            });
            if near_edge {
                continue;
            }
            compared += 1;
            // The ray from the near plane to the far plane through the pixel centre, by
            // unprojecting with the same matrix: hits nearer than the near plane are clipped.
            let ndc = DVec2::new(2.0 * centre.x / width as f64 - 1.0, 1.0 - 2.0 * centre.y / height as f64);
            let unproject = |z: f64| {
                let p: DVec4 = inverse * DVec4::new(ndc.x, ndc.y, z, 1.0);
                p.truncate() / p.w
            };
            let (from, to) = (unproject(0.0), unproject(1.0));
            let hit = cast(mesh, from, to - from).filter(|h| h.0 <= 1.0);
            let got = gbuffer.hit(x, y);
            match (hit, got) {
                (None, None) => {}
                (Some((_, triangle, b)), Some(got)) => {
                    assert_eq!(got.triangle as usize, triangle, "pixel ({x}, {y}): a different triangle");
                    let tri = &mesh.indices[3 * triangle..3 * triangle + 3];
                    let attribute = |values: &[[f32; 3]]| {
                        (0..3).map(|k| b[k] * Vec3::from(values[tri[k] as usize]).as_dvec3()).sum::<DVec3>()
                    };
                    let (position, normal) = (attribute(&mesh.positions), attribute(&mesh.normals).normalize());
                    // The snapped vertices shift the screen-to-triangle map by up to 2.8e-3
                    // pixels, i.e. the pixel's world footprint (larger where the surface is seen
                    // edge-on) times that; 2e-3 pixels of f32 rounding and the ray's own.
                    let footprint =
                        2.0 * (0.5 * f64::from(camera.fov_y())).tan() * (position - from).length() / height as f64;
                    let face = (b_of(mesh, triangle)).dot((to - from).normalize()).abs().max(0.05);
                    let tolerance = 5e-3 * footprint / face + 1e-6;
                    let error = (got.position - position).length();
                    assert!(error <= tolerance, "pixel ({x}, {y}): position off by {error:.2e} > {tolerance:.2e}");
                    // The interpolated normal changes by at most the corners' largest
                    // difference over the triangle's smallest altitude per unit of length.
                    let normal_error = (got.normal - normal).length();
                    let normal_tolerance = tolerance * normal_gradient(mesh, triangle) + 1e-6;
                    assert!(
                        normal_error <= normal_tolerance,
                        "pixel ({x}, {y}): normal off by {normal_error:.2e} > {normal_tolerance:.2e}"
                    );
                }
                (hit, got) => panic!("pixel ({x}, {y}): ray casting {hit:?}, rasterizer {got:?}"),
            }
        }
    }
    compared
}

/// A bound on how fast the (unnormalized) interpolated normal changes across a triangle, per unit
/// of length; normalizing unit-length-ish vectors does not increase it by much (the corners are
/// unit vectors and their mix is at least 0.5 long on these meshes: factor 2).
fn normal_gradient(mesh: &Mesh, triangle: usize) -> f64 {
    let tri = &mesh.indices[3 * triangle..3 * triangle + 3];
    let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize]).as_dvec3());
    let [na, nb, nc] = [0, 1, 2].map(|k| Vec3::from(mesh.normals[tri[k] as usize]).as_dvec3());
    let spread = [(na - nb).length(), (nb - nc).length(), (nc - na).length()].into_iter().fold(0.0, f64::max);
    let longest = [(a - b).length(), (b - c).length(), (c - a).length()].into_iter().fold(0.0, f64::max);
    let altitude = (b - a).cross(c - a).length() / longest;
    2.0 * spread / altitude
}

/// The unit geometric normal of a triangle.
fn b_of(mesh: &Mesh, triangle: usize) -> DVec3 {
    let tri = &mesh.indices[3 * triangle..3 * triangle + 3];
    let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[tri[k] as usize]).as_dvec3());
    (b - a).cross(c - a).normalize()
}

#[test]
fn agrees_with_ray_casting() {
    // A sphere and a torus over a floor that reaches behind the camera (clipped at the near
    // plane and the guard band), from above and at an angle, in a non-square image.
    let mesh = merge(&[
        Mesh::sphere(0.6, 24, 12),
        transformed(&Mesh::torus(0.9, 0.2, 32, 12), Vec3::new(0.0, 0.0, -0.3), 1.0),
        floor(30.0, -0.8),
    ]);
    let camera = Camera::orbit(Vec3::new(0.1, 0.0, 0.0), 3.0, 0.7, 0.35, 50f32.to_radians()).expect("valid");
    let compared = compare_with_ray_casting(&mesh, &camera, 80, 60);
    assert!(compared > 80 * 60 / 2, "only {compared} pixels far from edges");
}

#[test]
fn agrees_with_ray_casting_through_the_near_plane() {
    // A floor 0.01 below the eye: the near plane (0.03 ahead) cuts it across the lower part of
    // the view, so the clipped edge shows, and pixels below it see past the clipped floor.
    let mesh = merge(&[Mesh::sphere(0.5, 24, 12), floor(30.0, -0.01)]);
    let camera = Camera::orbit(Vec3::ZERO, 3.0, 0.3, 0.0, 70f32.to_radians()).expect("valid");
    let compared = compare_with_ray_casting(&mesh, &camera, 64, 64);
    assert!(compared > 64 * 64 / 2, "only {compared} pixels far from edges");
    // Rows below the clipped edge see nothing (the floor is nearer than the near plane there).
    let g = raster::rasterize(&mesh, camera.view_proj(1.0), 64, 64).expect("valid");
    assert!(g.hits[63 * 64..].iter().all(Option::is_none), "the bottom row must be clipped away");
    assert!(g.hits[40 * 64..41 * 64].iter().all(Option::is_some), "row 40 sees the floor");
}

#[test]
fn camera_ray_matches_the_projection() {
    let camera = Camera::orbit(Vec3::new(0.2, -0.1, 0.3), 2.5, 2.0, -0.4, 40f32.to_radians()).expect("valid");
    let (width, height) = (40, 30);
    let inverse = camera.view_proj(width as f32 / height as f32).as_dmat4().inverse();
    for (x, y) in [(0, 0), (39, 0), (20, 15), (0, 29), (39, 29), (7, 22)] {
        let ndc = DVec2::new(2.0 * (x as f64 + 0.5) / width as f64 - 1.0, 1.0 - 2.0 * (y as f64 + 0.5) / height as f64);
        let unproject = |z: f64| {
            let p = inverse * DVec4::new(ndc.x, ndc.y, z, 1.0);
            p.truncate() / p.w
        };
        let expected = (unproject(1.0) - unproject(0.0)).normalize();
        let ray = camera.ray(x, y, width, height);
        assert!((ray - expected).length() < 1e-5, "pixel ({x}, {y}): {ray} vs {expected}");
    }
}

/// The area, in square pixels, of a polygon (shoelace).
fn area(polygon: &[DVec2]) -> f64 {
    0.5 * (0..polygon.len()).map(|i| polygon[i].perp_dot(polygon[(i + 1) % polygon.len()])).sum::<f64>().abs()
}

#[test]
fn covers_the_area_of_projected_quads() {
    let mut rng = StdRng::seed_from_u64(3);
    let camera = Camera::default();
    let (width, height) = (200, 200);
    let view_proj = camera.view_proj(1.0);
    let mut tested = 0;
    while tested < 10 {
        // A random quad (two triangles) within the view, at a random tilt.
        let centre = Vec3::new(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5));
        let axis_u = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
            .normalize()
            * rng.random_range(0.3..0.8);
        let axis_v = axis_u.any_orthonormal_vector() * rng.random_range(0.3..0.8);
        let corners =
            [centre - axis_u - axis_v, centre + axis_u - axis_v, centre + axis_u + axis_v, centre - axis_u + axis_v];
        let mesh = Mesh {
            positions: corners.iter().map(|c| c.to_array()).collect(),
            normals: vec![axis_u.cross(axis_v).normalize().to_array(); 4],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        let projected: Vec<DVec2> = corners
            .iter()
            .map(|c| {
                let p = view_proj.as_dmat4() * c.as_dvec3().extend(1.0);
                DVec2::new((p.x / p.w + 1.0) * 0.5 * width as f64, (1.0 - p.y / p.w) * 0.5 * height as f64)
            })
            .collect();
        let (expected, perimeter) =
            (area(&projected), (0..4).map(|i| (projected[(i + 1) % 4] - projected[i]).length()).sum::<f64>());
        let inside = projected.iter().all(|p| p.x >= 0.0 && p.y >= 0.0 && p.x <= width as f64 && p.y <= height as f64);
        if expected < 500.0 || !inside {
            // Seen nearly edge-on (too few pixels for the comparison to mean much) or cut by
            // the image's border.
            continue;
        }
        tested += 1;
        let covered = raster::rasterize(&mesh, view_proj, width, height).expect("valid").hits.iter().flatten().count();
        // Pixel centres count the area up to the lattice points near the boundary, whose
        // discrepancy grows like the logarithm of an edge's length for generic slopes: far below
        // perimeter / 8. A row of pixels along any edge or along the diagonal (a wrong fill
        // rule, an off-by-one bounding box) exceeds it.
        let tolerance = perimeter / 8.0 + 2.0;
        assert!(
            (covered as f64 - expected).abs() <= tolerance,
            "{covered} pixels for an area of {expected:.1} (tolerance {tolerance:.1})"
        );
    }
}

/// How many times each pixel of a `width x height` viewport is covered by the triangles, given
/// in pixel units (multiplied by 256 and rounded here).
fn coverage_counts(triangles: &[[[f64; 2]; 3]], width: usize, height: usize) -> Vec<u32> {
    let mut counts = vec![0u32; width * height];
    for t in triangles {
        let v = t.map(|p| p.map(|c| (c * 256.0).round() as i64));
        raster::for_each_covered(v, width, 0..height, |x, y, b| {
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-12 && b.iter().all(|&w| w >= 0.0), "{b:?}");
            counts[y * width + x] += 1;
        });
    }
    counts
}

#[test]
fn fill_rule_covers_a_split_square_once() {
    // A rectangle from pixel centre (2.5, 2.5) to (20.5, 14.5): every edge runs through pixel
    // centres, and so does the diagonal (slope 2/3). The top-left rule includes the top and left
    // edges and excludes the bottom and right ones: exactly columns 2 ..= 19, rows 2 ..= 13.
    let (a, b, c, d) = ([2.5, 2.5], [20.5, 2.5], [20.5, 14.5], [2.5, 14.5]);
    for triangles in [[[a, b, c], [a, c, d]], [[a, c, b], [c, a, d]], [[b, d, a], [d, b, c]]] {
        let counts = coverage_counts(&triangles, 24, 18);
        for y in 0..18 {
            for x in 0..24 {
                let expected = u32::from((2..=19).contains(&x) && (2..=13).contains(&y));
                assert_eq!(counts[y * 24 + x], expected, "pixel ({x}, {y}) with {triangles:?}");
            }
        }
    }
}

#[test]
fn fill_rule_covers_a_fan_once() {
    // Eight triangles around a vertex on a pixel centre, corners on pixel centres too, so many
    // edges pass through pixel centres, in every direction. Pixels strictly inside the octagon
    // are covered exactly once, whichever way each triangle winds; none outside.
    let centre = [16.5, 16.5];
    let ring: Vec<[f64; 2]> = [(10, 0), (7, 7), (0, 10), (-7, 7), (-10, 0), (-7, -7), (0, -10), (7, -7)]
        .iter()
        .map(|&(dx, dy)| [centre[0] + f64::from(dx), centre[1] + f64::from(dy)])
        .collect();
    let triangles: Vec<[[f64; 2]; 3]> = (0..8)
        .map(|i| if i % 2 == 0 { [centre, ring[i], ring[(i + 1) % 8]] } else { [ring[(i + 1) % 8], ring[i], centre] })
        .collect();
    let counts = coverage_counts(&triangles, 34, 34);
    let inside = |p: [f64; 2]| {
        // Strictly inside the convex octagon (counter-clockwise in these coordinates).
        (0..8).all(|i| {
            let (a, b) = (ring[i], ring[(i + 1) % 8]);
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) > 0.0
        })
    };
    let on_boundary = |p: [f64; 2]| {
        (0..8).any(|i| {
            let (a, b) = (DVec2::from(ring[i]), DVec2::from(ring[(i + 1) % 8]));
            segment_distance(DVec2::from(p), a, b) < 1e-9
        })
    };
    for y in 0..34 {
        for x in 0..34 {
            let p = [x as f64 + 0.5, y as f64 + 0.5];
            let count = counts[y * 34 + x];
            if inside(p) {
                assert_eq!(count, 1, "pixel ({x}, {y}) inside");
            } else if on_boundary(p) {
                assert!(count <= 1, "pixel ({x}, {y}) on the boundary covered {count} times");
            } else {
                assert_eq!(count, 0, "pixel ({x}, {y}) outside");
            }
        }
    }
}

#[test]
fn nearest_wins_and_ties_go_to_the_first_triangle() {
    let camera = Camera::default();
    let view_proj = camera.view_proj(1.0);
    let near = floor(0.5, 0.0);
    // The default camera looks along -x: planes facing +x, one in front of the other.
    let facing = |m: &Mesh, x: f32| {
        let mut m = m.clone();
        for p in &mut m.positions {
            *p = [x, p[0], p[1]];
        }
        for n in &mut m.normals {
            *n = [1.0, 0.0, 0.0];
        }
        m
    };
    let (front, back) = (facing(&near, 0.5), facing(&near, -0.5));
    for mesh in [merge(&[front.clone(), back.clone()]), merge(&[back.clone(), front.clone()])] {
        let g = raster::rasterize(&mesh, view_proj, 32, 32).expect("valid");
        for hit in g.hits.iter().flatten() {
            assert!((hit.position.x - 0.5).abs() < 1e-6, "the nearer plane must win: {hit:?}");
        }
    }
    // The same plane twice: the first copy wins every pixel.
    let g = raster::rasterize(&merge(&[front.clone(), front]), view_proj, 32, 32).expect("valid");
    assert!(g.hits.iter().flatten().count() > 100);
    assert!(g.hits.iter().flatten().all(|hit| hit.triangle < 2), "ties must go to the first triangle drawn");
}

#[test]
fn snapping_rounds_to_a_256th_of_a_pixel() {
    assert_eq!(raster::snap(0.0), 0);
    assert_eq!(raster::snap(1.0), 256);
    assert_eq!(raster::snap(-2.5), -640);
    // Halfway between two steps rounds to even.
    assert_eq!(raster::snap(0.5 / 256.0), 0);
    assert_eq!(raster::snap(1.5 / 256.0), 2);
    assert_eq!(raster::snap(0.7 / 256.0), 1);
    // The viewport maps clip (0, 0) to the centre and y up to row 0.
    let v = raster::to_viewport(glam::Vec4::new(0.0, 1.0, 0.5, 1.0), 64, 32);
    assert_eq!(v, Vec3::new(32.0, 0.0, 0.5));
}
