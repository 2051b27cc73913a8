//! The sphere parameterization of section 4.1 and the `n x n` grid of directions on it.

use std::f64::consts::PI;

use glam::DVec3;

use crate::Error;

/// The direction of angles `(theta, phi)`, both in `[0, pi]` for the upper hemisphere:
/// `(sin phi cos theta, cos phi, sin theta sin phi)`. The poles (`phi = 0, pi`) lie on the local
/// `y` axis, in the tangent plane; `z` is the normal.
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(phi.sin() * theta.cos(), phi.cos(), theta.sin() * phi.sin())
}

/// The angles `(theta, phi)` of a unit direction with `z >= 0` (the inverse of [`direction`]):
/// `theta = atan2(z, x)`, `phi = atan2(sqrt(x^2 + z^2), y)` (`acos y`, by `atan2` because GPUs
/// compute `acos` coarsely, and the WGSL port must agree with this to rounding).
pub fn angles(w: DVec3) -> (f64, f64) {
    (w.z.atan2(w.x), (w.x * w.x + w.z * w.z).sqrt().atan2(w.y))
}

/// An `n x n` grid over `(theta, phi)` in `[0, pi]^2`: cell `(row, col)` (index `row n + col`)
/// spans `phi` in `[row, row + 1] pi / n` and `theta` in `[col, col + 1] pi / n`; its sample is
/// its centre. Rows run along `phi` (the wavelet layout's axis 0), columns along `theta`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    side: usize,
}

impl Grid {
    /// A grid of `side x side` cells: a power of two from 2 to [`asset::MAX_WAVELET_SIDE`].
    pub fn new(side: usize) -> Result<Grid, Error> {
        if !side.is_power_of_two() || !(2..=asset::MAX_WAVELET_SIDE as usize).contains(&side) {
            return Err(Error::Invalid(format!(
                "the grid side must be a power of two from 2 to {}, found {side}",
                asset::MAX_WAVELET_SIDE
            )));
        }
        Ok(Grid { side })
    }

    pub fn side(&self) -> usize {
        self.side
    }

    /// `n^2`, the directions of one grid.
    pub fn cells(&self) -> usize {
        self.side * self.side
    }

    /// `log2 n`, the levels of the transform of one slice.
    pub fn levels(&self) -> usize {
        self.side.trailing_zeros() as usize
    }

    /// The direction at the centre of cell `cell`.
    pub fn direction(&self, cell: usize) -> DVec3 {
        let step = PI / self.side as f64;
        let (row, col) = (cell / self.side, cell % self.side);
        direction((col as f64 + 0.5) * step, (row as f64 + 0.5) * step)
    }

    /// The four cells around `w` and their bilinear weights (summing to 1), between cell centres
    /// and clamped to the edge cells beyond the outermost centres (the grid does not wrap: `theta
    /// = 0` and `theta = pi` are opposite sides of the horizon, `phi = 0` and `phi = pi` opposite
    /// poles). `None` below the horizon (`w.z < 0`).
    pub fn bilinear(&self, w: DVec3) -> Option<[(usize, f64); 4]> {
        if w.z.is_nan() || w.z < 0.0 {
            return None;
        }
        let (theta, phi) = angles(w);
        let n = self.side;
        let axis = |angle: f64| {
            let x = (angle / PI * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
            let i0 = (x.floor() as usize).min(n - 2);
            (i0, x - i0 as f64)
        };
        let ((r0, tr), (c0, tc)) = (axis(phi), axis(theta));
        let cell = |r: usize, c: usize| r * n + c;
        Some([
            (cell(r0, c0), (1.0 - tr) * (1.0 - tc)),
            (cell(r0, c0 + 1), (1.0 - tr) * tc),
            (cell(r0 + 1, c0), tr * (1.0 - tc)),
            (cell(r0 + 1, c0 + 1), tr * tc),
        ])
    }
}
