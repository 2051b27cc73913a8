//! Invalid configurations are refused with a message that says what is wrong.

use envmap::EnvMap;
use prefilter::{Config, Error, MAX_EXPONENT, Method, prefilter};

fn check(edit: impl FnOnce(&mut Config), expected: &str) {
    let mut config = Config::default();
    edit(&mut config);
    let map = EnvMap::constant(8, 4, [1.0; 3]).unwrap();
    match prefilter(&map, &config) {
        Err(Error::InvalidConfig(message)) => assert!(message.contains(expected), "{expected:?} not in {message:?}"),
        other => panic!("{config:?}: expected an invalid config, got {other:?}"),
    }
}

#[test]
fn bad_exponents_are_refused() {
    check(|c| c.exponents.clear(), "no exponents");
    check(|c| c.exponents = vec![0, 4], "exponent 0 outside 1 ..= 16777216");
    check(|c| c.exponents = vec![1, MAX_EXPONENT + 1], "exponent 16777217 outside");
    check(|c| c.exponents = vec![1, 16, 4], "exponents must increase strictly, found 16 then 4");
    check(|c| c.exponents = vec![4, 4], "found 4 then 4");
}

#[test]
fn layers_must_be_lat_long() {
    check(|c| (c.width, c.height) = (256, 256), "layer size 256 x 256: expected width = 2 x height");
    check(|c| (c.width, c.height) = (0, 0), "layer size 0 x 0");
    check(|c| (c.width, c.height) = (2 * 16384, 16384), "height 1 ..= 8192");
}

#[test]
fn harmonics_refuse_lobes_too_narrow_for_them() {
    check(
        |c| (c.exponents, c.method) = (vec![1 << 20], Method::SphericalHarmonics),
        "needs spherical harmonics of degree",
    );
}

/// The smallest maps and layers work: a 2 x 1 source, a 2 x 1 layer, both methods.
#[test]
fn tiny_maps_and_layers() {
    let map = EnvMap::new(2, 1, vec![1.0, 2.0, 3.0, 3.0, 2.0, 1.0]).unwrap();
    for method in [Method::Auto, Method::SphericalHarmonics, Method::Window] {
        for (width, height) in [(2, 1), (6, 3)] {
            let config = Config { exponents: vec![1, 100], width, height, method, ..Config::default() };
            let layers = prefilter(&map, &config).unwrap();
            assert_eq!(layers.layers.len(), 2);
            assert!(layers.layers.iter().all(|l| (l.map.width(), l.map.height()) == (width, height)));
        }
    }
}
