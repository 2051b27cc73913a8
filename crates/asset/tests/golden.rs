//! The golden v1 file: it must always load and equal the value built here. Its bytes are
//! checked against an independent writer that follows `data-schema/README.md` field by field,
//! so the README, the committed file and the crate's writer cannot drift apart unnoticed.

use std::f64::consts::{FRAC_PI_3, FRAC_PI_6};

use asset::{Asset, AssetKind, MaterialInfo, Payload, Provenance, encode, read_file, read_header};

use crate::{fixtures_dir, regenerating};

pub const GOLDEN_V1: &str = "assets/golden-v1-material-info.asset";

/// The content of the golden v1 file. Frozen: changing it means a new golden file.
pub fn golden_v1_asset() -> Asset {
    Asset {
        provenance: Provenance {
            source_name: "golden-lambert-0.5.binary".into(),
            source_sha256: asset::sha256(b"golden v1 source"),
            tool: "merl-info".into(),
            tool_version: "0.1.0".into(),
            parameters: vec![
                ("interp".into(), "nearest".into()),
                ("quadrature".into(), "64x128".into()),
                ("note".into(), "unicode survives: é λ 日本 🎨".into()),
            ],
        },
        payload: Payload::MaterialInfo(MaterialInfo {
            dims: [90, 90, 180],
            no_data_cells: 0,
            channel_min: [0.5 / std::f64::consts::PI; 3],
            channel_max: [0.5 / std::f64::consts::PI; 3],
            channel_mean: [0.5 / std::f64::consts::PI; 3],
            peak_rgb: [0.5 / std::f64::consts::PI; 3],
            peak_cell: [0, 0, 0],
            albedo_theta_o: vec![0.0, FRAC_PI_6, FRAC_PI_3, 80f64.to_radians()],
            albedo_rgb: vec![[0.5; 3], [0.4999, 0.4999, 0.4999], [0.4998, 0.4998, 0.4998], [0.25, 0.375, 0.125]],
            albedo_no_data_fraction: vec![0.0, 0.0, 0.0, 0.015625],
        }),
    }
}

/// Bincode with fixed-width little-endian integers, written by hand from the README's tables.
#[derive(Default)]
struct V1Writer(Vec<u8>);

impl V1Writer {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn len(&mut self, n: usize) {
        self.u64(n as u64);
    }
    fn string(&mut self, s: &str) {
        self.len(s.len());
        self.0.extend_from_slice(s.as_bytes());
    }
    fn f64s(&mut self, vs: &[f64]) {
        vs.iter().for_each(|&v| self.f64(v));
    }
}

/// A v1 file written without the crate's encoder.
pub fn hand_built_v1(asset: &Asset) -> Vec<u8> {
    let p = &asset.provenance;
    let mut provenance = V1Writer::default();
    provenance.string(&p.source_name);
    provenance.0.extend_from_slice(&p.source_sha256);
    provenance.string(&p.tool);
    provenance.string(&p.tool_version);
    provenance.len(p.parameters.len());
    for (name, value) in &p.parameters {
        provenance.string(name);
        provenance.string(value);
    }

    let Payload::MaterialInfo(info) = &asset.payload else { unreachable!("the golden asset is material info") };
    let mut payload = V1Writer::default();
    info.dims.iter().for_each(|&v| payload.u32(v));
    payload.u64(info.no_data_cells);
    for rgb in [info.channel_min, info.channel_max, info.channel_mean, info.peak_rgb] {
        payload.f64s(&rgb);
    }
    info.peak_cell.iter().for_each(|&v| payload.u32(v));
    payload.len(info.albedo_theta_o.len());
    payload.f64s(&info.albedo_theta_o);
    payload.len(info.albedo_rgb.len());
    info.albedo_rgb.iter().for_each(|rgb| payload.f64s(rgb));
    payload.len(info.albedo_no_data_fraction.len());
    payload.f64s(&info.albedo_no_data_fraction);

    let mut file = V1Writer::default();
    file.0.extend_from_slice(b"BRDFASET");
    file.u32(1);
    file.u32(1);
    file.len(provenance.0.len());
    file.len(payload.0.len());
    file.0.extend_from_slice(&asset::sha256(&[provenance.0.as_slice(), &payload.0].concat()));
    file.0.extend_from_slice(&provenance.0);
    file.0.extend_from_slice(&payload.0);
    file.0
}

#[test]
fn golden_v1_file_is_the_documented_layout() {
    let path = fixtures_dir().join(GOLDEN_V1);
    let expected = hand_built_v1(&golden_v1_asset());
    if regenerating() {
        asset::write_atomic(&path, &expected).unwrap();
    }
    let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    assert!(committed == expected, "{} differs from the documented v1 layout of its value", path.display());
}

#[test]
fn golden_v1_material_info_loads() {
    let path = fixtures_dir().join(GOLDEN_V1);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let header = read_header(&bytes).unwrap();
    assert_eq!((header.version, header.kind), (1, AssetKind::MaterialInfo));
    assert_eq!(read_file(&path).unwrap(), golden_v1_asset());
}

/// While the writer writes v1 its output is the documented v1 layout. When the version is
/// bumped this compares against a hand-built writer of the new layout instead.
#[test]
fn the_writer_writes_the_documented_layout() {
    assert_eq!(asset::FORMAT_VERSION, 1, "a new version needs a hand-built writer of its layout here");
    assert_eq!(encode(&golden_v1_asset()), hand_built_v1(&golden_v1_asset()));
    assert_eq!(encode(&crate::small_asset()), hand_built_v1(&crate::small_asset()));
}

/// Golden v1 files of the kinds added after the first: each must always load and equal the value
/// built here, and today's writer must reproduce it byte for byte. (Kind 1 above is also held to
/// a hand-built writer of the README's tables.) Regenerate only while a kind is unreleased.
fn golden_kinds() -> Vec<(&'static str, Asset)> {
    let provenance = |tool: &str| Provenance {
        source_name: "golden-source".into(),
        source_sha256: asset::sha256(b"golden v1 source"),
        tool: tool.into(),
        tool_version: "0.1.0".into(),
        parameters: vec![("golden".into(), "yes".into())],
    };
    let linked = |name: &str| asset::LinkedFile { name: name.into(), sha256: asset::sha256(name.as_bytes()) };
    let analysis = asset::BandwidthAnalysis {
        parameterization: "cos-theta-phi-grid/incidence-plane-azimuthal-equidistant".into(),
        analysis_size: 64,
        eps: 0.01,
        c: 2f64.powf(-2.5),
    };
    vec![
        (
            "assets/golden-v1-importance-samples.asset",
            Asset {
                provenance: provenance("merl-importance"),
                payload: Payload::ImportanceSamples(asset::ImportanceSamples {
                    theta_o: vec![0.0, FRAC_PI_6],
                    n_vectors: 1,
                    n_samples: 2,
                    theta_h_edges: vec![0.0, 0.5, std::f64::consts::FRAC_PI_2],
                    n_phi_h: 2,
                    samples: vec![
                        [0.0, 0.0, 1.0, 0.5],
                        [0.6, 0.0, 0.8, 0.25],
                        [0.0, 0.6, 0.8, 0.125],
                        [0.0, 0.0, 1.0, 0.0],
                    ],
                    marginal_cdf: vec![0.0, 0.75, 1.0, 0.0, 0.5, 1.0],
                    conditional_cdf: vec![0.0, 0.5, 1.0, 0.0, 0.25, 1.0, 0.0, 0.5, 1.0, 0.0, 0.75, 1.0],
                    h_density: vec![1.0, 1.0, 0.25, 0.75, 2.0, 2.0, 0.5, 1.5],
                }),
            },
        ),
        (
            "assets/golden-v1-prefiltered-envmap.asset",
            Asset {
                provenance: provenance("envmap-prefilter"),
                payload: Payload::PrefilteredEnvmap(asset::PrefilteredEnvmap {
                    source_size: [8, 4],
                    source_mean_radiance: [0.5, 0.25, 0.125],
                    layer_size: [4, 2],
                    mip_levels: 3,
                    layers_radiance_scale: 1.0,
                    mips_radiance_scale: 0.5,
                    exponents: vec![1, 64],
                    lobe_bandwidth: vec![
                        3f64.sqrt() / (2.0 * std::f64::consts::PI),
                        66f64.sqrt() / (2.0 * std::f64::consts::PI),
                    ],
                    bandwidth_thresholds: vec![(3f64.sqrt() * 66f64.sqrt()).sqrt() / (2.0 * std::f64::consts::PI)],
                    layer_mean_radiance: vec![[0.5, 0.25, 0.125], [0.5, 0.25, 0.125]],
                    layers_ktx2: linked("layers.ktx2"),
                    layer_exrs: vec![linked("layer-n1.exr"), linked("layer-n64.exr")],
                    mips_ktx2: linked("mips.ktx2"),
                    contact_sheet_png: linked("contact-sheet.png"),
                }),
            },
        ),
        (
            "assets/golden-v1-bandwidth-atlas.asset",
            Asset {
                provenance: provenance("brdf-bandwidth"),
                payload: Payload::BandwidthAtlas(asset::BandwidthAtlas {
                    lobes_x: 2,
                    lobes_y: 1,
                    tile: 2,
                    analysis: analysis.clone(),
                    data: vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
                }),
            },
        ),
        (
            "assets/golden-v1-bandwidth-pca.asset",
            Asset {
                provenance: provenance("bandwidth-pca"),
                payload: Payload::BandwidthPca(asset::BandwidthPca {
                    lobes_x: 2,
                    lobes_y: 1,
                    tile: 2,
                    analysis: analysis.clone(),
                    n_components: 1,
                    mean: vec![1.0, 1.5, 2.0, 2.5],
                    components: vec![0.5, 0.5, 0.5, 0.5],
                    coefficients: vec![-1.0, 1.0],
                }),
            },
        ),
        (
            "assets/golden-v1-layer-selection.asset",
            Asset {
                provenance: provenance("brdf-bake"),
                payload: Payload::LayerSelection(asset::LayerSelection {
                    analysis: analysis.clone(),
                    rows: 3,
                    reduction: "band-0.99".into(),
                    exponents: vec![1, 64],
                    layer_bandwidth: vec![0.25, 1.5],
                    view_bandwidth: vec![0.3, 1.0, 2.0],
                    view_layer: vec![0, 1, 1],
                }),
            },
        ),
        (
            "assets/golden-v1-bandwidth-rows.asset",
            Asset {
                provenance: provenance("brdf-bandwidth"),
                payload: Payload::BandwidthRows(asset::BandwidthRows {
                    lobes_x: 3,
                    lobes_y: 2,
                    tile: 2,
                    analysis,
                    data: vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5],
                }),
            },
        ),
        (
            "assets/golden-v1-wavelet-brdf.asset",
            Asset {
                provenance: provenance("brdf-wavelet"),
                payload: Payload::WaveletBrdf(asset::WaveletBrdf {
                    side: 2,
                    epsilon: 0.01,
                    channel_mean: [0.25, 0.5, 0.125],
                    map: vec![1, 0, 2, 0],
                    coefficients: asset::WaveletCoefficients::Quantized {
                        offset: vec![-1.0, -0.5, 0.0, -2.0, -1.0, -0.25],
                        step: vec![0.25, 0.0, 0.125, 0.5, 0.25, 0.0625],
                        codes: (0..24).map(|k| (k * 10) as u8).collect(),
                    },
                }),
            },
        ),
    ]
}

#[test]
fn golden_v1_files_of_every_later_kind_load_and_are_reproduced() {
    let kinds = golden_kinds();
    // One file per kind after the first, so none is forgotten when a kind is added.
    let covered: Vec<AssetKind> = kinds.iter().map(|(_, a)| a.kind()).collect();
    assert_eq!(covered, AssetKind::ALL[1..], "every kind needs a golden file");
    for (relative, value) in kinds {
        let path = fixtures_dir().join(relative);
        if regenerating() {
            asset::write_file(&path, &value).unwrap();
        }
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        assert_eq!(read_header(&bytes).unwrap().version, 1, "{relative}");
        assert_eq!(read_file(&path).unwrap(), value, "{relative} no longer loads as the value it was made from");
        assert!(encode(&value) == bytes, "{relative}: today's writer no longer writes the released bytes");
    }
}
