//! The campaign file: a TOML list of records (measurement CSVs), each with its label, its ball
//! set-up, its kinematic parameters, whether its readings were zeroed and, optionally, when it
//! started on a campaign clock (`docs/campaigns.md`).
//!
//! ```toml
//! machine = "seed-ac"                  # optional: the machine the campaign was measured on
//! description = "two ball heights"     # optional
//!
//! [[record]]
//! file = "k4-low.csv"                  # required; relative to this file's directory
//! label = "k4-low"                     # optional: the file's stem, made unique
//! setup = "low"                        # optional: the label (a set-up of its own)
//! params = { Zw = 211.537 }            # optional: kinematic symbols, mm; the others default
//! zeroed = false                       # optional: readings zeroed at the first sample
//! start = 0.0                          # optional: s on the campaign clock; all records or none
//! ```
//!
//! Every problem is reported with the file, the line, the column and the field. Each record's
//! CSV is read with its own kinematic parameters: its linear axes, when the file gives them,
//! must keep the sensor nest on the ball *at those parameters*, and when it does not give them
//! they are filled by the inverse kinematics at those parameters.

use crate::fitting::campaign::{Campaign, CampaignError, CampaignRecord, check_label, label_char};
use crate::io::csv::{CsvError, ReadOptions, read_measurement};
use model_spec::Machine;
use model_spec::text::TextError;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The largest campaign file read (bytes): far above any real one.
pub const MAX_CAMPAIGN_BYTES: u64 = 4 << 20;

/// The keys of a campaign file, for messages.
const TOP_KEYS: &str = "machine, description, [[record]]";
/// The keys of a record, for messages.
const RECORD_KEYS: &str = "file, label, setup, params, zeroed, start";

/// Why a campaign cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CampaignFileError {
    /// The file cannot be read, is too large or is not UTF-8.
    #[error(transparent)]
    Text(#[from] TextError),
    /// A malformed or wrong field, located.
    #[error("{file}:{line}:{column}: {message}")]
    Invalid {
        /// The campaign file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What is wrong, naming the field.
        message: String,
    },
    /// A record's measurement CSV cannot be read (its own file, line and column are named).
    #[error("record `{label}` ({campaign}:{line}): {error}{at}")]
    Record {
        /// Where the record's kinematic parameters differ from the machine's defaults, what
        /// they are (the file was read at them): `; read at its kinematic parameters Zw = 300
        /// mm`; else empty.
        at: String,
        /// The campaign file.
        campaign: String,
        /// The line of the record's `file` field.
        line: usize,
        /// The record's label.
        label: String,
        /// What the CSV reader said.
        error: Box<CsvError>,
    },
    /// The records do not make a campaign (e.g. starts on some records only).
    #[error("{file}: {error}")]
    Campaign {
        /// The campaign file.
        file: String,
        /// What is wrong.
        error: CampaignError,
    },
}

/// One record of a campaign file, before its CSV is read.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignEntry {
    /// The CSV's path: the `file` field, relative to the campaign file's directory unless
    /// absolute.
    pub path: PathBuf,
    /// The label (given, or the file's stem made unique).
    pub label: String,
    /// The set-up label (given, or the label).
    pub setup: String,
    /// The kinematic parameters (mm, symbol order): the machine's defaults with `params`.
    pub params: Vec<f64>,
    /// Whether the readings were zeroed at the first sample.
    pub zeroed: bool,
    /// The record's time 0 on the campaign clock, s.
    pub start_s: Option<f64>,
    /// The line of the record's `file` field, for messages.
    pub line: usize,
}

/// A campaign file as read: its records, not yet loaded.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignFile {
    /// The file, as named in messages.
    pub file: String,
    /// What the campaign is, for people (may be empty).
    pub description: String,
    /// The records, in file order.
    pub records: Vec<CampaignEntry>,
}

/// A label from a file's stem: the characters a label may not hold replaced by `_`, `record`
/// when nothing is left.
pub fn stem_label(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let l: String = stem
        .chars()
        .map(|c| if label_char(c) { c } else { '_' })
        .collect();
    if l.is_empty() { "record".into() } else { l }
}

/// `label` made unique among `taken`: as it is, else with `-2`, `-3`, … appended.
pub fn unique_label(label: &str, taken: &[String]) -> String {
    if !taken.iter().any(|t| t == label) {
        return label.to_string();
    }
    (2..)
        .map(|k| format!("{label}-{k}"))
        .find(|l| !taken.iter().any(|t| t == l))
        .unwrap_or_else(|| label.to_string())
}

/// The labels of records read from `paths`: each file's stem ([`stem_label`]), made unique in
/// order ([`unique_label`]).
pub fn labels_from_files(paths: &[PathBuf]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(paths.len());
    for p in paths {
        let l = unique_label(&stem_label(p), &out);
        out.push(l);
    }
    out
}

/// `m` with its symbols' defaults set to `params` (mm, symbol order): the machine a record
/// planned at those parameters is read with.
pub fn machine_at(m: &Machine, params: &[f64]) -> Machine {
    let mut at = m.clone();
    for (s, &v) in at.symbols.iter_mut().zip(params) {
        s.default = v;
    }
    at
}

/// Reads the measurement CSV at `path` planned at kinematic parameters `params` (mm): as
/// [`read_measurement`] with the machine's defaults replaced by `params`.
///
/// # Errors
/// As [`read_measurement`].
pub fn read_record_at(
    path: &Path,
    m: &Machine,
    params: &[f64],
    opts: &ReadOptions,
) -> Result<crate::record::Record, CsvError> {
    if params == m.default_parameters().as_slice() {
        read_measurement(path, m, opts)
    } else {
        read_measurement(path, &machine_at(m, params), opts)
    }
}

/// `; read at its kinematic parameters Zw = 300 mm (the machine's defaults for the others)`
/// when `params` differ from `m`'s defaults, else empty: what a message about a record read at
/// those parameters adds.
pub fn parameters_note(m: &Machine, params: &[f64]) -> String {
    let differ: Vec<String> = m
        .symbols
        .iter()
        .zip(params)
        .filter(|(s, v)| s.default != **v)
        .map(|(s, v)| format!("{} = {} mm", s.name, model_spec::units::short(*v)))
        .collect();
    if differ.is_empty() {
        String::new()
    } else {
        format!(
            "; read at its kinematic parameters {} (the machine's defaults for the others)",
            differ.join(", ")
        )
    }
}

/// Reads the campaign file at `path` for machine `m` (records not loaded).
///
/// # Errors
/// [`CampaignFileError::Text`] or [`CampaignFileError::Invalid`].
pub fn read_campaign_file(path: &Path, m: &Machine) -> Result<CampaignFile, CampaignFileError> {
    let text = model_spec::text::read_text(path, MAX_CAMPAIGN_BYTES)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    parse_campaign(&path.display().to_string(), &text, dir, m)
}

/// Reads the campaign file at `path` and every record's CSV (each at its own kinematic
/// parameters, with `opts`): the file and the campaign.
///
/// # Errors
/// As [`read_campaign_file`]; [`CampaignFileError::Record`] for a CSV that cannot be read;
/// [`CampaignFileError::Campaign`] for records that do not make a campaign.
pub fn load_campaign(
    path: &Path,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<(CampaignFile, Campaign), CampaignFileError> {
    let f = read_campaign_file(path, m)?;
    let c = f.load(m, opts)?;
    Ok((f, c))
}

impl CampaignFile {
    /// Reads every record's CSV at its kinematic parameters (with `opts`) into a campaign.
    ///
    /// # Errors
    /// [`CampaignFileError::Record`] naming the record and the CSV's own line;
    /// [`CampaignFileError::Campaign`] for records that do not make a campaign.
    pub fn load(&self, m: &Machine, opts: &ReadOptions) -> Result<Campaign, CampaignFileError> {
        let mut records = Vec::with_capacity(self.records.len());
        for e in &self.records {
            let record = read_record_at(&e.path, m, &e.params, opts).map_err(|error| {
                CampaignFileError::Record {
                    at: parameters_note(m, &e.params),
                    campaign: self.file.clone(),
                    line: e.line,
                    label: e.label.clone(),
                    error: Box::new(error),
                }
            })?;
            if e.start_s.is_some() && !record.has_times() {
                return Err(CampaignFileError::Invalid {
                    file: self.file.clone(),
                    line: e.line,
                    column: 1,
                    message: format!(
                        "record `{}`: `start` puts the record on the campaign clock, but {} has no `t_s` column (its samples are only numbered): add the times in s",
                        e.label,
                        e.path.display()
                    ),
                });
            }
            let mut r = CampaignRecord::new(
                e.label.clone(),
                record,
                e.params.clone(),
                e.setup.clone(),
                e.zeroed,
            );
            r.start_s = e.start_s;
            records.push(r);
        }
        Campaign::new(records).map_err(|error| CampaignFileError::Campaign {
            file: self.file.clone(),
            error,
        })
    }
}

type Key<'i> = Spanned<std::borrow::Cow<'i, str>>;
type Val<'i> = Spanned<DeValue<'i>>;
type Res<T> = Result<T, CampaignFileError>;

/// Parses the text of a campaign file (`file` names it in messages; `dir` is the directory
/// its relative `file` fields are taken from) for machine `m`.
///
/// # Errors
/// [`CampaignFileError::Invalid`] naming the line, the column and the field.
pub fn parse_campaign(file: &str, text: &str, dir: &Path, m: &Machine) -> Res<CampaignFile> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let p = Parser { file, text, m };
    let root = DeTable::parse(text).map_err(|e| p.err(e.span().unwrap_or(0..0), e.message()))?;
    p.campaign(root.get_ref(), dir)
}

/// The validator of one file.
struct Parser<'a> {
    file: &'a str,
    text: &'a str,
    m: &'a Machine,
}

/// The entries of a table in file order.
fn in_order<'t, 'i>(t: &'t DeTable<'i>) -> Vec<(&'t Key<'i>, &'t Val<'i>)> {
    let mut v: Vec<_> = t.iter().collect();
    v.sort_by_key(|(k, _)| k.span().start);
    v
}

impl Parser<'_> {
    fn err(&self, span: Range<usize>, message: impl Into<String>) -> CampaignFileError {
        let (line, column) = model_spec::locate::line_col(self.text, span.start);
        CampaignFileError::Invalid {
            file: self.file.to_string(),
            line,
            column,
            message: message.into(),
        }
    }

    fn line(&self, span: &Range<usize>) -> usize {
        model_spec::locate::line_col(self.text, span.start).0
    }

    fn string(&self, field: &str, v: &Val<'_>) -> Res<String> {
        match v.get_ref() {
            DeValue::String(s) => Ok(s.to_string()),
            other => Err(self.err(
                v.span(),
                format!("`{field}` must be a string, not {}", other.type_str()),
            )),
        }
    }

    fn number(&self, field: &str, v: &Val<'_>) -> Res<f64> {
        let x = match v.get_ref() {
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|x| x as f64),
            other => {
                return Err(self.err(
                    v.span(),
                    format!("`{field}` must be a number, not {}", other.type_str()),
                ));
            }
        };
        match x {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(self.err(v.span(), format!("`{field}` must be a finite number"))),
        }
    }

    fn campaign(&self, root: &DeTable<'_>, dir: &Path) -> Res<CampaignFile> {
        let mut description = String::new();
        let mut entries: Option<&Val<'_>> = None;
        for (k, v) in in_order(root) {
            match k.get_ref().as_ref() {
                "machine" => {
                    let name = self.string("machine", v)?;
                    if name != self.m.name {
                        return Err(self.err(
                            v.span(),
                            format!(
                                "`machine`: this campaign was measured on machine `{name}`, not `{}`",
                                self.m.name
                            ),
                        ));
                    }
                }
                "description" => description = self.string("description", v)?.trim().into(),
                "record" => entries = Some(v),
                other => {
                    return Err(self.err(
                        k.span(),
                        format!("unknown key `{other}` (expected {TOP_KEYS})"),
                    ));
                }
            }
        }
        let Some(entries) = entries else {
            return Err(self.err(
                0..0,
                "no record: a campaign lists its records as [[record]] tables, each with at least `file = \"...\"`",
            ));
        };
        let DeValue::Array(items) = entries.get_ref() else {
            return Err(self.err(
                entries.span(),
                "`record` must be an array of tables, written [[record]]",
            ));
        };
        let mut records: Vec<CampaignEntry> = Vec::with_capacity(items.len());
        let mut label_spans: Vec<Option<Range<usize>>> = Vec::new();
        let mut setup_given: Vec<bool> = Vec::new();
        for item in items.iter() {
            let DeValue::Table(t) = item.get_ref() else {
                return Err(self.err(
                    item.span(),
                    format!(
                        "a record must be a table, written [[record]], not {}",
                        item.get_ref().type_str()
                    ),
                ));
            };
            let (entry, label_span, given) =
                self.record(t, item.span(), dir, &records, &label_spans)?;
            records.push(entry);
            label_spans.push(label_span);
            setup_given.push(given);
        }
        // Labels taken from file stems are made unique against every label given.
        let given: Vec<String> = records
            .iter()
            .zip(&label_spans)
            .filter(|(_, s)| s.is_some())
            .map(|(r, _)| r.label.clone())
            .collect();
        let mut taken = given;
        for ((r, s), &given) in records.iter_mut().zip(&label_spans).zip(&setup_given) {
            if s.is_none() {
                r.label = unique_label(&r.label, &taken);
                if !given {
                    r.setup = r.label.clone();
                }
                taken.push(r.label.clone());
            }
        }
        for (i, r) in records.iter().enumerate() {
            let Some(o) = records[..i].iter().find(|o| o.setup == r.setup) else {
                continue;
            };
            if let Some(k) = (0..r.params.len()).find(|&k| r.params[k] != o.params[k]) {
                return Err(CampaignFileError::Invalid {
                    file: self.file.to_string(),
                    line: r.line,
                    column: 1,
                    message: format!(
                        "record `{}`: `params.{}` is {} mm, but record `{}` (line {}) on the same set-up `{}` has {} mm: one ball set-up has one position; give the records different `setup` labels",
                        r.label,
                        self.m.symbols[k].name,
                        r.params[k],
                        o.label,
                        o.line,
                        r.setup,
                        o.params[k]
                    ),
                });
            }
        }
        Ok(CampaignFile {
            file: self.file.to_string(),
            description,
            records,
        })
    }

    /// One `[[record]]` table (`span` the table's), its label's span when given, and whether its
    /// set-up was given.
    fn record(
        &self,
        t: &DeTable<'_>,
        span: Range<usize>,
        dir: &Path,
        before: &[CampaignEntry],
        before_spans: &[Option<Range<usize>>],
    ) -> Res<(CampaignEntry, Option<Range<usize>>, bool)> {
        let m = self.m;
        let mut path: Option<(PathBuf, Range<usize>)> = None;
        let mut label: Option<(String, Range<usize>)> = None;
        let mut setup: Option<String> = None;
        let mut params = m.default_parameters();
        let mut zeroed = false;
        let mut start_s = None;
        for (k, v) in in_order(t) {
            match k.get_ref().as_ref() {
                "file" => {
                    let f = self.string("file", v)?;
                    if f.trim().is_empty() {
                        return Err(self.err(v.span(), "`file` is empty"));
                    }
                    let p = PathBuf::from(&f);
                    path = Some((if p.is_absolute() { p } else { dir.join(p) }, v.span()));
                }
                "label" => {
                    let l = self.string("label", v)?;
                    check_label("`label`", &l).map_err(|e| self.err(v.span(), e.0))?;
                    if let Some(i) = before
                        .iter()
                        .zip(before_spans)
                        .position(|(r, s)| s.is_some() && r.label == l)
                    {
                        return Err(self.err(
                            v.span(),
                            format!(
                                "`label`: `{l}` is already the label of the record at line {}; every record needs its own label",
                                before[i].line
                            ),
                        ));
                    }
                    label = Some((l, v.span()));
                }
                "setup" => {
                    let s = self.string("setup", v)?;
                    check_label("`setup`", &s).map_err(|e| self.err(v.span(), e.0))?;
                    setup = Some(s);
                }
                "params" => {
                    let DeValue::Table(pt) = v.get_ref() else {
                        return Err(self.err(
                            v.span(),
                            format!(
                                "`params` must be a table of kinematic symbols in mm (params = {{ Zw = 150.0 }}), not {}",
                                v.get_ref().type_str()
                            ),
                        ));
                    };
                    for (pk, pv) in in_order(pt) {
                        let name = pk.get_ref().as_ref();
                        let Some(s) = m.symbol_by_name(name) else {
                            let known: Vec<&str> =
                                m.symbols.iter().map(|s| s.name.as_str()).collect();
                            return Err(self.err(
                                pk.span(),
                                format!(
                                    "`params`: machine {} has no kinematic symbol `{name}` (symbols: {})",
                                    m.name,
                                    if known.is_empty() {
                                        "none".to_string()
                                    } else {
                                        known.join(", ")
                                    }
                                ),
                            ));
                        };
                        let field = format!("params.{name}");
                        let x = self.number(&field, pv)?;
                        if x.abs() > model_spec::limits::MAX_LENGTH_MM {
                            return Err(self.err(
                                pv.span(),
                                format!(
                                    "`{field}`: {x} mm is beyond the largest length a machine may have, {} mm",
                                    model_spec::limits::MAX_LENGTH_MM
                                ),
                            ));
                        }
                        params[s] = x;
                    }
                }
                "zeroed" => match v.get_ref() {
                    DeValue::Boolean(b) => zeroed = *b,
                    other => {
                        return Err(self.err(
                            v.span(),
                            format!("`zeroed` must be true or false, not {}", other.type_str()),
                        ));
                    }
                },
                "start" => {
                    let x = self.number("start", v)?;
                    if x.abs() > 1e9 {
                        return Err(self.err(
                            v.span(),
                            format!("`start`: {x} s is beyond ±1e9 s (about 30 years)"),
                        ));
                    }
                    start_s = Some(x);
                }
                other => {
                    return Err(self.err(
                        k.span(),
                        format!("unknown key `{other}` in a record (expected {RECORD_KEYS})"),
                    ));
                }
            }
        }
        let Some((path, file_span)) = path else {
            return Err(self.err(
                span,
                "a record needs `file = \"...\"` (its measurement CSV)",
            ));
        };
        let line = self.line(&file_span);
        let label_span = label.as_ref().map(|(_, s)| s.clone());
        let label = match label {
            Some((l, _)) => l,
            None => stem_label(&path),
        };
        let given = setup.is_some();
        let setup = setup.unwrap_or_else(|| label.clone());
        Ok((
            CampaignEntry {
                path,
                label,
                setup,
                params,
                zeroed,
                start_s,
                line,
            },
            label_span,
            given,
        ))
    }
}
