//! inverse(forward(x)) = x and energy preservation on random inputs in [-1, 1), fixed seeds.
//!
//! Tolerance 1e-12 absolute for the round trip (each level adds a few ulps of O(1) values), and
//! 1e-12 relative for the energy (a sum of n squares, each off by a few ulps).

use dwt::{Wavelet, dwt, dwt2, idwt, idwt2, max_levels, max_levels2, wavedec, wavedec2, waverec, waverec2};

use crate::{max_abs_diff, random_image, random_signal, rng};

const WAVELETS: [Wavelet; 2] = [Wavelet::Haar, Wavelet::D4];

#[test]
fn one_dimensional_round_trip_at_every_level() {
    let mut rng = rng(1);
    for w in WAVELETS {
        for n in [2, 4, 6, 24, 40, 1000, 1024] {
            let x = random_signal(&mut rng, n);
            let (a, d) = dwt(&x, w).unwrap();
            let diff = max_abs_diff(&idwt(&a, &d, w).unwrap(), &x);
            assert!(diff < 1e-12, "{w:?} n={n} one level: {diff:e}");
            for levels in 1..=max_levels(n) {
                let dec = wavedec(&x, w, levels).unwrap();
                let diff = max_abs_diff(&waverec(&dec).unwrap(), &x);
                assert!(diff < 1e-12, "{w:?} n={n} levels={levels}: {diff:e}");
            }
        }
    }
}

#[test]
fn two_dimensional_round_trip_at_every_level() {
    let mut rng = rng(2);
    for w in WAVELETS {
        for (width, height) in [(2, 2), (2, 8), (48, 16), (16, 48), (40, 24), (128, 64), (6, 10)] {
            let x = random_image(&mut rng, width, height);
            let (a, d) = dwt2(&x, w).unwrap();
            let diff = max_abs_diff(idwt2(&a, &d, w).unwrap().data(), x.data());
            assert!(diff < 1e-12, "{w:?} {width}x{height} one level: {diff:e}");
            for levels in 1..=max_levels2(width, height) {
                let dec = wavedec2(&x, w, levels).unwrap();
                let back = waverec2(&dec).unwrap();
                assert_eq!((back.width(), back.height()), (width, height));
                let diff = max_abs_diff(back.data(), x.data());
                assert!(diff < 1e-12, "{w:?} {width}x{height} levels={levels}: {diff:e}");
            }
        }
    }
}

#[test]
fn energy_is_preserved() {
    let mut rng = rng(3);
    for w in WAVELETS {
        for n in [8, 96, 512] {
            let x = random_signal(&mut rng, n);
            let energy: f64 = x.iter().map(|v| v * v).sum();
            for levels in 1..=max_levels(n) {
                let got = wavedec(&x, w, levels).unwrap().energy();
                let rel = (got - energy).abs() / energy;
                assert!(rel < 1e-12, "{w:?} n={n} levels={levels}: relative error {rel:e}");
            }
        }
        for (width, height) in [(8, 8), (64, 32), (24, 40)] {
            let x = random_image(&mut rng, width, height);
            for levels in 1..=max_levels2(width, height) {
                let got = wavedec2(&x, w, levels).unwrap().energy();
                let rel = (got - x.energy()).abs() / x.energy();
                assert!(rel < 1e-12, "{w:?} {width}x{height} levels={levels}: relative error {rel:e}");
            }
        }
    }
}

/// The parallel 2D path (large images are split into rayon tasks) agrees with the 1D transform
/// applied by hand to every row and then every column.
#[test]
fn two_dimensional_transform_is_the_separable_product_of_one_dimensional_ones() {
    let mut rng = rng(4);
    let (width, height) = (256, 192);
    for w in WAVELETS {
        let x = random_image(&mut rng, width, height);
        let (w2, h2) = (width / 2, height / 2);
        // Rows: [low | high] per row.
        let mut rows = vec![0.0; width * height];
        for (y, row) in x.rows().enumerate() {
            let (a, d) = dwt(row, w).unwrap();
            rows[y * width..y * width + w2].copy_from_slice(&a);
            rows[y * width + w2..(y + 1) * width].copy_from_slice(&d);
        }
        // Columns: low half of the columns -> (cA, cH), high half -> (cV, cD).
        let mut want = [(); 4].map(|_| vec![0.0; w2 * h2]);
        for c in 0..width {
            let column: Vec<f64> = (0..height).map(|y| rows[y * width + c]).collect();
            let (a, d) = dwt(&column, w).unwrap();
            let (lo, hi, cc) = if c < w2 { (0, 1, c) } else { (2, 3, c - w2) };
            for y in 0..h2 {
                want[lo][y * w2 + cc] = a[y];
                want[hi][y * w2 + cc] = d[y];
            }
        }
        let (a, [ch, cv, cd]) = dwt2(&x, w).unwrap();
        for (got, want) in [a, ch, cv, cd].iter().zip(&want) {
            let diff = max_abs_diff(got.data(), want);
            assert!(diff < 1e-13, "{w:?}: {diff:e}");
        }
    }
}
