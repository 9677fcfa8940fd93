//! Position against time: where an error of an axis that depends on the axis's position and a
//! term of time (a drift `time:K`, `rate`, a settling `exp:TAU`, a warm-up `warmup:TAU`, of any
//! effect, a record's own or shared) explain the same part of the readings, the records cannot
//! tell which is the cause. That happens on a record where the axis moves monotonically in
//! time: its position is then a function of time, and so is every error of its position.
//!
//! For every finding of the selection that is one of the two kinds, the other kind's candidates
//! are measured against it, given the rest of the model (the base model and the other findings
//! of the extended model projected out of both, as the selection saw them; whitened):
//!
//! ```text
//! r  = the readings, the rest of the model projected out
//! u  = the part of r the time term explains      (its projection on the time term's columns)
//! v  = the part of r the position term explains  (its projection on the position term's columns)
//! time in position  = ‖P_p·u‖ / ‖u‖     position in time = ‖P_t·v‖ / ‖v‖
//! ```
//!
//! (`P_p`, `P_t` the projections on the position term's and the time term's columns): the
//! cosines of the angles between what each explains and the other's span. The two are nearly
//! collinear on these records when both cosines are at least [`COLLINEAR_COSINE`], or when the
//! selection already lists the other as one of the finding's alternatives (it explains what the
//! finding explains, as far as the data tell); the partner of a finding is the nearly collinear
//! candidate of the other kind with the largest smaller cosine. Then the data decide, if they
//! can, by the two raw F-tests at the diagnosis's α: the position term
//! added to the time term, the time term added to the position term ([`Verdict`]):
//!
//! - neither adds significantly to the other: the two **cannot be told apart on these records**;
//! - one adds, the other does not: the data prefer the one that adds.
//!
//! An entry ([`PositionOrTime`]) is made when the verdict is not the selection's choice (the
//! pair cannot be told apart, or the data prefer the term the selection did not choose), with
//! the axis, the records on which it moves monotonically in time, the tests that separate the
//! two (the axis's turn there and back in one record, `turn-R-back`, or reversed, `turn-R-rev`:
//! the axis then takes its positions at other times) and the `rtest plan` arguments that check
//! it before measuring. The other term is added to the finding's alternatives. The finding is
//! not moved (the extended model keeps what the selection chose): the entry says what the data
//! prefer and how sure; a position error of an axis is a property of the machine that holds on
//! every record, a drift is a record's own, so the position term is the physical reading, to be
//! confirmed by the separating test.

use super::columns::Columns;
use super::projected::Projected;
use super::select::{Span, f_p_value, f_statistic};
pub use fitting::plan::separate::{is_time, position_axis};
use model_spec::terms::Term;
use model_spec::{AxisKind, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;

/// The least cosine, both ways, between what one term explains and the other's span for a
/// position term and a time term to count as nearly collinear on the records (0.9: each
/// explains at least 81 % of the other's part of the readings in sum of squares).
pub const COLLINEAR_COSINE: f64 = 0.9;

/// What the data say of a nearly collinear position term and time term.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Neither adds significantly to the other: the records cannot tell them apart.
    Undecided,
    /// The position term adds significantly to the time term, not the reverse.
    Position,
    /// The time term adds significantly to the position term, not the reverse.
    Time,
}

/// The least change of an axis between its first and last sample of a record (mm or rad) for it
/// to move on that record.
const MOVES: f64 = 1e-9;

/// A position term of an axis and a time term that explain the same part of the readings of
/// the fitted records.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionOrTime {
    /// The error of the axis that depends on its position (`EBB@harmonic:1`).
    pub position: Term,
    /// The term of time (`BOC@rate`, `dx0@exp:120000`).
    pub time: Term,
    /// Which of the two the selection chose (a finding); the other is among its alternatives.
    pub chosen: Term,
    /// What the data say: the two cannot be told apart, or one is preferred (the one the
    /// selection did not choose).
    pub verdict: Verdict,
    /// The axis.
    pub axis: String,
    /// The fitted records (labels) on which the axis moves monotonically in time.
    pub monotonic: Vec<String>,
    /// The cosine between what the time term explains and the position term's span, given the
    /// rest of the model.
    pub time_in_position: f64,
    /// The cosine between what the position term explains and the time term's span.
    pub position_in_time: f64,
    /// The p-value of the position term added to the time term (F-test, raw): small when the
    /// data need the position term beyond the time term.
    pub position_beyond_time_p: f64,
    /// The p-value of the time term added to the position term.
    pub time_beyond_position_p: f64,
    /// The tests that separate the two: the axis's turn there and back and reversed
    /// (`turn-B-back`, `turn-B-rev`); empty for a linear axis (reverse the record's path).
    pub separating: Vec<String>,
    /// The arguments of `rtest plan` after `--machine` that check the separation before
    /// measuring: the two terms, planned on the axis's turn (`--terms EBB@harmonic:1,BOC@rate
    /// --paths turn-B`); empty for a linear axis.
    pub plan_arguments: Vec<String>,
}

/// What the measurement needs.
pub(super) struct Inputs<'a> {
    /// The machine.
    pub m: &'a Machine,
    /// The whitened columns of the base model and the candidates.
    pub cols: &'a Columns,
    /// The candidates (group `nb + c` is candidate `c`).
    pub candidates: &'a [Term],
    /// The candidates the records excite.
    pub live: &'a [usize],
    /// Every finding: its term, its candidate and its alternatives (the selection's).
    pub findings: &'a [(Term, usize, Vec<Term>)],
    /// The groups of the extended model (base groups and plausible findings').
    pub model: &'a [usize],
    /// The fitted records (outliers left out).
    pub records: &'a Campaign,
    /// The significance level of the F-tests.
    pub alpha: f64,
}

/// The labels of the records of `c` on which axis `a` moves monotonically in time.
pub fn monotonic_records(c: &Campaign, a: usize) -> Vec<String> {
    c.records
        .iter()
        .filter(|r| {
            let q: Vec<f64> = r.record.samples.iter().map(|s| s.commands[a]).collect();
            let (Some(first), Some(last)) = (q.first(), q.last()) else {
                return false;
            };
            let up = last - first;
            up.abs() > MOVES && q.windows(2).all(|w| (w[1] - w[0]) * up.signum() >= 0.0)
        })
        .map(|r| r.label.clone())
        .collect()
}

/// How two groups of columns relate given the rest of the model.
struct Measure {
    time_in_position: f64,
    position_in_time: f64,
    position_beyond_time_p: f64,
    time_beyond_position_p: f64,
}

/// The part of `r` in the span of the orthonormal columns `q`.
fn part(q: &DMatrix<f64>, r: &DVector<f64>) -> DVector<f64> {
    q * (q.transpose() * r)
}

/// The cosines of [`measure`] (time in position, position in time), as it computes them;
/// `None` where it gives none.
fn cosines(t: &DMatrix<f64>, p: &DMatrix<f64>, r: &DVector<f64>) -> Option<(f64, f64)> {
    let u = part(t, r);
    let v = part(p, r);
    let (nu, nv) = (u.norm(), v.norm());
    if nu == 0.0 || nv == 0.0 {
        return None;
    }
    Some((
        (p.transpose() * &u).norm() / nu,
        (t.transpose() * &v).norm() / nv,
    ))
}

/// The measure of the time directions `t` and the position directions `p` (orthonormal, the
/// rest of the model projected out) on `r`, the rest's residual, the rest of rank `rank`.
fn measure(t: &DMatrix<f64>, p: &DMatrix<f64>, r: &DVector<f64>, rank: usize) -> Option<Measure> {
    let u = part(t, r);
    let v = part(p, r);
    let (nu, nv) = (u.norm(), v.norm());
    if nu == 0.0 || nv == 0.0 {
        return None;
    }
    let n = r.len();
    let rss = r.norm_squared();
    // Both together: the directions of p beyond t.
    let mut both = Span { q: t.clone() };
    let extra = both.new_directions(p);
    both.extend(&extra);
    let joint = part(&both.q, r).norm_squared();
    let beyond = |added: f64, q: usize, first: usize| {
        f_statistic(
            added.max(0.0),
            rss - (joint - added),
            q.max(1),
            n,
            rank + first,
        )
        .map_or(1.0, |f| f_p_value(f, q.max(1), n, rank + first))
    };
    let p_beyond_t = beyond(joint - nu * nu, extra.ncols(), t.ncols());
    let t_extra = Span { q: p.clone() }.new_directions(t);
    let t_beyond_p = beyond(joint - nv * nv, t_extra.ncols(), p.ncols());
    Some(Measure {
        time_in_position: (p.transpose() * &u).norm() / nu,
        position_in_time: (t.transpose() * &v).norm() / nv,
        position_beyond_time_p: p_beyond_t,
        time_beyond_position_p: t_beyond_p,
    })
}

/// The position terms and time terms that cannot be told apart on the fitted records, one entry
/// per finding of either kind that has such a partner (the partner that explains most alike).
pub(super) fn find(inp: &Inputs) -> Vec<PositionOrTime> {
    let m = inp.m;
    let cols = inp.cols;
    let nb = cols.nb;
    let n = cols.y.len();
    let group = |g: usize| cols.group(g);
    let moving: Vec<(usize, Vec<String>)> = (0..m.axes.len())
        .map(|a| (a, monotonic_records(inp.records, a)))
        .filter(|(_, r)| !r.is_empty())
        .collect();
    let monotonic = |a: usize| moving.iter().find(|(x, _)| *x == a).map(|(_, r)| r);
    // The candidates of either kind outside the extended model, with the extended model
    // projected out once: the rest of the model of a finding is the extended model without
    // it, whose span the finding's own directions complete ([`Projected::without`]).
    let of_a_kind = |o: &usize| {
        let other = inp.candidates[*o];
        (is_time(&other) || position_axis(m, &other).is_some_and(|a| monotonic(a).is_some()))
            && !inp.model.contains(&(nb + o))
    };
    let mut held: Option<Projected> = None;
    let mut out = Vec::new();
    for (term, c, alternatives) in inp.findings {
        let (term, c) = (*term, *c);
        let finding_is_time = is_time(&term);
        let finding_axis = position_axis(m, &term);
        if !finding_is_time && finding_axis.is_none_or(|a| monotonic(a).is_none()) {
            continue;
        }
        let g = nb + c;
        let rest: Vec<usize> = inp.model.iter().copied().filter(|&x| x != g).collect();
        let span = Span::of_groups(n, rest.iter().copied(), &group);
        let r = span.project_out(&cols.y);
        let own = span.new_directions(&group(g));
        if own.ncols() == 0 {
            continue;
        }
        // The candidates of the other kind, and their directions outside the rest.
        let others: Vec<usize> = inp
            .live
            .iter()
            .copied()
            .filter(|&o| {
                let other = inp.candidates[o];
                let fits = if finding_is_time {
                    position_axis(m, &other).is_some_and(|a| monotonic(a).is_some())
                } else {
                    is_time(&other)
                };
                fits && !inp.model.contains(&(nb + o))
            })
            .collect();
        let held = held.get_or_insert_with(|| {
            let kinds: Vec<usize> = inp.live.iter().copied().filter(of_a_kind).collect();
            let full = Span::of_groups(n, inp.model.iter().copied(), &group);
            Projected::new(full, &cols.y, inp.candidates.len(), &kinds, &|o| {
                group(nb + o)
            })
        });
        let without = held.without(span.clone(), own.clone(), &cols.y);
        let directions: Vec<DMatrix<f64>> = others.iter().map(|&o| without.directions(o)).collect();
        // The partner: the collinear candidate with the largest smaller cosine (the F-tests
        // are made for it alone).
        let mut best: Option<((bool, f64), usize, usize)> = None;
        for (k, (&o, dirs)) in others.iter().zip(&directions).enumerate() {
            let other = inp.candidates[o];
            if dirs.ncols() == 0 {
                continue;
            }
            let (t, p) = if finding_is_time {
                (&own, dirs)
            } else {
                (dirs, &own)
            };
            let Some((time_in_position, position_in_time)) = cosines(t, p, &r) else {
                continue;
            };
            let cosine = time_in_position.min(position_in_time);
            // The selection's alternatives explain what the finding explains as far as the
            // data tell: collinear enough whatever the cosine.
            let collinear = cosine >= COLLINEAR_COSINE || alternatives.contains(&other);
            let score = (collinear, cosine);
            if best.as_ref().is_none_or(|b| score > b.0) {
                best = Some((score, o, k));
            }
        }
        let Some(((collinear, _), o, k)) = best else {
            continue;
        };
        if !collinear {
            continue;
        }
        let (t, p) = if finding_is_time {
            (&own, &directions[k])
        } else {
            (&directions[k], &own)
        };
        let Some(x) = measure(t, p, &r, span.rank()) else {
            continue;
        };
        let verdict = match (
            x.position_beyond_time_p < inp.alpha,
            x.time_beyond_position_p < inp.alpha,
        ) {
            (true, false) => Verdict::Position,
            (false, true) => Verdict::Time,
            // Both add: each explains something the other does not, the two are told apart.
            (true, true) => continue,
            (false, false) => Verdict::Undecided,
        };
        let chose = if finding_is_time {
            Verdict::Time
        } else {
            Verdict::Position
        };
        if verdict == chose {
            continue;
        }
        let other = inp.candidates[o];
        let (position, time) = if finding_is_time {
            (other, term)
        } else {
            (term, other)
        };
        let Some(axis) = position_axis(m, &position) else {
            continue;
        };
        let name = m.axes[axis].name.clone();
        let (separating, plan_arguments) = if m.axes[axis].kind == AxisKind::Rotary {
            let turn = format!("turn-{name}");
            (
                vec![format!("{turn}-back"), format!("{turn}-rev")],
                vec![
                    "--terms".to_string(),
                    format!("{},{}", position.spelling(m), time.spelling(m)),
                    "--paths".to_string(),
                    turn,
                ],
            )
        } else {
            (Vec::new(), Vec::new())
        };
        out.push(PositionOrTime {
            position,
            time,
            chosen: term,
            verdict,
            axis: name,
            monotonic: monotonic(axis).cloned().unwrap_or_default(),
            time_in_position: x.time_in_position,
            position_in_time: x.position_in_time,
            position_beyond_time_p: x.position_beyond_time_p,
            time_beyond_position_p: x.time_beyond_position_p,
            separating,
            plan_arguments,
        });
    }
    out
}

/// Adds to every finding of `findings` that an entry of `entries` chose the entry's other term
/// as an alternative (the position term of a drift, the drift of a position term).
pub(super) fn name_alternatives(findings: &mut [super::Finding], entries: &[PositionOrTime]) {
    for e in entries {
        let other = if e.chosen == e.position {
            e.time
        } else {
            e.position
        };
        for f in findings.iter_mut().filter(|f| f.term == e.chosen) {
            if !f.alternatives.contains(&other) {
                f.alternatives.push(other);
            }
        }
    }
}
