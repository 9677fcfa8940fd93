//! An identification report read back: the model and values `validate` applies, after the
//! checks that they belong to the machine.
//!
//! Checked, in order, each failure naming the file and the field:
//! - the file is at most [`MAX_REPORT_BYTES`], UTF-8 (a byte-order mark is accepted), JSON;
//! - `machine` is the machine's name and `fingerprint` its fingerprint (the same topology and
//!   machine-side kinematic defaults: a copy of `seed-ac` with C reversed has another one);
//! - `base_model`, when given, is a model of the machine;
//! - every parameter has `error` (an effect of the machine), `basis` (a column of the
//!   vocabulary; a harmonic's `cos` column followed by its `sin` column), `value` (a finite
//!   number, or `null`: undetermined) and `unit` (the effect's);
//! - `terms`, when given, lists exactly the terms of the parameters, in order.

use crate::model::{Basis, Effect, Model, Term};
use model_spec::Machine;
use model_spec::text::{TextError, decode_text};
use serde_json::Value;

/// The largest identification report read (bytes): far above any real one.
pub const MAX_REPORT_BYTES: u64 = 64 << 20;

/// Why an identification report cannot be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The file cannot be read, is too large or is not UTF-8 text.
    #[error(transparent)]
    Text(#[from] TextError),
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

/// The model and values of an identification report, in internal units.
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifiedValues {
    /// The machine it was identified on.
    pub machine: String,
    /// The model's label.
    pub model_name: String,
    /// The model (terms in file order; the two columns of a harmonic are one term).
    pub model: Model,
    /// One value per model column (mm or rad); `None` where the file has `null`.
    pub values: Vec<Option<f64>>,
}

/// Reads the identification report at `path` for machine `m`; see [`parse_identification`].
///
/// # Errors
/// [`ReportError`] naming the file and, for a wrong field, the field.
pub fn read_identification(
    path: &std::path::Path,
    m: &Machine,
) -> Result<IdentifiedValues, ReportError> {
    let text = model_spec::text::read_text(path, MAX_REPORT_BYTES)?;
    parse_identification(&path.display().to_string(), &text, m)
}

/// Parses the bytes of an identification report (`file` names it in messages) for machine `m`.
///
/// # Errors
/// As [`parse_identification`]; [`ReportError::Text`] for bytes that are not UTF-8.
pub fn parse_identification_bytes(
    file: &str,
    bytes: Vec<u8>,
    m: &Machine,
) -> Result<IdentifiedValues, ReportError> {
    let text = decode_text(file, bytes)?;
    parse_identification(file, &text, m)
}

/// Parses the text of an identification report (`file` names it in messages) for machine `m`;
/// see the module documentation for what is checked. Other fields are ignored.
///
/// # Errors
/// [`ReportError::Json`] for text that is not JSON, [`ReportError::Field`] for a missing or
/// wrong field.
pub fn parse_identification(
    file: &str,
    text: &str,
    m: &Machine,
) -> Result<IdentifiedValues, ReportError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let root: Value = serde_json::from_str(text).map_err(|source| ReportError::Json {
        file: file.to_string(),
        source,
    })?;
    let r = Reader { file, m };
    if !root.is_object() {
        return Err(r.bad("(top level)", "expected a JSON object".into()));
    }
    let machine = r.string(&root, "machine", "machine")?;
    if machine != m.name {
        return Err(r.bad(
            "machine",
            format!("the values are for machine `{machine}`, not `{}`", m.name),
        ));
    }
    let fingerprint = match root.get("fingerprint") {
        Some(_) => r.string(&root, "fingerprint", "fingerprint")?,
        None => {
            return Err(r.bad(
                "fingerprint",
                "missing: the report does not say which machine description it was identified on (identify again with this rtest)".into(),
            ));
        }
    };
    let own = m.fingerprint();
    if fingerprint != own {
        return Err(r.bad(
            "fingerprint",
            format!(
                "`{fingerprint}` is not this description of machine {}'s (`{own}`): the values were identified on a machine with another topology or other kinematic defaults, and do not apply to this one",
                m.name
            ),
        ));
    }
    if let Some(base) = root.get("base_model").filter(|v| !v.is_null()) {
        let Value::String(base) = base else {
            return Err(r.bad(
                "base_model",
                format!("expected a string or null, found {base}"),
            ));
        };
        if m.model_errors(base).is_none() {
            return Err(r.bad(
                "base_model",
                format!(
                    "machine {} has no model `{base}` (models: {})",
                    m.name,
                    m.model_names().join(", ")
                ),
            ));
        }
    }
    let model_name = r.string(&root, "model", "model")?;
    let (model, values) = r.parameters(&root)?;
    if let Some(terms) = root.get("terms") {
        let Value::Array(items) = terms else {
            return Err(r.bad("terms", format!("expected an array, found {terms}")));
        };
        let spelled: Vec<String> = model.terms.iter().map(|t| t.spelling(m)).collect();
        let listed: Vec<String> = items
            .iter()
            .map(|v| {
                v.as_str()
                    .map(str::to_string)
                    .unwrap_or_else(|| v.to_string())
            })
            .collect();
        let parsed: Vec<Option<Term>> = listed.iter().map(|t| Term::parse(m, t).ok()).collect();
        if parsed
            .iter()
            .map(Option::as_ref)
            .ne(model.terms.iter().map(Some))
        {
            return Err(r.bad(
                "terms",
                format!(
                    "[{}] are not the terms of the parameters [{}]: a parameter is missing or extra",
                    listed.join(", "),
                    spelled.join(", ")
                ),
            ));
        }
    }
    Ok(IdentifiedValues {
        machine,
        model_name,
        model,
        values,
    })
}

/// Reads fields of one report, naming its file in errors.
struct Reader<'a> {
    file: &'a str,
    m: &'a Machine,
}

impl Reader<'_> {
    fn bad(&self, field: &str, message: String) -> ReportError {
        ReportError::Field {
            file: self.file.to_string(),
            field: field.to_string(),
            message,
        }
    }

    /// The string field `key` of `v`, named `field` in errors.
    fn string(&self, v: &Value, key: &str, field: &str) -> Result<String, ReportError> {
        match v.get(key) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(other) => Err(self.bad(field, format!("expected a string, found {other}"))),
            None => Err(self.bad(field, "missing".into())),
        }
    }

    /// The model and values of `parameters`.
    fn parameters(&self, root: &Value) -> Result<(Model, Vec<Option<f64>>), ReportError> {
        let m = self.m;
        let params = match root.get("parameters") {
            Some(Value::Array(a)) if !a.is_empty() => a,
            Some(Value::Array(_)) => return Err(self.bad("parameters", "is empty".into())),
            Some(other) => {
                return Err(self.bad("parameters", format!("expected an array, found {other}")));
            }
            None => return Err(self.bad("parameters", "missing".into())),
        };
        let mut model = Model::default();
        let mut values = Vec::new();
        let mut i = 0;
        while i < params.len() {
            let field = |name: &str| format!("parameters[{i}].{name}");
            let p = &params[i];
            if !p.is_object() {
                return Err(self.bad(&format!("parameters[{i}]"), "expected an object".into()));
            }
            let error = self.string(p, "error", &field("error"))?;
            let effect = Effect::parse(m, &error).ok_or_else(|| {
                self.bad(
                    &field("error"),
                    format!(
                        "`{error}` is neither an error of machine {} nor dx0/dy0/dz0",
                        m.name
                    ),
                )
            })?;
            let basis_text = self.string(p, "basis", &field("basis"))?;
            let (basis_str, part) = match basis_text.rsplit_once(':') {
                Some((b, s)) if s == "cos" || s == "sin" => (b, Some(s)),
                _ => (basis_text.as_str(), None),
            };
            let basis = Basis::parse(basis_str).map_err(|e| self.bad(&field("basis"), e.0))?;
            let harmonic = matches!(basis, Basis::Harmonic(_));
            if harmonic != (part == Some("cos")) {
                return Err(self.bad(
                    &field("basis"),
                    format!(
                        "`{basis_text}`: a harmonic is written as its `{basis}:cos` column followed by its `{basis}:sin` column"
                    ),
                ));
            }
            let term = Term::new(m, effect, basis).map_err(|e| self.bad(&field("basis"), e.0))?;
            if model.terms.contains(&term) {
                return Err(self.bad(
                    &field("error"),
                    format!("`{error}` with basis `{basis}` appears twice"),
                ));
            }
            for k in 0..basis.width() {
                let j = i + k;
                let field = |name: &str| format!("parameters[{j}].{name}");
                let q = params.get(j).ok_or_else(|| {
                    self.bad(
                        &field("basis"),
                        format!("`{basis}:sin` of `{error}` is missing"),
                    )
                })?;
                if k == 1 {
                    let e2 = self.string(q, "error", &field("error"))?;
                    let b2 = self.string(q, "basis", &field("basis"))?;
                    if Effect::parse(m, &e2) != Some(effect) || b2 != format!("{basis}:sin") {
                        return Err(self.bad(
                            &field("basis"),
                            format!(
                                "expected `{basis}:sin` of `{error}` after its `cos` column, found `{b2}` of `{e2}`"
                            ),
                        ));
                    }
                }
                let unit = self.string(q, "unit", &field("unit"))?;
                if unit != effect.unit(m) {
                    return Err(self.bad(
                        &field("unit"),
                        format!("`{unit}`: `{error}` is in `{}`", effect.unit(m)),
                    ));
                }
                let value =
                    match q.get("value") {
                        Some(Value::Null) => None,
                        Some(Value::Number(x)) => match x.as_f64() {
                            Some(v) if v.is_finite() => Some(v / effect.display_factor(m)),
                            _ => {
                                return Err(self
                                    .bad(&field("value"), format!("{x} is not a finite number")));
                            }
                        },
                        Some(other) => {
                            return Err(self.bad(
                                &field("value"),
                                format!("expected a number or null, found {other}"),
                            ));
                        }
                        None => {
                            return Err(self
                                .bad(&field("value"), "missing (write null for no value)".into()));
                        }
                    };
                values.push(value);
            }
            model.terms.push(term);
            i += basis.width();
        }
        Ok((model, values))
    }
}
