//! Your own machine in your own crate: the build-script API.
//!
//! A crate of yours (controller firmware, a calibration tool) keeps its machine description in
//! a TOML file (`docs/model-spec.md`) and has its `build.rs` turn it into the generated code in
//! `OUT_DIR`, at every build, from the description in the repository: no generated file to
//! check in, and the code cannot drift from the description. The code is that of
//! [`emit::generate_machine`](crate::emit::generate_machine) (what `rtest generate` writes):
//! `no_std`, no allocation, no maths library (the sines and cosines of the rotary commands are
//! inputs), gains in `f64`, and per model a `compensation` module with the corrected commands
//! in `f64` and the first-order correction in `f32`.
//!
//! What it does for you:
//! - prints `cargo::rerun-if-changed=` for the description, so that cargo runs the script
//!   again when the description changes (and only then, or when the script or `codegen`
//!   changes);
//! - returns an error that is one line naming the file, line, column and field of a bad
//!   description (the messages of [`model_spec::parse_machine`]); a file that cannot be read
//!   is named with the reason; a model the description does not have is named with the models
//!   it has;
//! - writes atomically: the code goes to a temporary file beside the target, which is then
//!   renamed over it, so a failed or interrupted build never leaves a partial file; a file
//!   whose contents would not change is left alone, so that its crate is not recompiled.
//!
//! # Example
//!
//! `Cargo.toml` of your crate (a path dependency, or a git dependency pinned to a revision so
//! that the generated code only changes when you move the pin; `codegen` brings `model-spec`):
//!
//! ```toml
//! [build-dependencies]
//! codegen = { path = "../rtest/codegen" }
//! # codegen = { git = "https://example.org/rtest.git", rev = "<commit>" }
//! ```
//!
//! `build.rs`, beside `Cargo.toml` and `machine.toml` (relative paths are relative to the
//! crate's root, where cargo runs build scripts):
//!
//! ```no_run
//! fn main() {
//!     let generated = codegen::build::Machine::from_file("machine.toml")
//!         .models(&["full", "location"]) // leave out for every model of the description
//!         .write_to_out_dir("machine.rs");
//!     if let Err(e) = generated {
//!         // One line (`machine.toml:12:9: axis B: ...`): cargo shows it and fails the build.
//!         println!("cargo::error={e}");
//!     }
//! }
//! ```
//!
//! `src/lib.rs`:
//!
//! ```ignore
//! #![no_std]
//!
//! /// The error model of the machine in `machine.toml`.
//! pub mod machine {
//!     include!(concat!(env!("OUT_DIR"), "/machine.rs"));
//! }
//! ```
//!
//! Then `machine::Pose`, `machine::Params` and, per model, `machine::location::gains`,
//! `machine::location::compensation::first_order_f32` and the rest (docs/codegen.md).
//! `examples/user-machine` in the rtest repository is such a crate, with tests against the
//! exact virtual machine.
//!
//! [`crate_files`] gives the other way: the files of a standalone crate holding a machine's
//! generated code (what `rtest generate --crate DIR` writes), pure text, no file access.

// The example above is a whole `build.rs`, `fn main` included.
#![allow(clippy::needless_doctest_main)]

pub mod crate_files;

use crate::emit::{GenerateError, generate_machine};
use model_spec::SpecError;
use model_spec::limits::MAX_FILE_BYTES;
use model_spec::text::{TextError, read_text};
use std::ffi::OsString;
use std::fs::{self, File, OpenOptions};
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Why code could not be generated or written. Each message is one line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// The description could not be read: missing, unreadable, larger than
    /// [`MAX_FILE_BYTES`], or not UTF-8 (with its line and column).
    #[error("{0}")]
    Read(TextError),
    /// The description is invalid: `file:line:column: field: what is wrong`.
    #[error("{0}")]
    Spec(SpecError),
    /// The description is valid but its code could not be generated (a model it does not
    /// have).
    #[error("{file}: {error}")]
    Generate {
        /// The description, as given.
        file: String,
        /// What went wrong.
        error: GenerateError,
    },
    /// A model was asked for twice.
    #[error("{file}: model `{model}` is asked for twice")]
    DuplicateModel {
        /// The description, as given.
        file: String,
        /// The model.
        model: String,
    },
    /// The description's path cannot be written as a cargo directive (it is not UTF-8 or
    /// holds a line break), so cargo could not watch it.
    #[error("`{}`: {reason}: cargo cannot watch it for changes", .path.display())]
    Unwatchable {
        /// The path, as given.
        path: PathBuf,
        /// Why.
        reason: &'static str,
    },
    /// The cargo directive could not be printed on standard output.
    #[error("cannot print the cargo directive on standard output: {0}")]
    Directive(io::Error),
    /// `OUT_DIR` is not set: the code was asked for outside a build script.
    #[error(
        "the environment variable OUT_DIR is not set: cargo sets it for build scripts \
         (outside one, write with `Generated::write_to`)"
    )]
    NoOutDir,
    /// The name given for a file in `OUT_DIR` is not a plain file name.
    #[error("`{0}` is not a plain file name (no directory, not `.` or `..`)")]
    FileName(String),
    /// The file could not be written; nothing was written (a temporary is removed).
    #[error("cannot write `{}`: {error}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What the system said.
        error: io::Error,
    },
}

/// A machine description to generate code from, builder style:
/// [`from_file`](Machine::from_file), then optionally [`models`](Machine::models), then
/// [`write_to_out_dir`](Machine::write_to_out_dir) (or [`generate`](Machine::generate)).
#[derive(Clone, Debug)]
pub struct Machine {
    path: PathBuf,
    models: Vec<String>,
}

/// The code generated from a description, with what it was generated from.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The machine, validated.
    pub machine: model_spec::Machine,
    /// The models the code holds, in the order of the code: those asked for, or every model of
    /// the machine (`full` first, then by name).
    pub models: Vec<String>,
    /// The Rust source (`no_std`, no crate attributes: `include!` it or make it a module).
    pub code: String,
}

impl Machine {
    /// The description in the TOML file at `path` (mm and degrees, `docs/model-spec.md`).
    /// Nothing is read until [`generate`](Machine::generate) or
    /// [`write_to_out_dir`](Machine::write_to_out_dir).
    pub fn from_file(path: impl AsRef<Path>) -> Machine {
        Machine {
            path: path.as_ref().to_path_buf(),
            models: Vec::new(),
        }
    }

    /// Generate only the models `names` (`full` and the description's `[models.NAME]`
    /// tables), in this order; without this call (or with an empty list), every model.
    pub fn models(mut self, names: &[&str]) -> Machine {
        self.models = names.iter().map(|n| n.to_string()).collect();
        self
    }

    /// Reads and validates the description and generates the code of its models. Prints
    /// `cargo::rerun-if-changed=PATH` for the description on standard output first (as a
    /// build script must, so that cargo runs it again when the file changes, also after a
    /// failure).
    pub fn generate(&self) -> Result<Generated, BuildError> {
        let file = self.path.display().to_string();
        let directive = rerun_directive(&self.path)?;
        writeln!(io::stdout().lock(), "{directive}").map_err(BuildError::Directive)?;
        let text = read_text(&self.path, MAX_FILE_BYTES).map_err(BuildError::Read)?;
        let machine = model_spec::parse_machine(&file, &text).map_err(BuildError::Spec)?;
        for (i, model) in self.models.iter().enumerate() {
            if self.models[..i].contains(model) {
                return Err(BuildError::DuplicateModel {
                    file,
                    model: model.clone(),
                });
            }
        }
        let asked: Vec<&str> = self.models.iter().map(String::as_str).collect();
        let code = generate_machine(&machine, &asked)
            .map_err(|error| BuildError::Generate { file, error })?;
        let models = if asked.is_empty() {
            machine
                .model_names()
                .iter()
                .map(|n| n.to_string())
                .collect()
        } else {
            self.models.clone()
        };
        Ok(Generated {
            machine,
            models,
            code,
        })
    }

    /// [`generate`](Machine::generate), then [`Generated::write_to_out_dir`]: the code in
    /// `OUT_DIR/file_name`, for `include!(concat!(env!("OUT_DIR"), "/file_name"))`.
    pub fn write_to_out_dir(&self, file_name: &str) -> Result<Generated, BuildError> {
        let generated = self.generate()?;
        generated.write_to_out_dir(file_name)?;
        Ok(generated)
    }
}

impl Generated {
    /// Writes the code to `OUT_DIR/file_name` atomically (see [`write_to_out_dir`]) and
    /// returns the path written.
    pub fn write_to_out_dir(&self, file_name: &str) -> Result<PathBuf, BuildError> {
        write_to_out_dir(file_name, &self.code)
    }

    /// Writes the code to `path` atomically (see [`write_atomically`]).
    pub fn write_to(&self, path: &Path) -> Result<(), BuildError> {
        write_atomically(path, self.code.as_bytes())
    }
}

/// `OUT_DIR`, the directory cargo gives a build script for its outputs.
pub fn out_dir() -> Result<PathBuf, BuildError> {
    std::env::var_os("OUT_DIR")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .ok_or(BuildError::NoOutDir)
}

/// Writes `contents` to `OUT_DIR/file_name` atomically (see [`write_atomically`]) and returns
/// the path written; `file_name` is a plain file name.
pub fn write_to_out_dir(file_name: &str, contents: &str) -> Result<PathBuf, BuildError> {
    let plain = Path::new(file_name)
        .file_name()
        .is_some_and(|n| n == file_name);
    if !plain {
        return Err(BuildError::FileName(file_name.to_string()));
    }
    let path = out_dir()?.join(file_name);
    write_atomically(&path, contents.as_bytes())?;
    Ok(path)
}

/// Writes `contents` to `path` atomically: to a new temporary file beside it (created
/// exclusively, synced to disk), then renamed over it, so that a reader (the compiler) sees
/// the old file or the new one, never a part. On an error the temporary is removed and `path`
/// is unchanged. A file that already holds exactly `contents` is not touched, so that its
/// modification time, and with it cargo's view of what must be rebuilt, stays.
pub fn write_atomically(path: &Path, contents: &[u8]) -> Result<(), BuildError> {
    let fail = |error| BuildError::Write {
        path: path.to_path_buf(),
        error,
    };
    if fs::metadata(path).is_ok_and(|m| m.is_file()) && fs::read(path).is_ok_and(|c| c == contents)
    {
        return Ok(());
    }
    let (temp, mut file) = create_temp(path).map_err(fail)?;
    let written = file.write_all(contents).and_then(|()| file.sync_all());
    drop(file);
    if let Err(e) = written.and_then(|()| fs::rename(&temp, path)) {
        let _ = fs::remove_file(&temp);
        return Err(fail(e));
    }
    Ok(())
}

/// A new temporary file beside `path`: `.{name}.{process id}-{counter}.tmp`, created
/// exclusively (an existing file of that name, or a link planted there, is never opened).
fn create_temp(path: &Path) -> io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(io::ErrorKind::InvalidInput, "the path does not name a file")
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut attempts = 0;
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut temp = OsString::from(".");
        temp.push(name);
        temp.push(format!(".{}-{n}.tmp", std::process::id()));
        let temp = dir.join(temp);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(file) => return Ok((temp, file)),
            // Left behind by an earlier process of the same id: take the next number.
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && attempts < 100 => attempts += 1,
            Err(e) => return Err(e),
        }
    }
}

/// The `cargo::rerun-if-changed=` line of `path`, or why cargo could not read one.
fn rerun_directive(path: &Path) -> Result<String, BuildError> {
    let unwatchable = |reason| BuildError::Unwatchable {
        path: path.to_path_buf(),
        reason,
    };
    let text = path.to_str().ok_or_else(|| unwatchable("not UTF-8"))?;
    if text.contains(['\n', '\r']) {
        return Err(unwatchable("it holds a line break"));
    }
    Ok(format!("cargo::rerun-if-changed={text}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A three-axis machine with one sub-model; `stroke` of Y on line 16, column 10.
    const MILL3: &str = r#"name = "mill3"

[[work]]
end = "ball"

[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-400, 400]

[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-300, 300]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-300, 300]

[[tool]]
end = "probe"

[models.square]
errors = ["COY", "AOZ", "BOZ"]
"#;

    /// A fresh, empty directory for one test, removed when dropped.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(name: &str) -> TempDir {
            let d = std::env::temp_dir()
                .join(format!("rtest-codegen-build-{}-{name}", std::process::id()));
            let _ = fs::remove_dir_all(&d);
            fs::create_dir_all(&d).unwrap();
            TempDir(d)
        }

        /// The names of the directory's entries, sorted.
        fn entries(&self) -> Vec<String> {
            let mut v: Vec<String> = fs::read_dir(&self.0)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            v.sort();
            v
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = fs::remove_dir_all(&self.0);
        }
    }

    fn description(dir: &TempDir, text: &str) -> PathBuf {
        let path = dir.0.join("mill3.toml");
        fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn generates_every_model_or_those_asked_for_in_their_order() {
        let dir = TempDir::new("models");
        let path = description(&dir, MILL3);
        let all = Machine::from_file(&path).generate().unwrap();
        assert_eq!(all.models, ["full", "square"]);
        assert_eq!(all.machine.name, "mill3");
        assert_eq!(all.code, generate_machine(&all.machine, &[]).unwrap());
        let some = Machine::from_file(&path)
            .models(&["square", "full"])
            .generate()
            .unwrap();
        assert_eq!(some.models, ["square", "full"]);
        assert!(
            some.code.find("pub mod square").unwrap() < some.code.find("pub mod full").unwrap()
        );
    }

    #[test]
    fn a_bad_description_is_named_by_file_line_column_and_field() {
        let dir = TempDir::new("bad");
        let path = description(&dir, &MILL3.replace("[-300, 300]", "[300, -300]"));
        let e = Machine::from_file(&path).generate().unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}:16:10: axis Y: `stroke` minimum 300 is not below maximum -300 (mm)",
                path.display()
            )
        );
        let missing = dir.0.join("missing.toml");
        let e = Machine::from_file(&missing).generate().unwrap_err();
        assert!(matches!(e, BuildError::Read(_)), "{e}");
        assert!(
            e.to_string()
                .starts_with(&format!("cannot read `{}`", missing.display()))
        );
    }

    #[test]
    fn an_unknown_or_repeated_model_is_refused_with_the_file() {
        let dir = TempDir::new("unknown");
        let path = description(&dir, MILL3);
        let e = Machine::from_file(&path)
            .models(&["ful"])
            .generate()
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: machine `mill3` has no model `ful` (its models: full, square)",
                path.display()
            )
        );
        let e = Machine::from_file(&path)
            .models(&["full", "square", "full"])
            .generate()
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("{}: model `full` is asked for twice", path.display())
        );
    }

    #[test]
    fn the_directive_names_the_path_or_the_path_is_refused() {
        assert_eq!(
            rerun_directive(Path::new("machines/m.toml")).unwrap(),
            "cargo::rerun-if-changed=machines/m.toml"
        );
        let e = rerun_directive(Path::new("a\nb.toml")).unwrap_err();
        assert!(matches!(e, BuildError::Unwatchable { .. }), "{e}");
        #[cfg(unix)]
        {
            use std::os::unix::ffi::OsStrExt;
            let path = Path::new(std::ffi::OsStr::from_bytes(b"m\xff.toml"));
            assert!(matches!(
                rerun_directive(path),
                Err(BuildError::Unwatchable {
                    reason: "not UTF-8",
                    ..
                })
            ));
        }
    }

    #[test]
    fn writes_replace_the_file_whole_and_leave_no_temporary() {
        let dir = TempDir::new("write");
        let target = dir.0.join("machine.rs");
        write_atomically(&target, b"old").unwrap();
        write_atomically(&target, b"new contents").unwrap();
        assert_eq!(fs::read(&target).unwrap(), b"new contents");
        assert_eq!(dir.entries(), ["machine.rs"]);
        // The same contents again: the file is not touched.
        let before = fs::metadata(&target).unwrap().modified().unwrap();
        write_atomically(&target, b"new contents").unwrap();
        assert_eq!(fs::metadata(&target).unwrap().modified().unwrap(), before);
    }

    #[test]
    fn a_failed_write_leaves_the_target_and_no_temporary() {
        let dir = TempDir::new("fail");
        // The target is a directory: the rename fails after the temporary was written.
        let target = dir.0.join("machine.rs");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("kept"), "x").unwrap();
        let e = write_atomically(&target, b"code").unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("cannot write `{}`: ", target.display())),
            "{e}"
        );
        assert_eq!(dir.entries(), ["machine.rs"]);
        assert_eq!(fs::read(target.join("kept")).unwrap(), b"x");
        // A directory that does not exist.
        let e = write_atomically(&dir.0.join("no/machine.rs"), b"code").unwrap_err();
        assert!(matches!(e, BuildError::Write { .. }), "{e}");
        assert_eq!(dir.entries(), ["machine.rs"]);
    }

    #[test]
    fn a_file_in_out_dir_must_be_a_plain_name() {
        for name in ["", ".", "..", "src/machine.rs", "/machine.rs"] {
            let e = write_to_out_dir(name, "code").unwrap_err();
            assert!(matches!(e, BuildError::FileName(_)), "{name:?}: {e}");
        }
    }
}
