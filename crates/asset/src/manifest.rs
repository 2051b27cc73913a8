//! The bake manifest: the JSON file a bake writes next to its outputs, saying what went in
//! (material, environment, tool, parameters) and what each stage wrote (path, format, role, size,
//! hash) and measured (figures), so that a later step can check its inputs without decoding them
//! and a rerun can tell that nothing changed. Its JSON Schema is
//! `data-schema/bake-manifest.schema.json` (version 2; version 1's is kept beside it); the two
//! must agree (a test checks).

use serde::{Deserialize, Serialize};

use crate::container::{FORMAT_VERSION, HEADER_BYTES, PAYLOAD_LIMIT, PROVENANCE_LIMIT};
use crate::error::Error;
use crate::files::{hex, sha256_open};

use crate::types::AssetKind;

/// The manifest version this build writes.
pub const MANIFEST_VERSION: u32 = 2;
/// Every manifest version this build reads.
pub const READABLE_MANIFEST_VERSIONS: &[u32] = &[1, 2];
/// The manifest's file name in a bake's folder.
pub const MANIFEST_FILE: &str = "manifest.json";
/// The largest manifest a reader accepts, in bytes: a bake's is a few tens of kilobytes.
pub const MANIFEST_LIMIT: u64 = 16 << 20;
/// The largest file a manifest may list, in bytes: the largest asset a reader accepts (its
/// header, provenance and payload limits); no other file a bake writes comes near it.
pub const OUTPUT_LIMIT: u64 = HEADER_BYTES as u64 + PROVENANCE_LIMIT + PAYLOAD_LIMIT;

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
    /// The settings of the bake as a whole (version 2; empty when read from version 1). With the
    /// inputs' hashes and the tool's version they decide whether a bake is up to date.
    pub parameters: serde_json::Map<String, serde_json::Value>,
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
    /// What the stage measured to validate its outputs (version 2; empty when read from
    /// version 1); free-form per stage, documented with the stage.
    pub figures: serde_json::Map<String, serde_json::Value>,
    pub outputs: Vec<StageOutput>,
}

/// The file formats a bake writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FileFormat {
    /// The asset container (`data-schema/README.md`).
    Asset,
    /// Khronos KTX 2.0 texture.
    Ktx2,
    /// OpenEXR image.
    Exr,
    /// PNG picture, for people.
    Png,
    /// JSON document.
    Json,
    /// glTF 2.0 JSON document.
    Gltf,
    /// A glTF buffer (`.bin`), named by a glTF document beside it.
    Bin,
    /// MERL BRDF table (`data-schema/merl.md`).
    Merl,
}

impl FileFormat {
    pub const ALL: [FileFormat; 8] = [
        FileFormat::Asset,
        FileFormat::Ktx2,
        FileFormat::Exr,
        FileFormat::Png,
        FileFormat::Json,
        FileFormat::Gltf,
        FileFormat::Bin,
        FileFormat::Merl,
    ];

    /// The name in the manifest.
    pub fn name(self) -> &'static str {
        match self {
            FileFormat::Asset => "asset",
            FileFormat::Ktx2 => "ktx2",
            FileFormat::Exr => "exr",
            FileFormat::Png => "png",
            FileFormat::Json => "json",
            FileFormat::Gltf => "gltf",
            FileFormat::Bin => "bin",
            FileFormat::Merl => "merl",
        }
    }
}

/// One file a stage wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageOutput {
    /// Relative to the manifest's folder, with `/` separators.
    pub path: String,
    pub format: FileFormat,
    /// What the file is for, stable across versions of the tools (e.g. `phong-layers`,
    /// `bandwidth-atlas-picture`): readers find a bake's files by role, not by name.
    pub role: String,
    /// The asset kind; present exactly when `format` is [`FileFormat::Asset`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<AssetKind>,
    /// The container format version of an asset; present exactly when `format` is
    /// [`FileFormat::Asset`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format_version: Option<u32>,
    pub size_bytes: u64,
    /// SHA-256 of the whole file, 64 lower-case hexadecimal digits.
    pub sha256: String,
}

impl StageOutput {
    /// Describes a file of `bytes` that this build writes at `path` (relative to the manifest).
    /// An asset's kind is read from its header.
    pub fn of_bytes(path: &str, format: FileFormat, role: &str, bytes: &[u8]) -> Result<StageOutput, Error> {
        let kind = match format {
            FileFormat::Asset => Some(crate::container::read_header(bytes)?.kind),
            _ => None,
        };
        Ok(StageOutput {
            path: path.to_owned(),
            format,
            role: role.to_owned(),
            kind,
            format_version: kind.map(|_| FORMAT_VERSION),
            size_bytes: bytes.len() as u64,
            sha256: hex(&crate::files::sha256(bytes)),
        })
    }

    /// Whether the file at `path` in the manifest's folder has the size described: a regular file
    /// (reached without following a link), its size from its metadata; nothing is read. A
    /// missing file, a link, a FIFO or a device is `false`.
    pub fn matches_size(&self, folder: &fsguard::Folder) -> std::io::Result<bool> {
        match folder.open_file(&self.path) {
            Ok(file) => Ok(file.metadata()?.len() == self.size_bytes),
            Err(e) if matches!(e.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::InvalidInput) => Ok(false),
            Err(e) => Err(e),
        }
    }

    /// Whether the file at `path` in the manifest's folder is still the one described: a regular
    /// file (reached without following a link, [`fsguard::Folder::open_file`]) of the same size,
    /// from its metadata, and hash, reading exactly that size. A missing file, a link, a FIFO or a
    /// device is `false`, never read; other failures to read are errors.
    pub fn matches_file(&self, folder: &fsguard::Folder) -> std::io::Result<bool> {
        let file = match folder.open_file(&self.path) {
            Ok(file) => file,
            Err(e) if matches!(e.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::InvalidInput) => {
                return Ok(false);
            }
            Err(e) => return Err(e),
        };
        if file.metadata()?.len() != self.size_bytes {
            return Ok(false);
        }
        Ok(hex(&sha256_open(file)?) == self.sha256)
    }

    /// The bytes of the file at `path` in the manifest's folder, when it is the one described:
    /// resolved and opened as [`StageOutput::matches_file`] does, its size checked against
    /// `size_bytes` (and [`OUTPUT_LIMIT`]) from its metadata before anything is read, its SHA-256
    /// against `sha256` after. The error says which check failed.
    pub fn read(&self, folder: &fsguard::Folder) -> std::io::Result<Vec<u8>> {
        let not_described = |why: String| {
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("not the file the manifest describes ({why}): bake again"),
            )
        };
        let file = folder.open_file(&self.path)?;
        let len = file.metadata()?.len();
        if len != self.size_bytes {
            return Err(not_described(format!("{len} bytes, the manifest says {}", self.size_bytes)));
        }
        let bytes = fsguard::read_to_end(file, self.size_bytes.min(OUTPUT_LIMIT))?;
        if hex(&crate::files::sha256(&bytes)) != self.sha256 {
            return Err(not_described("its sha256 differs".into()));
        }
        Ok(bytes)
    }

    /// Checks the invariants the types cannot express: `kind` and `format_version` come with
    /// assets and only with them; the path names a file inside the manifest's folder
    /// ([`fsguard::check_relative`]: relative, `/`-separated, no empty, `.` or `..` component, no
    /// `\` or NUL).
    fn check(&self) -> Result<(), String> {
        let is_asset = self.format == FileFormat::Asset;
        if is_asset != self.kind.is_some() || is_asset != self.format_version.is_some() {
            return Err(format!("output {:?}: kind and format_version belong to assets and only to them", self.path));
        }
        fsguard::check_relative(&self.path).map_err(|e| format!("output {e}"))
    }
}

impl BakeManifest {
    /// A manifest of the current version with no stages yet.
    pub fn new(
        material: SourceFile,
        environment: Option<SourceFile>,
        tool: Tool,
        parameters: serde_json::Map<String, serde_json::Value>,
    ) -> BakeManifest {
        BakeManifest { manifest_version: MANIFEST_VERSION, material, environment, tool, parameters, stages: Vec::new() }
    }

    /// Parses a manifest of any readable version (version 1 is converted: its outputs are
    /// assets whose role is their kind's name, with no figures and no bake parameters) and checks
    /// what the types cannot (paths, asset fields, no path listed twice). The JSON Schema says
    /// more (hash patterns).
    pub fn from_json(text: &str) -> Result<BakeManifest, Error> {
        let invalid = |e: serde_json::Error| Error::Invalid(format!("invalid bake manifest: {e}"));
        // Parsed from the text, not through a `Value`, so that a key given twice is named
        // (`duplicate field `manifest_version``) rather than the last one read silently.
        #[derive(Deserialize)]
        struct Version {
            manifest_version: Option<serde_json::Value>,
        }
        let version = serde_json::from_str::<Version>(text).map_err(invalid)?.manifest_version;
        let manifest = match version.as_ref().and_then(serde_json::Value::as_u64) {
            Some(1) => serde_json::from_str::<v1::BakeManifest>(text).map_err(invalid)?.into(),
            Some(2) => serde_json::from_str::<BakeManifest>(text).map_err(invalid)?,
            Some(found) => {
                return Err(Error::UnsupportedVersion {
                    what: "manifest",
                    found: u32::try_from(found).unwrap_or(u32::MAX),
                    readable: READABLE_MANIFEST_VERSIONS,
                });
            }
            None => return Err(Error::Invalid("invalid bake manifest: no integer manifest_version".into())),
        };
        // Every version: paths name files inside the folder (version 1's schema allowed any
        // relative path; its readers apply the same rule as version 2's).
        // A path listed twice is refused rather than read, hashed or drawn again for each copy.
        let mut paths = std::collections::HashSet::new();
        for output in manifest.outputs() {
            output.check().map_err(|e| Error::Invalid(format!("invalid bake manifest: {e}")))?;
            if !paths.insert(output.path.as_str()) {
                return Err(Error::Invalid(format!("invalid bake manifest: output {:?} is listed twice", output.path)));
            }
        }
        Ok(manifest)
    }

    /// [`BakeManifest::from_json`] of a file's bytes, which must be UTF-8 and at most
    /// [`MANIFEST_LIMIT`] long.
    pub fn from_bytes(bytes: &[u8]) -> Result<BakeManifest, Error> {
        if bytes.len() as u64 > MANIFEST_LIMIT {
            return Err(Error::LimitExceeded { what: "manifest", found: bytes.len() as u64, limit: MANIFEST_LIMIT });
        }
        let text = std::str::from_utf8(bytes)
            .map_err(|e| Error::Invalid(format!("invalid bake manifest: not utf-8 text ({e})")))?;
        BakeManifest::from_json(text)
    }

    /// The manifest of the bake held open as `folder` ([`MANIFEST_FILE`]): a regular file in it
    /// (not a link, a FIFO or a device), at most [`MANIFEST_LIMIT`] bytes by its metadata before
    /// it is read. A missing manifest is [`Error::Io`] of kind `NotFound`.
    pub fn read(folder: &fsguard::Folder) -> Result<BakeManifest, Error> {
        BakeManifest::from_bytes(&folder.read(MANIFEST_FILE, MANIFEST_LIMIT)?)
    }

    /// Pretty JSON with a trailing newline, ready for [`crate::write_atomic`].
    pub fn to_json(&self) -> String {
        // Maps with string keys and plain structs always serialize.
        let mut text = serde_json::to_string_pretty(self).expect("manifest types always serialize");
        text.push('\n');
        text
    }

    /// Every output of every stage, in order.
    pub fn outputs(&self) -> impl Iterator<Item = &StageOutput> {
        self.stages.iter().flat_map(|s| &s.outputs)
    }

    /// The output with this role, if the bake wrote one.
    pub fn output(&self, role: &str) -> Option<&StageOutput> {
        self.outputs().find(|o| o.role == role)
    }

    /// The output at this path, if the bake wrote one.
    pub fn output_by_path(&self, path: &str) -> Option<&StageOutput> {
        self.outputs().find(|o| o.path == path)
    }
}

/// Manifest version 1, read and converted; never written.
mod v1 {
    use serde::Deserialize;

    use super::{FileFormat, SourceFile, Tool};
    use crate::types::AssetKind;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct BakeManifest {
        #[allow(dead_code, reason = "checked by from_json before this type is chosen")]
        manifest_version: u32,
        material: SourceFile,
        #[serde(default)]
        environment: Option<SourceFile>,
        tool: Tool,
        stages: Vec<Stage>,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Stage {
        name: String,
        parameters: serde_json::Map<String, serde_json::Value>,
        outputs: Vec<StageOutput>,
    }

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct StageOutput {
        path: String,
        kind: AssetKind,
        format_version: u32,
        size_bytes: u64,
        sha256: String,
    }

    impl From<BakeManifest> for super::BakeManifest {
        fn from(m: BakeManifest) -> super::BakeManifest {
            let stages = m
                .stages
                .into_iter()
                .map(|s| super::Stage {
                    name: s.name,
                    parameters: s.parameters,
                    figures: serde_json::Map::new(),
                    outputs: s
                        .outputs
                        .into_iter()
                        .map(|o| super::StageOutput {
                            path: o.path,
                            format: FileFormat::Asset,
                            role: o.kind.name().to_string(),
                            kind: Some(o.kind),
                            format_version: Some(o.format_version),
                            size_bytes: o.size_bytes,
                            sha256: o.sha256,
                        })
                        .collect(),
                })
                .collect();
            super::BakeManifest {
                manifest_version: 1,
                material: m.material,
                environment: m.environment,
                tool: m.tool,
                parameters: serde_json::Map::new(),
                stages,
            }
        }
    }
}
