//! Test 5 (crate part): PCA with all components reproduces the atlas; fewer components trade
//! error for size as the eigenvalues predict; bad requests are errors.

use bandwidth_atlas::{Atlas, Components, Config, Error, Parameterization, build_atlas, evaluate, fit};
use rand::{Rng, SeedableRng, rngs::StdRng};

use crate::phong;

/// An atlas of random tiles with a shared structure (fixed seed): a few patterns mixed with
/// random weights plus noise, like an atlas but with a known rank.
fn random_atlas(lobes: usize, tile: usize, seed: u64) -> Atlas {
    let mut rng = StdRng::seed_from_u64(seed);
    let d = tile * tile;
    let patterns: Vec<Vec<f32>> = (0..4).map(|_| (0..d).map(|_| rng.random::<f32>()).collect()).collect();
    let mut atlas = Atlas {
        lobes_x: lobes,
        lobes_y: lobes,
        tile,
        data: vec![0.0; lobes * lobes * d],
        parameterization: Parameterization::IncidencePlaneEquidistant,
        analysis_size: 64,
        eps: 0.01,
        c: bandwidth::DEFAULT_C,
    };
    for lobe in 0..lobes * lobes {
        let w: Vec<f32> = (0..4).map(|_| rng.random::<f32>() * 3.0).collect();
        let tile: Vec<f32> = (0..d)
            .map(|t| 1.0 + (0..4).map(|p| w[p] * patterns[p][t]).sum::<f32>() + 0.01 * rng.random::<f32>())
            .collect();
        atlas.set_tile(lobe, &tile);
    }
    atlas
}

/// Tolerance of a reconstruction with every component, relative to the atlas's largest texel:
/// the model is stored in f32 (6e-8 relative), and a texel sums the mean and `tile^2` products
/// of f32 values, each rounded; measured about 5e-8.
const FULL_TOLERANCE: f64 = 1e-6;

#[test]
fn all_components_reproduce_the_atlas() {
    for atlas in [
        random_atlas(16, 8, 1),
        build_atlas(&phong(30.0), &Config { lobes: 8, analysis_size: 64, ..Config::default() }, &|_| {}).unwrap().atlas,
    ] {
        let model = fit(&atlas, Components::Count(atlas.tile_len())).unwrap().model;
        model.check().unwrap();
        let report = evaluate(&atlas, &model);
        println!(
            "{} lobes x {} texels, all components: max error {:.2e} of the largest texel {:.3}",
            atlas.n_lobes(),
            atlas.tile_len(),
            report.max_abs_error,
            report.max_value
        );
        assert!(report.max_abs_error <= FULL_TOLERANCE * report.max_value, "{report:?}");
        // reconstruct(lobe) is what the atlas holds.
        for lobe in [0, atlas.n_lobes() / 2, atlas.n_lobes() - 1] {
            for (r, a) in model.reconstruct(lobe).iter().zip(atlas.tile_of(lobe)) {
                assert!(f64::from((r - a).abs()) <= FULL_TOLERANCE * report.max_value);
            }
        }
    }
}

#[test]
fn fewer_components_meet_the_requested_error_and_cost_less() {
    let atlas = random_atlas(16, 8, 2);
    let fitted = fit(&atlas, Components::MaxRelativeRmse(0.02)).unwrap();
    let report = evaluate(&atlas, &fitted.model);
    let k = fitted.model.n_components;
    println!("rank-4 atlas: K = {k} for 2%, rmse {:.4}, size ratio {:.3}", report.relative_rmse, report.size_ratio);
    assert!(report.relative_rmse <= 0.02);
    // Four patterns and a constant explain everything but the noise.
    assert!(k <= 4, "K = {k}");
    // The predicted error is the measured one (to f32 rounding).
    assert!((fitted.predicted_relative_rmse[k] - report.relative_rmse).abs() < 1e-5);
    // One fewer misses the bound: K is the fewest.
    let fewer = fit(&atlas, Components::Count(k - 1)).unwrap();
    assert!(evaluate(&atlas, &fewer.model).relative_rmse > 0.02);
    // Size: mean + K components + K coefficients per lobe.
    assert_eq!(fitted.model.stored_values(), 64 + k * 64 + 256 * k);
    // No components: the mean tile everywhere.
    let mean = fit(&atlas, Components::Count(0)).unwrap().model;
    assert_eq!(mean.reconstruct(3), mean.mean);
}

#[test]
fn bad_requests_are_errors() {
    let atlas = random_atlas(4, 4, 3);
    let err = fit(&atlas, Components::Count(17)).unwrap_err();
    assert!(matches!(err, Error::Config(_)) && err.to_string().contains("17 components"), "{err}");
    let err = fit(&atlas, Components::MaxRelativeRmse(f64::NAN)).unwrap_err();
    assert!(err.to_string().contains("maximum relative rmse"), "{err}");
    let mut short = atlas.clone();
    short.data.truncate(10);
    assert!(matches!(fit(&short, Components::Count(1)), Err(Error::Invalid(_))));
}

/// The PCA of an isotropic atlas fitted on its rows is the fit on the full grid: repeating every
/// tile `lobes_x` times multiplies the covariance by `lobes_x` and keeps the mean, so the
/// components, and with them every tile's reconstruction, are the same. Compared through the
/// reconstruction (components are defined up to sign) on 6 columns (a factor that is not a power
/// of two, so the two eigenproblems differ in rounding): for every K the relative RMSEs agree and
/// the reconstructions differ by at most 1e-5 of the atlas's norm (f64 eigensolver, f32 model;
/// measured: equal after rounding to f32), and the rows' model is smaller by exactly the coefficients of the
/// repeated columns.
#[test]
fn an_isotropic_atlas_fitted_on_its_rows_equals_the_fit_on_the_full_grid() {
    let mut atlas = random_atlas(6, 8, 4);
    for j in 0..6 {
        let first = atlas.tile_of(atlas.lobe_index(0, j));
        for i in 1..6 {
            atlas.set_tile(atlas.lobe_index(i, j), &first);
        }
    }
    assert!(atlas.is_isotropic());
    let rows = atlas.rows();
    let norm: f64 = atlas.data.iter().map(|v| f64::from(*v).powi(2)).sum::<f64>().sqrt();
    for k in [0, 1, 2, 3, 5] {
        let full = fit(&atlas, Components::Count(k)).unwrap().model;
        let per_row = fit(&rows, Components::Count(k)).unwrap().model;
        let (full_report, rows_report) = (evaluate(&atlas, &full), evaluate(&rows, &per_row));
        // The rows' model stands for the full grid: expanded, it reconstructs the same texels.
        let expanded = per_row.reconstruct_atlas().expand_rows(6).unwrap();
        let diff: f64 = expanded
            .data
            .iter()
            .zip(&full.reconstruct_atlas().data)
            .map(|(a, b)| f64::from(a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        println!(
            "K {k}: relative rmse full {:.6e}, rows {:.6e}; reconstructions differ by {:.2e} of the atlas",
            full_report.relative_rmse,
            rows_report.relative_rmse,
            diff / norm
        );
        assert!((full_report.relative_rmse - rows_report.relative_rmse).abs() <= 1e-5, "K {k}");
        assert!(diff <= 1e-5 * norm, "K {k}");
        assert_eq!((per_row.lobes_x, per_row.lobes_y, per_row.coefficients.len()), (1, 6, 6 * k));
        assert_eq!(full.stored_values() - per_row.stored_values(), 5 * 6 * k);
    }
    // The error bound picks the same K either way.
    let bound = Components::MaxRelativeRmse(0.02);
    assert_eq!(fit(&atlas, bound).unwrap().model.n_components, fit(&rows, bound).unwrap().model.n_components);
}
