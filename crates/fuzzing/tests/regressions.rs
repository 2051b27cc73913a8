//! Every reproducer the fuzzers found (`fuzz/regressions/<target>/`), every seed
//! (`fuzz/corpus/<target>/`), and the inputs every target shares, kept where they already are
//! (the committed fixtures, `fixtures/`, and the shared hostile files, `../shared/data/hostile/`),
//! replayed through each harness on stable Rust, under the counting allocator: no input may panic
//! or allocate beyond `fuzzing::check_memory`'s bound. Then the
//! same bound on the largest legitimate inputs: the real maps in `../shared/data/env` and a MERL
//! table of full size. A run without `../shared` that allows it replays the rest
//! ([`shared_data::shared_or_skip`]).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once};

use fuzzing::CountingAllocator;

/// Finds `../shared`, or skips a test's use of it where the run allows.
#[path = "../../../tests/support/shared_data.rs"]
mod shared_data;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator;

/// The tests of this binary run on parallel threads, and the allocator counts every thread: a
/// test holds this from its first allocation to its last, so that no other test's inputs (a MERL
/// table of full size is 35 MB) land in its measurements.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Proof that the calling test holds [`ONE_AT_A_TIME`]; [`run`] measures only under it.
type Alone = MutexGuard<'static, ()>;

fn alone() -> Alone {
    ONE_AT_A_TIME.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The workspace root: file names are shown relative to it (`fuzz/regressions/asset/...`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().expect("the workspace root")
}

fn shown(path: &Path) -> String {
    let root = root();
    path.strip_prefix(&root).unwrap_or(path).display().to_string()
}

/// The files of a folder of inputs and of its subfolders, sorted (`README.md` files are not
/// inputs); a missing or empty folder fails with what it should hold.
fn inputs(dir: &Path, what: &str) -> Vec<PathBuf> {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}: expected {what} there", shown(dir)));
    let mut files = Vec::new();
    for path in entries.map(|entry| entry.expect("listing a folder of inputs").path()) {
        if path.is_dir() {
            files.extend(inputs(&path, what));
        } else if path.file_name().is_some_and(|n| n != "README.md") {
            files.push(path);
        }
    }
    files.sort();
    assert!(!files.is_empty(), "{} is empty: expected {what} there", shown(dir));
    files
}

/// The inputs every target reads besides its own, as seeds in `make fuzz` (`FUZZ_SHARED_SEEDS`)
/// and here: the committed fixtures (valid and damaged files of every format) and the shared
/// hostile files in `../shared/data/hostile` (reproducers found before fuzzing was in the
/// repository). A harness skips or refuses another format's bytes.
fn shared_inputs() -> Vec<PathBuf> {
    let mut files = inputs(&root().join("fixtures"), "the committed fixtures");
    if let Some(shared) = shared_data::shared_or_skip(&["data/hostile"]) {
        files.extend(inputs(&shared.join("data/hostile"), "the shared hostile inputs"));
    }
    files
}

/// Runs `harness` on `bytes` under the allocator: `Err` when it panics or holds more than the
/// bound allows, with the peak either way.
fn run(_alone: &Alone, harness: fuzzing::Harness, bytes: &[u8]) -> (Result<(), String>, usize) {
    // The default hook symbolizes a backtrace (with RUST_BACKTRACE set) on the first panic, tens
    // of megabytes that are not the reader's; print the message only, as the fuzz targets do.
    static QUIET_PANICS: Once = Once::new();
    QUIET_PANICS.call_once(|| std::panic::set_hook(Box::new(|info| eprintln!("{info}"))));
    let (outcome, peak) = fuzzing::measure(|| catch_unwind(AssertUnwindSafe(|| harness(bytes))));
    let outcome = match outcome {
        Ok(()) => fuzzing::check_memory(bytes.len(), peak),
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("(not a string)");
            Err(format!("panicked: {message}"))
        }
    };
    (outcome, peak)
}

/// Replays every file of `regressions/<target>/` and `corpus/<target>/`, then fails listing
/// every input that misbehaved.
fn replay(target: &str) {
    let alone = alone();
    let harness = fuzzing::HARNESSES.iter().find(|(name, _)| *name == target).expect("a harness of that name").1;
    let dir = root().join("fuzz");
    // A target's own folders exist once it has inputs of its own.
    let mut files = Vec::new();
    for own in [dir.join("regressions").join(target), dir.join("corpus").join(target)] {
        if own.exists() {
            files.extend(inputs(&own, "the inputs of this target"));
        }
    }
    files.extend(shared_inputs());
    let mut failures = Vec::new();
    let mut largest = (0, String::new());
    for file in &files {
        let bytes = std::fs::read(file).unwrap_or_else(|e| panic!("reading {}: {e}", shown(file)));
        let (outcome, peak) = run(&alone, harness, &bytes);
        if let Err(problem) = outcome {
            failures.push(format!("{}: {problem}", shown(file)));
        }
        if peak > largest.0 {
            largest = (peak, shown(file));
        }
    }
    eprintln!("{target}: {} inputs replayed, peak {} bytes ({})", files.len(), largest.0, largest.1);
    assert!(
        failures.is_empty(),
        "{target}: {} of {} inputs failed:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

#[test]
fn merl() {
    replay("merl");
}

#[test]
fn asset() {
    replay("asset");
}

#[test]
fn envmap_exr() {
    replay("envmap_exr");
}

#[test]
fn envmap_hdr() {
    replay("envmap_hdr");
}

#[test]
fn manifest() {
    replay("manifest");
}

#[test]
fn obj() {
    replay("obj");
}

/// The largest inputs a reader accepts keep the bound too: the real maps (at the harnesses'
/// limits, the size they are) and a MERL table of full size (no fuzzer input is that large).
#[test]
fn legitimate_inputs_keep_the_bound() {
    let alone = alone();
    let maps = shared_data::shared_or_skip(&["data/env"]).map_or_else(Vec::new, |shared| real_maps(&shared));
    let mut failures = Vec::new();
    for path in &maps {
        let bytes = std::fs::read(path).expect("reading a shared map");
        let harness = if bytes.starts_with(b"#?") { fuzzing::envmap_hdr } else { fuzzing::envmap_exr };
        let (outcome, peak) = run(&alone, harness, &bytes);
        eprintln!("{}: {} bytes, peak {peak} bytes", shown(path), bytes.len());
        if let Err(problem) = outcome {
            failures.push(format!("{}: {problem}", shown(path)));
        }
    }

    for dims in [merl::Dims::MERL, merl::Dims::MERL_FULL_PHI] {
        let bytes = merl::MerlTable::from_raw(dims, vec![0.5; 3 * dims.cells()]).expect("a valid table").to_bytes();
        let (outcome, peak) = run(&alone, fuzzing::merl, &bytes);
        eprintln!(
            "merl table {} x {} x {}: {} bytes, peak {peak} bytes",
            dims.n_theta_h,
            dims.n_theta_d,
            dims.n_phi_d,
            bytes.len()
        );
        if let Err(problem) = outcome {
            failures.push(format!("a merl table of {} bytes: {problem}", bytes.len()));
        }
    }
    for (name, bytes) in full_size_atlases() {
        let payload = asset::decode(&bytes).expect("a valid asset").payload;
        assert!(bake::stage::bandwidth_atlas::from_payload(payload).is_ok(), "{name}: the tools read it back");
        let (outcome, peak) = run(&alone, fuzzing::asset, &bytes);
        eprintln!("{name}: {} bytes, peak {peak} bytes", bytes.len());
        if let Err(problem) = outcome {
            failures.push(format!("{name}: {problem}"));
        }
    }
    assert!(failures.is_empty(), "legitimate inputs above the bound:\n{}", failures.join("\n"));
}

/// The real maps of `../shared/data/env` and its `decoder/` folder, sorted.
fn real_maps(shared: &Path) -> Vec<PathBuf> {
    let env = shared.join("data/env");
    let mut maps: Vec<PathBuf> = [env.clone(), env.join("decoder")]
        .iter()
        .flat_map(|dir| std::fs::read_dir(dir).expect("listing the shared maps"))
        .map(|entry| entry.expect("listing the shared maps").path())
        .filter(|path| path.extension().is_some_and(|e| e == "exr" || e == "hdr"))
        .collect();
    maps.sort();
    maps
}

/// A bandwidth atlas of the size `brdf-bandwidth` writes (64 x 64 lobes of 16 x 16 texels) as
/// both kinds: whole, and as rows that the reader expands to the whole (64 times its payload).
fn full_size_atlases() -> [(&'static str, Vec<u8>); 2] {
    let golden = |name: &str| {
        let bytes = std::fs::read(root().join("fixtures/assets").join(name)).expect("reading a golden asset");
        asset::decode(&bytes).expect("a golden asset decodes")
    };
    let (lobes, tile) = (64u32, 16u32);
    let mut atlas = golden("golden-v1-bandwidth-atlas.asset");
    let asset::Payload::BandwidthAtlas(a) = &mut atlas.payload else { panic!("not an atlas") };
    (a.lobes_x, a.lobes_y, a.tile) = (lobes, lobes, tile);
    a.data = vec![0.5; (lobes * lobes * tile * tile) as usize];
    let mut rows = golden("golden-v1-bandwidth-rows.asset");
    let asset::Payload::BandwidthRows(r) = &mut rows.payload else { panic!("not a rows atlas") };
    (r.lobes_x, r.lobes_y, r.tile) = (lobes, lobes, tile);
    r.data = vec![0.5; (lobes * tile * tile) as usize];
    [("a 64 x 64 bandwidth atlas", asset::encode(&atlas)), ("its 64 bandwidth rows", asset::encode(&rows))]
}

/// The asset harness's fix-up repairs exactly the header: a golden asset with its lengths and
/// checksum damaged decodes again to the same asset; a consistent file needs no fix-up.
#[test]
fn fix_up_repairs_the_header_only() {
    let _alone = alone();
    let golden = root().join("fixtures/assets/golden-v1-bandwidth-pca.asset");
    let bytes = std::fs::read(&golden).expect("reading a golden asset");
    assert_eq!(fuzzing::fix_up_asset(&bytes), None, "a golden asset is already consistent");
    let expected = asset::decode(&bytes).expect("the golden asset decodes");

    let mut damaged = bytes.clone();
    damaged[0] = b'X';
    damaged[8] = 9;
    damaged[24..32].copy_from_slice(&u64::MAX.to_le_bytes());
    damaged[40] ^= 0xff;
    assert!(asset::decode(&damaged).is_err());
    let fixed = fuzzing::fix_up_asset(&damaged).expect("a damaged header is fixed");
    assert_eq!(fixed, bytes);
    assert_eq!(asset::decode(&fixed).expect("the fixed asset decodes"), expected);
    assert_eq!(fuzzing::fix_up_asset(&bytes[..10]), None, "shorter than a header");
}

#[test]
fn the_bound_is_floor_plus_multiple() {
    let _alone = alone();
    use fuzzing::{FLOOR, MULTIPLE, check_memory};
    assert!(check_memory(0, FLOOR).is_ok());
    assert!(check_memory(1000, FLOOR + MULTIPLE * 1000).is_ok());
    let err = check_memory(1000, FLOOR + MULTIPLE * 1000 + 1).unwrap_err();
    assert!(err.contains("above the bound"), "{err}");
}
