//! Which Phong layer serves each view of a material (`001` sections 2.5 and 4.3; crate
//! `bandwidth-atlas`, module `view`): the material's lobes and the layers' own lobes measured with the
//! same analysis, as an asset of kind `layer-selection` that the renderers read.
//!
//! How often the 20 shared real-derived materials select each layer (views per layer over the 64
//! rows, default bake, `asset-info --json layer-selection.asset`'s `view_layer`): n = 1: 0,
//! n = 4: 2, n = 16: 146, n = 64: 236, n = 256: 115, n = 1024: 118, n = 4096: 161, n = 16384:
//! 502. Six of them (black-obsidian, blue-acrylic, brass, chrome, red-metallic-paint, steel)
//! select n = 16384 at every view: their lobes carry a cusp at the mirror direction (the neural
//! fits' `sqrt(theta_h)` input), whose fine detail the band quantile counts, and the renderers
//! read them sharper still (`bandwidth_atlas::view::view_coordinates`: past the sharpest layer, the
//! map itself); the diffuse-looking ones (pink-fabric, silver-metallic-paint) stay at n = 16 to
//! 256, most rows at 16 and 64.

use bandwidth_atlas::view::{ViewLayers, ViewReduction, select_layers};
use bandwidth_atlas::{AtlasBuild, Config};
use serde_json::json;

use crate::stage::bandwidth_atlas::analysis_of;
use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "layer-selection.asset";

/// The reduction `brdf-bake` uses, chosen by what the `prefiltered` mode renders against the
/// converged estimate (`cargo bench -p brdf-preview --bench preview`: six cases, white-paint,
/// gold-paint and chrome under potsdamer_platz and quarry_01, a 128 x 128 sphere, 16 samples per
/// pixel, one frame; mean PSNR over the six cases in dB):
///
/// | analysis | max | band-0.9 | band-0.95 | band-0.99 |
/// |---------:|----:|---------:|----------:|----------:|
/// | 64       | 34.90 | 38.55 | 38.21 | 38.71 |
/// | 128      | 36.74 | 38.91 | 38.88 | 39.04 |
/// | 256      | 37.94 | 38.94 | 38.92 | 39.02 |
/// | 512      | 38.60 | 39.01 | 38.90 | 39.05 |
///
/// The maximum (the papers' literal "maximum frequency") is worst at every size: it picks sharp
/// layers for every view (real-derived lobes reach the grid's limit at the mirror direction) and
/// leaves the noise of few samples. The band quantiles agree within 0.15 dB and are flat from
/// 128 up; 0.99 is best or within 0.1 dB of it everywhere. The analysis size therefore follows the
/// atlas's own needs (`bandwidth_atlas::Config`, 512); 256 or more is needed to tell the default layers
/// apart (at 128, n = 1024 and 4096 measure within 10% of each other).
pub const DEFAULT_REDUCTION: ViewReduction = ViewReduction::BandQuantile(0.99);

/// Selects the layers of `exponents` for the material whose atlas build (made with `config`) is
/// `build`.
pub fn select(
    build: &AtlasBuild,
    config: &Config,
    exponents: &[u32],
    reduction: ViewReduction,
) -> Result<ViewLayers, Error> {
    select_layers(build, config, exponents, reduction).map_err(|e| Error::stage("layer selection", e))
}

/// The stage of `selection` ([`select`] of the atlas build `build`, made with `config`); `source`
/// is the material.
pub fn run(
    selection: &ViewLayers,
    config: &Config,
    build: &AtlasBuild,
    source: &Source,
    program: &Program,
) -> Result<Staged, Error> {
    let (exponents, reduction) = (&selection.exponents, selection.reduction);
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
    Ok(staged)
}
