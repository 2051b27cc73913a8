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
//! `(t, phi_h)` (4 x 4 at least in the cells the horizon crosses, where the integrand has its
//! edge), times the cell's `dt`: an estimate of the cell's share of the integral.
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

use color::luminance;
use glam::DVec3;
use merl::{Interp, MerlTable, spherical_dir};
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
            supersampling: 1,
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
    /// Stored tables that do not make a distribution.
    #[error("invalid table: {0}")]
    Table(String),
}

impl Config {
    /// Checks every setting against its range ([`build`] calls it; callers that want to refuse a
    /// configuration before doing anything else call it first).
    pub fn check(&self) -> Result<(), Error> {
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

    /// The rows of a stored table: its row edges in `theta_h` (asset kind 2's `theta_h_edges`),
    /// at least two, from 0 to `pi / 2`, increasing.
    pub fn from_theta_edges(theta_edges: &[f64]) -> Result<HalfVectorRows, Error> {
        let increasing = theta_edges.windows(2).all(|w| w[1] > w[0]);
        let (first, last) = (theta_edges.first().copied(), theta_edges.last().copied());
        let ends = first == Some(0.0) && last.is_some_and(|l| (l - std::f64::consts::FRAC_PI_2).abs() <= 1e-9);
        if theta_edges.len() < 2 || !increasing || !ends {
            return Err(Error::Table(format!(
                "{} theta_h edges from {first:?} to {last:?}: need at least two, increasing from 0 to pi/2",
                theta_edges.len()
            )));
        }
        Ok(HalfVectorRows { t_edges: theta_edges.iter().map(|&theta| t_of_theta(theta)).collect() })
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
#[derive(Debug, Clone, PartialEq)]
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
    /// The slice of a stored table (asset kind 2): outgoing elevation `theta_o`, the rows, and the
    /// distribution over `[phi_h / 2 pi, row coordinate]` with `rows.len()` rows (for example
    /// `sampling::Distribution2D::from_cdfs` of the stored CDFs, which samples them as they are).
    pub fn from_tables(theta_o: f64, rows: HalfVectorRows, dist: Distribution2D) -> Result<Slice, Error> {
        if dist.nv() != rows.len() {
            return Err(Error::Table(format!(
                "{} rows of half vectors, but the distribution has {}",
                rows.len(),
                dist.nv()
            )));
        }
        if !(0.0..std::f64::consts::FRAC_PI_2).contains(&theta_o) {
            return Err(Error::Table(format!("theta_o {theta_o} is outside [0, pi/2)")));
        }
        Ok(Slice { theta_o, wo: spherical_dir(theta_o, 0.0), rows, dist })
    }

    /// The slice as a renderer reads it back from the asset (kind 2): the CDF tables rounded to
    /// `f32` (`sampling::Distribution2D::rounded_to_f32`), the rows through their `theta_h` edges.
    pub fn as_stored(&self) -> Slice {
        let rows = HalfVectorRows::from_theta_edges(&self.rows.theta_edges()).expect("the rows of a build are valid");
        Slice { theta_o: self.theta_o, wo: self.wo, rows, dist: self.dist.rounded_to_f32() }
    }

    pub fn theta_o(&self) -> f64 {
        self.theta_o
    }

    pub fn wo(&self) -> DVec3 {
        self.wo
    }

    /// The rows of half vectors the distribution's rows are.
    pub fn rows(&self) -> &HalfVectorRows {
        &self.rows
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

    /// Every vector of slice `k`, one after the other.
    pub fn slice_samples(&self, k: usize) -> &[DirectionSample] {
        let per_slice = self.config.n_vectors * self.config.n_samples;
        &self.samples[k * per_slice..(k + 1) * per_slice]
    }

    /// Every sample, slice-major, then vector, then sample.
    pub fn all_samples(&self) -> &[DirectionSample] {
        &self.samples
    }

    /// Every sample as the renderers and the asset (kind 2) store it: an RGBA32F texel
    /// `(wi.x, wi.y, wi.z, pdf)`, in the order of [`ImportanceTables::all_samples`].
    pub fn sample_texels(&self) -> Vec<[f32; 4]> {
        self.all_samples().iter().map(|s| [s.wi.x as f32, s.wi.y as f32, s.wi.z as f32, s.pdf as f32]).collect()
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

/// Points per axis in the cells the horizon crosses (see `build_slice`).
const HORIZON_SUPERSAMPLING: usize = 4;

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
            // Cells the horizon crosses (corners on both sides) hold the integrand's edge, where
            // one point per cell misjudges it badly (GGX alpha 0.1 at 80 degrees: relative
            // variance 0.25 with one point, 0.006 with 4 x 4): they get HORIZON_SUPERSAMPLING.
            let corners_above = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .filter(|(a, b)| reflects_above(t0 + a * dt, (iu as f64 + b) * dphi).is_some())
                .count();
            let s = if corners_above % 4 == 0 { s } else { s.max(HORIZON_SUPERSAMPLING) };
            let mut sum = 0.0;
            let mut reachable = corners_above > 0;
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

/// How well a slice samples its material, by deterministic quadrature (no sampling noise): the
/// numbers `merl-importance` reports and the tests bound (relative variance, albedo error, the
/// mass above the horizon: `tests/importance.rs`).
pub mod quality {
    use color::luminance;
    use merl::albedo::{Quadrature, hemisphere_integral};
    use merl::{Interp, MerlTable};

    use crate::{DirectionSample, Slice};

    /// Quality of one slice.
    #[derive(Debug, Clone, Copy, PartialEq)]
    pub struct SliceQuality {
        pub theta_o: f64,
        /// Relative variance `Var[g / p] / E[g / p]^2` of the estimator of `integral g` with
        /// `g = L(f) cos theta_i`, under this slice's density.
        pub rv: f64,
        /// The same under cosine-weighted sampling (`p = cos theta_i / pi`), for comparison.
        pub rv_cos: f64,
        /// Directional albedo (RGB) by quadrature of the nearest lookup, the reference of the
        /// sample estimates.
        pub albedo: [f64; 3],
        /// Probability the density puts on the upper hemisphere (the rest falls below it).
        pub upper_mass: f64,
    }

    /// Computes [`SliceQuality`] with the half-vector quadrature `q` of the `merl` crate.
    pub fn slice_quality(table: &MerlTable, slice: &Slice, q: Quadrature) -> SliceQuality {
        let wo = slice.wo();
        // One pass over the nodes: the same lookup feeds the variances and the albedo.
        let [g1, g2_p, g2_cos, upper_mass, red, green, blue] = hemisphere_integral(
            |wi| {
                let p = slice.pdf(wi);
                let f = table.lookup(wi, wo, Interp::Nearest).unwrap_or([0.0; 3]);
                let g = luminance(f) * wi.z;
                let g2_p = if g > 0.0 { g * g / p } else { 0.0 };
                [g, g2_p, g * g * std::f64::consts::PI / wi.z, p, f[0] * wi.z, f[1] * wi.z, f[2] * wi.z]
            },
            wo,
            q,
        );
        let albedo = [red, green, blue];
        let rv = |second: f64| if g1 > 0.0 { second / (g1 * g1) - 1.0 } else { 0.0 };
        SliceQuality { theta_o: slice.theta_o(), rv: rv(g2_p), rv_cos: rv(g2_cos), albedo, upper_mass }
    }

    /// Pearson's chi-square test of `n` directions drawn by `slice` from independent uniform `u`
    /// (seeded) against the slice's own density: 80 bins over the upper hemisphere of `wi`
    /// (8 bands of `cos theta_i` x 10 sectors of `phi_i`, unrelated to the table's half-vector
    /// cells) plus one for everything below the horizon or nowhere. Expected counts integrate
    /// `pdf(wi)` over each bin with the half-vector quadrature `q`, so peaked densities are
    /// resolved.
    pub fn chi2_against_density(slice: &Slice, n: usize, seed: u64, q: Quadrature) -> sampling::chi2::Chi2 {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        chi2_of_points(slice, (0..n).map(|_| [rng.random(), rng.random()]), q)
    }

    /// [`chi2_against_density`] of the directions `slice` draws from the given points, which must
    /// be uniform on `[0, 1)^2` for the test to accept: a renderer's points, say.
    pub fn chi2_of_points(
        slice: &Slice,
        points: impl ExactSizeIterator<Item = [f64; 2]>,
        q: Quadrature,
    ) -> sampling::chi2::Chi2 {
        const BINS: usize = 80;
        let n = points.len();
        let bin = |wi: glam::DVec3| {
            (wi.z > 0.0).then(|| {
                let band = ((wi.z * 8.0) as usize).min(7);
                let phi = wi.y.atan2(wi.x).rem_euclid(2.0 * std::f64::consts::PI);
                band * 10 + ((phi / (2.0 * std::f64::consts::PI) * 10.0) as usize).min(9)
            })
        };
        let per_bin: [f64; BINS] = hemisphere_integral(
            |wi| {
                let mut v = [0.0; BINS];
                if let Some(b) = bin(wi) {
                    v[b] = slice.pdf(wi);
                }
                v
            },
            slice.wo(),
            q,
        );
        let mut expected: Vec<f64> = per_bin.iter().map(|p| p * n as f64).collect();
        let upper: f64 = expected.iter().sum();
        expected.push((n as f64 - upper).max(0.0));
        let total: f64 = expected.iter().sum();
        expected.iter_mut().for_each(|e| *e *= n as f64 / total);

        let mut observed = vec![0u64; BINS + 1];
        for u in points {
            let s = slice.sample(u);
            let b = if s.pdf > 0.0 { bin(s.wi) } else { None };
            observed[b.unwrap_or(BINS)] += 1;
        }
        sampling::chi2::chi2_test(&observed, &expected)
    }

    /// The mean of `f cos theta_i / pdf` (RGB) over `samples` drawn from `slice`: the estimate of
    /// the directional albedo a renderer gets from them.
    pub fn albedo_estimate(table: &MerlTable, slice: &Slice, samples: &[DirectionSample]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for s in samples.iter().filter(|s| s.pdf > 0.0 && s.wi.z > 0.0) {
            if let Some(f) = table.lookup(s.wi, slice.wo(), Interp::Nearest) {
                for c in 0..3 {
                    sum[c] += f[c] * s.wi.z / s.pdf;
                }
            }
        }
        sum.map(|v| v / samples.len() as f64)
    }
}
