//! The built-in machines (`model-spec/machines/*.toml`), compiled into the library.

use crate::{Machine, SpecError, parse_machine};

/// Name and TOML text of every built-in machine, in the order `rtest machines` lists them.
pub const BUILTIN: &[(&str, &str)] = &[
    ("seed-ac", include_str!("../machines/seed-ac.toml")),
    ("seed-3axis", include_str!("../machines/seed-3axis.toml")),
    (
        "head-table-bc",
        include_str!("../machines/head-table-bc.toml"),
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

/// A machine given by built-in name or by the path of a TOML file.
pub fn load_machine(name_or_path: &str) -> Result<Machine, LoadError> {
    if let Some(m) = builtin(name_or_path) {
        return m.map_err(LoadError::Spec);
    }
    let path = std::path::Path::new(name_or_path);
    if !path.exists() {
        return Err(LoadError::NotFound(name_or_path.to_string()));
    }
    let text =
        std::fs::read_to_string(path).map_err(|e| LoadError::Io(name_or_path.to_string(), e))?;
    parse_machine(name_or_path, &text).map_err(LoadError::Spec)
}

/// Why a machine could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Neither a built-in name nor an existing file.
    #[error("no built-in machine and no file called `{0}` (built-in: {names})", names = BUILTIN.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "))]
    NotFound(String),
    /// The file could not be read.
    #[error("cannot read `{0}`: {1}")]
    Io(String, std::io::Error),
    /// The description is invalid.
    #[error("{0}")]
    Spec(SpecError),
}
