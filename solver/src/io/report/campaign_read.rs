//! A campaign identification report read back: the model, the layout and the values
//! `validate` applies, after the checks of a single report ([`super::read`]) and these:
//!
//! - `kind` is `campaign`; `terms` are terms of the machine, none twice;
//! - `records` lists every record with `label`, `setup`, `params` (an object of the machine's
//!   symbols, mm; a symbol left out takes its default), `zeroed` and, when the report has a
//!   `clock` (`{"start_s", "end_s"}`), `start_s`;
//! - the layout these give ([`crate::fitting::campaign::Layout::of_records`]) has exactly the
//!   columns of `parameters`, in order, with the same names and owners; each parameter is
//!   checked as in a single report (unit, basis, value, `std`, `determined`, `fixed`); a
//!   kinematic offset's `nominal_mm` is its owner's records' value of the symbol.
//!
//! [`read_values`] reads either kind of report: a single identification becomes a campaign of
//! one record, labelled by the stem of its `data` file, on the set-up of that label.

use super::read::{
    Columns, IdentifiedValues, MAX_REPORT_BYTES, Reader, ReportError, json_error,
    parse_identification,
};
use crate::fitting::campaign::{CampaignValues, Layout, RecordSpec};
use crate::io::campaign::stem_label;
use crate::model::{Model, Term};
use model_spec::Machine;
use serde_json::Value;

/// The values of a campaign report, with what it says of them.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignRead {
    /// The file, as named in messages.
    pub file: String,
    /// The model's label.
    pub model_name: String,
    /// The values, one per layout column.
    pub values: CampaignValues,
    /// Per layout column: determined by the data.
    pub determined: Vec<bool>,
    /// The constraint of the fit as written.
    pub constraint: String,
}

/// Identified values of either kind of report.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadValues {
    /// A single identification (`rtest identify --data FILE`).
    Single {
        /// Its values.
        values: IdentifiedValues,
        /// Its `data` field: the file it was identified on.
        data: Option<String>,
    },
    /// A campaign identification.
    Campaign(CampaignRead),
}

/// Reads the report at `path` for machine `m`: a campaign report when its `kind` is
/// `campaign`, else a single identification.
///
/// # Errors
/// [`ReportError`] naming the file and the field.
pub fn read_values(path: &std::path::Path, m: &Machine) -> Result<ReadValues, ReportError> {
    let text = model_spec::text::read_text(path, MAX_REPORT_BYTES)?;
    let file = path.display().to_string();
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let root: Value = serde_json::from_str(text).map_err(|e| json_error(&file, text, &e))?;
    if root.get("kind").and_then(Value::as_str) == Some(super::campaign::CAMPAIGN_KIND) {
        parse_campaign_report(&file, &root, m).map(ReadValues::Campaign)
    } else {
        let data = root.get("data").and_then(Value::as_str).map(str::to_string);
        parse_identification(&file, text, m).map(|values| ReadValues::Single { values, data })
    }
}

/// The label of a single identification seen as a campaign of one record: the stem of its
/// `data` file, `fitted` when it has none.
pub fn single_label(data: Option<&str>) -> String {
    match data {
        Some(d) if !d.is_empty() => stem_label(std::path::Path::new(d)),
        _ => "fitted".into(),
    }
}

impl ReadValues {
    /// The values as a campaign sees them (a single identification: one record, see
    /// [`single_label`], at the machine's default kinematic parameters), the model's label.
    ///
    /// # Errors
    /// [`ReportError::Field`] when the single identification's model does not fit the machine.
    pub fn as_campaign(&self, m: &Machine) -> Result<(CampaignValues, String), ReportError> {
        match self {
            ReadValues::Campaign(c) => Ok((c.values.clone(), c.model_name.clone())),
            ReadValues::Single { values: v, data } => {
                let label = single_label(data.as_deref());
                let values = CampaignValues::single(
                    m,
                    &v.model,
                    &v.values,
                    &v.std,
                    &label,
                    m.default_parameters(),
                )
                .map_err(|e| ReportError::Field {
                    file: v.file.clone(),
                    field: "parameters".into(),
                    message: e.to_string(),
                })?;
                Ok((values, v.model_name.clone()))
            }
        }
    }
}

/// Parses a campaign report (`root`, from `file`) for machine `m`.
///
/// # Errors
/// [`ReportError::Field`] naming the field.
pub fn parse_campaign_report(
    file: &str,
    root: &Value,
    m: &Machine,
) -> Result<CampaignRead, ReportError> {
    let r = Reader { file, m };
    r.header(root)?;
    r.base_model(root)?;
    r.converged(root)?;
    let model_name = r.string(root, "model", "model")?;
    let model = terms(&r, root)?;
    let (specs, clock) = records(&r, root)?;
    let layout = Layout::of_records(m, &model, &specs, clock)
        .map_err(|e| r.bad("records", e.to_string()))?;
    let params = match root.get("parameters") {
        Some(Value::Array(a)) => a,
        Some(other) => return Err(r.bad("parameters", format!("expected an array, found {other}"))),
        None => return Err(r.bad("parameters", "missing".into())),
    };
    if params.len() != layout.columns.len() {
        return Err(r.bad(
            "parameters",
            format!(
                "{} parameters, but the terms and records give {} ({})",
                params.len(),
                layout.columns.len(),
                layout.names().join(", ")
            ),
        ));
    }
    let mut all = Columns::default();
    let nominal = layout.nominal_mm();
    let mut j = 0;
    while j < params.len() {
        let c = &layout.columns[j];
        let field = |f: &str| format!("parameters[{j}].{f}");
        let name = r.string(&params[j], "name", &field("name"))?;
        if name != c.name {
            return Err(r.bad(
                &field("name"),
                format!("`{name}`: the terms and records give `{}` here", c.name),
            ));
        }
        let (owner, of) = match c.owner {
            crate::fitting::campaign::Owner::Shared => ("shared", None),
            crate::fitting::campaign::Owner::Setup(_) => {
                ("setup", Some(layout.owner_label(c.owner)))
            }
            crate::fitting::campaign::Owner::Record(_) => {
                ("record", Some(layout.owner_label(c.owner)))
            }
        };
        let written_owner = r.string(&params[j], "owner", &field("owner"))?;
        let written_of = params[j].get("of").and_then(Value::as_str);
        if written_owner != owner || written_of != of {
            return Err(r.bad(
                &field("owner"),
                format!(
                    "`{written_owner}` of {written_of:?}: `{name}` is {owner}{}",
                    of.map_or(String::new(), |o| format!(" of `{o}`"))
                ),
            ));
        }
        let (term, cols) = r.term_at(params, j)?;
        if term != c.term {
            return Err(r.bad(
                &field("error"),
                format!("the terms and records give `{}` here", c.term.spelling(m)),
            ));
        }
        // A kinematic offset's change is relative to its owner's records' value of the symbol.
        for (k, n) in cols.nominal.iter().enumerate() {
            if let (Some(n), Some(want)) = (n, nominal[j + k])
                && n.to_bits() != want.to_bits()
            {
                return Err(r.bad(
                    &format!("parameters[{}].nominal_mm", j + k),
                    format!(
                        "{} mm, but the records of `{name}` are modelled with {} mm",
                        model_spec::units::short(*n),
                        model_spec::units::short(want)
                    ),
                ));
            }
        }
        all.values.extend(cols.values);
        all.std.extend(cols.std);
        all.determined.extend(cols.determined);
        all.fixed.extend(cols.fixed);
        j += term.basis.width();
    }
    Ok(CampaignRead {
        file: file.to_string(),
        model_name,
        values: CampaignValues {
            model,
            layout,
            values: all.values,
            std: all.std,
        },
        determined: all.determined,
        constraint: r.constraint(root)?,
    })
}

/// The model of `terms`.
fn terms(r: &Reader, root: &Value) -> Result<Model, ReportError> {
    let Some(Value::Array(items)) = root.get("terms") else {
        return Err(r.bad("terms", "missing, or not an array of terms".into()));
    };
    let mut model = Model::default();
    for (i, v) in items.iter().enumerate() {
        let field = format!("terms[{i}]");
        let text = v
            .as_str()
            .ok_or_else(|| r.bad(&field, format!("expected a term, found {v}")))?;
        let t = Term::parse(r.m, text).map_err(|e| r.bad(&field, format!("`{text}`: {e}")))?;
        if model.terms.contains(&t) {
            return Err(r.bad(&field, format!("`{text}` is given twice")));
        }
        model.terms.push(t);
    }
    if model.terms.is_empty() {
        return Err(r.bad("terms", "is empty".into()));
    }
    Ok(model)
}

/// The records as the layout needs them, and the campaign clock's span (s).
type Records = (Vec<RecordSpec>, Option<(f64, f64)>);

/// The records as the layout needs them, and the campaign clock.
fn records(r: &Reader, root: &Value) -> Result<Records, ReportError> {
    let m = r.m;
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
    for (i, v) in items.iter().enumerate() {
        let field = |f: &str| format!("records[{i}].{f}");
        let label = r.string(v, "label", &field("label"))?;
        crate::fitting::campaign::check_label("label", &label)
            .map_err(|e| r.bad(&field("label"), e.0))?;
        if specs.iter().any(|s| s.label == label) {
            return Err(r.bad(&field("label"), format!("`{label}` is given twice")));
        }
        let setup = r.string(v, "setup", &field("setup"))?;
        crate::fitting::campaign::check_label("setup", &setup)
            .map_err(|e| r.bad(&field("setup"), e.0))?;
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
                        .filter(|x| x.is_finite() && x.abs() <= model_spec::limits::MAX_LENGTH_MM)
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
                format!("record `{label}` and record `{}` share set-up `{setup}` with other kinematic parameters", o.label),
            ));
        }
        specs.push(RecordSpec {
            label,
            setup,
            params,
            zeroed,
            start_s,
            samples: 0,
        });
    }
    Ok((specs, clock))
}
