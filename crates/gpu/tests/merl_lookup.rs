//! Holds the WGSL MERL lookup to the CPU reference in the `merl` crate: for every direction pair
//! the shader must pick the cell that `Dims::nearest_cell` picks (except where f32 arithmetic can
//! legitimately round across a cell boundary, which must be rare) and return that cell's value.
//!
//! These tests run on whatever adapter `Gpu::new` finds: lavapipe in CI. They never skip: on a
//! machine without an adapter they fail with the message that says how to install one.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

use glam::DVec3;
use gpu::{MerlLookup, MerlSample};
use merl::analytic::Analytic;
use merl::{Cell, Dims, HalfDiff, MerlTable, half_diff, spherical_dir};
use rand::{Rng, SeedableRng, rngs::StdRng};

use crate::support::{gpu, log};

/// Budget for the absolute error of each angle the shader computes (theta_h, phi_h, theta_d,
/// phi_d), in radians. Spec-level reasoning gives no useful bound: Vulkan lets atan2 be off by 4096
/// ulp and sin and cos by 2^-11. So the budget is measured, on the adapter CI runs: lavapipe
/// (Mesa 22.3) computes sin and cos to within an ulp but atan2 only to 3.4e-6 rad (29
/// f32::EPSILON, worst at pi/4), and the error it leaves in the angles, over 10^6 pairs (random
/// ones like these and near-mirror ones), was at most 42 f32::EPSILON, in theta_d, where two such
/// atan2 errors add up. 96 leaves a factor of 2.3.
const ANGLE_ERROR: f64 = 96.0 * f32::EPSILON as f64;

/// Roundings of a grid coordinate after its angle (divide, multiply, add the phi_d range), each
/// at most one ulp of the coordinate.
const COORD_ULPS: f64 = 4.0;

/// Pairs whose CPU coordinate lies within tolerance of a boundary, as a fraction of all pairs,
/// must stay below this: a larger share means the tolerance hides real disagreements.
const MAX_BORDERLINE_FRACTION: f64 = 0.01;

const N_RANDOM_PAIRS: usize = 10_000;

fn cached(cell: &'static OnceLock<MerlTable>, brdf: Analytic) -> &'static MerlTable {
    cell.get_or_init(|| brdf.table(Dims::MERL))
}

/// Sharp enough that neighbouring cells differ in value, so a wrong cell shows in the values too.
fn ggx() -> &'static MerlTable {
    static TABLE: OnceLock<MerlTable> = OnceLock::new();
    cached(&TABLE, Analytic::Ggx { alpha: 0.1, f0: [0.04, 0.5, 0.9] })
}

fn phong() -> &'static MerlTable {
    static TABLE: OnceLock<MerlTable> = OnceLock::new();
    cached(&TABLE, Analytic::Phong { n: 30.0, ks: [0.8, 0.6, 0.3], kd: [0.0; 3] })
}

/// A table whose values name their cell, with a band of no-data cells; instant to build, so it
/// covers the dimensions that no analytic table in these tests has.
fn index_table(dims: Dims) -> MerlTable {
    let raw: Vec<f64> = (0..3)
        .flat_map(|c| (0..dims.cells()).map(move |i| if dims.cell(i).theta_d >= 85 { -1.0 } else { (i + c) as f64 }))
        .collect();
    MerlTable::from_raw(dims, raw).expect("finite values of the right count")
}

fn lookup(table: &MerlTable) -> MerlLookup {
    MerlLookup::new(gpu(), table).unwrap_or_else(|e| panic!("uploading the table: {e}"))
}

fn to_f32(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn to_f64(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// Uniform in solid angle over the upper hemisphere, strictly above the horizon.
fn random_upper(rng: &mut StdRng) -> DVec3 {
    let z = 1.0 - rng.random::<f64>();
    spherical_dir(z.acos(), 2.0 * PI * rng.random::<f64>())
}

fn random_pairs(seed: u64, n: usize) -> Vec<([f32; 3], [f32; 3])> {
    let mut rng = StdRng::seed_from_u64(seed);
    (0..n).map(|_| (to_f32(random_upper(&mut rng)), to_f32(random_upper(&mut rng)))).collect()
}

/// The CPU's view of a pair, from the same f32 directions the GPU received.
struct Reference {
    hd: HalfDiff,
    coords: [f64; 3],
    cell: Cell,
}

fn reference(dims: Dims, (wi, wo): ([f32; 3], [f32; 3])) -> Reference {
    let hd = half_diff(to_f64(wi), to_f64(wo));
    Reference { hd, coords: dims.grid_coords(&hd), cell: dims.nearest_cell(&hd) }
}

/// How far, in cells, the f32 coordinate of each axis may stray from the f64 one: the angle
/// error [`ANGLE_ERROR`] times the slope of the map from angle to coordinate, plus
/// [`COORD_ULPS`] ulps of the coordinate itself (at most `n` cells, so `eps * n` per ulp).
/// - theta_d: `x = theta_d / (pi/2) * n`, slope `n / (pi/2)` = 57 per radian.
/// - theta_h: `x = sqrt(theta_h / (pi/2)) * n`, slope `n^2 / (pi x)`: the square-root spacing is
///   steepest at the pole. Boundaries start at `x = 1`, where the slope is 2578 per radian, so
///   taking `x >= 1` bounds it where it matters.
/// - phi_d: `x = phi_d / range * n`, slope `n / range` = 57 per radian; but `phi_d` is the
///   azimuth of the difference vector, whose horizontal part has length `sin theta_d`, so an
///   absolute error in that vector is divided by `sin theta_d` in `phi_d`. At `theta_d = 0` the
///   azimuth is undefined and any cell is as right as another.
///
/// That is about 7e-4 cells away from the poles, 1e-3 cells in phi_d for a typical theta_d and
/// 3e-2 cells at the first theta_h boundary: about 0.6% of random pairs come out borderline.
fn tolerances(dims: Dims, r: &Reference) -> [f64; 3] {
    let ulp = COORD_ULPS * f64::from(f32::EPSILON);
    let (n_h, n_d, n_p) = (dims.n_theta_h as f64, dims.n_theta_d as f64, dims.n_phi_d as f64);
    let sin_theta_d = r.hd.theta_d.sin();
    [
        ANGLE_ERROR * n_h * n_h / (PI * r.coords[0].max(1.0)) + ulp * n_h,
        ANGLE_ERROR * n_d / FRAC_PI_2 + ulp * n_d,
        if sin_theta_d > 0.0 {
            ANGLE_ERROR * n_p / dims.phi_d_range() / sin_theta_d + ulp * n_p
        } else {
            f64::INFINITY
        },
    ]
}

/// Distance from a coordinate to the nearest boundary across which its cell index changes:
/// interior integers for the clamped theta axes; every integer for phi_d, which wraps (`0` and
/// `n` are the same angle).
fn boundary_distance(x: f64, n: usize, wraps: bool) -> f64 {
    let nearest = if wraps { x.round() } else { x.round().clamp(1.0, (n - 1) as f64) };
    (x - nearest).abs()
}

/// If GPU index `g` and CPU index `c` are the same or adjacent cells, the distance from the CPU
/// coordinate `x` to the boundary between them (0 if the same); `None` if they are further apart.
fn distance_to_shared_boundary(x: f64, g: usize, c: usize, n: usize, wraps: bool) -> Option<f64> {
    if g == c {
        return Some(0.0);
    }
    let boundary = if g.abs_diff(c) == 1 {
        g.max(c) as f64
    } else if wraps && g.min(c) == 0 && g.max(c) == n - 1 {
        if x < n as f64 / 2.0 { 0.0 } else { n as f64 }
    } else {
        return None;
    };
    Some((x - boundary).abs())
}

#[derive(Debug, Default)]
struct Agreement {
    pairs: usize,
    /// Pairs with some CPU coordinate within tolerance of a boundary.
    borderline: usize,
    /// Pairs where the GPU picked another cell (all of them borderline, or the test fails).
    other_cell: usize,
    /// Over those pairs and their axes, the largest distance of the CPU coordinate to the
    /// boundary the GPU crossed, as a fraction of the tolerance: how much of it was used.
    tolerance_used: f64,
    no_data: usize,
}

/// Looks up `pairs` on the GPU and checks every result against the CPU; panics listing the
/// first disagreements.
fn check_against_cpu(name: &str, table: &MerlTable, pairs: &[([f32; 3], [f32; 3])]) -> Agreement {
    let dims = table.dims();
    let samples = lookup(table).evaluate(pairs).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(samples.len(), pairs.len(), "{name}: one sample per pair");

    // (cells, whether the axis wraps) for theta_h, theta_d, phi_d.
    let axes = [(dims.n_theta_h, false), (dims.n_theta_d, false), (dims.n_phi_d, true)];
    let mut agreement = Agreement { pairs: pairs.len(), ..Default::default() };
    let mut failures = Vec::new();
    for (i, (&pair, sample)) in pairs.iter().zip(&samples).enumerate() {
        let r = reference(dims, pair);
        let tol = tolerances(dims, &r);
        let borderline = (0..3).any(|a| boundary_distance(r.coords[a], axes[a].0, axes[a].1) <= tol[a]);
        agreement.borderline += usize::from(borderline);

        if sample.cell as usize >= dims.cells() {
            failures.push(format!("pair {i} {pair:?}: cell {} out of range", sample.cell));
            continue;
        }
        let cpu_index = dims.index(r.cell);
        if sample.cell as usize != cpu_index {
            agreement.other_cell += 1;
            let g = dims.cell(sample.cell as usize);
            let (gi, ci) = ([g.theta_h, g.theta_d, g.phi_d], [r.cell.theta_h, r.cell.theta_d, r.cell.phi_d]);
            let distances: Option<Vec<f64>> =
                (0..3).map(|a| distance_to_shared_boundary(r.coords[a], gi[a], ci[a], axes[a].0, axes[a].1)).collect();
            let used = distances.map_or(f64::INFINITY, |d| (0..3).map(|a| d[a] / tol[a]).fold(0.0, f64::max));
            agreement.tolerance_used = agreement.tolerance_used.max(used);
            if used > 1.0 {
                failures.push(format!(
                    "pair {i} {pair:?}: gpu cell {g:?}, cpu cell {:?} at coordinates {:?} \
                     (tolerances {tol:?})",
                    r.cell, r.coords
                ));
            }
        }
        if let Err(e) = check_value(table, sample) {
            failures.push(format!("pair {i} {pair:?}: {e}"));
        }
        agreement.no_data += usize::from(!sample.has_data());
    }
    log(&format!("{name}: {agreement:?}"));
    assert!(
        failures.is_empty(),
        "{name}: {} of {} pairs disagree, first ones:\n{}",
        failures.len(),
        pairs.len(),
        failures.iter().take(10).cloned().collect::<Vec<_>>().join("\n")
    );
    let fraction = agreement.borderline as f64 / agreement.pairs as f64;
    assert!(
        fraction < MAX_BORDERLINE_FRACTION,
        "{name}: {} of {} pairs lie within tolerance of a cell boundary: the tolerance is too loose",
        agreement.borderline,
        agreement.pairs
    );
    agreement
}

/// The GPU's value must be the CPU table's value of the cell the GPU reports, up to the f32
/// rounding of the upload (relative 6e-8; 1e-6 leaves room, none for a neighbouring cell of a
/// table that varies). The absolute floor covers values below f32's normal range, which a
/// driver may flush to zero.
fn check_value(table: &MerlTable, sample: &MerlSample) -> Result<(), String> {
    match table.cell_value(sample.cell as usize) {
        None if sample.has_data() => Err(format!("cpu: no data, gpu: {:?}", sample.rgb)),
        None => Ok(()),
        Some(rgb) => {
            let close = (0..3).all(|c| {
                let (g, v) = (f64::from(sample.rgb[c]), rgb[c]);
                (g - v).abs() <= 1e-6 * v.abs() + f64::from(f32::MIN_POSITIVE)
            });
            if close { Ok(()) } else { Err(format!("cpu value {rgb:?}, gpu {:?}", sample.rgb)) }
        }
    }
}

#[test]
fn ggx_cells_and_values_match_the_cpu() {
    let agreement = check_against_cpu("ggx alpha 0.1", ggx(), &random_pairs(1, N_RANDOM_PAIRS));
    // Above-horizon pairs do land in cells whose sample point is below it; make sure the no-data
    // path was exercised.
    assert!(agreement.no_data > 0, "no pair hit a no-data cell: {agreement:?}");
}

#[test]
fn phong_cells_and_values_match_the_cpu() {
    check_against_cpu("phong n 30", phong(), &random_pairs(2, N_RANDOM_PAIRS));
}

#[test]
fn full_phi_table_cells_match_the_cpu() {
    check_against_cpu("index table 90 x 90 x 360", &index_table(Dims::MERL_FULL_PHI), &random_pairs(3, N_RANDOM_PAIRS));
}

/// The cell the GPU picks for one pair, checked against a hand-computed cell and the CPU.
fn check_cell(lookup: &MerlLookup, wi: [f32; 3], wo: [f32; 3], expect: Cell) {
    let dims = lookup.dims();
    let sample = lookup.evaluate(&[(wi, wo)]).expect("gpu lookup")[0];
    assert_eq!(reference(dims, (wi, wo)).cell, expect, "cpu, {wi:?} {wo:?}");
    assert_eq!(dims.cell(sample.cell as usize), expect, "gpu, {wi:?} {wo:?}");
}

/// `wi` at polar angle `theta` and azimuth `phi`, `wo` its mirror image about the normal, built in
/// f32 so that `wi + wo` is exactly on the normal.
fn mirror_pair(theta: f32, phi: f32) -> ([f32; 3], [f32; 3]) {
    let wi = [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()];
    (wi, [-wi[0], -wi[1], wi[2]])
}

#[test]
fn hand_checked_cells() {
    let merl = lookup(&index_table(Dims::MERL));
    let full = lookup(&index_table(Dims::MERL_FULL_PHI));
    let cell = |theta_h, theta_d, phi_d| Cell { theta_h, theta_d, phi_d };

    // Normal incidence, normal exitance: h = d = z, both azimuths are atan2(0, 0).
    check_cell(&merl, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], cell(0, 0, 0));

    // Mirror configuration: h = z, so theta_h = 0, d = wi. theta_d = 0.3 rad is at
    // 0.3 / (pi/2) * 90 = 17.19; phi_d = 1 rad is at 1 / pi * 180 = 57.30.
    let (wi, wo) = mirror_pair(0.3, 1.0);
    check_cell(&merl, wi, wo, cell(0, 17, 57));
    check_cell(&full, wi, wo, cell(0, 17, 57));

    // phi_d = -1 rad: 180 cells fold it by reciprocity to pi - 1, at 122.70; 360 cells keep it as
    // 2 pi - 1, at 302.70.
    let (wi, wo) = mirror_pair(0.3, -1.0);
    check_cell(&merl, wi, wo, cell(0, 17, 122));
    check_cell(&full, wi, wo, cell(0, 17, 302));

    // A general configuration: theta_h = 0.5 is at sqrt(0.5 / (pi/2)) * 90 = 50.78 (the square
    // root spacing), theta_d = 0.4 at 22.92, phi_d = 0.9 at 51.57.
    let hd = HalfDiff { theta_h: 0.5, phi_h: 2.0, theta_d: 0.4, phi_d: 0.9 };
    let (wi, wo) = hd.to_dirs();
    check_cell(&merl, to_f32(wi), to_f32(wo), cell(50, 22, 51));
}

#[test]
fn retro_reflection_reads_theta_h_through_the_square_root_spacing() {
    // wi = wo: h = wi and d is the pole, so theta_d = 0 and phi_d is undefined (left unchecked).
    // theta_h = 0.7 is at sqrt(0.7 / (pi/2)) * 90 = 60.08.
    let merl = lookup(&index_table(Dims::MERL));
    let w = to_f32(spherical_dir(0.7, 1.1));
    let got = merl.dims().cell(merl.evaluate(&[(w, w)]).expect("gpu lookup")[0].cell as usize);
    assert_eq!((got.theta_h, got.theta_d), (60, 0), "{got:?}");
}

#[test]
fn batches_split_across_dispatches_give_the_same_samples() {
    let table = index_table(Dims::MERL);
    // 2500 pairs in dispatches of 1000: two full ones and a partial one, none a whole number of
    // workgroups.
    let pairs = random_pairs(4, 2500);
    let whole = lookup(&table).evaluate(&pairs).expect("one dispatch");
    let split = lookup(&table).with_max_pairs_per_dispatch(1000);
    assert_eq!(split.max_pairs_per_dispatch(), 1000);
    assert_eq!(split.evaluate(&pairs).expect("three dispatches"), whole);
    assert!(split.evaluate(&[]).expect("no pairs").is_empty());
}

#[test]
fn the_device_can_hold_a_full_phi_table() {
    // Gpu::new promises this; the limits it requested must say so too.
    let limits = gpu().limits();
    let bytes = 3 * Dims::MERL_FULL_PHI.cells() as u64 * 4;
    assert!(limits.max_storage_buffer_binding_size >= bytes, "{limits:?}");
    assert!(limits.max_buffer_size >= bytes, "{limits:?}");
}

#[test]
fn the_no_adapter_error_says_how_to_get_one() {
    let message = gpu::GpuError::NoAdapter.to_string();
    assert!(message.contains("apt-get install mesa-vulkan-drivers libvulkan1"), "{message}");
    assert!(message.contains("WGPU_BACKEND"), "{message}");
}
