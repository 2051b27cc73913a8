//! The real maps in ../shared/data/env load with the right size and the values an independent
//! decoder gives. Reference values: tests/reference/spot_values.py (the reference OpenEXR library
//! for EXR, a separate RGBE reader for HDR). Both give exact `f32` values (RGBE mantissa times a
//! power of two, `f16` widened), so texels compare exactly; the means are sums of about 1.5
//! million values in a different order, and the script printed 9 digits: 1e-8 relative.

// The literals are the exact decimal expansions of the f32 values (RGBE and f16 values are
// dyadic), as the reference script prints them, so that provenance is visible digit for digit.
#![allow(clippy::excessive_precision)]

use crate::{assert_close, shared_env};

struct Expect {
    file: &'static str,
    max: f32,
    /// (x, y, channel) of the first maximum in row-major order.
    max_at: (usize, usize, usize),
    /// Plain mean over all texels and channels (the README's "mean").
    mean: f64,
    weighted_mean: [f64; 3],
    spots: [(usize, usize, [f32; 3]); 4],
}

const MAPS: &[Expect] = &[
    Expect {
        file: "quarry_01_1k.hdr",
        max: 86528.0,
        max_at: (614, 227, 0),
        mean: 0.465756585,
        weighted_mean: [0.763200716, 0.659417737, 0.475235356],
        spots: [
            (0, 0, [0.0517578125, 0.119140625, 0.2041015625]),
            (341, 102, [0.068359375, 0.1484375, 0.25]),
            (1023, 256, [0.39453125, 0.326171875, 0.16796875]),
            (512, 511, [0.24609375, 0.1943359375, 0.138671875]),
        ],
    },
    Expect {
        file: "potsdamer_platz_1k.hdr",
        max: 11.8125,
        max_at: (366, 197, 0),
        mean: 0.714065256,
        weighted_mean: [0.560510534, 0.549579042, 0.638718986],
        spots: [
            (0, 0, [1.8125, 1.90625, 2.28125]),
            (341, 102, [1.921875, 1.96875, 2.328125]),
            (1023, 256, [0.08544921875, 0.08447265625, 0.0908203125]),
            (512, 511, [0.171875, 0.08984375, 0.0859375]),
        ],
    },
    Expect {
        file: "studio_small_03_1k.hdr",
        max: 3568.0,
        max_at: (235, 133, 2),
        mean: 1.88191313,
        weighted_mean: [1.96813281, 2.26062185, 2.54910237],
        spots: [
            (0, 0, [0.0064697265625, 0.007568359375, 0.00909423828125]),
            (341, 102, [0.003448486328125, 0.004180908203125, 0.0068359375]),
            (1023, 256, [0.003570556640625, 0.004425048828125, 0.005157470703125]),
            (512, 511, [0.52734375, 0.6328125, 0.70703125]),
        ],
    },
    Expect {
        file: "piz_compressed.exr",
        max: 19.96875,
        max_at: (389, 120, 2),
        mean: 0.202551355,
        weighted_mean: [0.209113909, 0.203875264, 0.199441528],
        spots: [
            (0, 0, [0.311279296875, 0.282470703125, 0.274658203125]),
            (341, 102, [0.2276611328125, 0.1912841796875, 0.1754150390625]),
            (1023, 256, [0.312744140625, 0.25, 0.156982421875]),
            (512, 511, [0.049530029296875, 0.0352783203125, 0.023895263671875]),
        ],
    },
    Expect {
        // Tiled, mip-mapped, ZIP, with an alpha channel: the full-resolution level, RGB only.
        file: "KernerEnvLatLong.exr",
        max: 1678.0,
        max_at: (721, 197, 0),
        mean: 0.165201442,
        weighted_mean: [0.14663367, 0.189851033, 0.263231542],
        spots: [
            (0, 0, [0.041046142578125, 0.0858154296875, 0.1815185546875]),
            (341, 102, [0.03607177734375, 0.08197021484375, 0.1744384765625]),
            (1023, 256, [0.28466796875, 0.326171875, 0.358642578125]),
            (512, 511, [0.07147216796875, 0.076171875, 0.08917236328125]),
        ],
    },
];

#[test]
fn every_real_map_is_covered() {
    let Some(env) = shared_env() else { return };
    let mut expected: Vec<&str> = MAPS.iter().map(|e| e.file).collect();
    expected.sort();
    assert_eq!(crate::file_names(&env, &["README.md", "decoder"]), expected);
}

#[test]
fn real_maps_load_with_the_reference_values() {
    let Some(env) = shared_env() else { return };
    for expect in MAPS {
        let path = env.join(expect.file);
        let map = envmap::load(&path).unwrap_or_else(|e| panic!("loading {}: {e}", expect.file));
        assert_eq!((map.width(), map.height()), (1024, 512), "{}", expect.file);
        for &(x, y, rgb) in &expect.spots {
            assert_eq!(map.texel(x, y), rgb, "{} texel ({x}, {y})", expect.file);
        }
        let (at, max) = map
            .rgb()
            .iter()
            .enumerate()
            .fold((0, f32::MIN), |(at, max), (i, &v)| if v > max { (i, v) } else { (at, max) });
        assert_eq!(max, expect.max, "{} max", expect.file);
        assert_eq!((at / 3 % 1024, at / 3 / 1024, at % 3), expect.max_at, "{} max at", expect.file);
        let mean = map.rgb().iter().map(|&v| f64::from(v)).sum::<f64>() / map.rgb().len() as f64;
        assert_close(mean, expect.mean, 1e-8, &format!("{} mean", expect.file));
        for (c, (got, want)) in map.mean_radiance().into_iter().zip(expect.weighted_mean).enumerate() {
            assert_close(got, want, 1e-8, &format!("{} weighted mean channel {c}", expect.file));
        }
    }
}

/// The README's plausibility figures, independent of the script above.
#[test]
fn real_maps_match_the_readme() {
    let Some(env) = shared_env() else { return };
    let max = |file: &str| {
        let map = envmap::load(&env.join(file)).expect(file);
        map.rgb().iter().copied().fold(0.0f32, f32::max)
    };
    assert!((86_000.0..87_000.0).contains(&max("quarry_01_1k.hdr")));
    assert_eq!(max("potsdamer_platz_1k.hdr"), 11.8125);
    assert_eq!(max("studio_small_03_1k.hdr"), 3568.0);
    assert!((19.5..20.5).contains(&max("piz_compressed.exr")));
}

#[test]
fn the_format_comes_from_the_content_not_the_extension() {
    let Some(env) = shared_env() else { return };
    let dir = tempfile::tempdir().expect("temporary folder");
    for (source, renamed) in [("piz_compressed.exr", "map.hdr"), ("potsdamer_platz_1k.hdr", "map.exr")] {
        let original = envmap::load(&env.join(source)).expect(source);
        let path = dir.path().join(renamed);
        std::fs::copy(env.join(source), &path).expect("copy");
        assert_eq!(envmap::load(&path).expect(renamed), original, "{source} renamed {renamed}");
    }
}

/// Every prefix of a real file is `Invalid`, never a panic and never a map with silently missing
/// texels. The one exception: a mip-mapped file stores its smaller levels after the full-resolution
/// one, and only that one is read, so a cut among the smaller levels loads the complete map.
#[test]
fn every_truncation_of_a_real_file_is_invalid() {
    use rand::{Rng, SeedableRng};

    let Some(env) = shared_env() else { return };
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for file in ["potsdamer_platz_1k.hdr", "piz_compressed.exr", "KernerEnvLatLong.exr"] {
        let bytes = std::fs::read(env.join(file)).expect(file);
        let full = envmap::load_from_memory(&bytes, &envmap::Limits::default()).expect(file);
        let mut lengths: Vec<usize> = (0..80).collect();
        lengths.extend((0..40).map(|_| rng.random_range(0..bytes.len())));
        lengths.push(bytes.len() - 1);
        for length in lengths {
            let what = format!("{file} cut to {length} bytes");
            let result =
                crate::no_panic(&what, || envmap::load_from_memory(&bytes[..length], &envmap::Limits::default()));
            match result {
                Ok(map) => {
                    assert!(file == "KernerEnvLatLong.exr" && length > bytes.len() / 2, "{what}: loaded");
                    assert!(map == full, "{what}: loaded a map that differs from the whole file's");
                }
                Err(e) => assert_eq!(crate::kind(&e), crate::Kind::Invalid, "{what}: {e}"),
            }
        }
    }
}
