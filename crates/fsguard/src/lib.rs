//! Opening the files that a person or a file names, so that no path can be turned against the
//! person running a tool: a reader never blocks, never reads without a bound, and never leaves the
//! folder it was asked to read.
//!
//! - [`open_regular`] and [`read_regular`]: a path as it was given (a command-line argument,
//!   followed where it leads), opened without blocking (`O_NONBLOCK`, so that a FIFO cannot hang
//!   the reader) and accepted only if it is a regular file (a FIFO, a device such as `/dev/zero`,
//!   a socket or a folder is refused); [`read_regular`] checks the size from the open file's
//!   metadata against a limit before reading, and then reads at most that many bytes.
//! - [`Folder`]: a folder held open, and paths inside it that a file names (a manifest's outputs,
//!   the files an asset links): `/`-separated components ([`check_relative`]) resolved one by one
//!   from the folder's descriptor with `openat(2)` and `O_NOFOLLOW`, so that no component may be a
//!   symbolic link, whatever the components' text says and whatever changes between a check and
//!   the open; the file itself must be a regular file. It also removes files the folder holds by a
//!   plain name (never through a link, never anything but a regular file) and takes the folder's
//!   advisory lock (`flock(2)` on the folder itself).
//!
//! - [`printable`]: a name taken from a file (a manifest's output path, a material's
//!   `source_path`) as a message may print it, control characters escaped, so that a name cannot
//!   break a message into lines or send escape sequences to a terminal.
//!
//! Messages are lower case and name the problem, not the path: callers add the path.
//!
//! Unix only: the toolchain runs where `openat(2)` and `flock(2)` exist.

use std::fs::{File, Metadata};
use std::io::{self, Read};
use std::os::fd::{AsFd, BorrowedFd, OwnedFd};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

use rustix::fs::{AtFlags, FlockOperation, Mode, OFlags};
use rustix::io::Errno;

/// Opens `path` for reading, following it as given, without blocking, and returns the file only if
/// it is a regular file (see the crate docs).
pub fn open_regular(path: &Path) -> io::Result<File> {
    let fd = rustix::fs::open(path, read_flags(), Mode::empty())?;
    regular(File::from(fd))
}

/// The bytes of the regular file at `path` ([`open_regular`]), which must hold at most `limit`
/// bytes: the size is checked from the open file's metadata before anything is read or allocated.
pub fn read_regular(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    read_to_end(open_regular(path)?, limit)
}

/// The bytes of an open regular file of at most `limit` bytes, checked from its metadata before
/// reading; at most one byte more than the metadata promised is read, and a file whose size
/// changed in the meantime is an error.
pub fn read_to_end(file: File, limit: u64) -> io::Result<Vec<u8>> {
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_large(len, limit));
    }
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(usize::try_from(len).map_err(|_| too_large(len, limit))?)
        .map_err(|_| io::Error::new(io::ErrorKind::OutOfMemory, format!("{len} bytes do not fit in memory")))?;
    file.take(len.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 != len {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("changed while being read: {len} bytes when opened, {} read", bytes.len()),
        ));
    }
    Ok(bytes)
}

/// `name` as a message prints it: every control character (`char::is_control`: C0, DEL and C1,
/// newlines, tabs and ANSI escapes among them) written as its Rust escape (`\n`, `\t`,
/// `\u{1b}`), everything else (spaces, any letter or symbol) as it is. Borrowed when there is
/// nothing to escape; escaping escaped text changes nothing.
pub fn printable(name: &str) -> std::borrow::Cow<'_, str> {
    if !name.chars().any(char::is_control) {
        return std::borrow::Cow::Borrowed(name);
    }
    let mut out = String::with_capacity(name.len() + 8);
    for c in name.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// [`printable`] of a path (as `Path::display` shows it).
pub fn printable_path(path: &Path) -> String {
    printable(&path.to_string_lossy()).into_owned()
}

/// Checks that `relative` names a file inside a folder: `/`-separated components, none of them
/// empty, `.` or `..`, without `\` or NUL; in particular not absolute. The error says why not.
pub fn check_relative(relative: &str) -> Result<(), String> {
    let bad = |why: &str| Err(format!("path {relative:?} {why}: expected a relative path inside the folder"));
    if relative.is_empty() {
        return bad("is empty");
    }
    if relative.starts_with('/') {
        return bad("is absolute");
    }
    if relative.contains(['\\', '\0']) {
        return bad("holds a backslash or a NUL");
    }
    for part in relative.split('/') {
        match part {
            "" => return bad("has an empty component"),
            "." | ".." => return bad(&format!("has a {part:?} component")),
            _ => {}
        }
    }
    Ok(())
}

/// A folder held open (see the crate docs). The lock of [`Folder::try_lock`] lasts as long as the
/// `Folder`.
#[derive(Debug)]
pub struct Folder {
    dir: OwnedFd,
    path: PathBuf,
}

impl Folder {
    /// Opens the folder at `path`, followed as given (it is the caller's path, not a file's).
    pub fn open(path: &Path) -> io::Result<Folder> {
        let flags = OFlags::RDONLY | OFlags::DIRECTORY | OFlags::CLOEXEC | OFlags::NONBLOCK;
        let dir = rustix::fs::open(path, flags, Mode::empty()).map_err(|e| match e {
            Errno::NOTDIR => io::Error::new(io::ErrorKind::InvalidInput, "not a folder"),
            other => other.into(),
        })?;
        Ok(Folder { dir, path: path.to_path_buf() })
    }

    /// Creates the folder at `path` if it is missing (the folder itself only: its parent must
    /// exist, a chain of missing folders is an error) and opens it.
    pub fn create(path: &Path) -> io::Result<Folder> {
        match std::fs::create_dir(path) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                let parent = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!(
                        "its parent folder {} does not exist (only the folder itself is created, not a chain of \
                         folders)",
                        parent.display()
                    ),
                ));
            }
            Err(e) => return Err(e),
        }
        Folder::open(path)
    }

    /// The path the folder was opened at.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// `relative` under the folder's path, for messages.
    pub fn join(&self, relative: &str) -> PathBuf {
        self.path.join(relative)
    }

    /// Opens the file `relative` names inside the folder ([`check_relative`]) for reading:
    /// every component is opened from the one before it without following a symbolic link, the
    /// file without blocking, and it must be a regular file.
    pub fn open_file(&self, relative: &str) -> io::Result<File> {
        check_relative(relative).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        let parts: Vec<&str> = relative.split('/').collect();
        let (name, folders) = parts.split_last().expect("check_relative refuses an empty path");
        let mut opened: Option<OwnedFd> = None;
        for part in folders {
            let at = opened.as_ref().map_or(self.dir.as_fd(), AsFd::as_fd);
            let flags = OFlags::RDONLY | OFlags::DIRECTORY | OFlags::NOFOLLOW | OFlags::CLOEXEC | OFlags::NONBLOCK;
            let next = rustix::fs::openat(at, *part, flags, Mode::empty()).map_err(|e| component_error(e, part))?;
            opened = Some(next);
        }
        let at = opened.as_ref().map_or(self.dir.as_fd(), AsFd::as_fd);
        let fd = rustix::fs::openat(at, *name, read_flags() | OFlags::NOFOLLOW, Mode::empty())
            .map_err(|e| component_error(e, name))?;
        regular(File::from(fd))
    }

    /// The bytes of the file `relative` names inside the folder ([`Folder::open_file`]), which
    /// must hold at most `limit` bytes ([`read_to_end`]).
    pub fn read(&self, relative: &str, limit: u64) -> io::Result<Vec<u8>> {
        read_to_end(self.open_file(relative)?, limit)
    }

    /// Removes the regular file the folder holds under the plain name `name` (one component, no
    /// `/`). Anything else under that name (a link, a folder, a FIFO) is left as it is and is an
    /// error; a missing file is `NotFound`. A link that replaces the file meanwhile is removed
    /// itself, never followed: the removal is `unlinkat(2)` in this folder.
    pub fn remove_file(&self, name: &str) -> io::Result<()> {
        check_relative(name).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        if name.contains('/') {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("{name:?} is not a plain file name")));
        }
        let stat = rustix::fs::statat(&self.dir, name, AtFlags::SYMLINK_NOFOLLOW)?;
        let kind = rustix::fs::FileType::from_raw_mode(stat.st_mode);
        if kind != rustix::fs::FileType::RegularFile {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{}, not a regular file: left in place", describe(kind)),
            ));
        }
        rustix::fs::unlinkat(&self.dir, name, AtFlags::empty())?;
        Ok(())
    }

    /// Takes the folder's exclusive advisory lock (`flock(2)` on the folder itself) without
    /// waiting: `true` when taken, `false` when another process holds it. It is released when the
    /// `Folder` is dropped (or the process ends).
    pub fn try_lock(&self) -> io::Result<bool> {
        match rustix::fs::flock(&self.dir, FlockOperation::NonBlockingLockExclusive) {
            Ok(()) => Ok(true),
            Err(Errno::WOULDBLOCK) => Ok(false),
            Err(e) => Err(e.into()),
        }
    }

    /// Takes the folder's shared advisory lock without waiting: `true` when taken, `false` when
    /// another process holds the exclusive one ([`Folder::try_lock`], a bake). Any number of
    /// processes hold it at once; it keeps a bake from starting while they write beside one.
    pub fn try_lock_shared(&self) -> io::Result<bool> {
        match rustix::fs::flock(&self.dir, FlockOperation::NonBlockingLockShared) {
            Ok(()) => Ok(true),
            Err(Errno::WOULDBLOCK) => Ok(false),
            Err(e) => Err(e.into()),
        }
    }

    /// Makes the folder's entries durable (`fsync` of the folder): after a rename or a removal.
    pub fn sync(&self) -> io::Result<()> {
        rustix::fs::fsync(&self.dir)?;
        Ok(())
    }

    /// Another handle on the same open folder (its descriptor duplicated). Like this one, it
    /// stays on the folder wherever the folder is moved; its lock is this one's.
    pub fn try_clone(&self) -> io::Result<Folder> {
        let dir = rustix::io::fcntl_dupfd_cloexec(&self.dir, 0)?;
        Ok(Folder { dir, path: self.path.clone() })
    }

    /// Creates the file `name` (a plain name) in the folder, for writing: it must not exist
    /// (`O_EXCL`, so no link is followed either); permissions `0o666` less the umask, as
    /// `File::create` gives.
    pub fn create_new(&self, name: &str) -> io::Result<File> {
        plain(name)?;
        let flags = OFlags::WRONLY | OFlags::CREATE | OFlags::EXCL | OFlags::NOFOLLOW | OFlags::CLOEXEC;
        let fd = rustix::fs::openat(&self.dir, name, flags, Mode::from_raw_mode(0o666))?;
        Ok(File::from(fd))
    }

    /// What the folder holds under the plain name `name`, a link not followed; `None` for nothing.
    pub fn entry(&self, name: &str) -> io::Result<Option<Entry>> {
        plain(name)?;
        match rustix::fs::statat(&self.dir, name, AtFlags::SYMLINK_NOFOLLOW) {
            Ok(stat) => Ok(Some(Entry::of(rustix::fs::FileType::from_raw_mode(stat.st_mode)))),
            Err(Errno::NOENT) => Ok(None),
            Err(e) => Err(e.into()),
        }
    }

    /// The plain names the folder holds (`.` and `..` aside, and names that are not UTF-8, which
    /// no tool of ours writes), each with what it is.
    pub fn entries(&self) -> io::Result<Vec<(String, Entry)>> {
        let mut out = Vec::new();
        for entry in rustix::fs::Dir::read_from(&self.dir)? {
            let entry = entry?;
            let Ok(name) = entry.file_name().to_str() else { continue };
            if name == "." || name == ".." {
                continue;
            }
            let kind = match entry.file_type() {
                rustix::fs::FileType::Unknown => match self.entry(name)? {
                    Some(kind) => kind,
                    None => continue,
                },
                kind => Entry::of(kind),
            };
            out.push((name.to_string(), kind));
        }
        Ok(out)
    }

    /// Renames the folder's `from` to `to` (plain names, `renameat(2)` within the folder): what
    /// `to` held (anything but a non-empty folder) is replaced, a link there not followed.
    pub fn rename(&self, from: &str, to: &str) -> io::Result<()> {
        plain(from)?;
        plain(to)?;
        rustix::fs::renameat(&self.dir, from, &self.dir, to)?;
        Ok(())
    }

    /// Gives the folder's `from` the second name `to` (plain names, `linkat(2)` within the folder,
    /// a link at `from` linked itself, never followed); `to` must not exist.
    pub fn link(&self, from: &str, to: &str) -> io::Result<()> {
        plain(from)?;
        plain(to)?;
        rustix::fs::linkat(&self.dir, from, &self.dir, to, AtFlags::empty())?;
        Ok(())
    }

    /// Removes the name `name` (a plain name, `unlinkat(2)`) whatever it names except a folder:
    /// for the files a writer made itself. [`Folder::remove_file`] is for files a manifest names.
    pub fn unlink(&self, name: &str) -> io::Result<()> {
        plain(name)?;
        rustix::fs::unlinkat(&self.dir, name, AtFlags::empty())?;
        Ok(())
    }
}

/// What a name in a folder is ([`Folder::entry`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entry {
    File,
    Link,
    Folder,
    /// A FIFO, a device or a socket: what it is, in words.
    Other(&'static str),
}

impl Entry {
    fn of(kind: rustix::fs::FileType) -> Entry {
        match kind {
            rustix::fs::FileType::RegularFile => Entry::File,
            rustix::fs::FileType::Symlink => Entry::Link,
            rustix::fs::FileType::Directory => Entry::Folder,
            other => Entry::Other(describe(other)),
        }
    }
}

/// `name` must be one component of a path inside a folder ([`check_relative`], no `/`).
fn plain(name: &str) -> io::Result<()> {
    check_relative(name).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
    if name.contains('/') {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("{name:?} is not a plain file name")));
    }
    Ok(())
}

impl AsFd for Folder {
    fn as_fd(&self) -> BorrowedFd<'_> {
        self.dir.as_fd()
    }
}

/// Read-only, never blocking (a FIFO opens at once and is then refused), no controlling terminal.
fn read_flags() -> OFlags {
    OFlags::RDONLY | OFlags::NONBLOCK | OFlags::CLOEXEC | OFlags::NOCTTY
}

/// `file` if it is a regular file; otherwise an error saying what it is.
fn regular(file: File) -> io::Result<File> {
    let meta = file.metadata()?;
    if meta.file_type().is_file() {
        return Ok(file);
    }
    Err(io::Error::new(io::ErrorKind::InvalidInput, format!("{}, not a regular file", what(&meta))))
}

fn what(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a fifo (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

fn describe(kind: rustix::fs::FileType) -> &'static str {
    use rustix::fs::FileType;
    match kind {
        FileType::Symlink => "a symbolic link",
        FileType::Directory => "a folder",
        FileType::Fifo => "a fifo (named pipe)",
        FileType::CharacterDevice => "a character device",
        FileType::BlockDevice => "a block device",
        FileType::Socket => "a socket",
        _ => "a special file",
    }
}

/// What opening one component of a path inside a folder failed on, in words.
fn component_error(e: Errno, part: &str) -> io::Error {
    match e {
        // O_NOFOLLOW on a link; with O_DIRECTORY some systems say "not a directory".
        Errno::LOOP | Errno::MLINK => io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{part:?} is a symbolic link, which is not followed inside the folder"),
        ),
        Errno::NOTDIR => io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{part:?} is not a folder (or is a symbolic link, which is not followed inside the folder)"),
        ),
        other => other.into(),
    }
}

fn too_large(len: u64, limit: u64) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidData, format!("{len} bytes, more than the limit of {limit} bytes"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder() -> (tempfile::TempDir, Folder) {
        let tmp = tempfile::tempdir().unwrap();
        let folder = Folder::open(tmp.path()).unwrap();
        (tmp, folder)
    }

    fn message(e: io::Error) -> String {
        e.to_string()
    }

    /// The forged line a hostile manifest can hold: a newline and ANSI colour codes in an output path.
    #[test]
    fn printable_escapes_control_characters_only() {
        let forged = "importance\n\u{1b}[32merror: none, the bake is fine\u{1b}[0m.asset";
        let shown = printable(forged);
        assert_eq!(shown, "importance\\n\\u{1b}[32merror: none, the bake is fine\\u{1b}[0m.asset");
        assert!(!shown.chars().any(char::is_control));
        assert_eq!(printable(&shown), shown, "escaping twice changes nothing");
        for plain in ["gold-paint.binary", "über café/ø.png", "a b\\n"] {
            assert!(matches!(printable(plain), std::borrow::Cow::Borrowed(p) if p == plain), "{plain}");
        }
        assert_eq!(printable("\t\r\u{7f}\u{85}\0"), "\\t\\r\\u{7f}\\u{85}\\u{0}");
        assert_eq!(printable_path(Path::new("dir/a\nb")), "dir/a\\nb");
    }

    #[test]
    fn regular_files_are_read_with_their_bound() {
        let (tmp, folder) = folder();
        std::fs::write(tmp.path().join("a"), b"12345").unwrap();
        assert_eq!(read_regular(&tmp.path().join("a"), 5).unwrap(), b"12345");
        assert_eq!(folder.read("a", 5).unwrap(), b"12345");
        let e = message(read_regular(&tmp.path().join("a"), 4).unwrap_err());
        assert_eq!(e, "5 bytes, more than the limit of 4 bytes");
        assert_eq!(folder.read("a", 4).unwrap_err().to_string(), e);
        std::fs::create_dir(tmp.path().join("sub")).unwrap();
        std::fs::write(tmp.path().join("sub/b"), b"x").unwrap();
        assert_eq!(folder.read("sub/b", 1).unwrap(), b"x");
    }

    /// A FIFO opens at once and is refused; a device and a folder are refused; nothing blocks
    /// (a blocking open of a FIFO with no writer would hang this test).
    #[test]
    fn fifos_devices_and_folders_are_refused_without_blocking() {
        let (tmp, folder) = folder();
        let fifo = tmp.path().join("fifo");
        rustix::fs::mknodat(rustix::fs::CWD, &fifo, rustix::fs::FileType::Fifo, Mode::RUSR | Mode::WUSR, 0).unwrap();
        assert_eq!(message(read_regular(&fifo, 10).unwrap_err()), "a fifo (named pipe), not a regular file");
        assert_eq!(message(folder.read("fifo", 10).unwrap_err()), "a fifo (named pipe), not a regular file");
        let zero = Path::new("/dev/zero");
        assert_eq!(message(read_regular(zero, 10).unwrap_err()), "a character device, not a regular file");
        assert_eq!(message(read_regular(tmp.path(), 10).unwrap_err()), "a folder, not a regular file");
    }

    /// Links inside the folder are never followed, as the file or as a folder on the way;
    /// paths that leave the folder by their text are refused before any open.
    #[test]
    fn links_and_escaping_paths_are_refused_inside_a_folder() {
        let (tmp, folder) = folder();
        let outside = tempfile::tempdir().unwrap();
        std::fs::write(outside.path().join("secret"), b"not yours").unwrap();
        std::os::unix::fs::symlink(outside.path().join("secret"), tmp.path().join("file-link")).unwrap();
        std::os::unix::fs::symlink(outside.path(), tmp.path().join("dir-link")).unwrap();
        std::os::unix::fs::symlink("/dev/zero", tmp.path().join("zero")).unwrap();
        for (path, expected) in [
            ("file-link", "\"file-link\" is a symbolic link, which is not followed inside the folder"),
            ("zero", "\"zero\" is a symbolic link, which is not followed inside the folder"),
            ("dir-link/secret", "is a symbolic link"),
            ("../secret", "has a \"..\" component"),
            ("/etc/passwd", "is absolute"),
            ("a//b", "has an empty component"),
            ("./a", "has a \".\" component"),
            ("", "is empty"),
            ("a\\..\\b", "backslash"),
        ] {
            let e = message(folder.open_file(path).unwrap_err());
            assert!(e.contains(expected), "{path:?}: {e}");
        }
        // Read through the path, the same file would be there.
        assert_eq!(read_regular(&tmp.path().join("file-link"), 100).unwrap(), b"not yours");
    }

    #[test]
    fn removal_takes_regular_files_by_plain_name_only() {
        let (tmp, folder) = folder();
        let outside = tempfile::tempdir().unwrap();
        let victim = outside.path().join("victim");
        std::fs::write(&victim, b"not yours").unwrap();
        std::os::unix::fs::symlink(&victim, tmp.path().join("link")).unwrap();
        std::os::unix::fs::symlink(outside.path(), tmp.path().join("dir-link")).unwrap();
        std::fs::write(tmp.path().join("ours"), b"ours").unwrap();
        std::fs::create_dir(tmp.path().join("sub")).unwrap();

        assert!(message(folder.remove_file("link").unwrap_err()).contains("a symbolic link, not a regular file"));
        assert!(message(folder.remove_file("dir-link/victim").unwrap_err()).contains("not a plain file name"));
        assert!(message(folder.remove_file("../victim").unwrap_err()).contains(".."));
        assert!(message(folder.remove_file("sub").unwrap_err()).contains("a folder, not a regular file"));
        assert_eq!(folder.remove_file("missing").unwrap_err().kind(), io::ErrorKind::NotFound);
        folder.remove_file("ours").unwrap();
        assert!(!tmp.path().join("ours").exists());
        assert!(tmp.path().join("link").is_symlink() && tmp.path().join("sub").is_dir());
        assert_eq!(std::fs::read(&victim).unwrap(), b"not yours");
    }

    #[test]
    fn one_lock_per_folder_at_a_time() {
        let (tmp, first) = folder();
        assert!(first.try_lock().unwrap());
        let second = Folder::open(tmp.path()).unwrap();
        assert!(!second.try_lock().unwrap(), "a second open of the folder must not get the lock");
        drop(first);
        assert!(second.try_lock().unwrap(), "the lock goes with the folder that held it");
    }

    #[test]
    fn create_makes_the_folder_itself_only() {
        let tmp = tempfile::tempdir().unwrap();
        Folder::create(&tmp.path().join("new")).unwrap();
        Folder::create(&tmp.path().join("new")).unwrap();
        let e = message(Folder::create(&tmp.path().join("missing/new")).unwrap_err());
        assert!(e.contains("parent folder") && e.contains("does not exist"), "{e}");
        assert!(!tmp.path().join("missing").exists());
        std::fs::write(tmp.path().join("file"), b"").unwrap();
        assert_eq!(message(Folder::open(&tmp.path().join("file")).unwrap_err()), "not a folder");
    }

    #[test]
    fn relative_paths() {
        for good in ["a", "a/b", "a.b/c..d", "...", "é"] {
            assert_eq!(check_relative(good), Ok(()), "{good}");
        }
        for bad in ["", "/a", "a/", "a/../b", "..", ".", "a\\b", "\\a", "a\0"] {
            assert!(check_relative(bad).is_err(), "{bad:?}");
        }
    }
}
