//! `brdf-wavelet`: a MERL BRDF encoded in Haar wavelets for real-time rendering (Claustres,
//! Barthe and Paulin 2007), as one asset, with the errors of its Table 1 and a picture of a few
//! slices. Argument parsing and printing around `bake::stage::wavelet_brdf`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use bake::stage::wavelet_brdf::Settings;
use bake::{Program, Source};
use clap::Parser;
use wavelet_brdf::{Config, DEFAULT_EPSILON, DEFAULT_SIDE, Keep};

/// Encode a MERL BRDF table in Haar wavelets (Claustres, Barthe and Paulin 2007, sections 4-5):
/// resample it on the sphere parameterization ((32 x 32)^2 direction pairs by default), log-encode
/// each channel, transform each outgoing slice with the 2D Haar wavelet, keep the coefficient
/// positions of largest energy across all slices (a compression map indexes them), optionally
/// quantize to 8 bits. Writes, in DIR: wavelet-brdf.asset (kind wavelet-brdf; layout in
/// data-schema/README.md) and wavelet-brdf.png (three slices before and after, and their relative
/// error). Reports the paper's Table 1 figures: RMS error and mean relative error against the
/// resampled table. brdf-preview --brdf wavelet-brdf renders from the asset.
///
/// Into a bake folder (one with a manifest.json, made by brdf-bake from the same table), the
/// files are added to the bake as brdf-bake --wavelet-brdf-ratio would add them: the manifest lists
/// them and records these settings, through the bake's own protocol (the folder locked, the new
/// files and manifest switched in together). A later brdf-bake without --wavelet-brdf-ratio rebakes the
/// folder without them.
///
/// Example: brdf-wavelet lewis.binary --out-dir lewis --ratio 16 --quantize 8
///
/// Exit status: 0 ok, 1 the table holds no data at some resampled directions (encoded as 0),
/// 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The folder to write into (created if missing: the folder itself, its parent must exist); a
    /// bake's folder gets the encoding added to its manifest.
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Keep 1/R of the coefficients (a power of two up to the grid's N x N positions; 4, 16 and 32
    /// are the paper's Table 1). The default unless --threshold is given: 4.
    #[arg(long, value_name = "R", conflicts_with = "threshold", value_parser = cli::parse_count)]
    ratio: Option<usize>,

    /// Instead of a ratio, keep the coefficient positions whose RMS coefficient (over all
    /// outgoing slices and channels, log units) is at least T, a finite number from 0; 0 keeps
    /// everything (lossless up to 32-bit floats).
    #[arg(long, value_name = "T", value_parser = parse_threshold)]
    threshold: Option<f64>,

    /// Quantize the kept coefficients to this many bits (only 8 is supported: the paper's
    /// 8-bit textures), with one offset and step per slice and channel.
    #[arg(long, value_name = "BITS")]
    quantize: Option<u32>,

    /// Directions per angle of the sphere grid (a power of two, 2 to 64): n x n incoming
    /// directions for each of n x n outgoing ones.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_SIDE, value_parser = cli::parse_count)]
    side: usize,

    /// Bias of the log encoding log((f + eps mu) / mu), mu the channel mean: from 1e-12 to 1.
    #[arg(long, value_name = "EPS", default_value_t = DEFAULT_EPSILON)]
    epsilon: f64,

    /// Print one JSON object (parameters, figures, files written) on stdout; the report goes to
    /// stderr.
    #[arg(long)]
    json: bool,
}

fn parse_threshold(text: &str) -> Result<f64, String> {
    cli::parse_finite(text, 0.0, f64::MAX).map_err(|_| "expected a finite number from 0".to_string())
}

const PROGRAM: Program = Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let keep = match (args.ratio, args.threshold) {
        (_, Some(t)) => Keep::Threshold(t),
        (Some(r), None) => Keep::Ratio(u32::try_from(r).map_err(|_| {
            anyhow::anyhow!("--ratio {r} is too large: use a power of two up to the grid's N x N coefficient positions")
        })?),
        (None, None) => Keep::Ratio(4),
    };
    let quantize = match args.quantize {
        None => false,
        Some(8) => true,
        Some(bits) => bail!("--quantize supports 8 bits only, found {bits}"),
    };
    let settings = Settings { side: args.side, config: Config { epsilon: args.epsilon, keep, quantize } };
    // Before the table is read: a refused setting costs nothing.
    settings.check()?;
    // The bytes hashed are the bytes parsed.
    let bytes = merl::read_bytes(&args.material).with_context(|| format!("reading {}", args.material.display()))?;
    let source = Source::of_bytes(&args.material, &bytes);
    let table = merl::MerlTable::parse(&bytes).with_context(|| format!("reading {}", args.material.display()))?;
    drop(bytes);
    let staged = bake::stage::wavelet_brdf::run(&table, &source, &PROGRAM, settings)?;
    let dir = &args.out_dir;
    let mut report = staged.report.clone();
    let parameters = serde_json::Value::Object(settings.parameters());
    if bake::write_stage(dir, &staged, &source, ("wavelet_brdf", parameters))? {
        report.push(format!(
            "added to the bake in {}: its {} lists the files and these settings",
            dir.display(),
            bake::MANIFEST
        ));
    }
    Ok(cli::finish(args.json, &staged.json(dir)?, &report, &staged.problems, &staged.written(dir)))
}
