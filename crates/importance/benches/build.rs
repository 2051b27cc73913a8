//! Benchmark: building one material's importance tables with the default settings (90 slices,
//! 90 x 128 cells, 8 x 256 samples), against a baseline measured in the same run (a million
//! nearest lookups of the same table), so the ratio means something on a shared, noisy machine.
//! Goal: at most 0.5 s on 2 cores. Run with `make bench` or
//! `cargo bench -p importance --bench build`.

use std::path::Path;
use std::time::{Duration, Instant};

use importance::{Config, build};
use merl::{Interp, MerlTable, spherical_dir};

fn median(mut runs: Vec<Duration>) -> Duration {
    runs.sort();
    runs[runs.len() / 2]
}

fn time(runs: usize, mut f: impl FnMut()) -> Duration {
    median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed()
            })
            .collect(),
    )
}

fn main() {
    // The real-derived chrome if the tests made it, else a sharp synthetic lobe.
    let chrome = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/merl/chrome.binary");
    let (name, table): (&str, MerlTable) = match merl::read_file(&chrome) {
        Ok(t) => ("chrome (real-derived)", t),
        Err(_) => (
            "ggx alpha 0.05 (synthetic)",
            merl::analytic::Analytic::Ggx { alpha: 0.05, f0: [0.9; 3] }.table(merl::Dims::MERL),
        ),
    };
    let pairs: Vec<_> = (0..1_000_000u32)
        .map(|i| {
            let (a, b) = ((i as f64 * 0.618_034).fract(), (i as f64 * 0.754_877).fract());
            (spherical_dir(a * 1.5, b * std::f64::consts::TAU), spherical_dir(b * 1.5, a * std::f64::consts::TAU))
        })
        .collect();
    let baseline = time(5, || {
        let sum: f64 = pairs.iter().filter_map(|(wi, wo)| table.lookup(*wi, *wo, Interp::Nearest)).map(|f| f[0]).sum();
        std::hint::black_box(sum);
    });
    let config = Config::default();
    let tables = time(5, || {
        std::hint::black_box(build(&table, &config).unwrap());
    });
    let threads = rayon::current_num_threads();
    println!("material: {name}; {threads} threads");
    println!("{:<44} {:>10} {:>12}", "operation", "median", "x baseline");
    println!(
        "{:<44} {:>8.1}ms {:>12.2}",
        "baseline: 1e6 nearest lookups, one thread",
        baseline.as_secs_f64() * 1e3,
        1.0
    );
    println!(
        "{:<44} {:>8.1}ms {:>12.2}",
        "build tables (90 slices, 8 x 256 samples)",
        tables.as_secs_f64() * 1e3,
        tables.as_secs_f64() / baseline.as_secs_f64()
    );
    let verdict = if tables.as_secs_f64() <= 0.5 { "met" } else { "NOT met" };
    println!("goal: build <= 0.5 s on 2 cores: {verdict}");
}
