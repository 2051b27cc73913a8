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
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let folder = folder_of(path);
    check_folder(folder)?;
    check_replaceable(path)?;
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
/// yet, never an index naming a file that does not match it. If a rename fails, the files already
/// renamed are removed, so the set is absent rather than partly new. Temporary files an earlier
/// interrupted run left for these names (`.NAME.XXXXXX.tmp`) are removed first.
///
/// `dir` is created if it is missing, the folder itself only: its parent must exist.
///
/// Errors name the target file the caller asked for, never a temporary one.
pub fn write_set(dir: &Path, files: &[(&str, &[u8])]) -> Result<(), (PathBuf, std::io::Error)> {
    create_folder(dir).map_err(|e| (dir.to_path_buf(), e))?;
    let names: Vec<&str> = files.iter().map(|(name, _)| *name).collect();
    remove_temporaries(dir, |target| names.contains(&target)).map_err(|e| (dir.to_path_buf(), e))?;
    let mut staging = Staging::new(dir);
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
#[derive(Debug)]
pub struct Staging {
    dir: PathBuf,
    files: Vec<(PathBuf, tempfile::NamedTempFile)>,
}

impl Staging {
    /// An empty set of files for the folder `dir` (which must exist).
    pub fn new(dir: &Path) -> Staging {
        Staging { dir: dir.to_path_buf(), files: Vec::new() }
    }

    /// Writes `bytes` for the file `name` of the folder to a synced temporary file. Errors name
    /// the target, never the temporary file.
    pub fn add(&mut self, name: &str, bytes: &[u8]) -> Result<(), (PathBuf, std::io::Error)> {
        let path = self.dir.join(name);
        let file = temporary(&self.dir, &path, bytes).map_err(|e| (path.clone(), e))?;
        self.files.push((path, file));
        Ok(())
    }

    /// Switches the files into place: the last one added (the index, which names the others) is
    /// removed first, then every other file is renamed over its target in the order added,
    /// `before_index` runs, and the index is renamed last; the folder is synced after the removal
    /// and at the end. Renames need no space, so on a full disk the folder still switches. If a
    /// rename fails, the files this call renamed are removed again.
    pub fn commit(
        self,
        before_index: impl FnOnce() -> Result<(), (PathBuf, std::io::Error)>,
    ) -> Result<(), (PathBuf, std::io::Error)> {
        let dir = self.dir;
        let mut files = self.files;
        let Some((index, _)) = files.last() else { return Ok(()) };
        match std::fs::remove_file(index) {
            Ok(()) => sync_folder(&dir).map_err(|e| (dir.clone(), e))?,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err((index.clone(), e)),
        }
        let last = files.pop().expect("a last file");
        let mut landed: Vec<PathBuf> = Vec::with_capacity(files.len() + 1);
        let undo = |landed: &[PathBuf]| {
            for done in landed {
                let _ = std::fs::remove_file(done);
            }
            let _ = sync_folder(&dir);
        };
        for (path, file) in files {
            if let Err(e) = file.persist(&path) {
                undo(&landed);
                return Err((path, e.error));
            }
            landed.push(path);
        }
        if let Err(e) = before_index() {
            undo(&landed);
            return Err(e);
        }
        let (path, file) = last;
        if let Err(e) = file.persist(&path) {
            undo(&landed);
            return Err((path, e.error));
        }
        sync_folder(&dir).map_err(|e| (dir.clone(), e))
    }
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

/// Removes from `dir` the temporary files ([`temporary_target`]) an interrupted run left for the
/// files `of` accepts: they are never outputs. Returns how many were removed.
pub fn remove_temporaries(dir: &Path, of: impl Fn(&str) -> bool) -> std::io::Result<usize> {
    let mut removed = 0;
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let ours = entry.file_name().to_str().and_then(temporary_target).is_some_and(&of);
        if ours && entry.file_type()?.is_file() {
            std::fs::remove_file(entry.path())?;
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

/// What is at an output's path may be replaced only if it is a regular file or a link (or
/// nothing).
fn check_replaceable(path: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.is_file() || meta.is_symlink() => Ok(()),
        Ok(meta) => Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "refusing to replace {} (a {}, not a regular file)",
                path.display(),
                if meta.is_dir() { "folder" } else { "fifo, device or socket" }
            ),
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
    }
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
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(target.file_name().unwrap_or_default());
    prefix.push(".");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp").rand_bytes(TEMPORARY_RANDOM_CHARS);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // `tempfile` appends "at path ..." to its errors: keep the system's message only.
    let mut file = builder.tempfile_in(folder).map_err(|e| {
        let message = e.to_string();
        let message = message.split(" at path ").next().unwrap_or(&message).to_string();
        std::io::Error::new(e.kind(), message)
    })?;
    let handle = file.as_file_mut();
    handle.write_all(bytes)?;
    handle.flush()?;
    handle.sync_all()?;
    Ok(file)
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
