//! The two parameterizations of the atlas (crate docs, "Incident directions" and "Lobe
//! images"): the grid of
//! incident directions (rows of equal solid angle in `theta_i`, columns in `phi_i`) and the
//! image of an outgoing lobe (an azimuthal equidistant projection of the hemisphere of `wo` in
//! the frame of the plane of incidence, continued below the horizon by extrapolation),
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
/// holds the lobe continued along its radius from points above the horizon
/// ([`Sample::Continued`]): with its value, slope and curvature at the horizon, so that the
/// wavelets see no edge there, blending into the odd reflection `2 f(0) - f(-t)` deeper down
/// (crate docs, "Lobe images").
///
/// Rows `y` and `size - 1 - y` are mirror images across the plane of incidence: at a
/// power-of-two size their `b` are each other's negatives exactly, so their samples are mirror
/// images `(x, -y, z)` of each other with the same weights, and their Jacobian factors are
/// equal, bit for bit (the analysis computes the top half alone).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeMap {
    pub size: usize,
}

/// What one pixel of a lobe image holds: the BRDF at one direction, or, below the horizon, a
/// combination of three.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// `f(wo)`.
    Direct(DVec3),
    /// `sum_k weights[k] f(points[k])`: the lobe continued below the horizon from directions
    /// above it on the pixel's great circle through the zenith ([`LobeMap::sample`]).
    Continued { points: [DVec3; 4], weights: [f64; 4] },
}

/// The weights of the three-point continuation in [`LobeMap::sample`]: `c_1 + c_2 + c_3 = 1`,
/// `-c_1 - 2 c_2 - 3 c_3 = 1`, `c_1 + 4 c_2 + 9 c_3 = 1` (the continuation of `1`, `t` and `t^2`
/// is `1`, `t`, `t^2`).
pub const CONTINUATION_WEIGHTS: [f64; 3] = [6.0, -8.0, 3.0];

/// The share of the three-point continuation at `s`, the depth in units of the blend
/// ([`CONTINUATION_REACH`]): 1 at the border, 0 from `s = 1` on, `1 - 3 s^2 + 2 s^3` between,
/// flat at both ends. The rest is the odd reflection's. Below the horizon and past the square's
/// edges alike.
pub(crate) fn three_point_share(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    1.0 - s * s * (3.0 - 2.0 * s)
}

/// Pixels (samples) over which the three-point continuation blends into the odd reflection,
/// below the horizon ([`LobeMap::sample`], along the radius) and past the square's edges
/// (`extend_periodic`). The three-point rule reads three times as far in, where a lobe narrower
/// than that is no longer a quadratic: blending over more pixels lets its misfit show (on a lobe
/// 16 samples wide with its inflection on the border, the finest wavelets read 1.9 times the
/// lobe's own finest detail over 3 samples, 5 times over 8), over fewer the blend's own turn
/// shows (at 64 x 64, a broad Phong lobe then reads the limit on the rim).
pub const CONTINUATION_REACH: usize = 3;

impl Sample {
    /// The pixel's value for a BRDF `f` (luminance of `f(wi, wo)` at fixed `wi`); `None` where
    /// `f` has no value at a direction it needs.
    pub fn eval(&self, mut f: impl FnMut(DVec3) -> Option<f64>) -> Option<f64> {
        match *self {
            Sample::Direct(wo) => f(wo),
            Sample::Continued { points, weights } => {
                let mut sum = 0.0;
                for (w, c) in points.into_iter().zip(weights) {
                    if c != 0.0 {
                        sum += c * f(w)?;
                    }
                }
                Some(sum)
            }
        }
    }
}

impl LobeMap {
    pub fn new(size: usize) -> Self {
        Self { size }
    }

    /// Whether rows `y` and `size - 1 - y` are mirror images of each other bit for bit (see the
    /// type's docs): at a power-of-two size of at least 2.
    pub fn rows_mirrored(&self) -> bool {
        self.size.is_power_of_two() && self.size >= 2
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
        let (a, b) = self.square(x, y);
        let depth = self.theta(x, y) - FRAC_PI_2;
        let at = |k: f64| direction_from_disk(a, b, FRAC_PI_2 - k * depth);
        // CONTINUATION_REACH pixels of pi / size radians along the radius.
        let w = three_point_share(depth / self.continuation_depth());
        let [c1, c2, c3] = CONTINUATION_WEIGHTS.map(|c| c * w);
        Sample::Continued {
            points: [at(0.0), at(1.0), at(2.0), at(3.0)],
            weights: [2.0 * (1.0 - w), c1 - (1.0 - w), c2, c3],
        }
    }

    /// The depth below the horizon, in radians, from which [`Self::sample`] holds the plain odd
    /// reflection: [`CONTINUATION_REACH`] pixels along the radius.
    pub fn continuation_depth(&self) -> f64 {
        CONTINUATION_REACH as f64 * PI / self.size as f64
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
                    Sample::Continued { points, weights } => {
                        // k times the pixel's depth above the horizon on the pixel's great
                        // circle through the zenith, on the pixel's side wherever weighted.
                        assert!(!map.inside(x, y));
                        assert!((weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                        let depth = map.theta(x, y) - FRAC_PI_2;
                        for (k, (w, c)) in points.into_iter().zip(weights).enumerate() {
                            assert!((w.length() - 1.0).abs() < 1e-12);
                            assert!((w.x * wo.y - w.y * wo.x).abs() < 1e-12);
                            if c != 0.0 {
                                let elevation = FRAC_PI_2 - merl::coords::theta_of(w);
                                assert!(w.x * wo.x + w.y * wo.y > 0.0, "{x} {y} {k}");
                                assert!((elevation - k as f64 * depth).abs() < 1e-12, "{x} {y} {k}");
                            }
                        }
                        if depth >= map.continuation_depth() {
                            assert_eq!(weights, [2.0, -1.0, 0.0, 0.0]);
                        }
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

    #[test]
    fn the_continuation_is_exact_for_linear_and_keeps_the_curvature() {
        // Along each pixel's great circle, f = alpha + beta e + gamma e^2 of the elevation e
        // (negative below the horizon). A linear f is continued exactly at every depth; a
        // quadratic one to O(t^4) near the horizon (the three-point continuation), and by the
        // odd reflection (exact for linear only) from the continuation depth on.
        let map = LobeMap::new(512);
        let elevation = |w: DVec3| FRAC_PI_2 - merl::coords::theta_of(w);
        let (alpha, beta, gamma) = (0.7, -1.3, 2.1);
        let mut checked = 0;
        for y in 0..512 {
            for x in 0..512 {
                let Sample::Continued { .. } = map.sample(x, y) else { continue };
                let t = map.theta(x, y) - FRAC_PI_2;
                let direction = map.direction(x, y);
                // Elevation measured on the pixel's side of the zenith.
                let e = |w: DVec3| {
                    if w.x * direction.x + w.y * direction.y >= 0.0 { elevation(w) } else { PI - elevation(w) }
                };
                let linear = map.sample(x, y).eval(|w| Some(alpha + beta * e(w))).unwrap();
                assert!((linear - (alpha - beta * t)).abs() < 1e-12, "{x} {y}");
                let blend = map.continuation_depth();
                if t < blend / 2.0 {
                    let q = map.sample(x, y).eval(|w| Some(alpha + beta * e(w) + gamma * e(w).powi(2))).unwrap();
                    let exact = alpha - beta * t + gamma * t * t;
                    // The blend's weight departs from 1 as 3 s^2, s = t / blend: error 6 gamma t^2 s^2.
                    let bound = 6.0 * gamma * t * t * (t / blend).powi(2) + 1e-12;
                    assert!((q - exact).abs() <= bound, "{x} {y}: {q} {exact} {bound}");
                    checked += 1;
                }
            }
        }
        assert!(checked > 100, "{checked}");
    }
}
