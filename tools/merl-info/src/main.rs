//! `merl-info`: validate a MERL BRDF table and summarize it, or evaluate it at directions read
//! from stdin. A thin layer over the `merl` crate: argument parsing, one library call, reporting.

use std::f64::consts::{PI, TAU};
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use merl::albedo::Quadrature;
use merl::summary::{Summary, summarize};
use merl::{Interp, MerlTable, spherical_dir};
use serde_json::json;

/// Validate a MERL BRDF table (.binary) and print a summary: dimensions, cells without data,
/// per-channel statistics, directional albedo at theta_o = 0, 30, 60, 80 degrees and the peak.
///
/// Exit status: 0 the table is valid, 1 it loaded but validation found a problem (albedo above
/// 1, or a noticeable part of the hemisphere without data), 2 it could not be read.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The MERL table to read.
    file: PathBuf,

    /// Print the summary as one JSON object on stdout, with `files`: the --asset written, if
    /// any; the text goes to stderr.
    #[arg(long, conflicts_with = "eval")]
    json: bool,

    /// Instead of the summary, read lines "theta_i phi_i theta_o phi_o" (radians) from stdin and
    /// print "r g b" (BRDF in 1/sr) for each.
    #[arg(long)]
    eval: bool,

    /// Lookup used by --eval: `nearest` is the reference MERL reader's.
    #[arg(long, value_enum, default_value_t = InterpArg::Nearest)]
    interp: InterpArg,

    /// What --eval prints for a cell without data: 0, NaN, or the stored value times the scale
    /// (negative; what the reference reader returns).
    #[arg(long, value_enum, default_value_t = NoData::Zero)]
    no_data: NoData,

    /// Lookup used to integrate the directional albedo. Trilinear by default: table samples are
    /// point values at the lower edge of their cells, so nearest lookups bias peaked lobes high.
    #[arg(long, value_enum, default_value_t = InterpArg::Trilinear)]
    albedo_interp: InterpArg,

    /// Also write the summary as a MaterialInfo asset to this file.
    #[arg(long, value_name = "FILE", conflicts_with = "eval")]
    asset: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum InterpArg {
    Nearest,
    Trilinear,
}

impl From<InterpArg> for Interp {
    fn from(i: InterpArg) -> Interp {
        match i {
            InterpArg::Nearest => Interp::Nearest,
            InterpArg::Trilinear => Interp::Trilinear,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum NoData {
    Zero,
    Nan,
    Raw,
}

/// Albedo above this is reported as a problem: 1 plus what the discretization of a table of an
/// energy-conserving BRDF can add (measured: under 1% for normalized Phong up to n = 1000).
const ALBEDO_LIMIT: f64 = 1.01;
/// Share of the cosine-weighted hemisphere without data above which the table is flagged.
const NO_DATA_LIMIT: f64 = 0.01;

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let table = merl::read_file(&args.file).with_context(|| format!("reading {}", args.file.display()))?;
    if args.eval {
        evaluate(&table, &args)?;
        return Ok(ExitCode::SUCCESS);
    }
    let albedo_interp = Interp::from(args.albedo_interp);
    let summary = summarize(&table, albedo_interp, Quadrature::default());
    let problems = problems(&summary);
    // The asset is written before anything is printed, so that the JSON can list it.
    let mut files = Vec::new();
    if let Some(out) = &args.asset {
        files.push(write_asset(out, &args, &summary).with_context(|| format!("writing {}", out.display()))?);
    }
    let value = summary_json(&args.file, &summary, &args, &problems, files);
    let written: Vec<String> = args.asset.iter().map(|p| p.display().to_string()).collect();
    Ok(cli::finish(args.json, &value, &summary_lines(&args.file, &summary, &args), &problems, &written))
}

fn problems(s: &Summary) -> Vec<String> {
    let mut out = Vec::new();
    if s.channels.is_none() {
        out.push("no cell holds data".to_string());
    }
    for (deg, a) in &s.albedo {
        if a.rgb.iter().any(|v| *v > ALBEDO_LIMIT) {
            out.push(format!(
                "albedo above {ALBEDO_LIMIT} at theta_o {deg} deg ({:.4} {:.4} {:.4}): the table reflects more than it receives",
                a.rgb[0], a.rgb[1], a.rgb[2]
            ));
        }
        if a.no_data_fraction > NO_DATA_LIMIT {
            out.push(format!(
                "{:.1}% of the hemisphere above the horizon holds no data at theta_o {deg} deg",
                100.0 * a.no_data_fraction
            ));
        }
    }
    out
}

fn evaluate(table: &MerlTable, args: &Args) -> Result<()> {
    let interp = Interp::from(args.interp);
    let stdin = std::io::stdin().lock();
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    for (n, line) in stdin.lines().enumerate() {
        let line = line.context("reading stdin")?;
        if line.trim().is_empty() || line.trim_start().starts_with('#') {
            continue;
        }
        let angles = parse_angles(&line).with_context(|| format!("stdin line {}", n + 1))?;
        let [theta_i, phi_i, theta_o, phi_o] = angles;
        let (wi, wo) = (spherical_dir(theta_i, phi_i), spherical_dir(theta_o, phi_o));
        let rgb = match (table.lookup(wi, wo, interp), args.no_data) {
            (Some(v), _) => v,
            (None, NoData::Zero) => [0.0; 3],
            (None, NoData::Nan) => [f64::NAN; 3],
            (None, NoData::Raw) => {
                let cell = table.dims().nearest_cell(&merl::half_diff(wi, wo));
                let raw = table.raw_cell(table.dims().index(cell));
                [raw[0] * merl::SCALE[0], raw[1] * merl::SCALE[1], raw[2] * merl::SCALE[2]]
            }
        };
        writeln!(out, "{:e} {:e} {:e}", rgb[0], rgb[1], rgb[2])?;
    }
    out.flush()?;
    Ok(())
}

fn parse_angles(line: &str) -> Result<[f64; 4]> {
    let fields: Vec<&str> = line.split_whitespace().collect();
    if fields.len() != 4 {
        bail!("expected 4 numbers (theta_i phi_i theta_o phi_o), found {}", fields.len());
    }
    let mut out = [0.0; 4];
    for (k, (o, f)) in out.iter_mut().zip(&fields).enumerate() {
        *o = f.parse::<f64>().with_context(|| format!("{f:?} is not a number"))?;
        // Polar angles in [0, pi], azimuths in [-2 pi, 2 pi]: a direction has no other
        // reading, and an angle like 1e308 is a mistake, not a direction.
        let (name, limit, low) =
            [("theta_i", PI, 0.0), ("phi_i", TAU, -TAU), ("theta_o", PI, 0.0), ("phi_o", TAU, -TAU)][k];
        if !(o.is_finite() && *o >= low && *o <= limit) {
            let range = if low == 0.0 { "[0, pi]" } else { "[-2 pi, 2 pi]" };
            bail!("{name} {f} is outside {range} (angles are in radians)");
        }
    }
    Ok(out)
}

fn interp_name(i: InterpArg) -> &'static str {
    match i {
        InterpArg::Nearest => "nearest",
        InterpArg::Trilinear => "trilinear",
    }
}

fn summary_lines(path: &Path, s: &Summary, args: &Args) -> Vec<String> {
    let d = s.dims;
    let mut lines = Vec::new();
    lines.push(format!("file       {}", path.display()));
    lines.push(format!("dims       {} x {} x {} (theta_h x theta_d x phi_d)", d.n_theta_h, d.n_theta_d, d.n_phi_d));
    lines.push(format!(
        "no data    {} of {} cells per channel ({:.1}%)",
        s.no_data_cells,
        s.cells,
        100.0 * s.no_data_cells as f64 / s.cells as f64
    ));
    if let Some(ch) = &s.channels {
        lines.push("BRDF (1/sr)        red        green       blue".to_string());
        for (name, pick) in [("min", 0), ("max", 1), ("mean", 2)] {
            let v = ch.map(|c| [c.min, c.max, c.mean][pick]);
            lines.push(format!("  {name:<10} {:>11.5e} {:>11.5e} {:>11.5e}", v[0], v[1], v[2]));
        }
    }
    lines.push(format!("directional albedo ({} lookup), half-vector quadrature", interp_name(args.albedo_interp)));
    for (deg, a) in &s.albedo {
        lines.push(format!(
            "  theta_o {deg:>2} deg  {:.4} {:.4} {:.4}   no data {:.2}%",
            a.rgb[0],
            a.rgb[1],
            a.rgb[2],
            100.0 * a.no_data_fraction
        ));
    }
    if let Some(p) = &s.peak {
        lines.push(format!(
            "peak       {:.5e} {:.5e} {:.5e} (luminance {:.5e}) at cell ({}, {}, {}): theta_h {:.3} deg, theta_d {:.3} deg, phi_d {:.3} deg",
            p.rgb[0],
            p.rgb[1],
            p.rgb[2],
            p.luminance,
            p.cell.theta_h,
            p.cell.theta_d,
            p.cell.phi_d,
            p.at.theta_h.to_degrees(),
            p.at.theta_d.to_degrees(),
            p.at.phi_d.to_degrees()
        ));
    }
    lines
}

/// The summary as JSON, with `files`: what this run wrote (the `--asset`, described as a bake
/// manifest describes its outputs).
fn summary_json(
    path: &Path,
    s: &Summary,
    args: &Args,
    problems: &[String],
    files: Vec<serde_json::Value>,
) -> serde_json::Value {
    let d = s.dims;
    let channels = s.channels.map(|ch| {
        json!({
            "min": ch.map(|c| c.min),
            "max": ch.map(|c| c.max),
            "mean": ch.map(|c| c.mean),
        })
    });
    let albedo: Vec<_> = s
        .albedo
        .iter()
        .map(|(deg, a)| json!({ "theta_o_deg": deg, "rgb": a.rgb, "no_data_fraction": a.no_data_fraction }))
        .collect();
    let peak = s.peak.map(|p| {
        json!({
            "rgb": p.rgb,
            "luminance": p.luminance,
            "cell": [p.cell.theta_h, p.cell.theta_d, p.cell.phi_d],
            "theta_h_deg": p.at.theta_h.to_degrees(),
            "theta_d_deg": p.at.theta_d.to_degrees(),
            "phi_d_deg": p.at.phi_d.to_degrees(),
        })
    });
    json!({
        "file": path.display().to_string(),
        "dims": [d.n_theta_h, d.n_theta_d, d.n_phi_d],
        "cells": s.cells,
        "no_data_cells": s.no_data_cells,
        "channels": channels,
        "albedo_interp": interp_name(args.albedo_interp),
        "albedo": albedo,
        "peak": peak,
        "problems": problems,
        "files": files,
    })
}

/// Writes the summary as a `material-info` asset and returns the file's description for `files`.
fn write_asset(out: &Path, args: &Args, s: &Summary) -> Result<serde_json::Value> {
    let parameters = vec![
        ("albedo_interp".to_string(), interp_name(args.albedo_interp).to_string()),
        ("quadrature".to_string(), {
            let q = Quadrature::default();
            format!("{} u nodes per theta_h cell x {} phi_h nodes", q.nodes_per_cell, q.n_phi_h)
        }),
    ];
    let provenance =
        asset::Provenance::of_source(&args.file, env!("CARGO_PKG_NAME"), env!("CARGO_PKG_VERSION"), parameters)
            .context("hashing the source")?;
    let d = s.dims;
    let ch = s.channels.unwrap_or([merl::summary::ChannelStats { min: 0.0, max: 0.0, mean: 0.0 }; 3]);
    let (peak_rgb, peak_cell) = s
        .peak
        .map_or(([0.0; 3], [0; 3]), |p| (p.rgb, [p.cell.theta_h as u32, p.cell.theta_d as u32, p.cell.phi_d as u32]));
    let info = asset::MaterialInfo {
        dims: [d.n_theta_h as u32, d.n_theta_d as u32, d.n_phi_d as u32],
        no_data_cells: s.no_data_cells as u64,
        channel_min: ch.map(|c| c.min),
        channel_max: ch.map(|c| c.max),
        channel_mean: ch.map(|c| c.mean),
        peak_rgb,
        peak_cell,
        albedo_theta_o: s.albedo.iter().map(|(deg, _)| deg.to_radians()).collect(),
        albedo_rgb: s.albedo.iter().map(|(_, a)| a.rgb).collect(),
        albedo_no_data_fraction: s.albedo.iter().map(|(_, a)| a.no_data_fraction).collect(),
    };
    let bytes = asset::encode_checked(&asset::Asset { provenance, payload: asset::Payload::MaterialInfo(info) })?;
    asset::write_atomic(out, &bytes)?;
    let path = out.display().to_string();
    let output = asset::StageOutput::of_bytes(&path, asset::FileFormat::Asset, "material-info", &bytes)?;
    Ok(serde_json::to_value(output)?)
}
