//! The JSON people and tools read: the result of `identify` and of `validate`, in µm and µrad,
//! and the reading of an `identify` JSON back into model values for `validate`.
//!
//! `identify`:
//! ```json
//! {"machine": "seed-ac", "model": "reduced",
//!  "parameters": [{"error": "XOC", "basis": "const", "value": 12.3, "std": 0.05, "unit": "um"}, …],
//!  "residual_rms_um": 0.49, "rank": 11, "condition": 4.2, "confounded": [["XOC", "dx0"]], …}
//! ```
//! `value` and `std` are `null` where the data do not determine the parameter; `basis` is
//! `const`, `harmonic:K:cos`, `harmonic:K:sin`, `poly:K`, `reversal` or `time:K`; `unit` is
//! `um` (translational errors, sensor offsets) or `urad` (angular errors). Fields beyond the
//! issue's (`samples`, `zeroed`, `constraint`, `sigma_um`, `near_confounded`, `gains`, `notes`)
//! are additions; readers need only `machine`, `model` and `parameters`.
//!
//! `validate`: `{"data", "samples", "measured_rms_um", "residual_rms_um", "per_direction": {"x":
//! {"measured_rms_um", "measured_max_um", "residual_rms_um", "residual_max_um"}, "y": …, "z": …},
//! …}`, RMS over all three directions `√(Σ r² / 3N)`.

use crate::fitting::hmatrix::Backend;
use crate::fitting::validate::{Stats, Validation};
use crate::fitting::{Constraint, Identification};
use crate::model::Basis;
use crate::model::{Effect, Model, Term};
use model_spec::Machine;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// µm per mm.
pub const UM_PER_MM: f64 = 1e3;
/// µrad per rad.
pub const URAD_PER_RAD: f64 = 1e6;

/// The factor from internal units (mm, rad) to the unit people see (µm, µrad) of `effect`.
pub fn display_factor(m: &Machine, effect: Effect) -> f64 {
    if effect.is_angular(m) {
        URAD_PER_RAD
    } else {
        UM_PER_MM
    }
}

/// One parameter of an identification, in µm or µrad.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterJson {
    /// Effect name (`XOC`, `dx0`).
    pub error: String,
    /// Basis column (`const`, `harmonic:2:cos`, `reversal`, …).
    pub basis: String,
    /// Estimate, µm or µrad; `null` when not determined.
    pub value: Option<f64>,
    /// Standard uncertainty, µm or µrad; `null` when not available.
    pub std: Option<f64>,
    /// `um` or `urad`.
    pub unit: String,
}

/// A pair of determined parameters with a high correlation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NearPairJson {
    /// The two parameter names.
    pub parameters: [String; 2],
    /// Correlation of their estimates.
    pub correlation: f64,
}

/// The JSON of `identify`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdentifyJson {
    /// Machine name.
    pub machine: String,
    /// Model name.
    pub model: String,
    /// Every parameter (H column), in model order.
    pub parameters: Vec<ParameterJson>,
    /// `√(RSS / 3N)`, µm.
    pub residual_rms_um: f64,
    /// Numerical rank of the scaled H.
    pub rank: usize,
    /// Condition number of the scaled H over the identifiable part; `null` when rank is 0.
    pub condition: Option<f64>,
    /// Groups of parameters the data cannot separate (names as in `parameters`: `XOC`,
    /// `ECC@harmonic:1:cos`).
    pub confounded: Vec<Vec<String>>,
    /// Number of samples fitted.
    pub samples: usize,
    /// Whether the readings were zeroed at the first sample (then `dx0 dy0 dz0` were fitted).
    pub zeroed: bool,
    /// `none`, `minimum-norm` or `zero: NAME, …`.
    pub constraint: String,
    /// σ̂ = √(RSS / (3N − rank)), µm; `null` without degrees of freedom.
    pub sigma_um: Option<f64>,
    /// Determined pairs with |correlation| > 0.99.
    pub near_confounded: Vec<NearPairJson>,
    /// `compiled`, `evaluator` or `mixed`: the code that computed the gains.
    pub gains: String,
    /// Statements for people (what was swallowed, what has no value and why).
    pub notes: Vec<String>,
}

/// Per direction, in µm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionJson {
    /// RMS of the measured values (nominal machine), µm.
    pub measured_rms_um: f64,
    /// Largest |measured value|, µm.
    pub measured_max_um: f64,
    /// RMS of measured minus predicted, µm.
    pub residual_rms_um: f64,
    /// Largest |measured minus predicted|, µm.
    pub residual_max_um: f64,
}

/// The three directions of the tool frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PerDirectionJson {
    /// x.
    pub x: DirectionJson,
    /// y.
    pub y: DirectionJson,
    /// z.
    pub z: DirectionJson,
}

/// The JSON of `validate`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ValidateJson {
    /// The measurement file validated on.
    pub data: String,
    /// Number of samples.
    pub samples: usize,
    /// RMS of the measurement over all three directions (before: nominal machine), µm.
    pub measured_rms_um: f64,
    /// RMS of measured minus predicted over all three directions (after), µm.
    pub residual_rms_um: f64,
    /// Largest |measured value|, µm.
    pub measured_max_um: f64,
    /// Largest |measured minus predicted|, µm.
    pub residual_max_um: f64,
    /// Per direction.
    pub per_direction: PerDirectionJson,
    /// Whether the prediction was zeroed at the first sample.
    pub zeroed: bool,
    /// Parameters without a value that the prediction set to 0.
    pub unidentified_set_to_zero: Vec<String>,
}

fn basis_column(b: Basis, k: usize) -> String {
    let names = b.column_names();
    names.get(k).unwrap_or(&names[0]).clone()
}

fn constraint_text(c: &Constraint) -> String {
    match c {
        Constraint::None => "none".into(),
        Constraint::MinimumNorm => "minimum-norm".into(),
        Constraint::Zero(names) => format!("zero: {}", names.join(", ")),
    }
}

/// The `identify` JSON of `ident` (model `model_name` of `m`).
pub fn identify_json(m: &Machine, model_name: &str, ident: &Identification) -> IdentifyJson {
    let fit = &ident.fit;
    let parameters = ident
        .model
        .columns()
        .into_iter()
        .enumerate()
        .map(|(j, (t, k))| {
            let term = ident.model.terms[t];
            let f = display_factor(m, term.effect);
            ParameterJson {
                error: term.effect.name(m),
                basis: basis_column(term.basis, k),
                value: fit.values.get(j).copied().flatten().map(|v| v * f),
                std: fit.std.get(j).copied().flatten().map(|v| v * f),
                unit: term.effect.unit(m).to_string(),
            }
        })
        .collect();
    let name = |j: usize| fit.names[j].clone();
    let id = &fit.identifiability;
    let confounded: Vec<Vec<String>> = id
        .confounded
        .iter()
        .map(|g| g.iter().map(|&j| name(j)).collect())
        .collect();
    let mut notes = Vec::new();
    for s in &ident.swallowed {
        notes.push(format!(
            "zeroed readings: the sensor offset{} {} cannot be told from {} (constant gains)",
            if s.offsets.len() > 1 { "s" } else { "" },
            s.offsets.join(", "),
            if s.errors.is_empty() {
                "each other".to_string()
            } else {
                s.errors.join(", ")
            }
        ));
    }
    let undetermined: Vec<String> = (0..fit.names.len())
        .filter(|&j| !id.determined[j])
        .map(name)
        .collect();
    if !undetermined.is_empty() {
        notes.push(match fit.constraint {
            Constraint::MinimumNorm => format!(
                "{} are not determined by the data; their values are the minimum-norm (scaled) solution, not measurements",
                undetermined.join(", ")
            ),
            _ => format!(
                "no value for {}: the data cannot determine them (see `confounded`)",
                undetermined.join(", ")
            ),
        });
    }
    if fit.sigma.is_none() {
        notes.push("no degree of freedom left (3N = rank): no uncertainties".into());
    }
    IdentifyJson {
        machine: ident.machine.clone(),
        model: model_name.to_string(),
        parameters,
        residual_rms_um: fit.residual_rms() * UM_PER_MM,
        rank: fit.rank,
        condition: fit.condition,
        confounded,
        samples: ident.samples,
        zeroed: ident.zeroed,
        constraint: constraint_text(&fit.constraint),
        sigma_um: fit.sigma.map(|s| s * UM_PER_MM),
        near_confounded: id
            .near_confounded
            .iter()
            .map(|p| NearPairJson {
                parameters: [name(p.a), name(p.b)],
                correlation: p.correlation,
            })
            .collect(),
        gains: match ident.backend {
            Backend::Compiled => "compiled",
            Backend::Evaluator => "evaluator",
            Backend::Mixed => "mixed",
        }
        .into(),
        notes,
    }
}

fn direction_json(s: &Stats) -> DirectionJson {
    DirectionJson {
        measured_rms_um: s.measured_rms * UM_PER_MM,
        measured_max_um: s.measured_max * UM_PER_MM,
        residual_rms_um: s.residual_rms * UM_PER_MM,
        residual_max_um: s.residual_max * UM_PER_MM,
    }
}

/// The `validate` JSON of `v` on the measurement file `data`.
pub fn validate_json(data: &str, v: &Validation) -> ValidateJson {
    let [x, y, z] = &v.per_direction;
    ValidateJson {
        data: data.to_string(),
        samples: v.samples,
        measured_rms_um: v.overall.measured_rms * UM_PER_MM,
        residual_rms_um: v.overall.residual_rms * UM_PER_MM,
        measured_max_um: v.overall.measured_max * UM_PER_MM,
        residual_max_um: v.overall.residual_max * UM_PER_MM,
        per_direction: PerDirectionJson {
            x: direction_json(x),
            y: direction_json(y),
            z: direction_json(z),
        },
        zeroed: v.zeroed,
        unidentified_set_to_zero: v.defaulted.clone(),
    }
}

/// Why an `identify` JSON cannot be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The file cannot be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: String,
        /// The cause.
        source: std::io::Error,
    },
    /// Not JSON.
    #[error("{file}: not valid JSON: {source}")]
    Json {
        /// The file.
        file: String,
        /// The cause (with line and column).
        source: serde_json::Error,
    },
    /// A field that is missing or wrong.
    #[error("{file}: field `{field}`: {message}")]
    Field {
        /// The file.
        file: String,
        /// The field (`parameters[3].unit`).
        field: String,
        /// What is wrong.
        message: String,
    },
}

/// The model and values of an `identify` JSON, in internal units.
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifiedValues {
    /// The machine it was identified on.
    pub machine: String,
    /// The model's name.
    pub model_name: String,
    /// The model (terms in file order; the two columns of a harmonic are one term).
    pub model: Model,
    /// One value per model column (mm or rad); `None` where the file has `null`.
    pub values: Vec<Option<f64>>,
}

/// Reads the `identify` JSON at `path` for machine `m`. See [`parse_identify_json`].
///
/// # Errors
/// [`ReportError`] naming the file and, for a wrong field, the field.
pub fn read_identify_json(
    path: &std::path::Path,
    m: &Machine,
) -> Result<IdentifiedValues, ReportError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| ReportError::Io {
        file: file.clone(),
        source,
    })?;
    parse_identify_json(&file, &text, m)
}

/// Parses the text of an `identify` JSON (`file` names it in messages) for machine `m`:
/// `machine` must be `m`'s name; every parameter needs `error` (an effect of `m`), `basis`
/// (a column of the vocabulary; a harmonic's `cos` column followed by its `sin` column),
/// `value` (number or null) and `unit` (the effect's: `um` or `urad`). Other fields are ignored.
///
/// # Errors
/// [`ReportError::Json`] for text that is not JSON, [`ReportError::Field`] for a missing or
/// wrong field.
pub fn parse_identify_json(
    file: &str,
    text: &str,
    m: &Machine,
) -> Result<IdentifiedValues, ReportError> {
    let root: Value = serde_json::from_str(text).map_err(|source| ReportError::Json {
        file: file.to_string(),
        source,
    })?;
    let bad = |field: &str, message: String| ReportError::Field {
        file: file.to_string(),
        field: field.to_string(),
        message,
    };
    let string = |v: &Value, field: &str| -> Result<String, ReportError> {
        match v.get(field.rsplit('.').next().unwrap_or(field)) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(other) => Err(bad(field, format!("expected a string, found {other}"))),
            None => Err(bad(field, "missing".into())),
        }
    };
    if !root.is_object() {
        return Err(bad("(top level)", "expected a JSON object".into()));
    }
    let machine = string(&root, "machine")?;
    if machine != m.name {
        return Err(bad(
            "machine",
            format!("the values are for machine `{machine}`, not `{}`", m.name),
        ));
    }
    let model_name = string(&root, "model")?;
    let params = match root.get("parameters") {
        Some(Value::Array(a)) if !a.is_empty() => a,
        Some(Value::Array(_)) => return Err(bad("parameters", "is empty".into())),
        Some(other) => {
            return Err(bad(
                "parameters",
                format!("expected an array, found {other}"),
            ));
        }
        None => return Err(bad("parameters", "missing".into())),
    };
    let mut model = Model::default();
    let mut values = Vec::new();
    let mut i = 0;
    while i < params.len() {
        let field = |name: &str| format!("parameters[{i}].{name}");
        let p = &params[i];
        if !p.is_object() {
            return Err(bad(
                &format!("parameters[{i}]"),
                "expected an object".into(),
            ));
        }
        let error = string(p, &field("error"))?;
        let effect = Effect::parse(m, &error).ok_or_else(|| {
            bad(
                &field("error"),
                format!(
                    "`{error}` is neither an error of machine {} nor dx0/dy0/dz0",
                    m.name
                ),
            )
        })?;
        let basis_text = string(p, &field("basis"))?;
        let (basis_str, part) = match basis_text.rsplit_once(':') {
            Some((b, s)) if s == "cos" || s == "sin" => (b, Some(s)),
            _ => (basis_text.as_str(), None),
        };
        let basis = Basis::parse(basis_str).map_err(|e| bad(&field("basis"), e.0))?;
        let harmonic = matches!(basis, Basis::Harmonic(_));
        if harmonic != (part == Some("cos")) {
            return Err(bad(
                &field("basis"),
                format!(
                    "`{basis_text}`: a harmonic is written as its `{basis}:cos` column followed by its `{basis}:sin` column"
                ),
            ));
        }
        let term = Term::new(m, effect, basis).map_err(|e| bad(&field("basis"), e.0))?;
        if model.terms.contains(&term) {
            return Err(bad(
                &field("error"),
                format!("`{error}` with basis `{basis}` appears twice"),
            ));
        }
        for k in 0..basis.width() {
            let j = i + k;
            let field = |name: &str| format!("parameters[{j}].{name}");
            let q = params.get(j).ok_or_else(|| {
                bad(
                    &field("basis"),
                    format!("`{basis}:sin` of `{error}` is missing"),
                )
            })?;
            if k == 1 {
                let (e2, b2) = (string(q, &field("error"))?, string(q, &field("basis"))?);
                if Effect::parse(m, &e2) != Some(effect) || b2 != format!("{basis}:sin") {
                    return Err(bad(
                        &field("basis"),
                        format!(
                            "expected `{basis}:sin` of `{error}` after its `cos` column, found `{b2}` of `{e2}`"
                        ),
                    ));
                }
            }
            let unit = string(q, &field("unit"))?;
            if unit != effect.unit(m) {
                return Err(bad(
                    &field("unit"),
                    format!("`{unit}`: `{error}` is in `{}`", effect.unit(m)),
                ));
            }
            let value = match q.get("value") {
                Some(Value::Null) => None,
                Some(Value::Number(x)) => x.as_f64().map(|v| v / display_factor(m, effect)),
                Some(other) => {
                    return Err(bad(
                        &field("value"),
                        format!("expected a number or null, found {other}"),
                    ));
                }
                None => {
                    return Err(bad(
                        &field("value"),
                        "missing (write null for no value)".into(),
                    ));
                }
            };
            values.push(value);
        }
        model.terms.push(term);
        i += basis.width();
    }
    Ok(IdentifiedValues {
        machine,
        model_name,
        model,
        values,
    })
}
