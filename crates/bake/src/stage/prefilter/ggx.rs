//! The GGX outputs of the prefilter stage (`--ggx-levels`): the split-sum chain engines read
//! (`prefilter::ggx`), lat-long and, with `--cube`, as a cube map, and the DFG table that goes
//! with it (`prefilter::dfg`) with its picture.

use envmap::EnvMap;
use picture::colormap::{Scale, viridis};
use picture::layout::{Axis, Grid, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};
use prefilter::Config;
use prefilter::ktx::{self, Shape, Storage};
use serde_json::json;

use crate::{Error, OutFile};

pub const GGX_KTX2: &str = "ggx.ktx2";
pub const GGX_CUBE_KTX2: &str = "ggx-cube.ktx2";
pub const DFG_KTX2: &str = "dfg.ktx2";
pub const DFG_PNG: &str = "dfg.png";

/// What the GGX outputs add to the stage.
pub(super) struct Outputs {
    pub files: Vec<OutFile>,
    pub figures: Vec<(&'static str, serde_json::Value)>,
    pub report: Vec<String>,
    pub clamped: usize,
}

/// The chain of `config.ggx_levels` levels of `map`, encoded, and the DFG table.
pub(super) fn outputs(
    map: &EnvMap,
    config: &Config,
    writer: &str,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<Outputs, Error> {
    let encoding = |what: &str, e: &dyn std::fmt::Display| Error::Internal(format!("encoding {what}: {e}"));
    let chain =
        prefilter::ggx::chain(map, config.width, config.ggx_levels, config.method, &|p| progress(p.done, p.total))
            .map_err(|e| Error::stage("ggx chain", e))?;
    let levels: Vec<&EnvMap> = chain.levels.iter().collect();
    let rgb: Vec<Vec<&[f32]>> = levels.iter().map(|l| vec![l.rgb()]).collect();
    let shape = Shape { width: config.width, height: config.height, layers: 0, faces: 1 };
    let latlong = ktx::encode(shape, &rgb, config.storage, writer).map_err(|e| encoding(GGX_KTX2, &e))?;
    let mut clamped = latlong.clamped;
    let mut files = vec![OutFile {
        name: GGX_KTX2.into(),
        format: asset::FileFormat::Ktx2,
        role: "ggx-chain",
        bytes: latlong.bytes,
    }];
    let mut formats = vec![json!({ "file": GGX_KTX2, "format": latlong.format.name() })];
    if config.cube {
        let cube =
            prefilter::cube::encode_levels(&levels, config.storage, writer).map_err(|e| encoding(GGX_CUBE_KTX2, &e))?;
        clamped += cube.clamped;
        formats.push(json!({ "file": GGX_CUBE_KTX2, "format": cube.format.name() }));
        files.push(OutFile {
            name: GGX_CUBE_KTX2.into(),
            format: asset::FileFormat::Ktx2,
            role: "ggx-chain-cube",
            bytes: cube.bytes,
        });
    }

    let size = prefilter::dfg::DFG_SIZE;
    let table = prefilter::dfg::table(size);
    let table_rgb: Vec<f32> = table.iter().flat_map(|[a, b]| [*a, *b, 0.0]).collect();
    let dfg_shape = Shape { width: size, height: size, layers: 0, faces: 1 };
    let dfg =
        ktx::encode(dfg_shape, &[vec![&table_rgb[..]]], Storage::Auto, writer).map_err(|e| encoding(DFG_KTX2, &e))?;
    files.push(OutFile { name: DFG_KTX2.into(), format: asset::FileFormat::Ktx2, role: "dfg-table", bytes: dfg.bytes });
    let figure = dfg_picture(&table, size);
    let png = envmap::encode_png_rgb8(figure.width, figure.height, &figure.rgb).map_err(|e| encoding(DFG_PNG, &e))?;
    files.push(OutFile { name: DFG_PNG.into(), format: asset::FileFormat::Png, role: "dfg-picture", bytes: png });

    let roughness: Vec<String> = chain.roughness.iter().map(|r| format_number((r * 1000.0).round() / 1000.0)).collect();
    let methods: Vec<&str> = chain.methods.iter().map(|m| m.name()).collect();
    let report = vec![
        format!(
            "ggx chain     {} levels from {} x {}, perceptual roughness {} (alpha = roughness^2; level 0 the mirror)",
            chain.levels.len(),
            config.width,
            config.height,
            roughness.join(", ")
        ),
        format!("dfg table     {size} x {size}: A (red) and B (green) of F0 A + B, n . v along x, roughness along y"),
    ];
    let figures = vec![
        ("ggx_roughness", json!(chain.roughness)),
        ("ggx_methods", json!(methods)),
        ("ggx_formats", json!(formats)),
        ("dfg_size", json!(size)),
        ("dfg_samples", json!(prefilter::dfg::DFG_SAMPLES)),
    ];
    Ok(Outputs { files, figures, report, clamped })
}

/// The DFG table as two labelled heat maps.
fn dfg_picture(table: &[[f32; 2]], size: usize) -> Canvas {
    let scale = Scale::linear(0.0, 1.0);
    let panel = |c: usize| {
        // Row 0 (smoothest) at the bottom, so that roughness grows upwards.
        let image = Canvas::from_fn(size, size, |x, y| viridis(f64::from(table[(size - 1 - y) * size + x][c])));
        heat_map(&image, 3, &Axis::new("n . v", 0.0, 1.0), &Axis::new("roughness", 1.0, 0.0))
    };
    let mut grid = Grid::new(2);
    grid.title("split-sum DFG table: int f cos = F0 A + B (GGX, height-correlated Smith, Schlick)");
    grid.add(panel(0), "A, the scale of F0");
    grid.add(panel(1), "B, the bias");
    let width = grid.width();
    let legend = Legend::new(scale, viridis, "A or B (linear)");
    let text = "Texel (i, j) at n . v = (i + 1/2) / N and perceptual roughness (j + 1/2) / N; dfg.ktx2 stores \
                row 0 (the smoothest) first, A in red and B in green.";
    grid.footer(stack(&[legend.render(width), caption(text, width)]));
    grid.render()
}
