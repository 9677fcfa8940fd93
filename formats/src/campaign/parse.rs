//! The validation of a campaign file's text: every key checked, every problem located by
//! line, column and field.

use super::{
    CampaignEntry, CampaignFile, CampaignFileError, RECORD_KEYS, TOP_KEYS, stem_label, unique_label,
};
use crate::located::{TomlText, Val, in_order};
use model_spec::Machine;
use simulation::campaign::{check_label, check_record_count};
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::de::{DeTable, DeValue};

type Res<T> = Result<T, CampaignFileError>;

/// Parses the text of a campaign file (`file` names it in messages; `dir` is the directory
/// its relative `file` fields are taken from) for machine `m`.
///
/// # Errors
/// [`CampaignFileError::Invalid`] naming the line, the column and the field.
pub fn parse_campaign(file: &str, text: &str, dir: &Path, m: &Machine) -> Res<CampaignFile> {
    let p = Parser {
        t: TomlText::new(file, text),
        m,
    };
    let root = p.t.root()?;
    p.campaign(root.get_ref(), dir)
}

/// The validator of one file.
struct Parser<'a> {
    t: TomlText<'a>,
    m: &'a Machine,
}

impl Parser<'_> {
    fn err(&self, span: Range<usize>, message: impl Into<String>) -> CampaignFileError {
        self.t.at(span, message).into()
    }

    fn line(&self, span: &Range<usize>) -> usize {
        self.t.line(span)
    }

    fn string(&self, field: &str, v: &Val<'_>) -> Res<String> {
        Ok(self.t.string(v, &format!("`{field}`"))?)
    }

    fn number(&self, field: &str, v: &Val<'_>) -> Res<f64> {
        Ok(self.t.number(v, &format!("`{field}`"))?.0)
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
        check_record_count(items.len()).map_err(|e| self.err(entries.span(), e.0))?;
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
                check_label("the label made unique", &r.label).map_err(|e| {
                    CampaignFileError::Invalid {
                        file: self.t.file().to_string(),
                        line: r.line,
                        column: 1,
                        message: format!("{}: give the record a `label`", e.0),
                    }
                })?;
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
                    file: self.t.file().to_string(),
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
            file: self.t.file().to_string(),
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
                                    "`{field}`: {} mm is beyond the largest length a machine may have, {} mm",
                                    model_spec::units::significant(x),
                                    model_spec::units::significant(model_spec::limits::MAX_LENGTH_MM)
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
                            format!(
                                "`start`: {} s is beyond ±1e9 s (about 30 years)",
                                model_spec::units::significant(x)
                            ),
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
            None => {
                let l = stem_label(&path);
                check_label("`file`: the label made from its name", &l).map_err(|e| {
                    self.err(
                        file_span.clone(),
                        format!("{}: give the record a `label`", e.0),
                    )
                })?;
                l
            }
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
