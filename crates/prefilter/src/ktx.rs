//! A KTX2 writer for uncompressed RGBA16F textures (`VK_FORMAT_R16G16B16A16_SFLOAT`): 2D, 2D
//! arrays, mip chains. No maintained crate writes KTX2, and the subset needed is small; the
//! tests read every file back with the maintained `ktx2` reader.
//!
//! Layout (KTX 2.0 specification, all little-endian), for `K` levels:
//!
//! | Offset | Size | Field |
//! |-------:|-----:|-------|
//! | 0 | 12 | identifier `AB 4B 54 58 20 32 30 BB 0D 0A 1A 0A` ("«KTX 20»\r\n\x1A\n") |
//! | 12 | 4 | `vkFormat` = 97 (`R16G16B16A16_SFLOAT`) |
//! | 16 | 4 | `typeSize` = 2 |
//! | 20 | 8 | `pixelWidth`, `pixelHeight` of level 0 |
//! | 28 | 4 | `pixelDepth` = 0 (2D) |
//! | 32 | 4 | `layerCount`: 0 for a plain 2D texture, the number of layers of an array |
//! | 36 | 4 | `faceCount` = 1 |
//! | 40 | 4 | `levelCount` = `K` |
//! | 44 | 4 | `supercompressionScheme` = 0 (none) |
//! | 48 | 16 | `dfdByteOffset`, `dfdByteLength`, `kvdByteOffset`, `kvdByteLength` (u32 each) |
//! | 64 | 16 | `sgdByteOffset`, `sgdByteLength` = 0, 0 (u64 each) |
//! | 80 | 24 K | level index, level 0 first: `byteOffset`, `byteLength`, `uncompressedByteLength` (u64 each; the lengths are equal) |
//! | 80 + 24 K | 92 | data format descriptor, below |
//! | 172 + 24 K | | key/value data: `KTXorientation` = `rd`, `KTXwriter`, `radiance_scale` (each `u32` length, key, NUL, value, NUL, padding to 4 bytes; sorted by key) |
//! | aligned to 8 | | the levels' texels, **smallest level first**; per level, layer after layer, rows top to bottom, 8 bytes per texel: R, G, B, A as IEEE half floats |
//!
//! The data format descriptor (Khronos Data Format 1.3, one basic block, 4 samples):
//! `dfdTotalSize` 92; block header: vendor 0 and type 0 (word `0`), version 2 and block size 88
//! (word `0x0058_0002`); model RGBSDA (1), primaries BT.709 (1), transfer linear (1), flags 0
//! (straight alpha); texel block `1 x 1 x 1 x 1` (stored as 0); `bytesPlane0` = 8. Samples R, G,
//! B, A at bit offsets 0, 16, 32, 48, 16 bits (stored as 15), channels 0, 1, 2, 15, qualifiers
//! float and signed (`0xC0`), positions 0, `sampleLower` = -1.0f (`0xBF800000`), `sampleUpper` =
//! 1.0f (`0x3F800000`): the values `libktx` writes for this format.
//!
//! Radiance above the largest half float (65504, e.g. a sun's texels) would become infinite;
//! instead every texel of the file is multiplied by a power of two `radiance_scale <= 1` chosen
//! so that the largest fits (1 when it already does; exact in binary, so only values that become
//! subnormal lose bits). Readers divide by it.

use envmap::{EnvMap, MipChain};
use half::f16;

use crate::error::Error;

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;

/// The 12-byte KTX2 file identifier.
pub const IDENTIFIER: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];

/// A KTX2 file in memory and the scale its texels were stored with.
#[derive(Clone, Debug, PartialEq)]
pub struct Encoded {
    pub bytes: Vec<u8>,
    /// Stored texel = radiance times this (a power of two, at most 1).
    pub radiance_scale: f32,
}

/// A 2D array texture of one level, one layer per map. The maps must all have the same size.
pub fn encode_array(layers: &[&EnvMap], writer: &str) -> Result<Encoded, Error> {
    let Some(first) = layers.first() else { return Err(Error::InvalidConfig("an array needs a layer".into())) };
    let (w, h) = (first.width(), first.height());
    if let Some(other) = layers.iter().find(|l| (l.width(), l.height()) != (w, h)) {
        return Err(Error::InvalidConfig(format!(
            "array layers differ in size: {w} x {h} and {} x {}",
            other.width(),
            other.height()
        )));
    }
    let level: Vec<&[f32]> = layers.iter().map(|l| l.rgb()).collect();
    encode_rgba16f(w, h, layers.len(), &[level], writer)
}

/// A 2D texture with the levels of a mip chain (`envmap`'s chain stops at the first odd height,
/// so it may hold fewer levels than a full chain down to 1 x 1; KTX2 allows that).
pub fn encode_mip_chain(chain: &MipChain, writer: &str) -> Result<Encoded, Error> {
    let level0 = chain.level(0);
    let levels: Vec<Vec<&[f32]>> = chain.levels().iter().map(|level| vec![level.rgb()]).collect();
    encode_rgba16f(level0.width(), level0.height(), 0, &levels, writer)
}

/// The general writer: `levels[l][layer]` holds level `l` of each layer (`max(1, layer_count)`
/// of them) as interleaved RGB, `max(1, width >> l) x max(1, height >> l)` texels; alpha is 1.
pub fn encode_rgba16f(
    width: usize,
    height: usize,
    layer_count: usize,
    levels: &[Vec<&[f32]>],
    writer: &str,
) -> Result<Encoded, Error> {
    let invalid = |message: String| Err(Error::InvalidConfig(message));
    if width == 0 || height == 0 || levels.is_empty() {
        return invalid(format!("empty texture: {width} x {height}, {} levels", levels.len()));
    }
    if u32::try_from(width.max(height)).is_err() || (width.max(height) >> (levels.len() - 1)) == 0 {
        return invalid(format!("{} levels do not fit a {width} x {height} texture", levels.len()));
    }
    let layers = layer_count.max(1);
    for (l, level) in levels.iter().enumerate() {
        let texels = (width >> l).max(1) * (height >> l).max(1);
        if level.len() != layers || level.iter().any(|rgb| rgb.len() != 3 * texels) {
            return invalid(format!("level {l} needs {layers} images of {texels} rgb texels"));
        }
    }
    let max = levels.iter().flatten().flat_map(|rgb| rgb.iter()).fold(0.0f32, |m, &v| m.max(v.abs()));
    if !max.is_finite() {
        return Err(Error::Overflow("a texel is not finite".into()));
    }
    let radiance_scale = half_scale(max);

    // Key/value data, sorted by key.
    let scale_text = format!("{radiance_scale}");
    let mut kvd = Vec::new();
    for (key, value) in [("KTXorientation", "rd"), ("KTXwriter", writer), ("radiance_scale", scale_text.as_str())] {
        let length = key.len() + 1 + value.len() + 1;
        kvd.extend_from_slice(&(length as u32).to_le_bytes());
        kvd.extend_from_slice(key.as_bytes());
        kvd.push(0);
        kvd.extend_from_slice(value.as_bytes());
        kvd.push(0);
        kvd.resize(kvd.len().next_multiple_of(4), 0);
    }
    let dfd = data_format_descriptor();

    let n_levels = levels.len();
    let dfd_offset = 80 + 24 * n_levels;
    let kvd_offset = dfd_offset + dfd.len();
    let data_start = (kvd_offset + kvd.len()).next_multiple_of(8);
    let level_bytes: Vec<usize> =
        (0..n_levels).map(|l| 8 * layers * (width >> l).max(1) * (height >> l).max(1)).collect();
    // Smallest level first; every level a multiple of 8 bytes, so each starts aligned to 8.
    let mut offsets = vec![0usize; n_levels];
    let mut at = data_start;
    for l in (0..n_levels).rev() {
        offsets[l] = at;
        at += level_bytes[l];
    }

    let mut bytes = Vec::with_capacity(at);
    bytes.extend_from_slice(&IDENTIFIER);
    for value in [
        VK_FORMAT_R16G16B16A16_SFLOAT,
        2,
        width as u32,
        height as u32,
        0,
        layer_count as u32,
        1,
        n_levels as u32,
        0,
        dfd_offset as u32,
        dfd.len() as u32,
        kvd_offset as u32,
        kvd.len() as u32,
    ] {
        bytes.extend_from_slice(&value.to_le_bytes());
    }
    bytes.extend_from_slice(&0u64.to_le_bytes());
    bytes.extend_from_slice(&0u64.to_le_bytes());
    for l in 0..n_levels {
        for value in [offsets[l], level_bytes[l], level_bytes[l]] {
            bytes.extend_from_slice(&(value as u64).to_le_bytes());
        }
    }
    bytes.extend_from_slice(&dfd);
    bytes.extend_from_slice(&kvd);
    bytes.resize(data_start, 0);
    let one = f16::ONE.to_le_bytes();
    for level in levels.iter().rev() {
        for rgb in level {
            for texel in rgb.chunks_exact(3) {
                for &v in texel {
                    bytes.extend_from_slice(&f16::from_f32(v * radiance_scale).to_le_bytes());
                }
                bytes.extend_from_slice(&one);
            }
        }
    }
    debug_assert_eq!(bytes.len(), at);
    Ok(Encoded { bytes, radiance_scale })
}

/// The largest power of two `s <= 1` with `max * s <= 65504`, the largest finite half float.
pub fn half_scale(max: f32) -> f32 {
    let mut scale = 1.0f32;
    while max * scale > f16::MAX.to_f32() {
        scale *= 0.5;
    }
    scale
}

/// The 92-byte data format descriptor of `R16G16B16A16_SFLOAT` (see the module documentation).
fn data_format_descriptor() -> Vec<u8> {
    const SAMPLES: u32 = 4;
    let block_size = 24 + 16 * SAMPLES;
    let mut words: Vec<u32> = vec![
        4 + block_size,           // dfdTotalSize
        0,                        // vendorId 0 (Khronos), descriptorType 0 (basic)
        2 | (block_size << 16),   // versionNumber 2 (KDF 1.3), descriptorBlockSize
        1 | (1 << 8) | (1 << 16), // colorModel RGBSDA, colorPrimaries BT709, transferFunction linear, flags 0
        0,                        // texelBlockDimension0..3 (value - 1): 1 x 1 x 1 x 1
        8,                        // bytesPlane0 = 8, bytesPlane1..3 = 0
        0,                        // bytesPlane4..7
    ];
    const FLOAT_SIGNED: u32 = 0x80 | 0x40;
    for (i, channel) in [0u32, 1, 2, 15].into_iter().enumerate() {
        let bit_offset = 16 * i as u32;
        words.push(bit_offset | (15 << 16) | ((FLOAT_SIGNED | channel) << 24));
        words.push(0); // samplePosition0..3
        words.push((-1.0f32).to_bits()); // sampleLower
        words.push(1.0f32.to_bits()); // sampleUpper
    }
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}
