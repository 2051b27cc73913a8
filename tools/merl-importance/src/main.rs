//! `merl-importance`: importance-sampling tables and precomputed samples of a MERL BRDF, as one
//! asset, plus a picture of the samples over the lobe. A thin layer over the `importance` crate.

mod picture;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Parser;
use importance::quality::{albedo_estimate, slice_quality};
use importance::{Config, ImportanceTables};
use merl::MerlTable;
use merl::albedo::Quadrature;

/// Build importance-sampling tables of a MERL BRDF table: for each outgoing elevation, the
/// luminance of f cos(theta_i) tabulated over the half vector (MERL's theta_h cells x phi_h
/// sectors), its marginal and conditional CDFs, and vectors of samples drawn by inverting them.
/// Writes one asset (kind importance-samples; layout in data-schema/README.md) and a PNG of the
/// samples over the lobe at 0, 30, 60 and 80 degrees.
///
/// Exit status: 0 ok, 1 --report found a slice whose relative variance exceeds 0.1, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The asset to write.
    #[arg(long, short)]
    out: PathBuf,

    /// The picture to write; defaults to the asset's path with the extension .png.
    #[arg(long)]
    png: Option<PathBuf>,

    /// Outgoing elevations: theta_o = k / N * 90 degrees, k = 0 .. N-1.
    #[arg(long = "theta-o", value_name = "N", default_value_t = Config::default().n_theta_o)]
    n_theta_o: usize,

    /// Vectors of samples per elevation.
    #[arg(long, value_name = "V", default_value_t = Config::default().n_vectors)]
    vectors: usize,

    /// Samples per vector (a power of two keeps each vector stratified).
    #[arg(long, value_name = "S", default_value_t = Config::default().n_samples)]
    samples: usize,

    /// Sectors of phi_h.
    #[arg(long, value_name = "N", default_value_t = Config::default().n_phi_h)]
    phi_h: usize,

    /// Seed of the scrambled Sobol' points the samples come from.
    #[arg(long, default_value_t = 0)]
    seed: u64,

    /// Also measure the tables by quadrature at 0, 30, 60 and 80 degrees: relative variance
    /// against cosine-weighted sampling, and the albedo the stored samples estimate.
    #[arg(long)]
    report: bool,
}

/// Slices drawn in the picture and measured by --report: the ones nearest these elevations.
const SHOWN_DEG: [f64; 4] = [0.0, 30.0, 60.0, 80.0];
/// Relative variance above which --report flags a slice.
const RV_LIMIT: f64 = 0.1;

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()))
}

fn run(args: Args) -> Result<ExitCode> {
    let start = Instant::now();
    let table = merl::read_file(&args.material).with_context(|| format!("reading {}", args.material.display()))?;
    let config = Config {
        n_theta_o: args.n_theta_o,
        n_phi_h: args.phi_h,
        n_vectors: args.vectors,
        n_samples: args.samples,
        seed: args.seed,
        ..Config::default()
    };
    let tables = importance::build(&table, &config)?;
    let built = start.elapsed();

    let asset = to_asset(&args, &config, &tables)?;
    asset::write_file(&args.out, &asset).with_context(|| format!("writing {}", args.out.display()))?;
    let png = args.png.clone().unwrap_or_else(|| args.out.with_extension("png"));
    let shown = shown_slices(&config);
    let picture = picture::lobes(&table, &tables, &shown, 256);
    envmap::write_png_rgb8(&png, picture.width, picture.height, &picture.rgb)
        .with_context(|| format!("writing {}", png.display()))?;
    eprintln!(
        "wrote {} ({} slices x {} vectors x {} samples, tables built in {:.2} s) and {}",
        args.out.display(),
        config.n_theta_o,
        config.n_vectors,
        config.n_samples,
        built.as_secs_f64(),
        png.display()
    );
    if args.report { Ok(report(&table, &tables, &shown)) } else { Ok(ExitCode::SUCCESS) }
}

/// The slices nearest to [`SHOWN_DEG`], without repeats.
fn shown_slices(config: &Config) -> Vec<usize> {
    let mut out: Vec<usize> = SHOWN_DEG
        .iter()
        .map(|deg| ((deg / 90.0 * config.n_theta_o as f64).round() as usize).min(config.n_theta_o - 1))
        .collect();
    out.dedup();
    out
}

fn report(table: &MerlTable, tables: &ImportanceTables, shown: &[usize]) -> ExitCode {
    cli::outln!("theta_o      rv    rv_cos  rv/rv_cos   upper mass   albedo (quadrature)      samples' estimate error");
    let mut problems = Vec::new();
    for &k in shown {
        let slice = &tables.slices()[k];
        let q = slice_quality(table, slice, Quadrature::default());
        let samples = tables.slice_samples(k);
        let estimate = albedo_estimate(table, slice, samples);
        let error =
            std::array::from_fn::<f64, 3, _>(|c| if q.albedo[c] > 0.0 { estimate[c] / q.albedo[c] - 1.0 } else { 0.0 });
        let deg = q.theta_o.to_degrees();
        cli::outln!(
            "{deg:>5.1}  {:>8.5} {:>9.4} {:>9.5} {:>12.6}   {:.4} {:.4} {:.4}   {:+.2}% {:+.2}% {:+.2}%",
            q.rv,
            q.rv_cos,
            q.rv / q.rv_cos,
            q.upper_mass,
            q.albedo[0],
            q.albedo[1],
            q.albedo[2],
            100.0 * error[0],
            100.0 * error[1],
            100.0 * error[2]
        );
        if q.rv > RV_LIMIT {
            problems.push(format!("relative variance {:.4} above {RV_LIMIT} at theta_o {deg:.1} deg", q.rv));
        }
    }
    for p in &problems {
        cli::outln!("problem: {p}");
    }
    if problems.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) }
}

/// The asset's payload, converted by hand from the crate's tables (f32 for textures).
fn to_asset(args: &Args, config: &Config, tables: &ImportanceTables) -> Result<asset::Asset> {
    let f32s = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<f32>>();
    let mut marginal_cdf = Vec::new();
    let mut conditional_cdf = Vec::new();
    let mut h_density = Vec::new();
    for slice in tables.slices() {
        let d = slice.distribution();
        marginal_cdf.extend(f32s(d.marginal().cdf()));
        conditional_cdf.extend(f32s(d.conditional_cdf()));
        for iv in 0..d.nv() {
            h_density.extend((0..d.nu()).map(|iu| slice.h_density([iu, iv]) as f32));
        }
    }
    let samples =
        tables.all_samples().iter().map(|s| [s.wi.x as f32, s.wi.y as f32, s.wi.z as f32, s.pdf as f32]).collect();
    let payload = asset::ImportanceSamples {
        theta_o: tables.slices().iter().map(|s| s.theta_o()).collect(),
        n_vectors: config.n_vectors as u32,
        n_samples: config.n_samples as u32,
        theta_h_edges: tables.rows().theta_edges(),
        n_phi_h: config.n_phi_h as u32,
        samples,
        marginal_cdf,
        conditional_cdf,
        h_density,
    };
    Ok(asset::Asset { provenance: provenance(&args.material, config)?, payload: payload.into() })
}

fn provenance(material: &Path, config: &Config) -> Result<asset::Provenance> {
    let parameters = [
        ("theta_o", config.n_theta_o.to_string()),
        ("theta_h_rows", format!("90 MERL cells x {}", config.theta_h_subdivision)),
        ("phi_h", config.n_phi_h.to_string()),
        ("supersampling", config.supersampling.to_string()),
        ("defensive", config.defensive.to_string()),
        ("vectors", config.n_vectors.to_string()),
        ("samples", config.n_samples.to_string()),
        ("seed", config.seed.to_string()),
    ];
    asset::Provenance::of_source(
        material,
        env!("CARGO_PKG_NAME"),
        env!("CARGO_PKG_VERSION"),
        parameters.into_iter().map(|(k, v)| (k.to_string(), v)).collect(),
    )
    .with_context(|| format!("hashing {}", material.display()))
}
