//! Prints `view::KNOWN_LAYER_BANDWIDTHS`: the bandwidth the default analysis measures for each
//! default Phong layer under the bake's default reduction, as the bits of the f64, so that a bake
//! reads them instead of measuring eight lobes it measured before (they depend on neither the
//! material nor the map). `cargo run --release -p bandwidth-atlas --example layer-bandwidths`; a test
//! holds the table to the measurement.

use bandwidth_atlas::Config;
use bandwidth_atlas::view::{KNOWN_LAYER_REDUCTION, ViewReduction, layer_bandwidth};

fn main() {
    let config = Config::default();
    let reduction: ViewReduction = KNOWN_LAYER_REDUCTION;
    for n in [1u32, 4, 16, 64, 256, 1024, 4096, 16384] {
        let b = layer_bandwidth(&config, n, reduction);
        println!("    ({n}, {:#018x}), // {b}", b.to_bits());
    }
}
