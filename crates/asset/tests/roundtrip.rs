//! read(write(a)) = a for random assets, in memory and through files.

use asset::{Asset, MaterialInfo, Payload, Provenance, decode, encode, read_file, write_file};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Characters of every UTF-8 width, plus the ones that trip naive escaping.
const CHARS: &[char] = &['a', 'Z', '0', ' ', '"', '\\', '\n', '\0', 'é', 'λ', 'ß', '日', '本', '☀', '🎨', '𝔹'];

/// Floats that are not in `[0, 1)`, including ones a lossy encoding would change (`-0.0`,
/// subnormals). No NaN: the comparison below is `PartialEq`.
const SPECIAL_F64: &[f64] = &[
    0.0,
    -0.0,
    1.0,
    -1.0,
    f64::MIN_POSITIVE,
    5e-324,
    f64::MAX,
    f64::MIN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    std::f64::consts::PI,
];

fn random_len(rng: &mut StdRng) -> usize {
    // Empty a quarter of the time, so that every empty vector and string is exercised often.
    if rng.random_bool(0.25) { 0 } else { rng.random_range(1..8) }
}

fn random_string(rng: &mut StdRng) -> String {
    (0..random_len(rng)).map(|_| CHARS[rng.random_range(0..CHARS.len())]).collect()
}

fn random_f64(rng: &mut StdRng) -> f64 {
    if rng.random_bool(0.1) {
        SPECIAL_F64[rng.random_range(0..SPECIAL_F64.len())]
    } else {
        (rng.random::<f64>() - 0.5) * 10f64.powi(rng.random_range(-8..8))
    }
}

fn random_rgb(rng: &mut StdRng) -> [f64; 3] {
    std::array::from_fn(|_| random_f64(rng))
}

fn random_asset(rng: &mut StdRng) -> Asset {
    let angles = random_len(rng);
    Asset {
        provenance: Provenance {
            source_name: random_string(rng),
            source_sha256: rng.random(),
            tool: random_string(rng),
            tool_version: random_string(rng),
            parameters: (0..random_len(rng)).map(|_| (random_string(rng), random_string(rng))).collect(),
        },
        payload: Payload::MaterialInfo(MaterialInfo {
            dims: rng.random(),
            no_data_cells: rng.random(),
            channel_min: random_rgb(rng),
            channel_max: random_rgb(rng),
            channel_mean: random_rgb(rng),
            peak_rgb: random_rgb(rng),
            peak_cell: rng.random(),
            albedo_theta_o: (0..angles).map(|_| random_f64(rng)).collect(),
            albedo_rgb: (0..angles).map(|_| random_rgb(rng)).collect(),
            albedo_no_data_fraction: (0..angles).map(|_| random_f64(rng)).collect(),
        }),
    }
}

/// Decoding gives the value back, and encoding that again gives the same bytes (which also
/// catches what `PartialEq` on floats cannot see, such as the sign of zero).
fn check_round_trip(asset: &Asset) {
    let bytes = encode(asset);
    let decoded = decode(&bytes).unwrap_or_else(|e| panic!("decoding {asset:?}: {e}"));
    assert_eq!(&decoded, asset);
    assert_eq!(encode(&decoded), bytes, "re-encoding {asset:?}");
}

#[test]
fn random_assets_round_trip_in_memory() {
    let mut rng = StdRng::seed_from_u64(0x5eed_a55e7);
    for _ in 0..1000 {
        check_round_trip(&random_asset(&mut rng));
    }
}

#[test]
fn empty_strings_and_vectors_round_trip() {
    let mut asset = random_asset(&mut StdRng::seed_from_u64(1));
    asset.provenance = Provenance {
        source_name: String::new(),
        source_sha256: [0; 32],
        tool: String::new(),
        tool_version: String::new(),
        parameters: Vec::new(),
    };
    let Payload::MaterialInfo(info) = &mut asset.payload;
    info.albedo_theta_o.clear();
    info.albedo_rgb.clear();
    info.albedo_no_data_fraction.clear();
    check_round_trip(&asset);
}

#[test]
fn random_assets_round_trip_through_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = StdRng::seed_from_u64(0xf11e);
    for i in 0..50 {
        let asset = random_asset(&mut rng);
        // Half the writes replace an existing file.
        let path = dir.path().join(format!("{}.asset", i % 25));
        write_file(&path, &asset).unwrap();
        assert_eq!(read_file(&path).unwrap(), asset, "{}", path.display());
        assert_eq!(std::fs::read(&path).unwrap(), encode(&asset));
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 25, "temporary files were left behind");
}
