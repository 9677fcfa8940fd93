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
extended model. An identification or validation may be of one record or of a campaign of \
several: the report then lists the records with their ball positions (kinematic parameters that \
differ from the machine's defaults) and set-ups, the shared values (the machine's errors), the \
values of each set-up and record, and for each validated record its set-up (fitted, or new and \
refitted on the record). The records and files the reports name are hashed when they can be \
read from the working directory.

The measured error against the identified model's prediction along each path (every record of \
the identification and of the validations, against the axis that moves most) is drawn from the \
records the reports name, read from the working directory at their kinematic parameters, with \
the identification's values on the exact virtual machine (a validated record on a new set-up \
with its set-up errors refitted, as rtest validate did); a record that cannot be read is named \
with why. The \
machine is --machine, or the built-in the reports name. The diagnosis's base and extended \
predictions along the paths are drawn by `rtest diagnose --report FILE`. `identify`, \
`diagnose` and `compensate` take --report FILE to write this report from what they just \
computed.

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
    let machine = match &args.machine {
        Some(name) => Some(super::load_machine(name)?),
        None => None,
    };
    if let Some(m) = &machine {
        inputs.machine = Some(MachineFacts::of(m));
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
        "The base and extended models' predictions along the paths are drawn by rtest diagnose --report; section 4 draws the identified model's.".into(),
    );
    draw_paths(&mut inputs, machine, &args.reports)?;
    let html = render("-o", &inputs)?;
    let mut files = Outputs::new();
    files.add("-o", args.output.clone(), html);
    let stdout_taken = matches!(args.output, Target::Stdout);
    let text = wrote(&write(files)?);
    print_text(&text, stdout_taken)
}

/// The identified model's prediction along the path of every record of the identification and
/// of every validation, when the machine is known (`--machine`, or the built-in the reports
/// name) and the records can be read from here; otherwise one line says why not. A validated
/// record on a set-up the identification did not fit has its set-up errors refitted on it, as
/// `rtest validate` did.
fn draw_paths(
    inputs: &mut Inputs,
    machine: Option<model_spec::Machine>,
    reports: &[PathBuf],
) -> CliResult<()> {
    let Some((id_file, id)) = &inputs.identification else {
        if !inputs.validations.is_empty() {
            inputs.prediction_not_drawn.push(
                "No path is drawn: the identified values are in the identification report, which is not given.".into(),
            );
        }
        return Ok(());
    };
    let m = match machine.map_or_else(|| model_spec::load_machine(&id.machine), Ok) {
        Ok(m) => m,
        Err(_) => {
            inputs.prediction_not_drawn.push(format!(
                "No path is drawn: machine {} is no built-in; give its description with --machine.",
                id.machine
            ));
            return Ok(());
        }
    };
    let id_path = reports
        .iter()
        .find(|p| p.display().to_string() == *id_file)
        .map_or_else(|| PathBuf::from(id_file), PathBuf::clone);
    let values = match solver::io::report::read_identification(&id_path, &m) {
        Ok(v) => v.values,
        Err(e) => {
            inputs
                .prediction_not_drawn
                .push(format!("No path is drawn: {e}"));
            return Ok(());
        }
    };
    // The records the reports name, read here at their kinematic parameters, each on its
    // set-up; one that cannot be read, or predicted, is named with why.
    let mut named: Vec<(String, &'static str, CampaignRecordSpec)> = Vec::new();
    for (r, data) in values
        .layout
        .records
        .iter()
        .zip(id.records.iter().map(|x| &x.data))
    {
        named.push((
            data.clone(),
            "fitted",
            CampaignRecordSpec {
                label: r.label.clone(),
                setup: values.layout.setups[r.setup].clone(),
                params: r.params.clone(),
                zeroed: r.zeroed,
                start_s: r.start_s,
            },
        ));
    }
    let sole_setup = match values.layout.setups.as_slice() {
        [s] => Some(s.clone()),
        _ => None,
    };
    for (_, v) in &inputs.validations {
        for x in &v.records {
            let mut params = m.default_parameters();
            for (k, value) in &x.params.0 {
                if let Some(s) = m.symbol_by_name(k) {
                    params[s] = *value;
                }
            }
            let setup = if x.setup.is_empty() {
                sole_setup.clone().unwrap_or_else(|| x.label.clone())
            } else {
                x.setup.clone()
            };
            named.push((
                x.data.clone(),
                "validation",
                CampaignRecordSpec {
                    label: x.label.clone(),
                    setup,
                    params,
                    zeroed: x.zeroed,
                    start_s: None,
                },
            ));
        }
    }
    let mut read = Vec::new();
    let mut not_drawn = Vec::new();
    for (name, role, spec) in named {
        match solver::io::campaign::read_record_at(
            Path::new(&name),
            &m,
            &spec.params,
            &solver::io::csv::ReadOptions::default(),
            None,
        ) {
            Ok(record) => {
                let mut r = solver::fitting::campaign::CampaignRecord::new(
                    spec.label,
                    record,
                    spec.params,
                    spec.setup,
                    spec.zeroed,
                );
                r.start_s = spec.start_s;
                read.push((name, role, r));
            }
            Err(e) => not_drawn.push(format!(
                "{name} is not drawn: it could not be read here ({e})"
            )),
        }
    }
    let records: Vec<PathRecord<'_>> = read
        .iter()
        .map(|(name, role, record)| PathRecord { name, role, record })
        .collect();
    let (figures, unpredicted) = path_figures("-o", &m, &values, &id.model, &records)?;
    not_drawn.extend(unpredicted);
    inputs.prediction_figures = figures;
    inputs.prediction_not_drawn = not_drawn;
    Ok(())
}

/// What a record of the reports is, besides its samples: its label, set-up, kinematic
/// parameters (mm), zeroing and start on the campaign clock.
struct CampaignRecordSpec {
    label: String,
    setup: String,
    params: Vec<f64>,
    zeroed: bool,
    start_s: Option<f64>,
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
        for x in &r.records {
            named("identification: fitted record", &x.data);
        }
    }
    for (_, v) in &inputs.validations {
        for x in &v.records {
            named("validation: record", &x.data);
        }
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

/// A record whose measured error is drawn against the identified model's prediction along
/// its path.
pub struct PathRecord<'a> {
    /// The record's name (its file, as given).
    pub name: &'a str,
    /// Its role in the check (`fitted`, `validation`).
    pub role: &'static str,
    /// The record with its label, set-up, kinematic parameters and zeroing, read as the
    /// identification (or the validation) read it.
    pub record: &'a solver::fitting::campaign::CampaignRecord,
}

/// Measured against predicted error along the path of each record, the prediction that of
/// the exact virtual machine at the identified `values` (model labelled `label`), each record
/// on its set-up (a set-up the identification did not fit refitted on the record, as `rtest
/// validate` does), drawn against the axis that moves most. A record that cannot be predicted
/// is not drawn: the second list says which and why, for the report.
///
/// # Errors
/// A figure that cannot be drawn (exit code 3).
pub fn path_figures(
    flag: &str,
    m: &model_spec::Machine,
    values: &solver::fitting::campaign::CampaignValues,
    label: &str,
    records: &[PathRecord<'_>],
) -> CliResult<(Vec<report::Figure>, Vec<String>)> {
    use solver::diagnosis::figures::{Figures, validation_figure};
    use solver::fitting::ValidateOptions;
    use solver::fitting::campaign::validate_record;
    let mut figures = Figures::default();
    let mut not_drawn = Vec::new();
    let mut taken = Vec::new();
    let opts = ValidateOptions::new().exact(true);
    for r in records {
        match validate_record(m, values, r.record, &opts) {
            Ok(v) => figures.paths.push(validation_figure(
                m,
                r.name,
                r.role,
                &r.record.record,
                &v.validation,
                label,
                &mut taken,
            )),
            Err(e) => not_drawn.push(format!("{} is not drawn: {e}", r.name)),
        }
    }
    let drawn = report::figures::path_figures(&figures)
        .map_err(|e| CliError::computation(format!("{flag}: {e}")))?;
    Ok((drawn, not_drawn))
}
