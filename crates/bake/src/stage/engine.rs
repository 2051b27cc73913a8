//! The engine textures (`brdf-bake --engine-textures`): everything the estimators of the `render`
//! crate read, as single-float KTX2 data textures that any engine can upload and index without
//! our asset reader (`data-schema/engine-textures.md` has every layout; `engines/three` reads
//! them). They are made from the bake's own outputs as `bake::load` reads them (`load::assemble`:
//! the KTX2 files' half floats, the lighting's peaks and sampling tables built from them), so an
//! engine draws with the very numbers `brdf-preview` draws with.

use prefilter::ktx::{self, DataShape};
use render::{Estimator, Lighting, Material, Settings};
use serde_json::json;

use crate::{Error, OutFile, Program, Staged, object};

/// The MERL table as a 3D RGBA texture.
pub const MERL_KTX2: &str = "engine-merl.ktx2";
/// Every slice's half-vector tables, one array layer per slice.
pub const BRDF_TABLES_KTX2: &str = "engine-brdf-tables.ktx2";
/// The Phong layer coordinate of each view row.
pub const VIEW_LAYERS_KTX2: &str = "engine-view-layers.ktx2";
/// Level 0 of the environment and its peaks.
pub const ENVIRONMENT_KTX2: &str = "engine-environment.ktx2";
/// The lat-long distributions of level 0 and of the peaks.
pub const LIGHT_TABLES_KTX2: &str = "engine-light-tables.ktx2";
/// The Phong layers of the smooth part.
pub const LAYERS_KTX2: &str = "engine-layers.ktx2";
/// The Phong layers of the whole environment, peaks included (the split estimator's).
pub const FULL_LAYERS_KTX2: &str = "engine-full-layers.ktx2";

/// Every file the stage writes, in order: a bake whose engine-textures stage lists fewer was made
/// before the stage wrote them all, and is not up to date (`run::is_same_bake`).
pub const FILES: [&str; 7] =
    [MERL_KTX2, BRDF_TABLES_KTX2, VIEW_LAYERS_KTX2, ENVIRONMENT_KTX2, LIGHT_TABLES_KTX2, LAYERS_KTX2, FULL_LAYERS_KTX2];

/// The engine textures of `material` under `lighting` (both as `bake::load` makes them).
pub fn run(material: &Material, lighting: &Lighting, program: &Program) -> Result<Staged, Error> {
    let writer = format!("{} {}", program.name, program.version);
    let encode = |name: &str, shape: DataShape, values: &[f32]| -> Result<Vec<u8>, Error> {
        ktx::encode_data(shape, values, &writer).map_err(|e| Error::Internal(format!("encoding {name}: {e}")))
    };
    let mut files = Vec::new();
    let mut add = |name: &'static str, role: &'static str, bytes: Vec<u8>| {
        files.push(OutFile { name: name.into(), format: asset::FileFormat::Ktx2, role, bytes });
    };

    // The MERL table: texel (phi_d, theta_d, theta_h), RGB in 1/sr, alpha 1; no data as 0.
    let table = &material.table;
    let dims = table.dims();
    let mut merl = Vec::with_capacity(4 * dims.cells());
    for cell in 0..dims.cells() {
        match table.cell_value(cell) {
            Some(rgb) => merl.extend(rgb.iter().map(|&v| v as f32).chain([1.0])),
            None => merl.extend([0.0; 4]),
        }
    }
    let merl_shape =
        DataShape { width: dims.n_phi_d, height: dims.n_theta_d, depth: dims.n_theta_h, layers: 0, channels: 4 };
    add(MERL_KTX2, "engine-merl", encode(MERL_KTX2, merl_shape, &merl)?);

    // The half-vector tables, one layer per slice: row 0 the row edges in t = 1 - cos theta_h
    // (R + 1), row 1 the marginal CDF over rows (R + 1), row 2 + i the conditional CDF over
    // sectors of row i (C + 1); f32 as the renderers sample them.
    let slices = &material.samples.tables;
    let first = slices.first().ok_or_else(|| Error::Internal("the importance samples have no slice".into()))?;
    let (rows, sectors) = (first.distribution().nv(), first.distribution().nu());
    let width = rows.max(sectors) + 1;
    let height = rows + 2;
    let mut brdf = vec![0.0f32; width * height * slices.len()];
    for (k, slice) in slices.iter().enumerate() {
        let layer = &mut brdf[k * width * height..(k + 1) * width * height];
        let mut put = |row: usize, values: &[f64]| {
            for (i, &v) in values.iter().enumerate() {
                layer[row * width + i] = v as f32;
            }
        };
        put(0, slice.rows().t_edges());
        put(1, slice.distribution().marginal().cdf());
        for (i, row) in slice.distribution().conditional_cdf().chunks_exact(sectors + 1).enumerate() {
            put(2 + i, row);
        }
    }
    let brdf_shape = DataShape { width, height, depth: 0, layers: slices.len(), channels: 1 };
    add(BRDF_TABLES_KTX2, "engine-brdf-tables", encode(BRDF_TABLES_KTX2, brdf_shape, &brdf)?);

    // The view rows' layer coordinates, one texel each.
    let view_layers = &material.view_layers;
    if view_layers.is_empty() {
        return Err(Error::Internal("the layer selection has no view rows".into()));
    }
    let view_shape = DataShape { width: view_layers.len(), height: 1, depth: 0, layers: 0, channels: 1 };
    add(VIEW_LAYERS_KTX2, "engine-view-layers", encode(VIEW_LAYERS_KTX2, view_shape, view_layers)?);

    // Level 0 and the peaks (0 where there are none), RGB and alpha 1.
    let level0 = lighting.mips.level(0);
    let (w, h) = (level0.width(), level0.height());
    let rgba = |rgb: &[f32]| rgb.chunks_exact(3).flat_map(|t| [t[0], t[1], t[2], 1.0]).collect::<Vec<f32>>();
    let mut environment = rgba(level0.rgb());
    match &lighting.peaks {
        Some(peaks) => environment.extend(rgba(peaks.map.rgb())),
        None => environment.extend(rgba(&vec![0.0; 3 * w * h])),
    }
    let environment_shape = DataShape { width: w, height: h, depth: 0, layers: 2, channels: 4 };
    add(ENVIRONMENT_KTX2, "engine-environment", encode(ENVIRONMENT_KTX2, environment_shape, &environment)?);

    // The two lat-long distributions (level 0's, the peaks' or level 0's again where there are
    // none): row 0 the marginal CDF over rows (H + 1), row 1 + y the conditional CDF of row y
    // (W + 1).
    let light_width = w.max(h) + 1;
    let mut light = vec![0.0f32; light_width * (h + 1) * 2];
    let distributions = [&lighting.environment, lighting.peaks.as_ref().map_or(&lighting.environment, |p| &p.sampling)];
    for (layer, distribution) in light.chunks_exact_mut(light_width * (h + 1)).zip(distributions) {
        let d = distribution.distribution();
        for (i, &v) in d.marginal().cdf().iter().enumerate() {
            layer[i] = v as f32;
        }
        for (y, row) in d.conditional_cdf().chunks_exact(w + 1).enumerate() {
            for (i, &v) in row.iter().enumerate() {
                layer[(1 + y) * light_width + i] = v as f32;
            }
        }
    }
    let light_shape = DataShape { width: light_width, height: h + 1, depth: 0, layers: 2, channels: 1 };
    add(LIGHT_TABLES_KTX2, "engine-light-tables", encode(LIGHT_TABLES_KTX2, light_shape, &light)?);

    // The smooth part's Phong layers, sharpest last as the bake orders them.
    let layers = lighting.smooth_layers();
    let layer0 = layers.first().ok_or_else(|| Error::Internal("the bake has no phong layers".into()))?;
    let layer_values: Vec<f32> = layers.iter().flat_map(|l| rgba(l.rgb())).collect();
    let layers_shape =
        DataShape { width: layer0.width(), height: layer0.height(), depth: 0, layers: layers.len(), channels: 4 };
    add(LAYERS_KTX2, "engine-layers", encode(LAYERS_KTX2, layers_shape, &layer_values)?);
    // The bake's own layers, of the whole environment (the smooth part's plus the peaks'), in
    // the same shape: what engines/three's split estimator reads its lobes from.
    let full_values: Vec<f32> = lighting.layers.iter().flat_map(|l| rgba(l.rgb())).collect();
    add(FULL_LAYERS_KTX2, "engine-full-layers", encode(FULL_LAYERS_KTX2, layers_shape, &full_values)?);

    let defaults = |mode: Estimator| {
        let s = Settings::previewer(mode, &material.samples, None, None, 0);
        json!({ "spp": s.spp, "frames": s.frames })
    };
    let exposure_ev = render::metrics::auto_tone_mapping(level0).exposure_ev;
    let figures = object([
        ("merl_size", json!([dims.n_phi_d, dims.n_theta_d, dims.n_theta_h])),
        ("phi_d_range", json!(dims.phi_d_range())),
        ("slices", json!(material.samples.n_slices)),
        ("vectors", json!(material.samples.n_vectors)),
        ("samples", json!(material.samples.n_samples)),
        ("rows", json!(rows)),
        ("sectors", json!(sectors)),
        ("view_rows", json!(view_layers.len())),
        ("environment_size", json!([w, h])),
        ("layers_size", json!([layer0.width(), layer0.height()])),
        ("exponents", json!(lighting.exponents)),
        ("peaks", json!(lighting.peaks.is_some())),
        ("peak_threshold", json!(lighting.peaks.as_ref().map(|p| p.threshold))),
        ("diffuse", json!(render::diffuse_split(material, lighting))),
        ("exposure_ev", json!(exposure_ev)),
        (
            "previewer",
            json!({ "reference": defaults(Estimator::Reference), "prefiltered": defaults(Estimator::Prefiltered) }),
        ),
    ]);
    let megabytes = files.iter().map(|f| f.bytes.len()).sum::<usize>() as f64 / 1e6;
    let report = vec![
        format!(
            "engine textures: the MERL table as a {} x {} x {} rgba32f 3D texture, {} slices of half-vector tables \
             ({rows} rows x {sectors} sectors), {} view rows, level 0 of {w} x {h} with its peaks ({}), {} Phong \
             layers of {} x {} of the smooth part and of the whole environment: {megabytes:.1} MB",
            dims.n_phi_d,
            dims.n_theta_d,
            dims.n_theta_h,
            slices.len(),
            view_layers.len(),
            if lighting.peaks.is_some() { "present" } else { "none" },
            layers.len(),
            layer0.width(),
            layer0.height(),
        ),
        format!("automatic exposure {exposure_ev:+.3} EV (brdf-preview's)"),
    ];
    Ok(Staged {
        name: "engine-textures",
        parameters: serde_json::Map::new(),
        figures,
        files,
        report,
        problems: Vec::new(),
    })
}
