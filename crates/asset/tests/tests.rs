//! Tests of the asset container, compiled into one binary with a module per topic. The shared
//! helpers here build the assets the topics use and locate the committed fixtures.

mod damage;
mod files;
mod golden;
mod invalid_fixtures;
mod manifest;
mod roundtrip;
mod values;

use std::path::PathBuf;

use asset::{Asset, MaterialInfo, Provenance};

/// The repository's `fixtures/` folder.
fn fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

/// Whether this run rewrites committed fixtures instead of checking them (see
/// `fixtures/assets/README.md`).
fn regenerating() -> bool {
    std::env::var_os("REGENERATE_GOLDEN").is_some_and(|v| v == "1")
}

/// A small but complete asset: every field set, a few albedo angles.
fn small_asset() -> Asset {
    Asset {
        provenance: Provenance {
            source_name: "tiny.binary".into(),
            source_sha256: std::array::from_fn(|i| i as u8),
            tool: "merl-info".into(),
            tool_version: "0.1.0".into(),
            parameters: vec![("interp".into(), "nearest".into())],
        },
        payload: MaterialInfo {
            dims: [2, 3, 4],
            no_data_cells: 5,
            channel_min: [0.0, 0.1, 0.2],
            channel_max: [1.0, 1.5, 2.0],
            channel_mean: [0.25, 0.5, 0.75],
            peak_rgb: [1.0, 1.5, 2.0],
            peak_cell: [0, 1, 2],
            albedo_theta_o: vec![0.0, 1.0],
            albedo_rgb: vec![[0.5, 0.5, 0.5], [0.25, 0.25, 0.25]],
            albedo_no_data_fraction: vec![0.0, 0.125],
        }
        .into(),
    }
}

/// Recomputes the stored checksum after a test edited the sections on purpose.
fn reseal(bytes: &mut [u8]) {
    let checksum = asset::sha256(&bytes[asset::HEADER_BYTES..]);
    bytes[32..64].copy_from_slice(&checksum);
}
