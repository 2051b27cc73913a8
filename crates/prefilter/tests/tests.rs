//! All integration tests of the `prefilter` crate, one module per topic, in one binary.

mod accuracy;
mod chain;
mod config;
mod cube;
mod dfg;
mod ggx;
mod ktx;
mod lobe;
mod sheet;

/// Finds `../shared`, or skips a test without it where the run allows.
#[path = "../../../tests/support/shared_data.rs"]
mod shared_data;

use envmap::EnvMap;

/// One of the real maps in `../shared/data/env` next to the workspace (never committed). `None`
/// when the calling test is to skip without them ([`shared_data::shared_or_skip`]).
pub fn real_map(name: &str) -> Option<EnvMap> {
    let path = shared_data::shared_or_skip(&["data/env"])?.join("data/env").join(name);
    Some(envmap::load(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display())))
}

/// A black map with one texel of radiance `rgb`: a point source of power `rgb * omega` at the
/// texel's centre.
pub fn point_source(width: usize, height: usize, x: usize, y: usize, rgb: [f32; 3]) -> EnvMap {
    let mut texels = vec![0.0f32; 3 * width * height];
    texels[3 * (y * width + x)..3 * (y * width + x) + 3].copy_from_slice(&rgb);
    EnvMap::new(width, height, texels).unwrap()
}
