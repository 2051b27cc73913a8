//! What the shading pass samples, laid out for its buffers: the lighting's maps (their records and
//! texels) and every sampling table (the material's and the environment's) with the view-layer
//! table, with where each starts.

use render::{Lighting, Material};

use super::*;

/// The maps' records `(width, height, offset, 0)` (the mip levels, then the prefiltered
/// layers), their texels concatenated, and where the maps start among the records, which go
/// into the index buffer from word `records` on (`Uploads`).
pub(super) fn env_buffers(lighting: &Lighting, records: u32) -> (Vec<[u32; 4]>, Vec<f32>, MapLayout) {
    let level0 = lighting.mips.level(0);
    let (smooth_mips, layers) = (lighting.smooth_mips().levels(), lighting.smooth_layers());
    // Without peaks the smooth chain is the chain, and map 0 its level 0.
    let (whole, peak) = match &lighting.peaks {
        Some(peaks) => (std::slice::from_ref(level0), Some(&peaks.map)),
        None => (&[][..], None),
    };
    let maps = MapLayout {
        mips_first: whole.len() as u32,
        layers_first: (whole.len() + smooth_mips.len()) as u32,
        peak_map: peak.map_or(NO_MAP, |_| (whole.len() + smooth_mips.len() + layers.len()) as u32),
        records,
    };
    let mut descriptors = Vec::new();
    let mut texels = Vec::new();
    for map in whole.iter().chain(smooth_mips).chain(layers).chain(peak) {
        descriptors.push([map.width() as u32, map.height() as u32, texels.len() as u32, 0]);
        texels.extend_from_slice(map.rgb());
    }
    (descriptors, texels, maps)
}

/// The CDF tables the shading pass samples, in one buffer: the material's half-vector rows and
/// every slice's tables, level 0's distribution and the peaks' (level 0's again where there are
/// none: a binding cannot be empty, and no mode reads them then), all `f32` as the CPU's
/// distributions hold them (`sampling::Distribution2D::from_cdfs`), so both pick the same bins;
/// then `view_layers`, the view-layer table (`Uploads`), where one binding serves both.
pub(super) fn sampling_tables(
    material: &Material,
    lighting: &Lighting,
    view_layers: &[f32],
) -> (Vec<f32>, TableLayout) {
    let mut data: Vec<f32> = Vec::new();
    let mut put = |values: &mut dyn Iterator<Item = f64>| -> u32 {
        let first = data.len() as u32;
        data.extend(values.map(|v| v as f32));
        first
    };
    let slices = &material.samples.tables;
    let rows = slices.first().map_or(1, |s| s.distribution().nv());
    let sectors = slices.first().map_or(1, |s| s.distribution().nu());
    let t_edges = put(&mut slices.first().map_or(&[0.0, 1.0][..], |s| s.rows().t_edges()).iter().copied());
    let brdf_marginal = put(&mut slices.iter().flat_map(|s| s.distribution().marginal().cdf().iter().copied()));
    let brdf_conditional = put(&mut slices.iter().flat_map(|s| s.distribution().conditional_cdf().iter().copied()));
    let environment = lighting.environment.distribution();
    let env_marginal = put(&mut environment.marginal().cdf().iter().copied());
    let env_conditional = put(&mut environment.conditional_cdf().iter().copied());
    let peaks = lighting.peaks.as_ref().map_or(environment, |p| p.sampling.distribution());
    let peak_marginal = put(&mut peaks.marginal().cdf().iter().copied());
    let peak_conditional = put(&mut peaks.conditional_cdf().iter().copied());
    let view_layers = put(&mut view_layers.iter().map(|&v| f64::from(v)));
    let layout = TableLayout {
        brdf_rows: rows as u32,
        brdf_sectors: sectors as u32,
        t_edges,
        brdf_marginal,
        brdf_conditional,
        env_marginal,
        env_conditional,
        peak_marginal,
        peak_conditional,
        view_layers,
    };
    (data, layout)
}
