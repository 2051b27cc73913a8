//! `brdf-fit`: the glTF material closest to a MERL table. Argument parsing, reading, writing and
//! reporting around `bake::stage::fit` (which runs `gltf_fit::fit`).

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use gltf_fit::{Masking, Objective, Settings, Stage, Variant};
use merl::MerlTable;

/// Fit glTF 2.0's metallic-roughness material (the specification's Appendix B BRDF: GGX with
/// alpha = roughness^2, Smith masking, Schlick Fresnel, Lambertian diffuse), with
/// KHR_materials_specular or KHR_materials_clearcoat (a second, colourless lobe) where one lowers
/// the error by 5%, to a MERL table. The initial roughness
/// comes from the table's backscattering by Dupuy et al. 2015's power iteration; the factors are
/// then refined by Levenberg-Marquardt on the error of ln(1 + f cos theta) over the table's
/// cells, each weighted by its solid angle (the crate gltf-fit documents the choice).
///
/// Writes, in DIR, together or not at all: fit.json (the factors, the objective, the directional
/// albedo of the table and of the fit at 0, 30, 60 and 80 degrees, the input's name and sha256;
/// data-schema/brdf-fit.md), material.gltf and material.bin (a sphere with the material), and
/// fit.binary (the fitted BRDF as a MERL table, for the renderers and merl-info).
///
/// Example: brdf-fit gold-paint.binary --out-dir gold-paint-fit --json
///
/// Exit status: 0 ok, 2 error.
#[derive(Debug, Parser)]
#[command(version, about, long_about)]
struct Args {
    /// The MERL table (.binary).
    material: PathBuf,

    /// The folder to write into (created if missing: the folder itself, its parent must exist);
    /// never a bake's folder (brdf-bake --fit writes the same files into a bake).
    #[arg(long, short, value_name = "DIR")]
    out_dir: PathBuf,

    /// The Smith masking-shadowing term: height-correlated (what the Khronos sample renderer,
    /// three.js and Filament draw) or separable (Appendix B.3.2's sample implementation).
    #[arg(long, value_enum, default_value_t = MaskingArg::HeightCorrelated)]
    masking: MaskingArg,

    /// The error minimized per cell and channel: ln(1 + f cos theta) or f cos theta.
    #[arg(long, value_enum, default_value_t = ObjectiveArg::LogCosine)]
    objective: ObjectiveArg,

    /// Print one JSON object (fit.json's contents and the files written) on stdout; the report
    /// goes to stderr.
    #[arg(long)]
    json: bool,

    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum MaskingArg {
    HeightCorrelated,
    Separable,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum ObjectiveArg {
    LogCosine,
    LinearCosine,
}

const PROGRAM: bake::Program = bake::Program { name: env!("CARGO_PKG_NAME"), version: env!("CARGO_PKG_VERSION") };

fn main() -> ExitCode {
    cli::main(|| run(cli::args()?))
}

fn run(args: Args) -> Result<ExitCode> {
    let dir = &args.out_dir;
    if dir.join(asset::MANIFEST_FILE).exists() {
        bail!(
            "{} is a bake folder (it holds {}): brdf-fit writes a folder of its own",
            dir.display(),
            asset::MANIFEST_FILE
        );
    }
    let settings = Settings {
        masking: match args.masking {
            MaskingArg::HeightCorrelated => Masking::HeightCorrelated,
            MaskingArg::Separable => Masking::Separable,
        },
        objective: match args.objective {
            ObjectiveArg::LogCosine => Objective::LogCosine,
            ObjectiveArg::LinearCosine => Objective::LinearCosine,
        },
        ..Settings::default()
    };
    // The bytes hashed are the bytes parsed.
    let path = &args.material;
    let bytes = merl::read_bytes(path).with_context(|| format!("reading {}", path.display()))?;
    let source = bake::Source::of_bytes(path, &bytes);
    let size_bytes = bytes.len() as u64;
    let table = MerlTable::parse(&bytes).with_context(|| format!("reading {}", path.display()))?;
    drop(bytes);
    // Before the fit: a folder that cannot be made costs nothing.
    asset::create_folder(dir).map_err(|e| anyhow::anyhow!("writing {}: {e}", dir.display()))?;

    let progress = cli::Progress::new(args.quiet);
    let fitted =
        bake::stage::fit::run(&table, &source, size_bytes, &PROGRAM, &settings, &|stage, settings| match stage {
            Stage::Estimate => progress.step("1/4 initial estimate (power iteration)".into()),
            Stage::Refine(variant, done) => {
                if done == 0 {
                    let step = match variant {
                        Variant::Core => "2/4 core material",
                        Variant::Specular => "3/4 specular variant",
                        Variant::Clearcoat => "4/4 clearcoat variant",
                    };
                    progress.step(format!("{step} (Levenberg-Marquardt)"));
                }
                progress.work(done as u64, settings.max_iterations as u64);
            }
        });
    progress.finish();
    let staged = &fitted.staged;
    staged.write(dir)?;
    // What every single-stage tool prints (the stage and its files), and fit.json's record.
    let mut value = staged.json(dir)?;
    value["fit"] = fitted.record;
    Ok(cli::finish(args.json, &value, &staged.report, &staged.problems, &staged.written(dir)))
}
