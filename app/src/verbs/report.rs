//! `rtest report`: one self-contained HTML document from the JSON reports of a check
//! (`identify`, `validate`, `diagnose`, `compensate`), and the `--report FILE` shortcut of
//! `identify`, `diagnose` and `compensate`, which renders what the verb just computed through
//! the same function.

use super::ReadFile;
use super::{EXIT_CODES, Error, VerbResult, check_outputs};
use crate::Done;
use model_spec::sha256::Digest;
use output::{Outputs, Target};
use report::{InputFile, Inputs, MachineFacts};
use std::collections::BTreeMap;
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
the axis that moves most (mm or degrees). The document makes no request of any kind: figures are \
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
/// of every validation, when the machine is known (`--machine`, or the built-in the reports
/// name) and the records were read (`records`); otherwise one line says why not. A validated
/// record on a set-up the identification did not fit has its set-up errors refitted on it, as
/// `rtest validate` did.
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
    let id_text = texts
        .iter()
        .find(|(f, _)| f == id_file)
        .map_or("", |(_, t)| t.as_str());
    let values = match report::json::read::parse_identification(id_file, id_text, &m) {
        Ok(v) => v.values,
        Err(e) => {
            inputs
                .prediction_not_drawn
                .push(format!("No path is drawn: {e}"));
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
        match formats::campaign::parse_record_at(
            name,
            bytes.as_slice(),
            &m,
            &spec.params,
            &formats::csv::ReadOptions::default(),
            None,
        ) {
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

/// The bytes of the records `rtest report` read, by (JSON report, name the report gives), or
/// why a record was not read.
type Records = BTreeMap<(String, String), Result<Vec<u8>, String>>;

/// A file a report names: the report (its file as given), the field, the role in the check,
/// the name, where it is looked for, and the most bytes a file of its kind may have.
struct Named {
    json: String,
    field: String,
    role: &'static str,
    name: String,
    at: PathBuf,
    max_bytes: u64,
}

/// Every file the reports name, in the order of the report (identification, validations,
/// diagnosis, compensation), each looked for relative to the directory of its report, or to
/// `data_dir` when it is given.
///
/// # Errors
/// A bad input naming the report, the field and the name, for an absolute name or one that
/// leaves the directory (`..`).
fn named_files(inputs: &Inputs, data_dir: Option<&Path>) -> VerbResult<Vec<Named>> {
    use formats::poses::MAX_FILE_BYTES as RECORD;
    use report::json::read::MAX_REPORT_BYTES as VALUES;
    let mut raw: Vec<(&str, String, &'static str, &str, u64)> = Vec::new();
    if let Some((f, r)) = &inputs.identification {
        for (i, x) in r.records.iter().enumerate() {
            let field = format!("records[{i}].data");
            raw.push((f, field, "identification: fitted record", &x.data, RECORD));
        }
    }
    for (f, v) in &inputs.validations {
        for (i, x) in v.records.iter().enumerate() {
            let field = format!("records[{i}].data");
            raw.push((f, field, "validation: record", &x.data, RECORD));
        }
        raw.push((f, "params".into(), "validation: values", &v.params, VALUES));
    }
    if let Some((f, d)) = &inputs.diagnosis {
        for (i, x) in d.records.iter().enumerate() {
            let role = if x.role == "fitted" {
                "diagnosis: fitted record"
            } else {
                "diagnosis: held-out record"
            };
            raw.push((f, format!("records[{i}].data"), role, &x.data, RECORD));
        }
        if d.records.is_empty() {
            for x in d.data.split(',') {
                raw.push((f, "data".into(), "diagnosis: fitted record", x, RECORD));
            }
            for (i, (x, _)) in d.held_out.iter().enumerate() {
                let field = format!("held_out[{i}]");
                raw.push((f, field, "diagnosis: held-out record", x, RECORD));
            }
        }
    }
    if let Some((f, c)) = &inputs.compensation {
        raw.push((
            f,
            "params_file".into(),
            "compensation: values",
            &c.params_file,
            VALUES,
        ));
        raw.push((
            f,
            "input".into(),
            "compensation: commanded poses",
            &c.input,
            RECORD,
        ));
    }
    raw.into_iter()
        .filter(|(_, _, _, name, _)| !name.is_empty())
        .map(|(json, field, role, name, max_bytes)| {
            let at = resolve(json, &field, name, data_dir)?;
            Ok(Named {
                json: json.to_string(),
                field,
                role,
                name: name.to_string(),
                at,
                max_bytes,
            })
        })
        .collect()
}

/// Where the file `name`, given by field `field` of report `json`, is looked for: relative to
/// the report's directory, or to `data_dir`.
///
/// # Errors
/// A bad input for an absolute name, or one whose `..` leave that directory.
fn resolve(json: &str, field: &str, name: &str, data_dir: Option<&Path>) -> VerbResult<PathBuf> {
    use std::path::Component;
    let (base, dir_words) = match data_dir {
        Some(d) => (d.to_path_buf(), "--data-dir"),
        None => (
            Path::new(json)
                .parent()
                .unwrap_or(Path::new(""))
                .to_path_buf(),
            "the report's directory",
        ),
    };
    let refuse = |what: &str| {
        Error::input(format!(
            "{json}: field `{field}`: `{name}` is {what}: rtest report reads the files a report names relative to {dir_words}, never elsewhere (give the files beside the report, or --data-dir DIR with the names relative to DIR)"
        ))
    };
    let mut depth = 0usize;
    for c in Path::new(name).components() {
        match c {
            Component::Prefix(_) | Component::RootDir => return Err(refuse("an absolute path")),
            Component::CurDir => {}
            Component::ParentDir => {
                depth = depth
                    .checked_sub(1)
                    .ok_or_else(|| refuse(&format!("a path that leaves {dir_words}")))?;
            }
            Component::Normal(_) => depth += 1,
        }
    }
    Ok(base.join(name))
}

/// Reads every regular file of `named` (at most its kind's bytes), hashed as read, and lists
/// it in `files` (once: a file two reports name, or that is given itself, is listed once);
/// anything else (a pipe, a device, a directory, a missing file) is listed as not hashed, and
/// never opened. The records' bytes are kept for the figures.
fn read_named(named: &[Named], files: &mut Vec<InputFile>) -> Records {
    let mut records = Records::new();
    for n in named {
        let shown = n.at.display().to_string();
        let read = read_regular(&n.at, n.max_bytes);
        if !files.iter().any(|f| same_path(Path::new(&f.path), &n.at)) {
            files.push(match &read {
                Ok((_, digest)) => InputFile::read(n.role, &shown, &n.at, digest.clone()),
                Err(why) => InputFile::not_hashed(n.role, &shown, Some(&n.at), why),
            });
        }
        if n.field.starts_with("records[") && !n.role.starts_with("diagnosis") {
            let at = n.at.display();
            records.insert(
                (n.json.clone(), n.name.clone()),
                read.map(|(bytes, _)| bytes)
                    .map_err(|why| format!("{at}: {why}")),
            );
        }
    }
    records
}

/// Whether `a` and `b` name the same file: equal once `./` prefixes are dropped, or both
/// found and the same file (resolved without opening either).
fn same_path(a: &Path, b: &Path) -> bool {
    let plain = |p: &Path| {
        p.components()
            .filter(|c| *c != std::path::Component::CurDir)
            .collect::<PathBuf>()
    };
    if plain(a) == plain(b) {
        return true;
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// The bytes of the regular file at `path` (at most `max_bytes`) and their digest, or why it
/// is not read (one line): not a regular file (a pipe, a device, a directory, or a link to
/// one: told by `metadata`, and the file is opened without blocking so that one swapped in
/// meanwhile cannot make the report wait), missing, unreadable or too large.
fn read_regular(path: &Path, max_bytes: u64) -> Result<(Vec<u8>, Digest), String> {
    const NOT_REGULAR: &str = "not a regular file";
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot be read here ({e})"))?;
    if !meta.is_file() {
        return Err(NOT_REGULAR.into());
    }
    let mut open = std::fs::OpenOptions::new();
    open.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        open.custom_flags(O_NONBLOCK);
    }
    let file = open
        .open(path)
        .map_err(|e| format!("cannot be read here ({e})"))?;
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        return Err(NOT_REGULAR.into());
    }
    model_spec::text::read_bytes_from(&path.display().to_string(), file, max_bytes).map_err(|e| {
        match e {
            model_spec::text::TextError::TooLarge { limit, .. } => {
                format!("larger than {limit} bytes, the most a file of its kind may have")
            }
            model_spec::text::TextError::Io { error, .. } => {
                format!("cannot be read here ({error})")
            }
            other => other.to_string(),
        }
    })
}

/// `O_NONBLOCK` of `open(2)`: opening a FIFO for reading returns at once instead of waiting
/// for a writer (a regular file reads as without it).
#[cfg(any(target_os = "linux", target_os = "android"))]
const O_NONBLOCK: i32 = 0o4000;
#[cfg(any(
    target_os = "macos",
    target_os = "ios",
    target_os = "freebsd",
    target_os = "netbsd",
    target_os = "openbsd",
    target_os = "dragonfly"
))]
const O_NONBLOCK: i32 = 0x0004;
/// No known `O_NONBLOCK` here: the type told by `metadata` before opening decides alone.
#[cfg(all(
    unix,
    not(any(
        target_os = "linux",
        target_os = "android",
        target_os = "macos",
        target_os = "ios",
        target_os = "freebsd",
        target_os = "netbsd",
        target_os = "openbsd",
        target_os = "dragonfly"
    ))
))]
const O_NONBLOCK: i32 = 0;

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
