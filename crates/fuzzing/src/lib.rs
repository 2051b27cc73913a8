//! The fuzzing harnesses of every reader in the toolchain, one function per reader, shared by
//! the cargo-fuzz targets in `fuzz/` (nightly) and by the replay of every reproducer and seed in
//! `tests/regressions.rs` (stable, part of `make test`). Each harness runs its reader on the
//! bytes and returns normally whether the reader accepts them or not: a reader must never panic,
//! so any panic is a finding.
//!
//! - [`merl()`] runs [`merl::MerlTable::parse`].
//! - [`asset()`] runs [`asset::decode`] on the bytes as they are, then on the same bytes with the
//!   header made consistent ([`fix_up_asset`]: magic, version, a known kind, the section lengths
//!   and the checksum) so that the fuzzer reaches the payload decoders behind the checksum. The
//!   container checks every kind's payload as it decodes it; an atlas of either kind is also
//!   read back as the tools read it ([`bake::stage::bandwidth_atlas::from_payload`]).
//! - [`envmap_exr`] and [`envmap_hdr`] run [`envmap::read_image_from_memory`] and
//!   [`envmap::load_from_memory`] with [`env_limits`] (1024 x 512), on inputs that start with the
//!   format's magic (`76 2f 31 01`, `#?`): two targets, so that each format gets its own inputs.
//! - [`manifest()`] runs [`asset::BakeManifest::from_bytes`] (the size limit, UTF-8, JSON, both
//!   versions and the path rules), and on a manifest it accepts what the readers do next: every
//!   output's role and path looked up again, and a version-2 manifest written back and read to the
//!   same value.
//! - [`obj`] runs [`render::Mesh::from_obj`] on inputs that are UTF-8 text (what `brdf-preview
//!   --mesh` reads after its size check), and checks what it accepts ([`render::Mesh::validate`]).
//!
//! # The memory bound
//!
//! A reader may hold at most [`FLOOR`] + [`MULTIPLE`] x (input bytes) live at once, beyond what
//! was live before the call (the input itself): [`check_memory`]. The binaries install
//! [`CountingAllocator`] as their global allocator and [`measure`] each call.
//!
//! - [`MULTIPLE`] = 4 covers readers whose output is the input in another form. A MERL table of
//!   `N` bytes is `N - 12` bytes of `f64` (measured: 1.0 x on full-size tables of both sizes). An
//!   asset's arrays are its payload again: serde preallocates at most 1 MiB of a vector and then
//!   doubles it, so the last growth holds the old and the new buffer, up to 3 x the array
//!   (measured: 1.5 x on a 4 MiB atlas); the asset harness also holds its fixed-up copy of the
//!   input (1 x).
//! - [`FLOOR`] = 32 MiB covers readers bounded by limits rather than by their input: an EXR or
//!   HDR image within [`env_limits`] (1024 x 512) is decoded under `envmap`'s own estimate of
//!   32 bytes per texel, which it reserves once before decoding (measured: 16.8 MB on every real
//!   map, at most 14.8 MB on a million fuzzed inputs of each format), and an atlas stored as rows
//!   is expanded to its full grid (measured: 4.3 MB for the 64 x 64 lobes of 16 x 16 texels that
//!   `brdf-bandwidth` writes). Twice the largest of these. The expansion is `lobes_x` times the
//!   stored texels, and a rows asset may stand for at most 4096 columns
//!   (`asset::MAX_ROWS_COLUMNS`, the largest incident grid): up to 16 KiB of stored texels (a
//!   file of about that size) it stays within the floor; this fuzzing found the file that
//!   declared 7.5 million columns.
//!
//! The fuzzers' inputs are at most a few kilobytes, so for them the bound is the floor: an
//! allocation sized by something the input does not hold is a finding, a change of a few percent
//! is not. `tests/regressions.rs` measures the legitimate inputs above on every run.

mod alloc;

pub use alloc::{CountingAllocator, live_bytes, measure};

/// A fuzz target's whole body (cargo-fuzz, in `fuzz/fuzz_targets/`): the counting allocator as
/// the global allocator, and `libfuzzer_sys::fuzz_target!` running [`fuzz_one`] on `$harness`.
/// libfuzzer-sys aborts on every panic, even one a reader catches and turns into an error (envmap
/// does so with the `exr` crate's B44 overflow): the target's panic hook only prints the message,
/// so that a panic is a crash when it escapes the harness, as in the stable replay.
#[macro_export]
macro_rules! fuzz_target_for {
    ($harness:path) => {
        #[global_allocator]
        static ALLOC: $crate::CountingAllocator = $crate::CountingAllocator;

        libfuzzer_sys::fuzz_target!(
            init: std::panic::set_hook(Box::new(|info| eprintln!("{info}"))),
            |data: &[u8]| $crate::fuzz_one($harness, data)
        );
    };
}

/// Bytes any input may make a reader hold, whatever its size (see the crate docs).
pub const FLOOR: usize = 32 << 20;
/// Bytes a reader may hold per byte of input, beyond [`FLOOR`] (see the crate docs).
pub const MULTIPLE: usize = 4;

/// The memory promise: a reader that held `peak` bytes at once on an input of `input_len` bytes
/// kept within `FLOOR + MULTIPLE * input_len`; otherwise a message that says by how much.
pub fn check_memory(input_len: usize, peak: usize) -> Result<(), String> {
    let bound = FLOOR.saturating_add(MULTIPLE.saturating_mul(input_len));
    if peak <= bound {
        return Ok(());
    }
    Err(format!(
        "allocated {peak} bytes at peak on a {input_len}-byte input, above the bound of {bound} \
         ({} MiB floor + {MULTIPLE} x the input)",
        FLOOR >> 20
    ))
}

/// One execution of a fuzz target: `harness` on `data`, measured; a panic (which libFuzzer
/// reports as a crash and saves) when it held more than [`check_memory`] allows. Needs
/// [`CountingAllocator`] as the global allocator.
///
/// Prints each new largest peak, so that a run's log says how close it came to the bound.
pub fn fuzz_one(harness: Harness, data: &[u8]) {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static LARGEST: AtomicUsize = AtomicUsize::new(0);

    let ((), peak) = measure(|| harness(data));
    if peak > LARGEST.fetch_max(peak, Ordering::Relaxed) {
        eprintln!("fuzzing: largest peak so far: {peak} bytes, on a {}-byte input", data.len());
    }
    if let Err(problem) = check_memory(data.len(), peak) {
        panic!("memory bound: {problem}");
    }
}

/// A harness: runs one reader on the bytes and returns, whatever the reader made of them.
pub type Harness = fn(&[u8]);

/// The harnesses by target name, in the order of `fuzz/Cargo.toml`: the replay runs the files
/// of `fuzz/regressions/<name>/` and `fuzz/corpus/<name>/`, and those every target shares
/// (`fixtures/`, `../shared/data/hostile/`), through the function named here.
pub const HARNESSES: [(&str, Harness); 6] = [
    ("merl", merl),
    ("asset", asset),
    ("envmap_exr", envmap_exr),
    ("envmap_hdr", envmap_hdr),
    ("manifest", manifest),
    ("obj", obj),
];

/// A MERL table from memory.
pub fn merl(bytes: &[u8]) {
    let _ = merl::MerlTable::parse(bytes);
}

/// An asset file as it is, then with its header made consistent (see [`fix_up_asset`]).
pub fn asset(bytes: &[u8]) {
    read_asset(bytes);
    if let Some(fixed) = fix_up_asset(bytes) {
        read_asset(&fixed);
    }
}

/// What a reader of an asset file does with it: decode the container (which checks the
/// payload's invariants) and read an atlas of either kind back as the tools do.
fn read_asset(bytes: &[u8]) {
    let Ok(decoded) = asset::decode(bytes) else { return };
    match decoded.payload {
        payload @ (asset::Payload::BandwidthAtlas(_) | asset::Payload::BandwidthRows(_)) => {
            let _ = bake::stage::bandwidth_atlas::from_payload(payload);
        }
        asset::Payload::WaveletBrdf(payload) => {
            // Decode it as the previewer does, and evaluate it at a few direction pairs.
            if let Ok(brdf) = wavelet_brdf::Decoded::from_payload(&payload) {
                let dirs =
                    [glam::DVec3::Z, glam::DVec3::new(0.6, 0.0, 0.8), glam::DVec3::new(-0.3, 0.9, 0.3).normalize()];
                for (wi, wo) in dirs.iter().zip(dirs.iter().rev()) {
                    let _ = brdf.eval(*wi, *wo, 1.5);
                }
            }
        }
        asset::Payload::MaterialInfo(_)
        | asset::Payload::ImportanceSamples(_)
        | asset::Payload::PrefilteredEnvmap(_)
        | asset::Payload::BandwidthPca(_)
        | asset::Payload::LayerSelection(_) => {}
    }
}

/// The bytes with a header that [`asset::decode`] accepts up to the sections' contents, or `None`
/// when they are shorter than a header or already consistent:
///
/// - magic `BRDFASET` and the current format version;
/// - the kind: the stored code if it is known, else one of the known kinds chosen by it
///   (`AssetKind::ALL[code % 7]`);
/// - the provenance length: the stored one, clipped to the body and to
///   [`asset::PROVENANCE_LIMIT`] (so the fuzzer still chooses where the payload starts); the
///   payload length: the rest of the body;
/// - the checksum: SHA-256 of the body.
pub fn fix_up_asset(bytes: &[u8]) -> Option<Vec<u8>> {
    use asset::{AssetKind, FORMAT_VERSION, HEADER_BYTES, MAGIC, PROVENANCE_LIMIT};

    if bytes.len() < HEADER_BYTES {
        return None;
    }
    let mut fixed = bytes.to_vec();
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));

    let body_len = (bytes.len() - HEADER_BYTES) as u64;
    let code = u32_at(12);
    let kind = AssetKind::ALL.iter().find(|k| k.code() == code).copied();
    let kind = kind.unwrap_or(AssetKind::ALL[code as usize % AssetKind::ALL.len()]);
    let provenance_len = u64_at(16).min(body_len).min(PROVENANCE_LIMIT);
    let payload_len = body_len - provenance_len;

    fixed[0..8].copy_from_slice(&MAGIC);
    fixed[8..12].copy_from_slice(&FORMAT_VERSION.to_le_bytes());
    fixed[12..16].copy_from_slice(&kind.code().to_le_bytes());
    fixed[16..24].copy_from_slice(&provenance_len.to_le_bytes());
    fixed[24..32].copy_from_slice(&payload_len.to_le_bytes());
    let checksum = asset::sha256(&bytes[HEADER_BYTES..]);
    fixed[32..64].copy_from_slice(&checksum);
    (fixed != bytes).then_some(fixed)
}

/// The limits the environment harnesses read with: small, so that any image a reader accepts
/// fits in [`FLOOR`], and the size of the real maps in `../shared/data/env/`.
pub fn env_limits() -> envmap::Limits {
    envmap::Limits { max_width: 1024, max_height: 512, ..Default::default() }
}

/// An OpenEXR file from memory (inputs that do not start with the EXR magic are the HDR
/// target's and are skipped).
pub fn envmap_exr(bytes: &[u8]) {
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        read_env(bytes);
    }
}

/// A Radiance HDR file from memory (inputs that do not start with `#?` are the EXR target's
/// and are skipped).
pub fn envmap_hdr(bytes: &[u8]) {
    if bytes.starts_with(b"#?") {
        read_env(bytes);
    }
}

/// Both environment readers: any image, then a lat-long map.
fn read_env(bytes: &[u8]) {
    let limits = env_limits();
    let _ = envmap::read_image_from_memory(bytes, &limits);
    let _ = envmap::load_from_memory(bytes, &limits);
}

/// A bake manifest from memory, as the bake and the previewer read one (see the crate docs). A
/// manifest that reads but does not survive being written and read again, or whose paths the
/// folder reader would not take, is a finding (a panic).
pub fn manifest(bytes: &[u8]) {
    let Ok(manifest) = asset::BakeManifest::from_bytes(bytes) else { return };
    for output in manifest.outputs() {
        assert!(fsguard::check_relative(&output.path).is_ok(), "a manifest read with path {:?}", output.path);
        assert!(manifest.output(&output.role).is_some() && manifest.output_by_path(&output.path).is_some());
    }
    if manifest.manifest_version == asset::MANIFEST_VERSION {
        let again = asset::BakeManifest::from_json(&manifest.to_json()).expect("a manifest written back reads");
        assert_eq!(again, manifest, "a manifest written back reads as itself");
    }
}

/// A Wavefront OBJ file from memory (UTF-8 text only, as `brdf-preview --mesh` reads it): what the
/// reader accepts must be a consistent mesh.
pub fn obj(bytes: &[u8]) {
    let Ok(text) = std::str::from_utf8(bytes) else { return };
    if let Ok(mesh) = render::Mesh::from_obj(text) {
        mesh.validate().expect("a mesh the reader accepts is consistent");
    }
}
