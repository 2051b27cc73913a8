//! One dialect for every tool: with `--json`, stdout is exactly
//! one JSON object, which lists the files the tool wrote (and those files exist, with the size
//! and hash it gives); the human report goes to stderr. With an error, stdout stays empty and
//! stderr is one `error: ...` line.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde_json::Value;
use sha2::{Digest, Sha256};

use crate::support::{Run, reference_bake, run, shared_or_skip, temp_dir, tool};

/// The files a folder holds, recursively, as full paths.
fn files_under(dir: &Path) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    let Ok(entries) = std::fs::read_dir(dir) else { return out };
    for entry in entries {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.insert(path);
        }
    }
    out
}

/// Checks one `--json` run: exit 0, one object on stdout, and its `files` are exactly `written`
/// (each entry a path, or an object with `path` and, where given, `size_bytes` and `sha256` that
/// match the file).
fn check(r: &Run, written: &BTreeSet<PathBuf>) -> serde_json::Map<String, Value> {
    assert_eq!(r.code, Some(0), "{r}");
    let json = r.json_object();
    let listed: Vec<&Value> = match json.get("files") {
        Some(Value::Array(files)) => files.iter().collect(),
        None => Vec::new(),
        Some(other) => panic!("files is not an array: {other}\n{r}"),
    };
    let mut paths = BTreeSet::new();
    for file in listed {
        let path = PathBuf::from(match file {
            Value::String(path) => path.as_str(),
            Value::Object(o) => o["path"].as_str().unwrap_or_else(|| panic!("a file without a path: {file}\n{r}")),
            _ => panic!("a file entry that is neither a path nor an object: {file}\n{r}"),
        });
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("listed file {}: {e}\n{r}", path.display()));
        if let Some(size) = file.get("size_bytes") {
            assert_eq!(size.as_u64(), Some(bytes.len() as u64), "size of {}\n{r}", path.display());
        }
        if let Some(sha256) = file.get("sha256") {
            assert_eq!(
                sha256.as_str(),
                Some(format!("{:x}", Sha256::digest(&bytes)).as_str()),
                "{}\n{r}",
                path.display()
            );
        }
        assert!(paths.insert(path.clone()), "{} is listed twice\n{r}", path.display());
    }
    assert_eq!(&paths, written, "the files listed are the files written\n{r}");
    json
}

fn tool_run(name: &str, args: &[&std::ffi::OsStr]) -> Run {
    let mut cmd = tool(name);
    cmd.args(args);
    run(cmd, "")
}

#[test]
fn every_tool_prints_one_json_object_listing_the_files_it_wrote() {
    let Some(shared) = shared_or_skip(&["data/env"]) else { return };
    let tmp = temp_dir();
    let dir = |name: &str| tmp.path().join(name);
    let os = |p: &Path| p.as_os_str().to_owned();

    // merl-synth: the table (outputs go into folders that exist).
    for folder in ["synth", "info"] {
        std::fs::create_dir(dir(folder)).unwrap();
    }
    let table = dir("synth").join("lambert.binary");
    let r = tool_run("merl-synth", &["lambertian".as_ref(), "--json".as_ref(), "--out".as_ref(), table.as_os_str()]);
    let json = check(&r, &files_under(&dir("synth")));
    assert_eq!(json["kind"], "lambertian", "{r}");
    assert!(r.stderr.contains("wrote"), "{r}");

    // merl-info: the summary, and the asset it wrote.
    let info = dir("info").join("lambert.asset");
    let r = tool_run("merl-info", &[table.as_os_str(), "--json".as_ref(), "--asset".as_ref(), info.as_os_str()]);
    let json = check(&r, &files_under(&dir("info")));
    assert_eq!(json["files"][0]["kind"], "material-info", "{r}");
    assert!(r.stderr.contains("albedo (trilinear lookup)"), "the report goes to stderr\n{r}");

    // asset-info writes nothing.
    let before = files_under(tmp.path());
    check(&tool_run("asset-info", &[info.as_os_str(), "--json".as_ref()]), &BTreeSet::new());
    assert_eq!(files_under(tmp.path()), before);

    // The stage tools, on small settings.
    let small: [(&str, Vec<std::ffi::OsString>); 6] = [
        (
            "merl-importance",
            vec![
                os(&table),
                "--theta-o".into(),
                "4".into(),
                "--vectors".into(),
                "1".into(),
                "--samples".into(),
                "16".into(),
            ],
        ),
        (
            "brdf-bandwidth",
            vec![os(&table), "--lobes".into(), "4".into(), "--analysis-size".into(), "128".into(), "--quiet".into()],
        ),
        (
            "bandwidth-pca",
            vec![os(&dir("brdf-bandwidth").join("bandwidth-atlas.asset")), "--components".into(), "2".into()],
        ),
        ("brdf-wavelet", vec![os(&table), "--side".into(), "8".into(), "--ratio".into(), "16".into()]),
        (
            "envmap-bandwidth",
            vec![os(&shared.join("data/env/decoder/imagers_rgbr4x4.hdr")), "--spatial".into(), "--pad".into()],
        ),
        (
            "envmap-prefilter",
            vec![
                os(&shared.join("data/env/potsdamer_platz_1k.hdr")),
                "--size".into(),
                "16x8".into(),
                "--exponents".into(),
                "1,64".into(),
                "--quiet".into(),
            ],
        ),
    ];
    for (name, args) in small {
        let out = dir(name);
        let mut cmd = tool(name);
        cmd.args(&args).arg("--out-dir").arg(&out).arg("--json");
        let r = run(cmd, "");
        let json = check(&r, &files_under(&out));
        assert!(!json["files"].as_array().unwrap().is_empty(), "{name} wrote nothing\n{r}");
        assert!(json.contains_key("figures") && json.contains_key("parameters"), "{r}");
    }

    // brdf-bake: the shared bake ran with --json.
    let bake = reference_bake();
    check(&bake.run, &files_under(&bake.dir));
}

#[test]
fn errors_leave_stdout_empty_with_json() {
    let tmp = temp_dir();
    let missing = tmp.path().join("missing.binary");
    let out = tmp.path().join("out");
    let cases: [(&str, Vec<&std::ffi::OsStr>); 8] = [
        ("merl-info", vec![]),
        ("asset-info", vec![]),
        ("merl-importance", vec!["--out-dir".as_ref(), out.as_os_str()]),
        ("brdf-bandwidth", vec!["--out-dir".as_ref(), out.as_os_str()]),
        ("bandwidth-pca", vec!["--out-dir".as_ref(), out.as_os_str(), "--components".as_ref(), "1".as_ref()]),
        ("envmap-bandwidth", vec!["--out-dir".as_ref(), out.as_os_str()]),
        ("envmap-prefilter", vec!["--out-dir".as_ref(), out.as_os_str()]),
        ("brdf-bake", vec!["--out-dir".as_ref(), out.as_os_str()]),
    ];
    for (name, args) in cases {
        let mut cmd = tool(name);
        cmd.arg(&missing).args(args).arg("--json");
        let r = run(cmd, "").expect_code(2).expect_error(&missing, "no such file");
        assert!(r.stdout.is_empty(), "{r}");
    }
    // merl-synth refuses to run without --out: a 35 MB table never lands in the current folder unasked.
    let r = tool_run("merl-synth", &["lambertian".as_ref(), "--json".as_ref()]).expect_code(2);
    assert!(r.stdout.is_empty() && r.stderr.contains("--out <FILE>"), "{r}");
    assert!(!out.exists());
}
