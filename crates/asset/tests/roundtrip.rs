//! read(write(a)) = a for random assets, in memory and through files.

use asset::{
    Asset, BandwidthAnalysis, BandwidthAtlas, BandwidthPca, BandwidthRows, ImportanceSamples, LinkedFile, MaterialInfo,
    Payload, PrefilteredEnvmap, Provenance, decode, encode, read_file, write_file,
};
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

/// A finite value of [`random_f64`]'s kinds (statistics of a table, whose cells are finite).
fn random_finite_f64(rng: &mut StdRng) -> f64 {
    loop {
        let v = random_f64(rng);
        if v.is_finite() {
            return v;
        }
    }
}

fn random_rgb(rng: &mut StdRng) -> [f64; 3] {
    std::array::from_fn(|_| random_finite_f64(rng))
}

/// A value that a field held to "finite and not negative" (bandwidths, densities, radiances)
/// accepts: zero of either sign and denormals among them.
fn random_non_negative(rng: &mut StdRng) -> f64 {
    const SPECIAL: [f64; 4] = [0.0, -0.0, f64::MIN_POSITIVE / 2.0, 1e-40];
    if rng.random_bool(0.1) {
        SPECIAL[rng.random_range(0..SPECIAL.len())]
    } else {
        rng.random::<f64>() * 10f64.powi(rng.random_range(-8..8))
    }
}

fn random_asset(rng: &mut StdRng) -> Asset {
    let angles = random_len(rng);
    let payload = match rng.random_range(0..6) {
        0 => Payload::MaterialInfo(MaterialInfo {
            dims: rng.random(),
            no_data_cells: rng.random(),
            channel_min: random_rgb(rng),
            channel_max: random_rgb(rng),
            channel_mean: random_rgb(rng),
            peak_rgb: random_rgb(rng),
            peak_cell: rng.random(),
            albedo_theta_o: (0..angles).map(|_| rng.random_range(0.0..=std::f64::consts::FRAC_PI_2)).collect(),
            albedo_rgb: (0..angles).map(|_| random_rgb(rng)).collect(),
            albedo_no_data_fraction: (0..angles).map(|_| rng.random_range(0.0..=1.0)).collect(),
        }),
        1 => random_importance_samples(rng),
        2 => random_prefiltered_envmap(rng),
        3 => random_bandwidth_atlas(rng),
        4 => random_bandwidth_rows(rng),
        _ => random_bandwidth_pca(rng),
    };
    Asset {
        provenance: Provenance {
            source_name: random_string(rng),
            source_sha256: rng.random(),
            tool: random_string(rng),
            tool_version: random_string(rng),
            parameters: (0..random_len(rng)).map(|_| (random_string(rng), random_string(rng))).collect(),
        },
        payload,
    }
}

/// Consistent sizes (the payload's invariant), random contents.
/// A grid of at least one pixel and a positive finite constant (what the payload checks hold
/// bandwidths against); any threshold.
fn random_analysis(rng: &mut StdRng) -> BandwidthAnalysis {
    BandwidthAnalysis {
        parameterization: random_string(rng),
        analysis_size: rng.random_range(1..=u32::MAX),
        eps: random_f64(rng),
        c: rng.random_range(f64::MIN_POSITIVE..10.0),
    }
}

/// `n` bandwidths of `analysis`: within `[0, its bound]`, zeros of either sign among them.
fn random_bandwidths(rng: &mut StdRng, analysis: &BandwidthAnalysis, n: usize) -> Vec<f32> {
    // Rounding to f32 may go past the bound by a hair: stay a little inside.
    let most = analysis.bandwidth_bound() * 0.999;
    let mut one = || match rng.random_range(0..10) {
        0 => -0.0,
        1 => most as f32,
        _ => (most * rng.random::<f64>()) as f32,
    };
    (0..n).map(|_| one()).collect()
}

/// Consistent sizes (the payload's invariant), random contents.
fn random_bandwidth_atlas(rng: &mut StdRng) -> Payload {
    let (lobes_x, lobes_y, tile) = (rng.random_range(1..4u32), rng.random_range(1..4u32), rng.random_range(1..4u32));
    let n = (lobes_x * lobes_y * tile * tile) as usize;
    let analysis = random_analysis(rng);
    let data = random_bandwidths(rng, &analysis, n);
    Payload::BandwidthAtlas(BandwidthAtlas { lobes_x, lobes_y, tile, analysis, data })
}

/// Consistent sizes (the payload's invariant), random contents; the columns the rows stand for
/// range over all they may (they size nothing that is stored, up to `MAX_ROWS_COLUMNS`).
fn random_bandwidth_rows(rng: &mut StdRng) -> Payload {
    let (lobes_y, tile) = (rng.random_range(1..4u32), rng.random_range(1..4u32));
    let lobes_x =
        if rng.random_bool(0.5) { rng.random_range(1..4u32) } else { rng.random_range(1..=asset::MAX_ROWS_COLUMNS) };
    let n = (lobes_y * tile * tile) as usize;
    let analysis = random_analysis(rng);
    let data = random_bandwidths(rng, &analysis, n);
    Payload::BandwidthRows(BandwidthRows { lobes_x, lobes_y, tile, analysis, data })
}

/// Consistent sizes (the payload's invariant), random contents.
fn random_bandwidth_pca(rng: &mut StdRng) -> Payload {
    let (lobes_x, lobes_y, tile) = (rng.random_range(1..4u32), rng.random_range(1..4u32), rng.random_range(1..4u32));
    let k = rng.random_range(0..4u32);
    let tile_len = (tile * tile) as usize;
    // What the values may be: the mean's bandwidths within the analysis's bound, unit components,
    // coefficients within sqrt(tile_len) times the bound (a little inside: f32 rounding).
    let analysis = random_analysis(rng);
    let mean = random_bandwidths(rng, &analysis, tile_len);
    let components = (0..k)
        .flat_map(|_| {
            let v: Vec<f64> = (0..tile_len).map(|_| rng.random_range(-1.0..=1.0) + 1e-3).collect();
            let length = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.into_iter().map(move |x| (x / length) as f32)
        })
        .collect();
    let most = (tile_len as f64).sqrt() * analysis.bandwidth_bound() * 0.999;
    let coefficients = (0..lobes_x * lobes_y * k).map(|_| (most * rng.random_range(-1.0..=1.0)) as f32).collect();
    Payload::BandwidthPca(BandwidthPca {
        lobes_x,
        lobes_y,
        tile,
        analysis,
        n_components: k,
        mean,
        components,
        coefficients,
    })
}

fn random_importance_samples(rng: &mut StdRng) -> Payload {
    let (slices, rows, cols) = (rng.random_range(1..4), rng.random_range(1..5), rng.random_range(1..6));
    let (vectors, samples) = (rng.random_range(1..3u32), rng.random_range(1..5u32));
    // What the values may be: unit directions, densities finite and not negative, CDFs in [0, 1].
    let samples_data = (0..slices * (vectors * samples) as usize)
        .map(|_| {
            let (z, phi) = (rng.random_range(-1.0..=1.0f64), rng.random_range(0.0..std::f64::consts::TAU));
            let r = (1.0 - z * z).sqrt();
            [(r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32, random_non_negative(rng) as f32]
        })
        .collect();
    let mut cdf = |n: usize| -> Vec<f32> { (0..n).map(|_| rng.random_range(0.0..=1.0f32)).collect() };
    let (marginal_cdf, conditional_cdf) = (cdf(slices * (rows + 1)), cdf(slices * rows * (cols + 1)));
    let h_density = (0..slices * rows * cols).map(|_| random_non_negative(rng) as f32).collect();
    Payload::ImportanceSamples(ImportanceSamples {
        theta_o: (0..slices).map(|_| random_f64(rng)).collect(),
        n_vectors: vectors,
        n_samples: samples,
        theta_h_edges: (0..=rows).map(|_| random_f64(rng)).collect(),
        n_phi_h: cols as u32,
        samples: samples_data,
        marginal_cdf,
        conditional_cdf,
        h_density,
    })
}

/// Consistent sizes and orders (the payload's invariants), random contents: bandwidths and
/// thresholds interleaved, distinct plain file names.
fn random_prefiltered_envmap(rng: &mut StdRng) -> Payload {
    let layers = rng.random_range(1..8);
    let mut exponents: Vec<u32> = Vec::new();
    for _ in 0..layers {
        let previous = exponents.last().copied().unwrap_or(0);
        exponents.push(previous + rng.random_range(1..5000));
    }
    // Increasing bandwidths, thresholds strictly between their neighbours.
    let mut lobe_bandwidth = Vec::new();
    let mut bandwidth_thresholds = Vec::new();
    let mut at = rng.random::<f64>() + 1e-3;
    for k in 0..layers {
        if k > 0 {
            at += rng.random::<f64>() + 1e-3;
            bandwidth_thresholds.push(at);
            at += rng.random::<f64>() + 1e-3;
        }
        lobe_bandwidth.push(at);
    }
    let mut file = |i: usize| LinkedFile {
        name: format!("{}-{i}", random_string(rng).replace(['/', '\\', '\0'], "_")),
        sha256: rng.random(),
    };
    let (layers_ktx2, mips_ktx2, contact_sheet_png) = (file(0), file(1), file(2));
    let layer_exrs = (3..3 + layers).map(file).collect();
    let height = rng.random_range(1..u32::MAX / 2);
    let layer_height = rng.random_range(1..=asset::MAX_LAYER_HEIGHT);
    let mut rgb = || [0; 3].map(|_| random_non_negative(rng));
    let (source_mean_radiance, layer_mean_radiance) = (rgb(), (0..layers).map(|_| rgb()).collect());
    Payload::PrefilteredEnvmap(PrefilteredEnvmap {
        source_size: [2 * height, height],
        source_mean_radiance,
        layer_size: [2 * layer_height, layer_height],
        mip_levels: rng.random_range(1..=1 + (2 * height).ilog2()),
        layers_radiance_scale: 0.5f64.powi(rng.random_range(0..20)),
        mips_radiance_scale: 0.5f64.powi(rng.random_range(0..20)),
        exponents,
        lobe_bandwidth,
        bandwidth_thresholds,
        layer_mean_radiance,
        layers_ktx2,
        layer_exrs,
        mips_ktx2,
        contact_sheet_png,
    })
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
    asset.payload = Payload::MaterialInfo(MaterialInfo {
        dims: [0; 3],
        no_data_cells: 0,
        channel_min: [0.0; 3],
        channel_max: [0.0; 3],
        channel_mean: [0.0; 3],
        peak_rgb: [0.0; 3],
        peak_cell: [0; 3],
        albedo_theta_o: vec![1.0],
        albedo_rgb: vec![[1.0; 3]],
        albedo_no_data_fraction: vec![0.0],
    });
    let Payload::MaterialInfo(info) = &mut asset.payload else { unreachable!() };
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
