//! The layer selection: a Phong material of a layer's own exponent selects that layer at every
//! view, and a sharper material never selects a broader layer.

use bandwidth_atlas::Config;
use bandwidth_atlas::view::select_layers_of_table;
use merl::analytic::Analytic;

/// Layers a factor 4 apart, the default's but the sharpest (`n = 16384`, whose lobe the
/// 256 x 256 analysis cannot tell from `n = 4096`'s).
const EXPONENTS: [u32; 7] = [1, 4, 16, 64, 256, 1024, 4096];

/// The bake's reduction on 16 rows of views (every fourth row of the default 64: the test's cost
/// is the atlas, linear in the rows) at 256 x 256, the smallest analysis that tells the default
/// layers apart (the default, 512, takes four times as long and selects the same layers).
fn config() -> Config {
    Config { lobes: 16, analysis_size: 256, ..Config::default() }
}

fn phong(n: u32) -> merl::MerlTable {
    Analytic::Phong { n: f64::from(n), ks: [1.0; 3], kd: [0.0; 3] }.table(merl::Dims::MERL)
}

/// `merl-synth phong -n N` for each layer's exponent from 16 up selects that layer at every row:
/// the table's lobe and the layer's lobe are the same `cos^n` around the mirror direction, read
/// through the table's cells and the projection at that row. The two broadest layers are the
/// exception the crate documents: the cosine lobe's slope at the horizon reads as detail, and
/// n = 1 and n = 4 measure within a few percent of each other, so either may be chosen; both
/// must still pick one of those two.
#[test]
fn phong_tables_select_their_own_layer_at_every_view() {
    let config = config();
    let reduction = bake::stage::layer_selection::DEFAULT_REDUCTION;
    let mut failures = Vec::new();
    for (k, &n) in EXPONENTS.iter().enumerate() {
        let selection = select_layers_of_table(&phong(n), &config, &EXPONENTS, reduction).unwrap();
        let rows: String = selection.view_layer.iter().map(|l| char::from(b'0' + *l as u8)).collect();
        println!("phong n {n:>5}: layers by row {rows}, view bandwidth {:.3?}", selection.view_bandwidth);
        let ok = |l: u32| if k < 2 { l < 2 } else { l as usize == k };
        if !selection.view_layer.iter().all(|&l| ok(l)) {
            failures.push(format!("phong n {n} selects {rows}, expected layer {k} everywhere"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The layers' own bandwidths increase with the exponent, by about a factor 2 per factor 4 in n
/// (a lobe of half the width) from n = 16 up: between 1.6 and 2.4 for each of those steps (the
/// broad lobes fill the analysed hemisphere and grow less: 1.4 from n = 4 to 16).
#[test]
fn layer_bandwidths_grow_like_sqrt_n() {
    let config = config();
    let b: Vec<f64> = EXPONENTS
        .iter()
        .map(|&n| bandwidth_atlas::view::layer_bandwidth(&config, n, bake::stage::layer_selection::DEFAULT_REDUCTION))
        .collect();
    println!("layer bandwidths {b:.4?}");
    for k in 3..b.len() {
        let ratio = b[k] / b[k - 1];
        assert!((1.6..=2.4).contains(&ratio), "layer {k} / layer {}: {ratio:.3} ({b:?})", k - 1);
    }
    assert!(b[2] > 1.2 * b[1] && b[1] > b[0] * 0.9, "{b:?}");
}

/// A Lambertian table's lobe is a constant: it has no detail above the analysis's noise floor, so
/// every view is flat and takes the broadest layer (the rounding noise of its lookups would read
/// as the finest frequencies and pick the sharpest).
#[test]
fn a_lambertian_table_selects_the_broadest_layer_at_every_view() {
    let table = Analytic::Lambertian { albedo: [0.8, 0.5, 0.2] }.table(merl::Dims::MERL);
    let selection =
        select_layers_of_table(&table, &config(), &EXPONENTS, bake::stage::layer_selection::DEFAULT_REDUCTION).unwrap();
    println!("lambertian: view bandwidths {:.3?}", selection.view_bandwidth);
    assert!(selection.view_bandwidth.iter().all(|&b| b == 0.0), "{:?}", selection.view_bandwidth);
    assert!(selection.view_layer.iter().all(|&l| l == 0), "{:?}", selection.view_layer);
}

/// A default bake reads its layers' bandwidths from `bandwidth_atlas::view::KNOWN_LAYER_BANDWIDTHS`:
/// they were measured for the bake's default reduction and Phong exponents (otherwise every bake
/// would measure them again: right, but slower).
#[test]
fn the_known_layer_bandwidths_serve_the_default_bake() {
    assert_eq!(bake::stage::layer_selection::DEFAULT_REDUCTION, bandwidth_atlas::view::KNOWN_LAYER_REDUCTION);
    let known: Vec<u32> = bandwidth_atlas::view::KNOWN_LAYER_BANDWIDTHS.iter().map(|(n, _)| *n).collect();
    assert_eq!(known, prefilter::DEFAULT_EXPONENTS.to_vec());
}
