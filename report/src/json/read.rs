//! An identification report read back, of one record or several, version 1 or 2: the model,
//! the layout of its records and set-ups, and the values `validate` and `compensate` apply,
//! after the checks that they belong to the machine. One reader for every report
//! ([`parse_identification`]); a record is a campaign of one.
//!
//! Checked, in order, each failure naming the file and the field:
//! - the file is at most [`MAX_REPORT_BYTES`], UTF-8 (a byte-order mark is accepted), JSON;
//! - `version`, when given, is 1 or 2 (a report without it is version 1);
//! - `machine` is the machine's name and `fingerprint` its fingerprint (the same topology and
//!   machine-side kinematic defaults: a copy of `seed-ac` with C reversed has another one);
//! - `base_model`, when given, is a model of the machine;
//! - the refinement, when the report has one, converged (an identification that did not is no
//!   result);
//! - every parameter has `error` (an effect of the machine), `basis` (a column of the
//!   vocabulary; a harmonic's `cos` column followed by its `sin` column), `value` (a finite
//!   number, or `null`: undetermined) and `unit` (the effect's); a `poly:K` parameter was
//!   normalised over the stroke this machine has for its axis; a kinematic offset (a symbol of
//!   the machine, `Zt`) has `nominal_mm`, the value its change is relative to (a finite length
//!   in mm), and `identified_mm`, when written, is `nominal_mm` plus the value;
//! - what the fit says of each value, when the report says it: `std` (a finite number or
//!   `null`), `determined` and `fixed` (booleans; a fixed parameter has the value 0), and
//!   `constraint` (`none`, `minimum-norm` or `zero: NAME, …`). A report without them reads as
//!   an unconstrained fit whose values are determined where they are not `null`.
//!
//! **A report of one record** (no `"kind": "campaign"`): `terms` lists exactly the terms of the
//! parameters, in order, and holds every term of the base model (and the sensor offsets when
//! the readings were zeroed): no parameter is missing. Version 2 has its record in `records`
//! (its label, set-up, kinematic parameters, zeroing), and a kinematic offset's `nominal_mm`
//! must be the record's value of the symbol. Version 1 has none: its record is labelled by the
//! stem of `data`, on its own set-up, at the machine's default kinematic parameters, and the
//! change of a symbol of the machine (not of the workpiece set-up) is re-expressed relative to
//! the default: `value` becomes the identified length minus the default (the change itself
//! when the identification used the default). The change of a ball position (`Xw`) is kept,
//! like the set-up errors `XOW YOW ZOW`.
//!
//! **A report of several records** (`"kind": "campaign"`): `terms` are terms of the machine,
//! none twice; `records` lists every record with `label`, `setup`, `params` (an object of the
//! machine's symbols, mm; a symbol left out takes its default), `zeroed` and, when the report
//! has a `clock` (`{"start_s", "end_s"}`), `start_s`; the layout these give
//! ([`fitting::campaign::Layout::of_records`]) has exactly the columns of `parameters`,
//! in order, with the same names and owners; a kinematic offset's `nominal_mm` is its owner's
//! records' value of the symbol.

mod fields;

pub(crate) use fields::{Columns, Reader, json_error, versioned};

use fitting::campaign::validate::single_columns;
use fitting::campaign::{CampaignValues, Layout, Owner, RecordSpec};
use formats::campaign::stem_label;
use model_spec::Machine;
use model_spec::text::{TextError, decode_text};
use serde_json::Value;
use simulation::model::Model;

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

/// The values of an identification report, with what it says of them, in internal units.
#[derive(Clone, Debug, PartialEq)]
pub struct IdentifiedValues {
    /// The file the values were read from, as named in messages.
    pub file: String,
    /// The machine it was identified on.
    pub machine: String,
    /// The fingerprint of the machine description it was identified on (the machine's own:
    /// another one is refused when the report is read).
    pub fingerprint: String,
    /// The report's version (1 when the file has none).
    pub version: u32,
    /// The model's label.
    pub model_name: String,
    /// The model, the layout of the records and set-ups, and per layout column the value (in
    /// the term's unit inside, [`simulation::model::Term::places`]: mm, rad; ms for `velocity`; 1
    /// for instrument terms), the standard uncertainty, determined and fixed.
    pub values: CampaignValues,
    /// Per record, the measurement file it was read from (empty when the report does not say).
    pub data: Vec<String>,
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

    /// The model and values of the only record of a report of one record: as
    /// [`IdentifiedValues::record_values`]; `None` for a report of several records.
    pub fn single_record(&self) -> Option<(Model, Vec<Option<f64>>)> {
        match self.values.layout.records.as_slice() {
            [r] => self.record_values(&r.label),
            _ => None,
        }
    }

    /// The model and values of the record labelled `label`: its own model (with its zero
    /// offsets when zeroed) and one value per column of it (`None`: not determined); `None`
    /// when no record has that label.
    pub fn record_values(&self, label: &str) -> Option<(Model, Vec<Option<f64>>)> {
        let r = self
            .values
            .layout
            .records
            .iter()
            .find(|r| r.label == label)?;
        Some((
            r.model.clone(),
            r.columns.iter().map(|&c| self.values.values[c]).collect(),
        ))
    }
}

/// The label of a version-1 report of one record seen as a campaign of one: the stem of its
/// `data` file, `fitted` when it has none.
pub fn single_label(data: Option<&str>) -> String {
    match data {
        Some(d) if !d.is_empty() => stem_label(std::path::Path::new(d)),
        _ => "fitted".into(),
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

/// Parses the text of an identification report (`file` names it in messages) for machine `m`,
/// of one record or several, version 1 or 2; see the module documentation for what is checked.
/// Other fields are ignored.
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
    if !root.is_object() {
        return Err(r.bad("(top level)", "expected a JSON object".into()));
    }
    let version = match root.get("version") {
        None => 1,
        Some(Value::Number(n)) if n.as_u64() == Some(1) || n.as_u64() == Some(2) => {
            n.as_u64().unwrap_or(1) as u32
        }
        Some(other) => {
            return Err(r.bad(
                "version",
                format!(
                    "{other}: this rtest reads versions 1 and {} (a newer rtest wrote it?)",
                    crate::json::identify::REPORT_VERSION
                ),
            ));
        }
    };
    let (machine, fingerprint) = r.header(&root)?;
    let base = r.base_model(&root)?;
    r.converged(&root)?;
    let model_name = r.string(&root, "model", "model")?;
    let campaign = match root.get("kind") {
        None | Some(Value::Null) => false,
        Some(Value::String(k)) if k == crate::json::identify::CAMPAIGN_KIND => true,
        Some(other) => {
            return Err(r.bad(
                "kind",
                format!("{other}: an identification report has no kind, or `campaign`"),
            ));
        }
    };
    let (values, data) = if campaign {
        campaign_values(&r, &root)?
    } else {
        record_values(&r, &root, version, base.as_ref())?
    };
    Ok(IdentifiedValues {
        file: file.to_string(),
        machine,
        fingerprint,
        version,
        model_name,
        values,
        data,
        constraint: r.constraint(&root)?,
    })
}

/// The columns' values as the campaign values of `layout`, the report's columns being those of
/// layout columns `at` (one per report column).
fn place(layout: Layout, model: Model, columns: Columns, at: &[usize]) -> CampaignValues {
    let n = layout.columns.len();
    let mut v = CampaignValues {
        model,
        layout,
        values: vec![None; n],
        std: vec![None; n],
        determined: vec![false; n],
        fixed: vec![false; n],
    };
    for (k, &c) in at.iter().enumerate() {
        v.values[c] = columns.values[k];
        v.std[c] = columns.std[k];
        v.determined[c] = columns.determined[k];
        v.fixed[c] = columns.fixed[k];
    }
    v
}

/// The values of a report of one record (`version` 1 or 2).
fn record_values(
    r: &Reader,
    root: &Value,
    version: u32,
    base: Option<&(String, Model)>,
) -> Result<(CampaignValues, Vec<String>), ReportError> {
    let m = r.m;
    let (fitted, mut columns) = r.parameters(root)?;
    let spelled: Vec<String> = fitted.terms.iter().map(|t| t.spelling(m)).collect();
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
    let parsed: Vec<Option<simulation::model::Term>> = listed
        .iter()
        .map(|t| simulation::model::Term::parse(m, t).ok())
        .collect();
    if parsed
        .iter()
        .map(Option::as_ref)
        .ne(fitted.terms.iter().map(Some))
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
    let zeroed = match root.get("zeroed") {
        None | Some(Value::Null) => None,
        Some(Value::Bool(b)) => Some(*b),
        Some(other) => {
            return Err(r.bad("zeroed", format!("expected true or false, found {other}")));
        }
    };
    let records = match (version, root.get("records")) {
        (1, None) => None,
        (_, None) => {
            return Err(r.bad(
                "records",
                "missing: a version-2 report lists its record (label, set-up, kinematic parameters)"
                    .into(),
            ));
        }
        (_, Some(_)) => Some(r.records(root)?),
    };
    if let Some(recs) = &records
        && recs.specs.len() != 1
    {
        return Err(r.bad(
            "records",
            format!(
                "{} records, but a report without `\"kind\": \"campaign\"` is of one record",
                recs.specs.len()
            ),
        ));
    }
    let zeroed = match (&records, zeroed) {
        (Some(recs), Some(z)) if recs.specs[0].zeroed != z => {
            return Err(r.bad(
                "zeroed",
                format!(
                    "{z}, but its record says {}: one record is zeroed or not",
                    recs.specs[0].zeroed
                ),
            ));
        }
        (Some(recs), _) => recs.specs[0].zeroed,
        (None, z) => z.unwrap_or(false),
    };
    if let Some((name, base)) = base {
        let wanted = if zeroed {
            fitting::with_offsets(base)
        } else {
            base.clone()
        };
        let missing: Vec<String> = wanted
            .terms
            .iter()
            .filter(|t| !fitted.terms.contains(t))
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
    let (spec, data, clock) = match records {
        Some(recs) => {
            let spec = recs.specs.into_iter().next().expect("one record");
            (spec, recs.data, recs.clock)
        }
        None => {
            // Version 1: a change of a machine's length, re-expressed from the
            // identification's value of the symbol to this machine's default (the fingerprint
            // makes the defaults the same).
            for (j, (t, _)) in fitted.columns().into_iter().enumerate() {
                if let (Some(s), Some(n), Some(v)) = (
                    fitted.terms[t].effect.symbol(),
                    columns.nominal[j],
                    columns.values[j],
                ) && !fitting::offsets::is_setup_symbol(m, s)
                {
                    columns.values[j] = Some(v + (n - m.symbols[s].default));
                    columns.nominal[j] = Some(m.symbols[s].default);
                }
            }
            let data = root.get("data").and_then(Value::as_str);
            let label = single_label(data);
            let spec = RecordSpec {
                label: label.clone(),
                setup: label,
                params: m.default_parameters(),
                zeroed,
                start_s: None,
                samples: root
                    .get("samples")
                    .and_then(Value::as_u64)
                    .map_or(0, |n| n as usize),
            };
            (spec, vec![data.unwrap_or("").to_string()], None)
        }
    };
    let model = fitting::campaign::validate::given_model(&fitted, zeroed);
    let layout = Layout::of_records(m, &model, std::slice::from_ref(&spec), clock)
        .map_err(|e| r.bad("records", e.to_string()))?;
    let at = single_columns(&layout, &fitted).ok_or_else(|| {
        r.bad(
            "parameters",
            "the parameters are not the columns of the record's model".into(),
        )
    })?;
    check_nominal(r, &layout, &columns, &at)?;
    Ok((place(layout, model, columns, &at), data))
}

/// Checks that a kinematic offset's `nominal_mm` (report column `k`, layout column `at[k]`) is
/// its owner's records' value of the symbol.
fn check_nominal(
    r: &Reader,
    layout: &Layout,
    columns: &Columns,
    at: &[usize],
) -> Result<(), ReportError> {
    let nominal = layout.nominal_mm();
    for (k, n) in columns.nominal.iter().enumerate() {
        if let (Some(n), Some(want)) = (n, nominal[at[k]])
            && n.to_bits() != want.to_bits()
        {
            return Err(r.bad(
                &format!("parameters[{k}].nominal_mm"),
                format!(
                    "{} mm, but the records of `{}` are modelled with {} mm",
                    model_spec::units::short(*n),
                    layout.columns[at[k]].name,
                    model_spec::units::short(want)
                ),
            ));
        }
    }
    Ok(())
}

/// The values of a report of several records.
fn campaign_values(r: &Reader, root: &Value) -> Result<(CampaignValues, Vec<String>), ReportError> {
    let m = r.m;
    let model = r.terms(root)?;
    let recs = r.records(root)?;
    let layout = Layout::of_records(m, &model, &recs.specs, recs.clock)
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
            Owner::Shared => ("shared", None),
            Owner::Setup(_) => ("setup", Some(layout.owner_label(c.owner))),
            Owner::Record(_) => ("record", Some(layout.owner_label(c.owner))),
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
        all.values.extend(cols.values);
        all.std.extend(cols.std);
        all.determined.extend(cols.determined);
        all.fixed.extend(cols.fixed);
        all.nominal.extend(cols.nominal);
        j += term.basis.width();
    }
    let at: Vec<usize> = (0..layout.columns.len()).collect();
    check_nominal(r, &layout, &all, &at)?;
    Ok((place(layout, model, all, &at), recs.data))
}
