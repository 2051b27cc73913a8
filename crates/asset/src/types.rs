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
}

impl AssetKind {
    /// Every kind this build knows, in code order.
    pub const ALL: [AssetKind; 2] = [AssetKind::MaterialInfo, AssetKind::ImportanceSamples];

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
        let expect = [
            ("samples", self.samples.len(), slices * self.n_vectors as usize * self.n_samples as usize),
            ("marginal cdf", self.marginal_cdf.len(), slices * (rows + 1)),
            ("conditional cdf", self.conditional_cdf.len(), slices * rows * (cols + 1)),
            ("h density", self.h_density.len(), slices * rows * cols),
        ];
        for (what, found, expected) in expect {
            if found != expected {
                return Err(format!("importance samples: {what} has {found} values, expected {expected}"));
            }
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
}

impl Payload {
    pub fn kind(&self) -> AssetKind {
        match self {
            Payload::MaterialInfo(_) => AssetKind::MaterialInfo,
            Payload::ImportanceSamples(_) => AssetKind::ImportanceSamples,
        }
    }

    /// The invariants of the payload's type, checked on write and after decoding.
    pub(crate) fn check(&self) -> Result<(), String> {
        match self {
            Payload::MaterialInfo(info) => info.check(),
            Payload::ImportanceSamples(samples) => samples.check(),
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
