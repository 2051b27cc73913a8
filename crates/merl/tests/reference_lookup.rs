//! The nearest lookup against an independent implementation of the reference MERL reader
//! (`BRDFRead.cpp`: `std_coords_to_half_diff_coords`, `rotate_vector`, `theta_half_index`,
//! `theta_diff_index`, `phi_diff_index`), written here from the published formulas with `acos`
//! and Rodrigues rotations instead of the crate's `atan2` and axis rotations.

use std::f64::consts::{FRAC_PI_2, PI};

use merl::{Dims, half_diff, spherical_dir};
use rand::{Rng, SeedableRng, rngs::StdRng};

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn rotate_vector(v: [f64; 3], axis: [f64; 3], angle: f64) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let dot = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2];
    let x = cross(axis, v);
    [0, 1, 2].map(|k| v[k] * c + axis[k] * dot * (1.0 - c) + x[k] * s)
}

/// The reference's (theta_half, theta_diff, phi_diff) from spherical angles.
fn reference_half_diff(theta_in: f64, fi_in: f64, theta_out: f64, fi_out: f64) -> [f64; 3] {
    let sph = |t: f64, f: f64| [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()];
    let (vin, vout) = (sph(theta_in, fi_in), sph(theta_out, fi_out));
    let mut half = [vin[0] + vout[0], vin[1] + vout[1], vin[2] + vout[2]];
    let norm = (half[0] * half[0] + half[1] * half[1] + half[2] * half[2]).sqrt();
    half = half.map(|v| v / norm);
    let theta_half = half[2].acos();
    let fi_half = half[1].atan2(half[0]);
    let temp = rotate_vector(vin, [0.0, 0.0, 1.0], -fi_half);
    let diff = rotate_vector(temp, [0.0, 1.0, 0.0], -theta_half);
    [theta_half, diff[2].clamp(-1.0, 1.0).acos(), diff[1].atan2(diff[0])]
}

/// Continuous index coordinates of the reference (before truncation) and the cell it picks.
fn reference_cell(hd: [f64; 3]) -> ([f64; 3], [usize; 3]) {
    let [theta_half, theta_diff, mut phi_diff] = hd;
    let x_h = if theta_half <= 0.0 { 0.0 } else { (theta_half / FRAC_PI_2 * 90.0 * 90.0).sqrt() };
    let x_d = theta_diff / (PI * 0.5) * 90.0;
    if phi_diff < 0.0 {
        phi_diff += PI;
    }
    let x_p = phi_diff / PI * 360.0 / 2.0;
    let clamp = |x: f64, n: i64| (x as i64).clamp(0, n - 1) as usize;
    ([x_h, x_d, x_p], [clamp(x_h, 90), clamp(x_d, 90), clamp(x_p, 180)])
}

#[test]
fn nearest_cell_matches_reference_reader_on_a_million_pairs() {
    let mut rng = StdRng::seed_from_u64(20261121);
    let dims = Dims::MERL;
    let (mut borderline, mut out_of_range) = (0, 0);
    let n = 1_000_000;
    for _ in 0..n {
        // Uniform over the upper hemisphere, strictly above the horizon.
        let mut angles = [0.0; 4];
        for k in 0..2 {
            angles[2 * k] = (1.0 - rng.random::<f64>()).acos().min(FRAC_PI_2 - 1e-9);
            angles[2 * k + 1] = 2.0 * PI * rng.random::<f64>();
        }
        let [ti, pi_, to, po] = angles;
        let (coords, expect) = reference_cell(reference_half_diff(ti, pi_, to, po));
        let c = dims.nearest_cell(&half_diff(spherical_dir(ti, pi_), spherical_dir(to, po)));
        if [c.theta_h, c.theta_d, c.phi_d] != expect {
            // The two implementations round differently (acos vs atan2): they may only disagree
            // where the reference's coordinate is within 1e-7 cells of an edge. That bound is
            // ~1e4 times the worst rounding of either path (acos(1 - e) near theta = 1e-4 loses
            // about 1e-12 rad, i.e. under 1e-9 cells after the square root).
            let near_edge = coords.iter().any(|x| (x - x.round()).abs() < 1e-7);
            assert!(near_edge, "cell {c:?} vs reference {expect:?} at coords {coords:?} (angles {angles:?})");
            borderline += 1;
        }
        if c.theta_h >= 90 || c.theta_d >= 90 || c.phi_d >= 180 {
            out_of_range += 1;
        }
    }
    eprintln!("{n} pairs: {borderline} disagree at cell edges");
    assert_eq!(out_of_range, 0);
    assert!(borderline <= 10, "{borderline} of {n} pairs disagree at cell edges");
}
