use sampling::{OwenSobol2D, owen_sobol_vectors};

use crate::chi2::{assert_accepts, chi2_test};

/// Cell of `x` in a grid of `2^bits` cells; exact, since points are multiples of 2^-32.
fn cell(x: f64, bits: u32) -> usize {
    (x * (1u64 << bits) as f64) as usize
}

/// Every elementary interval of area `2^-m`, of each shape `2^-a x 2^-(m-a)`, holds exactly one
/// of the `2^m` points.
#[track_caller]
fn assert_net(points: &[[f64; 2]], m: u32, what: &str) {
    assert_eq!(points.len(), 1 << m);
    for a in 0..=m {
        let mut counts = vec![0u32; 1 << m];
        for p in points {
            counts[(cell(p[1], m - a) << a) | cell(p[0], a)] += 1;
        }
        assert!(counts.iter().all(|&c| c == 1), "{what}: m {m}, shape 2^{a} x 2^{}: counts {counts:?}", m - a);
    }
}

#[test]
fn points_lie_in_the_unit_square() {
    for seed in 0..16 {
        let sequence = OwenSobol2D::new(seed);
        let mut points = sequence.points(4096);
        points.extend([sequence.point(u32::MAX), sequence.point(u32::MAX - 1), sequence.point(1 << 31)]);
        for p in points {
            assert!(p.iter().all(|x| (0.0..1.0).contains(x)), "seed {seed}: {p:?}");
        }
    }
}

#[test]
fn power_of_two_prefixes_are_nets() {
    for seed in [0, 1, 2, 12345, u64::MAX] {
        let points = OwenSobol2D::new(seed).points(1 << 12);
        for m in 0..=12 {
            assert_net(&points[..1 << m], m, &format!("seed {seed}"));
        }
    }
}

#[test]
fn aligned_blocks_are_nets() {
    // Points [k 2^m, (k + 1) 2^m) of a (0,2)-sequence form a net too: a vector can grow by
    // doubling and every new half is stratified on its own.
    let points = OwenSobol2D::new(99).points(1 << 10);
    for (k, block) in points.chunks(1 << 6).enumerate() {
        assert_net(block, 6, &format!("block {k}"));
    }
}

#[test]
fn vectors_are_nets_with_different_scrambles() {
    let (n_vectors, n_samples) = (8, 256);
    let points = owen_sobol_vectors(5, n_vectors, n_samples);
    assert_eq!(points.len(), n_vectors * n_samples);
    let vectors: Vec<&[[f64; 2]]> = points.chunks(n_samples).collect();
    for (v, vector) in vectors.iter().enumerate() {
        assert_eq!(*vector, &OwenSobol2D::for_vector(5, v as u64).points(n_samples)[..], "vector {v}");
        assert_net(vector, 8, &format!("vector {v}"));
        for (w, other) in vectors.iter().enumerate().skip(v + 1) {
            assert_ne!(vector[0], other[0], "vectors {v} and {w} start at the same point");
        }
    }
    assert_ne!(owen_sobol_vectors(5, 1, 4), owen_sobol_vectors(6, 1, 4));
}

#[test]
fn each_point_is_uniform_over_seeds() {
    // Unscrambled, point 0 is (0, 0) and point 1 is (1/2, 1/2): only a working scramble spreads
    // them over the square. 20000 seeds binned 8 x 8 expect 312.5 per cell.
    for index in [0, 1, 6, 1001] {
        let mut observed = vec![0u64; 64];
        for seed in 0..20_000 {
            let p = OwenSobol2D::new(seed).point(index);
            observed[cell(p[1], 3) * 8 + cell(p[0], 3)] += 1;
        }
        assert_accepts(chi2_test(&observed, &[20_000.0 / 64.0; 64]), &format!("point {index}"));
    }
}

#[test]
fn integrates_smooth_functions_far_better_than_independent_samples() {
    // f(x, y) = x e^x y integrates to 1/2 with variance sigma^2 = (e^2 + 1) / 12 - 1/4 under
    // independent uniform samples. The RMS error of 64 scrambled 256-point estimates should be
    // near 256^-1.5 sigma for a smooth f; 1/10 of the independent 256^-0.5 sigma is a loose bound
    // that independent or merely shuffled points fail by a factor of 10.
    let f = |p: [f64; 2]| p[0] * p[0].exp() * p[1];
    let sigma = (((1.0_f64).exp().powi(2) + 1.0) / 12.0 - 0.25).sqrt();
    let (n_vectors, n_samples) = (64, 256);
    let points = owen_sobol_vectors(17, n_vectors, n_samples);
    let squared_error: f64 = points
        .chunks(n_samples)
        .map(|vector| (vector.iter().map(|&p| f(p)).sum::<f64>() / n_samples as f64 - 0.5).powi(2))
        .sum();
    let rmse = (squared_error / n_vectors as f64).sqrt();
    let independent = sigma / (n_samples as f64).sqrt();
    assert!(rmse < 0.1 * independent, "rmse {rmse}, independent samples {independent}");
}
