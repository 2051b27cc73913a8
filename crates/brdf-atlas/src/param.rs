//! The two parameterizations of the atlas (crate docs, "Incident directions" and "Lobe
//! images"): the grid of
//! incident directions (rows of equal solid angle in `theta_i`, columns in `phi_i`) and the
//! image of an outgoing lobe (an azimuthal equidistant projection of the hemisphere of `wo` in
//! the frame of the plane of incidence, continued below the horizon by an odd reflection),
//! with the Jacobian that turns cycles per pixel into cycles per radian.
//!
//! Both images are seen from `+z`, looking down at the surface; normalized coordinates
//! `(u, v)` in `[0, 1]^2` put the centre of cell `i` of `n` at `(i + 1/2) / n`, like texture
//! coordinates, `u` along a row (column index `x` or `i`), `v` down the rows (`y` or `j`).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::DVec3;

/// The unit vector of polar angle `theta` whose azimuth is that of the planar vector `(x, y)`
/// (the azimuth 0 when it is zero).
fn direction_from_disk(x: f64, y: f64, theta: f64) -> DVec3 {
    let r = x.hypot(y);
    let (s, c) = theta.sin_cos();
    if r == 0.0 { DVec3::new(0.0, 0.0, c) } else { DVec3::new(s * x / r, s * y / r, c) }
}

/// The grid of incident directions: `lobes x lobes` cells. Row `j` holds the directions of
/// polar angle `cos(theta_i) = 1 - (j + 1/2) / lobes` (rows of equal solid angle, finer towards
/// grazing incidence where lobes change fastest); column `i` the azimuth
/// `phi_i = 2 pi (i + 1/2) / lobes` (crate docs, "Incident directions").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IncidentGrid {
    pub lobes: usize,
}

impl IncidentGrid {
    pub fn new(lobes: usize) -> Self {
        Self { lobes }
    }

    /// `theta_i` of row `j`.
    pub fn theta_i(&self, j: usize) -> f64 {
        (1.0 - (j as f64 + 0.5) / self.lobes as f64).acos()
    }

    /// `phi_i` of column `i`.
    pub fn phi_i(&self, i: usize) -> f64 {
        TAU * (i as f64 + 0.5) / self.lobes as f64
    }

    /// The incident direction of lobe `(i, j)` (column `i`, row `j`), in the tangent frame.
    pub fn wi(&self, i: usize, j: usize) -> DVec3 {
        merl::spherical_dir(self.theta_i(j), self.phi_i(i))
    }

    /// The normalized coordinates `(u, v)` of a direction of the upper hemisphere:
    /// `u = phi_i / 2 pi` (wrapped to `[0, 1]`), `v = 1 - cos(theta_i)`; lobe `(i, j)` covers `u` in
    /// `[i, i + 1) / lobes`, likewise `v`. `wi` need not be normalized; directions below the
    /// horizon clamp to it.
    pub fn uv(&self, wi: DVec3) -> (f64, f64) {
        let wi = wi.normalize();
        let phi = wi.y.atan2(wi.x).rem_euclid(TAU);
        (phi / TAU, 1.0 - wi.z.clamp(0.0, 1.0))
    }
}

/// Turns a direction of the tangent frame into the frame of the plane of incidence of an
/// incident direction of azimuth `phi_i`: the rotation by `-phi_i` about `z`, after which `wi`
/// lies in the `x z` half-plane with `x > 0`. Lobe images are drawn in that frame.
pub fn to_incidence_frame(w: DVec3, phi_i: f64) -> DVec3 {
    let (s, c) = phi_i.sin_cos();
    DVec3::new(c * w.x + s * w.y, -s * w.x + c * w.y, w.z)
}

/// The image of an outgoing lobe: `size x size` pixels over the square `[-1, 1]^2`, an azimuthal
/// equidistant projection of the hemisphere of `wo` in the frame of the plane of incidence
/// ([`to_incidence_frame`]: `wi` towards `+x`, its mirror direction on the left half): the disk
/// point `(a, b) = r (cos phi, sin phi)` is the direction `theta_o = (pi / 2) r`,
/// `phi_o - phi_i = phi`; column `x` grows with `a`, row `y` with `-b`. The corners (`r > 1`, up to
/// `theta_o = 127` degrees) are below the horizon, where the BRDF does not exist: a corner pixel
/// holds the odd reflection of the lobe across the horizon along its radius,
/// `2 f(pi / 2) - f(pi - theta_o)` ([`Sample::Reflected`]), which continues the image with its
/// slope, so that the wavelets (D4 ignores linear trends) see neither a jump nor a kink at the
/// horizon (crate docs, "Lobe images").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeMap {
    pub size: usize,
}

/// What one pixel of a lobe image holds: the BRDF at one direction, or, below the horizon, a
/// combination of two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// `f(wo)`.
    Direct(DVec3),
    /// `2 f(horizon) - f(mirrored)`: `horizon` is the direction of the pixel's azimuth on the
    /// horizon, `mirrored` its direction reflected across the horizon (`wo.z -> -wo.z`).
    Reflected { horizon: DVec3, mirrored: DVec3 },
}

impl Sample {
    /// The pixel's value for a BRDF `f` (luminance of `f(wi, wo)` at fixed `wi`); `None` where
    /// `f` has no value at a direction it needs.
    pub fn eval(&self, mut f: impl FnMut(DVec3) -> Option<f64>) -> Option<f64> {
        match *self {
            Sample::Direct(wo) => f(wo),
            Sample::Reflected { horizon, mirrored } => Some(2.0 * f(horizon)? - f(mirrored)?),
        }
    }
}

impl LobeMap {
    pub fn new(size: usize) -> Self {
        Self { size }
    }

    /// The square coordinates `(a, b)` of the centre of pixel `(x, y)`.
    fn square(&self, x: usize, y: usize) -> (f64, f64) {
        let n = self.size as f64;
        (2.0 * (x as f64 + 0.5) / n - 1.0, 1.0 - 2.0 * (y as f64 + 0.5) / n)
    }

    /// The polar angle `theta_o` of the projection at the centre of pixel `(x, y)`; above
    /// `pi / 2` in the corners, below the horizon.
    pub fn theta(&self, x: usize, y: usize) -> f64 {
        let (a, b) = self.square(x, y);
        FRAC_PI_2 * a.hypot(b)
    }

    /// The direction of the projection at the centre of pixel `(x, y)` (below the horizon in
    /// the corners).
    pub fn direction(&self, x: usize, y: usize) -> DVec3 {
        let (a, b) = self.square(x, y);
        direction_from_disk(a, b, FRAC_PI_2 * a.hypot(b))
    }

    /// What pixel `(x, y)` holds ([`Sample`]).
    pub fn sample(&self, x: usize, y: usize) -> Sample {
        let w = self.direction(x, y);
        if w.z >= 0.0 {
            return Sample::Direct(w);
        }
        let rho = w.x.hypot(w.y);
        Sample::Reflected { horizon: DVec3::new(w.x / rho, w.y / rho, 0.0), mirrored: DVec3::new(w.x, w.y, -w.z) }
    }

    /// Whether the centre of pixel `(x, y)` lies on the hemisphere (`theta_o <= pi / 2`).
    pub fn inside(&self, x: usize, y: usize) -> bool {
        self.theta(x, y) <= FRAC_PI_2
    }

    /// The normalized coordinates `(u, v)` of a direction `wo` of the upper hemisphere, given in
    /// the frame of the plane of incidence (the inverse of [`Self::direction`] inside the disk);
    /// pixel `(x, y)` covers `u` in `[x, x + 1) / size`, likewise `v`.
    pub fn uv(&self, wo: DVec3) -> (f64, f64) {
        let r = merl::coords::theta_of(wo).min(FRAC_PI_2) / FRAC_PI_2;
        let rho = wo.x.hypot(wo.y);
        let (a, b) = if rho == 0.0 { (0.0, 0.0) } else { (r * wo.x / rho, r * wo.y / rho) };
        ((a + 1.0) / 2.0, (1.0 - b) / 2.0)
    }

    /// The singular values of the Jacobian of the projection at the centre of pixel `(x, y)`, in
    /// radians of arc per pixel: along the radius `pi / size` everywhere; across it
    /// `(2 / size) sin(theta) / r`, from `pi / size` at the centre to `2 / size` on the
    /// horizon and `1.13 / size` in the far corners. Returns `(radial, tangential)`.
    pub fn radians_per_pixel(&self, x: usize, y: usize) -> (f64, f64) {
        let n = self.size as f64;
        let (a, b) = self.square(x, y);
        let r = a.hypot(b);
        let tangential = if r == 0.0 { PI / n } else { 2.0 / n * (FRAC_PI_2 * r).sin() / r };
        (PI / n, tangential)
    }

    /// The factor that turns cycles per pixel into cycles per radian at pixel `(x, y)`: one
    /// over the smaller singular value of [`Self::radians_per_pixel`] (the tangential one), the
    /// conservative choice the `bandwidth` crate makes for lat-long maps: content running along
    /// the radius is overstated by `theta / sin(theta)` (at most `pi / 2` on the hemisphere),
    /// never understated.
    pub fn pixels_per_radian(&self, x: usize, y: usize) -> f64 {
        let (radial, tangential) = self.radians_per_pixel(x, y);
        1.0 / radial.min(tangential)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn incident_grid_round_trip_and_layout() {
        let grid = IncidentGrid::new(8);
        for j in 0..8 {
            for i in 0..8 {
                let wi = grid.wi(i, j);
                assert!((wi.length() - 1.0).abs() < 1e-12 && wi.z > 0.0);
                let (u, v) = grid.uv(wi);
                assert!((u * 8.0 - (i as f64 + 0.5)).abs() < 1e-9 && (v * 8.0 - (j as f64 + 0.5)).abs() < 1e-9);
                // In its own frame, wi lies in the x z half-plane towards +x.
                let local = to_incidence_frame(wi, grid.phi_i(i));
                assert!(local.y.abs() < 1e-12 && local.x > 0.0 && (local.z - wi.z).abs() < 1e-15);
            }
        }
        // Rows of equal solid angle: equal steps of cos(theta_i), the first near the normal.
        assert!((grid.theta_i(0).cos() - 15.0 / 16.0).abs() < 1e-15);
        assert!((grid.theta_i(7).cos() - 1.0 / 16.0).abs() < 1e-15);
    }

    #[test]
    fn lobe_map_round_trip_and_reflection() {
        let map = LobeMap::new(16);
        for y in 0..16 {
            for x in 0..16 {
                let wo = map.direction(x, y);
                assert!((wo.length() - 1.0).abs() < 1e-12);
                match map.sample(x, y) {
                    Sample::Direct(w) => {
                        assert!(map.inside(x, y) && w == wo);
                        let (u, v) = map.uv(wo);
                        assert!(
                            (u * 16.0 - (x as f64 + 0.5)).abs() < 1e-9 && (v * 16.0 - (y as f64 + 0.5)).abs() < 1e-9
                        );
                    }
                    Sample::Reflected { horizon, mirrored } => {
                        assert!(!map.inside(x, y) && horizon.z == 0.0 && mirrored.z > 0.0);
                        assert!((map.theta(x, y) - (PI - merl::coords::theta_of(mirrored))).abs() < 1e-12);
                        assert!((horizon.x * mirrored.y - horizon.y * mirrored.x).abs() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn lobe_map_jacobian_matches_finite_differences() {
        // Arc length between the directions of neighbouring points, against the singular values.
        let map = LobeMap::new(64);
        let direction = |a: f64, b: f64| direction_from_disk(a, b, FRAC_PI_2 * a.hypot(b));
        for (x, y) in [(40, 30), (60, 33), (33, 2), (5, 60), (50, 50)] {
            let (a, b) = map.square(x, y);
            let r = a.hypot(b);
            let (ra, rb) = (a / r, b / r);
            let h = 1e-5;
            let pixel = 2.0 / 64.0;
            // Central differences; the chord equals the arc to O(h^2).
            let arc = |da: f64, db: f64| (direction(a + da, b + db) - direction(a - da, b - db)).length() / 2.0;
            let radial = arc(h * ra, h * rb) / h * pixel;
            let tangential = arc(-h * rb, h * ra) / h * pixel;
            let (r_expect, t_expect) = map.radians_per_pixel(x, y);
            assert!((radial - r_expect).abs() < 1e-6 * r_expect, "{radial} {r_expect}");
            assert!((tangential - t_expect).abs() < 1e-6 * t_expect, "{tangential} {t_expect}");
        }
    }
}
