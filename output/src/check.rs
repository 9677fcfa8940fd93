//! The checks made before anything changes: what each output will be written as, whether it can
//! be, whether two outputs name one file, and whether an output names an input.

use std::ffi::{CString, OsStr};
use std::fs::{self, File, OpenOptions};
use std::io;
use std::os::fd::AsFd;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::MetadataExt;
use std::path::{Component, Path, PathBuf};

use crate::error::{Cause, WriteError};
use crate::target::{
    Identity, Kind, Resolved, Target, dir_of, identity_of_path, normalize_missing, resolve,
};

/// How one output will be written.
#[derive(Debug)]
pub(crate) enum Action {
    /// Atomic replacement through a temporary in the file's directory; `old` is the file
    /// replaced, if there is one (its mode and owner are kept).
    Replace {
        path: PathBuf,
        old: Option<fs::Metadata>,
    },
    /// A regular file with other hard links: truncated and written in place.
    InPlace { path: PathBuf },
    /// A FIFO or a device: opened for writing and written, nothing else.
    Stream { path: PathBuf },
    /// Standard output.
    Stdout,
}

/// One output, checked.
#[derive(Debug)]
pub(crate) struct Planned {
    pub(crate) label: String,
    pub(crate) target: Target,
    pub(crate) action: Action,
    /// Who the file is, to find two outputs naming one file (`None`: outputs may share it).
    pub(crate) identity: Option<Identity>,
    /// A directory to create first (`add_in_dir` with a directory that does not exist yet).
    pub(crate) create_dir: Option<PathBuf>,
}

/// Checks one output named by `target`.
pub(crate) fn plan_target(label: &str, target: &Target) -> Result<Planned, WriteError> {
    let fail = |cause: Cause| WriteError::cannot(label, target, cause);
    let path = match target {
        Target::Stdout => {
            return Ok(Planned {
                label: label.to_string(),
                target: Target::Stdout,
                action: Action::Stdout,
                identity: stdout_identity(),
                create_dir: None,
            });
        }
        Target::Path(p) => p,
    };
    let resolved = resolve(path).map_err(fail)?;
    let identity = resolved.identity();
    let Resolved { path, kind } = resolved;
    let action = match kind {
        Kind::Missing => {
            dir_writable(dir_of(&path)).map_err(fail)?;
            Action::Replace { path, old: None }
        }
        Kind::Regular(meta) if meta.nlink() > 1 => {
            open_for_write(&path).map_err(fail)?;
            Action::InPlace { path }
        }
        Kind::Regular(meta) => {
            // Refused exactly where `> file` would be refused, although a rename could replace
            // a read-only file.
            open_for_write(&path).map_err(fail)?;
            dir_writable(dir_of(&path)).map_err(fail)?;
            Action::Replace {
                path,
                old: Some(meta),
            }
        }
        Kind::Stream(_) => {
            // Not opened here: opening a FIFO waits for its reader, and opening some devices
            // does something.
            access(&path, libc::W_OK).map_err(fail)?;
            Action::Stream { path }
        }
    };
    Ok(Planned {
        label: label.to_string(),
        target: target.clone(),
        action,
        identity,
        create_dir: None,
    })
}

/// Checks the output `name` in directory `dir`, which is created if it does not exist.
pub(crate) fn plan_in_dir(label: &str, dir: &Path, name: &str) -> Result<Planned, WriteError> {
    let path = dir.join(name);
    let target = Target::Path(path.clone());
    let plain = Path::new(name).components().collect::<Vec<_>>();
    if !matches!(plain.as_slice(), [Component::Normal(n)] if *n == OsStr::new(name)) {
        return Err(WriteError::cannot(label, &target, Cause::NoFileName));
    }
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => plan_target(label, &target),
        Ok(_) => Err(WriteError::cannot(
            label,
            &target,
            Cause::NotADirectory(dir.to_path_buf()),
        )),
        Err(e)
            if e.kind() == io::ErrorKind::NotFound || e.raw_os_error() == Some(libc::ENOTDIR) =>
        {
            check_dir(label, dir).map_err(|e| match e {
                WriteError::Cannot { label, cause, .. } => WriteError::Cannot {
                    label,
                    target: target.clone(),
                    cause,
                },
                other => other,
            })?;
            Ok(Planned {
                label: label.to_string(),
                identity: Some(Identity::Path(normalize_missing(&path))),
                target,
                action: Action::Replace { path, old: None },
                create_dir: Some(dir.to_path_buf()),
            })
        }
        Err(e) => Err(WriteError::cannot(label, &target, e)),
    }
}

/// Checks that `dir` is a directory new files can be created in, or that it does not exist yet
/// and can be created (its nearest existing ancestor is a writable directory).
pub fn check_dir(label: &str, dir: &Path) -> Result<(), WriteError> {
    let target = Target::Path(dir.to_path_buf());
    let fail = |cause: Cause| WriteError::cannot(label, &target, cause);
    let mut current = dir;
    loop {
        match fs::metadata(current) {
            Ok(m) if m.is_dir() => return dir_writable(current).map_err(fail),
            Ok(_) => return Err(fail(Cause::NotADirectory(current.to_path_buf()))),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            // A file somewhere above: the loop finds it.
            Err(e) if e.raw_os_error() == Some(libc::ENOTDIR) => {}
            Err(e) => return Err(fail(Cause::Io(e))),
        }
        current = match current.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            Some(_) => Path::new("."),
            None => return Err(fail(Cause::MissingDirectory(current.to_path_buf()))),
        };
    }
}

/// Checks, before the command does its work, every output it will write: each can be written,
/// no two name the same file, standard output is named at most once.
///
/// [`Outputs::write_all`](crate::Outputs::write_all) checks all this again; checking early only
/// spares the work of a command whose outputs would be refused.
pub fn check_targets(targets: &[(&str, &Target)]) -> Result<(), WriteError> {
    let planned = targets
        .iter()
        .map(|(label, target)| plan_target(label, target))
        .collect::<Result<Vec<_>, _>>()?;
    check_distinct(&planned)
}

/// Refuses two outputs naming one file, and standard output named twice.
pub(crate) fn check_distinct(planned: &[Planned]) -> Result<(), WriteError> {
    for (i, later) in planned.iter().enumerate() {
        for earlier in &planned[..i] {
            let stdouts =
                matches!(later.action, Action::Stdout) && matches!(earlier.action, Action::Stdout);
            let same = stdouts || (later.identity.is_some() && later.identity == earlier.identity);
            if !same {
                continue;
            }
            // Name the path, not standard output, when standard output is that file.
            let (named, other) = match (&later.action, &earlier.action) {
                (Action::Stdout, _) if !stdouts => (earlier, later),
                _ => (later, earlier),
            };
            let other = match other.action {
                Action::Stdout if !stdouts => format!("{} (standard output)", other.label),
                _ => other.label.clone(),
            };
            return Err(WriteError::SameOutput {
                label: named.label.clone(),
                target: named.target.clone(),
                other,
            });
        }
    }
    Ok(())
}

/// Refuses an output that names an input of the same command, before any work.
///
/// Each input is `(label, path)`, each output `(label, target)`. An output is an input when,
/// after following its symbolic links as writing would, it is the same existing file (same
/// device and inode: a hard link, a symbolic link or another spelling such as `./x.csv` of the
/// input all count) or the same canonical path.
///
/// ```
/// use output::{Target, refuse_overwriting_inputs};
/// use std::path::Path;
///
/// let input = std::env::temp_dir().join(format!("rtest-doc-input-{}.csv", std::process::id()));
/// std::fs::write(&input, "x\n").unwrap();
/// let same = Target::Path(input.clone());
/// let err = refuse_overwriting_inputs(&[("--data", &input)], &[("--json", &same)]).unwrap_err();
/// assert!(err.to_string().ends_with("is also the input of --data: refusing to overwrite an input"));
/// let other = Target::Path(input.with_extension("json"));
/// assert!(refuse_overwriting_inputs(&[("--data", &input)], &[("--json", &other)]).is_ok());
/// std::fs::remove_file(&input).unwrap();
/// ```
pub fn refuse_overwriting_inputs(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, &Target)],
) -> Result<(), WriteError> {
    let inputs: Vec<(&str, Identity)> = inputs
        .iter()
        .map(|(label, path)| (*label, identity_of_path(path)))
        .collect();
    for (label, target) in outputs {
        let Target::Path(path) = target else { continue };
        // An output that cannot be resolved is reported by the write itself.
        let Some(identity) = resolve(path).ok().and_then(|r| r.identity()) else {
            continue;
        };
        if let Some((input, _)) = inputs.iter().find(|(_, id)| *id == identity) {
            return Err(WriteError::IsInput {
                label: label.to_string(),
                path: path.clone(),
                input: input.to_string(),
            });
        }
    }
    Ok(())
}

/// Refuses, before any work, an output directory that holds an input under a name the command
/// may write there: every entry of `dir` whose name `writes` accepts (the names the command
/// writes, e.g. `*.svg` for plots) is compared with the inputs as
/// [`refuse_overwriting_inputs`] compares them, so that a hard or symbolic link into the
/// directory is caught too. A directory that does not exist yet holds nothing.
///
/// ```
/// use output::refuse_inputs_in_dir;
/// let dir = std::env::temp_dir().join(format!("rtest-doc-dir-{}", std::process::id()));
/// std::fs::create_dir_all(&dir).unwrap();
/// let input = dir.join("k4-path.svg");
/// std::fs::write(&input, "x\n").unwrap();
/// let svg = |name: &str| name.ends_with(".svg");
/// let e = refuse_inputs_in_dir(&[("--validate", &input)], "--plot", &dir, &svg).unwrap_err();
/// assert!(e.to_string().ends_with("is also the input of --validate: refusing to overwrite an input"));
/// assert!(refuse_inputs_in_dir(&[("--validate", &input)], "--plot", &dir, &|n: &str| n.ends_with(".png")).is_ok());
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn refuse_inputs_in_dir(
    inputs: &[(&str, &Path)],
    label: &str,
    dir: &Path,
    writes: &dyn Fn(&str) -> bool,
) -> Result<(), WriteError> {
    // A directory that cannot be listed is reported by `check_dir` or the write itself.
    let Ok(entries) = fs::read_dir(dir) else {
        return Ok(());
    };
    let written: Vec<Target> = entries
        .flatten()
        .filter_map(|e| {
            e.file_name()
                .to_str()
                .filter(|n| writes(n))
                .map(|n| dir.join(n))
        })
        .map(Target::Path)
        .collect();
    let outputs: Vec<(&str, &Target)> = written.iter().map(|t| (label, t)).collect();
    refuse_overwriting_inputs(inputs, &outputs)
}

/// Who standard output is, when it is a regular file (a command's output redirected to a file
/// that is also named as another output).
fn stdout_identity() -> Option<Identity> {
    let fd = io::stdout().as_fd().try_clone_to_owned().ok()?;
    let meta = File::from(fd).metadata().ok()?;
    meta.is_file()
        .then(|| Identity::Inode(meta.dev(), meta.ino()))
}

/// Opens an existing file for writing, without truncating or creating it, and closes it again.
fn open_for_write(path: &Path) -> Result<(), Cause> {
    OpenOptions::new().write(true).open(path)?;
    Ok(())
}

/// Whether new files can be created in `dir`.
fn dir_writable(dir: &Path) -> Result<(), Cause> {
    access(dir, libc::W_OK | libc::X_OK)
        .map_err(|e| Cause::DirectoryNotWritable(dir.to_path_buf(), io_error(e)))
}

/// `faccessat` with the effective ids, as the kernel checks an `open` (so root passes).
fn access(path: &Path, mode: libc::c_int) -> Result<(), Cause> {
    let c = CString::new(path.as_os_str().as_bytes())
        .map_err(|e| Cause::Io(io::Error::new(io::ErrorKind::InvalidInput, e)))?;
    // SAFETY: `c` is a valid NUL-terminated string that outlives the call.
    let rc = unsafe { libc::faccessat(libc::AT_FDCWD, c.as_ptr(), mode, libc::AT_EACCESS) };
    if rc == 0 {
        Ok(())
    } else {
        Err(Cause::Io(io::Error::last_os_error()))
    }
}

/// The I/O error inside a cause (for nesting one cause in another).
fn io_error(cause: Cause) -> io::Error {
    match cause {
        Cause::Io(e) => e,
        other => io::Error::other(other.to_string()),
    }
}
