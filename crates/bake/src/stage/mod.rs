//! One module per stage. Each takes its inputs in memory (a stage that reads a file names it in
//! its errors), computes everything, and returns a [`crate::Staged`] without touching the disk.

pub mod bandwidth_atlas;
pub mod engine;
pub mod env_bandwidth;
pub mod fit;
pub mod importance;
pub mod layer_selection;
pub mod material_info;
pub mod pca;
pub mod prefilter;
pub mod wavelet_brdf;

/// Whether `name` is the name of a file some stage writes (`importance.asset`, `layer-n16.exr`,
/// ...; `data-schema/README.md` lists them by role): a rebake removes a file of the previous
/// manifest only under such a name, so that no manifest can make it remove anything else.
pub fn is_output_name(name: &str) -> bool {
    const NAMES: [&str; 35] = [
        importance::ASSET,
        importance::PICTURE,
        bandwidth_atlas::ASSET,
        bandwidth_atlas::EXR,
        bandwidth_atlas::PICTURE,
        pca::ASSET,
        pca::PICTURE,
        wavelet_brdf::ASSET,
        wavelet_brdf::PICTURE,
        env_bandwidth::EXR,
        env_bandwidth::PICTURE,
        prefilter::ASSET,
        prefilter::LAYERS_KTX2,
        prefilter::MIPS_KTX2,
        prefilter::CONTACT_SHEET,
        prefilter::LAYERS_CUBE_KTX2,
        prefilter::MIPS_CUBE_KTX2,
        prefilter::engine::PHONG_CHAIN_KTX2,
        prefilter::engine::PHONG_CHAIN_CUBE_KTX2,
        prefilter::engine::GGX_KTX2,
        prefilter::engine::GGX_CUBE_KTX2,
        prefilter::engine::DFG_KTX2,
        prefilter::engine::DFG_PNG,
        layer_selection::ASSET,
        engine::MERL_KTX2,
        engine::BRDF_TABLES_KTX2,
        engine::VIEW_LAYERS_KTX2,
        engine::ENVIRONMENT_KTX2,
        engine::LIGHT_TABLES_KTX2,
        engine::LAYERS_KTX2,
        engine::FULL_LAYERS_KTX2,
        fit::RECORD,
        fit::GLTF,
        fit::BIN,
        fit::TABLE,
    ];
    let layer_exr = name
        .strip_prefix("layer-n")
        .and_then(|rest| rest.strip_suffix(".exr"))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
    layer_exr || NAMES.contains(&name)
}
