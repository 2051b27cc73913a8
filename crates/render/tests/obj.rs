//! Reading Wavefront OBJ text, and refusing damaged files.

use glam::Vec3;
use render::{Error, Mesh};

const CUBE: &str = "# a cube, quads, no normals
o cube
v -1 -1 -1
v 1 -1 -1
v 1 1 -1
v -1 1 -1
v -1 -1 1
v 1 -1 1
v 1 1 1
v -1 1 1
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
";

#[test]
fn a_cube_is_triangulated_centred_and_scaled() {
    // Shifted and scaled: the reader undoes both.
    let text: String = CUBE
        .lines()
        .map(|line| match line.strip_prefix("v ") {
            Some(rest) => {
                let c: Vec<f32> = rest.split_whitespace().map(|w| w.parse().expect("a number")).collect();
                format!("v {} {} {}\n", 5.0 * c[0] + 10.0, 5.0 * c[1] - 3.0, 5.0 * c[2] + 1.0)
            }
            None => format!("{line}\n"),
        })
        .collect();
    let mesh = Mesh::from_obj(&text).expect("a valid file");
    assert_eq!(mesh.n_triangles(), 12);
    assert_eq!(mesh.positions.len(), 8);
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let (p, n) = (Vec3::from(*p), Vec3::from(*n));
        // Corners of a cube of half-size 1 / sqrt(3) centred at the origin.
        assert!((p.length() - 1.0).abs() < 1e-6, "{p}");
        assert!(p.abs().max_element() - p.abs().min_element() < 1e-6, "{p}");
        // Smooth normals: unit length, pointing out of the corner.
        assert!((n.length() - 1.0).abs() < 1e-6);
        assert!(n.dot(p.normalize()) > 0.5, "normal {n} at corner {p}");
    }
    // Triangles are the faces' halves: total area 6 (2 / sqrt(3))^2.
    let area: f32 = mesh
        .indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(mesh.positions[t[k] as usize]));
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    assert!((area - 6.0 * 4.0 / 3.0).abs() < 1e-5, "{area}");
}

#[test]
fn file_normals_are_used_and_normalized() {
    let mesh = Mesh::from_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 3\nf 1//1 2//1 3//1\n").expect("valid");
    assert_eq!(mesh.n_triangles(), 1);
    assert!(mesh.normals.iter().all(|n| *n == [0.0, 0.0, 1.0]), "{:?}", mesh.normals);
    // The same triangle without normals gets the face normal, also +z (counter-clockwise).
    let mesh = Mesh::from_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("valid");
    assert!(mesh.normals.iter().all(|n| *n == [0.0, 0.0, 1.0]), "{:?}", mesh.normals);
}

#[test]
fn relative_indices_polygons_and_objects() {
    let text = "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\nf -5 -4 -3 -1 -2\no b\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 6 7 8\n";
    let mesh = Mesh::from_obj(text).expect("valid");
    // A pentagon (three triangles) and a triangle, the second object's indices offset.
    assert_eq!(mesh.n_triangles(), 4);
    mesh.validate().expect("consistent");
    // The pentagon lies at the lower z, the second object's triangle at the upper one.
    let z: Vec<f32> = mesh.indices.iter().map(|&i| mesh.positions[i as usize][2]).collect();
    assert!(z[..9].iter().all(|&v| v == z[0]) && z[9..].iter().all(|&v| v == z[9]), "{z:?}");
    assert!(z[0] < 0.0 && z[9] > 0.0, "{z:?}");
}

#[test]
fn damaged_files_are_refused() {
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases = [
        ("", "no faces"),
        ("# nothing\nv 0 0 0\n", "no faces"),
        (&format!("{tri}f 1 2\n"), "no faces"),
        (&format!("{tri}f 1 2 4\n"), "line 4: vertex index 4 is out of range"),
        (&format!("{tri}f 0 1 2\n"), "line 4: vertex index 0 is out of range"),
        (&format!("{tri}f -4 1 2\n"), "line 4: vertex index -4 is out of range"),
        (&format!("{tri}f 1/0 2/1 3/1\n"), "texture coordinate index 0"),
        (&format!("{tri}f 1//1 2//1 3//1\n"), "normal index 1 is out of range"),
        (&format!("{tri}f 1 2 99999999999999999999\n"), "is not an integer"),
        (&format!("{tri}f 1 2 x\n"), "is not an integer"),
        (&format!("{tri}f 1/1/1/1 2 3\n"), "bad face vertex"),
        ("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
        ("v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "zero area"),
        ("v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n", "span no volume"),
        (&format!("{tri}vn 0 0 0\nf 1//1 2//1 3//1\n"), "zero or not finite"),
        ("v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "obj: "),
    ];
    for (text, expected) in cases {
        match Mesh::from_obj(text) {
            Err(Error::Invalid(message)) => {
                assert!(message.contains(expected), "{text:?}: {message:?} does not say {expected:?}")
            }
            other => panic!("{text:?}: expected an error saying {expected:?}, got {other:?}"),
        }
    }
}
