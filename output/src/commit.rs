//! Writing checked outputs all or none: stage, rename, write in place, then streams; on an
//! error before the streams, undo everything done so far.

use std::collections::BTreeSet;
use std::fs::{self, File, Metadata, OpenOptions, Permissions};
use std::io::{self, Write};
use std::os::unix::fs::{MetadataExt, PermissionsExt, fchown};
use std::path::{Path, PathBuf};

use crate::check::{Action, Planned};
use crate::error::WriteError;
use crate::target::dir_of;
use crate::{temp, testing};

/// A temporary written and synced, waiting for its rename.
struct Staged {
    /// Index of the output.
    index: usize,
    temp: PathBuf,
    path: PathBuf,
    existed: bool,
    /// The temporary's inode, to recognise it after the rename.
    ino: u64,
}

/// A file replaced by its temporary (the undo of the rename is registered with it in
/// [`temp`], where a signal finds it too).
struct Replaced {
    /// A hard link to the file that was replaced (none if the file was new, or if the link
    /// could not be made).
    backup: Option<PathBuf>,
}

/// A file written in place, with its old contents if they could be read.
struct Rewritten {
    path: PathBuf,
    old: Option<Vec<u8>>,
}

/// What has been done so far, to undo it.
#[derive(Default)]
struct Transaction {
    /// Its number in the registry of renames to undo ([`temp::transaction`]).
    id: u64,
    created_dirs: Vec<PathBuf>,
    staged: Vec<Staged>,
    replaced: Vec<Replaced>,
    rewritten: Vec<Rewritten>,
}

/// Writes `contents[i]` to `planned[i]` for every `i`, all or none (see the crate docs).
pub(crate) fn write(planned: &[Planned], contents: &[&[u8]]) -> Result<(), WriteError> {
    let mut tx = Transaction {
        id: temp::transaction(),
        ..Transaction::default()
    };
    if let Err(e) = tx.files(planned, contents) {
        tx.roll_back();
        return Err(e);
    }
    tx.commit();
    streams(planned, contents)
}

impl Transaction {
    /// Every regular file, in place.
    fn files(&mut self, planned: &[Planned], contents: &[&[u8]]) -> Result<(), WriteError> {
        for p in planned {
            if let Some(dir) = &p.create_dir {
                self.create_dir(dir)
                    .map_err(|e| WriteError::cannot(&p.label, &p.target, e))?;
            }
        }
        for (index, (p, data)) in planned.iter().zip(contents).enumerate() {
            if let Action::Replace { path, old } = &p.action {
                self.stage(index, path, old.as_ref(), data)
                    .map_err(|e| WriteError::cannot(&p.label, &p.target, e))?;
            }
        }
        testing::after_staging();
        self.rename_all().map_err(|(index, e)| {
            WriteError::cannot(&planned[index].label, &planned[index].target, e)
        })?;
        for (p, data) in planned.iter().zip(contents) {
            if let Action::InPlace { path } = &p.action {
                self.rewrite(path, data)
                    .map_err(|e| WriteError::cannot(&p.label, &p.target, e))?;
            }
        }
        Ok(())
    }

    /// Creates `dir` and its missing parents, remembering which were created.
    fn create_dir(&mut self, dir: &Path) -> io::Result<()> {
        let mut missing = Vec::new();
        let mut current = dir;
        while fs::symlink_metadata(current).is_err() {
            missing.push(current.to_path_buf());
            match current.parent() {
                Some(p) if !p.as_os_str().is_empty() => current = p,
                _ => break,
            }
        }
        for d in missing.into_iter().rev() {
            if let Some(created) = temp::create_dir(&d)? {
                self.created_dirs.push(created);
            }
        }
        Ok(())
    }

    /// Writes `data` to a new temporary beside `path`, with the mode and owner of `old`, synced.
    fn stage(
        &mut self,
        index: usize,
        path: &Path,
        old: Option<&Metadata>,
        data: &[u8],
    ) -> io::Result<()> {
        let name = path
            .file_name()
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "no file name"))?;
        // Private until its final mode is set, when it replaces a file; a new file gets the
        // mode a shell would give it (0o666 less the umask).
        let mode = if old.is_some() { 0o600 } else { 0o666 };
        let (mut file, temp) = temp::create(dir_of(path), name, mode)?;
        self.staged.push(Staged {
            index,
            temp,
            path: path.to_path_buf(),
            existed: old.is_some(),
            ino: 0,
        });
        file.write_all(data)?;
        if let Some(old) = old {
            keep_owner(&file, old);
            file.set_permissions(Permissions::from_mode(old.mode() & 0o7777))?;
        }
        file.sync_all()?;
        let ino = file.metadata()?.ino();
        if let Some(s) = self.staged.last_mut() {
            s.ino = ino;
        }
        Ok(())
    }

    /// Renames every staged temporary over its file, keeping a backup link of each file
    /// replaced; on an error, the output's index and the error.
    fn rename_all(&mut self) -> Result<(), (usize, io::Error)> {
        let mut dirs = BTreeSet::new();
        while !self.staged.is_empty() {
            let s = self.staged.remove(0);
            let dir = dir_of(&s.path).to_path_buf();
            let backup = match (s.existed, s.path.file_name()) {
                (true, Some(name)) => temp::backup(&s.path, &dir, name).ok(),
                _ => None,
            };
            if let Err(e) = temp::replace(
                self.id,
                &s.temp,
                &s.path,
                backup.as_deref(),
                s.existed,
                s.ino,
            ) {
                if let Some(b) = &backup {
                    temp::remove(b);
                }
                let index = s.index;
                self.staged.insert(0, s);
                return Err((index, e));
            }
            self.replaced.push(Replaced { backup });
            testing::after_rename();
            dirs.insert(dir);
        }
        // Makes the renames durable (best effort: not every file system syncs directories).
        for dir in dirs {
            if let Ok(d) = File::open(&dir) {
                let _ = d.sync_all();
            }
        }
        Ok(())
    }

    /// Truncates the hard-linked file `path` and writes `data` into it, keeping its old
    /// contents for an undo.
    fn rewrite(&mut self, path: &Path, data: &[u8]) -> io::Result<()> {
        let old = fs::read(path).ok();
        let mut file = OpenOptions::new().write(true).open(path)?;
        self.rewritten.push(Rewritten {
            path: path.to_path_buf(),
            old,
        });
        file.set_len(0)?;
        file.write_all(data)?;
        file.sync_all()
    }

    /// Every file is in place: the backups go.
    fn commit(self) {
        let backups: Vec<PathBuf> = self
            .replaced
            .iter()
            .filter_map(|r| r.backup.clone())
            .collect();
        temp::commit_renames(self.id, &backups);
        for d in &self.created_dirs {
            temp::keep_dir(d);
        }
    }

    /// Undoes everything done so far, newest first (best effort).
    fn roll_back(self) {
        for r in self.rewritten.iter().rev() {
            if let Some(old) = &r.old {
                let _ = OpenOptions::new()
                    .write(true)
                    .open(&r.path)
                    .and_then(|mut f| {
                        f.set_len(0)?;
                        f.write_all(old)?;
                        f.sync_all()
                    });
            }
        }
        // The renames, newest first: backups put back, new files removed (only the file this
        // call created, not one that appeared since).
        temp::undo_renames(self.id);
        for s in &self.staged {
            temp::remove(&s.temp);
        }
        for d in self.created_dirs.iter().rev() {
            temp::remove_dir(d);
        }
    }
}

/// Gives the new file the owner and group of the old one where permitted (an ordinary user
/// cannot give a file away; the group alone may still be allowed).
fn keep_owner(file: &File, old: &Metadata) {
    let same = file
        .metadata()
        .is_ok_and(|m| m.uid() == old.uid() && m.gid() == old.gid());
    if !same && fchown(file, Some(old.uid()), Some(old.gid())).is_err() {
        let _ = fchown(file, None, Some(old.gid()));
    }
}

/// Writes the FIFOs, devices and standard output, in order, after every file is in place.
fn streams(planned: &[Planned], contents: &[&[u8]]) -> Result<(), WriteError> {
    for (p, data) in planned.iter().zip(contents) {
        let result = match &p.action {
            Action::Stream { path } => OpenOptions::new()
                .write(true)
                .open(path)
                .and_then(|mut f| f.write_all(data)),
            Action::Stdout => {
                let mut out = io::stdout().lock();
                out.write_all(data).and_then(|()| out.flush())
            }
            Action::Replace { .. } | Action::InPlace { .. } => Ok(()),
        };
        result.map_err(|e| WriteError::cannot(&p.label, &p.target, e))?;
    }
    Ok(())
}
