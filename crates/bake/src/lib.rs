//! The bake: every stage of the toolchain as one library call — inputs and parameters in; the
//! files, their manifest entries, the figures that validate them and a human report out — so
//! that the single-stage tools (`merl-importance`, `brdf-bandwidth`, `bandwidth-pca`,
//! `envmap-bandwidth`, `envmap-prefilter`) and `brdf-bake` write the same bytes through the same
//! code, and every tool's `main` is argument parsing and printing.
//!
//! - [`stage`]: one module per stage. A stage computes everything in memory and returns a
//!   [`Staged`]; nothing touches the disk until [`Staged::write`], which writes the files one by
//!   one, each atomically (temporary file, then rename: `asset::write_atomic`).
//! - [`run_bake`]: the per-material stages (importance samples, bandwidth atlas, optional PCA)
//!   and, with an environment, the environment stages (bandwidth map, Phong layers and mip chain)
//!   and the layer selection that ties the two together, into one folder with a
//!   `manifest.json` (`data-schema/README.md`, manifest version 2), incrementally.
//! - [`load`]: a finished bake read back for the renderers (`render::Material`,
//!   `render::Lighting`).
//!
//! Architecture Invariant: a stage's outputs are deterministic: the same inputs and parameters
//! give the same bytes, whatever the number of threads (no time stamps, no absolute paths, no
//! unordered reductions), so that a manifest's hashes say whether anything changed.
//!
//! Architecture Invariant: a bake's manifest is written last, after every file it names, and the
//! previous manifest is removed before the first file is replaced, so that a manifest never
//! names a missing or stale file, even after an interrupted bake.

mod error;
mod load;
mod run;
pub mod sheet;
pub mod stage;

use std::path::{Path, PathBuf};

pub use error::Error;
pub use load::{Loaded, load, wavelet as load_wavelet};
pub use run::{BakeConfig, BakeOutcome, MANIFEST, Progress, run_bake};

use asset::{FileFormat, StageOutput};

/// The program a stage runs in, recorded in every asset's provenance and in the manifest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Program {
    pub name: &'static str,
    pub version: &'static str,
}

/// An input file and the SHA-256 of its bytes, hashed once per run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Source {
    pub path: PathBuf,
    pub sha256: [u8; 32],
}

impl Source {
    /// Hashes the file at `path` (in a stream).
    pub fn hash(path: &Path) -> Result<Source, Error> {
        let sha256 = asset::sha256_file(path).map_err(|e| Error::read(path, e))?;
        Ok(Source { path: path.to_path_buf(), sha256 })
    }

    /// A file this run holds in memory (e.g. an asset it wrote and reads on).
    pub fn of_bytes(path: &Path, bytes: &[u8]) -> Source {
        Source { path: path.to_path_buf(), sha256: asset::sha256(bytes) }
    }

    /// The file's name, without its folder: what provenance records, so that an asset does not
    /// depend on where the bake ran.
    pub fn file_name(&self) -> String {
        self.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
    }

    /// The file's name without its extension, for reports and manifests.
    pub fn stem(&self) -> String {
        self.path.file_stem().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
    }

    /// The provenance of an asset `program` made from this file with `parameters`.
    pub fn provenance(&self, program: &Program, parameters: &[(&str, String)]) -> asset::Provenance {
        asset::Provenance {
            source_name: self.file_name(),
            source_sha256: self.sha256,
            tool: program.name.to_string(),
            tool_version: program.version.to_string(),
            parameters: parameters.iter().map(|(k, v)| (k.to_string(), v.clone())).collect(),
        }
    }
}

/// One file a stage made, in memory.
#[derive(Clone, Debug, PartialEq)]
pub struct OutFile {
    /// The file name in the output folder.
    pub name: String,
    pub format: FileFormat,
    /// What the file is for (`data-schema/README.md` lists the roles).
    pub role: &'static str,
    pub bytes: Vec<u8>,
}

/// What a stage made: its files, the settings that shaped them, the figures that validate them,
/// a report for people and the problems its validation found.
#[derive(Clone, Debug, PartialEq)]
pub struct Staged {
    pub name: &'static str,
    pub parameters: serde_json::Map<String, serde_json::Value>,
    pub figures: serde_json::Map<String, serde_json::Value>,
    pub files: Vec<OutFile>,
    /// Lines for a person, without trailing newlines; plain numbers, every column explained.
    pub report: Vec<String>,
    /// What validation found wrong (the tools exit 1 when there is any).
    pub problems: Vec<String>,
}

impl Staged {
    /// Writes the stage's files into `dir` (created if missing) as one set ([`asset::write_set`]):
    /// all of them or none, the asset, which may name the others, landing last. Returns the
    /// stage's manifest entry with the files' paths relative to `dir`.
    pub fn write(&self, dir: &Path) -> Result<asset::Stage, Error> {
        let mut files: Vec<&OutFile> = self.files.iter().collect();
        files.sort_by_key(|f| f.format == asset::FileFormat::Asset);
        let set: Vec<(&str, &[u8])> = files.iter().map(|f| (f.name.as_str(), &f.bytes[..])).collect();
        asset::write_set(dir, &set).map_err(|(path, e)| Error::write(&path, e))?;
        self.manifest_stage()
    }

    /// The stage's manifest entry (paths are the file names).
    pub fn manifest_stage(&self) -> Result<asset::Stage, Error> {
        // Hashing is most of the work: the files in parallel, in order.
        use rayon::prelude::*;
        let outputs = self
            .files
            .par_iter()
            .map(|f| StageOutput::of_bytes(&f.name, f.format, f.role, &f.bytes))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| Error::Internal(format!("describing the outputs of stage {}: {e}", self.name)))?;
        Ok(asset::Stage {
            name: self.name.to_string(),
            parameters: self.parameters.clone(),
            figures: self.figures.clone(),
            outputs,
        })
    }

    /// The object a tool prints with `--json`: the stage's figures, parameters, problems and the
    /// files it wrote into `dir` (path, format, role, size, SHA-256).
    pub fn json(&self, dir: &Path) -> Result<serde_json::Value, Error> {
        let stage = self.manifest_stage()?;
        let files: Vec<serde_json::Value> = stage
            .outputs
            .iter()
            .map(|o| {
                let mut v = serde_json::to_value(o).expect("manifest outputs serialize");
                v["path"] = dir.join(&o.path).display().to_string().into();
                v
            })
            .collect();
        Ok(serde_json::json!({
            "stage": self.name,
            "parameters": self.parameters,
            "figures": self.figures,
            "problems": self.problems,
            "files": files,
        }))
    }

    /// The paths of the files in `dir`, for "wrote ..." lines.
    pub fn written(&self, dir: &Path) -> Vec<String> {
        self.files.iter().map(|f| dir.join(&f.name).display().to_string()).collect()
    }

    /// The file with this role, if the stage made one.
    pub fn file(&self, role: &str) -> Option<&OutFile> {
        self.files.iter().find(|f| f.role == role)
    }
}

/// A JSON object from `(key, value)` pairs, in order.
pub(crate) fn object<const N: usize>(
    pairs: [(&str, serde_json::Value); N],
) -> serde_json::Map<String, serde_json::Value> {
    pairs.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}
