//! The MERL `.binary` table: layout, validation and lookup.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use crate::coords::{HalfDiff, half_diff};
use crate::error::Error;

/// Channel scales of the MERL files: a stored value times its scale is the BRDF in 1/sr.
pub const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// Raw value written into the cells of a table that hold no data (below the horizon).
/// Readers treat any negative value as no data, whatever its magnitude.
pub const NO_DATA_RAW: f64 = -1.0;

/// Size of the header: three little-endian `i32`.
pub const HEADER_BYTES: usize = 12;

/// The largest header dimension read as a table of another resolution rather than as a file
/// that is not a MERL table at all. A table of 1024^3 cells would be 24 GiB; the first bytes of a
/// text or image file, read as integers, are in the millions or negative.
pub const PLAUSIBLE_DIM: i32 = 1024;

/// The resolutions of a table. Only MERL's own are accepted: 90 x 90 x 180, or 360 in `phi_d`
/// for a table that covers `phi_d` in `[0, 2 pi)` instead of relying on reciprocity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dims {
    pub n_theta_h: usize,
    pub n_theta_d: usize,
    pub n_phi_d: usize,
}

impl Dims {
    pub const MERL: Dims = Dims { n_theta_h: 90, n_theta_d: 90, n_phi_d: 180 };
    pub const MERL_FULL_PHI: Dims = Dims { n_theta_h: 90, n_theta_d: 90, n_phi_d: 360 };

    /// Checks header values read from a file (as `i32`, before anything is allocated).
    ///
    /// Dimensions that no table could have (zero, negative, or beyond [`PLAUSIBLE_DIM`]) mean
    /// the file is something else: the error then starts with `not a MERL table`, so that a
    /// text file is not reported as a table of an odd size.
    pub fn from_header(header: [i32; 3]) -> Result<Dims, Error> {
        let [h, d, p] = header;
        if h != 90 || d != 90 || (p != 180 && p != 360) {
            let detail = format!("unsupported dimensions {h} x {d} x {p}: expected 90 x 90 x 180 (or 360 in phi_d)");
            let plausible = header.iter().all(|n| (1..=PLAUSIBLE_DIM).contains(n));
            return Err(Error::Invalid(if plausible { detail } else { format!("not a MERL table: {detail}") }));
        }
        Ok(Dims { n_theta_h: 90, n_theta_d: 90, n_phi_d: p as usize })
    }

    /// Cells per channel.
    pub const fn cells(&self) -> usize {
        self.n_theta_h * self.n_theta_d * self.n_phi_d
    }

    /// Size of a file of these dimensions.
    pub const fn file_bytes(&self) -> u64 {
        HEADER_BYTES as u64 + 3 * 8 * self.cells() as u64
    }

    /// Flat index of a cell within a channel (the MERL order).
    pub fn index(&self, c: Cell) -> usize {
        (c.theta_h * self.n_theta_d + c.theta_d) * self.n_phi_d + c.phi_d
    }

    /// Inverse of [`Dims::index`].
    pub fn cell(&self, index: usize) -> Cell {
        Cell {
            theta_h: index / (self.n_theta_d * self.n_phi_d),
            theta_d: index / self.n_phi_d % self.n_theta_d,
            phi_d: index % self.n_phi_d,
        }
    }

    /// The range of `phi_d` that the table covers: `pi` (reciprocity folds the rest) or `2 pi`.
    pub fn phi_d_range(&self) -> f64 {
        if self.n_phi_d == 360 { 2.0 * PI } else { PI }
    }

    /// Continuous grid coordinates of a configuration: sample `i` sits at coordinate `i`,
    /// the lower edge of cell `i`. `theta_h` uses MERL's square-root spacing.
    pub fn grid_coords(&self, hd: &HalfDiff) -> [f64; 3] {
        let x_h = (hd.theta_h.max(0.0) / FRAC_PI_2).sqrt() * self.n_theta_h as f64;
        let x_d = hd.theta_d / FRAC_PI_2 * self.n_theta_d as f64;
        let range = self.phi_d_range();
        let phi_d = if hd.phi_d < 0.0 { hd.phi_d + range } else { hd.phi_d };
        let x_p = phi_d / range * self.n_phi_d as f64;
        [x_h, x_d, x_p]
    }

    /// The cell the reference MERL reader picks: truncate each grid coordinate, clamp to range.
    pub fn nearest_cell(&self, hd: &HalfDiff) -> Cell {
        let [x_h, x_d, x_p] = self.grid_coords(hd);
        let clamp = |x: f64, n: usize| (x.max(0.0) as usize).min(n - 1);
        Cell {
            theta_h: clamp(x_h, self.n_theta_h),
            theta_d: clamp(x_d, self.n_theta_d),
            phi_d: clamp(x_p, self.n_phi_d),
        }
    }

    /// `theta_h` at grid coordinate `x` along its axis (the inverse of [`Dims::grid_coords`]'s
    /// square-root spacing): `(x / n_theta_h)^2 pi / 2`; cell `i` spans `[i, i + 1)`.
    pub fn theta_h_at(&self, x: f64) -> f64 {
        let u = x / self.n_theta_h as f64;
        u * u * FRAC_PI_2
    }

    /// `theta_d` at grid coordinate `x` along its axis: `x / n_theta_d pi / 2`.
    pub fn theta_d_at(&self, x: f64) -> f64 {
        x / self.n_theta_d as f64 * FRAC_PI_2
    }

    /// The configuration at which cell `c` is sampled: its lower edge.
    pub fn sample_point(&self, c: Cell) -> HalfDiff {
        HalfDiff {
            theta_h: self.theta_h_at(c.theta_h as f64),
            phi_h: 0.0,
            theta_d: self.theta_d_at(c.theta_d as f64),
            phi_d: c.phi_d as f64 / self.n_phi_d as f64 * self.phi_d_range(),
        }
    }
}

/// A cell of the table, by index along each axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Cell {
    pub theta_h: usize,
    pub theta_d: usize,
    pub phi_d: usize,
}

/// How [`MerlTable::lookup`] reads the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interp {
    /// The cell the reference MERL reader picks ([`Dims::nearest_cell`]).
    #[default]
    Nearest,
    /// Trilinear between samples placed at the lower edges of their cells. `theta_h` and
    /// `theta_d` clamp at the last sample; `phi_d` wraps around (it is periodic). Corners that
    /// hold no data are left out and the remaining weights renormalized; if all eight hold no
    /// data, the result is no data.
    Trilinear,
}

/// A MERL BRDF table. Values are stored raw (as in the file); [`SCALE`] converts them to 1/sr.
#[derive(Clone, PartialEq)]
pub struct MerlTable {
    dims: Dims,
    /// `3 * dims.cells()` values, all red, then all green, then all blue.
    raw: Vec<f64>,
}

impl std::fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MerlTable").field("dims", &self.dims).finish_non_exhaustive()
    }
}

impl MerlTable {
    /// A table from raw channel-major values. Fails if the length does not match `dims` or a
    /// value is NaN or infinite.
    pub fn from_raw(dims: Dims, raw: Vec<f64>) -> Result<MerlTable, Error> {
        if raw.len() != 3 * dims.cells() {
            return Err(Error::Invalid(format!(
                "expected {} values for {} x {} x {}, found {}",
                3 * dims.cells(),
                dims.n_theta_h,
                dims.n_theta_d,
                dims.n_phi_d,
                raw.len()
            )));
        }
        if let Some(pos) = raw.iter().position(|v| !v.is_finite()) {
            let channel = ["red", "green", "blue"][pos / dims.cells()];
            let cell = dims.cell(pos % dims.cells());
            return Err(Error::Invalid(format!(
                "{} value in the {channel} channel at cell (theta_h {}, theta_d {}, phi_d {})",
                if raw[pos].is_nan() { "NaN" } else { "infinite" },
                cell.theta_h,
                cell.theta_d,
                cell.phi_d
            )));
        }
        Ok(MerlTable { dims, raw })
    }

    /// Samples `f(sample point)` at every cell. `f` returns the BRDF in 1/sr, or `None` where
    /// there is no data (stored as [`NO_DATA_RAW`]).
    pub fn from_fn(dims: Dims, f: impl Fn(&HalfDiff) -> Option<[f64; 3]> + Sync) -> MerlTable {
        use rayon::prelude::*;
        let cells = dims.cells();
        let values: Vec<[f64; 3]> = (0..cells)
            .into_par_iter()
            .map(|index| match f(&dims.sample_point(dims.cell(index))) {
                Some(rgb) => [rgb[0] / SCALE[0], rgb[1] / SCALE[1], rgb[2] / SCALE[2]],
                None => [NO_DATA_RAW; 3],
            })
            .collect();
        let mut raw = vec![0.0; 3 * cells];
        for (index, rgb) in values.iter().enumerate() {
            for (c, v) in rgb.iter().enumerate() {
                raw[c * cells + index] = *v;
            }
        }
        MerlTable::from_raw(dims, raw).expect("analytic BRDF produced a NaN or infinite value")
    }

    pub fn dims(&self) -> Dims {
        self.dims
    }

    /// Raw stored values, channel-major, as in the file.
    pub fn raw(&self) -> &[f64] {
        &self.raw
    }

    /// Raw stored values of one cell (flat index within a channel).
    pub fn raw_cell(&self, index: usize) -> [f64; 3] {
        let n = self.dims.cells();
        [self.raw[index], self.raw[n + index], self.raw[2 * n + index]]
    }

    /// BRDF of one cell in 1/sr, or `None` if it holds no data (any channel negative).
    pub fn cell_value(&self, index: usize) -> Option<[f64; 3]> {
        let r = self.raw_cell(index);
        if r.iter().any(|v| *v < 0.0) {
            return None;
        }
        Some([r[0] * SCALE[0], r[1] * SCALE[1], r[2] * SCALE[2]])
    }

    /// Number of cells that hold no data.
    pub fn no_data_cells(&self) -> usize {
        (0..self.dims.cells()).filter(|&i| self.cell_value(i).is_none()).count()
    }

    /// BRDF in 1/sr for a direction pair, or `None` where the table holds no data.
    pub fn lookup(&self, wi: DVec3, wo: DVec3, interp: Interp) -> Option<[f64; 3]> {
        self.lookup_half_diff(&half_diff(wi, wo), interp)
    }

    pub fn lookup_half_diff(&self, hd: &HalfDiff, interp: Interp) -> Option<[f64; 3]> {
        match interp {
            Interp::Nearest => self.cell_value(self.dims.index(self.dims.nearest_cell(hd))),
            Interp::Trilinear => self.trilinear(hd),
        }
    }

    fn trilinear(&self, hd: &HalfDiff) -> Option<[f64; 3]> {
        let d = self.dims;
        let [x_h, x_d, x_p] = d.grid_coords(hd);
        // (lower index, upper index, weight of the upper) along one clamped axis.
        let clamped = |x: f64, n: usize| {
            let x = x.clamp(0.0, (n - 1) as f64);
            let i0 = (x as usize).min(n - 1);
            ((i0, (i0 + 1).min(n - 1)), x - i0 as f64)
        };
        let ((h0, h1), th) = clamped(x_h, d.n_theta_h);
        let ((d0, d1), td) = clamped(x_d, d.n_theta_d);
        let x_p = x_p.rem_euclid(d.n_phi_d as f64);
        let p0 = (x_p as usize).min(d.n_phi_d - 1);
        let (p1, tp) = ((p0 + 1) % d.n_phi_d, x_p - p0 as f64);

        let mut sum = [0.0; 3];
        let mut weight = 0.0;
        for (ih, wh) in [(h0, 1.0 - th), (h1, th)] {
            for (id, wd) in [(d0, 1.0 - td), (d1, td)] {
                for (ip, wp) in [(p0, 1.0 - tp), (p1, tp)] {
                    let w = wh * wd * wp;
                    if w == 0.0 {
                        continue;
                    }
                    let cell = Cell { theta_h: ih, theta_d: id, phi_d: ip };
                    if let Some(v) = self.cell_value(d.index(cell)) {
                        for c in 0..3 {
                            sum[c] += w * v[c];
                        }
                        weight += w;
                    }
                }
            }
        }
        (weight > 0.0).then(|| sum.map(|s| s / weight))
    }

    /// Parses a whole file held in memory.
    pub fn parse(bytes: &[u8]) -> Result<MerlTable, Error> {
        let header = parse_header(bytes)?;
        let dims = Dims::from_header(header)?;
        check_size(dims, bytes.len() as u64)?;
        let raw = bytes[HEADER_BYTES..]
            .chunks_exact(8)
            .map(|b| f64::from_le_bytes(b.try_into().expect("chunks of 8")))
            .collect();
        MerlTable::from_raw(dims, raw)
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.dims.file_bytes() as usize);
        for n in [self.dims.n_theta_h, self.dims.n_theta_d, self.dims.n_phi_d] {
            out.extend_from_slice(&(n as i32).to_le_bytes());
        }
        for v in &self.raw {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }
}

/// Reads the three header integers; fails on a short header.
pub fn parse_header(bytes: &[u8]) -> Result<[i32; 3], Error> {
    if let Some(format) = other_format(bytes) {
        return Err(Error::Invalid(format!(
            "not a MERL table: this is {format} (a MERL .binary table starts with its dimensions, 90 90 180, as \
             32-bit integers)"
        )));
    }
    if bytes.len() < HEADER_BYTES {
        return Err(Error::Invalid(format!("truncated header: expected {HEADER_BYTES} bytes, found {}", bytes.len())));
    }
    let int = |i: usize| i32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().expect("4 bytes"));
    Ok([int(0), int(1), int(2)])
}

/// The kind of file `bytes` start like, among those a person may give for a table by mistake
/// (the toolchain's own formats and common pictures); `None` for anything else. No MERL header
/// starts like any of them.
pub fn other_format(bytes: &[u8]) -> Option<&'static str> {
    const MAGICS: [(&[u8], &str); 9] = [
        (b"\x89PNG\r\n\x1a\n", "a PNG image"),
        (&[0x76, 0x2f, 0x31, 0x01], "an OpenEXR image"),
        (b"#?", "a Radiance HDR image"),
        (b"BRDFASET", "an asset of this toolchain (asset-info shows what it holds)"),
        (b"\xabKTX 20\xbb\r\n\x1a\n", "a KTX2 texture"),
        (&[0xff, 0xd8, 0xff], "a JPEG image"),
        (b"GIF8", "a GIF image"),
        (&[0x1f, 0x8b], "a gzip archive (decompress it first)"),
        (b"PK\x03\x04", "a zip archive (extract it first)"),
    ];
    let text = bytes.iter().find(|b| !b.is_ascii_whitespace()).is_some_and(|&b| b == b'{' || b == b'[');
    MAGICS
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map(|(_, name)| *name)
        .or(text.then_some("JSON text (a bake's manifest.json names its table in material.source_path)"))
}

/// Checks that the size of a file agrees with its header.
pub fn check_size(dims: Dims, file_bytes: u64) -> Result<(), Error> {
    let expected = dims.file_bytes();
    if file_bytes != expected {
        let what = if file_bytes < expected { "truncated payload" } else { "trailing bytes" };
        return Err(Error::Invalid(format!(
            "{what}: a {} x {} x {} table is {expected} bytes, found {file_bytes}",
            dims.n_theta_h, dims.n_theta_d, dims.n_phi_d
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A table of another size is "unsupported"; a header no table could have (the first bytes
    /// of a text file, a negative or zero size) is "not a MERL table", with the same detail.
    #[test]
    fn implausible_headers_are_not_merl_tables() {
        let message = |header: [i32; 3]| Dims::from_header(header).unwrap_err().to_string();
        assert_eq!(
            message([90, 90, 90]),
            "unsupported dimensions 90 x 90 x 90: expected 90 x 90 x 180 (or 360 in phi_d)"
        );
        assert!(message([1024, 1, 1024]).starts_with("unsupported dimensions 1024 x 1 x 1024"));
        let text = parse_header(b"# BRDF toolchain").unwrap();
        for header in [text, [-90, 90, 180], [0, 90, 180], [90, 90, 1025]] {
            let m = message(header);
            let detail = format!("unsupported dimensions {} x {} x {}: expected", header[0], header[1], header[2]);
            assert!(m.starts_with(&format!("not a MERL table: {detail}")), "{m}");
        }
        assert_eq!(Dims::from_header([90, 90, 360]).unwrap(), Dims::MERL_FULL_PHI);
    }

    /// A file of another known kind says what it is instead of quoting a header no table has.
    #[test]
    fn other_formats_are_named() {
        let png = b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
        let message = parse_header(png).unwrap_err().to_string();
        assert!(message.starts_with("not a MERL table: this is a PNG image"), "{message}");
        for (bytes, name) in [
            (&b"BRDFASET\x01\0\0\0"[..], "an asset"),
            (b"#?RADIANCE\n", "a Radiance HDR image"),
            (&[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 0, 0, 0, 0], "an OpenEXR image"),
            (b"  {\"manifest_version\": 2}", "JSON text"),
        ] {
            let message = MerlTable::parse(bytes).unwrap_err().to_string();
            assert!(message.contains(name), "{message}");
        }
        let table = MerlTable::from_raw(Dims::MERL, vec![0.5; 3 * Dims::MERL.cells()]).unwrap().to_bytes();
        assert_eq!(other_format(&table), None);
    }

    #[test]
    fn index_round_trip() {
        for dims in [Dims::MERL, Dims::MERL_FULL_PHI] {
            for index in [0, 1, 179, 180, 12345, dims.cells() - 1] {
                let c = dims.cell(index);
                assert_eq!(dims.index(c), index);
                assert!(c.theta_h < 90 && c.theta_d < 90 && c.phi_d < dims.n_phi_d);
            }
        }
    }

    #[test]
    fn sample_points_fall_in_their_own_cell() {
        // The sample of cell i sits at its lower edge, so the nearest lookup of a point just
        // above it returns cell i: the two conventions agree.
        let d = Dims::MERL;
        for index in (0..d.cells()).step_by(997) {
            let c = d.cell(index);
            let mut hd = d.sample_point(c);
            hd.theta_h = hd.theta_h * (1.0 + 1e-9) + 1e-15;
            hd.theta_d = hd.theta_d * (1.0 + 1e-9) + 1e-15;
            hd.phi_d = hd.phi_d * (1.0 + 1e-9) + 1e-15;
            assert_eq!(d.nearest_cell(&hd), c);
        }
    }

    #[test]
    fn negative_phi_d_folds_by_reciprocity() {
        let d = Dims::MERL;
        let hd = HalfDiff { theta_h: 0.3, phi_h: 0.0, theta_d: 0.4, phi_d: -0.25 };
        let folded = HalfDiff { phi_d: -0.25 + PI, ..hd };
        assert_eq!(d.nearest_cell(&hd), d.nearest_cell(&folded));
        let full = Dims::MERL_FULL_PHI;
        let folded_full = HalfDiff { phi_d: -0.25 + 2.0 * PI, ..hd };
        assert_eq!(full.nearest_cell(&hd), full.nearest_cell(&folded_full));
        assert_eq!(full.nearest_cell(&hd).phi_d, ((2.0 * PI - 0.25) / (2.0 * PI) * 360.0) as usize);
    }

    #[test]
    fn trilinear_reproduces_samples_and_is_linear_between() {
        // A table whose raw value is a linear function of the grid coordinates is reproduced
        // exactly by trilinear interpolation away from the clamped and wrapped edges.
        let d = Dims::MERL;
        let lin = |c: Cell| 1.0 + c.theta_h as f64 * 3.0 + c.theta_d as f64 * 5.0 + c.phi_d as f64;
        let raw: Vec<f64> = (0..3).flat_map(|_| (0..d.cells()).map(|i| lin(d.cell(i)))).collect();
        let t = MerlTable::from_raw(d, raw).unwrap();
        for (xh, xd, xp) in [(10.25, 20.5, 30.75), (3.0, 4.0, 5.0), (88.9, 0.1, 178.5)] {
            let u = xh / 90.0;
            let hd = HalfDiff {
                theta_h: u * u * FRAC_PI_2,
                phi_h: 0.0,
                theta_d: xd / 90.0 * FRAC_PI_2,
                phi_d: xp / 180.0 * PI,
            };
            let v = t.lookup_half_diff(&hd, Interp::Trilinear).unwrap();
            let expect = (1.0 + xh * 3.0 + xd * 5.0 + xp) * SCALE[0];
            assert!((v[0] - expect).abs() < 1e-9 * expect, "{xh} {xd} {xp}: {} vs {expect}", v[0]);
        }
    }

    #[test]
    fn trilinear_skips_no_data_corners() {
        let d = Dims::MERL;
        let mut raw = vec![2.0; 3 * d.cells()];
        let hole = d.index(Cell { theta_h: 10, theta_d: 10, phi_d: 10 });
        for c in 0..3 {
            raw[c * d.cells() + hole] = NO_DATA_RAW;
        }
        let t = MerlTable::from_raw(d, raw).unwrap();
        let mut hd = d.sample_point(Cell { theta_h: 10, theta_d: 10, phi_d: 10 });
        hd.theta_h *= 1.0 + 1e-6;
        assert_eq!(t.lookup_half_diff(&hd, Interp::Nearest), None);
        let v = t.lookup_half_diff(&hd, Interp::Trilinear).unwrap();
        assert!((v[0] - 2.0 * SCALE[0]).abs() < 1e-15, "no-data leaked: {v:?}");
    }

    #[test]
    fn rejects_non_finite_values_with_their_place() {
        let d = Dims::MERL;
        let mut raw = vec![1.0; 3 * d.cells()];
        raw[d.cells() + 181] = f64::NAN;
        let err = MerlTable::from_raw(d, raw).unwrap_err().to_string();
        assert!(err.contains("NaN") && err.contains("green") && err.contains("theta_d 1"), "{err}");
    }

    #[test]
    fn bytes_round_trip() {
        let t = MerlTable::from_fn(Dims::MERL_FULL_PHI, |hd| {
            (hd.theta_d < 1.2).then_some([hd.theta_h, hd.theta_d, hd.phi_d])
        });
        let bytes = t.to_bytes();
        assert_eq!(bytes.len() as u64, Dims::MERL_FULL_PHI.file_bytes());
        assert_eq!(MerlTable::parse(&bytes).unwrap(), t);
    }
}
