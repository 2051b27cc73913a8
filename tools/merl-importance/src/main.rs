//! `merl-importance`: importance-sampling tables and precomputed samples of a MERL BRDF, as one
//! asset, plus a picture of the samples over the lobe. Argument parsing and printing around
//! `bake::stage::importance`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use bake::{Program, Source};
use clap::Parser;
use importance::Config;

/// Build importance-sampling tables of a MERL BRDF table: for each outgoing elevation, the
/// luminance of f cos(theta_i) tabulated over the half vector (MERL's theta_h cells x phi_h
/// sectors), its marginal and conditional CDFs, and vectors of samples drawn by inverting them.
/// Writes, in DIR: importance.asset (kind importance-samples; layout in data-schema/README.md) and
/// importance.png (the samples over the lobe at 0, 30, 60 and 80 degrees).
///
/// Exit status: 0 ok, 1 --report found a slice whose relative variance exceeds 0.1, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The folder to write into (created if missing: the folder itself, its parent must exist).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Outgoing elevations, 1 to 1024: theta_o = k / N * 90 degrees, k = 0 .. N-1.
    #[arg(long = "theta-o", value_name = "N", default_value_t = Config::default().n_theta_o, value_parser = cli::parse_count)]
    n_theta_o: usize,

    /// Vectors of samples per elevation, 1 to 1024.
    #[arg(long, value_name = "V", default_value_t = Config::default().n_vectors, value_parser = cli::parse_count)]
    vectors: usize,

    /// Samples per vector, 1 to 1048576 (a power of two keeps each vector stratified).
    #[arg(long, value_name = "S", default_value_t = Config::default().n_samples, value_parser = cli::parse_count)]
    samples: usize,

    /// Sectors of phi_h, 1 to 4096.
    #[arg(long, value_name = "N", default_value_t = Config::default().n_phi_h, value_parser = cli::parse_count)]
    phi_h: usize,

    /// Seed of the scrambled Sobol' points the samples come from: any whole number from 0 to
    /// 18446744073709551615.
    #[arg(long, default_value_t = 0)]
    seed: u64,

    /// Also measure the tables by quadrature at 0, 30, 60 and 80 degrees: relative variance
    /// against cosine-weighted sampling, and the albedo the stored samples estimate.
    #[arg(long)]
    report: bool,

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
    let table = merl::read_file(&args.material).with_context(|| format!("reading {}", args.material.display()))?;
    let source = Source::hash(&args.material)?;
    let config = Config {
        n_theta_o: args.n_theta_o,
        n_phi_h: args.phi_h,
        n_vectors: args.vectors,
        n_samples: args.samples,
        seed: args.seed,
        ..Config::default()
    };
    let staged = bake::stage::importance::run(&table, &source, &PROGRAM, &config, args.report)?;
    let dir = &args.out_dir;
    staged.write(dir)?;
    Ok(cli::finish(args.json, &staged.json(dir)?, &staged.report, &staged.problems, &staged.written(dir)))
}
