//! The squareness file: the squareness errors of the linear axes from their own measurement
//! (µrad), and the reference point where the predicted error is zero.
//!
//! ```toml
//! machine = "seed-3axis"   # optional: the machine it was measured on
//! COX = 20.0               # µrad, every squareness error of the machine
//! AOZ = -15.0
//! BOZ = 20.0
//!
//! [reference]              # optional: where du = 0, mm (default: every axis at 0)
//! X = 0.0
//! Y = 0.0
//! Z = 0.0
//! ```
//!
//! The squareness errors are named and signed as in the machine's catalogue
//! (docs/conventions.md §3); names are matched without regard to case, the digit zero read as
//! the letter O. Every problem is an error naming the file, line and column.

use super::{MAX_ANGLE_RAD, VolumetricError};
use formats::located::{TomlText, in_order};
use model_spec::units::{format_scaled, parse_scaled};
use model_spec::{ErrorId, ErrorKind, Machine, canonical_name};
use std::ops::Range;
use std::path::Path;
use toml::de::DeValue;

/// The largest squareness file read, bytes.
pub const MAX_SQUARENESS_BYTES: u64 = 1 << 16;

/// The squareness errors and the reference point, in the units inside (rad, mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Squareness {
    /// Where it came from (the file name), for messages.
    pub source: String,
    /// Every squareness error of the machine (catalogue order) and its value, rad.
    pub values: Vec<(ErrorId, f64)>,
    /// The reference point, one command per axis ([`Machine::axes`] order), mm: the predicted
    /// error is zero there.
    pub reference: Vec<f64>,
}

impl Squareness {
    /// Every squareness error of `m` at `values` (rad, catalogue order of the squareness
    /// errors), the reference point at every axis 0.
    pub fn new(m: &Machine, source: &str, values: &[f64]) -> Squareness {
        let ids = squareness_errors(m);
        assert_eq!(ids.len(), values.len(), "one value per squareness error");
        Squareness {
            source: source.to_string(),
            values: ids.into_iter().zip(values.iter().copied()).collect(),
            reference: vec![0.0; m.axes.len()],
        }
    }

    /// The value of squareness error `id` (rad), 0 if it is not listed.
    pub fn value(&self, id: ErrorId) -> f64 {
        self.values
            .iter()
            .find(|(e, _)| *e == id)
            .map_or(0.0, |(_, v)| *v)
    }
}

/// The squareness errors of `m`, catalogue order.
pub fn squareness_errors(m: &Machine) -> Vec<ErrorId> {
    (0..m.catalogue.len())
        .filter(|&e| matches!(m.catalogue[e].kind, ErrorKind::Squareness { .. }))
        .collect()
}

/// Reads the squareness file `path` of machine `m`.
///
/// # Errors
/// [`VolumetricError::Text`] when the file cannot be read; see [`parse_squareness`].
pub fn read_squareness(path: &Path, m: &Machine) -> Result<Squareness, VolumetricError> {
    let text = model_spec::text::read_text(path, MAX_SQUARENESS_BYTES)?;
    parse_squareness(&path.display().to_string(), &text, m)
}

/// Parses a squareness file of machine `m`; `file` names it in messages.
///
/// # Errors
/// [`VolumetricError::Toml`] for the first problem: TOML syntax, an unknown key, a name that
/// is not a squareness error of the machine, a squareness error missing or given twice, a
/// value that is not a finite number or is beyond ±10 000 µrad, a reference outside a stroke.
pub fn parse_squareness(
    file: &str,
    text: &str,
    m: &Machine,
) -> Result<Squareness, VolumetricError> {
    let src = TomlText::new(file, text);
    let err = |span: Range<usize>, message: String| VolumetricError::from(src.at(span, message));
    let root = src.root()?;
    let root = root.get_ref();
    let ids = squareness_errors(m);
    let names: Vec<&str> = ids.iter().map(|&e| m.catalogue[e].name.as_str()).collect();
    let mut values: Vec<Option<(f64, Range<usize>)>> = vec![None; ids.len()];
    let mut reference = vec![0.0; m.axes.len()];
    let entries = in_order(root);
    for (k, v) in entries {
        let key = k.get_ref().as_ref();
        match key {
            "machine" => match v.get_ref() {
                DeValue::String(s) if s.as_ref() == m.name => {}
                DeValue::String(s) => {
                    return Err(err(
                        v.span(),
                        format!("this file was measured on machine `{s}`, not `{}`", m.name),
                    ));
                }
                other => {
                    return Err(err(
                        v.span(),
                        format!("`machine` must be a string, not {}", other.type_str()),
                    ));
                }
            },
            "reference" => {
                let DeValue::Table(t) = v.get_ref() else {
                    return Err(err(
                        v.span(),
                        format!(
                            "`reference` must be a table of axis positions (mm), not {}",
                            v.get_ref().type_str()
                        ),
                    ));
                };
                let rows = in_order(t);
                for (ak, av) in rows {
                    let a = ak.get_ref().as_ref();
                    let Some(i) = m.axis_by_name(a) else {
                        let known: Vec<&str> = m.axes.iter().map(|x| x.name.as_str()).collect();
                        return Err(err(
                            ak.span(),
                            format!(
                                "machine {} has no axis `{a}` (its axes: {})",
                                m.name,
                                known.join(" ")
                            ),
                        ));
                    };
                    let (x, text_x) = src.number(av, &format!("reference {a} (mm)"))?;
                    let [lo, hi] = m.axes[i].limits;
                    let tol = model_spec::pose::LIMIT_TOLERANCE;
                    if x < lo - tol || x > hi + tol {
                        return Err(err(
                            av.span(),
                            format!(
                                "reference {a} = {text_x} mm is outside its stroke {} .. {} mm",
                                model_spec::units::short(lo),
                                model_spec::units::short(hi)
                            ),
                        ));
                    }
                    reference[i] = x;
                }
            }
            other => {
                let canonical = canonical_name(other);
                let Some(j) = names.iter().position(|n| *n == canonical) else {
                    return Err(err(
                        k.span(),
                        format!(
                            "unknown key `{other}`: a squareness file holds the squareness errors of {} ({}, µrad), `machine` and `[reference]`",
                            m.name,
                            names.join(" ")
                        ),
                    ));
                };
                if let Some((_, first)) = &values[j] {
                    let (line, _) = src.line_col(first.start);
                    return Err(err(
                        k.span(),
                        format!("{canonical} is given twice (first on line {line})"),
                    ));
                }
                let what = format!("{canonical} (µrad)");
                let (x, text_x) = src.number(v, &what)?;
                let rad = parse_scaled(&text_x, -6).unwrap_or(x * 1e-6);
                if rad.abs() > MAX_ANGLE_RAD {
                    return Err(err(
                        v.span(),
                        format!(
                            "{canonical} = {text_x} µrad is beyond ±10000 µrad: not a squareness error of a machine tool"
                        ),
                    ));
                }
                values[j] = Some((rad, k.span()));
            }
        }
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&values)
        .filter(|(_, v)| v.is_none())
        .map(|(n, _)| *n)
        .collect();
    if !missing.is_empty() {
        return Err(VolumetricError::Toml {
            file: file.to_string(),
            line: 1,
            column: 1,
            message: format!(
                "the squareness file misses {}: give every squareness error of {} in µrad ({})",
                missing.join(", "),
                m.name,
                names.join(" ")
            ),
        });
    }
    Ok(Squareness {
        source: file.to_string(),
        values: ids
            .into_iter()
            .zip(values)
            .map(|(e, v)| (e, v.map_or(0.0, |(x, _)| x)))
            .collect(),
        reference,
    })
}

/// The TOML text of `sq` (machine `m`): `comments` as `# ` lines, `machine`, the squareness
/// errors (µrad) and the reference point (mm), every number the shortest decimal that reads
/// back to the same value.
pub fn format_squareness(m: &Machine, sq: &Squareness, comments: &[String]) -> String {
    let mut out = formats::csv::comment_lines(comments);
    out += &format!("machine = \"{}\"\n", m.name);
    for &(e, v) in &sq.values {
        out += &format!("{} = {}\n", m.catalogue[e].name, format_scaled(v, 6));
    }
    out += "\n[reference]\n";
    for a in super::laser::column_axes(m) {
        out += &format!(
            "{} = {}\n",
            m.axes[a].name,
            format_scaled(sq.reference[a], 0)
        );
    }
    out
}
