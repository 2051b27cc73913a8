//! What the host shares with the WGSL: the uniforms' layouts and the constants both sides name,
//! with the tests that hold them to the shader's.

use bytemuck::{Pod, Zeroable};
use render::Estimator;

/// The wavelet BRDF decoder's uniform, as `wavelet_brdf.wgsl` declares it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct WaveletUniform {
    pub(crate) side: u32,
    pub(crate) levels: u32,
    pub(crate) enabled: u32,
    pub(crate) lod: f32,
    pub(crate) mean: [f32; 3],
    pub(crate) epsilon: f32,
}

impl WaveletUniform {
    pub(crate) fn new(wavelet: Option<&render::WaveletBrdfLod>) -> WaveletUniform {
        match wavelet {
            Some(w) => {
                let grid = w.brdf.grid();
                WaveletUniform {
                    side: grid.side() as u32,
                    levels: grid.levels() as u32,
                    enabled: 1,
                    lod: w.lod as f32,
                    mean: w.brdf.channel_mean().map(|m| m as f32),
                    epsilon: w.brdf.epsilon() as f32,
                }
            }
            None => WaveletUniform { side: 2, levels: 1, enabled: 0, lod: 0.0, mean: [1.0; 3], epsilon: 0.01 },
        }
    }
}

/// The frame's uniform (`preview_bindings.wgsl`): the index of the frame a dispatch shades, one
/// slot per frame of a submission at the dynamic-offset alignment.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub(crate) struct FrameUniform {
    pub(crate) index: u32,
}

/// Must equal `SHADE_WORKGROUP` in the WGSL (checked by a test below).
pub(crate) const SHADE_WORKGROUP: u32 = 8;

/// Values per vertex in the mesh buffer: clip-space position, snapped viewport x and y,
/// position, normal (`preview_geometry.wgsl`).
pub(crate) const VERTEX_FLOATS: u64 = 12;

/// The shading uniform, as `preview_bindings.wgsl` declares it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct ShadeUniform {
    pub(crate) eye: [f32; 4],
    pub(crate) ray_forward: [f32; 4],
    pub(crate) ray_right: [f32; 4],
    pub(crate) ray_up: [f32; 4],
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) seed: u32,
    pub(crate) mode: u32,
    pub(crate) spp: u32,
    pub(crate) n_slices: u32,
    pub(crate) n_vectors: u32,
    pub(crate) n_samples: u32,
    pub(crate) n_levels: u32,
    pub(crate) n_view_rows: u32,
    pub(crate) n_layers: u32,
    pub(crate) layer_shift: u32,
    pub(crate) maps: MapLayout,
    pub(crate) tables: TableLayout,
    /// The length of the list a pass over items reads (`Renderer::run_items`, an adaptive
    /// frame's parts); 0 for the passes over pixels.
    pub(crate) items: u32,
    /// The samples the fis estimator's footprints are sized for: `spp` times the frames the
    /// picture averages (`render`'s crate docs, `Estimator::Fis`).
    pub(crate) filter_samples: u32,
    /// `render::diffuse_split` (w unused): the filtered estimators' diffuse part.
    pub(crate) diffuse: [f32; 4],
}

/// Where the lighting's maps start among the map records (`ShadeUniform::mips_first`,
/// `layers_first`, `peak_map` of the WGSL): map 0 is level 0 of the environment whole; the chain
/// and the layers the filtered estimators read are the smooth part's where the environment has
/// peaks (`render::Lighting::smooth_mips`), then come the peaks' level 0. The records themselves
/// follow the mesh's indices in one buffer, from word `records` on.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct MapLayout {
    pub(crate) mips_first: u32,
    pub(crate) layers_first: u32,
    pub(crate) peak_map: u32,
    pub(crate) records: u32,
}

/// `ShadeUniform::peak_map` where the environment has no peaks (`NO_MAP` of the WGSL).
pub(crate) const NO_MAP: u32 = u32::MAX;

/// Where the sampling tables and the view-layer table start in the `sampling_tables` buffer
/// (`ShadeUniform::brdf_rows` to `view_layers` of the WGSL; [`sampling_tables`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct TableLayout {
    pub(crate) brdf_rows: u32,
    pub(crate) brdf_sectors: u32,
    pub(crate) t_edges: u32,
    pub(crate) brdf_marginal: u32,
    pub(crate) brdf_conditional: u32,
    pub(crate) env_marginal: u32,
    pub(crate) env_conditional: u32,
    pub(crate) peak_marginal: u32,
    pub(crate) peak_conditional: u32,
    pub(crate) view_layers: u32,
}

/// The prediction's uniform, as `adaptive/predict.wgsl` declares it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub(crate) struct PredictUniform {
    pub(crate) n_b: u32,
    pub(crate) env_width: u32,
    pub(crate) env_height: u32,
    pub(crate) lobes_x: u32,
    pub(crate) lobes_y: u32,
    pub(crate) tile: u32,
    pub(crate) radians_per_pixel: f32,
    pub(crate) _pad: u32,
}

/// `MODE_*` of the WGSL.
pub(crate) fn mode_index(mode: Estimator) -> u32 {
    match mode {
        Estimator::Reference => 0,
        Estimator::Fis => 1,
        Estimator::Prefiltered => 2,
    }
}

/// `MODE_GBUFFER_*` of the WGSL: the shading pass writes the G-buffer instead of shading.
pub(crate) const MODE_GBUFFER_POSITION: u32 = 3;

pub(crate) const MODE_GBUFFER_NORMAL: u32 = 4;

/// `MODE_DEBUG_*` of the WGSL.
pub(crate) const MODE_DEBUG_NORMAL: u32 = 5;

pub(crate) const MODE_DEBUG_LAYER: u32 = 6;

pub(crate) const MODE_DEBUG_SLICE: u32 = 7;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wgsl::{ADAPTIVE_PREDICT, PREVIEW_BINDINGS, PREVIEW_ENVIRONMENT, PREVIEW_SAMPLING};

    #[test]
    fn workgroup_size_matches_the_shader() {
        let decl = format!("const SHADE_WORKGROUP: u32 = {SHADE_WORKGROUP}u;");
        assert!(PREVIEW_BINDINGS.source.contains(&decl), "the WGSL does not declare `{decl}`");
    }

    #[test]
    fn rasterization_constants_match_the_cpu_rasterizer() {
        let guard_band = format!("const GUARD_BAND: f32 = {:?};", render::raster::GUARD_BAND);
        let subpixels = format!("const SUBPIXELS: f32 = {:?};", (1u32 << render::raster::SUBPIXEL_BITS) as f32);
        for decl in [guard_band, subpixels] {
            assert!(PREVIEW_BINDINGS.source.contains(&decl), "the WGSL does not declare `{decl}`");
        }
    }

    #[test]
    fn sampling_constants_match_the_cpu() {
        let salt = format!("const SEQUENCE_SALT: u32 = {:#010x}u;", render::SEQUENCE_SALT);
        let prediction_salt = format!("const PREDICTION_SALT: u32 = {:#010x}u;", render::adaptive::PREDICTION_SALT);
        let no_map = format!("const NO_MAP: u32 = {NO_MAP:#010x}u;");
        let lod_bias = format!("const FIS_LOD_BIAS: f32 = {:?};", render::FIS_LOD_BIAS as f32);
        let footprint =
            format!("const PREFILTERED_FOOTPRINT_LAYERS: f32 = {:?};", render::PREFILTERED_FOOTPRINT_LAYERS as f32);
        for (wgsl, decl) in [
            (&PREVIEW_SAMPLING, salt),
            (&ADAPTIVE_PREDICT, prediction_salt),
            (&PREVIEW_BINDINGS, no_map),
            (&PREVIEW_ENVIRONMENT, lod_bias),
            (&PREVIEW_ENVIRONMENT, footprint),
        ] {
            assert!(wgsl.source.contains(&decl), "{} does not declare `{decl}`", wgsl.file);
        }
    }

    #[test]
    fn mode_indices_match_the_shader() {
        let modes = [
            ("REFERENCE", mode_index(Estimator::Reference)),
            ("FIS", mode_index(Estimator::Fis)),
            ("PREFILTERED", mode_index(Estimator::Prefiltered)),
            ("GBUFFER_POSITION", MODE_GBUFFER_POSITION),
            ("GBUFFER_NORMAL", MODE_GBUFFER_NORMAL),
            ("DEBUG_NORMAL", MODE_DEBUG_NORMAL),
            ("DEBUG_LAYER", MODE_DEBUG_LAYER),
            ("DEBUG_SLICE", MODE_DEBUG_SLICE),
        ];
        for (name, index) in modes {
            let decl = format!("const MODE_{name}: u32 = {index}u;");
            assert!(PREVIEW_BINDINGS.source.contains(&decl), "the WGSL does not declare `{decl}`");
        }
    }
}
