//! The read-back of a probing program: its text read by [`crate::reader`] must give, block by
//! block, the steps and the positions it was written with (bit for bit), every move in machine
//! coordinates (but the Heidenhain cycle's position, in the preset's), and its order must be
//! that of a probing program ([`check_order`]).

use super::ProbeError;
use super::ProbeOptions;
use super::text::Expected;
use crate::reader::{ReadProgram, Step, read_program};
use formats::nc::{Dialect, NcError};
use formats::poses::axis_words;
use model_spec::Machine;

/// Two poses equal bit for bit (NaN equal to NaN).
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()))
}

/// Checks that `text` (a probing program of `m` under `o`) reads back as `expected`, block by
/// block, and in the order of a probing program.
///
/// # Errors
/// [`ProbeError::ReadBack`] naming the first block that differs.
pub(crate) fn read_back(
    m: &Machine,
    o: &ProbeOptions,
    text: &str,
    expected: &[Expected],
) -> Result<(), ProbeError> {
    let name = "<probing program>";
    let read = read_program(name, text, o.dialect, &axis_words(m)).map_err(ProbeError::ReadBack)?;
    let fail = |message: String| {
        ProbeError::ReadBack(NcError::Program {
            file: name.into(),
            message,
        })
    };
    if read.blocks.len() != expected.len() {
        return Err(fail(format!(
            "{} blocks read, {} written",
            read.blocks.len(),
            expected.len()
        )));
    }
    for (b, e) in read.blocks.iter().zip(expected) {
        let pose = b.motion.as_ref().map(|mv| (mv.pose.as_slice(), mv.machine));
        let pose_ok = match (&e.pose, pose) {
            (Some((p, machine)), Some((q, read_machine))) => same(p, q) && *machine == read_machine,
            (None, None) => true,
            _ => false,
        };
        if b.line != e.line || b.step != e.step || !pose_ok || b.statement != e.statement {
            return Err(fail(format!(
                "line {} reads back as {:?} {:?}, written as line {} {:?} {:?}",
                b.line,
                b.step,
                b.motion.as_ref().map(|mv| &mv.pose),
                e.line,
                e.step,
                e.pose.as_ref().map(|p| &p.0)
            )));
        }
    }
    check_order(&read, o.dialect).map_err(fail)
}

/// The blocks a hit takes after its probing block and before its retract, in `dialect`: ISO
/// the three skip positions read, the check, the `DPRNT`; Heidenhain the cycle's position
/// block and the `FN 16`; LinuxCNC none (it logs by itself).
pub fn hit_steps(dialect: Dialect) -> &'static [Step] {
    match dialect {
        Dialect::Iso => &[
            Step::PreTouch,
            Step::Probe,
            Step::Latch,
            Step::Latch,
            Step::Latch,
            Step::Check,
            Step::Log,
            Step::Retract,
        ],
        Dialect::LinuxCnc => &[Step::PreTouch, Step::Probe, Step::Retract],
        Dialect::Heidenhain => &[
            Step::PreTouch,
            Step::Probe,
            Step::Probe,
            Step::Log,
            Step::Retract,
        ],
    }
}

/// Checks the order of the blocks of a probing program `read` of `dialect`: the setup (and
/// ISO, LinuxCNC: the log opened), the clearance, the orientation, the stop; then passes,
/// each of the rotary axes turned (one or two blocks), positioning over the sphere, hits
/// (each [`hit_steps`], with positioning before and after), positioning to the clearance; the
/// log closed (ISO, LinuxCNC), the end. Every move in machine coordinates but the Heidenhain
/// cycle's position.
///
/// # Errors
/// What is out of order, with the line.
pub fn check_order(read: &ReadProgram, dialect: Dialect) -> Result<(), String> {
    let b = &read.blocks;
    let at = |i: usize| b.get(i).map_or(0, |x| x.line);
    let mut i = 0;
    let expect = |i: &mut usize, steps: &[Step], what: &str| -> Result<usize, String> {
        let start = *i;
        while *i < b.len() && steps.contains(&b[*i].step) {
            *i += 1;
        }
        if *i == start {
            Err(format!(
                "line {}: {:?} where {what} belongs",
                at(start),
                b.get(start).map(|x| x.step)
            ))
        } else {
            Ok(*i - start)
        }
    };
    expect(&mut i, &[Step::Setup, Step::Spindle], "the setup")?;
    let logged = dialect != Dialect::Heidenhain;
    if logged {
        expect(&mut i, &[Step::LogOpen], "the log opened")?;
    }
    expect(&mut i, &[Step::Clearance], "the clearance")?;
    expect(&mut i, &[Step::Orient], "the orientation")?;
    expect(&mut i, &[Step::Stop], "the stop")?;
    let hit = hit_steps(dialect);
    let mut passes = 0;
    while i < b.len() && b[i].step == Step::Pose {
        passes += 1;
        expect(&mut i, &[Step::Pose], "the rotary axes")?;
        let mut hits = 0;
        loop {
            expect(&mut i, &[Step::Position], "positioning")?;
            if b.get(i).is_none_or(|x| x.step != Step::PreTouch) {
                break;
            }
            for s in hit {
                if b.get(i).map(|x| x.step) != Some(*s) {
                    return Err(format!(
                        "line {}: {:?} where {s:?} belongs in hit {} of pass {passes}",
                        at(i),
                        b.get(i).map(|x| x.step),
                        hits + 1
                    ));
                }
                i += 1;
            }
            hits += 1;
        }
        if hits == 0 {
            return Err(format!("line {}: a pose without a hit", at(i)));
        }
    }
    if passes == 0 {
        return Err(format!("line {}: no pose after the stop", at(i)));
    }
    if logged {
        expect(&mut i, &[Step::LogClose], "the log closed")?;
    }
    expect(&mut i, &[Step::End], "the end")?;
    if i != b.len() {
        return Err(format!("line {}: a block after the end", at(i)));
    }
    for x in b {
        if let Some(mv) = &x.motion {
            let preset = dialect == Dialect::Heidenhain && x.step == Step::Probe;
            if !mv.machine && !preset {
                return Err(format!(
                    "line {}: a move not in machine coordinates",
                    x.line
                ));
            }
        }
    }
    Ok(())
}
