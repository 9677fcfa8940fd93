//! `rtest diagnose`: where the model and the measurement disagree, the missing effect named as
//! an engineer reads it, the extended model (as a machine description `identify` and `generate`
//! accept) and its gain on the fitted and the held-out data.

use super::args::{self, RecordLimits, ValueBounds};
use super::campaign;
use super::diagnose_records::Reader;
use super::{EXIT_CODES, Error, ReadFile, VerbResult, check_outputs};
use crate::Done;
use diagnosis::dictionary::DictionaryOptions;
use diagnosis::figures::figures;
use diagnosis::{DiagnoseError, DiagnoseOptions, diagnose};
use fitting::check_values;
use output::{Outputs, Target};
use report::json::{DiagnosisReport, DiagnosisSource, to_json};
use report::text::diagnose::diagnosis;
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Finds what a model lacks from a measurement CSV (--data, the fitted path, e.g. K4: axes in mm and \
degrees, dx_um,dy_um,dz_um in µm), extends the model with it and measures the gain on the fitted \
data and on held-out measurements (--validate, e.g. K1 and K2). Details: docs/diagnosis.md.

1. Base fit: --model identified on --data; its residual RMS (µm); outliers listed and left out.
2. Noise model (--noise, --noise-record, else estimated): σ (µm), AR(1) φ; every test whitened.
3. Residual structure: the residual (µm) against every axis that moves, time and reversal.
4. Candidates: every term of the machine's topology the model lacks (harmonics, polynomials, \
reversal, constants, zero offsets, drifts) and scanned ones (period, step, warm-up, jump).
5. Selection: one at a time, F-test at --alpha corrected for the candidates tried (Bonferroni, \
else a Monte-Carlo null); confounded candidates and alternatives named; beyond --budget: \
implausible.
6. Gain: the extended model's residual RMS (µm) on every --validate file; findings confirmed.
7. Verdict: what remains tested against the noise; the extended model recommended or not, and why.

Values are in µm (translational errors, offsets) and µrad (angular errors); a harmonic as cos, \
sin, amplitude and phase (degrees). Several records: --data a.csv,b.csv or --campaign FILE \
(docs/campaigns.md).

--json FILE writes the report (`-`: standard output); --model-out FILE the machine description \
with the extended model appended as [models.extended]; --plot DIR SVG figures of every record; \
--report FILE the HTML report (docs/report.md). All outputs are written, or none.";

/// Flags of `rtest diagnose`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Find what a model lacks (named ISO 230 error, µm/µrad), extend it, and measure the gain on held-out data",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct DiagnoseArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The base model to diagnose (`reduced`, `full`, or a model of the machine file).
    #[arg(long, value_name = "NAME")]
    model: String,
    /// The measurement CSV the models are fitted on (axes in mm and degrees, dx_um,dy_um,dz_um
    /// in µm), or a comma list of them: a campaign, each record on its own ball set-up and with
    /// its own R-test zero, the machine's errors shared (docs/campaigns.md).
    #[arg(
        long,
        value_name = "FILE[,FILE...]",
        required_unless_present = "campaign"
    )]
    data: Option<String>,
    /// A campaign file (TOML, docs/campaigns.md) whose records are fitted together.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["data", "zeroed", "param"])]
    pub(super) campaign: Option<PathBuf>,
    /// A campaign file of held-out records (their set-ups, ball positions, zeroing): a record
    /// on a fitted set-up takes its set-up errors from the fit.
    #[arg(long, value_name = "FILE")]
    pub(super) validate_campaign: Option<PathBuf>,
    /// Kinematic symbols (mm), `NAME=VALUE,...`, of every --data and --validate record (the
    /// ball's position).
    #[arg(long, value_name = "NAME=VALUE,...")]
    param: Option<String>,
    /// Held-out measurement CSVs (comma list) on which the gain is measured; not fitted. On the
    /// fitted records' set-up when they have one, else each on a set-up of its own.
    #[arg(long, value_name = "FILE,FILE")]
    validate: Option<String>,
    /// The readings were zeroed at the first sample: every record's own zero offsets dx0 dy0
    /// dz0 join the base model (fitted records) or are refitted on it (held-out records).
    #[arg(long)]
    pub(super) zeroed: bool,
    /// Significance level of each step, after the correction for the candidates tried
    /// (strictly between 0 and 1).
    #[arg(long, value_name = "A", default_value = "0.01", value_parser = parse_alpha,
          allow_negative_numbers = true)]
    alpha: f64,
    /// Highest harmonic K of rotary-axis candidates (harmonic:1..K, cycles per revolution).
    #[arg(long, value_name = "K", default_value = "4",
          value_parser = clap::value_parser!(u32).range(0..=36))]
    harmonics: u32,
    /// Highest Legendre order P of linear-axis candidates (poly:1..P over the stroke).
    #[arg(long, value_name = "P", default_value = "3",
          value_parser = clap::value_parser!(u32).range(0..=12))]
    poly: u32,
    /// Highest order T of the zero-offset drift candidates: a linear drift (rate, or time:1 on
    /// a record without t_s) and time:2..T.
    #[arg(long, value_name = "T", default_value = "2",
          value_parser = clap::value_parser!(u32).range(0..=12))]
    time: u32,
    /// Largest plausible size of a finding, per unit (`um=100,urad=200,ms=20,1=0.1,um/s=0.5,
    /// urad/s=1`; any subset, the others keep these defaults): a larger finding fits, but is
    /// not named as a cause and is left out of the extended model.
    #[arg(long, value_name = "UNIT=SIZE,…")]
    budget: Option<String>,
    /// What the fits do with parameters the data cannot determine: `none` (no value),
    /// `min-norm`, or `zero:NAME,NAME` (as `identify`). Held-out predictions that need them are
    /// flagged and not counted either way.
    #[arg(long, value_name = "none|min-norm|zero:NAME,…")]
    constraint: Option<String>,
    #[command(flatten)]
    noise: args::NoiseArgs,
    /// Also write the diagnosis as JSON to FILE (values in µm and µrad; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
    /// Write the machine description with the extended model appended ([models.extended]).
    #[arg(long, value_name = "FILE")]
    model_out: Option<Target>,
    /// Write SVG plots (measured against predicted along each path; residual spectra) to DIR
    /// (created if missing).
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
    /// Also write the HTML report of this diagnosis to FILE (docs/report.md: findings, gain,
    /// what remains, the figures inline; `-`: standard output).
    #[arg(long, value_name = "FILE")]
    report: Option<Target>,
    #[command(flatten)]
    records: RecordLimits,
    #[command(flatten)]
    instrument: args::InstrumentArgs,
    #[command(flatten)]
    probe: super::probe_records::ProbeArgs,
    #[command(flatten)]
    bounds: ValueBounds,
}

/// `--alpha`: a number strictly between 0 and 1.
fn parse_alpha(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(a) if a.is_finite() && a > 0.0 && a < 1.0 => Ok(a),
        _ => Err("expected a number strictly between 0 and 1, e.g. 0.01".into()),
    }
}

/// Runs `rtest diagnose`: the fitted records (`--data`, or `--campaign`) and the held-out
/// records (`--validate`, or `--validate-campaign`) read as two campaigns, one record being the
/// campaign of that record, and diagnosed by [`diagnose`].
pub fn run(args: &DiagnoseArgs) -> VerbResult<Done> {
    let machine = super::load_machine_read(&args.machine)?;
    let (m, machine_text) = (machine.machine, machine.text);
    let (label, model) = args::model(&m, Some(&args.model), None)?;
    let held_files = match &args.validate {
        Some(list) => args::files("--validate", list)?,
        None => Vec::new(),
    };
    let files = match &args.data {
        Some(list) => args::files("--data", list)?,
        None => Vec::new(),
    };
    if args.validate.is_some() && args.validate_campaign.is_some() {
        return Err(Error::usage(
            "--validate and --validate-campaign both give held-out records: give one",
        ));
    }
    // Every output is checked before any work, against every input known so far (the records
    // of campaign files are checked again once the files are read).
    let mut outputs: Vec<(&str, &Target)> = args.json.iter().map(|t| ("--json", t)).collect();
    outputs.extend(args.model_out.iter().map(|t| ("--model-out", t)));
    outputs.extend(args.report.iter().map(|t| ("--report", t)));
    let dirs: Vec<(&str, &Path)> = args.plot.iter().map(|d| ("--plot", d.as_path())).collect();
    let mut given: Vec<(&str, &Path)> = files.iter().map(|f| ("--data", f.as_path())).collect();
    given.extend(args.campaign.iter().map(|f| ("--campaign", f.as_path())));
    given.extend(held_files.iter().map(|f| ("--validate", f.as_path())));
    given.extend(
        args.validate_campaign
            .iter()
            .map(|f| ("--validate-campaign", f.as_path())),
    );
    given.extend(args.noise.input());
    given.extend(args.instrument.input());
    given.extend(args.probe.input());
    given.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    check_outputs(&given, &outputs, &dirs)?;
    if let Some(dir) = &args.plot {
        super::check_dir_inputs(&given, "--plot", dir, &|n: &str| n.ends_with(".svg"))?;
    }

    let (instrument, instrument_read) = args.instrument.load_read()?;
    let (probe, probe_read) = args.probe.load_read()?;
    let through = campaign::Through::of(&instrument, &probe);
    // Progress bars on a terminal's standard error, unless the JSON report takes standard output.
    let shown = super::progress::wanted(matches!(args.json, Some(Target::Stdout)));
    let reader = Reader {
        m: &m,
        args,
        params: super::pose_args::params(&m, args.param.as_deref())?,
        read: args.records.read_options(),
        through,
        shown,
    };
    let fitted = reader.fitted(&files)?;
    let held = reader.held_out(&fitted, &held_files)?;
    let (fitted_inputs, held_inputs) = (fitted.inputs(), held.inputs());
    let mut inputs: Vec<(&str, &Path)> = fitted_inputs
        .iter()
        .map(|p| ("--data", p.as_path()))
        .collect();
    inputs.extend(held_inputs.iter().map(|p| ("--validate", p.as_path())));
    inputs.extend(args.noise.input());
    inputs.extend(args.instrument.input());
    inputs.extend(args.probe.input());
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    if args.campaign.is_some() || args.validate_campaign.is_some() {
        check_outputs(&inputs, &outputs, &dirs)?;
        if let Some(dir) = &args.plot {
            super::check_dir_inputs(&inputs, "--plot", dir, &|n: &str| n.ends_with(".svg"))?;
        }
    }
    let flag = if args.campaign.is_some() {
        "--campaign"
    } else {
        "--data"
    };
    fitted.check_times(flag, &m, &model)?;
    held.check_times("--validate", &m, &model)?;

    let (opts, noise_read) = options(args, &m, &reader.read, through)?;
    // The files as read, with the digests of the bytes read, for --report.
    let mut read_files: Vec<ReadFile> = fitted.read.clone();
    read_files.extend(held.read.iter().cloned());
    read_files.extend(noise_read);
    read_files.extend(instrument_read);
    read_files.extend(probe_read);
    read_files.extend(ReadFile::machine(&args.machine, machine.digest));
    let bar = super::progress::Bar::new(shown, false);
    let d = diagnose(&m, &model, &fitted.campaign, &held.campaign, &opts, &bar);
    drop(bar);
    let d = d.map_err(|e| match e {
        DiagnoseError::Estimate(e) | DiagnoseError::Refine(fitting::IdentifyError::Estimate(e)) => {
            super::identify::estimate_error(e)
        }
        DiagnoseError::Campaign(e) => Error::usage(format!("{flag}: {e}")),
        other => Error::computation(format!("{flag}: cannot diagnose: {other}")),
    })?;
    for fit in [&d.base_fit, &d.extended_fit] {
        check_values(&m, &fit.as_identification(), &args.bounds.values()).map_err(|e| {
            Error::computation(format!(
                "{flag}: implausible result: {e}; the fit does not describe this machine (--max-error-um, --max-error-urad change the bounds)"
            ))
        })?;
    }

    // Everything is computed before anything is written.
    let diagnosed = Diagnosed {
        m: &m,
        label: &label,
        d: &d,
        fitted: &fitted,
        held: &held,
        opts: &opts,
    };
    let (out, report) = diagnosed.outputs(args, &machine_text, &read_files, &inputs)?;
    let mut text = diagnosis(&report);
    text.push_str(&fitted.zeroed_notes(if args.campaign.is_some() {
        "say `zeroed = true` for it in the campaign file"
    } else {
        "give --zeroed"
    }));
    let stdout_taken = outputs.iter().any(|(_, t)| matches!(t, Target::Stdout));
    Ok(Done::new(text, out, stdout_taken))
}

/// A diagnosis and what it was made of, for its outputs.
struct Diagnosed<'a> {
    m: &'a model_spec::Machine,
    label: &'a str,
    d: &'a diagnosis::Diagnosis,
    fitted: &'a campaign::Loaded,
    held: &'a campaign::Loaded,
    opts: &'a DiagnoseOptions,
}

impl Diagnosed<'_> {
    /// The outputs the flags ask for (`--model-out`, `--json`, `--plot`, `--report`), none of
    /// them over an input, and the report; `machine_text` the description as read,
    /// `read_files` the inputs as read (for `--report`).
    fn outputs(
        &self,
        args: &DiagnoseArgs,
        machine_text: &str,
        read_files: &[ReadFile],
        inputs: &[(&str, &Path)],
    ) -> VerbResult<(Outputs, DiagnosisReport)> {
        let (label, d, fitted, held, opts) =
            (self.label, self.d, self.fitted, self.held, self.opts);
        let flag = if args.campaign.is_some() {
            "--campaign"
        } else {
            "--data"
        };
        let data = fitted.files.join(",");
        let mut out = Outputs::new();
        out.protect(inputs);
        let mut model_out = None;
        if let Some(target) = &args.model_out {
            let (name, contents) = d
                .extended_machine(
                    self.m,
                    machine_text,
                    label,
                    &format!("rtest diagnose on {data}"),
                )
                .map_err(|e| Error::computation(format!("--model-out: {e}")))?;
            out.add("--model-out", target.clone(), contents);
            model_out = Some((name, target.to_string()));
        }
        let source = DiagnosisSource {
            machine_source: &args.machine,
            label,
            data: fitted.files.clone(),
            held_out: held.files.clone(),
            data_arguments: data_arguments(args, &data),
            opts,
            model_out,
        };
        let report = DiagnosisReport::new(self.m, &source, d)
            .map_err(|e| Error::computation(format!("{flag}: {e}")))?;
        if let Some(target) = &args.json {
            let json = to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
            out.add("--json", target.clone(), json);
        }
        let figs = if args.plot.is_some() || args.report.is_some() {
            let what = if args.plot.is_some() {
                "--plot"
            } else {
                "--report"
            };
            let mut names = fitted.files.clone();
            names.extend(held.files.iter().cloned());
            Some(
                figures(
                    self.m,
                    d,
                    label,
                    opts,
                    &fitted.campaign,
                    &held.campaign,
                    &names,
                )
                .map_err(|e| Error::computation(format!("{what}: {e}")))?,
            )
        } else {
            None
        };
        if let (Some(dir), Some(figs)) = (&args.plot, &figs) {
            for (name, _, svg) in super::figures::svgs(figs)? {
                out.add_in_dir("--plot", dir, &name, svg);
            }
        }
        if let Some(target) = &args.report {
            let mut i = super::report::inputs_for(self.m, read_files);
            if let Some(figs) = &figs {
                i.path_figures = ::report::figures::path_figures(figs)
                    .map_err(|e| Error::computation(format!("--report: {e}")))?;
            }
            add_diagnosis(&mut i, &report)?;
            out.add(
                "--report",
                target.clone(),
                super::report::render("--report", &i)?,
            );
        }
        Ok((out, report))
    }
}

/// The command-line words that give the fitted records of `args` to another command (`data`
/// the `--data` files as given).
fn data_arguments(args: &DiagnoseArgs, data: &str) -> Vec<String> {
    let mut out = match &args.campaign {
        Some(c) => vec!["--campaign".to_string(), c.display().to_string()],
        None => vec!["--data".to_string(), data.to_string()],
    };
    if args.zeroed {
        out.push("--zeroed".into());
    }
    if let Some(p) = &args.param {
        out.extend(["--param".to_string(), p.clone()]);
    }
    if let Some(i) = &args.instrument.instrument {
        out.extend(["--instrument".to_string(), i.clone()]);
    }
    if let Some(f) = &args.instrument.readings_frame {
        out.extend(["--readings-frame".to_string(), f.clone()]);
    }
    if let Some(p) = &args.probe.probe {
        out.extend(["--probe".to_string(), p.display().to_string()]);
    }
    out
}

/// The options of a diagnosis from the flags (all but the data).
fn options(
    args: &DiagnoseArgs,
    m: &model_spec::Machine,
    read: &formats::csv::ReadOptions,
    instrument: campaign::Through,
) -> VerbResult<(DiagnoseOptions, Option<ReadFile>)> {
    let mut opts = DiagnoseOptions::default();
    opts.dictionary = DictionaryOptions::new(args.harmonics, args.poly, args.time);
    opts.alpha = args.alpha;
    opts.constraint = args::constraint(args.constraint.as_deref())?;
    let (noise, noise_read) = args.noise.choice(m, read, instrument)?;
    opts.noise = noise;
    if let Some(b) = &args.budget {
        opts.budget = diagnosis::plausible::Budget::parse(b)
            .map_err(|e| Error::usage(format!("--budget: {e}")))?;
    }
    Ok((opts, noise_read))
}

/// Adds the diagnosis just computed to the inputs of its HTML report (`--report`).
fn add_diagnosis(i: &mut ::report::Inputs, r: &DiagnosisReport) -> VerbResult {
    i.add(
        "this run of rtest diagnose",
        ::report::Document::Diagnosis(Box::new(r.clone())),
    )
    .map_err(|e| Error::computation(format!("--report: {e}")))
}
