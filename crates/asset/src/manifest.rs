//! The bake manifest: the JSON file a bake writes next to its outputs, saying what went in
//! (material, environment, tool) and what each stage wrote (path, kind, size, hash), so that a
//! later step can check its inputs without decoding them. Its JSON Schema is
//! `data-schema/bake-manifest.schema.json`; the two must agree (a test checks).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::container::FORMAT_VERSION;
use crate::error::Error;
use crate::files::{hex, sha256_file};
use crate::types::AssetKind;

/// The manifest version this build writes.
pub const MANIFEST_VERSION: u32 = 1;
/// Every manifest version this build reads.
pub const READABLE_MANIFEST_VERSIONS: &[u32] = &[1];

/// What a bake read and wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BakeManifest {
    pub manifest_version: u32,
    pub material: SourceFile,
    /// The environment map, for bakes that use one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<SourceFile>,
    pub tool: Tool,
    /// In the order they ran.
    pub stages: Vec<Stage>,
}

/// An input of the bake.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceFile {
    /// A short name for reports, e.g. `gold-metallic-paint`.
    pub name: String,
    /// Where the bake read it, as given to the tool.
    pub source_path: String,
    /// SHA-256 of its bytes, 64 lower-case hexadecimal digits.
    pub source_sha256: String,
}

/// The program that ran the bake.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tool {
    pub name: String,
    pub version: String,
}

/// One step of the bake.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    pub name: String,
    /// The settings that shaped the outputs; free-form per stage.
    pub parameters: serde_json::Map<String, serde_json::Value>,
    pub outputs: Vec<StageOutput>,
}

/// One file a stage wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageOutput {
    /// Relative to the manifest's folder, with `/` separators.
    pub path: String,
    pub kind: AssetKind,
    /// The container format version of the file.
    pub format_version: u32,
    pub size_bytes: u64,
    /// SHA-256 of the whole file, 64 lower-case hexadecimal digits.
    pub sha256: String,
}

impl StageOutput {
    /// Describes an asset file that this build wrote at `manifest_dir/path`, hashing it.
    pub fn of_file(manifest_dir: &Path, path: &str, kind: AssetKind) -> std::io::Result<StageOutput> {
        let full = manifest_dir.join(path);
        Ok(StageOutput {
            path: path.to_owned(),
            kind,
            format_version: FORMAT_VERSION,
            size_bytes: std::fs::metadata(&full)?.len(),
            sha256: hex(&sha256_file(&full)?),
        })
    }
}

impl BakeManifest {
    /// A manifest of the current version with no stages yet.
    pub fn new(material: SourceFile, environment: Option<SourceFile>, tool: Tool) -> BakeManifest {
        BakeManifest { manifest_version: MANIFEST_VERSION, material, environment, tool, stages: Vec::new() }
    }

    /// Parses a manifest and checks its version. The JSON Schema says more (hash patterns);
    /// this checks what the types can.
    pub fn from_json(text: &str) -> Result<BakeManifest, Error> {
        let manifest: BakeManifest =
            serde_json::from_str(text).map_err(|e| Error::Invalid(format!("invalid bake manifest: {e}")))?;
        if !READABLE_MANIFEST_VERSIONS.contains(&manifest.manifest_version) {
            return Err(Error::UnsupportedVersion {
                what: "manifest",
                found: manifest.manifest_version,
                readable: READABLE_MANIFEST_VERSIONS,
            });
        }
        Ok(manifest)
    }

    /// Pretty JSON with a trailing newline, ready for [`crate::write_atomic`].
    pub fn to_json(&self) -> String {
        // Maps with string keys and plain structs always serialize.
        let mut text = serde_json::to_string_pretty(self).expect("manifest types always serialize");
        text.push('\n');
        text
    }
}
