//! What a report is made of: the JSON reports rtest writes (recognised by their content), the
//! figures the verb that asks for the report has drawn, the input files with their SHA-256, and
//! the checks that the reports belong together (one machine, one model, the same data).

use crate::json::compensate::CompensationReport;
use crate::json::{DiagnosisReport, IdentificationReport, ValidationReport};
use model_spec::sha256::Digest;
use serde_json::Value;
use std::path::Path;

/// One report of rtest, recognised by its content.
#[derive(Clone, Debug, PartialEq)]
pub enum Document {
    /// What `rtest identify --json` writes (one record or a campaign of several).
    Identification(Box<IdentificationReport>),
    /// What `rtest validate --json` writes (one record or several).
    Validation(Box<ValidationReport>),
    /// What `rtest diagnose --json` writes.
    Diagnosis(Box<DiagnosisReport>),
    /// What `rtest compensate --json` writes.
    Compensation(Box<CompensationReport>),
}

impl Document {
    /// The report's kind in words (`identification`, …).
    pub fn kind(&self) -> &'static str {
        match self {
            Document::Identification(_) => "identification",
            Document::Validation(_) => "validation",
            Document::Diagnosis(_) => "diagnosis",
            Document::Compensation(_) => "compensation",
        }
    }

    /// The machine it is of.
    pub fn machine(&self) -> &str {
        match self {
            Document::Identification(r) => &r.machine,
            Document::Validation(r) => &r.machine,
            Document::Diagnosis(r) => &r.machine,
            Document::Compensation(r) => &r.machine,
        }
    }
}

/// Why a report cannot be read or does not fit with the others.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file cannot be read as text: an I/O error, more than
    /// [`crate::json::read::MAX_REPORT_BYTES`], or not UTF-8 (the message names the
    /// file).
    #[error("{0}")]
    Read(#[from] model_spec::text::TextError),
    /// The file is not JSON, or is a JSON that no verb of rtest writes.
    #[error(
        "{file}: not a report of rtest ({why}); give what identify --json, validate --json, diagnose --json or compensate --json writes"
    )]
    Unknown {
        /// The file.
        file: String,
        /// Where and why, with line and column when the text is not JSON.
        why: String,
    },
    /// A report of a known kind with a missing or malformed field.
    #[error("{file}: {kind} report: {why}")]
    Field {
        /// The file.
        file: String,
        /// The kind of report its content names.
        kind: &'static str,
        /// serde's message: the field, its line and column.
        why: String,
    },
    /// Two reports of a kind that can appear once.
    #[error("{file}: a second {kind} report ({first} is one): give one")]
    Twice {
        /// The second file.
        file: String,
        /// The kind.
        kind: &'static str,
        /// The first file of that kind.
        first: String,
    },
    /// Two reports that cannot be of the same check.
    #[error("{file} and {other} disagree: {why}")]
    Disagree {
        /// The report added last.
        file: String,
        /// The one it disagrees with.
        other: String,
        /// What differs.
        why: String,
    },
}

/// Reads the report in `path` (opened once) and recognises its kind from its fields: the
/// report, its text and the digest of the bytes read.
///
/// # Errors
/// [`InputError`]: unreadable, larger than 64 MiB, not UTF-8, not JSON, not a report of rtest,
/// a field missing or malformed.
pub fn read_document(path: &Path) -> Result<(Document, String, Digest), InputError> {
    let file = path.display().to_string();
    let (text, digest) =
        model_spec::text::read_text_hashed(path, crate::json::read::MAX_REPORT_BYTES)?;
    let doc = classify(&file, &text)?;
    Ok((doc, text, digest))
}

/// The report in `text` (read from `file`), recognised by its fields: `findings` and
/// `base_fit` (diagnosis), `compensated` and `left_out` (compensation), `per_direction` and
/// `prediction` (validation), `parameters`, `fingerprint` and `refinement` (identification).
/// Identifications and validations of one record or several, version 1 or 2, are read as
/// [`IdentificationReport::from_json`] and [`ValidationReport::from_json`] read them.
///
/// # Errors
/// As [`read_document`].
pub fn classify(file: &str, text: &str) -> Result<Document, InputError> {
    let value: Value = serde_json::from_str(text).map_err(|e| InputError::Unknown {
        file: file.to_string(),
        why: format!("not JSON: {e}"),
    })?;
    let Value::Object(map) = &value else {
        return Err(InputError::Unknown {
            file: file.to_string(),
            why: "the JSON is not an object".into(),
        });
    };
    let has = |keys: &[&str]| keys.iter().all(|k| map.contains_key(*k));
    let typed = |kind: &'static str| {
        move |e: serde_json::Error| InputError::Field {
            file: file.to_string(),
            kind,
            why: e.to_string(),
        }
    };
    let read = |kind: &'static str| {
        move |e: crate::json::ReportError| InputError::Field {
            file: file.to_string(),
            kind,
            why: match e {
                crate::json::ReportError::Json {
                    line,
                    column,
                    message,
                    ..
                } => format!("{message} at line {line} column {column}"),
                crate::json::ReportError::Field { field, message, .. } => {
                    format!("field `{field}`: {message}")
                }
                other => other.to_string(),
            },
        }
    };
    let doc = if has(&["findings", "base_fit"]) {
        let r = serde_json::from_str(text).map_err(typed("diagnosis"))?;
        Document::Diagnosis(Box::new(r))
    } else if has(&["compensated", "left_out", "axes"]) {
        let r = serde_json::from_str(text).map_err(typed("compensation"))?;
        Document::Compensation(Box::new(r))
    } else if has(&["per_direction", "prediction"]) {
        let r = ValidationReport::from_json(file, text).map_err(read("validation"))?;
        Document::Validation(Box::new(r))
    } else if has(&["parameters", "fingerprint", "refinement"]) {
        let r = IdentificationReport::from_json(file, text).map_err(read("identification"))?;
        Document::Identification(Box::new(r))
    } else {
        return Err(InputError::Unknown {
            file: file.to_string(),
            why: "a JSON object without the fields of any of them (parameters, per_direction, findings, compensated)".into(),
        });
    };
    if doc.machine().trim().is_empty() {
        return Err(InputError::Field {
            file: file.to_string(),
            kind: doc.kind(),
            why: "field `machine` is empty: a report names the machine it is of".into(),
        });
    }
    Ok(doc)
}

/// A figure ready for the page: its id (an HTML id), its SVG text and its caption (what it
/// shows, what the abscissa is).
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// The HTML id (`fig-k4-path`).
    pub id: String,
    /// The SVG text, as `plots` returns it.
    pub svg: String,
    /// What it shows and what its abscissa is.
    pub caption: String,
    /// The numbers it draws, for programs, as `data-*` attributes of its `<figure>`: (name
    /// after `data-`, of lower-case letters, digits and `-`; value). Empty for most figures.
    pub data: Vec<(String, String)>,
}

/// An input file of the check: its role, its path and, when it was read, the size and SHA-256
/// of the bytes read.
#[derive(Clone, Debug, PartialEq)]
pub struct InputFile {
    /// What it was (`--data`, `identification report`).
    pub role: String,
    /// The path as given.
    pub path: String,
    /// Size and SHA-256 of the bytes read (by the verb, or by `rtest report` when it wrote
    /// the report), or why the file was not hashed (one line: `not a regular file`).
    pub digest: Result<Digest, String>,
    /// When the file was last modified, RFC 3339 UTC, as its file system says (the only date
    /// a record carries: its samples hold seconds from its start); `None` when unknown.
    pub modified: Option<String>,
}

impl InputFile {
    /// The file `path` (as shown), found at `at`, read as `digest` says: its modification
    /// time is asked of the file system (`metadata`, which opens nothing).
    pub fn read(role: &str, path: &str, at: &Path, digest: Digest) -> InputFile {
        InputFile {
            role: role.to_string(),
            path: path.to_string(),
            digest: Ok(digest),
            modified: modified(at),
        }
    }

    /// The file `path` (as shown), not hashed, and `why` (one line).
    pub fn not_hashed(role: &str, path: &str, at: Option<&Path>, why: &str) -> InputFile {
        InputFile {
            role: role.to_string(),
            path: path.to_string(),
            digest: Err(why.to_string()),
            modified: at.and_then(modified),
        }
    }
}

/// When the file at `at` was last modified (RFC 3339 UTC), as its file system says.
fn modified(at: &Path) -> Option<String> {
    std::fs::metadata(at)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| formats::time::Timestamp::of(t).ok())
        .map(|t| t.to_string())
}

/// The machine as its description gives it, when the verb has it (the reports name it only).
#[derive(Clone, Debug, PartialEq)]
pub struct MachineFacts {
    /// Its name.
    pub name: String,
    /// Its description.
    pub description: String,
    /// Its fingerprint (topology and machine-side kinematic defaults).
    pub fingerprint: String,
    /// Per axis: name, kind (`linear`, `rotary`), side (`work`, `tool`), stroke in mm or
    /// degrees with its unit (`unlimited` for a rotary axis without limits).
    pub axes: Vec<[String; 4]>,
    /// The kinematic symbols and their default values, mm (a record's ball position is shown
    /// where it differs from them).
    pub symbols: Vec<(String, f64)>,
}

impl MachineFacts {
    /// The facts of `m`.
    pub fn of(m: &model_spec::Machine) -> MachineFacts {
        let axes = m
            .axes
            .iter()
            .map(|a| {
                // Limits are in the axis's command unit: mm, or degrees.
                let rotary = a.kind == model_spec::AxisKind::Rotary;
                let [lo, hi] = a.limits;
                [
                    a.name.clone(),
                    if rotary { "rotary" } else { "linear" }.to_string(),
                    match a.side {
                        model_spec::Side::Work => "work",
                        model_spec::Side::Tool => "tool",
                    }
                    .to_string(),
                    if lo.is_finite() && hi.is_finite() {
                        format!(
                            "{} to {} {}",
                            model_spec::units::short(lo),
                            model_spec::units::short(hi),
                            if rotary { "deg" } else { "mm" }
                        )
                    } else {
                        "unlimited".to_string()
                    },
                ]
            })
            .collect();
        MachineFacts {
            name: m.name.clone(),
            description: m.description.clone(),
            fingerprint: m.fingerprint(),
            axes,
            symbols: m
                .symbols
                .iter()
                .map(|s| (s.name.clone(), s.default))
                .collect(),
        }
    }
}

/// Everything a report shows: the reports, with the file each came from, the figures, the
/// input files and when the report was written.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    /// The identification and its file.
    pub identification: Option<(String, IdentificationReport)>,
    /// The validations and their files, in the order given.
    pub validations: Vec<(String, ValidationReport)>,
    /// The diagnosis and its file.
    pub diagnosis: Option<(String, DiagnosisReport)>,
    /// The compensation and its file.
    pub compensation: Option<(String, CompensationReport)>,
    /// The machine's description, when the verb has it.
    pub machine: Option<MachineFacts>,
    /// Measured against predicted along each path, drawn by the verb that computed the
    /// predictions (`diagnose --report`); empty otherwise.
    pub path_figures: Vec<Figure>,
    /// Why there are no path figures, when there are none (one line).
    pub no_path_figures: Option<String>,
    /// Why there is no compensation, when the verb knows where it is (one line).
    pub no_compensation: Option<String>,
    /// Measured against the identified model's prediction along the path of each record (the
    /// fitted one and the validations'), drawn by the verb that read the records.
    pub prediction_figures: Vec<Figure>,
    /// The records of the check whose prediction is not drawn, and why (one line each).
    pub prediction_not_drawn: Vec<String>,
    /// The input files, hashed.
    pub files: Vec<InputFile>,
    /// When the report was written (RFC 3339, UTC); `None` leaves it out.
    pub written_at: Option<String>,
}

/// Two paths that name the same file: equal once `./` prefixes are dropped, or both readable
/// and the same file.
fn same_file(a: &str, b: &str) -> bool {
    let plain = |s: &str| s.trim_start_matches("./").to_string();
    if plain(a) == plain(b) {
        return true;
    }
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

impl Inputs {
    /// No report yet.
    pub fn new() -> Inputs {
        Inputs::default()
    }

    /// Whether no report has been added.
    pub fn is_empty(&self) -> bool {
        self.identification.is_none()
            && self.validations.is_empty()
            && self.diagnosis.is_none()
            && self.compensation.is_none()
    }

    /// Every report added, as (file, machine name).
    fn machines(&self) -> Vec<(&str, &str)> {
        let mut out: Vec<(&str, &str)> = Vec::new();
        if let Some((f, r)) = &self.identification {
            out.push((f, &r.machine));
        }
        out.extend(
            self.validations
                .iter()
                .map(|(f, r)| (f.as_str(), r.machine.as_str())),
        );
        if let Some((f, r)) = &self.diagnosis {
            out.push((f, &r.machine));
        }
        if let Some((f, r)) = &self.compensation {
            out.push((f, &r.machine));
        }
        out
    }

    /// Adds `doc`, read from `file`, after checking that it belongs with the reports already
    /// added: the same machine (and the machine of [`Inputs::machine`], fingerprint included),
    /// the identification's model for validations and compensations, the identification's data
    /// and its model (the base or the extended one) for a diagnosis; one identification,
    /// diagnosis and compensation at most, and no record validated twice.
    ///
    /// # Errors
    /// [`InputError::Twice`], [`InputError::Disagree`].
    pub fn add(&mut self, file: &str, doc: Document) -> Result<(), InputError> {
        let disagree = |other: &str, why: String| InputError::Disagree {
            file: file.to_string(),
            other: other.to_string(),
            why,
        };
        if let Some((other, machine)) = self.machines().first()
            && *machine != doc.machine()
        {
            return Err(disagree(
                other,
                format!(
                    "machine `{}` against `{machine}`: reports of two machines",
                    doc.machine()
                ),
            ));
        }
        if let Some(m) = &self.machine {
            if m.name != doc.machine() {
                return Err(disagree(
                    "--machine",
                    format!("machine `{}` against `{}`", doc.machine(), m.name),
                ));
            }
            if let Document::Identification(r) = &doc
                && r.fingerprint != m.fingerprint
            {
                return Err(disagree(
                    "--machine",
                    format!(
                        "fingerprint {} against {}: the description has changed since the identification",
                        r.fingerprint, m.fingerprint
                    ),
                ));
            }
        }
        let twice = |kind: &'static str, first: &str| InputError::Twice {
            file: file.to_string(),
            kind,
            first: first.to_string(),
        };
        match doc {
            Document::Identification(r) => {
                if let Some((first, _)) = &self.identification {
                    return Err(twice("identification", first));
                }
                for (f, v) in &self.validations {
                    check_model(&v.model, &r.model).map_err(|why| disagree(f, why))?;
                }
                if let Some((f, c)) = &self.compensation {
                    check_model(&c.model, &r.model).map_err(|why| disagree(f, why))?;
                }
                if let Some((f, d)) = &self.diagnosis {
                    check_diagnosis(d, &r).map_err(|why| disagree(f, why))?;
                }
                self.identification = Some((file.to_string(), *r));
            }
            Document::Validation(v) => {
                if let Some((f, r)) = &self.identification {
                    check_model(&v.model, &r.model).map_err(|why| disagree(f, why))?;
                }
                for (f, w) in &self.validations {
                    if let Some(x) = v
                        .records
                        .iter()
                        .find(|x| w.records.iter().any(|y| same_file(&y.data, &x.data)))
                    {
                        return Err(disagree(
                            f,
                            format!("both validate on {}: the same record twice", x.data),
                        ));
                    }
                }
                self.validations.push((file.to_string(), *v));
            }
            Document::Diagnosis(d) => {
                if let Some((first, _)) = &self.diagnosis {
                    return Err(twice("diagnosis", first));
                }
                if let Some((f, r)) = &self.identification {
                    check_diagnosis(&d, r).map_err(|why| disagree(f, why))?;
                }
                self.diagnosis = Some((file.to_string(), *d));
            }
            Document::Compensation(c) => {
                if let Some((first, _)) = &self.compensation {
                    return Err(twice("compensation", first));
                }
                if let Some((f, r)) = &self.identification {
                    check_model(&c.model, &r.model).map_err(|why| disagree(f, why))?;
                }
                self.compensation = Some((file.to_string(), *c));
            }
        }
        Ok(())
    }
}

/// A validation's or compensation's model against the identification's.
fn check_model(model: &str, identified: &str) -> Result<(), String> {
    if model == identified {
        Ok(())
    } else {
        Err(format!(
            "model `{model}` against the identified model `{identified}`: values of another model"
        ))
    }
}

/// A diagnosis against the identification: the same fitted records, and the identified model
/// is the diagnosis's base model or its extended model.
fn check_diagnosis(d: &DiagnosisReport, r: &IdentificationReport) -> Result<(), String> {
    let diagnosed: Vec<&str> = d
        .records
        .iter()
        .filter(|x| x.role == "fitted")
        .map(|x| x.data.as_str())
        .collect();
    let identified: Vec<&str> = r.records.iter().map(|x| x.data.as_str()).collect();
    let same = diagnosed.len() == identified.len()
        && identified
            .iter()
            .all(|i| diagnosed.iter().any(|d| same_file(d, i)));
    if !same {
        return Err(format!(
            "the diagnosis fitted {} and the identification {}: other data",
            diagnosed.join(", "),
            identified.join(", ")
        ));
    }
    if r.model != d.base_model && r.model != d.extended_model.label {
        return Err(format!(
            "the identified model `{}` is neither the diagnosed model `{}` nor its extension `{}`",
            r.model, d.base_model, d.extended_model.label
        ));
    }
    Ok(())
}
