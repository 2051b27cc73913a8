//! What a lobe image holds: the Rec. 709 luminance of the BRDF, read from the MERL table by
//! trilinear interpolation ([`merl::Interp::Trilinear`]), at the pixels of a [`LobeMap`].
//!
//! [`LuminanceTable`] is the table reduced to one luminance per cell, read by its own copy of
//! `merl`'s trilinear lookup: the lookup is linear in the cell values, so wherever the eight
//! corners of a pair hold data it returns exactly the luminance of `merl`'s RGB lookup (to
//! rounding; the tests hold it to 1e-12) while reading a third of the memory and computing the
//! angles from `wi + wo` by arithmetic and the crate's own `atan2`, many pairs in one vectorized
//! loop ([`LuminanceTable::lookup_many`], crate docs, "Angles").
//!
//! Where corners hold no data (configurations below the horizon, only near it) the two differ on
//! purpose. `merl` leaves those corners out and renormalizes, which holds the lobe flat across
//! the last cell before the horizon: an edge in the lobe's slope that a narrow lobe reaching
//! the horizon shows as detail at the analysis grid's limit, at any grid size. Here the cells
//! without data are continued instead ([`LuminanceTable::new`]): along `theta_d`, the axis on
//! which a configuration sinks below the horizon, linearly from the last two cells with data,
//! and never below 0, so the lookup carries the lobe's slope up to the horizon. A pair only
//! ever reads them across its last cell; pairs below the horizon are never looked up.

use std::f64::consts::FRAC_2_PI;

use glam::DVec3;
use merl::{Dims, MerlTable};

use crate::atan::atan2;
use crate::param::{LobeMap, Sample};

/// A MERL table reduced to the luminance of each cell, in 1/sr, with the cells that hold no data
/// continued (module docs); NaN only in a `(theta_h, phi_d)` column that holds no data at all.
#[derive(Clone)]
pub struct LuminanceTable {
    dims: Dims,
    luminance: Vec<f64>,
    /// Whether every cell holds a value (no NaN); all are `>= 0`.
    complete: bool,
}

impl std::fmt::Debug for LuminanceTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LuminanceTable").field("dims", &self.dims).finish_non_exhaustive()
    }
}

impl LuminanceTable {
    pub fn new(table: &MerlTable) -> Self {
        use rayon::prelude::*;
        let dims = table.dims();
        let mut luminance = (0..dims.cells())
            .into_par_iter()
            .map(|i| table.cell_value(i).map_or(f64::NAN, color::luminance))
            .collect::<Vec<f64>>();
        continue_below_horizon(dims, &mut luminance);
        let complete = !luminance.iter().any(|v| v.is_nan());
        Self { dims, luminance, complete }
    }

    pub fn dims(&self) -> Dims {
        self.dims
    }

    /// Whether every cell holds a value: then every lookup has one.
    pub(crate) fn is_complete(&self) -> bool {
        self.complete
    }

    /// The luminance of the BRDF for a pair of unit directions, trilinear between cells as in
    /// [`merl::MerlTable::lookup`] with [`merl::Interp::Trilinear`], the cells without data
    /// continued (module docs); `None` where all eight corners are in columns without data.
    /// The angles come from the directions by arithmetic and this crate's `atan2` (crate docs,
    /// "Angles"); [`Self::lookup_libm`] is the same lookup with libm's.
    pub fn lookup(&self, wi: DVec3, wo: DVec3) -> Option<f64> {
        let [x_h, x_d, x_p] = self.grid_coords(wi, wo);
        self.trilinear(x_h, x_d, x_p)
    }

    /// [`Self::lookup`] with the angles of [`merl::half_diff`], by the system's libm `atan2`
    /// after normalizing the half vector and rotating `wi` into its frame: the reference the
    /// fast angles are held to (crate docs, "Angles").
    pub fn lookup_libm(&self, wi: DVec3, wo: DVec3) -> Option<f64> {
        let [x_h, x_d, x_p] = self.grid_coords_libm(wi, wo);
        self.trilinear(x_h, x_d, x_p)
    }

    /// [`Self::lookup`] of `wi` and each direction of `wo` into `out` (NaN for `None`): the same
    /// values, bit for bit, the angles of a block of pairs computed in one loop that the
    /// compiler vectorizes, then their trilinear reads; compiled for the best instruction set the
    /// processor has ([`Lookups`]).
    /// `block` holds the arrays of each block of lookups ([`Block`]), made once by the caller.
    ///
    /// With `mirror`, and `wi` in the `x z` plane (`wi.y == 0`), also the lookups of the mirror
    /// images `(x, -y, z)` of the directions into `mirror`, bit for bit, mostly from the same
    /// angles ([`Self::mirror_coords_many`]): a lobe image's rows `y` and `size - 1 - y`.
    pub(crate) fn lookup_many(
        &self,
        wi: DVec3,
        wo: DirectionsRef<'_>,
        out: &mut [f64],
        mirror: Option<&mut [f64]>,
        block: &mut LookupBlock,
    ) {
        assert_eq!(wo.x.len(), out.len(), "one value per direction");
        if let Some(mirror) = &mirror {
            assert!(wi.y == 0.0 && mirror.len() == out.len(), "mirror images of wi's plane, one value per direction");
        }
        pulp::Arch::new().dispatch(Lookups { table: self, wi, wo, out, mirror, block });
    }

    /// [`Self::grid_coords`] of `wi` and each direction of `wo` (at most `N`) into
    /// `block.coords`.
    #[inline(always)]
    fn grid_coords_many<const N: usize>(&self, wi: DVec3, wo: DirectionsRef<'_>, block: &mut Block<N>) {
        // Three loops, each short enough to keep its values in registers: the arguments of the
        // three angles, the angles (one atan2 per element), their grid coordinates.
        let n = wo.x.len();
        assert!(n <= N && wo.y.len() == n && wo.z.len() == n, "a block of directions");
        let Block { y, x, coords, .. } = block;
        for k in 0..n {
            let (a, b) = self.angle_arguments(wi, DVec3::new(wo.x[k], wo.y[k], wo.z[k]));
            for i in 0..3 {
                (y[i][k], x[i][k]) = (a[i], b[i]);
            }
        }
        for ((angle, &y), &x) in coords.as_flattened_mut().iter_mut().zip(y.as_flattened()).zip(x.as_flattened()) {
            *angle = atan2(y, x);
        }
        block.phi_d[..n].copy_from_slice(&coords[2][..n]);
        let [x_h, x_d, x_p] = coords;
        for ((h, d), p) in x_h[..n].iter_mut().zip(&mut x_d[..n]).zip(&mut x_p[..n]) {
            [*h, *d, *p] = self.scale(*h, *d, *p);
        }
    }

    /// `block.coords` of the mirror images `(x, -y, z)` of the directions `wo` whose coordinates
    /// it holds ([`Self::grid_coords_many`]), for a `wi` with `wi.y == 0`. Then `theta_h` and
    /// `theta_d` are the same, and so is every argument of [`Self::angle_arguments`] but `dy`,
    /// which changes sign exactly where it is not zero (`wi.y s.x` is a zero of the same sign for
    /// both, `wi.x s.y` changes sign), and so does `phi_d = atan2(dy, dx)` ([`crate::atan::atan2`]
    /// is odd in `y`, exactly): the mirror image's `x_p` is the grid coordinate of `-phi_d`.
    /// Where `dy` is zero (`s.y = 0`, or the half vector the normal: no pixel of a lobe image)
    /// `phi_d` is 0 or pi and the signs of zeros decide: the coordinates are computed afresh.
    #[inline(always)]
    fn mirror_coords_many<const N: usize>(&self, wi: DVec3, wo: DirectionsRef<'_>, block: &mut Block<N>) {
        let n = wo.x.len();
        for (x_p, &phi_d) in block.coords[2][..n].iter_mut().zip(&block.phi_d[..n]) {
            *x_p = self.scale_phi_d(-phi_d);
        }
        for k in (0..n).filter(|&k| block.y[2][k] == 0.0) {
            let coords = self.grid_coords(wi, DVec3::new(wo.x[k], -wo.y[k], wo.z[k]));
            for (c, value) in block.coords.iter_mut().zip(coords) {
                c[k] = value;
            }
        }
    }

    /// [`merl::Dims::grid_coords`] of [`merl::half_diff`]`(wi, wo)`, to the accuracy of
    /// [`crate::atan::atan2`] (crate docs, "Angles"): the steps of [`Self::grid_coords_many`]
    /// for one pair.
    #[inline(always)]
    fn grid_coords(&self, wi: DVec3, wo: DVec3) -> [f64; 3] {
        let (y, x) = self.angle_arguments(wi, wo);
        self.scale(atan2(y[0], x[0]), atan2(y[1], x[1]), atan2(y[2], x[2]))
    }

    /// The `(y, x)` whose `atan2` are `theta_h`, `theta_d` and `phi_d` of `(wi, wo)`.
    #[inline(always)]
    fn angle_arguments(&self, wi: DVec3, wo: DVec3) -> ([f64; 3], [f64; 3]) {
        let s = wi + wo;
        let rho2 = s.x * s.x + s.y * s.y;
        // theta_d is the angle between wi and h, i.e. between wi and s.
        let (cross, dot) = (wi.cross(s).length(), wi.dot(s));
        // d's x and y times rho |s| > 0; at rho = 0 (h the normal) the reference's (wi.x, wi.y).
        let length = (rho2 + s.z * s.z).sqrt();
        let normal = rho2 == 0.0;
        let dy = if normal { wi.y } else { (wi.y * s.x - wi.x * s.y) * length };
        let dx = if normal { wi.x } else { (wi.x * s.x + wi.y * s.y) * s.z - wi.z * rho2 };
        ([rho2.sqrt(), cross, dy], [s.z, dot, dx])
    }

    /// [`merl::Dims::grid_coords`] of [`merl::half_diff`]`(wi, wo)`, computed without
    /// trigonometric calls for the rotations: the half vector's own components are the cosines
    /// and sines of `theta_h` and `phi_h`.
    fn grid_coords_libm(&self, wi: DVec3, wo: DVec3) -> [f64; 3] {
        let h = (wi + wo).normalize();
        let rho = (h.x * h.x + h.y * h.y).sqrt();
        let theta_h = rho.atan2(h.z);
        let (cos_phi, sin_phi) = if rho > 0.0 { (h.x / rho, h.y / rho) } else { (1.0, 0.0) };
        // d = rotate_y(rotate_z(wi, -phi_h), -theta_h), as in merl::coords.
        let x1 = wi.x * cos_phi + wi.y * sin_phi;
        let dy = -wi.x * sin_phi + wi.y * cos_phi;
        let (cos_t, sin_t) = (h.z, rho);
        let dx = x1 * cos_t - wi.z * sin_t;
        let dz = x1 * sin_t + wi.z * cos_t;
        let theta_d = (dx * dx + dy * dy).sqrt().atan2(dz);
        let phi_d = dy.atan2(dx);
        self.scale(theta_h, theta_d, phi_d)
    }

    /// The grid coordinates of the angles, as [`merl::Dims::grid_coords`].
    #[inline(always)]
    fn scale(&self, theta_h: f64, theta_d: f64, phi_d: f64) -> [f64; 3] {
        let d = self.dims;
        let x_h = (theta_h.max(0.0) * FRAC_2_PI).sqrt() * d.n_theta_h as f64;
        let x_d = theta_d * FRAC_2_PI * d.n_theta_d as f64;
        [x_h, x_d, self.scale_phi_d(phi_d)]
    }

    /// [`Self::scale`]'s grid coordinate of `phi_d`.
    #[inline(always)]
    fn scale_phi_d(&self, phi_d: f64) -> f64 {
        let d = self.dims;
        let range = d.phi_d_range();
        let phi_d = if phi_d < 0.0 { phi_d + range } else { phi_d };
        phi_d * (d.n_phi_d as f64 / range)
    }

    /// The same interpolation as `merl`'s `trilinear`, on one channel: corners that are NaN
    /// (a column without data) or have weight 0 are left out and the other weights renormalized.
    /// Branch-free over the eight corners.
    #[inline(always)]
    fn trilinear(&self, x_h: f64, x_d: f64, x_p: f64) -> Option<f64> {
        let (cells, weights) = self.corners(x_h, x_d, x_p);
        let (mut sum, mut weight) = (0.0, 0.0);
        for (cell, w) in cells.into_iter().zip(weights) {
            let v = self.luminance[cell];
            // A NaN (no data) corner contributes nothing; nor does a zero weight.
            let w = if v.is_nan() { 0.0 } else { w };
            sum += if w == 0.0 { 0.0 } else { w * v };
            weight += w;
        }
        (weight > 0.0).then(|| sum / weight)
    }

    /// The eight cells [`Self::trilinear`] reads and their weights, in its order: the four
    /// `(theta_h, theta_d)` rows of `phi_d` values, each at `p0` then `p1` (the next cell, `p0`
    /// again across the period's end; the same row twice at the last `theta_h` or `theta_d`).
    #[inline(always)]
    fn corners(&self, x_h: f64, x_d: f64, x_p: f64) -> ([usize; 8], [f64; 8]) {
        let d = self.dims;
        let clamped = |x: f64, n: usize| {
            let x = x.clamp(0.0, (n - 1) as f64);
            let i0 = (x as usize).min(n - 1);
            (i0, usize::from(i0 + 1 < n), x - i0 as f64)
        };
        let (h0, h_step, th) = clamped(x_h, d.n_theta_h);
        let (d0, d_step, td) = clamped(x_d, d.n_theta_d);
        // `grid_coords` keeps x_p in [0, n_phi_d]; merl's rem_euclid is this subtraction there.
        let n_p = d.n_phi_d;
        let x_p = if x_p >= n_p as f64 { x_p - n_p as f64 } else { x_p };
        let p0 = (x_p as usize).min(n_p - 1);
        let (p1, tp) = (if p0 + 1 == n_p { 0 } else { p0 + 1 }, x_p - p0 as f64);
        let base = (h0 * d.n_theta_d + d0) * n_p;
        let (dh, dd) = (h_step * d.n_theta_d * n_p, d_step * n_p);
        let rows = [base, base + dd, base + dh, base + dh + dd];
        let row_weights = [(1.0 - th) * (1.0 - td), (1.0 - th) * td, th * (1.0 - td), th * td];
        let cells = std::array::from_fn(|c| rows[c / 2] + if c % 2 == 0 { p0 } else { p1 });
        let weights = std::array::from_fn(|c| row_weights[c / 2] * if c % 2 == 0 { 1.0 - tp } else { tp });
        (cells, weights)
    }

    /// [`Self::trilinear`] of a table without holes (`complete`) at a block of grid coordinates
    /// (the first `out.len()`), into `out`, bit for bit: no value is NaN and all are `>= 0`, so
    /// a zero weight's product is a zero there too, and the weights sum to about 1 (never 0). The
    /// cells and weights of every lookup first ([`Self::corners`]), then the reads, then the
    /// weighted sums corner by corner across the block (each lookup's sum in `trilinear`'s
    /// order), so that the sums vectorize and their chains of additions overlap.
    #[inline(always)]
    fn trilinear_complete_many<const N: usize>(&self, block: &mut Block<N>, out: &mut [f64]) {
        let n = out.len();
        let Block { coords, cells, weights, values, .. } = block;
        for k in 0..n {
            let (c, w) = self.corners(coords[0][k], coords[1][k], coords[2][k]);
            for corner in 0..8 {
                (cells[corner][k], weights[corner][k]) = (c[corner], w[corner]);
            }
        }
        // Every cell is in the table; the `min` says so to the compiler, which then reads a
        // vector of cells at once (a gather) instead of one checked read after another.
        let (table, last) = (&self.luminance[..], self.luminance.len() - 1);
        for (values, cells) in values.iter_mut().zip(&*cells) {
            for (v, &cell) in values[..n].iter_mut().zip(&cells[..n]) {
                *v = table[cell.min(last)];
            }
        }
        let (mut sum, mut weight) = ([0.0; N], [0.0; N]);
        for (w, v) in weights.iter().zip(&*values) {
            for (((s, t), &w), &v) in sum[..n].iter_mut().zip(&mut weight[..n]).zip(&w[..n]).zip(&v[..n]) {
                *s += w * v;
                *t += w;
            }
        }
        for ((o, &s), &t) in out.iter_mut().zip(&sum).zip(&weight) {
            *o = s / t;
        }
    }

    /// [`Self::trilinear`] at `block.coords` (the first `out.len()`) into `out`, NaN for `None`.
    #[inline(always)]
    fn trilinear_many<const N: usize>(&self, block: &mut Block<N>, out: &mut [f64]) {
        if self.complete {
            self.trilinear_complete_many(block, out);
        } else {
            let [x_h, x_d, x_p] = &block.coords;
            for (((value, &x_h), &x_d), &x_p) in out.iter_mut().zip(x_h).zip(x_d).zip(x_p) {
                *value = self.trilinear(x_h, x_d, x_p).unwrap_or(f64::NAN);
            }
        }
    }
}

/// The arrays of one block of [`LuminanceTable::lookup_many`]'s lookups, made once per lobe image
/// and overwritten block after block: each step writes the first `n` entries of an array before
/// the next reads them (made per block, their clearing took a tenth of the lookups' time).
pub(crate) struct Block<const N: usize> {
    /// The `(y, x)` of each lookup's three angles ([`LuminanceTable::angle_arguments`]).
    y: [[f64; N]; 3],
    x: [[f64; N]; 3],
    /// The angles, then their grid coordinates.
    coords: [[f64; N]; 3],
    /// The angles `phi_d` ([`LuminanceTable::mirror_coords_many`] reads them).
    phi_d: [f64; N],
    /// Each corner's cell, weight and value ([`LuminanceTable::corners`]).
    cells: [[usize; N]; 8],
    weights: [[f64; N]; 8],
    values: [[f64; N]; 8],
}

/// The lookups' block: [`Block`] of 64, which fits the first-level cache.
pub(crate) type LookupBlock = Block<64>;

impl<const N: usize> Block<N> {
    pub(crate) fn new() -> Self {
        Block {
            y: [[0.0; N]; 3],
            x: [[0.0; N]; 3],
            coords: [[0.0; N]; 3],
            phi_d: [0.0; N],
            cells: [[0; N]; 8],
            weights: [[0.0; N]; 8],
            values: [[0.0; N]; 8],
        }
    }
}

/// [`LuminanceTable::lookup_many`]'s work, as a [`pulp::WithSimd`]: its body, and the angles
/// and reads inlined into it, are compiled for the instruction set the dispatch chose (AVX-512
/// or AVX2 where present), the same operations in the same order (no fused multiply-add: the compiler
/// never contracts unasked), so the same bits on every processor.
struct Lookups<'a> {
    table: &'a LuminanceTable,
    wi: DVec3,
    wo: DirectionsRef<'a>,
    out: &'a mut [f64],
    mirror: Option<&'a mut [f64]>,
    block: &'a mut LookupBlock,
}

impl pulp::WithSimd for Lookups<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) {
        let Self { table, wi, wo, out, mut mirror, block } = self;
        let mut start = 0;
        while start < out.len() {
            let end = (start + block.cells[0].len()).min(out.len());
            let wo = wo.slice(start..end);
            table.grid_coords_many(wi, wo, block);
            table.trilinear_many(block, &mut out[start..end]);
            if let Some(mirror) = mirror.as_deref_mut() {
                table.mirror_coords_many(wi, wo, block);
                table.trilinear_many(block, &mut mirror[start..end]);
            }
            start = end;
        }
    }
}

/// Continues each `(theta_h, phi_d)` column of `luminance` (NaN where a cell holds no data)
/// past its last cell with data, linearly from the last two (or constant from a single one),
/// never below 0. The cells with data of a column are its first ones: a configuration sinks
/// below the horizon as `theta_d` grows (both directions' heights are unimodal in `theta_d` and
/// positive at 0), so the cells after the last one with data are all without.
fn continue_below_horizon(dims: Dims, luminance: &mut [f64]) {
    use rayon::prelude::*;
    let (n_d, n_p) = (dims.n_theta_d, dims.n_phi_d);
    luminance.par_chunks_exact_mut(n_d * n_p).for_each(|block| {
        for p in 0..n_p {
            let at = |d: usize| d * n_p + p;
            let Some(last) = (0..n_d).rev().find(|&d| !block[at(d)].is_nan()) else { continue };
            let value = block[at(last)];
            let slope = match last.checked_sub(1).map(|d| block[at(d)]) {
                Some(before) if !before.is_nan() => value - before,
                _ => 0.0,
            };
            for d in last + 1..n_d {
                block[at(d)] = (value + slope * (d - last) as f64).max(0.0);
            }
        }
    });
}

/// Unit vectors as three arrays of components, for loops over many of them that vectorize.
#[derive(Clone, Debug, Default)]
pub(crate) struct Directions {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
}

/// A run of [`Directions`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct DirectionsRef<'a> {
    x: &'a [f64],
    y: &'a [f64],
    z: &'a [f64],
}

impl<'a> DirectionsRef<'a> {
    fn slice(self, range: std::ops::Range<usize>) -> DirectionsRef<'a> {
        DirectionsRef { x: &self.x[range.clone()], y: &self.y[range.clone()], z: &self.z[range] }
    }
}

impl Directions {
    fn push(&mut self, w: DVec3) {
        self.x.push(w.x);
        self.y.push(w.y);
        self.z.push(w.z);
    }

    fn slice(&self, range: std::ops::Range<usize>) -> DirectionsRef<'_> {
        DirectionsRef { x: &self.x, y: &self.y, z: &self.z }.slice(range)
    }

    fn iter(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.x.iter().zip(&self.y).zip(&self.z).map(|((&x, &y), &z)| DVec3::new(x, y, z))
    }
}

/// What every pixel of a [`LobeMap`] holds ([`LobeMap::sample`]), kept compactly for the lobe
/// images of many incident directions, row by row ([`PixelRow`]).
#[derive(Clone, Debug)]
pub(crate) struct Pixels {
    len: usize,
    rows: Vec<PixelRow>,
    /// Whether each row `size - 1 - y` holds the mirror images `(x, -y, z)` of row `y`'s
    /// directions, with the same weights: [`render`] looks such pairs up together.
    mirrored: bool,
}

impl Pixels {
    /// The samples of `map`'s pixels, computed in parallel over rows. At a power-of-two size
    /// (every analysis size), row `size - 1 - y` is row `y` mirrored across the plane of
    /// incidence, bit for bit ([`LobeMap`]): only the top half is sampled.
    pub(crate) fn new(map: LobeMap) -> Self {
        use rayon::prelude::*;
        let n = map.size;
        let mirrored = map.rows_mirrored();
        let sampled = if mirrored { n / 2 } else { n };
        let mut rows: Vec<PixelRow> = (0..sampled)
            .into_par_iter()
            .map(|y| {
                let mut row = PixelRow::default();
                for x in 0..n {
                    row.push(x as u32, map.sample(x, y));
                }
                row
            })
            .collect();
        if mirrored {
            let bottom: Vec<PixelRow> = rows.par_iter().rev().map(PixelRow::mirrored).collect();
            rows.extend(bottom);
        }
        Pixels { len: n * n, rows, mirrored }
    }

    /// The number of pixels.
    pub(crate) fn len(&self) -> usize {
        self.len
    }
}

/// The pixels of one row of a [`Pixels`]: the directions of the pixels on the hemisphere, in
/// runs of consecutive pixels, and for each continued pixel below it the points of nonzero
/// weight (the terms [`Sample::eval`] sums, in its order). Pixels are numbered by their column.
#[derive(Clone, Debug, Default)]
struct PixelRow {
    /// `(first pixel, count)` of each run of direct pixels; their directions in `direct`.
    runs: Vec<(u32, u32)>,
    direct: Directions,
    /// `(pixel, end of its terms in `terms`)` of each continued pixel.
    continued: Vec<(u32, u32)>,
    /// The terms' points and weights.
    terms: Directions,
    weights: Vec<f64>,
}

impl PixelRow {
    /// Appends pixel `x`, which holds `sample`.
    fn push(&mut self, x: u32, sample: Sample) {
        match sample {
            Sample::Direct(wo) => {
                match self.runs.last_mut() {
                    Some((first, count)) if *first + *count == x => *count += 1,
                    _ => self.runs.push((x, 1)),
                }
                self.direct.push(wo);
            }
            Sample::Continued { points, weights } => {
                for (w, c) in points.into_iter().zip(weights).filter(|&(_, c)| c != 0.0) {
                    self.terms.push(w);
                    self.weights.push(c);
                }
                self.continued.push((x, self.weights.len() as u32));
            }
        }
    }

    /// The row of the mirror images `(x, -y, z)` of this row's directions, with the same
    /// weights.
    fn mirrored(&self) -> PixelRow {
        let mirror =
            |d: &Directions| Directions { x: d.x.clone(), y: d.y.iter().map(|y| -y).collect(), z: d.z.clone() };
        PixelRow {
            runs: self.runs.clone(),
            direct: mirror(&self.direct),
            continued: self.continued.clone(),
            terms: mirror(&self.terms),
            weights: self.weights.clone(),
        }
    }
}

/// The continued pixels' terms [`render`] looks up at once: a few hundred pixels (at most 4
/// terms each).
const TERMS: usize = 1024;

/// Fills `out` (row-major, `map.size^2` values) with the luminance of the BRDF at `wi` for the
/// map's pixels (`pixels`, from [`LobeMap::sample`]); NaN where the table holds no data
/// around a pair the pixel needs: [`render_fn`] of [`LuminanceTable::lookup`], bit for bit, by
/// [`LuminanceTable::lookup_many`]. For a `wi` in the `x z` plane (`wi.y == 0`, as in the frame
/// of the plane of incidence) each mirrored pair of rows is looked up together.
pub(crate) fn render(table: &LuminanceTable, wi: DVec3, pixels: &Pixels, out: &mut [f64]) {
    assert_eq!(out.len(), pixels.len, "one value per pixel");
    let n = pixels.rows.len();
    let (block, values) = (&mut LookupBlock::new(), &mut [[0.0; TERMS]; 2]);
    let mut out_rows: Vec<Option<&mut [f64]>> = out.chunks_exact_mut(n).map(Some).collect();
    for (y, row) in pixels.rows.iter().enumerate() {
        // None: rendered with the row it mirrors.
        let Some(out_row) = out_rows[y].take() else { continue };
        let m = n - 1 - y;
        let mirror = (wi.y == 0.0 && y < m && pixels.mirrored)
            .then(|| (&pixels.rows[m], out_rows[m].take().expect("a row below is not rendered yet")));
        render_row(table, wi, row, out_row, mirror, block, values);
    }
}

/// One row of [`render`] into `out` (the row's `size` values), and with `mirror`, the mirror
/// images' row ([`PixelRow::mirrored`] of this one) into its values.
fn render_row(
    table: &LuminanceTable,
    wi: DVec3,
    row: &PixelRow,
    out: &mut [f64],
    mut mirror: Option<(&PixelRow, &mut [f64])>,
    block: &mut LookupBlock,
    values: &mut [[f64; TERMS]; 2],
) {
    let mut start = 0;
    for &(first, count) in &row.runs {
        let pixels = first as usize..(first + count) as usize;
        let mirror_out = mirror.as_mut().map(|(_, out)| &mut out[pixels.clone()]);
        table.lookup_many(
            wi,
            row.direct.slice(start..start + pixels.len()),
            &mut out[pixels.clone()],
            mirror_out,
            block,
        );
        start += pixels.len();
    }
    let mut pixel = 0;
    while pixel < row.continued.len() {
        let first_term = pixel.checked_sub(1).map_or(0, |p| row.continued[p].1 as usize);
        let mut end = pixel + 1;
        while end < row.continued.len() && row.continued[end].1 as usize - first_term <= TERMS {
            end += 1;
        }
        let last_term = row.continued[end - 1].1 as usize;
        let [values, mirror_values] = values.each_mut().map(|v| &mut v[..last_term - first_term]);
        let terms = row.terms.slice(first_term..last_term);
        table.lookup_many(wi, terms, values, mirror.is_some().then_some(&mut *mirror_values), block);
        // Sample::eval's sum in its order; a term without a value (NaN) makes the sum NaN.
        let sums = |weights: &[f64], values: &[f64], out: &mut [f64]| {
            let mut term = first_term;
            for &(x, term_end) in &row.continued[pixel..end] {
                let mut sum = 0.0;
                for t in term..term_end as usize {
                    sum += weights[t] * values[t - first_term];
                }
                out[x as usize] = sum;
                term = term_end as usize;
            }
        };
        sums(&row.weights, values, out);
        if let Some((mirror_row, mirror_out)) = &mut mirror {
            sums(&mirror_row.weights, mirror_values, mirror_out);
        }
        pixel = end;
    }
}

/// [`render`] of any BRDF slice `f(wo)`: each pixel is [`Sample::eval`] of its sample.
pub(crate) fn render_fn(pixels: &Pixels, f: impl Fn(DVec3) -> Option<f64>, out: &mut [f64]) {
    assert_eq!(out.len(), pixels.len, "one value per pixel");
    for (row, out) in pixels.rows.iter().zip(out.chunks_exact_mut(pixels.rows.len())) {
        let mut directions = row.direct.iter();
        for &(first, count) in &row.runs {
            for (value, wo) in out[first as usize..][..count as usize].iter_mut().zip(directions.by_ref()) {
                *value = f(wo).unwrap_or(f64::NAN);
            }
        }
        let mut start = 0;
        let mut terms = row.terms.iter().zip(&row.weights);
        for &(x, end) in &row.continued {
            // Sample::eval: the sum of the weighted terms in order, None if any term has no value.
            let mut sum = Some(0.0);
            for (wo, &c) in terms.by_ref().take(end as usize - start) {
                sum = sum.and_then(|s| f(wo).map(|v| s + c * v));
            }
            out[x as usize] = sum.unwrap_or(f64::NAN);
            start = end as usize;
        }
    }
}

/// Replaces the NaN pixels (no data around the pair: a few pixels near the horizon at grazing
/// incidence) by the mean of their finite 4-neighbours, sweep after sweep, so that a hole reads
/// as its surroundings instead of an edge. An image with no finite pixel becomes zeros.
/// Returns the number of pixels filled. `next` is scratch space for the sweeps.
pub(crate) fn fill_holes(size: usize, image: &mut [f64], next: &mut Vec<(usize, f64)>) -> usize {
    let holes = image.iter().filter(|v| v.is_nan()).count();
    if holes == 0 {
        return 0;
    }
    if holes == image.len() {
        image.fill(0.0);
        return holes;
    }
    loop {
        next.clear();
        for y in 0..size {
            for x in 0..size {
                if !image[y * size + x].is_nan() {
                    continue;
                }
                let (mut sum, mut count) = (0.0, 0);
                let neighbours = [
                    (x > 0).then(|| y * size + x - 1),
                    (x + 1 < size).then(|| y * size + x + 1),
                    (y > 0).then(|| (y - 1) * size + x),
                    (y + 1 < size).then(|| (y + 1) * size + x),
                ];
                for v in neighbours.into_iter().flatten().map(|k| image[k]).filter(|v| !v.is_nan()) {
                    sum += v;
                    count += 1;
                }
                if count > 0 {
                    next.push((y * size + x, sum / count as f64));
                }
            }
        }
        if next.is_empty() {
            return holes;
        }
        for &(k, v) in next.iter() {
            image[k] = v;
        }
    }
}

/// The lobe image of `wi` on `map`, with holes filled: row-major, `map.size^2` luminances in
/// 1/sr (crate docs, "Lobe images").
pub fn lobe_image(table: &LuminanceTable, map: LobeMap, wi: DVec3) -> Vec<f64> {
    lobe_image_from_fn(map, |wo| table.lookup(wi, wo))
}

/// The lobe image of any BRDF slice `f(wo)` (luminance at a fixed `wi`; `None` where it has no
/// value) on `map`, with holes filled, e.g. of an analytic BRDF.
pub fn lobe_image_from_fn(map: LobeMap, mut f: impl FnMut(DVec3) -> Option<f64>) -> Vec<f64> {
    let n = map.size;
    let mut image: Vec<f64> = (0..n * n).map(|k| map.sample(k % n, k / n).eval(&mut f).unwrap_or(f64::NAN)).collect();
    fill_holes(n, &mut image, &mut Vec::new());
    image
}

#[cfg(test)]
mod tests {
    use super::*;
    use merl::analytic::Analytic;
    use merl::{Interp, MerlTable, spherical_dir};
    use rand::{Rng, SeedableRng, rngs::StdRng};

    /// The eight cells `merl`'s trilinear lookup reads for a pair.
    fn corners(dims: Dims, wi: DVec3, wo: DVec3) -> impl Iterator<Item = usize> {
        let [x_h, x_d, x_p] = dims.grid_coords(&merl::half_diff(wi, wo));
        let axis = |x: f64, n: usize| {
            let i = (x.clamp(0.0, (n - 1) as f64) as usize).min(n - 1);
            [i, (i + 1).min(n - 1)]
        };
        let p0 = (x_p as usize) % dims.n_phi_d;
        let (h, d, p) = (axis(x_h, dims.n_theta_h), axis(x_d, dims.n_theta_d), [p0, (p0 + 1) % dims.n_phi_d]);
        h.into_iter().flat_map(move |ih| {
            d.into_iter()
                .flat_map(move |id| p.into_iter().map(move |ip| (ih * dims.n_theta_d + id) * dims.n_phi_d + ip))
        })
    }

    #[test]
    fn equals_the_luminance_of_merls_trilinear_lookup_where_the_table_holds_data() {
        // A table with structure in every coordinate, and holes below the horizon.
        let table = Analytic::Ggx { alpha: 0.2, f0: [0.9, 0.5, 0.1] }.table(Dims::MERL);
        let luminance = LuminanceTable::new(&table);
        let mut rng = StdRng::seed_from_u64(3);
        let (mut compared, mut continued) = (0, 0);
        for _ in 0..200_000 {
            let mut dir = || spherical_dir(rng.random::<f64>().acos(), rng.random::<f64>() * std::f64::consts::TAU);
            let (wi, wo) = (dir(), dir());
            let got = luminance.lookup(wi, wo).expect("every column of a GGX table holds data");
            assert!(got.is_finite() && got >= 0.0, "{wi} {wo}: {got}");
            if corners(table.dims(), wi, wo).any(|c| table.cell_value(c).is_none()) {
                continued += 1;
                continue;
            }
            let expect = color::luminance(table.lookup(wi, wo, Interp::Trilinear).unwrap());
            assert!((expect - got).abs() <= 1e-12 * expect.abs().max(1e-3), "{wi} {wo}: {expect} {got}");
            compared += 1;
        }
        println!("{compared} pairs equal merl's lookup, {continued} read continued cells");
        assert!(compared > 150_000, "{compared}");
    }

    /// A random pair of directions of the upper hemisphere, uniform in solid angle.
    fn random_pair(rng: &mut StdRng) -> (DVec3, DVec3) {
        let mut dir = || spherical_dir(rng.random::<f64>().acos(), rng.random::<f64>() * std::f64::consts::TAU);
        (dir(), dir())
    }

    /// The angles of the fast lookup against libm's (crate docs, "Angles"): the grid
    /// coordinates within `1e-13` (`theta_h`'s near its pole, where the square root spacing
    /// stretches it, and `phi_d`'s, where `theta_d` is near 0 and `phi_d` is undefined, scaled by
    /// the conditioning), and the luminance within `1e-13` of the largest corner.
    #[test]
    fn fast_angles_equal_libms_to_rounding() {
        let table = Analytic::Ggx { alpha: 0.2, f0: [0.9, 0.5, 0.1] }.table(Dims::MERL);
        let luminance = LuminanceTable::new(&table);
        let mut rng = StdRng::seed_from_u64(33);
        let mut worst = [0.0f64; 4];
        for _ in 0..1_000_000 {
            let (wi, wo) = random_pair(&mut rng);
            let fast = luminance.grid_coords(wi, wo);
            let libm = luminance.grid_coords_libm(wi, wo);
            let hd = merl::half_diff(wi, wo);
            // The angles come from s = wi + wo, rounded to 1e-16, of length 2 cos(theta_d): they
            // move by 1e-16 / |s|. x_h = 90 sqrt(2 theta_h / pi) moves by 1 / sqrt(theta_h) times
            // theta_h, phi_d by 1 / sin(theta_d) times the pole's move.
            let s = 1.0f64.max((2.0 * hd.theta_d.cos()).recip());
            let scale = [
                s * 1.0f64.max((2.0 * hd.theta_h / std::f64::consts::PI).sqrt().recip()),
                s,
                s * 1.0f64.max(hd.theta_d.sin().recip()),
            ];
            for k in 0..3 {
                let mut difference = (fast[k] - libm[k]).abs();
                if k == 2 {
                    // phi_d wraps around.
                    difference = difference.min(luminance.dims.n_phi_d as f64 - difference);
                }
                worst[k] = worst[k].max(difference / scale[k]);
                assert!(difference <= 1e-13 * scale[k], "{wi} {wo}: coordinate {k}: {fast:?} vs {libm:?}");
            }
            let (a, b) = (luminance.lookup(wi, wo).unwrap(), luminance.lookup_libm(wi, wo).unwrap());
            let largest = corners(table.dims(), wi, wo).map(|c| luminance.luminance[c]).fold(0.0, f64::max);
            worst[3] = worst[3].max((a - b).abs() / largest);
            assert!((a - b).abs() <= 1e-13 * largest, "{wi} {wo}: {a} vs {b}");
        }
        println!("largest differences (x_h, x_d, x_p scaled; luminance relative to the largest corner): {worst:?}");
    }

    /// The batch lookup is the single one, bit for bit, with and without cells lacking data: the
    /// batch compiled for the instruction set chosen at run time, the single one for the
    /// baseline.
    #[test]
    fn lookup_many_is_lookup_bit_for_bit() {
        let mut table = Analytic::Ggx { alpha: 0.3, f0: [0.2, 0.5, 0.9] }.table(Dims::MERL);
        let complete = LuminanceTable::new(&table);
        assert!(complete.complete);
        // Columns without data anywhere (theta_h cells 40 to 49): lookups near them renormalize.
        let dims = table.dims();
        let mut raw = table.raw().to_vec();
        for h in 40..50 {
            for cell in h * dims.n_theta_d * dims.n_phi_d..(h + 1) * dims.n_theta_d * dims.n_phi_d {
                for channel in 0..3 {
                    raw[channel * dims.cells() + cell] = merl::NO_DATA_RAW;
                }
            }
        }
        table = MerlTable::from_raw(dims, raw).unwrap();
        let holes = LuminanceTable::new(&table);
        assert!(!holes.complete);
        let mut rng = StdRng::seed_from_u64(34);
        for luminance in [complete, holes] {
            // Any wi; and one in the x z plane, with the mirror images looked up too, among
            // them those whose dy is zero (computed afresh): s.y = 0 (wo.y = +-0) and h on the
            // normal.
            let any = random_pair(&mut rng).0;
            let in_plane = DVec3::new(any.x.hypot(any.y), 0.0, any.z);
            for (wi, mirrored) in [(any, false), (in_plane, true)] {
                let mut directions = Directions::default();
                for _ in 0..10_000 {
                    directions.push(random_pair(&mut rng).1);
                }
                // The mirror direction: h on the normal.
                directions.push(DVec3::new(-wi.x, -wi.y, wi.z));
                for y in [0.0, -0.0] {
                    // phi_d 0 and (nearer the horizon than wi) pi.
                    directions.push(DVec3::new(0.6, y, 0.8));
                    directions.push(DVec3::new(0.995, y, (1.0f64 - 0.995 * 0.995).sqrt()));
                }
                let n = directions.x.len();
                let (mut out, mut mirror) = (vec![0.0; n], vec![0.0; n]);
                let block = &mut LookupBlock::new();
                luminance.lookup_many(wi, directions.slice(0..n), &mut out, mirrored.then_some(&mut mirror[..]), block);
                let mut checked = vec![(directions.iter().collect::<Vec<_>>(), &out)];
                if mirrored {
                    checked.push((directions.iter().map(|w| DVec3::new(w.x, -w.y, w.z)).collect(), &mirror));
                }
                let (mut none, mut some) = (0, 0);
                for (directions, out) in checked {
                    for (&wo, got) in directions.iter().zip(out) {
                        let expect = luminance.lookup(wi, wo);
                        match expect {
                            Some(v) => assert_eq!(v.to_bits(), got.to_bits(), "{wi} {wo}"),
                            None => assert!(got.is_nan(), "{wi} {wo}"),
                        }
                        (none, some) = if expect.is_some() { (none, some + 1) } else { (none + 1, some) };
                    }
                }
                println!("{some} values, {none} without");
            }
        }
    }

    /// The lobe image of the batch lookups is the one of the single lookup, bit for bit: the
    /// runs of direct pixels and the continued pixels' terms (at 1024 x 1024 rows of more than
    /// one buffer of them, at 64 x 64 of less), with and without cells lacking data.
    #[test]
    fn render_is_render_fn_of_lookup_bit_for_bit() {
        let table = Analytic::Ggx { alpha: 0.1, f0: [0.9, 0.9, 0.9] }.table(Dims::MERL);
        let dims = table.dims();
        let mut raw = table.raw().to_vec();
        for cell in 60 * dims.n_theta_d * dims.n_phi_d..dims.cells() {
            for channel in 0..3 {
                raw[channel * dims.cells() + cell] = merl::NO_DATA_RAW;
            }
        }
        let holes = MerlTable::from_raw(dims, raw).unwrap();
        let tables = [table, holes].map(|table| LuminanceTable::new(&table));
        for (size, more_than_a_buffer) in [(64, false), (1024, true)] {
            let pixels = Pixels::new(LobeMap::new(size));
            assert!(pixels.mirrored, "{size}: render looks the mirrored rows up together");
            let most_terms = pixels.rows.iter().map(|row| row.weights.len()).max().unwrap();
            assert_eq!(most_terms > 1024, more_than_a_buffer, "{most_terms} terms in a row at {size}");
            for luminance in &tables {
                for theta_i in [0.1, 0.8, 1.5] {
                    let wi = spherical_dir(theta_i, 0.0);
                    let (mut fast, mut single) = (vec![0.0; pixels.len()], vec![0.0; pixels.len()]);
                    render(luminance, wi, &pixels, &mut fast);
                    render_fn(&pixels, |wo| luminance.lookup(wi, wo), &mut single);
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
                    assert_eq!(
                        bits(&fast),
                        bits(&single),
                        "{size}: theta_i {theta_i}, complete {}",
                        luminance.complete
                    );
                }
            }
        }
    }

    #[test]
    fn cells_without_data_continue_the_last_two_linearly() {
        let dims = Dims::MERL;
        let (n_d, n_p) = (dims.n_theta_d, dims.n_phi_d);
        let mut luminance = vec![f64::NAN; dims.cells()];
        // Column (0, 0): data in the first 10 cells, a line 2 + 0.5 d; column (0, 1): one cell;
        // column (1, 3): falling, reaches 0 and stays there; column (2, 2): no data.
        let (a, b, c) = (0, 1, n_d * n_p + 3);
        for d in 0..10 {
            luminance[a + d * n_p] = 2.0 + 0.5 * d as f64;
            luminance[c + d * n_p] = 10.0 - d as f64;
        }
        luminance[b] = 7.0;
        continue_below_horizon(dims, &mut luminance);
        for d in 0..n_d {
            assert_eq!(luminance[a + d * n_p], 2.0 + 0.5 * d as f64, "column a, cell {d}");
            assert_eq!(luminance[b + d * n_p], 7.0, "column b, cell {d}");
            assert_eq!(luminance[c + d * n_p], (10.0 - d as f64).max(0.0), "column c, cell {d}");
            assert!(luminance[2 * n_d * n_p + 2 + d * n_p].is_nan(), "column (2, 2) stays without data");
        }
    }

    #[test]
    fn holes_take_their_neighbours_values() {
        let mut image = vec![2.0, f64::NAN, f64::NAN, 4.0];
        assert_eq!(fill_holes(2, &mut image, &mut Vec::new()), 2);
        assert_eq!(image, [2.0, 3.0, 3.0, 4.0]);
        let mut all = vec![f64::NAN; 9];
        fill_holes(3, &mut all, &mut Vec::new());
        assert!(all.iter().all(|v| *v == 0.0));
    }
}
