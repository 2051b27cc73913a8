//! The validation summary that `merl-info` prints.

use crate::albedo::{Albedo, Quadrature, directional_albedo};
use crate::coords::HalfDiff;
use crate::table::{Cell, Dims, Interp, MerlTable};
use std::f64::consts::TAU;

/// The outgoing elevations (degrees) at which the summary reports the directional albedo.
pub const SUMMARY_THETA_O_DEG: [f64; 4] = [0.0, 30.0, 60.0, 80.0];

/// Statistics of one channel over the cells that hold data, in 1/sr.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelStats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

/// The cell of largest luminance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    pub rgb: [f64; 3],
    pub luminance: f64,
    pub cell: Cell,
    /// Where the cell is sampled (its lower edge).
    pub at: HalfDiff,
}

/// The cell that would reflect the largest share of a directional albedo on its own
/// ([`cell_share`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellShare {
    /// The estimated share, of the channel whose share is largest.
    pub share: f64,
    pub rgb: [f64; 3],
    pub cell: Cell,
    /// The incoming and outgoing elevations at the cell's centre, in radians.
    pub theta_i: f64,
    pub theta_o: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    pub dims: Dims,
    pub cells: usize,
    pub no_data_cells: usize,
    /// Red, green, blue. `None` if no cell holds data.
    pub channels: Option<[ChannelStats; 3]>,
    pub peak: Option<Peak>,
    /// `(theta_o in degrees, albedo)` for each of [`SUMMARY_THETA_O_DEG`].
    pub albedo: Vec<(f64, Albedo)>,
    /// The cell of the largest [`cell_share`]: the albedo at four elevations misses a cell whose
    /// value alone reflects more than the light received (a corrupt value). `None` if no cell
    /// holds data.
    pub largest_share: Option<CellShare>,
}

/// The share of the directional albedo at the cell's own outgoing elevation that cell `c` of
/// value `value` (1/sr) reflects on its own: `value cos theta_i` times the solid angle of the
/// incoming directions whose half and difference angles fall in the cell, estimated as `4 cos
/// theta_d` (the Jacobian from half vectors to incoming directions) times the cell's band of
/// `theta_h` (`2 pi (cos theta_a - cos theta_b)`) times its fraction of `phi_d` (`1 / n_phi_d`
/// of the turn, counting the half turn that reciprocity folds onto it), at the cell's centre.
/// The fraction takes `phi_d` to follow the half vector's azimuth one for one, which holds near
/// the mirror configuration and overestimates elsewhere: for a physical table every cell's
/// share is far below 1 (`merl-info` on the 20 real-derived materials of `../shared/data/nbrdf`:
/// at most 3.6e-4, teflon's; a Lambertian's 4.2e-4), and a share above 1 is a value no material
/// has. A cell below the horizon on either side has no share.
pub fn cell_share(dims: Dims, c: Cell, value: f64) -> CellShare {
    let (theta_a, theta_b) = (dims.theta_h_at(c.theta_h as f64), dims.theta_h_at(c.theta_h as f64 + 1.0));
    let centre = HalfDiff {
        theta_h: dims.theta_h_at(c.theta_h as f64 + 0.5),
        phi_h: 0.0,
        theta_d: dims.theta_d_at(c.theta_d as f64 + 0.5),
        phi_d: (c.phi_d as f64 + 0.5) / dims.n_phi_d as f64 * dims.phi_d_range(),
    };
    let (wi, wo) = centre.to_dirs();
    let solid_angle = 4.0 * centre.theta_d.cos() * TAU * (theta_a.cos() - theta_b.cos()) / dims.n_phi_d as f64;
    // A cell whose configuration lies below the horizon on either side takes part in no albedo.
    let share = if wo.z > 0.0 { value * wi.z.max(0.0) * solid_angle } else { 0.0 };
    CellShare {
        share,
        rgb: [value; 3],
        cell: c,
        theta_i: wi.z.clamp(-1.0, 1.0).acos(),
        theta_o: wo.z.clamp(-1.0, 1.0).acos(),
    }
}

/// Summarizes a table; the albedo uses `interp` lookups and quadrature `q`.
pub fn summarize(table: &MerlTable, interp: Interp, q: Quadrature) -> Summary {
    let albedo = SUMMARY_THETA_O_DEG
        .iter()
        .map(|&deg| (deg, directional_albedo(|wi, wo| table.lookup(wi, wo, interp), deg.to_radians(), q)))
        .collect();
    Summary { albedo, ..summarize_cells(table) }
}

/// What one pass over the cells finds (statistics, peak, largest [`cell_share`]), without the
/// albedo's quadrature: `albedo` is empty. A tenth of [`summarize`]'s time on a MERL table.
pub fn summarize_cells(table: &MerlTable) -> Summary {
    let dims = table.dims();
    let mut stats = [ChannelStats { min: f64::INFINITY, max: f64::NEG_INFINITY, mean: 0.0 }; 3];
    let mut valid = 0usize;
    let mut peak: Option<Peak> = None;
    let mut largest_share: Option<CellShare> = None;
    for index in 0..dims.cells() {
        let Some(rgb) = table.cell_value(index) else { continue };
        valid += 1;
        for (s, v) in stats.iter_mut().zip(rgb) {
            s.min = s.min.min(v);
            s.max = s.max.max(v);
            s.mean += v;
        }
        let largest = rgb.into_iter().fold(f64::NEG_INFINITY, f64::max);
        let share = CellShare { rgb, ..cell_share(dims, dims.cell(index), largest) };
        if largest_share.is_none_or(|s: CellShare| share.share > s.share) {
            largest_share = Some(share);
        }
        let luminance = color::luminance(rgb);
        if peak.is_none_or(|p| luminance > p.luminance) {
            let cell = dims.cell(index);
            peak = Some(Peak { rgb, luminance, cell, at: dims.sample_point(cell) });
        }
    }
    stats.iter_mut().for_each(|s| s.mean /= valid.max(1) as f64);
    Summary {
        dims,
        cells: dims.cells(),
        no_data_cells: dims.cells() - valid,
        channels: (valid > 0).then_some(stats),
        peak,
        albedo: Vec::new(),
        largest_share,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::Analytic;

    #[test]
    fn normalized_phong_tables_stay_at_or_below_one() {
        // Exact albedo: 1 at normal incidence, less elsewhere. The table adds its discretization
        // error (trilinear between lower-edge samples, measured +0.06% at n = 10, +0.8% at
        // n = 1000); 1% covers that and nothing else: a wrong Jacobian is off by far more.
        for n in [1.0, 10.0, 100.0, 1000.0] {
            let table = Analytic::Phong { n, ks: [1.0; 3], kd: [0.0; 3] }.table(Dims::MERL);
            let s = summarize(&table, Interp::Trilinear, Quadrature::default());
            for (deg, a) in &s.albedo {
                assert!(a.rgb[0] <= 1.01, "n {n}, theta_o {deg}: {:?}", a.rgb);
            }
            assert!(s.albedo[0].1.rgb[0] > 0.99, "n {n}: normal incidence {:?}", s.albedo[0].1.rgb);
        }
    }

    #[test]
    fn one_corrupt_cell_carries_the_largest_share_and_physical_tables_stay_far_below_one() {
        // Physical tables: a Lambertian of albedo 1 and sharp lobes (Phong n = 1000, whose peak
        // cells hold ~160 1/sr; GGX alpha 0.01, measured 1.04e-3, the largest) never let one cell
        // reflect a hundredth of the light: the estimate's factor-of-a-few error cannot reach the
        // bound of 1.
        for brdf in [
            Analytic::Lambertian { albedo: [1.0; 3] },
            Analytic::Phong { n: 1000.0, ks: [1.0; 3], kd: [0.0; 3] },
            Analytic::Ggx { alpha: 0.01, f0: [1.0; 3] },
        ] {
            let table = brdf.table(Dims::MERL);
            let s = summarize(&table, Interp::Nearest, Quadrature::default());
            let share = s.largest_share.expect("cells with data").share;
            assert!(share > 0.0 && share < 1e-2, "{brdf:?}: {share}");
        }
        // One cell of about 7e11 1/sr (raw 1e15) at the mirror configuration, which the albedo at
        // four elevations misses: it carries the largest share, above 1 (its solid angle, about
        // 2.6e-9 sr times cos theta_i 0.37, makes it a few hundred), and the albedos do not see it.
        let table = Analytic::Lambertian { albedo: [0.5; 3] }.table(Dims::MERL);
        let cell = Cell { theta_h: 0, theta_d: 68, phi_d: 105 };
        let mut raw = table.raw().to_vec();
        for c in 0..3 {
            raw[c * Dims::MERL.cells() + Dims::MERL.index(cell)] = 1e15;
        }
        let table = MerlTable::from_raw(Dims::MERL, raw).unwrap();
        let s = summarize(&table, Interp::Nearest, Quadrature::default());
        let c = s.largest_share.unwrap();
        assert_eq!(c.cell, cell);
        assert!(c.share > 100.0 && c.share < 1e4, "{c:?}");
        assert!(s.albedo.iter().all(|(_, a)| a.rgb[0] < 0.51), "{:?}", s.albedo);
        // A cell below the horizon has no share: theta_h 89 deg with theta_d 80 deg puts wo under it.
        let below = cell_share(Dims::MERL, Cell { theta_h: 89, theta_d: 80, phi_d: 0 }, 1e30);
        assert_eq!(below.share, 0.0, "{below:?}");
    }

    #[test]
    fn statistics_skip_cells_without_data() {
        let table = Analytic::Lambertian { albedo: [0.5; 3] }.table(Dims::MERL);
        let s = summarize(&table, Interp::Nearest, Quadrature::default());
        let ch = s.channels.expect("cells with data");
        for c in ch {
            // Every cell with data holds 0.5/pi; a no-data -1 leaking in would lower min and mean.
            assert!((c.min - 0.5 / std::f64::consts::PI).abs() < 1e-12, "{c:?}");
            // The mean sums 1.1e6 values: allow their rounding (1e-9 relative), not a -1.
            assert!((c.mean - 0.5 / std::f64::consts::PI).abs() < 1e-9, "{c:?}");
        }
        assert_eq!(s.no_data_cells, 346_570);
    }
}
