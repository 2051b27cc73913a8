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
