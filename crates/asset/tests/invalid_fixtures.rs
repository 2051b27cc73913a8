//! The damaged asset files committed in `fixtures/invalid/`: each is derived from the golden v1
//! file by one edit, and each is rejected with a message that names its problem.

use asset::{Error, read_file};

use crate::golden::{golden_v1_asset, hand_built_v1};
use crate::{fixtures_dir, regenerating};

/// One damaged file: its name, its bytes, and what its error message must start with.
struct Damaged {
    name: &'static str,
    bytes: Vec<u8>,
    message: &'static str,
    /// Whether the error is the checksum variant (exit 1 in `asset-info`) rather than a refusal.
    checksum: bool,
}

fn damaged_files() -> Vec<Damaged> {
    let golden = hand_built_v1(&golden_v1_asset());
    let edited = |edit: &dyn Fn(&mut Vec<u8>)| {
        let mut bytes = golden.clone();
        edit(&mut bytes);
        bytes
    };
    let last = golden.len() - 1;
    vec![
        Damaged {
            name: "asset-bad-magic.asset",
            bytes: edited(&|b| b[..8].copy_from_slice(b"BRDFTBL\0")),
            message: "not an asset file: expected magic \"BRDFASET\", found \"BRDFTBL\\x00\"",
            checksum: false,
        },
        Damaged {
            name: "asset-bad-checksum.asset",
            bytes: edited(&|b| b[last] ^= 0x01),
            message: "checksum mismatch: header stores sha256 ",
            checksum: true,
        },
        Damaged {
            name: "asset-future-version.asset",
            bytes: edited(&|b| b[8..12].copy_from_slice(&7u32.to_le_bytes())),
            message: "unsupported format version 7: this build reads version 1",
            checksum: false,
        },
        Damaged {
            name: "asset-truncated.asset",
            bytes: edited(&|b| b.truncate(100)),
            message: "truncated: header declares ",
            checksum: false,
        },
        Damaged {
            name: "asset-huge-length.asset",
            bytes: edited(&|b| b[24..32].copy_from_slice(&(1u64 << 60).to_le_bytes())),
            message: "payload length 1152921504606846976 bytes exceeds the limit of 4294967296 bytes",
            checksum: false,
        },
    ]
}

#[test]
fn damaged_fixtures_are_what_their_recipe_makes() {
    let dir = fixtures_dir().join("invalid");
    for file in damaged_files() {
        let path = dir.join(file.name);
        if regenerating() {
            asset::write_atomic(&path, &file.bytes).unwrap();
        }
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        assert!(committed == file.bytes, "{} differs from its recipe in damaged_files()", path.display());
    }
}

#[test]
fn every_damaged_fixture_is_rejected_with_a_message_naming_the_problem() {
    let dir = fixtures_dir().join("invalid");
    for file in damaged_files() {
        let path = dir.join(file.name);
        match read_file(&path) {
            Ok(_) => panic!("{} was accepted", path.display()),
            Err(e) => {
                let message = e.to_string();
                assert!(message.starts_with(file.message), "{}: {message}", path.display());
                assert_eq!(matches!(e, Error::ChecksumMismatch { .. }), file.checksum, "{}: {e:?}", path.display());
            }
        }
    }
}

/// Every `asset-*` file in the folder is one of the recipes, so none goes untested.
#[test]
fn every_asset_file_in_the_invalid_folder_has_a_recipe() {
    let names: Vec<&str> = damaged_files().iter().map(|f| f.name).collect();
    for entry in std::fs::read_dir(fixtures_dir().join("invalid")).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        if name.starts_with("asset-") {
            assert!(names.contains(&name.as_str()), "fixtures/invalid/{name} has no recipe");
        }
    }
}
