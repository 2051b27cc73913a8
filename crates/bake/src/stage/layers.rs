//! Which Phong layer serves each view of a material (`001` sections 2.5 and 4.3; crate
//! `brdf-atlas`, module `view`): the material's lobes and the layers' own lobes measured with the
//! same analysis, as an asset of kind `layer-selection` that the renderers read.

use brdf_atlas::view::{LayerSelection, ViewReduction, select_layers};
use brdf_atlas::{AtlasBuild, Config};
use serde_json::json;

use crate::stage::atlas::analysis_of;
use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "layer-selection.asset";

/// The reduction `brdf-bake` uses; `bake::BakeConfig` documents the measurements behind it.
pub const DEFAULT_REDUCTION: ViewReduction = ViewReduction::BandQuantile(0.99);

/// Selects the layers of `exponents` for the material whose atlas build (made with `config`) is
/// `build`; `source` is the material.
pub fn run(
    build: &AtlasBuild,
    config: &Config,
    exponents: &[u32],
    reduction: ViewReduction,
    source: &Source,
    program: &Program,
) -> Result<(Staged, LayerSelection), Error> {
    let selection =
        select_layers(build, config, exponents, reduction).map_err(|e| Error::stage("layer selection", e))?;
    let payload = asset::LayerSelection {
        analysis: analysis_of(&build.atlas),
        rows: selection.view_layer.len() as u32,
        reduction: reduction.name(),
        exponents: exponents.to_vec(),
        layer_bandwidth: selection.layer_bandwidth.clone(),
        view_bandwidth: selection.view_bandwidth.clone(),
        view_layer: selection.view_layer.clone(),
    };
    let parameters = [
        ("reduction", reduction.name()),
        ("analysis_size", config.analysis_size.to_string()),
        ("exponents", exponents.iter().map(u32::to_string).collect::<Vec<_>>().join(",")),
    ];
    let bytes = asset::encode_checked(&asset::Asset {
        provenance: source.provenance(program, &parameters),
        payload: payload.into(),
    })
    .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;
    let histogram = selection.histogram();
    let mut report = vec![format!(
        "reduction {} at {} x {} analysis: each view's lobe and each layer's lobe measured alike (cycles per radian)",
        reduction.name(),
        config.analysis_size,
        config.analysis_size
    )];
    report.push("  layer  exponent  bandwidth  views (of the atlas's rows in cos theta_o)".to_string());
    for (k, (n, b)) in exponents.iter().zip(&selection.layer_bandwidth).enumerate() {
        report.push(format!("  {k:>5}  {n:>8}  {b:>9.4}  {:>5}", histogram[k]));
    }
    let layers: String = selection.view_layer.iter().map(|k| char::from_digit(*k, 36).unwrap_or('?')).collect();
    report.push(format!("  layer per row, normal incidence first: {layers}"));
    let staged = Staged {
        name: "layer-selection",
        parameters: object([
            ("reduction", json!(reduction.name())),
            ("analysis_size", json!(config.analysis_size)),
            ("exponents", json!(exponents)),
        ]),
        figures: object([
            ("layer_bandwidth", json!(selection.layer_bandwidth)),
            ("views_per_layer", json!(histogram)),
            ("view_bandwidth", json!(selection.view_bandwidth)),
        ]),
        files: vec![OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "layer-selection", bytes }],
        report,
        problems: Vec::new(),
    };
    Ok((staged, selection))
}
