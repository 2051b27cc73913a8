//! `envmap-prefilter`: an environment map convolved with normalized Phong lobes of several
//! exponents (prefiltered shading) and its mip chain (filtered importance sampling). Argument
//! parsing and printing around `bake::stage::prefilter`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use bake::{Program, Source};
use clap::{Parser, ValueEnum};
use prefilter::{Config, Method};

/// Convolve a lat-long environment map (OpenEXR or Radiance HDR, 2:1) with the normalized Phong
/// lobe (n + 1) / (2 pi) max(0, w . r)^n for each exponent n, around every direction r of a
/// lat-long grid. Writes, in DIR: layers.ktx2 (2D array, one layer per exponent),
/// layer-n<N>.exr (RGB float, one per exponent, tagged envmap = latlong), mips.ktx2 (2D texture
/// with the source's mip chain, for filtered importance sampling), layers.png (the source and the layers, tone
/// mapped) and prefiltered.asset (kind prefiltered-envmap: exponents, bandwidths, the
/// bandwidth-to-layer thresholds, file names and hashes; layout in data-schema/README.md).
///
/// The KTX2 files hold radiance as it is, with no scale an engine would have to know of: RGBA16F
/// (half floats) when every texel fits them, RGBA32F when some exceed 65504 (a sun), or, with
/// --clamp-half, RGBA16F with those texels clamped to 65504 (the report says how many).
///
/// Exit status: 0 ok, 1 --verify found a file that does not read back as written, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about, allow_negative_numbers = true)]
struct Args {
    /// The environment map (.exr or .hdr, lat-long, width = 2 x height).
    env: PathBuf,

    /// The folder to write into (created if missing).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// Phong exponents, one layer each, strictly increasing, each from 1 to 16777216.
    #[arg(long, value_name = "N,N,...", value_delimiter = ',', default_value = "1,4,16,64,256,1024,4096,16384")]
    exponents: Vec<u32>,

    /// Size of every layer, WIDTHxHEIGHT with WIDTH = 2 x HEIGHT, HEIGHT from 1 to 8192.
    #[arg(long, value_name = "WxH", default_value = "512x256", value_parser = cli::parse_size)]
    size: (usize, usize),

    /// Memory budget (4G, 512M, ...; from 1 byte to 16 EiB, more than the layers alone need): a map
    /// whose estimated need (60 bytes per texel, plus the layers) is larger is refused from its
    /// header, before decoding.
    #[arg(long, value_name = "SIZE", default_value = "4G", value_parser = cli::parse_bytes)]
    max_memory: u64,

    /// How the layers are computed: auto picks the cheaper per layer.
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    method: MethodArg,

    /// Also write the layers and the mip chain as KTX2 cube maps for engines: layers-cube.ktx2 (a
    /// cube-map array, one cube per exponent, faces of WIDTH / 4) and mips-cube.ktx2 (a cube map
    /// with the mip chain). Vulkan/KTX2 face order and orientation, +Y up: the world's +z (the
    /// map's top row) is the +Y face (data-schema/README.md has the picture).
    #[arg(long)]
    cube: bool,

    /// Also write the Phong exponents as one mip chain, the layout engines read (cmft's):
    /// phong-chain.ktx2, level m the m-th sharpest exponent at (WIDTH >> m) x (HEIGHT >> m) (the
    /// defaults give 16384, 4096, ..., 1 from 512 x 256 down), and phong-chain-cube.ktx2 with --cube.
    #[arg(long)]
    chain: bool,

    /// Also write the GGX chain engines read (split sum, n = v = r): ggx.ktx2, M mip levels from
    /// the --size grid down, level m at perceptual roughness m / (M - 1) (alpha = roughness^2;
    /// level 0 the mirror), ggx-cube.ktx2 with --cube, and the split-sum DFG table (dfg.ktx2: A
    /// in red, B in green of F0 A + B; dfg.png). From 2 to log2(WIDTH) - 1 levels (8 for 512x256).
    #[arg(long, value_name = "M", value_parser = |s: &str| cli::parse_whole(s, 2))]
    ggx_levels: Option<usize>,

    /// Store the KTX2 files as half floats even when some texels exceed 65504, clamping those
    /// (smaller files; the default stores such a file as single floats).
    #[arg(long)]
    clamp_half: bool,

    /// Read the KTX2 files back (with the `ktx2` crate) and check that they hold the EXR layers
    /// and the mip chain (up to half-float rounding when stored as half floats).
    #[arg(long)]
    verify: bool,

    /// Print one JSON object (parameters, figures, files written) on stdout; the report goes to
    /// stderr.
    #[arg(long)]
    json: bool,

    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum MethodArg {
    Auto,
    SphericalHarmonics,
    Window,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Auto => Method::Auto,
            MethodArg::SphericalHarmonics => Method::SphericalHarmonics,
            MethodArg::Window => Method::Window,
        }
    }
}

const PROGRAM: Program = Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let config = Config {
        exponents: args.exponents.clone(),
        width: args.size.0,
        height: args.size.1,
        method: args.method.into(),
        storage: if args.clamp_half { prefilter::ktx::Storage::ClampHalf } else { prefilter::ktx::Storage::Auto },
        cube: args.cube,
        ggx_levels: args.ggx_levels.unwrap_or(0),
        chain: args.chain,
    };
    config.check().context("invalid arguments")?;
    let progress = cli::Progress::new(args.quiet);
    progress.step("loading".to_string());
    let limits = bake::stage::prefilter::limits(&config, args.max_memory)?;
    let map =
        envmap::load_with_limits(&args.env, &limits).with_context(|| format!("reading {}", args.env.display()))?;
    let source = Source::hash(&args.env)?;
    progress.step("prefiltering".to_string());
    let (mut staged, prefiltered) =
        bake::stage::prefilter::run(&map, &source, &PROGRAM, &config, &|done, total| progress.work(done, total))
            .with_context(|| format!("analysing {}", args.env.display()))?;
    progress.finish();
    let dir = &args.out_dir;
    staged.write(dir)?;
    if args.verify {
        let verified = bake::stage::prefilter::verify(dir, &map, &prefiltered)?;
        staged.report.extend(verified.report);
        staged.problems.extend(verified.problems);
    }
    Ok(cli::finish(args.json, &staged.json(dir)?, &staged.report, &staged.problems, &staged.written(dir)))
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::Args;

    #[test]
    fn the_defaults_are_the_crate_defaults() {
        let args = Args::parse_from(["envmap-prefilter", "map.hdr", "--out-dir", "dir"]);
        let config = prefilter::Config::default();
        assert_eq!(args.exponents, config.exponents);
        assert_eq!(args.size, (config.width, config.height));
    }
}
