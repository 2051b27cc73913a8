//! Test 4: on Phong lobes the bandwidth at the lobe's centre grows like `sqrt(n)` while the
//! analysis grid resolves the lobe, and sits at the grid's Nyquist limit beyond.
//!
//! A Phong lobe `cos^n(alpha)` is close to a Gaussian of standard deviation `1 / sqrt(n)`
//! radians, whose bandwidth is proportional to `sqrt(n)`. The estimate comes in octaves (one
//! wavelet level per factor 2, so one step per factor 4 in `n`); sampling `n` every half octave
//! over several steps and fitting a line to `log(bandwidth)` against `log(n)` recovers the
//! slope. Measured: the centre reads wavelet level 5 down to 2 as `n` goes from 2 to 256 at
//! 256 x 256 pixels (steps near n = 4, 20, 70, 300), slope 0.44; the tolerance 0.5 +- 0.15 is
//! a bit more than half a step of the staircase over the fitted range.

use bandwidth_atlas::{Analyser, Config, IncidentGrid, LuminanceTable};
use glam::DVec3;

use crate::{phong, slope};

/// Pixels per side of the lobe images: fine enough for four octaves below the limit.
const SIZE: usize = 256;

/// Eight angles of incidence from 10 to 59 degrees, all with the mirror direction well inside
/// the hemisphere (rows 0, 2, ..., 14 of a 32-row grid).
fn lobes() -> Vec<f64> {
    let grid = IncidentGrid::new(32);
    (0..16).step_by(2).map(|j| grid.theta_i(j)).collect()
}

/// Full width at half maximum of `cos^n`, in pixels of the lobe image (radial pitch `pi / SIZE`
/// radians).
fn fwhm_pixels(n: f64) -> f64 {
    2.0 * 0.5f64.powf(1.0 / n).acos() / (std::f64::consts::PI / SIZE as f64)
}

/// For each incident direction: the bandwidth (cycles per radian) and the wavelet level at the
/// pixel of the mirror direction, and whether the lobe has any pixel at the limit.
fn centres(n: f64, analyser: &Analyser) -> Vec<(f64, u8, bool)> {
    let table = LuminanceTable::new(&phong(n));
    let map = analyser.map();
    lobes()
        .into_iter()
        .map(|theta_i| {
            // The mirror direction, in the frame of the plane of incidence.
            let (u, v) = map.uv(DVec3::new(-theta_i.sin(), 0.0, theta_i.cos()));
            let k = (v * SIZE as f64) as usize * SIZE + (u * SIZE as f64) as usize;
            let lobe = analyser.analyse(&table, theta_i);
            (lobe.cycles_per_radian[k], lobe.level[k], lobe.nyquist_count() > 0)
        })
        .collect()
}

#[test]
fn centre_bandwidth_grows_like_sqrt_n_until_the_grid_limit() {
    let analyser = Analyser::new(&Config { analysis_size: SIZE, tile: 16, ..Config::default() });
    let (mut log_n, mut log_b) = (Vec::new(), Vec::new());
    let mut failures = Vec::new();
    println!("     n   fwhm px   centre cycles/rad (geometric mean)   levels   lobes at the limit");
    for k in 2..=22 {
        let n = 2f64.powf(k as f64 / 2.0);
        let fwhm = fwhm_pixels(n);
        let c = centres(n, &analyser);
        let mean = (c.iter().map(|(b, _, _)| b.ln()).sum::<f64>() / c.len() as f64).exp();
        let levels: String = c.iter().map(|(_, l, _)| char::from(b'0' + l)).collect();
        let at_limit = c.iter().filter(|(_, _, nyquist)| *nyquist).count();
        println!("{n:6.0} {fwhm:9.1} {mean:21.3} {levels:>24} {at_limit:>8}/{}", c.len());
        if fwhm >= 12.0 {
            // Resolved: the centre is below the limit and enters the fit.
            if c.iter().any(|(_, l, _)| *l == 1) {
                failures.push(format!("n {n}: a resolved lobe (fwhm {fwhm:.1} px) reads the limit at its centre"));
            }
            log_n.push(n.ln());
            log_b.push(mean.ln());
        } else if fwhm <= 8.0 && !c.iter().all(|(_, l, nyquist)| *l == 1 && *nyquist) {
            failures.push(format!("n {n}: an unresolved lobe (fwhm {fwhm:.1} px) does not read the limit: {levels}"));
        }
    }
    let s = slope(&log_n, &log_b);
    println!("log-log slope over {} exponents with fwhm >= 12 px: {s:.3}", log_n.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!((s - 0.5).abs() <= 0.15, "slope {s:.3} is not 0.5 +- 0.15");
}

#[test]
fn the_atlas_counts_the_lobes_at_the_limit() {
    // The same statement at the default analysis size, through the atlas builder: a sharp lobe
    // (fwhm 2 px at 64 x 64) reaches the limit in every lobe, a broad one (fwhm 19 px) in none
    // away from grazing incidence.
    let config = Config { lobes: 8, analysis_size: 64, ..Config::default() };
    let sharp = bandwidth_atlas::build_atlas(&phong(1000.0), &config, &|_| {}).unwrap();
    assert_eq!(sharp.stats.nyquist_lobes(), 64, "{:?}", sharp.stats.nyquist_pixels);
    let broad = bandwidth_atlas::build_atlas(&phong(6.0), &config, &|_| {}).unwrap();
    let grid = IncidentGrid::new(8);
    for j in 0..8 {
        for i in 0..8 {
            let theta_i = grid.theta_i(j).to_degrees();
            let count = broad.stats.nyquist_pixels[j * 8 + i];
            assert!(theta_i > 70.0 || count == 0, "lobe ({i}, {j}) at {theta_i:.0} deg: {count} pixels at the limit");
        }
    }
}

/// Phong n = 1000 analysed at the default 1024 x 1024: the pixels at the grid's limit of (a) the
/// analytic lobe at every row of the default 64-row grid and (b) a table of it made as
/// `merl-synth` makes it (no data below the horizon) at the eight most grazing rows, where the
/// mirror direction lies within 8 degrees of the horizon and the lobe (1/e half width 2.6
/// degrees) straddles it.
///
/// Both must read none. (a): the continuation below the horizon (three-point extrapolation) and
/// across the square's edges (odd reflection) carry the lobe's value, slope and curvature, so
/// the cut reads as no edge; before them, the analytic lobe read 12 to 50 pixels at the limit
/// in rows 60 to 63 at 512 (the odd reflection `2 f(0) - f(-t)` flips the curvature, the
/// square's mirrored edge makes a kink). At 512 it still reads 16 at its peak in row 4 (the
/// lobe is on the estimate's edge there, `Config::analysis_size`). (b): the table's cells
/// below the horizon are continued along `theta_d`; read as `merl` reads them (left out,
/// weights renormalized) the lobe is flat across the last cell and reads the limit on the
/// horizon's last pixel (row 60 at 1024; rows 60 and 63 at 512).
#[test]
fn phong_1000_is_resolved_at_the_default_size() {
    let config = Config::default();
    assert_eq!(config.analysis_size, 1024);
    let analyser = Analyser::new(&config);
    let n = 1000.0;
    let lobe = |wi: DVec3, wo: DVec3| {
        let r = DVec3::new(-wi.x, -wi.y, wi.z);
        (n + 2.0) / std::f64::consts::TAU * wo.dot(r).max(0.0).powf(n)
    };
    let table = LuminanceTable::new(&phong(n));
    let grid = IncidentGrid::new(64);
    let mut failures = Vec::new();
    for j in 0..64 {
        let theta_i = grid.theta_i(j);
        let wi = merl::spherical_dir(theta_i, 0.0);
        let analytic =
            analyser.analyse_image(bandwidth_atlas::lobe_image_from_fn(analyser.map(), |wo| Some(lobe(wi, wo))));
        let tabulated = if j >= 56 { analyser.analyse(&table, theta_i).nyquist_count() } else { 0 };
        let counts = (analytic.nyquist_count(), tabulated);
        if counts != (0, 0) {
            failures.push(format!("row {j}, theta_i {:.2} deg: {counts:?} pixels at the limit", theta_i.to_degrees()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
