//! `rtest validate`: identified values (an `identify` JSON) predict another measurement;
//! residuals before (nominal machine) and after (identified model), per direction.

use super::args::{RecordLimits, ValueBounds};
use super::{CliError, CliResult, EXIT_CODES, check_outputs, print_text, write, wrote};
use output::{Outputs, Target};
use solver::fitting::hmatrix::parameter_names;
use solver::fitting::sanity::check_model_values;
use solver::fitting::validate::Unidentified;
use solver::fitting::{ValidateError, ValidateOptions, validate};
use solver::io::report::{ValidationReport, ValidationSource, read_identification, to_json};
use solver::io::text::validate::{validation, zeroed_note};
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Checks identified values on another measurement: the model and values of an `rtest identify` \
JSON (--params) predict the readings of a measurement CSV (--data: axes in mm and degrees, \
dx_um,dy_um,dz_um in µm), and the residual (measured minus predicted) is reported per direction \
x, y, z of the tool frame and overall: RMS and maximum in µm, before (the nominal machine: \
prediction 0) and after (the identified model). Overall RMS = sqrt(Σ r² / 3N).

The values must belong to the machine: the JSON's machine name and fingerprint (topology and \
machine-side kinematic defaults) must be this machine's, its base model must exist, every \
parameter must be there, and every value within --max-error-um / --max-error-urad.

The prediction is the exact virtual machine at the identified values (no linearisation); with \
--first-order it is the first-order model H·v (the difference is the second-order terms, about \
1e-3 µm for errors of tens of µm and µrad). With --zeroed (readings zeroed at the first sample) \
the prediction is zeroed at the first sample too, so constant effects cancel.

Parameters the identification could not determine (value null) are set to 0 and named; \
--refuse-undetermined makes that an error instead.

--json writes {machine, model, params, data, samples, prediction, measured_rms_um, \
residual_rms_um, measured_max_um, residual_max_um, per_direction: {x, y, z: {measured_rms_um, \
measured_max_um, residual_rms_um, residual_max_um}}, zeroed, unidentified_set_to_zero} \
(docs/identification.md); `--json -` writes it to standard output.";

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
    /// The JSON written by `rtest identify --json` (values in µm and µrad).
    #[arg(long, value_name = "FILE")]
    params: PathBuf,
    /// The measurement CSV to predict (axes in mm and degrees, dx_um,dy_um,dz_um in µm).
    #[arg(long, value_name = "FILE")]
    data: PathBuf,
    /// The readings of --data were zeroed at the first sample: zero the prediction there too.
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
    #[command(flatten)]
    records: RecordLimits,
    #[command(flatten)]
    instrument: super::args::InstrumentArgs,
    #[command(flatten)]
    bounds: ValueBounds,
}

/// Runs `rtest validate`.
pub fn run(args: &ValidateArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let mut inputs = vec![
        ("--params", args.params.as_path()),
        ("--data", args.data.as_path()),
    ];
    inputs.extend(super::machine_file(&args.machine).map(|p| ("--machine", p)));
    let outputs: Vec<(&str, &Target)> = args.json.iter().map(|t| ("--json", t)).collect();
    check_outputs(&inputs, &outputs, &[])?;
    let params = read_identification(&args.params, &m)
        .map_err(|e| CliError::input(format!("--params: {e}")))?;
    let names = parameter_names(&m, &params.model);
    check_model_values(
        &m,
        &params.model,
        &names,
        &params.values,
        &args.bounds.values(),
    )
    .map_err(|e| {
        CliError::input(format!(
            "--params: {}: {e}: these cannot be the errors of a machine tool (--max-error-um, --max-error-urad change the bounds)",
            args.params.display()
        ))
    })?;
    let record = super::read_record(
        "--data",
        &m,
        &args.data,
        &args.records.read_options(),
        &args.instrument,
    )?;
    super::check_times("--data", &args.data, &m, &params.model, &record)?;
    let mut opts = ValidateOptions::default();
    opts.zeroed = args.zeroed;
    opts.exact = !args.first_order;
    if args.refuse_undetermined {
        opts.unidentified = Unidentified::Refuse;
    }
    let v = validate(&m, &params.model, &params.values, &record, &opts).map_err(|e| match e {
        ValidateError::Unidentified(names) => CliError::input(format!(
            "--params: {} gave no value for {} (not determined by the identification) and --refuse-undetermined is set (without it they are set to 0)",
            args.params.display(),
            names.join(", ")
        )),
        other => CliError::computation(format!("--data: cannot validate: {other}")),
    })?;
    let (params_file, data) = (
        args.params.display().to_string(),
        args.data.display().to_string(),
    );
    let source = ValidationSource {
        machine: &m.name,
        model: &params.model_name,
        params: &params_file,
        data: &data,
        exact: !args.first_order,
    };
    let report = ValidationReport::new(source, &v)
        .map_err(|e| CliError::computation(format!("--data: {e}")))?;
    let mut text = validation(&report);
    text.push_str(zeroed_note(&record, args.zeroed));
    let mut files = Outputs::new();
    if let Some(target) = &args.json {
        let json = to_json(&report).map_err(|e| CliError::computation(format!("--json: {e}")))?;
        files.add("--json", target.clone(), json);
    }
    text.push_str(&wrote(&write(files)?));
    print_text(&text, matches!(args.json, Some(Target::Stdout)))
}
