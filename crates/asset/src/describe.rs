//! What a payload says about itself, for people (`asset-info`'s text) and for scripts (its JSON):
//! one arm per kind, so that a new kind is described in one place. The arrays themselves are too
//! large to print; a description gives their shapes and figures that summarize them.

use serde_json::{Value, json};

use crate::hex;
use crate::types::{
    BandwidthAnalysis, ImportanceSamples, LayerSelection, LinkedFile, MaterialInfo, Payload, PrefilteredEnvmap,
    WaveletBrdf, WaveletCoefficients,
};

/// A payload's summary: text lines (the first names the kind) and the same facts as JSON.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    pub lines: Vec<String>,
    pub json: Value,
}

impl Payload {
    /// The payload's summary (see the module documentation).
    pub fn describe(&self) -> Description {
        let mut lines = Vec::new();
        let json = match self {
            // The payload's own serde form: the field names of the type, angles in radians.
            Payload::MaterialInfo(info) => {
                material_info(info, &mut lines);
                serde_json::to_value(info).expect("material info serializes to json")
            }
            Payload::ImportanceSamples(samples) => importance_samples(samples, &mut lines),
            Payload::PrefilteredEnvmap(prefiltered) => prefiltered_envmap(prefiltered, &mut lines),
            Payload::BandwidthAtlas(atlas) => {
                lines.push("payload: bandwidth atlas".into());
                let value = tiles(atlas.lobes_x, atlas.lobes_y, atlas.tile, &atlas.analysis, &mut lines);
                let max = atlas.data.iter().fold(0.0f32, |m, v| m.max(*v));
                lines.push(format!("  max bandwidth    {max} cycles per radian"));
                value
            }
            Payload::BandwidthPca(pca) => {
                lines.push("payload: bandwidth pca".into());
                let mut value = tiles(pca.lobes_x, pca.lobes_y, pca.tile, &pca.analysis, &mut lines);
                lines.push(format!("  components       {}", pca.n_components));
                value["n_components"] = pca.n_components.into();
                value
            }
            Payload::LayerSelection(selection) => {
                layer_selection(selection, &mut lines);
                serde_json::to_value(selection).expect("layer selection serializes to json")
            }
            Payload::BandwidthRows(rows) => {
                lines.push("payload: bandwidth rows (an isotropic bandwidth atlas, one tile per row)".into());
                let mut value = tiles(rows.lobes_x, rows.lobes_y, rows.tile, &rows.analysis, &mut lines);
                lines.push(format!("  stored           {} row tiles: row j's tile serves every column", rows.lobes_y));
                let max = rows.data.iter().fold(0.0f32, |m, v| m.max(*v));
                lines.push(format!("  max bandwidth    {max} cycles per radian"));
                value["stored_tiles"] = rows.lobes_y.into();
                value
            }
            Payload::WaveletBrdf(wavelet) => wavelet_brdf(wavelet, &mut lines),
        };
        Description { lines, json }
    }
}

fn wavelet_brdf(w: &WaveletBrdf, lines: &mut Vec<String>) -> Value {
    let (n, k) = (w.side as usize, w.stored_slices());
    lines.push("payload: wavelet brdf (Haar, Claustres et al. 2007)".into());
    lines.push(format!("  grid             ({n} x {n})^2 directions: {n} x {n} incoming per outgoing cell"));
    lines.push(format!(
        "  log encoding     eps {}, channel means {} {} {} (1/sr)",
        w.epsilon, w.channel_mean[0], w.channel_mean[1], w.channel_mean[2]
    ));
    lines.push(format!(
        "  kept             {k} of {} coefficient positions (ratio {}:1), each {} outgoing cells x 3 channels",
        n * n,
        (n * n) as f64 / k.max(1) as f64,
        n * n
    ));
    let storage = match &w.coefficients {
        WaveletCoefficients::Float(_) => "32-bit floats",
        WaveletCoefficients::Quantized { .. } => "8-bit codes, one offset and step per slice and channel",
    };
    lines.push(format!("  coefficients     {storage}"));
    json!({
        "side": w.side,
        "epsilon": w.epsilon,
        "channel_mean": w.channel_mean,
        "positions": w.map.len(),
        "kept_positions": k,
        "quantized": matches!(w.coefficients, WaveletCoefficients::Quantized { .. }),
    })
}

fn layer_selection(selection: &LayerSelection, lines: &mut Vec<String>) {
    lines.push("payload: layer selection".into());
    let a = &selection.analysis;
    lines
        .push(format!("  analysis         {} at {} px, eps {}, c {}", a.parameterization, a.analysis_size, a.eps, a.c));
    lines.push(format!("  reduction        {}", selection.reduction));
    lines.push(format!(
        "  layer            exponent  bandwidth (cycles per radian)  views (rows of {})",
        selection.rows
    ));
    for (k, (n, b)) in selection.exponents.iter().zip(&selection.layer_bandwidth).enumerate() {
        let views = selection.view_layer.iter().filter(|&&l| l as usize == k).count();
        lines.push(format!("  {k:>5}            {n:>8}  {b:>29.4}  {views:>5}"));
    }
}

/// The grid and analysis of a bandwidth payload (kinds 4, 5 and 7).
fn tiles(lobes_x: u32, lobes_y: u32, tile: u32, analysis: &BandwidthAnalysis, lines: &mut Vec<String>) -> Value {
    lines.push(format!("  lobes            {lobes_x} x {lobes_y}, tiles of {tile} x {tile} texels"));
    lines.push(format!(
        "  analysis         {} at {} px, eps {}, c {}",
        analysis.parameterization, analysis.analysis_size, analysis.eps, analysis.c
    ));
    json!({
        "lobes_x": lobes_x,
        "lobes_y": lobes_y,
        "tile": tile,
        "analysis": serde_json::to_value(analysis).expect("analysis serializes to json"),
    })
}

fn material_info(info: &MaterialInfo, lines: &mut Vec<String>) {
    let [theta_h, theta_d, phi_d] = info.dims;
    let cells = u64::from(theta_h) * u64::from(theta_d) * u64::from(phi_d);
    let rgb = |v: [f64; 3]| format!("{:.6} {:.6} {:.6}", v[0], v[1], v[2]);
    lines.push("payload: material info".into());
    lines.push(format!("  dims             {theta_h} x {theta_d} x {phi_d} (theta_h x theta_d x phi_d)"));
    lines.push(format!("  no-data cells    {} of {cells}", info.no_data_cells));
    lines.push(format!("  min (1/sr)       {}", rgb(info.channel_min)));
    lines.push(format!("  max (1/sr)       {}", rgb(info.channel_max)));
    lines.push(format!("  mean (1/sr)      {}", rgb(info.channel_mean)));
    let [h, d, p] = info.peak_cell;
    lines.push(format!("  peak (1/sr)      {} at cell ({h}, {d}, {p})", rgb(info.peak_rgb)));
    lines.push("  directional albedo".into());
    lines.push("    theta_o_deg        red      green       blue   no data".into());
    let rows = info.albedo_theta_o.iter().zip(&info.albedo_rgb).zip(&info.albedo_no_data_fraction);
    for ((theta_o, albedo), no_data) in rows {
        lines.push(format!(
            "    {:>11.2} {:>10.6} {:>10.6} {:>10.6} {:>8.2}%",
            theta_o.to_degrees(),
            albedo[0],
            albedo[1],
            albedo[2],
            100.0 * no_data
        ));
    }
}

fn importance_samples(s: &ImportanceSamples, lines: &mut Vec<String>) -> Value {
    let degrees = |v: Option<&f64>| v.map_or(0.0, |t| t.to_degrees());
    let rows = s.theta_h_edges.len().saturating_sub(1);
    let zero_pdf_samples = s.samples.iter().filter(|t| t[3] == 0.0).count();
    lines.push("payload: importance samples".into());
    lines.push(format!(
        "  slices           {} (theta_o {:.1} to {:.1} deg)",
        s.theta_o.len(),
        degrees(s.theta_o.first()),
        degrees(s.theta_o.last())
    ));
    lines.push(format!("  samples          {} vectors x {} samples per slice", s.n_vectors, s.n_samples));
    lines.push(format!("  cells            {rows} theta_h rows x {} phi_h sectors", s.n_phi_h));
    lines.push(format!("  samples with pdf 0  {zero_pdf_samples}"));
    json!({
        "theta_o": s.theta_o,
        "n_vectors": s.n_vectors,
        "n_samples": s.n_samples,
        "theta_h_rows": rows,
        "n_phi_h": s.n_phi_h,
        "zero_pdf_samples": zero_pdf_samples,
    })
}

fn prefiltered_envmap(p: &PrefilteredEnvmap, lines: &mut Vec<String>) -> Value {
    let rgb = |v: [f64; 3]| format!("{:.6} {:.6} {:.6}", v[0], v[1], v[2]);
    let [sw, sh] = p.source_size;
    let [lw, lh] = p.layer_size;
    lines.push("payload: prefiltered envmap".into());
    lines.push(format!("  source           {sw} x {sh}, mean radiance {}", rgb(p.source_mean_radiance)));
    lines.push(format!("  layers           {} of {lw} x {lh}", p.exponents.len()));
    lines.push("    exponent  bandwidth (cycles/rad)  up to (cycles/rad)   mean radiance".into());
    for (k, (n, nu)) in p.exponents.iter().zip(&p.lobe_bandwidth).enumerate() {
        let up_to = p.bandwidth_thresholds.get(k).map_or_else(|| "-".to_string(), |t| format!("{t:.4}"));
        lines.push(format!("    {n:>8} {nu:>22.4} {up_to:>19}   {}", rgb(p.layer_mean_radiance[k])));
    }
    let file = |f: &LinkedFile| format!("{} (sha256 {})", f.name, hex(&f.sha256));
    lines.push(format!("  layers ktx2      {}, radiance scale {}", file(&p.layers_ktx2), p.layers_radiance_scale));
    for (n, exr) in p.exponents.iter().zip(&p.layer_exrs) {
        lines.push(format!("  layer exr        n = {n}: {}", file(exr)));
    }
    lines.push(format!(
        "  mips ktx2        {}, {} levels, radiance scale {}",
        file(&p.mips_ktx2),
        p.mip_levels,
        p.mips_radiance_scale
    ));
    lines.push(format!("  contact sheet    {}", file(&p.contact_sheet_png)));
    // Its own fields, hashes as hexadecimal.
    let file = |f: &LinkedFile| json!({ "name": f.name, "sha256": hex(&f.sha256) });
    json!({
        "source_size": p.source_size,
        "source_mean_radiance": p.source_mean_radiance,
        "layer_size": p.layer_size,
        "mip_levels": p.mip_levels,
        "layers_radiance_scale": p.layers_radiance_scale,
        "mips_radiance_scale": p.mips_radiance_scale,
        "exponents": p.exponents,
        "lobe_bandwidth": p.lobe_bandwidth,
        "bandwidth_thresholds": p.bandwidth_thresholds,
        "layer_mean_radiance": p.layer_mean_radiance,
        "layers_ktx2": file(&p.layers_ktx2),
        "layer_exrs": p.layer_exrs.iter().map(file).collect::<Vec<_>>(),
        "mips_ktx2": file(&p.mips_ktx2),
        "contact_sheet_png": file(&p.contact_sheet_png),
    })
}
