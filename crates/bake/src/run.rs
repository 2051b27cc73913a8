//! A bake: every per-material stage and, with an environment, every environment stage, into one
//! folder with a manifest; incremental and safe to interrupt.

use std::path::{Path, PathBuf};

use asset::{BakeManifest, SourceFile, Tool};
use serde_json::json;

use crate::stage::{self, engine, env_bandwidth, fit, importance, layer_selection, pca, prefilter, wavelet_brdf};
use crate::{Error, OutFile, Program, Source, Staged, object};

/// The manifest's file name in a bake's folder.
pub const MANIFEST: &str = asset::MANIFEST_FILE;

/// What to bake and how.
#[derive(Clone, Debug)]
pub struct BakeConfig {
    /// The MERL table.
    pub material: PathBuf,
    /// The environment map, for the environment stages.
    pub environment: Option<PathBuf>,
    /// The folder the bake writes (created if missing: the folder itself, its parent must exist).
    pub out_dir: PathBuf,
    pub importance: ::importance::Config,
    pub atlas: bandwidth_atlas::Config,
    /// Fit a PCA model of the atlas with the fewest components within this relative RMSE.
    pub pca_max_error: Option<f64>,
    /// Encode the material in Haar wavelets (`brdf-wavelet`) with these settings.
    pub wavelet_brdf: Option<wavelet_brdf::Settings>,
    /// Fit the closest glTF material (`brdf-fit`) with these settings.
    pub fit: Option<gltf_fit::Settings>,
    /// The environment bandwidth's settings; its reading is [`BakeConfig::env_reading`]'s, resolved
    /// for the material (the reading of `config` here is not read).
    pub env_bandwidth: env_bandwidth::Settings,
    /// Which reading the environment's bandwidth takes ([`env_bandwidth::ReadingChoice`]).
    pub env_reading: env_bandwidth::ReadingChoice,
    pub prefilter: ::prefilter::Config,
    /// How a view's lobe and a layer's lobe become the numbers the layer selection compares.
    pub layer_reduction: bandwidth_atlas::view::ViewReduction,
    /// With an environment, also write the engine textures (`stage::engine`): what the
    /// estimators read, as KTX2 data textures for engines.
    pub engine_textures: bool,
    /// Bake even when the folder's manifest says it is up to date.
    pub force: bool,
}

impl BakeConfig {
    /// The default settings of every stage.
    pub fn new(material: PathBuf, environment: Option<PathBuf>, out_dir: PathBuf) -> BakeConfig {
        BakeConfig {
            material,
            environment,
            out_dir,
            importance: ::importance::Config::default(),
            atlas: bandwidth_atlas::Config::default(),
            pca_max_error: None,
            wavelet_brdf: None,
            fit: None,
            env_bandwidth: env_bandwidth::Settings::default(),
            env_reading: env_bandwidth::ReadingChoice::Auto,
            prefilter: ::prefilter::Config::default(),
            layer_reduction: layer_selection::DEFAULT_REDUCTION,
            engine_textures: false,
            force: false,
        }
    }

    /// Checks every stage's settings, so that a bake that cannot finish refuses to start (and
    /// leaves the folder as it was).
    pub fn check(&self) -> Result<(), Error> {
        if self.engine_textures && self.environment.is_none() {
            return Err(Error::Invalid(
                "the engine textures hold the lighting too: they need an environment (--env)".into(),
            ));
        }
        self.importance.check().map_err(|e| Error::stage("importance samples", e))?;
        if !self.importance.n_samples.is_power_of_two() {
            return Err(Error::Invalid(format!(
                "{} importance samples per vector: the renderers take power-of-two blocks of a vector, so it must \
                 be a power of two",
                self.importance.n_samples
            )));
        }
        self.atlas.check().map_err(|e| Error::stage("bandwidth atlas", e))?;
        if let Some(e) = self.pca_max_error
            && !(e > 0.0 && e < 1.0)
        {
            return Err(Error::Invalid(format!("the pca's largest relative rmse {e} is not in (0, 1)")));
        }
        self.prefilter.check().map_err(|e| Error::stage("prefilter", e))?;
        if let Some(w) = &self.wavelet_brdf {
            w.check()?;
        }
        Ok(())
    }

    /// Every setting that shapes an output, as the manifest records it.
    pub fn parameters(&self) -> serde_json::Map<String, serde_json::Value> {
        let i = &self.importance;
        let a = &self.atlas;
        let e = &self.env_bandwidth;
        let p = &self.prefilter;
        object([
            (
                "importance",
                json!({
                    "theta_o": i.n_theta_o, "theta_h_subdivision": i.theta_h_subdivision, "phi_h": i.n_phi_h,
                    "supersampling": i.supersampling, "defensive": i.defensive, "vectors": i.n_vectors,
                    "samples": i.n_samples, "seed": i.seed,
                }),
            ),
            (
                "bandwidth_atlas",
                json!({
                    "lobes": a.lobes, "tile": a.tile, "analysis_size": a.analysis_size, "eps": a.eps, "c": a.c,
                    "relative_noise_floor": a.relative_noise_floor,
                }),
            ),
            ("pca_max_error", json!(self.pca_max_error)),
            (
                "wavelet_brdf",
                self.wavelet_brdf
                    .as_ref()
                    .map_or(serde_json::Value::Null, |w| serde_json::Value::Object(w.parameters())),
            ),
            (
                "fit",
                self.fit.as_ref().map_or(
                    serde_json::Value::Null,
                    |f| json!({ "masking": f.masking.name(), "objective": f.objective.name(), "margin": f.margin }),
                ),
            ),
            (
                "environment_bandwidth",
                json!({
                    "mode": e.mode.name(), "eps": e.config.eps, "c": e.config.c, "levels": e.config.levels,
                    "reading": self.env_reading.name(), "fft_diagnostic": e.fft_diagnostic,
                }),
            ),
            (
                "prefilter",
                json!({
                    "exponents": p.exponents, "size": [p.width, p.height], "method": p.method.name(),
                    "storage": p.storage.name(), "cube": p.cube, "ggx_levels": p.ggx_levels, "chain": p.chain,
                }),
            ),
            ("layer_reduction", json!(self.layer_reduction.name())),
            ("engine_textures", json!(self.engine_textures)),
        ])
    }
}

/// What a bake reports while it runs.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// Stage `index` (from 0) of `count` begins.
    Stage { index: usize, count: usize, name: &'static str },
    /// Within the current stage, `done` of `total` units of work are done.
    Work { done: u64, total: u64 },
}

/// What a bake did.
#[derive(Debug)]
pub struct BakeOutcome {
    /// The manifest now in the folder.
    pub manifest: BakeManifest,
    /// The folder already held this bake: nothing was written.
    pub up_to_date: bool,
    /// Each stage's report for people, in order (empty when up to date).
    pub reports: Vec<(&'static str, Vec<String>)>,
    /// What the stages' validation found (the tool exits 1 when there is any).
    pub problems: Vec<String>,
}

/// Runs the bake described by `config`, as `data-schema/README.md` ("Bake folders") specifies:
///
/// 1. The inputs are read (regular files only, with their size bounds) and hashed before the
///    folder is touched; the folder is created if missing (itself only, not its parents) and its
///    advisory lock taken for the whole run (a second bake of the same folder is
///    [`Error::Busy`], at once, without waiting).
/// 2. When the folder's manifest was written by this program and version from inputs with the
///    same hashes and the same parameters, and every file it names is still the one it describes,
///    nothing is written (only temporary files a killed bake left are removed) and the outcome
///    says so.
/// 3. Otherwise every stage runs and its files are written beside the old ones as synced
///    temporary files, the new manifest last. Any failure up to here (a refused input, a full
///    disk, a read-only folder) removes them and leaves the previous bake as it was, listed by
///    its manifest.
/// 4. The switch, by renames alone: the old manifest is removed, every new file renamed into
///    place, the previous bake's files that this one does not write removed (only under a name
///    some stage writes, as a regular file that is still the one the old manifest describes), and
///    the new manifest renamed into place last.
pub fn run_bake(
    config: &BakeConfig,
    program: &Program,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<BakeOutcome, Error> {
    config.check()?;
    // The map is held through both environment stages: the larger of their needs per texel,
    // under the budget less the layers (a budget the layers alone exceed is refused here).
    let limits = envmap::Limits {
        bytes_per_texel: env_bandwidth::BYTES_PER_TEXEL.max(prefilter::BYTES_PER_TEXEL),
        ..prefilter::limits(&config.prefilter, config.env_bandwidth.max_memory)?
    };
    let out = &config.out_dir;
    // The table's bytes are read once: what is hashed is what is parsed.
    let material_bytes = merl::read_bytes(&config.material).map_err(|e| Error::read(&config.material, e))?;
    let material_source = Source::of_bytes(&config.material, &material_bytes);
    let environment_source = config.environment.as_deref().map(Source::hash).transpose()?;
    let mut manifest = BakeManifest::new(
        source_file(&material_source),
        environment_source.as_ref().map(source_file),
        Tool { name: program.name.to_string(), version: program.version.to_string() },
        config.parameters(),
    );
    let folder = BakeFolder::lock(out)?;
    let previous = folder.manifest();
    if !config.force
        && let Some(previous) = &previous
        && is_same_bake(previous, &manifest)
        && folder.all_files_match(previous, &config.prefilter.exponents)?
    {
        // Only the temporary files a killed run of ours left (none the manifest names) go.
        folder.remove_temporaries()?;
        let problems = recorded_problems(previous);
        return Ok(BakeOutcome { manifest: previous.clone(), up_to_date: true, reports: Vec::new(), problems });
    }

    // Both inputs are decoded before anything is written: a bake that cannot run leaves the
    // previous one as it was.
    let table = merl::MerlTable::parse(&material_bytes).map_err(|e| Error::read(&config.material, e))?;
    let material_size = material_bytes.len() as u64;
    drop(material_bytes);
    // The cells' pass finds a value no material has; the albedo waits for the importance stage's
    // quadrature, below (a refusal then drops what was staged: the folder is left as it was).
    let problems = crate::stage::material_info::unphysical(&merl::summary::summarize_cells(&table));
    if !problems.is_empty() {
        return Err(Error::Unphysical { path: config.material.clone(), problems });
    }
    let map = config
        .environment
        .as_deref()
        .map(|path| envmap::load_with_limits(path, &limits).map_err(|e| Error::read(path, e)))
        .transpose()?;

    // Temporary files an interrupted bake left: the folder is locked, so none is being written.
    folder.remove_temporaries()?;
    let mut staging = folder.staging()?;

    let stages = stage_names(config);
    let mut reports = Vec::new();
    let mut problems = Vec::new();
    let mut next = 0;
    let mut begin = |name: &'static str| {
        progress(Progress::Stage { index: next, count: stages.len(), name });
        next += 1;
    };
    // The outputs the engine textures are made of, as `load` would read them back.
    let kept: std::cell::RefCell<Vec<OutFile>> = std::cell::RefCell::new(Vec::new());
    let mut record = |staged: Staged, manifest: &mut BakeManifest| -> Result<(), Error> {
        if config.engine_textures {
            kept.borrow_mut().extend(staged.files.iter().filter(|f| ENGINE_INPUTS.contains(&f.role)).cloned());
        }
        let mut stage = staged.stage(&mut staging)?;
        // The manifest keeps what validation found, so that a rerun that finds the bake up to
        // date reports (and exits with) the same.
        if !staged.problems.is_empty() {
            stage.figures.insert("problems".into(), json!(staged.problems));
        }
        manifest.stages.push(stage);
        problems.extend(staged.problems.iter().map(|p| format!("{}: {p}", staged.name)));
        reports.push((staged.name, staged.report));
        Ok(())
    };
    let work = |done: u64, total: u64| progress(Progress::Work { done, total });

    begin("importance samples");
    let (staged, albedo) = importance::run_measured(&table, &material_source, program, &config.importance, true)?;
    let unphysical = crate::stage::material_info::unphysical_albedo(&albedo);
    if !unphysical.is_empty() {
        return Err(Error::Unphysical { path: config.material.clone(), problems: unphysical });
    }
    record(staged, &mut manifest)?;
    begin("bandwidth atlas");
    let lobes = (config.atlas.lobes * config.atlas.lobes) as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    let tick = |n: usize| {
        let now = done.fetch_add(n as u64, std::sync::atomic::Ordering::Relaxed) + n as u64;
        work(now, lobes);
    };
    let analyser = bandwidth_atlas::Analyser::new(&config.atlas);
    let (staged, atlas_build) = stage::bandwidth_atlas::run(
        &bandwidth_atlas::LuminanceTable::new(&table),
        &analyser,
        &material_source,
        program,
        &tick,
    )?;
    let atlas_source = staged.file("bandwidth-atlas").map(|f| Source::of_bytes(Path::new(&f.name), &f.bytes));
    record(staged, &mut manifest)?;
    if let Some(max_error) = config.pca_max_error {
        begin("bandwidth pca");
        let source = atlas_source.ok_or_else(|| Error::Internal("the atlas stage wrote no atlas".into()))?;
        let components = bandwidth_atlas::Components::MaxRelativeRmse(max_error);
        record(pca::run(&atlas_build.atlas, &source, program, components)?, &mut manifest)?;
    }
    if let Some(settings) = config.wavelet_brdf {
        begin("wavelet encoding");
        record(wavelet_brdf::run(&table, &material_source, program, settings)?, &mut manifest)?;
    }
    if let Some(settings) = &config.fit {
        begin("glTF fit");
        let report = |stage: gltf_fit::Stage, s: &gltf_fit::Settings| {
            if let gltf_fit::Stage::Refine(_, done) = stage {
                work(done as u64, s.max_iterations as u64);
            }
        };
        let staged = fit::run(&table, &material_source, material_size, program, settings, &report).staged;
        record(staged, &mut manifest)?;
    }

    if let (Some(path), Some(source), Some(map)) = (&config.environment, &environment_source, &map) {
        begin("environment bandwidth");
        // The layer selection is made first: the reading of the environment's bandwidth follows
        // the material's lobes (`env_bandwidth::ReadingChoice`).
        let selection =
            layer_selection::select(&atlas_build, &config.atlas, &config.prefilter.exponents, config.layer_reduction)?;
        let settings = env_bandwidth::Settings {
            config: bandwidth::Config {
                reading: config.env_reading.resolve(&selection),
                ..config.env_bandwidth.config
            },
            ..config.env_bandwidth.clone()
        };
        record(env_bandwidth::run_on_map(path, map, &settings).map_err(of_map(path))?, &mut manifest)?;
        begin("phong layers and mip chain");
        let (staged, _prefiltered) =
            prefilter::run(map, source, program, &config.prefilter, &work).map_err(of_map(path))?;
        record(staged, &mut manifest)?;
        begin("layer selection");
        record(
            layer_selection::run(&selection, &config.atlas, &atlas_build, &material_source, program)?,
            &mut manifest,
        )?;
        if config.engine_textures {
            begin("engine textures");
            let file = |role: &str| -> Result<(PathBuf, Vec<u8>), Error> {
                let kept = kept.borrow();
                let f = kept.iter().find(|f| f.role == role).ok_or_else(|| {
                    Error::Internal(format!("the engine textures need the {role} output, which no stage made"))
                })?;
                Ok((out.join(&f.name), f.bytes.clone()))
            };
            let (material, lighting) = crate::load::assemble(table, true, &file)?;
            let lighting = lighting.ok_or_else(|| Error::Internal("the bake's lighting is missing".into()))?;
            record(engine::run(&material, &lighting, program)?, &mut manifest)?;
        }
    }

    folder.switch(staging, previous.as_ref(), &manifest)?;
    Ok(BakeOutcome { manifest, up_to_date: false, reports, problems })
}

/// Writes one stage's files (`staged`, made by `program` from `material`) into `dir` for a
/// single-stage tool: into a plain folder as one set ([`Staged::write`]); into a bake folder (one
/// with a manifest) as `brdf-bake` would have written that stage, through the bake's protocol
/// ([`run_bake`]): the folder locked, the files and the updated manifest (the stage added or
/// replaced in `brdf-bake`'s order of stages, the bake's parameter `parameter` set) written beside
/// the old ones and switched in, the replaced stage's files that the new one does not write
/// removed. The material must be the bake's (same SHA-256). Returns whether `dir` was a bake.
pub fn write_stage(
    dir: &Path,
    staged: &Staged,
    material: &Source,
    parameter: (&str, serde_json::Value),
) -> Result<bool, Error> {
    let folder = BakeFolder::lock(dir)?;
    let manifest_path = dir.join(MANIFEST);
    let previous = match BakeManifest::read(&folder.folder) {
        Ok(previous) => previous,
        Err(asset::Error::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => {
            staged.write_set(dir)?;
            return Ok(false);
        }
        Err(e) => {
            return Err(Error::read(
                &manifest_path,
                format!("{e}: a bake folder whose manifest this build cannot read: bake it again with brdf-bake"),
            ));
        }
    };
    if previous.material.source_sha256 != asset::hex(&material.sha256) {
        return Err(Error::Invalid(format!(
            "{} is a bake of {} (sha256 {}), not of {}: write into another folder, or bake this material with \
             brdf-bake",
            dir.display(),
            previous.material.name,
            previous.material.source_sha256,
            material.path.display()
        )));
    }
    let mut manifest = previous.clone();
    manifest.manifest_version = asset::MANIFEST_VERSION;
    manifest.parameters.insert(parameter.0.to_string(), parameter.1);
    folder.remove_temporaries()?;
    let mut staging = folder.staging()?;
    let mut stage = staged.stage(&mut staging)?;
    if !staged.problems.is_empty() {
        stage.figures.insert("problems".into(), json!(staged.problems));
    }
    let order = |name: &str| STAGE_ORDER.iter().position(|n| *n == name).unwrap_or(STAGE_ORDER.len());
    manifest.stages.retain(|s| s.name != stage.name);
    let at = manifest.stages.iter().position(|s| order(&s.name) > order(&stage.name)).unwrap_or(manifest.stages.len());
    manifest.stages.insert(at, stage);
    folder.switch(staging, Some(&previous), &manifest)?;
    Ok(true)
}

/// The stages' names (`Staged::name`) in the order `run_bake` runs them.
const STAGE_ORDER: [&str; 9] = [
    "importance",
    "bandwidth-atlas",
    "bandwidth-pca",
    "wavelet-brdf",
    "fit",
    "environment-bandwidth",
    "prefilter",
    "layer-selection",
    "engine-textures",
];

/// The roles of the outputs the engine textures are made of (`load::assemble` reads them).
const ENGINE_INPUTS: [&str; 5] =
    ["importance-samples", "prefiltered-envmap", "environment-mips", "phong-layers", "layer-selection"];

/// A bake's folder held by one writer: created if it was missing (the folder itself, never a
/// chain of parents) and locked (`flock(2)` on the folder) for as long as this value lives.
struct BakeFolder {
    folder: fsguard::Folder,
}

impl BakeFolder {
    fn lock(dir: &Path) -> Result<BakeFolder, Error> {
        let folder = fsguard::Folder::create(dir).map_err(|e| Error::write(dir, e))?;
        if !folder.try_lock().map_err(|e| Error::write(dir, e))? {
            return Err(Error::Busy(dir.to_path_buf()));
        }
        // A switch a kill interrupted is finished or undone first: the folder holds one whole
        // bake again before anything reads its manifest.
        asset::recover_switch(&folder).map_err(|e| Error::write(&dir.join(asset::SWITCH_JOURNAL), e))?;
        Ok(BakeFolder { folder })
    }

    /// The folder's manifest, if there is one this build can read; anything else (none, a link, a
    /// FIFO, a damaged or hostile manifest) is treated as no manifest: the bake then runs and
    /// replaces it, and removes none of the files it named.
    fn manifest(&self) -> Option<BakeManifest> {
        BakeManifest::read(&self.folder).ok()
    }

    /// Whether every file `manifest` names is the one it describes (a link, a FIFO or a device is
    /// not; none is followed or read). The work is bounded by what this bake writes, whatever the
    /// manifest lists: a path that is no stage's file name, or a Phong layer of an exponent this
    /// bake does not make (`exponents`), means another bake, and so does any file of another
    /// size; only then are the files hashed, at most one per name the stages write.
    fn all_files_match(&self, manifest: &BakeManifest, exponents: &[u32]) -> Result<bool, Error> {
        let ours = |path: &str| match path.strip_prefix("layer-n") {
            Some(_) => exponents.iter().any(|&n| crate::stage::prefilter::layer_exr(n) == path),
            None => crate::stage::is_output_name(path),
        };
        if !manifest.outputs().all(|output| ours(&output.path)) {
            return Ok(false);
        }
        for output in manifest.outputs() {
            let path = self.folder.join(&output.path);
            if !output.matches_size(&self.folder).map_err(|e| Error::read(&path, e))? {
                return Ok(false);
            }
        }
        for output in manifest.outputs() {
            let path = self.folder.join(&output.path);
            if !output.matches_file(&self.folder).map_err(|e| Error::read(&path, e))? {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Removes the temporary files an interrupted bake or tool left for the files a bake writes
    /// and for the manifest (`.NAME.XXXXXX.tmp`, regular files only).
    fn remove_temporaries(&self) -> Result<(), Error> {
        let ours = |target: &str| {
            target == MANIFEST || target == asset::SWITCH_JOURNAL || crate::stage::is_output_name(target)
        };
        asset::remove_temporaries(&self.folder, ours).map_err(|e| Error::write(self.folder.path(), e))?;
        Ok(())
    }

    /// An empty set of new files for the folder: written and switched in through its descriptor,
    /// so that the bake lands in this folder wherever it is moved meanwhile.
    fn staging(&self) -> Result<asset::Staging, Error> {
        asset::Staging::new(&self.folder).map_err(|e| Error::write(self.folder.path(), e))
    }

    /// The switch (step 4 of [`run_bake`]): `staging` holds the new files; the manifest is added
    /// as the set's index, the previous bake's files that the new manifest does not list are
    /// retired, and everything is switched into place ([`asset::Staging::commit`]: every name
    /// checked first, the old files restored if any step fails).
    fn switch(
        &self,
        mut staging: asset::Staging,
        previous: Option<&BakeManifest>,
        manifest: &BakeManifest,
    ) -> Result<(), Error> {
        // Decided before the switch: only files some stage writes, still as described.
        let obsolete = previous
            .into_iter()
            .flat_map(BakeManifest::outputs)
            .filter(|old| manifest.output_by_path(&old.path).is_none() && crate::stage::is_output_name(&old.path))
            .filter(|old| old.matches_file(&self.folder).unwrap_or(false));
        for old in obsolete {
            staging.retire(&old.path);
        }
        // Never a manifest its readers would refuse (a hostile previous manifest near the size
        // limit, with a stage added, would pass it).
        let json = manifest.to_json();
        let path = self.folder.join(MANIFEST);
        BakeManifest::from_bytes(json.as_bytes()).map_err(|e| {
            Error::write(&path, format!("the new manifest would be refused by its readers ({e}): nothing was changed"))
        })?;
        staging.add(MANIFEST, json.as_bytes()).map_err(|(path, e)| Error::write(&path, e))?;
        staging.commit(|| Ok(())).map_err(|(path, e)| Error::write(&path, e))
    }
}

/// An environment stage's own failure, which names no file (a layer whose radiance overflows,
/// say), names the map it was made from.
fn of_map(path: &Path) -> impl Fn(Error) -> Error + '_ {
    move |e| match e {
        Error::Stage { .. } => Error::analyse(path, e),
        other => other,
    }
}

/// The problems the stages of a manifest recorded (`figures.problems`), as `run_bake` reports
/// them.
fn recorded_problems(manifest: &BakeManifest) -> Vec<String> {
    manifest
        .stages
        .iter()
        .flat_map(|stage| {
            let listed = stage.figures.get("problems").and_then(serde_json::Value::as_array);
            listed.into_iter().flatten().filter_map(|p| p.as_str()).map(move |p| format!("{}: {p}", stage.name))
        })
        .collect()
}

/// The stages `run_bake` will announce, in order.
fn stage_names(config: &BakeConfig) -> Vec<&'static str> {
    let mut names = vec!["importance samples", "bandwidth atlas"];
    if config.pca_max_error.is_some() {
        names.push("bandwidth pca");
    }
    if config.wavelet_brdf.is_some() {
        names.push("wavelet encoding");
    }
    if config.fit.is_some() {
        names.push("glTF fit");
    }
    if config.environment.is_some() {
        names.extend(["environment bandwidth", "phong layers and mip chain", "layer selection"]);
        if config.engine_textures {
            names.push("engine textures");
        }
    }
    names
}

fn source_file(source: &Source) -> SourceFile {
    SourceFile {
        name: source.stem(),
        source_path: source.path.display().to_string(),
        source_sha256: asset::hex(&source.sha256),
    }
}

/// Same tool and version, same inputs (by hash), same parameters, and every engine texture the
/// stage now writes where the bake has them.
fn is_same_bake(previous: &BakeManifest, next: &BakeManifest) -> bool {
    let hashes =
        |m: &BakeManifest| (m.material.source_sha256.clone(), m.environment.as_ref().map(|e| e.source_sha256.clone()));
    // An engine-textures stage from before the stage wrote every one of its files.
    let engine_complete = previous
        .stages
        .iter()
        .filter(|s| s.name == "engine-textures")
        .all(|s| crate::stage::engine::FILES.iter().all(|name| s.outputs.iter().any(|o| o.path.as_str() == *name)));
    previous.manifest_version == next.manifest_version
        && previous.tool == next.tool
        && hashes(previous) == hashes(next)
        && previous.parameters == next.parameters
        && engine_complete
}
