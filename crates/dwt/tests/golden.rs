//! Every transform against PyWavelets 1.9.0 (`mode="periodization"`): golden vectors written by
//! `tests/golden/make_golden.py`, whose header explains the layout.
//!
//! Tolerance 1e-12 absolute: inputs lie in [-1, 1], so coefficients are O(1) (at most
//! 2^(levels/2) per axis for the approximation) and the two implementations differ only in the
//! order of a handful of additions per level, i.e. by a few ulps.

use dwt::{
    Decomposition, Decomposition2, Image, Wavelet, dwt, dwt2, idwt, idwt2, wavedec, wavedec2, waverec, waverec2,
};
use serde_json::Value;

use crate::max_abs_diff;

const TOLERANCE: f64 = 1e-12;

fn cases(json: &str) -> Vec<Value> {
    let root: Value = serde_json::from_str(json).expect("golden json parses");
    root["cases"].as_array().expect("cases").clone()
}

fn wavelet(case: &Value) -> Wavelet {
    match case["wavelet"].as_str().expect("wavelet name") {
        "db2" => Wavelet::D4,
        "haar" => Wavelet::Haar,
        other => panic!("unknown wavelet {other}"),
    }
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().expect("array of numbers").iter().map(|x| x.as_f64().expect("number")).collect()
}

fn list(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().expect("list of arrays").iter().map(floats).collect()
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().expect("unsigned") as usize
}

/// Tracks the worst difference seen and the context it was seen in.
#[derive(Default)]
struct Worst {
    diff: f64,
    checks: usize,
}

impl Worst {
    fn check(&mut self, context: &str, got: &[f64], want: &[f64]) {
        let diff = max_abs_diff(got, want);
        assert!(diff <= TOLERANCE, "{context}: max |difference| {diff:e} > {TOLERANCE:e}");
        self.diff = self.diff.max(diff);
        self.checks += 1;
    }
}

#[test]
fn one_dimensional_transforms_match_pywavelets() {
    let cases = cases(include_str!("golden/golden_1d.json"));
    assert_eq!(cases.len(), 12, "golden_1d.json: 6 lengths x 2 wavelets");
    let mut worst = Worst::default();
    for case in &cases {
        let w = wavelet(case);
        let n = usize_of(&case["shape"][0]);
        let levels = usize_of(&case["max_level"]);
        assert_eq!(levels, dwt::max_levels(n));
        let name = format!("{} n={n}", w.pywt_name());
        let x = floats(&case["input"]);
        let (approx, details) = (list(&case["approx"]), list(&case["details"]));

        let (a, d) = dwt(&x, w).unwrap();
        worst.check(&format!("{name} dwt approx"), &a, &approx[0]);
        worst.check(&format!("{name} dwt detail"), &d, &details[0]);
        for l in 1..=levels {
            let dec = wavedec(&x, w, l).unwrap();
            assert_eq!(dec.levels(), l);
            worst.check(&format!("{name} wavedec level={l} approx"), &dec.approx, &approx[l - 1]);
            for j in 1..=l {
                worst.check(&format!("{name} wavedec level={l} detail {j}"), dec.detail(j), &details[j - 1]);
            }
        }

        let (inv_details, recon) = (list(&case["inv_details"]), list(&case["inv_recon"]));
        let approx_at = |l: usize| if l == levels { floats(&case["inv_approx"]) } else { recon[l].clone() };
        for l in 1..=levels {
            let got = idwt(&approx_at(l), &inv_details[l - 1], w).unwrap();
            worst.check(&format!("{name} idwt level {l}"), &got, &recon[l - 1]);
            let dec = Decomposition { wavelet: w, approx: approx_at(l), details: inv_details[..l].to_vec() };
            worst.check(&format!("{name} waverec level={l}"), &waverec(&dec).unwrap(), &recon[0]);
        }
    }
    eprintln!("1d: {} comparisons, max |difference| against PyWavelets {:e}", worst.checks, worst.diff);
}

fn image(case: &Value, data: Vec<f64>, level: usize) -> Image {
    let (h, w) = (usize_of(&case["shape"][0]), usize_of(&case["shape"][1]));
    Image::new(w >> level, h >> level, data).unwrap()
}

fn levels2(case: &Value, key: &str) -> Vec<[Vec<f64>; 3]> {
    case[key]
        .as_array()
        .expect("list of levels")
        .iter()
        .map(|level| {
            let o = list(level);
            assert_eq!(o.len(), 3, "three orientations");
            [o[0].clone(), o[1].clone(), o[2].clone()]
        })
        .collect()
}

#[test]
fn two_dimensional_transforms_match_pywavelets() {
    let cases = cases(include_str!("golden/golden_2d.json"));
    assert_eq!(cases.len(), 7, "golden_2d.json: 4 shapes for db2, 3 for haar");
    let mut worst = Worst::default();
    for case in &cases {
        let w = wavelet(case);
        let (h, wd) = (usize_of(&case["shape"][0]), usize_of(&case["shape"][1]));
        let levels = usize_of(&case["max_level"]);
        assert_eq!(levels, dwt::max_levels2(wd, h));
        let name = format!("{} {h}x{wd} (numpy shape)", w.pywt_name());
        let x = image(case, floats(&case["input"]), 0);
        let (approx, details) = (list(&case["approx"]), levels2(case, "details"));

        let (a, d) = dwt2(&x, w).unwrap();
        worst.check(&format!("{name} dwt2 approx"), a.data(), &approx[0]);
        for (o, (got, want)) in d.iter().zip(&details[0]).enumerate() {
            worst.check(&format!("{name} dwt2 detail {o}"), got.data(), want);
        }
        for l in 1..=levels {
            let dec = wavedec2(&x, w, l).unwrap();
            assert_eq!(dec.levels(), l);
            assert_eq!((dec.approx.width(), dec.approx.height()), (wd >> l, h >> l));
            worst.check(&format!("{name} wavedec2 level={l} approx"), dec.approx.data(), &approx[l - 1]);
            for j in 1..=l {
                for (o, want) in dwt::Orientation::ALL.into_iter().zip(&details[j - 1]) {
                    let got = dec.detail(j, o);
                    let context = format!("{name} wavedec2 level={l} detail {j} {}", o.name());
                    worst.check(&context, got.data(), want);
                }
            }
        }

        let inv_details = levels2(case, "inv_details");
        let recon = list(&case["inv_recon"]);
        let approx_at = |l: usize| {
            let data = if l == levels { floats(&case["inv_approx"]) } else { recon[l].clone() };
            image(case, data, l)
        };
        let details_at = |j: usize| inv_details[j - 1].clone().map(|o| image(case, o, j));
        for l in 1..=levels {
            let got = idwt2(&approx_at(l), &details_at(l), w).unwrap();
            worst.check(&format!("{name} idwt2 level {l}"), got.data(), &recon[l - 1]);
            let dec = Decomposition2 { wavelet: w, approx: approx_at(l), details: (1..=l).map(details_at).collect() };
            let got = waverec2(&dec).unwrap();
            assert_eq!((got.width(), got.height()), (wd, h));
            worst.check(&format!("{name} waverec2 level={l}"), got.data(), &recon[0]);
        }
    }
    eprintln!("2d: {} comparisons, max |difference| against PyWavelets {:e}", worst.checks, worst.diff);
}

/// The filters are PyWavelets' to the last bit (printed there with `repr`).
#[test]
fn filters_are_pywavelets_filters() {
    let db2_dec_lo = [-0.12940952255126037, 0.2241438680420134, 0.8365163037378079, 0.48296291314453416];
    let db2_dec_hi = [-0.48296291314453416, 0.8365163037378079, -0.2241438680420134, -0.12940952255126037];
    let db2_rec_lo = [0.48296291314453416, 0.8365163037378079, 0.2241438680420134, -0.12940952255126037];
    let db2_rec_hi = [-0.12940952255126037, -0.2241438680420134, 0.8365163037378079, -0.48296291314453416];
    assert_eq!(Wavelet::D4.dec_lo(), db2_dec_lo);
    assert_eq!(Wavelet::D4.dec_hi(), db2_dec_hi);
    assert_eq!(Wavelet::D4.rec_lo(), db2_rec_lo);
    assert_eq!(Wavelet::D4.rec_hi(), db2_rec_hi);
    // Parsed from PyWavelets' printout rather than written as a literal (clippy wants the std
    // constant there, and equality with it is what this checks).
    let s: f64 = "0.7071067811865476".parse().unwrap();
    assert_eq!(Wavelet::Haar.dec_lo(), [s, s]);
    assert_eq!(Wavelet::Haar.dec_hi(), [-s, s]);
    assert_eq!(Wavelet::Haar.rec_lo(), [s, s]);
    assert_eq!(Wavelet::Haar.rec_hi(), [s, -s]);
}
