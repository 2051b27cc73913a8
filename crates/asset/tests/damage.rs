//! Damaged bytes: every flipped byte, every truncation and every lying length is an error that
//! names the problem, never a panic and never an allocation sized by the lie.

use asset::{Error, HEADER_BYTES, Payload, decode, encode, read_file, write_file};

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
        "unknown asset kind 9: this build knows 1 (material-info), 2 (importance-samples)"
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
