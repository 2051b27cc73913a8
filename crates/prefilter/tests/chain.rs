//! The Phong exponents as one mip chain: cmft's layout (the sharpest lobe on the finest level),
//! each level the same convolution as the array's, held to the brute force.

use prefilter::{Config, Reference, phong_chain};

use crate::real_map;

#[test]
fn the_default_exponents_make_cmfts_chain_and_match_the_brute_force() {
    let Some(map) = real_map("potsdamer_platz_1k.hdr") else { return };
    let config = Config::default();
    let chain = phong_chain(&map, &config, &|_| {}).unwrap();
    let exponents: Vec<u32> = chain.iter().map(|(n, _)| *n).collect();
    assert_eq!(exponents, [16384, 4096, 1024, 256, 64, 16, 4, 1]);
    let sizes: Vec<(usize, usize)> = chain.iter().map(|(_, l)| (l.width(), l.height())).collect();
    assert_eq!(sizes, [(512, 256), (256, 128), (128, 64), (64, 32), (32, 16), (16, 8), (8, 4), (4, 2)]);
    // Every level against the brute force at every texel from 32 x 16 down, every 8th texel
    // above. Relative RMSE below 1e-3 (the n = 1 lobe's harmonics, truncated at its kink, reach
    // 1e-4; the others are f32 rounding).
    let reference = Reference::new(&map);
    for (n, level) in &chain {
        let (w, h) = (level.width(), level.height());
        let step = if w > 32 { 8 } else { 1 };
        let (mut num, mut den) = (0.0, 0.0);
        for y in (0..h).step_by(step) {
            for x in (0..w).step_by(step) {
                let r = reference.at_texel(x, y, w, h, &[*n])[0];
                let ours = level.texel(x, y);
                for c in 0..3 {
                    num += (f64::from(ours[c]) - r[c]).powi(2);
                    den += r[c] * r[c];
                }
            }
        }
        let error = (num / den).sqrt();
        assert!(error < 1e-3, "n {n} at {w} x {h}: relative rmse {error:.2e}");
    }
    let too_long = Config { width: 256, height: 128, ..Config::default() };
    let err = phong_chain(&map, &too_long, &|_| {}).unwrap_err().to_string();
    assert!(err.contains("at most 7 levels"), "8 levels need a level 0 of 512 x 256 at least: {err}");
}

#[test]
fn prefilter_all_gives_the_same_layers_and_chains_in_one_pass() {
    // One convolve_lobes for the array, the Phong chain and a GGX chain: the same maps as the
    // separate calls, and the chain's level 0 (the sharpest exponent at the layers' size, asked
    // for twice) is the array's layer.
    let Some(map) = real_map("potsdamer_platz_1k.hdr") else { return };
    let config =
        Config { exponents: vec![1, 16, 256], width: 64, height: 32, chain: true, ggx_levels: 4, ..Config::default() };
    let all = prefilter::prefilter_all(&map, &envmap::MipChain::new(&map), &config, &|_| {}).unwrap();
    assert_eq!(all.prefiltered, prefilter::prefilter(&map, &config).unwrap());
    let chain = all.phong_chain.unwrap();
    assert_eq!(chain, phong_chain(&map, &config, &|_| {}).unwrap());
    assert_eq!(chain[0].1, all.prefiltered.layers[2].map);
    let ggx = prefilter::ggx::chain(&map, 64, 4, prefilter::Method::Auto, &|_| {}).unwrap();
    assert_eq!(all.ggx.unwrap(), ggx);
}
