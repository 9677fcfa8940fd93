//! `rtest identify`: the errors of a model from an R-test measurement, with uncertainties and
//! what the data cannot separate.

use super::args::{self, RecordLimits, ValueBounds};
use super::campaign;
use super::record;
use super::{EXIT_CODES, Error, ReadFile, VerbResult, check_outputs};
use crate::Done;
use fitting::campaign::{CampaignIdentification, CampaignValues, identify};
use fitting::hmatrix::HMatrixError;
use fitting::noise::NoiseChoice;
use fitting::streaming::{StreamingError, identify_file};
use fitting::{EstimateError, IdentifyError, IdentifyOptions, RefineOptions};
use output::{Outputs, Target};
use report::json::identify::StreamingReport;
use report::json::{CampaignSource, IdentificationReport, to_json};
use report::text::identify::identification;
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Identifies the errors of a model from a measurement CSV (axes in mm and degrees, \
dx_um,dy_um,dz_um in µm) by least squares on the H matrix, refined against the exact virtual \
machine: values in µm (translational errors, sensor offsets, changes of kinematic symbols) and \
µrad (angular errors), standard uncertainties, correlations, rank, condition number, and what \
the data cannot separate.

The model is --model NAME (full, reduced, …), --terms LIST (NAME or NAME@BASIS: XOC, \
ECC@harmonic:2, EXX@reversal, dx0@time:1, ECC@velocity, Zt, …), or both (the terms added). A \
parameter the data cannot determine is printed as \"not determined: confounded with …\" (null \
in the JSON) unless --constraint min-norm or zero:NAME,... gives it a value. --zeroed: \
readings zeroed at the first sample (dx0 dy0 dz0 join the model).

The refinement (Gauss-Newton, two or three steps) removes the second-order terms (about 1e-3 µm \
for errors of tens of µm and µrad); one that does not converge is exit code 3, and \
--first-order skips it. The uncertainties assume a noise model per direction (white or AR(1), \
by generalized least squares): --noise, --noise-record, else estimated from the residual.

--data a.csv,b.csv or --campaign FILE fit several records together (docs/campaigns.md); \
--stream reads one long record in blocks. --json FILE (`-`: standard output) writes the report \
that validate and compensate read, --report FILE the HTML report, --record the history entry. \
Plausibility bounds: --max-reading-um (readings), --max-error-um, --max-error-urad (values).

Details: docs/identification.md (§16: the command line).";

/// Flags of `rtest identify`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Identify a model's errors (µm, µrad) from a measurement CSV, with uncertainties",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct IdentifyArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// Model of the machine whose terms are identified (`reduced`, `full`, …); required
    /// unless --terms is given.
    #[arg(long, value_name = "NAME")]
    model: Option<String>,
    /// Terms to identify, added to --model or alone: comma list of NAME or NAME@BASIS
    /// (`ECC@harmonic:2,dx0@time:1`; bases const, harmonic:K, poly:K, reversal, time:K,
    /// period:P, step:V, exp:TAU, velocity; instrument terms SXX … SZY; kinematic symbols by
    /// their exact name, `Zt`, identified as a change in µm).
    #[arg(long, value_name = "LIST")]
    terms: Option<String>,
    /// The measurement CSV (axes in mm and degrees, dx_um,dy_um,dz_um in µm), or a comma list
    /// of them: a campaign, each record on its own ball set-up (its own XOW YOW ZOW) and with
    /// its own R-test zero, the machine's errors shared (docs/campaigns.md).
    #[arg(
        long,
        value_name = "FILE[,FILE...]",
        required_unless_present = "campaign"
    )]
    data: Option<String>,
    /// A campaign file (TOML: records with their files, labels, set-ups, ball positions,
    /// zeroing and start times; docs/campaigns.md), fitted together.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["data", "zeroed", "param", "stream"])]
    campaign: Option<PathBuf>,
    /// Kinematic symbols (mm), `NAME=VALUE,...`, overriding the machine's defaults for every
    /// record of --data (the ball's position: Xw=...,Zw=...): the gains and the exact machine
    /// use them, and the files' linear axes must keep the nest on that ball.
    #[arg(long, value_name = "NAME=VALUE,...")]
    param: Option<String>,
    /// The readings were zeroed at the first sample: fit dx0 dy0 dz0 too and say which errors
    /// they swallow.
    #[arg(long)]
    zeroed: bool,
    /// Values for undetermined parameters: `none` (default: no value), `min-norm` (the
    /// minimum-norm solution), or `zero:NAME,NAME` (fix those to 0 before the fit).
    #[arg(long, value_name = "none|min-norm|zero:NAME,...")]
    constraint: Option<String>,
    /// Skip the refinement against the exact machine: keep the first-order least-squares
    /// values (biased by second-order terms, ~1e-3 µm at tens of µm/µrad).
    #[arg(long)]
    first_order: bool,
    /// Also write the report as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
    /// Also write the HTML report of this identification to FILE (docs/report.md; one record
    /// or a campaign; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    report: Option<Target>,
    /// Read the measurement in blocks and fold them into an incremental QR: for long records
    /// (10^6 samples and more), memory bounded by the number of parameters. First order (the
    /// refinement needs the whole record); one --data file.
    #[arg(long)]
    stream: bool,
    #[command(flatten)]
    noise: args::NoiseArgs,
    /// Samples per block with --stream (at least 1).
    #[arg(long, value_name = "N", default_value_t = 4096, requires = "stream",
          value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
    block: u64,
    #[command(flatten)]
    records: RecordLimits,
    #[command(flatten)]
    instrument: args::InstrumentArgs,
    #[command(flatten)]
    probe: super::probe_records::ProbeArgs,
    #[command(flatten)]
    bounds: ValueBounds,
    #[command(flatten)]
    history: record::RecordArgs,
}

/// Runs `rtest identify`: one record or several, read as a campaign (a record is a campaign
/// of one), fitted together, reported once; `--stream` reads one long record in blocks.
pub fn run(args: &IdentifyArgs) -> VerbResult<Done> {
    let machine = super::load_machine_read(&args.machine)?;
    let m = machine.machine;
    let (label, model) = args::model(&m, args.model.as_deref(), args.terms.as_deref())?;
    let files = match &args.data {
        Some(list) => args::files("--data", list)?,
        None => Vec::new(),
    };
    let flag = if args.campaign.is_some() {
        "--campaign"
    } else {
        "--data"
    };
    let declared = args.noise.declared()?;
    if args.stream {
        check_stream_flags(args, files.len(), &declared)?;
    }
    let params = super::pose_args::params(&m, args.param.as_deref())?;
    let read = args.records.read_options();
    // A progress bar while the records are read, on a terminal's standard error, unless the
    // JSON report takes standard output.
    let shown = super::progress::wanted(matches!(args.json, Some(Target::Stdout)));
    let (instrument, instrument_read) = args.instrument.load_read()?;
    let (probe, probe_read) = args.probe.load_read()?;
    let through = campaign::Through::of(&instrument, &probe);
    // The records' files: those of --data now; a campaign file's once it is read.
    let campaign_file = match &args.campaign {
        Some(path) => {
            check_outputs(&[("--campaign", path.as_path())], &[], &[])?;
            Some(campaign::read_file("--campaign", &m, path)?)
        }
        None => None,
    };
    let file_list: Vec<PathBuf> = match &campaign_file {
        Some((f, _)) => f.records.iter().map(|r| r.path.clone()).collect(),
        None => files.clone(),
    };
    let mut inputs: Vec<(&str, &std::path::Path)> = args
        .campaign
        .iter()
        .map(|p| ("--campaign", p.as_path()))
        .collect();
    inputs.extend(file_list.iter().map(|p| (flag, p.as_path())));
    inputs.extend(args.noise.input());
    inputs.extend(args.instrument.input());
    inputs.extend(args.probe.input());
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let mut outputs: Vec<(&str, &Target)> = args.json.iter().map(|t| ("--json", t)).collect();
    outputs.extend(args.report.iter().map(|t| ("--report", t)));
    let db = args.history.input();
    let mut all_inputs = inputs.clone();
    all_inputs.extend(db.as_ref().map(|(f, p)| (*f, p.as_path())));
    check_outputs(&all_inputs, &outputs, &[])?;
    let mut recorder = args.history.recorder()?;
    let (noise, noise_read) = args.noise.choice(&m, &read, through)?;
    // The files as read, with the digests of the bytes read, for --report and --record: the
    // records' (and the campaign file), then the others.
    let mut read_files: Vec<ReadFile> = Vec::new();
    let opts = IdentifyOptions::new().constraint(args::constraint(args.constraint.as_deref())?);
    let (ident, refinement, streaming, loaded) = if args.stream {
        let (ident, streaming, file) = streamed(args, &m, &model, &files[0], &opts, &read, shown)?;
        read_files.push(file);
        (ident, None, Some(streaming), None)
    } else {
        let loaded = {
            let (_bar, read) = super::progress::reading_all(shown, &file_list, &read);
            match (&args.campaign, campaign_file) {
                (Some(path), Some(file)) => {
                    campaign::from_file("--campaign", &m, path, file, &read, through)?
                }
                _ => campaign::from_files(
                    "--data",
                    &m,
                    &files,
                    &params,
                    args.zeroed,
                    &read,
                    through,
                )?,
            }
        };
        loaded.check_times(flag, &m, &model)?;
        let c = &loaded.campaign;
        let opts = IdentifyOptions::new()
            .constraint(opts.constraint.clone())
            .noise(noise);
        // Records modelled with different values of a machine length cannot share its change:
        // a bad input, said before any fitting.
        let labelled: Vec<(&str, &[f64])> = c
            .records
            .iter()
            .map(|r| (r.label.as_str(), r.params.as_slice()))
            .collect();
        fitting::offsets::check_shared_symbols(&m, &model, &labelled)
            .map_err(|e| Error::input(format!("{flag}: {e}")))?;
        let opts = if args.first_order {
            opts
        } else {
            opts.refined(RefineOptions::default())
        };
        let ident = identify(&m, &model, c, &opts).map_err(refine_error)?;
        let refinement = ident.refinement.clone();
        read_files.extend(loaded.read.iter().cloned());
        (ident, refinement, None, Some(loaded))
    };
    read_files.extend(noise_read);
    read_files.extend(instrument_read);
    let probe_file = probe_read
        .as_ref()
        .map(|f| (f.path.clone(), f.digest.clone()));
    read_files.extend(probe_read);
    read_files.extend(ReadFile::machine(&args.machine, machine.digest));
    campaign::check_campaign_values(&m, &ident.layout, &ident.fit.values, &args.bounds.values())
        .map_err(|e| implausible(&e))?;
    let data: Vec<String> = match &loaded {
        Some(l) => l.files.clone(),
        None => files.iter().map(|f| f.display().to_string()).collect(),
    };
    let source = CampaignSource {
        label: &label,
        base_model: args.model.as_deref(),
        data: &data,
    };
    let mut report = IdentificationReport::of_campaign(&m, source, &ident, refinement.as_ref())
        .map_err(|e| Error::computation(format!("{flag}: {e}")))?;
    report.streaming = streaming;
    if let (Some(p), Some(l)) = (&probe, &loaded) {
        let mut fits =
            report::json::probe::ProbeReport::of(&m, p, &l.campaign, &l.files, &l.probe, &ident);
        // Named with its digest, so that `rtest report` reads the records through it again.
        if let Some((file, digest)) = &probe_file {
            fits = fits.read_from(file, digest);
        }
        report.probe = Some(fits);
    }
    if args.param.is_some() {
        report.notes.push(format!(
            "kinematic parameters (--param): {}",
            parameters_text(&m, &params)
        ));
    }
    let mut text = identification(&report);
    if let Some(p) = &report.probe {
        text.push_str(&report::text::probe::probe(p));
    }
    if args.param.is_some() {
        text.push_str(&format!(
            "Kinematic parameters (--param): {}\n",
            parameters_text(&m, &params)
        ));
    }
    if let Some(l) = &loaded {
        text.push_str(&l.zeroed_notes(if args.campaign.is_some() {
            "say `zeroed = true` for it in the campaign file"
        } else {
            "give --zeroed"
        }));
    }
    let mut out = Outputs::new();
    if let Some(target) = &args.json {
        let json = to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
        out.add("--json", target.clone(), json);
    }
    if let Some(target) = &args.report {
        let html = html_report(&m, &read_files, &report, &ident, loaded.as_ref(), &label)?;
        out.add("--report", target.clone(), html);
    }
    let stdout_taken = [&args.json, &args.report]
        .iter()
        .any(|t| matches!(t, Some(Target::Stdout)));
    if let Some(r) = recorder.as_mut() {
        r.add_read(&read_files);
    }
    let done = Done::new(text, out, stdout_taken);
    Ok(match recorder {
        Some(r) => {
            let check = ::history::Check::from_identification(&report, r.provenance());
            done.recording(r, check)
        }
        None => done,
    })
}

/// Refuses, with `--stream`, what a stream read once in blocks cannot do: several `files`,
/// a noise model (`declared`) or a noise record, other kinematic parameters.
fn check_stream_flags(args: &IdentifyArgs, files: usize, declared: &NoiseChoice) -> VerbResult {
    if files > 1 {
        return Err(Error::usage(
            "--stream reads one long record in blocks into an incremental QR; several records are fitted whole (each with its own set-up and zero, in one design matrix held in memory): give one --data file, or drop --stream",
        ));
    }
    if args.noise.noise_record.is_some() || matches!(declared, NoiseChoice::Model(_)) {
        return Err(Error::usage(
            "--stream fits by ordinary least squares in one pass; --noise models and --noise-record need the whole record (drop --stream, or use --noise white)",
        ));
    }
    if args.param.is_some() {
        return Err(Error::usage(
            "--stream reads the file at the machine's default kinematic parameters; drop --param, or --stream",
        ));
    }
    Ok(())
}

/// The one `--data` record at `path` identified as a stream (read in blocks into an
/// incremental QR with the options `opts`, at the default kinematic parameters: `--param` is
/// refused with `--stream`), as a campaign of one; the blocks read and the file as read.
fn streamed(
    args: &IdentifyArgs,
    m: &model_spec::Machine,
    model: &simulation::model::Model,
    path: &std::path::Path,
    opts: &IdentifyOptions,
    read: &formats::csv::ReadOptions,
    shown: bool,
) -> VerbResult<(CampaignIdentification, StreamingReport, ReadFile)> {
    let data_path = path;
    let (bar, read) = super::progress::reading(shown, data_path, read);
    let opts = opts.clone().zeroed(args.zeroed);
    let fitted = identify_file(m, model, data_path, &opts, args.block as usize, &read);
    drop(bar);
    let (ident, run, digest) = fitted.map_err(|e| stream_error(e, data_path))?;
    let file = ReadFile::new("--data", data_path, digest);
    let streaming = StreamingReport {
        blocks: run.blocks,
        block: args.block as usize,
        first_block: run.first_block,
    };
    let record_label = formats::campaign::stem_label(data_path);
    let ident = CampaignIdentification::of_record(m, &ident, &record_label, m.default_parameters())
        .map_err(estimate_error)?;
    Ok((ident, streaming, file))
}

/// The HTML report (`--report`) of this identification: its records, set-ups and values, and
/// each record's measured error against its prediction along its path (not drawn for a
/// streamed record, whose samples were never held whole).
fn html_report(
    m: &model_spec::Machine,
    inputs: &[ReadFile],
    report: &IdentificationReport,
    ident: &CampaignIdentification,
    loaded: Option<&campaign::Loaded>,
    label: &str,
) -> VerbResult<String> {
    let mut i = super::report::inputs_for(m, inputs);
    i.add(
        "this run of rtest identify",
        ::report::Document::Identification(Box::new(report.clone())),
    )
    .map_err(|e| Error::computation(format!("--report: {e}")))?;
    match loaded {
        None => i.prediction_not_drawn.push(format!(
            "{} is not drawn: a streamed record is read block by block, and its figure would read it all",
            report.data.as_deref().unwrap_or("the record")
        )),
        Some(l) => {
            let values = CampaignValues::of(ident);
            let records: Vec<super::report::PathRecord<'_>> = l
                .campaign
                .records
                .iter()
                .zip(&l.files)
                .map(|(r, f)| super::report::PathRecord {
                    name: f,
                    role: "fitted",
                    record: r,
                })
                .collect();
            // A probe's records: per pose, not along a path.
            let draw = if report.probe.is_some() {
                super::report::probe_figures
            } else {
                super::report::path_figures
            };
            (i.prediction_figures, i.prediction_not_drawn) =
                draw("--report", m, &values, label, &records)?;
        }
    }
    super::report::render("--report", &i)
}

/// A streaming error as a verb's error.
fn stream_error(e: StreamingError<formats::csv::CsvError>, data_path: &std::path::Path) -> Error {
    match e {
        StreamingError::Read(e) => Error::input(format!("--data: {e}")),
        e @ StreamingError::ReadTwice(_) => Error::input(format!("--data: {e}")),
        StreamingError::HMatrix(e @ HMatrixError::Times { .. }) => {
            Error::input(format!("--data {}: {e}", data_path.display()))
        }
        StreamingError::Estimate(e) => estimate_error(e),
        other => Error::computation(format!("--data: cannot identify: {other}")),
    }
}

/// `Xw = -217.504 mm, …`: every symbol and its value.
fn parameters_text(m: &model_spec::Machine, params: &[f64]) -> String {
    m.symbols
        .iter()
        .zip(params)
        .map(|(s, v)| format!("{} = {} mm", s.name, model_spec::units::short(*v)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// An implausible result as a verb's error.
fn implausible(e: &fitting::Implausible) -> Error {
    Error::computation(format!(
        "--data: implausible result: {e}; the fit does not describe this machine (too few or unsuitable data, or a model the data cannot determine; --max-error-um, --max-error-urad change the bounds)"
    ))
}

/// A refinement error as a verb's error.
fn refine_error(e: IdentifyError) -> Error {
    match e {
        IdentifyError::Estimate(e) => estimate_error(e),
        e @ IdentifyError::NotConverged { .. } => Error::computation(format!(
            "--data: {e}: the data do not determine the model well enough for the exact machine (--first-order gives the first-order values)"
        )),
        other => Error::computation(format!(
            "--data: the refinement against the exact machine failed: {other} (--first-order skips it)"
        )),
    }
}

/// An estimation error as a verb's error: an unknown constraint name is a usage error, too few
/// samples a bad input, anything else a failed computation.
pub(super) fn estimate_error(e: EstimateError) -> Error {
    match e {
        EstimateError::UnknownParameter(name, names) => Error::usage(format!(
            "--constraint: `{name}` is not a parameter of the model (parameters: {names})"
        )),
        e @ EstimateError::TooFewReadings { .. } => Error::input(format!("--data: {e}")),
        other => Error::computation(format!("--data: cannot identify: {other}")),
    }
}
