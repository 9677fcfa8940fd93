//! Temporary files: unpredictable names, created without ever following a link, and registered
//! process-wide (with the directories created for outputs) so that every error path and a
//! terminating signal can remove them.
//!
//! A temporary is `.{name}.rtest-{16 hex digits}.tmp` in the directory of the file it will
//! replace (so that the final `rename` stays on one file system); the backup hard link of a file
//! about to be replaced is `.{name}.rtest-{16 hex digits}.bak`. The hex digits come from
//! [`RandomState`] (seeded by the operating system) hashing the process id, the time and a
//! counter. Names are created with `O_CREAT | O_EXCL` (`create_new`) or `link`, which fail on
//! anything already there — a symbolic link planted at the name included — and are then retried
//! with fresh digits.
//!
//! Every operation that creates, renames away or removes a registered path holds the registry's
//! lock, and so does the signal watcher while it removes them all and terminates the process:
//! no temporary can appear or vanish between the watcher's sweep and the process's death.

use std::collections::hash_map::RandomState;
use std::ffi::{OsStr, OsString};
use std::fs::{self, File, OpenOptions};
use std::hash::{BuildHasher, Hasher};
use std::io;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::os::unix::fs::MetadataExt;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{SystemTime, UNIX_EPOCH};

use crate::{signals, testing};

/// How many names are tried before giving up (each collision needs a file already at a name
/// with 64 random bits).
const ATTEMPTS: usize = 100;

/// The longest part of the target's name kept in a temporary's name, so that the temporary's
/// name stays within the 255 bytes a directory entry allows.
const NAME_BYTES: usize = 200;

/// How to undo one rename of a temporary over its file.
enum Step {
    /// Put the backup link of the file's old contents back.
    Restore { backup: PathBuf, target: PathBuf },
    /// Remove the file, which did not exist before (if it is still the one made, inode `ino`).
    Created { target: PathBuf, ino: u64 },
}

/// The undo of one rename, with the transaction it belongs to (several `write_all` may run at
/// once in one process, on several threads).
struct Undo {
    transaction: u64,
    step: Step,
}

/// A fresh transaction number for [`replace`], [`undo_renames`] and [`commit_renames`].
pub(crate) fn transaction() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// What this process has created and not yet kept or removed, as absolute paths.
pub(crate) struct Live {
    /// Temporaries and backups.
    files: Vec<PathBuf>,
    /// Directories created for outputs (removed only if empty).
    dirs: Vec<PathBuf>,
    /// The renames of a transaction not yet committed, oldest first.
    undo: Vec<Undo>,
}

impl Live {
    /// Undoes the renames not yet committed of `transaction` (every one for `None`), newest
    /// first (a backup that cannot be put back is the only copy of the old contents: it stays,
    /// forgotten).
    fn undo_renames(&mut self, transaction: Option<u64>) {
        let mut i = self.undo.len();
        while i > 0 {
            i -= 1;
            if transaction.is_some_and(|t| self.undo[i].transaction != t) {
                continue;
            }
            match self.undo.remove(i).step {
                Step::Restore { backup, target } => {
                    // Put back, or left where it is if that fails: forgotten either way.
                    let _ = fs::rename(&backup, &target);
                    self.files.retain(|p| *p != backup);
                }
                Step::Created { target, ino } => {
                    if fs::symlink_metadata(&target).is_ok_and(|m| m.ino() == ino) {
                        let _ = fs::remove_file(&target);
                    }
                }
            }
        }
    }

    /// Undoes the renames not yet committed, then removes every registered temporary and every
    /// registered directory that is empty, newest first; the caller keeps the lock so that
    /// nothing new can be created after.
    pub(crate) fn remove_all(&mut self) {
        self.undo_renames(None);
        for path in self.files.drain(..) {
            let _ = fs::remove_file(path);
        }
        for dir in self.dirs.drain(..).rev() {
            let _ = fs::remove_dir(dir);
        }
    }
}

static LIVE: Mutex<Live> = Mutex::new(Live {
    files: Vec::new(),
    dirs: Vec::new(),
    undo: Vec::new(),
});

/// The registry, locked; a panic elsewhere while holding it does not make it unusable.
pub(crate) fn lock() -> MutexGuard<'static, Live> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The name of a temporary (`suffix` `tmp`) or backup (`bak`) for a file `name`, with `bits` as
/// its unpredictable part.
pub(crate) fn name_for(name: &OsStr, bits: u64, suffix: &str) -> OsString {
    let bytes = name.as_bytes();
    let kept = &bytes[..bytes.len().min(NAME_BYTES)];
    let mut out = Vec::with_capacity(kept.len() + 32);
    out.push(b'.');
    out.extend_from_slice(kept);
    out.extend_from_slice(format!(".rtest-{bits:016x}.{suffix}").as_bytes());
    OsString::from_vec(out)
}

/// 64 bits nobody can guess: the process's random hasher keys over the pid, the time and a
/// counter (or the test hook's bits).
fn random_bits() -> u64 {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    if let Some(bits) = testing::next_name_bits() {
        return bits;
    }
    let mut h = RandomState::new().build_hasher();
    h.write_u32(std::process::id());
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    h.write_u128(now);
    h.write_u64(COUNTER.fetch_add(1, Ordering::Relaxed));
    h.finish()
}

/// Tries fresh names in `dir` until `make` succeeds on one that did not exist; registers it.
fn create_with(
    dir: &Path,
    name: &OsStr,
    suffix: &str,
    mut make: impl FnMut(&Path) -> io::Result<()>,
) -> io::Result<PathBuf> {
    let dir = std::path::absolute(dir)?;
    let mut live = lock();
    signals::install();
    for _ in 0..ATTEMPTS {
        let path = dir.join(name_for(name, random_bits(), suffix));
        match make(&path) {
            Ok(()) => {
                live.files.push(path.clone());
                return Ok(path);
            }
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::AlreadyExists,
        "no free name for a temporary file",
    ))
}

/// Creates and registers a new empty temporary for a file `name` in `dir`, with permission bits
/// `mode` (before the umask).
pub(crate) fn create(dir: &Path, name: &OsStr, mode: u32) -> io::Result<(File, PathBuf)> {
    let mut file = None;
    let path = create_with(dir, name, "tmp", |path| {
        file = Some(
            OpenOptions::new()
                .write(true)
                .create_new(true)
                .mode(mode)
                .open(path)?,
        );
        Ok(())
    })?;
    match file {
        Some(file) => Ok((file, path)),
        None => Err(io::Error::other("temporary file not opened")),
    }
}

/// Makes and registers a backup hard link to `file` (whose name is `name`) in `dir`.
pub(crate) fn backup(file: &Path, dir: &Path, name: &OsStr) -> io::Result<PathBuf> {
    create_with(dir, name, "bak", |path| fs::hard_link(file, path))
}

/// Renames the registered `temp` over its file `to`, forgets it, and records how to undo it in
/// `transaction`: put `backup` (a registered link to the old contents) back, or, for a file
/// that did not exist before (`existed` false), remove the new one (inode `ino`). A file that
/// existed and has no backup cannot be undone.
pub(crate) fn replace(
    transaction: u64,
    temp: &Path,
    to: &Path,
    backup: Option<&Path>,
    existed: bool,
    ino: u64,
) -> io::Result<()> {
    let mut live = lock();
    fs::rename(temp, to)?;
    live.files.retain(|p| p != temp);
    let target = to.to_path_buf();
    let step = match (backup, existed) {
        (Some(b), _) => Step::Restore {
            backup: b.to_path_buf(),
            target,
        },
        (None, false) => Step::Created { target, ino },
        (None, true) => return Ok(()),
    };
    live.undo.push(Undo { transaction, step });
    Ok(())
}

/// Undoes every rename of `transaction` not yet committed, newest first (the roll-back of a
/// failed write; a signal undoes those of every transaction).
pub(crate) fn undo_renames(transaction: u64) {
    lock().undo_renames(Some(transaction));
}

/// The renames of `transaction` are final: forgets how to undo them and removes the `backups`.
pub(crate) fn commit_renames(transaction: u64, backups: &[PathBuf]) {
    let mut live = lock();
    live.undo.retain(|u| u.transaction != transaction);
    for b in backups {
        let _ = fs::remove_file(b);
        live.files.retain(|p| p != b);
    }
}

/// Removes the registered `temp` (best effort) and forgets it.
pub(crate) fn remove(temp: &Path) {
    let mut live = lock();
    let _ = fs::remove_file(temp);
    live.files.retain(|p| p != temp);
}

/// Creates the directory `dir` and registers it; `Ok(None)` if it exists already.
pub(crate) fn create_dir(dir: &Path) -> io::Result<Option<PathBuf>> {
    let dir = std::path::absolute(dir)?;
    let mut live = lock();
    signals::install();
    match fs::create_dir(&dir) {
        Ok(()) => {
            live.dirs.push(dir.clone());
            Ok(Some(dir))
        }
        Err(e) if e.kind() == io::ErrorKind::AlreadyExists => Ok(None),
        Err(e) => Err(e),
    }
}

/// Removes the registered directory `dir` if it is empty, and forgets it.
pub(crate) fn remove_dir(dir: &Path) {
    let mut live = lock();
    let _ = fs::remove_dir(dir);
    live.dirs.retain(|d| d != dir);
}

/// Forgets the registered directory `dir`: it stays.
pub(crate) fn keep_dir(dir: &Path) {
    lock().dirs.retain(|d| d != dir);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_hidden_and_bounded() {
        let n = name_for(OsStr::new("fit.json"), 0xab, "tmp");
        assert_eq!(n, ".fit.json.rtest-00000000000000ab.tmp");
        let long = "x".repeat(255);
        assert!(name_for(OsStr::new(&long), u64::MAX, "bak").len() <= 255);
        assert_ne!(random_bits(), random_bits());
    }
}
