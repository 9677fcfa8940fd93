//! The built-in machines (`model-spec/machines/*.toml`), compiled into the library.

use crate::limits::MAX_FILE_BYTES;
use crate::sha256::Digest;
use crate::text::{TextError, read_text_hashed};
use crate::{Machine, SpecError, parse_machine};
use std::path::Path;

/// Name and TOML text of every built-in machine, in the order `rtest machines` lists them: the
/// seed's machines and `head-table-bc` first (their places are fixed), then the templates of
/// the other families: table-table B/C, head-head C/A, the nutating head and the nutating
/// table (inclined B axes), the four-axis horizontal machine.
pub const BUILTIN: &[(&str, &str)] = &[
    ("seed-ac", include_str!("../machines/seed-ac.toml")),
    ("seed-3axis", include_str!("../machines/seed-3axis.toml")),
    (
        "head-table-bc",
        include_str!("../machines/head-table-bc.toml"),
    ),
    (
        "table-table-bc",
        include_str!("../machines/table-table-bc.toml"),
    ),
    (
        "head-head-ca",
        include_str!("../machines/head-head-ca.toml"),
    ),
    (
        "nutating-head-bc",
        include_str!("../machines/nutating-head-bc.toml"),
    ),
    (
        "nutating-table-bc",
        include_str!("../machines/nutating-table-bc.toml"),
    ),
    (
        "horizontal-4axis-b",
        include_str!("../machines/horizontal-4axis-b.toml"),
    ),
];

/// The built-in machine called `name`, validated.
pub fn builtin(name: &str) -> Option<Result<Machine, SpecError>> {
    BUILTIN
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| parse_machine(&format!("<built-in {n}>"), text))
}

/// Every built-in machine, validated. A built-in that does not validate is a bug, caught by
/// the tests.
pub fn all_builtin() -> Vec<Machine> {
    BUILTIN
        .iter()
        .map(|(n, _)| {
            builtin(n)
                .expect("listed")
                .expect("built-in machines are valid")
        })
        .collect()
}

/// A machine given by built-in name or by the path of a TOML file. A file is read with
/// [`crate::text::read_text`], at most [`MAX_FILE_BYTES`] bytes, and named in messages as
/// given.
pub fn load_machine(name_or_path: &str) -> Result<Machine, LoadError> {
    load_machine_and_text(name_or_path).map(|(m, _)| m)
}

/// A machine given by built-in name or by the path of a TOML file, with the text it was read
/// from (a file is read once: a FIFO or a file changed meanwhile cannot give two texts).
pub fn load_machine_and_text(name_or_path: &str) -> Result<(Machine, String), LoadError> {
    load_machine_read(name_or_path).map(|l| (l.machine, l.text))
}

/// A machine as it was loaded: what [`load_machine_read`] gives.
#[derive(Clone, Debug)]
pub struct LoadedMachine {
    /// The machine.
    pub machine: Machine,
    /// The text it was parsed from.
    pub text: String,
    /// The digest of the file's bytes as read; `None` for a built-in machine.
    pub digest: Option<Digest>,
}

/// A machine given by built-in name or by the path of a TOML file, with the text it was read
/// from and, for a file, the digest of the bytes read (the file is opened once).
pub fn load_machine_read(name_or_path: &str) -> Result<LoadedMachine, LoadError> {
    if let Some((n, text)) = BUILTIN.iter().find(|(n, _)| *n == name_or_path) {
        let m = parse_machine(&format!("<built-in {n}>"), text).map_err(LoadError::Spec)?;
        return Ok(LoadedMachine {
            machine: m,
            text: text.to_string(),
            digest: None,
        });
    }
    let (text, digest) = file_text_hashed(name_or_path)?;
    let m = parse_machine(name_or_path, &text).map_err(LoadError::Spec)?;
    Ok(LoadedMachine {
        machine: m,
        text,
        digest: Some(digest),
    })
}

/// The text of the machine description file `path`: at most [`MAX_FILE_BYTES`] bytes of UTF-8.
pub(crate) fn file_text(path: &str) -> Result<String, LoadError> {
    file_text_hashed(path).map(|(text, _)| text)
}

/// [`file_text`], with the digest of the bytes read.
fn file_text_hashed(path: &str) -> Result<(String, Digest), LoadError> {
    if !Path::new(path).exists() {
        return Err(LoadError::NotFound(path.to_string()));
    }
    // Named as given: the display of a path given as UTF-8 text is that text.
    read_text_hashed(Path::new(path), MAX_FILE_BYTES).map_err(LoadError::Io)
}

/// Why a machine could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Neither a built-in name nor an existing file.
    #[error("no built-in machine and no file called `{0}` (built-in: {names})", names = BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "))]
    NotFound(String),
    /// The file could not be read as a machine description's text: an I/O error, more than
    /// [`MAX_FILE_BYTES`] bytes, or a byte that is not UTF-8 (with its line and column).
    #[error("{0}")]
    Io(TextError),
    /// The description is invalid.
    #[error("{0}")]
    Spec(SpecError),
}
