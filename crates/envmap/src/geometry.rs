//! The lat-long parameterization: directions, texel coordinates and texel solid angles. Pure
//! functions of `(u, v)` or of the map's size; they never fail.

use std::f64::consts::PI;

use glam::DVec3;

/// The unit direction at map coordinates `(u, v)` in `[0, 1]^2`: `phi = 2 pi u`, `theta = pi v`,
/// `(sin theta cos phi, sin theta sin phi, cos theta)`. `v = 0` is the `+z` pole, `u = 0` the
/// `+x` direction, and `u` grows towards `+y`. Values outside `[0, 1]` are not wrapped: they
/// give the direction of the corresponding angles.
pub fn direction(u: f64, v: f64) -> DVec3 {
    let phi = 2.0 * PI * u;
    let theta = PI * v;
    let (sin_theta, cos_theta) = theta.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    DVec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// The map coordinates `(u, v)` of a direction, the inverse of [`direction`]: `u` in `[0, 1)`,
/// `v` in `[0, 1]`. The direction need not be normalized. On the poles (`x = y = 0`, including the
/// zero vector) `phi` is undefined and `u` is 0.
pub fn uv(wi: DVec3) -> (f64, f64) {
    // atan2 of the two legs rather than acos(z): acos loses half the digits near the poles.
    let theta = wi.x.hypot(wi.y).atan2(wi.z);
    let mut u = wi.y.atan2(wi.x) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
        // A tiny negative phi rounds to exactly 1, which is the same meridian as 0.
        if u >= 1.0 {
            u = 0.0;
        }
    }
    (u, theta / PI)
}

/// The map coordinates of the centre of texel `(x, y)` of a `width x height` map:
/// `((x + 0.5) / width, (y + 0.5) / height)`.
pub fn texel_center_uv(x: usize, y: usize, width: usize, height: usize) -> (f64, f64) {
    ((x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64)
}

/// The exact solid angle of one texel in row `y` of a `width x height` lat-long map:
/// `(cos theta0 - cos theta1) 2 pi / width` with `theta0 = pi y / height`,
/// `theta1 = pi (y + 1) / height`. All texels of a row have the same solid angle; the rows of a
/// map sum to `4 pi`.
pub fn texel_solid_angle(y: usize, width: usize, height: usize) -> f64 {
    let theta0 = PI * y as f64 / height as f64;
    let theta1 = PI * (y + 1) as f64 / height as f64;
    // cos a - cos b = 2 sin((a + b) / 2) sin((b - a) / 2), without the cancellation of the
    // difference near the poles, where both cosines are close to 1.
    let cos_difference = 2.0 * (0.5 * (theta0 + theta1)).sin() * (0.5 * (theta1 - theta0)).sin();
    cos_difference * 2.0 * PI / width as f64
}

/// The Jacobian `d omega / (du dv) = 2 pi^2 sin(pi v)` of the parameterization: a pdf over the
/// unit square of `(u, v)` is this times the pdf over solid angle, `pdf_uv = pdf_omega * 2 pi^2
/// sin theta`.
pub fn uv_jacobian(v: f64) -> f64 {
    2.0 * PI * PI * (PI * v).sin()
}
