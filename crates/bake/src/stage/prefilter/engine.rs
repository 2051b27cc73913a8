//! The prefilter stage's outputs in the layouts engines read: the Phong exponents as one mip
//! chain (`--layout chain`, `prefilter::phong_chain`), the GGX split-sum chain (`--ggx-levels`,
//! `prefilter::ggx`), each lat-long and, with `--cube`, as a cube map, and the DFG table that goes
//! with the GGX chain (`prefilter::dfg`) with its picture.

use envmap::EnvMap;
use picture::colormap::{Scale, viridis};
use picture::layout::{Axis, Grid, caption, heat_map, stack};
use picture::legend::Legend;
use picture::{Canvas, format_number};
use prefilter::Config;
use prefilter::ktx::{self, Shape, Storage};
use serde_json::json;

use crate::{Error, OutFile};

pub const PHONG_CHAIN_KTX2: &str = "phong-chain.ktx2";
pub const PHONG_CHAIN_CUBE_KTX2: &str = "phong-chain-cube.ktx2";
pub const GGX_KTX2: &str = "ggx.ktx2";
pub const GGX_CUBE_KTX2: &str = "ggx-cube.ktx2";
pub const DFG_KTX2: &str = "dfg.ktx2";
pub const DFG_PNG: &str = "dfg.png";

/// What the engine outputs add to the stage.
#[derive(Default)]
pub(super) struct Outputs {
    pub files: Vec<OutFile>,
    pub figures: Vec<(&'static str, serde_json::Value)>,
    pub report: Vec<String>,
    pub clamped: usize,
}

impl Outputs {
    /// Encodes `levels` (each half the size of the one before) as `name` and, with `config.cube`,
    /// as the cube map `cube_name`; records their formats as the figure `formats_figure`.
    fn chain(
        &mut self,
        levels: &[&EnvMap],
        (name, role): (&str, &'static str),
        (cube_name, cube_role): (&str, &'static str),
        formats_figure: &'static str,
        config: &Config,
        writer: &str,
    ) -> Result<(), Error> {
        let rgb: Vec<Vec<&[f32]>> = levels.iter().map(|l| vec![l.rgb()]).collect();
        let shape = Shape { width: levels[0].width(), height: levels[0].height(), layers: 0, faces: 1 };
        let latlong = ktx::encode(shape, &rgb, config.storage, writer).map_err(|e| encoding(name, &e))?;
        self.clamped += latlong.clamped;
        let mut formats = vec![json!({ "file": name, "format": latlong.format.name() })];
        self.files.push(OutFile { name: name.into(), format: asset::FileFormat::Ktx2, role, bytes: latlong.bytes });
        if config.cube {
            let cube =
                prefilter::cube::encode_levels(levels, config.storage, writer).map_err(|e| encoding(cube_name, &e))?;
            self.clamped += cube.clamped;
            formats.push(json!({ "file": cube_name, "format": cube.format.name() }));
            self.files.push(OutFile {
                name: cube_name.into(),
                format: asset::FileFormat::Ktx2,
                role: cube_role,
                bytes: cube.bytes,
            });
        }
        self.figures.push((formats_figure, json!(formats)));
        Ok(())
    }
}

fn encoding(what: &str, e: &dyn std::fmt::Display) -> Error {
    Error::Internal(format!("encoding {what}: {e}"))
}

/// The engine outputs of the chains `prefilter::prefilter_all` made for `config` (`chain`,
/// `ggx_levels`).
pub(super) fn outputs(
    phong_chain: Option<Vec<(u32, EnvMap)>>,
    ggx_chain: Option<prefilter::ggx::Chain>,
    config: &Config,
    writer: &str,
) -> Result<Outputs, Error> {
    let mut out = Outputs::default();
    if let Some(chain) = phong_chain {
        let levels: Vec<&EnvMap> = chain.iter().map(|(_, level)| level).collect();
        let names = (PHONG_CHAIN_KTX2, "phong-chain");
        let cube = (PHONG_CHAIN_CUBE_KTX2, "phong-chain-cube");
        out.chain(&levels, names, cube, "phong_chain_formats", config, writer)?;
        let exponents: Vec<u32> = chain.iter().map(|(n, _)| *n).collect();
        out.report.push(format!(
            "phong chain   {} levels from {} x {}, exponents {} (level m: the m-th sharpest lobe at half the size of m - 1)",
            levels.len(),
            config.width,
            config.height,
            exponents.iter().map(u32::to_string).collect::<Vec<_>>().join(", ")
        ));
        out.figures.push(("phong_chain_exponents", json!(exponents)));
    }
    if let Some(chain) = ggx_chain {
        ggx(&chain, config, writer, &mut out)?;
    }
    Ok(out)
}

/// The GGX chain and the DFG table.
fn ggx(chain: &prefilter::ggx::Chain, config: &Config, writer: &str, out: &mut Outputs) -> Result<(), Error> {
    let levels: Vec<&EnvMap> = chain.levels.iter().collect();
    let cube = (GGX_CUBE_KTX2, "ggx-chain-cube");
    out.chain(&levels, (GGX_KTX2, "ggx-chain"), cube, "ggx_formats", config, writer)?;

    let size = prefilter::dfg::DFG_SIZE;
    let table = prefilter::dfg::table(size);
    let table_rgb: Vec<f32> = table.iter().flat_map(|[a, b]| [*a, *b, 0.0]).collect();
    let dfg_shape = Shape { width: size, height: size, layers: 0, faces: 1 };
    let dfg =
        ktx::encode(dfg_shape, &[vec![&table_rgb[..]]], Storage::Auto, writer).map_err(|e| encoding(DFG_KTX2, &e))?;
    out.files.push(OutFile {
        name: DFG_KTX2.into(),
        format: asset::FileFormat::Ktx2,
        role: "dfg-table",
        bytes: dfg.bytes,
    });
    let figure = dfg_picture(&table, size);
    let png = envmap::encode_png_rgb8(figure.width, figure.height, &figure.rgb).map_err(|e| encoding(DFG_PNG, &e))?;
    out.files.push(OutFile { name: DFG_PNG.into(), format: asset::FileFormat::Png, role: "dfg-picture", bytes: png });

    let roughness: Vec<String> = chain.roughness.iter().map(|r| format_number((r * 1000.0).round() / 1000.0)).collect();
    let methods: Vec<&str> = chain.methods.iter().map(|m| m.name()).collect();
    out.report.push(format!(
        "ggx chain     {} levels from {} x {}, perceptual roughness {} (alpha = roughness^2; level 0 the mirror)",
        chain.levels.len(),
        config.width,
        config.height,
        roughness.join(", ")
    ));
    out.report.push(format!(
        "dfg table     {size} x {size}: A (red) and B (green) of F0 A + B, n . v along x, roughness along y"
    ));
    out.figures.extend([
        ("ggx_roughness", json!(chain.roughness)),
        ("ggx_methods", json!(methods)),
        ("dfg_size", json!(size)),
        ("dfg_samples", json!(prefilter::dfg::DFG_SAMPLES)),
    ]);
    Ok(())
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
