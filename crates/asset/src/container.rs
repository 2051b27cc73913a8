//! The container: a fixed 64-byte header (magic, version, kind, section lengths, checksum)
//! followed by the provenance and the payload, each in bincode. The byte layout is documented
//! in `data-schema/README.md`; this file is its reference implementation.

use std::io::Read;
use std::path::Path;

use bincode::config::{Configuration, Fixint, LittleEndian, NoLimit};
use bincode::error::DecodeError;
use serde::Serialize;
use serde::de::DeserializeOwned;
use sha2::{Digest, Sha256};

use crate::error::Error;
use crate::files::write_atomic;
use crate::types::{
    Asset, AssetKind, BandwidthAtlas, BandwidthPca, BandwidthRows, ImportanceSamples, LayerSelection, MaterialInfo,
    Payload, PrefilteredEnvmap, Provenance, WaveletBrdf,
};

/// The first eight bytes of every asset file.
pub const MAGIC: [u8; 8] = *b"BRDFASET";
/// The format version this build writes.
pub const FORMAT_VERSION: u32 = 1;
/// Every format version this build reads. Released versions are never dropped from this list.
pub const READABLE_VERSIONS: &[u32] = &[1];
/// Size of the fixed header; the checksummed region starts here.
pub const HEADER_BYTES: usize = 64;
/// The largest provenance section a reader accepts.
pub const PROVENANCE_LIMIT: u64 = 1 << 20;
/// The largest payload section a reader accepts.
pub const PAYLOAD_LIMIT: u64 = 4 << 30;

/// Fixed-width little-endian integers make the layout a plain table of offsets (see
/// `data-schema/README.md`) rather than depend on bincode's varint rules.
const CONFIG: Configuration<LittleEndian, Fixint, NoLimit> =
    bincode::config::standard().with_fixed_int_encoding().with_little_endian();

/// The fixed header of an asset file, as stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    pub version: u32,
    pub kind: AssetKind,
    /// Bytes of the provenance section.
    pub provenance_len: u64,
    /// Bytes of the payload section.
    pub payload_len: u64,
    /// SHA-256 of the provenance and payload sections, as stored.
    pub checksum: [u8; 32],
}

impl Header {
    /// The size of the file this header describes. Cannot overflow: [`read_header`] bounds both
    /// lengths first.
    pub fn file_len(&self) -> u64 {
        HEADER_BYTES as u64 + self.provenance_len + self.payload_len
    }

    /// Checks that a file of `actual` bytes is exactly what the header describes.
    pub fn check_file_len(&self, actual: u64) -> Result<(), Error> {
        let expected = self.file_len();
        let parts =
            format!("{HEADER_BYTES} header + {} provenance + {} payload", self.provenance_len, self.payload_len);
        if actual < expected {
            Err(Error::Invalid(format!("truncated: header declares {expected} bytes ({parts}), file has {actual}")))
        } else if actual > expected {
            Err(Error::Invalid(format!(
                "trailing bytes: file has {actual} bytes, header declares {expected} ({parts})"
            )))
        } else {
            Ok(())
        }
    }
}

/// Parses and checks the fixed header at the start of `bytes`: magic, then version, then kind,
/// then the section lengths against [`PROVENANCE_LIMIT`] and [`PAYLOAD_LIMIT`]. Does not look at
/// anything past the header, so the file size is checked separately with
/// [`Header::check_file_len`].
pub fn read_header(bytes: &[u8]) -> Result<Header, Error> {
    let found_magic = &bytes[..bytes.len().min(MAGIC.len())];
    if found_magic != &MAGIC[..found_magic.len()] {
        return Err(Error::Invalid(format!(
            "not an asset file: expected magic \"{}\", found \"{}\"",
            MAGIC.escape_ascii(),
            found_magic.escape_ascii()
        )));
    }
    let Some(header) = bytes.first_chunk::<HEADER_BYTES>() else {
        return Err(Error::Invalid(format!(
            "truncated: {} bytes, shorter than the {HEADER_BYTES}-byte header",
            bytes.len()
        )));
    };
    let u32_at = |at: usize| u32::from_le_bytes(header[at..at + 4].try_into().unwrap());
    let u64_at = |at: usize| u64::from_le_bytes(header[at..at + 8].try_into().unwrap());

    let version = u32_at(8);
    if !READABLE_VERSIONS.contains(&version) {
        return Err(Error::UnsupportedVersion { what: "format", found: version, readable: READABLE_VERSIONS });
    }
    let kind = AssetKind::from_code(u32_at(12))?;
    let provenance_len = u64_at(16);
    if provenance_len > PROVENANCE_LIMIT {
        return Err(Error::LimitExceeded { what: "provenance", found: provenance_len, limit: PROVENANCE_LIMIT });
    }
    let payload_len = u64_at(24);
    if payload_len > PAYLOAD_LIMIT {
        return Err(Error::LimitExceeded { what: "payload", found: payload_len, limit: PAYLOAD_LIMIT });
    }
    let checksum = header[32..64].try_into().unwrap();
    Ok(Header { version, kind, provenance_len, payload_len, checksum })
}

/// Serializes an asset into the bytes of a file of the current [`FORMAT_VERSION`].
///
/// Does not enforce the readers' limits or the payload's invariants; [`write_file`] does.
pub fn encode(asset: &Asset) -> Vec<u8> {
    let provenance = encode_section(&asset.provenance);
    let payload = match &asset.payload {
        Payload::MaterialInfo(info) => encode_section(info),
        Payload::ImportanceSamples(samples) => encode_section(samples),
        Payload::PrefilteredEnvmap(prefiltered) => encode_section(prefiltered),
        Payload::BandwidthAtlas(atlas) => encode_section(atlas),
        Payload::BandwidthPca(pca) => encode_section(pca),
        Payload::LayerSelection(selection) => encode_section(selection),
        Payload::BandwidthRows(rows) => encode_section(rows),
        Payload::WaveletBrdf(wavelet) => encode_section(wavelet),
    };
    let checksum: [u8; 32] = Sha256::new().chain_update(&provenance).chain_update(&payload).finalize().into();

    let mut bytes = Vec::with_capacity(HEADER_BYTES + provenance.len() + payload.len());
    bytes.extend_from_slice(&MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&asset.kind().code().to_le_bytes());
    bytes.extend_from_slice(&(provenance.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&checksum);
    bytes.extend_from_slice(&provenance);
    bytes.extend_from_slice(&payload);
    bytes
}

fn encode_section<T: Serialize>(value: &T) -> Vec<u8> {
    // Every sequence in the serialized types has a known length and the writer is a `Vec`, so
    // bincode has no way to fail here.
    bincode::serde::encode_to_vec(value, CONFIG).expect("asset types always serialize")
}

/// Parses a whole asset file held in memory: header, size, checksum, then the sections.
pub fn decode(bytes: &[u8]) -> Result<Asset, Error> {
    decode_with_header(bytes).map(|(_, asset)| asset)
}

/// [`decode`], also returning the header as stored (for tools that show it).
pub fn decode_with_header(bytes: &[u8]) -> Result<(Header, Asset), Error> {
    let header = read_header(bytes)?;
    header.check_file_len(bytes.len() as u64)?;
    let body = &bytes[HEADER_BYTES..];
    let computed: [u8; 32] = Sha256::digest(body).into();
    if computed != header.checksum {
        return Err(Error::ChecksumMismatch { header, computed });
    }
    // Every readable version has this body layout so far; a future version with a different
    // one dispatches on `header.version` here and keeps this path for the old files.
    let (provenance, payload) = body.split_at(header.provenance_len as usize);
    let provenance: Provenance = decode_section("provenance", provenance)?;
    let payload = match header.kind {
        AssetKind::MaterialInfo => Payload::MaterialInfo(decode_section::<MaterialInfo>("payload", payload)?),
        AssetKind::ImportanceSamples => {
            Payload::ImportanceSamples(decode_section::<ImportanceSamples>("payload", payload)?)
        }
        AssetKind::PrefilteredEnvmap => {
            Payload::PrefilteredEnvmap(decode_section::<PrefilteredEnvmap>("payload", payload)?)
        }
        AssetKind::BandwidthAtlas => Payload::BandwidthAtlas(decode_section::<BandwidthAtlas>("payload", payload)?),
        AssetKind::BandwidthPca => Payload::BandwidthPca(decode_section::<BandwidthPca>("payload", payload)?),
        AssetKind::LayerSelection => Payload::LayerSelection(decode_section::<LayerSelection>("payload", payload)?),
        AssetKind::BandwidthRows => Payload::BandwidthRows(decode_section::<BandwidthRows>("payload", payload)?),
        AssetKind::WaveletBrdf => Payload::WaveletBrdf(decode_section::<WaveletBrdf>("payload", payload)?),
    };
    payload.check().map_err(|problem| Error::Invalid(format!("invalid payload: {problem}")))?;
    Ok((header, Asset { provenance, payload }))
}

/// Decodes one section, which must be consumed exactly.
///
/// Bincode allocates a string's bytes before reading them, so a lying length inside a section
/// is bounded by the decoder's limit. The limit is a type parameter, hence the buckets: the
/// smallest one that holds the section, so that a section of `n` bytes can make the decoder
/// claim at most `max(1 MiB, 64 n)`.
fn decode_section<T: DeserializeOwned>(what: &str, bytes: &[u8]) -> Result<T, Error> {
    const MIB: usize = 1 << 20;
    const LARGEST: usize = if PAYLOAD_LIMIT as u128 > usize::MAX as u128 { usize::MAX } else { PAYLOAD_LIMIT as usize };
    let decoded = match bytes.len() {
        n if n <= MIB => decode_limited::<T, MIB>(bytes),
        n if n <= 64 * MIB => decode_limited::<T, { 64 * MIB }>(bytes),
        _ => decode_limited::<T, LARGEST>(bytes),
    };
    let invalid = |problem: String| Error::Invalid(format!("invalid {what}: {problem}"));
    let (value, used) = decoded.map_err(|e| invalid(decode_problem(e)))?;
    if used != bytes.len() {
        return Err(invalid(format!("{} trailing bytes after a {used}-byte value", bytes.len() - used)));
    }
    Ok(value)
}

fn decode_limited<T: DeserializeOwned, const LIMIT: usize>(bytes: &[u8]) -> Result<(T, usize), DecodeError> {
    bincode::serde::decode_from_slice(bytes, CONFIG.with_limit::<LIMIT>())
}

/// Bincode's own messages are its `Debug` output; these say the same in this crate's style.
fn decode_problem(e: DecodeError) -> String {
    match e {
        DecodeError::UnexpectedEnd { .. } => "ends in the middle of a value".into(),
        DecodeError::LimitExceeded => "a length field claims more bytes than the section holds".into(),
        DecodeError::Utf8 { .. } => "a string is not valid utf-8".into(),
        DecodeError::OutsideUsizeRange(n) => format!("length {n} does not fit in memory"),
        other => format!("malformed data ({other:?})"),
    }
}

/// Writes an asset atomically (see [`write_atomic`]) after checking that a reader would accept
/// it: the payload's invariants and the section limits.
pub fn write_file(path: &Path, asset: &Asset) -> Result<(), Error> {
    write_atomic(path, &encode_checked(asset)?)?;
    Ok(())
}

/// [`encode`] after the checks [`write_file`] makes: the payload's invariants and the section
/// limits. For writers that hold every output in memory before writing any.
pub fn encode_checked(asset: &Asset) -> Result<Vec<u8>, Error> {
    asset
        .payload
        .check()
        .map_err(|problem| Error::Invalid(format!("refusing to write an invalid payload: {problem}")))?;
    let bytes = encode(asset);
    // The header parser is the one place that knows the limits.
    read_header(&bytes)?;
    Ok(bytes)
}

/// Reads and checks an asset file, which must be a regular file (a FIFO or a device is refused
/// without blocking or reading). The header is read and checked against the file's size before
/// anything sized by it is allocated.
pub fn read_file(path: &Path) -> Result<Asset, Error> {
    read_file_with_header(path).map(|(_, asset)| asset)
}

/// [`read_file`], also returning the header as stored (for tools that show it).
pub fn read_file_with_header(path: &Path) -> Result<(Header, Asset), Error> {
    // A regular file only, opened without blocking: a FIFO or a device is refused unread.
    let mut file = fsguard::open_regular(path)?;
    let file_len = file.metadata()?.len();
    let mut bytes = Vec::with_capacity(HEADER_BYTES);
    file.by_ref().take(HEADER_BYTES as u64).read_to_end(&mut bytes)?;
    let header = read_header(&bytes)?;
    header.check_file_len(file_len)?;
    bytes.reserve_exact((file_len - HEADER_BYTES as u64) as usize);
    // Read at most one byte more than promised: a file that grew since `metadata` is caught by
    // `decode`'s size check, not by an unbounded read.
    file.take(file_len - HEADER_BYTES as u64 + 1).read_to_end(&mut bytes)?;
    decode_with_header(&bytes)
}
