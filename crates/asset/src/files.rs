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
/// one. A switch an earlier run left interrupted is first finished or undone
/// ([`recover_switch`]), and the temporary files it left for these names (`.NAME.XXXXXX.tmp`)
/// are removed. The caller holds the folder (its lock) for both.
///
/// `dir` is created if it is missing, the folder itself only: its parent must exist.
///
/// Errors name the target file the caller asked for, never a temporary one.
pub fn write_set(dir: &Path, files: &[(&str, &[u8])]) -> Result<(), (PathBuf, std::io::Error)> {
    let folder = fsguard::Folder::create(dir).map_err(|e| (dir.to_path_buf(), e))?;
    let names: Vec<&str> = files.iter().map(|(name, _)| *name).collect();
    recover_switch(&folder).map_err(|e| (dir.to_path_buf(), e))?;
    remove_temporaries(&folder, |target| names.contains(&target) || target == SWITCH_JOURNAL)
        .map_err(|e| (dir.to_path_buf(), e))?;
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
    /// 2. The switch's steps are planned, each old file's temporary name (`.NAME.XXXXXX.tmp`)
    ///    chosen, and written to the folder's journal ([`SWITCH_JOURNAL`], synced) before any of
    ///    them is taken.
    /// 3. The old index (the last file added, which names the others) is set aside: it leaves its
    ///    name, which no reader then finds, and the folder is synced. Every other file is renamed
    ///    over its target in the order added, the old file kept under its planned name (a second
    ///    link to it); then the retired files are set aside, `before_index` runs, and the index is
    ///    renamed into place; the folder is synced.
    /// 4. The journal is removed, then the old files kept aside.
    ///
    /// If anything fails in 3, every step already taken is undone from the journal: each old
    /// file is renamed back over its name (the new one removed where there was none) and the old
    /// index is put back, so the folder lists the previous set again. An interruption (a kill)
    /// leaves the journal: [`recover_switch`], which the next holder of the folder runs first,
    /// undoes the switch if the new index had not landed and finishes it if it had. Either way the
    /// folder then holds one whole set, listed by its index.
    pub fn commit(
        mut self,
        before_index: impl FnOnce() -> Result<(), (PathBuf, std::io::Error)>,
    ) -> Result<(), (PathBuf, std::io::Error)> {
        let mut files = std::mem::take(&mut self.files);
        let retired = std::mem::take(&mut self.retired);
        let folder = &self.folder;
        let at = |name: &str, e: std::io::Error| (folder.join(name), e);
        let Some((index, index_temporary)) = files.pop() else { return Ok(()) };
        // Until the journal takes them over, dropping a temporary file (an early return) removes it.
        let pending: Vec<Pending> = files.iter().map(|(_, t)| Pending::new(folder, t)).collect();
        let index_pending = Pending::new(folder, &index_temporary);
        for (name, _) in &files {
            check_replaceable(folder, name).map_err(|e| at(name, e))?;
        }
        check_index_replaceable(folder, &index).map_err(|e| at(&index, e))?;
        for name in &retired {
            check_removable(folder, name).map_err(|e| at(name, e))?;
        }
        let steps = plan(folder, (&index, &index_temporary), &files, &retired).map_err(|e| at(&index, e))?;
        write_journal(folder, &steps).map_err(|e| at(SWITCH_JOURNAL, e))?;
        index_pending.landed_for_good();
        pending.into_iter().for_each(Pending::landed_for_good);
        let sync = || folder.sync().map_err(|e| (folder.path().to_path_buf(), e));
        let last = steps.len() - 1;
        let mut before_index = Some(before_index);
        let result = (|| {
            for (i, step) in steps.iter().enumerate() {
                if i == last
                    && let Some(before_index) = before_index.take()
                {
                    before_index()?;
                }
                step.take(folder).map_err(|e| at(step.target(), e))?;
                if i == 0 || i == last {
                    sync()?;
                }
            }
            Ok(())
        })();
        match result {
            Ok(()) => {
                // The new set is listed: the journal goes first, then what it kept.
                folder.unlink(SWITCH_JOURNAL).and_then(|()| folder.sync()).map_err(|e| at(SWITCH_JOURNAL, e))?;
                roll_forward(folder, &steps);
                Ok(())
            }
            Err(e) => {
                // Best effort: what cannot be undone now, recover_switch undoes from the journal.
                if roll_back(folder, &steps).is_ok() {
                    let _ = folder.unlink(SWITCH_JOURNAL).and_then(|()| folder.sync());
                }
                Err(e)
            }
        }
    }
}

/// The journal of a switch in progress ([`Staging::commit`]): its planned steps, one per line,
/// written before the first is taken and removed once the new index is in place. Its presence
/// means a switch was interrupted; [`recover_switch`] reads it.
pub const SWITCH_JOURNAL: &str = ".switch.journal";

/// The largest journal [`recover_switch`] reads: a bake's switch plans a few dozen steps.
const JOURNAL_LIMIT: u64 = 1 << 20;

/// One planned step of a switch. `kept`: the temporary name the old file at `target` is kept
/// under, `None` when nothing was there when the switch was planned.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    /// The file at `target` moved to `kept`, leaving the name free.
    Aside { target: String, kept: Option<String> },
    /// The new file `new` (a temporary file) renamed over `target`, the old one kept.
    Replace { target: String, kept: Option<String>, new: String },
}

impl Step {
    fn target(&self) -> &str {
        match self {
            Step::Aside { target, .. } | Step::Replace { target, .. } => target,
        }
    }

    fn kept(&self) -> Option<&str> {
        match self {
            Step::Aside { kept, .. } | Step::Replace { kept, .. } => kept.as_deref(),
        }
    }

    fn take(&self, folder: &fsguard::Folder) -> std::io::Result<()> {
        if let Some(kept) = self.kept() {
            keep(folder, self.target(), kept)?;
        }
        match self {
            Step::Aside { target, .. } => unlink_if_present(folder, target),
            Step::Replace { target, new, .. } => folder.rename(new, target),
        }
    }

    /// Undoes the step, whether it was taken, half taken or not at all, and whether it was
    /// undone before (a kill during an undo): the old file, if it was kept, back at `target`.
    fn undo(&self, folder: &fsguard::Folder) -> std::io::Result<()> {
        let exists = |name: &str| folder.entry(name).map(|e| e.is_some());
        let restore = |kept: &str, target: &str| -> std::io::Result<()> {
            if !exists(kept)? {
                return Ok(());
            }
            // A second link to a file still at its name, or the file itself.
            if exists(target)? { folder.unlink(kept) } else { folder.rename(kept, target) }
        };
        match self {
            Step::Aside { target, kept } => kept.as_deref().map_or(Ok(()), |kept| restore(kept, target)),
            Step::Replace { target, kept, new } if exists(new)? => {
                // Not landed: the target is the old file's (or, without hard links, free).
                folder.unlink(new)?;
                kept.as_deref().map_or(Ok(()), |kept| restore(kept, target))
            }
            Step::Replace { target, kept: Some(kept), .. } => {
                // Landed: the old file back over the new one, unless that was done before.
                if exists(kept)? { folder.rename(kept, target) } else { Ok(()) }
            }
            Step::Replace { target, kept: None, .. } => unlink_if_present(folder, target),
        }
    }

    fn line(&self) -> String {
        let kept = self.kept().unwrap_or("-");
        match self {
            Step::Aside { target, .. } => format!("aside\t{target}\t{kept}"),
            Step::Replace { target, new, .. } => format!("replace\t{target}\t{kept}\t{new}"),
        }
    }

    /// A journal line, checked: plain names, each temporary one of its target's.
    fn parse(line: &str) -> Option<Step> {
        let fields: Vec<&str> = line.split('\t').collect();
        let plain = |name: &str| !name.is_empty() && name != "." && name != ".." && !name.contains(['/', '\0']);
        let target = *fields.get(1)?;
        let of_target = |name: &str| temporary_target(name) == Some(target);
        let kept = match *fields.get(2)? {
            "-" => None,
            name if of_target(name) => Some(name.to_string()),
            _ => return None,
        };
        if !plain(target) {
            return None;
        }
        match (fields[0], fields.len()) {
            ("aside", 3) => Some(Step::Aside { target: target.to_string(), kept }),
            ("replace", 4) if of_target(fields[3]) => {
                Some(Step::Replace { target: target.to_string(), kept, new: fields[3].to_string() })
            }
            _ => None,
        }
    }
}

/// The steps of a switch (see [`Staging::commit`]): the old index aside, each file replaced, each
/// retired file aside, the new index in; a free temporary name for each old file there is.
fn plan(
    folder: &fsguard::Folder,
    (index, index_temporary): (&str, &str),
    files: &[(String, String)],
    retired: &[String],
) -> std::io::Result<Vec<Step>> {
    let mut chosen: Vec<String> = Vec::new();
    let mut kept_name = |target: &str| -> std::io::Result<Option<String>> {
        if folder.entry(target)?.is_none() {
            return Ok(None);
        }
        for _ in 0..TEMPORARY_ATTEMPTS {
            let name = temporary_name(target);
            if folder.entry(&name)?.is_none() && !chosen.contains(&name) {
                chosen.push(name.clone());
                return Ok(Some(name));
            }
        }
        Err(too_many_temporaries())
    };
    let mut steps = vec![Step::Aside { target: index.to_string(), kept: kept_name(index)? }];
    for (target, new) in files {
        steps.push(Step::Replace { target: target.clone(), kept: kept_name(target)?, new: new.clone() });
    }
    for target in retired {
        steps.push(Step::Aside { target: target.clone(), kept: kept_name(target)? });
    }
    steps.push(Step::Replace { target: index.to_string(), kept: None, new: index_temporary.to_string() });
    if steps.iter().any(|s| s.line().lines().count() != 1 || Step::parse(&s.line()).as_ref() != Some(s)) {
        return Err(std::io::Error::new(std::io::ErrorKind::InvalidInput, "a file name a journal cannot hold"));
    }
    Ok(steps)
}

/// Writes the journal of `steps` in place of any other ([`SWITCH_JOURNAL`]), synced, and syncs
/// the folder: on disk before the first step is taken.
fn write_journal(folder: &fsguard::Folder, steps: &[Step]) -> std::io::Result<()> {
    let text: String = steps.iter().map(|s| s.line() + "\n").collect();
    let temporary = write_temporary(folder, SWITCH_JOURNAL, text.as_bytes())?;
    if let Err(e) = folder.rename(&temporary, SWITCH_JOURNAL) {
        let _ = folder.unlink(&temporary);
        return Err(e);
    }
    folder.sync()
}

/// Every step undone, last first; the first error is returned after trying them all.
fn roll_back(folder: &fsguard::Folder, steps: &[Step]) -> std::io::Result<()> {
    let mut first = Ok(());
    for step in steps.iter().rev() {
        if let Err(e) = step.undo(folder)
            && first.is_ok()
        {
            first = Err(e);
        }
    }
    let _ = folder.sync();
    first
}

/// The new set is in place: the old files kept aside go.
fn roll_forward(folder: &fsguard::Folder, steps: &[Step]) {
    for kept in steps.iter().filter_map(Step::kept) {
        let _ = folder.unlink(kept);
    }
}

/// What [`recover_switch`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recovery {
    /// No switch was interrupted.
    None,
    /// The new index had not landed: the previous set is back.
    RolledBack,
    /// The new index had landed: the old files kept aside are gone.
    Finished,
}

/// Finishes or undoes a switch ([`Staging::commit`]) that an interruption left, from its journal
/// ([`SWITCH_JOURNAL`]): the folder then holds one whole set again, listed by its index. The
/// caller must hold the folder (its lock): nothing else may switch meanwhile. A journal that is
/// not a regular file, is larger than a switch writes or holds a line that is not a step (each
/// name plain, each temporary name one of its target's) is an error and nothing is touched.
pub fn recover_switch(folder: &fsguard::Folder) -> std::io::Result<Recovery> {
    let damaged = |why: String| {
        std::io::Error::new(std::io::ErrorKind::InvalidData, format!("{SWITCH_JOURNAL}: {why}: remove it by hand"))
    };
    match folder.entry(SWITCH_JOURNAL)? {
        None => return Ok(Recovery::None),
        Some(fsguard::Entry::File) => {}
        Some(_) => return Err(damaged("not a regular file".into())),
    }
    let bytes = fsguard::read_to_end(folder.open_file(SWITCH_JOURNAL)?, JOURNAL_LIMIT)?;
    let text = String::from_utf8(bytes).map_err(|_| damaged("not text".into()))?;
    let steps = text
        .lines()
        .enumerate()
        .map(|(i, line)| Step::parse(line).ok_or_else(|| damaged(format!("line {} is not a switch step", i + 1))))
        .collect::<std::io::Result<Vec<Step>>>()?;
    let landed = match steps.last() {
        Some(Step::Replace { target, kept: None, new }) => {
            folder.entry(new)?.is_none() && folder.entry(target)?.is_some()
        }
        _ => return Err(damaged("it does not end with the index's step".into())),
    };
    let recovery = if landed {
        roll_forward(folder, &steps);
        Recovery::Finished
    } else {
        roll_back(folder, &steps)?;
        Recovery::RolledBack
    };
    folder.unlink(SWITCH_JOURNAL)?;
    folder.sync()?;
    Ok(recovery)
}

impl Drop for Staging {
    /// Files staged and never committed leave no temporary file behind.
    fn drop(&mut self) {
        for (_, temporary) in &self.files {
            let _ = self.folder.unlink(temporary);
        }
    }
}

/// A temporary file of a commit that is removed when this drops, unless the switch's journal
/// took it over.
struct Pending<'a> {
    folder: &'a fsguard::Folder,
    name: Option<String>,
}

impl<'a> Pending<'a> {
    fn new(folder: &'a fsguard::Folder, name: &str) -> Pending<'a> {
        Pending { folder, name: Some(name.to_string()) }
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

/// Removes `name` from the folder; nothing there (a step taken or undone before) is nothing to do.
fn unlink_if_present(folder: &fsguard::Folder, name: &str) -> std::io::Result<()> {
    match folder.unlink(name) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// A second name `kept` for the file (or link) `target` of the folder: a hard link, or, where
/// the file system has none, the file itself renamed there. Nothing at `target` (a step taken
/// again) is nothing to do.
fn keep(folder: &fsguard::Folder, target: &str, kept: &str) -> std::io::Result<()> {
    match folder.link(target, kept) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => {
            let no_links = matches!(e.kind(), std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::Unsupported);
            let renameable = matches!(folder.entry(target)?, Some(fsguard::Entry::File | fsguard::Entry::Link));
            if no_links && renameable && folder.entry(kept)?.is_none() { folder.rename(target, kept) } else { Err(e) }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    const OLD: [(&str, &str); 3] = [("a", "old a"), ("b", "old b"), ("index", "old index")];
    const NEW: [(&str, &str); 3] = [("a", "new a"), ("c", "new c"), ("index", "new index")];

    /// The folder's files (no temporary, no journal may be left), by name.
    fn contents(folder: &fsguard::Folder) -> Vec<(String, String)> {
        let mut files: Vec<(String, String)> = folder
            .entries()
            .unwrap()
            .into_iter()
            .map(|(name, _)| {
                let text = std::fs::read_to_string(folder.join(&name)).unwrap();
                (name, text)
            })
            .collect();
        files.sort();
        files
    }

    fn set(files: &[(&str, &str)]) -> Vec<(String, String)> {
        files.iter().map(|(n, t)| (n.to_string(), t.to_string())).collect()
    }

    /// A switch from OLD to NEW (retiring `b`) killed after `taken` whole steps, with the next
    /// one half taken (its old file kept, nothing else) when `half`, and, when `undone` is given,
    /// an undo of its own killed after that many steps: what the folder holds once recovered.
    fn recovered(taken: usize, half: bool, undone: Option<usize>) -> (Recovery, Vec<(String, String)>) {
        let dir = tempfile::tempdir().unwrap();
        let folder = fsguard::Folder::open(dir.path()).unwrap();
        for (name, text) in OLD {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        let mut staging = Staging::new(&folder).unwrap();
        for (name, text) in NEW {
            staging.add(name, text.as_bytes()).unwrap();
        }
        staging.retire("b");
        let mut files = std::mem::take(&mut staging.files);
        let (index, index_temporary) = files.pop().unwrap();
        let steps = plan(&folder, (&index, &index_temporary), &files, &["b".to_string()]).unwrap();
        write_journal(&folder, &steps).unwrap();
        for step in &steps[..taken.min(steps.len())] {
            step.take(&folder).unwrap();
        }
        if half
            && let Some(step) = steps.get(taken)
            && let Some(kept) = step.kept()
        {
            keep(&folder, step.target(), kept).unwrap();
        }
        if let Some(undone) = undone {
            for step in steps.iter().rev().take(undone) {
                step.undo(&folder).unwrap();
            }
        }
        let recovery = recover_switch(&folder).unwrap();
        assert_eq!(recover_switch(&folder).unwrap(), Recovery::None, "the journal is gone");
        (recovery, contents(&folder))
    }

    #[test]
    fn a_switch_killed_at_any_step_recovers_one_whole_set() {
        // Five steps: old index aside, a replaced, c added, b retired, new index in.
        for taken in 0..=5 {
            for half in [false, true] {
                let (recovery, files) = recovered(taken, half, None);
                let expect =
                    if taken == 5 { (Recovery::Finished, set(&NEW)) } else { (Recovery::RolledBack, set(&OLD)) };
                assert_eq!((recovery, files), expect, "killed after {taken} steps (half of the next: {half})");
            }
        }
        // Killed again while undoing a failed switch: the undo is finished, whatever it had done.
        for taken in 1..=5 {
            for undone in 0..=taken {
                let (_, files) = recovered(taken, false, Some(undone));
                let whole = files == set(&OLD) || (taken == 5 && undone == 0 && files == set(&NEW));
                assert!(whole, "killed after {taken} steps, then after undoing {undone}: {files:?}");
            }
        }
    }

    #[test]
    fn a_damaged_journal_touches_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let folder = fsguard::Folder::open(dir.path()).unwrap();
        std::fs::write(dir.path().join("index"), "old index").unwrap();
        for journal in [
            "",
            "aside\tindex\t-\n",
            "replace\tindex\t-\t.other.abcdef.tmp\n",
            "aside\t../x\t-\nreplace\tindex\t-\t.index.abcdef.tmp\n",
        ] {
            std::fs::write(dir.path().join(SWITCH_JOURNAL), journal).unwrap();
            let e = recover_switch(&folder).unwrap_err();
            assert!(e.to_string().contains(SWITCH_JOURNAL), "{e}");
            assert_eq!(std::fs::read_to_string(dir.path().join("index")).unwrap(), "old index");
        }
    }
}
