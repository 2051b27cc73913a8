//! The atlas and PCA stages store each distinct tile once: an analytic (isotropic) table's atlas
//! is written as kind 7 (`bandwidth-rows`) and reads back as the full grid texel for texel; the
//! PCA of it is fitted on the rows, with the full grid's error and a size reported against both.

use std::path::Path;
use std::sync::OnceLock;

use asset::{AssetKind, Payload};
use bake::stage::{self, pca};
use bake::{Program, Source, Staged};
use bandwidth_atlas::{Atlas, AtlasBuild, Components, Config, evaluate, fit};
use merl::analytic::Analytic;

const PROGRAM: Program = Program { name: "bake-tests", version: "0" };

/// 16 x 16 lobes of 16 x 16 texels analysed at 64 x 64: small, and the rows are still 1/16 of
/// the grid.
const LOBES: usize = 16;

fn config() -> Config {
    Config { lobes: LOBES, analysis_size: 64, ..Config::default() }
}

/// The atlas stage on a GGX table (made once for the module).
fn ggx_stage() -> &'static (Staged, AtlasBuild) {
    static STAGE: OnceLock<(Staged, AtlasBuild)> = OnceLock::new();
    STAGE.get_or_init(|| {
        let table = Analytic::Ggx { alpha: 0.2, f0: [0.9, 0.6, 0.3] }.table(merl::Dims::MERL);
        let source = Source::of_bytes(Path::new("ggx.binary"), b"ggx");
        let analyser = bandwidth_atlas::Analyser::new(&config());
        stage::bandwidth_atlas::run(
            &bandwidth_atlas::LuminanceTable::new(&table),
            &analyser,
            &source,
            &PROGRAM,
            &|_| {},
        )
        .unwrap()
    })
}

fn decoded(staged: &Staged, role: &str) -> asset::Asset {
    let file = staged.file(role).unwrap_or_else(|| panic!("no file of role {role}"));
    asset::decode(&file.bytes).unwrap()
}

fn figure(staged: &Staged, name: &str) -> f64 {
    staged.figures[name].as_f64().unwrap_or_else(|| panic!("figure {name} is not a number: {:?}", staged.figures))
}

/// A MERL table is isotropic, so the stage writes kind 7: the 16 row tiles (1/16 of the texels,
/// in the manifest under the same role) that expand to the atlas the builder made column by
/// column, bit for bit.
#[test]
fn an_analytic_table_is_stored_once_per_row() {
    let (staged, build) = ggx_stage();
    assert!(build.atlas.is_isotropic());
    let Payload::BandwidthRows(rows) = decoded(staged, "bandwidth-atlas").payload else {
        panic!("the atlas of a MERL table is not stored as rows")
    };
    assert_eq!((rows.lobes_x, rows.lobes_y, rows.tile), (LOBES as u32, LOBES as u32, 16));
    assert_eq!(rows.data.len(), LOBES * 256);
    let stage = staged.manifest_stage().unwrap();
    let output = stage.outputs.iter().find(|o| o.role == "bandwidth-atlas").unwrap();
    assert_eq!(output.kind, Some(AssetKind::BandwidthRows));
    assert_eq!(staged.figures["stored_kind"], "bandwidth-rows");
    assert_eq!(staged.figures["isotropic"], true);
    assert_eq!(figure(staged, "stored_texels") as usize, LOBES * 256);

    let expanded = stage::bandwidth_atlas::from_payload(Payload::BandwidthRows(rows)).unwrap();
    assert_eq!((expanded.lobes_x, expanded.lobes_y, expanded.tile), (LOBES, LOBES, 16));
    let bits = |a: &Atlas| a.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert!(bits(&expanded) == bits(&build.atlas), "the expanded rows differ from the atlas");
    assert_eq!(expanded, build.atlas);
}

/// A full-grid asset (kind 4) reads back as it is; a rows asset whose grid exceeds the atlas
/// limit is refused before the grid is allocated (two billion columns of one texel would be
/// 8 GiB); other kinds are named.
#[test]
fn either_kind_reads_back_and_oversized_rows_are_refused() {
    let (_, build) = ggx_stage();
    let full =
        stage::bandwidth_atlas::from_payload(Payload::BandwidthAtlas(stage::bandwidth_atlas::to_asset(&build.atlas)))
            .unwrap();
    assert_eq!(full, build.atlas);
    let mut huge = stage::bandwidth_atlas::to_rows_asset(&build.atlas);
    (huge.lobes_x, huge.lobes_y, huge.tile, huge.data) = (1 << 31, 1, 1, vec![0.5]);
    let err = stage::bandwidth_atlas::from_payload(Payload::BandwidthRows(huge)).unwrap_err();
    assert!(err.contains("exceeds the limit of 1073741824 texels"), "{err}");
    let source = Source::of_bytes(Path::new("a"), b"a");
    let model = decoded(&pca::run(&build.atlas, &source, &PROGRAM, Components::Count(1)).unwrap(), "bandwidth-pca");
    let err = stage::bandwidth_atlas::from_payload(model.payload).unwrap_err();
    assert_eq!(err, "expected a bandwidth-atlas or bandwidth-rows asset (from brdf-bandwidth), found bandwidth-pca");
}

/// The PCA of an isotropic atlas is fitted on its 16 rows: a model one lobe wide, the relative
/// RMSE of a fit on the full grid with as many components (equal to 1e-6: the two fits have
/// the same components, see `bandwidth-atlas`'s test), a size against the distinct tiles exactly 16
/// times its size against the full grid, and the same error bound met with the same K.
#[test]
fn the_pca_of_rows_is_the_full_grid_fit_and_reports_both_sizes() {
    let (staged, build) = ggx_stage();
    let full = &build.atlas;
    let source = Source::of_bytes(Path::new("bandwidth-atlas.asset"), &staged.file("bandwidth-atlas").unwrap().bytes);
    let pca = pca::run(full, &source, &PROGRAM, Components::MaxRelativeRmse(0.02)).unwrap();
    let Payload::BandwidthPca(model) = decoded(&pca, "bandwidth-pca").payload else { panic!("not a pca model") };
    let k = model.n_components as usize;
    assert_eq!((model.lobes_x, model.lobes_y, model.coefficients.len()), (1, LOBES as u32, LOBES * k));
    assert_eq!(figure(&pca, "distinct_tiles") as usize, LOBES);
    assert_eq!(figure(&pca, "lobes") as usize, LOBES * LOBES);

    let on_full_grid = fit(full, Components::Count(k)).unwrap().model;
    let full_report = evaluate(full, &on_full_grid);
    let (rmse, ratio, ratio_full) =
        (figure(&pca, "relative_rmse"), figure(&pca, "size_ratio"), figure(&pca, "size_ratio_full_grid"));
    println!(
        "K {k}: relative rmse {rmse:.6} (full-grid fit {:.6}); size {ratio:.4} of the rows, {ratio_full:.6} of the \
         grid (full-grid fit: {:.4})",
        full_report.relative_rmse, full_report.size_ratio
    );
    assert!(rmse <= 0.02 && (rmse - full_report.relative_rmse).abs() <= 1e-6);
    assert!((ratio - LOBES as f64 * ratio_full).abs() <= 1e-12 * ratio);
    let stored = 256 + k * 256 + LOBES * k;
    assert!((ratio - stored as f64 / (LOBES * 256) as f64).abs() <= 1e-12);
    assert_eq!(fit(full, Components::MaxRelativeRmse(0.02)).unwrap().model.n_components, k);

    // The report says when the model outgrows the tiles it stands for (16 components of 16 rows:
    // 256 + 16 x 256 + 16 x 16 floats for 16 x 256 texels), and only then.
    let note = "holds more floats than the 16 distinct tiles";
    assert!(ratio < 1.0 && !pca.report.iter().any(|l| l.contains(note)), "{:?}", pca.report);
    let large = pca::run(full, &source, &PROGRAM, Components::Count(16)).unwrap();
    assert!(figure(&large, "size_ratio") > 1.0 && large.report.iter().any(|l| l.contains(note)), "{:?}", large.report);
}

/// An atlas whose tiles differ within a row is fitted whole: one coefficient set per lobe, and
/// the two sizes coincide.
#[test]
fn an_anisotropic_atlas_is_fitted_on_every_tile() {
    let (_, build) = ggx_stage();
    let mut anisotropic = build.atlas.clone();
    let lobe = anisotropic.lobe_index(3, 5);
    let tile: Vec<f32> = anisotropic.tile_of(lobe).iter().map(|v| v * 1.5 + 0.25).collect();
    anisotropic.set_tile(lobe, &tile);
    assert!(!anisotropic.is_isotropic());
    let source = Source::of_bytes(Path::new("a"), b"a");
    let pca = pca::run(&anisotropic, &source, &PROGRAM, Components::Count(3)).unwrap();
    let Payload::BandwidthPca(model) = decoded(&pca, "bandwidth-pca").payload else { panic!("not a pca model") };
    assert_eq!((model.lobes_x, model.lobes_y), (LOBES as u32, LOBES as u32));
    assert_eq!(figure(&pca, "distinct_tiles") as usize, LOBES * LOBES);
    assert_eq!(figure(&pca, "size_ratio"), figure(&pca, "size_ratio_full_grid"));
}
