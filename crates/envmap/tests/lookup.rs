//! EnvMap construction, bilinear lookups and means.

use std::f64::consts::PI;

use envmap::EnvMap;
use glam::DVec3;
use rand::{Rng, SeedableRng};

use crate::{assert_close, shared_env};

fn random_map(width: usize, height: usize, seed: u64) -> EnvMap {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    EnvMap::new(width, height, (0..3 * width * height).map(|_| rng.random_range(0.0..10.0)).collect()).expect("map")
}

#[test]
fn new_rejects_what_is_not_a_map() {
    let cases: [(usize, usize, Vec<f32>, &str); 6] = [
        (0, 0, vec![], "empty map: 0 x 0"),
        (6, 2, vec![1.0; 36], "not a lat-long map: 6 x 2, expected width = 2 x height"),
        (4, 2, vec![1.0; 23], "4 x 2 map needs 24 rgb values, got 23"),
        (
            4,
            2,
            [vec![1.0; 8], vec![f32::NAN], vec![1.0; 15]].concat(),
            "non-finite radiance NaN at x 2, y 0, channel B",
        ),
        (
            4,
            2,
            [vec![1.0; 13], vec![f32::INFINITY], vec![1.0; 10]].concat(),
            "non-finite radiance inf at x 0, y 1, channel G",
        ),
        (4, 2, [vec![1.0; 21], vec![-1e-3], vec![1.0; 2]].concat(), "negative radiance -0.001 at x 3, y 1, channel R"),
    ];
    for (width, height, rgb, message) in cases {
        let error = EnvMap::new(width, height, rgb).expect_err(message);
        assert!(matches!(error, envmap::Error::Invalid(_)), "{error}");
        assert_eq!(error.to_string(), message);
    }
    // Zero and negative zero are radiance.
    assert!(EnvMap::new(2, 1, vec![0.0, -0.0, 0.0, 1.0, 2.0, 3.0]).is_ok());
}

/// At a texel centre the lookup is the texel, bit for bit (widths are powers of two here, so the
/// centre coordinates are exact).
#[test]
fn bilinear_is_exact_at_texel_centres() {
    let Some(env) = shared_env() else { return };
    let map = envmap::load(&env.join("quarry_01_1k.hdr")).expect("quarry");
    for y in 0..map.height() {
        for x in 0..map.width() {
            let (u, v) = envmap::geometry::texel_center_uv(x, y, map.width(), map.height());
            assert_eq!(map.lookup_uv(u, v), map.texel(x, y), "texel ({x}, {y})");
        }
    }
    // Through a direction the centre is off by rounding (~1e-16 of a texel), which next to the
    // sun (86 528 beside values near 1) is still below 1e-6 relative.
    for y in 0..map.height() {
        for x in 0..map.width() {
            let got = map.lookup(map.texel_direction(x, y));
            for (c, (g, want)) in got.into_iter().zip(map.texel(x, y)).enumerate() {
                assert!((g - want).abs() <= 1e-6 * want.max(1e-3), "texel ({x}, {y}) channel {c}: {g} vs {want}");
            }
        }
    }
}

/// Halfway between two centres the lookup is their mean; a quarter of the way, 3:1.
#[test]
fn bilinear_interpolates_linearly() {
    let map = random_map(16, 8, 2);
    let (w, h) = (16.0, 8.0);
    for (x, y) in [(3, 2), (10, 5), (0, 0)] {
        let a = map.texel(x, y);
        let b = map.texel(x + 1, y);
        let c = map.texel(x, y + 1);
        let got = map.lookup_uv((x as f64 + 1.0) / w, (y as f64 + 0.5) / h);
        let got_v = map.lookup_uv((x as f64 + 0.5) / w, (y as f64 + 0.75) / h);
        for i in 0..3 {
            assert_close(f64::from(got[i]), 0.5 * f64::from(a[i] + b[i]), 1e-6, "halfway in u");
            assert_close(f64::from(got_v[i]), 0.75 * f64::from(a[i]) + 0.25 * f64::from(c[i]), 1e-6, "quarter in v");
        }
    }
}

/// Across phi = 0 the lookup is continuous: u = 0 and u = 1 are the same meridian, halfway between
/// the last and the first column, and the value changes by O(epsilon) either side.
#[test]
fn bilinear_is_continuous_across_the_seam() {
    let map = random_map(32, 16, 3);
    for y in 0..16 {
        let v = (y as f64 + 0.5) / 16.0;
        let at_0 = map.lookup_uv(0.0, v);
        assert_eq!(at_0, map.lookup_uv(1.0, v));
        let (first, last) = (map.texel(0, y), map.texel(31, y));
        for c in 0..3 {
            assert_close(f64::from(at_0[c]), 0.5 * f64::from(first[c] + last[c]), 1e-6, "seam value");
        }
        for epsilon in [1e-3, 1e-6, 1e-9] {
            let (left, right) = (map.lookup_uv(1.0 - epsilon, v), map.lookup_uv(epsilon, v));
            for c in 0..3 {
                let jump = (left[c] - right[c]).abs();
                assert!(jump <= 2.0 * 32.0 * 10.0 * epsilon as f32 + 1e-5, "row {y}, epsilon {epsilon}: jump {jump}");
            }
        }
        // The same through directions just either side of +x in the xy plane.
        let (theta_sin, theta_cos) = (PI * v).sin_cos();
        let below = map.lookup(DVec3::new(theta_sin, -1e-12, theta_cos));
        let above = map.lookup(DVec3::new(theta_sin, 1e-12, theta_cos));
        for c in 0..3 {
            assert!((below[c] - above[c]).abs() < 1e-5, "row {y}: {below:?} vs {above:?}");
        }
    }
}

/// Within half a texel of a pole the lookup is clamped to the first or last row of centres.
#[test]
fn bilinear_clamps_at_the_poles() {
    let map = random_map(16, 8, 4);
    for u in [0.0, 0.1, 0.53, 0.99] {
        let first_row = map.lookup_uv(u, 0.5 / 8.0);
        assert_eq!(map.lookup_uv(u, 0.0), first_row);
        assert_eq!(map.lookup_uv(u, 0.01), first_row);
        let last_row = map.lookup_uv(u, 7.5 / 8.0);
        assert_eq!(map.lookup_uv(u, 1.0), last_row);
        assert_eq!(map.lookup_uv(u, 1.5), last_row);
    }
    // Not finite coordinates give a value, never a panic.
    let _ = map.lookup_uv(f64::NAN, f64::INFINITY);
    let _ = map.lookup(DVec3::new(f64::NAN, 0.0, 0.0));
}

/// The smallest lat-long map, 2 x 1: two hemispheres of phi, each 2 pi sr.
#[test]
fn tiny_map() {
    let map = EnvMap::new(2, 1, vec![1.0, 2.0, 3.0, 3.0, 4.0, 5.0]).expect("2 x 1");
    assert_close(map.texel_solid_angle(0), 2.0 * PI, 1e-15, "solid angle");
    assert_eq!(map.mean_radiance(), [2.0, 3.0, 4.0]);
    for v in [0.0, 0.3, 0.5, 1.0] {
        assert_eq!(map.lookup_uv(0.25, v), [1.0, 2.0, 3.0]);
        assert_eq!(map.lookup_uv(0.75, v), [3.0, 4.0, 5.0]);
        assert_eq!(map.lookup_uv(0.0, v), [2.0, 3.0, 4.0]);
        assert_eq!(map.lookup_uv(0.5, v), [2.0, 3.0, 4.0]);
    }
    assert_eq!(map.lookup(DVec3::Z), [2.0, 3.0, 4.0]);
}

/// Known answers: a constant map's mean is the constant; radiance 1 on the upper hemisphere and 0
/// below has mean 1/2 (the rows split exactly at the equator).
#[test]
fn solid_angle_weighted_means() {
    let constant = EnvMap::constant(64, 32, [0.25, 1.5, 3.0]).expect("constant");
    for (got, want) in constant.mean_radiance().into_iter().zip([0.25, 1.5, 3.0]) {
        assert_close(got, want, 1e-14, "constant map");
    }
    assert_close(constant.mean_luminance(), 0.2126 * 0.25 + 0.7152 * 1.5 + 0.0722 * 3.0, 1e-14, "luminance");
    let rgb: Vec<f32> = (0..64 * 32).flat_map(|i| if i / 64 < 16 { [1.0, 2.0, 0.0] } else { [0.0; 3] }).collect();
    let hemisphere = EnvMap::new(64, 32, rgb).expect("hemisphere");
    let mean = hemisphere.mean_radiance();
    assert_close(mean[0], 0.5, 1e-14, "upper hemisphere");
    assert_close(mean[1], 1.0, 1e-14, "upper hemisphere");
    assert_eq!(mean[2], 0.0);
    // A plain mean over texels is the same here by symmetry, but not for a polar cap: row 0 alone.
    let rgb: Vec<f32> = (0..64 * 32).flat_map(|i| if i / 64 == 0 { [1.0; 3] } else { [0.0; 3] }).collect();
    let cap = EnvMap::new(64, 32, rgb).expect("cap");
    let want = (1.0 - (PI / 32.0).cos()) / 2.0;
    assert_close(cap.mean_radiance()[0], want, 1e-12, "polar cap");
}

#[test]
fn a_maps_luminance_is_rec_709_per_texel() {
    let map = EnvMap::new(2, 1, vec![1.0, 0.0, 0.0, 0.0, 1.0, 0.0]).expect("map");
    assert_eq!(map.luminance(), vec![0.2126, 0.7152]);
}
