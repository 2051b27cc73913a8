//! Importance sampling of measured (MERL) BRDFs by numerical inversion of tabulated CDFs, as in
//! Bagher et al. 2013, section 3.3: for each outgoing elevation `theta_o` of a grid (isotropic
//! data, `phi_o = 0`; a renderer rotates about the normal), the luminance of `f cos theta_i` is
//! tabulated over incident directions, and samples are drawn by inverting its marginal and
//! conditional CDFs.
//!
//! # Parameterization: the half vector, in MERL's cells
//!
//! Incident directions are parameterized by the half vector `h` about the normal, with `wi` the
//! reflection of `wo` about `h` (`wi = 2 (wo . h) h - wo`, `dwi = 4 (wo . h) dwh`):
//! - the specular peak of every `theta_o` sits at `h = n`, so one grid resolves mirror-like lobes
//!   at every view angle, where a grid over `wi` would have to follow the mirror direction;
//! - the rows are MERL's own `theta_h` cells (`theta_h = (i / 90)^2 pi/2`, optionally subdivided),
//!   finest at the peak, so the BRDF, which the nearest lookup reads as constant in `theta_h`
//!   across a row, never varies along a row's `theta_h` extent: within a cell only the `theta_d`,
//!   `phi_d` dependence and the `4 (wo . h) cos theta_i` factor remain;
//! - the columns are `n_phi_h` equal sectors of `phi_h`.
//!
//! Within a cell, samples are uniform in the **solid angle of `h`**: `t = 1 - cos theta_h` is
//! linear in the cell, and `dwh = dt dphi_h`. So the density over `h` is constant per cell,
//! `p_h = P(cell) / (dt dphi_h of the cell)`, and the density over `wi` is
//! `p(wi) = p_h / (4 wo . h)` with `h` the exact half vector of `wi`: the Jacobian is taken at the
//! sample, never at a cell centre. The tabulated value of a cell is the mean of
//! `L(f(wi, wo)) cos theta_i 4 (wo . h)` over `supersampling^2` points spread uniformly in
//! `(t, phi_h)`, times the cell's `dt`: an estimate of the cell's share of the integral.
//!
//! A small defensive share (`Config::defensive`, default 1e-3) of the probability is spread
//! uniformly in `h` over every cell that can reflect above the horizon, so the density is
//! positive wherever `f cos theta_i` is, even in cells whose supersampling points all missed
//! the lobe or held no data. Half vectors with `wo . h <= 0` are outside the domain (density 0).
//! A sample can still fall below the horizon inside a cell that straddles it; its `wi.z <= 0`
//! tells the caller that it contributes nothing.
//!
//! `L` is Rec. 709 luminance; cells without data count as 0; lookups are nearest (the
//! reference MERL reader's, what a renderer of the raw table sees).

use std::f64::consts::PI;

use glam::DVec3;
use merl::{Interp, MerlTable, luminance, spherical_dir};
use rayon::prelude::*;
use sampling::{Distribution2D, owen_sobol_vectors};

/// Settings of [`build`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Config {
    /// Outgoing elevations `theta_o = k / n_theta_o * pi/2`, `k = 0 .. n_theta_o - 1`.
    pub n_theta_o: usize,
    /// Rows per MERL `theta_h` cell (90 cells).
    pub theta_h_subdivision: usize,
    /// Columns over `phi_h` in `[0, 2 pi)`.
    pub n_phi_h: usize,
    /// Points per cell and axis at which `f cos` is averaged.
    pub supersampling: usize,
    /// Share of the probability spread uniformly over the reachable half vectors.
    pub defensive: f64,
    /// Vectors of samples per `theta_o`.
    pub n_vectors: usize,
    /// Samples per vector.
    pub n_samples: usize,
    /// Seed of the Owen-scrambled Sobol' points the samples are drawn from.
    pub seed: u64,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            n_theta_o: 90,
            theta_h_subdivision: 1,
            n_phi_h: 128,
            supersampling: 2,
            defensive: 1e-3,
            n_vectors: 8,
            n_samples: 256,
            seed: 0,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("invalid setting: {0}")]
    Config(String),
}

impl Config {
    fn check(&self) -> Result<(), Error> {
        let positive = [
            ("theta_o count", self.n_theta_o),
            ("theta_h subdivision", self.theta_h_subdivision),
            ("phi_h cells", self.n_phi_h),
            ("supersampling", self.supersampling),
            ("vectors", self.n_vectors),
            ("samples per vector", self.n_samples),
        ];
        if let Some((name, _)) = positive.iter().find(|(_, v)| *v == 0) {
            return Err(Error::Config(format!("{name} must be at least 1")));
        }
        let limits = [
            ("theta_o count", self.n_theta_o, 1024),
            ("theta_h subdivision", self.theta_h_subdivision, 16),
            ("phi_h cells", self.n_phi_h, 4096),
            ("supersampling", self.supersampling, 16),
            ("samples per vector", self.n_samples, 1 << 20),
            ("vectors", self.n_vectors, 1024),
        ];
        if let Some((name, v, max)) = limits.iter().find(|(_, v, max)| v > max) {
            return Err(Error::Config(format!("{name} {v} exceeds the limit of {max}")));
        }
        if !(0.0..1.0).contains(&self.defensive) {
            return Err(Error::Config(format!("the defensive share must lie in [0, 1), found {}", self.defensive)));
        }
        Ok(())
    }

    /// The outgoing elevation of slice `k`.
    pub fn theta_o(&self, k: usize) -> f64 {
        k as f64 / self.n_theta_o as f64 * std::f64::consts::FRAC_PI_2
    }
}

/// A direction drawn by [`Slice::sample`]: `wi` and its density with respect to solid angle.
/// `pdf` is 0 (and `wi` meaningless) for the rare half vector that no direction reflects about
/// (`wo . h <= 0`); `wi.z <= 0` for one that reflects below the horizon. Neither contributes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirectionSample {
    pub wi: DVec3,
    pub pdf: f64,
}

/// The rows of the grid over `h`: `t = 1 - cos theta_h` at the row edges.
#[derive(Debug, Clone, PartialEq)]
pub struct HalfVectorRows {
    t_edges: Vec<f64>,
}

impl HalfVectorRows {
    /// MERL's 90 `theta_h` cells, each split into `subdivision` rows equal in `u`.
    pub fn merl(subdivision: usize) -> HalfVectorRows {
        let n = 90 * subdivision;
        let t_edges = (0..=n)
            .map(|i| {
                let u = i as f64 / n as f64;
                t_of_theta(u * u * std::f64::consts::FRAC_PI_2)
            })
            .collect();
        HalfVectorRows { t_edges }
    }

    pub fn len(&self) -> usize {
        self.t_edges.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// `1 - cos theta_h` at the `len() + 1` row edges, from 0 to 1.
    pub fn t_edges(&self) -> &[f64] {
        &self.t_edges
    }

    /// The `theta_h` of the row edges.
    pub fn theta_edges(&self) -> Vec<f64> {
        self.t_edges.iter().map(|t| (1.0 - t).acos()).collect()
    }

    fn width(&self, row: usize) -> f64 {
        self.t_edges[row + 1] - self.t_edges[row]
    }

    /// The row holding `t` (the upper one on an edge), clamped to the grid.
    fn row_of(&self, t: f64) -> usize {
        self.t_edges[1..].partition_point(|e| *e <= t).min(self.len() - 1)
    }
}

/// `1 - cos theta`, without the cancellation near 0.
fn t_of_theta(theta: f64) -> f64 {
    let s = (0.5 * theta).sin();
    2.0 * s * s
}

/// The half vector of `(t, phi_h)`.
fn half_vector(t: f64, phi_h: f64) -> DVec3 {
    let cos_theta = 1.0 - t;
    let sin_theta = (t * (2.0 - t)).max(0.0).sqrt();
    let (s, c) = phi_h.sin_cos();
    DVec3::new(sin_theta * c, sin_theta * s, cos_theta)
}

/// The importance-sampling table of one outgoing direction.
#[derive(Debug, Clone)]
pub struct Slice {
    theta_o: f64,
    wo: DVec3,
    rows: HalfVectorRows,
    dist: Distribution2D,
}

/// Where a direction falls in a slice's grid, and the grid coordinates in `[0, 1)^2`.
struct Located {
    p: [f64; 2],
    cell: [usize; 2],
    wo_h: f64,
}

impl Slice {
    pub fn theta_o(&self) -> f64 {
        self.theta_o
    }

    pub fn wo(&self) -> DVec3 {
        self.wo
    }

    /// The piecewise-constant distribution over `[phi_h / 2 pi, row coordinate]`, row-major
    /// with `theta_h` rows and `phi_h` columns.
    pub fn distribution(&self) -> &Distribution2D {
        &self.dist
    }

    /// Density over the solid angle of `h`, constant in each cell `[column, row]`.
    pub fn h_density(&self, cell: [usize; 2]) -> f64 {
        let [iu, iv] = cell;
        let d = &self.dist;
        let p_cell = if d.integral() > 0.0 { d.func()[iv * d.nu() + iu] / d.integral() } else { 1.0 };
        p_cell / (d.nv() as f64 * self.rows.width(iv) * 2.0 * PI)
    }

    /// Draws `wi` from `u` in `[0, 1)^2`. The density is with respect to the solid angle of `wi`.
    pub fn sample(&self, u: [f64; 2]) -> DirectionSample {
        let s = self.dist.sample(u);
        let [iu, iv] = s.index;
        let nv = self.dist.nv() as f64;
        let frac = (s.p[1] * nv - iv as f64).clamp(0.0, 1.0);
        let t = self.rows.t_edges[iv] + frac * self.rows.width(iv);
        let h = half_vector(t, 2.0 * PI * s.p[0]);
        let wo_h = self.wo.dot(h);
        let wi = 2.0 * wo_h * h - self.wo;
        // A cell can straddle wo . h = 0 (only at grazing theta_o): there no direction reflects.
        let pdf = if wo_h > 0.0 { self.h_density([iu, iv]) / (4.0 * wo_h) } else { 0.0 };
        DirectionSample { wi, pdf }
    }

    fn locate(&self, wi: DVec3) -> Option<Located> {
        let sum = wi + self.wo;
        let len = sum.length();
        if len == 0.0 {
            return None;
        }
        let h = sum / len;
        if h.z <= 0.0 {
            return None;
        }
        let t = (h.x * h.x + h.y * h.y) / (1.0 + h.z);
        let iv = self.rows.row_of(t);
        let frac = ((t - self.rows.t_edges[iv]) / self.rows.width(iv)).clamp(0.0, 1.0);
        let nv = self.dist.nv();
        let nu = self.dist.nu();
        let py = ((iv as f64 + frac) / nv as f64).min(sampling::ONE_MINUS_EPSILON);
        let phi = h.y.atan2(h.x);
        let px = (if phi < 0.0 { phi + 2.0 * PI } else { phi } / (2.0 * PI)).min(sampling::ONE_MINUS_EPSILON);
        let iu = ((px * nu as f64) as usize).min(nu - 1);
        Some(Located { p: [px, py], cell: [iu, iv], wo_h: self.wo.dot(h) })
    }

    /// Density of `wi` (with respect to solid angle) that [`Slice::sample`] draws from.
    pub fn pdf(&self, wi: DVec3) -> f64 {
        match self.locate(wi) {
            Some(l) if l.wo_h > 0.0 => self.h_density(l.cell) / (4.0 * l.wo_h),
            _ => 0.0,
        }
    }

    /// The `u` that [`Slice::sample`] maps to `wi`; `None` outside the domain.
    pub fn invert(&self, wi: DVec3) -> Option<[f64; 2]> {
        self.locate(wi).filter(|l| l.wo_h > 0.0).map(|l| self.dist.invert(l.p))
    }
}

/// The tables of one material: a [`Slice`] per outgoing elevation and, for each, `n_vectors`
/// vectors of `n_samples` precomputed samples.
#[derive(Debug, Clone)]
pub struct ImportanceTables {
    config: Config,
    slices: Vec<Slice>,
    samples: Vec<DirectionSample>,
}

impl ImportanceTables {
    pub fn config(&self) -> &Config {
        &self.config
    }

    pub fn slices(&self) -> &[Slice] {
        &self.slices
    }

    /// The rows of the half-vector grid (shared by every slice).
    pub fn rows(&self) -> &HalfVectorRows {
        &self.slices[0].rows
    }

    /// The precomputed samples of slice `k`, vector `v`.
    pub fn samples(&self, k: usize, v: usize) -> &[DirectionSample] {
        let c = &self.config;
        let start = (k * c.n_vectors + v) * c.n_samples;
        &self.samples[start..start + c.n_samples]
    }

    /// Every sample, slice-major, then vector, then sample.
    pub fn all_samples(&self) -> &[DirectionSample] {
        &self.samples
    }
}

/// Builds the importance-sampling tables of `table`.
pub fn build(table: &MerlTable, config: &Config) -> Result<ImportanceTables, Error> {
    config.check()?;
    let rows = HalfVectorRows::merl(config.theta_h_subdivision);
    let slices: Vec<Slice> =
        (0..config.n_theta_o).into_par_iter().map(|k| build_slice(table, config, &rows, config.theta_o(k))).collect();
    let samples = slices
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, slice)| {
            let seed = config.seed ^ (k as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
            owen_sobol_vectors(seed, config.n_vectors, config.n_samples).into_iter().map(|u| slice.sample(u))
        })
        .collect();
    Ok(ImportanceTables { config: *config, slices, samples })
}

fn build_slice(table: &MerlTable, config: &Config, rows: &HalfVectorRows, theta_o: f64) -> Slice {
    let wo = spherical_dir(theta_o, 0.0);
    let (nu, nv, s) = (config.n_phi_h, rows.len(), config.supersampling);
    let dphi = 2.0 * PI / nu as f64;
    // Per cell: the mean of the integrand over its points, and whether any point or corner of
    // the cell reflects above the horizon.
    let cells: Vec<(f64, bool)> = (0..nv * nu)
        .into_par_iter()
        .map(|index| {
            let (iv, iu) = (index / nu, index % nu);
            let (t0, dt) = (rows.t_edges[iv], rows.width(iv));
            let reflects_above = |t: f64, phi: f64| {
                let h = half_vector(t, phi);
                let wo_h = wo.dot(h);
                let wi = 2.0 * wo_h * h - wo;
                (wo_h > 0.0 && wi.z > 0.0).then_some((h, wo_h, wi))
            };
            let mut sum = 0.0;
            let mut reachable = false;
            for a in 0..s {
                for b in 0..s {
                    let t = t0 + (a as f64 + 0.5) / s as f64 * dt;
                    let phi = (iu as f64 + (b as f64 + 0.5) / s as f64) * dphi;
                    if let Some((_, wo_h, wi)) = reflects_above(t, phi) {
                        reachable = true;
                        if let Some(f) = table.lookup(wi, wo, Interp::Nearest) {
                            sum += luminance(f) * wi.z * 4.0 * wo_h;
                        }
                    }
                }
            }
            if !reachable {
                reachable = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .iter()
                    .any(|(a, b)| reflects_above(t0 + a * dt, (iu as f64 + b) * dphi).is_some());
            }
            (sum / (s * s) as f64 * dt, reachable)
        })
        .collect();
    let total: f64 = cells.iter().map(|c| c.0).sum();
    let reachable_measure: f64 = cells.iter().enumerate().filter(|(_, c)| c.1).map(|(i, _)| rows.width(i / nu)).sum();
    let defensive = if total > 0.0 { config.defensive } else { 1.0 };
    let func: Vec<f64> = cells
        .iter()
        .enumerate()
        .map(|(i, &(value, reachable))| {
            let main = if total > 0.0 { value / total } else { 0.0 };
            let uniform =
                if reachable && reachable_measure > 0.0 { rows.width(i / nu) / reachable_measure } else { 0.0 };
            (1.0 - defensive) * main + defensive * uniform
        })
        .collect();
    let dist = Distribution2D::new(&func, nu, nv).expect("cell values are finite and non-negative");
    Slice { theta_o, wo, rows: rows.clone(), dist }
}
