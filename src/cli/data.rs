//! The inputs of `simulate`, `identify`, `validate` and `demo`, read from their flags: truths,
//! test paths, measurement files, models (`--model`, `--terms`), constraints, and the
//! identification itself (solver::fitting, refined by solver::fitting::refine). Every error names its
//! flag; exit code 2 for a wrong command line, 1 for a file that cannot be read or does not fit.

use super::{CliError, CliResult};
use model_spec::Machine;
use solver::fitting::hmatrix::{GainSource, parameter_names};
use solver::fitting::refine::{RefineError, RefineOptions, Refinement, identify_refined_with};
use solver::fitting::{
    Constraint, EstimateError, Identification, IdentifyOptions, identify_with, with_offsets,
};
use solver::io::csv::{CsvError, ReadOptions};
use solver::model::{Effect, Model, Term};
use solver::record::Record;
use solver::simulation::paths::PathError;
use solver::simulation::truth::{Truth, TruthError};
use std::path::Path;

/// The truth of `--truth` (a built-in name or a TOML file), or, without it, the machine's
/// built-in demo truth `<machine>-demo` if there is one (`seed-ac-demo`), else the nominal
/// machine. An unknown name is a usage error; a file that cannot be read or is invalid is a
/// failure.
pub fn truth(m: &Machine, name: Option<&str>) -> CliResult<Truth> {
    let Some(name) = name else {
        return default_truth(m);
    };
    solver::simulation::truth::load_truth(name, m).map_err(|e| match e {
        TruthError::NotFound(_) => CliError::usage(format!("--truth: {e}")),
        TruthError::Invalid { .. } | TruthError::Io { .. } => {
            CliError::failure(format!("--truth: {e}"))
        }
    })
}

/// The name of the built-in demo truth of machine `m`, whether or not it exists.
pub fn demo_truth_name(m: &Machine) -> String {
    format!("{}-demo", m.name)
}

/// The machine's built-in demo truth (`<machine>-demo`), else the nominal machine.
pub fn default_truth(m: &Machine) -> CliResult<Truth> {
    let name = demo_truth_name(m);
    match solver::simulation::truth::builtin_truth(&name, m) {
        Some(Ok(t)) => Ok(t),
        Some(Err(e)) => Err(CliError::failure(format!(
            "--truth: the default truth {name} of machine {} does not fit this description of it: {e} (give --truth)",
            m.name
        ))),
        None => Ok(Truth::nominal(m)),
    }
}

/// The path of `--path`: `K1`, `K2`, `K4` (any case) or a path CSV file.
pub fn path(m: &Machine, name: &str) -> CliResult<Record> {
    solver::simulation::paths::load_path(m, name, &ReadOptions::default()).map_err(|e| match e {
        PathError::NotFound(_) | PathError::NotAC { .. } => CliError::usage(format!("--path: {e}")),
        PathError::Ik { .. } => CliError::failure(format!("--path: {e}")),
        PathError::Csv(c) => CliError::failure(format!("--path: {}", csv_message(&c))),
    })
}

/// A CSV problem for people: a file that cannot be read says so.
fn csv_message(e: &CsvError) -> String {
    match e {
        CsvError::Io { file, source } => format!("cannot read `{file}`: {source}"),
        other => other.to_string(),
    }
}

/// The measurement CSV of `flag` (`--data`): commands, readings (mm inside), times.
pub fn measurement(flag: &str, m: &Machine, file: &Path) -> CliResult<Record> {
    solver::io::csv::read_measurement(file, m, &ReadOptions::default())
        .map_err(|e| CliError::failure(format!("{flag}: {}", csv_message(&e))))
}

/// `true` when the first reading is exactly zero, as R-test software leaves zeroed readings.
pub fn looks_zeroed(record: &Record) -> bool {
    record.measured.first() == Some(&[0.0; 3]) && record.measured.len() > 1
}

/// A model chosen by `--model` and `--terms`, with a label for reports and JSON
/// (`reduced`, `reduced + ECC@harmonic:2`, `XOC + ECC@harmonic:2`).
pub fn model(m: &Machine, name: Option<&str>, terms: Option<&str>) -> CliResult<(String, Model)> {
    let mut label = Vec::new();
    let mut model = Model::default();
    if let Some(name) = name {
        model = Model::of(m, name).ok_or_else(|| {
            CliError::usage(format!(
                "--model: machine {} has no model `{name}` (models: {})",
                m.name,
                m.model_names().join(", ")
            ))
        })?;
        label.push(name.to_string());
    }
    let from_model = model.terms.len();
    if let Some(list) = terms {
        for (text, term) in parse_terms(m, list)? {
            if let Some(i) = model.terms.iter().position(|t| *t == term) {
                return Err(CliError::usage(if i < from_model {
                    format!("--terms: `{text}` is already in model {}", label[0])
                } else {
                    format!("--terms: `{text}` is given twice")
                }));
            }
            model.terms.push(term);
            label.push(text);
        }
    }
    if model.terms.is_empty() {
        return Err(CliError::usage(
            "--model: give a model (e.g. --model reduced) or terms (--terms XOC,ECC@harmonic:2)",
        ));
    }
    Ok((label.join(" + "), model))
}

/// Parses `--terms`: a comma list of `NAME` (constant) or `NAME@BASIS` terms
/// (`ECC@harmonic:2,dx0@time:1`); each with its text as written (trimmed).
pub fn parse_terms(m: &Machine, list: &str) -> CliResult<Vec<(String, Term)>> {
    let example = "expected a comma list of NAME or NAME@BASIS, e.g. ECC@harmonic:2,dx0@time:1";
    if list.trim().is_empty() {
        return Err(CliError::usage(format!("--terms: empty list ({example})")));
    }
    let mut out = Vec::new();
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(CliError::usage(format!(
                "--terms: empty item in `{list}` ({example})"
            )));
        }
        let term = Term::parse(m, item).map_err(|e| {
            let name = item.split_once('@').map_or(item, |(n, _)| n);
            let hint = if Effect::parse(m, name).is_none() {
                format!(" (its errors: `rtest machines --machine {}`)", m.name)
            } else {
                String::new()
            };
            CliError::usage(format!("--terms: `{item}`: {e}{hint}"))
        })?;
        out.push((item.to_string(), term));
    }
    Ok(out)
}

/// Parses `--constraint`: `none`, `min-norm` (or `minimum-norm`), or `zero:NAME,NAME`.
pub fn constraint(text: Option<&str>) -> CliResult<Constraint> {
    let Some(text) = text else {
        return Ok(Constraint::None);
    };
    let t = text.trim();
    match t {
        "none" => return Ok(Constraint::None),
        "min-norm" | "minimum-norm" => return Ok(Constraint::MinimumNorm),
        _ => {}
    }
    let Some(list) = t.strip_prefix("zero:") else {
        return Err(CliError::usage(format!(
            "--constraint: `{text}` is not one of none, min-norm, zero:NAME,NAME (e.g. zero:XOC,YOA,ZOA)"
        )));
    };
    let mut names: Vec<String> = Vec::new();
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(CliError::usage(format!(
                "--constraint: empty name in `{text}` (expected zero:NAME,NAME, e.g. zero:XOC,YOA,ZOA)"
            )));
        }
        if names.iter().any(|n| n == item) {
            return Err(CliError::usage(format!(
                "--constraint: `{item}` is given twice"
            )));
        }
        names.push(item.to_string());
    }
    Ok(Constraint::Zero(names))
}

/// An identification and, unless it was skipped, its refinement against the exact machine.
pub struct Identified {
    /// The identification (values refined when `refinement` is `Some`).
    pub ident: Identification,
    /// What the refinement did.
    pub refinement: Option<Refinement>,
}

/// Identifies `model` of `m` on `record` (solver::fitting::identify_with), then, when
/// `exact`, refines it against the exact machine (solver::fitting::refine::refine) with the same gain
/// source. `data` names the measurement flag in error messages.
pub fn identify(
    m: &Machine,
    model: &Model,
    record: &Record,
    opts: &IdentifyOptions,
    exact: bool,
) -> CliResult<Identified> {
    let params = opts
        .params
        .clone()
        .unwrap_or_else(|| m.default_parameters());
    let fitted = if opts.zeroed {
        with_offsets(model)
    } else {
        model.clone()
    };
    let mut source = GainSource::new(m, &fitted.errors(), &params)
        .map_err(|e| CliError::failure(format!("--machine: {e}")))?;
    let cannot_identify = |e: EstimateError| match e {
        EstimateError::UnknownParameter(name, _) => CliError::usage(format!(
            "--constraint: `{name}` is not a parameter of the model (parameters: {})",
            parameter_names(m, &fitted).join(", ")
        )),
        other => CliError::failure(format!("--data: cannot identify: {other}")),
    };
    let (ident, refinement) = if exact {
        let (ident, r) = identify_refined_with(m, model, record, &mut source, opts, &RefineOptions::default())
            .map_err(|e| match e {
                RefineError::Estimate(e) => cannot_identify(e),
                other => CliError::failure(format!(
                    "--data: the refinement against the exact machine failed: {other} (--first-order skips it)"
                )),
            })?;
        (ident, Some(r))
    } else {
        (
            identify_with(m, model, record, &mut source, opts).map_err(cannot_identify)?,
            None,
        )
    };
    Ok(Identified { ident, refinement })
}

/// A length in mm as µm for people: four decimals, or two significant digits in scientific
/// notation below 1e-4 µm (noise-free fits).
pub fn um(mm: f64) -> String {
    people(mm * 1e3)
}

/// A value already in µm or µrad for people (see [`um`]); no negative zero.
pub fn people(x: f64) -> String {
    if x != 0.0 && x.abs() < 5e-5 {
        return format!("{x:.1e}");
    }
    let s = format!("{x:.4}");
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// `um` → `µm`, `urad` → `µrad`.
pub fn unit(u: &str) -> String {
    u.replacen('u', "µ", 1)
}
