//! The mip chain: sizes, the solid-angle-weighted mean at every level, trilinear lookups, lod.

use envmap::{EnvMap, MipChain};
use rand::{Rng, SeedableRng};

use crate::{assert_close, shared_env};

#[test]
fn level_sizes() {
    let sizes = |w, h| -> Vec<(usize, usize)> {
        let chain = MipChain::new(&EnvMap::constant(w, h, [1.0; 3]).expect("map"));
        chain.levels().iter().map(|l| (l.width(), l.height())).collect()
    };
    assert_eq!(sizes(16, 8), [(16, 8), (8, 4), (4, 2), (2, 1)]);
    assert_eq!(sizes(1024, 512).len(), 10);
    // An odd height stops the chain.
    assert_eq!(sizes(12, 6), [(12, 6), (6, 3)]);
    assert_eq!(sizes(6, 3), [(6, 3)]);
    assert_eq!(sizes(2, 1), [(2, 1)]);
}

/// Every level keeps level 0's solid-angle-weighted mean within 1e-6 relative (the texels are
/// stored as f32, 6e-8 relative each; the sums are f64). An unweighted 2x2 average misses by far
/// more on these maps, which is why the filter is weighted.
#[test]
fn every_level_keeps_the_weighted_mean() {
    let Some(env) = shared_env() else { return };
    for file in ["quarry_01_1k.hdr", "studio_small_03_1k.hdr", "KernerEnvLatLong.exr"] {
        let map = envmap::load(&env.join(file)).expect(file);
        let chain = MipChain::new(&map);
        let want = map.mean_radiance();
        for (l, level) in chain.levels().iter().enumerate() {
            for (c, (got, want)) in level.mean_radiance().into_iter().zip(want).enumerate() {
                assert_close(got, want, 1e-6, &format!("{file} level {l} channel {c}"));
            }
        }
        // The unweighted box filter, for contrast: the coarsest level's mean is off by far more.
        let mut plain = map.clone();
        while plain.height() > 1 {
            let (w, h) = (plain.width() / 2, plain.height() / 2);
            let t = plain.texels();
            let rgb = (0..w * h)
                .flat_map(|i| {
                    let (x, y) = (i % w, i / w);
                    let fine = |dx, dy| t[(2 * y + dy) * plain.width() + 2 * x + dx];
                    std::array::from_fn::<f32, 3, _>(|c| {
                        (fine(0, 0)[c] + fine(1, 0)[c] + fine(0, 1)[c] + fine(1, 1)[c]) / 4.0
                    })
                })
                .collect();
            plain = EnvMap::new(w, h, rgb).expect("plain level");
        }
        let off = (plain.mean_radiance()[0] - want[0]).abs() / want[0];
        assert!(off > 1e-3, "{file}: the plain box filter keeps the mean to {off}; the test would not catch it");
    }
}

#[test]
fn trilinear_lookup() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let map = EnvMap::new(64, 32, (0..3 * 64 * 32).map(|_| rng.random_range(0.0..4.0)).collect()).expect("map");
    let chain = MipChain::new(&map);
    assert_eq!(chain.n_levels(), 6);
    for _ in 0..1000 {
        let (u, v): (f64, f64) = (rng.random(), rng.random());
        // Integer levels are the levels' bilinear lookups.
        for l in 0..chain.n_levels() {
            assert_eq!(chain.lookup_uv(u, v, l as f64), chain.level(l).lookup_uv(u, v), "level {l}");
        }
        let lod: f64 = rng.random_range(0.0..5.0);
        let (l0, t) = (lod.floor() as usize, lod - lod.floor());
        let (a, b) = (chain.level(l0).lookup_uv(u, v), chain.level(l0 + 1).lookup_uv(u, v));
        let got = chain.lookup_uv(u, v, lod);
        for c in 0..3 {
            let want = f64::from(a[c]) * (1.0 - t) + f64::from(b[c]) * t;
            assert_close(f64::from(got[c]), want, 1e-6, "between levels");
        }
        // Clamped at both ends; NaN reads level 0.
        assert_eq!(chain.lookup_uv(u, v, 99.0), chain.level(5).lookup_uv(u, v));
        assert_eq!(chain.lookup_uv(u, v, -3.0), map.lookup_uv(u, v));
        assert_eq!(chain.lookup_uv(u, v, f64::NAN), map.lookup_uv(u, v));
        assert_eq!(chain.lookup(envmap::direction(u, v), 5.0), chain.level(5).lookup_uv(u, v));
    }
    // The coarsest level is the mean of each half in phi.
    let constant = MipChain::new(&EnvMap::constant(64, 32, [0.5, 1.0, 2.0]).expect("constant"));
    for lod in [0.0, 0.5, 2.25, 5.0] {
        for (got, want) in constant.lookup_uv(0.3, 0.7, lod).into_iter().zip([0.5, 1.0, 2.0]) {
            assert_close(f64::from(got), want, 1e-6, "constant map");
        }
    }
}

/// lod = max(log4(w h / (n pdf_uv)), 0): with one sample from the uniform pdf over the square the
/// sample stands for the whole map, half of log2(w h) levels up.
#[test]
fn level_of_detail() {
    let chain = MipChain::new(&EnvMap::constant(1024, 512, [1.0; 3]).expect("map"));
    assert_close(chain.lod(1, 1.0), 9.5, 1e-15, "one uniform sample");
    assert_close(chain.lod(4, 1.0), 8.5, 1e-15, "four uniform samples");
    assert_eq!(chain.lod(1024 * 512, 1.0), 0.0);
    assert_eq!(chain.lod(16, 1e6), 0.0);
    // A solid-angle pdf converts with the Jacobian: uniform over the sphere is 1 / (4 pi) per sr.
    let pdf_uv = envmap::geometry::uv_jacobian(0.5) / (4.0 * std::f64::consts::PI);
    assert_close(chain.lod(1, pdf_uv), 0.5 * (1024.0 * 512.0 / pdf_uv).log2(), 1e-15, "solid angle pdf");
}
