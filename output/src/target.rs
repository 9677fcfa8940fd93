//! What an output names ([`Target`]), and what that turns out to be on disk: symbolic links
//! followed as a shell redirection follows them, the final file classified as missing, regular
//! or a stream.

use std::convert::Infallible;
use std::ffi::{OsStr, OsString};
use std::fmt;
use std::fs::{self, Metadata};
use std::io;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Component, Path, PathBuf};
use std::str::FromStr;

use crate::error::Cause;

/// The most symbolic links followed in a row before giving up, as Linux does.
pub(crate) const MAX_LINKS: usize = 40;

/// Where one output goes: standard output, or a path.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Target {
    /// Standard output (the argument `-`).
    Stdout,
    /// A file, a symbolic link, a FIFO or a device, named by a path.
    Path(PathBuf),
}

impl Target {
    /// The target a command-line argument names: `-` is standard output, anything else a path.
    pub fn parse(arg: impl AsRef<OsStr>) -> Target {
        let arg = arg.as_ref();
        if arg == "-" {
            Target::Stdout
        } else {
            Target::Path(PathBuf::from(arg))
        }
    }

    /// The path, unless the target is standard output.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Target::Stdout => None,
            Target::Path(p) => Some(p),
        }
    }
}

/// The path as given, or `-` for standard output.
impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Stdout => f.write_str("-"),
            Target::Path(p) => write!(f, "{}", p.display()),
        }
    }
}

/// Same as [`Target::parse`] (so that `clap` parses a `Target` argument as one).
impl From<OsString> for Target {
    fn from(arg: OsString) -> Target {
        Target::parse(arg)
    }
}

/// Same as [`Target::parse`].
impl From<&OsStr> for Target {
    fn from(arg: &OsStr) -> Target {
        Target::parse(arg)
    }
}

/// Same as [`Target::parse`]; never fails.
impl FromStr for Target {
    type Err = Infallible;
    fn from_str(s: &str) -> Result<Target, Infallible> {
        Ok(Target::parse(s))
    }
}

/// What the final file of a path is, after following symbolic links.
#[derive(Debug)]
pub(crate) enum Kind {
    /// Nothing there yet (its directory exists).
    Missing,
    /// A regular file.
    Regular(Metadata),
    /// A FIFO or a device: opened and written directly.
    Stream(Metadata),
}

/// A path with its symbolic links followed.
#[derive(Debug)]
pub(crate) struct Resolved {
    /// The file actually written: the path itself, or the end of its chain of links.
    pub(crate) path: PathBuf,
    /// What is there.
    pub(crate) kind: Kind,
}

/// Who a file is, to tell whether two names are one file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Identity {
    /// An existing file: its device and inode.
    Inode(u64, u64),
    /// A file yet to be created: its canonical directory joined with its name.
    Path(PathBuf),
}

impl Resolved {
    /// Who the file is; `None` for a character device, which any number of outputs may share
    /// (writing twice to a terminal or a null device harms nothing).
    pub(crate) fn identity(&self) -> Option<Identity> {
        match &self.kind {
            Kind::Missing => Some(Identity::Path(normalize_missing(&self.path))),
            Kind::Stream(m) if m.file_type().is_char_device() => None,
            Kind::Regular(m) | Kind::Stream(m) => Some(Identity::Inode(m.dev(), m.ino())),
        }
    }
}

/// The directory a file lives in: its parent, or `.` for a bare file name.
pub(crate) fn dir_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Follows `path` as a shell redirection would and classifies the file at its end.
///
/// Symbolic links are followed one at a time (a relative link against the link's own
/// directory), at most [`MAX_LINKS`] of them. A directory, a socket, a path that names no file
/// and a missing directory are errors.
pub(crate) fn resolve(path: &Path) -> Result<Resolved, Cause> {
    let mut current = path.to_path_buf();
    for _ in 0..=MAX_LINKS {
        let meta = match fs::symlink_metadata(&current) {
            Ok(meta) => meta,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return missing(current),
            Err(e) if e.raw_os_error() == Some(libc::ENOTDIR) => {
                return Err(not_a_directory(&current, e));
            }
            Err(e) => return Err(Cause::Io(e)),
        };
        let kind = meta.file_type();
        if kind.is_symlink() {
            let link = fs::read_link(&current)?;
            current = if link.is_absolute() {
                link
            } else {
                dir_of(&current).join(link)
            };
        } else if kind.is_dir() {
            return Err(Cause::IsDirectory);
        } else if kind.is_socket() {
            return Err(Cause::Socket);
        } else if kind.is_file() {
            return Ok(Resolved {
                path: current,
                kind: Kind::Regular(meta),
            });
        } else {
            return Ok(Resolved {
                path: current,
                kind: Kind::Stream(meta),
            });
        }
    }
    Err(Cause::SymlinkLoop)
}

/// A path where nothing exists: fine if it names a file in an existing directory.
fn missing(path: PathBuf) -> Result<Resolved, Cause> {
    if path.file_name().is_none() || path.as_os_str().as_bytes().ends_with(b"/") {
        return Err(Cause::NoFileName);
    }
    let dir = dir_of(&path);
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => Ok(Resolved {
            path,
            kind: Kind::Missing,
        }),
        Ok(_) => Err(Cause::NotADirectory(dir.to_path_buf())),
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            Err(Cause::MissingDirectory(dir.to_path_buf()))
        }
        Err(e) if e.raw_os_error() == Some(libc::ENOTDIR) => Err(not_a_directory(dir, e)),
        Err(e) => Err(Cause::Io(e)),
    }
}

/// The cause of `ENOTDIR` for `path`: the nearest ancestor that exists and is not a directory.
pub(crate) fn not_a_directory(path: &Path, error: io::Error) -> Cause {
    path.ancestors()
        .skip(1)
        .filter(|a| !a.as_os_str().is_empty())
        .find(|a| fs::metadata(a).is_ok_and(|m| !m.is_dir()))
        .map(|a| Cause::NotADirectory(a.to_path_buf()))
        .unwrap_or(Cause::Io(error))
}

/// A path that may not exist yet, made comparable: the canonical form of its longest existing
/// ancestor joined with the rest.
pub(crate) fn normalize_missing(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let parts: Vec<Component> = absolute.components().collect();
    for known in (1..=parts.len()).rev() {
        let Ok(mut out) = fs::canonicalize(parts[..known].iter().collect::<PathBuf>()) else {
            continue;
        };
        // What follows does not exist, so holds no link: `..` is lexical there.
        for part in &parts[known..] {
            match part {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(name) => out.push(name),
                _ => {}
            }
        }
        return out;
    }
    absolute
}

/// Who the file at `path` is, following symbolic links: an existing file by inode, a missing one
/// by its normalized path.
pub(crate) fn identity_of_path(path: &Path) -> Identity {
    match fs::metadata(path) {
        Ok(m) => Identity::Inode(m.dev(), m.ino()),
        Err(_) => Identity::Path(normalize_missing(path)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_dash_is_stdout() {
        assert_eq!(Target::parse("-"), Target::Stdout);
        assert_eq!(Target::parse("./-"), Target::Path("./-".into()));
        assert_eq!(Target::parse("a.csv").to_string(), "a.csv");
        assert_eq!("-".parse::<Target>(), Ok(Target::Stdout));
    }

    #[test]
    fn names_without_a_file() {
        for p in ["", "no-such-dir-rtest/", "no-such-dir-rtest/.."] {
            assert!(
                matches!(resolve(Path::new(p)), Err(Cause::NoFileName)),
                "{p:?}"
            );
        }
        assert!(matches!(resolve(Path::new("/")), Err(Cause::IsDirectory)));
    }
}
