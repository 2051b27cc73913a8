//! Our KTX2 writer read back with the maintained `ktx2` reader: the header, the data format
//! descriptor (against the one `ktx2` builds for the format), the key/value data, the level
//! index and the texels (against the layers written as EXR and read back).

use envmap::{EnvMap, MipChain, SampleType};
use ktx2::dfd::Basic;
use ktx2::{ColorModel, ColorPrimaries, Format, Reader, TransferFunction};
use prefilter::ktx::{self, Encoded};
use prefilter::{Config, prefilter};

use crate::real_map;

/// Half-float rounding: round to nearest keeps 11 significant bits, so a normal value moves by at
/// most `2^-11` of itself; below the smallest normal half (`2^-14`) the spacing is `2^-24`, so a
/// subnormal moves by at most `2^-25`. Stored values are radiance times the file's scale.
fn half_tolerance(value: f32, scale: f32) -> f32 {
    value.abs() * 2f32.powi(-11) + 2f32.powi(-25) / scale
}

fn halves(data: &[u8]) -> Vec<f32> {
    data.chunks_exact(2).map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32()).collect()
}

/// The parts every file of ours shares: format, descriptor, key/value data, alignment.
fn check_common(reader: &Reader<&[u8]>, encoded: &Encoded) {
    let header = reader.header();
    assert_eq!(header.format, Some(Format::R16G16B16A16_SFLOAT));
    assert_eq!(header.type_size, 2);
    assert_eq!((header.pixel_depth, header.face_count, header.supercompression_scheme), (0, 1, None));
    let (expected_dfd, type_size) = Basic::from_format_with(
        Format::R16G16B16A16_SFLOAT,
        false,
        Some(TransferFunction::Linear),
        Some(ColorPrimaries::BT709),
        Some(ColorModel::RGBSDA),
    )
    .unwrap();
    assert_eq!(type_size, 2);
    assert_eq!(reader.dfd_blocks().len(), 1);
    assert_eq!(reader.basic_dfd(), Some(&expected_dfd), "the descriptor ktx2 builds for R16G16B16A16_SFLOAT");
    let pairs: Vec<(&str, &[u8])> = reader.key_value_data().collect();
    let scale = format!("{}\0", encoded.radiance_scale);
    let expected: Vec<(&str, &[u8])> =
        vec![("KTXorientation", b"rd\0"), ("KTXwriter", b"prefilter tests\0"), ("radiance_scale", scale.as_bytes())];
    assert_eq!(pairs, expected);
    // Levels start at multiples of 8 and are stored smallest first, without gaps.
    let index = level_index(reader.data(), header.level_count as usize);
    let mut end = reader.data().len() as u64;
    for &(offset, length, uncompressed) in &index {
        assert_eq!(offset % 8, 0);
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

/// Compares stored RGBA halves with RGB `f32` values.
fn check_texels(stored: &[f32], expected: &[f32], scale: f32, what: &str) {
    assert_eq!(stored.len() / 4, expected.len() / 3, "{what}: texel count");
    for (i, (rgba, rgb)) in stored.chunks_exact(4).zip(expected.chunks_exact(3)).enumerate() {
        for c in 0..3 {
            let got = rgba[c] / scale;
            assert!(
                (got - rgb[c]).abs() <= half_tolerance(rgb[c], scale),
                "{what}, texel {i}, channel {c}: {got} vs {}",
                rgb[c]
            );
        }
        assert_eq!(rgba[3], 1.0, "{what}, texel {i}: alpha");
    }
}

/// The layers of quarry (whose `n = 4096` layer peaks near 1800) as an array: every layer reads
/// back equal, up to half-float rounding, to the same layer written as an EXR and read back.
#[test]
fn the_layer_array_reads_back_and_matches_the_exr_layers() {
    let map = real_map("quarry_01_1k.hdr");
    let config = Config { width: 64, height: 32, ..Config::default() };
    let layers = prefilter(&map, &config).unwrap();
    let maps: Vec<&EnvMap> = layers.layers.iter().map(|l| &l.map).collect();
    let encoded = ktx::encode_array(&maps, "prefilter tests").unwrap();
    assert_eq!(encoded.radiance_scale, 1.0);
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let header = reader.header();
    assert_eq!((header.pixel_width, header.pixel_height), (64, 32));
    assert_eq!((header.layer_count, header.level_count), (7, 1));
    let level = reader.levels().next().unwrap();
    assert_eq!(level.data.len(), 7 * 64 * 32 * 8);
    let stored = halves(level.data);

    let dir = tempfile::tempdir().unwrap();
    for (k, layer) in layers.layers.iter().enumerate() {
        let path = dir.path().join(format!("layer-{k}.exr"));
        layer.map.write_exr(&path, SampleType::F32).unwrap();
        let exr = envmap::read_image(&path, &envmap::Limits::default()).unwrap();
        assert_eq!(exr.rgb, layer.map.rgb(), "the EXR holds the f32 layer exactly");
        let texels = &stored[k * 64 * 32 * 4..(k + 1) * 64 * 32 * 4];
        check_texels(texels, &exr.rgb, encoded.radiance_scale, &format!("layer {k} (n = {})", layer.exponent));
    }
}

/// Quarry's sun texels (up to about 86 500) exceed the largest half float: the mip chain is stored
/// at half scale and reads back to the chain's levels within half-float rounding.
#[test]
fn the_mip_chain_reads_back_with_its_scale() {
    let chain = MipChain::new(&real_map("quarry_01_1k.hdr"));
    let encoded = ktx::encode_mip_chain(&chain, "prefilter tests").unwrap();
    assert_eq!(encoded.radiance_scale, 0.5);
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let header = reader.header();
    assert_eq!((header.pixel_width, header.pixel_height, header.layer_count), (1024, 512, 0));
    assert_eq!(header.level_count as usize, chain.n_levels());
    assert_eq!(chain.n_levels(), 10, "1024 x 512 halves down to 2 x 1");
    for (l, level) in reader.levels().enumerate() {
        let expected = chain.level(l);
        assert_eq!(level.data.len(), 8 * expected.width() * expected.height(), "level {l}");
        check_texels(&halves(level.data), expected.rgb(), encoded.radiance_scale, &format!("level {l}"));
    }
}

/// The scale is the largest power of two that fits the brightest texel; the byte layout adds up.
#[test]
fn scale_and_size() {
    let check = |max: f32, scale: f32| assert_eq!(ktx::half_scale(max), scale, "largest value {max}");
    check(0.0, 1.0);
    check(65504.0, 1.0);
    check(65505.0, 0.5);
    check(131_008.0, 0.5);
    check(131_009.0, 0.25);
    check(1e9, 2f32.powi(-14));

    let map = EnvMap::new(4, 2, [1e6f32, 0.0, 3.0].repeat(8)).unwrap();
    let encoded = ktx::encode_array(&[&map, &map], "prefilter tests").unwrap();
    assert_eq!(encoded.radiance_scale, 2f32.powi(-4));
    let reader = Reader::new(&encoded.bytes[..]).unwrap();
    check_common(&reader, &encoded);
    let kvd_length = reader.header().index.kvd_byte_length as usize;
    // Header and level index, descriptor, key/value data, padding to 8, 2 layers of 8 texels.
    let data_start = (80 + 24 + 92 + kvd_length).next_multiple_of(8);
    assert_eq!(encoded.bytes.len(), data_start + 2 * 8 * 8);
    check_texels(
        &halves(reader.levels().next().unwrap().data),
        &[map.rgb(), map.rgb()].concat(),
        encoded.radiance_scale,
        "scaled",
    );
}

#[test]
fn inconsistent_inputs_are_refused() {
    let a = EnvMap::constant(4, 2, [1.0; 3]).unwrap();
    let b = EnvMap::constant(8, 4, [1.0; 3]).unwrap();
    let message = ktx::encode_array(&[&a, &b], "w").unwrap_err().to_string();
    assert_eq!(message, "array layers differ in size: 4 x 2 and 8 x 4");
    assert!(ktx::encode_array(&[], "w").is_err());
    let too_many = vec![vec![a.rgb()]; 4];
    let message = ktx::encode_rgba16f(4, 2, 0, &too_many, "w").unwrap_err().to_string();
    assert_eq!(message, "4 levels do not fit a 4 x 2 texture");
}
