use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use sampling::{Distribution1D, Distribution2D, ONE_MINUS_EPSILON};

use crate::chi2::{assert_accepts, assert_rejects, chi2_2d};

/// As in 1D: about 4500 ulps of 1, far above the rounding of the few operations involved for
/// grids up to 64 x 48, far below a misplaced bin or row.
const TOL: f64 = 1e-12;

/// A test function: `nv` rows of `nu` values, and `nu`, `nv`.
type Grid = (Vec<f64>, usize, usize);

/// `nv` rows of `nu` values of `f(u, v)` at the cell centres.
fn tabulate(nu: usize, nv: usize, f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    (0..nu * nv).map(|k| f(((k % nu) as f64 + 0.5) / nu as f64, ((k / nu) as f64 + 0.5) / nv as f64)).collect()
}

fn smooth() -> Grid {
    (tabulate(32, 16, |u, v| 1.0 + (3.0 * u).sin() * (2.0 * v).cos() + u * v), 32, 16)
}

/// A narrow diagonal ridge, about one cell wide, with exact zeros away from it.
fn ridge() -> Grid {
    let f = |u: f64, v: f64| {
        let g = (-((u - 0.2 - 0.6 * v) / 0.01).powi(2)).exp();
        if g < 1e-6 { 0.0 } else { g }
    };
    (tabulate(64, 48, f), 64, 48)
}

/// The ridge over a floor of 1e-3 and no zeros, so that a wrong sampler is rejected by the
/// statistic rather than by a sample in a cell of zero probability.
fn ridge_on_floor() -> Grid {
    let (func, nu, nv) = ridge();
    (func.into_iter().map(|f| f + 1e-3).collect(), nu, nv)
}

/// Whole zero rows and columns, zero cells inside rows, and one dominant cell.
fn with_zeros() -> Grid {
    #[rustfmt::skip]
    let func = vec![
        0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 1.0, 0.0, 2.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0,
        3.0, 0.0, 900.0, 0.0, 0.0,
        0.0, 0.5, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0, 0.0,
    ];
    (func, 5, 7)
}

fn functions() -> Vec<(&'static str, Grid)> {
    vec![
        ("smooth", smooth()),
        ("ridge", ridge()),
        ("ridge on a floor", ridge_on_floor()),
        ("zeros", with_zeros()),
        ("single cell", (vec![2.0], 1, 1)),
        ("single row", (vec![1.0, 0.0, 3.0], 3, 1)),
        ("single column", (vec![1.0, 0.0, 3.0], 1, 3)),
        ("all zero", (vec![0.0; 12], 4, 3)),
    ]
}

fn dist((func, nu, nv): &Grid) -> Distribution2D {
    Distribution2D::new(func, *nu, *nv).unwrap()
}

fn centre(k: usize, nu: usize, nv: usize) -> [f64; 2] {
    [((k % nu) as f64 + 0.5) / nu as f64, ((k / nu) as f64 + 0.5) / nv as f64]
}

#[test]
fn known_answer_two_by_two() {
    // Rows [1, 3] and [0, 4]: row integrals 2 and 2, integral 2.
    let d = Distribution2D::new(&[1.0, 3.0, 0.0, 4.0], 2, 2).unwrap();
    assert_eq!((d.nu(), d.nv(), d.integral()), (2, 2, 2.0));
    assert_eq!(d.marginal().func(), &[2.0, 2.0]);
    assert_eq!(d.marginal().cdf(), &[0.0, 0.5, 1.0]);
    assert_eq!(d.conditional_cdf(), &[0.0, 0.25, 1.0, 0.0, 0.0, 1.0]);
    assert_eq!([d.pdf([0.2, 0.2]), d.pdf([0.7, 0.2]), d.pdf([0.2, 0.7]), d.pdf([0.7, 0.7])], [0.5, 1.5, 0.0, 2.0]);
    // u[1] = 0.75 is halfway through the second row's marginal range; u[0] = 0.5 then lands
    // halfway through that row's only cell with mass.
    let s = d.sample([0.5, 0.75]);
    assert_eq!((s.p, s.pdf, s.index), ([0.75, 0.75], 2.0, [1, 1]));
    assert_eq!(d.invert([0.75, 0.75]), [0.5, 0.75]);
}

#[test]
fn tables_have_the_documented_layout() {
    for (name, f) in functions() {
        let (func, nu, nv) = &f;
        let d = dist(&f);
        assert_eq!((d.nu(), d.nv(), d.func()), (*nu, *nv, &func[..]), "{name}");
        assert_eq!(d.conditional_cdf().len(), nv * (nu + 1), "{name}");
        assert_eq!((d.marginal().len(), d.marginal().cdf().len()), (*nv, nv + 1), "{name}");
        for (iv, (row, cdf)) in func.chunks(*nu).zip(d.conditional_cdf().chunks(nu + 1)).enumerate() {
            // Each row's table is exactly the 1D distribution of that row.
            let row_dist = Distribution1D::new(row).unwrap();
            assert_eq!(cdf, row_dist.cdf(), "{name}: row {iv}");
            assert_eq!(d.marginal().func()[iv], row_dist.integral(), "{name}: row {iv}");
        }
        let mean = func.iter().sum::<f64>() / func.len() as f64;
        assert!((d.integral() - mean).abs() <= TOL * mean, "{name}: integral {} != mean {mean}", d.integral());
    }
}

#[test]
fn pdf_integrates_to_one() {
    for (name, f) in functions() {
        let (func, nu, nv) = &f;
        let d = dist(&f);
        let area = 1.0 / func.len() as f64;
        let total: f64 = (0..func.len()).map(|k| d.pdf(centre(k, *nu, *nv)) * area).sum();
        assert!((total - 1.0).abs() < TOL, "{name}: pdf integrates to {total}");
    }
}

#[test]
fn pdf_is_func_over_integral() {
    for (name, f) in functions() {
        let (func, nu, nv) = &f;
        let d = dist(&f);
        for (k, value) in func.iter().enumerate() {
            let expected = if d.integral() > 0.0 { value / d.integral() } else { 1.0 };
            let pdf = d.pdf(centre(k, *nu, *nv));
            // Marginal times conditional rounds twice where func / integral rounds once.
            assert!((pdf - expected).abs() <= TOL * expected, "{name}: cell {k}: {pdf} != {expected}");
        }
        for outside in [[-1e-300, 0.5], [0.5, -1e-300], [1.0 + f64::EPSILON, 0.5], [0.5, f64::NAN]] {
            assert_eq!(d.pdf(outside), 0.0, "{name}: {outside:?}");
        }
    }
}

#[test]
fn invert_undoes_sample_and_pdf_agrees_with_sample() {
    let mut rng = StdRng::seed_from_u64(21);
    for (name, f) in functions() {
        let d = dist(&f);
        for _ in 0..100_000 {
            let u: [f64; 2] = [rng.random(), rng.random()];
            let s = d.sample(u);
            let back = d.invert(s.p);
            assert!((back[0] - u[0]).abs() < TOL && (back[1] - u[1]).abs() < TOL, "{name}: {u:?} -> {s:?} -> {back:?}");
            assert_eq!(d.pdf(s.p), s.pdf, "{name}: {u:?} -> {s:?}");
        }
    }
}

#[test]
fn chi2_accepts_sampler_on_test_functions() {
    for (seed, (name, f)) in functions().into_iter().enumerate() {
        let d = dist(&f);
        let result = chi2_2d(|u| d.sample(u).p, |p| d.pdf(p), [f.1, f.2], [45, 37], 1_000_000, 20 + seed as u64);
        assert_accepts(result, name);
    }
}

#[test]
fn chi2_rejects_a_sampler_that_ignores_the_conditional() {
    // The right row, but the column drawn uniformly: the ridge smeared over its rows.
    for (name, f) in [("ridge", ridge()), ("ridge on a floor", ridge_on_floor())] {
        let d = dist(&f);
        let wrong = |u: [f64; 2]| [u[0], d.sample(u).p[1]];
        assert_rejects(chi2_2d(wrong, |p| d.pdf(p), [f.1, f.2], [45, 37], 1_000_000, 30), name);
    }
}

#[test]
fn chi2_rejects_a_sampler_that_uses_the_neighbouring_row() {
    // An off-by-one in the row index: the ridge moves by 0.6 / 48 = 0.0125 in u, about its width.
    for (name, (func, nu, nv)) in [("ridge", ridge()), ("ridge on a floor", ridge_on_floor())] {
        let d = Distribution2D::new(&func, nu, nv).unwrap();
        let rows: Vec<Distribution1D> = func.chunks(nu).map(|row| Distribution1D::new(row).unwrap()).collect();
        let wrong = |u: [f64; 2]| {
            let sv = d.marginal().sample(u[1]);
            [rows[(sv.index + 1) % nv].sample(u[0]).x, sv.x]
        };
        assert_rejects(chi2_2d(wrong, |p| d.pdf(p), [nu, nv], [45, 37], 1_000_000, 31), name);
    }
}

#[test]
fn never_samples_a_zero_cell_and_never_returns_nan() {
    let mut rng = StdRng::seed_from_u64(22);
    for (name, f) in functions() {
        let (func, nu, _) = &f;
        let d = dist(&f);
        let all_zero = func.iter().all(|&v| v == 0.0);
        // The awkward u of each coordinate: ends of [0, 1), outside it, and every CDF value with
        // its neighbours, crossed with each other.
        let mut u1 = vec![0.0, ONE_MINUS_EPSILON, 1.0, -0.5, f64::NAN];
        for &c in d.marginal().cdf() {
            u1.extend([c, c.next_down(), c.next_up()]);
        }
        let mut u0 = u1.clone();
        for &c in d.conditional_cdf() {
            u0.extend([c, c.next_down(), c.next_up()]);
        }
        let mut us: Vec<[f64; 2]> = u0.iter().flat_map(|&a| u1.iter().map(move |&b| [a, b])).collect();
        us.extend((0..100_000).map(|_| [rng.random(), rng.random()]));
        for u in us {
            let s = d.sample(u);
            let [iu, iv] = s.index;
            assert!(func[iv * nu + iu] > 0.0 || all_zero, "{name}: {u:?} -> zero cell: {s:?}");
            assert!(s.p.iter().all(|x| (0.0..1.0).contains(x)), "{name}: {u:?} -> {s:?}");
            assert!(s.pdf.is_finite() && s.pdf > 0.0, "{name}: {u:?} -> {s:?}");
            assert_eq!(d.pdf(s.p), s.pdf, "{name}: {u:?} -> {s:?}");
            let back = d.invert(s.p);
            assert!(back.iter().all(|x| (0.0..=1.0).contains(x)), "{name}: {u:?} -> {s:?} -> {back:?}");
        }
    }
}

#[test]
fn zero_rows_have_uniform_conditionals_and_no_mass() {
    let f = with_zeros();
    let d = dist(&f);
    let row0 = &d.conditional_cdf()[..6];
    assert_eq!(row0, &[0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
    assert_eq!(d.marginal().func()[0], 0.0);
    assert_eq!(d.pdf([0.5, 0.01]), 0.0);
}

#[test]
fn all_zero_function_is_uniform() {
    let d = Distribution2D::new(&[0.0; 6], 3, 2).unwrap();
    assert_eq!(d.integral(), 0.0);
    let s = d.sample([0.5, 0.25]);
    assert_eq!((s.index, s.pdf), ([1, 0], 1.0));
    assert!((s.p[0] - 0.5).abs() < 1e-15 && (s.p[1] - 0.25).abs() < 1e-15, "{s:?}");
    assert_eq!(d.pdf([0.9, 0.9]), 1.0);
}

#[test]
fn stored_tables_sample_as_the_distribution_they_came_from() {
    let mut rng = StdRng::seed_from_u64(23);
    for (name, f) in functions() {
        let (_, nu, nv) = f;
        let d = dist(&f);
        let stored = Distribution2D::from_cdfs(d.marginal().cdf(), d.conditional_cdf(), nu, nv).unwrap();
        assert_eq!((stored.marginal().cdf(), stored.conditional_cdf()), (d.marginal().cdf(), d.conditional_cdf()));
        for _ in 0..20_000 {
            let u: [f64; 2] = [rng.random(), rng.random()];
            let (a, b) = (d.sample(u), stored.sample(u));
            assert_eq!((a.p, a.index), (b.p, b.index), "{name}: {u:?}");
            // The stored tables' bin values are CDF differences: the same pdf up to rounding.
            assert!((a.pdf - b.pdf).abs() <= TOL * a.pdf, "{name}: {u:?}: pdf {} against {}", b.pdf, a.pdf);
            assert_eq!(stored.pdf(b.p), b.pdf, "{name}: {u:?}");
        }
    }
}

/// The bin an `f32` CDF table gives `u`, found with `f32` comparisons as a GPU finds it.
fn f32_bin(cdf: &[f64], u: f32) -> usize {
    cdf.iter().map(|&c| c as f32).rposition(|c| c <= u).unwrap().min(cdf.len() - 2)
}

#[test]
fn tables_rounded_to_f32_choose_the_bins_a_gpu_chooses() {
    let mut rng = StdRng::seed_from_u64(24);
    for (name, f) in functions() {
        let (func, nu, _) = &f;
        let rounded = dist(&f).rounded_to_f32();
        let tables = rounded.marginal().cdf().iter().chain(rounded.conditional_cdf());
        assert!(tables.into_iter().all(|&c| f64::from(c as f32) == c), "{name}: a table entry is not an f32");
        for _ in 0..20_000 {
            // u on the 2^-24 grid, as a GPU makes it from 24 bits of a random word.
            let u = [0, 1].map(|_| (rng.random::<u32>() >> 8) as f32 / 16_777_216.0);
            let s = rounded.sample(u.map(f64::from));
            let iv = f32_bin(rounded.marginal().cdf(), u[1]);
            let iu = f32_bin(&rounded.conditional_cdf()[iv * (nu + 1)..(iv + 1) * (nu + 1)], u[0]);
            // Zero-width bins share their edge with the next: the search takes the last bin whose
            // edge is at most u, which is the one of positive width.
            assert_eq!(s.index, [iu, iv], "{name}: {u:?}");
            assert!(func[iv * nu + iu] > 0.0 || func.iter().all(|&v| v == 0.0), "{name}: {u:?} in a zero cell");
        }
        let chi2 = chi2_2d(|u| rounded.sample(u).p, |p| rounded.pdf(p), [f.1, f.2], [45, 37], 200_000, 25);
        assert_accepts(chi2, name);
    }
}

#[test]
fn stored_tables_that_are_not_cdfs_are_refused() {
    use sampling::Error;
    let conditional = [0.0, 0.5, 1.0, 0.0, 1.0, 1.0];
    let cases: [(&str, Vec<f64>, Vec<f64>, Error); 5] = [
        ("marginal not from 0", vec![0.1, 0.5, 1.0], conditional.to_vec(), Error::InvalidCdf { index: 0, value: 0.1 }),
        ("marginal not to 1", vec![0.0, 0.5, 0.9], conditional.to_vec(), Error::InvalidCdf { index: 2, value: 0.9 }),
        (
            "decreasing",
            vec![0.0, 0.5, 1.0],
            vec![0.0, 0.6, 1.0, 0.0, 1.5, 1.0],
            Error::InvalidCdf { index: 5, value: 1.0 },
        ),
        ("NaN", vec![0.0, f64::NAN, 1.0], conditional.to_vec(), Error::InvalidCdf { index: 1, value: f64::NAN }),
        ("wrong size", vec![0.0, 1.0], conditional.to_vec(), Error::WrongSize { len: 6, nu: 3, nv: 2 }),
    ];
    for (name, marginal, conditional, expected) in cases {
        let error = Distribution2D::from_cdfs(&marginal, &conditional, 2, 2).unwrap_err();
        // NaN != NaN: compare the messages.
        assert_eq!(error.to_string(), expected.to_string(), "{name}");
    }
}
