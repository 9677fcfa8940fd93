//! The steps of the lines read (see the module documentation of [`crate::reader`]).

use super::{Block, Raw, Step};
use formats::poses::AxisWord;
use model_spec::AxisKind;

/// The steps of the lines read, for the axes `axes`: a program with a probing block is sorted
/// as a probing program, any other as a measurement program.
pub(super) fn sort(raws: Vec<Raw>, axes: &[AxisWord]) -> Vec<Block> {
    let probing = raws.iter().any(|r| r.probe.is_some());
    let steps: Vec<Step> = if probing {
        probing_steps(&raws, axes)
    } else {
        measuring_steps(&raws)
    };
    raws.into_iter()
        .zip(steps)
        .map(|(r, step)| Block {
            line: r.line,
            step,
            motion: r.motion,
            dwell_s: r.dwell_s,
            m_codes: r.m_codes,
            comment: r.comment,
            probe: r.probe,
            statement: r.special.map(|(_, s)| s),
        })
        .collect()
}

/// The step of a block that is not a move (the same in both kinds of program), or `None` for a
/// move. `first_move`: the index of the first move.
fn other_step(i: usize, r: &Raw, first_move: Option<usize>) -> Option<Step> {
    Some(if r.end {
        Step::End
    } else if r.stop {
        Step::Stop
    } else if r.probe.is_some() {
        Step::Probe
    } else if let Some((step, _)) = &r.special {
        *step
    } else if r.motion.is_some() {
        return None;
    } else if r.dwell_block {
        Step::Dwell
    } else if r.m_codes.contains(&19) {
        Step::Orient
    } else if r.m_codes.contains(&5) {
        Step::Spindle
    } else if first_move.is_none_or(|x| i < x) && r.m_codes.iter().all(|&c| c == 127) {
        Step::Setup
    } else if !r.m_codes.is_empty() {
        Step::Marker
    } else {
        Step::Setup
    })
}

/// The steps of a measurement program.
fn measuring_steps(raws: &[Raw]) -> Vec<Step> {
    let orient = raws.iter().position(|r| r.m_codes.contains(&19));
    let stop = raws.iter().position(|r| r.stop);
    let last_dwell = raws.iter().rposition(|r| r.dwell_block);
    let first_move = raws.iter().position(|r| r.motion.is_some());
    raws.iter()
        .enumerate()
        .map(|(i, r)| {
            let before = |x: Option<usize>| x.is_none_or(|x| i < x);
            other_step(i, r, first_move).unwrap_or(if before(orient) && before(stop) {
                Step::Clearance
            } else if before(stop) {
                Step::Approach
            } else if last_dwell.is_some_and(|d| i < d) {
                Step::Measure
            } else {
                Step::Retract
            })
        })
        .collect()
}

/// The steps of a probing program.
fn probing_steps(raws: &[Raw], axes: &[AxisWord]) -> Vec<Step> {
    let orient = raws.iter().position(|r| r.m_codes.contains(&19));
    let stop = raws.iter().position(|r| r.stop);
    let first_move = raws.iter().position(|r| r.motion.is_some());
    // The blocks that move or probe, in order: a move's neighbours among them decide its step.
    let moving: Vec<usize> = (0..raws.len())
        .filter(|&i| raws[i].motion.is_some() || raws[i].probe.is_some())
        .collect();
    let probe_at = |k: Option<&usize>| k.is_some_and(|&j| raws[j].probe.is_some());
    raws.iter()
        .enumerate()
        .map(|(i, r)| {
            let before = |x: Option<usize>| x.is_none_or(|x| i < x);
            if let Some(step) = other_step(i, r, first_move) {
                return step;
            }
            if before(stop) {
                return if before(orient) {
                    Step::Clearance
                } else {
                    Step::Approach
                };
            }
            let turns = r.motion.as_ref().is_some_and(|m| {
                m.named
                    .iter()
                    .any(|&a| axes.get(a).is_some_and(|w| w.kind == AxisKind::Rotary))
            });
            let k = moving.binary_search(&i).unwrap_or(0);
            if turns {
                Step::Pose
            } else if probe_at(moving.get(k + 1)) {
                Step::PreTouch
            } else if k > 0 && probe_at(moving.get(k - 1)) {
                Step::Retract
            } else {
                Step::Position
            }
        })
        .collect()
}
