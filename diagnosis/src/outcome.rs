//! What a diagnosis finds: the findings and what the data cannot see, the records and their
//! gain, the verdict; and the extended model as a machine description.

use super::structure::Component;
use super::{adequacy, confirm, heldout, outliers, profile, unexplained, verdict};
use fitting::campaign::CampaignIdentification;
use fitting::noise::NoiseModel;
use model_spec::Machine;
use model_spec::terms::Term;
use simulation::model::Model;

/// How the corrected p-value of a step was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Correction {
    /// `p·N` (conservative), decisive on its own.
    Bonferroni,
    /// The Monte-Carlo null of the selection rule (level α exactly under Gaussian noise).
    MonteCarlo,
}

/// One significant effect found.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// The term added to the model.
    pub term: Term,
    /// Its name for people (`ECC harmonic:2: angular positioning error of C, twice per revolution`).
    pub description: String,
    /// Candidates the data cannot tell from this one: those of the same span given the model,
    /// and those to which this one adds nothing significant (raw F-test at α: they explain what
    /// it explains, as far as the data can tell). The finding may be any of them.
    pub alternatives: Vec<Term>,
    /// Its value(s) in the extended model, mm or rad (`[cos, sin]` for a harmonic; ms for a
    /// velocity term, a fraction for an instrument term; one value per record or set-up for a
    /// term a record or set-up owns, in the order of the campaign's columns); `None` where the
    /// fit cannot determine it. For a finding left out of the extended model, its value(s)
    /// with every finding fitted together.
    pub values: Vec<Option<f64>>,
    /// Their standard uncertainties (same units).
    pub stds: Vec<Option<f64>>,
    /// Its size in the unit people see (µm, µrad, ms, 1): `|value|`, or the amplitude of a
    /// pair ([`super::plausible`]).
    pub size: f64,
    /// The budget of its unit it was compared with.
    pub limit: f64,
    /// `size ≤ limit`: a plausible cause. An implausible finding fits the data but is not
    /// named as a cause and is left out of the extended model.
    pub plausible: bool,
    /// What the held-out (or left-out) records say of it on its own: its held-out gain given
    /// the other findings, and whether they chose it among the alternatives; `None` when no
    /// record judged it (nothing held out and one record fitted) or it is implausible.
    pub confirmation: Option<confirm::Confirmation>,
    /// In the extended model: plausible and confirmed on its own, or plausible when no finding
    /// is confirmed (the extended model then holds every plausible finding and is not
    /// recommended).
    pub in_model: bool,
    /// For `period:P`, `step:V`, `exp:TAU`, `warmup:TAU`: the refined parameter and its 95 %
    /// interval ([`profile`]); the values' standard uncertainties are conditional on it.
    pub scan: Option<profile::Scan>,
    /// Share of the base model's residual sum of squares it explains beyond all the other
    /// findings (its step in the final exchange pass).
    pub explained_fraction: f64,
    /// The F statistic of that step (given all the other findings).
    pub f: f64,
    /// Its p-value corrected for the number of candidates tried.
    pub p_value: f64,
    /// How the correction was made.
    pub correction: Correction,
    /// Candidates tried at that step.
    pub candidates_tried: usize,
}

/// A candidate the model spans: the data cannot see it apart from what is already there.
#[derive(Clone, Debug, PartialEq)]
pub struct Confounded {
    /// The candidate.
    pub term: Term,
    /// The model's terms it is a combination of (largest share first).
    pub with: Vec<Term>,
}

/// What a step stopped on (the best candidate not significant), for the report.
#[derive(Clone, Debug, PartialEq)]
pub struct Stop {
    /// The best remaining candidate, if any.
    pub best: Option<Term>,
    /// Its corrected p-value.
    pub p_value: f64,
    /// Why the selection stopped, for people.
    pub reason: String,
}

/// A finding of the selection left out because the fit of the extended model with it did not
/// converge: the diagnosis goes on without it.
#[derive(Clone, Debug, PartialEq)]
pub struct Dropped {
    /// The term.
    pub term: Term,
    /// Why, for people (the refinement's failure).
    pub why: String,
}

/// One fitted record of a diagnosis.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordDiagnosis {
    /// Its label in the campaign.
    pub label: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its samples, outliers included.
    pub samples: usize,
    /// Whether its readings were zeroed at the first sample (its own `dx0 dy0 dz0` fitted).
    pub zeroed: bool,
    /// Its kinematic parameters, mm (symbol order).
    pub params: Vec<f64>,
    /// Isolated readings far outside the base residual's scale; their samples are left out of
    /// every fit and test (`sample` indexes the record as given).
    pub outliers: Vec<outliers::Outlier>,
    /// Its residual RMS under the base model and under the extended one (mm, outliers left
    /// out).
    pub rms: (f64, f64),
}

/// A diagnosis.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    /// The base model as given (without the offsets of zeroed readings).
    pub base_given: Model,
    /// The base model's terms as fitted: with `dx0 dy0 dz0` when a fitted record is zeroed.
    pub base: Model,
    /// The base model's fit on the fitted records (refined against the exact machine, outliers
    /// left out).
    pub base_fit: CampaignIdentification,
    /// The fitted records, in the campaign's order.
    pub records: Vec<RecordDiagnosis>,
    /// Residual structure of the base fit (the records one after the other), largest first.
    pub structure_before: Vec<Component>,
    /// Candidates in the dictionary.
    pub dictionary_size: usize,
    /// The findings, in the order they were added.
    pub findings: Vec<Finding>,
    /// The grouped candidates added after the findings ([`super::groups`]; only with
    /// [`super::DiagnoseOptions::groups`]): confirmed ones are in the extended model.
    pub groups: Vec<super::groups::GroupFinding>,
    /// Findings left out because the extended fit with them did not converge.
    pub dropped: Vec<Dropped>,
    /// Candidates spanned by the final model.
    pub confounded: Vec<Confounded>,
    /// Candidates that do not vary at all on the fitted paths.
    pub unexcited: Vec<Term>,
    /// Why the selection stopped.
    pub stop: Stop,
    /// The extended model as fitted: the base model as given plus the plausible findings (each
    /// zeroed record adds its own offsets).
    pub extended: Model,
    /// Its fit (refined).
    pub extended_fit: CampaignIdentification,
    /// Residual structure after the extension.
    pub structure_after: Vec<Component>,
    /// Residual RMS over the fitted records (outliers left out), before and after (mm).
    pub fit_rms: (f64, f64),
    /// Residual RMS of the base fit with the outliers in the fit, mm.
    pub fit_rms_with_outliers: f64,
    /// Per held-out record: the residual RMS before and after, what it needs that the fits do
    /// not determine, what was refitted on it, its outliers.
    pub validation: Vec<heldout::HeldOut>,
    /// With nothing held out and several records fitted: every fitted record predicted by the
    /// fits on the others, base and extended model (the rows the verdict judges); empty
    /// otherwise.
    pub left_out: Vec<heldout::HeldOut>,
    /// Whether the extended model is recommended, and why (not).
    pub recommendation: verdict::Recommendation,
    /// The noise model every test assumes (the readings and columns are whitened by it).
    pub noise: NoiseModel,
    /// The lack-of-fit test of the extended model's residual against the noise; `Err(why)`
    /// when there is no noise model independent of the fit (noise-free data, or ordinary least
    /// squares asked for).
    pub adequacy: Result<adequacy::Adequacy, String>,
    /// What remains in each direction the adequacy test finds inconsistent with the noise.
    pub unexplained: Vec<unexplained::Unexplained>,
    /// Position errors of axes and terms of time that the fitted records cannot tell apart (an
    /// axis that moves monotonically in time), with the tests that separate them
    /// ([`super::separable`]).
    pub position_or_time: Vec<super::separable::PositionOrTime>,
}

/// The verdict on the extension, the held-out records named `names` (one per record, in
/// order), under the noise the tests assume (φ raised when estimated), with σ the lack-of-fit
/// test's reference.
pub(super) fn recommend(
    findings: &[Finding],
    validation: &[heldout::HeldOut],
    adequacy: &Result<adequacy::Adequacy, String>,
    names: &[String],
) -> verdict::Recommendation {
    let noise = adequacy.as_ref().ok().map(|a| {
        let mut n = a.noise.clone();
        if let Some(r) = a.records.first() {
            n.sigma_mm = r.noise_sigma_mm;
        }
        n
    });
    let consistent = adequacy.as_ref().ok().map(|a| a.consistent_with_noise);
    verdict::recommend(findings, validation, names, noise.as_ref(), consistent)
}

impl Finding {
    /// Confirmed on its own by the held-out (or left-out) records.
    pub fn confirmed(&self) -> bool {
        self.confirmation.as_ref().is_some_and(|c| c.confirmed)
    }

    /// A jump in time of a fitted record (`jump:T`): the ball or the sensor moved during it.
    pub fn is_jump(&self) -> bool {
        self.term.basis.jump_at().is_some()
    }
}

impl Diagnosis {
    /// Whether finding `f` is named a cause: in the extended model, confirmed on its own, the
    /// extended model recommended, and no jump in time of a fitted record (a jump is an event
    /// of the record, never a cause of the machine).
    pub fn is_cause(&self, f: &Finding) -> bool {
        f.in_model && f.confirmed() && self.recommendation.recommended && !f.is_jump()
    }

    /// The rows of the records that judged the extension: the held-out records, or with none
    /// the fitted records each left out in turn.
    pub fn judging_rows(&self) -> &[heldout::HeldOut] {
        if self.validation.is_empty() {
            &self.left_out
        } else {
            &self.validation
        }
    }

    /// [`Diagnosis::recommendation`] with the held-out records named `names` (their files, one
    /// per record in order) instead of their labels: the same verdict, for a report.
    pub fn recommendation_named(&self, names: &[String]) -> verdict::Recommendation {
        recommend(&self.findings, self.judging_rows(), &self.adequacy, names)
    }

    /// The extended model as a sub-model lists it: the base model's terms as given (without
    /// the offsets zeroed readings add) followed by the findings in it.
    pub fn extended_terms(&self) -> Model {
        let mut out = self.base_given.clone();
        for f in self.findings.iter().filter(|f| f.in_model) {
            if !out.terms.contains(&f.term) {
                out.terms.push(f.term);
            }
        }
        for t in self
            .groups
            .iter()
            .filter(|g| g.confirmed)
            .flat_map(|g| &g.group.terms)
        {
            if !out.terms.contains(t) {
                out.terms.push(*t);
            }
        }
        out
    }

    /// The extended model's label: the base model's `label` and the findings in the model
    /// (`reduced + ECC@harmonic:2`).
    pub fn extended_label(&self, m: &Machine, label: &str) -> String {
        self.label_of(m, label, true)
    }

    /// `label` and the findings in the extended model (but jumps when `jumps` is `false`),
    /// joined by ` + `.
    fn label_of(&self, m: &Machine, label: &str, jumps: bool) -> String {
        std::iter::once(label.to_string())
            .chain(
                self.findings
                    .iter()
                    .filter(|f| f.in_model && (jumps || !f.is_jump()))
                    .map(|f| f.term.spelling(m)),
            )
            .chain(
                self.groups
                    .iter()
                    .filter(|g| g.confirmed)
                    .map(|g| format!("[{}]", g.group.name)),
            )
            .collect::<Vec<_>>()
            .join(" + ")
    }

    /// The machine description `text` of `m` with the extended model appended as a sub-model
    /// ([`model_spec::write::append_model`]), described by its label and `context` (`rtest
    /// diagnose on k4.csv`): the model's name and the new text. A jump in time of a fitted
    /// record (`jump:T`) is left out of it: an event of that record, no term of the machine to
    /// fit on another record.
    ///
    /// # Errors
    /// [`model_spec::write::AppendError`] when the text does not read back as the same machine
    /// with that model.
    pub fn extended_machine(
        &self,
        m: &Machine,
        text: &str,
        label: &str,
        context: &str,
    ) -> Result<(String, String), model_spec::write::AppendError> {
        let terms: Vec<String> = self
            .extended_terms()
            .terms
            .iter()
            .filter(|t| t.basis.jump_at().is_none())
            .map(|t| t.spelling(m))
            .collect();
        let description = format!("{} ({context})", self.label_of(m, label, false));
        model_spec::write::append_model(m, text, &terms, &description)
    }
}
