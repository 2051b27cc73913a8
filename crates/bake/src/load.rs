//! A finished bake read back for the renderers: the manifest, the MERL table it was made from
//! (checked against the manifest's hash), the importance samples, and with an environment the mip
//! chain and the Phong layers as the KTX2 files hold them (half floats, divided by the file's
//! radiance scale), so that what the previewer draws is what an engine would load.

use std::path::{Path, PathBuf};

use asset::{BakeManifest, Payload};
use envmap::{EnvMap, MipChain};

use crate::Error;
use crate::run::MANIFEST;

/// A bake in memory.
#[derive(Debug)]
pub struct Loaded {
    pub dir: PathBuf,
    pub manifest: BakeManifest,
    pub material: render::Material,
    /// Present when the bake has an environment.
    pub lighting: Option<render::Lighting>,
    /// What adaptive shading predicts from (the environment's bandwidth and the material's
    /// atlas); present when the bake has an environment.
    pub bandwidths: Option<render::adaptive::Bandwidths>,
}

/// Finishes or undoes a switch a kill interrupted ([`asset::recover_switch`]) when no bake holds
/// the folder: the lock is taken for the recovery alone.
fn recover(folder: &fsguard::Folder, dir: &Path) -> Result<(), Error> {
    let journal = dir.join(asset::SWITCH_JOURNAL);
    if folder.entry(asset::SWITCH_JOURNAL).map_err(|e| Error::read(&journal, e))?.is_none() {
        return Ok(());
    }
    // An open folder of its own (a lock belongs to an open file description, which a duplicated
    // descriptor shares): dropping it releases the lock.
    let held = fsguard::Folder::open(dir).map_err(|e| Error::read(dir, e))?;
    if held.try_lock().map_err(|e| Error::read(dir, e))? {
        asset::recover_switch(&held).map_err(|e| Error::write(&journal, e))?;
    }
    Ok(())
}

/// Reads the bake in `dir`. The MERL table is `material` when given, else the manifest's
/// `source_path` (as given to the bake: absolute, or relative to the working folder or, failing
/// that, to the bake's parent folder); either way its SHA-256 must be the manifest's.
///
/// Every file is read once, as the bytes that are checked and decoded: the manifest and the
/// files it lists inside the folder without following a link, regular files only, each size
/// checked from the file's metadata before it is read (the manifest's against
/// [`asset::MANIFEST_LIMIT`], each output's against its `size_bytes`, then its SHA-256); the table
/// (which may lie anywhere) as a regular file of at most [`merl::MAX_FILE_BYTES`], its SHA-256
/// compared before anything in it is parsed or quoted.
///
/// A switch a kill interrupted ([`asset::recover_switch`]) is finished or undone before the
/// manifest is read, where no bake holds the folder (its lock, taken for the recovery alone): the
/// folder then holds one whole bake. While a bake holds it, the reader goes on as it is.
pub fn load(dir: &Path, material: Option<&Path>) -> Result<Loaded, Error> {
    let folder = fsguard::Folder::open(dir).map_err(|e| Error::read(dir, e))?;
    recover(&folder, dir)?;
    let manifest_path = dir.join(MANIFEST);
    let manifest = match BakeManifest::read(&folder) {
        Ok(manifest) => manifest,
        Err(asset::Error::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::read(
                dir,
                format!(
                    "not a bake folder (it has no {MANIFEST}): make one with brdf-bake MATERIAL.binary --env ENV.hdr \
                     --out-dir {}",
                    dir.display()
                ),
            ));
        }
        Err(e) => return Err(Error::read(&manifest_path, e)),
    };
    let file = |role: &str| -> Result<(PathBuf, Vec<u8>), Error> {
        let output = manifest.output(role).ok_or_else(|| {
            Error::read(&manifest_path, format!("the bake has no {role} output: bake it again with this version"))
        })?;
        let path = dir.join(&output.path);
        let bytes = output.read(&folder).map_err(|e| Error::read(&path, e))?;
        Ok((path, bytes))
    };

    let table_path = match material {
        Some(path) => path.to_path_buf(),
        None => locate(&manifest.material.source_path, dir),
    };
    let table_bytes =
        fsguard::read_regular(&table_path, merl::MAX_FILE_BYTES).map_err(|e| Error::read(&table_path, e))?;
    if asset::hex(&asset::sha256(&table_bytes)) != manifest.material.source_sha256 {
        return Err(Error::read(
            &table_path,
            format!("not the material of the bake in {} (its sha256 differs)", dir.display()),
        ));
    }
    let table = merl::MerlTable::parse(&table_bytes).map_err(|e| Error::read(&table_path, e))?;
    drop(table_bytes);

    let (material, lighting) = assemble(table, manifest.environment.is_some(), &file)?;
    let bandwidths = match &lighting {
        Some(_) => Some(bandwidths(&file)?),
        None => None,
    };
    Ok(Loaded { dir: dir.to_path_buf(), manifest, material, lighting, bandwidths })
}

/// A bake's outputs by role: the path that names the file in errors, and its bytes.
pub(crate) type Outputs<'a> = dyn Fn(&str) -> Result<(PathBuf, Vec<u8>), Error> + 'a;

/// The material (the importance samples, and with an environment the view layers of the layer
/// selection) and, with an environment, the lighting, from a bake's outputs as `file` gives them
/// by role: what [`load`] reads from a folder, and what the engine textures are made of while a
/// bake runs (`stage::engine`), so that both are the same numbers.
pub(crate) fn assemble(
    table: merl::MerlTable,
    has_environment: bool,
    file: &Outputs,
) -> Result<(render::Material, Option<render::Lighting>), Error> {
    let (samples_path, samples_bytes) = file("importance-samples")?;
    let samples = match read_payload(&samples_path, &samples_bytes)? {
        Payload::ImportanceSamples(s) => sample_set(s).map_err(|e| Error::read(&samples_path, e))?,
        other => {
            return Err(Error::read(&samples_path, format!("expected importance samples, found {}", other.kind())));
        }
    };
    let mut view_layers = Vec::new();
    let lighting = if has_environment {
        let (asset_path, asset_bytes) = file("prefiltered-envmap")?;
        let Payload::PrefilteredEnvmap(prefiltered) = read_payload(&asset_path, &asset_bytes)? else {
            return Err(Error::read(&asset_path, "expected a prefiltered-envmap asset"));
        };
        let (mips_path, mips_bytes) = file("environment-mips")?;
        let mips = read_ktx2(&mips_path, &mips_bytes, prefiltered.mips_radiance_scale as f32)?;
        let levels: Vec<EnvMap> = mips.into_iter().map(|mut layers| layers.remove(0)).collect();
        let mips = MipChain::from_levels(levels).map_err(|e| Error::read(&mips_path, e))?;
        let (layers_path, layers_bytes) = file("phong-layers")?;
        let mut layers = read_ktx2(&layers_path, &layers_bytes, prefiltered.layers_radiance_scale as f32)?;
        let layers = layers.remove(0);
        if layers.len() != prefiltered.exponents.len() {
            return Err(Error::read(
                &layers_path,
                format!("{} layers for {} exponents", layers.len(), prefiltered.exponents.len()),
            ));
        }
        let (selection_path, selection_bytes) = file("layer-selection")?;
        let Payload::LayerSelection(selection) = read_payload(&selection_path, &selection_bytes)? else {
            return Err(Error::read(&selection_path, "expected a layer-selection asset"));
        };
        if selection.exponents != prefiltered.exponents {
            return Err(Error::read(
                &selection_path,
                format!(
                    "selects among exponents {:?}, the layers have {:?}",
                    selection.exponents, prefiltered.exponents
                ),
            ));
        }
        view_layers = bandwidth_atlas::view::view_coordinates(&selection.view_bandwidth, &selection.layer_bandwidth);
        Some(render::Lighting::new(mips, layers, prefiltered.exponents).map_err(|e| Error::read(&mips_path, e))?)
    } else {
        None
    };
    Ok((render::Material::new(table, samples, view_layers), lighting))
}

/// What adaptive shading predicts from: the environment's bandwidth and the material's atlas.
fn bandwidths(file: &Outputs) -> Result<render::adaptive::Bandwidths, Error> {
    let (bandwidth_path, bandwidth_bytes) = file("environment-bandwidth")?;
    let image = envmap::read_image_from_memory(&bandwidth_bytes, &envmap::Limits::default())
        .map_err(|e| Error::read(&bandwidth_path, e))?;
    let grey = image.rgb.chunks_exact(3).map(|t| t[0]).collect();
    let environment = render::adaptive::EnvBandwidth::new(image.width, image.height, grey)
        .map_err(|e| Error::read(&bandwidth_path, e))?;
    let (atlas_path, atlas_bytes) = file("bandwidth-atlas")?;
    let brdf = crate::stage::bandwidth_atlas::from_payload(read_payload(&atlas_path, &atlas_bytes)?)
        .map_err(|e| Error::read(&atlas_path, e))?;
    Ok(render::adaptive::Bandwidths { environment, brdf })
}

/// Reads a `wavelet-brdf` asset (`brdf-wavelet`) for the material of a loaded bake: it must have
/// been made from the same MERL table (same SHA-256). `path` is the caller's (a regular file only,
/// [`asset::read_file`]).
pub fn load_wavelet_brdf(path: &Path, loaded: &Loaded) -> Result<wavelet_brdf::Decoded, Error> {
    let asset = asset::read_file(path).map_err(|e| Error::read(path, e))?;
    wavelet_brdf_of_asset(path, &asset, loaded)
}

/// The bake's own `wavelet-brdf` output (`brdf-wavelet MATERIAL --out-dir BAKE` and `brdf-bake
/// --wavelet-brdf-ratio R` list it in the manifest), read as [`load`] reads every output, with the path
/// it was read from.
pub fn bake_wavelet_brdf(loaded: &Loaded) -> Result<(PathBuf, wavelet_brdf::Decoded), Error> {
    let how = format!(
        "add one with brdf-wavelet MATERIAL.binary --out-dir {} (or brdf-bake --wavelet-brdf-ratio R), or name an \
         asset with --wavelet-brdf FILE",
        loaded.dir.display()
    );
    let (path, bytes) = bake_output(loaded, "wavelet-brdf", &how)?;
    let asset = asset::decode(&bytes).map_err(|e| Error::read(&path, e))?;
    let brdf = wavelet_brdf_of_asset(&path, &asset, loaded)?;
    Ok((path, brdf))
}

/// The bake's glTF fit as a MERL table (`brdf-bake --fit`, role `fit-table`: the fitted material
/// tabulated on the MERL grid, so that every estimator renders it exactly), read as [`load`] reads
/// every output, with the path it was read from.
pub fn bake_fit_table(loaded: &Loaded) -> Result<(PathBuf, merl::MerlTable), Error> {
    let (path, bytes) = bake_output(loaded, "fit-table", "bake it again with brdf-bake --fit")?;
    let table = merl::MerlTable::parse(&bytes).map_err(|e| Error::read(&path, e))?;
    Ok((path, table))
}

/// The output of role `role` of a loaded bake, read as [`load`] reads every output (inside the
/// folder, no link followed, its size and SHA-256 the manifest's); where the bake has none, an
/// error that says `how` to add one.
fn bake_output(loaded: &Loaded, role: &str, how: &str) -> Result<(PathBuf, Vec<u8>), Error> {
    let Some(output) = loaded.manifest.output(role) else {
        return Err(Error::read(&loaded.dir.join(MANIFEST), format!("the bake has no {role} output: {how}")));
    };
    let path = loaded.dir.join(&output.path);
    let folder = fsguard::Folder::open(&loaded.dir).map_err(|e| Error::read(&loaded.dir, e))?;
    let bytes = output.read(&folder).map_err(|e| Error::read(&path, e))?;
    Ok((path, bytes))
}

fn wavelet_brdf_of_asset(path: &Path, asset: &asset::Asset, loaded: &Loaded) -> Result<wavelet_brdf::Decoded, Error> {
    let Payload::WaveletBrdf(payload) = &asset.payload else {
        return Err(Error::read(path, format!("expected a wavelet-brdf asset, found {}", asset.kind())));
    };
    if asset::hex(&asset.provenance.source_sha256) != loaded.manifest.material.source_sha256 {
        return Err(Error::read(
            path,
            format!(
                "made from {} (sha256 {}), not from the bake's material {}",
                asset.provenance.source_name,
                asset::hex(&asset.provenance.source_sha256),
                loaded.manifest.material.name
            ),
        ));
    }
    wavelet_brdf::Decoded::from_payload(payload).map_err(|e| Error::read(path, e.to_string()))
}

/// A path as the bake was given it: absolute, relative to the working folder, or relative to the
/// bake's parent folder (for bakes moved with their inputs).
fn locate(source_path: &str, dir: &Path) -> PathBuf {
    let given = PathBuf::from(source_path);
    if given.is_absolute() || given.exists() {
        return given;
    }
    dir.parent().map(|parent| parent.join(&given)).filter(|p| p.exists()).unwrap_or(given)
}

/// The payload of an asset file's bytes (`path` names it in errors).
fn read_payload(path: &Path, bytes: &[u8]) -> Result<Payload, Error> {
    asset::decode(bytes).map(|a| a.payload).map_err(|e| Error::read(path, e))
}

/// The samples as the renderers read them; the slices must be the uniform ones
/// `merl-importance` writes (`theta_o[k] = k / S * pi / 2`).
fn sample_set(s: asset::ImportanceSamples) -> Result<render::SampleSet, String> {
    // The estimators weigh each sample's pdf against the tables' density of its direction.
    s.check_densities()?;
    let n_slices = s.theta_o.len();
    for (k, theta) in s.theta_o.iter().enumerate() {
        let expected = k as f64 / n_slices as f64 * std::f64::consts::FRAC_PI_2;
        if (theta - expected).abs() > 1e-9 {
            return Err(format!("slice {k} is at theta_o {theta}, expected {expected} (uniform slices)"));
        }
    }
    if !s.n_samples.is_power_of_two() {
        return Err(format!("{} samples per vector: the renderers need a power of two", s.n_samples));
    }
    // The payload's check holds the tables' lengths to the slices, rows and sectors.
    let rows = importance::HalfVectorRows::from_theta_edges(&s.theta_h_edges).map_err(|e| e.to_string())?;
    let (n_rows, n_phi) = (rows.len(), s.n_phi_h as usize);
    let f64s = |t: &[f32]| t.iter().map(|&v| f64::from(v)).collect::<Vec<f64>>();
    let tables = s
        .theta_o
        .iter()
        .enumerate()
        .map(|(k, &theta_o)| {
            let marginal = &s.marginal_cdf[k * (n_rows + 1)..(k + 1) * (n_rows + 1)];
            let conditional = &s.conditional_cdf[k * n_rows * (n_phi + 1)..(k + 1) * n_rows * (n_phi + 1)];
            let dist = sampling::Distribution2D::from_cdfs(&f64s(marginal), &f64s(conditional), n_phi, n_rows)
                .map_err(|e| format!("slice {k}'s tables: {e}"))?;
            importance::Slice::from_tables(theta_o, rows.clone(), dist).map_err(|e| format!("slice {k}: {e}"))
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(render::SampleSet {
        n_slices,
        n_vectors: s.n_vectors as usize,
        n_samples: s.n_samples as usize,
        texels: s.samples,
        tables,
    })
}

/// The texels of a KTX2 file of ours (`prefilter::ktx`: RGBA16F or RGBA32F) as maps:
/// `[level][layer]` (a plain 2D texture has one layer), radiance divided by `scale` (1 since the
/// files hold radiance as it is; older bakes stored some at a power of two below 1).
fn read_ktx2(path: &Path, bytes: &[u8], scale: f32) -> Result<Vec<Vec<EnvMap>>, Error> {
    let decoded = ::prefilter::ktx::decode(bytes).map_err(|e| Error::read(path, e))?;
    if decoded.shape.faces != 1 {
        return Err(Error::read(path, "expected a lat-long 2d texture, found a cube map"));
    }
    let shape = decoded.shape;
    decoded
        .levels
        .into_iter()
        .enumerate()
        .map(|(l, images)| {
            let (w, h) = shape.level_size(l);
            images
                .into_iter()
                .map(|mut rgb| {
                    rgb.iter_mut().for_each(|v| *v /= scale);
                    EnvMap::new(w, h, rgb).map_err(|e| Error::read(path, format!("level {l}: {e}")))
                })
                .collect()
        })
        .collect()
}
