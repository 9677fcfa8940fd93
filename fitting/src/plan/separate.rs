//! Position against time in a plan: a term of the model that depends on an axis's position (a
//! harmonic, a polynomial, a period or a step of an error of that axis) and a term of time
//! (`time:K`, `rate`, `exp:TAU`, `warmup:TAU`) that the planned tests cannot separate, and the
//! addition that separates them.
//!
//! On a test where an axis moves monotonically in time its position is a function of time, and
//! so is every error of its position: the estimates of the two terms then correlate. The plan's
//! pairs are those whose estimates correlate by at least [`NEARLY_CONFOUNDED`] in absolute value
//! (a pair in one confounded group counts as 1). The candidates that can separate them are the
//! other orders of the planned tests (`T-rev`, `T-back` of a planned `T`, at the planned ball
//! positions): each is added to the plan on its own, and the one that leaves the smallest
//! largest correlation among every position term and time term of the plan with it (the
//! candidate's own record's time terms included) is named. A record's own drift is on the
//! record's clock: `T-rev` turns the axis the other way on another clock, which a drift of its
//! own follows as well, so that `T-back`, there and back on one clock, is what separates a
//! record's own drift.

use super::{CandidateSet, Plan, PlanError, PlannedTest, Prediction};
use crate::least_squares::Tolerances;
use crate::noise::NoiseModel;
use model_spec::Machine;
use model_spec::basis::{Basis, Carrier};
use model_spec::terms::Term;
use simulation::generator::Order;
use simulation::model::Model;

/// The least absolute correlation of the estimates of a position term and a time term for the
/// plan to count them as not separated.
pub const NEARLY_CONFOUNDED: f64 = 0.9;

/// The axis of a term that depends on the position of its own axis (a harmonic, a polynomial,
/// a period or a step of an error of that axis).
pub fn position_axis(m: &Machine, t: &Term) -> Option<usize> {
    match (t.effect.carrier(m), t.basis) {
        (
            Carrier::Axis(a),
            Basis::Harmonic(_) | Basis::Poly(_) | Basis::Period(_) | Basis::Step(_),
        ) => Some(a),
        _ => None,
    }
}

/// `true` for a term of time (`time:K`, `rate`, `exp:TAU`, `warmup:TAU`).
pub fn is_time(t: &Term) -> bool {
    t.basis.of_time()
}

/// A position column and a time column of a plan and the correlation of their estimates.
#[derive(Clone, Debug, PartialEq)]
pub struct PositionTimePair {
    /// The position term's column (`EBB@harmonic:1:sin`).
    pub position: String,
    /// The time term's column (`BOC@rate[turn-B]`).
    pub time: String,
    /// The correlation of their estimates; ±1 when they are confounded.
    pub correlation: f64,
}

/// One candidate that may separate them, and what it leaves.
#[derive(Clone, Debug, PartialEq)]
pub struct SeparatingCandidate {
    /// Index into [`CandidateSet::candidates`].
    pub candidate: usize,
    /// The largest absolute correlation of a position term and a time term with it.
    pub largest: f64,
}

/// What the plan does not separate, and the addition that separates it best.
#[derive(Clone, Debug, PartialEq)]
pub struct Separation {
    /// The pairs at or above [`NEARLY_CONFOUNDED`] on the plan, largest first.
    pub pairs: Vec<PositionTimePair>,
    /// Every candidate evaluated, best (smallest largest correlation) first.
    pub candidates: Vec<SeparatingCandidate>,
}

impl Separation {
    /// The addition that separates them best, if any was evaluated.
    pub fn best(&self) -> Option<&SeparatingCandidate> {
        self.candidates.first()
    }
}

/// Every position column and time column of `p` with the correlation of their estimates
/// (undetermined columns only when confounded together: ±1), largest first.
fn pairs(m: &Machine, p: &Prediction) -> Vec<PositionTimePair> {
    let cols = &p.layout.columns;
    let together = |i: usize, k: usize| {
        p.confounded
            .iter()
            .any(|g| g.contains(&i) && g.contains(&k))
    };
    let mut out = Vec::new();
    for i in (0..cols.len()).filter(|&i| position_axis(m, &cols[i].term).is_some()) {
        for k in (0..cols.len()).filter(|&k| is_time(&cols[k].term)) {
            let correlation = if p.determined[i] && p.determined[k] {
                let c = &p.covariance;
                c[(i, k)] / (c[(i, i)] * c[(k, k)]).sqrt()
            } else if together(i, k) {
                1.0
            } else {
                continue;
            };
            if correlation.is_finite() {
                out.push(PositionTimePair {
                    position: p.names[i].clone(),
                    time: p.names[k].clone(),
                    correlation,
                });
            }
        }
    }
    out.sort_by(|a, b| b.correlation.abs().total_cmp(&a.correlation.abs()));
    out
}

/// The position terms and time terms of `model` that `plan` (predicted as `prediction` under
/// `noise`) does not separate, and its candidates of `set` in other orders of the planned tests
/// at the planned ball positions, each added on its own, best first; `None` when the plan
/// separates every such pair (or has none).
///
/// # Errors
/// A candidate plan that cannot be predicted.
pub fn separation(
    m: &Machine,
    model: &Model,
    plan: &Plan,
    prediction: &Prediction,
    set: &CandidateSet,
    noise: &NoiseModel,
    tol: &Tolerances,
) -> Result<Option<Separation>, PlanError> {
    let pairs: Vec<PositionTimePair> = pairs(m, prediction)
        .into_iter()
        .filter(|p| p.correlation.abs() >= NEARLY_CONFOUNDED)
        .collect();
    if pairs.is_empty() {
        return Ok(None);
    }
    let mut candidates = Vec::new();
    for (k, c) in set.candidates.iter().enumerate() {
        let Some(ball) = set.balls[c.ball].planned else {
            continue;
        };
        let Ok(spec) = plan.spec(m, &c.test) else {
            continue;
        };
        let planned_forward = |t: &PlannedTest| {
            plan.spec(m, &t.test).is_ok_and(|s| {
                let stem = &s.name[..s.name.len() - s.order.suffix().len()];
                let own = &spec.name[..spec.name.len() - spec.order.suffix().len()];
                stem == own && s.order != spec.order
            })
        };
        if spec.order == Order::Forward || !plan.tests.iter().any(planned_forward) {
            continue;
        }
        let mut with = plan.clone();
        with.tests.push(PlannedTest {
            test: c.test.clone(),
            ball,
        });
        let p = with.predict(m, model, noise, tol)?;
        let largest = super::separate::pairs(m, &p.prediction)
            .first()
            .map_or(0.0, |x| x.correlation.abs());
        candidates.push(SeparatingCandidate {
            candidate: k,
            largest,
        });
    }
    candidates.sort_by(|a, b| a.largest.total_cmp(&b.largest));
    Ok(Some(Separation { pairs, candidates }))
}
