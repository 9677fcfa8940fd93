//! `rtest validate`: identified values (an `identify` JSON) predict another measurement;
//! residuals before (nominal machine) and after (identified model), per direction.

use super::args::{self, RecordLimits, ValueBounds};
use super::campaign;
use super::{EXIT_CODES, Error, ReadFile, VerbResult, check_outputs};
use crate::Done;
use fitting::validate;
use fitting::validate::Extent;
use fitting::validate::Unidentified;
use fitting::{ValidateError, ValidateOptions};
use formats::tolerance::{MAX_TOLERANCE_BYTES, TestTolerances};
use history::{Check, RecheckedCalibration};
use model_spec::units::UM_PER_MM;
use output::{Outputs, Target};
use report::json::read::{IdentifiedValues, MAX_REPORT_BYTES, ReportError, parse_identification};
use report::json::recheck::RecheckReport;
use report::json::tolerance::{JudgeError, NoiseReport, RecordExtents, ToleranceReport};
use report::json::{ValidationReport, ValidationSource, to_json};
use report::text::validate::validation;
use std::path::{Path, PathBuf};

const LONG_ABOUT: &str = "\
Checks identified values on other measurements: the values of an `rtest identify` JSON \
(--params) predict the readings of measurement CSVs (--data FILE[,FILE...], or --campaign FILE), \
each record on its set-up; the residual (measured minus predicted) is reported per record, per \
direction x, y, z of the tool frame and overall: RMS and max in µm, before (the nominal machine) \
and after (the identified model).

The values must belong to the machine (name, fingerprint, model; within --max-error-um / \
--max-error-urad). The prediction is the exact machine at the values (--first-order: H·v).

A record on a set-up the identification fitted uses its XOW YOW ZOW; on a new set-up they are \
refitted on the record, everything else held (--setup LABEL chooses; default the fitted set-up \
at the records' kinematic parameters). --zeroed refits each record's zero dx0 dy0 dz0. Values \
the identification did not determine are set to 0 and named (--refuse-undetermined: an error).

--tolerance FILE: verdicts per test and direction by ISO 14253-1 (docs/tolerances.md).

A re-check (--refit XOB,ZOB: one sphere at a few poses after a head change, as a controller's \
preset cycle) refits the named machine parameters (the pivot) over every record with each new \
set-up (the preset), the rest held; a change beyond --max-change-um/-urad is refused; \
--params-out FILE writes the calibration with the re-checked values (for compensate); --record \
puts the re-check into the history as its own series (docs/probe.md).

--json FILE (`-`: standard output) writes the report. Details: docs/campaigns.md §6, \
docs/identification.md §9, §11, §16.";

/// Flags of `rtest validate`.
#[derive(Debug, clap::Args)]
#[command(
    about = "Check identified values on another measurement: residual RMS and max (µm) before and after",
    long_about = LONG_ABOUT,
    after_help = EXIT_CODES
)]
pub struct ValidateArgs {
    /// Built-in machine (see `rtest machines`) or path of a machine TOML file.
    #[arg(long, value_name = "NAME|FILE")]
    machine: String,
    /// The JSON written by `rtest identify --json`, of one record or a campaign (values in µm
    /// and µrad).
    #[arg(long, value_name = "FILE")]
    params: PathBuf,
    /// The measurement CSV to predict (axes in mm and degrees, dx_um,dy_um,dz_um in µm), or a
    /// comma list of them (each record labelled by its file's stem).
    #[arg(
        long,
        value_name = "FILE[,FILE...]",
        required_unless_present = "campaign"
    )]
    data: Option<String>,
    /// A campaign file to predict (TOML: records with their set-ups, ball positions, zeroing;
    /// docs/campaigns.md): a record on a fitted set-up uses its values, a record on a new
    /// set-up has its set-up errors (and its zero, when zeroed) refitted.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["data", "zeroed", "param", "setup"])]
    campaign: Option<PathBuf>,
    /// The set-up label of every --data record: a set-up of the identification (its set-up
    /// errors are used) or a new one (refitted on each record). Default: the identification's
    /// set-up when it fitted one at the records' kinematic parameters, else each record its own
    /// set-up, named by its file's stem.
    #[arg(long, value_name = "LABEL")]
    setup: Option<String>,
    /// Kinematic symbols (mm), `NAME=VALUE,...`, of every --data record (the ball's position),
    /// overriding the machine's defaults.
    #[arg(long, value_name = "NAME=VALUE,...")]
    param: Option<String>,
    /// The readings of --data were zeroed at the first sample: each record's zero dx0 dy0 dz0
    /// is refitted on it (the fitted record's own is used).
    #[arg(long)]
    zeroed: bool,
    /// Predict with the first-order model H·v instead of the exact machine.
    #[arg(long)]
    first_order: bool,
    /// Fail when a parameter has no value, instead of setting it to 0.
    #[arg(long)]
    refuse_undetermined: bool,
    /// Also write the report as JSON to FILE (`-`: standard output).
    #[arg(long, value_name = "FILE")]
    json: Option<Target>,
    /// A tolerance file (TOML: [[test]] tables with name, direction x|y|z, max_um, range_um;
    /// docs/tolerances.md): a verdict per test and direction, before and after, by ISO 14253-1.
    #[arg(long, value_name = "FILE")]
    tolerance: Option<PathBuf>,
    /// The standard uncertainty of a reading for the verdicts, µm, every direction (default:
    /// the identification's noise model).
    #[arg(
        long,
        value_name = "S",
        requires = "tolerance",
        conflicts_with = "noise_record"
    )]
    noise_um: Option<f64>,
    /// A record of the machine standing still (a measurement CSV, at least 100 samples): the
    /// reading noise per direction for the verdicts (default: the identification's noise model).
    #[arg(long, value_name = "FILE", requires = "tolerance")]
    noise_record: Option<PathBuf>,
    #[command(flatten)]
    records: RecordLimits,
    #[command(flatten)]
    instrument: super::args::InstrumentArgs,
    #[command(flatten)]
    probe: super::probe_records::ProbeArgs,
    /// A re-check (as a controller's preset cycle, e.g. one sphere at a few poses after a head
    /// change): refit these machine parameters (the pivot, e.g. XOB,ZOB) over every record,
    /// with each record's new set-up (the preset) and zero, every other value held.
    #[arg(long, value_name = "NAME[,NAME...]")]
    refit: Option<String>,
    /// With --refit: write the calibration's identification with the re-checked values in
    /// place (what `rtest compensate --params` takes) to FILE.
    #[arg(long, value_name = "FILE", requires = "refit")]
    params_out: Option<Target>,
    /// With --refit: refuse a re-check that moves a translational parameter by more than this,
    /// µm (a controller's maxModification).
    #[arg(long, value_name = "UM", default_value_t = compensation::limits::MAX_CHANGE_UM, value_parser = super::args::positive, requires = "refit")]
    max_change_um: f64,
    /// With --refit: refuse a re-check that moves an angular parameter by more than this, µrad.
    #[arg(long, value_name = "URAD", default_value_t = compensation::limits::MAX_CHANGE_URAD, value_parser = super::args::positive, requires = "refit")]
    max_change_urad: f64,
    #[command(flatten)]
    bounds: ValueBounds,
    #[command(flatten)]
    history: super::record::RecordArgs,
}

/// Runs `rtest validate`: the identification's values (of one record or several) predict
/// the records of `--data` or `--campaign`, each on its set-up.
pub fn run(args: &ValidateArgs) -> VerbResult<Done> {
    let machine = super::load_machine_read(&args.machine)?;
    let m = machine.machine;
    let files = match &args.data {
        Some(list) => args::files("--data", list)?,
        None => Vec::new(),
    };
    let flag = if args.campaign.is_some() {
        "--campaign"
    } else {
        "--data"
    };
    let mut inputs = vec![("--params", args.params.as_path())];
    inputs.extend(files.iter().map(|f| ("--data", f.as_path())));
    inputs.extend(args.campaign.iter().map(|f| ("--campaign", f.as_path())));
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    inputs.extend(args.instrument.input());
    inputs.extend(args.probe.input());
    inputs.extend(args.tolerance.iter().map(|f| ("--tolerance", f.as_path())));
    inputs.extend(
        args.noise_record
            .iter()
            .map(|f| ("--noise-record", f.as_path())),
    );
    let mut outputs: Vec<(&str, &Target)> = args.json.iter().map(|t| ("--json", t)).collect();
    outputs.extend(args.params_out.iter().map(|t| ("--params-out", t)));
    let db = args.history.input();
    inputs.extend(db.as_ref().map(|(f, p)| (*f, p.as_path())));
    check_outputs(&inputs, &outputs, &[])?;
    let pivot = refit_names(args)?;
    if args.history.record && pivot.is_none() {
        return Err(Error::usage(
            "--record records a re-check (--refit NAMES); a validation changes no value of the machine: record the identification (rtest identify --record)",
        ));
    }
    let mut recorder = args.history.recorder()?;
    let tolerances = args.tolerance.as_deref().map(read_tolerances).transpose()?;
    let noise_um = match args.noise_um {
        Some(s) if s.is_finite() && s >= 0.0 => Some(s),
        Some(s) => {
            return Err(Error::usage(format!(
                "--noise-um: {s} is not a standard uncertainty (a finite number ≥ 0, µm)"
            )));
        }
        None => None,
    };
    let (id, params_text) =
        read_params(&args.params, &m).map_err(|e| Error::input(format!("--params: {e}")))?;
    let params_read = ReadFile::new(
        "--params",
        &args.params,
        model_spec::sha256::Digest::of(params_text.as_bytes()),
    );
    let values = &id.values;
    if let Some(names) = &pivot {
        fitting::campaign::recheck::pivot_columns(&m, values, names)
            .map_err(|e| Error::usage(format!("--refit: {e} ({})", args.params.display())))?;
    }
    campaign::check_campaign_values(&m, &values.layout, &values.values, &args.bounds.values())
        .map_err(|e| implausible(args, &e))?;
    let read = args.records.read_options();
    let shown = super::progress::wanted(matches!(args.json, Some(Target::Stdout)));
    let (instrument, instrument_read) = args.instrument.load_read()?;
    let (probe, probe_read) = args.probe.load_read()?;
    let through = campaign::Through::of(&instrument, &probe);
    let campaign_file = match &args.campaign {
        Some(path) => Some(campaign::read_file("--campaign", &m, path)?),
        None => None,
    };
    let file_list: Vec<PathBuf> = match &campaign_file {
        Some((f, _)) => f.records.iter().map(|r| r.path.clone()).collect(),
        None => files.clone(),
    };
    let mut loaded = {
        let (_bar, read) = super::progress::reading_all(shown, &file_list, &read);
        match (&args.campaign, campaign_file) {
            (Some(path), Some(file)) => {
                campaign::from_file("--campaign", &m, path, file, &read, through)?
            }
            _ => {
                let params = super::pose_args::params(&m, args.param.as_deref())?;
                campaign::from_files("--data", &m, &files, &params, args.zeroed, &read, through)?
            }
        }
    };
    if args.campaign.is_none() {
        let setup = match &args.setup {
            Some(setup) => {
                simulation::campaign::check_label("--setup", setup)
                    .map_err(|e| Error::usage(e.to_string()))?;
                Some(setup.clone())
            }
            // A re-check's records are on new set-ups (the preset is refitted).
            None if pivot.is_some() => None,
            None => fitted_setup(values, &loaded.campaign),
        };
        if let Some(setup) = setup {
            for r in &mut loaded.campaign.records {
                r.setup = setup.clone();
            }
        }
    }
    if let Some(t) = &tolerances {
        let labels: Vec<String> = loaded
            .campaign
            .records
            .iter()
            .map(|r| r.label.clone())
            .collect();
        t.check_names(&labels)
            .map_err(|e| Error::input(format!("--tolerance {e}")))?;
    }
    let noise = match &tolerances {
        Some(_) => Some(reading_noise(
            args,
            noise_um,
            &params_text,
            &m,
            &read,
            through,
        )?),
        None => None,
    };
    loaded.check_times(flag, &m, &values.model)?;
    let mut opts = ValidateOptions::default();
    opts.exact = !args.first_order;
    if args.refuse_undetermined {
        opts.unidentified = Unidentified::Refuse;
    }
    let (v, recheck) = {
        let bar = super::progress::counting(shown);
        match &pivot {
            Some(names) => {
                let r =
                    fitting::campaign::recheck(&m, values, &loaded.campaign, names, &opts, &bar)
                        .map_err(|e| validate_error(args, e))?;
                let report = RecheckReport::new(&m, names, &r)
                    .map_err(|e| Error::computation(format!("--refit: {e}")))?;
                check_changes(args, &report)?;
                (r.validation, Some(report))
            }
            None => (
                validate(&m, values, &loaded.campaign, &opts, &bar)
                    .map_err(|e| validate_error(args, e))?,
                None,
            ),
        }
    };
    let params_file = args.params.display().to_string();
    let kinematics: Vec<Vec<f64>> = loaded
        .campaign
        .records
        .iter()
        .map(|r| r.params.clone())
        .collect();
    let source = ValidationSource {
        model: &id.model_name,
        params: &params_file,
        data: &loaded.files,
        kinematics: &kinematics,
        exact: !args.first_order,
    };
    let mut report = ValidationReport::new(&m, source, &v)
        .map_err(|e| Error::computation(format!("{flag}: {e}")))?;
    report.recheck = recheck;
    if let (Some(t), Some(noise)) = (&tolerances, noise) {
        let extents = extents(&loaded.campaign, &v)?;
        report.tolerance = Some(ToleranceReport::new(t, &report, &extents, noise).map_err(
            |e| match e {
                JudgeError::Name(e) => Error::input(format!("--tolerance {e}")),
                other => Error::computation(format!("--tolerance: {other}")),
            },
        )?);
    }
    let mut text = validation(&report);
    text.push_str(&loaded.zeroed_notes(if args.campaign.is_some() {
        "say `zeroed = true` for it in the campaign file"
    } else {
        "give --zeroed"
    }));
    let mut files = Outputs::new();
    if let Some(target) = &args.json {
        let json = to_json(&report).map_err(|e| Error::computation(format!("--json: {e}")))?;
        files.add("--json", target.clone(), json);
    }
    if let (Some(target), Some(c)) = (&args.params_out, &report.recheck) {
        let file = args.params.display().to_string();
        let updated =
            report::json::recheck::updated_identification(&file, &params_text, c, &loaded.files)
                .map_err(|e| Error::input(format!("--params: {e}")))?;
        files.add("--params-out", target.clone(), updated);
    }
    let stdout_taken = [&args.json, &args.params_out]
        .iter()
        .any(|t| matches!(t, Some(Target::Stdout)));
    let done = Done::new(text, files, stdout_taken);
    let Some(mut r) = recorder.take() else {
        return Ok(done);
    };
    r.add_read(&loaded.read);
    r.add_read(&[params_read]);
    r.add_read(
        &instrument_read
            .into_iter()
            .chain(probe_read)
            .collect::<Vec<_>>(),
    );
    r.add_read(
        &ReadFile::machine(&args.machine, machine.digest)
            .into_iter()
            .collect::<Vec<_>>(),
    );
    let calibration = RecheckedCalibration {
        fingerprint: id.fingerprint.clone(),
        model: id.model_name.clone(),
        base_model: serde_json::from_str::<serde_json::Value>(&params_text)
            .ok()
            .and_then(|j| j.get("base_model")?.as_str().map(str::to_string)),
        terms: values.model.terms.iter().map(|t| t.spelling(&m)).collect(),
    };
    let check = Check::from_recheck(&report, &calibration, r.provenance())
        .ok_or_else(|| Error::computation("--record: the re-check has no report"))?;
    Ok(done.recording(r, check))
}

/// The names of `--refit` (a re-check), or `None` (a validation).
///
/// # Errors
/// A usage error for an empty name.
fn refit_names(args: &ValidateArgs) -> VerbResult<Option<Vec<String>>> {
    let Some(list) = &args.refit else {
        return Ok(None);
    };
    let names: Vec<String> = list.split(',').map(|n| n.trim().to_string()).collect();
    if names.iter().any(String::is_empty) {
        return Err(Error::usage(format!(
            "--refit `{list}`: give machine parameters separated by commas (XOB,ZOB)"
        )));
    }
    Ok(Some(names))
}

/// Refuses a re-check whose pivot moved beyond `--max-change-um` / `--max-change-urad`: a
/// change that large is a crash or a wrong set-up, not what a re-check corrects.
fn check_changes(args: &ValidateArgs, r: &RecheckReport) -> VerbResult<()> {
    for p in &r.pivot {
        let (limit, flag) = if p.unit == "urad" {
            (args.max_change_urad, "--max-change-urad")
        } else {
            (args.max_change_um, "--max-change-um")
        };
        if let Some(d) = p.change
            && d.abs() > limit
        {
            return Err(Error::computation(format!(
                "--refit: the re-check moves {} by {} {} from the calibration's value, beyond {flag} {}: a change that large is a crash, a wrong set-up or another head, not what a re-check corrects; calibrate again (or raise {flag} if it is real)",
                p.name,
                model_spec::units::significant(d),
                model_spec::units::symbol(&p.unit),
                model_spec::units::significant(limit)
            )));
        }
    }
    Ok(())
}

/// The set-up of `--data` records without `--setup`: the identification's, when it fitted one
/// set-up whose kinematic parameters are every record's (one ball mounting, measured along
/// other paths: the usual check of one record on another); `None` (each record on a new set-up
/// of its own, refitted) otherwise.
fn fitted_setup(
    values: &fitting::campaign::CampaignValues,
    c: &simulation::campaign::Campaign,
) -> Option<String> {
    let layout = &values.layout;
    let [setup] = layout.setups.as_slice() else {
        return None;
    };
    let params = &layout.records.first()?.params;
    c.records
        .iter()
        .all(|r| r.params == *params)
        .then(|| setup.clone())
}

/// Values that cannot be a machine's, as a verb's error.
fn implausible(args: &ValidateArgs, e: &fitting::Implausible) -> Error {
    Error::input(format!(
        "--params: {}: {e}: these cannot be the errors of a machine tool (--max-error-um, --max-error-urad change the bounds)",
        args.params.display()
    ))
}

/// A validation error as a verb's error: a record that does not fit the identification (its
/// set-up, its start) is a bad input.
fn validate_error(args: &ValidateArgs, e: ValidateError) -> Error {
    match e {
        ValidateError::Unidentified(names) => Error::input(format!(
            "--params: {} gave no value for {} (not determined by the identification) and --refuse-undetermined is set (without it they are set to 0)",
            args.params.display(),
            names.join(", ")
        )),
        ValidateError::Shape(why) => Error::input(format!("--data: cannot validate: {why}")),
        other => Error::computation(format!("--data: cannot validate: {other}")),
    }
}

/// The identification report at `path` for machine `m`, with its text (read once).
fn read_params(
    path: &Path,
    m: &model_spec::Machine,
) -> Result<(IdentifiedValues, String), ReportError> {
    let text = model_spec::text::read_text(path, MAX_REPORT_BYTES)?;
    let id = parse_identification(&path.display().to_string(), &text, m)?;
    Ok((id, text))
}

/// The tolerance file of `--tolerance`, read and checked (its names are checked against the
/// records once they are read).
fn read_tolerances(path: &Path) -> VerbResult<TestTolerances> {
    let text = model_spec::text::read_text(path, MAX_TOLERANCE_BYTES)
        .map_err(|e| Error::input(format!("--tolerance: {e}")))?;
    formats::tolerance::parse_file(&path.display().to_string(), &text)
        .map_err(|e| Error::input(format!("--tolerance {e}")))
}

/// The standard uncertainty of a reading per direction (µm) the verdicts assume, and where it
/// comes from: `--noise-um`, the static record of `--noise-record`, or the noise model of the
/// identification report (`params_text`).
fn reading_noise(
    args: &ValidateArgs,
    noise_um: Option<f64>,
    params_text: &str,
    m: &model_spec::Machine,
    read: &formats::csv::ReadOptions,
    through: campaign::Through,
) -> VerbResult<NoiseReport> {
    if let Some(s) = noise_um {
        return Ok(NoiseReport {
            source: format!("--noise-um {}", model_spec::units::significant(s)),
            sigma_um: [s; 3],
        });
    }
    if let Some(path) = &args.noise_record {
        let (still, _, _) = super::read_record(
            "--noise-record",
            m,
            path,
            read,
            through,
            &m.default_parameters(),
        )?;
        let model = fitting::NoiseModel::from_static_record(&still)
            .map_err(|e| Error::input(format!("--noise-record: {}: {e}", path.display())))?;
        return Ok(NoiseReport {
            source: format!("the static record {}", path.display()),
            sigma_um: model.sigma_mm.map(|s| s * UM_PER_MM),
        });
    }
    let params = args.params.display();
    let json: serde_json::Value = serde_json::from_str(params_text)
        .map_err(|e| Error::input(format!("--params: {params}: {e}")))?;
    let Some(noise) = json.get("noise_model") else {
        return Err(Error::input(format!(
            "--params: {params} has no `noise_model` (written before noise models): the verdicts of --tolerance need the reading noise; give --noise-um or --noise-record"
        )));
    };
    let sigma: Option<Vec<f64>> = noise
        .get("sigma_um")
        .and_then(|s| s.as_array())
        .and_then(|a| a.iter().map(serde_json::Value::as_f64).collect());
    let sigma = match sigma.as_deref() {
        Some(&[x, y, z]) if [x, y, z].iter().all(|s| s.is_finite() && *s >= 0.0) => [x, y, z],
        _ => {
            return Err(Error::input(format!(
                "--params: {params}: field `noise_model.sigma_um` must be three numbers ≥ 0 (µm, x y z)"
            )));
        }
    };
    let what = noise
        .get("source")
        .and_then(|s| s.as_str())
        .unwrap_or("unknown");
    Ok(NoiseReport {
        source: format!("the noise model of {params} ({what})"),
        sigma_um: sigma,
    })
}

/// Per record of `c`, the extents of its readings and of its residual in `v`, mm.
fn extents(
    c: &simulation::campaign::Campaign,
    v: &fitting::campaign::CampaignValidation,
) -> VerbResult<Vec<RecordExtents>> {
    c.records
        .iter()
        .zip(&v.records)
        .map(|(r, rv)| {
            match (
                Extent::of(&r.record.measured),
                Extent::of(&rv.validation.residual),
            ) {
                (Some(measured), Some(residual)) => Ok(RecordExtents { measured, residual }),
                _ => Err(Error::input(format!(
                    "--tolerance: record {} has no sample to judge",
                    r.label
                ))),
            }
        })
        .collect()
}
