//! PCA compression of a bandwidth atlas (`bandwidth-pca`; `000` Fig. 8): the mean tile, the first
//! K principal components and every lobe's K coefficients, as an asset of kind `bandwidth-pca`,
//! and a false-colour picture of the reconstruction's absolute error.

use brdf_atlas::{Atlas, Components, PcaModel, evaluate, fit};
use serde_json::json;

use crate::stage::atlas::analysis_of;
use crate::stage::atlas::picture as atlas_picture;
use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "bandwidth-pca.asset";
pub const PICTURE: &str = "bandwidth-pca.png";

/// Fits the model of `atlas` (read from `source`, an atlas asset) with `components`.
pub fn run(atlas: &Atlas, source: &Source, program: &Program, components: Components) -> Result<Staged, Error> {
    let fitted = fit(atlas, components).map_err(|e| Error::stage("bandwidth pca", e))?;
    let report = evaluate(atlas, &fitted.model);
    let model = &fitted.model;
    let asset = asset::encode_checked(&asset::Asset {
        provenance: source.provenance(program, &[("components", model.n_components.to_string())]),
        payload: to_asset(model, atlas).into(),
    })
    .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;
    let title = format!(
        "bandwidth PCA: absolute error with K = {} components, relative RMSE {}%",
        report.n_components,
        picture::format_number(100.0 * report.relative_rmse)
    );
    let notes = format!(
        "|reconstruction - atlas| per texel, in the atlas's layout. {} The reconstruction may read below the \
         atlas: it is not conservative.",
        atlas_picture::tile_notes(atlas)
    );
    let text = atlas_picture::Text {
        title: &title,
        legend: "absolute error, cycles per radian, log scale",
        zero: "0: reconstructed exactly",
        notes: &notes,
    };
    let (figure, scale) = atlas_picture::figure(atlas, &report.errors, &text);
    let range = (scale.lo(), scale.hi());
    let png = envmap::encode_png_rgb8(figure.width, figure.height, &figure.rgb)
        .map_err(|e| Error::Internal(format!("encoding {PICTURE}: {e}")))?;

    // The fewest components the eigenvalues predict for a few error levels.
    let k_for = |e: f64| fitted.predicted_relative_rmse.iter().position(|p| *p <= e).unwrap_or(atlas.tile_len());
    let levels = [0.1, 0.05, 0.02, 0.01];
    let requested = match components {
        Components::Count(k) => json!({ "components": k }),
        Components::MaxRelativeRmse(e) => json!({ "max_relative_rmse": e }),
    };
    let figures = object([
        ("lobes", json!(atlas.n_lobes())),
        ("tile_len", json!(atlas.tile_len())),
        ("components", json!(report.n_components)),
        ("relative_rmse", json!(report.relative_rmse)),
        ("max_abs_error", json!(report.max_abs_error)),
        ("max_value", json!(report.max_value)),
        ("size_ratio", json!(report.size_ratio)),
        (
            "predicted_components",
            json!(levels.iter().map(|e| json!({"relative_rmse": e, "components": k_for(*e)})).collect::<Vec<_>>()),
        ),
    ]);
    let predicted: Vec<String> = levels.iter().map(|e| format!("{}% -> K = {}", 100.0 * e, k_for(*e))).collect();
    let lines = vec![
        format!("lobes           {} (tiles of {} texels)", atlas.n_lobes(), atlas.tile_len()),
        format!("components      {}", report.n_components),
        format!(
            "relative rmse   {:.3}% (|reconstruction - atlas| / |atlas| over all texels)",
            100.0 * report.relative_rmse
        ),
        format!(
            "max error       {:.4} cycles per radian ({:.2}% of the largest texel, {:.4})",
            report.max_abs_error,
            100.0 * report.max_abs_error / report.max_value.max(f64::MIN_POSITIVE),
            report.max_value
        ),
        format!(
            "size            {:.2}% of the atlas ({} of {} floats), compression {:.1}:1",
            100.0 * report.size_ratio,
            model.stored_values(),
            atlas.data.len(),
            1.0 / report.size_ratio
        ),
        format!("predicted       components needed for a relative rmse of {}", predicted.join(", ")),
        format!(
            "picture         absolute error per texel with axes, log colour scale from {} to {} cycles per radian, \
             black 0",
            picture::format_number(range.0),
            picture::format_number(range.1)
        ),
    ];
    Ok(Staged {
        name: "bandwidth-pca",
        parameters: object([("requested", requested)]),
        figures,
        files: vec![
            OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "bandwidth-pca", bytes: asset },
            OutFile {
                name: PICTURE.into(),
                format: asset::FileFormat::Png,
                role: "bandwidth-pca-error-picture",
                bytes: png,
            },
        ],
        report: lines,
        problems: Vec::new(),
    })
}

fn to_asset(model: &PcaModel, atlas: &Atlas) -> asset::BandwidthPca {
    asset::BandwidthPca {
        lobes_x: model.lobes_x as u32,
        lobes_y: model.lobes_y as u32,
        tile: model.tile as u32,
        analysis: analysis_of(atlas),
        n_components: model.n_components as u32,
        mean: model.mean.clone(),
        components: model.components.clone(),
        coefficients: model.coefficients.clone(),
    }
}
