//! `merl-importance` and the `importance` crate on the 20 shared real-derived materials: the
//! bars on relative variance and albedo, a chi-square test on peaked and broad
//! materials, and the tool end to end.

use importance::quality::{albedo_estimate, chi2_against_density, slice_quality};
use importance::{Config, build};
use merl::albedo::Quadrature;

use crate::support::{MATERIALS, NBRDF, nbrdf_table, png_decode, run, shared_or_skip, temp_dir, tool};

/// Nine slices, 10 degrees apart: 0, 30, 60 and 80 degrees are slices 0, 3, 6 and 8.
const SLICES: [usize; 4] = [0, 3, 6, 8];

fn config(n_samples: usize) -> Config {
    Config { n_theta_o: 9, n_samples, ..Config::default() }
}

/// Worst relative error over the channels of the albedo estimated by all vectors of slice `k`.
fn worst_albedo_error(
    table: &merl::MerlTable,
    tables: &importance::ImportanceTables,
    k: usize,
    reference: [f64; 3],
) -> f64 {
    let slice = &tables.slices()[k];
    let samples = tables.slice_samples(k);
    let estimate = albedo_estimate(table, slice, samples);
    (0..3).map(|c| (estimate[c] / reference[c] - 1.0).abs()).fold(0.0, f64::max)
}

#[test]
fn relative_variance_and_albedo_on_all_shared_materials() {
    let Some(_) = shared_or_skip(&[NBRDF]) else { return };
    let mut report =
        String::from("material                 theta_o      rv   rv_cos   albedo err 8x256   8x64   (8x4096)\n");
    let mut failures = Vec::new();
    for name in MATERIALS {
        let table = merl::read_file(&nbrdf_table(name)).unwrap();
        let t256 = build(&table, &config(256)).unwrap();
        let t64 = build(&table, &config(64)).unwrap();
        let t4096 = matches!(name, "chrome" | "steel").then(|| build(&table, &config(4096)).unwrap());
        for k in SLICES {
            let q = slice_quality(&table, &t256.slices()[k], Quadrature::default());
            let e256 = worst_albedo_error(&table, &t256, k, q.albedo);
            let e64 = worst_albedo_error(&table, &t64, k, q.albedo);
            let e4096 = t4096.as_ref().map(|t| worst_albedo_error(&table, t, k, q.albedo));
            let deg = q.theta_o.to_degrees();
            report += &format!(
                "{name:<24} {deg:>5.0} {:>9.5} {:>9.4} {:>14.2}% {:>6.2}%   {}\n",
                q.rv,
                q.rv_cos,
                100.0 * e256,
                100.0 * e64,
                e4096.map_or(String::new(), |e| format!("{:.3}%", 100.0 * e))
            );
            let mut check = |ok: bool, what: String| {
                if !ok {
                    failures.push(format!("{name} at {deg} deg: {what}"));
                }
            };
            check(q.rv <= 0.1, format!("rv {} > 0.1", q.rv));
            if matches!(name, "chrome" | "nickel" | "red-metallic-paint" | "color-changing-paint3" | "gold-paint") {
                check(q.rv <= q.rv_cos / 10.0, format!("rv {} > rv_cos / 10 = {}", q.rv, q.rv_cos / 10.0));
            }
            if matches!(name, "white-paint" | "pink-fabric") {
                check(q.rv <= 1.2 * q.rv_cos + 0.01, format!("rv {} > 1.2 rv_cos + 0.01", q.rv));
            }
            check(e256 <= 0.02, format!("8 x 256 albedo off by {:.2}%", 100.0 * e256));
            check(e64 <= 0.04, format!("8 x 64 albedo off by {:.2}%", 100.0 * e64));
            if let Some(e) = e4096 {
                check(e <= 0.0075, format!("8 x 4096 albedo off by {:.3}%", 100.0 * e));
            }
            check((0.995..=1.0 + 1e-4).contains(&q.upper_mass), format!("upper-hemisphere mass {}", q.upper_mass));
        }
    }
    eprintln!("{report}");
    assert!(failures.is_empty(), "{}\n{report}", failures.join("\n"));
}

#[test]
fn samples_pass_a_chi_square_test_on_real_derived_materials() {
    let Some(_) = shared_or_skip(&[NBRDF]) else { return };
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(12);
    for name in ["chrome", "gold-paint", "white-paint", "pink-fabric"] {
        let table = merl::read_file(&nbrdf_table(name)).unwrap();
        let tables = build(&table, &config(256)).unwrap();
        for k in SLICES {
            // The density is positive wherever the integrand is.
            let slice = &tables.slices()[k];
            for _ in 0..20_000 {
                let z: f64 = 1.0 - rng.random::<f64>();
                let wi = merl::spherical_dir(z.acos(), 2.0 * std::f64::consts::PI * rng.random::<f64>());
                if let Some(f) = table.lookup(wi, slice.wo(), merl::Interp::Nearest)
                    && color::luminance(f) > 0.0
                {
                    assert!(slice.pdf(wi) > 0.0, "{name} slice {k}: pdf 0 at {wi} where f cos > 0");
                }
            }
            let q = Quadrature { nodes_per_cell: 16, n_phi_h: 2880 };
            let r = chi2_against_density(&tables.slices()[k], 200_000, 11 + k as u64, q);
            assert!(r.p_value > sampling::chi2::ACCEPT, "{name} slice {k}: {r:?}");
        }
    }
}

#[test]
fn merl_importance_writes_an_asset_and_a_picture() {
    let dir = temp_dir();
    let material = dir.path().join("ggx.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["ggx", "--alpha", "0.1", "--out"]).arg(&material);
    run(cmd, "").expect_code(0);

    let out_dir = dir.path().join("out");
    let mut cmd = tool("merl-importance");
    cmd.arg(&material).arg("--out-dir").arg(&out_dir).args([
        "--theta-o",
        "18",
        "--vectors",
        "2",
        "--samples",
        "64",
        "--report",
    ]);
    let r = run(cmd, "").expect_code(0).expect_stdout("relative variance").expect_stdout("cosine");
    assert!(r.stderr.contains("wrote"), "{r}");
    let out = out_dir.join("importance.asset");

    let mut cmd = tool("asset-info");
    cmd.arg(&out).arg("--json");
    let info = run(cmd, "").expect_code(0);
    let json = info.json();
    assert_eq!(json["header"]["kind"], "importance-samples", "{info}");
    assert_eq!(json["payload"]["theta_o"].as_array().unwrap().len(), 18, "{info}");
    assert_eq!(json["payload"]["n_samples"], 64, "{info}");

    let asset = asset::read_file(&out).unwrap();
    let asset::Payload::ImportanceSamples(p) = asset.payload else { panic!("wrong kind") };
    assert_eq!(p.samples.len(), 18 * 2 * 64);
    // Every stored sample is a unit direction with the density its own tables give it.
    let rows = p.theta_h_edges.len() - 1;
    let cols = p.n_phi_h as usize;
    for (i, s) in p.samples.iter().enumerate() {
        let k = i / (2 * 64);
        let wi = glam::DVec3::new(s[0] as f64, s[1] as f64, s[2] as f64);
        assert!((wi.length() - 1.0).abs() < 1e-5, "sample {i}: {wi}");
        if s[3] == 0.0 {
            continue;
        }
        let wo = merl::spherical_dir(p.theta_o[k], 0.0);
        let h = (wi + wo).normalize();
        let theta_h = h.x.hypot(h.y).atan2(h.z);
        let row = p.theta_h_edges[1..].partition_point(|e| *e <= theta_h).min(rows - 1);
        let col = ((h.y.atan2(h.x).rem_euclid(2.0 * std::f64::consts::PI)) / (2.0 * std::f64::consts::PI) * cols as f64)
            as usize;
        let density = p.h_density[(k * rows + row) * cols + col.min(cols - 1)] as f64 / (4.0 * wo.dot(h));
        // f32 storage: the direction is rounded, which can move h across a cell edge only for
        // samples within ~1e-7 of it; allow those few.
        if (density - s[3] as f64).abs() > 1e-4 * density {
            let near_edge = p.theta_h_edges.iter().any(|e| (e - theta_h).abs() < 1e-5);
            assert!(near_edge, "sample {i}: stored pdf {} vs tables {density}", s[3]);
        }
    }

    // The picture's layout is the picture code's business: it must be a whole PNG.
    png_decode(&out_dir.join("importance.png"));
    let mut names: Vec<_> = std::fs::read_dir(&out_dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    names.sort();
    assert_eq!(names, ["importance.asset", "importance.png"], "the files --help names, and no temporary file");
}

#[test]
fn merl_importance_refuses_bad_settings() {
    let dir = temp_dir();
    let material = dir.path().join("lambert.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["lambertian", "--out"]).arg(&material);
    run(cmd, "").expect_code(0);
    let mut cmd = tool("merl-importance");
    cmd.arg(&material).arg("--out-dir").arg(dir.path().join("x")).args(["--samples", "0"]);
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("invalid value '0' for '--samples <S>': expected a whole number from 1 up"), "{r}");
    // A count the option takes but the tables cannot hold is the library's to refuse.
    let mut cmd = tool("merl-importance");
    cmd.arg(&material).arg("--out-dir").arg(dir.path().join("x")).args(["--vectors", "2000"]);
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("invalid setting: vectors 2000 exceeds the limit of 1024"), "{r}");
    assert!(!dir.path().join("x").exists(), "nothing is written for a bad setting\n{r}");
}

/// A tool's outputs land together or not at all: an asset left behind when the PNG cannot be
/// written (exit 2) is a target a build system takes for done. Here the PNG's name is taken by a folder: exit 2 naming the PNG (not a temporary file),
/// no asset, no temporary file. Temporaries an interrupted run left for these names are removed
/// by the next run.
#[test]
fn outputs_land_as_a_set_and_stale_temporaries_are_removed() {
    let dir = temp_dir();
    let material = dir.path().join("lambert.binary");
    let mut cmd = tool("merl-synth");
    cmd.args(["lambertian", "--out"]).arg(&material);
    run(cmd, "").expect_code(0);
    let out = dir.path().join("out");
    std::fs::create_dir_all(out.join("importance.png")).unwrap();
    let importance = || {
        let mut cmd = tool("merl-importance");
        cmd.arg(&material).arg("--out-dir").arg(&out).args(["--theta-o", "4", "--vectors", "2", "--samples", "16"]);
        cmd
    };
    let r = run(importance(), "").expect_code(2);
    let png = out.join("importance.png");
    assert!(r.stderr.starts_with(&format!("error: writing {}: ", png.display())), "{r}");
    assert!(!r.stderr.contains("/.importance."), "the error names a temporary file\n{r}");
    let left: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(left, ["importance.png"], "only the folder in the way remains\n{r}");

    std::fs::remove_dir(&png).unwrap();
    let stale = [".importance.asset.Ab3dE9.tmp", ".importance.png.x7YqZ2.tmp"];
    for name in stale {
        std::fs::write(out.join(name), b"left by a killed run").unwrap();
    }
    std::fs::write(out.join(".notes.txt.Ab3dE9.tmp"), b"not ours").unwrap();
    run(importance(), "").expect_code(0);
    let mut left: Vec<String> =
        std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, [".notes.txt.Ab3dE9.tmp", "importance.asset", "importance.png"]);
}
