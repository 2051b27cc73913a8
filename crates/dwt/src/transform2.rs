use rayon::prelude::*;

use crate::kernels::{analysis_rows, analyze_across_split, analyze_split, synthesize, synthesize_across};
use crate::wavelet::{Bank, D4, HAAR};
use crate::{Error, Image, Wavelet, check_finite, check_levels, with_bank};

/// The three detail orientations of a 2D level, in PyWavelets' order `(cH, cV, cD)`; the value is
/// the index into a `[Image; 3]`.
///
/// Axis 0 runs down the rows (`y`), axis 1 along a row (`x`), as in numpy.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Orientation {
    /// `cH`: high-pass along axis 0 (`y`), low-pass along axis 1 (`x`). Responds to horizontal
    /// edges and lines: intensity that changes from row to row.
    Horizontal = 0,
    /// `cV`: low-pass along axis 0 (`y`), high-pass along axis 1 (`x`). Responds to vertical
    /// edges: intensity that changes along a row.
    Vertical = 1,
    /// `cD`: high-pass along both axes.
    Diagonal = 2,
}

impl Orientation {
    /// The three orientations in storage order.
    pub const ALL: [Orientation; 3] = [Orientation::Horizontal, Orientation::Vertical, Orientation::Diagonal];

    /// The index into a `[Image; 3]` of details.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name for messages: `"horizontal"`, `"vertical"`, `"diagonal"`.
    pub const fn name(self) -> &'static str {
        match self {
            Orientation::Horizontal => "horizontal",
            Orientation::Vertical => "vertical",
            Orientation::Diagonal => "diagonal",
        }
    }
}

/// A multi-level 2D decomposition: the approximation after `levels()` steps and, per level, the
/// three detail images, finest level first.
///
/// `details[j - 1][o.index()]` is level `j` (1 = finest, `width / 2` x `height / 2`; `levels()` =
/// coarsest, the size of `approx`), orientation `o`. PyWavelets' `wavedec2` lists the same images
/// coarsest first: `[approx, tuple(details[J-1]), ..., tuple(details[0])]`. Coefficient `(kx, ky)`
/// of level `j` describes the pixels around `(coefficient_center(j, kx), coefficient_center(j, ky))`
/// ([`crate::coefficient_center`], [`Wavelet::support`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Decomposition2 {
    pub wavelet: Wavelet,
    pub approx: Image,
    pub details: Vec<[Image; 3]>,
}

impl Decomposition2 {
    /// Number of levels `J`.
    pub fn levels(&self) -> usize {
        self.details.len()
    }

    /// The detail image of level `level` (1 = finest) and `orientation`. Panics unless
    /// `1 <= level <= J`.
    pub fn detail(&self, level: usize, orientation: Orientation) -> &Image {
        assert!((1..=self.levels()).contains(&level), "level {level} is not in 1..={}", self.levels());
        &self.details[level - 1][orientation.index()]
    }

    /// Mutable access to one detail image, e.g. to threshold it before [`waverec2`].
    pub fn detail_mut(&mut self, level: usize, orientation: Orientation) -> &mut Image {
        assert!((1..=self.levels()).contains(&level), "level {level} is not in 1..={}", self.levels());
        &mut self.details[level - 1][orientation.index()]
    }

    /// Sum of squares of all coefficients; equals the image's energy.
    pub fn energy(&self) -> f64 {
        self.approx.energy() + self.details.iter().flatten().map(Image::energy).sum::<f64>()
    }
}

/// One level of the forward transform: `cA, (cH, cV, cD)` of
/// `pywt.dwt2(x, w, mode="periodization")`. Width and height must be even.
pub fn dwt2(image: &Image, wavelet: Wavelet) -> Result<(Image, [Image; 3]), Error> {
    check_size(image.width(), image.height(), 1)?;
    with_bank!(wavelet, bank => forward_level(bank, image))
}

/// One level of the inverse transform: `pywt.idwt2((approx, details), w, mode="periodization")`,
/// an image twice as wide and high as the four (equally sized) coefficient images.
pub fn idwt2(approx: &Image, details: &[Image; 3], wavelet: Wavelet) -> Result<Image, Error> {
    check_coefficients(approx, std::slice::from_ref(details))?;
    Ok(with_bank!(wavelet, bank => inverse_level(bank, approx, details)))
}

/// The forward transform over `levels` levels: `pywt.wavedec2(x, w, mode="periodization",
/// level=levels)`. Width and height must both be divisible by `2^levels`
/// ([`crate::max_levels2`]).
pub fn wavedec2(image: &Image, wavelet: Wavelet, levels: usize) -> Result<Decomposition2, Error> {
    let mut workspace = Workspace2::default();
    workspace.wavedec2(image, wavelet, levels)?;
    Ok(workspace.decomposition.take().expect("just computed"))
}

/// Buffers for repeated [`wavedec2`] calls on images of one size (a lobe image per row of an
/// atlas, say): the decomposition and the approximation between two levels stay allocated
/// between calls, so a call allocates nothing and touches no fresh memory. The coefficients are
/// [`wavedec2`]'s, bit for bit.
#[derive(Debug, Default)]
pub struct Workspace2 {
    decomposition: Option<Decomposition2>,
    /// The approximations between levels, alternately.
    between: [Vec<f64>; 2],
}

impl Workspace2 {
    /// [`wavedec2`] into this workspace's buffers; the result is borrowed until the next call.
    pub fn wavedec2(&mut self, image: &Image, wavelet: Wavelet, levels: usize) -> Result<&Decomposition2, Error> {
        self.wavedec2_where(image, wavelet, levels, &|_, _| true)
    }

    /// [`Self::wavedec2`] with the detail coefficients of level `j` (1 = finest) computed only in
    /// the rows `k` where `rows_with_details(j, k)` holds: the other rows of that level's three detail
    /// images hold whatever the workspace held before (unspecified). The approximation is
    /// computed everywhere, as the coarser levels read it. An estimate that reads the details
    /// of part of an image ([`wavedec2`]'s work for a row without details: the low-pass across
    /// rows and along the row, three eighths) uses it; every coefficient it computes is
    /// [`wavedec2`]'s, bit for bit.
    pub fn wavedec2_where(
        &mut self,
        image: &dyn Rows,
        wavelet: Wavelet,
        levels: usize,
        rows_with_details: &(dyn Fn(usize, usize) -> bool + Sync),
    ) -> Result<&Decomposition2, Error> {
        check_size(image.width(), image.height(), levels)?;
        let decomposition = self.decomposition.get_or_insert_with(|| Decomposition2 {
            wavelet,
            approx: Image::zeros(0, 0),
            details: Vec::new(),
        });
        decomposition.wavelet = wavelet;
        let blank = || std::array::from_fn(|_| Image::zeros(0, 0));
        decomposition.details.resize_with(levels, blank);
        let (mut w, mut h) = (image.width(), image.height());
        // Level j reads the approximation of level j - 1 (the image for j = 1) and writes its own
        // ([`level_buffers`]); the last one is copied into the decomposition's `approx`.
        let between = &mut self.between;
        for level in 0..levels {
            let (w2, h2) = (w / 2, h / 2);
            let (src, dst) = level_buffers(between, image, level, w, h);
            let details = &mut decomposition.details[level];
            let [mut ch, mut cv, mut cd] = details.each_mut().map(|image| {
                let mut data = std::mem::replace(image, Image::zeros(0, 0)).into_data();
                data.truncate(w2 * h2);
                data.resize(w2 * h2, 0.0);
                data
            });
            let with_details = |k: usize| rows_with_details(level + 1, k);
            let sink = Sink::Store([&mut ch[..], &mut cv[..], &mut cd[..]], &with_details);
            let finite = with_bank!(wavelet, bank => forward_level_into(bank, src, w, h, dst, sink));
            if level == 0 && !finite {
                return Err(first_non_finite(image));
            }
            *details = [ch, cv, cd].map(|data| Image::new(w2, h2, data).expect("sizes match"));
            (w, h) = (w2, h2);
        }
        let mut approx = std::mem::replace(&mut decomposition.approx, Image::zeros(0, 0)).into_data();
        approx.clear();
        approx.extend_from_slice(&between[(levels - 1) % 2][..w * h]);
        decomposition.approx = Image::new(w, h, approx).expect("sizes match");
        Ok(decomposition)
    }

    /// The energy of each detail level of [`wavedec2`] of `image` (finest first), counting a
    /// coefficient of level `j` only where its magnitude is at least `floor(j)`: the sum of the
    /// squares of the three orientations' coefficients. The details are never stored, only the
    /// approximations between levels: each output row's are summed while in cache, in eight
    /// partial sums per orientation (pairwise at the end), `(cH + cV) + cD` per row, the rows of a
    /// level added in order (the same bits on any number of threads). The image is given row by
    /// row ([`Rows`]), so that one made from a smaller one (a mirror tiling) is never stored
    /// either; it is refused with a NaN or an infinity.
    pub fn detail_energy(
        &mut self,
        image: &dyn Rows,
        wavelet: Wavelet,
        levels: usize,
        floor: &(dyn Fn(usize) -> f64 + Sync),
    ) -> Result<Vec<f64>, Error> {
        let (mut w, mut h) = (image.width(), image.height());
        check_size(w, h, levels)?;
        let between = &mut self.between;
        let mut sums = Vec::new();
        let mut energy = Vec::with_capacity(levels);
        for level in 0..levels {
            let (w2, h2) = (w / 2, h / 2);
            let (src, dst) = level_buffers(between, image, level, w, h);
            sums.resize(h2, 0.0);
            let sink = Sink::Energy { floor: floor(level + 1), sums: &mut sums[..] };
            let finite = with_bank!(wavelet, bank => forward_level_into(bank, src, w, h, dst, sink));
            if level == 0 && !finite {
                return Err(first_non_finite(image));
            }
            let mut total = 0.0;
            for sum in &sums {
                total += sum;
            }
            energy.push(total);
            (w, h) = (w2, h2);
        }
        Ok(energy)
    }
}

/// Level `level`'s input, `w x h` (the image, or the approximation of the level before), and its
/// output, `w / 2 x h / 2`: the two buffers of `between` alternate, and only grow (a buffer cut
/// to a coarse level's size and grown again for the next image's first level would be cleared
/// again).
fn level_buffers<'a>(
    between: &'a mut [Vec<f64>; 2],
    image: &'a dyn Rows,
    level: usize,
    w: usize,
    h: usize,
) -> (Source<'a>, &'a mut [f64]) {
    let [even, odd] = between;
    let (dst, previous) = if level.is_multiple_of(2) { (even, &*odd) } else { (odd, &*even) };
    let src = if level == 0 { Source::Rows(image) } else { Source::Stored(&previous[..w * h]) };
    let len = (w / 2) * (h / 2);
    // Every value is written: only a buffer that grows is filled first.
    if dst.len() < len {
        dst.resize(len, 0.0);
    }
    (src, &mut dst[..len])
}

/// An image given row by row ([`Workspace2::wavedec2_where`], [`Workspace2::detail_energy`]): an
/// image that is a function of a smaller one need not be stored. Each row is either stored
/// ([`Self::stored_row`]) or made on demand ([`Self::make_row`]); the transform makes each row
/// it reads once, though two output rows read it. An [`Image`] stores all of its rows.
pub trait Rows: Sync {
    fn width(&self) -> usize;
    fn height(&self) -> usize;
    /// Row `r` (`width` values) where the image stores it; `None` where it is made.
    fn stored_row(&self, r: usize) -> Option<&[f64]>;
    /// Writes row `r`, which the image does not store, into `buffer` (`width` values).
    fn make_row(&self, r: usize, buffer: &mut [f64]);
    /// Row `r`: the stored one, or the one made in `buffer` (`width` values).
    fn row<'a>(&'a self, r: usize, buffer: &'a mut [f64]) -> &'a [f64] {
        match self.stored_row(r) {
            Some(row) => row,
            None => {
                self.make_row(r, buffer);
                buffer
            }
        }
    }
}

impl Rows for Image {
    fn width(&self) -> usize {
        Image::width(self)
    }

    fn height(&self) -> usize {
        Image::height(self)
    }

    fn stored_row(&self, r: usize) -> Option<&[f64]> {
        let w = Image::width(self);
        Some(&self.data()[r * w..(r + 1) * w])
    }

    fn make_row(&self, _: usize, _: &mut [f64]) {
        unreachable!("an image stores every row")
    }
}

/// The error for the first non-finite value of `image`, row-major (one is known to be there).
fn first_non_finite(image: &dyn Rows) -> Error {
    let w = image.width();
    let mut buffer = vec![0.0; w];
    (0..image.height())
        .find_map(|r| {
            check_finite(|| "image".to_owned(), image.row(r, &mut buffer)).err().map(|e| match e {
                Error::NonFinite { what, index } => Error::NonFinite { what, index: r * w + index },
                other => other,
            })
        })
        .expect("a non-finite value")
}

/// The sum of the squares of the `values` whose magnitude is at least `floor`, as a
/// [`pulp::WithSimd`] (compiled for AVX-512 or AVX2 where the processor has them): eight partial
/// sums of every eighth value, added pairwise at the end, so that the loop vectorizes (one sum
/// after another is bound by the addition's latency). The terms are all `>= 0`: the result is
/// within `m u` of the exact sum of its `m` terms (`u = 2^-53`), as a sum in order is.
pub(crate) struct SquaresFrom<'a> {
    pub values: &'a [f64],
    pub floor: f64,
}

impl pulp::WithSimd for SquaresFrom<'_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> f64 {
        const LANES: usize = 8;
        let Self { values, floor } = self;
        let mut sums = [0.0f64; LANES];
        let square = |v: f64| if v.abs() >= floor { v * v } else { 0.0 };
        let blocks = values.chunks_exact(LANES);
        let rest = blocks.remainder();
        for block in blocks {
            for (sum, &v) in sums.iter_mut().zip(block) {
                *sum += square(v);
            }
        }
        for (sum, &v) in sums.iter_mut().zip(rest) {
            *sum += square(v);
        }
        let [a, b, c, d, e, f, g, h] = sums;
        ((a + b) + (c + d)) + ((e + f) + (g + h))
    }
}

/// The inverse of [`wavedec2`]: `pywt.waverec2(coeffs, w, mode="periodization")` with `coeffs` in
/// PyWavelets' order. Fails unless the three details of level `j` are `2^(J-j)` times as wide and
/// high as `approx` and every value is finite.
pub fn waverec2(decomposition: &Decomposition2) -> Result<Image, Error> {
    let Decomposition2 { wavelet, approx, details } = decomposition;
    check_coefficients(approx, details)?;
    let (coarsest, finer) = details.split_last().expect("checked: at least one level");
    let mut image = with_bank!(*wavelet, bank => inverse_level(bank, approx, coarsest));
    for level in finer.iter().rev() {
        image = with_bank!(*wavelet, bank => inverse_level(bank, &image, level));
    }
    Ok(image)
}

/// The checks of a `width x height` image's shape; its values are checked by the first level's
/// pass ([`forward_level_into`]), which reads them anyway.
fn check_size(width: usize, height: usize, levels: usize) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::Empty { what: "image" });
    }
    check_levels("width", width, levels)?;
    check_levels("height", height, levels)
}

fn check_coefficients(approx: &Image, details: &[[Image; 3]]) -> Result<(), Error> {
    if details.is_empty() {
        return Err(Error::ZeroLevels);
    }
    if approx.data().is_empty() {
        return Err(Error::Empty { what: "approximation" });
    }
    check_finite(|| "approximation".to_owned(), approx.data())?;
    let (mut width, mut height) = (approx.width(), approx.height());
    for (j, level) in details.iter().enumerate().rev() {
        for (o, image) in Orientation::ALL.into_iter().zip(level) {
            let what = || format!("level {} {} detail", j + 1, o.name());
            if (image.width(), image.height()) != (width, height) {
                return Err(Error::ShapeMismatch(format!(
                    "{} is {}x{}, expected {width}x{height}",
                    what(),
                    image.width(),
                    image.height()
                )));
            }
            check_finite(what, image.data())?;
        }
        (width, height) = (2 * width, 2 * height);
    }
    Ok(())
}

/// Rows per rayon task: enough that a task is worth its scheduling (~16k samples).
fn min_rows(width: usize) -> usize {
    (1 << 14) / width.max(1) + 1
}

/// One forward level of an image of checked shape (even width and height), one output row `k`
/// at a time: the column filters combine the `F` input rows that row `k` depends on (contiguous
/// rows, so the loops vectorize), then the row filter splits each of the two results. Columns
/// first is also PyWavelets' order (axis 0, then axis 1), and no intermediate image is ever
/// allocated. An image with a NaN or an infinity is refused.
fn forward_level<const F: usize>(bank: &Bank<F>, image: &Image) -> Result<(Image, [Image; 3]), Error> {
    let (w, h) = (image.width(), image.height());
    let (w2, h2) = (w / 2, h / 2);
    let mut out: [Vec<f64>; 4] = std::array::from_fn(|_| vec![0.0; w2 * h2]);
    let [ca, ch, cv, cd] = out.each_mut().map(|b| &mut b[..]);
    if !forward_level_into(bank, Source::Stored(image.data()), w, h, ca, Sink::Store([ch, cv, cd], &|_| true)) {
        return Err(first_non_finite(image));
    }
    let [ca, ch, cv, cd] = out.map(|data| Image::new(w2, h2, data).expect("sizes match"));
    Ok((ca, [ch, cv, cd]))
}

/// The input of a level: a stored image (`w x h`, row-major) or one given row by row.
#[derive(Clone, Copy)]
enum Source<'a> {
    Stored(&'a [f64]),
    Rows(&'a dyn Rows),
}

impl<'a> Source<'a> {
    /// The `F` input rows of output row `k` of an image of `h` rows of `w`: slices of a stored
    /// image, or made in `made`.
    fn rows<const F: usize>(self, k: usize, w: usize, h: usize, made: &'a mut MadeRows<F>) -> [&'a [f64]; F] {
        let indices = analysis_rows::<F>(k, h);
        match self {
            Source::Stored(src) => indices.map(|r| &src[r * w..(r + 1) * w]),
            Source::Rows(rows) => made.rows(rows, indices),
        }
    }
}

/// The rows a job of [`forward_level_into`] made of a [`Rows`] image, `F` slots of `w` values:
/// output row `k + 1` reads two of the rows `k` read (the filter steps by 2), which are taken
/// from their slots instead of made again.
struct MadeRows<const F: usize> {
    buffer: Vec<f64>,
    /// The row each slot holds (`usize::MAX`: none).
    held: [usize; F],
}

impl<const F: usize> MadeRows<F> {
    fn new(w: usize) -> Self {
        MadeRows { buffer: vec![0.0; F * w], held: [usize::MAX; F] }
    }

    /// The rows `indices` of `rows`: the stored ones, and the others from the slots, made where
    /// no slot holds them (in a slot that holds none of `indices`: there is always one, since a
    /// row is made only when no slot holds it).
    fn rows<'a>(&'a mut self, rows: &'a dyn Rows, indices: [usize; F]) -> [&'a [f64]; F] {
        let w = self.buffer.len() / F;
        let stored = indices.map(|r| rows.stored_row(r));
        let mut slot_of = [0; F];
        for ((slot_of, &r), stored) in slot_of.iter_mut().zip(&indices).zip(&stored) {
            if stored.is_some() {
                continue;
            }
            *slot_of = match self.held.iter().position(|&held| held == r) {
                Some(slot) => slot,
                None => {
                    let slot = (0..F).find(|&s| !indices.contains(&self.held[s])).expect("a free slot");
                    rows.make_row(r, &mut self.buffer[slot * w..(slot + 1) * w]);
                    self.held[slot] = r;
                    slot
                }
            };
        }
        let buffer = &self.buffer;
        std::array::from_fn(|j| stored[j].unwrap_or(&buffer[slot_of[j] * w..(slot_of[j] + 1) * w]))
    }
}

/// Where a level's detail rows go.
enum Sink<'a> {
    /// Into the level's three images (`[cH, cV, cD]`), in the rows `k` where the predicate holds.
    Store([&'a mut [f64]; 3], &'a (dyn Fn(usize) -> bool + Sync)),
    /// Each row's squares of the three orientations' coefficients at least `floor` in magnitude,
    /// summed (`SquaresFrom`: `(cH + cV) + cD`), into `sums[k]`.
    Energy { floor: f64, sums: &'a mut [f64] },
}

/// One level of `src` (`w x h`) into `approx` (`w / 2 x h / 2`), its details into `sink`;
/// whether every value of `src` is finite. Each output row checks the last two of the rows it
/// reads, which covers every row once, while they are in cache (a separate pass over the image
/// cost as much as a tenth of the transform). The loops are compiled for the best instruction
/// set the processor has ([`pulp::Arch`]: AVX-512 or AVX2 where present): the same operations in
/// the same order (no fused multiply-add), so the same bits.
fn forward_level_into<const F: usize>(
    bank: &Bank<F>,
    src: Source<'_>,
    w: usize,
    h: usize,
    approx: &mut [f64],
    sink: Sink<'_>,
) -> bool {
    let w2 = w / 2;
    let arch = pulp::Arch::new();
    // Per job: the input rows where they are made, the two column-filtered rows, and, for the
    // energy, the three detail rows.
    let buffers = || (MadeRows::<F>::new(w), vec![0.0; 2 * w], vec![0.0; 3 * w2]);
    match sink {
        Sink::Store([ch, cv, cd], with_details) => approx
            .par_chunks_mut(w2)
            .zip(ch.par_chunks_mut(w2))
            .zip(cv.par_chunks_mut(w2))
            .zip(cd.par_chunks_mut(w2))
            .enumerate()
            .with_min_len(min_rows(w))
            .map_init(buffers, |(input, scratch, _), (k, (((a, hh), v), dd))| {
                let rows = src.rows::<F>(k, w, h, input);
                arch.dispatch(OutputRow { bank, rows, scratch, out: [a, hh, v, dd], details: with_details(k) })
            })
            .reduce(|| true, |a, b| a & b),
        Sink::Energy { floor, sums } => approx
            .par_chunks_mut(w2)
            .zip(sums.par_iter_mut())
            .enumerate()
            .with_min_len(min_rows(w))
            .map_init(buffers, |(input, scratch, detail), (k, (a, sum))| {
                let rows = src.rows::<F>(k, w, h, input);
                let [hh, v, dd] = {
                    let mut parts = detail.chunks_exact_mut(w2);
                    std::array::from_fn(|_| parts.next().expect("three rows"))
                };
                let finite = arch.dispatch(OutputRow { bank, rows, scratch, out: [a, hh, v, dd], details: true });
                let energy = |part: &[f64]| arch.dispatch(SquaresFrom { values: part, floor });
                let mut parts = detail.chunks_exact(w2);
                let mut next = || energy(parts.next().expect("three rows"));
                *sum = (next() + next()) + next();
                finite
            })
            .reduce(|| true, |a, b| a & b),
    }
}

/// One output row of [`forward_level_into`] from its `F` input rows, as a [`pulp::WithSimd`]:
/// its body is inlined into the function compiled for the instruction set (a closure would be
/// called from it, compiled for the baseline).
struct OutputRow<'a, const F: usize> {
    bank: &'a Bank<F>,
    rows: [&'a [f64]; F],
    scratch: &'a mut [f64],
    /// `[cA, cH, cV, cD]`'s rows.
    out: [&'a mut [f64]; 4],
    /// Whether to compute the details (else `cA` alone).
    details: bool,
}

impl<const F: usize> pulp::WithSimd for OutputRow<'_, F> {
    type Output = bool;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> bool {
        let Self { bank, rows, scratch, out: [a, hh, v, dd], details } = self;
        let w2 = a.len();
        // The two column-filtered rows, each deinterleaved into its even and odd columns.
        let (lo, hi) = scratch.split_at_mut(2 * w2);
        let ((lo_even, lo_odd), (hi_even, hi_odd)) = (lo.split_at_mut(w2), hi.split_at_mut(w2));
        if details {
            analyze_across_split(bank, &rows, [&mut *lo_even, &mut *lo_odd], Some([&mut *hi_even, &mut *hi_odd]));
            // Low-pass along axis 0 -> (cA, cV) along axis 1; high-pass -> (cH, cD).
            analyze_split(bank, lo_even, lo_odd, a, Some(v));
            analyze_split(bank, hi_even, hi_odd, hh, Some(dd));
        } else {
            analyze_across_split(bank, &rows, [&mut *lo_even, &mut *lo_odd], None);
            analyze_split(bank, lo_even, lo_odd, a, None);
        }
        all_finite(rows[F - 2]) & all_finite(rows[F - 1])
    }
}

/// Whether no value is NaN or infinite, by an integer test on the exponent that vectorizes.
#[inline(always)]
fn all_finite(values: &[f64]) -> bool {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    values.iter().fold(0u64, |acc, v| acc | u64::from(v.to_bits() & EXPONENT == EXPONENT)) == 0
}

/// One inverse level of checked coefficients: the transpose of [`forward_level`], one output
/// row at a time: the column synthesis of row `n` of the two half-width images (low-pass and
/// high-pass along axis 1), then the row synthesis of the two into the output row.
fn inverse_level<const F: usize>(bank: &Bank<F>, approx: &Image, details: &[Image; 3]) -> Image {
    let (w2, h2) = (approx.width(), approx.height());
    let (w, h) = (2 * w2, 2 * h2);
    let [ch, cv, cd] = details;
    let mut out = vec![0.0; w * h];
    out.par_chunks_mut(w).enumerate().with_min_len(min_rows(w)).for_each_init(
        || vec![0.0; w],
        |scratch, (n, row)| {
            let (lo, hi) = scratch.split_at_mut(w2);
            synthesize_across(bank, n, approx.data(), ch.data(), w2, lo);
            synthesize_across(bank, n, cv.data(), cd.data(), w2, hi);
            synthesize(bank, lo, hi, row);
        },
    );
    Image::new(w, h, out).expect("sizes match")
}

#[cfg(test)]
mod tests {
    use super::*;
    use pulp::WithSimd;

    /// An output row computed with the instruction set chosen at run time is the baseline's, bit
    /// for bit, with and without its details.
    fn check_dispatch<const F: usize>(bank: &Bank<F>) {
        let w = 38;
        let rows: Vec<Vec<f64>> =
            (0..F).map(|r| (0..w).map(|c| ((r * 131 + c * 71) as f64 * 0.37).sin() * 1e3).collect()).collect();
        let rows: [&[f64]; F] = std::array::from_fn(|r| &rows[r][..]);
        for details in [true, false] {
            let run = |dispatch: bool| {
                let (mut scratch, mut out) = (vec![0.0; 2 * w], [(); 4].map(|_| vec![0.0; w / 2]));
                let [a, hh, v, dd] = out.each_mut().map(|b| &mut b[..]);
                let row = OutputRow { bank, rows, scratch: &mut scratch, out: [a, hh, v, dd], details };
                let finite =
                    if dispatch { pulp::Arch::new().dispatch(row) } else { row.with_simd(pulp::Scalar::new()) };
                (finite, out.map(|b| b.iter().map(|x| x.to_bits()).collect::<Vec<u64>>()))
            };
            assert_eq!(run(true), run(false), "details {details}");
        }
    }

    #[test]
    fn dispatched_rows_are_the_baselines_bit_for_bit() {
        check_dispatch(&D4);
        check_dispatch(&HAAR);
    }

    #[test]
    fn lane_sums_are_the_sequential_sum_to_rounding() {
        use rand::{Rng, SeedableRng, rngs::StdRng};
        let mut rng = StdRng::seed_from_u64(7);
        for len in [0, 1, 7, 8, 9, 1000, 100_003] {
            // Magnitudes over ten decades, both signs; the floor drops about three tenths.
            let values: Vec<f64> = (0..len)
                .map(|_| {
                    let magnitude = 10f64.powf(rng.random_range(-5.0..5.0));
                    if rng.random() { magnitude } else { -magnitude }
                })
                .collect();
            let floor = 0.01;
            let squares: Vec<f64> = values.iter().filter(|v| v.abs() >= floor).map(|v| v * v).collect();
            let mut sequential = 0.0;
            for square in &squares {
                sequential += square;
            }
            let lanes = pulp::Arch::new().dispatch(SquaresFrom { values: &values, floor });
            let bound = 2.0 * squares.len() as f64 * (f64::EPSILON / 2.0) * sequential;
            assert!((lanes - sequential).abs() <= bound, "{len} values: {lanes} against {sequential}");
            // The instruction set chosen at run time computes the baseline's bits.
            let baseline = SquaresFrom { values: &values, floor }.with_simd(pulp::Scalar::new());
            assert_eq!(lanes.to_bits(), baseline.to_bits(), "{len} values");
        }
    }

    /// An image given row by row, made in the buffer (not the stored rows), counting the rows
    /// it makes.
    struct Copied<'a>(&'a Image, std::sync::atomic::AtomicUsize);

    fn copied(image: &Image) -> Copied<'_> {
        Copied(image, std::sync::atomic::AtomicUsize::new(0))
    }

    impl Rows for Copied<'_> {
        fn width(&self) -> usize {
            self.0.width()
        }
        fn height(&self) -> usize {
            self.0.height()
        }
        fn stored_row(&self, _: usize) -> Option<&[f64]> {
            None
        }
        fn make_row(&self, r: usize, buffer: &mut [f64]) {
            self.1.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            buffer.copy_from_slice(&self.0.data()[r * self.0.width()..][..self.0.width()]);
        }
    }

    #[test]
    fn rows_made_on_demand_give_the_stored_images_coefficients() {
        // Bit for bit, on both wavelets, heights where an output row's input rows wrap onto
        // each other (2: rows 0 1 0 1) or across the image's end, one level and several.
        for wavelet in [Wavelet::Haar, Wavelet::D4] {
            for (w, h, levels) in [(4, 2, 1), (8, 6, 1), (16, 10, 1), (64, 48, 3)] {
                let data: Vec<f64> = (0..w * h).map(|k| ((k * 29 % 83) as f64 * 0.7).cos() * (k % 7) as f64).collect();
                let image = Image::new(w, h, data).unwrap();
                let stored = wavedec2(&image, wavelet, levels).unwrap();
                let mut workspace = Workspace2::default();
                let made = workspace.wavedec2_where(&copied(&image), wavelet, levels, &|_, _| true).unwrap();
                let bits = |d: &Decomposition2| {
                    let images = std::iter::once(&d.approx).chain(d.details.iter().flatten());
                    images.flat_map(|i| i.data().iter().map(|v| v.to_bits())).collect::<Vec<u64>>()
                };
                assert_eq!(bits(made), bits(&stored), "{wavelet:?} {w} x {h}, {levels} levels");
            }
        }
        // Each output row reads four rows, two of them read by the row before: on one thread
        // (a few jobs, each starting with empty slots) a row is made about once, not twice.
        let (w, h) = (256, 256);
        let image = Image::new(w, h, (0..w * h).map(|k| k as f64).collect()).unwrap();
        let counted = copied(&image);
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        one.install(|| Workspace2::default().wavedec2_where(&counted, Wavelet::D4, 1, &|_, _| true).map(|_| ()))
            .unwrap();
        let made = counted.1.into_inner();
        assert!((h..h + h / 4).contains(&made), "{made} rows made for {h}");
    }

    #[test]
    fn detail_energy_is_the_stored_decompositions_to_rounding() {
        // The thresholded energy of every level of the stored decomposition, summed in order,
        // against the streamed one: within 2 m u of each other (m terms of one sign), on either
        // wavelet, with a floor that drops part of each level, and the same on one thread.
        let (w, h, levels) = (256, 256, 4);
        let data: Vec<f64> =
            (0..w * h).map(|k| ((k * 37 % 101) as f64 * 0.3).sin() * (1.0 + k as f64 * 1e-2)).collect();
        let image = Image::new(w, h, data).unwrap();
        let floor = |level: usize| 0.05 * (1u64 << level) as f64;
        for wavelet in [Wavelet::Haar, Wavelet::D4] {
            let stored = wavedec2(&image, wavelet, levels).unwrap();
            let streamed = Workspace2::default().detail_energy(&copied(&image), wavelet, levels, &floor).unwrap();
            for (j, (level, &got)) in stored.details.iter().zip(&streamed).enumerate() {
                let squares: Vec<f64> =
                    level.iter().flat_map(Image::data).filter(|c| c.abs() >= floor(j + 1)).map(|c| c * c).collect();
                assert!(!squares.is_empty() && squares.len() < 3 * level[0].data().len(), "level {}", j + 1);
                let expect: f64 = squares.iter().sum();
                let bound = 2.0 * squares.len() as f64 * (f64::EPSILON / 2.0) * expect;
                assert!((got - expect).abs() <= bound, "{wavelet:?} level {}: {got} against {expect}", j + 1);
            }
            let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
            let alone = one.install(|| Workspace2::default().detail_energy(&copied(&image), wavelet, levels, &floor));
            assert_eq!(alone.unwrap(), streamed, "{wavelet:?} on one thread");
        }
        // A non-finite value is named by its index, as the stored transform names it.
        let mut bad = image.clone();
        bad.data_mut()[5 * w + 7] = f64::NAN;
        let err = Workspace2::default().detail_energy(&copied(&bad), Wavelet::D4, levels, &floor).unwrap_err();
        assert_eq!(err, wavedec2(&bad, Wavelet::D4, levels).unwrap_err());
        assert_eq!(err, Error::NonFinite { what: "image".into(), index: 5 * w + 7 });
    }
}
