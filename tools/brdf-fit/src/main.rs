//! `brdf-fit`: the glTF material closest to a MERL table. Argument parsing, reading, writing and
//! reporting around `gltf_fit::fit`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use gltf_fit::{AlbedoRow, Fit, Masking, Material, Objective, Settings, Stage, Variant};
use merl::MerlTable;
use serde_json::{Value, json};

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
    /// never a bake's folder.
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

/// The files written, in the order `asset::write_set` switches them in: fit.json, which names
/// the others, last.
const GLTF: &str = "material.gltf";
const BIN: &str = "material.bin";
const TABLE: &str = "fit.binary";
const FIT_JSON: &str = "fit.json";

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
    let source = json!({
        "name": path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
        "size_bytes": bytes.len(),
        "sha256": asset::hex(&asset::sha256(&bytes)),
    });
    let table = MerlTable::parse(&bytes).with_context(|| format!("reading {}", path.display()))?;
    drop(bytes);
    // Before the fit: a folder that cannot be made costs nothing.
    asset::create_folder(dir).map_err(|e| anyhow::anyhow!("writing {}: {e}", dir.display()))?;

    let progress = cli::Progress::new(args.quiet);
    let fit = gltf_fit::fit_reporting(&table, &settings, &|stage, settings| match stage {
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
    let material = fit.chosen().material;
    let fitted = gltf_fit::fitted_table(&material, settings.masking, table.dims());
    let albedo = gltf_fit::albedo_rows(&table, &fitted);
    let name = path.file_stem().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "material".into());
    let generator = format!("{} {}", env!("CARGO_PKG_NAME"), env!("CARGO_PKG_VERSION"));
    let gltf = gltf_fit::gltf::gltf_files(&material, &name, BIN, &generator);
    // The kept material under every objective, so that fits by one can be judged by the other.
    let by_kind: Vec<(Objective, f64)> = [Objective::LogCosine, Objective::LinearCosine]
        .into_iter()
        .map(|objective| (objective, gltf_fit::objective(&table, &material, &Settings { objective, ..settings })))
        .collect();
    let record = fit_json(&fit, &albedo, &by_kind, source);
    let record_text = serde_json::to_string_pretty(&record).expect("json values serialize") + "\n";
    let table_bytes = fitted.to_bytes();
    let files: [(&str, &[u8]); 4] =
        [(BIN, &gltf.bin), (TABLE, &table_bytes), (GLTF, gltf.gltf.as_bytes()), (FIT_JSON, record_text.as_bytes())];
    asset::write_set(dir, &files).map_err(|(p, e)| anyhow::anyhow!("writing {}: {e}", p.display()))?;

    let written: Vec<String> = files.iter().map(|(n, _)| dir.join(n).display().to_string()).collect();
    let value = json!({ "fit": record, "files": files.iter().map(|(n, b)| file_entry(dir, n, b)).collect::<Vec<_>>() });
    Ok(cli::finish(args.json, &value, &report(&fit, &albedo), &[], &written))
}

fn file_entry(dir: &Path, name: &str, bytes: &[u8]) -> Value {
    json!({ "path": dir.join(name).display().to_string(), "size_bytes": bytes.len(), "sha256": asset::hex(&asset::sha256(bytes)) })
}

fn material_json(m: &Material) -> Value {
    json!({
        "baseColorFactor": m.base_color,
        "metallicFactor": m.metallic,
        "roughnessFactor": m.roughness,
        "alpha": m.alpha(),
        "specularFactor": m.specular,
        "specularColorFactor": m.specular_color,
        "clearcoatFactor": m.clearcoat,
        "clearcoatRoughnessFactor": m.clearcoat_roughness,
    })
}

/// fit.json (data-schema/brdf-fit.md).
fn fit_json(fit: &Fit, albedo: &[AlbedoRow], by_kind: &[(Objective, f64)], source: Value) -> Value {
    let chosen = fit.chosen();
    let extensions = chosen.material.extensions();
    json!({
        "format": "brdf-fit",
        "version": 2,
        "model": { "brdf": "gltf-2.0-metallic-roughness", "masking": fit.settings.masking.name(), "extensions": extensions },
        "variant": chosen.variant.name(),
        "material": material_json(&chosen.material),
        "objective": {
            "kind": fit.settings.objective.name(),
            "value": chosen.objective,
            "core": fit.core.objective,
            "specular": fit.specular.objective,
            "clearcoat": fit.clearcoat.objective,
            "margin": fit.settings.margin,
            "by_kind": by_kind.iter().map(|(o, v)| (o.name().to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
        },
        "initial_estimate": {
            "alpha": fit.estimate.alpha,
            "power_iterations": fit.estimate.iterations,
            "material": material_json(&fit.initial),
        },
        "refinement": {
            "method": "levenberg-marquardt",
            "phi_d_stride": fit.settings.phi_d_stride,
            "core_iterations": fit.core.iterations,
            "specular_iterations": fit.specular.iterations,
            "clearcoat_iterations": fit.clearcoat.iterations,
        },
        "albedo": albedo.iter().map(|row| json!({
            "theta_o_deg": row.theta_o_deg,
            "measured": row.measured,
            "fit": row.fit,
            "relative_error": row.relative_error(),
        })).collect::<Vec<_>>(),
        "files": { "gltf": GLTF, "bin": BIN, "table": TABLE },
        "provenance": {
            "source": source,
            "tool": { "name": env!("CARGO_PKG_NAME"), "version": env!("CARGO_PKG_VERSION") },
        },
    })
}

fn report(fit: &Fit, albedo: &[AlbedoRow]) -> Vec<String> {
    let m = fit.chosen().material;
    let rgb = |c: [f64; 3]| format!("{:.4} {:.4} {:.4}", c[0], c[1], c[2]);
    let mut lines = vec![
        format!(
            "{} material: baseColor {}, metallic {:.4}, roughness {:.4} (alpha {:.5})",
            fit.chosen.name(),
            rgb(m.base_color),
            m.metallic,
            m.roughness,
            m.alpha()
        ),
        format!(
            "objective ({}, {} masking): {:.6e} (core {:.6e}, with KHR_materials_specular {:.6e}, with \
             KHR_materials_clearcoat {:.6e})",
            fit.settings.objective.name(),
            fit.settings.masking.name(),
            fit.chosen().objective,
            fit.core.objective,
            fit.specular.objective,
            fit.clearcoat.objective
        ),
        format!("initial estimate: alpha {:.5} after {} power iterations", fit.estimate.alpha, fit.estimate.iterations),
    ];
    if m.uses_clearcoat_extension() {
        lines.insert(
            1,
            format!(
                "KHR_materials_clearcoat: clearcoat {:.4}, clearcoatRoughness {:.4}",
                m.clearcoat, m.clearcoat_roughness
            ),
        );
    }
    if m.uses_specular_extension() {
        lines.insert(
            1,
            format!("KHR_materials_specular: specular {:.4}, specularColor {}", m.specular, rgb(m.specular_color)),
        );
    }
    lines.push("directional albedo (nearest lookup), measured -> fit, luminance error:".into());
    for row in albedo {
        lines.push(format!(
            "  theta_o {:>2}: {} -> {}  {:+.2}%",
            row.theta_o_deg,
            rgb(row.measured),
            rgb(row.fit),
            100.0 * row.relative_error()
        ));
    }
    lines
}
