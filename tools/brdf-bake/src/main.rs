//! `brdf-bake`: the pipeline step. Runs every per-material stage and, with an environment, every
//! environment stage into one folder with a `manifest.json`. Argument parsing and printing around
//! `bake::run_bake`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use bake::{BakeConfig, Program, Progress};
use clap::Parser;
use serde_json::json;

/// Bake a MERL material (and, with --env, an environment map) for real-time rendering. Writes, in
/// DIR: the importance samples (importance.asset, importance.png), the bandwidth atlas
/// (bandwidth-atlas.asset: once per row for an isotropic table, kind bandwidth-rows; .exr: the full
/// 1024 x 1024 texture; .png), with --pca-max-error its PCA model (bandwidth-pca.asset, .png), with
/// --wavelet-brdf-ratio its Haar wavelet encoding (wavelet-brdf.asset, .png; what brdf-preview
/// --brdf wavelet-brdf reads), with --fit the closest glTF material (fit.json, material.gltf,
/// material.bin, fit.binary), and with --env the environment's bandwidth (env-bandwidth.exr/.png),
/// its Phong-lobe layers and mip chain (prefiltered.asset, layers.ktx2, layer-n<N>.exr, mips.ktx2,
/// layers.png), the layer selection (layer-selection.asset) and with --engine-textures the engine
/// textures (engine-*.ktx2); then manifest.json (data-schema/README.md: every file with its sha256,
/// the parameters, the tool version and each stage's validation figures), written last.
///
/// A rerun with the same inputs (by sha256), parameters and tool version finds the manifest up to
/// date and writes nothing (--force bakes anyway). Outputs are deterministic: reruns and thread
/// counts give identical bytes. An interrupted bake leaves no manifest naming a missing or stale
/// file; the next run cleans up and bakes again.
///
/// Exit status: 0 ok, 1 validation found a problem: a stage's (the bake is written and says so),
/// or the table's values are no material's (it reflects more than twice the light it receives,
/// at one of merl-info's elevations or through one cell alone; nothing is baked), 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The environment map (lat-long OpenEXR or Radiance HDR, 2:1), for the environment stages.
    #[arg(long, value_name = "ENV")]
    env: Option<PathBuf>,

    /// The folder to bake into (created if missing: the folder itself, its parent must exist). One
    /// bake at a time holds a folder: a second brdf-bake (or a single-stage tool) started on it
    /// meanwhile exits 2 at once, naming it.
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Also compress the bandwidth atlas by PCA, with the fewest components whose relative RMSE
    /// is at most E, in (0, 1) (e.g. 0.02).
    #[arg(long, value_name = "E")]
    pca_max_error: Option<f64>,

    /// Also encode the material in Haar wavelets (as brdf-wavelet does, on its default (32 x 32)^2
    /// grid), keeping 1/R of the coefficients: a power of two up to 1024 (4, 16 and 32 are the
    /// paper's Table 1).
    #[arg(long, value_name = "R", value_parser = cli::parse_count)]
    wavelet_brdf_ratio: Option<usize>,

    /// With --wavelet-brdf-ratio, store the kept coefficients as 8-bit codes.
    #[arg(long, requires = "wavelet_brdf_ratio")]
    wavelet_brdf_quantize: bool,

    /// Also fit the closest glTF 2.0 material (as brdf-fit does, at its defaults: fit.json,
    /// material.gltf + material.bin, fit.binary; data-schema/brdf-fit.md). About 10 to 30 s on 2
    /// cores.
    #[arg(long)]
    fit: bool,

    /// Vectors of importance samples per view elevation (each of --samples samples): the
    /// reference mode's accuracy grows with them (a bright sun seen in a mirror-like material
    /// needs tens of vectors for percent-level agreement). From 1 to 1024.
    #[arg(long, value_name = "V", default_value_t = importance::Config::default().n_vectors, value_parser = cli::parse_count)]
    vectors: usize,

    /// Importance samples per vector (a power of two from 1 to 1048576).
    #[arg(long, value_name = "N", default_value_t = importance::Config::default().n_samples, value_parser = cli::parse_count)]
    samples: usize,

    /// Pixels per side of the images each lobe is analysed on, for the bandwidth atlas and the
    /// layer selection (a power of two from 16 to 4096; 256 or more tells the default layers
    /// apart, and 512 resolves Phong lobes up to n = 1000).
    #[arg(long = "analysis-size", value_name = "N", default_value_t = bandwidth_atlas::Config::default().analysis_size, value_parser = cli::parse_count)]
    analysis_size: usize,

    /// Also write the environment's layers and mip chain as KTX2 cube maps for engines
    /// (layers-cube.ktx2, mips-cube.ktx2; see envmap-prefilter --help).
    #[arg(long, requires = "env")]
    cube: bool,

    /// Also write the Phong exponents as one mip chain, the layout engines read (cmft's):
    /// phong-chain.ktx2, level m the m-th sharpest exponent at (WIDTH >> m) x (HEIGHT >> m) (the
    /// defaults give 16384, 4096, ..., 1 from 512 x 256 down), and phong-chain-cube.ktx2 with --cube.
    #[arg(long, requires = "env")]
    chain: bool,

    /// Also write the environment's GGX chain of M levels, from 2 to log2 of the layers' width
    /// less 1 (8 for the default 512 x 256), and the split-sum DFG table (ggx.ktx2, dfg.ktx2,
    /// dfg.png; see envmap-prefilter --help).
    #[arg(long, value_name = "M", value_parser = |s: &str| cli::parse_whole(s, 2), requires = "env")]
    ggx_levels: Option<usize>,

    /// How the environment's bandwidth compares wavelet levels (see envmap-bandwidth --help):
    /// paper, level-normalized, or auto (the default): level-normalized for a mirror-like
    /// material (its lobe at every view as sharp as the sharpest Phong layer, as chrome's), whose
    /// pictures show the fine detail the paper's reading lets strong edges mask, paper otherwise.
    /// brdf-preview's adaptive modes plan their frames from it.
    #[arg(long, value_name = "auto|paper|level-normalized", default_value = "auto", requires = "env")]
    env_reading: bake::stage::env_bandwidth::ReadingChoice,

    /// Also write the engine textures (engine-*.ktx2): everything brdf-preview's reference and
    /// prefiltered estimators read (the MERL table as a 3D texture, the importance tables, the
    /// view rows' layer coordinates, level 0 and its peaks, their sampling tables, the smooth
    /// Phong layers), as single-float KTX2 data textures that engines index directly
    /// (data-schema/engine-textures.md; engines/three renders them in three.js). About 60 MB for a
    /// MERL table under a 1024 x 512 map.
    #[arg(long, requires = "env")]
    engine_textures: bool,

    /// Store the environment's KTX2 files as half floats even where texels exceed 65504, clamping
    /// them (the default stores such a file as single floats).
    #[arg(long)]
    clamp_half: bool,

    /// Bake even when the folder's manifest is up to date.
    #[arg(long)]
    force: bool,

    /// Memory budget of the environment stages (4G, 512M, ...; from 1 byte to 16 EiB, more than the
    /// layers alone need): a map whose estimated need (80 bytes per texel, plus the layers) is
    /// larger is refused from its header, before decoding.
    #[arg(long, value_name = "SIZE", default_value = "4G", value_parser = cli::parse_bytes)]
    max_memory: u64,

    /// Print one JSON object on stdout: whether the bake was up to date, the manifest, and the
    /// problems found; the report goes to stderr.
    #[arg(long)]
    json: bool,

    /// No progress bar and no report (errors and problems still print).
    #[arg(long, short)]
    quiet: bool,
}

const PROGRAM: Program = Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    if let Some(e) = args.pca_max_error
        && !(e > 0.0 && e < 1.0)
    {
        anyhow::bail!("--pca-max-error {e:?} is not in (0, 1)");
    }
    let mut config = BakeConfig::new(args.material.clone(), args.env.clone(), args.out_dir.clone());
    config.pca_max_error = args.pca_max_error;
    config.fit = args.fit.then(gltf_fit::Settings::default);
    if let Some(ratio) = args.wavelet_brdf_ratio {
        let ratio = u32::try_from(ratio).map_err(|_| {
            anyhow::anyhow!(
                "--wavelet-brdf-ratio {ratio} is too large: use a power of two up to the grid's N x N coefficient positions"
            )
        })?;
        let config_w = wavelet_brdf::Config {
            keep: wavelet_brdf::Keep::Ratio(ratio),
            quantize: args.wavelet_brdf_quantize,
            ..Default::default()
        };
        config.wavelet_brdf = Some(bake::stage::wavelet_brdf::Settings { config: config_w, ..Default::default() });
    }
    config.importance.n_vectors = args.vectors;
    config.importance.n_samples = args.samples;
    config.atlas.analysis_size = args.analysis_size;
    config.force = args.force;
    if args.clamp_half {
        config.prefilter.storage = prefilter::ktx::Storage::ClampHalf;
    }
    config.prefilter.cube = args.cube;
    config.prefilter.ggx_levels = args.ggx_levels.unwrap_or(0);
    config.prefilter.chain = args.chain;
    config.engine_textures = args.engine_textures;
    config.env_bandwidth.max_memory = args.max_memory;
    config.env_reading = args.env_reading;
    let progress = cli::Progress::new(args.quiet);
    let outcome = bake::run_bake(&config, &PROGRAM, &|p| match p {
        Progress::Stage { index, count, name } => progress.step(format!("{}/{count} {name}", index + 1)),
        Progress::Work { done, total } => progress.work(done, total),
    });
    progress.finish();
    // Validation found the table is no material: its problems, exit 1, nothing written.
    let outcome = match outcome {
        Err(bake::Error::Unphysical { path, problems }) => {
            let value = json!({ "up_to_date": false, "manifest": null, "problems": problems, "files": [] });
            let report = [format!("{}: not a physical material, nothing baked", path.display())];
            return Ok(cli::finish(args.json, &value, &report, &problems, &[]));
        }
        outcome => outcome?,
    };

    let dir = &args.out_dir;
    let mut report = Vec::new();
    if outcome.up_to_date {
        report.push(format!(
            "{} is up to date: same inputs, parameters and tool version; nothing written",
            dir.join(bake::MANIFEST).display()
        ));
    } else if !args.quiet {
        for (stage, lines) in &outcome.reports {
            report.push(format!("[{stage}]"));
            report.extend(lines.iter().map(|l| format!("  {l}")));
        }
    }
    // Like every tool's `files`: what this run wrote, each with its format, role, size and hash.
    let written: Vec<serde_json::Value> = if outcome.up_to_date {
        Vec::new()
    } else {
        let manifest_path = dir.join(bake::MANIFEST);
        let manifest_bytes = outcome.manifest.to_json().into_bytes();
        outcome
            .manifest
            .outputs()
            .map(|o| {
                let mut v = json!(o);
                v["path"] = json!(dir.join(&o.path).display().to_string());
                v
            })
            .chain([json!({
                "path": manifest_path.display().to_string(),
                "format": "json",
                "role": "manifest",
                "size_bytes": manifest_bytes.len(),
                "sha256": asset::hex(&asset::sha256(&manifest_bytes)),
            })])
            .collect()
    };
    let value = json!({
        "up_to_date": outcome.up_to_date,
        "manifest": outcome.manifest,
        "problems": outcome.problems,
        "files": written,
    });
    let written_line: Vec<String> = if written.is_empty() || args.quiet {
        Vec::new()
    } else {
        vec![format!("{} files in {}", written.len(), dir.display())]
    };
    Ok(cli::finish(args.json, &value, &report, &outcome.problems, &written_line))
}
