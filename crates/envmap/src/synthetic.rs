//! A procedural environment map for demos and tests, made by our own code so that the repository
//! needs no image it did not make: an outdoor "calibration sky" whose orientation can be read off
//! any reflection.
//!
//! - Sky above the horizon: a gradient from a pale horizon to a blue zenith.
//! - A sun: a disk of angular radius [`SUN_RADIUS_DEG`] at elevation 35 degrees and azimuth
//!   `phi = 60` degrees (from `+x` towards `+y`), radiance 20 000 per channel (times a warm tint),
//!   enough to dominate the map's energy as a real sun does (here about 60%).
//! - Three coloured panels standing on the horizon, 20 degrees wide and 15 high: red centred on
//!   `+x` (`phi = 0`), green on `+y` (`phi = 90` degrees), blue on `-x` (`phi = 180` degrees).
//! - Ground below the horizon: a checkerboard of 15 x 10 degree squares in two greys, so that a
//!   mirror shows which way is down and how a lobe blurs.
//!
//! Every texel is the value at its centre (no antialiasing): edges are sharp to the texel, which
//! is what the bandwidth tools should see.

use crate::error::Error;
use crate::geometry;
use crate::map::EnvMap;

/// The sun's angular radius, degrees.
pub const SUN_RADIUS_DEG: f64 = 1.5;
/// The sun's direction: elevation and azimuth, degrees.
pub const SUN_ELEVATION_DEG: f64 = 35.0;
pub const SUN_AZIMUTH_DEG: f64 = 60.0;

/// The calibration sky at `width x height` (2:1, at least 8 x 4).
pub fn calibration_sky(width: usize, height: usize) -> Result<EnvMap, Error> {
    if height < 4 || width != 2 * height {
        return Err(Error::Invalid(format!(
            "a calibration sky needs a 2:1 size of at least 8 x 4, got {width} x {height}"
        )));
    }
    let (elevation, azimuth) = (SUN_ELEVATION_DEG.to_radians(), SUN_AZIMUTH_DEG.to_radians());
    let sun = glam::DVec3::new(elevation.cos() * azimuth.cos(), elevation.cos() * azimuth.sin(), elevation.sin());
    let cos_sun = SUN_RADIUS_DEG.to_radians().cos();
    let mut rgb = Vec::with_capacity(3 * width * height);
    for y in 0..height {
        for x in 0..width {
            let (u, v) = geometry::texel_center_uv(x, y, width, height);
            let w = geometry::direction(u, v);
            rgb.extend(radiance(w, u, sun, cos_sun).map(|c| c as f32));
        }
    }
    EnvMap::new(width, height, rgb)
}

/// The radiance towards `w` (map coordinate `u` for its azimuth).
fn radiance(w: glam::DVec3, u: f64, sun: glam::DVec3, cos_sun: f64) -> [f64; 3] {
    let elevation = w.z.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = u * 360.0;
    if w.dot(sun) >= cos_sun {
        return [20_000.0, 19_000.0, 17_000.0];
    }
    if elevation >= 0.0 {
        // Panels: 20 degrees wide around their azimuth, up to 15 degrees high.
        let near = |centre: f64| {
            let d = (azimuth - centre).rem_euclid(360.0);
            d.min(360.0 - d) <= 10.0
        };
        if elevation <= 15.0 {
            if near(0.0) {
                return [4.0, 0.3, 0.2];
            }
            if near(90.0) {
                return [0.3, 3.0, 0.3];
            }
            if near(180.0) {
                return [0.2, 0.4, 4.0];
            }
        }
        let t = (elevation / 90.0).sqrt();
        let horizon = [1.6, 1.55, 1.45];
        let zenith = [0.25, 0.45, 1.0];
        return std::array::from_fn(|c| horizon[c] * (1.0 - t) + zenith[c] * t);
    }
    let square = ((azimuth / 15.0).floor() as i64 + (-elevation / 10.0).floor() as i64).rem_euclid(2);
    let grey = if square == 0 { 0.35 } else { 0.12 };
    // A warm ground, a little brighter towards the horizon (sky light).
    let lift = 1.0 + 0.5 * (1.0 + elevation / 90.0);
    [grey * lift * 1.05, grey * lift, grey * lift * 0.9]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_panels_and_the_sun_are_where_the_docs_say() {
        let map = calibration_sky(720, 360).unwrap();
        let at = |phi_deg: f64, elevation_deg: f64| {
            let (phi, theta) = (phi_deg.to_radians(), (90.0 - elevation_deg).to_radians());
            map.lookup(glam::DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()))
        };
        let red = at(0.0, 7.0);
        let green = at(90.0, 7.0);
        let blue = at(180.0, 7.0);
        assert!(
            red[0] > 3.0 * red[1] && green[1] > 3.0 * green[0] && blue[2] > 3.0 * blue[1],
            "{red:?} {green:?} {blue:?}"
        );
        assert!(at(SUN_AZIMUTH_DEG, SUN_ELEVATION_DEG)[0] > 1e4);
        let sky = at(270.0, 60.0);
        assert!(sky[2] > sky[0], "the sky is blue at altitude: {sky:?}");
        let ground = at(200.0, -30.0);
        assert!(ground[0] < 1.0, "{ground:?}");
    }

    #[test]
    fn the_sun_dominates_the_energy() {
        let map = calibration_sky(1024, 512).unwrap();
        let mut total = 0.0;
        let mut sun = 0.0;
        for y in 0..map.height() {
            let omega = map.texel_solid_angle(y);
            for x in 0..map.width() {
                let l = color::luminance(map.texel(x, y).map(f64::from)) * omega;
                total += l;
                if l / omega > 1e4 {
                    sun += l;
                }
            }
        }
        let share = sun / total;
        assert!((0.3..0.9).contains(&share), "the sun holds {share} of the energy");
    }

    #[test]
    fn sizes_are_checked() {
        assert!(calibration_sky(10, 4).is_err());
        assert!(calibration_sky(4, 2).is_err());
        assert!(calibration_sky(8, 4).is_ok());
    }
}
