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

use std::path::{Path, PathBuf};

use envmap::EnvMap;

/// `../shared/data/env` next to the workspace: real maps that are never committed. Absent data is
/// a failure, not a skip: CI always has it.
pub fn shared_env() -> PathBuf {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/env"));
    assert!(
        dir.join("README.md").is_file(),
        "the shared data is missing: expected the real environment maps in {} (../shared/data/env next to \
         the workspace root); CI always has it",
        dir.display()
    );
    dir.to_path_buf()
}

/// One of the real maps in `../shared/data/env`.
pub fn real_map(name: &str) -> EnvMap {
    let path = shared_env().join(name);
    envmap::load(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

/// A black map with one texel of radiance `rgb`: a point source of power `rgb * omega` at the
/// texel's centre.
pub fn point_source(width: usize, height: usize, x: usize, y: usize, rgb: [f32; 3]) -> EnvMap {
    let mut texels = vec![0.0f32; 3 * width * height];
    texels[3 * (y * width + x)..3 * (y * width + x) + 3].copy_from_slice(&rgb);
    EnvMap::new(width, height, texels).unwrap()
}
