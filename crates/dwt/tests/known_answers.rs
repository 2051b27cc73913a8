//! Analytic cases: constants under Haar, polynomials of degree 1 under D4 (two vanishing
//! moments), stripes in one orientation only, and the support of every coefficient.

use dwt::{Image, Orientation, Wavelet, coefficient_center, dwt2, wavedec, wavedec2};

/// Constant `c`: no detail anywhere, approximation `c 2^(levels / 2)` per axis (each Haar
/// low-pass sums two samples and divides by sqrt 2). Exact up to rounding of O(1) values.
#[test]
fn haar_of_a_constant_is_a_scaled_constant() {
    let c = 0.7;
    for levels in 1..=6 {
        let dec = wavedec(&[c; 64], Wavelet::Haar, levels).unwrap();
        let want = c * 2f64.powf(levels as f64 / 2.0);
        assert!(dec.approx.iter().all(|v| (v - want).abs() < 1e-12), "levels={levels}: {:?}", dec.approx);
        assert!(dec.details.iter().flatten().all(|v| v.abs() < 1e-12), "levels={levels}");
    }
    let image = Image::from_fn(32, 16, |_, _| c);
    for levels in 1..=4 {
        let dec = wavedec2(&image, Wavelet::Haar, levels).unwrap();
        let want = c * 2f64.powi(levels as i32);
        assert!(dec.approx.data().iter().all(|v| (v - want).abs() < 1e-12), "2d levels={levels}");
        assert!(dec.details.iter().flatten().all(|d| d.data().iter().all(|v| v.abs() < 1e-12)), "2d levels={levels}");
    }
}

/// Whether the support of coefficient `k` at `level` lies inside `0..n`, i.e. does not wrap.
fn inside(level: usize, k: usize, n: usize) -> bool {
    let support = Wavelet::D4.support(level, k);
    support.start >= 0 && support.end <= n as i64
}

/// D4 has two vanishing moments, so its details vanish on a + b i wherever the filter does not
/// wrap around the periodic boundary; where it wraps, the jump from the end of the ramp to its
/// start shows up. Tolerance: the coefficients are O(1) (ramp from 0.3 to 1.3) and the vanishing
/// moments hold to rounding, so 1e-12; the wrapped ones are O(0.1).
#[test]
fn d4_annihilates_linear_ramps_away_from_the_wrap() {
    let n = 128;
    let ramp: Vec<f64> = (0..n).map(|i| 0.3 + i as f64 / n as f64).collect();
    let dec = wavedec(&ramp, Wavelet::D4, 5).unwrap();
    for level in 1..=5 {
        let detail = dec.detail(level);
        let (mut zero, mut wrapped) = (0, 0);
        for (k, v) in detail.iter().enumerate() {
            if inside(level, k, n) {
                assert!(v.abs() < 1e-12, "level {level} k={k}: {v:e}");
                zero += 1;
            } else if v.abs() > 1e-3 {
                wrapped += 1;
            }
        }
        assert!(zero > 0 && wrapped > 0, "level {level}: {zero} interior, {wrapped} visibly wrapped");
    }

    // In 2D a plane a + b x + c y: a detail vanishes where its high-pass axis does not wrap.
    let (width, height) = (64, 32);
    let plane = Image::from_fn(width, height, |x, y| 0.2 + 0.5 * x as f64 / 64.0 - 0.7 * y as f64 / 32.0);
    let dec = wavedec2(&plane, Wavelet::D4, 3).unwrap();
    for level in 1..=3 {
        let mut checked = 0;
        for o in Orientation::ALL {
            let detail = dec.detail(level, o);
            for ky in 0..detail.height() {
                for kx in 0..detail.width() {
                    let (in_x, in_y) = (inside(level, kx, width), inside(level, ky, height));
                    let vanishes = match o {
                        Orientation::Horizontal => in_y,
                        Orientation::Vertical => in_x,
                        Orientation::Diagonal => in_x || in_y,
                    };
                    if vanishes {
                        let v = detail.get(kx, ky);
                        assert!(v.abs() < 1e-12, "level {level} {} ({kx}, {ky}): {v:e}", o.name());
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 0, "level {level}");
    }
    // Where the high-pass axis wraps the ramp's jump is visible: e.g. cH at ky = 0.
    assert!(dec.detail(1, Orientation::Horizontal).row(0).iter().all(|v| v.abs() > 1e-3));
    assert!(dec.detail(1, Orientation::Vertical).rows().all(|r| r[0].abs() > 1e-3));
}

/// Horizontal stripes (rows alternate) are seen by cH only; vertical stripes by cV only. This
/// pins which orientation is which axis (PyWavelets: cH is high-pass along axis 0).
#[test]
fn stripes_land_in_one_orientation() {
    for w in [Wavelet::Haar, Wavelet::D4] {
        let horizontal = Image::from_fn(16, 8, |_, y| if y % 2 == 0 { 1.0 } else { -1.0 });
        let vertical = Image::from_fn(16, 8, |x, _| if x % 2 == 0 { 1.0 } else { -1.0 });
        for (image, lit) in [(horizontal, Orientation::Horizontal), (vertical, Orientation::Vertical)] {
            let (approx, details) = dwt2(&image, w).unwrap();
            assert!(approx.data().iter().all(|v| v.abs() < 1e-12), "{w:?} {lit:?}: approximation");
            for o in Orientation::ALL {
                let energy = details[o.index()].energy();
                if o == lit {
                    assert!((energy - image.energy()).abs() < 1e-9, "{w:?} {lit:?}: {} holds {energy}", o.name());
                } else {
                    assert!(energy < 1e-20, "{w:?} {lit:?}: {} holds {energy}", o.name());
                }
            }
        }
    }
}

/// A unit impulse at sample p reaches exactly the coefficients whose support (wrapped
/// periodically) contains p, and the support is centred on `coefficient_center`.
#[test]
fn support_covers_exactly_the_coefficients_an_impulse_reaches() {
    let n = 64;
    for w in [Wavelet::Haar, Wavelet::D4] {
        for level in 1..=4 {
            for k in 0..n >> level {
                let s = w.support(level, k);
                let center = (s.start + s.end - 1) as f64 / 2.0;
                assert_eq!(center, coefficient_center(level, k), "{w:?} level {level} k={k}");
            }
        }
        for p in 0..n {
            let mut x = vec![0.0; n];
            x[p] = 1.0;
            let dec = wavedec(&x, w, 4).unwrap();
            for level in 1..=4 {
                let coefficients = [dec.detail(level)].into_iter().chain((level == 4).then_some(&dec.approx[..]));
                for c in coefficients {
                    for (k, v) in c.iter().enumerate() {
                        let covers = w.support(level, k).any(|i| i.rem_euclid(n as i64) == p as i64);
                        if !covers {
                            assert_eq!(*v, 0.0, "{w:?} impulse at {p} reached level {level} k={k} outside its support");
                        }
                    }
                }
            }
            // Every level's details see the impulse somewhere.
            assert!((1..=4).all(|l| dec.detail(l).iter().any(|v| *v != 0.0)), "{w:?} impulse at {p}");
        }
    }
}
