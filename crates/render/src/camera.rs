//! The orbit camera: where the eye is, the `f32` view-projection matrix both renderers use, and
//! the ray through a pixel centre for the background.

use std::f32::consts::FRAC_PI_2;

use glam::{DVec3, Mat4, Vec3};

use crate::error::Error;

/// A camera on a sphere around `target`, looking at it with `+z` up: the eye is at
/// `target + distance (cos el cos az, cos el sin az, sin el)` (azimuth from `+x` towards `+y`,
/// elevation above the `xy` plane, radians). Built by [`Camera::orbit`], which checks the values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    target: Vec3,
    distance: f32,
    azimuth: f32,
    elevation: f32,
    fov_y: f32,
}

impl Default for Camera {
    /// Frames a unit sphere at the origin with some margin at 1:1 (its silhouette spans 79% of
    /// the image height: `tan(asin(1 / 3.2)) / tan(22.5 deg)`), looking horizontally from `+x`,
    /// so the environment's horizon crosses the middle of the background.
    fn default() -> Self {
        Camera { target: Vec3::ZERO, distance: 3.2, azimuth: 0.0, elevation: 0.0, fov_y: 45f32.to_radians() }
    }
}

impl Camera {
    /// Elevations are kept within this of the poles, where looking at the target with `+z` up
    /// has no defined roll.
    pub const MAX_ELEVATION: f32 = FRAC_PI_2 - 1e-3;

    /// The camera at `distance` from `target`, at `azimuth` and `elevation` (radians), with a
    /// vertical field of view `fov_y` (radians). `elevation` is clamped to
    /// `[-MAX_ELEVATION, MAX_ELEVATION]`; a non-finite value, a distance that is not positive or a
    /// field of view outside `(0, pi)` is an error.
    pub fn orbit(target: Vec3, distance: f32, azimuth: f32, elevation: f32, fov_y: f32) -> Result<Camera, Error> {
        if !(target.is_finite() && azimuth.is_finite() && elevation.is_finite()) {
            return Err(Error::Invalid(format!(
                "camera target {target}, azimuth {azimuth} and elevation {elevation} must be finite"
            )));
        }
        if !(distance.is_finite() && distance > 0.0) {
            return Err(Error::Invalid(format!("camera distance {distance} must be positive and finite")));
        }
        if !(fov_y > 0.0 && fov_y < std::f32::consts::PI) {
            return Err(Error::Invalid(format!("vertical field of view {fov_y} must lie in (0, pi)")));
        }
        let elevation = elevation.clamp(-Self::MAX_ELEVATION, Self::MAX_ELEVATION);
        Ok(Camera { target, distance, azimuth, elevation, fov_y })
    }

    pub fn target(&self) -> Vec3 {
        self.target
    }

    pub fn distance(&self) -> f32 {
        self.distance
    }

    pub fn azimuth(&self) -> f32 {
        self.azimuth
    }

    pub fn elevation(&self) -> f32 {
        self.elevation
    }

    pub fn fov_y(&self) -> f32 {
        self.fov_y
    }

    /// The near plane, `distance / 100`: far enough for depth precision, near enough that a mesh
    /// in the unit sphere is never clipped from any distance above 1.02.
    pub fn near(&self) -> f32 {
        self.distance * 0.01
    }

    /// The far plane, `100 distance`.
    pub fn far(&self) -> f32 {
        self.distance * 100.0
    }

    /// The eye position, in `f32` (what the GPU gets as a uniform; the CPU widens it to `f64`).
    pub fn eye(&self) -> Vec3 {
        let (sin_el, cos_el) = self.elevation.sin_cos();
        let (sin_az, cos_az) = self.azimuth.sin_cos();
        self.target + self.distance * Vec3::new(cos_el * cos_az, cos_el * sin_az, sin_el)
    }

    /// The right-handed look-at view matrix, `+z` up (`Mat4::look_at_rh`).
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye(), self.target, Vec3::Z)
    }

    /// The projection, depth in `[0, 1]` (`Mat4::perspective_rh`) with [`Camera::near`] and
    /// [`Camera::far`]; `aspect` is width over height.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.fov_y, aspect, self.near(), self.far())
    }

    /// `projection(aspect) * view()`, in `f32`: the matrix both renderers project vertices with.
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view()
    }

    /// The camera's basis in world space, in `f64`: `[f, r, u]` with `f = normalize(target -
    /// eye)`, `r = normalize(f x z)` (screen right), `u = r x f` (screen up), the basis of
    /// `look_at_rh`.
    pub fn basis(&self) -> [DVec3; 3] {
        let forward = (self.target.as_dvec3() - self.eye().as_dvec3()).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        [forward, right, right.cross(forward)]
    }

    /// The unit world-space direction of the ray from the eye through the centre of pixel
    /// `(x, y)` (row 0 at the top) of a `width x height` image, in `f64`:
    /// `normalize(f + x_ndc tan(fov_y / 2) aspect r + y_ndc tan(fov_y / 2) u)` with
    /// `f = normalize(target - eye)`, `r = normalize(f x z)`, `u = r x f` (the basis of
    /// `look_at_rh`), `x_ndc = 2 (x + 1/2) / width - 1`, `y_ndc = 1 - 2 (y + 1/2) / height`.
    pub fn ray(&self, x: usize, y: usize, width: usize, height: usize) -> DVec3 {
        self.rays(width, height).ray(x, y)
    }

    /// [`Camera::ray`] for every pixel of a `width x height` image, with the basis and the
    /// tangent made once (they cost as much as the rest of a ray).
    pub fn rays(&self, width: usize, height: usize) -> Rays {
        Rays {
            basis: self.basis(),
            aspect: width as f64 / height as f64,
            tan_half: (0.5 * f64::from(self.fov_y)).tan(),
            width: width as f64,
            height: height as f64,
        }
    }
}

/// The pixel rays of one camera and image size ([`Camera::rays`]).
#[derive(Clone, Copy, Debug)]
pub struct Rays {
    basis: [DVec3; 3],
    aspect: f64,
    tan_half: f64,
    width: f64,
    height: f64,
}

impl Rays {
    /// [`Camera::ray`] through the centre of pixel `(x, y)`.
    pub fn ray(&self, x: usize, y: usize) -> DVec3 {
        let [forward, right, up] = self.basis;
        let (aspect, tan_half) = (self.aspect, self.tan_half);
        let x_ndc = 2.0 * (x as f64 + 0.5) / self.width - 1.0;
        let y_ndc = 1.0 - 2.0 * (y as f64 + 0.5) / self.height;
        (forward + x_ndc * tan_half * aspect * right + y_ndc * tan_half * up).normalize()
    }
}
