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
