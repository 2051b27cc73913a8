//! The awkward files in ../shared/data/env/decoder: each decodes correctly (read_image, any shape)
//! and, none being 2:1, `load` rejects each with a clear message. Values: the independent decoders
//! of tests/reference/spot_values.py.

// The literals are the exact decimal expansions of the f32 values (RGBE and f16 values are
// dyadic), as the reference script prints them, so that provenance is visible digit for digit.
#![allow(clippy::excessive_precision)]

use std::path::{Path, PathBuf};

/// `../shared/data/env/decoder`, or `None` when the test is to skip.
fn decoder_dir() -> Option<PathBuf> {
    crate::shared_env().map(|env| env.join("decoder"))
}

fn read(dir: &Path, name: &str) -> envmap::HdrImage {
    let path = dir.join(name);
    crate::no_panic(name, || envmap::read_image(&path, &envmap::Limits::default()))
        .unwrap_or_else(|e| panic!("reading {name}: {e}"))
}

fn texel(image: &envmap::HdrImage, x: usize, y: usize) -> [f32; 3] {
    let i = 3 * (y * image.width + x);
    [image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]]
}

/// (file, size, what `load` says).
const EXPECTED: &[(&str, (usize, usize), &str)] = &[
    ("imagers_old-rle.hdr", (551, 276), "not a lat-long map: 551 x 276, expected width = 2 x height"),
    ("imagers_rgbr4x4.hdr", (4, 4), "not a lat-long map: 4 x 4, expected width = 2 x height"),
    ("imagers_scale.hdr", (256, 8), "not a lat-long map: 256 x 8, expected width = 2 x height"),
    ("memorial.exr", (512, 768), "not a lat-long map: 512 x 768, expected width = 2 x height"),
];

#[test]
fn every_decoder_file_has_an_expected_outcome() {
    let Some(dir) = decoder_dir() else { return };
    let expected: Vec<&str> = EXPECTED.iter().map(|e| e.0).collect();
    assert_eq!(crate::file_names(&dir, &[]), expected);
}

#[test]
fn decoder_files_decode_and_are_rejected_as_maps() {
    let Some(dir) = decoder_dir() else { return };
    for &(name, size, message) in EXPECTED {
        let image = read(&dir, name);
        assert_eq!((image.width, image.height), size, "{name}");
        let path = dir.join(name);
        let error = crate::no_panic(name, || envmap::load(Path::new(&path))).expect_err(name);
        assert!(matches!(error, envmap::Error::Invalid(_)), "{name}: {error}");
        assert_eq!(error.to_string(), message, "{name}");
    }
}

/// The old (pre-1991) run-length scheme: the image is two colours split by the diagonal.
#[test]
fn old_run_length_scheme() {
    let Some(dir) = decoder_dir() else { return };
    let image = read(&dir, "imagers_old-rle.hdr");
    for y in 0..image.height {
        for x in 0..image.width {
            let want = if x < y { [0.375, 0.25, 0.125] } else { [0.125, 0.25, 0.375] };
            assert_eq!(texel(&image, x, y), want, "texel ({x}, {y})");
        }
    }
}

/// Exponents up to 255: values up to 1.7e38 stay finite and exact (the literals are the shortest
/// decimal forms of the exact f32 values).
#[test]
fn extreme_exponents() {
    let Some(dir) = decoder_dir() else { return };
    let image = read(&dir, "imagers_scale.hdr");
    assert_eq!(texel(&image, 0, 0), [0.0, 0.0, 0.0]);
    assert_eq!(texel(&image, 85, 1), [5.684342e-14, 4.440892e-16, 1.1279866e-13]);
    assert_eq!(texel(&image, 255, 4), [8.507059e37, 5.316912e36, 1.6415966e38]);
    assert_eq!(texel(&image, 128, 7), [0.5, 0.25, 0.74609375]);
    let max = image.rgb.iter().copied().fold(0.0f32, f32::max);
    assert_eq!(max, 1.694_765_7e38);
}

/// A file narrower than 8 texels is always stored flat (no run-length encoding).
#[test]
fn tiny_flat_file() {
    let Some(dir) = decoder_dir() else { return };
    let image = read(&dir, "imagers_rgbr4x4.hdr");
    let rows = [[0.00994873046875, 0.0, 0.0], [0.0, 0.099609375, 0.0], [0.0, 0.0, 1.0], [10.0, 1.0, 0.0625]];
    for (y, row) in rows.iter().enumerate() {
        for x in 0..4 {
            assert_eq!(texel(&image, x, y), *row, "texel ({x}, {y})");
        }
    }
}

#[test]
fn portrait_exr() {
    let Some(dir) = decoder_dir() else { return };
    let image = read(&dir, "memorial.exr");
    assert_eq!(texel(&image, 0, 0), [0.000457763671875, 0.000720977783203125, 0.0008697509765625]);
    assert_eq!(texel(&image, 170, 153), [11.6875, 12.3125, 11.0]);
    assert_eq!(texel(&image, 511, 384), [0.041748046875, 0.025634765625, 0.007568359375]);
    assert_eq!(texel(&image, 256, 767), [0.059326171875, 0.0341796875, 0.01318359375]);
}
