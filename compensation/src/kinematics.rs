//! The corrected kinematic description: the machine's TOML text with the identified location
//! errors of its rotary axes folded in, as a controller's kinematics table is updated after a
//! calibration: the translations (`XOC YOC`, `YOA ZOA`, `XOB ZOB`, …) into the kinematic
//! offsets, the angular ones (`AOC BOC`, …) into the axis directions where the description can
//! hold them.
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
//! The angular location errors of a rotary axis along +z or inclined already, on the work
//! side, whose carried axes are such axes too, turn its direction (`direction = [x, y, z]`, a
//! unit vector) and what it carries (the directions and offsets of the axes it carries; the
//! ball's place is a set-up): exact at command zero and for the axis motion, see
//! [`turns`] for the derivation and the one second-order difference (the component errors'
//! directions about the new axis). Not folded, with the reason: an axis along x or y (inclined,
//! its errors would be renamed in its own frame, which breaks the models written for it), along
//! -z (its own frame would flip y and z), on the tool side (the end it carries would have to
//! turn with it) or carrying such an axis, and every angular error with [`Directions::Keep`].
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
//! that cannot be, the squareness errors (they would make a linear axis inclined, whose errors
//! are named in its own frame), and the component errors, which move with their axis.
//!
//! Numbers are written as the shortest decimal that reads back to the same `f64` (mm).

mod spans;
pub mod turns;

pub use turns::{Directions, FoldedAngle, FoldedDirection, TurnedOffset};

use super::values::{CompensationError, MachineErrors, ValueSource};
use model_spec::catalogue::Motion;
use model_spec::units::format_scaled;
use model_spec::{AxisId, Dir, ErrorId, ErrorKind, Link, Machine, Side, Value, parse_machine};
use nalgebra::{Matrix3, Vector3};
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
    /// The axes whose directions it turns: by their own angular location errors, by those of
    /// the axes carrying them, or both; work chain first, each from the bed outwards.
    pub directions: Vec<FoldedDirection>,
    /// The offset coordinates of carried axes turned with the axes that carry them.
    pub turned: Vec<TurnedOffset>,
    /// The turn `Q` (rows, machine coordinates) of the work chain's last frame: the original
    /// machine has the ball at `Q·(p + w)` where the corrected one has it at `p + w`, so an
    /// identification with the corrected description finds the set-up `w′ = Q·(p + w) − p`;
    /// `None` when no folded direction turns it.
    pub set_up_turn: Option<[[f64; 3]; 3]>,
    /// `(Q − I)·p` (mm) for the ball's place `p` in that frame (the end offset and the fixed
    /// links after the last axis): what the set-up errors `XOW YOW ZOW` identified with the
    /// corrected description are larger by, to within the angle times the set-up itself.
    pub set_up_change_mm: [f64; 3],
    /// The compensated terms it cannot hold.
    pub not_folded: Vec<NotFolded>,
}

/// Why a compensated error cannot be held by the description; `None` for a constant location
/// translation of a rotary axis, and for a constant angular location error of an axis whose
/// direction can take it ([`turns::blocked`]).
fn not_foldable(m: &Machine, e: ErrorId, constant: bool, directions: Directions) -> Option<String> {
    match m.catalogue[e].kind {
        ErrorKind::Location {
            motion: Motion::Translation(_),
            ..
        } if constant => None,
        ErrorKind::Location {
            axis,
            motion: Motion::Rotation(_),
        } if constant => turns::blocked(m, axis, directions),
        ErrorKind::Squareness { .. } => Some(
            "a squareness error: it turns a linear axis, which would then be inclined, and an inclined linear axis has its errors named in its own frame (its positioning error EZ…), which would rename them".into(),
        ),
        ErrorKind::Component { .. } => Some(
            "a component error: it moves with its axis, so it belongs in the axis's compensation, not in the kinematic offsets".into(),
        ),
        _ => Some("not a constant location error of a rotary axis's line".into()),
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
/// with the constant location errors of `errors` folded into the kinematic offsets and, where
/// the description can hold them, the axis directions; see the module documentation.
///
/// # Errors
/// As [`corrected_description_with`].
pub fn corrected_description(
    m: &Machine,
    source: &str,
    errors: &MachineErrors,
) -> Result<CorrectedDescription, CompensationError> {
    corrected_description_with(m, source, errors, Directions::Fold)
}

/// [`corrected_description`], the angular location errors folded into the axis directions or
/// not (`directions`).
///
/// # Errors
/// [`CompensationError::OtherMachine`] when `errors` were identified on another description;
/// [`CompensationError::Description`] when `source` is not the text of `m`, or the corrected
/// text does not read back as `m` with exactly the folded changes (an offset beyond the
/// limits of a description, a direction within rounding of x); [`CompensationError::NonFinite`]
/// for a folded coordinate that is not finite.
pub fn corrected_description_with(
    m: &Machine,
    source: &str,
    errors: &MachineErrors,
    directions: Directions,
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
    let mut w = Writer {
        m,
        uses: symbol_uses(m),
        expected: m.clone(),
        changed: Vec::new(),
        file: errors.file(),
    };
    let mut folded = Vec::new();
    let mut not_folded = Vec::new();
    // Per axis, its angular location errors to fold into its direction.
    let mut angles: Vec<Vec<FoldedAngle>> = vec![Vec::new(); m.axes.len()];
    let symbols = fold_symbols(m, errors, &mut w.expected, &mut not_folded)?;
    for t in errors.terms() {
        let model_spec::terms::Effect::Error(e) = t.term.effect else {
            continue;
        };
        let constant = t.term.basis == model_spec::basis::Basis::Const;
        if let Some(reason) = not_foldable(m, e, constant, directions) {
            not_folded.push(NotFolded {
                term: t.term,
                spelling: t.spelling.clone(),
                values: t.coefficients.clone(),
                reason,
            });
            continue;
        }
        let ErrorKind::Location { axis, motion } = m.catalogue[e].kind else {
            continue;
        };
        let value = t.coefficients[0];
        if value == 0.0 {
            // Fixed to 0 by the constraint: nothing moves.
            continue;
        }
        let d = match motion {
            Motion::Translation(d) => d,
            Motion::Rotation(_) => {
                angles[axis].push(FoldedAngle {
                    error: e,
                    name: m.catalogue[e].name.clone(),
                    value_rad: value,
                });
                continue;
            }
        };
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
            let (symbol, before, place) = w.place(axis, k);
            // On an inclined axis, `value_mm` is one coordinate's part of the error: say so.
            let place = if m.axes[axis].direction.inclined.is_some() {
                format!("{place}, the {c} part of {}·{d}′", m.catalogue[e].name)
            } else {
                place
            };
            let after = w.set(axis, k, symbol, before + part, &place)?;
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
    let turns = fold_turns(&mut w, &angles).map_err(bad)?;

    let expected = w.expected;
    let mut changed = w.changed;
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
    for d in &turns.directions {
        let span = spans.directions.get(&d.axis).ok_or_else(|| {
            bad(format!(
                "the direction of axis {} is not found in the text",
                d.axis
            ))
        })?;
        edits.push((span.clone(), vector(d.after)));
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
    if !folded.is_empty() || !symbols.is_empty() || !turns.directions.is_empty() {
        toml.push_str(&comment_block(errors.file(), &folded, &symbols, &turns, m));
    }

    let back_file = format!("<{} corrected>", m.name);
    let back = parse_machine(&back_file, &toml)
        .map_err(|e| bad(format!("the corrected description does not read back: {e}")))?;
    if back != expected {
        return Err(bad(format!(
            "the corrected description does not read back as machine `{}` with the folded offsets and directions",
            m.name
        )));
    }
    Ok(CorrectedDescription {
        toml: format!("{bom}{toml}"),
        folded,
        symbols,
        directions: turns.directions,
        turned: turns.turned,
        set_up_turn: turns.set_up_turn,
        set_up_change_mm: turns.set_up_change_mm,
        not_folded,
    })
}

/// The corrected machine as it is being built, and which written offset coordinates changed.
struct Writer<'a> {
    /// The original machine.
    m: &'a Machine,
    /// How many offset coordinates use each symbol ([`symbol_uses`]).
    uses: Vec<usize>,
    /// The corrected machine.
    expected: Machine,
    /// The offset coordinates whose written number changes: (axis, coordinate index).
    changed: Vec<(AxisId, usize)>,
    /// The values' file, for errors.
    file: &'a str,
}

impl Writer<'_> {
    /// Where coordinate `k` of the offset of `axis` is held: the symbol used there alone (its
    /// default changes), else `None` (the coordinate is or becomes a number); its value now
    /// (mm); where that is, for people.
    fn place(&self, axis: AxisId, k: usize) -> (Option<usize>, f64, String) {
        let (name, c) = (&self.m.axes[axis].name, Dir::ALL[k]);
        let e = &self.expected;
        match e.axes[axis].offset[k] {
            Value::Number(x) => (None, x, format!("offset {c} of axis {name}")),
            Value::Symbol(s) if self.uses[s] == 1 => (
                Some(s),
                e.symbols[s].default,
                format!("symbol {} (offset {c} of axis {name})", e.symbols[s].name),
            ),
            Value::Symbol(s) => (
                None,
                e.symbols[s].default,
                format!(
                    "offset {c} of axis {name}, which was the shared symbol {} and is now a number",
                    e.symbols[s].name
                ),
            ),
        }
    }

    /// Sets coordinate `k` of the offset of `axis` to `after` (mm) where [`Writer::place`]
    /// says; returns `after`.
    fn set(
        &mut self,
        axis: AxisId,
        k: usize,
        symbol: Option<usize>,
        after: f64,
        place: &str,
    ) -> Result<f64, CompensationError> {
        if !after.is_finite() {
            return Err(CompensationError::NonFinite {
                file: self.file.to_string(),
                what: format!("the corrected {place}"),
                value: after,
            });
        }
        match symbol {
            Some(s) => self.expected.symbols[s].default = after,
            None => {
                self.expected.axes[axis].offset[k] = Value::Number(after);
                self.changed.push((axis, k));
            }
        }
        Ok(after)
    }

    /// The offset of `axis` in the corrected machine (mm).
    fn offset(&self, axis: AxisId) -> Vector3<f64> {
        self.value(&self.expected.axes[axis].offset)
    }

    /// `o` with the corrected machine's symbol defaults (mm).
    fn value(&self, o: &[Value; 3]) -> Vector3<f64> {
        Vector3::from_fn(|k, _| match o[k] {
            Value::Number(x) => x,
            Value::Symbol(s) => self.expected.symbols[s].default,
        })
    }
}

/// The directions and offsets a fold of angular location errors changes.
struct Turns {
    directions: Vec<FoldedDirection>,
    turned: Vec<TurnedOffset>,
    set_up_turn: Option<[[f64; 3]; 3]>,
    set_up_change_mm: [f64; 3],
}

/// Folds `angles` (per axis, its angular location errors that [`turns::blocked`] lets fold)
/// into the directions of `w`'s machine, turning what each axis carries
/// ([`turns`]); `Err` with why when a carried axis cannot be turned or a direction does not
/// read.
fn fold_turns(w: &mut Writer, angles: &[Vec<FoldedAngle>]) -> Result<Turns, String> {
    let m = w.m;
    let mut out = Turns {
        directions: Vec::new(),
        turned: Vec::new(),
        set_up_turn: None,
        set_up_change_mm: [0.0; 3],
    };
    for side in [Side::Work, Side::Tool] {
        let chain = m.chain(side);
        let mut q = Matrix3::identity();
        let mut by: Vec<String> = Vec::new();
        // The fixed links since the last axis (mm).
        let mut links = Vector3::zeros();
        for l in &chain.links {
            let axis = match l {
                Link::Fixed { offset, .. } => {
                    links += w.value(offset);
                    continue;
                }
                Link::Axis(a) => *a,
            };
            let name = &m.axes[axis].name;
            let carried = !turns::is_identity(&q);
            if carried {
                if m.axes[axis].kind != model_spec::AxisKind::Rotary {
                    return Err(format!(
                        "linear axis {name} is carried by the turned axes {}",
                        by.join(", ")
                    ));
                }
                let o = w.offset(axis);
                let new = q * (links + o) - links;
                for k in 0..3 {
                    if new[k].to_bits() == o[k].to_bits() {
                        continue;
                    }
                    let (symbol, before, place) = w.place(axis, k);
                    let after = w
                        .set(axis, k, symbol, new[k], &place)
                        .map_err(|e| e.to_string())?;
                    out.turned.push(TurnedOffset {
                        axis: name.clone(),
                        coordinate: Dir::ALL[k],
                        by: by.clone(),
                        symbol: symbol.map(|s| m.symbols[s].name.clone()),
                        before_mm: before,
                        after_mm: after,
                        place,
                    });
                }
            }
            links = Vector3::zeros();
            let own = &angles[axis];
            if own.is_empty() && !carried {
                continue;
            }
            let r = turns::location_rotation(m, own);
            let t = turns::turn(m, axis, &q, &r).ok_or_else(|| {
                format!("the folded direction of axis {name} is within rounding of x")
            })?;
            w.expected.axes[axis].direction = t.direction;
            out.directions.push(FoldedDirection {
                axis: name.clone(),
                errors: own.clone(),
                carried_by: by.clone(),
                before: m.axes[axis].direction.unit(),
                after: t.written,
                frame_turn_rad: t.frame_turn_rad,
            });
            q = t.passed_on;
            if !own.is_empty() {
                by.push(name.clone());
            }
        }
        if turns::is_identity(&q) {
            continue;
        }
        if side == Side::Tool {
            return Err(format!(
                "the {} end would be turned by the axes {}",
                chain.end_name,
                by.join(", ")
            ));
        }
        let p = links + w.value(&chain.end_offset);
        let change = (q - Matrix3::identity()) * p;
        out.set_up_turn = Some(std::array::from_fn(|i| std::array::from_fn(|j| q[(i, j)])));
        out.set_up_change_mm = [change[0], change[1], change[2]];
    }
    Ok(out)
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
fn comment_block(
    file: &str,
    folded: &[Folded],
    symbols: &[FoldedSymbol],
    turns: &Turns,
    m: &Machine,
) -> String {
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
    for d in &turns.directions {
        let a = m.axis_by_name(&d.axis).map(|a| &m.axes[a]);
        let before = a.map_or_else(|| vector(d.before), |a| a.direction.to_string());
        let own: Vec<String> = d
            .errors
            .iter()
            .map(|e| format!("{} = {} µrad", e.name, format_scaled(e.value_rad + 0.0, 6)))
            .collect();
        let what = match (own.is_empty(), d.carried_by.is_empty()) {
            (false, true) => format!(
                "#   {} folded into the direction of axis {}:",
                own.join(" and "),
                d.axis
            ),
            (false, false) => format!(
                "#   {} folded into the direction of axis {}, turned with axis {} too:",
                own.join(" and "),
                d.axis,
                d.carried_by.join(", ")
            ),
            _ => format!(
                "#   the direction of axis {} turned with axis {}:",
                d.axis,
                d.carried_by.join(", ")
            ),
        };
        out.push_str(&format!("{what} {before} → {}\n", vector(d.after)));
    }
    for t in &turns.turned {
        out.push_str(&format!(
            "#   the {} turned with axis {}: {} → {} mm\n",
            t.place,
            t.by.join(", "),
            number(t.before_mm),
            number(t.after_mm)
        ));
    }
    if turns.set_up_turn.is_some() {
        let c = turns.set_up_change_mm.map(|x| format_scaled(x + 0.0, 3));
        out.push_str(&format!(
            "#   the ball's place in the last frame turns with them (a set-up, not the machine):\n#   identified with this description, XOW YOW ZOW are larger by {} µm, {} µm, {} µm\n",
            c[0], c[1], c[2]
        ));
    }
    out
}

/// `v` as a direction written into the description: `[x, y, z]`, shortest decimals.
fn vector(v: [f64; 3]) -> String {
    format!("[{}, {}, {}]", number(v[0]), number(v[1]), number(v[2]))
}
