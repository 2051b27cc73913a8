//! The serialized types: what every asset says about where it came from, the kinds of asset,
//! and each kind's payload. Changing any of them changes the format (see
//! `data-schema/README.md`): bump [`crate::FORMAT_VERSION`] and keep a reader for the old layout.

use serde::{Deserialize, Serialize};

use crate::error::Error;

/// Where an asset came from: enough to tell whether it is stale and to bake it again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The source file's name as the tool saw it (a file name, not a full path, so that the
    /// asset does not depend on where the bake ran).
    pub source_name: String,
    /// SHA-256 of the source file's bytes.
    pub source_sha256: [u8; 32],
    /// The tool that wrote the asset, e.g. `merl-info`.
    pub tool: String,
    pub tool_version: String,
    /// The tool's settings that shaped the output, as `(name, value)` in the tool's order.
    pub parameters: Vec<(String, String)>,
}

impl Provenance {
    /// The provenance of an asset that `tool` (name and version) made from the file at `source`
    /// with `parameters`: the file's name and the SHA-256 of its bytes, read in a stream.
    pub fn of_source(
        source: &std::path::Path,
        tool: &str,
        tool_version: &str,
        parameters: Vec<(String, String)>,
    ) -> std::io::Result<Provenance> {
        Ok(Provenance {
            source_name: source.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
            source_sha256: crate::files::sha256_file(source)?,
            tool: tool.to_string(),
            tool_version: tool_version.to_string(),
            parameters,
        })
    }
}

/// The kinds of asset. The code is what the header stores; codes are never reused.
///
/// In JSON (the bake manifest) a kind is written by [`AssetKind::name`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AssetKind {
    /// [`MaterialInfo`]: the validation summary of a MERL table.
    MaterialInfo = 1,
    /// [`ImportanceSamples`]: importance-sampling tables and precomputed samples of a material.
    ImportanceSamples = 2,
    /// [`PrefilteredEnvmap`]: an environment map convolved with Phong lobes, and its mip chain.
    PrefilteredEnvmap = 3,
    /// [`BandwidthAtlas`]: the angular bandwidth of a BRDF's lobes, packed in tiles.
    BandwidthAtlas = 4,
    /// [`BandwidthPca`]: a bandwidth atlas compressed by PCA.
    BandwidthPca = 5,
    /// [`LayerSelection`]: which Phong layer of a prefiltered environment serves each view of a
    /// material.
    LayerSelection = 6,
    /// [`BandwidthRows`]: a bandwidth atlas whose tiles repeat along each row (an isotropic
    /// material), stored one tile per row.
    BandwidthRows = 7,
    /// [`WaveletBrdf`]: a BRDF encoded in Haar wavelets on the sphere, thresholded and optionally
    /// quantized (Claustres et al. 2007).
    WaveletBrdf = 8,
}

impl AssetKind {
    /// Every kind this build knows, in code order.
    pub const ALL: [AssetKind; 8] = [
        AssetKind::MaterialInfo,
        AssetKind::ImportanceSamples,
        AssetKind::PrefilteredEnvmap,
        AssetKind::BandwidthAtlas,
        AssetKind::BandwidthPca,
        AssetKind::LayerSelection,
        AssetKind::BandwidthRows,
        AssetKind::WaveletBrdf,
    ];

    /// The number stored in the header.
    pub fn code(self) -> u32 {
        self as u32
    }

    /// The kind stored as `code`; an unknown code is [`Error::UnknownKind`].
    pub fn from_code(code: u32) -> Result<AssetKind, Error> {
        AssetKind::ALL.into_iter().find(|kind| kind.code() == code).ok_or(Error::UnknownKind { code })
    }

    /// The kebab-case name used in the bake manifest and by `asset-info`.
    pub fn name(self) -> &'static str {
        match self {
            AssetKind::MaterialInfo => "material-info",
            AssetKind::ImportanceSamples => "importance-samples",
            AssetKind::PrefilteredEnvmap => "prefiltered-envmap",
            AssetKind::BandwidthAtlas => "bandwidth-atlas",
            AssetKind::BandwidthPca => "bandwidth-pca",
            AssetKind::LayerSelection => "layer-selection",
            AssetKind::BandwidthRows => "bandwidth-rows",
            AssetKind::WaveletBrdf => "wavelet-brdf",
        }
    }
}

impl std::fmt::Display for AssetKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The validation summary of a MERL BRDF table (payload of [`AssetKind::MaterialInfo`]).
///
/// BRDF values are in 1/sr and only cells that hold data enter the statistics. The three
/// albedo vectors are parallel: entry `i` of each belongs to the angle `albedo_theta_o[i]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MaterialInfo {
    /// Table resolution as `[theta_h, theta_d, phi_d]`.
    pub dims: [u32; 3],
    /// Cells whose raw value marks them as holding no data.
    pub no_data_cells: u64,
    /// Red, green, blue.
    pub channel_min: [f64; 3],
    pub channel_max: [f64; 3],
    pub channel_mean: [f64; 3],
    /// The value of the cell of largest luminance.
    pub peak_rgb: [f64; 3],
    /// That cell's index as `[theta_h, theta_d, phi_d]`.
    pub peak_cell: [u32; 3],
    /// Outgoing elevations of the albedo table, radians.
    pub albedo_theta_o: Vec<f64>,
    /// Directional albedo (red, green, blue) at each of those angles.
    pub albedo_rgb: Vec<[f64; 3]>,
    /// Fraction of the quadrature's samples at each angle that fell on cells without data.
    pub albedo_no_data_fraction: Vec<f64>,
}

impl MaterialInfo {
    /// The invariants a reader relies on that the types cannot express.
    fn check(&self) -> Result<(), String> {
        let angles = self.albedo_theta_o.len();
        if self.albedo_rgb.len() != angles || self.albedo_no_data_fraction.len() != angles {
            return Err(format!(
                "material info has {angles} albedo angles but {} albedo values and {} no-data \
                 fractions",
                self.albedo_rgb.len(),
                self.albedo_no_data_fraction.len()
            ));
        }
        // Statistics of a table whose cells are finite (the reader refuses others): finite,
        // no-data fractions within [0, 1], albedo angles within the hemisphere.
        let values = [self.channel_min, self.channel_max, self.channel_mean, self.peak_rgb].into_iter().flatten();
        if let Some(v) = values.chain(self.albedo_rgb.iter().flatten().copied()).find(|v| !v.is_finite()) {
            return Err(format!("material info: a statistic or an albedo is {v:e}, not finite"));
        }
        if let Some(f) = self.albedo_no_data_fraction.iter().find(|f| !(0.0..=1.0).contains(*f)) {
            return Err(format!("material info: a no-data fraction is {f:e}, outside [0, 1]"));
        }
        if let Some(t) = self.albedo_theta_o.iter().find(|t| !(0.0..=std::f64::consts::FRAC_PI_2).contains(*t)) {
            return Err(format!("material info: an albedo angle is {t:e} radians, outside [0, pi / 2]"));
        }
        Ok(())
    }
}

/// Importance-sampling tables of a MERL material and precomputed samples (payload of
/// [`AssetKind::ImportanceSamples`], written by `merl-importance`). `data-schema/README.md`
/// describes the parameterization and how a renderer reads it.
///
/// With `n_slices = theta_o.len()`, `rows = theta_h_edges.len() - 1`, `cols = n_phi_h`:
/// - `samples`: `n_slices * n_vectors * n_samples` texels `(wi.x, wi.y, wi.z, pdf)`, slice-major,
///   then vector, then sample (a texture `n_samples` wide and `n_slices * n_vectors` tall);
///   `wi` for `phi_o = 0`, `pdf` per unit solid angle, 0 for a sample that reflects nowhere.
/// - `marginal_cdf`: per slice, `rows + 1` values from 0 to 1 over the `theta_h` rows.
/// - `conditional_cdf`: per slice and row, `cols + 1` values from 0 to 1 over the `phi_h` sectors.
/// - `h_density`: per slice and row, `cols` densities per unit solid angle of the half vector;
///   the density of a direction `wi` is `h_density[cell of h] / (4 wo . h)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImportanceSamples {
    /// Outgoing elevation of each slice, radians.
    pub theta_o: Vec<f64>,
    pub n_vectors: u32,
    pub n_samples: u32,
    /// `theta_h` at the row edges, radians, from 0 to pi/2.
    pub theta_h_edges: Vec<f64>,
    /// Sectors of `phi_h` over `[0, 2 pi)`.
    pub n_phi_h: u32,
    pub samples: Vec<[f32; 4]>,
    pub marginal_cdf: Vec<f32>,
    pub conditional_cdf: Vec<f32>,
    pub h_density: Vec<f32>,
}

impl ImportanceSamples {
    fn check(&self) -> Result<(), String> {
        let slices = self.theta_o.len();
        let rows = self.theta_h_edges.len().saturating_sub(1);
        let cols = self.n_phi_h as usize;
        if slices == 0 || rows == 0 || cols == 0 || self.n_vectors == 0 || self.n_samples == 0 {
            return Err(format!(
                "importance samples need at least one slice, row, sector, vector and sample, found {slices}, {rows}, \
                 {cols}, {}, {}",
                self.n_vectors, self.n_samples
            ));
        }
        // Counts from the file, multiplied without wrapping: a product past u64 is no file's.
        let (slices, rows, cols) = (slices as u64, rows as u64, cols as u64);
        let expect = [
            ("samples", self.samples.len(), product(&[slices, self.n_vectors.into(), self.n_samples.into()])),
            ("marginal cdf", self.marginal_cdf.len(), product(&[slices, rows + 1])),
            ("conditional cdf", self.conditional_cdf.len(), product(&[slices, rows, cols + 1])),
            ("h density", self.h_density.len(), product(&[slices, rows, cols])),
        ];
        for (what, found, expected) in expect {
            if Some(found as u64) != expected {
                let expected = expected.map_or("more than any file holds".to_string(), |e| e.to_string());
                return Err(format!("importance samples: {what} has {found} values, expected {expected}"));
            }
        }
        self.check_values()
    }

    /// What the values may be: every `wi` a unit direction (a reflection of `wo`, even where it
    /// reflects nowhere) and every pdf finite and not negative; the CDFs within `[0, 1]`; the
    /// half-vector densities finite and not negative. Samples of 1e30, -1 or 0 passed every
    /// checksum and changed the picture.
    fn check_values(&self) -> Result<(), String> {
        for (i, &[x, y, z, pdf]) in self.samples.iter().enumerate() {
            let length = (f64::from(x).powi(2) + f64::from(y).powi(2) + f64::from(z).powi(2)).sqrt();
            let at = || sample_at(i, self.n_vectors, self.n_samples);
            let off = (length - 1.0).abs();
            if off.is_nan() || off > UNIT_TOLERANCE {
                return Err(format!("importance samples: {}: wi ({x:e}, {y:e}, {z:e}) is not a unit direction", at()));
            }
            if !(pdf.is_finite() && pdf >= 0.0) {
                return Err(format!("importance samples: {}: pdf {pdf:e} is not a finite density of 0 or more", at()));
            }
        }
        for (what, cdf) in [("marginal cdf", &self.marginal_cdf), ("conditional cdf", &self.conditional_cdf)] {
            if let Some((i, v)) = cdf.iter().enumerate().find(|(_, v)| !(0.0..=1.0).contains(*v)) {
                return Err(format!("importance samples: {what} value {i} is {v:e}, outside [0, 1]"));
            }
        }
        if let Some((i, d)) = self.h_density.iter().enumerate().find(|(_, d)| !(d.is_finite() && **d >= 0.0)) {
            return Err(format!("importance samples: h density {i} is {d:e}, not a finite density of 0 or more"));
        }
        Ok(())
    }

    /// Whether every sample's pdf is the density the tables give its direction,
    /// `h_density[cell of h] / (4 wo . h)` with `h` the half vector of `wo` (the slice's
    /// outgoing direction at `phi_o = 0`) and the stored `wi`: a renderer weighs the samples'
    /// pdfs against the tables' density of the same directions (multiple importance sampling),
    /// so a pdf that passes [`ImportanceSamples`]' value check but not this one changes the
    /// picture. Decoding does not ask for it (the golden file of version 1 is a synthetic payload
    /// whose pdfs are twice its tables'); the renderers' reader and `asset-info` do.
    ///
    /// What a writer's rounding allows: the direction is stored in `f32`, which moves `h` by
    /// about `1e-7 / (2 wo . h)` and `wo . h` (taken as `|wi + wo| / 2`) by `1e-7 / (wo . h)`
    /// relatively; so `h` is taken to lie anywhere within `d = 1e-6 / (wo . h)` of where it is
    /// found (a neighbouring row or sector where a cell's edge is that near, every sector where
    /// `sin theta_h <= d`), and `wo . h` relatively as far. A pdf passes within
    /// `1e-3 + d` of the density relatively (the pdf and the density are `f32`). A pdf of 0 (a
    /// sample that reflects nowhere) passes where `h` is below the horizon or `wo . h <= 1e-3`,
    /// or where a cell it may lie in has no density.
    pub fn check_densities(&self) -> Result<(), String> {
        use std::f64::consts::TAU;
        let rows = self.theta_h_edges.len() - 1;
        let cols = self.n_phi_h as usize;
        let t_edges: Vec<f64> = self.theta_h_edges.iter().map(|&theta| 2.0 * (0.5 * theta).sin().powi(2)).collect();
        let per_slice = self.n_vectors as usize * self.n_samples as usize;
        for (i, &[x, y, z, pdf]) in self.samples.iter().enumerate() {
            let slice = i / per_slice;
            let (sin_o, cos_o) = self.theta_o[slice].sin_cos();
            let pdf = f64::from(pdf);
            let s = [f64::from(x) + sin_o, f64::from(y), f64::from(z) + cos_o];
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            let h = s.map(|c| c / len);
            // For unit `wi` and `wo`, `wo . h = |wi + wo| / 2`: rounding `wi` moves it by about
            // `1e-7` where `wo . normalize(wi + wo)` would move by `1e-7 / (2 wo . h)`.
            let wo_h = 0.5 * len;
            let at = || sample_at(i, self.n_vectors, self.n_samples);
            if !(len > 0.0 && h[2] > 0.0) {
                if pdf == 0.0 {
                    continue;
                }
                return Err(format!(
                    "importance samples: {}: pdf {pdf:e} for a direction no half vector above the surface reflects",
                    at()
                ));
            }
            let slack = 1e-6 / wo_h;
            let t = (h[0] * h[0] + h[1] * h[1]) / (1.0 + h[2]);
            let row = t_edges[1..].partition_point(|e| *e <= t).min(rows - 1);
            let below = usize::from(row > 0 && t - t_edges[row] <= slack);
            let above = usize::from(row + 1 < rows && t_edges[row + 1] - t <= slack);
            let sector = TAU / cols as f64;
            let phi = h[1].atan2(h[0]).rem_euclid(TAU);
            let col = ((phi / sector) as usize).min(cols - 1);
            let sin_h = (t * (2.0 - t)).max(0.0).sqrt();
            let (before, after) = if sin_h <= slack {
                (0, cols - 1)
            } else {
                let from_edge = phi - col as f64 * sector;
                (usize::from(from_edge * sin_h <= slack), usize::from((sector - from_edge) * sin_h <= slack))
            };
            let density = |r: usize, c: usize| f64::from(self.h_density[(slice * rows + r) * cols + c]) / (4.0 * wo_h);
            let tolerance = 1e-3 + slack;
            let matches = |r: usize, c: usize| {
                let expected = density(r, c);
                (pdf - expected).abs() <= tolerance * expected || (pdf == 0.0 && (wo_h <= 1e-3 || expected == 0.0))
            };
            let found = (row - below..=row + above)
                .any(|r| (0..=before + after).any(|k| matches(r, (col + cols - before + k) % cols)));
            if !found {
                return Err(format!(
                    "importance samples: {}: pdf {pdf:e} is not the density the tables give its direction ({:e}: h \
                     density {:e} of row {row}, sector {col}, over 4 wo . h = {:e})",
                    at(),
                    density(row, col),
                    self.h_density[(slice * rows + row) * cols + col],
                    4.0 * wo_h
                ));
            }
        }
        Ok(())
    }
}

/// Where sample texel `i` is: `sample i (slice k, vector v, sample s)`.
fn sample_at(i: usize, n_vectors: u32, n_samples: u32) -> String {
    let per_slice = n_vectors as usize * n_samples as usize;
    let (slice, vector, sample) = (i / per_slice, i % per_slice / n_samples as usize, i % n_samples as usize);
    format!("sample {i} (slice {slice}, vector {vector}, sample {sample})")
}

/// How far from 1 a stored direction's length may be: `f32` rounding makes about `1e-7`.
const UNIT_TOLERANCE: f64 = 1e-4;

/// The product of sizes read from a file, `None` past `u64`: no file holds that many, and a
/// wrapped product could match what a damaged file holds. Every payload check multiplies sizes
/// through it.
fn product(factors: &[u64]) -> Option<u64> {
    factors.iter().try_fold(1u64, |p, &f| p.checked_mul(f))
}

/// A file written next to an asset: its name in the asset's folder and its SHA-256, so that a
/// reader can find it and check that it is the file the asset describes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkedFile {
    /// A plain file name: not empty, no `/` or `\`, not `.` or `..`.
    pub name: String,
    pub sha256: [u8; 32],
}

impl LinkedFile {
    fn check(&self) -> Result<(), String> {
        let name = &self.name;
        if name.is_empty() || name == "." || name == ".." || name.contains(['/', '\\', '\0']) {
            return Err(format!("linked file name {name:?} is not a plain file name"));
        }
        Ok(())
    }
}

/// An environment map convolved with normalized Phong lobes `(n + 1) / (2 pi) max(0, w . r)^n`,
/// one layer per exponent, and the source's mip chain (payload of [`AssetKind::PrefilteredEnvmap`],
/// written by `envmap-prefilter`). The texels are in the linked files; `data-schema/README.md`
/// describes them and how a renderer picks a layer from a BRDF's bandwidth.
///
/// With `K = exponents.len()`: `lobe_bandwidth`, `layer_mean_radiance` and `layer_exrs` have `K`
/// entries (entry `k` is layer `k`), `bandwidth_thresholds` has `K - 1`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrefilteredEnvmap {
    /// Width and height of the source map (lat-long, `width = 2 height`).
    pub source_size: [u32; 2],
    /// The source's solid-angle-weighted mean radiance, red, green, blue.
    pub source_mean_radiance: [f64; 3],
    /// Width and height of every layer (lat-long, `width = 2 height`).
    pub layer_size: [u32; 2],
    /// Levels of the mip chain in `mips_ktx2`, level 0 being the source.
    pub mip_levels: u32,
    /// Texels of `layers_ktx2` are radiance times this (a power of two, at most 1); 1 in files
    /// written since the KTX2 files switch to single floats where half floats overflow.
    pub layers_radiance_scale: f64,
    /// Texels of `mips_ktx2` are radiance times this (a power of two, at most 1).
    pub mips_radiance_scale: f64,
    /// The Phong exponent of each layer, strictly increasing.
    pub exponents: Vec<u32>,
    /// The angular bandwidth of each layer's lobe, cycles per radian: `sqrt(n) / (2 pi)`.
    pub lobe_bandwidth: Vec<f64>,
    /// Between layers `k` and `k + 1`: `sqrt(lobe_bandwidth[k] lobe_bandwidth[k + 1])`. A BRDF
    /// of bandwidth `nu` uses the layer whose index is the number of thresholds below `nu`.
    pub bandwidth_thresholds: Vec<f64>,
    /// Each layer's solid-angle-weighted mean radiance (equal to the source's up to rounding and
    /// sampling: the lobes integrate to 1).
    pub layer_mean_radiance: Vec<[f64; 3]>,
    /// The layers as a KTX2 2D array texture, RGBA16F (RGBA32F when a texel exceeds half floats),
    /// one layer per exponent.
    pub layers_ktx2: LinkedFile,
    /// The layers as OpenEXR files (RGB, 32-bit float), one per exponent.
    pub layer_exrs: Vec<LinkedFile>,
    /// The source's mip chain as a KTX2 2D texture, RGBA16F (RGBA32F when a texel exceeds half
    /// floats).
    pub mips_ktx2: LinkedFile,
    /// The source and the layers side by side, tone mapped (PNG, for people).
    pub contact_sheet_png: LinkedFile,
}

impl PrefilteredEnvmap {
    /// Every file the asset names: the layers and mips KTX2 files, the contact sheet, the layer
    /// EXRs.
    pub fn linked_files(&self) -> Vec<&LinkedFile> {
        [&self.layers_ktx2, &self.mips_ktx2, &self.contact_sheet_png].into_iter().chain(&self.layer_exrs).collect()
    }

    fn check(&self) -> Result<(), String> {
        let k = self.exponents.len();
        if k == 0 {
            return Err("prefiltered envmap has no layers".into());
        }
        if let Some(w) = self.exponents.windows(2).find(|w| w[0] >= w[1]) {
            return Err(format!("prefiltered envmap exponents must increase strictly, found {} then {}", w[0], w[1]));
        }
        if self.exponents[0] == 0 {
            return Err("prefiltered envmap exponent 0: exponents start at 1".into());
        }
        for (what, [w, h]) in [("source", self.source_size), ("layer", self.layer_size)] {
            if h == 0 || u64::from(w) != 2 * u64::from(h) {
                return Err(format!("prefiltered envmap {what} size {w} x {h} is not a 2:1 lat-long map"));
            }
        }
        if self.mip_levels == 0 {
            return Err("prefiltered envmap has no mip levels".into());
        }
        // What the writer can make: a chain halves the source down to one texel at most, and a
        // layer is at most MAX_LAYER_HEIGHT tall.
        let most_levels = 1 + self.source_size[0].max(1).ilog2();
        if self.mip_levels > most_levels {
            return Err(format!(
                "prefiltered envmap: {} mip levels of a {} x {} source, which has at most {most_levels}",
                self.mip_levels, self.source_size[0], self.source_size[1]
            ));
        }
        if self.layer_size[1] > MAX_LAYER_HEIGHT {
            return Err(format!(
                "prefiltered envmap: layers of {} x {}, taller than the {MAX_LAYER_HEIGHT} rows any writer makes",
                self.layer_size[0], self.layer_size[1]
            ));
        }
        let means = std::iter::once(&self.source_mean_radiance).chain(&self.layer_mean_radiance);
        for (i, mean) in means.enumerate() {
            if !mean.iter().all(|m| m.is_finite() && *m >= 0.0) {
                let what = if i == 0 { "the source's".to_string() } else { format!("layer {}'s", i - 1) };
                return Err(format!(
                    "prefiltered envmap: {what} mean radiance {mean:?} is not finite and not negative"
                ));
            }
        }
        let expect = [
            ("lobe bandwidths", self.lobe_bandwidth.len(), k),
            ("bandwidth thresholds", self.bandwidth_thresholds.len(), k - 1),
            ("layer means", self.layer_mean_radiance.len(), k),
            ("layer exr files", self.layer_exrs.len(), k),
        ];
        for (what, found, expected) in expect {
            if found != expected {
                return Err(format!("prefiltered envmap: {what} has {found} entries, expected {expected}"));
            }
        }
        if !self.lobe_bandwidth.iter().all(|b| b.is_finite() && *b > 0.0) {
            return Err("prefiltered envmap lobe bandwidths must be positive and finite".into());
        }
        for (i, t) in self.bandwidth_thresholds.iter().enumerate() {
            let (lower, upper) = (self.lobe_bandwidth[i], self.lobe_bandwidth[i + 1]);
            if !(lower < *t && *t < upper) {
                return Err(format!(
                    "prefiltered envmap threshold {i} ({t}) does not lie between the bandwidths of its layers ({lower}, \
                     {upper})"
                ));
            }
        }
        for (what, scale) in [("layers", self.layers_radiance_scale), ("mips", self.mips_radiance_scale)] {
            if !(scale > 0.0 && scale <= 1.0) {
                return Err(format!("prefiltered envmap {what} radiance scale {scale} outside (0, 1]"));
            }
        }
        let files = self.linked_files();
        for (i, file) in files.iter().enumerate() {
            file.check().map_err(|problem| format!("prefiltered envmap: {problem}"))?;
            if files[..i].iter().any(|other| other.name == file.name) {
                return Err(format!("prefiltered envmap names the file {:?} twice", file.name));
            }
        }
        Ok(())
    }
}

/// How the lobes of a bandwidth atlas were analysed: shared by [`BandwidthAtlas`] and
/// [`BandwidthPca`]. `data-schema/bandwidth-atlas.md` defines the parameterizations by name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandwidthAnalysis {
    /// The lobe and incident-grid parameterization, e.g. `incidence-plane-equidistant`.
    pub parameterization: String,
    /// Side of the grid each lobe was analysed on, pixels.
    pub analysis_size: u32,
    /// The estimator's significance threshold and level-to-frequency constant.
    pub eps: f64,
    pub c: f64,
}

/// The angular bandwidth of a BRDF's lobes (payload of [`AssetKind::BandwidthAtlas`], written by
/// `brdf-bandwidth`): `lobes_x x lobes_y` tiles of `tile x tile` texels, packed row-major into
/// an atlas `lobes_x tile` texels wide; `data` holds its texels, top row first, in cycles per
/// radian.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandwidthAtlas {
    pub lobes_x: u32,
    pub lobes_y: u32,
    pub tile: u32,
    pub analysis: BandwidthAnalysis,
    pub data: Vec<f32>,
}

impl BandwidthAtlas {
    fn check(&self) -> Result<(), String> {
        // Sizes come from the file: a product that overflows is a size no file can hold.
        let texels = product(&[self.lobes_x, self.lobes_y, self.tile, self.tile].map(u64::from));
        if texels.is_none_or(|t| t == 0 || t != self.data.len() as u64) {
            return Err(format!(
                "bandwidth atlas of {} x {} tiles of {} x {} texels holds {} values, expected {} (and at least one)",
                self.lobes_x,
                self.lobes_y,
                self.tile,
                self.tile,
                self.data.len(),
                texels.map_or("more than any file holds".to_string(), |t| t.to_string())
            ));
        }
        self.analysis.check_bandwidths("bandwidth atlas: texel", &self.data)
    }
}

/// The tallest layer a prefiltered environment holds (`prefilter::MAX_LAYER_HEIGHT`, the
/// writer's own limit; layers are `2 h x h`).
pub const MAX_LAYER_HEIGHT: u32 = 8192;

impl BandwidthAnalysis {
    /// The largest bandwidth a payload of this analysis may hold, in cycles per radian: twice the
    /// grid's limit, the finest level's `c / 2` cycles per pixel at `n / 2` pixels per radian on
    /// the horizon (`bandwidth_atlas`, "Units and the grid's limit"; the atlas reaches the limit, the
    /// factor 2 leaves a margin). A bandwidth past it is no measurement of this analysis.
    pub fn bandwidth_bound(&self) -> f64 {
        self.c * f64::from(self.analysis_size) / 2.0
    }

    fn check(&self) -> Result<(), String> {
        if self.analysis_size == 0 || !(self.c.is_finite() && self.c > 0.0) {
            return Err(format!(
                "analysis on a {} grid with constant c {:e}: expected a grid of at least 1 and a finite c above 0",
                self.analysis_size, self.c
            ));
        }
        Ok(())
    }

    /// `data` (bandwidths, cycles per radian) within `[0, bandwidth_bound]`; the error names the
    /// first value outside, as `what` `index`.
    fn check_bandwidths<T: Into<f64> + Copy + std::fmt::LowerExp>(&self, what: &str, data: &[T]) -> Result<(), String> {
        self.check()?;
        let bound = self.bandwidth_bound();
        match data.iter().enumerate().find(|(_, b)| !((**b).into() >= 0.0 && (**b).into() <= bound)) {
            Some((i, b)) => Err(format!(
                "{what} {i} is {b:e}, outside [0, {bound}] cycles per radian (twice the limit of a {} grid)",
                self.analysis_size
            )),
            None => Ok(()),
        }
    }
}

/// A bandwidth atlas whose every tile equals the first tile of its row, stored once per row
/// (payload of [`AssetKind::BandwidthRows`], written by `brdf-bandwidth` for an isotropic
/// material): the atlas it stands for has `lobes_x x lobes_y` tiles of `tile x tile` texels, and
/// lobe `(i, j)` is row `j`'s tile for every column `i`. `data` holds the `lobes_y` row tiles one
/// after another, each `tile x tile` texels row-major, in cycles per radian; this is the layout of
/// a [`BandwidthAtlas`] one lobe wide.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandwidthRows {
    /// The columns of the atlas it stands for: every row's tile serves each of them.
    pub lobes_x: u32,
    pub lobes_y: u32,
    pub tile: u32,
    pub analysis: BandwidthAnalysis,
    pub data: Vec<f32>,
}

/// The most columns a [`BandwidthRows`] payload may stand for: the largest side of an incident
/// grid the atlas builder accepts (`bandwidth_atlas::Config`, 4096). Expanding rows to the full grid
/// multiplies the stored texels by at most this.
pub const MAX_ROWS_COLUMNS: u32 = 4096;

impl BandwidthRows {
    fn check(&self) -> Result<(), String> {
        // Sizes come from the file: a product that overflows is a size no file can hold. The
        // full grid (`lobes_x` times the stored texels) is not allocated here; a reader that
        // expands the rows bounds it first.
        let stored = product(&[self.tile, self.tile, self.lobes_y].map(u64::from));
        if stored.is_none_or(|s| s == 0 || s != self.data.len() as u64) {
            return Err(format!(
                "bandwidth rows of {} tiles of {} x {} texels hold {} values, expected {} (and at least one)",
                self.lobes_y,
                self.tile,
                self.tile,
                self.data.len(),
                stored.map_or("more than any file holds".to_string(), |s| s.to_string())
            ));
        }
        // The columns the rows stand for are at most an incident grid's side: a reader that
        // expands the rows holds at most MAX_ROWS_COLUMNS times what the file holds, never a
        // count the file declares alone (a 321-byte file declaring 7.5 million columns made
        // `bandwidth-pca` hold 951 MB).
        if self.lobes_x == 0 || self.lobes_x > MAX_ROWS_COLUMNS {
            return Err(format!(
                "bandwidth rows stand for {} columns of lobes: expected 1 to {MAX_ROWS_COLUMNS}",
                self.lobes_x
            ));
        }
        self.analysis.check_bandwidths("bandwidth rows: texel", &self.data)
    }
}

/// A bandwidth atlas compressed by PCA (payload of [`AssetKind::BandwidthPca`], written by
/// `bandwidth-pca`; Bagher et al. 2011, Fig. 8): tile `l` is `mean + sum_k coefficients[l][k]
/// components[k]`, each tile a row-major `tile x tile` vector of `tile_len = tile^2` values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandwidthPca {
    pub lobes_x: u32,
    pub lobes_y: u32,
    pub tile: u32,
    pub analysis: BandwidthAnalysis,
    /// `K`.
    pub n_components: u32,
    /// `tile_len` values.
    pub mean: Vec<f32>,
    /// `K x tile_len`, by decreasing variance, unit length.
    pub components: Vec<f32>,
    /// `lobes_x lobes_y x K`, lobes row-major.
    pub coefficients: Vec<f32>,
}

impl BandwidthPca {
    fn check(&self) -> Result<(), String> {
        // Sizes come from the file: a product that overflows is a size no file can hold.
        let tile_len = product(&[self.tile, self.tile].map(u64::from));
        let lobes = product(&[self.lobes_x, self.lobes_y].map(u64::from));
        let k = u64::from(self.n_components);
        let (Some(tile_len), Some(lobes)) = (tile_len, lobes) else {
            return Err("bandwidth pca sizes exceed what any file holds".to_string());
        };
        if tile_len == 0 || lobes == 0 {
            return Err("bandwidth pca needs at least one lobe of at least one texel".to_string());
        }
        let expect = [
            ("mean", self.mean.len() as u64, Some(tile_len)),
            ("components", self.components.len() as u64, product(&[k, tile_len])),
            ("coefficients", self.coefficients.len() as u64, product(&[lobes, k])),
        ];
        for (what, found, expected) in expect {
            if Some(found) != expected {
                let expected = expected.map_or("more than any file holds".to_string(), |e| e.to_string());
                return Err(format!("bandwidth pca: {what} has {found} values, expected {expected}"));
            }
        }
        self.check_values(tile_len as usize)
    }

    /// The ranges the values' meanings allow: the mean tile's bandwidths within the analysis's
    /// bound ([`BandwidthAnalysis::bandwidth_bound`]); each component of unit length (within
    /// [`UNIT_TOLERANCE`]); each coefficient, a tile's projection on a unit component after the
    /// mean is taken out, finite and at most `sqrt(tile_len)` times the bound in magnitude, the
    /// length of a tile of bandwidths within the bound.
    fn check_values(&self, tile_len: usize) -> Result<(), String> {
        self.analysis.check_bandwidths("bandwidth pca: mean value", &self.mean)?;
        for (k, component) in self.components.chunks_exact(tile_len).enumerate() {
            let length = component.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>().sqrt();
            let off = (length - 1.0).abs();
            if off.is_nan() || off > UNIT_TOLERANCE {
                return Err(format!("bandwidth pca: component {k} has length {length:e}, not 1"));
            }
        }
        let bound = (tile_len as f64).sqrt() * self.analysis.bandwidth_bound();
        let k = self.n_components as usize;
        if let Some((i, c)) =
            self.coefficients.iter().enumerate().find(|(_, c)| c.is_nan() || f64::from(c.abs()) > bound)
        {
            return Err(format!(
                "bandwidth pca: coefficient {} of lobe {} is {c:e}, outside [-{bound}, {bound}] (a tile of bandwidths \
                 within the analysis's bound)",
                i % k,
                i / k
            ));
        }
        Ok(())
    }
}

/// Which Phong layer of a prefiltered environment serves each view elevation of a material
/// (payload of [`AssetKind::LayerSelection`], written by `brdf-bake`; crate `bandwidth-atlas`,
/// module `view`). The material's lobes and the layers' own Phong lobes were measured with the
/// same analysis (`analysis`, `reduction`); a view uses the layer whose bandwidth is nearest on a
/// log scale. `data-schema/README.md` says how a renderer reads it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayerSelection {
    pub analysis: BandwidthAnalysis,
    /// `R`: view elevations in equal steps of `cos theta_o`, row `r` covering
    /// `1 - cos theta_o` in `[r / R, (r + 1) / R)` (the rows of the bandwidth atlas).
    pub rows: u32,
    /// How a lobe became one number, e.g. `band-0.99` or `max`.
    pub reduction: String,
    /// The layers' Phong exponents, `K` of them (those of the prefiltered environment).
    pub exponents: Vec<u32>,
    /// `K` bandwidths, cycles per radian: each layer's lobe measured like the material's.
    pub layer_bandwidth: Vec<f64>,
    /// `R` bandwidths, cycles per radian: the material's lobe for views in each row.
    pub view_bandwidth: Vec<f64>,
    /// `R` layer indices (`< K`): the layer each row of views reads.
    pub view_layer: Vec<u32>,
}

impl LayerSelection {
    fn check(&self) -> Result<(), String> {
        let (k, rows) = (self.exponents.len(), self.rows as usize);
        if k == 0 || rows == 0 {
            return Err("layer selection needs at least one layer and one row".into());
        }
        let expect = [
            ("layer bandwidths", self.layer_bandwidth.len(), k),
            ("view bandwidths", self.view_bandwidth.len(), rows),
            ("view layers", self.view_layer.len(), rows),
        ];
        for (what, found, expected) in expect {
            if found != expected {
                return Err(format!("layer selection: {what} has {found} entries, expected {expected}"));
            }
        }
        if let Some(bad) = self.view_layer.iter().find(|&&l| l as usize >= k) {
            return Err(format!("layer selection names layer {bad} of {k}"));
        }
        self.analysis.check_bandwidths("layer selection: layer bandwidth", &self.layer_bandwidth)?;
        self.analysis.check_bandwidths("layer selection: view bandwidth", &self.view_bandwidth)
    }
}

/// The largest grid side of a [`WaveletBrdf`]: `2^8` cells per angle, the paper's limit for 16-bit
/// compression-map indices (section 5.2).
pub const MAX_WAVELET_SIDE: u32 = 256;

/// The range of a [`WaveletBrdf`]'s log-encoding bias `epsilon`: the encoding's floor `eps mu` is
/// from `1e-12` of the channel mean (log values down to `ln 1e-12 = -27.6`) to the mean itself
/// (the paper's is `0.01`). A larger bias flattens the BRDF to nothing: `1e308` renders black.
pub const WAVELET_EPSILON_RANGE: std::ops::RangeInclusive<f64> = 1e-12..=1.0;

/// The largest channel mean `mu` of a [`WaveletBrdf`], in 1/sr: a material reflecting as much as
/// that on average is no BRDF (a Lambertian white is `1 / pi`).
pub const MAX_WAVELET_CHANNEL_MEAN: f64 = 1e6;

/// The largest log-encoded value `|log((f + eps mu) / mu)|` a [`WaveletBrdf`] stands for: `f` from
/// the floor up to `e^64` (6e27) times the channel mean. The transform is orthonormal, so an
/// `n x n` slice of such values has no coefficient beyond `64 n` in magnitude (each coefficient
/// is at most the slice's L2 norm): a stored coefficient (or a quantized slice's range) beyond
/// that is refused.
pub const WAVELET_LOG_BOUND: f64 = 64.0;

/// A BRDF encoded in Haar wavelets (payload of [`AssetKind::WaveletBrdf`], written by
/// `brdf-wavelet`; Claustres, Barthe and Paulin 2007, sections 4-5). Crate `wavelet-brdf`
/// documents the parameterization, the transform and the reconstruction;
/// `data-schema/README.md` the bytes.
///
/// Directions are on an `n x n` grid of the sphere parameterization (`n = side`) for both
/// `wo` (the slice) and `wi` (within a slice). Each slice's log-encoded values were transformed by
/// a 2D non-standard Haar transform into `n^2` coefficient positions. Coefficient position `p`
/// (row-major in the `n x n` coefficient layout) taken across all `n^2` outgoing cells and the 3
/// channels is one stored "slice" or none: `map[p]` is `0` for a dropped position (the shared zero
/// slice) or `k` in `1..=K` for stored slice `k - 1`; the kept positions, in increasing order,
/// hold slices `1, 2, ..., K`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WaveletBrdf {
    /// `n`: cells per angle of both direction grids, a power of two in `2..=256`.
    pub side: u32,
    /// `eps` of the log encoding `log((f + eps mu) / mu)`.
    pub epsilon: f64,
    /// `mu` per channel: the mean of the resampled values, 1/sr, positive.
    pub channel_mean: [f64; 3],
    /// `n^2` entries, one per coefficient position.
    pub map: Vec<u32>,
    pub coefficients: WaveletCoefficients,
}

/// The stored slices of a [`WaveletBrdf`]: `K` slices, each `n^2` outgoing cells (row-major) of 3
/// channels, slice-major: value `(k, o, c)` is entry `(k n^2 + o) 3 + c`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum WaveletCoefficients {
    /// The coefficients as `f32`.
    Float(Vec<f32>),
    /// 8-bit codes: value `(k, o, c)` is `offset[3 k + c] + code step[3 k + c]`, the range of each
    /// slice and channel cut into 255 equal steps.
    Quantized { offset: Vec<f32>, step: Vec<f32>, codes: Vec<u8> },
}

impl WaveletBrdf {
    /// `K`, the number of stored slices (the map's nonzero entries).
    pub fn stored_slices(&self) -> usize {
        self.map.iter().filter(|&&m| m != 0).count()
    }

    /// The payload's invariants (checked on write and read; public for readers that build a
    /// payload themselves).
    pub fn check(&self) -> Result<(), String> {
        let n = self.side;
        if !n.is_power_of_two() || !(2..=MAX_WAVELET_SIDE).contains(&n) {
            return Err(format!("wavelet brdf side {n} is not a power of two in 2..={MAX_WAVELET_SIDE}"));
        }
        if !WAVELET_EPSILON_RANGE.contains(&self.epsilon) {
            return Err(format!(
                "wavelet brdf epsilon {} is outside {:e} to {}",
                self.epsilon,
                WAVELET_EPSILON_RANGE.start(),
                WAVELET_EPSILON_RANGE.end()
            ));
        }
        if !self.channel_mean.iter().all(|m| *m > 0.0 && *m <= MAX_WAVELET_CHANNEL_MEAN) {
            return Err(format!(
                "wavelet brdf channel means {:?} must be positive and at most {MAX_WAVELET_CHANNEL_MEAN:e} 1/sr",
                self.channel_mean
            ));
        }
        let cells = u64::from(n) * u64::from(n);
        if self.map.len() as u64 != cells {
            return Err(format!("wavelet brdf map has {} entries, expected {cells}", self.map.len()));
        }
        let mut next = 1u32;
        for (p, &m) in self.map.iter().enumerate() {
            if m != 0 && m != next {
                return Err(format!(
                    "wavelet brdf map gives position {p} slice {m}, expected 0 or {next} (kept positions hold slices 1, 2, ... in order)"
                ));
            }
            next += u32::from(m != 0);
        }
        let k = u64::from(next - 1);
        let values = product(&[k, cells, 3]).expect("k and cells are at most 2^16 each");
        // Every stored coefficient within WAVELET_LOG_BOUND n (NaN and infinities fail too).
        let bound = WAVELET_LOG_BOUND * f64::from(n);
        let within = |x: f64| x.abs() <= bound;
        let (what, found, in_range) = match &self.coefficients {
            WaveletCoefficients::Float(v) => ("values", v.len(), v.iter().all(|&x| within(f64::from(x)))),
            WaveletCoefficients::Quantized { offset, step, codes } => {
                for (what, found) in [("offsets", offset.len()), ("steps", step.len())] {
                    if found as u64 != 3 * k {
                        return Err(format!("wavelet brdf has {found} quantization {what}, expected {}", 3 * k));
                    }
                }
                // Codes 0 to 255: the slice's range is offset .. offset + 255 step.
                let ranges = offset.iter().zip(step).all(|(&o, &s)| {
                    let (o, s) = (f64::from(o), f64::from(s));
                    s >= 0.0 && within(o) && within(o + 255.0 * s)
                });
                ("codes", codes.len(), ranges)
            }
        };
        if found as u64 != values {
            return Err(format!(
                "wavelet brdf holds {found} {what}, expected {values} ({k} slices of {cells} cells x 3)"
            ));
        }
        if !in_range {
            return Err(format!(
                "wavelet brdf coefficients must be finite and within {bound} in magnitude ({WAVELET_LOG_BOUND} times the \
                 side: log-encoded values within {WAVELET_LOG_BOUND}), and quantization steps not negative"
            ));
        }
        Ok(())
    }
}

/// The payload of an asset, one variant per [`AssetKind`].
///
/// Only the variant's content is serialized; the header's kind code says which type follows.
#[derive(Debug, Clone, PartialEq)]
pub enum Payload {
    MaterialInfo(MaterialInfo),
    ImportanceSamples(ImportanceSamples),
    PrefilteredEnvmap(PrefilteredEnvmap),
    BandwidthAtlas(BandwidthAtlas),
    BandwidthPca(BandwidthPca),
    LayerSelection(LayerSelection),
    BandwidthRows(BandwidthRows),
    WaveletBrdf(WaveletBrdf),
}

impl Payload {
    /// The files next to the asset that it names with their SHA-256 (empty for most kinds).
    pub fn linked_files(&self) -> Vec<&LinkedFile> {
        match self {
            Payload::PrefilteredEnvmap(p) => p.linked_files(),
            _ => Vec::new(),
        }
    }

    pub fn kind(&self) -> AssetKind {
        match self {
            Payload::MaterialInfo(_) => AssetKind::MaterialInfo,
            Payload::ImportanceSamples(_) => AssetKind::ImportanceSamples,
            Payload::PrefilteredEnvmap(_) => AssetKind::PrefilteredEnvmap,
            Payload::BandwidthAtlas(_) => AssetKind::BandwidthAtlas,
            Payload::BandwidthPca(_) => AssetKind::BandwidthPca,
            Payload::LayerSelection(_) => AssetKind::LayerSelection,
            Payload::BandwidthRows(_) => AssetKind::BandwidthRows,
            Payload::WaveletBrdf(_) => AssetKind::WaveletBrdf,
        }
    }

    /// The invariants of the payload's type, checked on write and after decoding.
    pub(crate) fn check(&self) -> Result<(), String> {
        match self {
            Payload::MaterialInfo(info) => info.check(),
            Payload::ImportanceSamples(samples) => samples.check(),
            Payload::PrefilteredEnvmap(prefiltered) => prefiltered.check(),
            Payload::BandwidthAtlas(atlas) => atlas.check(),
            Payload::BandwidthPca(pca) => pca.check(),
            Payload::LayerSelection(selection) => selection.check(),
            Payload::BandwidthRows(rows) => rows.check(),
            Payload::WaveletBrdf(wavelet) => wavelet.check(),
        }
    }
}

impl From<MaterialInfo> for Payload {
    fn from(info: MaterialInfo) -> Payload {
        Payload::MaterialInfo(info)
    }
}

impl From<ImportanceSamples> for Payload {
    fn from(samples: ImportanceSamples) -> Payload {
        Payload::ImportanceSamples(samples)
    }
}

impl From<BandwidthAtlas> for Payload {
    fn from(atlas: BandwidthAtlas) -> Payload {
        Payload::BandwidthAtlas(atlas)
    }
}

impl From<BandwidthRows> for Payload {
    fn from(rows: BandwidthRows) -> Payload {
        Payload::BandwidthRows(rows)
    }
}

impl From<BandwidthPca> for Payload {
    fn from(pca: BandwidthPca) -> Payload {
        Payload::BandwidthPca(pca)
    }
}

impl From<LayerSelection> for Payload {
    fn from(selection: LayerSelection) -> Payload {
        Payload::LayerSelection(selection)
    }
}

impl From<WaveletBrdf> for Payload {
    fn from(wavelet: WaveletBrdf) -> Payload {
        Payload::WaveletBrdf(wavelet)
    }
}

impl From<PrefilteredEnvmap> for Payload {
    fn from(prefiltered: PrefilteredEnvmap) -> Payload {
        Payload::PrefilteredEnvmap(prefiltered)
    }
}

/// One baked output: where it came from and what it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Asset {
    pub provenance: Provenance,
    pub payload: Payload,
}

impl Asset {
    pub fn kind(&self) -> AssetKind {
        self.payload.kind()
    }
}
