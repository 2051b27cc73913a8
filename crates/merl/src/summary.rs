//! The validation summary that `merl-info` prints.

use crate::albedo::{Albedo, Quadrature, directional_albedo};
use crate::coords::HalfDiff;
use crate::table::{Cell, Dims, Interp, MerlTable};

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
}

/// Summarizes a table; the albedo uses `interp` lookups and quadrature `q`.
pub fn summarize(table: &MerlTable, interp: Interp, q: Quadrature) -> Summary {
    let dims = table.dims();
    let mut stats = [ChannelStats { min: f64::INFINITY, max: f64::NEG_INFINITY, mean: 0.0 }; 3];
    let mut valid = 0usize;
    let mut peak: Option<Peak> = None;
    for index in 0..dims.cells() {
        let Some(rgb) = table.cell_value(index) else { continue };
        valid += 1;
        for (s, v) in stats.iter_mut().zip(rgb) {
            s.min = s.min.min(v);
            s.max = s.max.max(v);
            s.mean += v;
        }
        let luminance = crate::luminance(rgb);
        if peak.is_none_or(|p| luminance > p.luminance) {
            let cell = dims.cell(index);
            peak = Some(Peak { rgb, luminance, cell, at: dims.sample_point(cell) });
        }
    }
    stats.iter_mut().for_each(|s| s.mean /= valid.max(1) as f64);
    let albedo = SUMMARY_THETA_O_DEG
        .iter()
        .map(|&deg| (deg, directional_albedo(|wi, wo| table.lookup(wi, wo, interp), deg.to_radians(), q)))
        .collect();
    Summary {
        dims,
        cells: dims.cells(),
        no_data_cells: dims.cells() - valid,
        channels: (valid > 0).then_some(stats),
        peak,
        albedo,
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
