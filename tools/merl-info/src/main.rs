//! `merl-info`: validate a MERL BRDF table and summarize it, or evaluate it at directions read
//! from stdin. A thin layer over the `merl` crate: argument parsing, one library call, reporting.

use std::f64::consts::{PI, TAU};
use std::io::{BufRead, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use merl::{Interp, MerlTable, spherical_dir};
use serde_json::json;

/// Validate a MERL BRDF table (.binary) and print a summary: dimensions, cells without data,
/// per-channel statistics, directional albedo at theta_o = 0, 30, 60, 80 degrees and the peak.
///
/// Exit status: 0 the table is valid, 1 it loaded but validation found a problem (albedo above
/// 1, one cell that on its own reflects more than the light received, or a noticeable part of
/// the hemisphere without data), 2 it could not be read.
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

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    // The table's bytes are read once: what is hashed is what is parsed.
    let bytes = merl::read_bytes(&args.file).and_then(|b| MerlTable::parse(&b).map(|t| (b, t)));
    let (bytes, table) = bytes.with_context(|| format!("reading {}", args.file.display()))?;
    if args.eval {
        evaluate(&table, &args)?;
        return Ok(ExitCode::SUCCESS);
    }
    let source = bake::Source::of_bytes(&args.file, &bytes);
    let program = bake::Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };
    let staged = bake::stage::material_info::run(&table, &source, &program, args.albedo_interp.into())?;
    // The asset is written before anything is printed, so that the JSON can list it.
    let mut files = Vec::new();
    if let Some(out) = &args.asset {
        let asset = staged.file("material-info").expect("the stage makes its asset");
        asset::write_atomic(out, &asset.bytes).with_context(|| format!("writing {}", out.display()))?;
        let path = out.display().to_string();
        let output = asset::StageOutput::of_bytes(&path, asset.format, asset.role, &asset.bytes)?;
        files.push(serde_json::to_value(output)?);
    }
    let mut value = serde_json::Map::new();
    value.insert("file".into(), args.file.display().to_string().into());
    value.extend(staged.figures.clone());
    value.insert("problems".into(), json!(staged.problems));
    value.insert("files".into(), json!(files));
    let written: Vec<String> = args.asset.iter().map(|p| p.display().to_string()).collect();
    Ok(cli::finish(args.json, &value.into(), &staged.report, &staged.problems, &written))
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
