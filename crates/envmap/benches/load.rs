//! Load times of the real maps in ../shared/data/env, and of building their mip chains: a table,
//! not a test. `cargo bench -p envmap --bench load` (release), or `cargo test -p envmap --bench
//! load` for the test profile.

use std::time::{Duration, Instant};

const MAPS: &[&str] = &[
    "quarry_01_1k.hdr",
    "potsdamer_platz_1k.hdr",
    "studio_small_03_1k.hdr",
    "piz_compressed.exr",
    "KernerEnvLatLong.exr",
];
const RUNS: usize = 7;

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn main() {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/env"));
    assert!(dir.join("README.md").is_file(), "the shared data is missing: expected it in {}", dir.display());
    println!("{:<24} {:>10} {:>12} {:>12} {:>14}", "file", "size", "load min", "load median", "mip chain med");
    for file in MAPS {
        let path = dir.join(file);
        let mut loads = Vec::new();
        let mut chains = Vec::new();
        let mut size = (0, 0);
        for _ in 0..RUNS {
            let start = Instant::now();
            let map = envmap::load(&path).unwrap_or_else(|e| panic!("error: reading {}: {e}", path.display()));
            loads.push(start.elapsed());
            let start = Instant::now();
            let chain = envmap::MipChain::new(&map);
            chains.push(start.elapsed());
            assert!(chain.n_levels() > 1);
            size = (map.width(), map.height());
        }
        let min = *loads.iter().min().expect("runs");
        println!(
            "{:<24} {:>10} {:>9.1} ms {:>9.1} ms {:>11.1} ms",
            file,
            format!("{}x{}", size.0, size.1),
            min.as_secs_f64() * 1e3,
            median(loads).as_secs_f64() * 1e3,
            median(chains).as_secs_f64() * 1e3
        );
    }
}
