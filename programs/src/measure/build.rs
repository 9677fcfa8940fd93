//! The measurement program and its plan, from the poses of a record.

use crate::measure::approach::{Retreat, retreat};
use crate::measure::motion::largest_gap_mm;
use crate::measure::plan::TimingPlan;
use crate::measure::text::{ProgramText, word_style};
use crate::measure::timing::{MAX_F, Move, f_text, ms, plan_moves, timing_plan};
use crate::measure::{
    MAX_APPROACH_MM, MeasureError, MeasureMode, MeasureOptions, MeasurementProgram,
};
use crate::reader::{Step, read_program};
use formats::csv::column_order;
use formats::nc::number::write_number;
use formats::nc::{MAX_DECIMALS, NcError};
use formats::poses::{axis_words, from_file_units, to_file_units};
use model_spec::Machine;
use model_spec::units::short;
use model_spec::units::significant;
use simulation::exact::VirtualMachine;
use simulation::record::Record;

/// The longest dwell written, s: the range of Heidenhain's cycle 9.
const MAX_DWELL_S: f64 = 3600.0;
/// The slowest sampling of the R-test a continuous program is planned for, Hz.
pub const MIN_SAMPLE_RATE_HZ: f64 = 0.1;
/// The fastest sampling of the R-test a continuous program is planned for, Hz (100 kHz, beyond
/// any displacement sensor's output rate).
pub const MAX_SAMPLE_RATE_HZ: f64 = 1e5;

/// The measurement program of `poses` (commands in mm and rad, one sample per pose, in order;
/// their times are not used) on machine `m`, and its sample-timing plan (see the module
/// documentation of [`crate::measure`]).
///
/// # Errors
/// [`MeasureError::Options`] for an option out of range or rates that are not one per axis, or
/// no pose; [`MeasureError::Pose`] for a pose that cannot be written; [`MeasureError::Move`]
/// for a move along which the nest leaves the ball by more than
/// [`MeasureOptions::max_gap_mm`], a feed out of the range of the `F` word, or (continuous) a
/// block shorter than the R-test's sampling period; [`MeasureError::ReadBack`] when the
/// written program would not read back as its poses.
pub fn measurement_program(
    m: &Machine,
    poses: &Record,
    opts: &MeasureOptions,
) -> Result<MeasurementProgram, MeasureError> {
    check_options(m, opts)?;
    if poses.samples.is_empty() {
        return Err(MeasureError::Options(
            "no pose: a measurement program needs at least one".into(),
        ));
    }
    let (words, written, rounding) = write_poses(m, poses, opts)?;
    let vm = VirtualMachine::new(m);
    let params = &opts.params;
    let internal: Vec<Vec<f64>> = written.iter().map(|w| from_file_units(m, w)).collect();
    let mut widest = 0.0f64;
    for i in 0..internal.len() {
        let next = internal.get(i + 1).unwrap_or(&internal[i]);
        let gap = largest_gap_mm(&vm, params, &internal[i], next);
        if gap > opts.max_gap_mm {
            return Err(MeasureError::Move {
                from: poses.place(i),
                message: format!(
                    "the nest leaves the ball by {} mm on the nominal machine, more than the {} mm allowed: add poses between (a smaller step), or allow more (rtest path --max-gap-mm)",
                    short(gap),
                    short(opts.max_gap_mm)
                ),
            });
        }
        widest = widest.max(gap);
    }
    let moves = plan_moves(poses, &written, opts)?;
    let plan = timing_plan(&internal, &moves, opts);
    let r = retreat(m, opts, &written[0], &written[written.len() - 1])?;
    let text = program_text(m, opts, &words, &moves, &plan, widest, &r)?;
    read_back(m, opts, &text, &written, &r)?;
    Ok(MeasurementProgram {
        text,
        plan,
        rounding,
        largest_gap_mm: widest,
    })
}

fn check_options(m: &Machine, o: &MeasureOptions) -> Result<(), MeasureError> {
    let bad = |s: String| Err(MeasureError::Options(s));
    let positive = |x: f64| x.is_finite() && x > 0.0;
    if o.decimals > MAX_DECIMALS {
        return bad(format!(
            "{} decimals asked for, at most {MAX_DECIMALS}",
            o.decimals
        ));
    }
    if o.params.len() != m.symbols.len() || o.params.iter().any(|v| !v.is_finite()) {
        return bad(format!(
            "{} kinematic parameters for the {} symbols of machine {}, all finite",
            o.params.len(),
            m.symbols.len(),
            m.name
        ));
    }
    if o.rates.len() != m.axes.len() {
        return bad(format!(
            "{} axis rates for the {} axes of machine {}",
            o.rates.len(),
            m.axes.len(),
            m.name
        ));
    }
    for (a, r) in m.axes.iter().zip(&o.rates) {
        let valid = positive(r.feed_per_min)
            && positive(r.rapid_per_min)
            && r.acceleration_per_s2.is_finite()
            && r.acceleration_per_s2 >= 0.0;
        if !valid {
            return bad(format!(
                "axis {}: the feed and rapid rates must be finite and above 0, the acceleration finite and at least 0 (feed {}, rapid {}, acceleration {})",
                a.name, r.feed_per_min, r.rapid_per_min, r.acceleration_per_s2
            ));
        }
    }
    if !(1..=9999).contains(&o.program_number) {
        return bad(format!(
            "program number {}: from 1 to 9999",
            o.program_number
        ));
    }
    if !positive(o.approach_feed_mm_min) || o.approach_feed_mm_min > MAX_F {
        return bad(format!(
            "approach feed {} mm/min: above 0 and at most {MAX_F}",
            significant(o.approach_feed_mm_min)
        ));
    }
    if !positive(o.approach_mm) || o.approach_mm > MAX_APPROACH_MM {
        return bad(format!(
            "approach {} mm along the tool axis: above 0 and at most {MAX_APPROACH_MM} mm",
            significant(o.approach_mm)
        ));
    }
    if o.clearance_mm.is_some_and(|z| !z.is_finite()) {
        return bad("the clearance must be a finite position, mm".into());
    }
    if !positive(o.max_gap_mm) {
        return bad(format!(
            "largest gap {} mm: finite and above 0",
            significant(o.max_gap_mm)
        ));
    }
    let dwell = |what: &str, s: f64, min: f64| {
        if s.is_finite() && s >= min && s <= MAX_DWELL_S {
            Ok(())
        } else {
            Err(MeasureError::Options(format!(
                "{what} {} s: from {min} to {MAX_DWELL_S} s",
                significant(s)
            )))
        }
    };
    match o.mode {
        MeasureMode::Static(t) => {
            if let Some(code) = t.marker_m
                && let Some(why) = marker_refusal(code)
            {
                return bad(format!("marker M{code}: {why}"));
            }
            dwell("settle time", t.settle_s, 0.0)?;
            dwell("measuring window", t.window_s, 0.001)?;
            dwell("settle time and window", t.settle_s + t.window_s, 0.001)?;
        }
        MeasureMode::Continuous(t) => {
            dwell("lead-in and lead-out", t.lead_s, 0.001)?;
            if !(MIN_SAMPLE_RATE_HZ..=MAX_SAMPLE_RATE_HZ).contains(&t.sample_rate_hz) {
                return bad(format!(
                    "sampling rate {} Hz: from {MIN_SAMPLE_RATE_HZ} to {MAX_SAMPLE_RATE_HZ} Hz",
                    significant(t.sample_rate_hz)
                ));
            }
        }
    }
    Ok(())
}

/// Why M function `code` cannot mark the measuring windows: it stops, ends or calls, moves the
/// spindle the nest sits in, changes tools or how positions are read. `None` for one that may.
fn marker_refusal(code: u16) -> Option<&'static str> {
    match code {
        0 | 1 | 2 | 30 | 60 => Some("it stops or ends the program"),
        3..=5 | 13 | 14 | 19 | 20 => {
            Some("it turns, stops or orients the spindle the nest sits in")
        }
        6 => Some("it changes tools and would unload the nest"),
        89 | 98 | 99 | 198 => Some("it calls or returns from a subprogram or cycle"),
        91 | 92 | 114 | 116 | 118 | 126..=129 | 140 | 144 | 145 => {
            Some("it changes how the positions or rotary axes are read")
        }
        _ => None,
    }
}

/// The axis words of every pose (`X-217.5040 Y… A… C…`, in [`column_order`]), the values they
/// read back as (mm, degrees; [`Machine::axes`] order) and the largest rounding per axis.
type WrittenPoses = (Vec<String>, Vec<Vec<f64>>, Vec<f64>);

fn write_poses(
    m: &Machine,
    poses: &Record,
    o: &MeasureOptions,
) -> Result<WrittenPoses, MeasureError> {
    let order = column_order(m);
    let letters = axis_words(m);
    let mut words = Vec::with_capacity(poses.samples.len());
    let mut written = Vec::with_capacity(poses.samples.len());
    let mut rounding = vec![0.0f64; m.axes.len()];
    for (i, s) in poses.samples.iter().enumerate() {
        let err = |message: String| MeasureError::Pose {
            place: poses.place(i),
            message,
        };
        if s.commands.len() != m.axes.len() {
            return Err(err(format!(
                "{} commands for the {} axes of machine {}",
                s.commands.len(),
                m.axes.len(),
                m.name
            )));
        }
        let given = to_file_units(m, &s.commands);
        let mut text = String::with_capacity(16 * order.len());
        let mut values = vec![0.0; m.axes.len()];
        for (k, &a) in order.iter().enumerate() {
            if k > 0 {
                text.push(' ');
            }
            let letter = letters[a].letter;
            text.push(letter);
            let style = word_style(o.dialect, letter);
            values[a] = write_number(&mut text, given[a], &style, o.decimals).ok_or_else(|| {
                err(format!(
                    "axis {letter}: {} {} cannot be written as an axis word (not finite, or not below ±{} with {} decimals)",
                    given[a],
                    letters[a].unit(),
                    formats::poses::MAX_COMMAND,
                    o.decimals
                ))
            })?;
            rounding[a] = rounding[a].max((values[a] - given[a]).abs());
        }
        m.check_pose(&from_file_units(m, &values))
            .map_err(|e| err(format!("as written with {} decimals: {e}", o.decimals)))?;
        words.push(text);
        written.push(values);
    }
    Ok((words, written, rounding))
}

/// The axis words of `values` (mm, degrees, [`Machine::axes`] order) of the axes `which`
/// picks, in [`column_order`], with `o.decimals` decimals.
fn words_of(
    m: &Machine,
    o: &MeasureOptions,
    values: &[f64],
    which: impl Fn(usize) -> bool,
) -> Result<String, MeasureError> {
    let letters = axis_words(m);
    let mut text = String::new();
    for a in column_order(m).into_iter().filter(|&a| which(a)) {
        if !text.is_empty() {
            text.push(' ');
        }
        let letter = letters[a].letter;
        text.push(letter);
        write_number(
            &mut text,
            values[a],
            &word_style(o.dialect, letter),
            o.decimals,
        )
        .ok_or_else(|| {
            MeasureError::Options(format!(
                "axis {letter}: {} {} of the approach or retract cannot be written as an axis word",
                values[a],
                letters[a].unit()
            ))
        })?;
    }
    Ok(text)
}

/// The operator's message at the stop.
pub(crate) const STOP_MESSAGE: &str =
    "check the nest sits on the ball, start the R-test log, then cycle start";

/// The program's text: the header, the setup, the clearance, the orientation and the approach,
/// the stop, the measuring moves and dwells, the retract, the end.
fn program_text(
    m: &Machine,
    o: &MeasureOptions,
    words: &[String],
    moves: &[Move],
    plan: &TimingPlan,
    gap_mm: f64,
    r: &Retreat,
) -> Result<String, MeasureError> {
    let mut p = ProgramText::new(
        o.dialect,
        o.program_number,
        "rtest R-test measurement program",
    );
    for line in super::header::lines(m, o, plan, gap_mm, r) {
        p.comment(&line);
    }
    let exact_stop = matches!(o.mode, MeasureMode::Static(_));
    let letters = axis_words(m);
    let zero_words: Vec<String> = column_order(m)
        .into_iter()
        .map(|a| format!("{}0", letters[a].letter))
        .collect();
    p.setup(exact_stop, &zero_words.join(" "));
    let rotary = |a: usize| m.axes[a].kind == model_spec::AxisKind::Rotary;
    let linear = |a: usize| !rotary(a);
    let mut clearance = r.above_first.clone();
    clearance[r.axis] = r.clearance_mm;
    p.machine_rapid(&words_of(m, o, &clearance, |a| a == r.axis)?);
    if m.axes
        .iter()
        .any(|a| a.kind == model_spec::AxisKind::Rotary)
    {
        p.machine_rapid(&words_of(m, o, &r.above_first, rotary)?);
    }
    p.orient();
    let others = |a: usize| linear(a) && a != r.axis;
    if m.axes.iter().enumerate().any(|(a, _)| others(a)) {
        p.machine_rapid(&words_of(m, o, &r.above_first, others)?);
    }
    p.machine_rapid(&words_of(m, o, &r.above_first, |a| a == r.axis)?);
    let (approach, _) = f_text(o.approach_feed_mm_min);
    p.machine_feed(&words[0], &approach);
    p.stop(STOP_MESSAGE);
    match o.mode {
        MeasureMode::Static(t) => {
            let (settle, window) = (ms(t.settle_s), ms(t.window_s));
            for (i, w) in words.iter().enumerate() {
                if i > 0 {
                    p.move_to(w, &moves[i - 1].feed);
                }
                let mark = format!("sample {}", i + 1);
                let comment = t.marker_comment.then_some(mark.as_str());
                match t.marker_m {
                    Some(code) => {
                        if settle > 0 {
                            p.dwell(settle, None);
                        }
                        p.m_function(code);
                        p.dwell(window, comment);
                    }
                    None => p.dwell(settle + window, comment),
                }
            }
        }
        MeasureMode::Continuous(t) => {
            let lead = ms(t.lead_s);
            p.dwell(lead, Some("lead-in"));
            for (i, w) in words.iter().enumerate().skip(1) {
                p.move_to(w, &moves[i - 1].feed);
            }
            p.dwell(lead, Some("lead-out"));
        }
    }
    p.machine_feed(&words_of(m, o, &r.above_last, linear)?, &approach);
    let mut back = r.above_last.clone();
    back[r.axis] = r.clearance_mm;
    p.machine_rapid(&words_of(m, o, &back, |a| a == r.axis)?);
    Ok(p.finish(o.program_number))
}

/// Reads `text` back with [`crate::reader`] and checks it: the steps in the order of the
/// sequence, every move in machine coordinates, the clearance first and last, and the
/// measuring poses the written ones, bit for bit.
fn read_back(
    m: &Machine,
    o: &MeasureOptions,
    text: &str,
    written: &[Vec<f64>],
    r: &Retreat,
) -> Result<(), MeasureError> {
    let name = "<measurement program>";
    let program =
        read_program(name, text, o.dialect, &axis_words(m)).map_err(MeasureError::ReadBack)?;
    let fail = |message: String| {
        MeasureError::ReadBack(NcError::Program {
            file: name.into(),
            message,
        })
    };
    use Step::*;
    let expected = [
        Setup, Spindle, Clearance, Orient, Approach, Stop, Measure, Retract, End,
    ];
    let steps = program.steps();
    if steps != expected {
        return Err(fail(format!(
            "its blocks run as {steps:?}, not in the order {expected:?}"
        )));
    }
    if let Some(b) = program
        .blocks
        .iter()
        .find(|b| b.motion.as_ref().is_some_and(|mv| !mv.machine))
    {
        return Err(fail(format!(
            "the move of line {} is not in machine coordinates",
            b.line
        )));
    }
    let written_clearance = |moves: Vec<&crate::reader::Motion>, first: bool| {
        let mv = if first { moves.first() } else { moves.last() };
        mv.is_some_and(|mv| {
            mv.named == [r.axis]
                && (mv.pose[r.axis] - r.clearance_mm).abs()
                    <= 0.6 * 10f64.powi(-(o.decimals as i32))
        })
    };
    if !written_clearance(program.moves(Clearance), true)
        || !written_clearance(program.moves(Retract), false)
    {
        return Err(fail(
            "it does not go to the clearance first and last".into(),
        ));
    }
    let poses = program.measuring_poses();
    let same = poses.len() == written.len()
        && poses
            .iter()
            .zip(written)
            .all(|(p, w)| p.iter().zip(w).all(|(a, b)| a.to_bits() == b.to_bits()));
    if same {
        Ok(())
    } else {
        Err(fail(format!(
            "it reads back as {} measuring poses that differ from the {} written",
            poses.len(),
            written.len()
        )))
    }
}
