//! `merl-info` and `merl-synth` end to end: known answers on analytic tables, the reference
//! reader's cells on real-derived tables, and `--eval`.

use std::f64::consts::{FRAC_PI_2, PI};

use rand::{Rng, SeedableRng, rngs::StdRng};

use crate::support::{NBRDF, nbrdf_table, run, shared_or_skip, temp_dir, tool};

fn synth(dir: &std::path::Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let out = dir.join(name);
    let mut cmd = tool("merl-synth");
    cmd.args(args).arg("--out").arg(&out);
    run(cmd, "").expect_code(0);
    out
}

fn summary_json(path: &std::path::Path) -> (i32, serde_json::Value) {
    let mut cmd = tool("merl-info");
    cmd.arg(path).arg("--json");
    let r = run(cmd, "");
    let code = r.code.unwrap_or_else(|| panic!("killed by a signal\n{r}"));
    let json = serde_json::from_str(&r.stdout).unwrap_or_else(|e| panic!("bad JSON: {e}\n{r}"));
    (code, json)
}

fn albedo_rows(json: &serde_json::Value) -> Vec<(f64, [f64; 3])> {
    json["albedo"]
        .as_array()
        .expect("albedo array")
        .iter()
        .map(|row| {
            let rgb: Vec<f64> = row["rgb"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
            (row["theta_o_deg"].as_f64().unwrap(), [rgb[0], rgb[1], rgb[2]])
        })
        .collect()
}

#[test]
fn lambertian_table_reports_its_albedo_at_every_angle() {
    let dir = temp_dir();
    let path = synth(dir.path(), "lambert.binary", &["lambertian", "--albedo", "0.5"]);
    let (code, json) = summary_json(&path);
    assert_eq!(code, 0, "{json:#}");
    let rows = albedo_rows(&json);
    assert_eq!(rows.iter().map(|r| r.0).collect::<Vec<_>>(), [0.0, 30.0, 60.0, 80.0]);
    for (deg, rgb) in rows {
        for v in rgb {
            assert!((v - 0.5).abs() <= 0.005, "theta_o {deg}: albedo {v}, expected 0.5 within 1%");
        }
    }
    assert_eq!(json["no_data_cells"], 346_570);
    assert_eq!(json["dims"], serde_json::json!([90, 90, 180]));

    // The text names the lookup the albedo was integrated with (other tools report albedos by
    // the nearest lookup).
    for (interp, label) in [("trilinear", "albedo (trilinear lookup)"), ("nearest", "albedo (nearest lookup)")] {
        let mut cmd = tool("merl-info");
        cmd.arg(&path).args(["--albedo-interp", interp]);
        let r = run(cmd, "").expect_code(0).expect_stdout(label);
        assert!(r.stdout.contains("theta_o 80 deg  0.5000 0.5000 0.5000"), "{r}");
    }
}

/// `merl-synth` needs `--out` (a table is 35 MB: never a default place), and every argument of
/// every BRDF has a help line.
#[test]
fn merl_synth_needs_out_and_explains_every_argument() {
    let mut cmd = tool("merl-synth");
    cmd.args(["phong", "-n", "10"]);
    let r = run(cmd, "").expect_code(2);
    assert!(r.stderr.contains("--out <FILE>") && r.stdout.is_empty(), "{r}");
    for brdf in ["lambertian", "phong", "blinn-phong", "ggx"] {
        let mut cmd = tool("merl-synth");
        cmd.args([brdf, "-h"]);
        let r = run(cmd, "").expect_code(0);
        let options = r.stdout.split_once("Options:\n").unwrap_or_else(|| panic!("no options\n{r}")).1;
        for line in options.lines().filter(|l| l.trim_start().starts_with('-')) {
            // "  -n, --n <N>   help": the option, then at least two spaces, then its help.
            let parts: Vec<&str> = line.trim().split("  ").filter(|p| !p.trim().is_empty()).collect();
            assert!(parts.len() >= 2, "merl-synth {brdf}: {:?} has no help\n{r}", line.trim());
        }
    }
}

#[test]
fn normalized_phong_table_does_not_exceed_one() {
    // Energy-normalized Phong reflects exactly 1 at normal incidence and less elsewhere; the
    // table may add its discretization error (trilinear between lower-edge samples: +0.24% at
    // n = 100, measured), which the 1% allowance of merl-info's own check covers. A missing
    // Jacobian term or a wrong solid angle would be off by far more.
    let dir = temp_dir();
    let path = synth(dir.path(), "phong.binary", &["phong", "-n", "100"]);
    let (code, json) = summary_json(&path);
    assert_eq!(code, 0, "merl-info flagged a problem: {json:#}");
    let rows = albedo_rows(&json);
    assert!((rows[0].1[0] - 1.0).abs() < 0.01, "normal incidence: {:?}", rows[0]);
    for (deg, rgb) in rows {
        assert!(rgb.iter().all(|v| *v <= 1.01), "theta_o {deg}: {rgb:?}");
    }
}

#[test]
fn validation_flags_a_table_that_reflects_more_than_it_receives() {
    // Lambertian albedo 1 scaled up is not something merl-synth writes, so build it by hand.
    let dir = temp_dir();
    let table = merl::analytic::Analytic::Lambertian { albedo: [0.5; 3] }.table(merl::Dims::MERL);
    let raw: Vec<f64> = table.raw().iter().map(|v| if *v < 0.0 { *v } else { v * 2.5 }).collect();
    let bright = merl::MerlTable::from_raw(merl::Dims::MERL, raw).unwrap();
    let path = dir.path().join("bright.binary");
    std::fs::write(&path, bright.to_bytes()).unwrap();
    let mut cmd = tool("merl-info");
    cmd.arg(&path);
    let r = run(cmd, "").expect_code(1);
    assert!(r.stdout.contains("problem: albedo above 1.01 at theta_o 0 deg"), "{r}");
}

/// The cell and the scaled stored value that the reference MERL reader returns, computed here
/// from the file's bytes with the reference formulas (acos, Rodrigues rotations).
struct Reference {
    bytes: Vec<u8>,
}

impl Reference {
    fn cell_and_coords(ti: f64, fi: f64, to: f64, fo: f64) -> (usize, [f64; 3]) {
        let sph = |t: f64, f: f64| [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()];
        let rot = |v: [f64; 3], axis: [f64; 3], a: f64| {
            let (s, c) = a.sin_cos();
            let dot = v[0] * axis[0] + v[1] * axis[1] + v[2] * axis[2];
            let x = [axis[1] * v[2] - axis[2] * v[1], axis[2] * v[0] - axis[0] * v[2], axis[0] * v[1] - axis[1] * v[0]];
            [0, 1, 2].map(|k| v[k] * c + axis[k] * dot * (1.0 - c) + x[k] * s)
        };
        let (a, b) = (sph(ti, fi), sph(to, fo));
        let h = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let n = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        let h = h.map(|v| v / n);
        let (th, fh) = (h[2].acos(), h[1].atan2(h[0]));
        let d = rot(rot(a, [0.0, 0.0, 1.0], -fh), [0.0, 1.0, 0.0], -th);
        let (td, mut pd) = (d[2].clamp(-1.0, 1.0).acos(), d[1].atan2(d[0]));
        if pd < 0.0 {
            pd += PI;
        }
        let coords = [(th / FRAC_PI_2 * 8100.0).sqrt(), td / FRAC_PI_2 * 90.0, pd / PI * 180.0];
        let idx = |x: f64, n: i64| (x as i64).clamp(0, n - 1) as usize;
        ((idx(coords[0], 90) * 90 + idx(coords[1], 90)) * 180 + idx(coords[2], 180), coords)
    }

    fn scaled(&self, cell: usize) -> [f64; 3] {
        let scale = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
        [0, 1, 2].map(|c| {
            let at = 12 + 8 * (c * 1_458_000 + cell);
            f64::from_le_bytes(self.bytes[at..at + 8].try_into().unwrap()) * scale[c]
        })
    }
}

#[test]
fn eval_returns_the_reference_readers_cells_on_real_derived_tables() {
    let Some(_) = shared_or_skip(&[NBRDF]) else { return };
    let mut rng = StdRng::seed_from_u64(7);
    for name in ["gold-paint", "chrome", "white-paint"] {
        let path = nbrdf_table(name);
        let reference = Reference { bytes: std::fs::read(&path).unwrap() };
        let mut input = String::new();
        let mut expected = Vec::new();
        for _ in 0..20_000 {
            let a: [f64; 4] = [
                (1.0 - rng.random::<f64>()).acos().min(FRAC_PI_2 - 1e-9),
                2.0 * PI * rng.random::<f64>(),
                (1.0 - rng.random::<f64>()).acos().min(FRAC_PI_2 - 1e-9),
                2.0 * PI * rng.random::<f64>(),
            ];
            input.push_str(&format!("{:e} {:e} {:e} {:e}\n", a[0], a[1], a[2], a[3]));
            expected.push(Reference::cell_and_coords(a[0], a[1], a[2], a[3]));
        }
        let mut cmd = tool("merl-info");
        cmd.arg(&path).args(["--eval", "--no-data", "raw"]);
        let r = run(cmd, &input).expect_code(0);
        let lines: Vec<&str> = r.stdout.lines().collect();
        assert_eq!(lines.len(), expected.len(), "{name}: one line per input line");
        let (mut exact, mut borderline, mut no_data) = (0, 0, 0);
        for (line, (cell, coords)) in lines.iter().zip(&expected) {
            let got: Vec<f64> = line.split_whitespace().map(|v| v.parse().unwrap()).collect();
            let want = reference.scaled(*cell);
            if want.iter().any(|v| *v < 0.0) {
                no_data += 1;
            }
            if got == want {
                exact += 1;
            } else {
                // Only a pair within 1e-7 cells of an edge may round into the neighbour cell
                // (see crates/merl/tests/reference_lookup.rs).
                assert!(coords.iter().any(|x| (x - x.round()).abs() < 1e-7), "{name}: {line} vs {want:?}");
                borderline += 1;
            }
        }
        eprintln!("{name}: {exact} exact, {borderline} at cell edges, {no_data} in no-data cells");
        assert!(borderline <= 2, "{name}: {borderline} pairs disagree at cell edges");
    }
}

#[test]
fn eval_reads_stdin_and_reports_bad_lines() {
    let dir = temp_dir();
    let path = synth(dir.path(), "lambert.binary", &["lambertian", "--albedo", "0.2,0.4,0.6"]);
    let mut cmd = tool("merl-info");
    cmd.arg(&path).args(["--eval", "--interp", "trilinear"]);
    let r = run(cmd, "# theta_i phi_i theta_o phi_o\n0.1 0 0.5 3.0\n\n1.2 2 0.3 -1\n").expect_code(0);
    let rows: Vec<Vec<f64>> =
        r.stdout.lines().map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 2, "{r}");
    for row in rows {
        for (v, a) in row.iter().zip([0.2, 0.4, 0.6]) {
            assert!((v - a / PI).abs() < 1e-12, "{v} vs {}", a / PI);
        }
    }
    let mut cmd = tool("merl-info");
    cmd.arg(&path).arg("--eval");
    let r = run(cmd, "0.1 0 0.5 3.0\n0.1 0 nan 3\n").expect_code(2);
    assert!(r.stderr.contains("stdin line 2") && r.stderr.contains("theta_o nan is outside [0, pi]"), "{r}");
    // An angle no direction has is a mistake, not a lookup that finds no data (1e308 must not
    // print zeros); the message names the angle and the range.
    for (line, says) in [
        ("1e308 0 0 0", "theta_i 1e308 is outside [0, pi]"),
        ("0.1 7 0.5 0", "phi_i 7 is outside [-2 pi, 2 pi]"),
        ("0.1 0 -0.5 0", "theta_o -0.5 is outside [0, pi]"),
    ] {
        let mut cmd = tool("merl-info");
        cmd.arg(&path).arg("--eval");
        let r = run(cmd, line).expect_code(2);
        assert!(r.stderr.contains("stdin line 1") && r.stderr.contains(says), "{line}: {r}");
        assert_eq!(r.stderr.lines().count(), 1, "{r}");
    }
}
