//! The corrected kinematic description: the machine's TOML text with the identified location
//! errors of its rotary axes that are translations (`XOC YOC`, `YOA ZOA`, `XOB ZOB`, …) folded
//! into the kinematic offsets, as a controller's kinematics table is updated after a
//! calibration.
//!
//! A rotary axis is composed as `Trans(offset) · Trans(location translations) · …`
//! ([`model_spec::kinematics::chain_steps`]), so a location translation adds exactly to the
//! axis's offset: the corrected machine with these errors at zero is the original machine with
//! them at their values, at every pose and to every order. An inclined axis's location errors
//! act along its own axes (`Trans(offset) · Frame · Trans(location) · …`): `YOB` along `y′`
//! adds `YOB·y′` to the offset, which moves every machine coordinate that `y′` has a share in.
//!
//! Where the offset coordinate is written:
//! - **a number**: the number becomes `number + value`;
//! - **a symbol used in no other offset coordinate** of the machine: its default becomes
//!   `default + value` (the symbol stays a symbol in the gain formulas);
//! - **a symbol used elsewhere too**: the coordinate becomes the number `default + value`, and
//!   the symbol keeps its default for its other uses (changing it would move them too; a new
//!   symbol would change the machine's parameter list and its generated code);
//! - **no `offset`** on the axis entry: an `offset = [x, y, z]` is added after its `axis` line.
//!
//! An identified kinematic symbol (a length identified as a term under its own name, `Zt`)
//! changes its default by the identified change, before the location errors are added. A
//! symbol of the workpiece side (where the ball sits: a set-up, not the machine) and a change
//! the data did not determine are not folded, and are listed.
//!
//! Everything else of the text stays byte for byte as it was, comments included; a comment
//! block at the end lists what was folded. The machine keeps its `name`, so that generated
//! code, reports and files keep lining up with it; its fingerprint changes (the offsets are
//! machine-side), so values identified on one description are never applied to the other.
//! The result is parsed back and must be the original machine with exactly these changes.
//!
//! Not folded, and listed with their values ([`NotFolded`]): the angular location errors
//! (`AOC BOC`, …) and the squareness errors, which would change the direction of an axis line
//! (not folded here), and the component errors, which move with their axis.
//!
//! Numbers are written as the shortest decimal that reads back to the same `f64` (mm).

mod spans;

use super::values::{CompensationError, MachineErrors, ValueSource};
use model_spec::catalogue::Motion;
use model_spec::units::format_scaled;
use model_spec::{AxisId, Dir, ErrorId, ErrorKind, Link, Machine, Value, parse_machine};
use spans::OffsetPlace;
use std::ops::Range;

/// A location error folded into a kinematic offset.
#[derive(Clone, Debug, PartialEq)]
pub struct Folded {
    /// The error.
    pub error: ErrorId,
    /// Its name (`XOC`).
    pub name: String,
    /// What it adds to the coordinate, mm: its value, times the coordinate's share of the
    /// error's direction where the axis is inclined.
    pub value_mm: f64,
    /// The rotary axis whose offset takes it.
    pub axis: String,
    /// The coordinate of the offset it moves: the error's direction, or for an inclined axis
    /// each machine coordinate of its own direction (`x′`, `y′`, `z′`) that is not zero, one
    /// entry each.
    pub coordinate: Dir,
    /// The symbol whose default changed; `None` where a number changed or was written.
    pub symbol: Option<String>,
    /// The coordinate before, mm (the symbol's default, or the number).
    pub before_mm: f64,
    /// The coordinate after, mm.
    pub after_mm: f64,
    /// Where it went, for people (`offset x of axis C`, `symbol Ya (offset y of axis A)`).
    pub place: String,
}

/// An identified kinematic symbol folded into its default.
#[derive(Clone, Debug, PartialEq)]
pub struct FoldedSymbol {
    /// The symbol's name (`Zt`).
    pub name: String,
    /// The identified change, mm.
    pub change_mm: f64,
    /// Its default before, mm.
    pub before_mm: f64,
    /// Its default after, mm.
    pub after_mm: f64,
}

/// A compensated term that is not folded into the description, with why.
#[derive(Clone, Debug, PartialEq)]
pub struct NotFolded {
    /// The term.
    pub term: model_spec::terms::Term,
    /// Its spelling (`AOC`, `EXX@poly:1`).
    pub spelling: String,
    /// Its coefficients, mm or rad (two for `harmonic:K` and `period:P`).
    pub values: Vec<f64>,
    /// Why it cannot be held by the description.
    pub reason: String,
}

/// The corrected description.
#[derive(Clone, Debug, PartialEq)]
pub struct CorrectedDescription {
    /// The TOML text of the corrected machine.
    pub toml: String,
    /// The errors folded into its offsets.
    pub folded: Vec<Folded>,
    /// The identified kinematic symbols folded into their defaults.
    pub symbols: Vec<FoldedSymbol>,
    /// The compensated terms it cannot hold.
    pub not_folded: Vec<NotFolded>,
}

/// Why a compensated error cannot be held as a kinematic offset; `None` for a constant
/// location translation of a rotary axis.
fn not_foldable(m: &Machine, e: ErrorId, constant: bool) -> Option<&'static str> {
    match m.catalogue[e].kind {
        ErrorKind::Location {
            motion: Motion::Translation(_),
            ..
        } if constant => None,
        ErrorKind::Location {
            motion: Motion::Rotation(_),
            ..
        } => Some(
            "an angular location error: it turns the axis line, which an offset cannot hold (directions are not corrected here)",
        ),
        ErrorKind::Squareness { .. } => Some(
            "a squareness error: it turns an axis, which an offset cannot hold (directions are not corrected here)",
        ),
        ErrorKind::Component { .. } => Some(
            "a component error: it moves with its axis, so it belongs in the axis's compensation, not in the kinematic offsets",
        ),
        _ => Some("not a constant translation of a rotary axis's line"),
    }
}

/// How many offset coordinates of `m` (axes, links and ends of both chains) use each symbol.
fn symbol_uses(m: &Machine) -> Vec<usize> {
    let mut uses = vec![0; m.symbols.len()];
    let mut count = |o: &[Value; 3]| {
        for v in o {
            if let Value::Symbol(s) = v {
                uses[*s] += 1;
            }
        }
    };
    for a in &m.axes {
        count(&a.offset);
    }
    for chain in [&m.work, &m.tool] {
        for l in &chain.links {
            if let Link::Fixed { offset, .. } = l {
                count(offset);
            }
        }
        count(&chain.end_offset);
    }
    uses
}

/// `x` as the number written into the description: the shortest decimal (mm), no `-0`.
fn number(x: f64) -> String {
    format_scaled(x + 0.0, 0)
}

/// The machine `m` described by `source` (its TOML text, [`model_spec::write::source_text`])
/// with the constant location translations of `errors` folded into the kinematic offsets;
/// see the module documentation.
///
/// # Errors
/// [`CompensationError::OtherMachine`] when `errors` were identified on another description;
/// [`CompensationError::Description`] when `source` is not the text of `m`, or the corrected
/// text does not read back as `m` with exactly the folded changes (an offset beyond the
/// limits of a description, say); [`CompensationError::NonFinite`] for a folded coordinate
/// that is not finite.
pub fn corrected_description(
    m: &Machine,
    source: &str,
    errors: &MachineErrors,
) -> Result<CorrectedDescription, CompensationError> {
    errors.check_machine(m)?;
    let file = format!("<{} description>", m.name);
    let bad = |why: String| CompensationError::Description {
        file: file.clone(),
        why,
    };
    let (bom, text) = match source.strip_prefix('\u{feff}') {
        Some(rest) => ("\u{feff}", rest),
        None => ("", source),
    };
    match parse_machine(&file, text) {
        Ok(parsed) if parsed == *m => {}
        Ok(_) => {
            return Err(bad(format!(
                "the text given is not the description of machine `{}`",
                m.name
            )));
        }
        Err(e) => return Err(bad(format!("the text given does not read: {e}"))),
    }
    let spans = spans::read(text).map_err(bad)?;
    let uses = symbol_uses(m);

    let mut expected = m.clone();
    let mut folded = Vec::new();
    let mut not_folded = Vec::new();
    // Per axis, the coordinates whose written value changes: (axis, coordinate index).
    let mut changed: Vec<(AxisId, usize)> = Vec::new();
    let symbols = fold_symbols(m, errors, &mut expected, &mut not_folded)?;
    for t in errors.terms() {
        let model_spec::terms::Effect::Error(e) = t.term.effect else {
            continue;
        };
        let constant = t.term.basis == model_spec::basis::Basis::Const;
        if let Some(reason) = not_foldable(m, e, constant) {
            not_folded.push(NotFolded {
                term: t.term,
                spelling: t.spelling.clone(),
                values: t.coefficients.clone(),
                reason: reason.to_string(),
            });
            continue;
        }
        let ErrorKind::Location {
            axis,
            motion: Motion::Translation(d),
        } = m.catalogue[e].kind
        else {
            continue;
        };
        let value = t.coefficients[0];
        if value == 0.0 {
            // Fixed to 0 by the constraint: nothing moves.
            continue;
        }
        let name = &m.axes[axis].name;
        // The error acts along the axis's own direction `d`: for an inclined axis, its own
        // frame's axis in machine coordinates, so that one error can move two or three
        // coordinates of the offset (the nutating B's `YOB` along y′ moves y and z).
        let along = m.axes[axis].direction.frame()[d.index()];
        for (k, &share) in along.iter().enumerate() {
            let part = value * share;
            if part == 0.0 {
                continue;
            }
            let c = Dir::ALL[k];
            let (symbol, before, place) = match expected.axes[axis].offset[k] {
                Value::Number(x) => (None, x, format!("offset {c} of axis {name}")),
                Value::Symbol(s) if uses[s] == 1 => {
                    let sym = &expected.symbols[s].name;
                    (
                        Some(s),
                        expected.symbols[s].default,
                        format!("symbol {sym} (offset {c} of axis {name})"),
                    )
                }
                Value::Symbol(s) => (
                    None,
                    expected.symbols[s].default,
                    format!(
                        "offset {c} of axis {name}, which was the shared symbol {} and is now a number",
                        expected.symbols[s].name
                    ),
                ),
            };
            // On an inclined axis, `value_mm` is one coordinate's part of the error: say so.
            let place = if m.axes[axis].direction.inclined.is_some() {
                format!("{place}, the {c} part of {}·{d}′", m.catalogue[e].name)
            } else {
                place
            };
            let after = before + part;
            if !after.is_finite() {
                return Err(CompensationError::NonFinite {
                    file: errors.file().to_string(),
                    what: format!("the corrected {place}"),
                    value: after,
                });
            }
            match symbol {
                Some(s) => expected.symbols[s].default = after,
                None => {
                    expected.axes[axis].offset[k] = Value::Number(after);
                    changed.push((axis, k));
                }
            }
            folded.push(Folded {
                error: e,
                name: m.catalogue[e].name.clone(),
                value_mm: part,
                axis: name.clone(),
                coordinate: c,
                symbol: symbol.map(|s| m.symbols[s].name.clone()),
                before_mm: before,
                after_mm: after,
                place,
            });
        }
    }

    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    for (s, sym) in expected.symbols.iter().enumerate() {
        if sym.default.to_bits() != m.symbols[s].default.to_bits() {
            let span = spans
                .symbols
                .get(&sym.name)
                .ok_or_else(|| bad(format!("symbol `{}` is not found in the text", sym.name)))?;
            edits.push((span.clone(), number(sym.default)));
        }
    }
    changed.sort_unstable();
    changed.dedup();
    let mut inserted: Vec<AxisId> = Vec::new();
    for &(axis, k) in &changed {
        let a = &expected.axes[axis];
        let Value::Number(x) = a.offset[k] else {
            continue;
        };
        match spans.offsets.get(&a.name) {
            Some(OffsetPlace::Written(items)) => edits.push((items[k].clone(), number(x))),
            Some(OffsetPlace::Missing { at, inline }) => {
                if inserted.contains(&axis) {
                    continue;
                }
                inserted.push(axis);
                let coords: Vec<String> = a
                    .offset
                    .iter()
                    .map(|v| match v {
                        Value::Number(x) => number(*x),
                        Value::Symbol(s) => format!("\"{}\"", m.symbols[*s].name),
                    })
                    .collect();
                let list = format!("offset = [{}]", coords.join(", "));
                let with = if *inline {
                    format!(", {list}")
                } else if *at == text.len() && !text.ends_with('\n') {
                    format!("\n{list}\n")
                } else {
                    format!("{list}\n")
                };
                edits.push((*at..*at, with));
            }
            None => {
                return Err(bad(format!("axis {} is not found in the text", a.name)));
            }
        }
    }
    let mut toml = spans::apply(text, edits);
    if !folded.is_empty() || !symbols.is_empty() {
        toml.push_str(&comment_block(errors.file(), &folded, &symbols, m));
    }

    let back_file = format!("<{} corrected>", m.name);
    let back = parse_machine(&back_file, &toml)
        .map_err(|e| bad(format!("the corrected description does not read back: {e}")))?;
    if back != expected {
        return Err(bad(format!(
            "the corrected description does not read back as machine `{}` with the folded offsets",
            m.name
        )));
    }
    Ok(CorrectedDescription {
        toml: format!("{bom}{toml}"),
        folded,
        symbols,
        not_folded,
    })
}

/// Folds the identified changes of the machine's kinematic symbols into their defaults in
/// `expected`; a symbol of the workpiece (where the ball sits: a set-up, not the machine) and
/// a change the data did not determine are listed in `not_folded` instead.
fn fold_symbols(
    m: &Machine,
    errors: &MachineErrors,
    expected: &mut Machine,
    not_folded: &mut Vec<NotFolded>,
) -> Result<Vec<FoldedSymbol>, CompensationError> {
    let workpiece = m.workpiece_symbols();
    let mut folded = Vec::new();
    for k in errors.kinematic_changes() {
        let not = |reason: &str| NotFolded {
            term: k.term,
            spelling: k.spelling.clone(),
            values: k.change_mm.into_iter().collect(),
            reason: reason.to_string(),
        };
        if workpiece.contains(&k.symbol) {
            not_folded.push(not(
                "a length of the workpiece side (where the ball sits in this set-up), not of the machine",
            ));
            continue;
        }
        let change = match (k.change_mm, k.source) {
            (Some(c), ValueSource::Measured | ValueSource::FixedToZero) => c,
            _ => {
                not_folded.push(not(
                    "the data did not determine it (a constraint's minimum-norm choice is no length of the machine)",
                ));
                continue;
            }
        };
        if change == 0.0 {
            continue;
        }
        let sym = &mut expected.symbols[k.symbol];
        let (before, after) = (sym.default, sym.default + change);
        if !after.is_finite() {
            return Err(CompensationError::NonFinite {
                file: errors.file().to_string(),
                what: format!("the corrected default of symbol {}", sym.name),
                value: after,
            });
        }
        sym.default = after;
        folded.push(FoldedSymbol {
            name: sym.name.clone(),
            change_mm: change,
            before_mm: before,
            after_mm: after,
        });
    }
    Ok(folded)
}

/// The comment appended to a corrected description: what was folded, from which file.
fn comment_block(file: &str, folded: &[Folded], symbols: &[FoldedSymbol], m: &Machine) -> String {
    let clean: String = file
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let mut out = format!(
        "\n# Kinematic offsets corrected by rtest with the values identified in\n# {clean} (machine {}); the rest of this file is as it was:\n",
        m.name
    );
    for f in folded {
        out.push_str(&format!(
            "#   {} = {} µm folded into the {}: {} → {} mm\n",
            f.name,
            format_scaled(f.value_mm + 0.0, 3),
            f.place,
            number(f.before_mm),
            number(f.after_mm)
        ));
    }
    for f in symbols {
        out.push_str(&format!(
            "#   {} changed by {} µm as identified: {} → {} mm\n",
            f.name,
            format_scaled(f.change_mm + 0.0, 3),
            number(f.before_mm),
            number(f.after_mm)
        ));
    }
    out
}
