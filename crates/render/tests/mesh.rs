//! The meshes made here: closed, wound outwards, with unit normals that point out.

use glam::Vec3;
use render::Mesh;

/// Every triangle's geometric normal points the way of its vertices' normals; returns the total
/// area.
fn check_outward(mesh: &Mesh) -> f32 {
    mesh.validate().expect("a consistent mesh");
    let mut area = 0.0;
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]));
        let n: Vec3 = t.iter().map(|&i| Vec3::from(mesh.normals[i as usize])).sum();
        let face = (b - a).cross(c - a);
        assert!(face.length() > 0.0, "degenerate triangle {t:?}");
        assert!(face.dot(n) > 0.0, "triangle {t:?} winds inwards");
        area += 0.5 * face.length();
    }
    for n in &mesh.normals {
        assert!((Vec3::from(*n).length() - 1.0).abs() < 1e-6);
    }
    area
}

#[test]
fn sphere_is_round_and_wound_outwards() {
    let (segments, rings) = (24, 12);
    let mesh = Mesh::sphere(2.0, segments, rings);
    assert_eq!(mesh.positions.len(), 2 + (rings - 1) * segments);
    assert_eq!(mesh.n_triangles(), 2 * segments * (rings - 1));
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let (p, n) = (Vec3::from(*p), Vec3::from(*n));
        assert!((p.length() - 2.0).abs() < 1e-6 && (p / 2.0 - n).length() < 1e-6, "{p} {n}");
    }
    // An inscribed polyhedron: a little less than the sphere's area, 16 pi.
    let area = check_outward(&mesh);
    assert!(area < 16.0 * std::f32::consts::PI && area > 0.97 * 16.0 * std::f32::consts::PI, "{area}");
    // Counts below the minimums are raised.
    assert_eq!(Mesh::sphere(1.0, 0, 0).n_triangles(), 2 * 3);
}

#[test]
fn torus_is_wound_outwards() {
    let mesh = Mesh::torus(1.0, 0.25, 32, 16);
    assert_eq!(mesh.n_triangles(), 2 * 32 * 16);
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let (p, n) = (Vec3::from(*p), Vec3::from(*n));
        // The tube's centre circle lies 0.25 behind every vertex along its normal.
        let centre = p - 0.25 * n;
        assert!((centre.truncate().length() - 1.0).abs() < 1e-6 && centre.z.abs() < 1e-6, "{p} {n}");
    }
    // Area 4 pi^2 R r for the smooth torus; the polyhedron is a little smaller.
    let area = check_outward(&mesh);
    let smooth = 4.0 * std::f32::consts::PI.powi(2) * 0.25;
    assert!(area < smooth && area > 0.97 * smooth, "{area}");
}
