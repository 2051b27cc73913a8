//! `merl-synth`: write a MERL table of an analytic BRDF, for references, fixtures and demos.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use merl::Dims;
use merl::analytic::Analytic;

/// Write a MERL BRDF table (.binary, 35 MB) sampled from an analytic BRDF with a known answer.
/// Cells are sampled at their lower edge; configurations below the horizon hold no data (-1),
/// as in MERL's files.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    #[command(subcommand)]
    brdf: Brdf,

    /// Output file.
    #[arg(long, short, global = true, default_value = "synthetic.binary")]
    out: PathBuf,

    /// Store 360 phi_d cells over [0, 2 pi) instead of MERL's 180 over [0, pi).
    #[arg(long, global = true)]
    full_phi: bool,
}

#[derive(Debug, Subcommand)]
enum Brdf {
    /// f = albedo / pi.
    Lambertian {
        /// Albedo: one value, or three (r,g,b).
        #[arg(long, default_value = "0.5", value_delimiter = ',')]
        albedo: Vec<f64>,
    },
    /// Energy-normalized Phong, f = ks (n+2)/(2 pi) max(0, wi . reflect(wo))^n.
    Phong {
        #[arg(long, short)]
        n: f64,
        /// Specular reflectance: one value, or three (r,g,b).
        #[arg(long, default_value = "1", value_delimiter = ',')]
        ks: Vec<f64>,
    },
    /// Blinn-Phong, f = ks (n+8)/(8 pi) cos^n theta_h.
    BlinnPhong {
        #[arg(long, short)]
        n: f64,
        #[arg(long, default_value = "1", value_delimiter = ',')]
        ks: Vec<f64>,
    },
    /// GGX microfacets with height-correlated Smith masking and Schlick Fresnel.
    Ggx {
        /// Roughness alpha (GGX width).
        #[arg(long)]
        alpha: f64,
        /// Reflectance at normal incidence: one value, or three (r,g,b).
        #[arg(long, default_value = "0.04", value_delimiter = ',')]
        f0: Vec<f64>,
    },
}

fn rgb(name: &str, v: &[f64], max: f64) -> Result<[f64; 3]> {
    let rgb = match v {
        [x] => [*x; 3],
        [r, g, b] => [*r, *g, *b],
        _ => bail!("--{name} takes one value or three (r,g,b), found {}", v.len()),
    };
    if rgb.iter().any(|x| !x.is_finite() || *x < 0.0 || *x > max) {
        bail!("--{name} must lie in [0, {max}], found {v:?}");
    }
    Ok(rgb)
}

fn positive(name: &str, v: f64) -> Result<f64> {
    if !v.is_finite() || v <= 0.0 {
        bail!("--{name} must be a positive number, found {v}");
    }
    Ok(v)
}

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()).map(|()| ExitCode::SUCCESS))
}

fn run(args: Args) -> Result<()> {
    let brdf = match &args.brdf {
        Brdf::Lambertian { albedo } => Analytic::Lambertian { albedo: rgb("albedo", albedo, 1.0)? },
        Brdf::Phong { n, ks } => Analytic::Phong { n: positive("n", *n)?, ks: rgb("ks", ks, 1.0)? },
        Brdf::BlinnPhong { n, ks } => Analytic::BlinnPhong { n: positive("n", *n)?, ks: rgb("ks", ks, 1.0)? },
        Brdf::Ggx { alpha, f0 } => Analytic::Ggx { alpha: positive("alpha", *alpha)?, f0: rgb("f0", f0, 1.0)? },
    };
    let dims = if args.full_phi { Dims::MERL_FULL_PHI } else { Dims::MERL };
    let table = brdf.table(dims);
    asset::write_atomic(&args.out, &table.to_bytes()).with_context(|| format!("writing {}", args.out.display()))?;
    eprintln!("wrote {} ({brdf:?}, {} x {} x {})", args.out.display(), dims.n_theta_h, dims.n_theta_d, dims.n_phi_d);
    Ok(())
}
