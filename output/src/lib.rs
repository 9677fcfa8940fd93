//! The one writer of every file rtest writes (CSV, JSON, TOML, Rust, SVG): outputs are written
//! as a shell redirection `> target` would write them, except that a regular file is replaced
//! atomically, and the outputs of one command are written all together or not at all.
//!
//! A command collects its outputs in [`Outputs`] — each with a label, the flag that named it
//! (`--json`, `-o`, `--plot`), used in every message — and writes them with
//! [`Outputs::write_all`]. [`check_targets`] and [`check_dir`] check the targets before the
//! command does its work, and [`refuse_overwriting_inputs`] refuses an output that names one of
//! the command's inputs. Errors are [`WriteError`]s, one line each, starting with the label:
//! ``--json: cannot write `out/fit.json`: the directory `out` does not exist``. Nothing here
//! panics.
//!
//! # What happens to each kind of target
//!
//! - **A missing file, or a regular file with one link**, is replaced atomically: the new
//!   contents go to a temporary file in the target's own directory, synced to disk, and that is
//!   renamed over the target. Readers see the old file or the new one, never a part. The
//!   temporary is created with create-new semantics (`O_CREAT | O_EXCL`, which never follows a
//!   symbolic link planted at its name) under an unpredictable name,
//!   `.{name}.rtest-{16 hex digits}.tmp`. A replaced file's permission bits are kept, and so
//!   are its owner and group where the process may set them; a new file gets `0o666` less the
//!   umask, as from a shell.
//! - **A regular file with other hard links** is truncated and written in place, so that every
//!   name still shows the same (new) contents; this one is not atomic.
//! - **A symbolic link** is followed (relative links against the link's own directory, at most
//!   40 links in a row; a loop is an error) and the file at its end is written by these same
//!   rules: a regular file there is replaced atomically in *its* directory and the link stays a
//!   link; a dangling link creates the file it points to.
//! - **A FIFO or a device** is opened for writing and written: no temporary, no rename, no
//!   truncation. [`Target::Stdout`] (the argument `-`) writes to standard output.
//!
//! # Refused before anything changes
//!
//! A directory; a path whose directory does not exist (or is not a directory); a path that
//! names no file (`..`, `/`, a trailing `/`); a socket; an existing file that cannot be opened
//! for writing — a read-only file is refused exactly as `> file` refuses it, even though a
//! rename could replace it (and, as in a shell, root may write it); a file whose directory does
//! not let the process create the temporary; two outputs naming the same file (by device and
//! inode, or by canonical path for files yet to be created, so a second spelling, a symbolic
//! link or a hard link all count); standard output named twice, or standard output redirected
//! to a file that is also named as an output. [`refuse_overwriting_inputs`] adds: an output
//! that is one of the command's inputs.
//!
//! # All or none, and its limits
//!
//! [`Outputs::write_all`] checks everything above, then:
//!
//! 1. creates the directories of [`Outputs::add_in_dir`] that are missing;
//! 2. stages every temporary (written and synced); if one fails, every temporary is removed
//!    and nothing has changed;
//! 3. renames the temporaries over their targets, one after the other, each replaced file
//!    first getting a backup hard link (`.{name}.rtest-{16 hex digits}.bak`); if a rename
//!    fails, the files already replaced are put back from their backups and the files that did
//!    not exist before are removed;
//! 4. writes the hard-linked files in place; if one fails, its old contents are written back
//!    and step 3 is undone;
//! 5. removes the backups: every regular file is now in place;
//! 6. writes the FIFOs, devices and standard output, last, in the order they were added.
//!
//! On any failure in steps 1–4 the directories created in step 1 are removed again (only those
//! this call created, and only if empty) and no temporary is left. So for regular files it is
//! all or none, with these limits: the undo is best effort (a file system that stops accepting
//! writes midway may refuse it too; a backup that cannot be put back is left beside its file,
//! holding the old contents, rather than removed); a backup link cannot be made on a file
//! system without hard links, and then that file cannot be put back; a crash or `SIGKILL` in
//! steps 3–4 leaves what was done so far (SIGINT and SIGTERM undo it: see below); the checks and the writes are not one atomic step
//! against other processes changing the same files; and a stream, once written, cannot be
//! taken back — which is why streams come last and an error writing one leaves the files
//! written.
//!
//! # Signals
//!
//! Every temporary and backup, every directory created for the outputs, and the undo of every
//! rename not yet final, is registered process-wide. When the first temporary is created,
//! SIGINT and SIGTERM get a watcher (unless they are ignored or handled already): on either
//! signal it first undoes the renames of step 3 not yet final (the replaced files get their old
//! contents back from their backups, the files that did not exist are removed), then removes
//! every registered temporary (and each registered directory left empty), and then ends the
//! process by the signal's default action, so the parent still sees death by that signal. So
//! an interrupted command leaves its regular files all old, not some new and some old. An
//! in-place write of a hard-linked file (step 4) interrupted by a signal is not undone, nor is
//! a stream. No file work is done inside a signal handler. `SIGKILL` cannot be caught: it may
//! leave a temporary behind (a hidden `.*.rtest-*.tmp` file that is safe to delete).
//!
//! # Example
//!
//! ```
//! use output::{Outputs, Target};
//!
//! let dir = std::env::temp_dir().join(format!("rtest-output-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let csv = dir.join("fit.csv");
//! std::fs::write(&csv, "old\n").unwrap();
//!
//! let mut outputs = Outputs::new();
//! outputs.add("-o", Target::Path(csv.clone()), "x,y\n1,2\n");
//! outputs.add_in_dir("--plot", dir.join("plots"), "fit.svg", "<svg/>");
//! let written = outputs.write_all().unwrap();
//!
//! assert_eq!(std::fs::read_to_string(&csv).unwrap(), "x,y\n1,2\n");
//! assert_eq!(std::fs::read_to_string(dir.join("plots/fit.svg")).unwrap(), "<svg/>");
//! assert_eq!(written[0].to_string(), format!("`{}`", csv.display()));
//! std::fs::remove_dir_all(&dir).unwrap();
//! ```
#![warn(missing_docs)]

mod check;
mod commit;
mod error;
mod outputs;
mod signals;
mod target;
mod temp;
/// Hooks for this crate's own tests (feature `testing`): fixed temporary names, and code run
/// between the stages of a write. Without the feature the hooks are no-ops the compiler removes.
#[cfg(feature = "testing")]
pub mod testing;
#[cfg(not(feature = "testing"))]
mod testing {
    pub(crate) fn next_name_bits() -> Option<u64> {
        None
    }
    pub(crate) fn after_staging() {}
    pub(crate) fn after_rename() {}
}

pub use check::{check_dir, check_targets, refuse_inputs_in_dir, refuse_overwriting_inputs};
pub use error::{Cause, WriteError};
pub use outputs::{Outputs, Written};
pub use target::Target;
