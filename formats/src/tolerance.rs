//! The tolerance file of the R-test checks, in the manner of ISO 10791-6 (the K tests of
//! five-axis machines): per test and direction of the R-test reading, the largest allowed
//! deviation and the largest allowed range, in µm. `rtest validate --tolerance FILE` judges
//! the validated records against it (docs/tolerances.md).
//!
//! ```toml
//! # Tolerances of the checks of machine M123, µm.
//! [[test]]
//! name = "K1"                  # a record's label: the campaign's label, or the file's stem
//! direction = "x"              # x, y or z of the tool frame, or a list: ["x", "y", "z"]
//! max_um = 20                  # largest allowed |deviation| over the test
//! range_um = 30                # largest allowed max − min of the deviation over the test
//! ```
//!
//! Each entry needs `name`, `direction` and at least one of `max_um`, `range_um` (positive
//! finite numbers). An unknown key, a value of the wrong type, a tolerance that is not
//! positive, an unknown direction and a test and direction given twice are errors naming the
//! file, the line, the column and the field; a name the validated records do not have is
//! refused by [`TestTolerances::check_names`], at the name.
//!
//! ```
//! use formats::tolerance::{Direction, parse_file};
//! let t = parse_file("tol.toml", "[[test]]\nname = \"K1\"\ndirection = [\"x\", \"y\"]\nmax_um = 20\n").unwrap();
//! assert_eq!(t.entries.len(), 2);
//! assert_eq!(t.entries[1].direction, Direction::Y);
//! let e = parse_file("tol.toml", "[[test]]\nname = \"K1\"\ndirection = \"x\"\nmax_um = -2\n").unwrap_err();
//! assert_eq!(e.to_string(), "tol.toml:4:10: `test[0].max_um`: a tolerance must be a positive number (µm), not -2");
//! ```

use crate::located::{Located, TomlText, Val, in_order};
use std::ops::Range;
use toml::de::DeValue;

/// The largest tolerance file read, bytes.
pub const MAX_TOLERANCE_BYTES: u64 = 1 << 20;

/// The keys of a `[[test]]` entry.
pub const TEST_KEYS: &str = "name, direction, max_um, range_um";

/// A direction of the R-test reading, of the tool frame (as `rtest validate` reports it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// x of the tool frame.
    X,
    /// y of the tool frame.
    Y,
    /// z of the tool frame (along the tool).
    Z,
}

impl Direction {
    /// The three, in order.
    pub const ALL: [Direction; 3] = [Direction::X, Direction::Y, Direction::Z];

    /// 0, 1 or 2: the index of the direction in a reading `[dx, dy, dz]`.
    pub fn index(self) -> usize {
        match self {
            Direction::X => 0,
            Direction::Y => 1,
            Direction::Z => 2,
        }
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }

    /// The direction named `name` (`x`, `y`, `z`, any case).
    pub fn parse(name: &str) -> Option<Direction> {
        match name.to_ascii_lowercase().as_str() {
            "x" => Some(Direction::X),
            "y" => Some(Direction::Y),
            "z" => Some(Direction::Z),
            _ => None,
        }
    }
}

/// The tolerance of one test in one direction, and where it was given.
#[derive(Clone, Debug, PartialEq)]
pub struct TestTolerance {
    /// The test's name as written (a record's label).
    pub name: String,
    /// The direction of the reading.
    pub direction: Direction,
    /// The largest allowed |deviation| over the test, µm.
    pub max_um: Option<f64>,
    /// The largest allowed range (max − min) of the deviation over the test, µm.
    pub range_um: Option<f64>,
    /// 1-based line and column of the entry's `name` value.
    pub at: (usize, usize),
    /// The index of its `[[test]]` table in the file (0-based).
    pub index: usize,
}

/// The tolerances of one file, in file order (an entry of several directions is one per
/// direction).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TestTolerances {
    /// The file, as named in messages.
    pub file: String,
    /// The tolerances.
    pub entries: Vec<TestTolerance>,
}

impl TestTolerances {
    /// The index among `labels` (the validated records' labels) of the record `t` names:
    /// the label written exactly, else the one label equal to it in any case.
    pub fn record_of(t: &TestTolerance, labels: &[String]) -> Option<usize> {
        labels.iter().position(|l| *l == t.name).or_else(|| {
            let mut same = labels
                .iter()
                .enumerate()
                .filter(|(_, l)| l.eq_ignore_ascii_case(&t.name));
            match (same.next(), same.next()) {
                (Some((i, _)), None) => Some(i),
                _ => None,
            }
        })
    }

    /// The index among `labels` of the record `t` names ([`TestTolerances::record_of`]).
    ///
    /// # Errors
    /// [`Located`] at the entry's `name` when no record is called so, listing the labels.
    pub fn record_index(&self, t: &TestTolerance, labels: &[String]) -> Result<usize, Located> {
        Self::record_of(t, labels).ok_or_else(|| Located {
            file: self.file.clone(),
            line: t.at.0,
            column: t.at.1,
            message: format!(
                "`test[{}].name`: no validated record is called `{}` (the records: {}; a record is named by its campaign label or its file's stem)",
                t.index,
                t.name,
                labels.join(", ")
            ),
        })
    }

    /// Refuses a test the records do not have (`labels`: the validated records' labels).
    ///
    /// # Errors
    /// [`Located`] at the first such entry's `name`, listing the records' labels.
    pub fn check_names(&self, labels: &[String]) -> Result<(), Located> {
        for t in &self.entries {
            self.record_index(t, labels)?;
        }
        Ok(())
    }
}

/// The tolerances of the TOML `text` of the file `file`.
///
/// # Errors
/// [`Located`] naming the file, the line, the column and the field.
pub fn parse_file(file: &str, text: &str) -> Result<TestTolerances, Located> {
    let src = TomlText::new(file, text);
    let root = src.root()?;
    let mut tests: Option<&Val<'_>> = None;
    for (k, v) in in_order(root.get_ref()) {
        match k.get_ref().as_ref() {
            "test" => tests = Some(v),
            other => {
                return Err(src.at(
                    k.span(),
                    format!("unknown key `{other}` (a tolerance file holds [[test]] tables only)"),
                ));
            }
        }
    }
    let Some(tests) = tests else {
        return Err(src.at(
            0..0,
            "no tolerance: the file lists [[test]] tables, each with `name`, `direction` and `max_um` or `range_um`",
        ));
    };
    let DeValue::Array(items) = tests.get_ref() else {
        return Err(src.at(
            tests.span(),
            "`test` must be an array of tables, written [[test]]",
        ));
    };
    let mut out = TestTolerances {
        file: file.to_string(),
        entries: Vec::new(),
    };
    for (i, item) in items.iter().enumerate() {
        let DeValue::Table(t) = item.get_ref() else {
            return Err(src.at(
                item.span(),
                format!(
                    "`test[{i}]` must be a table, written [[test]], not {}",
                    item.get_ref().type_str()
                ),
            ));
        };
        let field = |f: &str| format!("`test[{i}].{f}`");
        let mut name: Option<(String, Range<usize>)> = None;
        let mut directions: Vec<(Direction, Range<usize>)> = Vec::new();
        let mut direction_given = false;
        let (mut max_um, mut range_um) = (None, None);
        for (k, v) in in_order(t) {
            match k.get_ref().as_ref() {
                "name" => {
                    let s = src.string(v, &field("name"))?;
                    if s.trim().is_empty() {
                        return Err(src.at(
                            v.span(),
                            format!("{}: a test's name cannot be empty", field("name")),
                        ));
                    }
                    name = Some((s, v.span()));
                }
                "direction" => {
                    direction_given = true;
                    directions = self::directions(&src, v, &field("direction"))?;
                }
                key @ ("max_um" | "range_um") => {
                    let (x, text) = src.number(v, &field(key))?;
                    if x <= 0.0 {
                        return Err(src.at(
                            v.span(),
                            format!(
                                "{}: a tolerance must be a positive number (µm), not {text}",
                                field(key)
                            ),
                        ));
                    }
                    if key == "max_um" {
                        max_um = Some(x);
                    } else {
                        range_um = Some(x);
                    }
                }
                other => {
                    return Err(src.at(
                        k.span(),
                        format!("unknown key `{other}` in `test[{i}]` (expected {TEST_KEYS})"),
                    ));
                }
            }
        }
        let Some((name, name_span)) = name else {
            return Err(src.at(item.span(), format!("{}: missing", field("name"))));
        };
        if !direction_given {
            return Err(src.at(
                item.span(),
                format!("{}: missing (x, y or z)", field("direction")),
            ));
        }
        if max_um.is_none() && range_um.is_none() {
            return Err(src.at(
                item.span(),
                format!("`test[{i}]` ({name}): give `max_um`, `range_um` or both"),
            ));
        }
        for (direction, span) in directions {
            if let Some(before) = out
                .entries
                .iter()
                .find(|e| e.direction == direction && e.name.eq_ignore_ascii_case(&name))
            {
                return Err(src.at(
                    span,
                    format!(
                        "{}: test `{name}` in direction {} is given twice (first at {file}:{})",
                        field("direction"),
                        direction.name(),
                        before.at.0
                    ),
                ));
            }
            out.entries.push(TestTolerance {
                name: name.clone(),
                direction,
                max_um,
                range_um,
                at: src.line_col(name_span.start),
                index: i,
            });
        }
    }
    Ok(out)
}

/// The direction or directions of `v` (a string or an array of strings), each with its place.
fn directions(
    src: &TomlText<'_>,
    v: &Val<'_>,
    what: &str,
) -> Result<Vec<(Direction, Range<usize>)>, Located> {
    let one = |v: &Val<'_>| -> Result<(Direction, Range<usize>), Located> {
        let s = src.string(v, what)?;
        Direction::parse(&s).map(|d| (d, v.span())).ok_or_else(|| {
            src.at(
                v.span(),
                format!(
                    "{what}: `{s}` is not a direction of the R-test reading: x, y or z of the tool frame (the directions rtest validate reports)"
                ),
            )
        })
    };
    match v.get_ref() {
        DeValue::Array(items) => {
            if items.is_empty() {
                return Err(src.at(v.span(), format!("{what}: an empty list")));
            }
            items.iter().map(one).collect()
        }
        _ => Ok(vec![one(v)?]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_reads_with_one_entry_per_direction() {
        let t = parse_file(
            "tol.toml",
            "# checks\n[[test]]\nname = \"K1\"\ndirection = \"x\"\nmax_um = 20\nrange_um = 30.5\n\n[[test]]\nname = \"turn-B\"\ndirection = [\"Y\", \"z\"]\nrange_um = 12\n",
        )
        .unwrap();
        assert_eq!(t.entries.len(), 3);
        let k1 = &t.entries[0];
        assert_eq!(
            (k1.name.as_str(), k1.direction, k1.max_um, k1.range_um),
            ("K1", Direction::X, Some(20.0), Some(30.5))
        );
        assert_eq!((k1.at, k1.index), ((3, 8), 0));
        assert_eq!(t.entries[1].direction, Direction::Y);
        assert_eq!(t.entries[2].direction, Direction::Z);
        assert_eq!(
            (t.entries[2].max_um, t.entries[2].range_um),
            (None, Some(12.0))
        );
        // Names match the records' labels exactly, else in any case when only one does.
        let labels: Vec<String> = ["k1", "turn-B"].map(String::from).to_vec();
        assert!(t.check_names(&labels).is_ok());
        assert_eq!(TestTolerances::record_of(k1, &labels), Some(0));
        let two: Vec<String> = ["k1", "K1x", "turn-b", "TURN-B"].map(String::from).to_vec();
        let e = t.check_names(&two).unwrap_err();
        assert_eq!((e.line, e.column), (9, 8));
        assert!(
            e.message.starts_with(
                "`test[1].name`: no validated record is called `turn-B` (the records: k1, K1x"
            ),
            "{e}"
        );
    }

    #[test]
    fn bad_files_are_refused_at_their_line_and_field() {
        let head = "[[test]]\nname = \"K1\"\ndirection = \"x\"\n";
        for (text, line, column, needle) in [
            (
                format!("{head}max_um = -1\n"),
                4,
                10,
                "`test[0].max_um`: a tolerance must be a positive number (µm), not -1",
            ),
            (format!("{head}max_um = 0\n"), 4, 10, "not 0"),
            (
                format!("{head}range_um = \"5\"\n"),
                4,
                12,
                "`test[0].range_um` must be a number, not string",
            ),
            (
                format!("{head}range_um = nan\n"),
                4,
                12,
                "must be a finite number",
            ),
            (
                format!("{head}max_um = 5\nmax_mm = 1\n"),
                5,
                1,
                "unknown key `max_mm` in `test[0]` (expected name, direction, max_um, range_um)",
            ),
            (
                format!(
                    "{head}max_um = 5\n[[test]]\nname = \"k1\"\ndirection = [\"y\", \"X\"]\nmax_um = 3\n"
                ),
                7,
                19,
                "`test[1].direction`: test `k1` in direction x is given twice (first at t.toml:2)",
            ),
            (
                "[[test]]\nname = \"K1\"\ndirection = \"radial\"\nmax_um = 5\n".into(),
                3,
                13,
                "`radial` is not a direction",
            ),
            (
                "[[test]]\nname = \"K1\"\ndirection = 1\nmax_um = 5\n".into(),
                3,
                13,
                "`test[0].direction` must be a string, not integer",
            ),
            (
                "[[test]]\nname = \"K1\"\nmax_um = 5\n".into(),
                1,
                1,
                "`test[0].direction`: missing",
            ),
            (
                "[[test]]\ndirection = \"x\"\nmax_um = 5\n".into(),
                1,
                1,
                "`test[0].name`: missing",
            ),
            (
                "[[test]]\nname = \" \"\ndirection = \"x\"\nmax_um = 5\n".into(),
                2,
                8,
                "cannot be empty",
            ),
            (head.to_string(), 1, 1, "give `max_um`, `range_um` or both"),
            (
                format!("tolerance = 5\n{head}"),
                1,
                1,
                "unknown key `tolerance`",
            ),
            (
                "test = 5\n".into(),
                1,
                8,
                "`test` must be an array of tables",
            ),
            ("test = [1]\n".into(), 1, 9, "`test[0]` must be a table"),
            ("# nothing\n".into(), 1, 1, "no tolerance"),
            (format!("{head}max_um = \n"), 4, 10, ""),
        ] {
            let e = parse_file("t.toml", &text).unwrap_err();
            assert_eq!(
                (e.file.as_str(), e.line, e.column),
                ("t.toml", line, column),
                "{text:?}: {e}"
            );
            assert!(e.message.contains(needle), "{text:?}: {e}");
        }
    }

    proptest::proptest! {
        /// A file damaged anywhere (a byte replaced, removed or doubled) is read or refused at a
        /// place inside the text, never with a panic.
        #[test]
        fn damaged_files_are_read_or_refused_at_a_place(at in 0usize..200, what in 0u8..3, byte in 0u8..128) {
            let good = "# µm\n[[test]]\nname = \"K1\"\ndirection = [\"x\", \"z\"]\nmax_um = 20\nrange_um = 30.5\n\n[[test]]\nname = \"turn-B\"\ndirection = \"y\"\nrange_um = 12\n";
            let mut bytes = good.as_bytes().to_vec();
            let at = at % bytes.len();
            match what {
                0 => bytes[at] = byte,
                1 => {
                    bytes.remove(at);
                }
                _ => bytes.insert(at, bytes[at]),
            }
            let text = String::from_utf8_lossy(&bytes).into_owned();
            match parse_file("t.toml", &text) {
                Ok(t) => {
                    for e in &t.entries {
                        proptest::prop_assert!(e.max_um.is_none_or(|x| x > 0.0 && x.is_finite()));
                        proptest::prop_assert!(e.range_um.is_none_or(|x| x > 0.0 && x.is_finite()));
                        proptest::prop_assert!(e.max_um.is_some() || e.range_um.is_some());
                    }
                }
                Err(e) => {
                    proptest::prop_assert_eq!(e.file.as_str(), "t.toml");
                    let lines = text.lines().count().max(1) + 1;
                    proptest::prop_assert!(e.line >= 1 && e.line <= lines, "{}", e);
                    proptest::prop_assert!(!e.message.is_empty());
                }
            }
        }
    }
}
