//! The wavelet estimator: per level, the largest detail coefficient whose support covers a pixel
//! (a separable sliding maximum over the coefficient grid), then the finest significant level
//! of eq. 7 per pixel.

use dwt::{Image, Wavelet, max_levels2};
use rayon::prelude::*;

use crate::Error;

/// `c` in `f = c 2^-j*` (cycles per pixel), calibrated on pure sinusoids (crate docs,
/// "Calibration"): `2^-2.5`.
pub const DEFAULT_C: f64 = 0.176_776_695_296_636_9;

/// How the estimator reads an image. [`Config::default`] is the paper's setting with the
/// calibrated constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// The relative threshold of eq. 7: level `j*` is the first (finest first) at which the sum
    /// of `lambda_1 .. lambda_j*` reaches `eps` times the largest `lambda_j` of the pixel. 0.01
    /// as in both papers.
    pub eps: f64,
    /// Amplitude, in the units of the image, below which a detail counts as zero: a level-`j`
    /// coefficient is dropped when its magnitude is below `noise_floor * 2^j`, the magnitude a
    /// pattern of that amplitude produces at level `j`. 1e-6 by default, for images of O(1)
    /// values such as [`crate::log1p_luminance`]; scale it with the data.
    pub noise_floor: f64,
    /// The mother wavelet's bandwidth constant: `f = c 2^-j*` cycles per pixel.
    pub c: f64,
    /// The wavelet; D4 (PyWavelets' `db2`) as in the papers.
    pub wavelet: Wavelet,
    /// Number of levels `J`; `None` for as many as the (padded or extended) image allows (crate
    /// docs, "Sizes").
    pub levels: Option<usize>,
    /// How eq. 7 compares the levels: as the paper does, or level-normalized.
    pub reading: Reading,
}

/// How eq. 7 compares the levels' coefficients (crate docs, "Readings").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Reading {
    /// Appendix A as printed: `lambda_j`, the largest coefficient of level `j` covering the
    /// pixel, against `eps` times the largest `lambda` of any level. An orthonormal transform
    /// answers a pattern of amplitude `a` with coefficients of about `a 2^j` at level `j`, so a
    /// strong edge's coarse coefficients set the bar and fine detail next to it reads as nothing.
    Paper,
    /// `lambda_j 2^-j`: every level in units of the amplitude of the pattern it answers (the
    /// scaling the noise floor already uses), so that detail of 1% of the local contrast counts
    /// whatever its scale.
    LevelNormalized,
}

impl Reading {
    /// The name on command lines and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Reading::Paper => "paper",
            Reading::LevelNormalized => "level-normalized",
        }
    }

    pub fn from_name(name: &str) -> Option<Reading> {
        [Reading::Paper, Reading::LevelNormalized].into_iter().find(|r| r.name() == name)
    }
}

impl std::str::FromStr for Reading {
    type Err = String;

    /// The name of [`Reading::name`], for command lines.
    fn from_str(text: &str) -> Result<Reading, String> {
        Reading::from_name(text.trim()).ok_or_else(|| format!("{text:?}: the readings are paper and level-normalized"))
    }
}

impl Default for Config {
    fn default() -> Self {
        Self { eps: 0.01, noise_floor: 1e-6, c: DEFAULT_C, wavelet: Wavelet::D4, levels: None, reading: Reading::Paper }
    }
}

impl Config {
    /// Every public entry point calls this first.
    pub(crate) fn check(&self) -> Result<(), Error> {
        if !(self.eps > 0.0 && self.eps <= 1.0) {
            return Err(Error::Config(format!("eps {} is not in (0, 1]", self.eps)));
        }
        if !(self.noise_floor >= 0.0 && self.noise_floor.is_finite()) {
            return Err(Error::Config(format!("noise floor {} is negative or not finite", self.noise_floor)));
        }
        if !(self.c > 0.0 && self.c.is_finite()) {
            return Err(Error::Config(format!("c {} is not positive and finite", self.c)));
        }
        match self.levels {
            Some(0) => Err(Error::Config("zero levels requested: at least one level is needed".to_owned())),
            Some(l) if l > 30 => Err(Error::Config(format!("{l} levels requested: at most 30 are supported"))),
            _ => Ok(()),
        }
    }
}

/// Per-pixel local bandwidth of an image: the finest significant level `j*` and the frequency
/// `c 2^-j*` in cycles per pixel, row-major like the image it was computed from.
#[derive(Clone, Debug, PartialEq)]
pub struct BandwidthMap {
    width: usize,
    height: usize,
    levels: usize,
    c: f64,
    level: Vec<u8>,
    frequency: Vec<f64>,
}

impl BandwidthMap {
    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// The number of levels `J` the estimate used.
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// Frequencies in cycles per pixel, row-major; 0 where no level is significant.
    pub fn frequency(&self) -> &[f64] {
        &self.frequency
    }

    /// The frequency at column `x`, row `y`, in cycles per pixel. Panics outside the map.
    pub fn frequency_at(&self, x: usize, y: usize) -> f64 {
        self.frequency[self.index(x, y)]
    }

    /// The finest significant level `j*` of every pixel, row-major; 0 where none is.
    pub fn level(&self) -> &[u8] {
        &self.level
    }

    /// `j*` at column `x`, row `y`: `None` where no level is significant (a flat neighbourhood).
    pub fn level_at(&self, x: usize, y: usize) -> Option<usize> {
        match self.level[self.index(x, y)] {
            0 => None,
            j => Some(j as usize),
        }
    }

    /// Whether the finest level is significant at `(x, y)`: the content may reach the grid's
    /// Nyquist limit, so the true bandwidth can be anything from [`Self::max_frequency`] up.
    pub fn at_nyquist(&self, x: usize, y: usize) -> bool {
        self.level[self.index(x, y)] == 1
    }

    /// Number of pixels at the Nyquist limit ([`Self::at_nyquist`]).
    pub fn nyquist_count(&self) -> usize {
        self.level.iter().filter(|&&j| j == 1).count()
    }

    /// The highest frequency the map can hold, `c / 2` cycles per pixel (level 1).
    pub fn max_frequency(&self) -> f64 {
        self.c / 2.0
    }

    /// The frequencies as an image, e.g. to analyse them further.
    pub fn to_image(&self) -> Image {
        Image::new(self.width, self.height, self.frequency.clone()).expect("sizes match")
    }

    fn index(&self, x: usize, y: usize) -> usize {
        assert!(x < self.width && y < self.height, "({x}, {y}) is outside a {}x{} map", self.width, self.height);
        y * self.width + x
    }
}

/// The local bandwidth of `image` taken as one period of a periodic image (the transform's
/// periodization): its right edge meets its left edge and its bottom its top. Both sides must
/// divide by `2^J` (crate docs, "Sizes").
pub fn local_bandwidth(image: &Image, config: &Config) -> Result<BandwidthMap, Error> {
    let mut workspace = Workspace::default();
    workspace.local_bandwidth(image, config)?;
    Ok(workspace.map.take().expect("just estimated"))
}

/// Buffers for repeated estimates of images of one size (the lobe images of a BRDF's atlas, one
/// per row): the transform's ([`dwt::Workspace2`]), each level's maxima and the map stay
/// allocated between calls, so that an estimate allocates (and touches fresh memory for) almost
/// nothing. The results are [`local_bandwidth`]'s, bit for bit.
#[derive(Debug, Default)]
pub struct Workspace {
    transform: dwt::Workspace2,
    levels: Vec<LevelRows>,
    map: Option<BandwidthMap>,
}

impl Workspace {
    /// [`local_bandwidth`] in this workspace; the map is borrowed until the next call.
    pub fn local_bandwidth(&mut self, image: &Image, config: &Config) -> Result<&BandwidthMap, Error> {
        config.check()?;
        let (w, h) = (image.width(), image.height());
        let levels = periodic_levels("image", w, h, config)?;
        self.run(image, levels, w, h, config, true)
    }

    /// The finest significant level `j*` ([`BandwidthMap::level`]) of the top-left `width x height`
    /// pixels only, row-major, `width` per row: each reads what it reads in the whole map, bit
    /// for bit, at a fraction of the cost when the image is an extension of the part the caller
    /// needs (a lobe image continued into a periodic one, whose rows the caller may make as they
    /// are read: [`dwt::Rows`]; an [`Image`] is one). The frequency of level `j` is
    /// [`level_frequency`]; it is not stored.
    pub fn levels_top_left(
        &mut self,
        image: &dyn dwt::Rows,
        config: &Config,
        width: usize,
        height: usize,
    ) -> Result<&[u8], Error> {
        config.check()?;
        let (w, h) = (image.width(), image.height());
        if width > w || height > h {
            return Err(Error::Size(format!("a {width}x{height} corner of a {w}x{h} image")));
        }
        let levels = periodic_levels("image", w, h, config)?;
        Ok(&self.run(image, levels, width, height, config, false)?.level)
    }

    /// The transform's buffers, for a caller that runs other transforms of the same size between
    /// estimates (they are overwritten by the next estimate).
    pub fn transform(&mut self) -> &mut dwt::Workspace2 {
        &mut self.transform
    }
}

/// The local bandwidth of an image of finite extent, zero outside (001 section 2.3, an area light
/// or a texture): zero padding to at least twice the size, the estimate, then the crop back to
/// the image. Any size works (crate docs, "Sizes").
pub fn local_bandwidth_zero_padded(image: &Image, config: &Config) -> Result<BandwidthMap, Error> {
    config.check()?;
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 {
        return Err(Error::Size(format!("image is empty ({w}x{h})")));
    }
    check_finite("image", image.data())?;
    // By default the deepest level whose grid is at most 2 coefficients on the shorter padded side.
    let levels = config.levels.unwrap_or_else(|| (usize::BITS - 1 - (2 * w.min(h)).leading_zeros()) as usize);
    // Deeper levels would only analyse more zeros (and allocate them).
    if 1usize << levels > (2 * w.max(h)).next_power_of_two() {
        return Err(Error::Config(format!(
            "{levels} levels requested for a {w}x{h} image: at most {} fit its padded size",
            (2 * w.max(h)).next_power_of_two().trailing_zeros()
        )));
    }
    let pad = |n: usize| (2 * n).div_ceil(1 << levels) << levels;
    let (pw, ph) = (pad(w), pad(h));
    let mut padded = vec![0.0; pw * ph];
    for (dst, src) in padded.chunks_exact_mut(pw).zip(image.rows()) {
        dst[..w].copy_from_slice(src);
    }
    let padded = Image::new(pw, ph, padded).expect("sizes match");
    estimate(&padded, levels, w, h, config)
}

/// The number of levels for a periodic image: the requested number, or the most the size allows
/// provided the coarsest grid is at most 3 coefficients on the shorter side (a level-`J` D4
/// support, `3 2^J - 2` pixels, then spans the side).
pub(crate) fn periodic_levels(what: &str, w: usize, h: usize, config: &Config) -> Result<usize, Error> {
    if w < 2 || h < 2 {
        return Err(Error::Size(format!("{what} is {w}x{h}: both sides need at least 2 pixels")));
    }
    if let Some(levels) = config.levels {
        return Ok(levels);
    }
    let levels = max_levels2(w, h);
    let coarsest = w.min(h) >> levels;
    if coarsest > 3 {
        let limiting = if w.trailing_zeros() <= h.trailing_zeros() { ("width", w) } else { ("height", h) };
        return Err(Error::Size(format!(
            "{what} is {w}x{h}: the {} {} allows {levels} level(s) only, which leave {coarsest} coefficients on \
             the shorter side at the coarsest level (at most 3 allowed); pad or resample it, or set the levels",
            limiting.0, limiting.1
        )));
    }
    Ok(levels)
}

pub(crate) fn check_finite(what: &'static str, data: &[f64]) -> Result<(), Error> {
    match data.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(Error::NonFinite { what, index }),
        None => Ok(()),
    }
}

/// The coefficients of one level that cover each pixel of one axis: pixel `x` is covered by the
/// `count[x]` coefficients `first[x], first[x] + 1, ...` (modulo the grid size `m`).
#[derive(Debug)]
struct Cover {
    first: Vec<u32>,
    count: Vec<u32>,
}

impl Cover {
    /// Pixels `0..out` of an axis of `n` pixels (`n` divisible by `2^level`). Coefficient `k`
    /// covers the pixels of `Wavelet::support(level, k)`, wrapped into `0..n`: pixel `x` is
    /// covered by the `k` with `start_k <= x + t n < start_k + len` for some integer `t`, and
    /// `t` only shifts `k` by multiples of `m = n / 2^level`.
    fn new(wavelet: Wavelet, level: usize, n: usize, out: usize) -> Self {
        let m = (n >> level) as i64;
        let support = wavelet.support(level, 0);
        let (start, len, step) = (support.start, support.end - support.start, 1i64 << level);
        let (mut first, mut count) = (Vec::with_capacity(out), Vec::with_capacity(out));
        for x in 0..out as i64 {
            let hi = (x - start).div_euclid(step);
            let lo = (x - start - len).div_euclid(step) + 1;
            let c = (hi - lo + 1).min(m);
            first.push(if c == m { 0 } else { lo.rem_euclid(m) as u32 });
            count.push(c as u32);
        }
        Self { first, count }
    }
}

/// One level ready for the per-row pass: the largest magnitude of each coefficient of one row
/// (`grid`, scratch), for every coefficient row `ky` that covers an output row the maximum over
/// the coefficients covering each output column (`rows[slot[ky] * out_w + x]`), and the row
/// cover.
#[derive(Debug, Default)]
struct LevelRows {
    grid: Vec<f64>,
    rows: Vec<f64>,
    /// Per coefficient row: its place in `rows`, `u32::MAX` when it covers no output row.
    slot: Vec<u32>,
    m_y: usize,
    cover_y: Option<Cover>,
}

/// The larger of two values that are neither NaN nor `-0.0` (coefficient magnitudes): `f64::max`
/// without its NaN handling, so that the loops vectorize.
#[inline]
fn larger(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// Eq. 7 for one output row `y` ([`Workspace::run`]), as a [`pulp::WithSimd`] so that its loops
/// are compiled for the best instruction set the processor has (AVX-512 or AVX2 where present;
/// the same operations in the same order, so the same bits).
struct Eq7Row<'a> {
    prepared: &'a [LevelRows],
    y: usize,
    eps: f64,
    /// `levels + 2` rows of scratch: each level's lambda, their maximum, the running sum.
    scratch: &'a mut [f64],
    /// Per level, the covering coefficient rows `(first, count)` its lambda in `scratch` is of.
    covered: &'a mut [Option<(u32, u32)>],
    level_row: &'a mut [u8],
}

impl pulp::WithSimd for Eq7Row<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let Self { prepared, y, eps, scratch, covered, level_row } = self;
        let out_w = level_row.len();
        let levels = prepared.len();
        let (lambdas, rest) = scratch.split_at_mut(levels * out_w);
        let (max, sum) = rest.split_at_mut(out_w);
        let lambdas_of = lambdas.chunks_exact_mut(out_w).zip(prepared).zip(covered.iter_mut());
        let mut changed = false;
        for ((lambda, prepared), covered) in lambdas_of {
            // lambda_j of this row: the maximum over the covering coefficient rows.
            let cover_y = prepared.cover_y.as_ref().expect("prepared above");
            let (first, count) = (cover_y.first[y], cover_y.count[y]);
            if *covered != Some((first, count)) {
                changed = true;
                let row = |ky: usize| &prepared.rows[prepared.slot[ky] as usize * out_w..][..out_w];
                lambda.fill(0.0);
                let mut ky = first as usize;
                for _ in 0..count {
                    for (l, s) in lambda.iter_mut().zip(row(ky)) {
                        *l = larger(*l, *s);
                    }
                    ky = if ky + 1 == prepared.m_y { 0 } else { ky + 1 };
                }
                *covered = Some((first, count));
            }
        }
        // Their maximum, kept while no lambda changes (level 1's changes every second row).
        if changed {
            max.copy_from_slice(&lambdas[..out_w]);
            for lambda in lambdas.chunks_exact(out_w).skip(1) {
                for (m, l) in max.iter_mut().zip(lambda) {
                    *m = larger(*m, *l);
                }
            }
        }
        // Eq. 7, finest level first: j* is the first level at which the sum of the finer or
        // equal levels reaches eps times the pixel's largest lambda (0 where every lambda is 0).
        // Level by level over the whole row, so that the loop vectorizes; each pixel's sum takes
        // its terms in the same order as a loop over its levels that stops at j*.
        level_row.fill(0);
        sum.fill(0.0);
        for (j, lambda) in lambdas.chunks_exact(out_w).enumerate() {
            let j = (j + 1) as u8;
            for (((out, s), &l), &m) in level_row.iter_mut().zip(sum.iter_mut()).zip(lambda).zip(max.iter()) {
                *s += l;
                let reached = *out == 0 && m > 0.0 && *s >= eps * m;
                *out = if reached { j } else { *out };
            }
        }
    }
}

/// A buffer of `len` values whose contents the caller overwrites: only growth is filled.
fn sized(buffer: &mut Vec<f64>, len: usize) -> &mut [f64] {
    buffer.truncate(len);
    buffer.resize(len, 0.0);
    buffer
}

/// The estimate for the top-left `out_w` x `out_h` pixels of a (padded or extended) image.
pub(crate) fn estimate(
    image: &Image,
    levels: usize,
    out_w: usize,
    out_h: usize,
    config: &Config,
) -> Result<BandwidthMap, Error> {
    let mut workspace = Workspace::default();
    workspace.run(image, levels, out_w, out_h, config, true)?;
    Ok(workspace.map.take().expect("just estimated"))
}

/// The frequency the estimator reads for level `j*` (1 = finest), in cycles per pixel: `c 2^-j*`,
/// 0 for no significant level (`j* = 0`).
pub fn level_frequency(c: f64, level: u8) -> f64 {
    if level == 0 { 0.0 } else { c * 0.5f64.powi(i32::from(level)) }
}

impl Workspace {
    /// [`estimate`] in this workspace's buffers; the frequencies only `with_frequency` (else the
    /// map's are left empty).
    fn run(
        &mut self,
        image: &dyn dwt::Rows,
        levels: usize,
        out_w: usize,
        out_h: usize,
        config: &Config,
        with_frequency: bool,
    ) -> Result<&BandwidthMap, Error> {
        let (w, h) = (image.width(), image.height());
        self.levels.resize_with(levels, LevelRows::default);
        self.levels.truncate(levels);
        // Only the coefficient rows that cover an output row are needed (about half of them when
        // the output is the top half of an extended image): the transform computes the details
        // of those rows alone.
        for (i, prepared) in self.levels.iter_mut().enumerate() {
            let level = i + 1;
            let m_y = h >> level;
            let cover_y = Cover::new(config.wavelet, level, h, out_h);
            prepared.slot.clear();
            prepared.slot.resize(m_y, u32::MAX);
            for (&first, &count) in cover_y.first.iter().zip(&cover_y.count) {
                for t in 0..count as usize {
                    prepared.slot[(first as usize + t) % m_y] = 0;
                }
            }
            for (place, slot) in prepared.slot.iter_mut().filter(|s| **s == 0).enumerate() {
                *slot = place as u32;
            }
            prepared.m_y = m_y;
            prepared.cover_y = Some(cover_y);
        }
        let levels_rows = &self.levels;
        let decomposition = self
            .transform
            .wavedec2_where(image, config.wavelet, levels, &|level, k| levels_rows[level - 1].slot[k] != u32::MAX)?;
        self.levels.par_iter_mut().zip(&decomposition.details).enumerate().for_each(|(i, (prepared, details))| {
            let level = i + 1;
            let m_x = w >> level;
            let floor = config.noise_floor * (1u64 << level) as f64;
            let gain = match config.reading {
                Reading::Paper => 1.0,
                Reading::LevelNormalized => 0.5f64.powi(level as i32),
            };
            let [ch, cv, cd] = details;
            let cover_x = Cover::new(config.wavelet, level, w, out_w);
            let needed = prepared.slot.iter().filter(|s| **s != u32::MAX).count();
            let rows = sized(&mut prepared.rows, needed * out_w);
            // One coefficient row at a time: the largest magnitude of the three orientations, zero
            // below the noise floor, in the reading's units; then its maximum over the coefficients
            // covering each output column.
            let grid = sized(&mut prepared.grid, m_x);
            let used = prepared.slot.iter().enumerate().filter(|(_, s)| **s != u32::MAX).map(|(ky, _)| ky);
            for (ky, row) in used.zip(rows.chunks_exact_mut(out_w)) {
                let span = ky * m_x..(ky + 1) * m_x;
                let (a, b, c) = (&ch.data()[span.clone()], &cv.data()[span.clone()], &cd.data()[span]);
                for (((g, a), b), c) in grid.iter_mut().zip(a).zip(b).zip(c) {
                    let v = larger(larger(a.abs(), b.abs()), c.abs());
                    *g = if v < floor { 0.0 } else { v * gain };
                }
                for ((out, &first), &count) in row.iter_mut().zip(&cover_x.first).zip(&cover_x.count) {
                    let mut best = 0.0f64;
                    let mut k = first as usize;
                    for _ in 0..count {
                        best = larger(best, grid[k]);
                        k = if k + 1 == m_x { 0 } else { k + 1 };
                    }
                    *out = best;
                }
            }
        });

        let map = self.map.get_or_insert_with(|| BandwidthMap {
            width: 0,
            height: 0,
            levels: 0,
            c: 0.0,
            level: Vec::new(),
            frequency: Vec::new(),
        });
        (map.width, map.height, map.levels, map.c) = (out_w, out_h, levels, config.c);
        map.level.truncate(out_w * out_h);
        map.level.resize(out_w * out_h, 0);
        sized(&mut map.frequency, if with_frequency { out_w * out_h } else { 0 });
        let prepared = &self.levels;
        let arch = pulp::Arch::new();
        // Bands of rows, each row after the other: a level's lambda changes only when the
        // coefficient rows covering the output row do (every 2^j rows at level j), and is kept
        // until then.
        const BAND: usize = 16;
        map.level.par_chunks_mut(BAND * out_w).enumerate().for_each_init(
            || (vec![0.0f64; (levels + 2) * out_w], vec![None; levels]),
            |(scratch, covered), (band, level_rows)| {
                covered.fill(None);
                for (r, level_row) in level_rows.chunks_exact_mut(out_w).enumerate() {
                    let y = band * BAND + r;
                    arch.dispatch(Eq7Row { prepared, y, eps: config.eps, scratch, covered, level_row });
                }
            },
        );
        if with_frequency {
            // c 2^-j per level j (index 0: no significant level).
            let frequency_of: Vec<f64> = (0..=levels as u8).map(|j| level_frequency(config.c, j)).collect();
            for (f, &j) in map.frequency.iter_mut().zip(&map.level) {
                *f = frequency_of[j as usize];
            }
        }
        Ok(map)
    }
}
