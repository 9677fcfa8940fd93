//! The measurement program and its plan, from the poses of a record.

use crate::io::csv::column_order;
use crate::io::nc::measure::motion::{
    acceleration_limit, combined_length, largest_gap_mm, ramp_loss_s, rate_limit, rest_to_rest_s,
};
use crate::io::nc::measure::plan::{PlanKind, PlanRow, TimingPlan};
use crate::io::nc::measure::text::{Feed, ProgramText, word_style};
use crate::io::nc::measure::{
    MeasureError, MeasureMode, MeasureOptions, MeasurementProgram, StaticMotion,
};
use crate::io::nc::number::write_number;
use crate::io::nc::{Dialect, MAX_DECIMALS, NcError, parse_program};
use crate::io::poses::{axis_words, from_file_units, to_file_units};
use crate::record::Record;
use crate::simulation::exact::VirtualMachine;
use model_spec::Machine;
use model_spec::units::short;

/// The largest `F` number written (five digits before the point, as ISO and Heidenhain
/// controls read feeds).
const MAX_F: f64 = 99_999.999;

/// Decimals of the `F` numbers written.
const F_DECIMALS: usize = 3;

/// The longest dwell written, s: the range of Heidenhain's cycle 9.
const MAX_DWELL_S: f64 = 3600.0;

/// The measurement program of `poses` (commands in mm and rad, one sample per pose, in order;
/// their times are not used) on machine `m`, and its sample-timing plan (see the module
/// documentation of [`crate::io::nc::measure`]).
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
    let params = m.default_parameters();
    let internal: Vec<Vec<f64>> = written.iter().map(|w| from_file_units(m, w)).collect();
    let mut widest = 0.0f64;
    for i in 0..internal.len() {
        let next = internal.get(i + 1).unwrap_or(&internal[i]);
        let gap = largest_gap_mm(&vm, &params, &internal[i], next);
        if gap > opts.max_gap_mm {
            return Err(MeasureError::Move {
                from: poses.place(i),
                message: format!(
                    "the nest leaves the ball by {} mm on the nominal machine, more than the {} mm allowed: add poses between, or allow more",
                    short(gap),
                    short(opts.max_gap_mm)
                ),
            });
        }
        widest = widest.max(gap);
    }
    let moves = plan_moves(poses, &written, opts)?;
    let plan = timing_plan(&internal, &moves, opts);
    let text = program_text(m, opts, &words, &moves, &plan, widest);
    read_back(m, opts, &text, &written)?;
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
            o.approach_feed_mm_min
        ));
    }
    if !positive(o.max_gap_mm) {
        return bad(format!(
            "largest gap {} mm: finite and above 0",
            o.max_gap_mm
        ));
    }
    let dwell = |what: &str, s: f64, min: f64| {
        if s.is_finite() && s >= min && s <= MAX_DWELL_S {
            Ok(())
        } else {
            Err(MeasureError::Options(format!(
                "{what} {s} s: from {min} to {MAX_DWELL_S} s"
            )))
        }
    };
    match o.mode {
        MeasureMode::Static(t) => {
            dwell("settle time", t.settle_s, 0.0)?;
            dwell("measuring window", t.window_s, 0.001)?;
            dwell("settle time and window", t.settle_s + t.window_s, 0.001)?;
        }
        MeasureMode::Continuous(t) => {
            dwell("lead-in and lead-out", t.lead_s, 0.001)?;
            if !positive(t.sample_rate_hz) {
                return bad(format!(
                    "sampling rate {} Hz: finite and above 0",
                    t.sample_rate_hz
                ));
            }
        }
    }
    Ok(())
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
                    crate::io::poses::MAX_COMMAND,
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

/// One move of the program, to a pose: its feed word and how long it takes.
struct Move {
    feed: Feed,
    /// From rest to rest (static), or at the commanded rate without ramps (continuous), s.
    duration_s: f64,
    /// The ramp loss of a start or stop at this move's rate, s (0 when neglected).
    ramp_s: f64,
}

/// The moves to poses 2, 3, … (the first move, to pose 1, comes from an unknown position).
fn plan_moves(
    poses: &Record,
    written: &[Vec<f64>],
    o: &MeasureOptions,
) -> Result<Vec<Move>, MeasureError> {
    let feeds: Vec<f64> = o.rates.iter().map(|r| r.feed_per_min).collect();
    let rapids: Vec<f64> = o.rates.iter().map(|r| r.rapid_per_min).collect();
    let accels: Vec<f64> = o.rates.iter().map(|r| r.acceleration_per_s2).collect();
    let rapid = matches!(o.mode, MeasureMode::Static(t) if t.motion == StaticMotion::Rapid);
    let mut moves = Vec::with_capacity(written.len().saturating_sub(1));
    for (i, pair) in written.windows(2).enumerate() {
        let delta: Vec<f64> = pair[1].iter().zip(&pair[0]).map(|(b, a)| b - a).collect();
        let accel = acceleration_limit(&delta, &accels);
        let err = |message: String| MeasureError::Move {
            from: poses.place(i),
            message,
        };
        let (feed, rate) = if delta.iter().all(|d| *d == 0.0) {
            let feed = match o.dialect {
                // In inverse time every feed block needs its F; the block moves nothing.
                Dialect::Iso if !rapid => Feed::Words(Some(f_text(MAX_F).0)),
                _ if rapid => Feed::Rapid,
                _ => Feed::Words(None),
            };
            (feed, f64::INFINITY)
        } else if rapid {
            (Feed::Rapid, rate_limit(&delta, &rapids))
        } else {
            let limit = rate_limit(&delta, &feeds);
            // ISO: inverse time, F = 1/min; Heidenhain: mm/min along the combined move.
            let per_rate = match o.dialect {
                Dialect::Iso => 60.0,
                Dialect::Heidenhain => 60.0 * combined_length(&delta),
            };
            let (text, f) = f_text((limit * per_rate).min(MAX_F));
            if f <= 0.0 {
                return Err(err(format!(
                    "its feed rounds to F0 with {F_DECIMALS} decimals: raise the axis feeds"
                )));
            }
            (Feed::Words(Some(text)), f / per_rate)
        };
        let continuous = matches!(o.mode, MeasureMode::Continuous(_));
        let duration_s = if continuous {
            if rate.is_infinite() { 0.0 } else { 1.0 / rate }
        } else {
            rest_to_rest_s(rate, accel)
        };
        if let MeasureMode::Continuous(t) = o.mode
            && duration_s > 0.0
            && duration_s < 1.0 / t.sample_rate_hz
        {
            return Err(err(format!(
                "the block lasts {} s, less than one sampling period of the R-test at {} Hz: lower the feeds, or sample faster",
                short(duration_s),
                short(t.sample_rate_hz)
            )));
        }
        moves.push(Move {
            feed,
            duration_s,
            ramp_s: ramp_loss_s(rate, accel),
        });
    }
    Ok(moves)
}

/// The text of `F` number `f` (rounded to [`F_DECIMALS`]) and the value it reads back as.
fn f_text(f: f64) -> (String, f64) {
    let mut s = String::new();
    let value = write_number(&mut s, f, &word_style(Dialect::Iso, 'F'), F_DECIMALS).unwrap_or(0.0);
    (s, value)
}

/// Whole milliseconds of `s` seconds.
fn ms(s: f64) -> u64 {
    (s * 1000.0).round() as u64
}

/// The plan of the poses `commands` (mm, rad) reached by `moves`.
fn timing_plan(commands: &[Vec<f64>], moves: &[Move], o: &MeasureOptions) -> TimingPlan {
    let mut rows = Vec::with_capacity(commands.len());
    match o.mode {
        MeasureMode::Static(t) => {
            let (settle, window) = (
                ms(t.settle_s) as f64 / 1000.0,
                ms(t.window_s) as f64 / 1000.0,
            );
            let mut arrive = 0.0;
            for (i, q) in commands.iter().enumerate() {
                if i > 0 {
                    arrive += moves[i - 1].duration_s;
                }
                let start = arrive + settle;
                let end = start + window;
                rows.push(PlanRow {
                    commands: q.clone(),
                    arrive_s: arrive,
                    start_s: start,
                    end_s: end,
                    depart_s: end,
                });
                arrive = end;
            }
            TimingPlan {
                kind: PlanKind::Static,
                rows,
            }
        }
        MeasureMode::Continuous(t) => {
            let lead = ms(t.lead_s) as f64 / 1000.0;
            let first_ramp = moves
                .iter()
                .find(|mv| mv.duration_s > 0.0)
                .map_or(0.0, |mv| mv.ramp_s);
            let last_ramp = moves
                .iter()
                .rev()
                .find(|mv| mv.duration_s > 0.0)
                .map_or(0.0, |mv| mv.ramp_s);
            let n = commands.len();
            let mut t_run = lead;
            for (i, q) in commands.iter().enumerate() {
                let (arrive, depart) = if i == 0 {
                    (0.0, lead)
                } else {
                    t_run += moves[i - 1].duration_s;
                    let at = t_run + first_ramp + if i == n - 1 { last_ramp } else { 0.0 };
                    (at, if i == n - 1 { at + lead } else { at })
                };
                let instant = if i == 0 { depart } else { arrive };
                rows.push(PlanRow {
                    commands: q.clone(),
                    arrive_s: arrive,
                    start_s: instant,
                    end_s: instant,
                    depart_s: depart,
                });
            }
            if n == 1 {
                // A single pose: the lead-in is also the lead-out.
                rows[0].depart_s = lead;
            }
            TimingPlan {
                kind: PlanKind::Continuous,
                rows,
            }
        }
    }
}

/// The program's text: the header, the approach to the first pose, then the moves and dwells.
fn program_text(
    m: &Machine,
    o: &MeasureOptions,
    words: &[String],
    moves: &[Move],
    plan: &TimingPlan,
    gap_mm: f64,
) -> String {
    let mut p = ProgramText::new(
        o.dialect,
        o.program_number,
        "rtest R-test measurement program",
    );
    for line in super::header::lines(m, o, plan, gap_mm) {
        p.comment(&line);
    }
    let exact_stop = matches!(o.mode, MeasureMode::Static(_));
    p.modes(exact_stop);
    let (approach, _) = f_text(o.approach_feed_mm_min);
    p.move_to(&words[0], &Feed::Words(Some(approach)), true);
    match o.mode {
        MeasureMode::Static(t) => {
            let (settle, window) = (ms(t.settle_s), ms(t.window_s));
            for (i, w) in words.iter().enumerate() {
                if i > 0 {
                    p.move_to(w, &moves[i - 1].feed, false);
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
                p.move_to(w, &moves[i - 1].feed, false);
            }
            p.dwell(lead, Some("lead-out"));
        }
    }
    p.finish(o.program_number)
}

/// Reads `text` back and checks that it gives the written poses, bit for bit.
fn read_back(
    m: &Machine,
    o: &MeasureOptions,
    text: &str,
    written: &[Vec<f64>],
) -> Result<(), MeasureError> {
    let name = "<measurement program>";
    let program =
        parse_program(name, text, o.dialect, &axis_words(m)).map_err(MeasureError::ReadBack)?;
    let same = program.poses().len() == written.len()
        && program.poses().iter().zip(written).all(|(p, w)| {
            p.commands
                .iter()
                .zip(w)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        });
    if same {
        Ok(())
    } else {
        Err(MeasureError::ReadBack(NcError::Program {
            file: name.into(),
            message: format!(
                "it reads back as {} poses that differ from the {} written",
                program.poses().len(),
                written.len()
            ),
        }))
    }
}
