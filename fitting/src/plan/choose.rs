//! The greedy choice: which single candidate, added to the plan, helps most.
//!
//! **Parameters of interest**: the machine's own parameters, the plan's shared columns
//! ([`Owner::Shared`]: errors of the machine, the same in every record); the set-up errors of
//! one mounting and the R-test's zero of one record are nuisances of that record. A model
//! without shared columns makes every column of interest.
//!
//! Every candidate is added to the plan on its own (as one more record: its own set-up, or the
//! set-up of its ball position with a shared set-up, and its own zero when the readings are
//! zeroed) and the campaign predicted again ([`Plan::predict`]). Its [`Score`]:
//!
//! 1. **separation**: how many parameters of interest the plan leaves undetermined and the
//!    plan with the candidate determines (more is better);
//! 2. **the largest uncertainty**: the largest predicted standard uncertainty among the
//!    parameters of interest determined with the candidate, relative to its [`Targets`] entry
//!    (`std / target`: µm against µm, µrad against µrad; smaller is better);
//! 3. **the sum** `Σ (std / target)²` over the same parameters (A-optimality in target units;
//!    smaller is better).
//!
//! Candidates are compared on 1, then 2, then 3; values within a relative
//! [`EQUAL_RELATIVE`] of each other count as equal (they are computed with rounding), and
//! candidates equal on all three keep their order (positions × tests). The ranking lists every
//! candidate, best first.

use super::candidates::CandidateSet;
use super::predict::Prediction;
use super::update::{Information, Outcome};
use super::{Plan, PlanError, Predicted};
use crate::campaign::Owner;
use crate::campaign::design::design_matrix;
use crate::least_squares::Tolerances;
use formats::progress::{Progress, Unwatched};
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::Model;
use std::cmp::Ordering;

/// Two scores closer than this, relative to the larger, count as equal.
pub const EQUAL_RELATIVE: f64 = 1e-9;

/// The label of the candidate record in the plan it is added to.
pub const CANDIDATE_LABEL: &str = "candidate";

/// The uncertainty each kind of parameter is measured against: a predicted standard
/// uncertainty `std` counts as `std / target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Targets {
    /// Translational errors, set-up errors and sensor offsets, µm.
    pub um: f64,
    /// Angular errors, µrad.
    pub urad: f64,
    /// Servo lags of `velocity` terms, ms.
    pub ms: f64,
}

impl Default for Targets {
    /// 1 µm, 5 µrad (1 µm at the tool point over a 200 mm lever, the usual distance between
    /// an R-test ball and the rotary axes), 0.1 ms (1 µm at 10 mm/s).
    fn default() -> Self {
        Targets {
            um: 1.0,
            urad: 5.0,
            ms: 0.1,
        }
    }
}

impl Targets {
    /// The target of a parameter whose unit is `unit` (`um`, `urad`, `ms`; 1 for a unit-free
    /// term).
    pub fn of(&self, unit: &str) -> f64 {
        match unit {
            "um" => self.um,
            "urad" => self.urad,
            "ms" => self.ms,
            _ => 1.0,
        }
    }

    /// Checks that every target is a finite number above 0.
    ///
    /// # Errors
    /// [`PlanError::Plan`] naming the first that is not.
    pub fn check(&self) -> Result<(), PlanError> {
        for (x, unit) in [(self.um, "µm"), (self.urad, "µrad"), (self.ms, "ms")] {
            if !(x.is_finite() && x > 0.0) {
                return Err(PlanError::Plan(format!(
                    "the target uncertainty in {unit} is {x}; it must be a finite number above 0"
                )));
            }
        }
        Ok(())
    }
}

/// The largest predicted uncertainty among the parameters of interest, against its target.
#[derive(Clone, Debug, PartialEq)]
pub struct Largest {
    /// The parameter.
    pub name: String,
    /// Its predicted standard uncertainty in `unit`.
    pub std: f64,
    /// `um`, `urad` or `ms`.
    pub unit: String,
    /// `std / target`.
    pub relative: f64,
}

/// What a plan (with or without a candidate) gives on the parameters of interest.
#[derive(Clone, Debug, PartialEq)]
pub struct Score {
    /// The parameters of interest the plan alone leaves undetermined and this one determines.
    pub newly_determined: Vec<String>,
    /// Rank of the column-scaled H.
    pub rank: usize,
    /// Columns (parameters).
    pub columns: usize,
    /// The parameters of interest determined.
    pub determined: usize,
    /// The largest uncertainty against its target, among the determined parameters of
    /// interest; `None` when none is determined.
    pub largest: Option<Largest>,
    /// `Σ (std / target)²` over the determined parameters of interest.
    pub sum_squares: f64,
}

/// One candidate and its score.
#[derive(Clone, Debug, PartialEq)]
pub struct Ranked {
    /// Index into [`CandidateSet::candidates`].
    pub candidate: usize,
    /// Its score.
    pub score: Score,
}

/// The suggestion: the plan's own score and every candidate ranked, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct Suggestion {
    /// The parameters of interest (names).
    pub interest: Vec<String>,
    /// The plan's own score (nothing newly determined).
    pub baseline: Score,
    /// Every candidate, best first.
    pub ranking: Vec<Ranked>,
}

impl Suggestion {
    /// The best single addition, if there is a candidate.
    pub fn best(&self) -> Option<&Ranked> {
        self.ranking.first()
    }
}

/// The parameters of interest of `p`: its shared columns, or every column when it has none.
pub fn interest(p: &Prediction) -> Vec<usize> {
    let shared: Vec<usize> = (0..p.names.len())
        .filter(|&j| p.owner(j) == Owner::Shared)
        .collect();
    if shared.is_empty() {
        (0..p.names.len()).collect()
    } else {
        shared
    }
}

/// The score of the plan with a candidate (`after`, its [`Outcome`] on the columns of interest
/// `wanted` of the plan's prediction `before`) against the plan (see the module
/// documentation); units and factors of `m`.
pub fn score(
    m: &Machine,
    before: &Prediction,
    after: &Outcome,
    wanted: &[usize],
    targets: &Targets,
) -> Score {
    let mut newly = Vec::new();
    let mut largest: Option<Largest> = None;
    let mut sum = 0.0;
    let mut determined = 0;
    for (&j, std) in wanted.iter().zip(&after.std) {
        let Some(std) = *std else { continue };
        let name = &before.names[j];
        determined += 1;
        if !before.determined[j] {
            newly.push(name.clone());
        }
        let term = &before.layout.columns[j].term;
        let unit = term.unit(m);
        let shown = std * term.display_factor(m);
        let relative = shown / targets.of(unit);
        sum += relative * relative;
        if largest.as_ref().is_none_or(|l| relative > l.relative) {
            largest = Some(Largest {
                name: name.clone(),
                std: shown,
                unit: unit.to_string(),
                relative,
            });
        }
    }
    Score {
        newly_determined: newly,
        rank: after.rank,
        columns: after.columns,
        determined,
        largest,
        sum_squares: sum,
    }
}

/// The plan's own outcome: its rank, columns and the uncertainties of the columns `wanted`.
fn own(p: &Prediction, wanted: &[usize]) -> Outcome {
    Outcome {
        rank: p.rank,
        columns: p.names.len(),
        std: wanted
            .iter()
            .map(|&j| if p.determined[j] { p.std[j] } else { None })
            .collect(),
    }
}

/// `a` against `b` with values within [`EQUAL_RELATIVE`] equal.
fn close_cmp(a: f64, b: f64) -> Ordering {
    if (a - b).abs() <= EQUAL_RELATIVE * a.abs().max(b.abs()) {
        Ordering::Equal
    } else {
        a.total_cmp(&b)
    }
}

/// The order of two scores: `Less` when `a` is the better addition (see the module
/// documentation).
pub fn compare(a: &Score, b: &Score) -> Ordering {
    let relative = |s: &Score| s.largest.as_ref().map_or(f64::INFINITY, |l| l.relative);
    b.newly_determined
        .len()
        .cmp(&a.newly_determined.len())
        .then_with(|| match (relative(a), relative(b)) {
            (x, y) if x.is_infinite() || y.is_infinite() => x.total_cmp(&y),
            (x, y) => close_cmp(x, y),
        })
        .then_with(|| close_cmp(a.sum_squares, b.sum_squares))
}

/// Every candidate of `set` added on its own to `plan` as `predicted` (its campaign, design
/// and prediction, [`Plan::predict`]), predicted under the same noise with `tol`, scored
/// against `targets` and ranked (see the module documentation). A candidate is zeroed as the
/// plan is, on its own set-up or, with [`Plan::shared_setup`], on its ball position's. The
/// candidates at one ball position have their design matrix computed together
/// ([`design_matrix`], one gain source per position).
///
/// # Errors
/// Bad targets; a design or prediction that fails (a failed computation).
pub fn suggest(
    m: &Machine,
    model: &Model,
    plan: &Plan,
    predicted: &Predicted,
    set: &CandidateSet,
    targets: &Targets,
    tol: &Tolerances,
) -> Result<Suggestion, PlanError> {
    suggest_with_progress(m, model, plan, predicted, set, targets, tol, &Unwatched)
}

/// [`suggest`], telling `progress` of every candidate predicted (`candidates`, done of the
/// number of candidates).
///
/// # Errors
/// As [`suggest`].
#[allow(clippy::too_many_arguments)]
pub fn suggest_with_progress(
    m: &Machine,
    model: &Model,
    plan: &Plan,
    predicted: &Predicted,
    set: &CandidateSet,
    targets: &Targets,
    tol: &Tolerances,
    progress: &dyn Progress,
) -> Result<Suggestion, PlanError> {
    targets.check()?;
    let total = set.candidates.len() as u64;
    progress.update("candidates", 0, total);
    let before = &predicted.prediction;
    let layout = &predicted.design.layout;
    let wanted = interest(before);
    let names: Vec<String> = wanted.iter().map(|&j| before.names[j].clone()).collect();
    let baseline = score(m, before, &own(before, &wanted), &wanted, targets);
    // With a shared set-up, a candidate at a planned ball position is measured on that
    // position's set-up: it joins the plan's group of that set-up.
    let joins = |ball: usize| -> Option<usize> {
        let planned = set.balls[ball].planned?;
        let name = &plan.balls[planned].name;
        plan.shared_setup
            .then(|| layout.setups.iter().position(|s| s == name))
            .flatten()
    };
    let joinable: Vec<bool> = (0..layout.setups.len())
        .map(|s| (0..set.balls.len()).any(|b| joins(b) == Some(s)))
        .collect();
    let information = Information::new(
        &predicted.design,
        wanted.clone(),
        &joinable,
        &before.noise,
        tol,
    )?;
    let mut ranking = Vec::with_capacity(set.candidates.len());
    for b in 0..set.balls.len() {
        let at: Vec<usize> = (0..set.candidates.len())
            .filter(|&c| set.candidates[c].ball == b)
            .collect();
        if at.is_empty() {
            continue;
        }
        let setup = |label: String| {
            if plan.shared_setup {
                set.balls[b].name.clone()
            } else {
                label
            }
        };
        let batch = Campaign::new(
            at.iter()
                .enumerate()
                .map(|(k, &c)| {
                    let label = format!("{CANDIDATE_LABEL}.{k}");
                    CampaignRecord::new(
                        label.clone(),
                        set.candidates[c].record.clone(),
                        set.balls[b].params.clone(),
                        setup(label),
                        plan.zeroed,
                    )
                })
                .collect(),
        )
        .map_err(|e| PlanError::Plan(format!("the candidates: {e}")))?;
        let batch_design = design_matrix(m, model, &batch)?;
        for (k, &c) in at.iter().enumerate() {
            let after = information.outcome(&batch_design, k, joins(b))?;
            ranking.push(Ranked {
                candidate: c,
                score: score(m, before, &after, &wanted, targets),
            });
            progress.update("candidates", ranking.len() as u64, total);
        }
    }
    ranking.sort_by_key(|r| r.candidate);
    Ok(Suggestion {
        interest: names,
        baseline,
        ranking: ranked(ranking),
    })
}

/// `items` in order of [`compare`], best first, equal ones in their given order: an insertion
/// sort, which needs no total order (equality within a tolerance is not transitive).
fn ranked(items: Vec<Ranked>) -> Vec<Ranked> {
    let mut out: Vec<Ranked> = Vec::with_capacity(items.len());
    for r in items {
        let at = out
            .iter()
            .position(|o| compare(&r.score, &o.score) == Ordering::Less)
            .unwrap_or(out.len());
        out.insert(at, r);
    }
    out
}
