//! An environment map convolved with normalized Phong lobes (`envmap-prefilter`; `001` sections 2.5
//! and 4.3) and the map's mip chain (`002`): a KTX2 array of the layers, one EXR per layer, the
//! mip chain as KTX2, a contact sheet, and the asset of kind `prefiltered-envmap` that ties them
//! together. [`verify`] reads the KTX2 files back with the maintained `ktx2` reader.

use std::path::Path;

use envmap::{EnvMap, MipChain, SampleType};
use prefilter::{Config, Method, Prefiltered};
use rayon::prelude::*;
use serde_json::json;

use crate::{Error, OutFile, Program, Source, Staged, object};

pub mod engine;

pub const ASSET: &str = "prefiltered.asset";
pub const LAYERS_KTX2: &str = "layers.ktx2";
pub const MIPS_KTX2: &str = "mips.ktx2";
pub const CONTACT_SHEET: &str = "layers.png";
pub const LAYERS_CUBE_KTX2: &str = "layers-cube.ktx2";
pub const MIPS_CUBE_KTX2: &str = "mips-cube.ktx2";

/// The EXR file of the layer of exponent `n`.
pub fn layer_exr(n: u32) -> String {
    format!("layer-n{n}.exr")
}

/// The peak memory of this stage per texel of the input map, in bytes, reading included:
/// measured 40 (the maximum resident size on 2048 x 1024 and 4096 x 2048 maps, the difference
/// over the difference in texels: the map, its mip chain in `f32` and in `f16` for the KTX2
/// file), plus 11 for a mip chain stored as `f32` (a map brighter than half floats), with room to
/// spare. The layers come on top ([`limits`]).
pub const BYTES_PER_TEXEL: u64 = 60;

/// The reading limits of this stage under a memory budget of `max_memory` bytes: the layers
/// (one `f32` RGB map of the configured size per exponent, twice over while they are encoded)
/// are set aside, the rest is the map's at [`BYTES_PER_TEXEL`], plus [`CUBE_BYTES_PER_TEXEL`] with
/// cube maps. A budget the layers alone exceed is an error that says so (`--max-memory`).
pub fn limits(config: &::prefilter::Config, max_memory: u64) -> Result<envmap::Limits, Error> {
    // A chain (GGX or Phong) holds 4/3 of a layer in its levels, encoded once more: counted as 2
    // layers each.
    let ggx = 2 * (u64::from(config.ggx_levels > 0) + u64::from(config.chain));
    let layers =
        (config.width as u64 * config.height as u64).saturating_mul(24 * (config.exponents.len() as u64 + ggx));
    if layers >= max_memory {
        return Err(Error::Invalid(format!(
            "a memory budget of {} (--max-memory) leaves nothing for the map: the {}x{} layers alone need {}",
            envmap::format_bytes(max_memory),
            config.width,
            config.height,
            envmap::format_bytes(layers)
        )));
    }
    let per_texel = BYTES_PER_TEXEL + if config.cube { CUBE_BYTES_PER_TEXEL } else { 0 };
    Ok(envmap::Limits::for_job(per_texel, max_memory - layers))
}

/// What the cube mip chain adds per texel of the map: its faces hold 3/4 of the map's texels (six
/// faces of `(w / 4)^2` for `w^2 / 2`), 4/3 of that with the levels, as `f32` RGB (12 bytes) and in
/// the KTX2 file (up to 16 bytes): 28, rounded up.
pub const CUBE_BYTES_PER_TEXEL: u64 = 32;

/// Convolves `map` (read from `source`) with the lobes of `config`; `progress(done, total)` is
/// called as the work advances (a progress bar's hook).
pub fn run(
    map: &EnvMap,
    source: &Source,
    program: &Program,
    config: &Config,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Staged, Prefiltered), Error> {
    config.check().map_err(|e| Error::stage("prefilter", e))?;
    // The layers and the chains in one pass over the map's harmonics; the mip chain once, for the
    // GGX chain's level 0 and the bake's mips.
    let mips = MipChain::new(map);
    let all = prefilter::prefilter_all(map, &mips, config, &|p| progress(p.done, p.total))
        .map_err(|e| Error::stage("prefilter", e))?;
    let prefiltered = all.prefiltered;
    let mut staged = outputs(map, &mips, source, program, config, &prefiltered)?;
    if all.phong_chain.is_some() || all.ggx.is_some() {
        let writer = format!("{} {}", program.name, program.version);
        let engine = engine::outputs(all.phong_chain, all.ggx, config, &writer)?;
        // The manifest entries list the files in order; the asset stays last.
        let asset = staged.files.pop().expect("the asset");
        staged.files.extend(engine.files);
        staged.files.push(asset);
        staged.figures.extend(engine.figures.into_iter().map(|(k, v)| (k.to_string(), v)));
        let clamped = staged.figures.get("clamped_values").and_then(serde_json::Value::as_u64).unwrap_or(0);
        staged.figures.insert("clamped_values".into(), json!(clamped + engine.clamped as u64));
        staged.report.extend(engine.report);
    }
    Ok((staged, prefiltered))
}

/// The stage's files: the layers, `chain` (the map's mip chain) and what `config` adds.
fn outputs(
    map: &EnvMap,
    chain: &MipChain,
    source: &Source,
    program: &Program,
    config: &Config,
    prefiltered: &Prefiltered,
) -> Result<Staged, Error> {
    let writer = format!("{} {}", program.name, program.version);
    let encoding = |what: &str, e: &dyn std::fmt::Display| Error::Internal(format!("encoding {what}: {e}"));
    let layer_maps: Vec<&EnvMap> = prefiltered.layers.iter().map(|layer| &layer.map).collect();
    // The encoders are serial (the EXR and PNG compressors above all): run them side by side.
    let ktx =
        |result: Result<prefilter::ktx::Ktx2File, prefilter::Error>, name: &str| result.map_err(|e| encoding(name, &e));
    let ((layers, mips), (exrs, (png, cubes))) = rayon::join(
        || {
            rayon::join(
                || ktx(prefilter::ktx::encode_array(&layer_maps, config.storage, &writer), LAYERS_KTX2),
                || ktx(prefilter::ktx::encode_mip_chain(chain, config.storage, &writer), MIPS_KTX2),
            )
        },
        || {
            let exrs = || {
                prefiltered
                    .layers
                    .par_iter()
                    .map(|layer| {
                        let name = layer_exr(layer.exponent);
                        let bytes = layer.map.encode_exr(SampleType::F32).map_err(|e| encoding(&name, &e))?;
                        Ok((name, bytes))
                    })
                    .collect::<Result<Vec<_>, Error>>()
            };
            let png = || {
                let exponents_and_maps: Vec<(u32, &EnvMap)> =
                    prefiltered.layers.iter().map(|layer| (layer.exponent, &layer.map)).collect();
                let sheet = prefilter::contact_sheet(chain, &exponents_and_maps);
                envmap::encode_png_rgb8(sheet.width, sheet.height, &sheet.rgb8).map_err(|e| encoding(CONTACT_SHEET, &e))
            };
            // Cube maps for engines (not linked from the asset: the previewer reads the lat-long
            // files).
            let cubes = || -> Result<Option<_>, Error> {
                if !config.cube {
                    return Ok(None);
                }
                Ok(Some((
                    ktx(prefilter::cube::encode_layers(&layer_maps, config.storage, &writer), LAYERS_CUBE_KTX2)?,
                    ktx(prefilter::cube::encode_mip_chain(chain, config.storage, &writer), MIPS_CUBE_KTX2)?,
                )))
            };
            rayon::join(exrs, || rayon::join(png, cubes))
        },
    );
    let (layers, mips, exrs, png, cubes) = (layers?, mips?, exrs?, png?, cubes?);
    let (layers_format, mips_format, mut clamped) = (layers.format, mips.format, layers.clamped + mips.clamped);
    let mut cube_files = Vec::new();
    if let Some((cube_layers, cube_mips)) = cubes {
        clamped += cube_layers.clamped + cube_mips.clamped;
        for (name, role, bytes) in [
            (LAYERS_CUBE_KTX2, "phong-layers-cube", cube_layers.bytes),
            (MIPS_CUBE_KTX2, "environment-mips-cube", cube_mips.bytes),
        ] {
            cube_files.push(OutFile { name: name.into(), format: asset::FileFormat::Ktx2, role, bytes });
        }
    }
    let mut files = Vec::new();
    let mut linked = |name: String, format, role, bytes: Vec<u8>| -> asset::LinkedFile {
        let file = asset::LinkedFile { name: name.clone(), sha256: asset::sha256(&bytes) };
        files.push(OutFile { name, format, role, bytes });
        file
    };
    let layers_ktx2 = linked(LAYERS_KTX2.into(), asset::FileFormat::Ktx2, "phong-layers", layers.bytes);
    let mips_ktx2 = linked(MIPS_KTX2.into(), asset::FileFormat::Ktx2, "environment-mips", mips.bytes);
    let layer_exrs: Vec<asset::LinkedFile> =
        exrs.into_iter().map(|(name, bytes)| linked(name, asset::FileFormat::Exr, "phong-layer-exr", bytes)).collect();
    let contact_sheet_png = linked(CONTACT_SHEET.into(), asset::FileFormat::Png, "phong-layers-picture", png);

    let source_mean = map.mean_radiance();
    let layer_means: Vec<[f64; 3]> = layer_maps.iter().map(|m| m.mean_radiance()).collect();
    let payload = asset::PrefilteredEnvmap {
        source_size: [map.width() as u32, map.height() as u32],
        source_mean_radiance: source_mean,
        layer_size: [config.width as u32, config.height as u32],
        mip_levels: chain.n_levels() as u32,
        // Texels are radiance as it is (no scale since the KTX2 files went to rgba32f where half
        // floats cannot hold them); the fields stay for the readers of older files.
        layers_radiance_scale: 1.0,
        mips_radiance_scale: 1.0,
        exponents: config.exponents.clone(),
        lobe_bandwidth: prefiltered.mapping.bandwidths().to_vec(),
        bandwidth_thresholds: prefiltered.mapping.thresholds().to_vec(),
        layer_mean_radiance: layer_means.clone(),
        layers_ktx2,
        layer_exrs,
        mips_ktx2,
        contact_sheet_png,
    };
    let asset = asset::encode_checked(&asset::Asset {
        provenance: source.provenance(program, &provenance_parameters(config, prefiltered)),
        payload: payload.into(),
    })
    .map_err(|e| encoding(ASSET, &e))?;
    // The asset names the other files with their hashes, so it comes last: a reader that finds it
    // finds them.
    files.extend(cube_files);
    files.push(OutFile {
        name: ASSET.into(),
        format: asset::FileFormat::Asset,
        role: "prefiltered-envmap",
        bytes: asset,
    });

    // Every lobe integrates to 1, so every layer keeps the source's mean radiance.
    let mean_error = layer_means
        .iter()
        .flat_map(|m| (0..3).map(move |c| (m[c] - source_mean[c]).abs() / source_mean[c].max(f64::MIN_POSITIVE)))
        .fold(0.0f64, f64::max);
    let methods: Vec<serde_json::Value> = prefiltered
        .layers
        .iter()
        .map(|l| json!({ "exponent": l.exponent, "method": l.method.name(), "degree": l.degree }))
        .collect();
    let mut report = vec![format!(
        "{} layers of {} x {} (exponents {}) from a {} x {} map with {} mip levels",
        config.exponents.len(),
        config.width,
        config.height,
        join(&config.exponents),
        map.width(),
        map.height(),
        chain.n_levels()
    )];
    report.push(format!(
        "layer means   within {:.2e} of the source's mean radiance (relative, worst channel and layer)",
        mean_error
    ));
    report.push(format!(
        "ktx2          {LAYERS_KTX2} {}, {MIPS_KTX2} {} ({})",
        layers_format.name(),
        mips_format.name(),
        match config.storage {
            prefilter::ktx::Storage::Auto => "half floats where every texel fits them, else single floats".to_string(),
            prefilter::ktx::Storage::ClampHalf => format!("half floats, {clamped} values clamped to 65504"),
        }
    ));
    Ok(Staged {
        name: "prefilter",
        parameters: object([
            ("exponents", json!(config.exponents)),
            ("size", json!([config.width, config.height])),
            ("method", json!(config.method.name())),
            ("storage", json!(config.storage.name())),
            ("cube", json!(config.cube)),
            ("ggx_levels", json!(config.ggx_levels)),
            ("chain", json!(config.chain)),
        ]),
        figures: object([
            ("mip_levels", json!(chain.n_levels())),
            ("layers_format", json!(layers_format.name())),
            ("mips_format", json!(mips_format.name())),
            ("clamped_values", json!(clamped)),
            ("layer_mean_max_relative_error", json!(mean_error)),
            ("layers", json!(methods)),
        ]),
        files,
        report,
        problems: Vec::new(),
    })
}

fn provenance_parameters(config: &Config, prefiltered: &Prefiltered) -> Vec<(&'static str, String)> {
    let mut parameters = vec![
        ("exponents", join(&config.exponents)),
        ("size", format!("{}x{}", config.width, config.height)),
        ("method", Method::name(config.method).to_string()),
        ("storage", config.storage.name().to_string()),
    ];
    for layer in &prefiltered.layers {
        let how = match layer.degree {
            Some(degree) => format!("{} to degree {degree}", layer.method.name()),
            None => layer.method.name().to_string(),
        };
        // Provenance names are free text; one per layer, in order.
        parameters.push(("layer", format!("n={}: {how}", layer.exponent)));
    }
    parameters
}

fn join(exponents: &[u32]) -> String {
    exponents.iter().map(u32::to_string).collect::<Vec<_>>().join(",")
}

/// Half-float rounding: round to nearest keeps 11 significant bits (relative error at most
/// `2^-11`), and below the smallest normal half (`2^-14`) the spacing is `2^-24`, so the absolute
/// error there is at most `2^-25`.
fn half_tolerance(value: f32) -> f32 {
    value.abs() * 2f32.powi(-11) + 2f32.powi(-25)
}

/// What [`verify`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Verified {
    /// One line per file checked.
    pub report: Vec<String>,
    pub problems: Vec<String>,
}

/// Reads both KTX2 files in `dir` back with the `ktx2` crate and compares them with the EXR
/// layers (read back with `envmap`) and the mip chain of `map`.
pub fn verify(dir: &Path, map: &EnvMap, prefiltered: &Prefiltered) -> Result<Verified, Error> {
    let asset_path = dir.join(ASSET);
    let asset = asset::read_file(&asset_path).map_err(|e| Error::read(&asset_path, e))?;
    let asset::Payload::PrefilteredEnvmap(payload) = asset.payload else {
        return Err(Error::read(
            &asset_path,
            format!("expected a prefiltered-envmap asset, found {}", asset.payload.kind()),
        ));
    };
    let mut problems = Vec::new();
    let mut report = Vec::new();
    if payload.layers_radiance_scale != 1.0 || payload.mips_radiance_scale != 1.0 {
        problems.push(format!(
            "{}: the KTX2 texels are stored scaled (radiance x {} and x {}), as versions before rgba32f did: bake \
             again",
            asset_path.display(),
            payload.layers_radiance_scale,
            payload.mips_radiance_scale
        ));
    }
    let exrs: Vec<Vec<f32>> = prefiltered
        .layers
        .iter()
        .map(|layer| {
            let path = dir.join(layer_exr(layer.exponent));
            let image = envmap::read_image(&path, &envmap::Limits::default()).map_err(|e| Error::read(&path, e))?;
            Ok(image.rgb)
        })
        .collect::<Result<_, Error>>()?;
    let first = &prefiltered.layers[0].map;
    let layers_path = dir.join(LAYERS_KTX2);
    let worst = compare_ktx2(
        &layers_path,
        (first.width(), first.height(), prefiltered.layers.len()),
        &[exrs.iter().map(Vec::as_slice).collect()],
        &mut problems,
    )?;
    report.push(format!(
        "{}: {} layers match the EXR layers within half-float rounding (largest relative difference {worst:.2e})",
        layers_path.display(),
        prefiltered.layers.len()
    ));
    let chain = MipChain::new(map);
    let mips_path = dir.join(MIPS_KTX2);
    let level0 = chain.level(0);
    let levels: Vec<Vec<&[f32]>> = chain.levels().iter().map(|level| vec![level.rgb()]).collect();
    let worst = compare_ktx2(&mips_path, (level0.width(), level0.height(), 0), &levels, &mut problems)?;
    report.push(format!(
        "{}: {} mip levels match the source's mip chain within half-float rounding (largest relative difference \
         {worst:.2e})",
        mips_path.display(),
        chain.n_levels()
    ));
    Ok(Verified { report, problems })
}

/// Checks one KTX2 file's header and texels against `expected[level][layer]` (interleaved RGB),
/// returning the largest relative difference; mismatches go to `problems`. Half floats are held to
/// their rounding, single floats must be exact.
fn compare_ktx2(
    path: &Path,
    (width, height, layer_count): (usize, usize, usize),
    expected: &[Vec<&[f32]>],
    problems: &mut Vec<String>,
) -> Result<f32, Error> {
    let bytes = fsguard::read_regular(path, asset::OUTPUT_LIMIT).map_err(|e| Error::read(path, e))?;
    let decoded = prefilter::ktx::decode(&bytes).map_err(|e| Error::read(path, e))?;
    let wanted = prefilter::ktx::Shape { width, height, layers: layer_count, faces: 1 };
    if decoded.shape != wanted || decoded.levels.len() != expected.len() {
        problems.push(format!(
            "{}: {:?} with {} levels, expected {wanted:?} with {}",
            path.display(),
            decoded.shape,
            decoded.levels.len(),
            expected.len()
        ));
        return Ok(f32::INFINITY);
    }
    let half = decoded.format == prefilter::ktx::TexelFormat::Rgba16f;
    let mut worst = 0.0f32;
    for (l, (images, wanted)) in decoded.levels.iter().zip(expected).enumerate() {
        for (layer, (stored, image)) in images.iter().zip(wanted).enumerate() {
            for (i, (&got, &want)) in stored.iter().zip(image.iter()).enumerate() {
                let difference = (got - want).abs();
                let tolerance = if half { half_tolerance(want) } else { 0.0 };
                if difference > tolerance {
                    problems.push(format!(
                        "{}: level {l} layer {layer} texel {} channel {}: {got}, expected {want}",
                        path.display(),
                        i / 3,
                        i % 3
                    ));
                }
                if want > 0.0 {
                    worst = worst.max(difference / want);
                }
            }
        }
    }
    Ok(worst)
}
