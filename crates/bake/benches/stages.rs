//! Benchmark: the stages of `brdf-bake MATERIAL --env MAP` one by one, then the whole bake, on a
//! real-derived material and a real map (`cargo bench -p bake --bench stages`; a table, not a
//! test). Each row is the median of 5 runs of the library call `brdf-bake` makes: wall time, CPU
//! time of the process over the run (all threads; CPU / wall is the parallelism), and the peak
//! resident memory of the process during the run (the kernel's high-water mark, reset before
//! each run through `/proc/self/clear_refs`; what the earlier rows left allocated counts too).
//! Goal: the whole bake in at most 4 s on 2 cores.
//!
//! Needs `target/merl/gold-paint.binary` (made by `make test-data`, or
//! `python3 ../shared/tools/nbrdf2merl.py --out target/merl gold-paint`) and
//! `../shared/data/env/quarry_01_1k.hdr`. Linux only (CPU time and memory from `/proc`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use bake::stage::{self, env_bandwidth, importance, layer_selection, prefilter};
use bake::{BakeConfig, Program, Source};
use bandwidth_atlas::{Analyser, LuminanceTable};

const RUNS: usize = 5;
const MATERIAL: &str = "gold-paint";
const MAP: &str = "quarry_01_1k.hdr";
const PROGRAM: Program = Program { name: "brdf-bake", version: env!("CARGO_PKG_VERSION") };

/// The CPU time of this process (user and system, all threads) from `/proc/self/stat`.
fn cpu_time() -> Duration {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which may hold spaces) start at the closing parenthesis.
    let fields: Vec<&str> = stat.rsplit_once(')').map_or("", |(_, rest)| rest).split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<u64>().ok()).unwrap_or(0);
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the state field; the
    // kernel counts them in USER_HZ = 100 ticks per second on every Linux ABI.
    Duration::from_millis((ticks(11) + ticks(12)) * 10)
}

/// Resets the process's peak resident size to its current size (Linux 4.0 and later).
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// The process's peak resident size since the last [`reset_peak`], in bytes.
fn peak_memory() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

struct Row {
    wall: Duration,
    cpu: Duration,
    peak: u64,
}

/// Runs `f` [`RUNS`] times; the median of each measure.
fn measure<T>(mut f: impl FnMut() -> T) -> Row {
    let mut walls = Vec::new();
    let mut cpus = Vec::new();
    let mut peaks = Vec::new();
    for _ in 0..RUNS {
        reset_peak();
        let (cpu, start) = (cpu_time(), Instant::now());
        std::hint::black_box(f());
        walls.push(start.elapsed());
        cpus.push(cpu_time().saturating_sub(cpu));
        peaks.push(peak_memory());
    }
    walls.sort();
    cpus.sort();
    peaks.sort();
    Row { wall: walls[RUNS / 2], cpu: cpus[RUNS / 2], peak: peaks[RUNS / 2] }
}

fn print(stage: &str, row: &Row) {
    println!(
        "{stage:<40} {:>9.3} s {:>9.3} s {:>6.2} {:>9.0} MB",
        row.wall.as_secs_f64(),
        row.cpu.as_secs_f64(),
        row.cpu.as_secs_f64() / row.wall.as_secs_f64().max(1e-9),
        row.peak as f64 / (1 << 20) as f64
    );
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let material = root.join("target/merl").join(format!("{MATERIAL}.binary"));
    let map_path: PathBuf = root.join("../shared/data/env").join(MAP);
    if !material.is_file() || !map_path.is_file() {
        println!(
            "skipped: {} or {} is missing (make test-data; the shared data beside this checkout)",
            material.display(),
            map_path.display()
        );
        return;
    }
    let loadavg = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "bake stages: {MATERIAL} under {MAP}, default settings, median of {RUNS} runs, release, rayon on {} thread(s), \
         load average {}",
        rayon::current_num_threads(),
        loadavg.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
    println!("{:<40} {:>11} {:>11} {:>6} {:>12}", "stage", "wall", "cpu", "cpu/wall", "peak memory");

    let config = BakeConfig::new(material.clone(), Some(map_path.clone()), PathBuf::new());
    let bytes = std::fs::read(&material).expect("the material");
    let source = Source::of_bytes(&material, &bytes);
    let map_source = Source::hash(&map_path).expect("the map");
    print("read the MERL table", &measure(|| merl::MerlTable::parse(&bytes).expect("a MERL table")));
    let table = merl::MerlTable::parse(&bytes).expect("a MERL table");
    print(
        "importance samples",
        &measure(|| importance::run(&table, &source, &PROGRAM, &config.importance, true).expect("importance")),
    );
    print(
        "bandwidth atlas",
        &measure(|| {
            let analyser = Analyser::new(&config.atlas);
            stage::bandwidth_atlas::run(&LuminanceTable::new(&table), &analyser, &source, &PROGRAM, &|_| {})
                .expect("the atlas")
        }),
    );
    let (_, build) = stage::bandwidth_atlas::run(
        &LuminanceTable::new(&table),
        &Analyser::new(&config.atlas),
        &source,
        &PROGRAM,
        &|_| {},
    )
    .expect("the atlas");
    print("read the map", &measure(|| envmap::load(&map_path).expect("the map")));
    let map = envmap::load(&map_path).expect("the map");
    print(
        "environment bandwidth",
        &measure(|| env_bandwidth::run_on_map(&map_path, &map, &config.env_bandwidth).expect("env bandwidth")),
    );
    print(
        "phong layers and mip chain",
        &measure(|| prefilter::run(&map, &map_source, &PROGRAM, &config.prefilter, &|_, _| {}).expect("prefilter")),
    );
    let exponents = &config.prefilter.exponents;
    print(
        "layer selection",
        &measure(|| {
            let selection =
                layer_selection::select(&build, &config.atlas, exponents, config.layer_reduction).expect("layers");
            layer_selection::run(&selection, &config.atlas, &build, &source, &PROGRAM).expect("layers")
        }),
    );
    drop((table, build, map));

    let out = tempfile::tempdir().expect("a temporary folder");
    let mut whole = BakeConfig::new(material, Some(map_path), out.path().join("bake"));
    whole.force = true;
    let row = measure(|| bake::run_bake(&whole, &PROGRAM, &|_| {}).expect("the bake"));
    print("whole bake (run_bake, files written)", &row);
    println!(
        "goal: the whole bake <= 4 s on 2 cores ({:.2} s): {}",
        row.wall.as_secs_f64(),
        if row.wall.as_secs_f64() <= 4.0 { "met" } else { "NOT met" }
    );
}
