//! Cube maps against known answers: a direction-coded map whose prefiltered layers are known in
//! closed form, read at the centre of every texel of all six faces through the KTX2 file, so that
//! a swapped, mirrored or rotated face fails.

use envmap::{EnvMap, MipChain};
use glam::DVec3;
use prefilter::cube::{self, FACES, face_direction, texel_direction, to_world};
use prefilter::ktx::{self, Storage};
use prefilter::{Config, prefilter};

/// `L(w) = (1 + w.x, 1 + w.y, 1 + w.z)`: each channel codes one world axis, so every face shows a
/// different pattern and no symmetry of the cube maps one face onto another unchanged.
fn direction_coded(width: usize) -> EnvMap {
    let height = width / 2;
    let mut rgb = Vec::with_capacity(3 * width * height);
    for y in 0..height {
        for x in 0..width {
            let (u, v) = envmap::geometry::texel_center_uv(x, y, width, height);
            let w = envmap::direction(u, v);
            rgb.extend([1.0 + w.x, 1.0 + w.y, 1.0 + w.z].map(|c| c as f32));
        }
    }
    EnvMap::new(width, height, rgb).unwrap()
}

/// The Phong layer of exponent `n` of [`direction_coded`], exactly: a zonal lobe scales the
/// degree-1 harmonics by its first Legendre coefficient, `int K(t) t dw = (n + 1) / (n + 2)` for
/// the normalized `(n + 1) / (2 pi) max(0, t)^n`, and keeps the constant.
fn known_layer(n: u32, r: DVec3) -> [f64; 3] {
    let k = f64::from(n + 1) / f64::from(n + 2);
    [1.0 + k * r.x, 1.0 + k * r.y, 1.0 + k * r.z]
}

#[test]
fn the_face_table_is_vulkans_and_the_cube_is_y_up() {
    // Face centres and the frame change, spelled out independently of the code's table.
    let centres = [DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z];
    for (face, centre) in centres.iter().enumerate() {
        assert_eq!(face_direction(face, 0.5, 0.5), *centre, "face {}", FACES[face]);
    }
    // Vulkan's selection rule applied to each face's (s, t) recovers them: for +X, sc = -z,
    // tc = -y; for -Y, sc = x, tc = -z; for -Z, sc = -x, tc = -y.
    let d = face_direction(0, 0.25, 0.75);
    assert_eq!((0.5 * (-d.z / d.x + 1.0), 0.5 * (-d.y / d.x + 1.0)), (0.25, 0.75));
    let d = face_direction(3, 0.25, 0.75);
    assert_eq!((0.5 * (d.x / d.y.abs() + 1.0), 0.5 * (-d.z / d.y.abs() + 1.0)), (0.25, 0.75));
    let d = face_direction(5, 0.25, 0.75);
    assert_eq!((0.5 * (-d.x / d.z.abs() + 1.0), 0.5 * (-d.y / d.z.abs() + 1.0)), (0.25, 0.75));
    // +Y up: the zenith is the +Y face's centre, the lat-long map's u = 0 column +X's, u = 1/4 -Z's.
    assert_eq!(to_world(DVec3::Y), DVec3::Z);
    assert_eq!(to_world(DVec3::X), DVec3::X);
    assert_eq!(to_world(DVec3::NEG_Z), DVec3::Y);
    assert!((texel_direction(2, 0, 0, 1) - DVec3::Z).length() < 1e-12);
}

#[test]
fn every_face_texel_equals_the_known_layer_at_its_direction() {
    // Source 512 x 256, layers 128 x 64, faces of 32. The lat-long layers are exact up to the
    // discrete sum over source texels (a few 1e-5 here) and bilinear interpolation of a function
    // of curvature about 1 over texels of 2.8 degrees: (pi / 64)^2 / 8 = 3e-4. Tolerance 1e-3, plus
    // the half-float rounding of the stored value (2^-11 of it).
    let map = direction_coded(512);
    let exponents = vec![1, 16, 256];
    let config = Config { exponents: exponents.clone(), width: 128, height: 64, ..Config::default() };
    let prefiltered = prefilter(&map, &config).unwrap();
    let layers: Vec<&EnvMap> = prefiltered.layers.iter().map(|l| &l.map).collect();
    let encoded = cube::encode_layers(&layers, Storage::Auto, "cube tests").unwrap();
    let decoded = ktx::decode(&encoded.bytes).unwrap();
    let n = 32;
    assert_eq!(decoded.shape, ktx::Shape { width: n, height: n, layers: 3, faces: 6 });
    let mut worst = 0.0f64;
    for (k, &exponent) in exponents.iter().enumerate() {
        for (face, name) in FACES.iter().enumerate() {
            let image = &decoded.levels[0][6 * k + face];
            for j in 0..n {
                for i in 0..n {
                    let expected = known_layer(exponent, texel_direction(face, i, j, n));
                    for c in 0..3 {
                        let got = f64::from(image[3 * (j * n + i) + c]);
                        worst = worst.max((got - expected[c]).abs());
                        assert!(
                            (got - expected[c]).abs() < 1e-3 + expected[c].abs() * 2f64.powi(-11),
                            "n {exponent}, face {name} texel ({i}, {j}) channel {c}: {got} against {}",
                            expected[c]
                        );
                    }
                }
            }
        }
    }
    eprintln!("largest difference from the known layers: {worst:.2e}");
}

#[test]
fn the_mip_chain_goes_down_to_one_texel_faces() {
    let map = direction_coded(256);
    let chain = MipChain::new(&map);
    let encoded = cube::encode_mip_chain(&chain, Storage::Auto, "cube tests").unwrap();
    let decoded = ktx::decode(&encoded.bytes).unwrap();
    assert_eq!(decoded.shape, ktx::Shape { width: 64, height: 64, layers: 0, faces: 6 });
    assert_eq!(decoded.levels.len(), 7, "64, 32, ..., 1");
    // Level 0 is the map itself at the texel directions (the box-filtered levels below blur the
    // linear function only by the curvature of the sphere).
    for (face, name) in FACES.iter().enumerate() {
        let image = &decoded.levels[0][face];
        for (k, texel) in image.chunks_exact(3).enumerate() {
            let w = texel_direction(face, k % 64, k / 64, 64);
            let expected = map.lookup(w);
            for c in 0..3 {
                let tolerance = expected[c].abs() * 2f32.powi(-11);
                assert!((texel[c] - expected[c]).abs() <= tolerance, "face {name} texel {k}: {texel:?}");
            }
            assert!((f64::from(texel[2]) - 1.0 - w.z).abs() < 2e-3, "face {name}: blue codes world z");
        }
    }
    assert_eq!(decoded.levels[6][2].len(), 3, "one texel per face at the last level");
}
