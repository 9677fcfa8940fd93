//! Where the plan's poses are in the log: the offset between the log's clock and the program's,
//! and for each pose the still period it rests in.
//!
//! **Static plans.** The machine's real timing drifts from the plan (move times the plan
//! models only approximately, block changes, PLC handshakes, the two clocks' rates), so each
//! pose is placed on its own, tracked from the one before: with the current offset `δ` (log
//! time minus program time), pose `i` should rest at `[arrive_i + δ, depart_i + δ]`. The
//! still period that overlaps that interval most is its period; if the period's end is within
//! the tolerance of the predicted departure, the offset is re-anchored there
//! (`δ = end − depart_i`: a departure is sharp in the readings); else if its start is within
//! the tolerance of the predicted arrival, there (an arrival is blurred by the servo's
//! settling); else the offset is carried over (the pose is **predicted**: the moves before and
//! after it did not show in the readings). A pose no still period overlaps is **missing**.
//!
//! The first offset is found by trying every still period as the rest of the first pose (its
//! end as the first departure) and as the rest of the last pose (its start as the last
//! arrival), tracking all poses from each, and keeping the placement with the fewest missing
//! poses and then the most anchored ones. Another placement as good elsewhere (a log of two
//! runs, a plan whose rests and moves all look alike with nothing before or after) makes the
//! alignment **ambiguous**; fewer than half the poses anchored makes it **poor**: both are
//! refused, and `--offset-s` gives the offset instead. Before the program the nest rests on the
//! ball at the first pose and after it at the last, so a placement shifted by one pose leaves
//! one end unanchored and loses to the right one.
//!
//! **Continuous plans.** The run is found by its lead-in and lead-out dwells: a still period
//! whose end is the departure from the first pose and a later one whose start is, within the
//! tolerance, the arrival at the last. The instants between are mapped linearly between the
//! two (the ratio of the real run time to the planned one is reported: a feed override, or a
//! control that reads the feed otherwise than the plan assumes).

use crate::measure::{PlanRow, TimingPlan};
use crate::segment::log::LogClock;
use crate::segment::still::StillPeriod;

/// How a pose was placed in the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// At the end of its still period: the departure to the next pose.
    Departure,
    /// At the start of its still period: the arrival from the pose before.
    Arrival,
    /// At the offset of the pose before: no edge of its still period near the predicted times.
    Predicted,
}

impl Anchor {
    /// `departure`, `arrival` or `predicted`.
    pub fn name(self) -> &'static str {
        match self {
            Anchor::Departure => "departure",
            Anchor::Arrival => "arrival",
            Anchor::Predicted => "predicted",
        }
    }
}

/// One pose placed in the log.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Placed {
    /// Its still period (index), `None` when missing.
    pub(crate) period: Option<usize>,
    /// Log time minus program time at this pose, s.
    pub(crate) offset: f64,
    pub(crate) anchor: Anchor,
}

/// The plan placed in the log.
#[derive(Clone, Debug)]
pub(crate) struct Alignment {
    /// Log time (s after its first row) of the program's `t = 0`.
    pub(crate) offset: f64,
    /// Continuous plans: the real run time over the planned one (1 for static plans).
    pub(crate) scale: f64,
    pub(crate) placed: Vec<Placed>,
    /// Poses placed at an edge of their still period.
    pub(crate) anchored: usize,
    /// The best other placement: its offset (log time of `t = 0`, s after the first row) and
    /// its anchored poses; `None` when there was none or the offset was given.
    pub(crate) runner_up: Option<(f64, usize)>,
}

/// A placement tried from one first offset.
struct Track {
    placed: Vec<Placed>,
    missing: usize,
    /// Missing poses that would rest before the log's first row.
    early: usize,
    anchored: usize,
}

/// The period of `periods` (sorted, disjoint) overlapping `[a, b]` most, if any does.
fn best_overlap(periods: &[StillPeriod], a: f64, b: f64) -> Option<usize> {
    let first = periods.partition_point(|p| p.hi < a);
    let mut best: Option<(usize, f64)> = None;
    for (j, p) in periods.iter().enumerate().skip(first) {
        if p.lo > b {
            break;
        }
        let overlap = p.hi.min(b) - p.lo.max(a);
        if overlap >= 0.0 && best.is_none_or(|(_, o)| overlap > o) {
            best = Some((j, overlap));
        }
    }
    best.map(|(j, _)| j)
}

/// Tracks every pose of `rows` from the first offset `start` (see the module documentation).
fn track(rows: &[PlanRow], periods: &[StillPeriod], start: f64, tol: f64, give_up: usize) -> Track {
    let mut offset = start;
    let mut t = Track {
        placed: Vec::with_capacity(rows.len()),
        missing: 0,
        early: 0,
        anchored: 0,
    };
    for r in rows {
        let (a, d) = (r.arrive_s + offset, r.depart_s + offset);
        let Some(j) = best_overlap(periods, a, d) else {
            t.missing += 1;
            if d < 0.0 {
                t.early += 1;
            }
            t.placed.push(Placed {
                period: None,
                offset,
                anchor: Anchor::Predicted,
            });
            if t.missing > give_up {
                break;
            }
            continue;
        };
        let p = periods[j];
        let anchor = if !p.open_hi && (p.hi - d).abs() <= tol {
            offset = p.hi - r.depart_s;
            Anchor::Departure
        } else if !p.open_lo && (p.lo - a).abs() <= tol {
            offset = p.lo - r.arrive_s;
            Anchor::Arrival
        } else {
            Anchor::Predicted
        };
        if anchor != Anchor::Predicted {
            t.anchored += 1;
        }
        t.placed.push(Placed {
            period: Some(j),
            offset,
            anchor,
        });
    }
    t
}

/// Places the static plan `plan` in a log with the still periods `periods` (`span` s long,
/// clock `clock` for messages), each edge within `tol` s of its prediction; from the first
/// offset `given` (log time of `t = 0`, s after the first row) when given.
///
/// # Errors
/// A message for a log where poses are missing (with the first few), an ambiguous or a poor
/// placement.
pub(crate) fn align_static(
    plan: &TimingPlan,
    periods: &[StillPeriod],
    span: f64,
    tol: f64,
    given: Option<f64>,
    clock: &LogClock,
) -> Result<Alignment, String> {
    let rows = &plan.rows;
    let n = rows.len();
    let starts: Vec<f64> = match given {
        Some(g) => vec![g],
        None => periods
            .iter()
            .flat_map(|p| {
                let first = (!p.open_hi).then(|| p.hi - rows[0].depart_s);
                let last = (!p.open_lo).then(|| p.lo - rows[n - 1].arrive_s);
                first.into_iter().chain(last)
            })
            .collect(),
    };
    if starts.is_empty() {
        return Err(format!(
            "no still period in the log ends or starts a rest (found {} still period(s) in {} s): the readings never settle, or never change; check the log, or give --offset-s and --still-um",
            periods.len(),
            short(span)
        ));
    }
    // A log starts before the program: a placement with poses before its first row is the
    // least likely, whatever else it explains.
    let key = |t: &Track| (t.early, t.missing, n - t.anchored);
    let mut best: Option<Track> = None;
    let mut runner_up: Option<Track> = None;
    for &s in &starts {
        let give_up = best.as_ref().map_or(n, |b| b.early + b.missing);
        let t = track(rows, periods, s, tol, give_up);
        if t.placed.len() < n {
            continue;
        }
        let distinct = |a: &Track, b: &Track| (a.placed[0].offset - b.placed[0].offset).abs() > tol;
        match &best {
            Some(b) if key(&t) < key(b) => {
                if distinct(&t, b) {
                    runner_up = best.take();
                }
                best = Some(t);
            }
            Some(b) => {
                if distinct(&t, b) && runner_up.as_ref().is_none_or(|r| key(&t) < key(r)) {
                    runner_up = Some(t);
                }
            }
            None => best = Some(t),
        }
    }
    let Some(best) = best else {
        return Err("no placement of the plan in the log".into());
    };
    if best.missing > 0 {
        return Err(missing_message(rows, &best, span, clock));
    }
    if given.is_none() {
        if let Some(r) = &runner_up
            && key(r) == key(&best)
        {
            return Err(format!(
                "the alignment is ambiguous: the plan fits the log equally well with the program starting at {} s and at {} s (log clock; {} of {} poses at the edges of their still periods): a log of two runs, or a plan with nothing to tell its poses apart; cut the log, or give --offset-s",
                short(clock.log_time(best.placed[0].offset)),
                short(clock.log_time(r.placed[0].offset)),
                best.anchored,
                n
            ));
        }
        if 2 * best.anchored < n {
            return Err(format!(
                "the alignment is poor: at best only {} of {} poses rest in still periods whose edges are where the plan puts them (program start at {} s, log clock): the log may not be of this plan, the machine's timing may differ from it by more than the tolerance ({} s), or the moves do not show in the readings; give --offset-s, --tolerance-s or --still-um",
                best.anchored,
                n,
                short(clock.log_time(best.placed[0].offset)),
                short(tol)
            ));
        }
    }
    Ok(Alignment {
        offset: given.unwrap_or(best.placed[0].offset),
        scale: 1.0,
        anchored: best.anchored,
        runner_up: runner_up.map(|r| (r.placed[0].offset, r.anchored)),
        placed: best.placed,
    })
}

/// The message for the missing poses of `t`.
fn missing_message(rows: &[PlanRow], t: &Track, span: f64, clock: &LogClock) -> String {
    let missing: Vec<usize> = (0..t.placed.len())
        .filter(|&i| t.placed[i].period.is_none())
        .collect();
    let i = missing[0];
    let (a, d) = (
        rows[i].arrive_s + t.placed[i].offset,
        rows[i].depart_s + t.placed[i].offset,
    );
    let listed: Vec<String> = missing
        .iter()
        .take(5)
        .map(|i| (i + 1).to_string())
        .collect();
    let why = if d > span {
        format!(
            "the log ends at {} s, before the rest of sample {} ({} .. {} s): the log is shorter than the program",
            short(clock.log_time(span)),
            i + 1,
            short(clock.log_time(a)),
            short(clock.log_time(d))
        )
    } else if a < 0.0 {
        format!(
            "the log starts at {} s, after the planned rest of sample {} ({} .. {} s): start the log before the program",
            short(clock.log_time(0.0)),
            i + 1,
            short(clock.log_time(a)),
            short(clock.log_time(d))
        )
    } else {
        format!(
            "no still period in the log at the planned rest of sample {} ({} .. {} s, log clock): the machine moved, the log has a gap, or its readings are noisier than the stillness limit",
            i + 1,
            short(clock.log_time(a)),
            short(clock.log_time(d))
        )
    };
    format!(
        "{} of {} poses not found (samples {}{}): {why}",
        missing.len(),
        rows.len(),
        listed.join(", "),
        if missing.len() > 5 { ", …" } else { "" }
    )
}

/// Places the continuous plan `plan` (see the module documentation): the departure from the
/// first pose at the end of a still period, the arrival at the last at the start of a later
/// one within `tol` s; from the offset `given` when given (the end found when it can be, for
/// the run time's ratio).
///
/// # Errors
/// A message when no run, or more than one, is found.
pub(crate) fn align_continuous(
    plan: &TimingPlan,
    periods: &[StillPeriod],
    span: f64,
    tol: f64,
    given: Option<f64>,
    clock: &LogClock,
) -> Result<Alignment, String> {
    let rows = &plan.rows;
    let (first, last) = (&rows[0], &rows[rows.len() - 1]);
    let run = last.arrive_s - first.depart_s;
    // The end of the run for a start at offset δ: the still period starting nearest the
    // predicted arrival, within the tolerance.
    let end_for = |offset: f64| -> Option<usize> {
        let at = last.arrive_s + offset;
        periods
            .iter()
            .enumerate()
            .filter(|(_, p)| {
                !p.open_lo && p.lo > first.depart_s + offset && (p.lo - at).abs() <= tol
            })
            .min_by(|(_, p), (_, q)| (p.lo - at).abs().total_cmp(&(q.lo - at).abs()))
            .map(|(j, _)| j)
    };
    let placed_run = |offset: f64, start: Option<usize>, end: Option<usize>| -> Alignment {
        let scale = match end {
            Some(j) if run > 0.0 => (periods[j].lo - (first.depart_s + offset)) / run,
            _ => 1.0,
        };
        let placed = (0..rows.len())
            .map(|i| {
                let (period, anchor) = if i == 0 && start.is_some() {
                    (start, Anchor::Departure)
                } else if i == rows.len() - 1 && end.is_some() {
                    (end, Anchor::Arrival)
                } else {
                    (None, Anchor::Predicted)
                };
                Placed {
                    period,
                    offset,
                    anchor,
                }
            })
            .collect();
        Alignment {
            offset,
            scale,
            placed,
            anchored: usize::from(start.is_some()) + usize::from(end.is_some()),
            runner_up: None,
        }
    };
    if let Some(g) = given {
        return Ok(placed_run(g, None, end_for(g)));
    }
    let runs: Vec<(f64, usize, usize)> = periods
        .iter()
        .enumerate()
        .filter(|(_, p)| !p.open_hi)
        .filter_map(|(j, p)| {
            let offset = p.hi - first.depart_s;
            end_for(offset).map(|e| (offset, j, e))
        })
        .collect();
    match runs.as_slice() {
        [] => Err(format!(
            "no run found: no still period ends where a run could start and another starts where it would end ({} s later, ±{} s) among the {} still periods of the log ({} s): check that the log is of this plan, or give --offset-s, --tolerance-s or --still-um",
            short(run),
            short(tol),
            periods.len(),
            short(span)
        )),
        [(offset, start, end)] => Ok(placed_run(*offset, Some(*start), Some(*end))),
        [(a, ..), (b, ..), ..] => Err(format!(
            "the alignment is ambiguous: {} runs of the plan's length found, starting at {} s and {} s (log clock): cut the log, or give --offset-s",
            runs.len(),
            short(clock.log_time(*a)),
            short(clock.log_time(*b))
        )),
    }
}

/// A time for messages: at most six decimals, no trailing zeros.
fn short(x: f64) -> String {
    model_spec::units::short(x)
}
