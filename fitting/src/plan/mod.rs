//! Measurement plans: what a planned campaign will determine, before anything is measured.
//!
//! A **plan** is a list of R-test tests of the machine's generator
//! ([`simulation::generator`]), each at a **ball position** (a set of kinematic
//! parameters, mm: the ball's offset symbols among them). Each planned test becomes a record of
//! a [`Campaign`] with its generated poses and no readings; every record is, as in a campaign
//! fit, its own ball set-up (`XOW YOW ZOW` of its own) with its own R-test zero when the
//! readings will be zeroed, unless the plan shares one set-up per ball position
//! ([`Plan::shared_setup`]).
//!
//! - [`mod@predict`]: the campaign's design matrix ([`crate::campaign::design_matrix`],
//!   which needs no readings) and what a fit of it would give for a stated reading noise: rank,
//!   condition number, confounded groups, the predicted standard uncertainty of every
//!   determined parameter;
//! - [`candidates`]: the single additions considered: every test of the generator at every
//!   planned ball position and at positions moved from them by a fixed step along the ball's
//!   offset symbols, each generated and checked; those the generator refuses are skipped, with
//!   the reason;
//! - [`choose`]: the criterion and the ranking of the candidates, best first;
//! - [`separate`]: a position term of an axis and a time term the plan does not separate, and
//!   the reversed or there-and-back test that separates them;
//! - [`mod@probe`]: a touch-probe campaign: the probing poses per rotary axis, their readings'
//!   covariances from the sphere fit, their prediction and the valuation numbers
//!   (`docs/probe-plan.md`).
//!
//! `docs/plan.md` describes the method, the criterion and `rtest plan`.

pub mod candidates;
pub mod choose;
pub mod predict;
pub mod probe;
pub mod separate;
pub mod update;

use crate::campaign::design::{Design, design_matrix};
use crate::least_squares::Tolerances;
use crate::noise::NoiseModel;
pub use candidates::{
    Candidate, CandidateBall, CandidateSet, MAX_CANDIDATES, Skipped, ball_symbols,
};
pub use choose::{Largest, Ranked, Score, Suggestion, Targets, suggest, suggest_with_progress};
pub use predict::{Prediction, predict, predict_design};

use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::generator::{self, GeneratorError, GeneratorOptions, TestSpec};
use simulation::model::{Effect, Model};
use simulation::record::Record;

/// The name of the plan's first ball position: the kinematic parameters every test takes
/// unless it names another position.
pub const BASE_BALL: &str = "base";

/// A ball position: a name and the kinematic parameters it stands for.
#[derive(Clone, Debug, PartialEq)]
pub struct BallPosition {
    /// Its name: [`BASE_BALL`], or a letter followed by letters, digits and `_ - . +`.
    pub name: String,
    /// The kinematic parameters, mm, one per machine symbol (symbol order).
    pub params: Vec<f64>,
}

/// One planned test: a test of the generator at one of the plan's ball positions.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedTest {
    /// The test's name as the generator lists it (`K4`, `turn-C`, `pair-A-C`; any case).
    pub test: String,
    /// Index of its ball position in [`Plan::balls`].
    pub ball: usize,
}

/// A measurement plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The ball positions; the first is [`BASE_BALL`].
    pub balls: Vec<BallPosition>,
    /// The planned tests, in measuring order.
    pub tests: Vec<PlannedTest>,
    /// The readings will be zeroed at each record's first sample: every record's
    /// `dx0 dy0 dz0` join the fit.
    pub zeroed: bool,
    /// Records at the same ball position share one ball set-up (one mounting measured along
    /// several tests); otherwise every record is its own set-up.
    pub shared_setup: bool,
    /// How the tests are generated (step, sample period, clearance rule).
    pub generator: GeneratorOptions,
}

/// Why a plan cannot be made or predicted.
#[derive(Debug, thiserror::Error)]
pub enum PlanError {
    /// The plan itself is wrong (no test, a bad ball name, a model term a plan cannot predict).
    #[error("{0}")]
    Plan(String),
    /// The generator refuses a planned test at its ball position (the test and the sample are
    /// named).
    #[error("{test} at ball position `{ball}`: {error}")]
    Generator {
        /// The test as planned.
        test: String,
        /// The ball position's name.
        ball: String,
        /// What the generator says.
        error: GeneratorError,
    },
    /// The campaign's design matrix or its least squares failed.
    #[error(transparent)]
    Estimate(#[from] crate::EstimateError),
}

/// One record of a planned campaign: which test at which ball position, its label and set-up.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRecord {
    /// The record's label (names its own parameters, `dx0[K4]`): the test's name at
    /// [`BASE_BALL`], `TEST:BALL` elsewhere, with `.2`, `.3`, … appended to repeats.
    pub label: String,
    /// The test's name as the generator spells it.
    pub test: String,
    /// Index of its ball position in [`Plan::balls`].
    pub ball: usize,
    /// Its set-up's label: the ball position's name with [`Plan::shared_setup`], else the
    /// record's label.
    pub setup: String,
    /// Its samples (poses in mm and rad, times in s, no readings).
    pub samples: usize,
}

/// A plan made into a campaign: the records with their generated poses, and what each is.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedCampaign {
    /// The campaign (no readings), records in plan order.
    pub campaign: Campaign,
    /// What each record is, in the same order.
    pub records: Vec<PlannedRecord>,
}

/// A plan made into a campaign and predicted ([`Plan::predict`]).
#[derive(Clone, Debug)]
pub struct Predicted {
    /// The campaign and what each record is.
    pub planned: PlannedCampaign,
    /// Its design matrix.
    pub design: Design,
    /// Its prediction.
    pub prediction: Prediction,
}

/// The most tests a plan may hold. A campaign of some tens of records is a long day on the
/// machine; each planned test adds its rows to every candidate's prediction, so the limit
/// bounds the plan's time and memory.
pub const MAX_TESTS: usize = 50;

/// The longest name of a ball position, in characters: a record's label is `TEST:BALL`, and
/// with a test's name of at most 64 characters it stays within a label's 256
/// ([`simulation::campaign::MAX_LABEL_CHARS`]).
pub const MAX_BALL_NAME_CHARS: usize = 128;

/// `true` for a ball position's name: a letter, then letters, digits, `_`, `-`, `.` or `+`,
/// at most [`MAX_BALL_NAME_CHARS`] characters (the names of moved candidate positions,
/// `base.Zw+100`, are valid names).
pub fn valid_ball_name(name: &str) -> bool {
    let mut c = name.chars();
    name.chars().count() <= MAX_BALL_NAME_CHARS
        && c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && c.all(|x| x.is_ascii_alphanumeric() || "_-.+".contains(x))
}

/// The label of a record of `test` at ball position `ball`: the test at [`BASE_BALL`],
/// `TEST:BALL` elsewhere.
pub fn record_label(test: &str, ball: &str) -> String {
    if ball == BASE_BALL {
        test.to_string()
    } else {
        format!("{test}:{ball}")
    }
}

/// `label` made unique among `taken`: as it is, else with `.2`, `.3`, … appended.
fn unique(label: String, taken: &[PlannedRecord]) -> String {
    let free = |l: &str| !taken.iter().any(|r| r.label == l);
    if free(&label) {
        return label;
    }
    (2..)
        .map(|k| format!("{label}.{k}"))
        .find(|l| free(l))
        .unwrap_or(label)
}

/// Refuses the terms a plan cannot predict: instrument terms (`SXX` … `SZY`), whose columns
/// are the readings themselves, which a plan does not have.
///
/// # Errors
/// [`PlanError::Plan`] naming the term.
pub fn check_model(m: &Machine, model: &Model) -> Result<(), PlanError> {
    if let Some(t) = model
        .terms
        .iter()
        .find(|t| matches!(t.effect, Effect::Instrument { .. }))
    {
        return Err(PlanError::Plan(format!(
            "term `{}` is an instrument term: its column is made of the readings, which a plan does not have, so no plan can predict it; leave it out of the plan",
            t.spelling(m)
        )));
    }
    Ok(())
}

impl Plan {
    /// The test spec called `name` among the machine's tests under this plan's clearance rule
    /// (`T-rev` and `T-back` included).
    ///
    /// # Errors
    /// [`GeneratorError::NoRotaryAxis`] or [`GeneratorError::UnknownTest`] (listing the
    /// machine's tests).
    pub fn spec(&self, m: &Machine, name: &str) -> Result<TestSpec, GeneratorError> {
        let all = generator::tests_with(m, &self.generator.clearance);
        if all.is_empty() {
            return Err(GeneratorError::NoRotaryAxis {
                machine: m.name.clone(),
            });
        }
        generator::lookup_test(&all, name).ok_or_else(|| GeneratorError::UnknownTest {
            machine: m.name.clone(),
            name: name.trim().to_string(),
            tests: all.iter().map(|t| t.name.clone()).collect(),
        })
    }

    /// Checks the plan's shape: at least one test, the first ball position [`BASE_BALL`],
    /// ball names valid and unique, every test's ball index within the positions, every
    /// position used by a test or the base, one parameter per machine symbol.
    ///
    /// # Errors
    /// [`PlanError::Plan`] saying what is wrong.
    pub fn check(&self, m: &Machine) -> Result<(), PlanError> {
        let bad = |s: String| Err(PlanError::Plan(s));
        if self.tests.is_empty() {
            return bad("a plan needs at least one test".into());
        }
        if self.tests.len() > MAX_TESTS {
            return bad(format!(
                "{} tests, more than {MAX_TESTS}, the most a plan may have",
                self.tests.len()
            ));
        }
        match self.balls.first() {
            Some(b) if b.name == BASE_BALL => {}
            _ => return bad(format!("the first ball position must be `{BASE_BALL}`")),
        }
        for (i, b) in self.balls.iter().enumerate() {
            if i > 0 && (b.name == BASE_BALL || !valid_ball_name(&b.name)) {
                return bad(format!(
                    "ball position name `{}`: a letter, then letters, digits, `_`, `-`, `.` or `+`, at most {MAX_BALL_NAME_CHARS} characters, and not `{BASE_BALL}` (the position of the plan's own parameters)",
                    model_spec::text::quoted_start(&b.name)
                ));
            }
            if self.balls[..i].iter().any(|o| o.name == b.name) {
                return bad(format!("ball position `{}` is given twice", b.name));
            }
            if b.params.len() != m.symbols.len() {
                return bad(format!(
                    "ball position `{}` has {} kinematic parameters for the {} symbols of machine {}",
                    b.name,
                    b.params.len(),
                    m.symbols.len(),
                    m.name
                ));
            }
            if i > 0 && !self.tests.iter().any(|t| t.ball == i) {
                return bad(format!(
                    "ball position `{}` is not used by any test (write TEST:{} in the test list)",
                    b.name, b.name
                ));
            }
        }
        if let Some(t) = self.tests.iter().find(|t| t.ball >= self.balls.len()) {
            return bad(format!(
                "test {} refers to ball position #{}, the plan has {}",
                t.test,
                t.ball,
                self.balls.len()
            ));
        }
        Ok(())
    }

    /// The set-up label of a record labelled `label` at ball position `ball` (a name).
    pub fn setup_of(&self, label: &str, ball: &str) -> String {
        if self.shared_setup {
            ball.to_string()
        } else {
            label.to_string()
        }
    }

    /// The plan as a campaign: every test generated at its ball position (each distinct test
    /// and position once), labelled and set up as [`PlannedRecord`] says.
    ///
    /// # Errors
    /// [`PlanError::Plan`] for a plan of the wrong shape ([`Plan::check`]);
    /// [`PlanError::Generator`] naming the test and the position when the generator refuses
    /// it (an unknown test, a sample out of a stroke or range or beyond the clearance rule,
    /// naming the sample).
    pub fn campaign(&self, m: &Machine) -> Result<PlannedCampaign, PlanError> {
        self.check(m)?;
        let mut generated: Vec<(String, usize, Record)> = Vec::new();
        let mut records: Vec<PlannedRecord> = Vec::new();
        let mut out: Vec<CampaignRecord> = Vec::new();
        for t in &self.tests {
            let ball = &self.balls[t.ball];
            let wrap = |error| PlanError::Generator {
                test: t.test.trim().to_string(),
                ball: ball.name.clone(),
                error,
            };
            let spec = self.spec(m, &t.test).map_err(wrap)?;
            let record = match generated
                .iter()
                .find(|(name, b, _)| *name == spec.name && *b == t.ball)
            {
                Some((_, _, r)) => r.clone(),
                None => {
                    let r = generator::generate_test(m, &spec, &ball.params, &self.generator)
                        .map_err(wrap)?;
                    generated.push((spec.name.clone(), t.ball, r.clone()));
                    r
                }
            };
            let label = unique(record_label(&spec.name, &ball.name), &records);
            let setup = self.setup_of(&label, &ball.name);
            records.push(PlannedRecord {
                label: label.clone(),
                test: spec.name.clone(),
                ball: t.ball,
                setup: setup.clone(),
                samples: record.samples.len(),
            });
            out.push(CampaignRecord::new(
                label,
                record,
                ball.params.clone(),
                setup,
                self.zeroed,
            ));
        }
        let campaign = Campaign::new(out)
            .map_err(|e| PlanError::Plan(format!("the planned campaign: {e}")))?;
        Ok(PlannedCampaign { campaign, records })
    }

    /// The plan of `model` of `m` made into a campaign ([`Plan::campaign`]), its design matrix
    /// and its prediction under the reading noise `noise` with the tolerances `tol`
    /// ([`predict_design`]).
    ///
    /// # Errors
    /// A model a plan cannot predict ([`check_model`]), what [`Plan::campaign`] refuses, a
    /// design or prediction that fails ([`PlanError::Estimate`]; too few readings for the
    /// parameters among them).
    pub fn predict(
        &self,
        m: &Machine,
        model: &Model,
        noise: &NoiseModel,
        tol: &Tolerances,
    ) -> Result<Predicted, PlanError> {
        check_model(m, model)?;
        let planned = self.campaign(m)?;
        let design = design_matrix(m, model, &planned.campaign)?;
        let prediction = predict_design(&design, noise, tol)?;
        Ok(Predicted {
            planned,
            design,
            prediction,
        })
    }
}
