//! The bake manifest: the JSON Schemas (versions 1 and 2), the committed examples and the
//! `BakeManifest` type agree, and the schemas reject what they should.

use std::path::{Path, PathBuf};

use asset::{AssetKind, BakeManifest, Error, FileFormat, SourceFile, Stage, StageOutput, Tool};
use serde_json::{Value, json};

fn schema_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data-schema")
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("parsing {}: {e}", path.display()))
}

fn validator_of(file: &str) -> jsonschema::Validator {
    let schema = read_json(&schema_dir().join(file));
    jsonschema::draft202012::new(&schema).unwrap_or_else(|e| panic!("{file} itself is invalid: {e}"))
}

fn validator() -> jsonschema::Validator {
    validator_of("bake-manifest.schema.json")
}

fn example() -> Value {
    read_json(&schema_dir().join("examples/bake-manifest.json"))
}

fn example_v1() -> Value {
    read_json(&schema_dir().join("examples/bake-manifest-v1.json"))
}

/// Panics with every validation error, so a failure says which field is wrong.
fn assert_valid(validator: &jsonschema::Validator, manifest: &Value) {
    let errors: Vec<String> =
        validator.iter_errors(manifest).map(|e| format!("{} at {}", e, e.instance_path())).collect();
    assert!(errors.is_empty(), "{manifest:#}\nfails the schema:\n{}", errors.join("\n"));
}

fn sample_manifest(environment: bool) -> BakeManifest {
    let source = |name: &str, bytes: &[u8]| SourceFile {
        name: name.into(),
        source_path: format!("inputs/{name}"),
        source_sha256: asset::hex(&asset::sha256(bytes)),
    };
    let mut parameters = serde_json::Map::new();
    parameters.insert("pca_max_error".into(), json!(0.02));
    let mut manifest = BakeManifest::new(
        source("blue-acrylic", b"material"),
        environment.then(|| source("studio-é", b"environment")),
        Tool { name: "bake".into(), version: "0.1.0".into() },
        parameters.clone(),
    );
    let golden = std::fs::read(schema_dir().join("examples/material-info.asset")).unwrap();
    let mut figures = serde_json::Map::new();
    figures.insert("albedo".into(), json!([0.5, 0.5, 0.5]));
    manifest.stages.push(Stage {
        name: "material-info".into(),
        parameters,
        figures,
        outputs: vec![
            StageOutput::of_bytes("blue-acrylic/material-info.asset", FileFormat::Asset, "material-info", &golden)
                .unwrap(),
            StageOutput::of_bytes("blue-acrylic/lobes.png", FileFormat::Png, "lobe-picture", b"png bytes").unwrap(),
        ],
    });
    manifest.stages.push(Stage {
        name: "empty".into(),
        parameters: serde_json::Map::new(),
        figures: serde_json::Map::new(),
        outputs: vec![],
    });
    manifest
}

#[test]
fn the_example_validates_against_the_schema() {
    assert_valid(&validator(), &example());
}

#[test]
fn the_example_parses_into_the_type_and_back_unchanged() {
    let text = std::fs::read_to_string(schema_dir().join("examples/bake-manifest.json")).unwrap();
    let manifest = BakeManifest::from_json(&text).unwrap();
    assert_eq!(serde_json::to_value(&manifest).unwrap(), example());
}

/// The examples' outputs are real files beside them, so their sizes and hashes are checkable.
#[test]
fn the_examples_describe_real_files() {
    for (name, value) in [("bake-manifest.json", example()), ("bake-manifest-v1.json", example_v1())] {
        let manifest = BakeManifest::from_json(&value.to_string()).unwrap();
        assert!(!manifest.stages[0].outputs.is_empty(), "{name}");
        for output in manifest.outputs() {
            let dir = schema_dir().join("examples");
            let folder = fsguard::Folder::open(&dir).unwrap();
            assert!(output.matches_file(&folder).unwrap(), "{name}: {} is not the file described", output.path);
            assert_eq!(output.read(&folder).unwrap(), std::fs::read(dir.join(&output.path)).unwrap(), "{name}");
            let bytes = std::fs::read(dir.join(&output.path)).unwrap();
            let described = StageOutput::of_bytes(&output.path, output.format, &output.role, &bytes).unwrap();
            assert_eq!(&described, output, "{name}");
        }
    }
}

/// Version 1 still reads: it validates against its own schema and converts to outputs that are
/// assets, with the kind's name as the role.
#[test]
fn version_1_reads_and_converts() {
    let v1 = example_v1();
    assert_valid(&validator_of("bake-manifest-v1.schema.json"), &v1);
    assert!(!validator().is_valid(&v1), "version 2's schema must not accept version 1");
    let manifest = BakeManifest::from_json(&v1.to_string()).unwrap();
    assert_eq!(manifest.manifest_version, 1);
    assert!(manifest.parameters.is_empty());
    let output = &manifest.stages[0].outputs[0];
    assert_eq!(output.format, FileFormat::Asset);
    assert_eq!(output.kind, Some(AssetKind::MaterialInfo));
    assert_eq!(output.role, "material-info");
    assert_eq!(output.sha256, v1["stages"][0]["outputs"][0]["sha256"]);
}

#[test]
fn serialized_manifests_validate_against_the_schema() {
    let validator = validator();
    for environment in [false, true] {
        let manifest = sample_manifest(environment);
        let text = manifest.to_json();
        assert_valid(&validator, &serde_json::from_str(&text).unwrap());
        assert_eq!(BakeManifest::from_json(&text).unwrap(), manifest);
    }
}

#[test]
fn the_schema_lists_every_asset_kind() {
    let schema = read_json(&schema_dir().join("bake-manifest.schema.json"));
    let listed = &schema["$defs"]["output"]["properties"]["kind"]["enum"];
    let known: Vec<Value> = AssetKind::ALL.iter().map(|k| json!(k.name())).collect();
    assert_eq!(listed, &json!(known));
    for kind in AssetKind::ALL {
        assert_eq!(serde_json::to_value(kind).unwrap(), json!(kind.name()));
    }
    let formats = &schema["$defs"]["output"]["properties"]["format"]["enum"];
    let known: Vec<Value> = FileFormat::ALL.iter().map(|f| json!(f.name())).collect();
    assert_eq!(formats, &json!(known));
    for format in FileFormat::ALL {
        assert_eq!(serde_json::to_value(format).unwrap(), json!(format.name()));
    }
}

/// One broken manifest: what was changed, and whether the `BakeManifest` type (not only the
/// schema) must refuse it too. The type does not check hash patterns or the version's value.
struct Broken {
    what: &'static str,
    edit: fn(&mut Value),
    type_refuses: bool,
}

const BROKEN: &[Broken] = &[
    Broken { what: "missing tool", edit: |m| drop(m.as_object_mut().unwrap().remove("tool")), type_refuses: true },
    Broken {
        what: "missing output hash",
        edit: |m| drop(m["stages"][0]["outputs"][0].as_object_mut().unwrap().remove("sha256")),
        type_refuses: true,
    },
    Broken { what: "hash too short", edit: |m| m["material"]["source_sha256"] = json!("abc123"), type_refuses: false },
    Broken {
        what: "hash not hexadecimal",
        edit: |m| m["stages"][0]["outputs"][0]["sha256"] = json!("g".repeat(64)),
        type_refuses: false,
    },
    Broken {
        what: "hash upper case",
        edit: |m| m["material"]["source_sha256"] = json!("AB".repeat(32)),
        type_refuses: false,
    },
    Broken { what: "version as a string", edit: |m| m["manifest_version"] = json!("2"), type_refuses: true },
    Broken { what: "version 3", edit: |m| m["manifest_version"] = json!(3), type_refuses: true },
    Broken { what: "extra top-level property", edit: |m| m["comment"] = json!("hi"), type_refuses: true },
    Broken {
        what: "extra output property",
        edit: |m| m["stages"][0]["outputs"][0]["mtime"] = json!(0),
        type_refuses: true,
    },
    Broken {
        what: "unknown kind",
        edit: |m| m["stages"][0]["outputs"][0]["kind"] = json!("brdf-table"),
        type_refuses: true,
    },
    Broken {
        what: "negative size",
        edit: |m| m["stages"][0]["outputs"][0]["size_bytes"] = json!(-1),
        type_refuses: true,
    },
    Broken {
        what: "absolute output path",
        edit: |m| m["stages"][0]["outputs"][0]["path"] = json!("/tmp/x.asset"),
        type_refuses: true,
    },
    Broken {
        what: "output path leaving the folder",
        edit: |m| m["stages"][0]["outputs"][0]["path"] = json!("a/../../x.asset"),
        type_refuses: true,
    },
    Broken {
        what: "asset without its kind",
        edit: |m| drop(m["stages"][0]["outputs"][0].as_object_mut().unwrap().remove("kind")),
        type_refuses: true,
    },
    Broken {
        what: "picture with an asset kind",
        edit: |m| m["stages"][0]["outputs"][1]["kind"] = json!("material-info"),
        type_refuses: true,
    },
    Broken {
        what: "unknown format",
        edit: |m| m["stages"][0]["outputs"][1]["format"] = json!("jpeg"),
        type_refuses: true,
    },
    Broken {
        what: "role with spaces",
        edit: |m| m["stages"][0]["outputs"][1]["role"] = json!("lobe picture"),
        type_refuses: false,
    },
    Broken {
        what: "missing figures",
        edit: |m| drop(m["stages"][0].as_object_mut().unwrap().remove("figures")),
        type_refuses: true,
    },
    Broken {
        what: "missing bake parameters",
        edit: |m| drop(m.as_object_mut().unwrap().remove("parameters")),
        type_refuses: true,
    },
    Broken {
        what: "parameters not an object",
        edit: |m| m["stages"][0]["parameters"] = json!([1, 2]),
        type_refuses: true,
    },
    Broken {
        what: "output path with an empty component",
        edit: |m| m["stages"][0]["outputs"][0]["path"] = json!("a//x.asset"),
        type_refuses: true,
    },
    Broken {
        what: "output path with a backslash",
        edit: |m| m["stages"][0]["outputs"][0]["path"] = json!("a\\..\\x.asset"),
        type_refuses: true,
    },
    Broken {
        what: "output path of a dot component",
        edit: |m| m["stages"][0]["outputs"][0]["path"] = json!("./x.asset"),
        type_refuses: true,
    },
    Broken { what: "environment null", edit: |m| m["environment"] = Value::Null, type_refuses: false },
];

#[test]
fn broken_manifests_are_rejected() {
    let validator = validator();
    for broken in BROKEN {
        let mut manifest = example();
        (broken.edit)(&mut manifest);
        assert_ne!(manifest, example(), "{}: the edit changed nothing", broken.what);
        assert!(!validator.is_valid(&manifest), "{}: the schema accepts\n{manifest:#}", broken.what);
        if broken.type_refuses {
            let parsed = BakeManifest::from_json(&manifest.to_string());
            assert!(parsed.is_err(), "{}: BakeManifest accepts it", broken.what);
        }
    }
}

/// Version 1 gets version 2's path rules: a file outside the folder, by an absolute path or by
/// `..`, is refused, whichever version the manifest says it is (`brdf-bake` once deleted such
/// files and `brdf-preview` read them).
#[test]
fn version_1_paths_stay_inside_the_folder() {
    for path in ["/etc/passwd", "../outside/victim.txt", "a/../../x", "a//b", "\\server\\x"] {
        let mut v1 = example_v1();
        v1["stages"][0]["outputs"][0]["path"] = json!(path);
        assert!(!validator_of("bake-manifest-v1.schema.json").is_valid(&v1), "{path}: the v1 schema accepts it");
        let e = BakeManifest::from_json(&v1.to_string()).unwrap_err().to_string();
        assert!(e.contains("expected a relative path inside the folder"), "{path}: {e}");
    }
}

/// Reading an output checks, in order, that it is a regular file reached without a link, its size
/// from its metadata, then its hash; `matches_file` says `false` for each instead.
#[cfg(unix)]
#[test]
fn outputs_are_read_only_when_they_are_the_files_described() {
    let dir = tempfile::tempdir().unwrap();
    let outside = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.png"), b"picture").unwrap();
    std::fs::write(outside.path().join("a.png"), b"picture").unwrap();
    let output = StageOutput::of_bytes("a.png", FileFormat::Png, "picture", b"picture").unwrap();
    let folder = fsguard::Folder::open(dir.path()).unwrap();
    assert_eq!(output.read(&folder).unwrap(), b"picture");
    assert!(output.matches_file(&folder).unwrap());

    let other = StageOutput::of_bytes("a.png", FileFormat::Png, "picture", b"pictures").unwrap();
    let e = other.read(&folder).unwrap_err().to_string();
    assert_eq!(e, "not the file the manifest describes (7 bytes, the manifest says 8): bake again");
    assert!(!other.matches_file(&folder).unwrap());
    let other = StageOutput::of_bytes("a.png", FileFormat::Png, "picture", b"Picture").unwrap();
    let e = other.read(&folder).unwrap_err().to_string();
    assert_eq!(e, "not the file the manifest describes (its sha256 differs): bake again");

    std::fs::remove_file(dir.path().join("a.png")).unwrap();
    std::os::unix::fs::symlink(outside.path().join("a.png"), dir.path().join("a.png")).unwrap();
    assert!(output.read(&folder).unwrap_err().to_string().contains("symbolic link"));
    assert!(!output.matches_file(&folder).unwrap(), "a link is not the file, even to the same bytes");
    std::fs::remove_file(dir.path().join("a.png")).unwrap();
    assert!(std::process::Command::new("mkfifo").arg(dir.path().join("a.png")).status().unwrap().success());
    assert!(output.read(&folder).unwrap_err().to_string().contains("fifo"));
    assert!(!output.matches_file(&folder).unwrap());
    std::fs::remove_file(dir.path().join("a.png")).unwrap();
    assert_eq!(output.read(&folder).unwrap_err().kind(), std::io::ErrorKind::NotFound);
    assert!(!output.matches_file(&folder).unwrap());
}

#[test]
fn manifests_over_the_limit_or_not_utf8_are_refused_before_parsing() {
    let e = BakeManifest::from_bytes(&vec![b' '; asset::MANIFEST_LIMIT as usize + 1]).unwrap_err().to_string();
    assert!(e.contains("exceeds the limit"), "{e}");
    let e = BakeManifest::from_bytes(b"{\xff}").unwrap_err().to_string();
    assert!(e.contains("not utf-8"), "{e}");
}

#[test]
fn an_unknown_manifest_version_is_named() {
    let mut manifest = example();
    manifest["manifest_version"] = json!(7);
    match BakeManifest::from_json(&manifest.to_string()) {
        Err(e @ Error::UnsupportedVersion { .. }) => {
            assert_eq!(e.to_string(), "unsupported manifest version 7: this build reads versions 1, 2")
        }
        other => panic!("expected an unsupported version, got {other:?}"),
    }
}

/// A path listed twice, in one stage or in two, of either version, is refused naming the path
/// (were it accepted, readers would hash and draw every copy of a file listed 1000 times).
#[test]
fn a_path_listed_twice_is_refused() {
    let mut in_one_stage = example();
    let output = in_one_stage["stages"][0]["outputs"][1].clone();
    in_one_stage["stages"][0]["outputs"].as_array_mut().unwrap().push(output.clone());
    let mut in_two_stages = example();
    let mut stage = in_two_stages["stages"][0].clone();
    stage["name"] = json!("other");
    stage["outputs"] = json!([output]);
    in_two_stages["stages"].as_array_mut().unwrap().push(stage);
    let mut v1 = example_v1();
    let output = v1["stages"][0]["outputs"][0].clone();
    v1["stages"][0]["outputs"].as_array_mut().unwrap().push(output);
    for (manifest, path) in [(in_one_stage, "picture.png"), (in_two_stages, "picture.png"), (v1, "material-info.asset")]
    {
        let e = BakeManifest::from_json(&manifest.to_string()).unwrap_err().to_string();
        assert_eq!(e, format!("invalid bake manifest: output \"{path}\" is listed twice"));
    }
    assert!(BakeManifest::from_json(&example().to_string()).is_ok());
}

/// A key given twice is named, whichever comes first (were the last one read, a second
/// `manifest_version` of 1 after a 2 would be reported as "unknown field `parameters`").
#[test]
fn a_key_given_twice_is_named() {
    let text = example().to_string();
    for (first, second) in [(2, 1), (1, 2), (2, 2)] {
        let twice = text.replacen(
            "\"manifest_version\":2",
            &format!("\"manifest_version\":{first},\"manifest_version\":{second}"),
            1,
        );
        assert_ne!(twice, text);
        let e = BakeManifest::from_json(&twice).unwrap_err().to_string();
        assert!(e.starts_with("invalid bake manifest: duplicate field `manifest_version`"), "{first}, {second}: {e}");
    }
    let twice = text.replacen("\"tool\":{", "\"tool\":{\"name\":\"x\",", 1);
    let e = BakeManifest::from_json(&twice).unwrap_err().to_string();
    assert!(e.starts_with("invalid bake manifest: duplicate field `name`"), "{e}");
}
