//! The fit: the initial estimate ([`crate::estimate`]) refined by a weighted nonlinear least
//! squares over the table's cells, for the core material, for one with `KHR_materials_specular`
//! and for one with `KHR_materials_clearcoat`; an extension is kept when it lowers the core
//! material's objective by [`Settings::margin`].

use merl::albedo::{Quadrature, directional_albedo};
use merl::analytic::HORIZON_EPS;
use merl::{Dims, Interp, MerlTable};
use rayon::prelude::*;

use crate::estimate::{NdfEstimate, estimate_ndf};
use crate::model::{Geometry, Masking, Material, brdf};

/// The error each cell contributes, per channel, for a BRDF value `f` at a direction pair
/// whose cosines are `cos theta_i` and `cos theta_o`. Both readings of the pair count (the table
/// stores `(wi, wo)` and, by reciprocity, `(wo, wi)` in the same cell), so a term is taken with
/// each cosine.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Objective {
    /// `ln(1 + f cos)`: the reflected radiance of a unit light, compressed where it is large
    /// (a specular peak), linear where it is small (the diffuse body).
    #[default]
    LogCosine,
    /// `f cos`: the reflected radiance itself; dominated by the peaks.
    LinearCosine,
}

impl Objective {
    pub fn name(self) -> &'static str {
        match self {
            Objective::LogCosine => "log-cosine",
            Objective::LinearCosine => "linear-cosine",
        }
    }

    fn transform(self, f: f64, cos: f64) -> f64 {
        match self {
            Objective::LogCosine => (f * cos).ln_1p(),
            Objective::LinearCosine => f * cos,
        }
    }
}

/// Which factors the least squares moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// `baseColorFactor`, `metallicFactor`, `roughnessFactor`; no extension.
    Core,
    /// `baseColorFactor`, `roughnessFactor`, `specularFactor`, `specularColorFactor` with
    /// `metallicFactor` 0: a dielectric whose F0 is free in colour and strength (a metal's
    /// specular with `baseColor` 0 and `specularColor = F0 / 0.04` is one).
    Specular,
    /// The core factors and `KHR_materials_clearcoat`'s `clearcoatFactor` and
    /// `clearcoatRoughnessFactor`: a second, colourless GGX lobe over the first (a measured
    /// material's sharp peak over a broad body, a varnish).
    Clearcoat,
}

impl Variant {
    pub fn name(self) -> &'static str {
        match self {
            Variant::Core => "core",
            Variant::Specular => "specular",
            Variant::Clearcoat => "clearcoat",
        }
    }
}

/// How the fit runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    pub masking: Masking,
    pub objective: Objective,
    /// The least squares reads every `phi_d_stride`-th `phi_d` cell (an isotropic BRDF varies
    /// slowly in `phi_d`); the objective reported is over every cell.
    pub phi_d_stride: usize,
    /// Iterations of Levenberg-Marquardt at most, per variant.
    pub max_iterations: usize,
    /// A variant with an extension is kept only when its objective is below `(1 - margin)` times
    /// the core material's (and lower by more than [`NEGLIGIBLE_OBJECTIVE`]); of two that are,
    /// the lower.
    pub margin: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            masking: Masking::HeightCorrelated,
            objective: Objective::LogCosine,
            phi_d_stride: 6,
            max_iterations: 100,
            margin: 0.05,
        }
    }
}

/// The smallest roughness the fit takes: `alpha = 1e-3`, `merl::analytic::Analytic::MIN_ALPHA`,
/// a lobe about a milliradian wide; a table cannot hold a narrower one.
pub const MIN_ROUGHNESS: f64 = 0.031_622_776_601_683_79;

/// The largest `specularColorFactor` the fit takes: beyond `1 / 0.04` the dielectric F0 is
/// clamped at 1 and the factor changes nothing.
pub const MAX_SPECULAR_COLOR: f64 = 25.0;

/// An objective difference below this is rounding (a root-mean-square error of 1e-6 in
/// `ln(1 + f cos)`): the extension is never kept for it.
pub const NEGLIGIBLE_OBJECTIVE: f64 = 1e-12;

/// One variant refined.
#[derive(Debug, Clone, PartialEq)]
pub struct VariantFit {
    pub variant: Variant,
    pub material: Material,
    /// The objective over every cell of the table ([`objective`]).
    pub objective: f64,
    /// Levenberg-Marquardt iterations (Jacobians computed).
    pub iterations: usize,
}

/// The result of [`fit`].
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub settings: Settings,
    /// The power iteration's distribution and its GGX width.
    pub estimate: NdfEstimate,
    /// The material the least squares started from (the estimate's roughness, colours by linear
    /// least squares).
    pub initial: Material,
    pub core: VariantFit,
    pub specular: VariantFit,
    pub clearcoat: VariantFit,
    /// The variant kept ([`Settings::margin`]).
    pub chosen: Variant,
}

impl Fit {
    pub fn chosen(&self) -> &VariantFit {
        self.variant(self.chosen)
    }

    pub fn variant(&self, variant: Variant) -> &VariantFit {
        match variant {
            Variant::Core => &self.core,
            Variant::Specular => &self.specular,
            Variant::Clearcoat => &self.clearcoat,
        }
    }
}

/// A cell the least squares reads: its direction pair's cosines, the measured value transformed
/// by the objective (once per cosine) and its weight.
#[derive(Debug, Clone, Copy)]
struct Sample {
    g: Geometry,
    cos: [f64; 2],
    target: [[f64; 3]; 2],
    /// The cell's measure in `dwi dwo` (up to the constant turn of `phi_h`): `4 cos theta_d
    /// sin theta_d sin theta_h dtheta_h dtheta_d dphi_d` integrated over the cell, times the
    /// stride.
    weight: f64,
}

/// The cell `index` as a sample, or `None` where it holds no data or its sample directions lie
/// at or below the horizon.
fn sample(table: &MerlTable, index: usize, objective: Objective, stride: usize) -> Option<Sample> {
    let dims = table.dims();
    let measured = table.cell_value(index)?;
    let cell = dims.cell(index);
    let (wi, wo) = dims.sample_point(cell).to_dirs();
    if wi.z <= HORIZON_EPS || wo.z <= HORIZON_EPS {
        return None;
    }
    let theta_h = |i: usize| dims.theta_h_at(i as f64);
    let theta_d = |j: usize| dims.theta_d_at(j as f64);
    let measure_h = theta_h(cell.theta_h).cos() - theta_h(cell.theta_h + 1).cos();
    let measure_d = 2.0 * (theta_d(cell.theta_d + 1).sin().powi(2) - theta_d(cell.theta_d).sin().powi(2));
    let measure_p = dims.phi_d_range() / dims.n_phi_d as f64 * stride as f64;
    let cos = [wi.z, wo.z];
    let target = cos.map(|c| measured.map(|f| objective.transform(f, c)));
    Some(Sample { g: Geometry::new(wi, wo), cos, target, weight: measure_h * measure_d * measure_p })
}

/// The samples the least squares reads: every cell with data, every `stride`-th in `phi_d`.
fn samples(table: &MerlTable, objective: Objective, stride: usize) -> Vec<Sample> {
    let dims = table.dims();
    (0..dims.cells())
        .into_par_iter()
        .filter(|&i| dims.cell(i).phi_d.is_multiple_of(stride))
        .filter_map(|i| sample(table, i, objective, stride))
        .collect()
}

/// The model's value for each reading of a sample's pair: the light at `wi` seen from `wo` (the
/// reading with `cos theta_i`), and the other way round. They differ only under a clear coat,
/// whose Fresnel weight reads the viewer's angle ([`brdf`]).
fn readings(m: &Material, masking: Masking, g: &Geometry) -> [[f64; 3]; 2] {
    let f = brdf(m, masking, g);
    if m.uses_clearcoat_extension() { [f, brdf(m, masking, &g.swapped())] } else { [f, f] }
}

/// A sample's squared error, weighted (six terms: three channels, two cosines).
fn sample_cost(s: &Sample, m: &Material, settings: &Settings) -> f64 {
    let mut sum = 0.0;
    for ((f, cos), target) in readings(m, settings.masking, &s.g).iter().zip(&s.cos).zip(&s.target) {
        for (f, t) in f.iter().zip(target) {
            sum += (settings.objective.transform(*f, *cos) - t).powi(2);
        }
    }
    s.weight * sum
}

/// Sums in a fixed grouping (chunks in order), so that the result is the same bits whatever the
/// number of threads.
fn ordered_sum<T: Sync>(items: &[T], f: impl Fn(&T) -> [f64; 2] + Sync) -> [f64; 2] {
    items
        .par_chunks(4096)
        .map(|chunk| chunk.iter().map(&f).fold([0.0; 2], |a, b| [a[0] + b[0], a[1] + b[1]]))
        .collect::<Vec<_>>()
        .into_iter()
        .fold([0.0; 2], |a, b| [a[0] + b[0], a[1] + b[1]])
}

/// The objective of `m` against the whole table: the weighted mean, over the cells with data
/// (by their measure in `dwi dwo`), the three channels and both cosines, of the squared
/// difference of the transformed values. For the log-cosine objective its square root is
/// roughly the typical relative error of the reflected radiance where it is large.
pub fn objective(table: &MerlTable, m: &Material, settings: &Settings) -> f64 {
    let indices: Vec<usize> = (0..table.dims().cells()).collect();
    let [cost, weight] = ordered_sum(&indices, |&i| match sample(table, i, settings.objective, 1) {
        Some(s) => [sample_cost(&s, m, settings), 6.0 * s.weight],
        None => [0.0; 2],
    });
    cost / weight
}

/// Fits the glTF material to the table: the stages in order.
pub fn fit(table: &MerlTable, settings: &Settings) -> Fit {
    fit_reporting(table, settings, &|_, _| {})
}

/// The stages of [`fit`], as [`fit_reporting`] reports them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The power iteration and the initial colours.
    Estimate,
    /// Levenberg-Marquardt on one variant; its iterations so far, of at most
    /// [`Settings::max_iterations`].
    Refine(Variant, usize),
}

/// [`fit`], calling `progress(stage, settings)` as each stage begins and after each iteration of
/// the refinements (a tool's progress bar).
pub fn fit_reporting(table: &MerlTable, settings: &Settings, progress: &dyn Fn(Stage, &Settings)) -> Fit {
    progress(Stage::Estimate, settings);
    let samples = samples(table, settings.objective, settings.phi_d_stride.max(1));
    let estimate = estimate_ndf(table, settings.masking);
    let initial = initial_material(&samples, settings, estimate.alpha.sqrt().max(MIN_ROUGHNESS));
    let core = refine(table, &samples, settings, Variant::Core, &initial, progress);
    let specular = refine(table, &samples, settings, Variant::Specular, &core.material, progress);
    let clearcoat = coat_starts(&core.material)
        .iter()
        .map(|start| refine(table, &samples, settings, Variant::Clearcoat, start, progress))
        .min_by(|a, b| a.objective.total_cmp(&b.objective))
        .expect("two starts");
    let gain = |v: &VariantFit| core.objective - v.objective;
    let kept = |v: &VariantFit| gain(v) > settings.margin * core.objective && gain(v) > NEGLIGIBLE_OBJECTIVE;
    let chosen = [&specular, &clearcoat]
        .into_iter()
        .filter(|v| kept(v))
        .min_by(|a, b| a.objective.total_cmp(&b.objective))
        .map_or(Variant::Core, |v| v.variant);
    Fit { settings: *settings, estimate, initial, core, specular, clearcoat, chosen }
}

/// Where the coated variant's refinement starts, from the core material's fit: the coat as the
/// core's lobe over a base four times as rough (a sharp peak over a broad body: the measured
/// metals), and a coat twice as rough as the core's lobe over the core as fitted (a broad
/// varnish over a sharp base); the refinement of lower objective is kept.
fn coat_starts(core: &Material) -> [Material; 2] {
    let r = core.roughness;
    [
        Material { roughness: (4.0 * r).min(1.0), clearcoat: 1.0, clearcoat_roughness: r, ..*core },
        Material { clearcoat: 0.5, clearcoat_roughness: (2.0 * r).min(1.0), ..*core },
    ]
}

/// The colours for a roughness, by linear least squares (the BRDF is linear in `baseColor` for a
/// fixed metallic and roughness), for a dielectric and for a metal; the one of lower objective.
/// Each cell weighs its measure times `cos theta_i cos theta_o`.
fn initial_material(samples: &[Sample], settings: &Settings, roughness: f64) -> Material {
    let candidates = [0.0, 1.0].map(|metallic| {
        let zero = Material::core([0.0; 3], metallic, roughness);
        let one = Material::core([1.0; 3], metallic, roughness);
        let mut base_color = [0.0; 3];
        for (c, base) in base_color.iter_mut().enumerate() {
            // f = a + b k per cell: a at baseColor 0, k the change to baseColor 1.
            let [num, den] = ordered_sum(samples, |s| {
                let (a, b) = (brdf(&zero, settings.masking, &s.g)[c], brdf(&one, settings.masking, &s.g)[c]);
                let measured = inverse(settings.objective, s.target[0][c], s.cos[0]);
                let w = s.weight * s.cos[0] * s.cos[1];
                [w * (b - a) * (measured - a), w * (b - a) * (b - a)]
            });
            *base = if den > 0.0 { (num / den).clamp(0.0, 1.0) } else { 0.0 };
        }
        Material::core(base_color, metallic, roughness)
    });
    let cost = |m: &Material| ordered_sum(samples, |s| [sample_cost(s, m, settings), 0.0])[0];
    if cost(&candidates[1]) < cost(&candidates[0]) { candidates[1] } else { candidates[0] }
}

/// The measured value back from its transformed target.
fn inverse(objective: Objective, t: f64, cos: f64) -> f64 {
    match objective {
        Objective::LogCosine => t.exp_m1() / cos,
        Objective::LinearCosine => t / cos,
    }
}

/// A variant's parameters, their bounds and the material they make.
fn parameters(variant: Variant, m: &Material) -> (Vec<f64>, Vec<(f64, f64)>) {
    let unit = (0.0, 1.0);
    let rough = (MIN_ROUGHNESS, 1.0);
    let b = m.base_color;
    match variant {
        Variant::Core => (vec![b[0], b[1], b[2], m.metallic, m.roughness], vec![unit, unit, unit, unit, rough]),
        Variant::Clearcoat => (
            vec![b[0], b[1], b[2], m.metallic, m.roughness, m.clearcoat, m.clearcoat_roughness.max(MIN_ROUGHNESS)],
            vec![unit, unit, unit, unit, rough, unit, rough],
        ),
        Variant::Specular => {
            // From a core material: the metal's part of F0 moves into the specular colour.
            let dielectric = |c: usize| crate::model::DIELECTRIC_F0 * m.specular_color[c] * m.specular;
            let f0: [f64; 3] = std::array::from_fn(|c| (1.0 - m.metallic) * dielectric(c) + m.metallic * b[c]);
            let sc = f0.map(|f| (f / crate::model::DIELECTRIC_F0).min(MAX_SPECULAR_COLOR));
            let base = b.map(|b| b * (1.0 - m.metallic));
            let color = (0.0, MAX_SPECULAR_COLOR);
            (
                vec![base[0], base[1], base[2], m.roughness, m.specular, sc[0], sc[1], sc[2]],
                vec![unit, unit, unit, rough, unit, color, color, color],
            )
        }
    }
}

fn material(variant: Variant, p: &[f64]) -> Material {
    match variant {
        Variant::Core => Material::core([p[0], p[1], p[2]], p[3], p[4]),
        Variant::Specular => Material {
            base_color: [p[0], p[1], p[2]],
            metallic: 0.0,
            roughness: p[3],
            specular: p[4],
            specular_color: [p[5], p[6], p[7]],
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
        },
        Variant::Clearcoat => {
            Material { clearcoat: p[5], clearcoat_roughness: p[6], ..Material::core([p[0], p[1], p[2]], p[3], p[4]) }
        }
    }
}

/// Levenberg-Marquardt (Marquardt's scaling: the damping multiplies the normal matrix's
/// diagonal) with forward-difference derivatives, steps projected onto the bounds. The normal
/// equations are accumulated cell by cell (the Jacobian, cells x parameters, is never stored).
fn refine(
    table: &MerlTable,
    samples: &[Sample],
    settings: &Settings,
    variant: Variant,
    start: &Material,
    progress: &dyn Fn(Stage, &Settings),
) -> VariantFit {
    let (mut p, bounds) = parameters(variant, start);
    let n = p.len();
    let cost = |p: &[f64]| ordered_sum(samples, |s| [sample_cost(s, &material(variant, p), settings), 0.0])[0];
    let mut current = cost(&p);
    let mut lambda = 1e-3;
    let mut iterations = 0;
    while iterations < settings.max_iterations {
        progress(Stage::Refine(variant, iterations), settings);
        iterations += 1;
        let (jtj, jtr) = normal_equations(samples, settings, variant, &p, &bounds);
        let mut improved = false;
        while lambda < 1e12 {
            let mut a = jtj.clone();
            for j in 0..n {
                a[j * n + j] += lambda * jtj[j * n + j].max(1e-12);
            }
            let Some(delta) = solve(a, jtr.iter().map(|g| -g).collect(), n) else {
                lambda *= 4.0;
                continue;
            };
            let candidate: Vec<f64> =
                p.iter().zip(&delta).zip(&bounds).map(|((p, d), (lo, hi))| (p + d).clamp(*lo, *hi)).collect();
            let c = cost(&candidate);
            if c < current {
                let decrease = (current - c) / current.max(f64::MIN_POSITIVE);
                (p, current, improved) = (candidate, c, decrease > 1e-10);
                lambda = (lambda / 3.0).max(1e-9);
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    let material = material(variant, &p);
    VariantFit { variant, material, objective: objective(table, &material, settings), iterations }
}

/// `J^T J` (row-major, `n x n`) and `J^T r` of the weighted residuals at `p`, by forward
/// differences (backward at an upper bound).
fn normal_equations(
    samples: &[Sample],
    settings: &Settings,
    variant: Variant,
    p: &[f64],
    bounds: &[(f64, f64)],
) -> (Vec<f64>, Vec<f64>) {
    let n = p.len();
    let steps: Vec<f64> = p.iter().zip(bounds).map(|(p, (_, hi))| if p + 1e-6 > *hi { -1e-6 } else { 1e-6 }).collect();
    let base = material(variant, p);
    let shifted: Vec<Material> = (0..n)
        .map(|j| {
            let mut q = p.to_vec();
            q[j] += steps[j];
            material(variant, &q)
        })
        .collect();
    let chunks: Vec<Vec<f64>> = samples
        .par_chunks(4096)
        .map(|chunk| {
            let mut acc = vec![0.0; n * n + n];
            let mut dr = vec![0.0; n];
            for s in chunk {
                let f0 = readings(&base, settings.masking, &s.g);
                let fj: Vec<[[f64; 3]; 2]> = shifted.iter().map(|m| readings(m, settings.masking, &s.g)).collect();
                for (k, cos) in s.cos.iter().enumerate() {
                    for c in 0..3 {
                        let t0 = settings.objective.transform(f0[k][c], *cos);
                        let r = t0 - s.target[k][c];
                        for j in 0..n {
                            dr[j] = (settings.objective.transform(fj[j][k][c], *cos) - t0) / steps[j];
                        }
                        for j in 0..n {
                            acc[n * n + j] += s.weight * dr[j] * r;
                            for l in 0..n {
                                acc[j * n + l] += s.weight * dr[j] * dr[l];
                            }
                        }
                    }
                }
            }
            acc
        })
        .collect();
    let mut total = vec![0.0; n * n + n];
    for chunk in chunks {
        total.iter_mut().zip(chunk).for_each(|(t, c)| *t += c);
    }
    let jtr = total.split_off(n * n);
    (total, jtr)
}

/// Solves `a x = b` (`a` row-major `n x n`) by Gaussian elimination with partial pivoting;
/// `None` when `a` is singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if a[pivot * n + col].abs() < 1e-300 {
            return None;
        }
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
        }
        b.swap(col, pivot);
        for row in col + 1..n {
            let factor = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= factor * a[col * n + k];
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let rest: f64 = (row + 1..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (b[row] - rest) / a[row * n + row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// The material as a MERL table of dimensions `dims`, sampled like `merl::analytic`'s tables: at
/// the lower edge of every cell, no data at or below the horizon. A table holds one value for
/// both readings of a pair (reciprocity); a coated material, whose two readings differ
/// ([`brdf`]), is stored as their mean. The two differ only by the coat's Fresnel weight of the
/// one angle or the other, which is 0.04 within 0.001 up to 40 degrees from the normal (0.07 at
/// 60): away from grazing views the table is the material.
///
/// Panics on a material whose values are not finite (a roughness below [`MIN_ROUGHNESS`]); the
/// fit never returns one.
pub fn fitted_table(m: &Material, masking: Masking, dims: Dims) -> MerlTable {
    MerlTable::from_fn(dims, |hd| {
        let (wi, wo) = hd.to_dirs();
        (wi.z > HORIZON_EPS && wo.z > HORIZON_EPS).then(|| {
            let [a, b] = readings(m, masking, &Geometry::new(wi, wo));
            std::array::from_fn(|c| 0.5 * (a[c] + b[c]))
        })
    })
}

/// The outgoing elevations of the albedo comparison, in degrees (those `merl-info` reports).
pub const ALBEDO_ANGLES_DEG: [f64; 4] = [0.0, 30.0, 60.0, 80.0];

/// The directional albedo of the measured table and of the fitted one at one elevation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlbedoRow {
    pub theta_o_deg: f64,
    pub measured: [f64; 3],
    pub fit: [f64; 3],
}

impl AlbedoRow {
    /// `(fit - measured) / measured` of the luminances (0 where both are 0).
    pub fn relative_error(&self) -> f64 {
        let (m, f) = (color::luminance(self.measured), color::luminance(self.fit));
        if m == 0.0 { if f == 0.0 { 0.0 } else { f64::INFINITY } } else { (f - m) / m }
    }
}

/// The albedo of both tables at [`ALBEDO_ANGLES_DEG`], each read by the nearest lookup (as the
/// renderers read a table), by `merl`'s half-vector quadrature.
pub fn albedo_rows(measured: &MerlTable, fitted: &MerlTable) -> Vec<AlbedoRow> {
    let albedo = |t: &MerlTable, theta: f64| {
        directional_albedo(|wi, wo| t.lookup(wi, wo, Interp::Nearest), theta, Quadrature::default()).rgb
    };
    ALBEDO_ANGLES_DEG
        .iter()
        .map(|&deg| {
            let theta = deg.to_radians();
            AlbedoRow { theta_o_deg: deg, measured: albedo(measured, theta), fit: albedo(fitted, theta) }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use merl::analytic::Analytic;
    use std::f64::consts::PI;

    /// What a failure shows: the estimate's width, the start and both variants.
    fn summary(fit: &Fit) -> String {
        format!(
            "alpha estimate {}\ninitial {:?}\n{:?}\n{:?}\n{:?}",
            fit.estimate.alpha, fit.initial, fit.core, fit.specular, fit.clearcoat
        )
    }

    fn check(table: &MerlTable, expected: &Material, variant: Variant, tolerance: f64) -> Fit {
        check_with(table, &Settings::default(), expected, variant, tolerance)
    }

    fn check_with(
        table: &MerlTable,
        settings: &Settings,
        expected: &Material,
        variant: Variant,
        tolerance: f64,
    ) -> Fit {
        check_each(table, settings, expected, variant, [tolerance; 8])
    }

    /// [`check_with`] with a tolerance per factor: the base colour's three, metallic, roughness,
    /// specular, clearcoat, clearcoat roughness.
    fn check_each(
        table: &MerlTable,
        settings: &Settings,
        expected: &Material,
        variant: Variant,
        tolerances: [f64; 8],
    ) -> Fit {
        let fit = fit(table, settings);
        let m = fit.chosen().material;
        assert_eq!(fit.chosen, variant, "{}", summary(&fit));
        let pairs = [
            (m.base_color[0], expected.base_color[0]),
            (m.base_color[1], expected.base_color[1]),
            (m.base_color[2], expected.base_color[2]),
            (m.metallic, expected.metallic),
            (m.roughness, expected.roughness),
            (m.specular, expected.specular),
            (m.clearcoat, expected.clearcoat),
            (m.clearcoat_roughness, expected.clearcoat_roughness),
        ];
        for ((got, want), tolerance) in pairs.into_iter().zip(tolerances) {
            assert!((got - want).abs() <= tolerance, "expected {expected:?}\n{}", summary(&fit));
        }
        fit
    }

    /// The cells' measures add up to the measure of the pairs of directions above the surface
    /// (`(2 pi)^2`, less the turn of `phi_h`, over the half of `phi_d` the table holds: `pi`).
    /// 5%: cells across the horizon count whole or not at all, by their sample point, which is
    /// their lower edge and so more often above the horizon than not (measured: 3.4% over).
    #[test]
    fn cell_measures_cover_the_domain() {
        let table = Analytic::Lambertian { albedo: [0.5; 3] }.table(Dims::MERL);
        let total: f64 = samples(&table, Objective::LogCosine, 1).iter().map(|s| s.weight).sum();
        assert!((total - PI).abs() < 0.05 * PI, "{total}");
    }

    /// A table of the model itself is a fixed point: the fit returns its factors. The table is
    /// sampled at the points the fit reads, so nothing but the optimizer's convergence separates
    /// them; 2e-3 in each factor is far below what a picture shows.
    #[test]
    fn recovers_a_ggx_metal() {
        // merl-synth ggx --alpha 0.1 --f0 0.95,0.64,0.54: a metal of roughness sqrt(0.1).
        let table = Analytic::Ggx { alpha: 0.1, f0: [0.95, 0.64, 0.54] }.table(Dims::MERL);
        let expected = Material::core([0.95, 0.64, 0.54], 1.0, 0.1_f64.sqrt());
        check(&table, &expected, Variant::Core, 2e-3);
    }

    #[test]
    fn recovers_a_dielectric() {
        let expected = Material::core([0.6, 0.3, 0.2], 0.0, 0.5);
        let table = fitted_table(&expected, Masking::HeightCorrelated, Dims::MERL);
        check(&table, &expected, Variant::Core, 2e-3);
    }

    /// With Appendix B.3.2's separable masking, a table of that model comes back the same way,
    /// metallic factor included (a mix of dielectric and metal).
    #[test]
    fn recovers_a_separable_mix() {
        let expected = Material::core([0.8, 0.5, 0.3], 0.4, 0.3);
        let table = fitted_table(&expected, Masking::Separable, Dims::MERL);
        let settings = Settings { masking: Masking::Separable, ..Settings::default() };
        check_with(&table, &settings, &expected, Variant::Core, 2e-3);
    }

    /// A Lambertian is the dielectric with `specularFactor` 0 (the core material always
    /// reflects at least 4% specularly): the extension is used, and `baseColor` is the albedo.
    #[test]
    fn recovers_a_lambertian() {
        let table = Analytic::Lambertian { albedo: [0.5, 0.3, 0.1] }.table(Dims::MERL);
        let expected = Material { specular: 0.0, ..Material::core([0.5, 0.3, 0.1], 0.0, 0.5) };
        let fit = fit(&table, &Settings::default());
        let m = fit.chosen().material;
        assert_eq!(fit.chosen, Variant::Specular, "{}", summary(&fit));
        for c in 0..3 {
            assert!((m.base_color[c] - expected.base_color[c]).abs() < 2e-3, "{}", summary(&fit));
        }
        assert!(m.specular < 2e-3, "{}", summary(&fit));
    }

    /// A coated metal (a broad lobe under a sharp colourless one, the shape of the measured
    /// metals' peaks over their haze) comes back as the clearcoat variant. Its table is not the
    /// model exactly: a table holds the mean of a coat's two readings ([`fitted_table`]), which
    /// differ where one direction is near grazing and the other is not (at `theta_h` 5 and
    /// `theta_d` 80 degrees the coat's Fresnel weight is 0.25 seen from one side and 0.65 from
    /// the other), and the fit, which compares each reading with the table, weighs the coat
    /// lower to meet the mean there: 0.82 for 0.9 here. Every other factor within 1e-2, the
    /// coat's within 0.1.
    #[test]
    fn recovers_a_coated_metal() {
        let expected =
            Material { clearcoat: 0.9, clearcoat_roughness: 0.1, ..Material::core([0.1, 0.06, 0.03], 1.0, 0.6) };
        let table = fitted_table(&expected, Masking::HeightCorrelated, Dims::MERL);
        let tolerances = [1e-2, 1e-2, 1e-2, 1e-2, 1e-2, 1e-2, 0.1, 1e-2];
        check_each(&table, &Settings::default(), &expected, Variant::Clearcoat, tolerances);
    }

    /// GGX plus a Lambertian, `kd / pi + GGX(alpha 0.05, F0 0.04)`, the usual "plastic", is not
    /// a glTF material exactly: glTF's dielectric weighs the diffuse by `1 - F`, which at
    /// `F0 = 0.04` is 0.96 at normal incidence and less at grazing angles. The fit should find
    /// the width within 5% and the diffuse colour within 0.05 (the `1 - F` it must absorb is 4%
    /// of 0.7 = 0.028 near normal incidence).
    #[test]
    fn recovers_ggx_plus_lambertian() {
        let kd = [0.7, 0.2, 0.1];
        let (diffuse, ggx) = (Analytic::Lambertian { albedo: kd }, Analytic::Ggx { alpha: 0.05, f0: [0.04; 3] });
        let table = MerlTable::from_fn(Dims::MERL, |hd| {
            let (wi, wo) = hd.to_dirs();
            (wi.z > HORIZON_EPS && wo.z > HORIZON_EPS).then(|| {
                let (a, b) = (diffuse.eval(wi, wo), ggx.eval(wi, wo));
                [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
            })
        });
        let fit = fit(&table, &Settings::default());
        let m = fit.chosen().material;
        assert!((m.alpha() - 0.05).abs() < 0.05 * 0.05, "{}", summary(&fit));
        for (got, want) in m.base_color.iter().zip(kd) {
            assert!((got - want).abs() < 0.05, "{}", summary(&fit));
        }
    }
}
