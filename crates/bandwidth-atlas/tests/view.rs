//! `view::layer_coordinate`: the blend between the two layers around a view's bandwidth agrees
//! with the nearest layer and moves continuously with the bandwidth.

use bandwidth_atlas::view::{LAYER_OVER_VIEW_BANDWIDTH, layer_coordinate, nearest_layer, view_coordinates};

/// The default layers' bandwidths at an analysis size of 256 (`bake`'s layer test prints them).
const LAYERS: [f64; 7] = [0.2909, 0.3176, 0.4484, 0.8741, 1.7171, 3.3612, 6.3283];

#[test]
fn the_coordinate_rounds_to_the_nearest_layer_and_never_jumps() {
    let mut previous = 0.0;
    for i in 0..=20_000 {
        let nu = 0.1 * (100.0f64).powf(i as f64 / 20_000.0);
        let x = layer_coordinate(nu, &LAYERS);
        // Exactly halfway on a log scale the two rules may part by the rounding of the logarithms.
        assert_eq!(x.round() as usize, nearest_layer(nu, &LAYERS), "nu {nu}: coordinate {x}");
        assert!(x >= previous && x - previous < 0.01, "nu {nu}: {previous} then {x}");
        previous = x;
    }
    assert_eq!(previous, 6.0);
}

#[test]
fn the_coordinate_is_exact_at_the_layers_and_halfway_between_them_on_a_log_scale() {
    for (k, &b) in LAYERS.iter().enumerate() {
        assert!((layer_coordinate(b, &LAYERS) - k as f64).abs() < 1e-12, "layer {k}");
    }
    let between = (LAYERS[3] * LAYERS[4]).sqrt();
    assert!((layer_coordinate(between, &LAYERS) - 3.5).abs() < 1e-12);
}

#[test]
fn flat_broad_and_sharp_views_take_the_end_layers() {
    assert_eq!(layer_coordinate(0.0, &LAYERS), 0.0, "a flat view takes the broadest layer");
    assert_eq!(layer_coordinate(0.01, &LAYERS), 0.0);
    assert_eq!(layer_coordinate(100.0, &LAYERS), 6.0);
    assert_eq!(layer_coordinate(1.0, &[0.5]), 0.0, "one layer");
}

/// What the renderers read: the layer of twice a view's bandwidth, continuing one layer past
/// the sharpest (the map itself) at the last step's ratio, continuously, and no further.
#[test]
fn views_sharper_than_the_sharpest_layer_read_one_past_it() {
    let last = LAYERS[6];
    let past = last * last / LAYERS[5];
    let views = [0.0, LAYERS[4] / 2.0, last / 2.0, last, (last * past).sqrt() / 2.0, past / 2.0, 100.0];
    let x = view_coordinates(&views, &LAYERS);
    let expected = [0.0, 4.0, 6.0, 7.0, 6.5, 7.0, 7.0];
    for ((nu, x), want) in views.iter().zip(&x).zip(expected) {
        // Up to one ulp of f32 away from the layer the doubled bandwidth measures.
        assert!((f64::from(*x) - want).abs() < 1e-5, "view {nu}: {x}, expected {want}");
    }
    assert_eq!(LAYER_OVER_VIEW_BANDWIDTH, 2.0, "the expectations above double the views");
    let mut previous = 0.0;
    for i in 0..=30_000 {
        let nu = 0.1 * (1000.0f64).powf(i as f64 / 30_000.0);
        let x = view_coordinates(&[nu], &LAYERS)[0];
        assert!(x >= previous && x - previous < 0.01, "nu {nu}: {previous} then {x}");
        previous = x;
    }
    assert_eq!(previous, 7.0, "at most one past the sharpest");
    assert_eq!(view_coordinates(&[5.0], &[0.5]), vec![0.0], "one layer: nothing to continue");
}

#[test]
fn layers_that_do_not_increase_blend_nothing() {
    let damaged = [0.3, 0.2, 0.9];
    for nu in [0.0, 0.25, 0.5, 2.0, f64::NAN] {
        assert_eq!(layer_coordinate(nu, &damaged), nearest_layer(nu, &damaged) as f64, "nu {nu}");
    }
}

/// The layer bandwidths a bake reads instead of measuring are the measurement, bit for bit
/// (`cargo run --release -p bandwidth-atlas --example layer-bandwidths` prints them again).
#[test]
fn the_known_layer_bandwidths_are_the_measured_ones() {
    let config = bandwidth_atlas::Config::default();
    for (n, bits) in bandwidth_atlas::view::KNOWN_LAYER_BANDWIDTHS {
        let measured = bandwidth_atlas::view::layer_bandwidth(&config, n, bandwidth_atlas::view::KNOWN_LAYER_REDUCTION);
        assert_eq!(measured.to_bits(), bits, "n = {n}: measured {measured}, known {}", f64::from_bits(bits));
    }
}
