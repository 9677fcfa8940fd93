//! The moves of a measurement program and the times of its plan: each move's feed word and
//! duration by the assumptions of [`crate::measure::motion`], the rows of the plan.

use crate::measure::motion::{
    acceleration_limit, combined_length, ramp_loss_s, rate_limit, rest_to_rest_s,
};
use crate::measure::plan::{PlanKind, PlanRow, TimingPlan};
use crate::measure::text::{Feed, word_style};
use crate::measure::{MeasureError, MeasureMode, MeasureOptions, StaticMotion};
use formats::nc::Dialect;
use formats::nc::number::write_number;
use model_spec::units::significant;
use simulation::record::Record;

/// The largest `F` number written (five digits before the point, as ISO and Heidenhain
/// controls read feeds).
pub(crate) const MAX_F: f64 = 99_999.999;

/// Decimals of the `F` numbers written.
const F_DECIMALS: usize = 3;

/// One move of the program, to a pose: its feed word and how long it takes.
pub(crate) struct Move {
    pub(crate) feed: Feed,
    /// From rest to rest (static), or at the commanded rate without ramps (continuous), s.
    pub(crate) duration_s: f64,
    /// The ramp loss of a start or stop at this move's rate, s (0 when neglected).
    pub(crate) ramp_s: f64,
}

/// The moves to poses 2, 3, … (pose 1 is reached by the approach, before the program clock
/// starts).
pub(crate) fn plan_moves(
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
                Dialect::Iso | Dialect::LinuxCnc if !rapid => Feed::Words(Some(f_text(MAX_F).0)),
                _ if rapid => Feed::Rapid,
                _ => Feed::Words(None),
            };
            (feed, f64::INFINITY)
        } else if rapid {
            (Feed::Rapid, rate_limit(&delta, &rapids))
        } else {
            let limit = rate_limit(&delta, &feeds);
            // ISO, LinuxCNC: inverse time, F = 1/min; Heidenhain: mm/min along the combined move.
            let per_rate = match o.dialect {
                Dialect::Iso | Dialect::LinuxCnc => 60.0,
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
                significant(duration_s),
                significant(t.sample_rate_hz)
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
pub(crate) fn f_text(f: f64) -> (String, f64) {
    let mut s = String::new();
    let value = write_number(&mut s, f, &word_style(Dialect::Iso, 'F'), F_DECIMALS).unwrap_or(0.0);
    (s, value)
}

/// Whole milliseconds of `s` seconds.
pub(crate) fn ms(s: f64) -> u64 {
    (s * 1000.0).round() as u64
}

/// The plan of the poses `commands` (mm, rad) reached by `moves`.
pub(crate) fn timing_plan(commands: &[Vec<f64>], moves: &[Move], o: &MeasureOptions) -> TimingPlan {
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
