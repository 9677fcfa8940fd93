//! The one error type of the crate and the causes it names.
//!
//! Every message is one line that starts with the label of the output (the flag that named it,
//! such as `--json`), so a command can print it as it is.

use std::fmt;
use std::io;
use std::path::PathBuf;

use crate::target::Target;

/// Why an output could not be written, or was refused before anything changed.
///
/// The [`Display`](fmt::Display) form is one line, e.g.
/// ``--json: cannot write `out/fit.json`: the directory `out` does not exist``.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The output cannot be written, for the reason in `cause`.
    #[error("{label}: cannot write {}: {cause}", Shown(target))]
    Cannot {
        /// The flag that named the output (`--json`, `-o`, `--plot`).
        label: String,
        /// The output as the user named it.
        target: Target,
        /// Why.
        cause: Cause,
    },
    /// The output names a file that is also an input of the same command.
    #[error(
        "{label}: `{}` is also the input of {input}: refusing to overwrite an input",
        path.display()
    )]
    IsInput {
        /// The flag that named the output.
        label: String,
        /// The output path as the user named it.
        path: PathBuf,
        /// The flag (or argument name) of the input it would overwrite.
        input: String,
    },
    /// Two outputs of the same command name the same file (or standard output twice).
    #[error("{label}: {} is also the output of {other}", Shown(target))]
    SameOutput {
        /// The flag of the later output.
        label: String,
        /// The later output as the user named it.
        target: Target,
        /// The flag of the earlier output naming the same file.
        other: String,
    },
}

impl WriteError {
    /// True when the error is the user's choice of outputs (two outputs naming one file, an
    /// output naming an input, a path that names no file), as opposed to the state of the file
    /// system; a command may report the two with different exit codes.
    pub fn is_usage(&self) -> bool {
        match self {
            WriteError::Cannot { cause, .. } => matches!(cause, Cause::NoFileName),
            WriteError::IsInput { .. } | WriteError::SameOutput { .. } => true,
        }
    }

    /// The label (flag) of the output the error is about.
    pub fn label(&self) -> &str {
        match self {
            WriteError::Cannot { label, .. }
            | WriteError::IsInput { label, .. }
            | WriteError::SameOutput { label, .. } => label,
        }
    }

    pub(crate) fn cannot(label: &str, target: &Target, cause: impl Into<Cause>) -> WriteError {
        WriteError::Cannot {
            label: label.to_string(),
            target: target.clone(),
            cause: cause.into(),
        }
    }
}

/// Why an output cannot be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Cause {
    /// The target is a directory.
    #[error("it is a directory")]
    IsDirectory,
    /// The path names no file (`..`, `/`, an empty path, or a path ending in `/` that is not a
    /// directory).
    #[error("it does not name a file")]
    NoFileName,
    /// The directory the file would be in does not exist.
    #[error("the directory `{}` does not exist", .0.display())]
    MissingDirectory(PathBuf),
    /// What should be the file's directory is not a directory.
    #[error("`{}` is not a directory", .0.display())]
    NotADirectory(PathBuf),
    /// New files cannot be created in the file's directory (needed for the temporary file of an
    /// atomic replacement).
    #[error("cannot create files in the directory `{}`: {}", .0.display(), Plain(.1))]
    DirectoryNotWritable(PathBuf, io::Error),
    /// The target is a socket, which cannot be opened as a file.
    #[error("it is a socket")]
    Socket,
    /// Following symbolic links did not end (a loop, or more than 40 links in a row).
    #[error("too many levels of symbolic links")]
    SymlinkLoop,
    /// Any other error of the operating system.
    #[error("{}", Plain(.0))]
    Io(#[from] io::Error),
}

/// An output for messages: a path in backticks, or "standard output".
pub(crate) struct Shown<'a>(pub(crate) &'a Target);

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Target::Stdout => f.write_str("standard output"),
            Target::Path(p) => write!(f, "`{}`", p.display()),
        }
    }
}

/// An I/O error as words: "permission denied" rather than "Permission denied (os error 13)".
struct Plain<'a>(&'a io::Error);

impl fmt::Display for Plain<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = self.0.to_string();
        let text = match text.rfind(" (os error ") {
            Some(i) if text.ends_with(')') => &text[..i],
            _ => &text,
        };
        let mut chars = text.chars();
        match chars.next() {
            Some(first) => {
                write!(f, "{}{}", first.to_lowercase(), chars.as_str())
            }
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_one_line() {
        let e = WriteError::cannot(
            "--json",
            &Target::Path("out/fit.json".into()),
            Cause::MissingDirectory("out".into()),
        );
        assert_eq!(
            e.to_string(),
            "--json: cannot write `out/fit.json`: the directory `out` does not exist"
        );
        let e = WriteError::cannot(
            "-o",
            &Target::Stdout,
            io::Error::from_raw_os_error(libc::EPIPE),
        );
        assert_eq!(
            e.to_string(),
            "-o: cannot write standard output: broken pipe"
        );
        let e = WriteError::IsInput {
            label: "--json".into(),
            path: "x.csv".into(),
            input: "--data".into(),
        };
        assert_eq!(
            e.to_string(),
            "--json: `x.csv` is also the input of --data: refusing to overwrite an input"
        );
        assert!(e.is_usage());
    }
}
