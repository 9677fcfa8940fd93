//! The fields of an identification report, read and checked one by one, each failure naming
//! the file and the field: the header (machine, fingerprint, base model, refinement,
//! constraint), the parameters (effect, basis, unit, value, uncertainty, flags, stroke of a
//! `poly:K` term, nominal length of a kinematic offset), the terms and the records.

use super::ReportError;
use crate::json::identify::poly_stroke;
use fitting::campaign::RecordSpec;
use model_spec::Machine;
use model_spec::units::short;
use serde_json::Value;
use simulation::model::{Basis, Effect, Model, Term};

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

/// A report of type `T` parsed from its JSON `text` (`file` names it in messages; a byte-order
/// mark is skipped), refused when its version (`version` of it) is not 1 to
/// [`crate::json::identify::REPORT_VERSION`].
pub(crate) fn versioned<T: serde::de::DeserializeOwned>(
    file: &str,
    text: &str,
    version: impl Fn(&T) -> u32,
) -> Result<T, ReportError> {
    use crate::json::identify::REPORT_VERSION;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let r: T = serde_json::from_str(text).map_err(|e| json_error(file, text, &e))?;
    match version(&r) {
        1..=REPORT_VERSION => Ok(r),
        v => Err(ReportError::Field {
            file: file.to_string(),
            field: "version".into(),
            message: format!(
                "{v}: this rtest reads versions 1 to {REPORT_VERSION} (a newer rtest wrote it?)"
            ),
        }),
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
                simulation::model::Carrier::Axis(a) => self.m.axes[a].name.clone(),
                simulation::model::Carrier::None => "?".into(),
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
    pub(crate) fn parameters(&self, root: &Value) -> Result<(Model, Columns), ReportError> {
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
                self.bad(
                    &field("error"),
                    simulation::model::unknown_effect(m, &error).0,
                )
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

impl Reader<'_> {
    /// The model of `terms`: terms of the machine, none twice, at least one.
    pub(crate) fn terms(&self, root: &Value) -> Result<Model, ReportError> {
        let Some(Value::Array(items)) = root.get("terms") else {
            return Err(self.bad("terms", "missing, or not an array of terms".into()));
        };
        let mut model = Model::default();
        for (i, v) in items.iter().enumerate() {
            let field = format!("terms[{i}]");
            let text = v
                .as_str()
                .ok_or_else(|| self.bad(&field, format!("expected a term, found {v}")))?;
            let t = Term::parse(self.m, text)
                .map_err(|e| self.bad(&field, format!("`{text}`: {e}")))?;
            if model.terms.contains(&t) {
                return Err(self.bad(&field, format!("`{text}` is given twice")));
            }
            model.terms.push(t);
        }
        if model.terms.is_empty() {
            return Err(self.bad("terms", "is empty".into()));
        }
        Ok(model)
    }

    /// The records as a layout needs them, with their data files, and the campaign clock's
    /// span (s): `records` lists every record with `label`, `setup`, `params` (an object of the
    /// machine's symbols, mm; a symbol left out takes its default), `zeroed` and, when the
    /// report has a `clock` (`{"start_s", "end_s"}`), `start_s`.
    pub(crate) fn records(&self, root: &Value) -> Result<Records, ReportError> {
        let (r, m) = (self, self.m);
        let clock = match root.get("clock") {
            None | Some(Value::Null) => None,
            Some(c) => {
                let num = |k: &str| {
                    c.get(k)
                        .and_then(Value::as_f64)
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            r.bad(
                                &format!("clock.{k}"),
                                "missing, or not a finite number (s)".into(),
                            )
                        })
                };
                Some((num("start_s")?, num("end_s")?))
            }
        };
        let Some(Value::Array(items)) = root.get("records") else {
            return Err(r.bad("records", "missing, or not an array".into()));
        };
        if items.is_empty() {
            return Err(r.bad("records", "is empty".into()));
        }
        let mut specs: Vec<RecordSpec> = Vec::with_capacity(items.len());
        let mut data = Vec::with_capacity(items.len());
        for (i, v) in items.iter().enumerate() {
            let field = |f: &str| format!("records[{i}].{f}");
            let label = r.string(v, "label", &field("label"))?;
            simulation::campaign::check_label("label", &label)
                .map_err(|e| r.bad(&field("label"), e.0))?;
            if specs.iter().any(|s| s.label == label) {
                return Err(r.bad(&field("label"), format!("`{label}` is given twice")));
            }
            let setup = r.string(v, "setup", &field("setup"))?;
            simulation::campaign::check_label("setup", &setup)
                .map_err(|e| r.bad(&field("setup"), e.0))?;
            data.push(match v.get("data") {
                Some(Value::String(s)) => s.clone(),
                None => String::new(),
                Some(other) => {
                    return Err(r.bad(&field("data"), format!("expected a string, found {other}")));
                }
            });
            let mut params = m.default_parameters();
            match v.get("params") {
                Some(Value::Object(p)) => {
                    for (k, x) in p {
                        let s = m.symbol_by_name(k).ok_or_else(|| {
                            r.bad(
                                &field("params"),
                                format!("machine {} has no kinematic symbol `{k}`", m.name),
                            )
                        })?;
                        params[s] = x
                            .as_f64()
                            .filter(|x| {
                                x.is_finite() && x.abs() <= model_spec::limits::MAX_LENGTH_MM
                            })
                            .ok_or_else(|| {
                                r.bad(
                                    &field(&format!("params.{k}")),
                                    format!("{x} is not a length in mm"),
                                )
                            })?;
                    }
                }
                None => {}
                Some(other) => {
                    return Err(r.bad(
                        &field("params"),
                        format!("expected an object, found {other}"),
                    ));
                }
            }
            let zeroed = match v.get("zeroed") {
                Some(Value::Bool(b)) => *b,
                None => false,
                Some(other) => {
                    return Err(r.bad(
                        &field("zeroed"),
                        format!("expected true or false, found {other}"),
                    ));
                }
            };
            let start_s = match v.get("start_s") {
                None | Some(Value::Null) => None,
                Some(x) => Some(x.as_f64().filter(|x| x.is_finite()).ok_or_else(|| {
                    r.bad(&field("start_s"), format!("{x} is not a finite number (s)"))
                })?),
            };
            if clock.is_some() != start_s.is_some() {
                return Err(r.bad(
                    &field("start_s"),
                    "every record has a start when the report has a clock, and none without".into(),
                ));
            }
            if let Some(o) = specs
                .iter()
                .find(|o| o.setup == setup && o.params != params)
            {
                return Err(r.bad(
                    &field("params"),
                    format!(
                        "record `{label}` and record `{}` share set-up `{setup}` with other kinematic parameters",
                        o.label
                    ),
                ));
            }
            let samples = match v.get("samples") {
                Some(Value::Number(n)) => n.as_u64().unwrap_or(0) as usize,
                _ => 0,
            };
            specs.push(RecordSpec {
                label,
                setup,
                params,
                zeroed,
                start_s,
                samples,
            });
        }
        Ok(Records { specs, data, clock })
    }
}

/// The records of a report: as a layout needs them, their data files, the campaign clock's
/// span (s).
pub(crate) struct Records {
    /// The records.
    pub(crate) specs: Vec<RecordSpec>,
    /// Per record, its data file (empty when the report does not say).
    pub(crate) data: Vec<String>,
    /// The campaign clock's span.
    pub(crate) clock: Option<(f64, f64)>,
}
