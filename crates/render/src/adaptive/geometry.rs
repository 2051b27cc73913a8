//! The G-buffer of a camera, read by all its frames (module docs, "The G-buffer").

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Error;
use crate::raster::GBuffer;
use crate::shade::{ShadingFrame, visibility_of};
use crate::{Camera, Mesh, Scene};

use super::*;

/// A shadeable pixel's G-buffer (module docs, "The G-buffer"), what the plan reads; its shading
/// frame is made again where a pixel is shaded or predicted (`shading_frame`). Kept small: a
/// frame allocates one per render pixel, and fresh memory costs more than the arithmetic.
#[derive(Clone, Copy, Debug)]
pub struct Pixel {
    /// `cos theta_o` of the shading frame.
    pub cos_o: f64,
    pub depth: f64,
    pub curvature: f64,
    /// The normal projected on the screen (x right, y down), unit, or zero when it faces the
    /// eye.
    pub screen_normal: [f64; 2],
    /// The mirror direction of the view about the normal: the axis of a specular lobe.
    pub mirror: DVec3,
}

/// What a camera sees, for its adaptive frames (module docs, "The G-buffer"): the G-buffer of
/// the render (the output's size times the supersampling) and its pixels' quantities. Made once
/// per camera; every frame of that camera and supersampling reads it.
#[derive(Clone)]
pub struct Geometry {
    pub(super) camera: Camera,
    /// The output's size.
    pub(super) size: (usize, usize),
    pub(super) supersample: usize,
    pub(super) gbuffer: GBuffer,
    pub(super) pixels: Vec<Option<Pixel>>,
    /// Per output pixel: whether a triangle covers any of its render pixels.
    pub(super) covered: Vec<bool>,
    /// Wall time it took to make, in milliseconds.
    pub(super) millis: f64,
}

impl Geometry {
    /// `mesh` seen from `camera` by an output image of `width x height` rendered at
    /// `supersample` (1, 2 or 4) times that size along each axis.
    pub fn new(
        mesh: &Mesh,
        camera: &Camera,
        (width, height): (usize, usize),
        supersample: usize,
    ) -> Result<Geometry, Error> {
        if !matches!(supersample, 1 | 2 | 4) {
            return Err(Error::Invalid(format!("supersample {supersample} must be 1, 2 or 4")));
        }
        let clock = std::time::Instant::now();
        let (render_width, render_height) = (width * supersample, height * supersample);
        let gbuffer = visibility_of(mesh, camera, render_width, render_height)?;
        let pixels = pixels(camera, &gbuffer);
        let covered = output_coverage(&gbuffer, width, height, supersample);
        let millis = clock.elapsed().as_secs_f64() * 1e3;
        Ok(Geometry { camera: *camera, size: (width, height), supersample, gbuffer, pixels, covered, millis })
    }

    /// The geometry of `scene` rendered at `supersample` times its size.
    pub fn of_scene(scene: &Scene, supersample: usize) -> Result<Geometry, Error> {
        Geometry::new(&scene.mesh, &scene.camera, (scene.width, scene.height), supersample)
    }

    pub fn supersample(&self) -> usize {
        self.supersample
    }

    /// The output's size.
    pub fn size(&self) -> (usize, usize) {
        self.size
    }

    /// Per render pixel, row-major: its G-buffer, `None` where it is not shadeable.
    pub fn pixels(&self) -> &[Option<Pixel>] {
        &self.pixels
    }

    /// Whether a triangle covers render pixel `i` (shadeable or not).
    pub fn covers(&self, i: usize) -> bool {
        self.gbuffer.hits[i].is_some()
    }

    /// Per output pixel: whether a triangle covers any of its render pixels.
    pub fn output_coverage(&self) -> &[bool] {
        &self.covered
    }

    /// Wall time it took to make, in milliseconds.
    pub fn millis(&self) -> f64 {
        self.millis
    }

    /// The render's size: the output's times the supersampling.
    pub fn render_size(&self) -> (usize, usize) {
        (self.gbuffer.width, self.gbuffer.height)
    }
}

impl std::fmt::Debug for Geometry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Geometry")
            .field("size", &self.size)
            .field("supersample", &self.supersample)
            .field("shadeable", &self.pixels.iter().filter(|p| p.is_some()).count())
            .field("millis", &self.millis)
            .finish_non_exhaustive()
    }
}

/// The G-buffer's pixels, `None` where a pixel is not shadeable.
pub(super) fn pixels(camera: &Camera, gbuffer: &GBuffer) -> Vec<Option<Pixel>> {
    let eye = camera.eye().as_dvec3();
    let [_, right, up] = camera.basis();
    let (w, h) = (gbuffer.width, gbuffer.height);
    let shadeable: Vec<bool> = gbuffer
        .hits
        .par_iter()
        .map(|hit| hit.as_ref().is_some_and(|hit| ShadingFrame::new(hit, eye).is_some()))
        .collect();
    let at = |x: usize, y: usize| gbuffer.hits[y * w + x].as_ref().filter(|_| shadeable[y * w + x]);
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let hit = gbuffer.hits[i].as_ref()?;
            let frame = ShadingFrame::new(hit, eye)?;
            // The curvature along one axis from the neighbours that are there (module docs).
            let axis = |a: Option<&crate::raster::Hit>, b: Option<&crate::raster::Hit>| {
                let (a, b) = (a.unwrap_or(hit), b.unwrap_or(hit));
                let dp = (a.position - b.position).length();
                if dp > 0.0 { (a.normal - b.normal).length() / dp } else { 0.0 }
            };
            let horizontal = axis((x > 0).then(|| at(x - 1, y)).flatten(), (x + 1 < w).then(|| at(x + 1, y)).flatten());
            let vertical = axis((y > 0).then(|| at(x, y - 1)).flatten(), (y + 1 < h).then(|| at(x, y + 1)).flatten());
            let n = frame.n;
            let projected = [n.dot(right), -n.dot(up)];
            let length = projected[0].hypot(projected[1]);
            let screen_normal = if length > 1e-9 { [projected[0] / length, projected[1] / length] } else { [0.0; 2] };
            let wo = (eye - hit.position).normalize();
            Some(Pixel {
                cos_o: frame.cos_o,
                mirror: 2.0 * frame.n.dot(wo) * frame.n - wo,
                depth: (eye - hit.position).length(),
                curvature: horizontal.max(vertical),
                screen_normal,
            })
        })
        .collect()
}

/// The shading frame of render pixel `i`, which [`pixels`] found shadeable, seen from `eye`.
pub(super) fn shading_frame(gbuffer: &GBuffer, eye: DVec3, i: usize) -> ShadingFrame {
    gbuffer.hits[i].as_ref().and_then(|hit| ShadingFrame::new(hit, eye)).expect("a shadeable pixel has a shading frame")
}
