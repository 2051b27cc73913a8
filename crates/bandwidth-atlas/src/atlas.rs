//! The atlas: every lobe of the incident grid analysed and reduced to a tile, the tiles packed
//! row-major into one image.

use rayon::prelude::*;

use crate::analysis::{Analyser, Scratch};
use crate::error::Error;
use crate::lobe::LuminanceTable;
use crate::param::{IncidentGrid, LobeMap, to_incidence_frame};
use glam::DVec3;

/// How the atlas is made. [`Config::default`] is the papers' layout, 64 x 64 incident
/// directions, each lobe reduced to 16 x 16, a 1024 x 1024 atlas, with each lobe analysed at
/// 1024 x 1024 ([`Config::analysis_size`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Lobes per side of the incident grid ([`IncidentGrid`]).
    pub lobes: usize,
    /// Texels per side of a lobe's tile in the atlas. A power of two.
    pub tile: usize,
    /// Pixels per side of the grid each lobe is analysed on ([`crate::LobeMap`]): a power of
    /// two from 16 to 4096, at least `tile`. The highest bandwidth it can report is
    /// [`DEFAULT_C`](bandwidth::DEFAULT_C)` / 2` cycles per pixel, `0.088 size / pi` cycles per
    /// radian at the centre of the lobe image (1.8 for 64, 14.4 for 512, 28.8 for 1024). The
    /// default, 1024, resolves normalized Phong lobes up to n = 1000 at every incident
    /// direction, the grazing ones whose lobe straddles the horizon included, analytically and
    /// as a table made by `merl-synth` (`lobes_at_limit` 0). At 512 such a lobe (1/e half width
    /// 5 pixels there) is on the estimate's edge: the analytic lobe reads the limit at its peak
    /// in one row (theta_i 21.6 degrees, where the peak falls on the finest wavelets' grid so
    /// that they see more than `eps` of the largest coefficient), a table of it in three rows
    /// (192 of 4096 lobes); at 256 every lobe of n = 1000 reaches the limit.
    /// The cost grows with `size^2` (crate docs, "Performance").
    pub analysis_size: usize,
    /// The relative threshold of eq. 7 (`bandwidth::Config::eps`).
    pub eps: f64,
    /// The wavelet's bandwidth constant (`bandwidth::Config::c`).
    pub c: f64,
    /// Details below this fraction of the lobe's largest luminance count as zero (the
    /// `bandwidth` crate's noise floor, scaled to each lobe): far above the rounding noise of
    /// the lookups and the transform (1e-16 relative), far below any visible detail.
    pub relative_noise_floor: f64,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            lobes: 64,
            tile: 16,
            analysis_size: 1024,
            eps: 0.01,
            c: bandwidth::DEFAULT_C,
            relative_noise_floor: 1e-6,
        }
    }
}

/// Atlases larger than this many texels are refused (4 GiB of `f32`).
pub const MAX_TEXELS: usize = 1 << 30;

impl Config {
    /// Checks the sizes and the estimator's settings.
    pub fn check(&self) -> Result<(), Error> {
        let bad = |msg: String| Err(Error::Config(msg));
        if self.lobes == 0 || self.lobes > 4096 {
            return bad(format!("{} lobes per side: expected 1 to 4096", self.lobes));
        }
        if !self.tile.is_power_of_two() {
            return bad(format!("tile size {} is not a power of two", self.tile));
        }
        if !self.analysis_size.is_power_of_two() || self.analysis_size < 16 || self.analysis_size > 4096 {
            return bad(format!("analysis size {} is not a power of two from 16 to 4096", self.analysis_size));
        }
        if self.tile > self.analysis_size {
            return bad(format!("tile size {} exceeds the analysis size {}", self.tile, self.analysis_size));
        }
        let side = self.lobes * self.tile;
        if side * side > MAX_TEXELS {
            return bad(format!("a {side} x {side} atlas exceeds the limit of {MAX_TEXELS} texels"));
        }
        if !(self.eps > 0.0 && self.eps <= 1.0) {
            return bad(format!("eps {} is not in (0, 1]", self.eps));
        }
        if !(self.c > 0.0 && self.c.is_finite()) {
            return bad(format!("c {} is not positive and finite", self.c));
        }
        if !(self.relative_noise_floor >= 0.0 && self.relative_noise_floor < 1.0) {
            return bad(format!("relative noise floor {} is not in [0, 1)", self.relative_noise_floor));
        }
        Ok(())
    }
}

/// The parameterizations an atlas was made with. One exists today; a new one gets a new name
/// and the readers say which they found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameterization {
    /// Incident directions in rows of equal `cos(theta_i)` steps and columns of `phi_i`
    /// ([`IncidentGrid`]); lobe images in the azimuthal equidistant projection of `wo` in the
    /// frame of the plane of incidence, continued below the horizon by extrapolation
    /// ([`crate::LobeMap`]); a texel holds the largest bandwidth of the analysis pixels of the
    /// hemisphere it covers, in cycles per radian (crate docs).
    IncidencePlaneEquidistant,
}

impl Parameterization {
    pub const ALL: [Parameterization; 1] = [Parameterization::IncidencePlaneEquidistant];

    /// The name files store.
    pub fn name(self) -> &'static str {
        match self {
            Parameterization::IncidencePlaneEquidistant => "cos-theta-phi-grid/incidence-plane-azimuthal-equidistant",
        }
    }

    /// The parameterization called `name`, if this build knows it.
    pub fn from_name(name: &str) -> Option<Parameterization> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// The bandwidth atlas: `lobes_x x lobes_y` tiles of `tile x tile` texels, each the angular
/// bandwidth of one outgoing lobe in cycles per radian. Lobe `(i, j)` of the incident grid
/// (column `i`: `phi_i`, row `j`: `theta_i`) occupies texels `[i tile, (i + 1) tile) x [j tile, (j + 1) tile)`;
/// `data` is the whole image row-major, `lobes_x tile` texels per row, top row first (crate
/// docs, "Atlas layout").
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    pub lobes_x: usize,
    pub lobes_y: usize,
    pub tile: usize,
    /// Texels, row-major: `(lobes_x tile) x (lobes_y tile)` values in cycles per radian.
    pub data: Vec<f32>,
    pub parameterization: Parameterization,
    /// The side of the grid each lobe was analysed on.
    pub analysis_size: usize,
    /// The estimator's `eps` and `c`.
    pub eps: f64,
    pub c: f64,
}

impl Atlas {
    /// Texels per row.
    pub fn width(&self) -> usize {
        self.lobes_x * self.tile
    }

    /// Rows of texels.
    pub fn height(&self) -> usize {
        self.lobes_y * self.tile
    }

    pub fn n_lobes(&self) -> usize {
        self.lobes_x * self.lobes_y
    }

    /// Texels per tile.
    pub fn tile_len(&self) -> usize {
        self.tile * self.tile
    }

    /// Checks that the sizes agree with each other and every value is finite and non-negative.
    pub fn check(&self) -> Result<(), Error> {
        let height = self.lobes_y.checked_mul(self.tile);
        let texels = self.lobes_x.checked_mul(self.tile).and_then(|w| height.and_then(|h| w.checked_mul(h)));
        if self.lobes_x == 0 || self.lobes_y == 0 || self.tile == 0 || texels.is_none_or(|t| t > MAX_TEXELS) {
            return Err(Error::Invalid(format!(
                "atlas of {} x {} lobes of {} x {} texels is empty or too large",
                self.lobes_x, self.lobes_y, self.tile, self.tile
            )));
        }
        if Some(self.data.len()) != texels {
            return Err(Error::Invalid(format!(
                "atlas holds {} values, expected {} x {} = {}",
                self.data.len(),
                self.width(),
                self.height(),
                self.width() * self.height()
            )));
        }
        if let Some(k) = self.data.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(Error::Invalid(format!(
                "texel ({}, {}) holds {}: expected a finite bandwidth >= 0",
                k % self.width(),
                k / self.width(),
                self.data[k]
            )));
        }
        Ok(())
    }

    /// Row-major index of lobe `(i, j)`: `j lobes_x + i`.
    pub fn lobe_index(&self, i: usize, j: usize) -> usize {
        j * self.lobes_x + i
    }

    /// The tile of lobe `lobe` (row-major lobe index), `tile x tile` values row-major.
    pub fn tile_of(&self, lobe: usize) -> Vec<f32> {
        let mut out = vec![0.0; self.tile_len()];
        self.copy_tile(lobe, &mut out);
        out
    }

    /// [`Self::tile_of`] into `out`.
    pub fn copy_tile(&self, lobe: usize, out: &mut [f32]) {
        let (i, j, t) = (lobe % self.lobes_x, lobe / self.lobes_x, self.tile);
        for (y, row) in out.chunks_exact_mut(t).enumerate() {
            let start = (j * t + y) * self.width() + i * t;
            row.copy_from_slice(&self.data[start..start + t]);
        }
    }

    /// Writes `tile` as the tile of lobe `lobe`.
    pub fn set_tile(&mut self, lobe: usize, tile: &[f32]) {
        let (i, j, t) = (lobe % self.lobes_x, lobe / self.lobes_x, self.tile);
        let width = self.width();
        for (y, row) in tile.chunks_exact(t).enumerate() {
            let start = (j * t + y) * width + i * t;
            self.data[start..start + t].copy_from_slice(row);
        }
    }

    /// The bandwidth of the lobe of `wi` in the direction `wo` (unit vectors of the tangent
    /// frame, `z >= 0`), in cycles per radian: the nearest texel, exactly as
    /// `data-schema/bandwidth-atlas.md` ("Looking up a bandwidth") tells a renderer to read it. The
    /// lobe's column comes from `wi`'s own azimuth, and `wo` is turned into the frame of that
    /// plane of incidence.
    pub fn lookup(&self, wi: DVec3, wo: DVec3) -> f32 {
        let phi_i = wi.y.atan2(wi.x);
        let column = |x: f64, n: usize| ((x * n as f64).floor().max(0.0) as usize).min(n - 1);
        let i = column(phi_i.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU, self.lobes_x);
        let j = column(1.0 - wi.z.clamp(0.0, 1.0), self.lobes_y);
        let (u, v) = LobeMap::new(self.tile).uv(to_incidence_frame(wo, phi_i));
        let (tx, ty) = (column(u, self.tile), column(v, self.tile));
        self.data[(j * self.tile + ty) * self.width() + i * self.tile + tx]
    }

    /// Whether every tile of every row equals the row's first tile, bit for bit: the atlas of an
    /// isotropic material (every MERL table), whose rows [`Self::rows`] hold all of it. Bits, not
    /// `==`, so that expanding the rows again gives back exactly these texels.
    pub fn is_isotropic(&self) -> bool {
        let (t, width) = (self.tile, self.width());
        if t == 0 || width == 0 {
            return true;
        }
        self.data.chunks_exact(width).all(|row| {
            let (first, rest) = row.split_at(t);
            rest.chunks_exact(t).all(|tile_row| tile_row.iter().zip(first).all(|(a, b)| a.to_bits() == b.to_bits()))
        })
    }

    /// The first column as an atlas one lobe wide (`lobes_x = 1`): row `j`'s first tile is lobe
    /// `j`, and `data` holds the tiles one after another, each row-major (the payload of asset
    /// kind 7, `bandwidth-rows`). For an isotropic atlas ([`Self::is_isotropic`]) these are its
    /// distinct tiles and [`Self::expand_rows`] gives the atlas back.
    pub fn rows(&self) -> Atlas {
        let (t, width) = (self.tile, self.width());
        let mut data = Vec::with_capacity(self.lobes_y * self.tile_len());
        if t > 0 {
            for row in self.data.chunks_exact(width) {
                data.extend_from_slice(&row[..t]);
            }
        }
        Atlas { lobes_x: 1, data, ..*self }
    }

    /// The atlas `lobes_x` lobes wide whose every column is this atlas of one column (each row's
    /// tile serves every column of its row): the inverse of [`Self::rows`] for an isotropic
    /// atlas. Checks the size before allocating: `lobes_x` may come from a file.
    pub fn expand_rows(&self, lobes_x: usize) -> Result<Atlas, Error> {
        self.check()?;
        if self.lobes_x != 1 {
            return Err(Error::Invalid(format!("expanding rows needs an atlas one lobe wide, not {}", self.lobes_x)));
        }
        let texels = lobes_x.checked_mul(self.data.len());
        if lobes_x == 0 || texels.is_none_or(|t| t > MAX_TEXELS) {
            return Err(Error::Invalid(format!(
                "an atlas of {} x {} lobes of {} x {} texels is empty or exceeds the limit of {MAX_TEXELS} texels",
                lobes_x, self.lobes_y, self.tile, self.tile
            )));
        }
        let t = self.tile;
        let mut data = Vec::with_capacity(lobes_x * self.data.len());
        for row in self.data.chunks_exact(t) {
            for _ in 0..lobes_x {
                data.extend_from_slice(row);
            }
        }
        Ok(Atlas { lobes_x, data, ..*self })
    }
}

/// What the build saw besides the atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildStats {
    /// Per lobe (row-major lobe index): the number of analysis pixels on the hemisphere at the
    /// grid's limit (finest wavelet level significant). Their bandwidth is a lower bound.
    pub nyquist_pixels: Vec<u32>,
    /// Texels that cover at least one such pixel.
    pub nyquist_texels: usize,
    /// Pixels whose value came from hole filling (no table data around the pair).
    pub filled_pixels: usize,
}

impl BuildStats {
    /// Lobes with at least one pixel at the grid's limit.
    pub fn nyquist_lobes(&self) -> usize {
        self.nyquist_pixels.iter().filter(|&&n| n > 0).count()
    }
}

/// The atlas of a table and what the build saw.
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasBuild {
    pub atlas: Atlas,
    pub stats: BuildStats,
    /// Per row of the incident grid: the lobe image's wavelet detail energy per level, finest
    /// first ([`crate::view::band_energy`]), for the per-view reductions of [`crate::view`].
    pub band_energy: Vec<Vec<f64>>,
}

/// Builds the bandwidth atlas of a MERL table. `progress` is called with the number of lobes
/// finished, from the worker threads, as they finish.
///
/// A MERL table is isotropic (it has no `phi_h` axis), so in the frame of its plane of
/// incidence the lobe of `wi` depends on `theta_i` alone: every lobe of a row of the incident
/// grid is the same image. Each row is analysed once, in parallel over rows, each row in
/// progress with a set of buffers from a pool, and its tile is written into every column of the
/// row.
pub fn build_atlas(
    table: &merl::MerlTable,
    config: &Config,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<AtlasBuild, Error> {
    config.check()?;
    Ok(build_atlas_with(&Analyser::new(config), &LuminanceTable::new(table), progress))
}

/// [`build_atlas`] of the table's luminance ([`LuminanceTable::new`]), which is all the atlas
/// reads (a caller that needs the table for nothing else can drop it first, 35 MB at MERL's
/// size), with the analyser of its configuration ([`Analyser::config`]), which does not depend
/// on the table (a caller can make it while the table is read).
pub fn build_atlas_with(
    analyser: &Analyser,
    luminance: &LuminanceTable,
    progress: &(dyn Fn(usize) + Sync),
) -> AtlasBuild {
    let config = analyser.config();
    let grid = IncidentGrid::new(config.lobes);
    let tile_len = config.tile * config.tile;

    let mut rows = vec![0.0f32; config.lobes * tile_len];
    // The buffers (about 100 MB at the default size) outlive the rayon jobs: `map_init` would
    // make a set per job, a few per thread, and the allocator hands such blocks back to the
    // system when they are freed, so every set would be fresh memory to fault in. The pool below
    // keeps the sets from row to row.
    let scratches = std::sync::Mutex::new(Vec::<Scratch>::new());
    let per_row: Vec<(u32, usize, usize, Vec<f64>)> = rows
        .par_chunks_mut(tile_len)
        .enumerate()
        .map(|(j, tile)| {
            // A set nobody uses, or a new one: a thread waiting inside a row's inner parallel
            // loops may start another row, which then needs a set of its own.
            let mut set = scratches.lock().expect("no panic while held").pop().unwrap_or_default();
            let scratch = &mut set;
            let filled = analyser.render(luminance, grid.theta_i(j), scratch);
            let peak = analyser.analyse_scratch(scratch);
            let band_energy = crate::view::band_energy_in(
                &scratch.image,
                config.analysis_size,
                config.relative_noise_floor * peak,
                scratch.estimator.transform(),
            );
            let (nyquist_texels, nyquist_pixels) = analyser.reduce(scratch, tile);
            progress(config.lobes);
            scratches.lock().expect("no panic while held").push(set);
            (nyquist_pixels as u32, nyquist_texels, filled, band_energy)
        })
        .collect();

    let side = config.lobes * config.tile;
    let mut atlas = Atlas {
        lobes_x: config.lobes,
        lobes_y: config.lobes,
        tile: config.tile,
        data: vec![0.0; side * side],
        parameterization: Parameterization::IncidencePlaneEquidistant,
        analysis_size: config.analysis_size,
        eps: config.eps,
        c: config.c,
    };
    let n_lobes = config.lobes * config.lobes;
    let mut stats = BuildStats { nyquist_pixels: vec![0; n_lobes], nyquist_texels: 0, filled_pixels: 0 };
    let mut band_energy = Vec::with_capacity(config.lobes);
    for (j, (tile, (nyquist_pixels, nyquist_texels, filled, energy))) in
        rows.chunks_exact(tile_len).zip(per_row).enumerate()
    {
        band_energy.push(energy);
        for i in 0..config.lobes {
            let lobe = atlas.lobe_index(i, j);
            atlas.set_tile(lobe, tile);
            stats.nyquist_pixels[lobe] = nyquist_pixels;
        }
        stats.nyquist_texels += config.lobes * nyquist_texels;
        stats.filled_pixels += config.lobes * filled;
    }
    AtlasBuild { atlas, stats, band_energy }
}
