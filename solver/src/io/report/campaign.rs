//! The campaign identification report (`rtest identify --data a.csv,b.csv --json` or
//! `--campaign FILE --json`).
//!
//! ```json
//! {"kind": "campaign", "machine": "seed-ac", "fingerprint": "…", "model": "reduced",
//!  "base_model": "reduced", "terms": ["XOW", …, "BOC"],
//!  "setups": [{"label": "k4", "records": ["k4"]}, …],
//!  "records": [{"label": "k4", "data": "k4.csv", "setup": "k4", "params": {"Xw": -217.504, …},
//!               "zeroed": false, "samples": 241, "residual_rms_um": 0.49}, …],
//!  "parameters": [{"name": "XOW[k4]", "owner": "setup", "of": "k4", "error": "XOW",
//!                  "basis": "const", "value": 12.3, "std": 0.05, "unit": "um",
//!                  "determined": true, "fixed": false}, …],
//!  "residual_rms_um": …, "rank": …, "confounded": [["XOC", "dx0[k4]"]], …}
//! ```
//!
//! `owner` is `shared` (the machine's errors: one value for the campaign), `setup` (the
//! ball set-up errors of the set-up `of`) or `record` (the zero and drift of the R-test, and the
//! terms of a time basis on a record's own clock, of the record `of`). `clock` (`{"start_s",
//! "end_s"}`) is there when the records are on one campaign clock, and then every record has
//! `start_s`. The other fields are those of the single identification report
//! ([`super::identify`]), over the whole campaign. Read back by [`super::campaign_read`].

use super::identify::{
    FitSummary, NearPairReport, NoiseModelReport, ParameterReport, RefinementReport,
    SwallowedReport, backend_name, fit_report, noise_report, notes, parameter_report,
    refinement_report,
};
use super::{NonFinite, Ordered, finite};
use crate::fitting::campaign::{CampaignIdentification, Owner};
use crate::fitting::refine::Refinement;
use model_spec::Machine;
use model_spec::units::UM_PER_MM;
use serde::Serialize;

/// The value of `"kind"` in a campaign report.
pub const CAMPAIGN_KIND: &str = "campaign";

/// One parameter of a campaign fit: whose it is, and the parameter as a single report has it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CampaignParameterReport {
    /// `shared`, `setup` or `record`.
    pub owner: String,
    /// The set-up's or the record's label; absent for a shared parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub of: Option<String>,
    /// The parameter (its `name` carries the owner: `XOW[k4]`).
    #[serde(flatten)]
    pub parameter: ParameterReport,
}

/// One set-up: its label and its records.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetupReport {
    /// The set-up's label.
    pub label: String,
    /// The labels of its records.
    pub records: Vec<String>,
}

/// One record of a campaign report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CampaignRecordReport {
    /// Its label.
    pub label: String,
    /// The measurement file it was read from.
    pub data: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its kinematic parameters, every symbol in the machine's order, mm.
    pub params: Ordered<f64>,
    /// Whether its readings were zeroed at the first sample (its own `dx0 dy0 dz0` fitted).
    pub zeroed: bool,
    /// Its time 0 on the campaign clock, s; absent when the records keep their own clocks.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start_s: Option<f64>,
    /// Its samples.
    pub samples: usize,
    /// The residual RMS of its readings, `√(RSS_r / 3N_r)`, µm.
    pub residual_rms_um: f64,
}

/// The campaign clock's span, s.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClockReport {
    /// The first sample of all records on the campaign clock, s.
    pub start_s: f64,
    /// The last, s.
    pub end_s: f64,
}

/// The campaign identification report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CampaignReport {
    /// Always `campaign`: tells the report from a single identification's.
    pub kind: String,
    /// Machine name.
    pub machine: String,
    /// The machine's fingerprint.
    pub fingerprint: String,
    /// The model's label.
    pub model: String,
    /// The machine's model it starts from, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_model: Option<String>,
    /// The model's terms as given (the records' zero offsets are not among them).
    pub terms: Vec<String>,
    /// The set-ups, in order of first appearance.
    pub setups: Vec<SetupReport>,
    /// The records, in campaign order.
    pub records: Vec<CampaignRecordReport>,
    /// The campaign clock, when the records are on one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockReport>,
    /// Every parameter, in layout order: shared, then per set-up, then per record.
    pub parameters: Vec<CampaignParameterReport>,
    /// `√(RSS / 3N)` over every record, µm.
    pub residual_rms_um: f64,
    /// Numerical rank of the column-scaled design matrix.
    pub rank: usize,
    /// Free parameters (not fixed by the constraint).
    pub free_parameters: usize,
    /// Condition number of the scaled design matrix; `null` when the rank is 0.
    pub condition: Option<f64>,
    /// Groups of parameters the campaign cannot separate.
    pub confounded: Vec<Vec<String>>,
    /// Samples over every record.
    pub samples: usize,
    /// Readings fitted (3 per sample).
    pub readings: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// `none`, `minimum-norm` or `zero: NAME, …`.
    pub constraint: String,
    /// σ̂, µm; `null` without degrees of freedom.
    pub sigma_um: Option<f64>,
    /// Determined pairs with |correlation| > 0.99.
    pub near_confounded: Vec<NearPairReport>,
    /// What the records' zero offsets swallow.
    pub swallowed: Vec<SwallowedReport>,
    /// `compiled`, `evaluator` or `mixed`.
    pub gains: String,
    /// The refinement against the exact machine.
    pub refinement: RefinementReport,
    /// The noise model the uncertainties assume (one for every record, records independent).
    pub noise_model: NoiseModelReport,
    /// Statements for people.
    pub notes: Vec<String>,
}

/// What a campaign report says besides the identification: the model's label and base model,
/// and each record's data file (in campaign order).
#[derive(Clone, Copy, Debug)]
pub struct CampaignSource<'a> {
    /// The model's label.
    pub label: &'a str,
    /// The machine's model it starts from, if any.
    pub base_model: Option<&'a str>,
    /// Per record, the file it was read from.
    pub data: &'a [String],
}

impl CampaignReport {
    /// The report of `ident` on machine `m`, refined as `refinement` says (`None`: first
    /// order).
    ///
    /// # Errors
    /// [`NonFinite`] when a value, uncertainty or statistic is not finite.
    pub fn new(
        m: &Machine,
        source: CampaignSource,
        ident: &CampaignIdentification,
        refinement: Option<&Refinement>,
    ) -> Result<CampaignReport, NonFinite> {
        let fit = &ident.fit;
        let layout = &ident.layout;
        let mut parameters = Vec::with_capacity(layout.columns.len());
        let nominal = layout.nominal_mm();
        for (j, c) in layout.columns.iter().enumerate() {
            let (owner, of) = match c.owner {
                Owner::Shared => ("shared", None),
                Owner::Setup(_) => ("setup", Some(layout.owner_label(c.owner).to_string())),
                Owner::Record(_) => ("record", Some(layout.owner_label(c.owner).to_string())),
            };
            parameters.push(CampaignParameterReport {
                owner: owner.into(),
                of,
                parameter: parameter_report(m, &c.term, c.component, fit, j, nominal[j])?,
            });
        }
        let refinement = refinement_report(refinement, fit)?;
        let FitSummary {
            residual_rms_um,
            rank,
            free_parameters,
            condition,
            confounded,
            readings,
            dof,
            constraint,
            sigma_um,
            near_confounded,
            ..
        } = fit_report(fit)?;
        let mut all_notes = notes(fit, &ident.swallowed, &refinement);
        all_notes.extend(campaign_notes(ident));
        let records = layout
            .records
            .iter()
            .zip(&ident.records)
            .enumerate()
            .map(|(r, (rc, rf))| {
                Ok(CampaignRecordReport {
                    label: rc.label.clone(),
                    data: source.data.get(r).cloned().unwrap_or_default(),
                    setup: layout.setups[rc.setup].clone(),
                    params: Ordered(
                        m.symbols
                            .iter()
                            .zip(&rc.params)
                            .map(|(s, &v)| (s.name.clone(), v + 0.0))
                            .collect(),
                    ),
                    zeroed: rc.zeroed,
                    start_s: rc.start_s,
                    samples: rc.samples,
                    residual_rms_um: finite(
                        || format!("records[{r}].residual_rms_um"),
                        rf.residual_rms() * UM_PER_MM,
                    )?,
                })
            })
            .collect::<Result<_, NonFinite>>()?;
        Ok(CampaignReport {
            kind: CAMPAIGN_KIND.into(),
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            model: source.label.to_string(),
            base_model: source.base_model.map(str::to_string),
            terms: ident.model.terms.iter().map(|t| t.spelling(m)).collect(),
            setups: layout
                .setups
                .iter()
                .enumerate()
                .map(|(s, label)| SetupReport {
                    label: label.clone(),
                    records: layout
                        .records
                        .iter()
                        .filter(|r| r.setup == s)
                        .map(|r| r.label.clone())
                        .collect(),
                })
                .collect(),
            records,
            clock: layout.clock.map(|(a, b)| ClockReport {
                start_s: a,
                end_s: b,
            }),
            parameters,
            residual_rms_um,
            rank,
            free_parameters,
            condition,
            confounded,
            samples: ident.records.iter().map(|r| r.samples).sum(),
            readings,
            dof,
            constraint,
            sigma_um,
            near_confounded,
            swallowed: FitSummary::swallowed_of(&ident.swallowed),
            gains: backend_name(ident.backend).into(),
            refinement,
            noise_model: noise_report(&ident.noise, ident.whitened_sigma)?,
            notes: all_notes,
        })
    }

    /// The parameters of `owner` (`shared`, `setup` or `record`) of `of` (a label; `None` for
    /// shared).
    pub fn parameters_of(&self, owner: &str, of: Option<&str>) -> Vec<&ParameterReport> {
        self.parameters
            .iter()
            .filter(|p| p.owner == owner && p.of.as_deref() == of)
            .map(|p| &p.parameter)
            .collect()
    }
}

/// What a campaign says besides the fit: the set-up errors a record cannot separate from the
/// machine's, named.
fn campaign_notes(ident: &CampaignIdentification) -> Vec<String> {
    let fit = &ident.fit;
    let layout = &ident.layout;
    let mut out = Vec::new();
    for g in &fit.identifiability.confounded {
        let setup: Vec<&str> = g
            .iter()
            .filter(|&&j| matches!(layout.columns[j].owner, Owner::Setup(_)))
            .map(|&j| fit.names[j].as_str())
            .collect();
        let shared: Vec<&str> = g
            .iter()
            .filter(|&&j| layout.columns[j].owner == Owner::Shared)
            .map(|&j| fit.names[j].as_str())
            .collect();
        if !setup.is_empty() && !shared.is_empty() {
            out.push(format!(
                "the set-up error{} {} cannot be told from the machine's {} on these records{}",
                if setup.len() > 1 { "s" } else { "" },
                setup.join(", "),
                shared.join(", "),
                if fit.constraint == crate::fitting::Constraint::None {
                    ": no number for either"
                } else {
                    ""
                }
            ));
        }
    }
    out
}
