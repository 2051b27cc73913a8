//! The damaged files in fixtures/invalid/envmap/ (made by fixtures/invalid/envmap/make_invalid.py, described in its
//! README): each gives the expected kind of error with a message that names the problem, and
//! none makes a reader panic.

use crate::{Kind, invalid_dir};

/// (file, kind, text the message contains).
const EXPECTED: &[(&str, Kind, &str)] = &[
    ("bad_dimensions.hdr", Kind::Invalid, "height"),
    ("empty.hdr", Kind::Invalid, "empty file"),
    ("garbage_chunks.exr", Kind::Invalid, "openexr"),
    ("garbage_data.hdr", Kind::Invalid, "scanline"),
    ("header_only.exr", Kind::Invalid, "openexr"),
    ("huge.exr", Kind::Limit, "32768 x 16384 is larger than the limit of 16384 x 8192"),
    ("huge.hdr", Kind::Limit, "32768 x 16384 is larger than the limit of 16384 x 8192"),
    ("magic_only.exr", Kind::Invalid, "openexr"),
    ("missing_dimensions.hdr", Kind::Invalid, "dimensions"),
    ("nan.exr", Kind::Invalid, "non-finite radiance NaN at x 3, y 1, channel G"),
    ("negative.exr", Kind::Invalid, "negative radiance -0.5 at x 5, y 2, channel B"),
    ("no_rgb.exr", Kind::Unsupported, "no R, G, B or Y channels (found Z)"),
    ("not_2to1.exr", Kind::Invalid, "not a lat-long map: 8 x 8, expected width = 2 x height"),
    ("not_2to1.hdr", Kind::Invalid, "not a lat-long map: 8 x 8, expected width = 2 x height"),
    ("not_an_image.png", Kind::Unsupported, "unknown file format (starts with 89 50 4e 47)"),
    ("reversed_window.exr", Kind::Invalid, "openexr"),
    ("rotated.hdr", Kind::Unsupported, "orientation"),
    ("signature_only.hdr", Kind::Invalid, "signature line"),
    ("truncated.exr", Kind::Invalid, "openexr"),
    ("truncated_data.hdr", Kind::Invalid, "truncated"),
    ("truncated_header.hdr", Kind::Invalid, "header"),
    ("truncated_offsets.exr", Kind::Invalid, "openexr"),
    ("uint.exr", Kind::Unsupported, "channel R holds u32 samples"),
    ("xyze.hdr", Kind::Unsupported, "xyze"),
    ("zero_size.hdr", Kind::Invalid, "empty map: 0 x 0"),
];

#[test]
fn every_damaged_file_has_an_expected_outcome() {
    let expected: Vec<&str> = EXPECTED.iter().map(|e| e.0).collect();
    assert_eq!(crate::file_names(&invalid_dir(), &["README.md", "make_invalid.py"]), expected);
}

#[test]
fn every_damaged_file_is_an_error_naming_the_problem() {
    let mut failures = Vec::new();
    for &(name, want_kind, text) in EXPECTED {
        let path = invalid_dir().join(name);
        let result = crate::no_panic(name, || envmap::load(&path));
        let also = crate::no_panic(name, || envmap::read_image(&path, &envmap::Limits::default()));
        match result {
            Ok(_) => failures.push(format!("{name}: loaded")),
            Err(e) => {
                let message = e.to_string();
                if crate::kind(&e) != want_kind || !message.to_lowercase().contains(&text.to_lowercase()) {
                    failures.push(format!(
                        "{name}: expected {want_kind:?} containing {text:?}, got {:?}: {message}",
                        crate::kind(&e)
                    ));
                }
                if message.chars().next().is_some_and(char::is_uppercase) || message.ends_with('.') {
                    failures.push(format!("{name}: message not lower case without a period: {message}"));
                }
            }
        }
        // Only the shape check differs between `load` and `read_image`.
        if !name.starts_with("not_2to1") {
            match also {
                Ok(_) => failures.push(format!("{name}: read_image succeeded")),
                Err(e) => assert_eq!(crate::kind(&e), want_kind, "{name}: read_image: {e}"),
            }
        }
    }
    assert!(failures.is_empty(), "{} of {} files:\n{}", failures.len(), EXPECTED.len(), failures.join("\n"));
}

#[test]
fn a_missing_file_is_an_io_error() {
    let error = envmap::load(&invalid_dir().join("does_not_exist.hdr")).expect_err("missing file");
    assert_eq!(crate::kind(&error), Kind::Io, "{error}");
}

/// The limit is checked from the header: a tiny file that claims a big map is refused under a
/// small limit, and the same file loads under the default one.
#[test]
fn limits_come_from_the_header() {
    let Some(env) = crate::shared_env() else { return };
    let path = env.join("potsdamer_platz_1k.hdr");
    let small = envmap::Limits { max_width: 1023, max_height: 8192, ..Default::default() };
    let error = envmap::load_with_limits(&path, &small).expect_err("over the limit");
    assert_eq!(error.to_string(), "limit exceeded: 1024 x 512 is larger than the limit of 1023 x 8192");
    let exact = envmap::Limits { max_width: 1024, max_height: 512, ..Default::default() };
    assert!(envmap::load_with_limits(&path, &exact).is_ok());
    let exr = env.join("KernerEnvLatLong.exr");
    let error =
        envmap::load_with_limits(&exr, &envmap::Limits { max_width: 1024, max_height: 511, ..Default::default() })
            .expect_err("exr");
    assert_eq!(crate::kind(&error), Kind::Limit, "{error}");
}

/// The memory a job needs is estimated from the header and refused over the budget, before any
/// decoding: a 98 KB old-RLE file declaring 16384 x 8192 would otherwise make `envmap-prefilter`
/// abort on a 1.4 GB allocation under a 4 GB address-space limit.
#[test]
fn the_memory_budget_comes_from_the_header() {
    let Some(shared) = crate::shared_data::shared_or_skip(&["data/env", "data/hostile"]) else { return };
    let path = shared.join("data/env/potsdamer_platz_1k.hdr");
    let error = envmap::load_with_limits(&path, &envmap::Limits::for_job(64, 1 << 20)).expect_err("over budget");
    assert_eq!(
        error.to_string(),
        "limit exceeded: a 1024 x 512 map needs about 32 MiB for this job (64 bytes per texel), more than the \
         memory budget of 1 MiB (--max-memory)"
    );
    assert!(envmap::load_with_limits(&path, &envmap::Limits::for_job(64, 32 << 20)).is_ok());

    let hostile = shared.join("data/hostile/repro-oldrle-16384x8192-abort.hdr");
    let job = envmap::Limits::for_job(48, envmap::DEFAULT_MAX_MEMORY);
    let error = envmap::load_with_limits(&hostile, &job).expect_err("over budget");
    assert_eq!(crate::kind(&error), Kind::Limit, "{error}");
    assert!(error.to_string().contains("a 16384 x 8192 map needs about 6 GiB"), "{error}");
    // The estimate is reserved once, fallibly: more than any system gives is an error, not an
    // abort.
    let error = envmap::load_with_limits(&path, &envmap::Limits::for_job(1 << 50, u64::MAX)).expect_err("unreservable");
    assert!(error.to_string().contains("the system cannot provide it"), "{error}");
}

/// An OpenEXR header that declares more pixels than the file can hold is truncated, found before
/// the image is allocated: an 808-byte header declaring the size limit would otherwise reach
/// 790 MB before "truncated". Made from a small valid file by widening its data window to 16384 x
/// 8192 and cutting it after the header.
#[test]
fn an_exr_header_at_the_size_limit_is_truncated_before_allocating() {
    let ramp: Vec<f32> = (0..32 * 16).map(|i| i as f32).collect();
    let mut bytes =
        envmap::encode_exr(32, 16, &[("R", &ramp), ("G", &ramp), ("B", &ramp)], envmap::SampleType::F32).expect("exr");
    let name = b"dataWindow\0box2i\0";
    let at = bytes.windows(name.len()).position(|w| w == name).expect("a data window") + name.len() + 4;
    bytes[at + 8..at + 12].copy_from_slice(&16383i32.to_le_bytes());
    bytes[at + 12..at + 16].copy_from_slice(&8191i32.to_le_bytes());
    // The chunk count the writer recorded follows the height: 16 rows became 8192.
    let name = b"chunkCount\0int\0";
    if let Some(p) = bytes.windows(name.len()).position(|w| w == name) {
        let at = p + name.len() + 4;
        let count = i32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        bytes[at..at + 4].copy_from_slice(&(count * 512).to_le_bytes());
    }
    let header_end = bytes.windows(3).rposition(|w| w == b"\0\0\0").map_or(bytes.len(), |p| p + 3).min(900);
    bytes.truncate(header_end);
    let error = envmap::read_image_from_memory(&bytes, &envmap::Limits::default()).expect_err("truncated");
    assert_eq!(crate::kind(&error), Kind::Invalid, "{error}");
    assert!(error.to_string().starts_with("openexr: truncated: a 16384 x 8192 image in "), "{error}");
    println!("{error}");
}

/// Damaged B44 files that make the `exr` crate (1.74.2) overflow in its B44 decompressor: with
/// overflow checks on, as in this test build, that panic inside the crate's thread pool aborted
/// the whole test process; the reader decodes B44 on its own thread and reports the file as
/// damaged (a release build reports the crate's own error).
#[test]
fn damaged_b44_files_are_errors_in_a_debug_build() {
    let Some(shared) = crate::shared_data::shared_or_skip(&["data/hostile"]) else { return };
    let hostile = shared.join("data/hostile");
    let mut files: Vec<_> = std::fs::read_dir(&hostile)
        .expect("the shared hostile inputs")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("b44-overflow-")))
        .collect();
    files.sort();
    assert_eq!(files.len(), 4, "expected the 4 b44-overflow-*.exr files in {}", hostile.display());
    for path in files {
        let error = envmap::read_image(&path, &envmap::Limits::default()).expect_err("damaged");
        println!("{}: {error}", path.display());
    }
}

/// Random byte damage (fixed seed) to small valid files of every kind: any outcome but a panic.
/// Damage to pixel data may well decode (to other values); damage to headers, offset tables and
/// run lengths must be an error.
#[test]
fn random_damage_never_panics() {
    use rand::{Rng, SeedableRng};

    let ramp: Vec<f32> = (0..32 * 16).map(|i| i as f32 * 0.125).collect();
    let channels: [(&str, &[f32]); 3] = [("R", &ramp), ("G", &ramp), ("B", &ramp)];
    let mut sources = vec![
        ("f32 exr".to_string(), envmap::encode_exr(32, 16, &channels, envmap::SampleType::F32).expect("exr")),
        ("f16 exr".to_string(), envmap::encode_exr(32, 16, &channels, envmap::SampleType::F16).expect("exr")),
    ];
    if let Some(env) = crate::shared_env() {
        for name in ["imagers_rgbr4x4.hdr", "imagers_old-rle.hdr"] {
            let path = env.join("decoder").join(name);
            sources.push((name.to_string(), std::fs::read(&path).expect(name)));
        }
    }
    let limits = envmap::Limits::default();
    let mut rng = rand::rngs::StdRng::seed_from_u64(17);
    for (name, bytes) in &sources {
        for i in 0..1000 {
            let mut damaged = bytes.clone();
            for _ in 0..rng.random_range(1..5) {
                let at = rng.random_range(0..damaged.len());
                damaged[at] = rng.random();
            }
            if i % 10 == 0 {
                damaged.truncate(rng.random_range(0..damaged.len()));
            }
            let _ =
                crate::no_panic(&format!("{name} damage {i}"), || envmap::read_image_from_memory(&damaged, &limits));
        }
    }
}
