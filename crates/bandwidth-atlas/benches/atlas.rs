//! Benchmark: `brdf-bandwidth`'s work on a real-derived material (the default 64 x 64 lobes,
//! 1024 x 1024 analysis, 16 x 16 tiles), against a baseline measured in the same run (reading and
//! validating the same MERL file). Goal: at most 1.5 s on 2 cores. Needs
//! `target/merl/gold-paint.binary` (made by the tests, or
//! `python3 ../shared/tools/nbrdf2merl.py --out target/merl gold-paint`).

use std::path::Path;
use std::time::{Duration, Instant};

fn median(f: &mut dyn FnMut() -> Duration) -> Duration {
    let mut runs: Vec<Duration> = (0..5).map(|_| f()).collect();
    runs.sort();
    runs[2]
}

fn main() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/merl/gold-paint.binary");
    if !path.exists() {
        println!(
            "skipped: {} is missing (python3 ../shared/tools/nbrdf2merl.py --out target/merl gold-paint)",
            path.display()
        );
        return;
    }
    let read = median(&mut || {
        let start = Instant::now();
        std::hint::black_box(merl::read_file(&path).unwrap());
        start.elapsed()
    });
    let table = merl::read_file(&path).unwrap();
    let config = bandwidth_atlas::Config::default();
    let build = median(&mut || {
        let start = Instant::now();
        std::hint::black_box(bandwidth_atlas::build_atlas(&table, &config, &|_| {}).unwrap());
        start.elapsed()
    });
    println!("material: gold-paint (real-derived); {} threads", rayon::current_num_threads());
    println!("{:<48} {:>10} {:>12}", "operation", "median", "x baseline");
    println!("{:<48} {:>8.1}ms {:>12.2}", "baseline: read and validate the MERL file", read.as_secs_f64() * 1e3, 1.0);
    println!(
        "{:<48} {:>8.1}ms {:>12.2}",
        "bandwidth atlas (64 x 64 lobes, 1024 x 1024 analysis)",
        build.as_secs_f64() * 1e3,
        build.as_secs_f64() / read.as_secs_f64()
    );
    let total = read + build;
    println!(
        "goal: brdf-bandwidth <= 1.5 s (read + atlas {:.0} ms): {}",
        total.as_secs_f64() * 1e3,
        if total.as_secs_f64() <= 1.5 { "met" } else { "NOT met" }
    );
}
