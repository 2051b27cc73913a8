//! The bandwidth atlas of a material (`brdf-bandwidth`; `000` section 2.4): every lobe's wavelet
//! bandwidth reduced to a tile, as an asset, a float EXR and a false-colour picture.
//!
//! The asset stores each distinct tile once: an isotropic atlas (every tile of a row equal to the
//! row's first, always the case for a MERL table, and checked, not assumed) is written as kind
//! `bandwidth-rows`, one tile per row, 1/`lobes` of the full grid; any other as kind
//! `bandwidth-atlas`, the full grid. [`from_payload`] reads either back into the full grid. The
//! EXR is always the full `lobes tile x lobes tile` texture: the export for renderers that index
//! the atlas by `wi` directly.

pub(crate) mod picture;

use bandwidth_atlas::{Analyser, Atlas, AtlasBuild, Config, LuminanceTable, build_atlas_with};
use serde_json::json;

use crate::{Error, OutFile, Program, Source, Staged, object};

pub const ASSET: &str = "bandwidth-atlas.asset";
pub const EXR: &str = "bandwidth-atlas.exr";
pub const PICTURE: &str = "bandwidth-atlas.png";

/// Builds the atlas of a table's luminance ([`LuminanceTable::new`]) with `analyser`, made of
/// a checked configuration ([`Config::check`]); `tick(n)` is called as `n` more lobes are done
/// (a progress bar's hook).
pub fn run(
    luminance: &LuminanceTable,
    analyser: &Analyser,
    source: &Source,
    program: &Program,
    tick: &(dyn Fn(usize) + Sync),
) -> Result<(Staged, AtlasBuild), Error> {
    let config = analyser.config();
    let build = build_atlas_with(analyser, luminance, tick);
    let atlas = &build.atlas;
    let notes = format!(
        "{} {} of {} lobes reach the analysis grid's limit: their values are lower bounds ({:.2} cycles per \
         radian at a lobe's centre).",
        picture::tile_notes(atlas),
        build.stats.nyquist_lobes(),
        atlas.n_lobes(),
        limit_at_centre(config)
    );
    let title = format!("bandwidth atlas of {}", source.stem());
    let text = picture::Text {
        title: &title,
        legend: "local bandwidth of the lobe, cycles per radian (log scale)",
        zero: "0: flat, no detail above the noise floor",
        notes: &notes,
    };
    // The texture and the picture are encoded side by side.
    let (exr, (png, scale)) = rayon::join(
        || envmap::encode_exr(atlas.width(), atlas.height(), &[("Y", &atlas.data)], envmap::SampleType::F32),
        || {
            let (figure, scale) = picture::figure(atlas, &atlas.data, &text);
            (envmap::encode_png_rgb8(figure.width, figure.height, &figure.rgb), scale)
        },
    );
    let exr = exr.map_err(|e| Error::Internal(format!("encoding {EXR}: {e}")))?;
    let png = png.map_err(|e| Error::Internal(format!("encoding {PICTURE}: {e}")))?;
    let range = (scale.lo(), scale.hi());
    let parameters = [
        ("lobes", config.lobes.to_string()),
        ("tile", config.tile.to_string()),
        ("analysis_size", config.analysis_size.to_string()),
    ];
    let payload: asset::Payload =
        if atlas.is_isotropic() { to_rows_asset(atlas).into() } else { to_asset(atlas).into() };
    let stored_kind = payload.kind();
    let asset = asset::encode_checked(&asset::Asset { provenance: source.provenance(program, &parameters), payload })
        .map_err(|e| Error::Internal(format!("encoding {ASSET}: {e}")))?;

    let (figures, report) = describe(config, &build, range, stored_kind);
    let staged = Staged {
        name: "bandwidth-atlas",
        parameters: object([
            ("lobes", json!(config.lobes)),
            ("tile", json!(config.tile)),
            ("analysis_size", json!(config.analysis_size)),
            ("eps", json!(config.eps)),
            ("c", json!(config.c)),
        ]),
        figures,
        files: vec![
            OutFile { name: ASSET.into(), format: asset::FileFormat::Asset, role: "bandwidth-atlas", bytes: asset },
            OutFile { name: EXR.into(), format: asset::FileFormat::Exr, role: "bandwidth-atlas-exr", bytes: exr },
            OutFile {
                name: PICTURE.into(),
                format: asset::FileFormat::Png,
                role: "bandwidth-atlas-picture",
                bytes: png,
            },
        ],
        report,
        problems: limit_problem(config, &build),
    };
    Ok((staged, build))
}

/// A validation problem when most lobes reach the analysis grid's limit: their bandwidth is then
/// a lower bound, and a renderer would shade too coarsely.
fn limit_problem(config: &Config, build: &AtlasBuild) -> Vec<String> {
    let (at_limit, lobes) = (build.stats.nyquist_lobes(), build.atlas.n_lobes());
    if 2 * at_limit <= lobes {
        return Vec::new();
    }
    vec![format!(
        "{at_limit} of {lobes} lobes reach the analysis grid's limit ({:.2} cycles per radian at a lobe's centre at \
         {} x {}): their bandwidth is a lower bound; analyse at a larger size (--analysis-size, up to 4096; each \
         doubling doubles the limit)",
        limit_at_centre(config),
        config.analysis_size,
        config.analysis_size
    )]
}

/// The highest bandwidth the analysis grid can report at a lobe's centre, cycles per radian: the
/// finest level's `c / 2` cycles per pixel over `pi / n` radians per pixel.
pub fn limit_at_centre(config: &Config) -> f64 {
    config.c / 2.0 * config.analysis_size as f64 / std::f64::consts::PI
}

fn describe(
    config: &Config,
    build: &AtlasBuild,
    range: (f64, f64),
    stored_kind: asset::AssetKind,
) -> (serde_json::Map<String, serde_json::Value>, Vec<String>) {
    let atlas = &build.atlas;
    let rows = stored_kind == asset::AssetKind::BandwidthRows;
    let stored_texels = if rows { atlas.lobes_y * atlas.tile_len() } else { atlas.data.len() };
    let stats = &build.stats;
    let [median, p90, p99, max] = quantiles(&atlas.data, [0.5, 0.9, 0.99, 1.0]);
    let n_lobes = atlas.n_lobes();
    let flat = atlas.data.iter().filter(|v| **v == 0.0).count();
    let at_limit = stats.nyquist_lobes();
    let figures = object([
        ("lobes", json!(n_lobes)),
        ("texels", json!(atlas.data.len())),
        ("median", json!(median)),
        ("p90", json!(p90)),
        ("p99", json!(p99)),
        ("max", json!(max)),
        ("flat_texels", json!(flat)),
        ("lobes_at_limit", json!(at_limit)),
        ("texels_at_limit", json!(stats.nyquist_texels)),
        ("limit_at_centre", json!(limit_at_centre(config))),
        ("filled_pixels", json!(stats.filled_pixels)),
        ("isotropic", json!(rows)),
        ("stored_kind", json!(stored_kind.name())),
        ("stored_texels", json!(stored_texels)),
    ]);
    let mut report = vec![
        format!(
            "atlas         {} x {} lobes of {} x {} texels ({} x {}), each lobe analysed at {} x {}",
            atlas.lobes_x,
            atlas.lobes_y,
            atlas.tile,
            atlas.tile,
            atlas.width(),
            atlas.height(),
            config.analysis_size,
            config.analysis_size
        ),
        format!(
            "bandwidth     cycles per radian: median {median:.3}, 90% {p90:.3}, 99% {p99:.3}, max {max:.3}; {flat} of {} \
             texels flat (0)",
            atlas.data.len()
        ),
        format!(
            "limit         {at_limit} of {n_lobes} lobes reach the analysis grid's limit ({} texels): {}",
            stats.nyquist_texels,
            if at_limit == 0 {
                "every bandwidth is resolved".to_string()
            } else {
                format!(
                    "their bandwidth is a lower bound ({:.2} cycles per radian at a lobe's centre); a larger \
                     --analysis-size resolves more",
                    limit_at_centre(config)
                )
            }
        ),
    ];
    report.push(if rows {
        format!(
            "stored        {ASSET}: kind {} ({}), each row's tile once ({} of {} texels: every tile of a row equals \
             the row's first); {EXR} holds the full {} x {} texture for renderers",
            stored_kind.code(),
            stored_kind.name(),
            stored_texels,
            atlas.data.len(),
            atlas.width(),
            atlas.height()
        )
    } else {
        format!(
            "stored        {ASSET}: kind {} ({}), every tile ({} texels: the tiles of a row differ); {EXR} holds \
             the same {} x {} texture",
            stored_kind.code(),
            stored_kind.name(),
            stored_texels,
            atlas.width(),
            atlas.height()
        )
    });
    if stats.filled_pixels > 0 {
        report.push(format!(
            "filled        {} lobe pixels had no table data around them: filled from their neighbours",
            stats.filled_pixels
        ));
    }
    report.push(format!(
        "picture       the atlas {} with axes, log colour scale from {} (dark violet) to {} (yellow) cycles per \
         radian, black 0",
        picture::Shown::of(atlas.width(), atlas.height()).words(),
        ::picture::format_number(range.0),
        ::picture::format_number(range.1)
    ));
    (figures, report)
}

/// The values of rank `round((n - 1) q)` in `values` (`n` of them, ordered by `total_cmp`) for
/// each of the ascending quantiles `qs`: what indexing the sorted values gives, by selection
/// (each selection leaves the values above its rank to the next) rather than a sort of the
/// million texels: the quantiles are taken after the atlas and before the files are written,
/// so their time adds to the stage's (`cargo bench -p bake --bench stages` times it).
fn quantiles<const Q: usize>(values: &[f32], qs: [f64; Q]) -> [f64; Q] {
    let mut values = values.to_vec();
    let mut start = 0;
    qs.map(|q| {
        let rank = ((values.len() - 1) as f64 * q).round() as usize;
        let (_, value, _) = values[start..].select_nth_unstable_by(rank - start, f32::total_cmp);
        start = rank;
        f64::from(*value)
    })
}

/// The full grid as an asset's payload (kind `bandwidth-atlas`, `data-schema/README.md`): what
/// the stage writes for an atlas whose tiles differ within a row.
pub fn to_asset(atlas: &Atlas) -> asset::BandwidthAtlas {
    asset::BandwidthAtlas {
        lobes_x: atlas.lobes_x as u32,
        lobes_y: atlas.lobes_y as u32,
        tile: atlas.tile as u32,
        analysis: analysis_of(atlas),
        data: atlas.data.clone(),
    }
}

/// The rows of an isotropic atlas as an asset's payload (kind `bandwidth-rows`): each row's
/// first tile ([`Atlas::rows`]) and the number of columns they serve. The caller checks
/// [`Atlas::is_isotropic`]; otherwise the other columns are lost.
pub fn to_rows_asset(atlas: &Atlas) -> asset::BandwidthRows {
    asset::BandwidthRows {
        lobes_x: atlas.lobes_x as u32,
        lobes_y: atlas.lobes_y as u32,
        tile: atlas.tile as u32,
        analysis: analysis_of(atlas),
        data: atlas.rows().data,
    }
}

/// The analysis record both the atlas and its PCA carry.
pub fn analysis_of(atlas: &Atlas) -> asset::BandwidthAnalysis {
    asset::BandwidthAnalysis {
        parameterization: atlas.parameterization.name().to_string(),
        analysis_size: atlas.analysis_size as u32,
        eps: atlas.eps,
        c: atlas.c,
    }
}

/// The full atlas an atlas asset of either kind stands for, checked: kind `bandwidth-atlas` as
/// it is, kind `bandwidth-rows` expanded (row `j`'s tile in every column), its size bounded before
/// anything is allocated. Any other payload is an error naming its kind.
pub fn from_payload(payload: asset::Payload) -> Result<Atlas, String> {
    match payload {
        asset::Payload::BandwidthAtlas(a) => from_asset(a),
        asset::Payload::BandwidthRows(r) => from_rows_asset(r),
        other => Err(format!(
            "expected a bandwidth-atlas or bandwidth-rows asset (from brdf-bandwidth), found {}",
            other.kind()
        )),
    }
}

fn parameterization_of(analysis: &asset::BandwidthAnalysis) -> Result<bandwidth_atlas::Parameterization, String> {
    let name = analysis.parameterization.as_str();
    bandwidth_atlas::Parameterization::from_name(name).ok_or_else(|| {
        format!(
            "unknown parameterization {name:?}: this build knows {:?}",
            bandwidth_atlas::Parameterization::IncidencePlaneEquidistant.name()
        )
    })
}

/// The full atlas of a rows asset: the rows checked as an atlas one lobe wide, then expanded to
/// `lobes_x` columns ([`Atlas::expand_rows`] refuses a grid above [`bandwidth_atlas::MAX_TEXELS`]
/// before allocating it).
fn from_rows_asset(r: asset::BandwidthRows) -> Result<Atlas, String> {
    let rows = atlas_of(1, r.lobes_y, r.tile, r.data, &r.analysis)?;
    rows.expand_rows(r.lobes_x as usize).map_err(|e| e.to_string())
}

/// An atlas read back from its full-grid asset, checked.
pub fn from_asset(a: asset::BandwidthAtlas) -> Result<Atlas, String> {
    atlas_of(a.lobes_x, a.lobes_y, a.tile, a.data, &a.analysis)
}

/// The in-memory atlas of an asset's fields, checked (`Atlas::check`: sizes with overflow checks,
/// the texel limit, finite values).
fn atlas_of(
    lobes_x: u32,
    lobes_y: u32,
    tile: u32,
    data: Vec<f32>,
    analysis: &asset::BandwidthAnalysis,
) -> Result<Atlas, String> {
    let atlas = Atlas {
        lobes_x: lobes_x as usize,
        lobes_y: lobes_y as usize,
        tile: tile as usize,
        data,
        parameterization: parameterization_of(analysis)?,
        analysis_size: analysis.analysis_size as usize,
        eps: analysis.eps,
        c: analysis.c,
    };
    atlas.check().map_err(|e| e.to_string())?;
    Ok(atlas)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The selected quantiles are the sorted values' at the same ranks, on values with runs of
    /// equal values, zeros and a negative zero, including equal and neighbouring ranks.
    #[test]
    fn quantiles_are_the_sorted_values_at_their_ranks() {
        let values: Vec<f32> =
            (0..10_007u32).map(|k| if k % 13 == 0 { -0.0 } else { ((k * 7919) % 1009) as f32 * 0.25 }).collect();
        let mut sorted = values.clone();
        sorted.sort_unstable_by(f32::total_cmp);
        let qs = [0.0, 0.5, 0.5, 0.9, 0.9001, 0.99, 1.0];
        let got = quantiles(&values, qs);
        for (q, got) in qs.into_iter().zip(got) {
            let expect = sorted[((sorted.len() - 1) as f64 * q).round() as usize];
            assert_eq!(got.to_bits(), f64::from(expect).to_bits(), "q {q}");
        }
    }
}
