//! `bandwidth-pca`: PCA compression of a bandwidth atlas (`000` Fig. 8). Argument parsing and
//! printing around `bake::stage::pca`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow};
use bake::{Program, Source};
use bandwidth_atlas::Components;
use clap::{ArgGroup, Parser};

/// Compress a bandwidth atlas (from brdf-bandwidth) by PCA: each distinct tile is one vector; the
/// model is the mean tile, K principal components and K coefficients per tile, and a tile is
/// reconstructed as mean + sum_k coefficient_k component_k. For an isotropic atlas (kind
/// bandwidth-rows, or any atlas whose tiles repeat along each row) the distinct tiles are the
/// rows: the model has one column and each row's coefficients serve every column. Reports the
/// relative RMSE (|reconstruction - atlas| / |atlas| over all texels), the largest error of a
/// texel, and the size of the model against the distinct tiles (size_ratio) and against the full
/// lobes x lobes grid (size_ratio_full_grid). Writes, in DIR: bandwidth-pca.asset (the model)
/// and bandwidth-pca.png (the absolute error in the full atlas's layout, log scale).
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
#[command(group(ArgGroup::new("k").required(true).args(["components", "max_error"])))]
struct Args {
    /// The atlas (bandwidth-atlas.asset written by brdf-bandwidth: kind bandwidth-rows or
    /// bandwidth-atlas).
    atlas: PathBuf,

    /// The folder to write into (created if missing: the folder itself, its parent must exist).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Keep exactly K components, 1 to the texels of a tile (256 for 16 x 16 tiles).
    #[arg(long, value_name = "K", value_parser = cli::parse_count)]
    components: Option<usize>,

    /// Keep the fewest components whose relative RMSE is at most E, a finite number from 0 (e.g.
    /// 0.02).
    #[arg(long = "max-error", value_name = "E")]
    max_error: Option<f64>,

    /// Print one JSON object (parameters, figures, files written) on stdout; the report goes to
    /// stderr.
    #[arg(long)]
    json: bool,
}

const PROGRAM: Program = Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    // A regular file only, within the largest asset a reader accepts, read once: the bytes hashed
    // for the provenance are the bytes decoded.
    let bytes = fsguard::read_regular(&args.atlas, asset::OUTPUT_LIMIT)
        .with_context(|| format!("reading {}", args.atlas.display()))?;
    let atlas = read_atlas(&bytes).with_context(|| format!("reading {}", args.atlas.display()))?;
    let components = match (args.components, args.max_error) {
        (Some(k), _) => Components::Count(k),
        (None, Some(e)) => Components::MaxRelativeRmse(e),
        (None, None) => unreachable!("clap requires one of them"),
    };
    let source = Source::of_bytes(&args.atlas, &bytes);
    let staged = bake::stage::pca::run(&atlas, &source, &PROGRAM, components)?;
    let dir = &args.out_dir;
    staged.write(dir)?;
    Ok(cli::finish(args.json, &staged.json(dir)?, &staged.report, &staged.problems, &staged.written(dir)))
}

/// The full atlas of the asset `brdf-bandwidth` wrote (either kind).
fn read_atlas(bytes: &[u8]) -> Result<bandwidth_atlas::Atlas> {
    bake::stage::bandwidth_atlas::from_payload(asset::decode(bytes)?.payload).map_err(|e| anyhow!(e))
}
