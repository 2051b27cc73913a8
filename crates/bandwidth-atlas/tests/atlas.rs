//! The atlas builder: configuration checks, the layout of lobes and texels, and that its
//! shortcut (one analysis per row of the incident grid, the table being isotropic) gives the
//! tiles a direct analysis of each lobe gives.

use bandwidth_atlas::{
    Analyser, Atlas, Config, Error, IncidentGrid, LobeMap, LuminanceTable, MAX_TEXELS, Parameterization, build_atlas,
    lobe_image_from_fn, to_incidence_frame,
};
use glam::DVec3;

use crate::phong;

#[test]
fn invalid_configurations_are_errors() {
    let table = phong(10.0);
    let cases = [
        (Config { lobes: 0, ..Config::default() }, "0 lobes"),
        (Config { tile: 12, ..Config::default() }, "tile size 12 is not a power of two"),
        (Config { analysis_size: 96, ..Config::default() }, "analysis size 96"),
        (Config { analysis_size: 8, tile: 8, ..Config::default() }, "analysis size 8"),
        (Config { tile: 64, analysis_size: 32, ..Config::default() }, "exceeds the analysis size"),
        (Config { eps: 0.0, ..Config::default() }, "eps"),
        (Config { relative_noise_floor: -1.0, ..Config::default() }, "noise floor"),
        (Config { lobes: 4096, tile: 16, ..Config::default() }, "exceeds the limit"),
    ];
    for (config, needle) in cases {
        let err = build_atlas(&table, &config, &|_| {}).unwrap_err();
        assert!(matches!(err, Error::Config(_)) && err.to_string().contains(needle), "{config:?}: {err}");
    }
}

#[test]
fn tiles_equal_a_direct_analysis_of_each_lobe() {
    // Every lobe of a 6 x 6 grid, rendered directly from its own `wi` in the tangent frame
    // (each pixel's direction turned from the frame of the plane of incidence by `phi_i`) and
    // analysed, gives the tile the builder wrote at the lobe's place. The direct images equal
    // the row's image to rounding (1e-16), which could only move a pixel across an eq. 7
    // threshold at an exact tie: the tiles are compared exactly.
    let table = phong(40.0);
    let config = Config { lobes: 6, tile: 8, analysis_size: 64, ..Config::default() };
    let build = build_atlas(&table, &config, &|_| {}).unwrap();
    let atlas = &build.atlas;
    assert_eq!((atlas.width(), atlas.height(), atlas.data.len()), (48, 48, 48 * 48));
    let analyser = Analyser::new(&config);
    let luminance = LuminanceTable::new(&table);
    let grid = IncidentGrid::new(6);
    for j in 0..6 {
        for i in 0..6 {
            let (wi, phi_i) = (grid.wi(i, j), grid.phi_i(i));
            let image = lobe_image_from_fn(LobeMap::new(64), |wo| luminance.lookup(wi, to_incidence_frame(wo, -phi_i)));
            let direct = analyser.analyse_image(image);
            let lobe = atlas.lobe_index(i, j);
            assert_eq!(atlas.tile_of(lobe), direct.tile(8), "lobe ({i}, {j})");
            assert_eq!(build.stats.nyquist_pixels[lobe] as usize, direct.nyquist_count(), "lobe ({i}, {j})");
        }
    }
}

#[test]
fn one_thread_and_two_give_the_same_bits() {
    // Rows (and the layers' lobes) are analysed in parallel, each thread reusing its buffers from
    // one row to the next: nothing may depend on which thread had which rows before. The atlas,
    // the band energies, the statistics and the layer selection, bit for bit.
    let table = phong(300.0);
    let config = Config { lobes: 8, tile: 8, analysis_size: 64, ..Config::default() };
    let reduction = bandwidth_atlas::view::ViewReduction::BandQuantile(0.99);
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let build = build_atlas(&table, &config, &|_| {}).unwrap();
            let selection =
                bandwidth_atlas::view::select_layers(&build, &config, &[1, 16, 256, 4096], reduction).unwrap();
            (build, selection)
        })
    };
    let ((one, one_layers), (two, two_layers)) = (on(1), on(2));
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert!(one.atlas.data.iter().zip(&two.atlas.data).all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(one.stats, two.stats);
    for (a, b) in one.band_energy.iter().zip(&two.band_energy) {
        assert_eq!(bits(a), bits(b));
    }
    assert_eq!(bits(&one_layers.layer_bandwidth), bits(&two_layers.layer_bandwidth));
    assert_eq!(bits(&one_layers.view_bandwidth), bits(&two_layers.view_bandwidth));
    assert_eq!(one_layers.view_layer, two_layers.view_layer);
}

#[test]
fn the_limit_is_reached_around_the_mirror_direction() {
    // A known answer for the layout: a sharp Phong lobe (fwhm 2 pixels at 64 x 64) reaches the
    // grid's limit around its mirror direction and nowhere else. The limit anywhere (c/2 cycles
    // per pixel, at least 0.088 x 64 / pi = 1.80 cycles per radian) exceeds the next level
    // anywhere (c/4 cycles per pixel, at most 0.044 x 32 = 1.41 on the rim), so the texels at
    // the limit are those of at least 1.80. The mirror of each tile's `wi`, found through the
    // documented maps (the tile's row gives theta_i, LobeMap::uv the texel), must be one of
    // them, and they must all lie within 3 texels of it (the finest wavelets span 4 pixels and
    // a texel 4 pixels).
    let config = Config { lobes: 8, tile: 16, analysis_size: 64, ..Config::default() };
    let atlas = build_atlas(&phong(1000.0), &config, &|_| {}).unwrap().atlas;
    let limit = (config.c / 2.0 * 64.0 / std::f64::consts::PI) as f32 * (1.0 - 1e-6);
    let grid = IncidentGrid::new(8);
    let map = LobeMap::new(16);
    let mut problems = Vec::new();
    for j in 0..8 {
        for i in 0..8 {
            // In the frame of the plane of incidence wi lies towards +x, its mirror towards -x.
            let theta_i = grid.theta_i(j);
            let (u, v) = map.uv(DVec3::new(-theta_i.sin(), 0.0, theta_i.cos()));
            let (tx, ty) = ((u * 16.0) as i64, (v * 16.0) as i64);
            let tile = atlas.tile_of(atlas.lobe_index(i, j));
            if tile[(ty * 16 + tx) as usize] < limit {
                problems.push(format!(
                    "lobe ({i}, {j}): mirror texel ({tx}, {ty}) holds {}",
                    tile[(ty * 16 + tx) as usize]
                ));
            }
            for (k, value) in tile.iter().enumerate() {
                let (x, y) = ((k % 16) as i64, (k / 16) as i64);
                if *value >= limit && ((x - tx).abs() > 3 || (y - ty).abs() > 3) {
                    problems.push(format!("lobe ({i}, {j}): texel ({x}, {y}) at the limit, mirror at ({tx}, {ty})"));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn tiles_round_trip_through_the_layout() {
    let mut atlas = Atlas {
        lobes_x: 3,
        lobes_y: 2,
        tile: 4,
        data: vec![0.0; 12 * 8],
        parameterization: Parameterization::IncidencePlaneEquidistant,
        analysis_size: 16,
        eps: 0.01,
        c: bandwidth::DEFAULT_C,
    };
    for lobe in 0..6 {
        let tile: Vec<f32> = (0..16).map(|t| (100 * lobe + t) as f32).collect();
        atlas.set_tile(lobe, &tile);
    }
    // Lobe (2, 1) is lobe 5; its texel (1, 3) is atlas texel (2 * 4 + 1, 1 * 4 + 3).
    assert_eq!(atlas.data[7 * 12 + 9], 513.0);
    for lobe in 0..6 {
        assert_eq!(atlas.tile_of(lobe), (0..16).map(|t| (100 * lobe + t) as f32).collect::<Vec<_>>());
    }
    atlas.check().unwrap();
    atlas.data[5] = f32::NAN;
    assert!(atlas.check().unwrap_err().to_string().contains("texel (5, 0)"));
    atlas.data.pop();
    assert!(atlas.check().unwrap_err().to_string().contains("holds 95 values"));
}

/// An atlas of `lobes_x x lobes_y` tiles of 4 x 4 whose texel `(tx, ty)` of lobe `(i, j)` is
/// `value(i, j, t)` with `t = ty * 4 + tx`.
fn atlas_of(lobes_x: usize, lobes_y: usize, value: impl Fn(usize, usize, usize) -> f32) -> Atlas {
    let mut atlas = Atlas {
        lobes_x,
        lobes_y,
        tile: 4,
        data: vec![0.0; lobes_x * lobes_y * 16],
        parameterization: Parameterization::IncidencePlaneEquidistant,
        analysis_size: 16,
        eps: 0.01,
        c: bandwidth::DEFAULT_C,
    };
    for j in 0..lobes_y {
        for i in 0..lobes_x {
            let tile: Vec<f32> = (0..16).map(|t| value(i, j, t)).collect();
            atlas.set_tile(atlas.lobe_index(i, j), &tile);
        }
    }
    atlas
}

/// Rows hold an isotropic atlas whole: `rows` keeps each row's first tile, one after another
/// (the layout of asset kind 7, checked against `tile_of` of the full grid), and `expand_rows`
/// gives back the full grid bit for bit.
#[test]
fn an_isotropic_atlas_is_its_rows_expanded() {
    let atlas = atlas_of(5, 3, |_, j, t| (10 * j + t) as f32 * 0.25);
    assert!(atlas.is_isotropic());
    let rows = atlas.rows();
    assert_eq!((rows.lobes_x, rows.lobes_y, rows.tile), (1, 3, 4));
    rows.check().unwrap();
    for j in 0..3 {
        assert_eq!(rows.data[j * 16..(j + 1) * 16], atlas.tile_of(atlas.lobe_index(0, j)));
    }
    let expanded = rows.expand_rows(5).unwrap();
    assert_eq!(expanded, atlas);
    // One column is its own rows.
    assert_eq!(rows.rows(), rows);
    assert!(rows.is_isotropic());
}

/// One texel of one tile away from its row's first tile makes an atlas anisotropic, wherever it
/// is; so does a zero of the other sign (the rows could not give those bits back).
#[test]
fn one_different_texel_makes_an_atlas_anisotropic() {
    let isotropic = atlas_of(4, 3, |_, j, t| (j + t) as f32);
    for (i, j, t) in [(1, 0, 0), (3, 2, 15), (2, 1, 7)] {
        let mut atlas = isotropic.clone();
        let mut tile = atlas.tile_of(atlas.lobe_index(i, j));
        tile[t] += 0.5;
        atlas.set_tile(atlas.lobe_index(i, j), &tile);
        assert!(!atlas.is_isotropic(), "lobe ({i}, {j}) texel {t}");
    }
    let mut signed = atlas_of(2, 1, |_, _, _| 0.0);
    signed.data[4] = -0.0;
    assert!(!signed.is_isotropic());
}

/// The columns to expand to may come from a file: a grid above `MAX_TEXELS` (or one whose size
/// overflows) is refused before anything is allocated, and only an atlas one lobe wide expands.
#[test]
fn expanding_rows_checks_the_size_first() {
    let rows = atlas_of(1, 2, |_, _, t| t as f32);
    for lobes_x in [0, MAX_TEXELS / 32 + 1, usize::MAX] {
        let err = rows.expand_rows(lobes_x).unwrap_err().to_string();
        assert!(err.contains("is empty or exceeds the limit"), "{lobes_x}: {err}");
    }
    let err = atlas_of(2, 2, |_, _, _| 1.0).expand_rows(3).unwrap_err().to_string();
    assert!(err.contains("one lobe wide, not 2"), "{err}");
}

/// `Atlas::lookup` reads the texel the layout puts a pair of directions in: for every lobe of a
/// 4 x 3 grid of 4 x 4 tiles whose texels all differ, the incident direction at the lobe's
/// centre (turned by a small azimuth within its column) and the outgoing direction at each
/// hemisphere texel's centre (turned into the tangent frame) read that texel.
#[test]
fn lookup_reads_the_texel_of_a_pair_of_directions() {
    use bandwidth_atlas::LobeMap;
    let atlas = atlas_of(4, 3, |i, j, t| ((j * 4 + i) * 16 + t) as f32);
    let map = LobeMap::new(4);
    let grid_phi = |i: usize| std::f64::consts::TAU * (i as f64 + 0.3) / 4.0;
    let mut checked = 0;
    for j in 0..3 {
        for i in 0..4 {
            let cos_theta = 1.0 - (j as f64 + 0.5) / 3.0;
            let phi_i = grid_phi(i);
            let wi = merl::spherical_dir(cos_theta.acos(), phi_i);
            for ty in 0..4 {
                for tx in 0..4 {
                    let w = map.direction(tx, ty);
                    if w.z <= 0.0 {
                        continue;
                    }
                    // Back from the frame of the plane of incidence: rotate by +phi_i.
                    let (s, c) = phi_i.sin_cos();
                    let wo = DVec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
                    let expect = ((j * 4 + i) * 16 + ty * 4 + tx) as f32;
                    assert_eq!(atlas.lookup(wi, wo), expect, "lobe ({i}, {j}), texel ({tx}, {ty})");
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 12 * 12, "the 12 texels of a 4 x 4 tile whose centre is on the hemisphere");
}
