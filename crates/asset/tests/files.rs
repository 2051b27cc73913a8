//! The output helpers: atomic writes, SHA-256, hexadecimal.

use asset::{hex, sha256, sha256_file, sha256_from_hex, write_atomic};

/// FIPS 180-2, appendix B.1.
const ABC_SHA256: &str = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";

fn entries(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

#[test]
fn sha256_matches_the_standard_test_vector() {
    assert_eq!(hex(&sha256(b"abc")), ABC_SHA256);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("abc");
    std::fs::write(&path, b"abc").unwrap();
    assert_eq!(hex(&sha256_file(&path).unwrap()), ABC_SHA256);
}

#[test]
fn sha256_file_streams_files_larger_than_its_buffer() {
    let bytes: Vec<u8> = (0..1_000_003u32).map(|i| (i * 7 + i / 251) as u8).collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big");
    std::fs::write(&path, &bytes).unwrap();
    assert_eq!(sha256_file(&path).unwrap(), sha256(&bytes));
}

#[test]
fn hex_parses_back_and_rejects_what_the_schema_rejects() {
    let hash = sha256(b"abc");
    assert_eq!(sha256_from_hex(&hex(&hash)), Some(hash));
    assert_eq!(hex(&[0x00, 0x0f, 0xf0, 0xff]), "000ff0ff");
    let upper = ABC_SHA256.to_uppercase();
    let plus = format!("+{}", &ABC_SHA256[1..]);
    for bad in [&ABC_SHA256[..62], &upper, &plus, "", &format!("{ABC_SHA256}00")] {
        assert_eq!(sha256_from_hex(bad), None, "{bad}");
    }
}

#[test]
fn write_atomic_replaces_the_file_and_leaves_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bin");
    write_atomic(&path, b"first").unwrap();
    write_atomic(&path, b"second").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"second");
    assert_eq!(entries(dir.path()), ["out.bin"]);
}

/// The result must be as readable as a file written by `File::create`, not owner-only like the
/// temporary file it started as.
#[cfg(unix)]
#[test]
fn write_atomic_gives_ordinary_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let atomic = dir.path().join("atomic");
    let plain = dir.path().join("plain");
    write_atomic(&atomic, b"x").unwrap();
    std::fs::write(&plain, b"x").unwrap();
    let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&atomic), mode(&plain));
}

#[test]
fn a_failed_write_leaves_the_target_and_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    // Renaming a file over a non-empty folder fails on every platform.
    let target = dir.path().join("occupied");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("keep"), b"keep").unwrap();
    assert!(write_atomic(&target, b"new").is_err());
    assert_eq!(entries(dir.path()), ["occupied"]);
    assert_eq!(std::fs::read(target.join("keep")).unwrap(), b"keep");

    // A file where the parent folder should be: the folder cannot be made.
    std::fs::write(dir.path().join("plain"), b"plain").unwrap();
    assert!(write_atomic(&dir.path().join("plain/out.bin"), b"new").is_err());
    assert_eq!(std::fs::read(dir.path().join("plain")).unwrap(), b"plain");
}

/// An output's folder must exist: a missing one is an error naming it, and nothing is created
/// (`--out /nonexistent/dir/x.png` must not make folders from the root). A set's folder is created
/// itself, its parent never.
#[test]
fn missing_parent_folders_are_not_created() {
    let dir = tempfile::tempdir().unwrap();
    let nested = dir.path().join("a/b/out.bin");
    let e = write_atomic(&nested, b"new").unwrap_err();
    assert_eq!(e.kind(), std::io::ErrorKind::NotFound);
    assert!(e.to_string().contains(&format!("the folder {} does not exist", dir.path().join("a/b").display())), "{e}");
    assert!(entries(dir.path()).is_empty());

    let (path, e) = asset::write_set(&dir.path().join("a/b"), &[("x", b"x")]).unwrap_err();
    assert_eq!(path, dir.path().join("a/b"));
    assert!(e.to_string().contains("parent folder"), "{e}");
    assert!(entries(dir.path()).is_empty());
    asset::write_set(&dir.path().join("a"), &[("x", b"x")]).unwrap();
    assert_eq!(entries(&dir.path().join("a")), ["x"]);
}

/// A set staged and then dropped (an error before the switch: a full disk, a refused input)
/// leaves the folder as it was; committed, it replaces the old files, the index last.
#[test]
fn a_staged_set_lands_on_commit_only() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("data"), b"old data").unwrap();
    std::fs::write(dir.path().join("index"), b"old index").unwrap();
    let mut staging = asset::Staging::new(&fsguard::Folder::open(dir.path()).unwrap()).unwrap();
    staging.add("data", b"new data").unwrap();
    staging.add("index", b"new index").unwrap();
    assert_eq!(entries(dir.path()).len(), 4, "two temporaries beside the old files");
    drop(staging);
    assert_eq!(entries(dir.path()), ["data", "index"]);
    assert_eq!(std::fs::read(dir.path().join("data")).unwrap(), b"old data");

    let mut staging = asset::Staging::new(&fsguard::Folder::open(dir.path()).unwrap()).unwrap();
    staging.add("data", b"new data").unwrap();
    staging.add("index", b"new index").unwrap();
    let seen = std::cell::RefCell::new(Vec::new());
    staging
        .commit(|| {
            // Between the renames and the index: the data is new, the index not there.
            seen.borrow_mut().push(std::fs::read(dir.path().join("data")).unwrap());
            seen.borrow_mut().push(vec![u8::from(dir.path().join("index").exists())]);
            Ok(())
        })
        .unwrap();
    assert_eq!(seen.into_inner(), [b"new data".to_vec(), vec![0]]);
    assert_eq!(entries(dir.path()), ["data", "index"]);
    assert_eq!(std::fs::read(dir.path().join("index")).unwrap(), b"new index");
}

/// The previous set of a folder: `data`, `gone` (which the new set retires), `index`; the new set
/// writes `data`, `extra` and `index`.
fn previous_set(dir: &std::path::Path) -> asset::Staging {
    for (name, bytes) in [("data", "old data"), ("gone", "old gone"), ("index", "old index")] {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let mut staging = asset::Staging::new(&fsguard::Folder::open(dir).unwrap()).unwrap();
    staging.add("data", b"new data").unwrap();
    staging.add("extra", b"new extra").unwrap();
    staging.retire("gone");
    staging.add("index", b"new index").unwrap();
    staging
}

fn contents(dir: &std::path::Path) -> Vec<(String, String)> {
    entries(dir).into_iter().map(|n| (n.clone(), std::fs::read_to_string(dir.join(&n)).unwrap_or_default())).collect()
}

fn old_set() -> Vec<(String, String)> {
    [("data", "old data"), ("gone", "old gone"), ("index", "old index")].map(|(n, c)| (n.into(), c.into())).to_vec()
}

/// A name the set writes that holds a folder (or a FIFO) fails the commit before anything is
/// touched: the old set, its index included, is as it was (a switch that renamed files over the
/// old ones until it met the folder, then undid by deleting the new files, would leave a rebake 3
/// of its 21 files).
#[test]
fn a_commit_blocked_by_a_folder_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let staging = previous_set(dir.path());
    std::fs::create_dir(dir.path().join("extra")).unwrap();
    std::fs::write(dir.path().join("extra/note"), b"keep").unwrap();
    let (path, e) = staging.commit(|| Ok(())).unwrap_err();
    assert_eq!(path, dir.path().join("extra"));
    assert_eq!(
        e.to_string(),
        "refusing to replace a folder (only a regular file or a link is replaced): nothing was changed"
    );
    std::fs::remove_dir_all(dir.path().join("extra")).unwrap();
    assert_eq!(contents(dir.path()), old_set());

    #[cfg(unix)]
    {
        let staging = previous_set(dir.path());
        std::fs::remove_file(dir.path().join("gone")).unwrap();
        std::os::unix::fs::symlink("data", dir.path().join("gone")).unwrap();
        let (path, e) = staging.commit(|| Ok(())).unwrap_err();
        assert_eq!(path, dir.path().join("gone"));
        assert!(e.to_string().starts_with("refusing to remove a symbolic link"), "{e}");
        assert_eq!(std::fs::read_link(dir.path().join("gone")).unwrap(), std::path::Path::new("data"));

        // A FIFO at the index's name (a damaged index) does not keep the set from landing.
        std::fs::remove_file(dir.path().join("gone")).unwrap();
        std::fs::remove_file(dir.path().join("index")).unwrap();
        let staging = previous_set(dir.path());
        std::fs::remove_file(dir.path().join("index")).unwrap();
        assert!(std::process::Command::new("mkfifo").arg(dir.path().join("index")).status().unwrap().success());
        staging.commit(|| Ok(())).unwrap();
        assert_eq!(std::fs::read(dir.path().join("index")).unwrap(), b"new index");
        assert_eq!(entries(dir.path()), ["data", "extra", "index"]);
    }
}

/// A switch that fails after files have landed puts the old ones back, the index and the retired
/// file included, and removes the files that had no old one: the folder lists the old set again.
#[test]
fn a_commit_that_fails_midway_restores_the_old_set() {
    let dir = tempfile::tempdir().unwrap();
    let staging = previous_set(dir.path());
    let failure = || Err((dir.path().join("index"), std::io::Error::other("injected")));
    let seen = std::cell::RefCell::new(Vec::new());
    let (path, e) = staging
        .commit(|| {
            // The new files have landed and the old ones are gone from their names.
            seen.borrow_mut()
                .extend(["data", "extra", "gone", "index"].map(|n| std::fs::read(dir.path().join(n)).ok()));
            failure()
        })
        .unwrap_err();
    assert_eq!((path, e.to_string()), (dir.path().join("index"), "injected".to_string()));
    assert_eq!(seen.into_inner(), [Some(b"new data".to_vec()), Some(b"new extra".to_vec()), None, None]);
    assert_eq!(contents(dir.path()), old_set(), "the old set, and nothing else (no temporaries)");

    // Committed, the new set lands, the retired file goes, no kept copy stays behind.
    previous_set(dir.path()).commit(|| Ok(())).unwrap();
    let new = [("data", "new data"), ("extra", "new extra"), ("index", "new index")];
    assert_eq!(contents(dir.path()), new.map(|(n, c)| (n.to_string(), c.to_string())));
}

/// A set goes through its folder's descriptor: a folder moved (and another made at its path)
/// between staging and commit gets the whole set, the new folder nothing (renames by path would
/// land in the new folder).
#[test]
fn a_set_lands_in_its_folder_wherever_the_folder_moved() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, moved) = (tmp.path().join("bake"), tmp.path().join("bake.old"));
    std::fs::create_dir(&dir).unwrap();
    let staging = previous_set(&dir);
    std::fs::rename(&dir, &moved).unwrap();
    std::fs::create_dir(&dir).unwrap();
    staging.commit(|| Ok(())).unwrap();
    let new = [("data", "new data"), ("extra", "new extra"), ("index", "new index")];
    assert_eq!(contents(&moved), new.map(|(n, c)| (n.to_string(), c.to_string())));
    assert!(entries(&dir).is_empty());
}

/// Beside a bake, `write_atomic` writes no name the bake's manifest lists, nor the manifest, and
/// nothing while a bake holds the folder's lock (so `merl-info --asset BAKE/importance.asset`
/// cannot overwrite a listed file, nor write into a folder a bake is writing).
#[test]
fn write_atomic_leaves_a_bakes_files_and_a_locked_folder_alone() {
    let dir = tempfile::tempdir().unwrap();
    let listed = asset::StageOutput::of_bytes("importance.png", asset::FileFormat::Png, "picture", b"bake's").unwrap();
    let tool = asset::Tool { name: "brdf-bake".into(), version: "0".into() };
    let source = asset::SourceFile { name: "m".into(), source_path: "m.binary".into(), source_sha256: "0".repeat(64) };
    let mut manifest = asset::BakeManifest::new(source, None, tool, serde_json::Map::new());
    let stage = asset::Stage {
        name: "importance".into(),
        parameters: serde_json::Map::new(),
        figures: serde_json::Map::new(),
        outputs: vec![listed],
    };
    manifest.stages.push(stage);
    std::fs::write(dir.path().join("importance.png"), b"bake's").unwrap();
    std::fs::write(dir.path().join(asset::MANIFEST_FILE), manifest.to_json()).unwrap();
    for name in ["importance.png", asset::MANIFEST_FILE] {
        let e = write_atomic(&dir.path().join(name), b"mine").unwrap_err().to_string();
        let expected = format!("{name} is a file of the bake in {} (its manifest lists it)", dir.path().display());
        assert!(e.starts_with(&expected), "{e}");
    }
    assert_eq!(std::fs::read(dir.path().join("importance.png")).unwrap(), b"bake's");
    assert_eq!(std::fs::read_to_string(dir.path().join(asset::MANIFEST_FILE)).unwrap(), manifest.to_json());
    write_atomic(&dir.path().join("preview.png"), b"mine").unwrap();

    // A bake holds the folder (here this process, through another open description of it).
    let bake = fsguard::Folder::open(dir.path()).unwrap();
    assert!(bake.try_lock().unwrap());
    let e = write_atomic(&dir.path().join("other.png"), b"mine").unwrap_err().to_string();
    assert!(e.starts_with("a bake is writing this folder"), "{e}");
    assert!(!dir.path().join("other.png").exists());
    drop(bake);
    write_atomic(&dir.path().join("other.png"), b"mine").unwrap();
    assert_eq!(entries(dir.path()), ["importance.png", "manifest.json", "other.png", "preview.png"]);
}

/// A FIFO or a device is refused without blocking or reading; a link is followed for a path
/// given as it is, never for a name an asset links (`linked_file_status`).
#[cfg(unix)]
#[test]
fn hashing_reads_regular_files_only() {
    use std::os::unix::fs::FileTypeExt;
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fifo");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let e = sha256_file(&fifo).unwrap_err();
    assert!(e.to_string().contains("fifo"), "{e}");
    let e = sha256_file(std::path::Path::new("/dev/zero")).unwrap_err();
    assert!(e.to_string().contains("character device"), "{e}");

    let outside = tempfile::tempdir().unwrap();
    std::fs::write(outside.path().join("abc"), b"abc").unwrap();
    std::os::unix::fs::symlink(outside.path().join("abc"), dir.path().join("link")).unwrap();
    assert_eq!(hex(&sha256_file(&dir.path().join("link")).unwrap()), ABC_SHA256);
    let status = asset::linked_file_status(dir.path(), "link", &sha256(b"abc"));
    assert!(matches!(&status, asset::LinkedStatus::Unreadable(e) if e.contains("symbolic link")), "{status:?}");
    let status = asset::linked_file_status(dir.path(), "fifo", &sha256(b"abc"));
    assert!(matches!(&status, asset::LinkedStatus::Unreadable(e) if e.contains("fifo")), "{status:?}");
    std::fs::write(dir.path().join("abc"), b"abc").unwrap();
    assert_eq!(asset::linked_file_status(dir.path(), "abc", &sha256(b"abc")), asset::LinkedStatus::Matches);

    // An output path that is a FIFO (or a device) is not renamed away.
    let e = write_atomic(&fifo, b"x").unwrap_err();
    assert!(e.to_string().contains("refusing to replace"), "{e}");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
}

/// The temporary files of `write_atomic` and `write_set` are recognised by their whole name, so
/// that a cleanup removes only ours: `.NAME.XXXXXX.tmp` with six letters or digits.
#[test]
fn temporary_files_are_recognised_by_their_whole_name() {
    use asset::temporary_target;
    assert_eq!(temporary_target(".importance.asset.Ab3dE9.tmp"), Some("importance.asset"));
    assert_eq!(temporary_target(".manifest.json.x7YqZ2.tmp"), Some("manifest.json"));
    for other in
        [".x.tmp", ".a.asset.Ab3d.tmp", "a.asset.Ab3dE9.tmp", ".a.asset.Ab3dE9", "..Ab3dE9.tmp", ".a.Ab-dE9.tmp"]
    {
        assert_eq!(temporary_target(other), None, "{other}");
    }
    // What write_atomic leaves behind while it writes is of that form.
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("x.asset");
    let file =
        tempfile::Builder::new().prefix(".x.asset.").suffix(".tmp").rand_bytes(6).tempfile_in(dir.path()).unwrap();
    let name = file.path().file_name().unwrap().to_str().unwrap().to_string();
    assert_eq!(temporary_target(&name), Some("x.asset"), "{name}");
    let folder = fsguard::Folder::open(dir.path()).unwrap();
    assert_eq!(asset::remove_temporaries(&folder, |t| t == "other.png").unwrap(), 0);
    assert_eq!(asset::remove_temporaries(&folder, |t| t == "x.asset").unwrap(), 1);
    assert!(!target.exists() && !file.path().exists());
}
