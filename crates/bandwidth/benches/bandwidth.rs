//! Timings against baselines measured in the same run: a table, not a test. `cargo bench -p
//! bandwidth` (release).
//!
//! - The 2D D4 forward transform of a 1024 x 1024 array against PyWavelets'
//!   `pywt.wavedec2(x, 'db2', mode='periodization', level=8)` (8 levels is PyWavelets' default
//!   for 1024 samples of db2) on the same array: written here as raw little-endian f64, read by
//!   `numpy.fromfile`, timed by `timeit` inside Python so that the interpreter's start is not
//!   counted. PyWavelets runs on one thread; the transform is timed on rayon's pool and on one
//!   thread. Goal: on one thread, at least 10x faster than PyWavelets (the ratio of the
//!   medians; the ratio of the minima, less sensitive to other work on the machine, beside it).
//! - The core of `envmap-bandwidth` on a real 1024 x 512 map (`log1p_luminance` and
//!   `latlong_bandwidth`), without and with `envmap::load` (the file is in the page cache after
//!   the first run), against one D4 `wavedec2` of a 1024 x 512 image with as many levels as it
//!   allows (9). Goal: at most 100 ms.
//!
//! Times are medians (and minima) of repeated runs after one warm-up run.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use bandwidth::{Config, Image, Wavelet, latlong_bandwidth, log1p_luminance};
use rand::{Rng, SeedableRng, rngs::StdRng};

const RUNS: usize = 21;
/// PyWavelets' default number of levels for 1024 samples of db2 (`pywt.dwt_max_level`).
const PYWT_LEVELS: usize = 8;
const MAP: &str = "quarry_01_1k.hdr";

/// Median and minimum of `RUNS` runs of `f`, after one warm-up run.
fn time<T>(mut f: impl FnMut() -> T) -> (Duration, Duration) {
    std::hint::black_box(f());
    let mut times: Vec<Duration> = (0..RUNS)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            start.elapsed()
        })
        .collect();
    times.sort();
    (times[RUNS / 2], times[0])
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// What PyWavelets reported: median and minimum seconds, and the energy of every coefficient
/// (to check that both sides transformed the same array the same way).
struct Pywt {
    median: Duration,
    min: Duration,
    energy: f64,
}

/// Times `pywt.wavedec2` on `image` in a Python subprocess; `Err(reason)` when Python, numpy or
/// PyWavelets is missing or the script failed.
fn time_pywt(image: &Image) -> Result<Pywt, String> {
    let raw = std::env::temp_dir().join(format!("bandwidth-bench-{}.f64", std::process::id()));
    let bytes: Vec<u8> = image.data().iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(&raw, bytes).map_err(|e| format!("writing {}: {e}", raw.display()))?;
    let script = format!(
        "import sys, timeit, statistics\n\
         try:\n    import numpy as np, pywt\n\
         except ImportError as e:\n    print('missing', e.name); sys.exit(3)\n\
         x = np.fromfile(sys.argv[1], dtype='<f8').reshape({h}, {w})\n\
         f = lambda: pywt.wavedec2(x, 'db2', mode='periodization', level={PYWT_LEVELS})\n\
         f()\n\
         t = timeit.repeat(f, number=1, repeat={RUNS})\n\
         c = f()\n\
         energy = float((c[0] ** 2).sum()) + sum(float((d ** 2).sum()) for level in c[1:] for d in level)\n\
         print(statistics.median(t), min(t), repr(energy))\n",
        h = image.height(),
        w = image.width()
    );
    let output = Command::new("python3").arg("-c").arg(&script).arg(&raw).output();
    let _ = std::fs::remove_file(&raw);
    let output = output.map_err(|e| format!("python3 could not be run ({e})"))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if output.status.code() == Some(3) {
        return Err(format!("python3 has no {}", stdout.trim().trim_start_matches("missing ")));
    }
    if !output.status.success() {
        return Err(format!("the pywt script failed: {}", String::from_utf8_lossy(&output.stderr).trim()));
    }
    let fields: Vec<f64> = stdout.split_whitespace().filter_map(|s| s.parse().ok()).collect();
    match fields[..] {
        [median, min, energy] => {
            Ok(Pywt { median: Duration::from_secs_f64(median), min: Duration::from_secs_f64(min), energy })
        }
        _ => Err(format!("unexpected output from the pywt script: {stdout:?}")),
    }
}

fn shared_env() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/env");
    assert!(dir.join("README.md").is_file(), "the shared data is missing: expected it in {}", dir.display());
    dir
}

fn row(case: &str, median: Duration, min: Duration, baseline: &str, ratio: &str, goal: &str) {
    let line = format!("{case:<56} {:>9.2} ms {:>9.2} ms   {baseline:<32} {ratio:<22} {goal}", ms(median), ms(min));
    println!("{}", line.trim_end());
}

fn main() {
    let threads = rayon::current_num_threads();
    println!("bandwidth benchmarks: median and min of {RUNS} runs, release, rayon on {threads} thread(s)\n");
    println!("{:<56} {:>12} {:>12}   {:<32} {:<22} goal", "case", "median", "min", "baseline (median)", "ratio");

    // The 2D D4 transform against PyWavelets.
    let mut rng = StdRng::seed_from_u64(1);
    let n = 1024;
    let array = Image::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    let (median, min) = time(|| dwt::wavedec2(&array, Wavelet::D4, PYWT_LEVELS).unwrap());
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a one-thread pool");
    let (median1, min1) = one_thread.install(|| time(|| dwt::wavedec2(&array, Wavelet::D4, PYWT_LEVELS).unwrap()));
    let case = format!("wavedec2 db2 {n}x{n}, {PYWT_LEVELS} levels");
    match time_pywt(&array) {
        Ok(pywt) => {
            let baseline = format!("pywt {:.2} ms (min {:.2})", ms(pywt.median), ms(pywt.min));
            let faster = |d: Duration, m: Duration| {
                format!(
                    "{:.1}x ({:.1}x min)",
                    pywt.median.as_secs_f64() / d.as_secs_f64(),
                    pywt.min.as_secs_f64() / m.as_secs_f64()
                )
            };
            row(&format!("{case}, {threads} thread(s)"), median, min, &baseline, &faster(median, min), "");
            row(&format!("{case}, 1 thread"), median1, min1, &baseline, &faster(median1, min1), ">= 10x faster");
            let energy = dwt::wavedec2(&array, Wavelet::D4, PYWT_LEVELS).unwrap().energy();
            let agree = ((energy - pywt.energy) / pywt.energy).abs() <= 1e-9;
            println!(
                "  pywt check: the energy of all coefficients {} ({energy:.9e} here, {:.9e} pywt)",
                if agree { "agrees to 1e-9" } else { "DIFFERS: not the same transform" },
                pywt.energy
            );
        }
        Err(reason) => {
            let skipped = format!("skipped: {reason} (pip install numpy PyWavelets)");
            row(&format!("{case}, {threads} thread(s)"), median, min, &skipped, "", "");
            row(&format!("{case}, 1 thread"), median1, min1, &skipped, "", "");
        }
    }

    // The core of envmap-bandwidth on a real map, against one transform of the same size.
    let path = shared_env().join(MAP);
    let map = envmap::load(&path).unwrap_or_else(|e| panic!("error: reading {}: {e}", path.display()));
    let (w, h) = (map.width(), map.height());
    let same_size = Image::from_fn(w, h, |_, _| rng.random_range(-1.0..1.0));
    let levels = dwt::max_levels2(w, h);
    let (transform, _) = time(|| dwt::wavedec2(&same_size, Wavelet::D4, levels).unwrap());
    let baseline = format!("wavedec2 {w}x{h} {levels} lv {:.2} ms", ms(transform));
    let config = Config::default();
    let core = |map: &envmap::EnvMap| {
        let image = log1p_luminance(map.width(), map.height(), map.texels()).unwrap();
        latlong_bandwidth(&image, &config).unwrap()
    };
    let ratio = |d: Duration| format!("{:.1}x the transform", d.as_secs_f64() / transform.as_secs_f64());
    let (median, min) = time(|| core(&map));
    row(&format!("envmap-bandwidth core, {MAP}, load excluded"), median, min, &baseline, &ratio(median), "<= 100 ms");
    let (median, min) = time(|| core(&envmap::load(&path).unwrap()));
    row(&format!("envmap-bandwidth core, {MAP}, load included"), median, min, &baseline, &ratio(median), "<= 100 ms");
}
