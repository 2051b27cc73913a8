//! The bake manifest: the JSON Schema, the committed example and the `BakeManifest` type agree,
//! and the schema rejects what it should.

use std::path::{Path, PathBuf};

use asset::{AssetKind, BakeManifest, Error, SourceFile, Stage, StageOutput, Tool};
use serde_json::{Value, json};

fn schema_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data-schema")
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("parsing {}: {e}", path.display()))
}

fn validator() -> jsonschema::Validator {
    let schema = read_json(&schema_dir().join("bake-manifest.schema.json"));
    jsonschema::draft202012::new(&schema).unwrap_or_else(|e| panic!("the schema itself is invalid: {e}"))
}

fn example() -> Value {
    read_json(&schema_dir().join("examples/bake-manifest.json"))
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
    let mut manifest = BakeManifest::new(
        source("blue-acrylic", b"material"),
        environment.then(|| source("studio-é", b"environment")),
        Tool { name: "bake".into(), version: "0.1.0".into() },
    );
    let mut parameters = serde_json::Map::new();
    parameters.insert("n_samples".into(), json!(1024));
    parameters.insert("interp".into(), json!("nearest"));
    manifest.stages.push(Stage {
        name: "material-info".into(),
        parameters,
        outputs: vec![StageOutput {
            path: "blue-acrylic/material-info.asset".into(),
            kind: AssetKind::MaterialInfo,
            format_version: asset::FORMAT_VERSION,
            size_bytes: 1234,
            sha256: asset::hex(&asset::sha256(b"output")),
        }],
    });
    manifest.stages.push(Stage { name: "empty".into(), parameters: serde_json::Map::new(), outputs: vec![] });
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

/// The example's output is the golden file, so its size and hash are real and checkable.
#[test]
fn the_example_describes_the_golden_file() {
    let manifest: BakeManifest = serde_json::from_value(example()).unwrap();
    let output = &manifest.stages[0].outputs[0];
    let described = StageOutput::of_file(&schema_dir().join("examples"), &output.path, output.kind).unwrap();
    assert_eq!(&described, output);
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
    Broken { what: "version as a string", edit: |m| m["manifest_version"] = json!("1"), type_refuses: true },
    Broken { what: "version 2", edit: |m| m["manifest_version"] = json!(2), type_refuses: false },
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
        type_refuses: false,
    },
    Broken {
        what: "parameters not an object",
        edit: |m| m["stages"][0]["parameters"] = json!([1, 2]),
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

#[test]
fn an_unknown_manifest_version_is_named() {
    let mut manifest = example();
    manifest["manifest_version"] = json!(2);
    match BakeManifest::from_json(&manifest.to_string()) {
        Err(e @ Error::UnsupportedVersion { .. }) => {
            assert_eq!(e.to_string(), "unsupported manifest version 2: this build reads version 1")
        }
        other => panic!("expected an unsupported version, got {other:?}"),
    }
}
