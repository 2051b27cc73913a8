//! The prefilter against the brute-force reference on real 1024 x 512 maps, the 7 exponents to
//! `n = 4096` on 256 x 128 layers (the defaults add `n = 16384` on 512 x 256; `measured`): a
//! table, not a test. `cargo bench -p prefilter --bench prefilter` (release).
//!
//! Our time is the median of 5 runs of `prefilter::prefilter` (all threads rayon has). The
//! reference (the sum over every source texel for every layer texel, all 7 exponents at once, all
//! threads) is timed on the 512 layer texels of every 8th row and column and scaled by
//! `32768 / 512`: its cost per texel does not depend on the texel, except that texels facing a
//! pole skip the same half of the map as any other. Accuracy is measured on the same 512 texels.

use std::time::{Duration, Instant};

use envmap::EnvMap;
use prefilter::{Config, Method, Reference, prefilter};
use rayon::prelude::*;

const MAPS: &[&str] = &["quarry_01_1k.hdr", "potsdamer_platz_1k.hdr"];
const RUNS: usize = 5;
const STEP: usize = 8;

/// The configuration the report in docs/benchmarks.md measures: the defaults' first 7 exponents
/// on 256 x 128 layers.
fn measured() -> Config {
    Config { exponents: vec![1, 4, 16, 64, 256, 1024, 4096], width: 256, height: 128, ..Config::default() }
}

fn median(mut times: Vec<Duration>) -> Duration {
    times.sort();
    times[times.len() / 2]
}

fn main() {
    let dir = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/env"));
    assert!(dir.join("README.md").is_file(), "the shared data is missing: expected it in {}", dir.display());
    let config = measured();
    let (w, h) = (config.width, config.height);
    println!(
        "{} threads; {} exponents {:?}; layers {w} x {h}; reference on {} of {} texels, scaled",
        rayon::current_num_threads(),
        config.exponents.len(),
        config.exponents,
        (w / STEP) * (h / STEP),
        w * h
    );
    println!(
        "{:<24} {:>10} {:>12} {:>14} {:>9} {:>13} {:>13}",
        "map", "size", "ours (med)", "reference", "speed-up", "worst RMSE", "worst p99"
    );
    for name in MAPS {
        let path = dir.join(name);
        let map = envmap::load(&path).unwrap_or_else(|e| panic!("error: reading {}: {e}", path.display()));
        let mut times = Vec::new();
        let mut result = None;
        for _ in 0..RUNS {
            let start = Instant::now();
            result = Some(prefilter(&map, &config).expect("default config"));
            times.push(start.elapsed());
        }
        let ours = median(times);
        let layers = result.expect("ran");
        assert!(layers.layers.iter().all(|l| l.method == Method::SphericalHarmonics));

        let texels: Vec<(usize, usize)> = (0..h)
            .step_by(STEP)
            .flat_map(|y| (0..w).step_by(STEP).map(move |x| (x + STEP / 2, y + STEP / 2)))
            .collect();
        let reference = Reference::new(&map);
        let start = Instant::now();
        let values: Vec<Vec<[f64; 3]>> =
            texels.par_iter().map(|&(x, y)| reference.at_texel(x, y, w, h, &config.exponents)).collect();
        let scaled = start.elapsed().as_secs_f64() * (w * h) as f64 / texels.len() as f64;
        let (rmse, p99) = accuracy(&layers.layers.iter().map(|l| &l.map).collect::<Vec<_>>(), &texels, &values);
        println!(
            "{:<24} {:>10} {:>9.1} ms {:>12.1} s {:>8.0}x {:>13.2e} {:>13.2e}",
            name,
            format!("{}x{}", map.width(), map.height()),
            ours.as_secs_f64() * 1e3,
            scaled,
            scaled / ours.as_secs_f64(),
            rmse,
            p99
        );
    }
    engine_outputs(dir);
}

/// The engine outputs against the Phong array, measured in the same run on the same map: the
/// GGX chain (default 7 levels from 256 x 128) with its accuracy against the brute force
/// on every 8th texel of every level, the cube maps, the DFG table.
fn engine_outputs(dir: &std::path::Path) {
    let config = measured();
    println!();
    println!("{:<24} {:<40} {:>10} {:>10} {:>16}", "map", "output", "time (med)", "x array", "worst rel. RMSE");
    for name in MAPS {
        let map = envmap::load(&dir.join(name)).expect("a shared map");
        let time = |f: &mut dyn FnMut()| {
            median(
                (0..RUNS)
                    .map(|_| {
                        let start = Instant::now();
                        f();
                        start.elapsed()
                    })
                    .collect(),
            )
        };
        let mut layers = None;
        let array = time(&mut || layers = Some(prefilter(&map, &config).expect("default config")));
        let layers = layers.expect("ran");
        let mut chain = None;
        let ggx = time(&mut || {
            chain = Some(prefilter::ggx::chain(&map, config.width, 7, Method::Auto, &|_| {}).expect("7 levels"))
        });
        let chain = chain.expect("ran");
        let reference = Reference::new(&map);
        let mut worst = 0.0f64;
        for (level, &rho) in chain.levels.iter().zip(&chain.roughness).skip(1) {
            let lobe = prefilter::Lobe::Ggx(prefilter::ggx::GgxLobe::new(prefilter::ggx::alpha(rho)));
            let (w, h) = (level.width(), level.height());
            let step = if w >= 64 { STEP } else { 1 };
            let texels: Vec<(usize, usize)> =
                (0..h).step_by(step).flat_map(|y| (0..w).step_by(step).map(move |x| (x, y))).collect();
            let (num, den) = texels
                .par_iter()
                .map(|&(x, y)| {
                    let (u, v) = envmap::geometry::texel_center_uv(x, y, w, h);
                    let r = reference.at_lobe(envmap::direction(u, v), &lobe);
                    let ours = level.texel(x, y);
                    (0..3).fold((0.0, 0.0), |(n, d), c| (n + (f64::from(ours[c]) - r[c]).powi(2), d + r[c] * r[c]))
                })
                .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
            worst = worst.max((num / den).sqrt());
        }
        let phong_chain = time(&mut || {
            std::hint::black_box(prefilter::phong_chain(&map, &config, &|_| {}).expect("7 levels"));
        });
        let maps: Vec<&EnvMap> = layers.layers.iter().map(|l| &l.map).collect();
        let cube_layers = time(&mut || {
            prefilter::cube::encode_layers(&maps, prefilter::ktx::Storage::Auto, "bench").expect("cube");
        });
        let levels: Vec<&EnvMap> = chain.levels.iter().collect();
        let cube_ggx = time(&mut || {
            prefilter::cube::encode_levels(&levels, prefilter::ktx::Storage::Auto, "bench").expect("cube");
        });
        let dfg = time(&mut || {
            std::hint::black_box(prefilter::dfg::table(prefilter::dfg::DFG_SIZE));
        });
        let row = |what: &str, t: Duration, accuracy: String| {
            println!(
                "{:<24} {:<40} {:>7.1} ms {:>10.2} {:>16}",
                name,
                what,
                t.as_secs_f64() * 1e3,
                t.as_secs_f64() / array.as_secs_f64(),
                accuracy
            );
        };
        row("baseline: phong array, 7 x 256 x 128", array, "(table above)".into());
        row("phong chain, 4096..1 from 256 x 128", phong_chain, "as the array".into());
        row("ggx chain, 7 levels from 256 x 128", ggx, format!("{worst:.2e}"));
        row("phong array as cube maps (+ encoding)", cube_layers, "resampled".into());
        row("ggx chain as a cube map (+ encoding)", cube_ggx, "resampled".into());
        row("dfg table 128 x 128, 2048 samples", dfg, "< 1e-3 (tests)".into());
    }
}

/// The worst layer's relative RMSE and 99th-percentile relative error (floor 1e-3 of the mean),
/// as in `tests/accuracy.rs`.
fn accuracy(layers: &[&EnvMap], texels: &[(usize, usize)], reference: &[Vec<[f64; 3]>]) -> (f64, f64) {
    let mut worst = (0.0f64, 0.0f64);
    for (k, layer) in layers.iter().enumerate() {
        let mean = reference.iter().map(|r| r[k].iter().sum::<f64>()).sum::<f64>() / (3 * texels.len()) as f64;
        let mut squared = 0.0;
        let mut relative = Vec::new();
        for (&(x, y), r) in texels.iter().zip(reference) {
            let ours = layer.texel(x, y);
            for c in 0..3 {
                let d = f64::from(ours[c]) - r[k][c];
                squared += d * d;
                relative.push(d.abs() / r[k][c].max(1e-3 * mean));
            }
        }
        relative.sort_by(f64::total_cmp);
        let rmse = (squared / relative.len() as f64).sqrt() / mean;
        let p99 = relative[(0.99 * (relative.len() - 1) as f64).round() as usize];
        worst = (worst.0.max(rmse), worst.1.max(p99));
    }
    worst
}
