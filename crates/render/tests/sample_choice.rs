//! The random word and the samples it picks, which the GPU renderer must reproduce bit for bit.

use rand::{Rng, SeedableRng, rngs::StdRng};
use render::{pcg_hash, sample_range};

#[test]
fn pcg_hash_known_values() {
    // From the paper's reference code (Jarzynski and Olano 2020, listing "pcg"), evaluated with
    // Python integers modulo 2^32:
    //   s = (v * 747796405 + 2891336453) % 2**32
    //   w = (((s >> ((s >> 28) + 4)) ^ s) * 277803737) % 2**32
    //   h = (w >> 22) ^ w
    for (v, h) in [
        (0, 129_708_002),
        (1, 2_831_084_092),
        (2, 2_055_130_248),
        (42, 1_223_963_391),
        (0xdead_beef, 1_730_779_506),
        (u32::MAX, 3_861_530_882),
    ] {
        assert_eq!(pcg_hash(v), h, "pcg_hash({v})");
    }
}

#[test]
fn sample_range_follows_its_formula() {
    // The crate documentation's formula, written out again.
    let (pixel, frame, seed) = (1234, 5, 77);
    let h = pcg_hash(pixel ^ pcg_hash(seed));
    // 8 vectors of 256 samples in chunks of 32: 8 chunks per vector, 64 in all.
    let chunk = (h % 64 + 5) % 64;
    assert_eq!(sample_range(pixel, frame, seed, 8, 256, 32), (chunk / 8, chunk % 8 * 32));
}

#[test]
fn the_frames_use_every_sample_of_the_slice_once_before_repeating() {
    for (pixel, seed) in [(0, 0), (77, 3), (40_000, 123)] {
        let frames = render::frames_to_exhaust(8, 256, 64);
        assert_eq!(frames, 32);
        let mut used = std::collections::BTreeSet::new();
        for f in 0..frames {
            assert!(used.insert(sample_range(pixel, f, seed, 8, 256, 64)), "frame {f} repeats a chunk");
        }
        assert_eq!(used.len(), 32);
        assert_eq!(sample_range(pixel, frames, seed, 8, 256, 64), sample_range(pixel, 0, seed, 8, 256, 64));
    }
}

#[test]
fn sample_range_stays_inside_the_vector_and_the_chunk() {
    let mut rng = StdRng::seed_from_u64(9);
    for _ in 0..100_000 {
        let n_vectors = rng.random_range(1..=64u32);
        let n_samples = 1u32 << rng.random_range(0..=16);
        let spp = 1u32 << rng.random_range(0..=n_samples.trailing_zeros());
        let (vector, first) = sample_range(rng.random(), rng.random(), rng.random(), n_vectors, n_samples, spp);
        assert!(vector < n_vectors, "vector {vector} of {n_vectors}");
        assert_eq!(first % spp, 0, "first sample {first} not aligned to spp {spp}");
        assert!(first + spp <= n_samples, "samples {first} + {spp} beyond {n_samples}");
    }
}

#[test]
fn sample_range_spreads_over_vectors_and_chunks() {
    // 8 vectors x 4 chunks = 32 choices, each drawn 1024 times on average over 32768 pixels:
    // the standard deviation of a count is about 32, so every count lies within 1024 +- 200.
    let mut counts = [0u32; 32];
    for pixel in 0..32_768 {
        let (vector, first) = sample_range(pixel, 3, 1, 8, 256, 64);
        counts[(vector * 4 + first / 64) as usize] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        assert!((824..=1224).contains(&c), "choice {i} drawn {c} times");
    }
}

/// A pixel's points are uniform on `[0, 1)^2` whatever the pixel: point `n` of many pixels'
/// sequences, pooled, fills a 16 x 16 grid evenly, for both of a pixel's sequences (the crate
/// documentation's argument that each pixel's directions have the table's density rests on it).
/// A scramble that ignored the pixel would put every pixel's point `n` in one place.
#[test]
fn pixels_points_pooled_over_pixels_are_uniform() {
    for (sequence, index) in [(0, 0), (0, 37), (1, 0), (1, 8191)] {
        let mut observed = vec![0u64; 256];
        for pixel in 0..65_536u32 {
            let [u0, u1] = render::point(&render::pixel_sequences(pixel, 11)[sequence], index);
            observed[(u1 * 16.0) as usize * 16 + (u0 * 16.0) as usize] += 1;
        }
        let result = sampling::chi2::chi2_test(&observed, &[256.0; 256]);
        assert!(result.p_value > sampling::chi2::ACCEPT, "sequence {sequence}, point {index}: {result:?}");
    }
}

/// Neighbouring pixels' points are unrelated: over 65536 pairs of horizontal neighbours the
/// correlation of a coordinate is within 0.02 of 0 (five standard deviations of 1 / sqrt(65536)).
/// Sequences shared by the pixels of a row would correlate them fully.
#[test]
fn neighbouring_pixels_points_are_uncorrelated() {
    for index in [0, 5, 1000] {
        let coordinate = |pixel: u32| render::point(&render::pixel_sequences(pixel, 3)[0], index)[0];
        let pairs: Vec<(f64, f64)> = (0..65_536u32).map(|p| (coordinate(2 * p), coordinate(2 * p + 1))).collect();
        let n = pairs.len() as f64;
        let (ma, mb) = (pairs.iter().map(|p| p.0).sum::<f64>() / n, pairs.iter().map(|p| p.1).sum::<f64>() / n);
        let cov = pairs.iter().map(|p| (p.0 - ma) * (p.1 - mb)).sum::<f64>() / n;
        let correlation = cov / (1.0 / 12.0);
        assert!(correlation.abs() < 0.02, "point {index}: correlation {correlation:.4}");
    }
}

/// The directions a slice's table maps many pixels' points to have the table's density
/// (`importance::quality::chi2_of_points`, 80 bins of the hemisphere unrelated to the table's
/// cells), at a point index and a view where Phong's lobe is off the normal. The expected counts
/// take the quadrature `importance`'s own chi-square test takes: with the default one, 200000
/// directions of this lobe see its error (independent uniform points over five seeds: p from
/// 0.012 to 0.45 with the default quadrature, from 0.011 to 0.88 with twice this one's nodes
/// per axis).
#[test]
fn pixels_directions_have_the_tables_density() {
    let material = crate::support::phong(0);
    let slice = &material.samples.tables[60];
    let q = merl::albedo::Quadrature { nodes_per_cell: 16, n_phi_h: 2880 };
    for index in [0, 4097] {
        let points = (0..200_000u32).map(|pixel| render::point(&render::pixel_sequences(pixel, 5)[0], index));
        let result = importance::quality::chi2_of_points(slice, points, q);
        assert!(result.p_value > sampling::chi2::ACCEPT, "point {index}: {result:?}");
    }
}
