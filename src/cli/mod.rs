//! The verbs of the `rtest` command line and what they share: the error type and its exit
//! codes, loading a machine and choosing a model from flags, writing files atomically, and a
//! small ordered JSON writer.

pub mod bench;
pub mod data;
pub mod demo;
pub mod diagnose;
pub mod gains;
pub mod generate;
pub mod identify;
pub mod json;
pub mod machines;
pub mod pose;
pub mod simulate;
pub mod validate;

use codegen::{GainModel, Program};
use model_spec::{ErrorId, LoadError, Machine};
use std::fmt;
use std::path::Path;

/// Exit code of a usage error: the command line itself is wrong.
pub const EXIT_USAGE: u8 = 2;
/// Exit code of any other failure.
pub const EXIT_FAILURE: u8 = 1;

/// The exit-code rule, shown after every verb's help.
pub const EXIT_CODES: &str = "\
Exit codes: 0 success; 2 the command line is wrong (missing or unknown flag; unknown machine, \
model, path, truth, axis, symbol, error or term name; malformed --at/--param/--errors/--terms/\
--constraint/--noise-um; non-finite number; unknown --format); 1 the command was understood but \
failed (a machine, truth, measurement CSV or JSON file that cannot be read, is malformed or \
belongs to another machine; inverse kinematics without a solution; an output file that cannot be \
written). Errors are one line on stderr, starting with the flag at fault (a malformed file is \
named with its line and column); no partial output file is ever left behind.";

/// A failure of a verb: a one-line message and its exit code.
#[derive(Debug)]
pub struct CliError {
    /// The exit code: [`EXIT_USAGE`] or [`EXIT_FAILURE`].
    pub code: u8,
    /// One line, naming the flag and the offending item.
    pub message: String,
}

impl CliError {
    /// A usage error (exit code 2).
    pub fn usage(message: impl Into<String>) -> CliError {
        CliError {
            code: EXIT_USAGE,
            message: message.into(),
        }
    }

    /// Any other failure (exit code 1).
    pub fn failure(message: impl Into<String>) -> CliError {
        CliError {
            code: EXIT_FAILURE,
            message: message.into(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// The result of a verb.
pub type CliResult<T = ()> = Result<T, CliError>;

/// Loads the machine of `--machine` (a built-in name or a TOML file). An unknown name is a
/// usage error; a file that cannot be read or does not validate is a failure.
pub fn load_machine(name_or_path: &str) -> CliResult<Machine> {
    model_spec::load_machine(name_or_path).map_err(|e| match e {
        LoadError::NotFound(_) => CliError::usage(format!("--machine: {e}")),
        LoadError::Io(..) | LoadError::Spec(_) => CliError::failure(format!("--machine: {e}")),
    })
}

/// The errors chosen by `--model` / `--errors` (default: the full model), with a label for
/// titles (`Some(model name)`, or `None` for an explicit list).
pub fn select_errors(
    m: &Machine,
    model: Option<&str>,
    errors: Option<&str>,
) -> CliResult<(Option<String>, Vec<ErrorId>)> {
    if let Some(list) = errors {
        return parse_error_list(m, list).map(|ids| (None, ids));
    }
    let name = model.unwrap_or(model_spec::FULL_MODEL);
    let ids = model_errors(m, name)?;
    Ok((Some(name.to_string()), ids))
}

/// The errors of the model `name` of `m`, or a usage error listing its models.
pub fn model_errors(m: &Machine, name: &str) -> CliResult<Vec<ErrorId>> {
    m.model_errors(name)
        .map(<[ErrorId]>::to_vec)
        .ok_or_else(|| {
            CliError::usage(format!(
                "--model: machine {} has no model `{name}` (models: {})",
                m.name,
                m.model_names().join(", ")
            ))
        })
}

/// Parses `--errors`: a comma list of catalogue names (digit-zero spelling accepted), kept in
/// the given order.
pub fn parse_error_list(m: &Machine, list: &str) -> CliResult<Vec<ErrorId>> {
    if list.trim().is_empty() {
        return Err(CliError::usage(
            "--errors: empty list (expected a comma list of error names, e.g. XOC,YOC,BOA)",
        ));
    }
    let mut ids = Vec::new();
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(CliError::usage(format!(
                "--errors: empty item in `{list}` (expected a comma list of error names, e.g. XOC,YOC,BOA)"
            )));
        }
        let Some(id) = m.error_by_name(item) else {
            let names: Vec<&str> = m.catalogue.iter().map(|e| e.name.as_str()).collect();
            return Err(CliError::usage(format!(
                "--errors: machine {} has no error `{item}` (its errors: {})",
                m.name,
                names.join(" ")
            )));
        };
        if ids.contains(&id) {
            return Err(CliError::usage(format!(
                "--errors: error {} given twice",
                m.catalogue[id].name
            )));
        }
        ids.push(id);
    }
    Ok(ids)
}

/// A model derived and compiled for in-process evaluation (works for machines from files).
pub struct Compiled {
    /// The symbolic gains.
    pub model: GainModel,
    /// Their straight-line program.
    pub program: Program,
}

impl Compiled {
    /// Derives and compiles the gains of `errors` of `m`.
    pub fn new(m: &Machine, errors: &[ErrorId]) -> Compiled {
        let model = GainModel::derive(m, errors);
        let program = codegen::compile(m, &model);
        Compiled { model, program }
    }

    /// Position gains `[gx, gy, gz]` per error (tool frame; mm/mm or mm/rad) at `commands`
    /// (per axis: mm, rad) with `params` (per symbol, mm). Negative zeros are written as zeros.
    pub fn position_gains(&self, commands: &[f64], params: &[f64]) -> Vec<[f64; 3]> {
        // The program's inputs are the model's atoms, in atom order (`codegen::lower::inputs`).
        let inputs = self.model.atoms.values(commands, params);
        let mut out = vec![0.0; self.program.outputs.len()];
        let mut scratch = Vec::new();
        self.program.eval(&inputs, &mut scratch, &mut out);
        out.chunks_exact(6)
            .map(|g| [g[0] + 0.0, g[1] + 0.0, g[2] + 0.0])
            .collect()
    }
}

/// Writes `contents` to `path` through a temporary file in the same directory and a rename, so
/// that a failure never leaves a partial file. `flag` names the flag for the message.
pub fn write_atomic(flag: &str, path: &Path, contents: &str) -> CliResult {
    let fail = |e: std::io::Error| {
        CliError::failure(format!("{flag}: cannot write `{}`: {e}", path.display()))
    };
    let Some(file_name) = path.file_name() else {
        return Err(CliError::usage(format!(
            "{flag}: `{}` is not a file name",
            path.display()
        )));
    };
    if path.is_dir() {
        return Err(CliError::failure(format!(
            "{flag}: cannot write `{}`: it is a directory",
            path.display()
        )));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = dir.join(format!(
        ".{}.rtest-tmp-{}",
        file_name.to_string_lossy(),
        std::process::id()
    ));
    let result = std::fs::write(&tmp, contents).and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail(e));
    }
    Ok(())
}

/// Formats a number for tables: fixed six decimals, no negative zero.
pub fn fixed(x: f64) -> String {
    let s = format!("{:.6}", x);
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// Formats a number for people: at most six decimals, no trailing zeros, no negative zero
/// (`-217.504`, `0`, `45`, `153.601271`).
pub fn short(x: f64) -> String {
    let s = fixed(x);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "" | "-" => "0".to_string(),
        s => s.to_string(),
    }
}

/// `--format` of the gain tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Aligned plain text.
    Text,
    /// A Markdown table.
    Markdown,
    /// A LaTeX longtable.
    Latex,
    /// JSON.
    Json,
}

impl Format {
    /// The table format of `codegen::table`, `None` for JSON.
    pub fn table(self) -> Option<codegen::table::Format> {
        match self {
            Format::Text => Some(codegen::table::Format::Text),
            Format::Markdown => Some(codegen::table::Format::Markdown),
            Format::Latex => Some(codegen::table::Format::Latex),
            Format::Json => None,
        }
    }
}
