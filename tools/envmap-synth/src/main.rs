//! `envmap-synth`: procedural environment maps for demos and tests. Argument parsing and writing
//! around `envmap::synthetic`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Parser;
use serde_json::json;

/// Write the calibration sky (`envmap::synthetic`) as a lat-long OpenEXR map (RGB, 32-bit float):
/// a blue sky over a checkered ground, a sun at elevation 35 degrees and azimuth 60 degrees, and
/// three panels on the horizon, red at +x, green at +y, blue at -x, so that the orientation of
/// any reflection can be read off a render.
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The map to write (OpenEXR).
    #[arg(long, short, value_name = "FILE.exr")]
    out: PathBuf,

    /// Width and height, WIDTHxHEIGHT with WIDTH = 2 x HEIGHT, from 8x4 to 16384x8192.
    #[arg(long, value_name = "WxH", default_value = "1024x512", value_parser = cli::parse_size)]
    size: (usize, usize),

    /// Print one JSON object (the file written, its size) on stdout.
    #[arg(long)]
    json: bool,
}

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let (w, h) = args.size;
    if h > 8192 {
        bail!("--size {w}x{h}: at most 16384x8192");
    }
    let map = envmap::synthetic::calibration_sky(w, h)?;
    map.write_exr(&args.out, envmap::SampleType::F32).with_context(|| format!("writing {}", args.out.display()))?;
    let value =
        json!({ "files": [args.out.display().to_string()], "width": w, "height": h, "kind": "calibration-sky" });
    let report = [format!("calibration sky {w} x {h}")];
    Ok(cli::finish(args.json, &value, &report, &[], &[args.out.display().to_string()]))
}
