//! Tolerances of a machine's errors: `|error| ≤ limit`, in µm for translational errors and
//! µrad for angular ones (the unit the error is reported in).
//!
//! A tolerance file is TOML, one file per machine, one `NAME = limit` line per error:
//!
//! ```toml
//! # Tolerances of machine M123 (|error| ≤ limit): µm for translations, µrad for angles.
//! machine_id = "M123"          # optional: the file is refused for another machine id
//! XOC = 5
//! YOC = 5
//! AOC = 20
//! BOC = 20
//! "ECC@harmonic:2:cos" = 8     # any parameter rtest reports, quoted when it has @ or :
//! ```
//!
//! Names are read as rtest reads error names (any case, `X0C` for `XOC`). A limit is a
//! positive finite number. A name given twice, a value that is not a number, a table, or a
//! name that no check of the machine identified (a misspelt name would silently switch its
//! tolerance off) is an error naming the file, the line and the column. On the command line,
//! `--tolerance XOC=5` gives one.
//!
//! These limits judge identified values. The deviations of R-test records over a test are
//! judged against another file, [`formats::tolerance`] (per test and direction, `max_um` and
//! `range_um`), by `rtest validate --tolerance`; both follow the decision rule of ISO 14253-1,
//! [`fitting::verdict`] (the tolerance flag's "nonconformance proven" is its fail branch, with
//! `U = 2σ` of the value's fit: the model's lack of fit is not in that margin).

use crate::check::canonical_key;
use formats::located::{Located, TomlText, in_order};
use std::ops::Range;
use toml::de::DeValue;

/// The largest tolerance file read, bytes.
pub const MAX_TOLERANCE_BYTES: u64 = 1 << 20;

/// The key naming the machine a tolerance file is for.
pub const MACHINE_KEY: &str = "machine_id";

/// A problem with a tolerance, located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct ToleranceError {
    /// The file (or `--tolerance`).
    pub file: String,
    /// 1-based line (1 for `--tolerance`).
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong, naming the field.
    pub message: String,
}

impl From<Located> for ToleranceError {
    fn from(e: Located) -> Self {
        ToleranceError {
            file: e.file,
            line: e.line,
            column: e.column,
            message: e.message,
        }
    }
}

/// One tolerance and where it was given.
#[derive(Clone, Debug, PartialEq)]
pub struct Tolerance {
    /// The name as written.
    pub name: String,
    /// The limit, µm or µrad.
    pub limit: f64,
    /// The file (or `--tolerance`).
    pub file: String,
    /// 1-based line and column of the name.
    pub at: (usize, usize),
}

/// The tolerances of one machine.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tolerances {
    /// The machine id the file names, if it names one, with its place.
    pub machine_id: Option<(String, (usize, usize))>,
    /// The tolerances, in file order.
    pub entries: Vec<Tolerance>,
}

impl Tolerances {
    /// The limit of `parameter`, if it has one.
    pub fn limit(&self, parameter: &str) -> Option<f64> {
        let key = canonical_key(parameter);
        self.entries
            .iter()
            .find(|t| canonical_key(&t.name) == key)
            .map(|t| t.limit)
    }

    /// Refuses a file for another machine id, and names that are not among `known` (the
    /// parameters identified in the machine's checks).
    ///
    /// # Errors
    /// [`ToleranceError`] at the offending line.
    pub fn check(&self, machine_id: &str, known: &[String]) -> Result<(), ToleranceError> {
        if let Some((id, (line, column))) = &self.machine_id
            && id != machine_id
        {
            let file = self
                .entries
                .first()
                .map_or_else(String::new, |t| t.file.clone());
            return Err(ToleranceError {
                file,
                line: *line,
                column: *column,
                message: format!(
                    "`{MACHINE_KEY}`: these tolerances are for machine `{id}`, not `{machine_id}`"
                ),
            });
        }
        let keys: Vec<String> = known.iter().map(|k| canonical_key(k)).collect();
        for t in &self.entries {
            if !keys.contains(&canonical_key(&t.name)) {
                return Err(ToleranceError {
                    file: t.file.clone(),
                    line: t.at.0,
                    column: t.at.1,
                    message: format!(
                        "`{}`: no check of machine `{machine_id}` identified it (its parameters: {})",
                        t.name,
                        known.join(", ")
                    ),
                });
            }
        }
        Ok(())
    }

    /// Adds `t`, refusing a name given before.
    fn push(&mut self, t: Tolerance) -> Result<(), ToleranceError> {
        let key = canonical_key(&t.name);
        if let Some(before) = self.entries.iter().find(|e| canonical_key(&e.name) == key) {
            return Err(ToleranceError {
                file: t.file.clone(),
                line: t.at.0,
                column: t.at.1,
                message: format!(
                    "`{}` is given twice (first at {}:{})",
                    t.name, before.file, before.at.0
                ),
            });
        }
        self.entries.push(t);
        Ok(())
    }
}

/// Checks a parameter name's characters.
fn name_ok(name: &str) -> bool {
    !name.is_empty()
        && name.chars().all(|c| {
            c.is_ascii_alphanumeric() || matches!(c, '@' | ':' | '.' | '-' | '[' | ']' | '_')
        })
}

/// The tolerances of the TOML `text` of the file `file`.
///
/// # Errors
/// [`ToleranceError`] naming the file, the line, the column and the field.
pub fn parse_file(file: &str, text: &str) -> Result<Tolerances, ToleranceError> {
    let src = TomlText::new(file, text);
    let err = |span: Range<usize>, message: String| ToleranceError::from(src.at(span, message));
    let root = src.root()?;
    let entries = in_order(root.get_ref());
    let mut out = Tolerances::default();
    for (k, v) in entries {
        let name = k.get_ref().as_ref();
        if name == MACHINE_KEY {
            match v.get_ref() {
                DeValue::String(s) => {
                    out.machine_id = Some((s.to_string(), src.line_col(k.span().start)));
                    continue;
                }
                other => {
                    return Err(err(
                        v.span(),
                        format!("`{MACHINE_KEY}` must be a string, not {}", other.type_str()),
                    ));
                }
            }
        }
        if !name_ok(name) {
            return Err(err(
                k.span(),
                format!("`{name}` is not an error name (XOC, ECC@harmonic:2:cos, …)"),
            ));
        }
        let limit = match v.get_ref() {
            DeValue::Float(f) => f.as_str().parse::<f64>().ok(),
            DeValue::Integer(i) => i64::from_str_radix(i.as_str(), i.radix())
                .ok()
                .map(|x| x as f64),
            DeValue::Table(_) | DeValue::Array(_) => {
                return Err(err(
                    v.span(),
                    format!(
                        "`{name}`: a tolerance is one number (`{name} = 5`), not a table or an array"
                    ),
                ));
            }
            other => {
                return Err(err(
                    v.span(),
                    format!(
                        "`{name}` must be a number (µm or µrad), not {}",
                        other.type_str()
                    ),
                ));
            }
        };
        let limit = match limit {
            Some(x) if x.is_finite() && x > 0.0 => x,
            _ => {
                return Err(err(
                    v.span(),
                    format!("`{name}`: a tolerance must be a positive finite number (µm or µrad)"),
                ));
            }
        };
        out.push(Tolerance {
            name: name.to_string(),
            limit,
            file: file.to_string(),
            at: src.line_col(k.span().start),
        })?;
    }
    Ok(out)
}

/// The tolerances of `--tolerance NAME=LIMIT` arguments.
///
/// # Errors
/// [`ToleranceError`] (file `--tolerance`, line 1, the column of the fault in the argument).
pub fn parse_args(args: &[String]) -> Result<Tolerances, ToleranceError> {
    let mut out = Tolerances::default();
    for arg in args {
        let err = |column: usize, message: String| ToleranceError {
            file: "--tolerance".into(),
            line: 1,
            column,
            message,
        };
        let Some((name, value)) = arg.split_once('=') else {
            return Err(err(1, format!("`{arg}`: write NAME=LIMIT (XOC=5)")));
        };
        let name = name.trim();
        if !name_ok(name) {
            return Err(err(
                1,
                format!("`{name}` is not an error name (XOC, ECC@harmonic:2:cos, …)"),
            ));
        }
        let column = arg.find('=').map_or(1, |i| arg[..i].chars().count() + 2);
        let limit = match value.trim().parse::<f64>() {
            Ok(x) if x.is_finite() && x > 0.0 => x,
            _ => {
                return Err(err(
                    column,
                    format!("`{name}`: the limit `{value}` is not a positive number (µm or µrad)"),
                ));
            }
        };
        out.push(Tolerance {
            name: name.to_string(),
            limit,
            file: "--tolerance".into(),
            at: (1, 1),
        })?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_reads_and_names_match_as_rtest_reads_them() {
        let t = parse_file(
            "tol.toml",
            "# M123\nmachine_id = \"M123\"\nXOC = 5\nyoc = 2.5\n\"ECC@harmonic:2:cos\" = 8\n",
        )
        .unwrap();
        assert_eq!(t.limit("XOC"), Some(5.0));
        assert_eq!(t.limit("x0c"), Some(5.0));
        assert_eq!(t.limit("YOC"), Some(2.5));
        assert_eq!(t.limit("ECC@harmonic:2:cos"), Some(8.0));
        assert_eq!(t.limit("AOC"), None);
        let known: Vec<String> = ["XOC", "YOC", "ECC@harmonic:2:cos"]
            .map(String::from)
            .to_vec();
        assert!(t.check("M123", &known).is_ok());
        let e = t.check("M124", &known).unwrap_err();
        assert_eq!((e.line, e.column), (2, 1));
        assert!(e.message.contains("for machine `M123`, not `M124`"), "{e}");
        let e = t.check("M123", &known[..1]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "tol.toml:4:1: `yoc`: no check of machine `M123` identified it (its parameters: XOC)"
        );
    }

    #[test]
    fn bad_files_are_located() {
        for (text, line, column, needle) in [
            ("XOC = 5\nYOC = -1\n", 2, 7, "positive"),
            ("XOC = 5\nYOC = 0\n", 2, 7, "positive"),
            ("XOC = 5\nYOC = nan\n", 2, 7, "positive"),
            ("XOC = 5\nYOC = \"5\"\n", 2, 7, "must be a number"),
            ("XOC = 5\n[YOC]\nx = 1\n", 2, 1, "not a table"),
            (
                "XOC = 5\nx0c = 4\n",
                2,
                1,
                "given twice (first at t.toml:1)",
            ),
            ("XOC = 5\nmachine_id = 3\n", 2, 14, "must be a string"),
            ("XOC = 5\n\"X OC\" = 3\n", 2, 1, "not an error name"),
            ("XOC = 5\nYOC = \n", 2, 7, ""),
        ] {
            let e = parse_file("t.toml", text).unwrap_err();
            assert_eq!(
                (e.file.as_str(), e.line, e.column),
                ("t.toml", line, column),
                "{text:?}: {e}"
            );
            assert!(e.message.contains(needle), "{text:?}: {e}");
        }
    }

    #[test]
    fn command_line_tolerances() {
        let t = parse_args(&["XOC=5".into(), "AOC = 20".into()]).unwrap();
        assert_eq!(t.limit("XOC"), Some(5.0));
        assert_eq!(t.limit("AOC"), Some(20.0));
        for (arg, needle) in [
            ("XOC", "NAME=LIMIT"),
            ("XOC=-2", "not a positive number"),
            ("XOC=abc", "not a positive number"),
            ("=5", "not an error name"),
        ] {
            let e = parse_args(&[arg.to_string()]).unwrap_err();
            assert!(e.message.contains(needle), "{arg}: {e}");
            assert_eq!(e.file, "--tolerance");
        }
        let e = parse_args(&["XOC=5".into(), "xoc=6".into()]).unwrap_err();
        assert!(e.message.contains("given twice"), "{e}");
    }
}
