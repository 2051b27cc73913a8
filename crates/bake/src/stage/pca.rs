//! PCA compression of a bandwidth atlas (`bandwidth-pca`; `000` Fig. 8): the mean tile, the first
//! K principal components and every lobe's K coefficients, as an asset of kind `bandwidth-pca`,
//! and a false-colour picture of the reconstruction's absolute error.
//!
//! The model is fitted on the atlas's distinct tiles. In an isotropic atlas (every tile of a row
//! equal to the row's first: every MERL table, stored as kind `bandwidth-rows`) those are the
//! rows ([`Atlas::rows`]); the model then has `lobes_x = 1` and one set of coefficients per row,
//! which serves every column. Repeating each tile `lobes_x` times scales the covariance and keeps
//! the mean, so the components and every tile's error are those of a fit on the full grid, at
//! 1/`lobes_x` of the coefficients. Sizes are reported against the distinct tiles
//! (`size_ratio`: what PCA saves over storing each tile once) and against the full grid
//! (`size_ratio_full_grid`: what it saves over the 1024 x 1024 texture).

use bandwidth_atlas::{Atlas, Components, PcaModel, evaluate, fit};
use serde_json::json;

use crate::stage::bandwidth_atlas::analysis_of;
use crate::stage::bandwidth_atlas::picture as atlas_picture;
use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "bandwidth-pca.asset";
pub const PICTURE: &str = "bandwidth-pca.png";

/// Fits the model of `atlas` (the full grid, read from `source`, an atlas asset of either kind)
/// with `components`, on its distinct tiles (module docs).
pub fn run(atlas: &Atlas, source: &Source, program: &Program, components: Components) -> Result<Staged, Error> {
    let rows = atlas.is_isotropic().then(|| atlas.rows());
    let distinct = rows.as_ref().unwrap_or(atlas);
    let fitted = fit(distinct, components).map_err(|e| Error::stage("bandwidth pca", e))?;
    let report = evaluate(distinct, &fitted.model);
    let model = &fitted.model;
    let size_ratio_full_grid = model.stored_values() as f64 / atlas.data.len() as f64;
    // The picture shows the error in the full grid's layout, like the atlas's picture.
    let errors = if rows.is_some() {
        Atlas { lobes_x: 1, data: report.errors.clone(), ..*atlas }
            .expand_rows(atlas.lobes_x)
            .map_err(|e| Error::Internal(format!("expanding the pca's errors to the full grid: {e}")))?
            .data
    } else {
        report.errors.clone()
    };
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
        "|reconstruction - atlas| per texel, in the atlas's layout{}. {} The reconstruction may read below the \
         atlas: it is not conservative.",
        if rows.is_some() { " (one model tile per row, serving every column)" } else { "" },
        atlas_picture::tile_notes(atlas)
    );
    let text = atlas_picture::Text {
        title: &title,
        legend: "absolute error, cycles per radian, log scale",
        zero: "0: reconstructed exactly",
        notes: &notes,
    };
    let (figure, scale) = atlas_picture::figure(atlas, &errors, &text);
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
        ("distinct_tiles", json!(distinct.n_lobes())),
        ("tile_len", json!(atlas.tile_len())),
        ("components", json!(report.n_components)),
        ("relative_rmse", json!(report.relative_rmse)),
        ("max_abs_error", json!(report.max_abs_error)),
        ("max_value", json!(report.max_value)),
        ("size_ratio", json!(report.size_ratio)),
        ("size_ratio_full_grid", json!(size_ratio_full_grid)),
        (
            "predicted_components",
            json!(levels.iter().map(|e| json!({"relative_rmse": e, "components": k_for(*e)})).collect::<Vec<_>>()),
        ),
    ]);
    let predicted: Vec<String> = levels.iter().map(|e| format!("{}% -> K = {}", 100.0 * e, k_for(*e))).collect();
    let lobes = if rows.is_some() {
        format!(
            "lobes           {} x {} of {} distinct tiles of {} texels (every tile of a row is the row's first: the \
             model is fitted on the {} row tiles, each row's coefficients serve all {} columns)",
            atlas.lobes_x,
            atlas.lobes_y,
            distinct.n_lobes(),
            atlas.tile_len(),
            distinct.n_lobes(),
            atlas.lobes_x
        )
    } else {
        format!("lobes           {} x {} (tiles of {} texels)", atlas.lobes_x, atlas.lobes_y, atlas.tile_len())
    };
    let size = if rows.is_some() {
        format!(
            "size            {:.2}% of the distinct tiles ({} of {} floats), compression {:.1}:1; against the full \
             {} x {} grid ({} floats) {:.2}%, {:.1}:1",
            100.0 * report.size_ratio,
            model.stored_values(),
            distinct.data.len(),
            1.0 / report.size_ratio,
            atlas.lobes_x,
            atlas.lobes_y,
            atlas.data.len(),
            100.0 * size_ratio_full_grid,
            1.0 / size_ratio_full_grid
        )
    } else {
        format!(
            "size            {:.2}% of the atlas ({} of {} floats), compression {:.1}:1",
            100.0 * report.size_ratio,
            model.stored_values(),
            atlas.data.len(),
            1.0 / report.size_ratio
        )
    };
    let mut lines = vec![
        lobes,
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
        size,
        format!("predicted       components needed for a relative rmse of {}", predicted.join(", ")),
        format!(
            "picture         absolute error per texel with axes, log colour scale from {} to {} cycles per radian, \
             black 0",
            picture::format_number(range.0),
            picture::format_number(range.1)
        ),
    ];
    if report.size_ratio >= 1.0 {
        lines.push(format!(
            "note            the model holds more floats than the {} distinct tiles it stands for: storing the tiles \
             (the atlas asset) is smaller and exact",
            distinct.n_lobes()
        ));
    }
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
