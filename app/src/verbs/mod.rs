//! The verbs of `rtest`, one module each: its options (clap `Args`, with its help) and its
//! `run`, which takes them and returns what it has done ([`crate::Done`]: its text and its
//! outputs, not yet written). What they share: loading a machine, reading a record, checking
//! the outputs before any work.

pub mod args;
pub mod bench;
pub mod campaign;
pub mod compensate;
mod compensate_held;
mod compensate_isg;
mod compensate_linuxcnc;
mod compensate_siemens;
pub mod demo;
pub mod diagnose;
mod diagnose_records;
pub mod figures;
pub mod gains;
pub mod generate;
pub mod generator_args;
pub mod history;
pub mod identify;
pub mod instrument;
pub mod machines;
pub mod path;
pub mod path_nc;
pub mod path_probe;
pub mod plan;
pub mod plan_probe;
pub mod pose_args;
pub mod probe_log;
pub mod probe_records;
pub mod progress;
pub mod record;
pub mod report;
mod report_files;
pub mod segment;
pub mod simulate;
pub mod simulate_probe;
pub mod validate;
pub mod volumetric;

use formats::csv::ReadOptions;
use model_spec::sha256::Digest;
use model_spec::{LoadError, Machine};
use output::{Target, WriteError, Written};
use simulation::record::Record;
use std::path::Path;

pub use crate::error::{EXIT_CODES, EXIT_COMPUTATION, EXIT_INPUT, EXIT_USAGE, Error, VerbResult};

/// Loads the machine of `--machine` (a built-in name or a TOML file). An unknown name is a
/// usage error; a file that cannot be read or does not validate is a bad input.
pub fn load_machine(name_or_path: &str) -> VerbResult<Machine> {
    load_machine_read(name_or_path).map(|l| l.machine)
}

/// [`load_machine`], with the text it was read from (read once).
pub fn load_machine_and_text(name_or_path: &str) -> VerbResult<(Machine, String)> {
    load_machine_read(name_or_path).map(|l| (l.machine, l.text))
}

/// [`load_machine`], with the text it was read from and, for a file, the digest of the bytes
/// read (read once).
pub fn load_machine_read(name_or_path: &str) -> VerbResult<model_spec::LoadedMachine> {
    model_spec::load_machine_read(name_or_path).map_err(|e| match e {
        LoadError::NotFound(_) => Error::usage(format!("--machine: {e}")),
        _ => Error::input(format!("--machine: {e}")),
    })
}

/// An input file a verb read: the flag that gave it, its path as given, and the digest of the
/// bytes the verb read from it (taken while reading, never by opening the path again). What
/// `--report` lists and `--record` keeps.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadFile {
    /// The flag that gave it (`--data`, `--machine`).
    pub flag: String,
    /// The path, as given.
    pub path: String,
    /// Size and SHA-256 of the bytes read.
    pub digest: Digest,
}

impl ReadFile {
    /// The file at `path`, given by `flag`, read as `digest` says.
    pub fn new(flag: &str, path: &Path, digest: Digest) -> ReadFile {
        ReadFile {
            flag: flag.to_string(),
            path: path.display().to_string(),
            digest,
        }
    }

    /// The machine file of `--machine ARG` read as `digest` says (`None`, and so no file,
    /// for a built-in machine).
    pub fn machine(arg: &str, digest: Option<Digest>) -> Option<ReadFile> {
        digest.map(|d| ReadFile::new("--machine", Path::new(arg), d))
    }
}

/// The record of a measurement CSV given by `flag` (mm and rad inside), read with `options`:
/// of error vectors, or of the sensor readings of the `instrument` it is read through
/// (turned into error vectors with their covariances, docs/instrument.md), planned at the
/// kinematic parameters `params` (mm: the ball position among them); with the digest of the
/// bytes read. Every problem with the file is a bad input naming the flag, the file and the
/// line.
pub fn read_record(
    flag: &str,
    m: &Machine,
    path: &Path,
    options: &ReadOptions,
    instrument: campaign::Through,
    params: &[f64],
) -> VerbResult<(Record, Digest, Option<fitting::probe::ProbeSummary>)> {
    read_record_file(path, m, params, options, instrument).map_err(|e| {
        Error::input(format!(
            "{flag}: {e}{}",
            formats::campaign::parameters_note(m, params)
        ))
    })
}

/// The record of the file at `path` at kinematic parameters `params` (mm) as `through` reads
/// it, with the digest of the bytes read and, for a probe's, what its sphere fits say.
pub fn read_record_file(
    path: &Path,
    m: &Machine,
    params: &[f64],
    options: &ReadOptions,
    through: campaign::Through,
) -> Result<(Record, Digest, Option<fitting::probe::ProbeSummary>), formats::csv::CsvError> {
    match through {
        campaign::Through::Probe(p) => {
            probe_records::read_probe_record(path, m, params, p, options)
                .map(|(r, d, s)| (r, d, Some(s)))
        }
        other => formats::campaign::read_record_at(path, m, params, options, other.sensors())
            .map(|(r, d)| (r, d, None)),
    }
}

/// Refuses `record` (read from `path`, given by `flag`) for `model` when a term needs the real
/// sample times (`velocity`, `exp:TAU`, `rate`, `warmup:TAU`) and the file had no `t_s`
/// column, or when a warm-up (`warmup:TAU`, from `t_s = 0`) has a sample before its start.
pub fn check_times(
    flag: &str,
    path: &Path,
    m: &Machine,
    model: &simulation::model::Model,
    record: &Record,
) -> VerbResult<()> {
    if let Some(t) = model.terms.iter().find(|t| t.basis.starts_at_zero()) {
        record
            .check_started(&t.spelling(m))
            .map_err(|e| Error::input(format!("{flag} {}: {e}", path.display())))?;
    }
    match model.terms.iter().find(|t| t.basis.needs_times()) {
        Some(t) if !record.has_times() => Err(Error::input(format!(
            "{flag} {}: term `{}` needs the real sample times, but the file has no `t_s` column (its samples are only numbered): add the times in s",
            path.display(),
            t.spelling(m)
        ))),
        _ => Ok(()),
    }
}

/// `--machine` as an input file, when it names one (a built-in name is not a file).
pub fn machine_file(name_or_path: &str) -> Option<&Path> {
    let builtin = model_spec::BUILTIN.iter().any(|(n, _)| *n == name_or_path);
    (!builtin).then(|| Path::new(name_or_path))
}

/// A writer error as a verb's error: a wrong command line (an output that names an input, two
/// outputs on one file) is a usage error, anything else a bad input.
pub fn write_error(e: WriteError) -> Error {
    if e.is_usage() {
        Error::usage(e.to_string())
    } else {
        Error::input(e.to_string())
    }
}

/// Checks, before any work, that no output names an input and that every output can be
/// written: `inputs` and `outputs` are (flag, path) pairs; `dirs` are output directories.
pub fn check_outputs(
    inputs: &[(&str, &Path)],
    outputs: &[(&str, &Target)],
    dirs: &[(&str, &Path)],
) -> VerbResult {
    output::refuse_overwriting_inputs(inputs, outputs).map_err(write_error)?;
    output::check_targets(outputs).map_err(write_error)?;
    for (flag, dir) in dirs {
        output::check_dir(flag, dir).map_err(write_error)?;
    }
    Ok(())
}

/// Checks, before any work, that the output directory `dir` of `flag` holds no input under a
/// name the verb may write there (`writes`: e.g. `*.svg` for `--plot`), links included.
pub fn check_dir_inputs(
    inputs: &[(&str, &Path)],
    flag: &str,
    dir: &Path,
    writes: &dyn Fn(&str) -> bool,
) -> VerbResult {
    output::refuse_inputs_in_dir(inputs, flag, dir, writes).map_err(write_error)
}

/// One `Wrote FILE` line per file written (standard output is not listed).
pub fn wrote(written: &[Written]) -> String {
    written
        .iter()
        .filter(|w| !matches!(w.target, Target::Stdout))
        .map(|w| format!("Wrote {}\n", w.target))
        .collect()
}
