//! ISG-kernel's volumetric compensation (Beckhoff TwinCAT CNC TF5280): which errors of a
//! machine its ISO 230 model takes, under its names, in its units, as the blocks of its
//! `ISG_CSV` file ([`isg_volumetric`]; written by `formats::controllers::isg`).
//!
//! The model (Beckhoff's TF5280 documentation, "Volumetric Compensation", the pages on the
//! supported parameters, units and the CSV format): serial kinematics of three linear axes
//! `X Y Z` and up to three rotary axes `A B C`; it compensates the tool position, not the tool
//! orientation. Its parameters carry ISO 230 names:
//!
//! - **position (location) errors** `{X..C}0{X..C}`: the location errors of the rotary axes
//!   (`X0C Y0C A0C B0C`, rtest's `XOC YOC AOC BOC`) and the squareness errors of the linear
//!   axes (`C0X`, rtest's `COX`): rtest's name with the letter `O` written as the digit `0`;
//!   constants, mm or rad;
//! - **component errors** `E{X..C}{X..C}` against their axis's position (the argument column,
//!   mm or degrees), mm or rad: rtest's axis tables at the chosen pitch.
//!
//! The values are rtest's identified errors in its sign convention, the ISO 230-1 one (along or
//! about the positive coordinate directions). ISG's documentation does not state whether it
//! takes errors or corrections (it has a per-axis `negate` in the list file); the file says so
//! in its comments.
//!
//! Not covered (refused with the reason): an inclined axis (its errors are in its own frame,
//! which ISO names do not describe), an axis letter other than `X Y Z A B C`, more than three
//! linear or three rotary axes. Not held, and listed: an identified length of the description
//! (the kinematics hold it), a location error that varies with time or position.

use super::super::tables::{Pitch, axis_tables};
use super::super::values::{CompensationError, MachineErrors};
pub use formats::controllers::isg::IsgBlock;
use model_spec::{AxisKind, ErrorKind, Machine};

/// A machine's errors as ISG's volumetric compensation takes them.
#[derive(Clone, Debug, PartialEq)]
pub struct IsgVolumetric {
    /// The blocks: the position errors (one row), then one block per axis with component
    /// errors.
    pub blocks: Vec<IsgBlock>,
    /// The axes from the workpiece outwards, then the tool side from the bed (`CAXYZ` for
    /// seed-ac), and how many are on the workpiece side: what the list file's `chain` and
    /// `workpiece_axes` describe (see the documentation of the output for how sure this is).
    pub chain: String,
    /// The number of axes on the workpiece side.
    pub workpiece_axes: usize,
    /// What is not held: `(term, why)`.
    pub not_held: Vec<(String, String)>,
}

/// Why ISG's volumetric compensation cannot take a machine's errors.
#[derive(Debug, thiserror::Error)]
pub enum IsgError {
    /// The topology is outside its model.
    #[error("machine `{machine}` is not covered by ISG's volumetric compensation: {why}")]
    NotCovered {
        /// The machine.
        machine: String,
        /// Why.
        why: String,
    },
    /// The tables could not be made.
    #[error(transparent)]
    Tables(#[from] CompensationError),
}

/// The ISG name of an rtest location or squareness error (`XOC` → `X0C`).
pub fn isg_name(rtest: &str) -> String {
    let mut c: Vec<char> = rtest.chars().collect();
    if c.len() == 3 && c[1] == 'O' {
        c[1] = '0';
    }
    c.into_iter().collect()
}

/// Checks the topology of `m` against ISG's model.
fn covered(m: &Machine) -> Result<(), String> {
    let linear = m.linear_axes().count();
    let rotary = m.rotary_axes().count();
    if linear > 3 || rotary > 3 {
        return Err(format!(
            "the model has at most three linear and three rotary axes; this machine has {linear} and {rotary}"
        ));
    }
    for a in &m.axes {
        let allowed = match a.kind {
            AxisKind::Linear => "XYZ",
            AxisKind::Rotary => "ABC",
        };
        if !allowed.contains(a.name.as_str()) {
            return Err(format!(
                "its axis {} is not one of the model's {allowed}",
                a.name
            ));
        }
        if a.direction.inclined.is_some() {
            return Err(format!(
                "its axis {} is inclined: its errors are in its own frame, which the model's ISO names do not describe",
                a.name
            ));
        }
    }
    Ok(())
}

/// The errors of `m` identified as `errors` in ISG's volumetric model, component errors
/// tabulated at `pitch`; see the module documentation.
///
/// # Errors
/// [`IsgError::NotCovered`] for a topology outside the model; [`IsgError::Tables`] when the
/// tables cannot be made (a pitch giving too many rows, a value not finite).
pub fn isg_volumetric(
    m: &Machine,
    errors: &MachineErrors,
    pitch: Pitch,
) -> Result<IsgVolumetric, IsgError> {
    covered(m).map_err(|why| IsgError::NotCovered {
        machine: m.name.clone(),
        why,
    })?;
    let mut not_held = Vec::new();
    let zero = vec![0.0; m.axes.len()];
    let mut values = vec![0.0; errors.errors().len()];
    errors.values_at(m, &zero, &mut values);
    let mut position = IsgBlock {
        columns: Vec::new(),
        rows: vec![Vec::new()],
    };
    for (slot, &e) in errors.errors().iter().enumerate() {
        let term = &m.catalogue[e];
        if !matches!(
            term.kind,
            ErrorKind::Location { .. } | ErrorKind::Squareness { .. }
        ) {
            continue;
        }
        if errors.varies(e) {
            not_held.push((
                term.name.clone(),
                "a position error that varies: the model's position errors are constants".into(),
            ));
            continue;
        }
        position.columns.push(isg_name(&term.name));
        position.rows[0].push(values[slot]);
    }
    let mut blocks = Vec::new();
    if !position.columns.is_empty() {
        blocks.push(position);
    }
    for t in axis_tables(m, errors, pitch)? {
        let mut columns = vec![t.axis.clone()];
        columns.extend(t.error_names.iter().cloned());
        let rows = t
            .rows
            .iter()
            .map(|r| {
                std::iter::once(r.position)
                    .chain(r.errors.iter().copied())
                    .collect()
            })
            .collect();
        blocks.push(IsgBlock { columns, rows });
    }
    for k in errors.kinematic_changes() {
        not_held.push((
            k.spelling.clone(),
            "a length of the description: the controller's kinematics hold it (ISG's PXA…PZC centres of rotation, the tool length), not its error tables".into(),
        ));
    }
    // The workpiece side from the workpiece towards the bed, then the tool side from the bed.
    let mut work: Vec<&str> = m.work.axes().map(|a| m.axes[a].name.as_str()).collect();
    work.reverse();
    let tool = m.tool.axes().map(|a| m.axes[a].name.as_str());
    let chain: String = work.iter().copied().chain(tool).collect();
    Ok(IsgVolumetric {
        blocks,
        chain,
        workpiece_axes: work.len(),
        not_held,
    })
}
