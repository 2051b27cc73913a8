//! The bandwidth of one lobe image: the image continued into a periodic image, the `bandwidth`
//! crate's wavelet estimate on it, the conversion to cycles per radian through the lobe map's
//! Jacobian, and the conservative reduction to a tile.

use rayon::prelude::*;

use crate::atlas::Config;
use crate::lobe::{LuminanceTable, Pixels, fill_holes, render, render_fn};
use crate::param::LobeMap;

/// The per-pixel bandwidth of one lobe at the analysis resolution.
#[derive(Clone, Debug, PartialEq)]
pub struct LobeBandwidth {
    /// Pixels per side of the analysis grid.
    pub size: usize,
    /// The lobe image that was analysed: luminance in 1/sr, row-major, holes filled.
    pub image: Vec<f64>,
    /// Angular bandwidth in cycles per radian, row-major; 0 where the lobe is flat.
    pub cycles_per_radian: Vec<f64>,
    /// The finest significant wavelet level `j*` per pixel: 0 flat, 1 at the grid's Nyquist
    /// limit (the true bandwidth may be higher; see [`Analyser::nyquist_cycles_per_radian`]).
    pub level: Vec<u8>,
}

impl LobeBandwidth {
    /// Number of pixels on the hemisphere ([`LobeMap::inside`]) at the grid's limit
    /// (`level == 1`).
    pub fn nyquist_count(&self) -> usize {
        let map = LobeMap::new(self.size);
        (0..self.level.len()).filter(|&k| self.level[k] == 1 && map.inside(k % self.size, k / self.size)).count()
    }

    /// The tile of this lobe ([`TileReduction`]): `tile x tile` texels, row-major.
    pub fn tile(&self, tile: usize) -> Vec<f32> {
        let mut out = vec![0.0f32; tile * tile];
        TileReduction::new(self.size, tile).reduce(&self.cycles_per_radian, &self.level, &mut out);
        out
    }
}

/// The conservative reduction of a lobe's `size x size` bandwidth to a `tile x tile` tile.
/// Texel `(tx, ty)` covers the `m x m` pixels `[tx m, (tx + 1) m) x [ty m, (ty + 1) m)`
/// (`m = size / tile`). A texel that covers pixels of the hemisphere ([`LobeMap::inside`])
/// holds the largest bandwidth among them; the pixels below the horizon, which only continue
/// the image, never count. A texel that covers none (in the corners of the tile) holds the
/// value of the nearest texel that does, so that filtering across the horizon reads the rim's
/// value.
#[derive(Clone, Debug, PartialEq)]
pub struct TileReduction {
    size: usize,
    tile: usize,
    inside: Vec<bool>,
    /// Per texel: the texel whose value it holds (itself when it covers the hemisphere).
    source: Vec<u32>,
}

impl TileReduction {
    /// The reduction from `size` to `tile` per side; `tile` must divide `size`.
    pub fn new(size: usize, tile: usize) -> Self {
        assert!(tile > 0 && size.is_multiple_of(tile), "tile {tile} does not divide the analysis size {size}");
        let map = LobeMap::new(size);
        let inside = mirrored_rows(map, |x, y| map.inside(x, y));
        let m = size / tile;
        let covers = |t: usize| {
            let (tx, ty) = (t % tile, t / tile);
            (ty * m..(ty + 1) * m).any(|y| (tx * m..(tx + 1) * m).any(|x| inside[y * size + x]))
        };
        let covering: Vec<usize> = (0..tile * tile).filter(|&t| covers(t)).collect();
        let distance2 = |a: usize, b: usize| {
            let (dx, dy) = ((a % tile) as i64 - (b % tile) as i64, (a / tile) as i64 - (b / tile) as i64);
            dx * dx + dy * dy
        };
        let source = (0..tile * tile)
            .map(|t| {
                // Ties go to the first in row-major order: deterministic.
                let nearest = covering.iter().copied().min_by_key(|&c| (distance2(t, c), c));
                nearest.expect("the centre texel covers the hemisphere") as u32
            })
            .collect();
        Self { size, tile, inside, source }
    }

    /// The texel whose value texel `(tx, ty)` holds.
    pub fn source(&self, tx: usize, ty: usize) -> (usize, usize) {
        let s = self.source[ty * self.tile + tx] as usize;
        (s % self.tile, s / self.tile)
    }

    /// Reduces one lobe (`cycles_per_radian` and `level` per pixel, row-major) into `out`
    /// (`tile^2` texels). Returns the number of texels that cover a pixel of the hemisphere at
    /// the grid's limit (`level == 1`).
    pub fn reduce(&self, cycles_per_radian: &[f64], level: &[u8], out: &mut [f32]) -> usize {
        let n = self.size;
        let rows = |y: usize, row: &mut [f64]| row.copy_from_slice(&cycles_per_radian[y * n..(y + 1) * n]);
        self.reduce_rows(level, rows, out).0
    }

    /// [`Self::reduce`] of the bandwidths `row(y, values)` writes for each row `y`; returns the
    /// texels and the pixels of the hemisphere at the grid's limit.
    fn reduce_rows(&self, level: &[u8], mut row: impl FnMut(usize, &mut [f64]), out: &mut [f32]) -> (usize, usize) {
        let (n, t) = (self.size, self.tile);
        let m = n / t;
        let (mut nyquist_texels, mut nyquist_pixels) = (0, 0);
        // Per band of `m` rows, each column's largest value on the hemisphere and whether it
        // has a pixel at the limit, row after row (the values are finite and >= 0, so the
        // largest of those on the hemisphere is the largest of the values with the others read
        // as 0: the loop vectorizes), then each texel's `m` columns.
        let (mut best, mut nyquist, mut values) = (vec![0.0f64; n], vec![false; n], vec![0.0f64; n]);
        let larger = |a: f64, b: f64| if b > a { b } else { a };
        for ty in 0..t {
            best.fill(0.0);
            nyquist.fill(false);
            for y in ty * m..(ty + 1) * m {
                row(y, &mut values);
                let range = y * n..(y + 1) * n;
                let pixels = values.iter().zip(&level[range.clone()]).zip(&self.inside[range]);
                for ((b, q), ((&v, &l), &inside)) in best.iter_mut().zip(&mut nyquist).zip(pixels) {
                    *b = larger(*b, if inside { v } else { 0.0 });
                    let limit = inside & (l == 1);
                    *q |= limit;
                    nyquist_pixels += usize::from(limit);
                }
            }
            for (tx, (b, q)) in best.chunks_exact(m).zip(nyquist.chunks_exact(m)).enumerate() {
                out[ty * t + tx] = b.iter().fold(0.0, |a, &v| larger(a, v)) as f32;
                nyquist_texels += usize::from(q.contains(&true));
            }
        }
        for (k, &s) in self.source.iter().enumerate() {
            if s as usize != k {
                out[k] = out[s as usize];
            }
        }
        (nyquist_texels, nyquist_pixels)
    }
}

/// Reusable buffers for one thread: a lobe image, its periodic continuation's rows that hold
/// the image, hole filling, the estimated levels.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    pub image: Vec<f64>,
    pub extended: Vec<f64>,
    holes: Vec<(usize, f64)>,
    /// The estimator's buffers (and the transform's, which the band energies borrow).
    pub estimator: bandwidth::Workspace,
    pub level: Vec<u8>,
}

/// Everything about the analysis grid that does not depend on the lobe: what its pixels hold,
/// their Jacobian factors, the reduction to a tile.
#[derive(Debug)]
pub struct Analyser {
    config: Config,
    map: LobeMap,
    pixels: Pixels,
    pixels_per_radian: Vec<f64>,
    reduction: TileReduction,
    /// The periodic continuation's steps ([`extend_periodic`]).
    plan: Continuation,
}

impl Analyser {
    /// The analyser of `config`'s analysis grid. The configuration must be valid
    /// ([`Config::check`]).
    pub fn new(config: &Config) -> Self {
        let n = config.analysis_size;
        let map = LobeMap::new(n);
        let pixels_per_radian = mirrored_rows(map, |x, y| map.pixels_per_radian(x, y));
        let reduction = TileReduction::new(n, config.tile);
        let plan = Continuation::new(n);
        Self { config: *config, map, pixels: Pixels::new(map), pixels_per_radian, reduction, plan }
    }

    pub fn map(&self) -> LobeMap {
        self.map
    }

    /// The configuration it analyses with.
    pub fn config(&self) -> &Config {
        &self.config
    }

    pub fn reduction(&self) -> &TileReduction {
        &self.reduction
    }

    /// The conversion factor of pixel `(x, y)`, in pixels per radian
    /// ([`LobeMap::pixels_per_radian`]).
    pub fn pixels_per_radian(&self, x: usize, y: usize) -> f64 {
        self.pixels_per_radian[y * self.map.size + x]
    }

    /// The highest bandwidth the grid can report at pixel `(x, y)`, in cycles per radian: the
    /// finest level's `c / 2` cycles per pixel, converted.
    pub fn nyquist_cycles_per_radian(&self, x: usize, y: usize) -> f64 {
        self.config.c / 2.0 * self.pixels_per_radian(x, y)
    }

    /// The bandwidth of the lobe of incidence `theta_i` with its image, in the frame of the
    /// plane of incidence (a convenience that allocates; the atlas builder reuses its buffers).
    /// The table is isotropic, so this is the lobe of every `wi` of polar angle `theta_i`.
    pub fn analyse(&self, table: &LuminanceTable, theta_i: f64) -> LobeBandwidth {
        let mut scratch = Scratch::default();
        self.render(table, theta_i, &mut scratch);
        self.analyse_scratch(&mut scratch);
        self.finish(scratch)
    }

    /// The bandwidth of a lobe image given directly (`size^2` finite luminances, row-major), e.g.
    /// of an analytic BRDF from [`crate::lobe_image_from_fn`].
    pub fn analyse_image(&self, image: Vec<f64>) -> LobeBandwidth {
        assert_eq!(image.len(), self.pixels.len(), "a lobe image has size^2 pixels");
        let mut scratch = Scratch { image, ..Scratch::default() };
        self.analyse_scratch(&mut scratch);
        self.finish(scratch)
    }

    fn finish(&self, scratch: Scratch) -> LobeBandwidth {
        let n = self.map.size;
        let frequency_of = self.level_frequencies();
        let mut cycles_per_radian = vec![0.0; n * n];
        for (y, row) in cycles_per_radian.chunks_exact_mut(n).enumerate() {
            self.cycles_per_radian_row(&frequency_of, &scratch.level, y, row);
        }
        LobeBandwidth { size: n, image: scratch.image, cycles_per_radian, level: scratch.level }
    }

    /// The frequency each level `j` reads (index `j`, 0: no significant level), cycles per
    /// pixel.
    fn level_frequencies(&self) -> Vec<f64> {
        (0..=analysis_levels(self.map.size) as u8).map(|j| bandwidth::level_frequency(self.config.c, j)).collect()
    }

    /// Row `y` of the bandwidths of `level` (the estimated levels per pixel), cycles per radian:
    /// the frequency each level reads ([`Self::level_frequencies`]), through the lobe map's
    /// Jacobian.
    fn cycles_per_radian_row(&self, frequency_of: &[f64], level: &[u8], y: usize, row: &mut [f64]) {
        let n = self.map.size;
        let pixels = level[y * n..(y + 1) * n].iter().zip(&self.pixels_per_radian[y * n..(y + 1) * n]);
        for (out, (&j, &s)) in row.iter_mut().zip(pixels) {
            *out = frequency_of[usize::from(j)] * s;
        }
    }

    /// The tile of `scratch`'s analysed lobe into `out` ([`TileReduction::reduce`]), the
    /// bandwidths made row by row as it reads them; returns the texels and the pixels of the
    /// hemisphere at the grid's limit.
    pub(crate) fn reduce(&self, scratch: &Scratch, out: &mut [f32]) -> (usize, usize) {
        let frequency_of = self.level_frequencies();
        let row = |y: usize, row: &mut [f64]| self.cycles_per_radian_row(&frequency_of, &scratch.level, y, row);
        self.reduction.reduce_rows(&scratch.level, row, out)
    }

    /// The lobe image of any BRDF slice `f(wo)` on this analyser's grid, holes filled: what
    /// [`crate::lobe_image_from_fn`] returns, from the pixels' samples computed once.
    pub fn lobe_image(&self, f: impl Fn(glam::DVec3) -> Option<f64>) -> Vec<f64> {
        let mut image = vec![0.0; self.pixels.len()];
        render_fn(&self.pixels, f, &mut image);
        fill_holes(self.map.size, &mut image, &mut Vec::new());
        image
    }

    /// Renders the lobe of incidence `theta_i` (in the frame of the plane of incidence: `wi` at
    /// azimuth 0) into `scratch.image` and fills its holes; returns how many pixels were filled.
    pub(crate) fn render(&self, table: &LuminanceTable, theta_i: f64, scratch: &mut Scratch) -> usize {
        scratch.image.resize(self.pixels.len(), 0.0);
        render(table, merl::spherical_dir(theta_i, 0.0), &self.pixels, &mut scratch.image);
        // Every lookup of a table without holes has a value: no pixel to look for.
        if table.is_complete() { 0 } else { fill_holes(self.map.size, &mut scratch.image, &mut scratch.holes) }
    }

    /// Analyses `scratch.image` into `scratch.level` (the estimated level per pixel, which
    /// [`Self::reduce`] converts): the periodic continuation
    /// ([`extend_periodic`]), the estimate with [`analysis_levels`] levels and the noise floor
    /// scaled to the lobe's peak, the estimate of the image's own pixels converted to cycles per
    /// radian. Returns the peak ([`peak`]), which the band energy's noise floor scales with too.
    pub(crate) fn analyse_scratch(&self, scratch: &mut Scratch) -> f64 {
        let n = self.map.size;
        let Scratch { image, extended: ext, estimator, level, .. } = scratch;
        let peak = peak(image);

        // The rows of the continuation that hold the image, continued; those below are made
        // from them as the transform reads them, never stored.
        self.plan.extend_rows_into(image, ext);

        let config = bandwidth::Config {
            eps: self.config.eps,
            c: self.config.c,
            noise_floor: self.config.relative_noise_floor * peak,
            levels: Some(analysis_levels(n)),
            ..bandwidth::Config::default()
        };
        let extended = Continued { plan: &self.plan, top: ext };
        // Only the image's own pixels are kept: the estimate of the top-left quarter alone.
        let levels = estimator.levels_top_left(&extended, &config, n, n).expect("the configuration was checked");

        level.clear();
        level.extend_from_slice(levels);
        peak
    }
}

/// `f(x, y)` at every pixel of `map`, row-major, for an `f` of the distance from the centre (the
/// same on mirrored rows): computed in parallel over rows, and where the map's rows are mirror
/// images of each other ([`LobeMap::rows_mirrored`]) for the top half alone, each row of the
/// bottom half a copy of its mirror row.
fn mirrored_rows<T: Copy + Default + Send + Sync>(map: LobeMap, f: impl Fn(usize, usize) -> T + Sync) -> Vec<T> {
    let n = map.size;
    let mut values = vec![T::default(); n * n];
    let computed = if map.rows_mirrored() { n / 2 } else { n };
    let (top, bottom) = values.split_at_mut(computed * n);
    top.par_chunks_exact_mut(n).enumerate().for_each(|(y, row)| {
        for (x, v) in row.iter_mut().enumerate() {
            *v = f(x, y);
        }
    });
    bottom.par_chunks_exact_mut(n).zip(top.par_chunks_exact(n).rev()).for_each(|(row, top)| row.copy_from_slice(top));
    values
}

/// The largest magnitude of a lobe image: the scale of its noise floor (the estimate's and the
/// band energies', [`Config::relative_noise_floor`]).
pub(crate) fn peak(image: &[f64]) -> f64 {
    image.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The number of wavelet levels a lobe image of side `n` is analysed with: `log2(n) - 1`, the
/// finest (level 1, half a pixel's period... up to the level whose wavelets have the scale of
/// the hemisphere's radius, `n / 2` pixels (crate docs, "Levels").
pub fn analysis_levels(n: usize) -> usize {
    n.trailing_zeros() as usize - 1
}

/// The periodic continuation of an `n x n` lobe image (row-major) that the analysis reads: a
/// `2n x 2n` image, the lobe image in its top-left quarter, periodic, and continuous with its
/// slope across every border of the lobe image (crate docs, "Boundaries"): each row, then
/// each column of the result, is continued by `extend_line`.
pub fn extend_periodic(image: &[f64], n: usize) -> dwt::Image {
    let plan = Continuation::new(n);
    let mut top = Vec::new();
    plan.extend_rows_into(image, &mut top);
    dwt::Image::from_rows(&Continued { plan: &plan, top: &top })
}

/// The `2n x 2n` tiling of an `n x n` image by its mirror images (to the right, below, and
/// both): periodic and continuous, with a kink wherever the image has a slope at its border.
/// The layer selection's band energy reads it ([`crate::view::band_energy`]): its detail
/// energy per level is that of four copies of the image, where [`extend_periodic`]'s
/// continuation adds ramps of its own that carry the slope across the borders and would count
/// as lobe energy (at grazing incidence it moves Phong n = 64 and 256 up a layer).
pub fn mirror_tiling(image: &[f64], n: usize) -> dwt::Image {
    dwt::Image::from_rows(&MirrorTiling { image, n })
}

/// [`mirror_tiling`] given row by row ([`dwt::Rows`]), never stored: row `y` of the `2n x 2n`
/// tiling is row `y` (or `2n - 1 - y` below the image) followed by its mirror image.
pub(crate) struct MirrorTiling<'a> {
    pub image: &'a [f64],
    pub n: usize,
}

impl dwt::Rows for MirrorTiling<'_> {
    fn width(&self) -> usize {
        2 * self.n
    }

    fn height(&self) -> usize {
        2 * self.n
    }

    fn stored_row(&self, _: usize) -> Option<&[f64]> {
        None
    }

    fn make_row(&self, r: usize, buffer: &mut [f64]) {
        let n = self.n;
        let line = &self.image[(if r < n { r } else { 2 * n - 1 - r }) * n..][..n];
        let (left, right) = buffer.split_at_mut(n);
        left.copy_from_slice(line);
        for (o, &v) in right.iter_mut().zip(line.iter().rev()) {
            *o = v;
        }
    }
}

/// The periodic continuation of a lobe image as the transform reads it ([`dwt::Rows`]): the
/// image's rows continued, stored (`top`, `n` rows of `2 n`), and the rows below made from them
/// on demand, so that the `2n x 2n` image is never stored.
struct Continued<'a> {
    plan: &'a Continuation,
    top: &'a [f64],
}

impl dwt::Rows for Continued<'_> {
    fn width(&self) -> usize {
        2 * self.plan.n()
    }

    fn height(&self) -> usize {
        2 * self.plan.n()
    }

    fn stored_row(&self, r: usize) -> Option<&[f64]> {
        let (n, e) = (self.plan.n(), 2 * self.plan.n());
        (r < n).then(|| &self.top[r * e..(r + 1) * e])
    }

    fn make_row(&self, r: usize, buffer: &mut [f64]) {
        self.plan.continue_row(self.top, r - self.plan.n(), buffer);
    }
}

/// How sample `n + j` of a line of `2 n` is continued ([`extend_line`]).
#[derive(Clone, Copy, Debug)]
enum Step {
    /// The plain mirror image, `v(n - 1 - j)`.
    Mirror,
    /// From the end at `end`, `k` samples out, `inward` stepping towards the data: the odd
    /// reflection blended into the mirror image by `blend` (`cos^2(pi k / n)`), plus, within the
    /// continuation's reach, the three-point rule's `share`.
    Continue { end: usize, inward: isize, k: usize, blend: f64, share: Option<f64> },
}

/// The steps of [`extend_line`] for lines of `2 n` samples, with their weights computed once.
#[derive(Debug)]
pub(crate) struct Continuation {
    steps: Vec<Step>,
}

impl Continuation {
    pub(crate) fn new(n: usize) -> Self {
        let reach = crate::param::CONTINUATION_REACH;
        let step = |end: usize, inward: isize, k: usize| Step::Continue {
            end,
            inward,
            k,
            blend: (std::f64::consts::PI * k as f64 / n as f64).cos().powi(2),
            share: (k <= reach).then(|| crate::param::three_point_share(k as f64 / reach as f64)),
        };
        let steps = (0..n)
            .map(|j| {
                // Samples past the last value, and before the first (the period wraps).
                let (right, left) = (j + 1, n - j);
                if right < n / 2 {
                    step(n - 1, -1, right)
                } else if left < n / 2 {
                    step(0, 1, left)
                } else {
                    Step::Mirror
                }
            })
            .collect();
        Self { steps }
    }

    /// The number of values of the lines it continues (to `2 n`).
    fn n(&self) -> usize {
        self.steps.len()
    }

    /// The `n` rows of `image` (`n x n`, row-major), each continued by [`Self::extend_line`]:
    /// `out` becomes `n` rows of `2 n` values.
    fn extend_rows_into(&self, image: &[f64], out: &mut Vec<f64>) {
        let (n, e) = (self.n(), 2 * self.n());
        // Every value is written below: only a buffer that grows is filled first.
        out.truncate(n * e);
        out.resize(n * e, 0.0);
        for (row, line) in out.chunks_exact_mut(e).zip(image.chunks_exact(n)) {
            row[..n].copy_from_slice(line);
            self.extend_line(row);
        }
    }

    /// Row `n + j` of the continuation, from its first `n` rows `top` (each `2 n` values,
    /// continued): every column continued as [`Self::extend_line`] continues a line, all columns
    /// of the row at once (contiguous rows, so that it vectorizes).
    fn continue_row(&self, top: &[f64], j: usize, out: &mut [f64]) {
        let (n, e) = (self.n(), 2 * self.n());
        let row = |i: usize| &top[i * e..(i + 1) * e];
        let mirror = row(n - 1 - j);
        match self.steps[j] {
            Step::Mirror => out.copy_from_slice(mirror),
            Step::Continue { end, inward, k, blend, share } => {
                let at = |i: usize| row((end as isize + inward * i as isize) as usize);
                let (a0, ak) = (at(0), at(k));
                match share {
                    None => {
                        for (((o, &m), &v0), &vk) in out.iter_mut().zip(mirror).zip(a0).zip(ak) {
                            let odd = 2.0 * v0 - vk;
                            *o = m + blend * (odd - m);
                        }
                    }
                    Some(share) => {
                        let [c1, c2, c3] = crate::param::CONTINUATION_WEIGHTS;
                        let (a2k, a3k) = (at(2 * k), at(3 * k));
                        for (x, o) in out.iter_mut().enumerate() {
                            let (m, v0, vk) = (mirror[x], a0[x], ak[x]);
                            let odd = 2.0 * v0 - vk;
                            let value = m + blend * (odd - m);
                            let three_point = c1 * vk + c2 * a2k[x] + c3 * a3k[x];
                            *o = value + share * (three_point - odd);
                        }
                    }
                }
            }
        }
    }

    /// [`extend_line`] with this plan's weights.
    fn extend_line(&self, line: &mut [f64]) {
        let n = line.len() / 2;
        let (data, rest) = line.split_at_mut(n);
        let [c1, c2, c3] = crate::param::CONTINUATION_WEIGHTS;
        for (j, (out, step)) in rest.iter_mut().zip(&self.steps).enumerate() {
            let mirror = data[n - 1 - j];
            *out = match *step {
                Step::Mirror => mirror,
                Step::Continue { end, inward, k, blend, share } => {
                    let at = |i: usize| data[(end as isize + inward * i as isize) as usize];
                    let odd = 2.0 * at(0) - at(k);
                    let value = mirror + blend * (odd - mirror);
                    match share {
                        None => value,
                        Some(share) => {
                            let three_point = c1 * at(k) + c2 * at(2 * k) + c3 * at(3 * k);
                            value + share * (three_point - odd)
                        }
                    }
                }
            };
        }
    }
}

/// Continues the `n` values in the first half of `line` (length `2 n`) over its second
/// half so that the whole is one period of a smooth function (`n >= 4 CONTINUATION_REACH`). Past each end of the data, the
/// value `k` samples out is, nearest the end, the three-point rule of the continuation below
/// the horizon ([`crate::param::CONTINUATION_WEIGHTS`]), `6 v(-k) - 8 v(-2k) + 3 v(-3k)` of the
/// values `k`, `2k` and `3k` samples in, which meets the data with its value, slope and
/// curvature, so that the lobe's flank where the square's edge touches the horizon (at `phi =
/// 0, 90, 180, 270` degrees) reads as no edge. Like the corners ([`crate::param::LobeMap::sample`])
/// it blends into the odd reflection `2 v(0) - v(-k)` (weight `1 - 3 s^2 + 2 s^3`,
/// `s = k / `[`crate::param::CONTINUATION_REACH`]), which keeps the slope, and that blends into the plain mirror image by
/// the middle of the extension (weight `cos^2(pi k / n)`, zero from `k = n / 2`), where the two
/// ends' continuations would disagree.
#[cfg(test)]
fn extend_line(line: &mut [f64]) {
    Continuation::new(line.len() / 2).extend_line(line);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_analyser_reads_the_documented_continuation() {
        // The analyser's own continuation equals extend_periodic, so the documented function is
        // the one that runs; it holds the image in its top-left quarter.
        let config = Config { analysis_size: 16, tile: 4, ..Config::default() };
        let analyser = Analyser::new(&config);
        let image: Vec<f64> = (0..256).map(|k| ((k * 37 % 101) as f64).sin()).collect();
        let mut scratch = Scratch { image: image.clone(), ..Scratch::default() };
        analyser.analyse_scratch(&mut scratch);
        let direct = bandwidth::local_bandwidth(
            &extend_periodic(&image, 16),
            &bandwidth::Config { levels: Some(3), noise_floor: 1e-6, ..bandwidth::Config::default() },
        )
        .unwrap();
        for y in 0..16 {
            for x in 0..16 {
                assert_eq!(scratch.level[y * 16 + x], direct.level()[y * 32 + x]);
            }
        }
        let ext = extend_periodic(&image, 16);
        assert!((0..16).all(|y| (0..16).all(|x| ext.get(x, y) == image[y * 16 + x])));
    }

    #[test]
    fn the_reductions_hemisphere_is_the_maps_at_any_size() {
        // Mirrored from the top half at a power-of-two size, computed row by row at the others
        // (odd ones included, which have a middle row).
        for (size, tile) in [(16, 4), (24, 8), (15, 5), (1, 1)] {
            let (map, reduction) = (LobeMap::new(size), TileReduction::new(size, tile));
            for (y, x) in (0..size).flat_map(|y| (0..size).map(move |x| (y, x))) {
                assert_eq!(reduction.inside[y * size + x], map.inside(x, y), "{size}: {x} {y}");
            }
        }
    }

    #[test]
    fn the_analysers_pixels_render_what_the_map_samples() {
        // The compact pixels (runs of directions, the continued pixels' weighted terms) give
        // lobe_image_from_fn's image bit for bit, holes (None, then filled) included: the top
        // half sampled and the bottom half mirrored from it (f tells the mirror images apart),
        // at the smallest size, the default and one between; the Jacobian factors and the
        // hemisphere's pixels are the map's own.
        for size in [16, 64, 1024] {
            let config = Config { analysis_size: size, tile: 8, ..Config::default() };
            let analyser = Analyser::new(&config);
            let f = |w: glam::DVec3| (w.x > -0.9).then(|| (3.0 * w.x + w.y).sin() + w.z.max(0.0).powi(7) + 2.0);
            let compact = analyser.lobe_image(f);
            let direct = crate::lobe_image_from_fn(analyser.map(), f);
            assert!(compact.iter().zip(&direct).all(|(a, b)| a.to_bits() == b.to_bits()), "{size}");
            let map = analyser.map();
            for (y, x) in (0..size).flat_map(|y| (0..size).map(move |x| (y, x))) {
                let factor = analyser.pixels_per_radian(x, y);
                assert_eq!(factor.to_bits(), map.pixels_per_radian(x, y).to_bits(), "{size}: {x} {y}");
                assert_eq!(analyser.reduction.inside[y * size + x], map.inside(x, y), "{size}: {x} {y}");
            }
        }
    }

    #[test]
    fn the_continuation_of_all_columns_at_once_is_extend_line_on_each_column() {
        // extend_periodic (Continuation::continue_row) continues the rows below the image a
        // whole row at a time; that must be, bit for bit, extend_line on every column after
        // every row (the definition).
        let n = 64;
        let image: Vec<f64> = (0..n * n).map(|k| ((k * 37 % 101) as f64).sin() * (k as f64 * 1e-3).exp()).collect();
        let e = 2 * n;
        let mut expect = vec![0.0; e * e];
        for (row, line) in expect.chunks_exact_mut(e).zip(image.chunks_exact(n)) {
            row[..n].copy_from_slice(line);
            extend_line(row);
        }
        let mut column = vec![0.0; e];
        for x in 0..e {
            for (y, v) in column[..n].iter_mut().enumerate() {
                *v = expect[y * e + x];
            }
            extend_line(&mut column);
            for (y, v) in column.iter().enumerate().skip(n) {
                expect[y * e + x] = *v;
            }
        }
        let got = extend_periodic(&image, n).into_data();
        assert!(got.iter().zip(&expect).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    /// The largest finest-level D4 detail of a periodic line: of all its coefficients, and of
    /// those whose support (samples `2k` to `2k + 3`) lies within the first `inside` samples.
    fn finest_details(line: &[f64], inside: usize) -> (f64, f64) {
        let (_, detail) = dwt::dwt(line, dwt::Wavelet::D4).unwrap();
        let all = detail.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let own =
            detail.iter().enumerate().filter(|(k, _)| 2 * k + 3 < inside).fold(0.0f64, |m, (_, d)| m.max(d.abs()));
        (all, own)
    }

    #[test]
    fn the_continuation_carries_slope_and_curvature_across_both_borders() {
        // A lobe of width 16 samples whose inflection, where its flank is steepest, lies on
        // either border of the 64 samples.
        let (n, width) = (64, 16.0);
        let inflection = width / std::f64::consts::SQRT_2;
        for centre in [n as f64 - 0.5 - inflection, inflection - 0.5] {
            let data: Vec<f64> = (0..n).map(|i| (-((i as f64 - centre) / width).powi(2)).exp()).collect();
            let mut line = data.clone();
            line.resize(2 * n, 0.0);
            extend_line(&mut line);
            assert_eq!(line[..n], data[..]);
            // Nearest each border, the three-point rule: the first value past it is
            // 6 v(-1) - 8 v(-2) + 3 v(-3), blended (weight 1 - 3 s^2 + 2 s^3, s = 1/3) with the
            // odd reflection 2 v(0) - v(-1), itself blended (cos^2(pi / n)) with the mirror v(0).
            let s = 1.0 / crate::param::CONTINUATION_REACH as f64;
            let w = 1.0 - 3.0 * s * s + 2.0 * s * s * s;
            let m = (std::f64::consts::PI / n as f64).cos().powi(2);
            let expect = |v: &dyn Fn(usize) -> f64| {
                let (three, odd) = (6.0 * v(1) - 8.0 * v(2) + 3.0 * v(3), 2.0 * v(0) - v(1));
                v(0) + m * (odd - v(0)) + w * (three - odd)
            };
            let right = expect(&|i| data[n - 1 - i]);
            assert!((line[n] - right).abs() < 1e-12, "{} {right}", line[n]);
            let left = expect(&|i| data[i]);
            assert!((line[2 * n - 1] - left).abs() < 1e-12, "{} {left}", line[2 * n - 1]);
            // The finest wavelets, which read an edge, see nothing on the period, borders and
            // blends included, that the data's own finest details do not match within a factor
            // 2 (measured: 1.9 and 1.4); the plain mirror image, which the continuation
            // replaces, has a kink at each border that reads 5.4 times the data's own.
            let (all, own) = finest_details(&line, n);
            println!("centre {centre}: finest detail {all:.3e} on the period, {own:.3e} of the data's own");
            assert!(all <= 2.0 * own, "{all} against {own} inside");
            let mirror: Vec<f64> = data.iter().chain(data.iter().rev()).copied().collect();
            let (kink, _) = finest_details(&mirror, n);
            println!("centre {centre}: mirror {kink:.3e}");
            assert!(kink > 4.0 * own, "{kink} against {own}");
        }
    }
}
