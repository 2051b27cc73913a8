//! A KTX2 writer for uncompressed float RGBA textures (`VK_FORMAT_R16G16B16A16_SFLOAT` or
//! `VK_FORMAT_R32G32B32A32_SFLOAT`): 2D, 2D arrays, cube maps, mip chains; and the reader the
//! toolchain reads them back with ([`decode`], on the maintained `ktx2` crate). No maintained
//! crate writes KTX2, and the subset needed is small; the tests read every file back with `ktx2`.
//! Also single-float data textures of one level ([`encode_data`], [`decode_data`]:
//! `VK_FORMAT_R32_SFLOAT` or `VK_FORMAT_R32G32B32A32_SFLOAT`, 2D, 2D arrays or 3D, every value as
//! given), the tables engines read (`bake`'s engine textures).
//!
//! Layout (KTX 2.0 specification, all little-endian), for `K` levels:
//!
//! | Offset | Size | Field |
//! |-------:|-----:|-------|
//! | 0 | 12 | identifier `AB 4B 54 58 20 32 30 BB 0D 0A 1A 0A` ("«KTX 20»\r\n\x1A\n") |
//! | 12 | 4 | `vkFormat`: 97 (`R16G16B16A16_SFLOAT`) or 109 (`R32G32B32A32_SFLOAT`); data textures 100 (`R32_SFLOAT`) or 109 |
//! | 16 | 4 | `typeSize`: 2 or 4 |
//! | 20 | 8 | `pixelWidth`, `pixelHeight` of level 0 |
//! | 28 | 4 | `pixelDepth` = 0 (2D; the depth of a 3D data texture) |
//! | 32 | 4 | `layerCount`: 0 for a plain 2D texture or cube map, the number of layers of an array |
//! | 36 | 4 | `faceCount`: 1, or 6 for a cube map |
//! | 40 | 4 | `levelCount` = `K` |
//! | 44 | 4 | `supercompressionScheme` = 0 (none) |
//! | 48 | 16 | `dfdByteOffset`, `dfdByteLength`, `kvdByteOffset`, `kvdByteLength` (u32 each) |
//! | 64 | 16 | `sgdByteOffset`, `sgdByteLength` = 0, 0 (u64 each) |
//! | 80 | 24 K | level index, level 0 first: `byteOffset`, `byteLength`, `uncompressedByteLength` (u64 each; the lengths are equal) |
//! | 80 + 24 K | 92 | data format descriptor, below |
//! | 172 + 24 K | | key/value data: `KTXorientation` = `rd` (`rdi` for a 3D texture; not for cube maps, whose face orientation the specification fixes), `KTXwriter` (each `u32` length, key, NUL, value, NUL, padding to 4 bytes; sorted by key): only keys the specification defines |
//! | aligned to the texel size (8 or 16; 4 for `R32_SFLOAT`), no more | | the levels' texels, **smallest level first**; per level, layer after layer (or depth slice after slice), within a layer face after face (`+X, -X, +Y, -Y, +Z, -Z`), rows top to bottom, 8 or 16 bytes per texel: R, G, B, A as IEEE half or single floats (4 bytes, R, for `R32_SFLOAT`) |
//!
//! The data format descriptor (Khronos Data Format 1.3, one basic block, 4 samples):
//! `dfdTotalSize` 92; block header: vendor 0 and type 0 (word `0`), version 2 and block size 88
//! (word `0x0058_0002`); model RGBSDA (1), primaries BT.709 (1), transfer linear (1), flags 0
//! (straight alpha); texel block `1 x 1 x 1 x 1` (stored as 0); `bytesPlane0` = 8 or 16. Samples
//! R, G, B, A at bit offsets `0, b, 2b, 3b` for `b` = 16 or 32 bits (the length stored as `b -
//! 1`), channels 0, 1, 2, 15, qualifiers float and signed (`0xC0`), positions 0, `sampleLower` =
//! -1.0f (`0xBF800000`), `sampleUpper` = 1.0f (`0x3F800000`): the values `libktx` writes for these
//! formats. `R32_SFLOAT` has one sample (R, 32 bits at offset 0), so `dfdTotalSize` 44, block size
//! 40 and `bytesPlane0` 4.
//!
//! **No hidden scale.** Texels are radiance as it is. [`Storage::Auto`] writes half floats when
//! every value fits them (at most 65504) and single floats otherwise (a sun's texels), so that an
//! engine that loads the file sees the radiance the tool computed; [`Storage::ClampHalf`] writes
//! half floats and clamps larger values to 65504, and says how many it clamped.

use envmap::{EnvMap, MipChain};
use half::f16;

use crate::error::Error;

/// `VK_FORMAT_R16G16B16A16_SFLOAT`.
pub const VK_FORMAT_R16G16B16A16_SFLOAT: u32 = 97;

/// `VK_FORMAT_R32G32B32A32_SFLOAT`.
pub const VK_FORMAT_R32G32B32A32_SFLOAT: u32 = 109;

/// `VK_FORMAT_R32_SFLOAT`.
pub const VK_FORMAT_R32_SFLOAT: u32 = 100;

/// The 12-byte KTX2 file identifier.
pub const IDENTIFIER: [u8; 12] = [0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A];

/// The largest finite half float.
pub const HALF_MAX: f32 = 65504.0;

/// The texel formats the writer knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexelFormat {
    /// `R16G16B16A16_SFLOAT`.
    Rgba16f,
    /// `R32G32B32A32_SFLOAT`.
    Rgba32f,
}

impl TexelFormat {
    pub fn vk_format(self) -> u32 {
        match self {
            TexelFormat::Rgba16f => VK_FORMAT_R16G16B16A16_SFLOAT,
            TexelFormat::Rgba32f => VK_FORMAT_R32G32B32A32_SFLOAT,
        }
    }

    /// Bytes of one channel.
    pub fn type_size(self) -> usize {
        match self {
            TexelFormat::Rgba16f => 2,
            TexelFormat::Rgba32f => 4,
        }
    }

    /// The name in reports: `rgba16f`, `rgba32f`.
    pub fn name(self) -> &'static str {
        match self {
            TexelFormat::Rgba16f => "rgba16f",
            TexelFormat::Rgba32f => "rgba32f",
        }
    }
}

/// How radiance is stored (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Storage {
    /// Half floats when every value fits, single floats otherwise.
    #[default]
    Auto,
    /// Half floats, values above 65504 clamped to it.
    ClampHalf,
}

impl Storage {
    pub fn name(self) -> &'static str {
        match self {
            Storage::Auto => "auto",
            Storage::ClampHalf => "clamp-half",
        }
    }
}

/// A texture's shape: level 0's size, its array layers (0: not an array) and faces (1, or 6 for
/// a cube map).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    pub width: usize,
    pub height: usize,
    pub layers: usize,
    pub faces: usize,
}

impl Shape {
    /// The images of one level: `max(1, layers) faces`.
    pub fn images(&self) -> usize {
        self.layers.max(1) * self.faces
    }

    /// The size of level `l`.
    pub fn level_size(&self, l: usize) -> (usize, usize) {
        ((self.width >> l).max(1), (self.height >> l).max(1))
    }
}

/// A KTX2 file in memory and how its texels were stored.
#[derive(Clone, Debug, PartialEq)]
pub struct Ktx2File {
    pub bytes: Vec<u8>,
    pub format: TexelFormat,
    /// Values clamped to 65504 ([`Storage::ClampHalf`] only).
    pub clamped: usize,
}

/// A 2D array texture of one level, one layer per map. The maps must all have the same size.
pub fn encode_array(layers: &[&EnvMap], storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
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
    encode(Shape { width: w, height: h, layers: layers.len(), faces: 1 }, &[level], storage, writer)
}

/// A 2D texture with the levels of a mip chain (`envmap`'s chain stops at the first odd height,
/// so it may hold fewer levels than a full chain down to 1 x 1; KTX2 allows that).
pub fn encode_mip_chain(chain: &MipChain, storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
    let level0 = chain.level(0);
    let levels: Vec<Vec<&[f32]>> = chain.levels().iter().map(|level| vec![level.rgb()]).collect();
    encode(Shape { width: level0.width(), height: level0.height(), layers: 0, faces: 1 }, &levels, storage, writer)
}

/// The general writer: `levels[l]` holds the [`Shape::images`] images of level `l` (layer-major,
/// then face) as interleaved RGB of [`Shape::level_size`]; alpha is 1.
pub fn encode(shape: Shape, levels: &[Vec<&[f32]>], storage: Storage, writer: &str) -> Result<Ktx2File, Error> {
    let invalid = |message: String| Err(Error::InvalidConfig(message));
    let Shape { width, height, layers: layer_count, faces } = shape;
    if width == 0 || height == 0 || levels.is_empty() {
        return invalid(format!("empty texture: {width} x {height}, {} levels", levels.len()));
    }
    if faces != 1 && !(faces == 6 && width == height) {
        return invalid(format!("{faces} faces of {width} x {height}: a cube map has 6 square faces"));
    }
    if u32::try_from(width.max(height)).is_err() || (width.max(height) >> (levels.len() - 1)) == 0 {
        return invalid(format!("{} levels do not fit a {width} x {height} texture", levels.len()));
    }
    for (l, level) in levels.iter().enumerate() {
        let (w, h) = shape.level_size(l);
        if level.len() != shape.images() || level.iter().any(|rgb| rgb.len() != 3 * w * h) {
            return invalid(format!("level {l} needs {} images of {} rgb texels", shape.images(), w * h));
        }
    }
    let values = || levels.iter().flatten().flat_map(|rgb| rgb.iter());
    if values().any(|v| !v.is_finite()) {
        return Err(Error::Overflow("a texel is not finite".into()));
    }
    let beyond_half = values().filter(|v| v.abs() > HALF_MAX).count();
    let (format, clamped) = match storage {
        Storage::Auto if beyond_half > 0 => (TexelFormat::Rgba32f, 0),
        Storage::Auto => (TexelFormat::Rgba16f, 0),
        Storage::ClampHalf => (TexelFormat::Rgba16f, beyond_half),
    };

    // A cube map's faces have the orientation the specification fixes for them, so it carries
    // no KTXorientation.
    let header = Header {
        vk_format: format.vk_format(),
        type_size: format.type_size(),
        channels: 4,
        width,
        height,
        depth: 0,
        layers: layer_count,
        faces,
        orientation: (faces == 1).then_some("rd"),
    };
    let level_bytes: Vec<usize> = (0..levels.len())
        .map(|l| {
            let (w, h) = shape.level_size(l);
            4 * format.type_size() * shape.images() * w * h
        })
        .collect();
    let mut bytes = container(&header, writer, &level_bytes);
    let at = bytes.len() + level_bytes.iter().sum::<usize>();
    bytes.reserve_exact(at - bytes.len());
    for level in levels.iter().rev() {
        for rgb in level {
            for texel in rgb.chunks_exact(3) {
                for v in [texel[0], texel[1], texel[2], 1.0] {
                    match format {
                        TexelFormat::Rgba16f => {
                            bytes.extend_from_slice(&f16::from_f32(v.clamp(-HALF_MAX, HALF_MAX)).to_le_bytes())
                        }
                        TexelFormat::Rgba32f => bytes.extend_from_slice(&v.to_le_bytes()),
                    }
                }
            }
        }
    }
    debug_assert_eq!(bytes.len(), at);
    Ok(Ktx2File { bytes, format, clamped })
}

/// The shape of a data texture ([`encode_data`]): 2D (`depth` 0, `layers` 0), a 2D array
/// (`layers` > 0) or 3D (`depth` > 0), of `channels` floats per texel (1: `R32_SFLOAT`, 4:
/// `R32G32B32A32_SFLOAT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DataShape {
    pub width: usize,
    pub height: usize,
    /// 0 for a 2D texture or array; the depth slices of a 3D texture.
    pub depth: usize,
    /// 0 for a texture that is not an array.
    pub layers: usize,
    pub channels: usize,
}

impl DataShape {
    /// The values of the texture: `channels width height max(1, depth) max(1, layers)`.
    pub fn values(&self) -> usize {
        self.channels * self.width * self.height * self.depth.max(1) * self.layers.max(1)
    }
}

/// The most texels (or layers) [`encode_data`] writes along one axis. Engines have their own
/// limits (WebGL 2 guarantees 2048 for 2D textures and 256 for 3D ones and array layers); the
/// caller keeps within what its readers need.
pub const MAX_DATA_DIMENSION: usize = 16384;

/// A data texture of one level, every value as given (single floats, no scale): `values` holds
/// [`DataShape::values`] floats, layer after layer (or depth slice after slice), rows top to
/// bottom, texel after texel, channel after channel. `KTXorientation` is `rd` (`rdi` for a 3D
/// texture): row 0 is the first stored, slice 0 the first.
pub fn encode_data(shape: DataShape, values: &[f32], writer: &str) -> Result<Vec<u8>, Error> {
    let invalid = |message: String| Err(Error::InvalidConfig(message));
    let DataShape { width, height, depth, layers, channels } = shape;
    let vk_format = match channels {
        1 => VK_FORMAT_R32_SFLOAT,
        4 => VK_FORMAT_R32G32B32A32_SFLOAT,
        _ => return invalid(format!("{channels} channels: a data texture has 1 or 4")),
    };
    if width == 0 || height == 0 {
        return invalid(format!("empty data texture: {width} x {height}"));
    }
    if depth > 0 && layers > 0 {
        return invalid("a data texture is 3D or an array, not both".into());
    }
    if [width, height, depth, layers].iter().any(|&n| n > MAX_DATA_DIMENSION) {
        return invalid(format!(
            "a data texture of {width} x {height} x {depth} ({layers} layers) exceeds {MAX_DATA_DIMENSION} texels \
             along an axis"
        ));
    }
    if values.len() != shape.values() {
        return invalid(format!(
            "a data texture of {width} x {height} x {} needs {} values, found {}",
            depth.max(1) * layers.max(1),
            shape.values(),
            values.len()
        ));
    }
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::Overflow(format!("a data texture's value is not finite: {v}")));
    }
    let header = Header {
        vk_format,
        type_size: 4,
        channels,
        width,
        height,
        depth,
        layers,
        faces: 1,
        orientation: Some(if depth > 0 { "rdi" } else { "rd" }),
    };
    let mut bytes = container(&header, writer, &[4 * values.len()]);
    bytes.reserve_exact(4 * values.len());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    Ok(bytes)
}

/// A data texture of ours read back ([`decode_data`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Ktx2Data {
    pub shape: DataShape,
    /// In [`encode_data`]'s order.
    pub values: Vec<f32>,
}

/// Reads a data texture ([`encode_data`]: `R32_SFLOAT` or `R32G32B32A32_SFLOAT`, one level, 2D,
/// 2D array or 3D) with the `ktx2` crate, checking every size against the bytes before
/// allocating. The error says what is wrong.
pub fn decode_data(bytes: &[u8]) -> Result<Ktx2Data, String> {
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a ktx2 file: {e:?}"))?;
    let header = reader.header();
    let channels = match header.format {
        Some(ktx2::Format::R32_SFLOAT) => 1,
        Some(ktx2::Format::R32G32B32A32_SFLOAT) => 4,
        other => return Err(format!("expected an r32f or rgba32f data texture, found {other:?}")),
    };
    if let Some(scheme) = header.supercompression_scheme {
        return Err(format!("expected no supercompression, found scheme {}", scheme.value()));
    }
    if header.face_count != 1 || header.level_count > 1 {
        return Err(format!(
            "expected one level of one face, found {} levels of {} faces",
            header.level_count, header.face_count
        ));
    }
    let shape = DataShape {
        width: header.pixel_width as usize,
        height: header.pixel_height as usize,
        depth: header.pixel_depth as usize,
        layers: header.layer_count as usize,
        channels,
    };
    if shape.width == 0 || shape.height == 0 || (shape.depth > 0 && shape.layers > 0) {
        return Err(format!(
            "expected a 2d, 2d array or 3d texture, found {} x {} x {} with {} layers",
            shape.width, shape.height, shape.depth, shape.layers
        ));
    }
    let Some(level) = reader.levels().next() else { return Err("the file has no level".into()) };
    // The sizes come from the file: products that cannot overflow, then compared with the bytes.
    let expected = [shape.width, shape.height, shape.depth.max(1), shape.layers.max(1)]
        .iter()
        .try_fold(4 * channels, |acc: usize, &n| acc.checked_mul(n));
    if expected != Some(level.data.len()) {
        return Err(format!(
            "level 0 holds {} bytes, a {} x {} x {} texture with {} layers of {channels} floats needs {}",
            level.data.len(),
            shape.width,
            shape.height,
            shape.depth,
            shape.layers,
            expected.map_or("more than any file".to_string(), |n| n.to_string())
        ));
    }
    let values = level.data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    Ok(Ktx2Data { shape, values })
}

/// What a file's header says besides its levels.
struct Header {
    vk_format: u32,
    type_size: usize,
    /// 4 (R, G, B, A) or 1 (R).
    channels: usize,
    width: usize,
    height: usize,
    /// 0 for a 2D texture, array or cube map.
    depth: usize,
    /// 0 for a texture that is not an array.
    layers: usize,
    faces: usize,
    orientation: Option<&'static str>,
}

/// The bytes of a file before its texels: header, level index, data format descriptor, key/value
/// data (`KTXorientation` when the header has one, `KTXwriter` = `writer`) and the
/// padding that aligns the first level (the specification's mip padding: the least that aligns it
/// to the texel's bytes, lcm of the texel block size and 4; more is an error to Khronos'
/// validator). Level `l` holds `level_bytes[l]` bytes, each a multiple of the texel's, stored
/// smallest level first right after these bytes, so each starts aligned.
fn container(header: &Header, writer: &str, level_bytes: &[usize]) -> Vec<u8> {
    let dfd = data_format_descriptor(header.type_size, header.channels as u32);
    // Key/value data, sorted by key: only keys the specification defines.
    let mut kvd = Vec::new();
    let orientation = header.orientation.map(|o| ("KTXorientation", o));
    for (key, value) in orientation.into_iter().chain([("KTXwriter", writer)]) {
        let length = key.len() + 1 + value.len() + 1;
        kvd.extend_from_slice(&(length as u32).to_le_bytes());
        kvd.extend_from_slice(key.as_bytes());
        kvd.push(0);
        kvd.extend_from_slice(value.as_bytes());
        kvd.push(0);
        kvd.resize(kvd.len().next_multiple_of(4), 0);
    }
    let texel_bytes = (header.channels * header.type_size).max(4);
    let n_levels = level_bytes.len();
    let dfd_offset = 80 + 24 * n_levels;
    let kvd_offset = dfd_offset + dfd.len();
    let data_start = (kvd_offset + kvd.len()).next_multiple_of(texel_bytes);
    let mut offsets = vec![0usize; n_levels];
    let mut at = data_start;
    for l in (0..n_levels).rev() {
        offsets[l] = at;
        at += level_bytes[l];
    }

    let mut bytes = Vec::with_capacity(data_start);
    bytes.extend_from_slice(&IDENTIFIER);
    for value in [
        header.vk_format,
        header.type_size as u32,
        header.width as u32,
        header.height as u32,
        header.depth as u32,
        header.layers as u32,
        header.faces as u32,
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
    bytes
}

/// A KTX2 file of ours read back: its shape and format, and `levels[l][image]` as interleaved
/// RGB `f32` (alpha dropped), images layer-major then face.
#[derive(Clone, Debug, PartialEq)]
pub struct Ktx2Texture {
    pub shape: Shape,
    pub format: TexelFormat,
    pub levels: Vec<Vec<Vec<f32>>>,
}

/// Reads a float RGBA KTX2 file (either format, any shape [`encode`] writes) with the `ktx2`
/// crate, checking every size against the bytes before allocating. The error says what is wrong.
pub fn decode(bytes: &[u8]) -> Result<Ktx2Texture, String> {
    let reader = ktx2::Reader::new(bytes).map_err(|e| format!("not a ktx2 file: {e:?}"))?;
    let header = reader.header();
    let format = match header.format {
        Some(ktx2::Format::R16G16B16A16_SFLOAT) => TexelFormat::Rgba16f,
        Some(ktx2::Format::R32G32B32A32_SFLOAT) => TexelFormat::Rgba32f,
        other => return Err(format!("expected an rgba16f or rgba32f texture, found {other:?}")),
    };
    // pixelDepth 0 is a 2D texture; 1 and more a 3D one, whose levels hold depth slices.
    if header.pixel_depth != 0 || !(header.face_count == 1 || header.face_count == 6) {
        return Err(format!(
            "expected a 2d texture or cube map, found depth {} and {} faces",
            header.pixel_depth, header.face_count
        ));
    }
    // Supercompressed levels (BasisLZ, Zstandard, ZLIB) are not texels: refused, never read raw.
    if let Some(scheme) = header.supercompression_scheme {
        return Err(format!("expected no supercompression, found scheme {}", scheme.value()));
    }
    let shape = Shape {
        width: header.pixel_width as usize,
        height: header.pixel_height.max(1) as usize,
        layers: header.layer_count as usize,
        faces: header.face_count as usize,
    };
    let texel_bytes = 4 * format.type_size();
    let mut levels = Vec::new();
    for (l, level) in reader.levels().enumerate() {
        // Sizes from the file: shifts and products that cannot overflow.
        let shrink = |size: usize| size.checked_shr(l as u32).unwrap_or(0).max(1);
        let (w, h) = (shrink(shape.width), shrink(shape.height));
        let image_bytes = texel_bytes.checked_mul(w).and_then(|b| b.checked_mul(h));
        let expected = image_bytes.and_then(|b| b.checked_mul(shape.images()));
        let (Some(image_bytes), Some(expected)) = (image_bytes, expected) else {
            return Err(format!("level {l} of {w} x {h} x {} texels is larger than any file", shape.images()));
        };
        if level.data.len() != expected {
            return Err(format!("level {l} holds {} bytes, expected {expected}", level.data.len()));
        }
        let images = level
            .data
            .chunks_exact(image_bytes)
            .map(|image| {
                image
                    .chunks_exact(texel_bytes)
                    .flat_map(|t| {
                        (0..3).map(move |c| match format {
                            TexelFormat::Rgba16f => f16::from_le_bytes([t[2 * c], t[2 * c + 1]]).to_f32(),
                            TexelFormat::Rgba32f => {
                                f32::from_le_bytes([t[4 * c], t[4 * c + 1], t[4 * c + 2], t[4 * c + 3]])
                            }
                        })
                    })
                    .collect()
            })
            .collect();
        levels.push(images);
    }
    Ok(Ktx2Texture { shape, format, levels })
}

/// The data format descriptor of float texels of `type_size` bytes per channel with `samples`
/// channels (4: R, G, B, A; 1: R); see the module documentation.
fn data_format_descriptor(type_size: usize, samples: u32) -> Vec<u8> {
    let bits = 8 * type_size as u32;
    let block_size = 24 + 16 * samples;
    let mut words: Vec<u32> = vec![
        4 + block_size,           // dfdTotalSize
        0,                        // vendorId 0 (Khronos), descriptorType 0 (basic)
        2 | (block_size << 16),   // versionNumber 2 (KDF 1.3), descriptorBlockSize
        1 | (1 << 8) | (1 << 16), // colorModel RGBSDA, colorPrimaries BT709, transferFunction linear, flags 0
        0,                        // texelBlockDimension0..3 (value - 1): 1 x 1 x 1 x 1
        samples * bits / 8,       // bytesPlane0 = 4, 8 or 16, bytesPlane1..3 = 0
        0,                        // bytesPlane4..7
    ];
    const FLOAT_SIGNED: u32 = 0x80 | 0x40;
    for (i, channel) in [0u32, 1, 2, 15].into_iter().take(samples as usize).enumerate() {
        let bit_offset = bits * i as u32;
        words.push(bit_offset | ((bits - 1) << 16) | ((FLOAT_SIGNED | channel) << 24));
        words.push(0); // samplePosition0..3
        words.push((-1.0f32).to_bits()); // sampleLower
        words.push(1.0f32.to_bits()); // sampleUpper
    }
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}
