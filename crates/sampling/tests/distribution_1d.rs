use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use sampling::{Distribution1D, ONE_MINUS_EPSILON};

use crate::chi2::{assert_accepts, assert_rejects, chi2_1d};

/// Tolerance for sums over bins and for invert(sample(u)) = u: about 4500 ulps of 1, far above
/// the rounding of the few operations involved for the table sizes here (up to 4096 bins) and
/// far below any error in the logic (a misplaced bin moves u by at least a bin's mass).
const TOL: f64 = 1e-12;

fn smooth(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let x = (i as f64 + 0.5) / n as f64;
            (-((x - 0.3) / 0.15).powi(2)).exp() + 0.2 * (7.0 * x).sin().powi(2)
        })
        .collect()
}

/// Bin `peak` holds 99.9% of the mass, the others share the rest.
fn peaked(n: usize, peak: usize) -> Vec<f64> {
    (0..n).map(|i| if i == peak { 0.999 } else { 0.001 / (n - 1) as f64 }).collect()
}

/// As [`peaked`], with every third other bin zero.
fn peaked_with_zeros(n: usize, peak: usize) -> Vec<f64> {
    peaked(n, peak).into_iter().enumerate().map(|(i, f)| if i != peak && i % 3 == 0 { 0.0 } else { f }).collect()
}

/// Zero runs at both ends and inside, single zero bins, and a peak.
fn with_zeros() -> Vec<f64> {
    vec![0.0, 0.0, 1.0, 0.0, 2.0, 0.5, 0.0, 0.0, 0.0, 3.0, 0.0, 50.0, 0.25, 0.0, 1.0, 0.0, 0.0]
}

fn random_with_zeros(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    (0..n).map(|_| if rng.random_bool(0.3) { 0.0 } else { rng.random::<f64>() * 10.0 }).collect()
}

/// Every function the tests below run on, with a name for the messages.
fn functions() -> Vec<(&'static str, Vec<f64>)> {
    vec![
        ("smooth", smooth(64)),
        ("peaked", peaked(50, 17)),
        ("peaked at the last bin", peaked(50, 49)),
        ("peaked with zero bins", peaked_with_zeros(50, 17)),
        ("zeros", with_zeros()),
        ("random with zeros", random_with_zeros(4096, 7)),
        ("single bin", vec![3.0]),
        ("all zero", vec![0.0; 10]),
        ("one nonzero bin", vec![0.0, 0.0, 0.0, 4.0, 0.0]),
    ]
}

fn dist(func: &[f64]) -> Distribution1D {
    Distribution1D::new(func).unwrap()
}

#[test]
fn known_answer_two_bins() {
    let d = dist(&[1.0, 3.0]);
    assert_eq!(d.integral(), 2.0);
    assert_eq!(d.cdf(), &[0.0, 0.25, 1.0]);
    assert_eq!((d.pdf(0.2), d.pdf(0.7)), (0.5, 1.5));
    // u = 0.5 lies a third of the way into the second bin's [0.25, 1) CDF range.
    let s = d.sample(0.5);
    assert_eq!((s.index, s.pdf), (1, 1.5));
    assert!((s.x - (0.5 + 0.5 / 3.0)).abs() < 1e-15, "{s:?}");
    assert_eq!(d.invert(0.75), 0.625);
}

#[test]
fn tables_have_the_documented_layout() {
    for (name, func) in functions() {
        let d = dist(&func);
        let cdf = d.cdf();
        assert_eq!((d.len(), d.func(), cdf.len()), (func.len(), &func[..], func.len() + 1), "{name}");
        assert_eq!((cdf[0], cdf[func.len()]), (0.0, 1.0), "{name}");
        assert!(cdf.windows(2).all(|w| w[0] <= w[1]), "{name}: cdf decreases: {cdf:?}");
        // A bin has CDF width exactly when it has mass (all-zero functions are uniform).
        let all_zero = func.iter().all(|&f| f == 0.0);
        for (i, f) in func.iter().enumerate() {
            assert_eq!(cdf[i + 1] > cdf[i], *f > 0.0 || all_zero, "{name}: bin {i}");
        }
        let mean = func.iter().sum::<f64>() / func.len() as f64;
        assert!((d.integral() - mean).abs() <= TOL * mean, "{name}: integral {} != mean {mean}", d.integral());
    }
}

#[test]
fn pdf_integrates_to_one() {
    for (name, func) in functions() {
        let d = dist(&func);
        let n = func.len() as f64;
        let total: f64 = (0..func.len()).map(|i| d.pdf((i as f64 + 0.5) / n) / n).sum();
        assert!((total - 1.0).abs() < TOL, "{name}: pdf integrates to {total}");
    }
}

#[test]
fn pdf_is_func_over_integral() {
    for (name, func) in functions() {
        let d = dist(&func);
        let n = func.len() as f64;
        for (i, f) in func.iter().enumerate() {
            let expected = if d.integral() > 0.0 { f / d.integral() } else { 1.0 };
            assert_eq!(d.pdf((i as f64 + 0.5) / n), expected, "{name}: bin {i}");
        }
        assert_eq!((d.pdf(-1e-300), d.pdf(1.0 + f64::EPSILON), d.pdf(f64::NAN)), (0.0, 0.0, 0.0), "{name}");
    }
}

#[test]
fn invert_undoes_sample_and_pdf_agrees_with_sample() {
    let mut rng = StdRng::seed_from_u64(1);
    for (name, func) in functions() {
        let d = dist(&func);
        for _ in 0..100_000 {
            let u: f64 = rng.random();
            let s = d.sample(u);
            assert!((d.invert(s.x) - u).abs() < TOL, "{name}: u {u} -> {s:?} -> {}", d.invert(s.x));
            // The same code path computes both, so they agree exactly.
            assert_eq!(d.pdf(s.x), s.pdf, "{name}: u {u} -> {s:?}");
        }
    }
}

#[test]
fn sample_undoes_invert_inside_bins_with_mass() {
    let mut rng = StdRng::seed_from_u64(2);
    for (name, func) in functions() {
        let d = dist(&func);
        for _ in 0..10_000 {
            let x: f64 = rng.random();
            if d.pdf(x) == 0.0 {
                continue;
            }
            // sample's slope dx/du is 1 / pdf, so invert's rounding (~1e-16) comes back
            // multiplied by it: 1e-9 allows a pdf down to ~1e-6, below the smallest here.
            let back = d.sample(d.invert(x)).x;
            assert!((back - x).abs() < 1e-9, "{name}: x {x} -> {back}");
        }
    }
}

#[test]
fn chi2_accepts_sampler_on_test_functions() {
    for (seed, (name, func)) in functions().into_iter().enumerate() {
        let d = dist(&func);
        let result = chi2_1d(|u| d.sample(u).x, |x| d.pdf(x), func.len(), 97, 200_000, seed as u64);
        assert_accepts(result, name);
    }
}

#[test]
fn chi2_rejects_a_sampler_that_ignores_func() {
    for (name, func) in [("smooth", smooth(64)), ("peaked", peaked(50, 17)), ("zeros", with_zeros())] {
        let d = dist(&func);
        assert_rejects(chi2_1d(|u| u, |x| d.pdf(x), func.len(), 97, 200_000, 10), name);
    }
}

#[test]
fn chi2_rejects_a_sampler_shifted_by_half_a_bin() {
    let func = smooth(64);
    let d = dist(&func);
    let shifted = |u| (d.sample(u).x + 0.5 / 64.0) % 1.0;
    assert_rejects(chi2_1d(shifted, |x| d.pdf(x), 64, 97, 200_000, 11), "smooth");
}

#[test]
fn chi2_rejects_a_pdf_shifted_by_one_bin() {
    let func = smooth(64);
    let d = dist(&func);
    let shifted_pdf = |x: f64| d.pdf((x + 1.0 / 64.0) % 1.0);
    assert_rejects(chi2_1d(|u| d.sample(u).x, shifted_pdf, 64, 97, 200_000, 12), "smooth");
}

/// The `u` most likely to break a sampler: the ends of [0, 1), each CDF value and its neighbours
/// (where a zero bin begins or ends), values outside [0, 1), and NaN.
fn awkward_u(cdf: &[f64]) -> Vec<f64> {
    let mut u = vec![0.0, -0.0, f64::MIN_POSITIVE, ONE_MINUS_EPSILON, 1.0, 1.5, -0.5, f64::NAN];
    for &c in cdf {
        u.extend([c, c.next_down(), c.next_up()]);
    }
    u
}

#[test]
fn never_samples_a_zero_bin_and_never_returns_nan() {
    let mut rng = StdRng::seed_from_u64(3);
    for (name, func) in functions() {
        let d = dist(&func);
        let all_zero = func.iter().all(|&f| f == 0.0);
        let mut us = awkward_u(d.cdf());
        us.extend((0..100_000).map(|_| rng.random::<f64>()));
        for u in us {
            let s = d.sample(u);
            assert!(func[s.index] > 0.0 || all_zero, "{name}: u {u} -> zero bin: {s:?}");
            assert!((0.0..1.0).contains(&s.x), "{name}: u {u} -> {s:?}");
            assert!(s.pdf.is_finite() && s.pdf > 0.0, "{name}: u {u} -> {s:?}");
            assert_eq!(d.pdf(s.x), s.pdf, "{name}: u {u} -> {s:?}");
            let back = d.invert(s.x);
            assert!((0.0..=1.0).contains(&back), "{name}: u {u} -> {s:?} -> {back}");
        }
    }
}

#[test]
fn u_outside_the_unit_interval_is_clamped() {
    let d = dist(&with_zeros());
    assert_eq!(d.sample(1.0), d.sample(ONE_MINUS_EPSILON));
    assert_eq!(d.sample(7.0), d.sample(ONE_MINUS_EPSILON));
    assert_eq!(d.sample(-1.0), d.sample(0.0));
    assert_eq!(d.sample(f64::NAN), d.sample(0.0));
    // The extreme u land in the first and last bins with mass: 2 and 14.
    assert_eq!((d.sample(0.0).index, d.sample(ONE_MINUS_EPSILON).index), (2, 14));
    assert!(d.sample(ONE_MINUS_EPSILON).x < 15.0 / 17.0);
}

#[test]
fn points_on_bin_edges_belong_to_the_upper_bin() {
    // 8 bins, so k / 8 is exact.
    let func = [1.0, 0.0, 2.0, 3.0, 0.0, 0.0, 5.0, 4.0];
    let d = dist(&func);
    for (k, f) in func.iter().enumerate() {
        let edge = k as f64 / 8.0;
        assert_eq!(d.pdf(edge), f / d.integral(), "edge {k}");
        assert_eq!(d.invert(edge), d.cdf()[k], "edge {k}");
        if *f > 0.0 {
            // u at the CDF value of a bin with mass starts that bin exactly.
            let s = d.sample(d.cdf()[k]);
            assert_eq!((s.x, s.index), (edge, k), "edge {k}");
        }
    }
    assert_eq!((d.pdf(1.0), d.invert(1.0)), (4.0 / d.integral(), 1.0));
}

#[test]
fn all_zero_function_is_uniform() {
    let d = dist(&[0.0; 4]);
    assert_eq!(d.integral(), 0.0);
    assert_eq!(d.cdf(), &[0.0, 0.25, 0.5, 0.75, 1.0]);
    let s = d.sample(0.3);
    assert_eq!((s.index, s.pdf), (1, 1.0));
    assert!((s.x - 0.3).abs() < 1e-15);
    assert_eq!((d.pdf(0.9), d.invert(0.6)), (1.0, 0.6));
    // A function too small for its mean to be represented is treated the same way.
    let tiny = dist(&[5e-324, 0.0, 0.0, 0.0]);
    assert_eq!((tiny.integral(), tiny.cdf()), (0.0, &[0.0, 0.25, 0.5, 0.75, 1.0][..]));
    assert_eq!(tiny.pdf(0.9), 1.0);
}

#[test]
fn extreme_magnitudes_stay_finite() {
    // Values near f64::MAX would overflow a plain running sum; subnormal ones underflow a mean.
    for func in [vec![f64::MAX, f64::MAX, 0.0, f64::MAX], vec![5e-324, 0.0, 1e-320], vec![f64::MAX, 5e-324]] {
        let d = dist(&func);
        assert!(d.integral().is_finite() && d.integral() > 0.0, "{func:?}: {}", d.integral());
        assert!(d.cdf().iter().all(|c| c.is_finite()), "{func:?}: {:?}", d.cdf());
        for u in awkward_u(d.cdf()) {
            let s = d.sample(u);
            assert!(s.pdf.is_finite() && s.pdf > 0.0 && func[s.index] > 0.0, "{func:?}: u {u} -> {s:?}");
        }
    }
}
