//! `merl-synth`: write a MERL table of an analytic BRDF, for references, fixtures and demos.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::error::ErrorKind;
use clap::{CommandFactory, Parser, Subcommand};
use merl::Dims;
use merl::analytic::Analytic;
use serde_json::json;

/// Write a MERL BRDF table (.binary, 35 MB) sampled from an analytic BRDF with a known answer,
/// to the file --out names. Cells are sampled at their lower edge; configurations below the
/// horizon hold no data (-1), as in MERL's files.
///
/// Example: merl-synth ggx --alpha 0.2 --f0 0.95,0.64,0.54 --out copper.binary
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    #[command(subcommand)]
    brdf: Brdf,

    /// The table to write (required: 35 MB, never written to a default place).
    #[arg(long, short, global = true, value_name = "FILE")]
    out: Option<PathBuf>,

    /// Store 360 phi_d cells over [0, 2 pi) instead of MERL's 180 over [0, pi).
    #[arg(long, global = true)]
    full_phi: bool,

    /// Print one JSON object (the BRDF, its parameters, the file written) on stdout; the report
    /// goes to stderr.
    #[arg(long, global = true)]
    json: bool,
}

#[derive(Debug, Subcommand)]
enum Brdf {
    /// f = albedo / pi.
    #[command(allow_negative_numbers = true)]
    Lambertian {
        /// Albedo: one value, or three (r,g,b), each in [0, 1].
        #[arg(long, default_value = "0.5", value_delimiter = ',', value_name = "A")]
        albedo: Vec<f64>,
    },
    /// Energy-normalized Phong with an optional Lambertian term (Lewis 1994),
    /// f = kd/pi + ks (n+2)/(2 pi) max(0, wi . reflect(wo))^n.
    ///
    /// Example (the Lewis-like material of Claustres et al. 2007, Table 1):
    /// merl-synth phong -n 10 --ks 0.2 --kd 0.8 --out lewis.binary
    #[command(allow_negative_numbers = true)]
    Phong {
        /// Phong exponent n, in (0, 1e6]: larger is sharper.
        #[arg(long, short, value_name = "N")]
        n: f64,
        /// Specular reflectance: one value, or three (r,g,b), each in [0, 1].
        #[arg(long, default_value = "1", value_delimiter = ',', value_name = "KS")]
        ks: Vec<f64>,
        /// Diffuse (Lambertian) reflectance: one value, or three (r,g,b), each in [0, 1]; kd + ks
        /// at most 1 per channel keeps the material energy-conserving.
        #[arg(long, default_value = "0", value_delimiter = ',', value_name = "KD")]
        kd: Vec<f64>,
    },
    /// Blinn-Phong, f = ks (n+8)/(8 pi) cos^n theta_h.
    #[command(allow_negative_numbers = true)]
    BlinnPhong {
        /// Blinn-Phong exponent n of cos theta_h, in (0, 1e6]: larger is sharper.
        #[arg(long, short, value_name = "N")]
        n: f64,
        /// Specular reflectance: one value, or three (r,g,b), each in [0, 1].
        #[arg(long, default_value = "1", value_delimiter = ',', value_name = "KS")]
        ks: Vec<f64>,
    },
    /// GGX microfacets with height-correlated Smith masking and Schlick Fresnel.
    #[command(allow_negative_numbers = true)]
    Ggx {
        /// Roughness alpha, the GGX width, in [1e-3, 100]: narrower is a mirror a table cannot hold.
        #[arg(long, value_name = "ALPHA")]
        alpha: f64,
        /// Reflectance at normal incidence: one value, or three (r,g,b), each in [0, 1].
        #[arg(long, default_value = "0.04", value_delimiter = ',', value_name = "F0")]
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

/// `v` in `(0, max]`: an exponent beyond `max` gives a table of values that overflow (or a lobe far
/// narrower than a MERL cell).
fn positive(name: &str, v: f64, max: f64) -> Result<f64> {
    if !(v > 0.0 && v <= max) {
        bail!("--{name} must be a number in (0, {max:e}], found {v:?}");
    }
    Ok(v)
}

/// `v` in `[min, max]` (the GGX width: [`Analytic::MIN_ALPHA`] says why it has a lower bound).
fn within(name: &str, v: f64, min: f64, max: f64) -> Result<f64> {
    if !(v >= min && v <= max) {
        bail!("--{name} must be a number in [{min:e}, {max:e}], found {v:?}");
    }
    Ok(v)
}

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    // `--out` is global (it may come before or after the BRDF), and clap cannot require a global
    // argument: refuse its absence the way clap refuses a missing argument (usage, exit 2).
    let Some(out) = &args.out else {
        Args::command()
            .error(ErrorKind::MissingRequiredArgument, "the following required argument was not provided: --out <FILE>")
            .exit()
    };
    let (brdf, kind, parameters) = match &args.brdf {
        Brdf::Lambertian { albedo } => {
            let albedo = rgb("albedo", albedo, 1.0)?;
            (Analytic::Lambertian { albedo }, "lambertian", json!({ "albedo": albedo }))
        }
        Brdf::Phong { n, ks, kd } => {
            let (n, ks, kd) = (positive("n", *n, Analytic::MAX_EXPONENT)?, rgb("ks", ks, 1.0)?, rgb("kd", kd, 1.0)?);
            (Analytic::Phong { n, ks, kd }, "phong", json!({ "n": n, "ks": ks, "kd": kd }))
        }
        Brdf::BlinnPhong { n, ks } => {
            let (n, ks) = (positive("n", *n, Analytic::MAX_EXPONENT)?, rgb("ks", ks, 1.0)?);
            (Analytic::BlinnPhong { n, ks }, "blinn-phong", json!({ "n": n, "ks": ks }))
        }
        Brdf::Ggx { alpha, f0 } => {
            let (alpha, f0) = (within("alpha", *alpha, Analytic::MIN_ALPHA, Analytic::MAX_ALPHA)?, rgb("f0", f0, 1.0)?);
            (Analytic::Ggx { alpha, f0 }, "ggx", json!({ "alpha": alpha, "f0": f0 }))
        }
    };
    let dims = if args.full_phi { Dims::MERL_FULL_PHI } else { Dims::MERL };
    let bytes = brdf.table(dims).to_bytes();
    asset::write_atomic(out, &bytes).with_context(|| format!("writing {}", out.display()))?;

    let dims_text = format!("{} x {} x {}", dims.n_theta_h, dims.n_theta_d, dims.n_phi_d);
    let value = json!({
        "kind": kind,
        "parameters": parameters,
        "dims": [dims.n_theta_h, dims.n_theta_d, dims.n_phi_d],
        "files": [{
            "path": out.display().to_string(),
            "format": "merl",
            "role": "merl-table",
            "size_bytes": bytes.len(),
            "sha256": asset::hex(&asset::sha256(&bytes)),
        }],
    });
    let report = [format!("{brdf}: a {dims_text} table (theta_h x theta_d x phi_d)")];
    Ok(cli::finish(args.json, &value, &report, &[], &[out.display().to_string()]))
}
