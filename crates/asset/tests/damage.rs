//! Damaged bytes: every flipped byte, every truncation and every lying length is an error that
//! names the problem, never a panic and never an allocation sized by the lie.

use asset::{
    Asset, BandwidthAnalysis, BandwidthAtlas, BandwidthPca, BandwidthRows, Error, HEADER_BYTES, ImportanceSamples,
    LinkedFile, Payload, PrefilteredEnvmap, decode, encode, read_file, write_file,
};

use crate::{reseal, small_asset};

/// Flipping these bits of a byte covers the lowest, the highest and all bits at once.
const MASKS: [u8; 3] = [0x01, 0x80, 0xff];

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap())
}

#[test]
fn every_flipped_byte_in_the_sections_is_a_checksum_mismatch() {
    let bytes = encode(&small_asset());
    for at in HEADER_BYTES..bytes.len() {
        for mask in MASKS {
            let mut damaged = bytes.clone();
            damaged[at] ^= mask;
            match decode(&damaged) {
                Err(Error::ChecksumMismatch { header, computed }) => {
                    assert_eq!(header.checksum, bytes[32..64]);
                    assert_eq!(computed, asset::sha256(&damaged[HEADER_BYTES..]));
                }
                other => {
                    panic!("byte {at} ^ {mask:#04x}: expected a checksum mismatch, got {other:?}")
                }
            }
        }
    }
}

/// What a flipped header byte must be reported as, by the field it falls in.
fn check_header_damage(at: usize, damaged: &[u8], result: Result<asset::Asset, Error>) {
    let field = |range: std::ops::Range<usize>| {
        let mut word = [0u8; 4];
        word.copy_from_slice(&damaged[range]);
        u32::from_le_bytes(word)
    };
    match (at, result) {
        (0..8, Err(Error::Invalid(message))) => assert!(message.contains("magic"), "{message}"),
        (8..12, Err(Error::UnsupportedVersion { found, .. })) => assert_eq!(found, field(8..12)),
        (12..16, Err(Error::UnknownKind { code })) => assert_eq!(code, field(12..16)),
        (16..32, Err(Error::LimitExceeded { .. })) => {}
        (16..32, Err(Error::Invalid(message)))
            if message.starts_with("truncated") || message.starts_with("trailing bytes") => {}
        (32..64, Err(Error::ChecksumMismatch { .. })) => {}
        (_, other) => panic!("header byte {at}: unexpected {other:?}"),
    }
}

#[test]
fn every_flipped_byte_in_the_header_is_named() {
    let bytes = encode(&small_asset());
    for at in 0..HEADER_BYTES {
        for mask in MASKS {
            let mut damaged = bytes.clone();
            damaged[at] ^= mask;
            check_header_damage(at, &damaged, decode(&damaged));
        }
    }
}

#[test]
fn every_truncation_is_invalid() {
    let bytes = encode(&small_asset());
    for len in 0..bytes.len() {
        match decode(&bytes[..len]) {
            Err(Error::Invalid(message)) => {
                assert!(message.starts_with("truncated"), "{len}: {message}")
            }
            other => panic!("{len} bytes: expected a truncation error, got {other:?}"),
        }
    }
}

#[test]
fn truncated_files_are_invalid() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = encode(&small_asset());
    for len in [0, 1, 8, 63, 64, 65, bytes.len() - 1] {
        let path = dir.path().join(format!("{len}.asset"));
        std::fs::write(&path, &bytes[..len]).unwrap();
        match read_file(&path) {
            Err(Error::Invalid(message)) => {
                assert!(message.starts_with("truncated"), "{len}: {message}")
            }
            other => panic!("{len} bytes: expected a truncation error, got {other:?}"),
        }
    }
}

#[test]
fn bytes_past_the_declared_end_are_invalid() {
    let mut bytes = encode(&small_asset());
    bytes.push(0);
    let message = decode(&bytes).unwrap_err().to_string();
    let expected = format!("trailing bytes: file has {} bytes, header declares {}", bytes.len(), bytes.len() - 1);
    assert!(message.starts_with(&expected), "{message}");
}

#[test]
fn the_unsupported_version_message_names_both_versions() {
    let mut bytes = encode(&small_asset());
    bytes[8..12].copy_from_slice(&7u32.to_le_bytes());
    assert_eq!(decode(&bytes).unwrap_err().to_string(), "unsupported format version 7: this build reads version 1");
}

#[test]
fn the_unknown_kind_message_names_the_number() {
    let mut bytes = encode(&small_asset());
    bytes[12..16].copy_from_slice(&9u32.to_le_bytes());
    assert_eq!(
        decode(&bytes).unwrap_err().to_string(),
        "unknown asset kind 9: this build knows 1 (material-info), 2 (importance-samples), 3 (prefiltered-envmap), \
         4 (bandwidth-atlas), 5 (bandwidth-pca), 6 (layer-selection), 7 (bandwidth-rows), 8 (wavelet-brdf)"
    );
}

#[test]
fn header_lengths_above_the_limits_are_refused_before_the_size_check() {
    let bytes = encode(&small_asset());
    let cases = [
        (16, asset::PROVENANCE_LIMIT + 1, "provenance"),
        (24, asset::PAYLOAD_LIMIT + 1, "payload"),
        (24, 1 << 60, "payload"),
    ];
    for (at, len, what) in cases {
        let mut damaged = bytes.clone();
        damaged[at..at + 8].copy_from_slice(&len.to_le_bytes());
        let message = decode(&damaged).unwrap_err().to_string();
        assert!(message.starts_with(&format!("{what} length {len} bytes exceeds the limit")), "{message}");
    }
}

#[test]
fn a_lying_length_inside_a_section_is_invalid_not_an_allocation() {
    let bytes = encode(&small_asset());
    let provenance_len = u64_at(&bytes, 16) as usize;
    // The first field of the provenance is `source_name`'s length; the first variable-size
    // field of the payload, `albedo_theta_o`'s length, follows 128 bytes of fixed-size fields
    // (see data-schema/README.md).
    let provenance_string = HEADER_BYTES;
    let payload_vec = HEADER_BYTES + provenance_len + 128;
    assert_eq!(u64_at(&bytes, payload_vec), 2, "the layout moved: update this test and the README");
    for (at, section) in [(provenance_string, "provenance"), (payload_vec, "payload")] {
        for lie in [1u64 << 40, 1 << 62, u64::MAX, 1000] {
            let mut damaged = bytes.clone();
            damaged[at..at + 8].copy_from_slice(&lie.to_le_bytes());
            reseal(&mut damaged);
            match decode(&damaged) {
                Err(Error::Invalid(message)) => {
                    assert!(message.starts_with(&format!("invalid {section}: ")), "{message}")
                }
                other => panic!("{section} length {lie}: expected invalid, got {other:?}"),
            }
        }
    }
}

#[test]
fn bytes_left_over_in_a_section_are_invalid() {
    let mut bytes = encode(&small_asset());
    let payload_len = u64_at(&bytes, 24);
    bytes[24..32].copy_from_slice(&(payload_len + 1).to_le_bytes());
    bytes.push(0);
    reseal(&mut bytes);
    let message = decode(&bytes).unwrap_err().to_string();
    assert!(message.starts_with("invalid payload: 1 trailing bytes"), "{message}");
}

#[test]
fn albedo_vectors_of_different_lengths_are_refused_on_write_and_read() {
    let mut asset = small_asset();
    let Payload::MaterialInfo(info) = &mut asset.payload else { unreachable!("small_asset is material info") };
    info.albedo_rgb.pop();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.asset");
    let message = write_file(&path, &asset).unwrap_err().to_string();
    assert!(message.contains("2 albedo angles but 1 albedo values"), "{message}");
    assert!(!path.exists());
    let message = decode(&encode(&asset)).unwrap_err().to_string();
    assert_eq!(
        message,
        "invalid payload: material info has 2 albedo angles but 1 albedo values and 2 no-data fractions"
    );
}

/// A valid prefiltered-envmap asset: three layers, exponents 1, 4, 16.
fn prefiltered_asset() -> Asset {
    let file = |name: &str| LinkedFile { name: name.into(), sha256: [7; 32] };
    let bandwidth = |n: f64| n.sqrt() / (2.0 * std::f64::consts::PI);
    Asset {
        provenance: small_asset().provenance,
        payload: PrefilteredEnvmap {
            source_size: [1024, 512],
            source_mean_radiance: [0.5, 0.4, 0.3],
            layer_size: [256, 128],
            mip_levels: 10,
            layers_radiance_scale: 1.0,
            mips_radiance_scale: 0.5,
            exponents: vec![1, 4, 16],
            lobe_bandwidth: vec![bandwidth(1.0), bandwidth(4.0), bandwidth(16.0)],
            bandwidth_thresholds: vec![bandwidth(2.0), bandwidth(8.0)],
            layer_mean_radiance: vec![[0.5, 0.4, 0.3]; 3],
            layers_ktx2: file("layers.ktx2"),
            layer_exrs: vec![file("layer-n1.exr"), file("layer-n4.exr"), file("layer-n16.exr")],
            mips_ktx2: file("mips.ktx2"),
            contact_sheet_png: file("contact-sheet.png"),
        }
        .into(),
    }
}

#[test]
fn prefiltered_envmap_invariants_are_refused_on_write_and_read() {
    type Edit = fn(&mut PrefilteredEnvmap);
    let cases: [(Edit, &str); 10] = [
        (|p| p.exponents = vec![1, 16, 4], "exponents must increase strictly, found 16 then 4"),
        (|p| p.exponents[0] = 0, "exponent 0: exponents start at 1"),
        (|p| p.layer_size = [256, 256], "layer size 256 x 256 is not a 2:1 lat-long map"),
        (|p| p.source_size = [0, 0], "source size 0 x 0 is not a 2:1 lat-long map"),
        (|p| p.mip_levels = 0, "has no mip levels"),
        (|p| p.bandwidth_thresholds.truncate(1), "bandwidth thresholds has 1 entries, expected 2"),
        (|p| p.bandwidth_thresholds[1] = 10.0, "threshold 1 (10) does not lie between the bandwidths of its layers"),
        (|p| p.mips_radiance_scale = 2.0, "mips radiance scale 2 outside (0, 1]"),
        (
            |p| p.layer_exrs[1].name = "../layer-n4.exr".into(),
            "linked file name \"../layer-n4.exr\" is not a plain file name",
        ),
        (|p| p.mips_ktx2.name = "layers.ktx2".into(), "names the file \"layers.ktx2\" twice"),
    ];
    let valid = prefiltered_asset();
    assert_eq!(decode(&encode(&valid)).unwrap(), valid);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.asset");
    for (edit, expected) in cases {
        let mut asset = valid.clone();
        let Payload::PrefilteredEnvmap(p) = &mut asset.payload else { unreachable!("a prefiltered envmap") };
        edit(p);
        let message = write_file(&path, &asset).unwrap_err().to_string();
        assert!(message.contains(expected), "{expected}: {message}");
        assert!(!path.exists());
        let message = decode(&encode(&asset)).unwrap_err().to_string();
        assert!(message.starts_with("invalid payload: prefiltered envmap"), "{message}");
        assert!(message.contains(expected), "{expected}: {message}");
    }
}

/// Rows of a bandwidth atlas (kind 7) with the sizes and stored values given.
fn rows_asset(lobes_x: u32, lobes_y: u32, tile: u32, values: usize) -> Asset {
    Asset {
        provenance: small_asset().provenance,
        payload: asset::BandwidthRows {
            lobes_x,
            lobes_y,
            tile,
            analysis: asset::BandwidthAnalysis { parameterization: "p".into(), analysis_size: 64, eps: 0.01, c: 0.25 },
            data: vec![0.5; values],
        }
        .into(),
    }
}

/// The sizes of a rows asset come from the file and are multiplied with overflow checks: claims
/// whose product exceeds 64 bits, or would wrap to the number of values stored in 32-bit
/// arithmetic (`954437177 x 3^2 = 2^33 + 1`), are refused on write and on read, like plainly
/// inconsistent ones; consistent sizes with one value pass.
#[test]
fn bandwidth_rows_sizes_are_multiplied_without_overflow() {
    let refused = [
        (
            1 << 31,
            1 << 31,
            1,
            1,
            "bandwidth rows of 2147483648 tiles of 1 x 1 texels hold 1 values, expected 2147483648",
        ),
        (1, u32::MAX, u32::MAX, 1, "hold 1 values, expected more than any file holds"),
        (1, 954_437_177, 3, 1, "hold 1 values, expected 8589934593"),
        (1 << 31, 1 << 16, 1 << 16, 1, "hold 1 values, expected 281474976710656"),
        (2, 1, 1, 0, "hold 0 values, expected 1"),
        (1, 0, 1, 0, "hold 0 values, expected 0 (and at least one)"),
        (0, 1, 1, 1, "stand for 0 columns of lobes: expected 1 to 4096"),
        // A file may not declare more columns than any incident grid has: expanding the rows
        // would hold that many times the file (fuzzing: 7 562 496 columns in 321 bytes).
        (4097, 1, 1, 1, "stand for 4097 columns of lobes: expected 1 to 4096"),
        (7_562_496, 2, 2, 8, "stand for 7562496 columns"),
    ];
    for (lobes_x, lobes_y, tile, values, message) in refused {
        let asset = rows_asset(lobes_x, lobes_y, tile, values);
        let written = asset::encode_checked(&asset).unwrap_err().to_string();
        assert!(
            written.starts_with("refusing to write an invalid payload: ") && written.contains(message),
            "{written}"
        );
        let read = decode(&encode(&asset)).unwrap_err().to_string();
        assert!(read.starts_with("invalid payload: ") && read.contains(message), "{read}");
    }
    // The most columns an incident grid has, of one row of one texel: consistent.
    for (lobes_x, lobes_y, tile, values) in [(asset::MAX_ROWS_COLUMNS, 1, 1, 1), (64, 2, 3, 18)] {
        let asset = rows_asset(lobes_x, lobes_y, tile, values);
        assert_eq!(decode(&asset::encode_checked(&asset).unwrap()).unwrap(), asset);
    }
}

/// Every size a payload declares is multiplied with checked arithmetic: counts whose product
/// wraps past 2^64 to the length the file holds must be refused, not accepted (release builds
/// accepted such files, debug builds panicked: `../shared/data/hostile/repro-pca-wrapped-check.asset`
/// and its siblings, made here for every kind that multiplies counts from the file).
#[test]
fn declared_sizes_that_wrap_are_invalid_not_accepted() {
    let analysis = || BandwidthAnalysis {
        parameterization: "incidence-plane-equidistant".into(),
        analysis_size: 64,
        eps: 0.01,
        c: 0.17,
    };
    let wrapped = [
        // 4 x 2^31 x 2^31 = 2^64 samples, stored as 0.
        (
            "importance samples",
            Payload::ImportanceSamples(ImportanceSamples {
                theta_o: vec![0.0, 0.1, 0.2, 0.3],
                n_vectors: 1 << 31,
                n_samples: 1 << 31,
                theta_h_edges: vec![0.0, 1.0],
                n_phi_h: 1,
                samples: vec![],
                marginal_cdf: vec![0.0; 8],
                conditional_cdf: vec![0.0; 8],
                h_density: vec![1.0; 4],
            }),
        ),
        // 2^16 x 2^16 lobes of 2^16 x 2^16 texels = 2^64 texels, stored as 0.
        (
            "bandwidth atlas",
            Payload::BandwidthAtlas(BandwidthAtlas {
                lobes_x: 1 << 16,
                lobes_y: 1 << 16,
                tile: 1 << 16,
                analysis: analysis(),
                data: vec![],
            }),
        ),
        // 2^32 rows of 2^16 x 2^16 texels wraps in u64 too: 2^64 stored as 0.
        (
            "bandwidth rows",
            Payload::BandwidthRows(BandwidthRows {
                lobes_x: 1,
                lobes_y: u32::MAX,
                tile: 1 << 16,
                analysis: analysis(),
                data: vec![],
            }),
        ),
        // 2^31 x 2^31 lobes x K = 4 coefficients = 2^64, stored as 0 (the hostile file's lie).
        (
            "bandwidth pca",
            Payload::BandwidthPca(BandwidthPca {
                lobes_x: 1 << 31,
                lobes_y: 1 << 31,
                tile: 1,
                analysis: analysis(),
                n_components: 4,
                mean: vec![0.0],
                components: vec![1.0, 0.0, 0.0, 0.0],
                coefficients: vec![],
            }),
        ),
    ];
    for (what, payload) in wrapped {
        let asset = Asset { provenance: small_asset().provenance, payload };
        match decode(&encode(&asset)) {
            Err(Error::Invalid(message)) => assert!(message.starts_with("invalid payload: "), "{what}: {message}"),
            other => panic!("{what}: expected an invalid payload, got {other:?}"),
        }
    }
}
