//! The plan report (`rtest plan --json`): what a planned campaign will determine and the
//! single addition that helps most (docs/plan.md).
//!
//! ```json
//! {"machine": "seed-ac", "fingerprint": "fa038fe9e24c960a", "model": "reduced", "terms": ["XOW", …],
//!  "noise": {"sigma_um": [0.5, 0.5, 0.5], "phi": [0.0, 0.0, 0.0],
//!            "text": "white, σ = 0.50 µm (x, y, z), declared"},
//!  "zeroed": false, "shared_setup": false, "ball_symbols": ["Xw", "Yw", "Zw"],
//!  "balls": [{"name": "base", "params_mm": {"Xa": 0.0, …, "Zp": 184.67}}],
//!  "records": [{"label": "K1", "test": "K1", "ball": "base", "setup": "K1", "samples": 361}],
//!  "parameters": [{"name": "YOA", "error": "YOA", "basis": "const", "owner": "shared",
//!                  "unit": "um", "determined": false, "std": null}, …,
//!                 {"name": "AOC", …, "determined": true, "std": 0.17134291229456736}, …],
//!  "rank": 7, "columns": 11, "condition": 3.4624256067636026,
//!  "confounded": [["YOA", "YOC"], ["ZOA", "ZOW[K1]"], ["BOA", "XOC", "BOC"],
//!                 ["COA", "XOW[K1]", "YOW[K1]"]],
//!  "targets": {"um": 1.0, "urad": 5.0, "ms": 0.1},
//!  "largest": {"parameter": "AOC", "std": 0.17134291229456736, "unit": "urad", …},
//!  "suggestion": {"criterion": "…", "interest": ["YOA", …], "step_mm": 100.0, "positions": […],
//!                 "evaluated": 40,
//!                 "ranking": [{"place": 1, "test": "K4", "ball": "base.Yw+100",
//!                              "paths_item": "K4:base.Yw+100", "samples": 241,
//!                              "ball_arg": "base.Yw+100:Yw=99.721",
//!                              "newly_determined": ["YOA", "ZOA", "BOA", "COA", "XOC", "YOC", "BOC"],
//!                              "rank": 14, "columns": 14, …}, …],
//!                 "skipped": [{"test": "K4", "ball": "base.Zw+100", "reason": "test K4, sample 170 of 241 …"}, …]}}
//! ```
//!
//! `std` (µm, µrad or ms) is `null` where the plan does not determine the parameter, and the
//! parameter is named in `confounded`; `condition` is `null` when the rank is 0; `largest` is
//! `null` when no parameter of interest is determined. Every number is finite.

use super::identify::{NearPairReport, poly_stroke};
use super::{NonFinite, Ordered, finite, finite_opt};
use fitting::plan::choose::{Largest, Score, Suggestion, Targets};
use fitting::plan::separate::{NEARLY_CONFOUNDED, Separation};
use fitting::plan::{CandidateSet, Plan, PlannedCampaign, Prediction, ball_symbols};
use model_spec::Machine;
use model_spec::units::{UM_PER_MM, short};
use serde::Serialize;
use simulation::model::Model;

/// The reading noise the prediction assumes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanNoiseReport {
    /// Marginal standard deviation of one reading, per direction x, y, z, µm.
    pub sigma_um: [f64; 3],
    /// Lag-1 autocorrelation per direction (0: white).
    pub phi: [f64; 3],
    /// The model for people.
    pub text: String,
}

/// A ball position: its name and every kinematic parameter, mm.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BallReport {
    /// Its name (`base`, `high`, `base.Zw+100`).
    pub name: String,
    /// Every kinematic parameter, mm, in the machine's symbol order.
    pub params_mm: Ordered<f64>,
}

/// A planned record.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlannedRecordReport {
    /// Its label (names its own parameters: `dx0[K4]`).
    pub label: String,
    /// The test.
    pub test: String,
    /// Its ball position's name.
    pub ball: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its samples.
    pub samples: usize,
}

/// One parameter (column) of the planned campaign.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlannedParameterReport {
    /// Its name (`XOC`, `XOW[K4]`, `dx0[K1]`, `ECC@harmonic:2:cos`).
    pub name: String,
    /// The effect (`XOC`, `dx0`).
    pub error: String,
    /// The basis column (`const`, `harmonic:2:cos`, …).
    pub basis: String,
    /// Whose parameter it is: `shared` (the machine's), or the label of its set-up or record.
    pub owner: String,
    /// `um`, `urad` or `ms`.
    pub unit: String,
    /// Whether the plan determines it.
    pub determined: bool,
    /// Its predicted standard uncertainty, in `unit`; `null` when the plan does not determine
    /// it.
    pub std: Option<f64>,
    /// For a `poly:K` column: the stroke its polynomial is normalised over, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub over_mm: Option<[f64; 2]>,
}

/// The targets the uncertainties are measured against.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetsReport {
    /// µm.
    pub um: f64,
    /// µrad.
    pub urad: f64,
    /// ms.
    pub ms: f64,
}

/// The largest predicted uncertainty among the parameters of interest.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LargestReport {
    /// The parameter.
    pub parameter: String,
    /// Its predicted standard uncertainty, in `unit`.
    pub std: f64,
    /// `um`, `urad` or `ms`.
    pub unit: String,
    /// `std` divided by the target of its unit.
    pub relative: f64,
}

/// A moved candidate position: from which planned position, along which symbol, by how much.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MoveReport {
    /// The planned position it is moved from.
    pub from: String,
    /// The ball symbol moved.
    pub symbol: String,
    /// The step, mm (signed).
    pub step_mm: f64,
}

/// A candidate ball position.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CandidateBallReport {
    /// Its name.
    pub name: String,
    /// `true` for a position of the plan.
    pub planned: bool,
    /// How it is moved from a planned position; absent for a planned one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moved: Option<MoveReport>,
    /// Every kinematic parameter, mm.
    pub params_mm: Ordered<f64>,
}

/// A candidate and what adding it gives.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CandidateReport {
    /// Its place in the ranking, from 1.
    pub place: usize,
    /// The test.
    pub test: String,
    /// Its ball position's name.
    pub ball: String,
    /// The item to add to `--paths` (`K2`, `K2:high`).
    pub paths_item: String,
    /// Its samples (as generated: a longer test brings more readings).
    pub samples: usize,
    /// The `--ball` argument that defines a position the plan does not have
    /// (`base.Zw+100:Zw=311.537`); absent for a planned position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ball_arg: Option<String>,
    /// The parameters of interest it determines that the plan alone does not.
    pub newly_determined: Vec<String>,
    /// Rank of the plan with it.
    pub rank: usize,
    /// Columns of the plan with it.
    pub columns: usize,
    /// Parameters of interest determined with it.
    pub determined: usize,
    /// The largest uncertainty among the determined parameters of interest with it.
    pub largest: Option<LargestReport>,
    /// `Σ (std / target)²` over the determined parameters of interest.
    pub sum_squares: f64,
}

/// A candidate the generator refuses.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkippedReport {
    /// The test.
    pub test: String,
    /// Its ball position's name.
    pub ball: String,
    /// The generator's reason.
    pub reason: String,
}

/// The suggestion.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SuggestionReport {
    /// The criterion, for people.
    pub criterion: String,
    /// The parameters of interest.
    pub interest: Vec<String>,
    /// The step the candidate positions are moved by, mm.
    pub step_mm: f64,
    /// The candidate ball positions.
    pub positions: Vec<CandidateBallReport>,
    /// Candidates evaluated.
    pub evaluated: usize,
    /// Every evaluated candidate, best first.
    pub ranking: Vec<CandidateReport>,
    /// The candidates the generator refuses, with the reason.
    pub skipped: Vec<SkippedReport>,
}

/// A position column and a time column whose estimates the plan does not separate.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PositionTimeReport {
    /// The position term's column (`EBB@harmonic:1:sin`).
    pub position: String,
    /// The time term's column (`BOC@time:1[turn-B]`).
    pub time: String,
    /// The correlation of their estimates (±1: confounded).
    pub correlation: f64,
}

/// A reversed or there-and-back candidate and the largest correlation it leaves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeparatingReport {
    /// The test (`turn-B-back`).
    pub test: String,
    /// Its ball position's name.
    pub ball: String,
    /// The item to add to `--paths`.
    pub paths_item: String,
    /// The largest absolute correlation of a position term and a time term with it.
    pub largest_correlation: f64,
}

/// What the plan does not separate of position and time, and what separates it
/// ([`fitting::plan::separate`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeparationReport {
    /// The least absolute correlation counted as not separated.
    pub threshold: f64,
    /// The pairs at or above it, largest first.
    pub pairs: Vec<PositionTimeReport>,
    /// The reversed and there-and-back candidates, best first.
    pub candidates: Vec<SeparatingReport>,
}

/// The plan report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanReport {
    /// Machine name.
    pub machine: String,
    /// The machine's fingerprint.
    pub fingerprint: String,
    /// The model's label (`reduced`, `reduced + EXX@poly:1`).
    pub model: String,
    /// The machine's model it starts from; absent for a list of terms only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_model: Option<String>,
    /// The terms, in order.
    pub terms: Vec<String>,
    /// The reading noise assumed.
    pub noise: PlanNoiseReport,
    /// Readings zeroed at each record's first sample (each record's `dx0 dy0 dz0` fitted).
    pub zeroed: bool,
    /// Records at one ball position share one set-up.
    pub shared_setup: bool,
    /// The symbols of the ball's position (those of the work chain's end offset).
    pub ball_symbols: Vec<String>,
    /// The planned ball positions.
    pub balls: Vec<BallReport>,
    /// The planned records.
    pub records: Vec<PlannedRecordReport>,
    /// Samples over all records.
    pub samples: usize,
    /// Readings (3 per sample).
    pub readings: usize,
    /// Every parameter, in the campaign's column order.
    pub parameters: Vec<PlannedParameterReport>,
    /// Numerical rank of the column-scaled H.
    pub rank: usize,
    /// Columns (parameters).
    pub columns: usize,
    /// Condition number of the column-scaled H; `null` when the rank is 0.
    pub condition: Option<f64>,
    /// Groups the plan cannot separate.
    pub confounded: Vec<Vec<String>>,
    /// Determined pairs whose estimates would correlate beyond 0.99.
    pub near_confounded: Vec<NearPairReport>,
    /// The targets.
    pub targets: TargetsReport,
    /// The largest predicted uncertainty among the parameters of interest.
    pub largest: Option<LargestReport>,
    /// The suggestion.
    pub suggestion: SuggestionReport,
    /// A position term and a time term the plan does not separate, and the reversed or
    /// there-and-back test that separates them; absent when there is none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub separation: Option<SeparationReport>,
}

/// What a plan report is made of.
#[derive(Clone, Copy, Debug)]
pub struct PlanSource<'a> {
    /// The model's label.
    pub label: &'a str,
    /// The machine's model it starts from, if any.
    pub base_model: Option<&'a str>,
    /// The model.
    pub model: &'a Model,
    /// The plan.
    pub plan: &'a Plan,
    /// The plan as a campaign.
    pub planned: &'a PlannedCampaign,
    /// The prediction.
    pub prediction: &'a Prediction,
    /// The candidates.
    pub candidates: &'a CandidateSet,
    /// The suggestion.
    pub suggestion: &'a Suggestion,
    /// The targets.
    pub targets: &'a Targets,
    /// What the plan does not separate of position and time, if anything.
    pub separation: Option<&'a Separation>,
}

/// The criterion, for people.
pub const CRITERION: &str = "first the most parameters of interest newly determined; then the smallest largest predicted uncertainty relative to its target; then the smallest sum of (std/target)^2";

/// Every kinematic parameter of `params` by symbol name, mm.
fn params_mm(m: &Machine, params: &[f64], field: &str) -> Result<Ordered<f64>, NonFinite> {
    m.symbols
        .iter()
        .zip(params)
        .map(|(s, &x)| Ok((s.name.clone(), finite(|| format!("{field}.{}", s.name), x)?)))
        .collect::<Result<Vec<_>, _>>()
        .map(Ordered)
}

fn largest_report(l: &Option<Largest>, field: &str) -> Result<Option<LargestReport>, NonFinite> {
    l.as_ref()
        .map(|l| {
            Ok(LargestReport {
                parameter: l.name.clone(),
                std: finite(|| format!("{field}.std"), l.std)?,
                unit: l.unit.clone(),
                relative: finite(|| format!("{field}.relative"), l.relative)?,
            })
        })
        .transpose()
}

/// `NAME:SYMBOL=VALUE,…` for `--ball`: the symbols where `params` differ from `base` (mm, at
/// most six decimals).
pub fn ball_arg(m: &Machine, name: &str, params: &[f64], base: &[f64]) -> String {
    let set: Vec<String> = m
        .symbols
        .iter()
        .enumerate()
        .filter(|&(s, _)| params[s] != base[s])
        .map(|(s, sym)| format!("{}={}", sym.name, short(params[s])))
        .collect();
    format!("{name}:{}", set.join(","))
}

impl PlanReport {
    /// The report of `source` on machine `m`.
    ///
    /// # Errors
    /// [`NonFinite`] when a number is not finite.
    pub fn new(m: &Machine, source: PlanSource) -> Result<PlanReport, NonFinite> {
        let p = source.prediction;
        let plan = source.plan;
        let mut parameters = Vec::with_capacity(p.names.len());
        for (j, c) in p.layout.columns.iter().enumerate() {
            let f = c.term.display_factor(m);
            let names = c.term.basis.column_names();
            parameters.push(PlannedParameterReport {
                name: p.names[j].clone(),
                error: c.term.effect.name(m),
                basis: names.get(c.component).unwrap_or(&names[0]).clone(),
                owner: p.layout.owner_label(c.owner).to_string(),
                unit: c.term.unit(m).to_string(),
                determined: p.determined[j],
                std: finite_opt(
                    || format!("parameters[{j}].std"),
                    p.std[j].filter(|_| p.determined[j]).map(|s| s * f),
                )?,
                over_mm: poly_stroke(m, &c.term),
            });
        }
        let name = |j: usize| p.names[j].clone();
        let set = source.candidates;
        let base = &plan.balls[0].params;
        let candidate = |place: usize, s: &Score, c: usize| -> Result<CandidateReport, NonFinite> {
            let cand = &set.candidates[c];
            let ball = &set.balls[cand.ball];
            let field = format!("suggestion.ranking[{}]", place - 1);
            Ok(CandidateReport {
                place,
                test: cand.test.clone(),
                ball: ball.name.clone(),
                paths_item: fitting::plan::record_label(&cand.test, &ball.name),
                samples: cand.record.samples.len(),
                ball_arg: ball
                    .planned
                    .is_none()
                    .then(|| ball_arg(m, &ball.name, &ball.params, base)),
                newly_determined: s.newly_determined.clone(),
                rank: s.rank,
                columns: s.columns,
                determined: s.determined,
                largest: largest_report(&s.largest, &format!("{field}.largest"))?,
                sum_squares: finite(|| format!("{field}.sum_squares"), s.sum_squares)?,
            })
        };
        let ranking = source
            .suggestion
            .ranking
            .iter()
            .enumerate()
            .map(|(i, r)| candidate(i + 1, &r.score, r.candidate))
            .collect::<Result<Vec<_>, _>>()?;
        let positions = set
            .balls
            .iter()
            .enumerate()
            .map(|(i, b)| {
                Ok(CandidateBallReport {
                    name: b.name.clone(),
                    planned: b.planned.is_some(),
                    moved: b.moved.map(|(from, s, step)| MoveReport {
                        from: plan.balls[from].name.clone(),
                        symbol: m.symbols[s].name.clone(),
                        step_mm: step,
                    }),
                    params_mm: params_mm(
                        m,
                        &b.params,
                        &format!("suggestion.positions[{i}].params_mm"),
                    )?,
                })
            })
            .collect::<Result<Vec<_>, NonFinite>>()?;
        let noise = &p.noise;
        let mut sigma_um = [0.0; 3];
        for (d, s) in sigma_um.iter_mut().enumerate() {
            *s = finite(
                || format!("noise.sigma_um[{d}]"),
                noise.sigma_mm[d] * UM_PER_MM,
            )?;
        }
        let separation = source
            .separation
            .map(|sep| -> Result<SeparationReport, NonFinite> {
                Ok(SeparationReport {
                    threshold: NEARLY_CONFOUNDED,
                    pairs: sep
                        .pairs
                        .iter()
                        .map(|p| {
                            Ok(PositionTimeReport {
                                position: p.position.clone(),
                                time: p.time.clone(),
                                correlation: finite(
                                    || "separation.pairs.correlation".into(),
                                    p.correlation,
                                )?,
                            })
                        })
                        .collect::<Result<_, NonFinite>>()?,
                    candidates: sep
                        .candidates
                        .iter()
                        .map(|c| {
                            let cand = &source.candidates.candidates[c.candidate];
                            let ball = &source.candidates.balls[cand.ball].name;
                            Ok(SeparatingReport {
                                test: cand.test.clone(),
                                ball: ball.clone(),
                                paths_item: fitting::plan::record_label(&cand.test, ball),
                                largest_correlation: finite(
                                    || "separation.candidates.largest_correlation".into(),
                                    c.largest,
                                )?,
                            })
                        })
                        .collect::<Result<_, NonFinite>>()?,
                })
            })
            .transpose()?;
        Ok(PlanReport {
            separation,
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            model: source.label.to_string(),
            base_model: source.base_model.map(str::to_string),
            terms: source.model.terms.iter().map(|t| t.spelling(m)).collect(),
            noise: PlanNoiseReport {
                sigma_um,
                phi: noise.phi,
                text: noise.to_string(),
            },
            zeroed: plan.zeroed,
            shared_setup: plan.shared_setup,
            ball_symbols: ball_symbols(m)
                .into_iter()
                .map(|s| m.symbols[s].name.clone())
                .collect(),
            balls: plan
                .balls
                .iter()
                .enumerate()
                .map(|(i, b)| {
                    Ok(BallReport {
                        name: b.name.clone(),
                        params_mm: params_mm(m, &b.params, &format!("balls[{i}].params_mm"))?,
                    })
                })
                .collect::<Result<Vec<_>, NonFinite>>()?,
            records: source
                .planned
                .records
                .iter()
                .map(|r| PlannedRecordReport {
                    label: r.label.clone(),
                    test: r.test.clone(),
                    ball: plan.balls[r.ball].name.clone(),
                    setup: r.setup.clone(),
                    samples: r.samples,
                })
                .collect(),
            samples: p.samples,
            readings: 3 * p.samples,
            parameters,
            rank: p.rank,
            columns: p.names.len(),
            condition: finite_opt(|| "condition".into(), p.condition)?,
            confounded: p
                .confounded
                .iter()
                .map(|g| g.iter().map(|&j| name(j)).collect())
                .collect(),
            near_confounded: p
                .near_confounded
                .iter()
                .map(|q| {
                    Ok(NearPairReport {
                        parameters: [name(q.a), name(q.b)],
                        correlation: finite(
                            || "near_confounded.correlation".into(),
                            q.correlation,
                        )?,
                    })
                })
                .collect::<Result<_, NonFinite>>()?,
            targets: TargetsReport {
                um: source.targets.um,
                urad: source.targets.urad,
                ms: source.targets.ms,
            },
            largest: largest_report(&source.suggestion.baseline.largest, "largest")?,
            suggestion: SuggestionReport {
                criterion: CRITERION.to_string(),
                interest: source.suggestion.interest.clone(),
                step_mm: set.step_mm,
                positions,
                evaluated: ranking.len(),
                ranking,
                skipped: set
                    .skipped
                    .iter()
                    .map(|s| SkippedReport {
                        test: s.test.clone(),
                        ball: set.balls[s.ball].name.clone(),
                        reason: s.reason.clone(),
                    })
                    .collect(),
            },
        })
    }
}
