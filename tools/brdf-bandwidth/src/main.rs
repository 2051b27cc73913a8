//! `brdf-bandwidth`: the angular-bandwidth atlas of a MERL BRDF (`000` section 2.4). Argument
//! parsing and printing around `bake::stage::bandwidth_atlas`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use bake::{Program, Source};
use bandwidth_atlas::{Analyser, Config};
use clap::Parser;

/// Build the angular-bandwidth atlas of a MERL BRDF: for each incident direction of a
/// lobes x lobes grid (rows in equal steps of cos theta_i, columns in phi_i), the BRDF's
/// outgoing lobe (luminance) as an image in the frame of its plane of incidence, its local
/// bandwidth from a D4 wavelet decomposition (eps 0.01, c = 2^-2.5) in cycles per radian,
/// reduced to a tile x tile tile by taking the maximum over the pixels of the hemisphere each
/// texel covers. A MERL table is isotropic: the lobes of a row are one image, analysed once.
/// Reports how many lobes reach the analysis grid's limit. Writes, in DIR:
/// bandwidth-atlas.asset (the atlas, for bandwidth-pca and brdf-bake: kind bandwidth-rows, one
/// tile per row, when every tile of a row is the same, as for every MERL table; else kind
/// bandwidth-atlas, every tile), bandwidth-atlas.exr (the full lobes tile x lobes tile texture
/// for renderers, one float channel Y) and bandwidth-atlas.png (false colour, log scale).
/// Parameterizations and layout: data-schema/bandwidth-atlas.md.
///
/// Exit status: 0 ok, 1 most lobes reach the analysis grid's limit (a validation problem: the
/// files are written, and the problem says which analysis size resolves more), 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The folder to write into (created if missing: the folder itself, its parent must exist).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Incident directions per side of the grid, 1 to 4096.
    #[arg(long, value_name = "N", default_value_t = Config::default().lobes, value_parser = cli::parse_count)]
    lobes: usize,

    /// Texels per side of each lobe's tile (a power of two, at most --analysis-size).
    #[arg(long, value_name = "T", default_value_t = Config::default().tile, value_parser = cli::parse_count)]
    tile: usize,

    /// Pixels per side of the image each lobe is analysed on (a power of two from 16 to 4096,
    /// >= the tile); the highest bandwidth it resolves grows with it.
    #[arg(long = "analysis-size", value_name = "N", default_value_t = Config::default().analysis_size, value_parser = cli::parse_count)]
    analysis_size: usize,

    /// Print one JSON object (parameters, figures, files written) on stdout; the report goes to
    /// stderr.
    #[arg(long)]
    json: bool,

    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

const PROGRAM: Program = Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let config = Config { lobes: args.lobes, tile: args.tile, analysis_size: args.analysis_size, ..Config::default() };
    config.check()?;
    let read = || format!("reading {}", args.material.display());
    // The analysis grid (what its pixels hold) does not depend on the table: it is made while
    // the table is read. The provenance's hash of the bytes read, beside their parsing; the
    // atlas reads the luminance alone, so the table (and the bytes) go before the analysis's
    // buffers come.
    let (analyser, read_table) = rayon::join(
        || Analyser::new(&config),
        || -> Result<_> {
            let bytes = merl::read_bytes(&args.material).with_context(read)?;
            let (source, luminance) = rayon::join(
                || Source::of_bytes(&args.material, &bytes),
                || merl::MerlTable::parse(&bytes).map(|table| bandwidth_atlas::LuminanceTable::new(&table)),
            );
            Ok((source, luminance.with_context(read)?))
        },
    );
    let (source, luminance) = read_table?;
    let progress = cli::Progress::new(args.quiet);
    progress.step("lobes".to_string());
    let total = (config.lobes * config.lobes) as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    let tick =
        |n: usize| progress.work(done.fetch_add(n as u64, std::sync::atomic::Ordering::Relaxed) + n as u64, total);
    let (staged, _) = bake::stage::bandwidth_atlas::run(&luminance, &analyser, &source, &PROGRAM, &tick)?;
    progress.finish();
    let dir = &args.out_dir;
    staged.write(dir)?;
    Ok(cli::finish(args.json, &staged.json(dir)?, &staged.report, &staged.problems, &staged.written(dir)))
}
