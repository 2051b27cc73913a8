//! The one container format of every baked asset, the serialized types it holds, and the bake
//! manifest that lists a bake's outputs. Every type that reaches a file lives here: other crates
//! convert their internal types into these by hand, so that changing an algorithm's internals
//! never silently changes a file format.
//!
//! An asset file is a fixed 64-byte header (magic `BRDFASET`, format version, asset kind,
//! section lengths, SHA-256 of the sections) followed by a [`Provenance`] section and a payload
//! section, both in bincode with fixed-width little-endian integers. `data-schema/README.md`
//! documents the layout byte by byte, the versioning policy and the changelog.
//!
//! Architecture invariant: readers check the magic, the version and the header's lengths
//! against limits and the file size before allocating anything sized by the header, and a
//! damaged or truncated file is an [`Error`], never a panic. Every released format version
//! stays readable; `fixtures/assets/` holds a golden file of each.
//!
//! ```
//! # fn main() -> Result<(), asset::Error> {
//! use asset::{Asset, MaterialInfo, Provenance};
//!
//! let asset = Asset {
//!     provenance: Provenance {
//!         source_name: "gold-metallic-paint.binary".into(),
//!         source_sha256: asset::sha256(b"the source file's bytes"),
//!         tool: "merl-info".into(),
//!         tool_version: "0.1.0".into(),
//!         parameters: vec![("interp".into(), "nearest".into())],
//!     },
//!     payload: MaterialInfo {
//!         dims: [90, 90, 180],
//!         no_data_cells: 0,
//!         channel_min: [0.0; 3],
//!         channel_max: [1.0; 3],
//!         channel_mean: [0.5; 3],
//!         peak_rgb: [1.0; 3],
//!         peak_cell: [0, 0, 0],
//!         albedo_theta_o: vec![0.0],
//!         albedo_rgb: vec![[0.5; 3]],
//!         albedo_no_data_fraction: vec![0.0],
//!     }
//!     .into(),
//! };
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("gold.material-info.asset");
//! asset::write_file(&path, &asset)?;
//! assert_eq!(asset::read_file(&path)?, asset);
//! # Ok(())
//! # }
//! ```

mod container;
mod describe;
mod error;
mod files;
mod manifest;
mod types;

pub use container::{
    FORMAT_VERSION, HEADER_BYTES, Header, MAGIC, PAYLOAD_LIMIT, PROVENANCE_LIMIT, READABLE_VERSIONS, decode,
    decode_with_header, encode, encode_checked, read_file, read_file_with_header, read_header, write_file,
};
pub use describe::Description;
pub use error::Error;
pub use files::{
    LinkedStatus, Recovery, SWITCH_JOURNAL, Staging, create_folder, hex, linked_file_status, recover_switch,
    remove_temporaries, sha256, sha256_file, sha256_from_hex, temporary_target, write_atomic, write_set,
};
pub use manifest::{
    BakeManifest, FileFormat, MANIFEST_FILE, MANIFEST_LIMIT, MANIFEST_VERSION, OUTPUT_LIMIT,
    READABLE_MANIFEST_VERSIONS, SourceFile, Stage, StageOutput, Tool,
};
pub use types::{
    Asset, AssetKind, BandwidthAnalysis, BandwidthAtlas, BandwidthPca, BandwidthRows, ImportanceSamples,
    LayerSelection, LinkedFile, MAX_LAYER_HEIGHT, MAX_ROWS_COLUMNS, MAX_WAVELET_CHANNEL_MEAN, MAX_WAVELET_SIDE,
    MaterialInfo, Payload, PrefilteredEnvmap, Provenance, WAVELET_EPSILON_RANGE, WAVELET_LOG_BOUND, WaveletBrdf,
    WaveletCoefficients,
};
