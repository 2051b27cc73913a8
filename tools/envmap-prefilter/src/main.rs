//! `envmap-prefilter`: an environment map convolved with normalized Phong lobes of several
//! exponents (pre-convolved shading), written as a KTX2 array texture, one EXR per layer, the
//! source's mip chain as a KTX2 texture (filtered importance sampling), a contact sheet and an
//! asset that ties them together. A thin layer over the `prefilter` crate.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use envmap::{EnvMap, MipChain, SampleType};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use prefilter::{Config, Method, Prefiltered};

/// Convolve a lat-long environment map (OpenEXR or Radiance HDR, 2:1) with the normalized Phong
/// lobe (n + 1) / (2 pi) max(0, w . r)^n for each exponent n, around every direction r of a
/// lat-long grid. Writes, in DIR: layers.ktx2 (RGBA16F 2D array, one layer per exponent),
/// layer-n<N>.exr (RGB float, one per exponent), mips.ktx2 (RGBA16F 2D texture with the source's
/// mip chain, for filtered importance sampling), contact-sheet.png (the source and the layers,
/// tone mapped) and prefiltered.asset (kind prefiltered-envmap: exponents, bandwidths, the
/// bandwidth-to-layer thresholds, file names and hashes; layout in data-schema/README.md).
///
/// Exit status: 0 ok, 1 --verify found a file that does not read back as written, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    /// The environment map (.exr or .hdr, lat-long, width = 2 x height).
    env: PathBuf,

    /// The folder to write into (created if missing).
    #[arg(long, short, value_name = "DIR")]
    out: PathBuf,

    /// Phong exponents, one layer each, strictly increasing.
    #[arg(long, value_name = "N,N,...", value_delimiter = ',', default_value = "1,4,16,64,256,1024,4096")]
    exponents: Vec<u32>,

    /// Size of every layer, WIDTHxHEIGHT with WIDTH = 2 x HEIGHT.
    #[arg(long, value_name = "WxH", default_value = "256x128", value_parser = parse_size)]
    size: (usize, usize),

    /// How the layers are computed: auto picks the cheaper per layer.
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    method: MethodArg,

    /// Read the KTX2 files back (with the `ktx2` crate) and check that they hold the EXR layers
    /// and the mip chain up to half-float rounding.
    #[arg(long)]
    verify: bool,
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

fn parse_size(text: &str) -> Result<(usize, usize), String> {
    let parse = |s: &str| s.trim().parse::<usize>().map_err(|e| format!("{s:?}: {e}"));
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got {text:?}"))?;
    Ok((parse(w)?, parse(h)?))
}

/// The files written in the output folder.
const ASSET: &str = "prefiltered.asset";
const LAYERS_KTX2: &str = "layers.ktx2";
const MIPS_KTX2: &str = "mips.ktx2";
const CONTACT_SHEET: &str = "contact-sheet.png";

fn layer_exr(n: u32) -> String {
    format!("layer-n{n}.exr")
}

fn main() -> ExitCode {
    cli::main(|| run(Args::parse()))
}

fn run(args: Args) -> Result<ExitCode> {
    let start = Instant::now();
    let config = Config {
        exponents: args.exponents.clone(),
        width: args.size.0,
        height: args.size.1,
        method: args.method.into(),
    };
    config.check().context("invalid arguments")?;
    let env = &args.env;
    let map = step("loading", |_| envmap::load(env)).with_context(|| format!("reading {}", env.display()))?;
    let loaded = start.elapsed();

    let prefiltered = step("prefiltering", |bar| {
        prefilter::prefilter_with_progress(&map, &config, &|p| {
            bar.set_length(p.total);
            bar.set_position(p.done);
        })
    })
    .with_context(|| format!("prefiltering {}", env.display()))?;
    let computed = start.elapsed();

    let outputs = step("writing", |_| write_outputs(&args, &map, &prefiltered))?;
    eprintln!(
        "wrote {} ({} layers of {} x {}, exponents {}) and its files in {:.2} s (loading {:.2} s, prefiltering {:.2} s)",
        args.out.join(ASSET).display(),
        config.exponents.len(),
        config.width,
        config.height,
        join(&config.exponents),
        start.elapsed().as_secs_f64(),
        loaded.as_secs_f64(),
        (computed - loaded).as_secs_f64(),
    );
    for scale in [("layers", outputs.layers_radiance_scale), ("mips", outputs.mips_radiance_scale)] {
        if scale.1 != 1.0 {
            eprintln!("note: {} texels are radiance x {} (the brightest exceed half floats)", scale.0, scale.1);
        }
    }
    if args.verify { verify(&args.out, &prefiltered, &MipChain::new(&map), &outputs) } else { Ok(ExitCode::SUCCESS) }
}

/// Runs one step; if it is still running after a second, shows a progress bar on stderr (a
/// spinner when the step reports no progress) until it ends.
fn step<T>(message: &'static str, work: impl FnOnce(&ProgressBar) -> T) -> T {
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden()).with_message(message);
    let done = AtomicBool::new(false);
    let result = std::thread::scope(|scope| {
        let watcher = scope.spawn(|| {
            let shown_at = Instant::now() + Duration::from_secs(1);
            while !done.load(Ordering::Acquire) {
                let now = Instant::now();
                if now >= shown_at {
                    let template = if bar.length().is_some() {
                        "{msg} [{bar:40}] {percent:>3}% {elapsed}"
                    } else {
                        "{spinner} {msg} {elapsed}"
                    };
                    bar.set_style(ProgressStyle::with_template(template).expect("a valid template"));
                    bar.set_draw_target(ProgressDrawTarget::stderr());
                    bar.enable_steady_tick(Duration::from_millis(100));
                    return;
                }
                std::thread::park_timeout(shown_at - now);
            }
        });
        let result = work(&bar);
        done.store(true, Ordering::Release);
        watcher.thread().unpark();
        result
    });
    bar.finish_and_clear();
    result
}

/// What [`write_outputs`] wrote, for the asset and `--verify`.
struct Outputs {
    layers_radiance_scale: f32,
    mips_radiance_scale: f32,
}

fn write_outputs(args: &Args, map: &EnvMap, prefiltered: &Prefiltered) -> Result<Outputs> {
    let out = &args.out;
    let writer = format!("{} {}", env!("CARGO_PKG_NAME"), env!("CARGO_PKG_VERSION"));
    let write = |name: &str, bytes: &[u8]| -> Result<asset::LinkedFile> {
        let path = out.join(name);
        asset::write_atomic(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
        Ok(asset::LinkedFile { name: name.to_string(), sha256: asset::sha256(bytes) })
    };
    let layer_maps: Vec<&EnvMap> = prefiltered.layers.iter().map(|layer| &layer.map).collect();
    let layers = prefilter::ktx::encode_array(&layer_maps, &writer).context("encoding the layers as ktx2")?;
    let layers_ktx2 = write(LAYERS_KTX2, &layers.bytes)?;
    let chain = MipChain::new(map);
    let mips = prefilter::ktx::encode_mip_chain(&chain, &writer).context("encoding the mip chain as ktx2")?;
    let mips_ktx2 = write(MIPS_KTX2, &mips.bytes)?;
    let layer_exrs = prefiltered
        .layers
        .iter()
        .map(|layer| {
            let name = layer_exr(layer.exponent);
            let texels = layer.map.texels();
            let planes: [Vec<f32>; 3] = std::array::from_fn(|c| texels.iter().map(|t| t[c]).collect());
            let channels = [("R", planes[0].as_slice()), ("G", &planes[1]), ("B", &planes[2])];
            let bytes = envmap::encode_exr(layer.map.width(), layer.map.height(), &channels, SampleType::F32)
                .with_context(|| format!("encoding {name}"))?;
            write(&name, &bytes)
        })
        .collect::<Result<Vec<_>>>()?;
    let sheet = prefilter::contact_sheet(&chain, &layer_maps);
    let png = envmap::encode_png_rgb8(sheet.width, sheet.height, &sheet.rgb8).context("encoding the contact sheet")?;
    let contact_sheet_png = write(CONTACT_SHEET, &png)?;

    let mean = |m: &EnvMap| m.mean_radiance();
    let payload = asset::PrefilteredEnvmap {
        source_size: [map.width() as u32, map.height() as u32],
        source_mean_radiance: mean(map),
        layer_size: [args.size.0 as u32, args.size.1 as u32],
        mip_levels: chain.n_levels() as u32,
        layers_radiance_scale: f64::from(layers.radiance_scale),
        mips_radiance_scale: f64::from(mips.radiance_scale),
        exponents: args.exponents.clone(),
        lobe_bandwidth: prefiltered.mapping.bandwidths().to_vec(),
        bandwidth_thresholds: prefiltered.mapping.thresholds().to_vec(),
        layer_mean_radiance: layer_maps.iter().map(|m| mean(m)).collect(),
        layers_ktx2,
        layer_exrs,
        mips_ktx2,
        contact_sheet_png,
    };
    let asset = asset::Asset { provenance: provenance(args, prefiltered)?, payload: payload.into() };
    let path = out.join(ASSET);
    asset::write_file(&path, &asset).with_context(|| format!("writing {}", path.display()))?;
    Ok(Outputs { layers_radiance_scale: layers.radiance_scale, mips_radiance_scale: mips.radiance_scale })
}

fn provenance(args: &Args, prefiltered: &Prefiltered) -> Result<asset::Provenance> {
    let env = &args.env;
    let mut parameters = vec![
        ("exponents".to_string(), join(&args.exponents)),
        ("size".to_string(), format!("{}x{}", args.size.0, args.size.1)),
        ("method".to_string(), Method::from(args.method).name().to_string()),
    ];
    for layer in &prefiltered.layers {
        let how = match layer.degree {
            Some(degree) => format!("{} to degree {degree}", layer.method.name()),
            None => layer.method.name().to_string(),
        };
        parameters.push((format!("layer n={}", layer.exponent), how));
    }
    asset::Provenance::of_source(env, env!("CARGO_PKG_NAME"), env!("CARGO_PKG_VERSION"), parameters)
        .with_context(|| format!("hashing {}", env.display()))
}

fn join(exponents: &[u32]) -> String {
    exponents.iter().map(u32::to_string).collect::<Vec<_>>().join(",")
}

/// Half-float rounding: round to nearest keeps 11 significant bits (relative error at most
/// `2^-11`), and below the smallest normal half (`2^-14`) the spacing is `2^-24`, so the absolute
/// error there is at most `2^-25`. Stored values are radiance times the file's scale.
fn half_tolerance(value: f32, scale: f32) -> f32 {
    value.abs() * 2f32.powi(-11) + 2f32.powi(-25) / scale
}

/// Reads both KTX2 files back with the `ktx2` crate and compares them with the EXR layers (read
/// back with `envmap`) and the mip chain; prints what it found on stdout.
fn verify(out: &Path, prefiltered: &Prefiltered, chain: &MipChain, outputs: &Outputs) -> Result<ExitCode> {
    let mut problems = Vec::new();
    let layers_path = out.join(LAYERS_KTX2);
    let exrs: Vec<Vec<f32>> = prefiltered
        .layers
        .iter()
        .map(|layer| {
            let path = out.join(layer_exr(layer.exponent));
            let image = envmap::read_image(&path, &envmap::Limits::default())
                .with_context(|| format!("reading {}", path.display()))?;
            Ok(image.rgb)
        })
        .collect::<Result<_>>()?;
    let first = &prefiltered.layers[0].map;
    let worst = compare_ktx2(
        &layers_path,
        (first.width(), first.height(), prefiltered.layers.len() as u32),
        &[exrs.iter().map(Vec::as_slice).collect()],
        outputs.layers_radiance_scale,
        &mut problems,
    )?;
    cli::outln!(
        "{}: {} layers match the EXR layers within half-float rounding (largest relative difference {worst:.2e})",
        layers_path.display(),
        prefiltered.layers.len()
    );
    let mips_path = out.join(MIPS_KTX2);
    let level0 = chain.level(0);
    let levels: Vec<Vec<&[f32]>> = chain.levels().iter().map(|level| vec![level.rgb()]).collect();
    let worst = compare_ktx2(
        &mips_path,
        (level0.width(), level0.height(), 0),
        &levels,
        outputs.mips_radiance_scale,
        &mut problems,
    )?;
    cli::outln!(
        "{}: {} mip levels match the source's mip chain within half-float rounding (largest relative difference {worst:.2e})",
        mips_path.display(),
        chain.n_levels()
    );
    for problem in &problems {
        cli::outln!("problem: {problem}");
    }
    Ok(if problems.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// Checks one KTX2 file's header and texels against `expected[level][layer]` (interleaved RGB),
/// returning the largest relative difference; mismatches go to `problems`.
fn compare_ktx2(
    path: &Path,
    (width, height, layer_count): (usize, usize, u32),
    expected: &[Vec<&[f32]>],
    scale: f32,
    problems: &mut Vec<String>,
) -> Result<f32> {
    let context = || format!("reading {}", path.display());
    let bytes = std::fs::read(path).with_context(context)?;
    let reader = ktx2::Reader::new(&bytes[..]).map_err(|e| anyhow::anyhow!("{e:?}")).with_context(context)?;
    let header = reader.header();
    let found = (header.format, header.pixel_width, header.pixel_height, header.layer_count, header.level_count);
    let wanted =
        (Some(ktx2::Format::R16G16B16A16_SFLOAT), width as u32, height as u32, layer_count, expected.len() as u32);
    if found != wanted {
        bail!("{}: header {found:?}, expected {wanted:?}", path.display());
    }
    let mut worst = 0.0f32;
    for (l, (level, images)) in reader.levels().zip(expected).enumerate() {
        let texels: Vec<f32> =
            level.data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect();
        let per_layer = texels.len() / images.len().max(1);
        for (layer, image) in images.iter().enumerate() {
            let stored = &texels[layer * per_layer..(layer + 1) * per_layer];
            if stored.len() != image.len() / 3 * 4 {
                problems.push(format!("{}: level {l} layer {layer} has {} values", path.display(), stored.len()));
                continue;
            }
            for (i, (rgba, rgb)) in stored.chunks_exact(4).zip(image.chunks_exact(3)).enumerate() {
                for c in 0..3 {
                    let (got, want) = (rgba[c] / scale, rgb[c]);
                    let difference = (got - want).abs();
                    if difference > half_tolerance(want, scale) {
                        problems.push(format!(
                            "{}: level {l} layer {layer} texel {i} channel {c}: {got}, expected {want}",
                            path.display()
                        ));
                    }
                    if want > 0.0 {
                        worst = worst.max(difference / want);
                    }
                }
                if rgba[3] != 1.0 {
                    problems.push(format!("{}: level {l} layer {layer} texel {i}: alpha {}", path.display(), rgba[3]));
                }
            }
        }
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::Args;

    #[test]
    fn the_defaults_are_the_crate_defaults() {
        let args = Args::parse_from(["envmap-prefilter", "map.hdr", "--out", "dir"]);
        let config = prefilter::Config::default();
        assert_eq!(args.exponents, config.exponents);
        assert_eq!(args.size, (config.width, config.height));
    }

    #[test]
    fn sizes_parse() {
        assert_eq!(super::parse_size("64x32"), Ok((64, 32)));
        assert_eq!(super::parse_size("64X32"), Ok((64, 32)));
        assert!(super::parse_size("64").is_err());
        assert!(super::parse_size("ax32").is_err());
    }
}
