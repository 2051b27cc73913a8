//! Benchmark and report: the paper's Table 1 (Claustres et al. 2007) for the 20 real-derived
//! materials of `make test-data` (`target/merl/*.binary`): RMS error and mean relative error of
//! the reconstruction against the resampled table at 4:1, 16:1 and 32:1, with 32-bit coefficients
//! and with 8-bit codes, on the default (32 x 32)^2 grid. Also the time of each step against
//! reading and validating the MERL file, measured in the same run. The numbers are reported, not
//! tuned to: real measured materials with moving highlights compress worse than the paper's
//! smooth gonioreflectometer data.

use std::path::Path;
use std::time::Instant;

use wavelet_brdf::{Config, Decoded, Grid, Keep, encode, errors, resample_table};

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/merl");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .map(|entries| entries.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    paths.retain(|p| p.extension().is_some_and(|e| e == "binary"));
    paths.sort();
    if paths.is_empty() {
        println!("skipped: no tables in {} (make test-data makes them)", dir.display());
        return;
    }
    let grid = Grid::new(wavelet_brdf::DEFAULT_SIDE).expect("the default side");
    println!(
        "{} threads; (32 x 32)^2 samples; rms in 1/sr; rel: mean |f - f'| / f in % over f > 0; rel>=floor: the same \
         over f >= eps mu (1% of the channel mean)",
        rayon::current_num_threads()
    );
    let (mut read_s, mut resample_s, mut encode_s, mut decode_s) = (0.0, 0.0, 0.0, 0.0);
    let mut rows: [Vec<String>; 2] = [Vec::new(), Vec::new()];
    for path in &paths {
        let start = Instant::now();
        let table = merl::read_file(path).expect("a valid table");
        read_s += start.elapsed().as_secs_f64();
        let start = Instant::now();
        let resampled = resample_table(grid, &table);
        resample_s += start.elapsed().as_secs_f64();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        for (q, quantize) in [false, true].into_iter().enumerate() {
            let mut cells = vec![name.clone()];
            for ratio in [4, 16, 32] {
                let start = Instant::now();
                let encoded = encode(&resampled, Config { keep: Keep::Ratio(ratio), quantize, ..Config::default() })
                    .expect("a valid config");
                encode_s += start.elapsed().as_secs_f64();
                let start = Instant::now();
                let brdf = Decoded::from_payload(&encoded.payload).expect("a valid payload");
                let decoded = brdf.decode(0);
                decode_s += start.elapsed().as_secs_f64();
                let e = errors(&resampled.values, &decoded, brdf.floor());
                if ratio == 4 {
                    cells.push(format!("{:.4}", e.mean_value));
                }
                cells.push(format!("{:.4}", e.rms));
                cells.push(format!("{:.3e}", 100.0 * e.mean_relative_error));
                cells.push(format!("{:.2}", 100.0 * e.mean_relative_error_above_floor));
            }
            rows[q].push(format!("| {} |", cells.join(" | ")));
        }
    }
    for (q, title) in ["32-bit coefficients", "8-bit codes"].iter().enumerate() {
        println!();
        println!("{title}:");
        println!(
            "| material | mean value | 4:1 rms | 4:1 rel % | 4:1 rel>=floor % | 16:1 rms | 16:1 rel % | 16:1 rel>=floor % \
             | 32:1 rms | 32:1 rel % | 32:1 rel>=floor % |"
        );
        println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        rows[q].iter().for_each(|row| println!("{row}"));
    }
    let n = paths.len() as f64;
    println!();
    println!("{:<52} {:>10} {:>12}", "step (mean per material)", "seconds", "x baseline");
    println!("{:<52} {:>10.3} {:>12.2}", "baseline: read and validate the MERL file", read_s / n, 1.0);
    println!("{:<52} {:>10.3} {:>12.2}", "resample (32 x 32)^2 pairs, trilinear", resample_s / n, resample_s / read_s);
    println!(
        "{:<52} {:>10.3} {:>12.2}",
        "encode (log, Haar, select, pack), 6 settings",
        encode_s / n,
        encode_s / read_s
    );
    println!(
        "{:<52} {:>10.3} {:>12.2}",
        "decode every sample (inverse Haar), 6 settings",
        decode_s / n,
        decode_s / read_s
    );
}
