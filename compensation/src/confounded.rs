//! The tool-side length hidden in the pivot: whether the length at the end of the tool chain
//! (the R-test holder's or the tool's, `Zp` or `Zt`, along the tool axis) can be told apart
//! from what the identification put onto the machine.
//!
//! On a machine whose tool chain does not turn (table-table machines, `seed-ac`), a holder
//! 12 µm longer than the description says moves the nest along z at every pose, exactly as a
//! location error of the first rotary axis along z does (`ZOA` on `seed-ac`, `ZOB` on
//! `table-table-bc`): the identification puts the holder's error into the location error, and
//! the compensation then corrects the holder's length as if it were the machine's, for every
//! tool. The reverse holds too: a length identified as a term takes the pivot's error.
//!
//! **The test** ([`tool_length`]): the identification's design, its terms that are functions
//! of the pose (every basis but those of time, `velocity`, `reversal` and `jump:T`, and no
//! instrument term), evaluated on the machine's model, is given the length's column
//! (`KinematicOffset`); when the length is itself a term of the identification, the design is
//! given instead the columns of the machine's constant location translations it does not hold.
//! When the length is then not determined (its column is in the span of the others: adding it
//! does not raise the rank), the members of its confounded group that compensation puts onto
//! the machine (a compensated error, an identified kinematic symbol folded into the
//! description, or for an identified length the location errors it cannot be told from) are
//! named.
//!
//! **The poses.** The identification's report holds its values, not its poses; the design is
//! evaluated at poses of the machine's model instead: every rotary axis at evenly spaced
//! angles over its range (9, or 2K + 3 for a `harmonic:K` of the axis; every combination), the
//! linear axes on the ball by the nominal tool-centre-point inverse kinematics, at the
//! kinematic parameters of the identification's first record. A length confounded there is
//! confounded at any poses: the columns are the same functions of the pose. A campaign whose
//! poses are poorer can confound more (`identify --terms Zp` on it tells).

use super::values::MachineErrors;
use fitting::campaign::CampaignValues;
use fitting::hmatrix::{h_matrix_auto, parameter_names};
use fitting::least_squares::{Constraint, Tolerances, least_squares};
use model_spec::catalogue::Motion;
use model_spec::{ErrorKind, Machine, Value};
use nalgebra::DVector;
use simulation::model::{Basis, Effect, Model, Term};
use simulation::paths::{fill_linear_ik, record_from_commands};

/// The tool-side length, and what it cannot be told from.
#[derive(Clone, Debug, PartialEq)]
pub struct LengthConfounded {
    /// The length's symbol (`Zp`).
    pub symbol: String,
    /// The name of the tool chain's end (`probe`).
    pub end: String,
    /// `true` when the length is itself a term of the identification.
    pub identified: bool,
    /// What it cannot be told from: compensated errors and folded symbols (`ZOA`), or for an
    /// identified length the location errors the model does not hold.
    pub with: Vec<String>,
}

/// Why the test could not be made.
#[derive(Debug, thiserror::Error)]
#[error("the test of the tool-side length {symbol}: {why}")]
pub struct ConfoundedError {
    /// The length's symbol.
    pub symbol: String,
    /// What failed.
    pub why: String,
}

/// The fewest angles per rotary axis.
pub const ANGLES: usize = 9;

/// Whether a term is a function of the pose alone (no time, no direction of motion, no
/// reading).
fn of_the_pose(t: &Term) -> bool {
    !matches!(t.effect, Effect::Instrument { .. } | Effect::PreTravel)
        && matches!(
            t.basis,
            Basis::Const | Basis::Harmonic(_) | Basis::Poly(_) | Basis::Period(_) | Basis::Step(_)
        )
}

/// The commanded poses of the test (mm, rad): every combination of the rotary axes' angles,
/// the linear axes by the inverse kinematics at `params`; poses where it fails are left out.
fn poses(m: &Machine, terms: &[Term], params: &[f64]) -> Vec<Vec<f64>> {
    let mut grids: Vec<(usize, Vec<f64>)> = Vec::new();
    for axis in m.rotary_axes() {
        let k = terms
            .iter()
            .filter(|t| t.effect.carrier(m) == simulation::model::Carrier::Axis(axis))
            .filter_map(|t| match t.basis {
                Basis::Harmonic(k) => Some(k as usize),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        let n = ANGLES.max(2 * k + 3);
        let a = &m.axes[axis];
        let angles: Vec<f64> = if a.limits[0].is_finite() && a.limits[1].is_finite() {
            let [lo, hi] = a.limits;
            (0..n)
                .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
                .collect()
        } else {
            (0..n).map(|i| 360.0 * i as f64 / n as f64).collect()
        };
        grids.push((axis, angles.into_iter().map(f64::to_radians).collect()));
    }
    let mut all = vec![vec![0.0; m.axes.len()]];
    for (axis, angles) in &grids {
        all = all
            .into_iter()
            .flat_map(|q| {
                angles.iter().map(move |&x| {
                    let mut q = q.clone();
                    q[*axis] = x;
                    q
                })
            })
            .collect();
    }
    let mut kept = Vec::with_capacity(all.len());
    for mut q in all {
        if fill_linear_ik(m, params, std::slice::from_mut(&mut q)).is_ok() {
            kept.push(q);
        }
    }
    kept
}

/// Whether the tool-side length of `m` (the symbol of the z of its tool chain's end offset)
/// can be told apart from what the identification of `values` puts onto the machine
/// (`errors`); see the module documentation. `None` when it can, or when the description
/// has no such symbol.
///
/// # Errors
/// [`ConfoundedError`] when the design cannot be evaluated or decomposed.
pub fn tool_length(
    m: &Machine,
    values: &CampaignValues,
    errors: &MachineErrors,
) -> Result<Option<LengthConfounded>, ConfoundedError> {
    let Value::Symbol(symbol) = m.tool.end_offset[2] else {
        return Ok(None);
    };
    let name = m.symbols[symbol].name.clone();
    let fail = |why: String| ConfoundedError {
        symbol: name.clone(),
        why,
    };
    let length = Term {
        effect: Effect::KinematicOffset(symbol),
        basis: Basis::Const,
    };
    let mut terms: Vec<Term> = Vec::new();
    for c in &values.layout.columns {
        if of_the_pose(&c.term) && !terms.contains(&c.term) {
            terms.push(c.term);
        }
    }
    let identified = terms.contains(&length);
    let mut added = Vec::new();
    if identified {
        for (e, entry) in m.catalogue.iter().enumerate() {
            let t = Term {
                effect: Effect::Error(e),
                basis: Basis::Const,
            };
            let translation = matches!(
                entry.kind,
                ErrorKind::Location {
                    motion: Motion::Translation(_),
                    ..
                }
            );
            if translation && !terms.contains(&t) {
                added.push(t);
            }
        }
    } else {
        added.push(length);
    }
    terms.extend(added.iter().copied());
    let model = Model { terms };
    let params = errors.record_params();
    let commands = poses(m, &model.terms, params);
    if commands.is_empty() {
        return Err(fail(
            "the inverse kinematics has no pose on the ball over the rotary axes' ranges".into(),
        ));
    }
    let times = (0..commands.len()).map(|i| i as f64).collect();
    let record = record_from_commands(commands, times);
    let h = h_matrix_auto(m, &model, &record, params).map_err(|e| fail(e.to_string()))?;
    let names = parameter_names(m, &model);
    let zeros = DVector::zeros(h.nrows());
    let fit = least_squares(
        &h,
        &zeros,
        &names,
        &Constraint::None,
        &Tolerances::default(),
    )
    .map_err(|e| fail(e.to_string()))?;
    let columns = model.columns();
    let column_of = |t: &Term| {
        columns
            .iter()
            .position(|&(i, _)| model.terms[i] == *t)
            .expect("every term has a column")
    };
    let at = column_of(&length);
    if fit.identifiability.determined[at] {
        return Ok(None);
    }
    let workpiece = m.workpiece_symbols();
    let applied = |t: &Term| {
        if identified {
            return added.contains(t);
        }
        errors.terms().iter().any(|c| c.term == *t)
            || errors
                .kinematic_changes()
                .iter()
                .any(|k| k.term == *t && *t != length && !workpiece.contains(&k.symbol))
    };
    let mut with: Vec<String> = Vec::new();
    for group in &fit.identifiability.confounded {
        if !group.contains(&at) {
            continue;
        }
        for &j in group {
            let t = model.terms[columns[j].0];
            let spelling = t.spelling(m);
            if t != length && applied(&t) && !with.contains(&spelling) {
                with.push(spelling);
            }
        }
    }
    Ok((!with.is_empty()).then(|| LengthConfounded {
        symbol: name.clone(),
        end: m.tool.end_name.clone(),
        identified,
        with,
    }))
}
