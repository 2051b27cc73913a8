//! Equirectangular (lat-long) maps: the pixel to direction convention, the Jacobian of the
//! mapping, the estimate over the sphere (periodic in `phi`, continued across the poles) and its
//! conversion to cycles per radian.

use std::f64::consts::{PI, TAU};

use dwt::Image;
use rayon::prelude::*;

use crate::Error;
use crate::estimate::{BandwidthMap, Config, estimate, periodic_levels};

/// The spherical angles of the centre of pixel `(x, y)` of a `width` x `height` lat-long map:
/// `phi = 2 pi (x + 1/2) / width`, `theta = pi (y + 1/2) / height`, `theta` from `+z` (row 0
/// touches the `+z` pole). Returns `(theta, phi)`.
pub fn latlong_angles(x: f64, y: f64, width: usize, height: usize) -> (f64, f64) {
    (PI * (y + 0.5) / height as f64, TAU * (x + 0.5) / width as f64)
}

/// The unit direction of the centre of pixel `(x, y)`: `(sin theta cos phi, sin theta sin phi,
/// cos theta)` with the angles of [`latlong_angles`].
pub fn latlong_direction(x: f64, y: f64, width: usize, height: usize) -> [f64; 3] {
    let (theta, phi) = latlong_angles(x, y, width, height);
    [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()]
}

/// The singular values of the Jacobian of the mapping from the image to the sphere at row `y`:
/// radians of arc per pixel along a row, `2 pi sin(theta) / width`, and down a column,
/// `pi / height`. Returns `(along_row, along_column)`.
pub fn latlong_radians_per_pixel(y: usize, width: usize, height: usize) -> (f64, f64) {
    let (theta, _) = latlong_angles(0.0, y as f64, width, height);
    (TAU * theta.sin() / width as f64, PI / height as f64)
}

/// The factor that turns cycles per pixel into cycles per radian at row `y`: the largest
/// singular value of the mapping from the sphere to the image, in pixels per radian,
/// `1 / min(latlong_radians_per_pixel(y))` (crate docs, "Angular units").
pub fn latlong_pixels_per_radian(y: usize, width: usize, height: usize) -> f64 {
    let (along_row, along_column) = latlong_radians_per_pixel(y, width, height);
    1.0 / along_row.min(along_column)
}

/// The angular bandwidth of a lat-long map: the estimate in pixels and its conversion.
#[derive(Clone, Debug, PartialEq)]
pub struct AngularBandwidthMap {
    pixels: BandwidthMap,
    cycles_per_radian: Vec<f64>,
}

impl AngularBandwidthMap {
    /// The estimate in cycles per pixel, with the levels and the Nyquist flags.
    pub fn pixels(&self) -> &BandwidthMap {
        &self.pixels
    }

    /// Angular bandwidth in cycles per radian of arc, row-major; 0 where no level is significant.
    /// `cos(k alpha)` reads `k / (2 pi)`; the papers' `nu_a` (radians of phase per radian) is
    /// `2 pi` times this.
    pub fn cycles_per_radian(&self) -> &[f64] {
        &self.cycles_per_radian
    }

    /// [`Self::cycles_per_radian`] at column `x`, row `y`. Panics outside the map.
    pub fn cycles_per_radian_at(&self, x: usize, y: usize) -> f64 {
        assert!(x < self.pixels.width() && y < self.pixels.height(), "({x}, {y}) is outside the map");
        self.cycles_per_radian[y * self.pixels.width() + x]
    }
}

/// The local angular bandwidth of a lat-long map (`width = 2 height` is the usual shape; any even
/// width works). The map is periodic in `phi` and is continued across both poles: the row above
/// row 0 is row 0 turned by half a turn (`x + width / 2`), and likewise below the last row, so
/// the estimate sees the sphere, not the seams of the image (crate docs, "Lat-long maps").
pub fn latlong_bandwidth(image: &Image, config: &Config) -> Result<AngularBandwidthMap, Error> {
    config.check()?;
    let (w, h) = (image.width(), image.height());
    if w < 2 || h < 1 || w % 2 != 0 {
        return Err(Error::Size(format!("lat-long map is {w}x{h}: the width must be even and at least 2")));
    }
    let levels = periodic_levels("lat-long map extended over the poles", w, 2 * h, config)?;
    let mut extended = Vec::with_capacity(2 * w * h);
    extended.extend_from_slice(image.data());
    for y in (0..h).rev() {
        let row = image.row(y);
        extended.extend_from_slice(&row[w / 2..]);
        extended.extend_from_slice(&row[..w / 2]);
    }
    let extended = Image::new(w, 2 * h, extended).expect("sizes match");
    let pixels = estimate(&extended, levels, w, h, config)?;
    let mut cycles_per_radian = pixels.frequency().to_vec();
    cycles_per_radian.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let scale = latlong_pixels_per_radian(y, w, h);
        row.iter_mut().for_each(|f| *f *= scale);
    });
    Ok(AngularBandwidthMap { pixels, cycles_per_radian })
}
