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
//! names a missing or stale file, even after an interrupted bake. The new files are written in full
//! beside the old ones before anything is replaced, so a bake that fails (a refused input, a full
//! disk, a read-only folder) leaves the previous bake intact and listed; one bake at a time holds a
//! folder (its advisory lock).
//!
//! Architecture Invariant: a bake touches nothing outside its folder, and nothing in it that it did
//! not write: paths a manifest names are resolved inside the folder without following links
//! (`fsguard`), only regular files are read, each with a size bound, and a rebake removes a
//! previous file only under a name some stage writes and only while it is the file the previous
//! manifest describes.

mod error;
mod load;
mod run;
pub mod sheet;
pub mod stage;

use std::path::{Path, PathBuf};

pub use error::Error;
pub use load::{Loaded, bake_fit_table, bake_wavelet_brdf, load, load_wavelet_brdf};
pub use run::{BakeConfig, BakeOutcome, MANIFEST, Progress, run_bake, write_stage};

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
    /// Hashes the file at `path` (in a stream; a regular file only, never a FIFO or a device:
    /// [`asset::sha256_file`]).
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
    /// Writes the stage's files into `dir` (created if missing: the folder itself, its parent must
    /// exist) as one set ([`asset::write_set`]): all of them or none, the asset, which may name
    /// the others, landing last. Returns the stage's manifest entry with the files' paths relative
    /// to `dir`.
    ///
    /// A bake folder (one with a manifest) is refused, with what to do instead: the files would
    /// replace some of the bake's and its manifest would then lie; [`write_stage`] writes a stage
    /// into a bake through the bake's protocol. The folder's lock is held while writing, so a bake
    /// running in it is [`Error::Busy`] too.
    pub fn write(&self, dir: &Path) -> Result<asset::Stage, Error> {
        let folder = fsguard::Folder::create(dir).map_err(|e| Error::write(dir, e))?;
        if !folder.try_lock().map_err(|e| Error::write(dir, e))? {
            return Err(Error::Busy(dir.to_path_buf()));
        }
        if std::fs::symlink_metadata(dir.join(MANIFEST)).is_ok() {
            return Err(Error::Invalid(format!(
                "{} is a bake folder (it has a {MANIFEST}): writing the {} stage's files into it would make its \
                 manifest lie; bake it again with brdf-bake, or write into another folder",
                dir.display(),
                self.name
            )));
        }
        self.write_set(dir)
    }

    /// [`Staged::write`] without the checks: the caller holds the folder.
    fn write_set(&self, dir: &Path) -> Result<asset::Stage, Error> {
        let set: Vec<(&str, &[u8])> = self.ordered().iter().map(|f| (f.name.as_str(), &f.bytes[..])).collect();
        asset::write_set(dir, &set).map_err(|(path, e)| Error::write(&path, e))?;
        self.manifest_stage()
    }

    /// Adds the stage's files to `staging` (the new files of a bake, switched in together) and
    /// returns the stage's manifest entry.
    fn stage(&self, staging: &mut asset::Staging) -> Result<asset::Stage, Error> {
        for f in self.ordered() {
            staging.add(&f.name, &f.bytes).map_err(|(path, e)| Error::write(&path, e))?;
        }
        self.manifest_stage()
    }

    /// The files with the asset, which may name the others, last.
    fn ordered(&self) -> Vec<&OutFile> {
        let mut files: Vec<&OutFile> = self.files.iter().collect();
        files.sort_by_key(|f| f.format == asset::FileFormat::Asset);
        files
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
