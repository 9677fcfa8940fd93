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
//! - `terms` lists exactly the terms of the parameters, in order, and holds every term of the
//!   base model (and the sensor offsets when the readings were zeroed): no parameter is missing;
//! - a `poly:K` parameter was normalised over the stroke this machine has for its axis;
//! - a kinematic offset (a symbol of the machine, `Zt`) has `nominal_mm`, the value its change
//!   is relative to (a finite length in mm). The change of a symbol of the machine (not of the
//!   workpiece set-up) is re-expressed relative to this machine's default value of the symbol,
//!   the value `validate` models a record with: `value` becomes the identified length minus
//!   the default (the change itself when the identification used the default). The change of
//!   a ball position (`Xw`) is kept, like the set-up errors `XOW YOW ZOW`;
//! - the refinement, when the report has one, converged (an identification that did not is no
//!   result);
//! - what the fit says of each value, when the report says it: `std` (a finite number or
//!   `null`), `determined` and `fixed` (booleans; a fixed parameter has the value 0), and
//!   `constraint` (`none`, `minimum-norm` or `zero: NAME, …`). Reports written by rtest always
//!   have them; a report without them reads as an unconstrained fit whose values are determined
//!   where they are not `null`.

use super::identify::poly_stroke;
use crate::model::{Basis, Effect, Model, Term};
use model_spec::Machine;
use model_spec::text::{TextError, decode_text};
use model_spec::units::short;
use serde_json::Value;

/// The largest identification report read (bytes): far above any real one.
pub const MAX_REPORT_BYTES: u64 = 64 << 20;

/// Why an identification report cannot be read back.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The file cannot be read, is too large or is not UTF-8 text.
    #[error(transparent)]
    Text(#[from] TextError),
    /// Not JSON, located by line and column (in characters, as every reader counts them).
    #[error("{file}:{line}:{column}: not valid JSON: {message}")]
    Json {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What the JSON parser said.
        message: String,
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
    /// The file the values were read from, as named in messages.
    pub file: String,
    /// The machine it was identified on.
    pub machine: String,
    /// The fingerprint of the machine description it was identified on (the machine's own:
    /// another one is refused when the report is read).
    pub fingerprint: String,
    /// The model's label.
    pub model_name: String,
    /// The model (terms in file order; the two columns of a harmonic are one term).
    pub model: Model,
    /// One value per model column, in the term's unit inside ([`Term::places`]: mm, rad; ms
    /// for `velocity`; 1 for instrument terms); `None` where the file has `null`.
    pub values: Vec<Option<f64>>,
    /// One standard uncertainty per model column, in the unit of `values`; `None` where the
    /// file has `null` (undetermined, fixed, or no degree of freedom) or no `std`.
    pub std: Vec<Option<f64>>,
    /// Per model column: whether the data determine it (`determined`; a fixed parameter
    /// counts as determined). Without the field: `true` where the value is not `null`.
    pub determined: Vec<bool>,
    /// Per model column: fixed to 0 by the constraint (`fixed`; `false` without the field).
    pub fixed: Vec<bool>,
    /// The constraint of the fit as the report writes it: `none`, `minimum-norm` or
    /// `zero: NAME, …` (`none` without the field). Under `minimum-norm` an undetermined
    /// parameter has a value (`determined: false`): the minimum-norm choice, not a measurement.
    pub constraint: String,
}

impl IdentifiedValues {
    /// `true` when the fit was constrained (`constraint` other than `none`): its undetermined
    /// parameters got a value from the constraint (0 for `zero:`, the minimum-norm choice for
    /// `minimum-norm`), not from the data.
    pub fn constrained(&self) -> bool {
        self.constraint != "none"
    }
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
    let root: Value = serde_json::from_str(text).map_err(|e| json_error(file, text, &e))?;
    let r = Reader { file, m };
    let (machine, fingerprint) = r.header(&root)?;
    let base = r.base_model(&root)?;
    r.converged(&root)?;
    let model_name = r.string(&root, "model", "model")?;
    let (model, columns) = r.parameters(&root)?;
    let spelled: Vec<String> = model.terms.iter().map(|t| t.spelling(m)).collect();
    let items = match root.get("terms") {
        Some(Value::Array(items)) => items,
        Some(other) => return Err(r.bad("terms", format!("expected an array, found {other}"))),
        None => {
            return Err(r.bad(
                "terms",
                format!(
                    "missing: the report must list the terms it identified ({})",
                    spelled.join(", ")
                ),
            ));
        }
    };
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
    if let Some((name, base)) = &base {
        let zeroed = root.get("zeroed") == Some(&Value::Bool(true));
        let wanted = if zeroed {
            crate::fitting::with_offsets(base)
        } else {
            base.clone()
        };
        let missing: Vec<String> = wanted
            .terms
            .iter()
            .filter(|t| !model.terms.contains(t))
            .map(|t| t.spelling(m))
            .collect();
        if !missing.is_empty() {
            return Err(r.bad(
                "parameters",
                format!(
                    "the base model `{name}`{} has {} that the parameters lack",
                    if zeroed {
                        " with the offsets of zeroed readings"
                    } else {
                        ""
                    },
                    missing.join(", ")
                ),
            ));
        }
    }
    let constraint = r.constraint(&root)?;
    let Columns {
        mut values,
        std,
        determined,
        fixed,
        nominal,
    } = columns;
    // A change of a machine's length, re-expressed from the identification's value of the
    // symbol to this machine's default (the fingerprint makes the defaults the same).
    for (j, (t, _)) in model.columns().into_iter().enumerate() {
        if let (Some(s), Some(n), Some(v)) = (model.terms[t].effect.symbol(), nominal[j], values[j])
            && !crate::fitting::offsets::is_setup_symbol(m, s)
        {
            values[j] = Some(v + (n - m.symbols[s].default));
        }
    }
    Ok(IdentifiedValues {
        file: file.to_string(),
        machine,
        fingerprint,
        model_name,
        model,
        values,
        std,
        determined,
        fixed,
        constraint,
    })
}

/// What a report says of each model column, in internal units.
#[derive(Default)]
pub(crate) struct Columns {
    /// Values.
    pub(crate) values: Vec<Option<f64>>,
    /// Standard uncertainties.
    pub(crate) std: Vec<Option<f64>>,
    /// Determined.
    pub(crate) determined: Vec<bool>,
    /// Fixed by the constraint.
    pub(crate) fixed: Vec<bool>,
    /// The value of a kinematic offset's symbol its change is relative to (`nominal_mm`, mm);
    /// `None` for other parameters.
    pub(crate) nominal: Vec<Option<f64>>,
}

/// A JSON syntax error located in characters: the parser counts columns in bytes.
pub(crate) fn json_error(file: &str, text: &str, e: &serde_json::Error) -> ReportError {
    let line = e.line().max(1);
    let line_text = text.split('\n').nth(line - 1).unwrap_or("");
    let mut byte = e.column().saturating_sub(1).min(line_text.len());
    while !line_text.is_char_boundary(byte) {
        byte -= 1;
    }
    let full = e.to_string();
    let message = match full.rfind(" at line ") {
        Some(i) => full[..i].to_string(),
        None => full,
    };
    ReportError::Json {
        file: file.to_string(),
        line,
        column: line_text[..byte].chars().count() + 1,
        message,
    }
}

/// Reads fields of one report, naming its file in errors.
pub(crate) struct Reader<'a> {
    /// The file, as named in messages.
    pub(crate) file: &'a str,
    /// The machine.
    pub(crate) m: &'a Machine,
}

impl Reader<'_> {
    /// Checks that `root` is an object for this machine (name and fingerprint): the machine's
    /// name and fingerprint as written.
    pub(crate) fn header(&self, root: &Value) -> Result<(String, String), ReportError> {
        let (r, m) = (self, self.m);
        if !root.is_object() {
            return Err(r.bad("(top level)", "expected a JSON object".into()));
        }
        let machine = r.string(root, "machine", "machine")?;
        if machine != m.name {
            return Err(r.bad(
                "machine",
                format!("the values are for machine `{machine}`, not `{}`", m.name),
            ));
        }
        let fingerprint = match root.get("fingerprint") {
            Some(_) => r.string(root, "fingerprint", "fingerprint")?,
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
        Ok((machine, fingerprint))
    }

    /// The base model named by `base_model`, if any.
    pub(crate) fn base_model(&self, root: &Value) -> Result<Option<(String, Model)>, ReportError> {
        let (r, m) = (self, self.m);
        Ok(match root.get("base_model") {
            None | Some(Value::Null) => None,
            Some(Value::String(base)) => match Model::of(m, base) {
                Some(model) => Some((base.clone(), model)),
                None => {
                    return Err(r.bad(
                        "base_model",
                        format!(
                            "machine {} has no model `{base}` (models: {})",
                            m.name,
                            m.model_names().join(", ")
                        ),
                    ));
                }
            },
            Some(other) => {
                return Err(r.bad("base_model", format!("expected a string, found {other}")));
            }
        })
    }

    /// Refuses a report whose refinement did not converge.
    pub(crate) fn converged(&self, root: &Value) -> Result<(), ReportError> {
        if let Some(Value::Object(refinement)) = root.get("refinement")
            && refinement.get("converged") == Some(&Value::Bool(false))
        {
            return Err(self.bad(
                "refinement.converged",
                "false: the refinement against the exact machine did not converge, so these values are not an identification".into(),
            ));
        }
        Ok(())
    }

    /// The constraint of the fit as written (`none` without the field).
    pub(crate) fn constraint(&self, root: &Value) -> Result<String, ReportError> {
        match root.get("constraint") {
            None | Some(Value::Null) => Ok("none".to_string()),
            Some(Value::String(c))
                if c == "none" || c == "minimum-norm" || c.starts_with("zero:") =>
            {
                Ok(c.clone())
            }
            Some(other) => Err(self.bad(
                "constraint",
                format!("expected `none`, `minimum-norm` or `zero: NAME, …`, found {other}"),
            )),
        }
    }

    pub(crate) fn bad(&self, field: &str, message: String) -> ReportError {
        ReportError::Field {
            file: self.file.to_string(),
            field: field.to_string(),
            message,
        }
    }

    /// The string field `key` of `v`, named `field` in errors.
    pub(crate) fn string(&self, v: &Value, key: &str, field: &str) -> Result<String, ReportError> {
        match v.get(key) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(other) => Err(self.bad(field, format!("expected a string, found {other}"))),
            None => Err(self.bad(field, "missing".into())),
        }
    }

    /// Checks that the `poly:K` parameter `q` was normalised over `stroke` (mm), the stroke of
    /// its axis on this machine.
    fn check_stroke(
        &self,
        q: &Value,
        field: &str,
        term: &Term,
        stroke: [f64; 2],
    ) -> Result<(), ReportError> {
        let given = q.get("over_mm").and_then(Value::as_array).and_then(|a| {
            let lo = a.first()?.as_f64()?;
            let hi = a.get(1)?.as_f64()?;
            (a.len() == 2).then_some([lo, hi])
        });
        let Some(given) = given else {
            return Err(self.bad(
                field,
                "missing or not [min, max]: a poly:K value means something only with the stroke (mm) it was normalised over".into(),
            ));
        };
        let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs());
        if !(same(given[0], stroke[0]) && same(given[1], stroke[1])) {
            let axis = match term.effect.carrier(self.m) {
                crate::model::Carrier::Axis(a) => self.m.axes[a].name.clone(),
                crate::model::Carrier::None => "?".into(),
            };
            return Err(self.bad(
                field,
                format!(
                    "{} was normalised over the stroke {} .. {} mm, but axis {axis} of this machine has {} .. {} mm: the value would mean another error",
                    term.spelling(self.m),
                    short(given[0]),
                    short(given[1]),
                    short(stroke[0]),
                    short(stroke[1])
                ),
            ));
        }
        Ok(())
    }

    /// The model and values of `parameters`.
    fn parameters(&self, root: &Value) -> Result<(Model, Columns), ReportError> {
        let params = match root.get("parameters") {
            Some(Value::Array(a)) if !a.is_empty() => a,
            Some(Value::Array(_)) => return Err(self.bad("parameters", "is empty".into())),
            Some(other) => {
                return Err(self.bad("parameters", format!("expected an array, found {other}")));
            }
            None => return Err(self.bad("parameters", "missing".into())),
        };
        let mut model = Model::default();
        let mut columns = Columns::default();
        let mut i = 0;
        while i < params.len() {
            let (term, c) = self.term_at(params, i)?;
            if model.terms.contains(&term) {
                return Err(self.bad(
                    &format!("parameters[{i}].error"),
                    format!(
                        "`{}` with basis `{}` appears twice",
                        term.effect.name(self.m),
                        term.basis
                    ),
                ));
            }
            columns.values.extend(c.values);
            columns.std.extend(c.std);
            columns.determined.extend(c.determined);
            columns.fixed.extend(c.fixed);
            columns.nominal.extend(c.nominal);
            model.terms.push(term);
            i += term.basis.width();
        }
        Ok((model, columns))
    }

    /// The term of `params[i]` (and of `params[i + 1]`, the `sin` column of a harmonic) and
    /// what the report says of its columns, checked as the module documentation says.
    pub(crate) fn term_at(
        &self,
        params: &[Value],
        i: usize,
    ) -> Result<(Term, Columns), ReportError> {
        let m = self.m;
        let mut columns = Columns::default();
        {
            let field = |name: &str| format!("parameters[{i}].{name}");
            let p = &params[i];
            if !p.is_object() {
                return Err(self.bad(&format!("parameters[{i}]"), "expected an object".into()));
            }
            let error = self.string(p, "error", &field("error"))?;
            let effect = Effect::parse_term(m, &error).ok_or_else(|| {
                self.bad(&field("error"), crate::model::unknown_effect(m, &error).0)
            })?;
            let basis_text = self.string(p, "basis", &field("basis"))?;
            let (basis_str, part) = match basis_text.rsplit_once(':') {
                Some((b, s)) if s == "cos" || s == "sin" => (b, Some(s)),
                _ => (basis_text.as_str(), None),
            };
            let basis = Basis::parse(basis_str).map_err(|e| self.bad(&field("basis"), e.0))?;
            let harmonic = basis.width() == 2;
            if harmonic != (part == Some("cos")) {
                return Err(self.bad(
                    &field("basis"),
                    format!(
                        "`{basis_text}`: a harmonic is written as its `{basis}:cos` column followed by its `{basis}:sin` column"
                    ),
                ));
            }
            let term = Term::new(m, effect, basis).map_err(|e| self.bad(&field("basis"), e.0))?;
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
                    if Effect::parse_term(m, &e2) != Some(effect) || b2 != format!("{basis}:sin") {
                        return Err(self.bad(
                            &field("basis"),
                            format!(
                                "expected `{basis}:sin` of `{error}` after its `cos` column, found `{b2}` of `{e2}`"
                            ),
                        ));
                    }
                }
                if let Some(stroke) = poly_stroke(m, &term) {
                    self.check_stroke(q, &field("over_mm"), &term, stroke)?;
                }
                let unit = self.string(q, "unit", &field("unit"))?;
                if unit != term.unit(m) {
                    return Err(self.bad(
                        &field("unit"),
                        format!("`{unit}`: `{error}` `{basis}` is in `{}`", term.unit(m)),
                    ));
                }
                let value =
                    match q.get("value") {
                        Some(Value::Null) => None,
                        Some(Value::Number(x)) => match x.as_f64() {
                            Some(v) if v.is_finite() => Some(v / term.display_factor(m)),
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
                let std = self.number_or_null(q, "std", &field("std"), &term)?;
                let determined = self.flag(q, "determined", &field("determined"))?;
                let fixed = self.flag(q, "fixed", &field("fixed"))?.unwrap_or(false);
                if fixed && value != Some(0.0) {
                    return Err(self.bad(
                        &field("value"),
                        "a parameter fixed by the constraint (`fixed: true`) has the value 0"
                            .into(),
                    ));
                }
                columns
                    .nominal
                    .push(self.nominal(q, &field("nominal_mm"), &term, value)?);
                columns.values.push(value);
                columns.std.push(std);
                columns
                    .determined
                    .push(determined.unwrap_or(value.is_some()));
                columns.fixed.push(fixed);
            }
            Ok((term, columns))
        }
    }

    /// The optional number `key` of the parameter `q` (`null` or absent: `None`), divided by
    /// the term's display factor; named `field` in errors.
    fn number_or_null(
        &self,
        q: &Value,
        key: &str,
        field: &str,
        term: &Term,
    ) -> Result<Option<f64>, ReportError> {
        match q.get(key) {
            None | Some(Value::Null) => Ok(None),
            Some(Value::Number(x)) => match x.as_f64() {
                Some(v) if v.is_finite() && v >= 0.0 => Ok(Some(v / term.display_factor(self.m))),
                _ => Err(self.bad(field, format!("{x} is not a finite number of at least 0"))),
            },
            Some(other) => {
                Err(self.bad(field, format!("expected a number or null, found {other}")))
            }
        }
    }

    /// The `nominal_mm` of the parameter `q` of `term` (value `value`, mm) when `term` is a
    /// kinematic offset (required: a finite length in mm; with `identified_mm`, when written,
    /// `nominal_mm` plus the value), `None` for other terms.
    fn nominal(
        &self,
        q: &Value,
        field: &str,
        term: &Term,
        value: Option<f64>,
    ) -> Result<Option<f64>, ReportError> {
        let Some(s) = term.effect.symbol() else {
            return Ok(None);
        };
        let name = &self.m.symbols[s].name;
        let nominal = match q.get("nominal_mm") {
            Some(Value::Number(x)) => x
                .as_f64()
                .filter(|x| x.is_finite() && x.abs() <= model_spec::limits::MAX_LENGTH_MM),
            _ => None,
        }
        .ok_or_else(|| {
            self.bad(
                field,
                format!(
                    "missing or not a length in mm: the value of kinematic offset `{name}` is a change from the symbol's value the records were modelled with, which `nominal_mm` gives"
                ),
            )
        })?;
        if let (Some(Value::Number(x)), Some(v)) = (q.get("identified_mm"), value) {
            let written = x.as_f64().unwrap_or(f64::NAN);
            let expected = nominal + v;
            let off = (written - expected).abs();
            if off.is_nan() || off > 1e-9 * (1.0 + expected.abs()) {
                return Err(self.bad(
                    &field.replace("nominal_mm", "identified_mm"),
                    format!(
                        "{} mm is not nominal_mm + value ({} mm) for `{name}`",
                        short(written),
                        short(expected)
                    ),
                ));
            }
        }
        Ok(Some(nominal))
    }

    /// The optional boolean `key` of the parameter `q`; named `field` in errors.
    fn flag(&self, q: &Value, key: &str, field: &str) -> Result<Option<bool>, ReportError> {
        match q.get(key) {
            None => Ok(None),
            Some(Value::Bool(b)) => Ok(Some(*b)),
            Some(other) => Err(self.bad(field, format!("expected true or false, found {other}"))),
        }
    }
}
