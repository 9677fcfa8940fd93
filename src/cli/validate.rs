//! `rtest validate`: identified values (an `identify` JSON) predict another measurement;
//! residuals before (nominal machine) and after (identified model), per direction.

use super::gains::text_table;
use super::{CliError, CliResult, EXIT_CODES};
use solver::fitting::validate::{
    Unidentified, ValidateError, ValidateOptions, Validation, validate,
};
use solver::io::json::{read_identify_json, validate_json};
use std::path::PathBuf;

const LONG_ABOUT: &str = "\
Checks identified values on another measurement: the model and values of an `rtest identify` \
JSON (--params) predict the readings of a measurement CSV (--data: axes in mm and degrees, \
dx_um,dy_um,dz_um in µm), and the residual (measured minus predicted) is reported per direction \
x, y, z of the tool frame and overall: RMS and maximum in µm, before (the nominal machine: \
prediction 0) and after (the identified model). Overall RMS = sqrt(Σ r² / 3N).

The prediction is the exact virtual machine at the identified values (no linearisation); with \
--first-order it is the first-order model H·v (the difference is the second-order terms, about \
1e-3 µm for errors of tens of µm and µrad). With --zeroed (readings zeroed at the first sample) \
the prediction is zeroed at the first sample too, so constant effects cancel.

Parameters the identification could not determine (value null) are set to 0 and named; \
--refuse-undetermined makes that an error instead.

--json writes {data, samples, measured_rms_um, residual_rms_um, measured_max_um, \
residual_max_um, per_direction: {x, y, z: {measured_rms_um, measured_max_um, residual_rms_um, \
residual_max_um}}, zeroed, unidentified_set_to_zero} (docs/identification.md), atomically.";

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
    /// Also write the result as JSON to FILE (atomically).
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// Runs `rtest validate`.
pub fn run(args: &ValidateArgs) -> CliResult {
    let m = super::load_machine(&args.machine)?;
    let params = read_identify_json(&args.params, &m)
        .map_err(|e| CliError::failure(format!("--params: {e}")))?;
    let record = super::data::measurement("--data", &m, &args.data)?;
    let opts = ValidateOptions {
        zeroed: args.zeroed,
        unidentified: if args.refuse_undetermined {
            Unidentified::Refuse
        } else {
            Unidentified::Zero
        },
        params: None,
        exact: !args.first_order,
    };
    let v = validate(&m, &params.model, &params.values, &record, &opts).map_err(|e| match e {
        ValidateError::Unidentified(names) => CliError::failure(format!(
            "--params: {} gave no value for {} (not determined by the identification) and --refuse-undetermined is set (without it they are set to 0)",
            args.params.display(),
            names.join(", ")
        )),
        other => CliError::failure(format!("--data: cannot validate: {other}")),
    })?;
    let data_name = args.data.display().to_string();
    let mut text = format!(
        "Validation on {data_name} ({} samples, readings {}): machine {}, model {} with the values of {}\n",
        v.samples,
        if v.zeroed {
            "zeroed at the first sample"
        } else {
            "not zeroed"
        },
        m.name,
        params.model_name,
        args.params.display()
    );
    text.push_str(&format!(
        "Prediction: {}; before = nominal machine (prediction 0), after = identified model.\n\n",
        if args.first_order {
            "first-order model H·v (--first-order)"
        } else {
            "the exact virtual machine at the identified values"
        }
    ));
    text.push_str(&residual_table(&[(data_name.as_str(), &v)]));
    text.push_str(&defaulted_note(&v));
    if super::data::looks_zeroed(&record) && !args.zeroed {
        text.push_str(
            "Note: the first reading is exactly 0: if the readings were zeroed at the first sample, give --zeroed.\n",
        );
    }
    if let Some(path) = &args.json {
        let json = validate_json(&data_name, &v);
        let body = serde_json::to_string_pretty(&json)
            .map_err(|e| CliError::failure(format!("--json: {e}")))?;
        super::write_atomic("--json", path, &(body + "\n"))?;
        text.push_str(&format!("Wrote {}\n", path.display()));
    }
    print!("{text}");
    Ok(())
}

/// The line naming the parameters set to 0, or nothing.
pub fn defaulted_note(v: &Validation) -> String {
    if v.defaulted.is_empty() {
        String::new()
    } else {
        format!(
            "Set to 0 in the prediction (no value: not determined by the identification): {}\n",
            v.defaulted.join(", ")
        )
    }
}

/// Residual RMS and max per direction and overall (µm), before and after, one block of rows
/// per validation.
pub fn residual_table(rows: &[(&str, &Validation)]) -> String {
    let header = [
        "data",
        "dir",
        "before RMS µm",
        "before max µm",
        "after RMS µm",
        "after max µm",
    ]
    .map(String::from);
    let mut table = Vec::new();
    for (name, v) in rows {
        let blocks = [
            ("x", &v.per_direction[0]),
            ("y", &v.per_direction[1]),
            ("z", &v.per_direction[2]),
            ("all", &v.overall),
        ];
        for (i, (dir, s)) in blocks.into_iter().enumerate() {
            table.push([
                if i == 0 {
                    name.to_string()
                } else {
                    String::new()
                },
                dir.to_string(),
                format!("{:.3}", s.measured_rms * 1e3),
                format!("{:.3}", s.measured_max * 1e3),
                small(s.residual_rms * 1e3),
                small(s.residual_max * 1e3),
            ]);
        }
    }
    text_table(&header, &table)
}

/// A non-negative µm value with three decimals, or in scientific notation below 5e-4.
fn small(x: f64) -> String {
    if x != 0.0 && x < 5e-4 {
        format!("{x:.1e}")
    } else {
        format!("{x:.3}")
    }
}
