//! Our KTX2 writer read back with the maintained `ktx2` reader: the header, the data format
//! descriptor (against the one `ktx2` builds for the format), the key/value data, the level
//! index and the texels (against the layers written as EXR and read back); half floats where
//! every texel fits them, single floats where not, clamping only on request; cube maps.

use envmap::{EnvMap, MipChain, SampleType};
use ktx2::dfd::Basic;
use ktx2::{ColorModel, ColorPrimaries, Format, Reader, TransferFunction};
use prefilter::ktx::{self, Ktx2File, Shape, Storage, TexelFormat};
use prefilter::{Config, prefilter};

use crate::real_map;

/// Half-float rounding: round to nearest keeps 11 significant bits, so a normal value moves by at
/// most `2^-11` of itself; below the smallest normal half (`2^-14`) the spacing is `2^-24`, so a
/// subnormal moves by at most `2^-25`.
fn half_tolerance(value: f32) -> f32 {
    value.abs() * 2f32.powi(-11) + 2f32.powi(-25)
}

/// The texels of one level as `f32`, whatever the format.
fn values(data: &[u8], format: TexelFormat) -> Vec<f32> {
    match format {
        TexelFormat::Rgba16f => data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect(),
        TexelFormat::Rgba32f => data.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect(),
    }
}

/// The data format descriptor `ktx2` builds for `format` as linear BT.709 RGBA (every texture
/// this writer makes), and its type size.
fn linear_descriptor(format: Format) -> (Basic, u32) {
    Basic::from_format_with(
        format,
        false,
        Some(TransferFunction::Linear),
        Some(ColorPrimaries::BT709),
        Some(ColorModel::RGBSDA),
    )
    .unwrap()
}

/// The parts every file of ours shares: format, descriptor, key/value data (only standard keys:
/// no hidden scale), alignment.
fn check_common(reader: &Reader<&[u8]>, encoded: &Ktx2File) {
    let header = reader.header();
    let format = match encoded.format {
        TexelFormat::Rgba16f => Format::R16G16B16A16_SFLOAT,
        TexelFormat::Rgba32f => Format::R32G32B32A32_SFLOAT,
    };
    assert_eq!(header.format, Some(format));
    assert_eq!(header.type_size as usize, encoded.format.type_size());
    assert_eq!((header.pixel_depth, header.supercompression_scheme), (0, None));
    let (expected_dfd, type_size) = linear_descriptor(format);
    assert_eq!(type_size as usize, encoded.format.type_size());
    assert_eq!(reader.dfd_blocks().len(), 1);
    assert_eq!(reader.basic_dfd(), Some(&expected_dfd), "the descriptor ktx2 builds for {format:?}");
    let pairs: Vec<(&str, &[u8])> = reader.key_value_data().collect();
    let expected: Vec<(&str, &[u8])> = if header.face_count == 6 {
        vec![("KTXwriter", b"prefilter tests\0")]
    } else {
        vec![("KTXorientation", b"rd\0"), ("KTXwriter", b"prefilter tests\0")]
    };
    assert_eq!(pairs, expected);
    // Levels start at multiples of the texel size and are stored smallest first, without gaps;
    // the first starts at the least such offset after the key/value data (more padding is an
    // error to Khronos' validator).
    let texel = 4 * encoded.format.type_size() as u64;
    let index = level_index(reader.data(), header.level_count as usize);
    let kvd_end = u64::from(header.index.kvd_byte_offset + header.index.kvd_byte_length);
    let first = index.iter().map(|l| l.0).min().unwrap();
    assert_eq!(first, kvd_end.next_multiple_of(texel), "mip padding");
    let mut end = reader.data().len() as u64;
    for &(offset, length, uncompressed) in &index {
        assert_eq!(offset % texel, 0);
        assert_eq!(length, uncompressed);
        assert_eq!(offset + length, end, "level data is contiguous, level 0 last");
        end = offset;
    }
}

/// `(byteOffset, byteLength, uncompressedByteLength)` per level, read by hand after the 80-byte
/// header.
fn level_index(bytes: &[u8], levels: usize) -> Vec<(u64, u64, u64)> {
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
    (0..levels).map(|l| (u64_at(80 + 24 * l), u64_at(88 + 24 * l), u64_at(96 + 24 * l))).collect()
}

/// Compares stored RGBA with RGB `f32` values: half floats within their rounding, single floats
/// exactly.
fn check_texels(stored: &[f32], expected: &[f32], format: TexelFormat, what: &str) {
    assert_eq!(stored.len() / 4, expected.len() / 3, "{what}: texel count");
    for (i, (rgba, rgb)) in stored.chunks_exact(4).zip(expected.chunks_exact(3)).enumerate() {
        for c in 0..3 {
            let tolerance = if format == TexelFormat::Rgba16f { half_tolerance(rgb[c]) } else { 0.0 };
            assert!((rgba[c] - rgb[c]).abs() <= tolerance, "{what}, texel {i}, channel {c}: {} vs {}", rgba[c], rgb[c]);
        }
        assert_eq!(rgba[3], 1.0, "{what}, texel {i}: alpha");
    }
}

/// The layers of quarry (whose `n = 4096` layer peaks near 1800) as an array: half floats, every
/// layer reads back equal, up to half-float rounding, to the same layer written as an EXR (tagged
/// as a lat-long environment) and read back.
#[test]
fn the_layer_array_reads_back_and_matches_the_exr_layers() {
    let Some(map) = real_map("quarry_01_1k.hdr") else { return };
    let config = Config { width: 64, height: 32, ..Config::default() };
    let layers = prefilter(&map, &config).unwrap();
    let maps: Vec<&EnvMap> = layers.layers.iter().map(|l| &l.map).collect();
    let encoded = ktx::encode_array(&maps, Storage::Auto, "prefilter tests").unwrap();
    assert_eq!((encoded.format, encoded.clamped), (TexelFormat::Rgba16f, 0));
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let header = reader.header();
    assert_eq!((header.pixel_width, header.pixel_height), (64, 32));
    assert_eq!((header.layer_count, header.face_count, header.level_count), (8, 1, 1));
    let level = reader.levels().next().unwrap();
    assert_eq!(level.data.len(), 8 * 64 * 32 * 8);
    let stored = values(level.data, encoded.format);

    let dir = tempfile::tempdir().unwrap();
    for (k, layer) in layers.layers.iter().enumerate() {
        let path = dir.path().join(format!("layer-{k}.exr"));
        layer.map.write_exr(&path, SampleType::F32).unwrap();
        let exr = envmap::read_image(&path, &envmap::Limits::default()).unwrap();
        assert_eq!(exr.rgb, layer.map.rgb(), "the EXR holds the f32 layer exactly");
        let texels = &stored[k * 64 * 32 * 4..(k + 1) * 64 * 32 * 4];
        check_texels(texels, &exr.rgb, encoded.format, &format!("layer {k} (n = {})", layer.exponent));
        let bytes = std::fs::read(&path).unwrap();
        let tag = b"envmap\0envmap\0\x01\0\0\0\0";
        assert!(bytes.windows(tag.len()).any(|w| w == tag), "layer {k}: the EXR says envmap = latlong (0)");
    }
}

/// Quarry's sun texels (up to about 86 500) exceed the largest half float: the mip chain is stored
/// as single floats, exactly, with no scale; on request as half floats with the sun clamped.
#[test]
fn the_mip_chain_of_a_map_brighter_than_half_floats_is_stored_as_single_floats() {
    let Some(map) = real_map("quarry_01_1k.hdr") else { return };
    let chain = MipChain::new(&map);
    let encoded = ktx::encode_mip_chain(&chain, Storage::Auto, "prefilter tests").unwrap();
    assert_eq!((encoded.format, encoded.clamped), (TexelFormat::Rgba32f, 0));
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let header = reader.header();
    assert_eq!((header.pixel_width, header.pixel_height, header.layer_count), (1024, 512, 0));
    assert_eq!(header.level_count as usize, chain.n_levels());
    assert_eq!(chain.n_levels(), 10, "1024 x 512 halves down to 2 x 1");
    for (l, level) in reader.levels().enumerate() {
        let expected = chain.level(l);
        assert_eq!(level.data.len(), 16 * expected.width() * expected.height(), "level {l}");
        check_texels(&values(level.data, encoded.format), expected.rgb(), encoded.format, &format!("level {l}"));
    }
    // The same chain through the toolchain's reader.
    let decoded = ktx::decode(&encoded.bytes).unwrap();
    assert_eq!(decoded.levels[3][0], chain.level(3).rgb());

    let clamped = ktx::encode_mip_chain(&chain, Storage::ClampHalf, "prefilter tests").unwrap();
    assert_eq!(clamped.format, TexelFormat::Rgba16f);
    let beyond = chain.levels().iter().flat_map(|m| m.rgb().iter()).filter(|v| **v > ktx::HALF_MAX).count();
    assert!(beyond > 0 && clamped.clamped == beyond, "{} clamped of {beyond}", clamped.clamped);
    let decoded = ktx::decode(&clamped.bytes).unwrap();
    let largest = decoded.levels[0][0].iter().fold(0.0f32, |m, v| m.max(*v));
    assert_eq!(largest, ktx::HALF_MAX);
}

/// The byte layout adds up, for both formats.
#[test]
fn sizes_add_up() {
    for (brightest, format, texel_bytes) in [(3.0f32, TexelFormat::Rgba16f, 8), (1e6, TexelFormat::Rgba32f, 16)] {
        let map = EnvMap::new(4, 2, [brightest, 0.0, 3.0].repeat(8)).unwrap();
        let encoded = ktx::encode_array(&[&map, &map], Storage::Auto, "prefilter tests").unwrap();
        assert_eq!(encoded.format, format);
        let reader = Reader::new(&encoded.bytes[..]).unwrap();
        check_common(&reader, &encoded);
        let kvd_length = reader.header().index.kvd_byte_length as usize;
        // Header and level index, descriptor, key/value data, padding to the texel, 2 layers of 8
        // texels.
        let data_start = (80 + 24 + 92 + kvd_length).next_multiple_of(texel_bytes);
        assert_eq!(encoded.bytes.len(), data_start + 2 * 8 * texel_bytes);
        let stored = values(reader.levels().next().unwrap().data, format);
        check_texels(&stored, &[map.rgb(), map.rgb()].concat(), format, format.name());
    }
}

/// A cube map: six square faces per level, in the specification's order, read back in that order.
#[test]
fn a_cube_map_holds_six_faces_per_level() {
    let faces: Vec<Vec<f32>> = (0..6).map(|f| [f as f32, 0.5, 1.0].repeat(16)).collect();
    let small: Vec<Vec<f32>> = (0..6).map(|f| [f as f32 + 10.0, 0.5, 1.0].repeat(4)).collect();
    let levels = vec![faces.iter().map(Vec::as_slice).collect(), small.iter().map(Vec::as_slice).collect()];
    let shape = Shape { width: 4, height: 4, layers: 0, faces: 6 };
    let encoded = ktx::encode(shape, &levels, Storage::Auto, "prefilter tests").unwrap();
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let header = reader.header();
    assert_eq!((header.face_count, header.layer_count, header.level_count), (6, 0, 2));
    let decoded = ktx::decode(&encoded.bytes).unwrap();
    assert_eq!(decoded.shape, shape);
    assert_eq!(decoded.levels[0], faces);
    assert_eq!(decoded.levels[1], small);
    let not_square = Shape { width: 4, height: 2, layers: 0, faces: 6 };
    assert!(ktx::encode(not_square, &levels, Storage::Auto, "w").is_err());
}

#[test]
fn inconsistent_inputs_are_refused() {
    let a = EnvMap::constant(4, 2, [1.0; 3]).unwrap();
    let b = EnvMap::constant(8, 4, [1.0; 3]).unwrap();
    let message = ktx::encode_array(&[&a, &b], Storage::Auto, "w").unwrap_err().to_string();
    assert_eq!(message, "array layers differ in size: 4 x 2 and 8 x 4");
    assert!(ktx::encode_array(&[], Storage::Auto, "w").is_err());
    let too_many = vec![vec![a.rgb()]; 4];
    let shape = Shape { width: 4, height: 2, layers: 0, faces: 1 };
    let message = ktx::encode(shape, &too_many, Storage::Auto, "w").unwrap_err().to_string();
    assert_eq!(message, "4 levels do not fit a 4 x 2 texture");
}

/// A KTX2 header that declares more texels than any file holds (`2^32 - 1` squared, `2^32 - 1`
/// layers: the byte count wraps past 2^64) is refused by the reader, never allocated or wrapped.
#[test]
fn a_header_whose_size_wraps_is_refused() {
    let rgb = [0.5f32; 3 * 4 * 2];
    let shape = Shape { width: 4, height: 2, layers: 0, faces: 1 };
    let mut bytes = ktx::encode(shape, &[vec![&rgb[..]]], Storage::Auto, "test").unwrap().bytes;
    assert_eq!(ktx::decode(&bytes).unwrap().levels[0][0], rgb);
    // Header: pixelWidth at 20, pixelHeight at 24, layerCount at 32 (KTX2 specification).
    for at in [20, 24, 32] {
        bytes[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    }
    let error = ktx::decode(&bytes).unwrap_err();
    assert!(error.contains("larger than any file") || error.contains("not a ktx2 file"), "{error}");
}

/// A file of our format but with a depth (a 3D texture, even of depth 1) or supercompressed levels
/// is refused: its levels are not the raw 2D texels the reader would take them for.
#[test]
fn depth_and_supercompression_are_refused() {
    let rgb = [0.5f32; 3 * 4 * 2];
    let shape = Shape { width: 4, height: 2, layers: 0, faces: 1 };
    let bytes = ktx::encode(shape, &[vec![&rgb[..]]], Storage::Auto, "test").unwrap().bytes;
    // Header: pixelDepth at 28, supercompressionScheme at 44 (KTX2 specification).
    for (at, value, expected) in [
        (28, 1u32, "found depth 1"),
        (44, 2, "expected no supercompression, found scheme 2"),
        (44, 1, "found scheme 1"),
    ] {
        let mut damaged = bytes.clone();
        damaged[at..at + 4].copy_from_slice(&value.to_le_bytes());
        let error = ktx::decode(&damaged).unwrap_err();
        assert!(error.contains(expected), "{at} = {value}: {error}");
    }
}

/// A data texture ([`ktx::encode_data`]) of every shape, checked field by field with `ktx2` and
/// read back exactly by [`ktx::decode_data`].
fn check_data(shape: ktx::DataShape, orientation: &[u8]) {
    let values: Vec<f32> = (0..shape.values()).map(|i| (i as f32 * 0.37).sin() * 1e5 - 3.25).collect();
    let bytes = ktx::encode_data(shape, &values, "prefilter tests").unwrap();
    let reader = Reader::new(&bytes[..]).unwrap();
    let header = reader.header();
    let format = if shape.channels == 1 { Format::R32_SFLOAT } else { Format::R32G32B32A32_SFLOAT };
    assert_eq!(header.format, Some(format));
    assert_eq!(header.type_size, 4);
    let dims = (header.pixel_width, header.pixel_height, header.pixel_depth, header.layer_count, header.face_count);
    let expected = (shape.width as u32, shape.height as u32, shape.depth as u32, shape.layers as u32, 1);
    assert_eq!(dims, expected);
    assert_eq!((header.level_count, header.supercompression_scheme), (1, None));
    let (expected_dfd, _) = linear_descriptor(format);
    assert_eq!(reader.basic_dfd(), Some(&expected_dfd), "the descriptor ktx2 builds for {format:?}");
    let pairs: Vec<(&str, &[u8])> = reader.key_value_data().collect();
    assert_eq!(pairs, vec![("KTXorientation", orientation), ("KTXwriter", b"prefilter tests\0")]);
    let (offset, length, _) = level_index(&bytes, 1)[0];
    assert_eq!(offset % (4 * shape.channels as u64).max(4), 0, "level 0 is aligned to its texel");
    assert_eq!((offset + length) as usize, bytes.len());
    let decoded = ktx::decode_data(&bytes).unwrap();
    assert_eq!(decoded.shape, shape);
    assert_eq!(decoded.values, values, "single floats read back exactly");
}

#[test]
fn data_textures_of_every_shape_read_back_exactly() {
    let shape = |width, height, depth, layers, channels| ktx::DataShape { width, height, depth, layers, channels };
    check_data(shape(7, 3, 0, 0, 1), b"rd\0");
    check_data(shape(5, 4, 0, 3, 1), b"rd\0");
    check_data(shape(6, 2, 0, 2, 4), b"rd\0");
    check_data(shape(4, 3, 5, 0, 4), b"rdi\0");
}

#[test]
fn data_textures_that_cannot_be_written_are_refused() {
    let shape = |width, height, depth, layers, channels| ktx::DataShape { width, height, depth, layers, channels };
    let refused = |s: ktx::DataShape, values: &[f32]| ktx::encode_data(s, values, "t").unwrap_err().to_string();
    assert!(refused(shape(2, 2, 0, 0, 3), &[0.0; 12]).contains("1 or 4"));
    assert!(refused(shape(0, 2, 0, 0, 1), &[]).contains("empty"));
    assert!(refused(shape(2, 2, 2, 2, 1), &[0.0; 16]).contains("not both"));
    assert!(refused(shape(2, 2, 0, 0, 1), &[0.0; 3]).contains("needs 4 values, found 3"));
    assert!(refused(shape(2, 1, 0, 0, 1), &[0.0, f32::NAN]).contains("not finite"));
    // A colour texture is not a data texture, and a truncated one is refused.
    let colour =
        ktx::encode(Shape { width: 2, height: 1, layers: 0, faces: 1 }, &[vec![&[0.0f32; 6][..]]], Storage::Auto, "t");
    assert!(ktx::decode_data(&colour.unwrap().bytes).unwrap_err().contains("expected an r32f or rgba32f"));
    let bytes = ktx::encode_data(shape(3, 2, 0, 0, 4), &[1.0; 24], "t").unwrap();
    assert!(ktx::decode_data(&bytes[..bytes.len() - 4]).is_err());
}
