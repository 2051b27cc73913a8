//! Rusinkiewicz half/difference coordinates.
//!
//! The frame is the local shading frame: `z` is the surface normal. `wi` and `wo` both point away
//! from the surface. The half vector is `h = normalize(wi + wo)` with spherical angles
//! `(theta_h, phi_h)`; the difference vector `d` is `wi` expressed in a frame where `h` is the
//! pole: rotate `wi` by `-phi_h` about `z`, then by `-theta_h` about `y` (Rusinkiewicz 1998, and
//! the reference MERL reader `BRDFRead.cpp`). `wo` is then the mirror of `d` about that pole.
//!
//! Angles are computed with `atan2` rather than `acos`, which keeps full precision near
//! `theta_h = 0` where MERL's square-root spacing puts its finest cells (cell 1 starts at
//! 1.9e-4 rad); the WGSL port in the `gpu` crate does the same so both agree in `f32`.

use glam::DVec3;

/// A direction pair in half/difference coordinates (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfDiff {
    pub theta_h: f64,
    pub phi_h: f64,
    pub theta_d: f64,
    /// In `(-pi, pi]`, as `atan2` returns it.
    pub phi_d: f64,
}

/// Unit vector of spherical angles `(theta, phi)` about `z`.
pub fn spherical_dir(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Polar angle of a vector (need not be normalized), accurate near the pole.
pub fn theta_of(v: DVec3) -> f64 {
    (v.x.hypot(v.y)).atan2(v.z)
}

fn rotate_z(v: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    DVec3::new(v.x * c - v.y * s, v.x * s + v.y * c, v.z)
}

fn rotate_y(v: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    DVec3::new(v.x * c + v.z * s, v.y, -v.x * s + v.z * c)
}

/// `(wi, wo)` -> half/difference angles. `wi` and `wo` must be unit vectors with `wi + wo != 0`.
pub fn half_diff(wi: DVec3, wo: DVec3) -> HalfDiff {
    let h = (wi + wo).normalize();
    let theta_h = theta_of(h);
    let phi_h = h.y.atan2(h.x);
    let d = rotate_y(rotate_z(wi, -phi_h), -theta_h);
    HalfDiff { theta_h, phi_h, theta_d: theta_of(d), phi_d: d.y.atan2(d.x) }
}

impl HalfDiff {
    /// Half/difference angles -> `(wi, wo)`, the inverse of [`half_diff`].
    pub fn to_dirs(&self) -> (DVec3, DVec3) {
        let d = spherical_dir(self.theta_d, self.phi_d);
        let d_mirror = DVec3::new(-d.x, -d.y, d.z);
        let to_world = |v: DVec3| rotate_z(rotate_y(v, self.theta_h), self.phi_h);
        (to_world(d), to_world(d_mirror))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng, rngs::StdRng};
    use std::f64::consts::{FRAC_PI_2, PI};

    fn random_upper(rng: &mut StdRng) -> DVec3 {
        let z: f64 = rng.random();
        let phi = 2.0 * PI * rng.random::<f64>();
        spherical_dir(z.acos(), phi)
    }

    #[test]
    fn round_trip_directions() {
        let mut rng = StdRng::seed_from_u64(1);
        for _ in 0..100_000 {
            let (wi, wo) = (random_upper(&mut rng), random_upper(&mut rng));
            let (wi2, wo2) = half_diff(wi, wo).to_dirs();
            assert!((wi - wi2).length() < 1e-12 && (wo - wo2).length() < 1e-12, "{wi} {wo} -> {wi2} {wo2}");
        }
    }

    #[test]
    fn round_trip_angles() {
        let mut rng = StdRng::seed_from_u64(2);
        for _ in 0..100_000 {
            let hd = HalfDiff {
                theta_h: rng.random::<f64>() * FRAC_PI_2,
                phi_h: (rng.random::<f64>() * 2.0 - 1.0) * PI * 0.999,
                theta_d: rng.random::<f64>() * FRAC_PI_2,
                phi_d: (rng.random::<f64>() * 2.0 - 1.0) * PI * 0.999,
            };
            let (wi, wo) = hd.to_dirs();
            let back = half_diff(wi, wo);
            assert!((back.theta_h - hd.theta_h).abs() < 1e-9, "{hd:?} {back:?}");
            assert!((back.theta_d - hd.theta_d).abs() < 1e-9, "{hd:?} {back:?}");
            // phi is undefined at the poles.
            if hd.theta_h > 1e-6 {
                assert!((back.phi_h - hd.phi_h).abs() < 1e-7, "{hd:?} {back:?}");
            }
            if hd.theta_d > 1e-6 {
                assert!((back.phi_d - hd.phi_d).abs() < 1e-7, "{hd:?} {back:?}");
            }
        }
    }

    #[test]
    fn known_configurations() {
        // Mirror configuration: h on the normal, theta_d is the angle of incidence.
        let wi = spherical_dir(0.3, 0.0);
        let wo = spherical_dir(0.3, PI);
        let hd = half_diff(wi, wo);
        assert!(hd.theta_h.abs() < 1e-15 && (hd.theta_d - 0.3).abs() < 1e-15);
        // Retro-reflection: wi = wo, so d is the pole and theta_d = 0.
        let w = spherical_dir(0.7, 1.1);
        let hd = half_diff(w, w);
        assert!((hd.theta_h - 0.7).abs() < 1e-15 && hd.theta_d.abs() < 1e-15);
        // Reciprocity: swapping wi and wo maps phi_d to phi_d + pi.
        let (wi, wo) = (spherical_dir(0.4, 0.2), spherical_dir(1.0, 2.5));
        let (a, b) = (half_diff(wi, wo), half_diff(wo, wi));
        assert!((a.theta_d - b.theta_d).abs() < 1e-12);
        let dphi = (a.phi_d - b.phi_d).rem_euclid(2.0 * PI);
        assert!((dphi - PI).abs() < 1e-12, "{a:?} {b:?}");
    }
}
