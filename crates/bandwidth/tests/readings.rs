//! The two readings of eq. 7 (crate docs, "Readings"): the level-normalized one never reads a
//! coarser level than the paper's, and it reads faint noise beside a strong step at the limit,
//! where the paper's reading masks it.

use bandwidth::{Config, Image, Reading, local_bandwidth};
use rand::{Rng, SeedableRng, rngs::StdRng};

/// 256 x 256: a unit step across the middle row, white noise of amplitude `noise` everywhere.
fn step_with_noise(noise: f64, seed: u64) -> Image {
    let n = 256;
    let mut rng = StdRng::seed_from_u64(seed);
    let data =
        (0..n * n).map(|i| if i / n < n / 2 { 0.0 } else { 1.0 } + noise * (rng.random::<f64>() - 0.5)).collect();
    Image::new(n, n, data).unwrap()
}

fn median_level(image: &Image, reading: Reading, rows: std::ops::Range<usize>) -> u8 {
    let map = local_bandwidth(image, &Config { reading, ..Config::default() }).unwrap();
    let mut levels: Vec<u8> = rows
        .flat_map(|y| (0..map.width()).map(move |x| (x, y)))
        .map(|(x, y)| map.level()[y * map.width() + x])
        .collect();
    levels.sort_unstable();
    levels[levels.len() / 2]
}

#[test]
fn level_normalized_reads_noise_beside_a_step_that_the_paper_masks() {
    // Rows 0..32, 96 to 128 rows from the step.
    let image = step_with_noise(0.05, 1);
    let paper = median_level(&image, Reading::Paper, 0..32);
    let normalized = median_level(&image, Reading::LevelNormalized, 0..32);
    println!("median level of the noise: paper {paper}, level-normalized {normalized}");
    assert!(paper >= 4, "the paper's reading masks faint noise beside a strong step (level {paper})");
    assert_eq!(normalized, 1, "level-normalized reads white noise at the finest level");
}

#[test]
fn level_normalized_is_never_coarser_than_the_paper() {
    // Every pixel of several images: the scaling by 2^-j can only move eq. 7's level finer.
    for (k, noise) in [0.0, 0.01, 0.3].into_iter().enumerate() {
        let mut image = step_with_noise(noise, k as u64);
        // A sinusoid of period 12 in the lower half, so that several levels are involved.
        for (i, v) in image.data_mut().iter_mut().enumerate() {
            if i / 256 >= 160 {
                *v += 0.5 * (std::f64::consts::TAU * (i % 256) as f64 / 12.0).sin();
            }
        }
        let paper = local_bandwidth(&image, &Config::default()).unwrap();
        let normalized =
            local_bandwidth(&image, &Config { reading: Reading::LevelNormalized, ..Config::default() }).unwrap();
        for (i, (p, q)) in paper.level().iter().zip(normalized.level()).enumerate() {
            // At every level the normalized ratio of eq. 7 is at least the paper's (the sums gain
            // at least 2^-j, the maximum at most 2^-m with m above the level), so its first
            // significant level is no coarser; level 0 (flat: nothing above the noise floor) is
            // flat under both.
            assert!((*p == 0) == (*q == 0) && q <= p, "image {k}, pixel {i}: paper {p}, normalized {q}");
        }
    }
}
