//! `rtest report`: one self-contained HTML document from the JSON reports of a check
//! (`identify`, `validate`, `diagnose`, `compensate`), and the `--report FILE` shortcut of
//! `identify`, `diagnose` and `compensate`, which renders what the verb just computed through
//! the same function.

use super::{CliError, CliResult, EXIT_CODES, check_outputs, print_text, write, wrote};
use output::{Outputs, Target};
use report::{InputFile, Inputs, MachineFacts};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Writes one self-contained HTML report of a check (docs/report.md), for reading on screen and \
printing to PDF (A4): the machine and model; the data (records with their samples, input files \
with their size and SHA-256); the identified values with their standard uncertainties (µm, \
µrad) and the groups the data could not separate; the validations (residual RMS and maximum per \
direction, µm, and a figure); the diagnosis (findings, gain on the fitted and held-out records, \
what remains unexplained, the residual components figure); the compensation summary. A part \
whose report is not given is one line saying so.

The inputs are the JSON files that `rtest identify --json`, `rtest validate --json`, `rtest \
diagnose --json` and `rtest compensate --json` write, in any order; each is recognised by its \
content. At most one identification, one diagnosis and one compensation; any number of \
validations (each of another record). They must belong to one check: one machine (and the \
machine of --machine, fingerprint included), the identification's model in every validation \
and compensation, and for a diagnosis the identification's fitted record and its base or \
extended model. Campaign reports (\"kind\": \"campaign\") are not covered. The records and \
files the reports name are hashed when they can be read from the working directory.

The measured-against-predicted figures along each path need the measurements, which the JSON \
reports do not hold: `rtest diagnose --report FILE` draws them. `identify`, `diagnose` and \
`compensate` take --report FILE to write this report from what they just computed.

The document makes no request of any kind: figures are inline SVG, their font (DejaVu Sans, \
about 1 MB of the file) is embedded, a Content-Security-Policy forbids every other source, and \
there is no script. -o - writes it to standard output.";

/// Flags of `rtest report`.
#[derive(Debug, clap::Args)]
#[command(
    about = "One self-contained HTML report of a check from the JSON of identify, validate, diagnose, compensate",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct ReportArgs {
    /// The JSON reports of the check (identify, validate, diagnose, compensate --json).
    #[arg(value_name = "JSON", required = true)]
    reports: Vec<PathBuf>,
    /// The HTML file to write (`-`: standard output).
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Target,
    /// Built-in machine or machine TOML file: lists its axes, and checks that the reports are
    /// of it (name, and the identification's fingerprint).
    #[arg(long, value_name = "NAME|FILE")]
    machine: Option<String>,
}

/// The time the report is written, RFC 3339 UTC (`None` when the clock is unusable).
fn now() -> Option<String> {
    history::Timestamp::now().ok().map(|t| t.to_string())
}

/// A new set of inputs for a report of machine `m`, written now, with `files` (flag, path)
/// hashed.
pub fn inputs_for(m: &model_spec::Machine, files: &[(&str, &Path)]) -> Inputs {
    let mut i = Inputs::new();
    i.machine = Some(MachineFacts::of(m));
    i.written_at = now();
    i.files = files
        .iter()
        .map(|(flag, p)| InputFile::hashed(flag, &p.display().to_string()))
        .collect();
    i
}

/// The HTML of `inputs` for the output of `flag`.
///
/// # Errors
/// A figure that cannot be drawn (exit code 3).
pub fn render(flag: &str, inputs: &Inputs) -> CliResult<String> {
    report::render(inputs).map_err(|e| CliError::computation(format!("{flag}: {e}")))
}

/// Runs `rtest report`.
pub fn run(args: &ReportArgs) -> CliResult {
    let mut inputs_list: Vec<(&str, &Path)> =
        args.reports.iter().map(|p| ("JSON", p.as_path())).collect();
    let machine_file = args.machine.as_deref().and_then(super::machine_file);
    inputs_list.extend(machine_file.map(|p| ("--machine", p)));
    check_outputs(&inputs_list, &[("-o", &args.output)], &[])?;
    let mut inputs = Inputs::new();
    if let Some(name) = &args.machine {
        inputs.machine = Some(MachineFacts::of(&super::load_machine(name)?));
    }
    inputs.written_at = now();
    for path in &args.reports {
        let doc =
            report::inputs::read_document(path).map_err(|e| CliError::input(e.to_string()))?;
        inputs
            .add(&path.display().to_string(), doc)
            .map_err(|e| CliError::input(e.to_string()))?;
    }
    inputs.files = named_files(&inputs, &args.reports, machine_file);
    inputs.no_path_figures = Some(
        "No path figures: they need the measurements, which the JSON reports do not hold (rtest diagnose --report draws them).".into(),
    );
    let html = render("-o", &inputs)?;
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), html);
    let stdout_taken = matches!(args.output, Target::Stdout);
    let text = wrote(&write(files)?);
    print_text(&text, stdout_taken)
}

/// The files of a report given to `rtest report`: the JSON reports, the machine file, and
/// every record and values file the reports name, each hashed when it can be read from here.
fn named_files(inputs: &Inputs, reports: &[PathBuf], machine: Option<&Path>) -> Vec<InputFile> {
    let mut out: Vec<InputFile> = reports
        .iter()
        .map(|p| InputFile::hashed("JSON report", &p.display().to_string()))
        .collect();
    out.extend(machine.map(|p| InputFile::hashed("--machine", &p.display().to_string())));
    let mut named = |role: &str, path: &str| {
        if !out.iter().any(|f| f.path == path) {
            out.push(InputFile::hashed(role, path));
        }
    };
    if let Some((_, r)) = &inputs.identification {
        named("identification: fitted record", &r.data);
    }
    for (_, v) in &inputs.validations {
        named("validation: record", &v.data);
        named("validation: values", &v.params);
    }
    if let Some((_, d)) = &inputs.diagnosis {
        named("diagnosis: fitted record", &d.data);
        for (f, _) in &d.held_out {
            named("diagnosis: held-out record", f);
        }
    }
    if let Some((_, c)) = &inputs.compensation {
        named("compensation: values", &c.params_file);
        named("compensation: commanded poses", &c.input);
    }
    out
}
