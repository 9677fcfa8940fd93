//! `rtest report`: one self-contained HTML document from the JSON reports of a check
//! (`identify`, `validate`, `diagnose`, `compensate`), and the `--report FILE` shortcut of
//! `identify`, `diagnose` and `compensate`, which renders what the verb just computed through
//! the same function.

use super::ReadFile;
use super::report_files::{Records, named_files, read_named};
use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use output::{Outputs, Target};
use report::{InputFile, Inputs, MachineFacts};
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Writes one self-contained HTML report of a check, for reading on screen and printing to PDF (A4): \
the machine and model; the data (records with their samples, input files with their size and \
SHA-256); the identified values with their standard uncertainties (µm, µrad) and the groups the \
data could not separate; the validations (residual RMS and maximum per direction, µm, and a \
figure); the diagnosis (findings, gain, what remains); the compensation summary. A part whose \
report is not given is one line saying so. Details: docs/report.md.

The inputs are the JSON files that `rtest identify --json`, `validate --json`, `diagnose --json` \
and `compensate --json` write, of one record or of a campaign, in any order; each is recognised by \
its content. At most one identification, one diagnosis and one compensation; any number of \
validations. They must belong to one check: one machine (that of --machine, fingerprint included) \
and the identification's model and records.

The records the reports name are read relative to the directory of the report that names them (or \
to --data-dir DIR; an absolute name, or one that leaves that directory, is refused), hashed, and \
drawn: the measured error against the identified model's prediction (µm) along each path, against \
the axis that moves most (mm or degrees); a touch probe's records per pose, each reading with its \
±1σ bar, read again through the probe file the identification names (its SHA-256 checked). The document makes no request of any kind: figures are \
inline SVG, their font (DejaVu Sans, about 1 MB) is embedded, a Content-Security-Policy forbids \
every other source, and there is no script. `identify`, `diagnose` and `compensate` write the same \
report with --report FILE. `-o -` writes it to standard output.";

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
    /// Where the records and files the reports name are looked for (names relative to DIR;
    /// default: the directory of the report that names them).
    #[arg(long, value_name = "DIR")]
    data_dir: Option<PathBuf>,
}

/// The time the report is written, RFC 3339 UTC (`None` when the clock is unusable).
fn now() -> Option<String> {
    history::Timestamp::now().ok().map(|t| t.to_string())
}

/// A new set of inputs for a report of machine `m`, written now, with the input `files` the
/// verb read (their digests those of the bytes it read).
pub fn inputs_for(m: &model_spec::Machine, files: &[ReadFile]) -> Inputs {
    let mut i = Inputs::new();
    i.machine = Some(MachineFacts::of(m));
    i.written_at = now();
    i.files = files
        .iter()
        .map(|f| InputFile::read(&f.flag, &f.path, Path::new(&f.path), f.digest.clone()))
        .collect();
    i
}

/// The HTML of `inputs` for the output of `flag`.
///
/// # Errors
/// A figure that cannot be drawn (exit code 3).
pub fn render(flag: &str, inputs: &Inputs) -> VerbResult<String> {
    report::render(inputs).map_err(|e| Error::computation(format!("{flag}: {e}")))
}

/// Runs `rtest report`.
pub fn run(args: &ReportArgs) -> VerbResult<Done> {
    let mut inputs_list: Vec<(&str, &Path)> =
        args.reports.iter().map(|p| ("JSON", p.as_path())).collect();
    let machine_file = args.machine.as_deref().and_then(super::machine_file);
    inputs_list.extend(machine_file.map(|p| ("--machine", p)));
    check_outputs(&inputs_list, &[("-o", &args.output)], &[])?;
    if let Some(dir) = &args.data_dir
        && !dir.is_dir()
    {
        return Err(Error::usage(format!(
            "--data-dir: `{}` is not a directory",
            dir.display()
        )));
    }
    let mut inputs = Inputs::new();
    let mut machine_read = None;
    let machine = match &args.machine {
        Some(name) => {
            let loaded = super::load_machine_read(name)?;
            machine_read = loaded
                .digest
                .map(|d| InputFile::read("--machine", name, Path::new(name), d));
            inputs.machine = Some(MachineFacts::of(&loaded.machine));
            Some(loaded.machine)
        }
        None => None,
    };
    inputs.written_at = now();
    let mut files = Vec::new();
    let mut texts = Vec::with_capacity(args.reports.len());
    for path in &args.reports {
        let (doc, text, digest) =
            report::inputs::read_document(path).map_err(|e| Error::input(e.to_string()))?;
        let file = path.display().to_string();
        inputs
            .add(&file, doc)
            .map_err(|e| Error::input(e.to_string()))?;
        files.push(InputFile::read("JSON report", &file, path, digest));
        texts.push((file, text));
    }
    files.extend(machine_read);
    let named = named_files(&inputs, args.data_dir.as_deref())?;
    let records = read_named(&named, &mut files);
    inputs.files = files;
    inputs.no_path_figures = Some(
        "The base and extended models' predictions along the paths are drawn by rtest diagnose --report; section 4 draws the identified model's.".into(),
    );
    draw_paths(&mut inputs, machine, &texts, &records)?;
    let html = render("-o", &inputs)?;
    let mut out = Outputs::new();
    out.add("-o", args.output.clone(), html);
    let stdout_taken = matches!(args.output, Target::Stdout);
    Ok(Done::new("", out, stdout_taken))
}

/// The identified model's prediction along the path of every record of the identification and
/// of every validation (for a touch probe's records, at each pose), when the machine is known
/// (`--machine`, or the built-in the reports name) and the records were read (`records`);
/// otherwise one line says why not. A validated record on a set-up the identification did not
/// fit has its set-up errors refitted on it, as `rtest validate` did. A probe's records are read
/// again through the probe file the identification names, once its bytes are those identify
/// read.
fn draw_paths(
    inputs: &mut Inputs,
    machine: Option<model_spec::Machine>,
    texts: &[(String, String)],
    records: &Records,
) -> VerbResult<()> {
    let Some((id_file, id)) = &inputs.identification else {
        if !inputs.validations.is_empty() {
            inputs.prediction_not_drawn.push(
                "No path is drawn: the identified values are in the identification report, which is not given.".into(),
            );
        }
        return Ok(());
    };
    let probe = match &id.probe {
        None => None,
        Some(p) => match probe_of(id_file, p, records) {
            Ok(probe) => Some(probe),
            Err(why) => {
                inputs
                    .prediction_not_drawn
                    .push(format!("No pose is drawn: {why}"));
                return Ok(());
            }
        },
    };
    let nothing = if probe.is_some() {
        "No pose is drawn"
    } else {
        "No path is drawn"
    };
    let m = match machine.map_or_else(|| model_spec::load_machine(&id.machine), Ok) {
        Ok(m) => m,
        Err(_) => {
            inputs.prediction_not_drawn.push(format!(
                "{nothing}: machine {} is no built-in; give its description with --machine.",
                id.machine
            ));
            return Ok(());
        }
    };
    let id_text = texts
        .iter()
        .find(|(f, _)| f == id_file)
        .map_or("", |(_, t)| t.as_str());
    let values = match report::json::read::parse_identification(id_file, id_text, &m) {
        Ok(v) => v.values,
        Err(e) => {
            inputs.prediction_not_drawn.push(format!("{nothing}: {e}"));
            return Ok(());
        }
    };
    // The records the reports name, as read by `read_named`, at their kinematic parameters,
    // each on its set-up; one that cannot be read, or predicted, is named with why.
    let mut named: Vec<(&str, &str, &'static str, CampaignRecordSpec)> = Vec::new();
    for (r, x) in values.layout.records.iter().zip(&id.records) {
        named.push((
            id_file,
            &x.data,
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
    for (file, v) in &inputs.validations {
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
                file,
                &x.data,
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
    let opts = formats::csv::ReadOptions::default();
    for (json, name, role, spec) in named {
        let bytes = match records.get(&(json.to_string(), name.to_string())) {
            Some(Ok(bytes)) => bytes,
            Some(Err(why)) => {
                not_drawn.push(format!("{name} is not drawn: {why}"));
                continue;
            }
            None => {
                not_drawn.push(format!("{name} is not drawn: it was not read"));
                continue;
            }
        };
        let record = match &probe {
            Some(p) => {
                super::probe_records::probe_record_of_bytes(name, bytes, &m, &spec.params, p, &opts)
                    .map(|(r, _)| r)
            }
            None => formats::campaign::parse_record_at(
                name,
                bytes.as_slice(),
                &m,
                &spec.params,
                &opts,
                None,
            ),
        };
        match record {
            Ok(record) => {
                let mut r = simulation::campaign::CampaignRecord::new(
                    spec.label,
                    record,
                    spec.params,
                    spec.setup,
                    spec.zeroed,
                );
                r.start_s = spec.start_s;
                read.push((name, role, r));
            }
            Err(e) => not_drawn.push(format!("{name} is not drawn: it could not be read ({e})")),
        }
    }
    let records: Vec<PathRecord<'_>> = read
        .iter()
        .map(|(name, role, record)| PathRecord { name, role, record })
        .collect();
    let (figures, unpredicted) = if probe.is_some() {
        probe_figures("-o", &m, &values, &id.model, &records)?
    } else {
        path_figures("-o", &m, &values, &id.model, &records)?
    };
    not_drawn.extend(unpredicted);
    inputs.prediction_figures = figures;
    inputs.prediction_not_drawn = not_drawn;
    Ok(())
}

/// The probe instrument the identification `p` (of report `id_file`) read its records
/// through: its file as `rtest report` read it (`records`), when its bytes are those identify
/// read; otherwise why not (one line).
fn probe_of(
    id_file: &str,
    p: &report::json::probe::ProbeReport,
    records: &Records,
) -> Result<formats::probe::ProbeInstrument, String> {
    let Some(file) = &p.file else {
        return Err(format!(
            "{id_file} does not name the probe file its records were read through (`probe.file`, which identify --json writes since rtest reads the records again); identify again with --json to draw them"
        ));
    };
    let bytes = match records.get(&(id_file.to_string(), file.clone())) {
        Some(Ok(bytes)) => bytes,
        Some(Err(why)) => return Err(format!("the probe file {why}")),
        None => return Err(format!("the probe file {file} was not read")),
    };
    let digest = model_spec::sha256::Digest::of(bytes);
    if let Some(sha) = &p.sha256
        && *sha != digest.sha256
    {
        return Err(format!(
            "the probe file {file} is not the one identify read (SHA-256 {} here, {sha} in {id_file}): through another probe's radii and σ the records would not be read as they were identified",
            digest.sha256
        ));
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|e| format!("the probe file {file} is not UTF-8 text ({e})"))?;
    formats::probe::parse_probe_instrument(file, text)
        .map_err(|e| format!("the probe file cannot be read ({e})"))
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

/// A record whose measured error is drawn against the identified model's prediction along
/// its path.
pub struct PathRecord<'a> {
    /// The record's name (its file, as given).
    pub name: &'a str,
    /// Its role in the check (`fitted`, `validation`).
    pub role: &'static str,
    /// The record with its label, set-up, kinematic parameters and zeroing, read as the
    /// identification (or the validation) read it.
    pub record: &'a simulation::campaign::CampaignRecord,
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
    values: &fitting::campaign::CampaignValues,
    label: &str,
    records: &[PathRecord<'_>],
) -> VerbResult<(Vec<report::Figure>, Vec<String>)> {
    use diagnosis::figures::{Figures, validation_figure};
    use fitting::ValidateOptions;
    use fitting::campaign::validate_record;
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
        .map_err(|e| Error::computation(format!("{flag}: {e}")))?;
    Ok((drawn, not_drawn))
}

/// The identified model's prediction at each pose of each probe record (the exact virtual
/// machine at the identified `values`, model labelled `label`, each record on its set-up as
/// [`path_figures`] has it) beside the measured readings with their ±1σ bars, one figure per
/// record. A record that cannot be predicted is not drawn: the second list says which and why.
///
/// # Errors
/// A figure that cannot be drawn (exit code 3).
pub fn probe_figures(
    flag: &str,
    m: &model_spec::Machine,
    values: &fitting::campaign::CampaignValues,
    label: &str,
    records: &[PathRecord<'_>],
) -> VerbResult<(Vec<report::Figure>, Vec<String>)> {
    use fitting::ValidateOptions;
    use fitting::campaign::validate_record;
    let opts = ValidateOptions::new().exact(true);
    let mut figures = Vec::new();
    let mut not_drawn = Vec::new();
    let mut taken = Vec::new();
    for r in records {
        let v = match validate_record(m, values, r.record, &opts) {
            Ok(v) => v.validation,
            Err(e) => {
                not_drawn.push(format!("{} is not drawn: {e}", r.name));
                continue;
            }
        };
        let record = &r.record.record;
        let measured: Vec<[f64; 3]> = v
            .prediction
            .iter()
            .zip(&v.residual)
            .map(|(p, e)| [p[0] + e[0], p[1] + e[1], p[2] + e[2]])
            .collect();
        let rotary = m
            .rotary_axes()
            .map(|a| {
                let q = record
                    .samples
                    .iter()
                    .map(|s| s.commands[a].to_degrees())
                    .collect();
                (m.axes[a].name.clone(), q)
            })
            .collect();
        let poses = report::probe_figure::ProbePoses {
            name: r.name,
            role: r.role,
            model: label,
            rotary,
            measured_mm: &measured,
            covariance: &record.covariance,
            prediction_mm: &v.prediction,
        };
        figures.push(
            report::probe_figure::probe_figure(&poses, &mut taken).map_err(|e| {
                Error::computation(format!("{flag}: a figure cannot be drawn: {e}"))
            })?,
        );
    }
    Ok((figures, not_drawn))
}
