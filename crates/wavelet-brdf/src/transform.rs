//! The 2D non-standard Haar transform of one slice (section 4.2) in its in-place ("Mallat")
//! layout, and the synthesis of one value from it (section 5.3).
//!
//! The transform is `dwt::wavedec2` with the Haar wavelet over all `J = log2 n` levels (rows
//! and columns transformed once per level, then the approximation again: the non-standard
//! decomposition). Its coefficients are laid out in one `n x n` array, row-major, index
//! `p = row n + col`: the approximation at `(0, 0)`, and level `j` (`1` finest .. `J`), whose
//! bands are `s = n / 2^j` coefficients wide, at
//!
//! | band | rows | columns |
//! |------|------|---------|
//! | `cH` (high-pass along rows, axis 0) | `s .. 2s` | `0 .. s` |
//! | `cV` (high-pass along columns, axis 1) | `0 .. s` | `s .. 2s` |
//! | `cD` (both) | `s .. 2s` | `s .. 2s` |
//!
//! Haar's analysis is `l = (a + b) / sqrt 2`, `h = (a - b) / sqrt 2` (the paper's and
//! PyWavelets'), so the value at cell `(r, c)` is
//!
//! ```text
//! f(r, c) = A / n + sum_j 1 / 2^j (cH_j(r / B, c / B) s_r + cV_j(...) s_c + cD_j(...) s_r s_c)
//! ```
//!
//! with `B = 2^j` the block a level-`j` coefficient covers, `s_r = +1` in the upper half of its
//! block (`r mod B < B / 2`) and `-1` in the lower, `s_c` likewise: `1 + 3 J` terms
//! ([`synthesis`]). Reconstruction at level of detail `L` leaves out the levels `j <= L`: the
//! value is then the mean of the `2^L x 2^L` block around the cell (Haar's approximation).

use dwt::{Decomposition2, Image, Orientation, Wavelet};
use rayon::prelude::*;

use crate::grid::Grid;

/// The layout position of coefficient `(ky, kx)` of `band` at level `level` (the band's first
/// row and column are `s` or `0`).
fn position(side: usize, level: usize, band: Orientation, ky: usize, kx: usize) -> usize {
    let s = side >> level;
    let (row0, col0) = match band {
        Orientation::Horizontal => (s, 0),
        Orientation::Vertical => (0, s),
        Orientation::Diagonal => (s, s),
    };
    (row0 + ky) * side + col0 + kx
}

/// The Haar coefficients of one `n x n` slice (row-major), in the layout of the module docs.
pub fn forward(grid: Grid, slice: &[f64]) -> Vec<f64> {
    let n = grid.side();
    let image = Image::new(n, n, slice.to_vec()).expect("a slice holds n^2 values");
    let d = dwt::wavedec2(&image, Wavelet::Haar, grid.levels()).expect("n is a power of two and values finite");
    let mut layout = vec![0.0; grid.cells()];
    layout[0] = d.approx.get(0, 0);
    for (j, bands) in d.details.iter().enumerate() {
        for band in Orientation::ALL {
            let image = &bands[band.index()];
            for ky in 0..image.height() {
                for kx in 0..image.width() {
                    layout[position(n, j + 1, band, ky, kx)] = image.get(kx, ky);
                }
            }
        }
    }
    layout
}

/// The slice of a coefficient layout, reconstructed at level of detail `lod` (`0` is full
/// resolution; the levels `1..=lod` are left out) by `dwt::waverec2`.
pub fn inverse(grid: Grid, layout: &[f64], lod: usize) -> Vec<f64> {
    let n = grid.side();
    let band_image = |level: usize, band: Orientation| {
        let s = n >> level;
        let keep = level > lod;
        Image::from_fn(s, s, |kx, ky| if keep { layout[position(n, level, band, ky, kx)] } else { 0.0 })
    };
    let details = (1..=grid.levels()).map(|j| Orientation::ALL.map(|band| band_image(j, band))).collect();
    let approx = Image::new(1, 1, vec![layout[0]]).expect("one value");
    let d = Decomposition2 { wavelet: Wavelet::Haar, approx, details };
    dwt::waverec2(&d).expect("a whole decomposition of finite values").into_data()
}

/// The terms `(position, weight)` whose sum `sum weight * layout[position]` is the value of cell
/// `cell` at the integer level of detail `lod` (module docs): the approximation's, then three per
/// level from the coarsest down to `lod + 1`.
pub fn synthesis(grid: Grid, cell: usize, lod: usize) -> impl Iterator<Item = (usize, f64)> {
    let n = grid.side();
    let (r, c) = (cell / n, cell % n);
    let approx = std::iter::once((0, 1.0 / n as f64));
    let details = ((lod + 1)..=grid.levels()).rev().flat_map(move |j| {
        let block = 1usize << j;
        let (ky, kx) = (r / block, c / block);
        let sign = |x: usize| if x % block < block / 2 { 1.0 } else { -1.0 };
        let (sr, sc, amplitude) = (sign(r), sign(c), 1.0 / block as f64);
        [
            (position(n, j, Orientation::Horizontal, ky, kx), amplitude * sr),
            (position(n, j, Orientation::Vertical, ky, kx), amplitude * sc),
            (position(n, j, Orientation::Diagonal, ky, kx), amplitude * sr * sc),
        ]
    });
    approx.chain(details)
}

/// `f` applied to every slice of a table of `n^2` outgoing cells x 3 channels x `n^2` entries, in
/// parallel: slice `(o, c)` is gathered by `read(o, c, k)` for `k` in `0..n^2` and entry `k` of
/// `f`'s result lands at index `write(o, c, k)` of the `3 n^4` values returned. The encoder and the
/// decoder differ only in the transform and the two layouts.
pub(crate) fn map_slices(
    grid: Grid,
    read: impl Fn(usize, usize, usize) -> f64 + Sync,
    f: impl Fn(&[f64]) -> Vec<f64> + Sync,
    write: impl Fn(usize, usize, usize) -> usize,
) -> Vec<f64> {
    let cells = grid.cells();
    let slices: Vec<[Vec<f64>; 3]> = (0..cells)
        .into_par_iter()
        .map(|o| [0, 1, 2].map(|c| f(&(0..cells).map(|k| read(o, c, k)).collect::<Vec<f64>>())))
        .collect();
    let mut values = vec![0.0; cells * cells * 3];
    for (o, channels) in slices.iter().enumerate() {
        for (c, slice) in channels.iter().enumerate() {
            for (k, v) in slice.iter().enumerate() {
                values[write(o, c, k)] = *v;
            }
        }
    }
    values
}
