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
}

impl AssetKind {
    /// Every kind this build knows, in code order.
    pub const ALL: [AssetKind; 1] = [AssetKind::MaterialInfo];

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

/// The payload of an asset, one variant per [`AssetKind`].
///
/// Only the variant's content is serialized; the header's kind code says which type follows.
#[derive(Debug, Clone, PartialEq)]
pub enum Payload {
    MaterialInfo(MaterialInfo),
}

impl Payload {
    pub fn kind(&self) -> AssetKind {
        match self {
            Payload::MaterialInfo(_) => AssetKind::MaterialInfo,
        }
    }

    /// The invariants of the payload's type, checked on write and after decoding.
    pub(crate) fn check(&self) -> Result<(), String> {
        match self {
            Payload::MaterialInfo(info) => info.check(),
        }
    }
}

impl From<MaterialInfo> for Payload {
    fn from(info: MaterialInfo) -> Payload {
        Payload::MaterialInfo(info)
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
