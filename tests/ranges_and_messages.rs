//! Numeric options with ranges, work with a ceiling, decoded values held to sane ranges, and the
//! messages a newcomer meets: every refusal is one line with exit 2 and comes at once, never a
//! panic, a hang or a result that is not a number.

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use crate::support::{BAKE_ENV, ggx_copper, reference_bake, run, run_within, shared_or_skip, temp_dir, tool};

/// Any of these runs ends in well under this; a refusal that computes first would not.
const QUICK: Duration = Duration::from_secs(30);

fn command(name: &str, args: &[&str]) -> Command {
    let mut cmd = tool(name);
    cmd.args(args);
    cmd
}

fn preview(args: &[&str]) -> Command {
    let mut cmd = tool("brdf-preview");
    cmd.arg(&reference_bake().dir).args(args);
    cmd
}

/// Each value no option should take is refused at once with one line that names the option and
/// says what it accepts; the work options name the limit and how to raise it.
#[test]
fn numeric_options_are_refused_outside_their_range() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let png = tmp.path().join("p.png");
    let png = png.to_str().unwrap();
    let env = crate::support::bake_env();
    let env = env.to_str().unwrap();
    let material = ggx_copper().to_str().unwrap();
    let out = tmp.path().join("out");
    let out = out.to_str().unwrap();
    let cases: Vec<(Command, &str)> = vec![
        // A panic ("attempt to divide by zero"), with and without --frames.
        (preview(&["--out", png, "--spp", "0"]), "'--spp <N>': expected a whole number from 1 to 4294967295"),
        (preview(&["--out", png, "--spp", "0", "--frames", "1"]), "--spp <N>"),
        // Work without a bound.
        (preview(&["--out", png, "--frames", "4294967295"]), "above the limit of 4294967296 (--max-samples)"),
        (preview(&["--out", png, "--converged", "4294967295"]), "raise --max-samples for a deliberate long run"),
        (preview(&["--out", png, "--mode", "adaptive", "--spp", "4294967295"]), "(--max-samples)"),
        (preview(&["--out", png, "--size", "8192x8192"]), "(--max-samples)"),
        // NaN and infinities where they make no sense (a NaN gate always passed).
        (preview(&["--out", png, "--exposure", "nan"]), "'--exposure <EV>': expected a number from -64 to 64"),
        (preview(&["--out", png, "--exposure", "inf"]), "--exposure"),
        (preview(&["--out", png, "--min-psnr", "nan"]), "'--min-psnr <DB>': expected a finite number of dB"),
        (preview(&["--out", png, "--camera", "nan,0"]), "not a finite angle"),
        (preview(&["--out", png, "--wavelet-brdf-lod", "nan"]), "--wavelet-brdf-lod"),
        (preview(&["--out", png, "--max-samples", "0"]), "--max-samples"),
        // A budget the layers alone exceed said "a budget of 0 bytes".
        (
            command("brdf-bake", &[material, "--env", env, "--out-dir", out, "--max-memory", "1"]),
            "a memory budget of 1 bytes (--max-memory) leaves nothing for the map",
        ),
        // 0 turned the GGX chain off where 1 and 8 are refused.
        (
            command("brdf-bake", &[material, "--env", env, "--out-dir", out, "--ggx-levels", "0"]),
            "'--ggx-levels <M>': expected a whole number from 2 up",
        ),
        (
            command("envmap-prefilter", &[env, "--out-dir", out, "--ggx-levels", "0"]),
            "expected a whole number from 2 up",
        ),
        // An epsilon that renders black, a threshold that is not a number.
        (
            command("brdf-wavelet", &[material, "--out-dir", out, "--epsilon", "1e308"]),
            "epsilon must be a number from 1e-12 to 1, found 1e308",
        ),
        (
            command("brdf-wavelet", &[material, "--out-dir", out, "--threshold", "nan"]),
            "'--threshold <T>': expected a finite number from 0",
        ),
        // A ratio past u32 said "out of range integral type conversion attempted".
        (
            command("brdf-wavelet", &[material, "--out-dir", out, "--ratio", "99999999999"]),
            "--ratio 99999999999 is too large: use a power of two up to the grid's N x N coefficient positions",
        ),
        (
            command("brdf-bake", &[material, "--out-dir", out, "--wavelet-brdf-ratio", "99999999999"]),
            "--wavelet-brdf-ratio 99999999999 is too large: use a power of two",
        ),
        // Exponents and widths whose tables overflow panicked.
        (
            command("merl-synth", &["phong", "-n", "1e308", "--out", out]),
            "--n must be a number in (0, 1e6], found 1e308",
        ),
        (command("merl-synth", &["ggx", "--alpha", "1e308", "--out", out]), "--alpha must be a number in [1e-3, 1e2]"),
        // A width far narrower than a cell made an infinite cell and panicked.
        (
            command("merl-synth", &["ggx", "--alpha", "1e-10", "--out", out]),
            "--alpha must be a number in [1e-3, 1e2], found 1e-10",
        ),
        (command("merl-synth", &["ggx", "--alpha", "1e-320", "--out", out]), "found 1e-320"),
        (command("merl-synth", &["ggx", "--alpha", "0", "--out", out]), "found 0.0"),
        (
            command("merl-synth", &["blinn-phong", "-n", "-1", "--out", out]),
            "--n must be a number in (0, 1e6], found -1",
        ),
    ];
    for (cmd, needle) in cases {
        let (r, took) = run_within(cmd, QUICK);
        r.expect_one_error_line(needle);
        assert!(took < QUICK, "{took:?}");
    }
    assert!(!Path::new(out).exists(), "a refused run wrote its folder");
}

/// Wavelet assets with values no BRDF has (coefficients of 1e30, a quantization step of 3e38,
/// epsilon 1e308) are refused by `asset-info` and the previewer; an asset within the ranges whose
/// reconstruction still overflows (every coefficient at the bound) renders non-finite pixels,
/// which is an error naming the asset, never exit 0 with "relative error inf".
#[test]
fn absurd_wavelet_assets_are_refused_and_a_render_that_overflows_is_an_error() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let dir = tmp.path().join("w");
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(ggx_copper()).arg("--out-dir").arg(&dir).args(["--side", "8", "--ratio", "4"]);
    run(cmd, "").expect_code(0);
    let good = asset::read_file(&dir.join("wavelet-brdf.asset")).unwrap();
    let asset::Payload::WaveletBrdf(payload) = &good.payload else { panic!("not a wavelet asset") };
    let write = |name: &str, edit: &dyn Fn(&mut asset::WaveletBrdf)| {
        let mut payload = payload.clone();
        edit(&mut payload);
        let asset = asset::Asset { provenance: good.provenance.clone(), payload: payload.into() };
        let path = tmp.path().join(name);
        // Written as a file would be damaged: the checks are the reader's.
        std::fs::write(&path, asset::encode(&asset)).unwrap();
        path
    };
    let float = |edit: fn(&mut Vec<f32>)| {
        move |p: &mut asset::WaveletBrdf| match &mut p.coefficients {
            asset::WaveletCoefficients::Float(v) => edit(v),
            _ => panic!("float coefficients"),
        }
    };
    let absurd = [
        write("coefficient-1e30.asset", &float(|v| v[0] = 1e30)),
        write("epsilon-1e308.asset", &|p| p.epsilon = 1e308),
        write("step-3e38.asset", &|p| {
            let k = 3 * p.stored_slices();
            let codes = vec![0u8; k * (p.side as usize).pow(2)];
            p.coefficients = asset::WaveletCoefficients::Quantized { offset: vec![0.0; k], step: vec![3e38; k], codes };
        }),
    ];
    let bake = reference_bake().dir.clone();
    let png = tmp.path().join("p.png");
    for path in &absurd {
        let mut cmd = tool("asset-info");
        cmd.arg(path);
        let r = run(cmd, "").expect_code(2);
        assert!(r.stderr.contains("invalid payload: wavelet brdf"), "{r}");
        let mut cmd = tool("brdf-preview");
        cmd.arg(&bake)
            .arg("--out")
            .arg(&png)
            .args(["--size", "16x16", "--brdf", "wavelet-brdf", "--wavelet-brdf"])
            .arg(path);
        run(cmd, "").expect_one_error_line("invalid payload: wavelet brdf");
    }

    // Every coefficient at the bound: a valid asset whose reconstruction overflows.
    let bound = (asset::WAVELET_LOG_BOUND * f64::from(payload.side)) as f32;
    let overflow = write("overflow.asset", &move |p: &mut asset::WaveletBrdf| {
        if let asset::WaveletCoefficients::Float(v) = &mut p.coefficients {
            v.iter_mut().for_each(|c| *c = bound);
        }
    });
    let mut cmd = tool("asset-info");
    cmd.arg(&overflow);
    run(cmd, "").expect_code(0);
    let mut cmd = tool("brdf-preview");
    cmd.arg(&bake).arg("--out").arg(&png).args(["--size", "16x16", "--spp", "16", "--frames", "1"]);
    cmd.args(["--brdf", "wavelet-brdf", "--wavelet-brdf"]).arg(&overflow);
    run(cmd, "").expect_one_error_line(&format!("rendering {}: the GPU render has", overflow.display()));
    assert!(!png.exists(), "a failed render wrote its picture");
}

/// What a newcomer meets: a PNG given as a table says it is a PNG; a folder that is not a bake
/// says so and how to make one; an output whose folder is missing creates no folder (from the
/// root or anywhere), while `--out-dir` is created itself; a successful headless preview prints no
/// line starting with `error:`, even where no Wayland session is set up (XDG_RUNTIME_DIR unset).
#[test]
fn messages_say_what_the_file_or_folder_is_and_what_to_do() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    let png = reference_bake().dir.join("importance.png");
    let mut cmd = tool("merl-info");
    cmd.arg(&png);
    run(cmd, "").expect_error(&png, "not a MERL table: this is a PNG image");

    let empty = tmp.path().join("not-a-bake");
    std::fs::create_dir(&empty).unwrap();
    let mut cmd = tool("brdf-preview");
    cmd.arg(&empty).args(["--out"]).arg(tmp.path().join("p.png"));
    let r = run(cmd, "").expect_one_error_line("not a bake folder (it has no manifest.json)");
    assert!(
        r.stderr.contains(&format!("brdf-bake MATERIAL.binary --env ENV.hdr --out-dir {}", empty.display())),
        "{r}"
    );

    let missing = tmp.path().join("nonexistent/dir");
    let mut cmd = preview(&["--size", "16x16", "--out"]);
    cmd.arg(missing.join("x.png"));
    run(cmd, "").expect_one_error_line(&format!("the folder {} does not exist", missing.display()));
    let mut cmd = tool("merl-synth");
    cmd.args(["lambertian", "--out"]).arg(missing.join("x.binary"));
    run(cmd, "").expect_one_error_line("does not exist");
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(ggx_copper()).arg("--out-dir").arg(&missing).args(["--side", "4"]);
    run(cmd, "").expect_one_error_line("its parent folder");
    assert!(!tmp.path().join("nonexistent").exists(), "a missing folder was created");
    let mut cmd = tool("brdf-wavelet");
    cmd.arg(ggx_copper()).arg("--out-dir").arg(tmp.path().join("new")).args(["--side", "4"]);
    run(cmd, "").expect_code(0);
    assert!(tmp.path().join("new/wavelet-brdf.asset").is_file());

    let mut cmd = preview(&["--size", "16x16", "--spp", "16", "--frames", "1", "--out"]);
    cmd.arg(tmp.path().join("ok.png")).env_remove("XDG_RUNTIME_DIR");
    let r = run(cmd, "").expect_code(0);
    assert!(!r.stderr.contains("error:"), "a successful run printed an error line\n{r}");
}

/// Values behind valid checksums: a bake whose importance samples, bandwidth rows or layer
/// selection hold a value no bake writes, with the manifest's size and hash made to match, is
/// refused by the previewer with one line naming the asset, the field and the value, and
/// `asset-info` says the same of the asset. A pdf within its range but not the density the tables
/// give its direction is refused as well: decoding
/// accepts it (a payload check across fields, `ImportanceSamples::check_densities`), the previewer
/// refuses it and `asset-info` reports it as a problem (exit 1).
#[test]
fn values_behind_valid_checksums_are_refused_by_every_reader() {
    let Some(_) = shared_or_skip(&[BAKE_ENV]) else { return };
    let tmp = temp_dir();
    /// The asset, what the message says, whether decoding refuses it (else only the densities'
    /// check does), the edit.
    type Case = (&'static str, &'static str, bool, fn(&mut asset::Payload));
    let cases: [Case; 5] = [
        ("importance.asset", "wi (1e30, 1e30, 1e30) is not a unit direction", true, |p| {
            let asset::Payload::ImportanceSamples(s) = p else { panic!("importance samples") };
            s.samples.iter_mut().for_each(|t| *t = [1e30; 4]);
        }),
        ("importance.asset", "h density 0 is NaN, not a finite density", true, |p| {
            let asset::Payload::ImportanceSamples(s) = p else { panic!("importance samples") };
            s.h_density[0] = f32::NAN;
        }),
        ("importance.asset", "is not the density the tables give its direction", false, |p| {
            let asset::Payload::ImportanceSamples(s) = p else { panic!("importance samples") };
            // 1% off: five times the tolerance or more wherever wo . h > 1e-3.
            let first = s.samples.iter_mut().find(|t| t[3] > 0.0).expect("a sample that reflects");
            first[3] *= 1.01;
        }),
        ("bandwidth-atlas.asset", "texel 0 is 1e30, outside [0, ", true, |p| {
            let asset::Payload::BandwidthRows(r) = p else { panic!("bandwidth rows") };
            r.data.iter_mut().for_each(|b| *b = 1e30);
        }),
        ("layer-selection.asset", "view bandwidth 0 is 1e300, outside [0, ", true, |p| {
            let asset::Payload::LayerSelection(l) = p else { panic!("layer selection") };
            l.view_bandwidth[0] = 1e300;
        }),
    ];
    for (i, (name, needle, decoding_refuses, edit)) in cases.into_iter().enumerate() {
        let dir = tmp.path().join(format!("case-{i}"));
        crate::support::copy_dir(&reference_bake().dir, &dir);
        let mut asset = asset::read_file(&dir.join(name)).unwrap();
        edit(&mut asset.payload);
        let bytes = asset::encode(&asset);
        std::fs::write(dir.join(name), &bytes).unwrap();
        // The manifest made to describe the new bytes: only the values are wrong.
        let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
        let mut manifest: serde_json::Value = serde_json::from_str(&text).unwrap();
        for stage in manifest["stages"].as_array_mut().unwrap() {
            for output in stage["outputs"].as_array_mut().unwrap().iter_mut().filter(|o| o["path"] == name) {
                output["size_bytes"] = bytes.len().into();
                output["sha256"] = asset::hex(&asset::sha256(&bytes)).into();
            }
        }
        std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&manifest).unwrap()).unwrap();

        let path = dir.join(name);
        let mut cmd = tool("brdf-preview");
        cmd.arg(&dir).arg("--out").arg(tmp.path().join("p.png")).args(["--size", "16x16", "--spp", "16"]);
        let (r, _) = run_within(cmd, QUICK);
        let prefix = if decoding_refuses { "invalid payload: " } else { "importance samples: sample " };
        let r = r.expect_one_error_line(&format!("reading {}: {prefix}", path.display()));
        assert!(r.stderr.contains(needle), "{r}");
        let mut cmd = tool("asset-info");
        cmd.arg(&path);
        if decoding_refuses {
            run(cmd, "").expect_error(&path, needle);
        } else {
            let r = run(cmd, "").expect_code(1);
            assert!(r.stderr.starts_with(&format!("error: checking {}: {prefix}", path.display())), "{r}");
            assert!(r.stderr.contains(needle) && r.stderr.lines().count() == 1, "{r}");
        }
    }
}

/// A map of finite radiance whose layers overflow (every texel RGBE exponent 255, about 1e38): the
/// error names the map (`analysing MAP: prefilter: ...`), not only the layer (`prefilter: layer of
/// the phong n 4096: non-finite radiance inf` alone names no file).
#[test]
fn a_map_whose_layers_overflow_is_named() {
    let tmp = temp_dir();
    let hdr = tmp.path().join("e255.hdr");
    let (w, h) = (64, 32);
    let mut bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    bytes.extend([200, 200, 200, 255].repeat(w * h));
    std::fs::write(&hdr, bytes).unwrap();
    let material = ggx_copper().to_str().unwrap();
    let out = tmp.path().join("out");
    let (hdr_text, out) = (hdr.to_str().unwrap(), out.to_str().unwrap());
    let needle = format!("analysing {hdr_text}: prefilter: ");
    for cmd in [
        command("brdf-bake", &[material, "--env", hdr_text, "--out-dir", out, "--analysis-size", "64"]),
        command("envmap-prefilter", &[hdr_text, "--out-dir", out]),
    ] {
        let (r, _) = run_within(cmd, QUICK);
        let r = r.expect_one_error_line(&needle);
        assert!(r.stderr.contains("non-finite radiance inf"), "{r}");
    }
}
