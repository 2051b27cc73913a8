//! The numbers and pictures that compare renders.

use envmap::{EnvMap, ToneMap, ToneMapping};
use render::{Image, metrics};

use crate::support;

#[test]
fn psnr_of_known_differences() {
    assert_eq!(metrics::psnr_db(&[1, 2, 3], &[1, 2, 3]), f64::INFINITY);
    assert_eq!(metrics::psnr_db(&[], &[]), f64::INFINITY);
    // Every value off by the full range: MSE = 255^2, 0 dB.
    assert!(metrics::psnr_db(&[0; 12], &[255; 12]).abs() < 1e-12);
    // One value of 300 off by 1: MSE = 1/300, 10 log10(255^2 300).
    let mut b = vec![100u8; 300];
    b[17] = 101;
    let expected = 10.0 * (255.0f64 * 255.0 * 300.0).log10();
    assert!((metrics::psnr_db(&vec![100; 300], &b) - expected).abs() < 1e-9);
}

#[test]
fn relative_error_uses_euclidean_norms() {
    assert_eq!(metrics::relative_error(&[1.0, 2.0], &[1.0, 2.0]), 0.0);
    assert_eq!(metrics::relative_error(&[0.0, 0.0], &[0.0, 0.0]), 0.0);
    assert_eq!(metrics::relative_error(&[1.0, 0.0], &[0.0, 0.0]), f64::INFINITY);
    // |(3, 4) - (0, 0)| / |(0, 0) + ...|: a = (3, 4, 0), b = (0, 0, 10): sqrt(9 + 16 + 100) / 10.
    let e = metrics::relative_error(&[3.0, 4.0, 0.0], &[0.0, 0.0, 10.0]);
    assert!((e - 125f64.sqrt() / 10.0).abs() < 1e-12, "{e}");
}

#[test]
fn mean_luminance_counts_covered_pixels_only() {
    let image = Image {
        width: 3,
        height: 1,
        rgb: vec![1.0, 1.0, 1.0, 0.0, 1.0, 0.0, 100.0, 100.0, 100.0],
        covered: vec![true, true, false],
    };
    // (1 + 0.7152) / 2.
    assert!((metrics::mean_luminance(&image) - 0.8576).abs() < 1e-6);
    let empty = Image { covered: vec![false; 3], ..image };
    assert_eq!(metrics::mean_luminance(&empty), 0.0);
}

#[test]
fn difference_is_amplified_and_clamped() {
    assert_eq!(metrics::difference_rgb8(&[10, 20, 7], &[13, 200, 7]), vec![12, 255, 0]);
}

#[test]
fn auto_exposure_maps_the_log_average_to_the_key() {
    let map: EnvMap = support::sky_lighting().mips.level(0).clone();
    // A constant map of luminance 0.18 (less the 1e-4 offset) needs no exposure change.
    let grey = EnvMap::constant(16, 8, [0.18 - 1e-4; 3]).expect("2:1");
    assert!(metrics::auto_tone_mapping(&grey).exposure_ev.abs() < 1e-5);
    // Four times brighter everywhere: two stops less.
    let bright = EnvMap::constant(16, 8, [4.0 * 0.18 - 1e-4; 3]).expect("2:1");
    assert!((metrics::auto_tone_mapping(&bright).exposure_ev + 2.0).abs() < 1e-4);
    let preview = metrics::auto_tone_mapping(&map);
    assert_eq!(preview.tone_map, ToneMap::Reinhard);
    let image = Image { width: 1, height: 1, rgb: vec![0.1, 1.0, 10.0], covered: vec![true] };
    assert_eq!(metrics::tonemap(&image, &preview), envmap::tonemap_rgb8(&image.rgb, &preview));
    assert_ne!(metrics::tonemap(&image, &ToneMapping::default()), metrics::tonemap(&image, &preview));
}

#[test]
fn windowed_bias_keeps_offsets_and_averages_noise() {
    let (w, h) = (20, 20);
    let all = vec![true; w * h];
    // A constant offset of 2 levels is a bias of 2 everywhere, whatever the window.
    let bias = metrics::windowed_bias(&vec![102; 3 * w * h], &vec![100; 3 * w * h], w, h, &all);
    assert_eq!((bias.p99, bias.max, bias.mean), (2.0, 2.0, 2.0));
    // A checkerboard of +-7 levels: noise, not structure. Inside, a window holds 25 of one sign
    // and 24 of the other: 7 / 49 = 1/7 of a level at most (partial windows at the edges hold
    // more of one sign, up to 2 of 6 at a corner's 4 x 4: 7 * 2 / 16).
    let a: Vec<u8> = (0..w * h).flat_map(|i| [if (i % w + i / w) % 2 == 0 { 107 } else { 93 }; 3]).collect();
    let bias = metrics::windowed_bias(&a, &vec![100; 3 * w * h], w, h, &all);
    assert!(bias.max <= 7.0 * 2.0 / 16.0 + 1e-12 && bias.p99 <= 7.0 * 2.0 / 16.0 + 1e-12, "{bias:?}");
    // One pixel 49 levels off: 1 level over its window's 49 pixels.
    let mut a = vec![100u8; 3 * w * h];
    a[3 * (10 * w + 10)] = 149;
    let bias = metrics::windowed_bias(&a, &vec![100; 3 * w * h], w, h, &all);
    assert_eq!(bias.max, 1.0);
    // Excluded pixels enter no window: a band of +50 outside the mask changes nothing.
    let mut include = all.clone();
    let mut a = vec![100u8; 3 * w * h];
    for x in 0..w {
        include[x] = false;
        a[3 * x..3 * x + 3].fill(150);
    }
    let bias = metrics::windowed_bias(&a, &vec![100; 3 * w * h], w, h, &include);
    assert_eq!((bias.p99, bias.max), (0.0, 0.0));
    let none = metrics::windowed_bias(&a, &a, w, h, &vec![false; w * h]);
    assert_eq!(none.max, 0.0);
}
