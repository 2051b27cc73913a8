//! Outputs: EXR round trips, PNG previews, and the errors of both writers.

use envmap::{EnvMap, SampleType, ToneMap, ToneMapping};
use rand::{Rng, SeedableRng};

use crate::shared_env;

fn random_map(width: usize, height: usize, seed: u64, max: f32) -> EnvMap {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut rgb: Vec<f32> = (0..3 * width * height).map(|_| rng.random_range(0.0..1.0f32).powi(4) * max).collect();
    // Exact zero, the smallest normal and a subnormal.
    rgb[0] = 0.0;
    rgb[1] = f32::MIN_POSITIVE;
    rgb[2] = 1e-40;
    EnvMap::new(width, height, rgb).expect("map")
}

/// Only the written file is in the folder afterwards: no temporary files left.
fn assert_only(dir: &std::path::Path, names: &[&str]) {
    assert_eq!(crate::file_names(dir, &[]), names);
}

#[test]
fn exr_round_trip_f32_is_exact() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("map.exr");
    let map = random_map(64, 32, 11, 86_528.0);
    map.write_exr(&path, SampleType::F32).expect("write");
    assert_only(dir.path(), &["map.exr"]);
    assert_eq!(envmap::load(&path).expect("load"), map);
    // A real map too.
    let Some(env) = shared_env() else { return };
    let quarry = envmap::load(&env.join("quarry_01_1k.hdr")).expect("quarry");
    quarry.write_exr(&path, SampleType::F32).expect("write quarry");
    assert_eq!(envmap::load(&path).expect("load quarry"), quarry);
}

/// f16 rounds each value to the nearest half; values past 65504 are an error, not infinity.
#[test]
fn exr_round_trip_f16() {
    use exr::prelude::f16;

    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("map.exr");
    let map = random_map(64, 32, 12, 60_000.0);
    map.write_exr(&path, SampleType::F16).expect("write");
    let back = envmap::load(&path).expect("load");
    for (i, (&got, &want)) in back.rgb().iter().zip(map.rgb()).enumerate() {
        assert_eq!(got, f16::from_f32(want).to_f32(), "value {i}");
        assert!((got - want).abs() <= want * 2f32.powi(-11) + 6e-8, "value {i}: {got} vs {want}");
    }
    let bright = random_map(64, 32, 13, 86_528.0);
    let error = bright.write_exr(&path, SampleType::F16).expect_err("sun in f16");
    assert!(error.to_string().contains("does not fit in f16 (largest 65504)"), "{error}");
    // The failed write left the earlier file alone.
    assert_eq!(envmap::load(&path).expect("still there"), back);
}

/// A single Y channel: written as a float channel named Y, read back as grey.
#[test]
fn exr_single_channel() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("table.exr");
    let y: Vec<f32> = (0..32 * 5).map(|i| i as f32 * 0.25).collect();
    envmap::write_exr(&path, 32, 5, &[("Y", &y)], SampleType::F32).expect("write");
    let image = envmap::read_image(&path, &envmap::Limits::default()).expect("read");
    assert_eq!((image.width, image.height), (32, 5));
    let grey: Vec<f32> = y.iter().flat_map(|&v| [v, v, v]).collect();
    assert_eq!(image.rgb, grey);
    // What is in the file, by the exr crate itself.
    let file = exr::prelude::read_first_flat_layer_from_file(&path).expect("exr");
    let channels = &file.layer_data.channel_data.list;
    assert_eq!(channels.len(), 1);
    assert_eq!(channels[0].name, *"Y");
    assert!(matches!(channels[0].sample_data, exr::prelude::FlatSamples::F32(_)));
}

#[test]
fn exr_writer_rejects_bad_input() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("bad.exr");
    let ok = vec![1.0f32; 8];
    let nan = [vec![1.0; 5], vec![f32::NAN], vec![1.0; 2]].concat();
    type Channels<'a> = Vec<(&'a str, &'a [f32])>;
    let cases: [(usize, usize, Channels, &str); 7] = [
        (0, 4, vec![("Y", &ok[..0])], "empty image: 0 x 4"),
        (4, 2, vec![], "no channels to write"),
        (4, 2, vec![("Y", &ok[..7])], "channel Y has 7 values, a 4 x 2 image needs 8"),
        (4, 2, vec![("R", &ok), ("R", &ok)], "channel R given twice"),
        (4, 2, vec![("", &ok)], "channel name \"\" is empty or not latin-1"),
        (4, 2, vec![("\u{3b1}\u{3b2}", &ok)], "is empty or not latin-1"),
        (4, 2, vec![("Y", &nan)], "channel Y: non-finite value NaN at x 1, y 1"),
    ];
    for (width, height, channels, message) in cases {
        let error = envmap::write_exr(&path, width, height, &channels, SampleType::F32).expect_err(message);
        assert!(matches!(error, envmap::Error::Invalid(_)), "{error}");
        assert!(error.to_string().contains(message), "{error}");
    }
    assert_only(dir.path(), &[]);
}

#[test]
fn png_preview_reads_back() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let Some(env) = shared_env() else { return };
    let path = dir.path().join("preview.png");
    let map = envmap::load(&env.join("studio_small_03_1k.hdr")).expect("studio");
    map.write_preview_png(&path, &ToneMapping::default()).expect("write");
    assert_only(dir.path(), &["preview.png"]);
    let image = image::open(&path).expect("png");
    assert_eq!((image.width(), image.height()), (1024, 512));
    assert_eq!(image.color(), image::ColorType::Rgb8);
    let want = envmap::tonemap_rgb8(map.rgb(), &ToneMapping::default());
    assert_eq!(image.into_rgb8().into_raw(), want);
}

/// Known values of the curves: sRGB(0.5) = 0.7354 -> 188, sRGB(0.0031308) = 0.0404 -> 10.
#[test]
fn tone_mapping() {
    let clamp = ToneMapping { exposure_ev: 0.0, tone_map: ToneMap::Clamp };
    assert_eq!(envmap::tonemap_rgb8(&[0.0, 0.5, 1.0, 7.0, 0.003_130_8], &clamp), [0, 188, 255, 255, 10]);
    let reinhard = ToneMapping::default();
    assert_eq!(envmap::tonemap_rgb8(&[0.0, 1.0, f32::INFINITY, f32::NAN, -1.0], &reinhard), [0, 188, 255, 0, 0]);
    let brighter = ToneMapping { exposure_ev: 1.0, tone_map: ToneMap::Clamp };
    assert_eq!(envmap::tonemap_rgb8(&[0.25, 0.5], &brighter), [188, 255]);
}

#[test]
fn png_writer_rejects_bad_input() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let path = dir.path().join("bad.png");
    let cases: [(usize, usize, usize, &str); 3] = [
        (4, 2, 23, "4 x 2 rgb image needs 24 bytes, got 23"),
        (0, 2, 0, "empty image: 0 x 2"),
        (1 << 33, 1, 0, "too large for png"),
    ];
    for (width, height, len, message) in cases {
        let error = envmap::write_png_rgb8(&path, width, height, &vec![0; len]).expect_err(message);
        assert!(error.to_string().contains(message), "{error}");
    }
    assert_only(dir.path(), &[]);
}
