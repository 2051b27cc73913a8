//! The glTF material closest to the table (`brdf-fit`, `brdf-bake --fit`; crate `gltf-fit`):
//! `fit.json` (`data-schema/brdf-fit.md`), a glTF sphere holding the material
//! (`material.gltf` and its buffer `material.bin`) and the fit as a MERL table (`fit.binary`).

use gltf_fit::{AlbedoRow, Fit, Material, Objective, Settings, Stage};
use merl::MerlTable;
use serde_json::{Value, json};

use crate::{OutFile, Program, Source, Staged, object};

pub const RECORD: &str = "fit.json";
pub const GLTF: &str = "material.gltf";
pub const BIN: &str = "material.bin";
pub const TABLE: &str = "fit.binary";

/// What the stage made: its files (`fit.json`, which names the others, listed last) and
/// `fit.json`'s record.
#[derive(Debug)]
pub struct Fitted {
    pub staged: Staged,
    pub record: Value,
}

/// Fits the material of `table` (read from `source`, a file of `size_bytes` bytes) with
/// `settings`, calling `progress` as [`gltf_fit::fit_reporting`] does.
pub fn run(
    table: &MerlTable,
    source: &Source,
    size_bytes: u64,
    program: &Program,
    settings: &Settings,
    progress: &dyn Fn(Stage, &Settings),
) -> Fitted {
    let fit = gltf_fit::fit_reporting(table, settings, progress);
    let material = fit.chosen().material;
    let fitted = gltf_fit::fitted_table(&material, settings.masking, table.dims());
    let albedo = gltf_fit::albedo_rows(table, &fitted);
    let generator = format!("{} {}", program.name, program.version);
    let gltf = gltf_fit::gltf::gltf_files(&material, &source.stem(), BIN, &generator);
    // The kept material under every objective, so that fits by one can be judged by the other.
    let by_kind: Vec<(Objective, f64)> = [Objective::LogCosine, Objective::LinearCosine]
        .into_iter()
        .map(|objective| (objective, gltf_fit::objective(table, &material, &Settings { objective, ..*settings })))
        .collect();
    let source_json =
        json!({ "name": source.file_name(), "size_bytes": size_bytes, "sha256": asset::hex(&source.sha256) });
    let record = record(&fit, &albedo, &by_kind, source_json, program);
    let record_text = serde_json::to_string_pretty(&record).expect("json values serialize") + "\n";
    let file = |name: &str, format, role, bytes: Vec<u8>| OutFile { name: name.into(), format, role, bytes };
    let files = vec![
        file(BIN, asset::FileFormat::Bin, "fit-gltf-buffer", gltf.bin),
        file(TABLE, asset::FileFormat::Merl, "fit-table", fitted.to_bytes()),
        file(GLTF, asset::FileFormat::Gltf, "fit-gltf", gltf.gltf.into_bytes()),
        file(RECORD, asset::FileFormat::Json, "fit-record", record_text.into_bytes()),
    ];
    let staged = Staged {
        name: "fit",
        parameters: object([
            ("masking", json!(settings.masking.name())),
            ("objective", json!(settings.objective.name())),
            ("margin", json!(settings.margin)),
        ]),
        figures: object([
            ("variant", json!(fit.chosen.name())),
            ("objective", json!(fit.chosen().objective)),
            ("albedo_relative_error", json!(albedo.iter().map(AlbedoRow::relative_error).collect::<Vec<_>>())),
        ]),
        files,
        report: report(&fit, &albedo),
        problems: Vec::new(),
    };
    Fitted { staged, record }
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
fn record(fit: &Fit, albedo: &[AlbedoRow], by_kind: &[(Objective, f64)], source: Value, program: &Program) -> Value {
    let chosen = fit.chosen();
    json!({
        "format": "brdf-fit",
        "version": 2,
        "model": {
            "brdf": "gltf-2.0-metallic-roughness",
            "masking": fit.settings.masking.name(),
            "extensions": chosen.material.extensions(),
        },
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
            "tool": { "name": program.name, "version": program.version },
        },
    })
}

/// The stage's report for people.
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
