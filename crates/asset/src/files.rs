//! File helpers every tool uses for its outputs and provenance: atomic writes, sets of files
//! that land together, and SHA-256. They know nothing about the asset format.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// Writes `bytes` to `path` so that `path` holds either its old contents or all of `bytes`,
/// never a prefix: the bytes go to a temporary file in the same folder (so the rename cannot
/// cross file systems), are synced to disk, and the file is then renamed over `path`.
///
/// The new file gets the permissions `File::create` would give it (0o666 less the umask on
/// Unix), not the owner-only ones of a temporary file. If writing or renaming fails, the
/// temporary file is removed and `path` is untouched. (On Unix the folder is synced after the
/// rename; if only that fails, `path` already holds the new bytes and the error says the rename
/// may not survive a power loss.) A symbolic link at `path` is replaced, not followed.
///
/// The folder must exist: an output path whose folder is missing is an error that says so, never
/// a chain of folders made from the root (tools create their `--out-dir` itself, [`write_set`]).
/// Nor is anything but a regular file or a link replaced: `--out /dev/zero` or a FIFO is an
/// error, not a device node renamed away.
///
/// Beside a bake: the folder's shared lock is held while the file is written (while a bake holds
/// the folder this is an error at once, and no bake starts meanwhile), and a name the folder's
/// manifest lists, or the manifest itself, is never written (a file of the bake would no longer
/// be the one its manifest describes).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let folder = folder_of(path);
    check_folder(folder)?;
    check_replaceable_path(path)?;
    let _lock = beside_a_bake(folder, path)?;
    let file = temporary(folder, path, bytes)?;
    file.persist(path).map_err(|e| e.error)?;
    // The rename itself is durable only once the folder's entry is on disk.
    sync_folder(folder)
}

/// Writes several files into `dir` so that they land together or not at all ([`Staging`]):
/// every file is first written in full to a temporary file beside its target and synced; only
/// then are they renamed into place, in order, with the last of `files` (the one that names the
/// others, such as an asset that records its linked files' SHA-256) removed first and renamed
/// last: an interruption at any moment leaves either the old set, or new files that no index names
/// yet, never an index naming a file that does not match it. A name that holds a folder (or
/// anything but a regular file or a link) fails the set before anything is replaced; if a rename
/// fails, the old files are put back, so the folder holds the old set rather than part of the new
/// one. Temporary files an earlier interrupted run left for these names (`.NAME.XXXXXX.tmp`) are
/// removed first.
///
/// `dir` is created if it is missing, the folder itself only: its parent must exist.
///
/// Errors name the target file the caller asked for, never a temporary one.
pub fn write_set(dir: &Path, files: &[(&str, &[u8])]) -> Result<(), (PathBuf, std::io::Error)> {
    let folder = fsguard::Folder::create(dir).map_err(|e| (dir.to_path_buf(), e))?;
    let names: Vec<&str> = files.iter().map(|(name, _)| *name).collect();
    remove_temporaries(&folder, |target| names.contains(&target)).map_err(|e| (dir.to_path_buf(), e))?;
    let mut staging = Staging::new(&folder).map_err(|e| (dir.to_path_buf(), e))?;
    for (name, bytes) in files {
        staging.add(name, bytes)?;
    }
    staging.commit(|| Ok(()))
}

/// Creates the folder `dir` if it is missing: the folder itself, not a chain of missing parents
/// (the error then names the parent that is missing).
pub fn create_folder(dir: &Path) -> std::io::Result<()> {
    fsguard::Folder::create(dir).map(drop)
}

/// New files written beside the ones they replace, as synced temporary files
/// (`.NAME.XXXXXX.tmp`), and then switched into place by renames alone ([`Staging::commit`]): a
/// failure while they are written (a full disk, a read-only folder) removes them and leaves the
/// folder as it was; dropping a `Staging` without committing does the same.
///
/// Every step goes through the folder's open descriptor (`openat`, `renameat`, `linkat`,
/// `unlinkat`), never its path: a folder moved or replaced meanwhile is still the one written,
/// wherever it is. Names are plain file names (no `/`).
#[derive(Debug)]
pub struct Staging {
    folder: fsguard::Folder,
    /// Each target's name and its temporary file's.
    files: Vec<(String, String)>,
    retired: Vec<String>,
}

impl Staging {
    /// An empty set of files for the open folder `folder`.
    pub fn new(folder: &fsguard::Folder) -> std::io::Result<Staging> {
        Ok(Staging { folder: folder.try_clone()?, files: Vec::new(), retired: Vec::new() })
    }

    /// Writes `bytes` for the file `name` of the folder to a synced temporary file. Errors name
    /// the target, never the temporary file.
    pub fn add(&mut self, name: &str, bytes: &[u8]) -> Result<(), (PathBuf, std::io::Error)> {
        let temporary = write_temporary(&self.folder, name, bytes).map_err(|e| (self.folder.join(name), e))?;
        self.files.push((name.to_string(), temporary));
        Ok(())
    }

    /// Removes the file `name` (a plain file name) of the folder in the switch, after the new
    /// files land and before the index does; a commit that fails puts it back. Only a regular
    /// file is removed (anything else under the name fails the commit before anything changes);
    /// a missing one is skipped.
    pub fn retire(&mut self, name: &str) {
        self.retired.push(name.to_string());
    }

    /// Switches the files into place, by renames and links alone (no free space needed, so on a
    /// full disk the folder still switches):
    ///
    /// 1. Every target must be replaceable (nothing, a regular file or a link; the index anything
    ///    but a folder, so that a damaged index, a FIFO say, never keeps a set from landing) and
    ///    every retired name a regular file or nothing: otherwise this fails naming it, and
    ///    nothing has changed.
    /// 2. The old index (the last file added, which names the others) is set aside: it leaves its
    ///    name, which no reader then finds, and the folder is synced.
    /// 3. Every other file is renamed over its target in the order added, the old file kept under
    ///    a temporary name (a second link to it); then the retired files are set aside,
    ///    `before_index` runs, and the index is renamed into place; the folder is synced.
    /// 4. The old files kept aside are removed.
    ///
    /// If anything fails in 2 or 3, every step already taken is undone: each old file is renamed
    /// back over its name (the new one removed where there was none) and the old index is put
    /// back, so the folder lists the previous set again. An interruption (a kill) leaves complete
    /// files, no index and the kept files as temporaries ([`remove_temporaries`] removes them).
    pub fn commit(
        mut self,
        before_index: impl FnOnce() -> Result<(), (PathBuf, std::io::Error)>,
    ) -> Result<(), (PathBuf, std::io::Error)> {
        let mut files = std::mem::take(&mut self.files);
        let retired = std::mem::take(&mut self.retired);
        let folder = &self.folder;
        let at = |name: &str, e: std::io::Error| (folder.join(name), e);
        let Some((index, index_temporary)) = files.pop() else { return Ok(()) };
        // Until a temporary file is renamed, dropping it (an early return) removes it.
        let mut pending: Vec<Pending> = files.iter().map(|(_, t)| Pending::new(folder, t)).collect();
        let index_pending = Pending::new(folder, &index_temporary);
        for (name, _) in &files {
            check_replaceable(folder, name).map_err(|e| at(name, e))?;
        }
        check_index_replaceable(folder, &index).map_err(|e| at(&index, e))?;
        for name in &retired {
            check_removable(folder, name).map_err(|e| at(name, e))?;
        }
        let mut switch = Switch { folder, undo: Vec::new() };
        let result = (|| {
            switch.set_aside(&index)?;
            folder.sync().map_err(|e| (folder.path().to_path_buf(), e))?;
            for ((name, temporary), pending) in files.iter().zip(&mut pending) {
                switch.replace(name, temporary)?;
                pending.landed();
            }
            for name in &retired {
                switch.set_aside(name)?;
            }
            before_index()?;
            switch.replace(&index, &index_temporary)?;
            folder.sync().map_err(|e| (folder.path().to_path_buf(), e))
        })();
        match result {
            Ok(()) => {
                index_pending.landed_for_good();
                pending.into_iter().for_each(Pending::landed_for_good);
                switch.forget();
                Ok(())
            }
            Err(e) => {
                switch.undo();
                Err(e)
            }
        }
    }
}

impl Drop for Staging {
    /// Files staged and never committed leave no temporary file behind.
    fn drop(&mut self) {
        for (_, temporary) in &self.files {
            let _ = self.folder.unlink(temporary);
        }
    }
}

/// A temporary file of a commit that is removed when this drops, unless it was renamed into place.
struct Pending<'a> {
    folder: &'a fsguard::Folder,
    name: Option<String>,
}

impl<'a> Pending<'a> {
    fn new(folder: &'a fsguard::Folder, name: &str) -> Pending<'a> {
        Pending { folder, name: Some(name.to_string()) }
    }

    /// Renamed: nothing left under its name. (An undo renames no new file back: it is removed or
    /// replaced by the old one.)
    fn landed(&mut self) {
        self.name = None;
    }

    fn landed_for_good(mut self) {
        self.name = None;
    }
}

impl Drop for Pending<'_> {
    fn drop(&mut self) {
        if let Some(name) = &self.name {
            let _ = self.folder.unlink(name);
        }
    }
}

/// The steps of a [`Staging::commit`] taken so far, with what undoes each.
struct Switch<'a> {
    folder: &'a fsguard::Folder,
    undo: Vec<Step>,
}

enum Step {
    /// A new file renamed over `target`; `old` is the temporary name of the file it replaced,
    /// if there was one.
    Replaced { target: String, old: Option<String> },
    /// The file at `target` moved to the temporary name `old`, leaving the name free.
    SetAside { target: String, old: String },
}

impl Switch<'_> {
    /// Renames the temporary file `temporary` over `target`, keeping the file it replaces.
    fn replace(&mut self, target: &str, temporary: &str) -> Result<(), (PathBuf, std::io::Error)> {
        let at = |e| (self.folder.join(target), e);
        let old = keep(self.folder, target).map_err(at)?;
        match self.folder.rename(temporary, target) {
            Ok(()) => {
                self.undo.push(Step::Replaced { target: target.to_string(), old });
                Ok(())
            }
            Err(e) => {
                // The old file is still at the target (only the extra name goes), unless `keep`
                // had to rename it away: then it goes back.
                if let Some(old) = old {
                    let _ = match self.folder.entry(target) {
                        Ok(None) => self.folder.rename(&old, target),
                        _ => self.folder.unlink(&old),
                    };
                }
                Err(at(e))
            }
        }
    }

    /// Moves the file at `target` aside (a second name, then `target` unlinked); nothing there is
    /// nothing to do.
    fn set_aside(&mut self, target: &str) -> Result<(), (PathBuf, std::io::Error)> {
        let at = |e| (self.folder.join(target), e);
        let Some(old) = keep(self.folder, target).map_err(at)? else { return Ok(()) };
        match self.folder.unlink(target) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                let _ = self.folder.unlink(&old);
                return Err(at(e));
            }
        }
        self.undo.push(Step::SetAside { target: target.to_string(), old });
        Ok(())
    }

    /// The switch succeeded: the kept old files go.
    fn forget(self) {
        for step in self.undo {
            if let Step::Replaced { old: Some(old), .. } | Step::SetAside { old, .. } = step {
                let _ = self.folder.unlink(&old);
            }
        }
    }

    /// Every step taken, undone in reverse order; best effort (the error that stopped the switch
    /// is the one reported).
    fn undo(self) {
        for step in self.undo.into_iter().rev() {
            match step {
                Step::Replaced { target, old: Some(old) } | Step::SetAside { target, old } => {
                    let _ = self.folder.rename(&old, &target);
                }
                Step::Replaced { target, old: None } => {
                    let _ = self.folder.unlink(&target);
                }
            }
        }
        let _ = self.folder.sync();
    }
}

/// A second name for the file (or link) `target` of the folder, a temporary one
/// (`.NAME.XXXXXX.tmp`): a hard link, or, where the file system has none, the file itself
/// renamed there. `None` when nothing is at `target`.
fn keep(folder: &fsguard::Folder, target: &str) -> std::io::Result<Option<String>> {
    for _ in 0..TEMPORARY_ATTEMPTS {
        let name = temporary_name(target);
        match folder.link(target, &name) {
            Ok(()) => return Ok(Some(name)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => {
                let no_links =
                    matches!(e.kind(), std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::Unsupported);
                let renameable = matches!(folder.entry(target)?, Some(fsguard::Entry::File | fsguard::Entry::Link));
                let free = folder.entry(&name)?.is_none();
                if no_links && renameable && free {
                    folder.rename(target, &name)?;
                    return Ok(Some(name));
                }
                return Err(e);
            }
        }
    }
    Err(too_many_temporaries())
}

/// A new temporary file for `target` in the folder, holding `bytes`, synced; its name. Removed
/// again if it cannot be written in full.
fn write_temporary(folder: &fsguard::Folder, target: &str, bytes: &[u8]) -> std::io::Result<String> {
    for _ in 0..TEMPORARY_ATTEMPTS {
        let name = temporary_name(target);
        let mut file = match folder.create_new(&name) {
            Ok(file) => file,
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        };
        let written = file.write_all(bytes).and_then(|()| file.flush()).and_then(|()| file.sync_all());
        return match written {
            Ok(()) => Ok(name),
            Err(e) => {
                let _ = folder.unlink(&name);
                Err(e)
            }
        };
    }
    Err(too_many_temporaries())
}

/// Names tried for a temporary file before giving up (each random: a clash is a hostile folder).
const TEMPORARY_ATTEMPTS: usize = 64;

fn too_many_temporaries() -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary file name: too many temporary files")
}

/// `.NAME.XXXXXX.tmp` for `target`, six random letters and digits ([`temporary_target`]).
fn temporary_name(target: &str) -> String {
    use std::hash::{BuildHasher, Hasher};
    const ALPHABET: &[u8; 62] = b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz";
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let mut hasher = std::collections::hash_map::RandomState::new().build_hasher();
    hasher.write_u64(COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed));
    hasher.write_u32(std::process::id());
    let mut bits = hasher.finish();
    let mut random = String::with_capacity(TEMPORARY_RANDOM_CHARS);
    for _ in 0..TEMPORARY_RANDOM_CHARS {
        random.push(ALPHABET[(bits % 62) as usize] as char);
        bits /= 62;
    }
    format!(".{target}.{random}.tmp")
}

/// The file a temporary file of [`write_atomic`] or [`write_set`] was for: `NAME` of
/// `.NAME.XXXXXX.tmp` (six letters or digits); `None` for any other name.
pub fn temporary_target(file_name: &str) -> Option<&str> {
    let rest = file_name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (target, random) = rest.rsplit_once('.')?;
    let ours = !target.is_empty()
        && random.len() == TEMPORARY_RANDOM_CHARS
        && random.chars().all(|c| c.is_ascii_alphanumeric());
    ours.then_some(target)
}

/// Removes from the folder the temporary files ([`temporary_target`]) an interrupted run left for
/// the files `of` accepts: they are never outputs. Returns how many were removed.
pub fn remove_temporaries(folder: &fsguard::Folder, of: impl Fn(&str) -> bool) -> std::io::Result<usize> {
    let mut removed = 0;
    for (name, entry) in folder.entries()? {
        if entry == fsguard::Entry::File && temporary_target(&name).is_some_and(&of) {
            folder.unlink(&name)?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// Random characters in a temporary file's name (`tempfile`'s default).
const TEMPORARY_RANDOM_CHARS: usize = 6;

fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// The folder `folder` held with its shared lock, once `path` is known not to be a file of the
/// bake the folder may hold ([`write_atomic`]).
fn beside_a_bake(folder: &Path, path: &Path) -> std::io::Result<fsguard::Folder> {
    let held = fsguard::Folder::open(folder)?;
    if !held.try_lock_shared()? {
        return Err(std::io::Error::new(
            std::io::ErrorKind::WouldBlock,
            "a bake is writing this folder (it holds the folder's lock): wait for it to finish, or write elsewhere",
        ));
    }
    let name = path.file_name().map(|n| n.to_string_lossy()).unwrap_or_default();
    if let Ok(manifest) = crate::BakeManifest::read(&held)
        && (name == crate::MANIFEST_FILE || manifest.output_by_path(&name).is_some())
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            format!(
                "{} is a file of the bake in {} (its manifest lists it): write elsewhere, or bake again with brdf-bake",
                fsguard::printable(&name),
                fsguard::printable_path(folder)
            ),
        ));
    }
    Ok(held)
}

/// What is at an output's path may be replaced only if it is a regular file or a link (or
/// nothing).
fn check_replaceable_path(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.is_file() || meta.is_symlink() => Ok(()),
        Ok(meta) => {
            let what = if meta.is_dir() { "a folder" } else { "a fifo, device or socket" };
            Err(not_a_file("replace", what, "a regular file or a link"))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
}

/// A target of a set may be replaced only if it is a regular file or a link (or nothing).
fn check_replaceable(folder: &fsguard::Folder, name: &str) -> std::io::Result<()> {
    use fsguard::Entry;
    check_entry(folder, name, "replace", "a regular file or a link", |e| matches!(e, Entry::File | Entry::Link))
}

/// The index of a set is replaced whatever it is (a link, a FIFO, a device node: a damaged or
/// hostile index must not keep a set from landing) except a folder.
fn check_index_replaceable(folder: &fsguard::Folder, name: &str) -> std::io::Result<()> {
    check_entry(folder, name, "replace", "anything but a folder", |e| e != fsguard::Entry::Folder)
}

/// What a set retires may be removed only if it is a regular file (or nothing).
fn check_removable(folder: &fsguard::Folder, name: &str) -> std::io::Result<()> {
    check_entry(folder, name, "remove", "a regular file", |e| e == fsguard::Entry::File)
}

fn check_entry(
    folder: &fsguard::Folder,
    name: &str,
    verb: &str,
    allowed: &str,
    ok: impl Fn(fsguard::Entry) -> bool,
) -> std::io::Result<()> {
    match folder.entry(name)? {
        None => Ok(()),
        Some(entry) if ok(entry) => Ok(()),
        Some(entry) => {
            let what = match entry {
                fsguard::Entry::Folder => "a folder",
                fsguard::Entry::Link => "a symbolic link",
                fsguard::Entry::File => "a regular file",
                fsguard::Entry::Other(what) => what,
            };
            Err(not_a_file(verb, what, allowed))
        }
    }
}

/// The error for a name the caller (who names the path) may not replace or remove.
fn not_a_file(verb: &str, what: &str, allowed: &str) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("refusing to {verb} {what} (only {allowed} is {verb}d): nothing was changed"),
    )
}

/// An output's folder must be there already: say so plainly rather than "no such file".
fn check_folder(folder: &Path) -> std::io::Result<()> {
    match std::fs::metadata(folder) {
        Ok(meta) if meta.is_dir() => Ok(()),
        Ok(_) => {
            Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, format!("{} is not a folder", folder.display())))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("the folder {} does not exist (outputs are written into existing folders)", folder.display()),
        )),
        Err(e) => Err(e),
    }
}

/// `bytes` in a synced temporary file `.NAME.XXXXXX.tmp` in `folder`, with the permissions
/// `File::create` would give (0o666 less the umask on Unix), not a temporary file's owner-only
/// ones. Errors carry no temporary path (the caller names the target); the file is removed
/// when the handle is dropped unpersisted.
fn temporary(folder: &Path, target: &Path, bytes: &[u8]) -> std::io::Result<tempfile::NamedTempFile> {
    let prefix = temporary_prefix(target);
    let mut builder = temporary_builder(&prefix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut file = builder.tempfile_in(folder).map_err(without_temporary_path)?;
    let handle = file.as_file_mut();
    handle.write_all(bytes)?;
    handle.flush()?;
    handle.sync_all()?;
    Ok(file)
}

/// The start of the names of `target`'s temporary files, `.NAME.` of `.NAME.XXXXXX.tmp`
/// ([`temporary_target`]).
fn temporary_prefix(target: &Path) -> std::ffi::OsString {
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(target.file_name().unwrap_or_default());
    prefix.push(".");
    prefix
}

/// Names temporary files `PREFIX` + six random characters + `.tmp` ([`temporary_prefix`]).
fn temporary_builder(prefix: &std::ffi::OsStr) -> tempfile::Builder<'_, 'static> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(prefix).suffix(".tmp").rand_bytes(TEMPORARY_RANDOM_CHARS);
    builder
}

/// `tempfile` appends "at path ..." to its errors: keep the system's message only (the caller
/// names the target, never a temporary file).
fn without_temporary_path(e: std::io::Error) -> std::io::Error {
    let message = e.to_string();
    let message = message.split(" at path ").next().unwrap_or(&message).to_string();
    std::io::Error::new(e.kind(), message)
}

fn sync_folder(folder: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    std::fs::File::open(folder)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = folder;
    Ok(())
}

/// What [`linked_file_status`] found for a file an asset names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LinkedStatus {
    /// The file exists and has the SHA-256 the asset records.
    Matches,
    /// No such file beside the asset.
    Missing,
    /// The file's SHA-256 differs from the recorded one: it belongs to another bake.
    Differs { found: [u8; 32] },
    /// The file could not be read.
    Unreadable(String),
}

/// Checks a file an asset names (`name`, `sha256`) in the asset's folder `dir`. The name is
/// resolved inside the folder without following a link ([`fsguard::Folder::open_file`]): a link,
/// a FIFO or a device is `Unreadable`, never read.
pub fn linked_file_status(dir: &Path, name: &str, sha256: &[u8; 32]) -> LinkedStatus {
    let hashed = fsguard::Folder::open(dir).and_then(|folder| sha256_open(folder.open_file(name)?));
    match hashed {
        Ok(found) if found == *sha256 => LinkedStatus::Matches,
        Ok(found) => LinkedStatus::Differs { found },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => LinkedStatus::Missing,
        Err(e) => LinkedStatus::Unreadable(e.to_string()),
    }
}

/// SHA-256 of a file's contents, read in a stream so that any size fits in memory. The file must
/// be a regular file ([`fsguard::open_regular`]: a FIFO or a device is refused, never read), and
/// exactly the size it had when opened is read.
pub fn sha256_file(path: &Path) -> std::io::Result<[u8; 32]> {
    sha256_open(fsguard::open_regular(path)?)
}

/// SHA-256 of an open regular file: its length from its metadata, then exactly that many bytes
/// (a file that grew or shrank meanwhile is an error).
pub(crate) fn sha256_open(file: std::fs::File) -> std::io::Result<[u8; 32]> {
    let len = file.metadata()?.len();
    let mut hasher = Sha256::new();
    let read = std::io::copy(&mut file.take(len.saturating_add(1)), &mut hasher)?;
    if read != len {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("changed while being read: {len} bytes when opened, {read} read"),
        ));
    }
    Ok(hasher.finalize().into())
}

/// SHA-256 of bytes in memory.
pub fn sha256(bytes: &[u8]) -> [u8; 32] {
    Sha256::digest(bytes).into()
}

/// Lower-case hexadecimal, two digits per byte (how hashes appear in manifests and reports).
pub fn hex(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mut out = String::with_capacity(2 * bytes.len());
    for &b in bytes {
        out.push(DIGITS[usize::from(b >> 4)] as char);
        out.push(DIGITS[usize::from(b & 0xf)] as char);
    }
    out
}

/// Parses a SHA-256 as [`hex`] writes it: exactly 64 lower-case hexadecimal digits, the form
/// the bake manifest's schema requires.
pub fn sha256_from_hex(text: &str) -> Option<[u8; 32]> {
    let digit = |c: u8| match c {
        b'0'..=b'9' => Some(c - b'0'),
        b'a'..=b'f' => Some(c - b'a' + 10),
        _ => None,
    };
    if text.len() != 64 {
        return None;
    }
    let mut out = [0u8; 32];
    for (byte, pair) in out.iter_mut().zip(text.as_bytes().chunks_exact(2)) {
        *byte = digit(pair[0])? << 4 | digit(pair[1])?;
    }
    Some(out)
}
