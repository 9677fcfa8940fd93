//! The blocks of a probing program in their order, their nominal times and the plan's rows:
//! the clearance, the orientation and the stop; per pass the rotary axes (at the clearance),
//! over the sphere at the safe height, per hit over it, down to the pre-touch point, the
//! probing move and its log, back, up; the clearance again; the end.
//!
//! **Nominal times** (the plan's `t_s`, s): from the resume after the stop (`t = 0`), rapids at
//! each axis's rapid rate (the slowest axis of a move sets its time), feed moves at their `F`
//! along the linear axes' combined path, a probing move at the probing feed from the pre-touch
//! point to the nominal contact (the hit's time) and back to the pre-touch point at the
//! positioning feed; no acceleration, no block change time, the macro statements and logs
//! instantaneous.

use super::build::{Pass, STOP_MESSAGE};
use super::geometry::{Frame, HitPoints};
use super::plan::{PlannedHit, ProbePlan};
use super::text::{Expected, Writer};
use super::{ProbeError, ProbeOptions};
use crate::reader::Step;
use formats::poses::{axis_words, from_file_units};
use model_spec::units::short;
use model_spec::{AxisKind, Machine};
use simulation::exact::VirtualMachine;
use simulation::record::Record;

/// The clearance: the tool-axis slide and its position, mm.
pub(crate) struct Clearance {
    /// The linear axis most nearly along the tool axis with the rotary axes at 0.
    pub(crate) axis: usize,
    /// Its clearance position, mm (machine coordinates).
    pub(crate) position_mm: f64,
}

/// The clearance of a program whose poses have the frames and hits `frames`: the tool-axis
/// slide (found with every rotary axis at 0, as the R-test programs find it) and its position,
/// the given one or the end of its stroke away from the sphere.
///
/// # Errors
/// [`ProbeError::Options`] for a clearance outside the slide's stroke, or not beyond every
/// hit's safe height.
pub(crate) fn clearance(
    m: &Machine,
    vm: &VirtualMachine,
    o: &ProbeOptions,
    frames: &[(Frame, Vec<HitPoints>)],
) -> Result<Clearance, ProbeError> {
    let mut level = frames[0].0.centre.clone();
    for a in m.rotary_axes() {
        level[a] = 0.0;
    }
    let at_zero = Frame::new(m, vm, &o.params, &level);
    let f = at_zero.as_ref().unwrap_or(&frames[0].0);
    let (k, along) = (0..3)
        .map(|k| (k, f.axis_cos(k, &f.tool_axis())))
        .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
        .unwrap_or((2, 1.0));
    let axis = f.linear()[k];
    let ax = &m.axes[axis];
    let up = along >= 0.0;
    let [lo, hi] = ax.limits;
    let position_mm = match o.clearance_mm {
        Some(z) => z,
        None if up && hi.is_finite() => hi,
        None if !up && lo.is_finite() => lo,
        None => {
            return Err(ProbeError::Options(format!(
                "axis {} has no stroke end to retract to: give the clearance (rtest path --clearance-mm)",
                ax.name
            )));
        }
    };
    if position_mm < lo || position_mm > hi {
        return Err(ProbeError::Options(format!(
            "clearance {} {} mm: outside the stroke of axis {} ({} .. {} mm)",
            ax.name,
            short(position_mm),
            ax.name,
            short(lo),
            short(hi)
        )));
    }
    for (frame, hits) in frames {
        for h in hits {
            let safe = frame.at(&h.safe)[axis];
            let beyond = if up {
                position_mm >= safe
            } else {
                position_mm <= safe
            };
            if !beyond {
                return Err(ProbeError::Options(format!(
                    "clearance {} {} mm: a hit's safe height is at {} {} mm, beyond it: give a clearance farther from the sphere (rtest path --clearance-mm) or a lower safe height",
                    ax.name,
                    short(position_mm),
                    ax.name,
                    short(safe)
                )));
            }
        }
    }
    Ok(Clearance { axis, position_mm })
}

/// The words of a move: their text, the values they read back as (axis, value), and the
/// position after the move (file units).
type Words = (String, Vec<(usize, f64)>, Vec<f64>);

/// A program's sequence, to write.
pub(crate) struct Sequence<'a> {
    pub(crate) m: &'a Machine,
    pub(crate) o: &'a ProbeOptions,
    pub(crate) frames: &'a [(Frame, Vec<HitPoints>)],
    pub(crate) passes: &'a [Pass],
    pub(crate) clearance: Clearance,
    pub(crate) poses: &'a Record,
}

/// The program's state while it is written: the commanded position (file units, NaN: not yet
/// commanded) and the nominal clock (s; counting from the stop's resume).
struct State {
    at: Vec<f64>,
    t_s: f64,
    clock: bool,
}

impl Sequence<'_> {
    /// The program's text, what each block reads back as, the plan and the nominal duration
    /// (s), written with `w`.
    ///
    /// # Errors
    /// [`ProbeError::Pose`] for a position outside the strokes or that cannot be written.
    pub(crate) fn write(
        &self,
        w: Writer,
    ) -> Result<(String, Vec<Expected>, ProbePlan, f64), ProbeError> {
        // A dry run gives the duration the header states; the program is then written again.
        let (_, _, duration_s) = self.body(w.clone(), None)?;
        let (w, rows, duration_s) = self.body(w, Some(duration_s))?;
        let (text, expected) = w.finish(self.o.program_number);
        Ok((text, expected, ProbePlan { rows }, duration_s))
    }

    fn body(
        &self,
        mut w: Writer,
        duration_s: Option<f64>,
    ) -> Result<(Writer, Vec<PlannedHit>, f64), ProbeError> {
        let (m, o) = (self.m, self.o);
        w.start(o.program_number, "rtest touch-probe calibration program");
        let hits = self.passes.len() * o.pattern.len();
        for line in super::header::lines(m, o, &self.clearance, self.passes.len(), hits, duration_s)
        {
            w.comment(&line);
        }
        let letters = axis_words(m);
        let zero: Vec<String> = formats::csv::column_order(m)
            .into_iter()
            .map(|a| format!("{}0", letters[a].letter))
            .collect();
        w.setup(&zero.join(" "));
        w.log_open(&o.log_name);
        let mut s = State {
            at: vec![f64::NAN; m.axes.len()],
            t_s: 0.0,
            clock: false,
        };
        let axis = self.clearance.axis;
        let mut up = s.at.clone();
        up[axis] = self.clearance.position_mm;
        self.rapid(&mut w, &mut s, &up, &|a| a == axis, Step::Clearance, 0)?;
        w.orient();
        w.stop(STOP_MESSAGE);
        s.clock = true;
        let mut rows = Vec::new();
        for pass in self.passes {
            let (frame, hits) = &self.frames[pass.sample];
            let i = pass.sample;
            w.comment(&format!(
                "pose {}: {}",
                pass.label,
                self.rotary_text(&frame.centre)
            ));
            let rotary = |a: usize| m.axes[a].kind == AxisKind::Rotary;
            if let Some(from) = &pass.from {
                self.rapid(&mut w, &mut s, from, &rotary, Step::Pose, i)?;
            }
            self.rapid(&mut w, &mut s, &frame.centre, &rotary, Step::Pose, i)?;
            let over = frame.at(&hits[0].safe);
            let others = |a: usize| !rotary(a) && a != axis;
            self.rapid(&mut w, &mut s, &over, &others, Step::Position, i)?;
            self.rapid(&mut w, &mut s, &over, &|a| a == axis, Step::Position, i)?;
            for (k, h) in hits.iter().enumerate() {
                let safe = frame.at(&h.safe);
                if k > 0 {
                    self.feed(&mut w, &mut s, &safe, Step::Position, i)?;
                }
                let pre = frame.at(&h.pre);
                self.feed(&mut w, &mut s, &pre, Step::PreTouch, i)?;
                let line = self.probe(&mut w, &mut s, frame, h, i)?;
                let mut contact = frame.at(&h.contact);
                for a in m.rotary_axes() {
                    contact[a] = frame.centre[a];
                }
                self.check(&contact, i, "the hit's contact")?;
                rows.push(PlannedHit {
                    pose: pass.label.clone(),
                    hit: k + 1,
                    axes: contact,
                    direction: [h.approach.x, h.approach.y, h.approach.z],
                    t_s: s.t_s,
                    line,
                });
                // Back to the pre-touch point after the trip.
                s.t_s += 60.0 * distance(&h.contact, &h.pre) / o.position_feed_mm_min;
                self.feed(&mut w, &mut s, &pre, Step::Retract, i)?;
                self.feed(&mut w, &mut s, &safe, Step::Position, i)?;
            }
            let back = up_from(&s.at, axis, self.clearance.position_mm);
            self.rapid(&mut w, &mut s, &back, &|a| a == axis, Step::Position, i)?;
        }
        w.log_close();
        Ok((w, rows, s.t_s))
    }

    /// `A0 C90` for the rotary axes of `pose` (file units).
    fn rotary_text(&self, pose: &[f64]) -> String {
        let letters = axis_words(self.m);
        self.m
            .rotary_axes()
            .map(|a| format!("{}{}", letters[a].letter, short(pose[a])))
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// Checks `pose` (file units, every axis known) within the strokes.
    fn check(&self, pose: &[f64], sample: usize, what: &str) -> Result<(), ProbeError> {
        if pose.iter().any(|v| v.is_nan()) {
            return Ok(());
        }
        self.m
            .check_pose(&from_file_units(self.m, pose))
            .map_err(|e| ProbeError::Pose {
                place: self.poses.place(sample),
                message: format!("{what} is outside the strokes: {e}"),
            })
    }

    /// The words of `target`'s axes `which`, the pose after them checked within the strokes.
    fn words(
        &self,
        w: &Writer,
        s: &State,
        target: &[f64],
        which: &dyn Fn(usize) -> bool,
        sample: usize,
    ) -> Result<Words, ProbeError> {
        let (text, read) = w.words(target, which).map_err(|e| ProbeError::Pose {
            place: self.poses.place(sample),
            message: e,
        })?;
        let mut after = s.at.clone();
        for &(a, v) in &read {
            after[a] = v;
        }
        self.check(&after, sample, "a position of the program")?;
        Ok((text, read, after))
    }

    fn rapid(
        &self,
        w: &mut Writer,
        s: &mut State,
        target: &[f64],
        which: &dyn Fn(usize) -> bool,
        step: Step,
        sample: usize,
    ) -> Result<(), ProbeError> {
        let (text, read, after) = self.words(w, s, target, which, sample)?;
        w.rapid(&text, &read, step);
        if s.clock {
            let t = (0..after.len())
                .filter(|&a| !s.at[a].is_nan())
                .map(|a| 60.0 * (after[a] - s.at[a]).abs() / self.o.rates[a].rapid_per_min)
                .fold(0.0, f64::max);
            s.t_s += t;
        }
        s.at = after;
        Ok(())
    }

    /// A feed move of the linear axes to `target` at the positioning feed.
    fn feed(
        &self,
        w: &mut Writer,
        s: &mut State,
        target: &[f64],
        step: Step,
        sample: usize,
    ) -> Result<(), ProbeError> {
        let m = self.m;
        let linear = |a: usize| m.axes[a].kind == AxisKind::Linear;
        let (text, read, after) = self.words(w, s, target, &linear, sample)?;
        let f = Writer::feed_number(self.o.position_feed_mm_min);
        w.feed(&text, &read, &f, step);
        s.t_s += 60.0 * path_mm(&s.at, &after) / self.o.position_feed_mm_min;
        s.at = after;
        Ok(())
    }

    /// The probing move of hit `h` from the pre-touch point (where the machine is); the line of
    /// its probing block. The clock advances to the contact.
    fn probe(
        &self,
        w: &mut Writer,
        s: &mut State,
        frame: &Frame,
        h: &HitPoints,
        sample: usize,
    ) -> Result<usize, ProbeError> {
        let (m, o) = (self.m, self.o);
        let linear = |a: usize| m.axes[a].kind == AxisKind::Linear;
        let letters = axis_words(m);
        let line = match h.axis {
            None => {
                let end = frame.at(&h.end);
                let (text, read, after) = self.words(w, s, &end, &linear, sample)?;
                let f = Writer::feed_number(o.probe_feed_mm_min);
                let line = w.probe(&text, &read, &f);
                if w.dialect == formats::nc::Dialect::Iso {
                    let value = |a: usize| w.number(after[a], false);
                    let [x, y, z] = frame.linear();
                    let threshold = format!("{:.4}", (0.5 * o.overtravel_mm).min(0.01));
                    w.iso_latch(
                        [letters[x].letter, letters[y].letter, letters[z].letter],
                        [value(x), value(y), value(z)],
                        &threshold,
                    );
                }
                // The machine stops at the trip, short of the end: it is at the contact.
                line
            }
            Some((k, positive)) => {
                let (text, read, _) = self.words(w, s, &s.at.clone(), &linear, sample)?;
                let name = &o.log_name;
                w.cycle0(
                    &text,
                    &read,
                    letters[frame.linear()[k]].letter,
                    positive,
                    &format!("{name}.A"),
                    &format!("{name}.TXT"),
                )
            }
        };
        s.t_s += 60.0 * distance(&h.pre, &h.contact) / o.probe_feed_mm_min;
        Ok(line)
    }
}

/// `at` with axis `axis` at `position`.
fn up_from(at: &[f64], axis: usize, position: f64) -> Vec<f64> {
    let mut v = at.to_vec();
    v[axis] = position;
    v
}

/// The distance between two points, mm.
fn distance(a: &nalgebra::Vector3<f64>, b: &nalgebra::Vector3<f64>) -> f64 {
    (a - b).norm()
}

/// The combined path of a move from `from` to `to` (file units) over the axes known in both,
/// mm (the feed moves move the linear axes only).
fn path_mm(from: &[f64], to: &[f64]) -> f64 {
    from.iter()
        .zip(to)
        .filter(|(a, b)| !a.is_nan() && !b.is_nan())
        .map(|(a, b)| (b - a).powi(2))
        .sum::<f64>()
        .sqrt()
}
