//! The parameterization: known directions, round trips, solid angles.

use std::f64::consts::PI;

use envmap::geometry::{texel_center_uv, uv_jacobian};
use envmap::{direction, texel_solid_angle, uv};
use glam::DVec3;
use rand::{Rng, SeedableRng};

use crate::assert_close;

#[track_caller]
fn assert_vec(a: DVec3, b: DVec3, tolerance: f64) {
    assert!((a - b).length() <= tolerance, "{a} vs {b}");
}

/// The orientation the crate documents (and the bandwidth crate assumes).
#[test]
fn known_directions() {
    let cases = [
        ((0.0, 0.5), DVec3::X),
        ((0.25, 0.5), DVec3::Y),
        ((0.5, 0.5), DVec3::NEG_X),
        ((0.75, 0.5), DVec3::NEG_Y),
        ((0.0, 0.0), DVec3::Z),
        ((0.0, 1.0), DVec3::NEG_Z),
    ];
    for ((u, v), wi) in cases {
        assert_vec(direction(u, v), wi, 1e-15);
        let (got_u, got_v) = uv(wi);
        assert!((got_u - u).abs() < 1e-15 && (got_v - v).abs() < 1e-15, "uv({wi}) = ({got_u}, {got_v})");
    }
    // Row 0 is near +z; increasing x turns from +x towards +y.
    let (u, v) = texel_center_uv(1, 0, 8, 4);
    let wi = direction(u, v);
    assert!(wi.z > 0.9 && wi.x > 0.0 && wi.y > 0.0, "{wi}");
}

#[test]
fn uv_direction_round_trip() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    for _ in 0..100_000 {
        let (u, v): (f64, f64) = (rng.random(), rng.random_range(1e-6..1.0 - 1e-6));
        let (u2, v2) = uv(direction(u, v));
        // u wraps: 0.9999999999999999 may come back as 0.
        let du = (u2 - u).abs().min(1.0 - (u2 - u).abs());
        assert!(du < 1e-12 / v.min(1.0 - v) && (v2 - v).abs() < 1e-13, "({u}, {v}) -> ({u2}, {v2})");
        let wi = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let (u, v) = uv(wi * 3.0);
        assert!((0.0..1.0).contains(&u) && (0.0..=1.0).contains(&v));
        assert_vec(direction(u, v), wi.normalize(), 1e-14);
    }
}

#[test]
fn uv_stays_in_range_at_the_seam_and_poles() {
    for wi in [DVec3::new(1.0, -1e-300, 0.0), DVec3::new(1.0, -0.0, 0.0), DVec3::new(-1.0, -0.0, 0.3), DVec3::ZERO] {
        let (u, v) = uv(wi);
        assert!((0.0..1.0).contains(&u) && (0.0..=1.0).contains(&v), "uv({wi}) = ({u}, {v})");
    }
    assert_eq!(uv(DVec3::new(0.0, 0.0, -2.0)), (0.0, 1.0));
}

#[test]
fn solid_angles_sum_to_4_pi() {
    for (width, height) in [(2, 1), (4, 2), (6, 3), (64, 32), (1024, 512), (16384, 8192)] {
        let total: f64 = (0..height).map(|y| width as f64 * texel_solid_angle(y, width, height)).sum();
        assert_close(total, 4.0 * PI, 1e-12, &format!("{width} x {height}"));
    }
}

/// Against the textbook form and, near the pole, the small-angle limit.
#[test]
fn solid_angle_is_the_cell_integral() {
    let (width, height) = (1024, 512);
    for y in [0, 1, 100, 255, 256, 511] {
        let theta0 = PI * y as f64 / height as f64;
        let theta1 = PI * (y + 1) as f64 / height as f64;
        let textbook = (theta0.cos() - theta1.cos()) * 2.0 * PI / width as f64;
        assert_close(texel_solid_angle(y, width, height), textbook, 1e-10, &format!("row {y}"));
    }
    // Row 0 is a spherical cap sliver: (1 - cos(pi / H)) 2 pi / W.
    let cap = 2.0 * (PI / 2.0 / height as f64).sin().powi(2) * 2.0 * PI / width as f64;
    assert_close(texel_solid_angle(0, width, height), cap, 1e-14, "row 0");
}

/// The Jacobian integrates to 4 pi over the unit square (midpoint rule, error ~1e-8).
#[test]
fn uv_jacobian_integrates_to_4_pi() {
    let n = 10_000;
    let total: f64 = (0..n).map(|i| uv_jacobian((i as f64 + 0.5) / n as f64) / n as f64).sum();
    assert_close(total, 4.0 * PI, 1e-7, "integral of the jacobian");
}
