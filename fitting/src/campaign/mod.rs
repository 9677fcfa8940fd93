//! Campaigns: several records, each measured with its own set-up, fitted together.
//!
//! A measurement campaign is several R-test records: several paths, often several ball
//! positions or heights. The machine's errors are the same in every record; what changes from
//! record to record is
//!
//! - the **kinematic parameters** the record was planned and is modelled with
//!   ([`CampaignRecord::params`], mm, symbol order): the ball's position lives there;
//! - the **ball set-up errors** `XOW YOW ZOW` (the set-up terms of the model, catalogue errors
//!   of kind [`model_spec::ErrorKind::Setup`]): one set per *set-up*
//!   ([`CampaignRecord::setup`]); records with the same set-up label share them (one ball
//!   mounting, several paths);
//! - the **R-test's zero** `dx0 dy0 dz0` ([`simulation::model::Effect::SensorOffset`]): one per
//!   record, joined when the record's readings were zeroed at its first sample
//!   ([`CampaignRecord::zeroed`]);
//! - the **clock**: terms of a time basis (`time:K`, `exp:TAU`) describe a drift within a
//!   record, on its own clock, unless every record says when it started on one campaign clock
//!   ([`CampaignRecord::start_s`]).
//!
//! [`design::Layout`] says which column belongs to whom, [`design::design_matrix`] stacks the
//! records' H matrices into one, [`fit::identify`] fits it (first order, ordinary or
//! generalized least squares) and, when asked, refines the fit against the exact machine (each
//! record with its own parameters and set-up values, [`refine`]), and
//! [`validate::validate()`] predicts other records, refitting the set-up errors of a
//! set-up that was not fitted (and a record's own zero) with the machine's errors held;
//! [`recheck()`] also refits named machine parameters (a re-check's pivot) over its records.
//! [`names`] lets a constraint of a campaign of one record use the record's own names.
//! `docs/campaigns.md` describes the campaign file and a worked campaign.
//!
//! [`CampaignRecord::params`]: simulation::campaign::CampaignRecord::params
//! [`CampaignRecord::setup`]: simulation::campaign::CampaignRecord::setup
//! [`CampaignRecord::zeroed`]: simulation::campaign::CampaignRecord::zeroed
//! [`CampaignRecord::start_s`]: simulation::campaign::CampaignRecord::start_s

pub mod clock;
pub mod design;
pub mod fit;
pub mod names;
pub mod recheck;
pub mod refine;
pub mod validate;

pub use design::{Column, Design, Layout, Owner, RecordColumns, RecordSpec, design_matrix};
pub use fit::{CampaignIdentification, RecordFit, choose_campaign_noise, fit_design, identify};
pub use recheck::{PivotRefit, Recheck, RecheckScale, recheck};
pub use refine::{exact_campaign_prediction, refine_campaign};
pub use validate::{
    CampaignValidation, CampaignValues, RecordPlan, RecordValidation, Refitted, record_plan,
    validate, validate_record,
};

use simulation::campaign::{Campaign, CampaignRecord};
use simulation::record::Record;

/// The per-sample whitening of `campaign`'s readings, stacked in record order, when its
/// records were read through an instrument (every record carries per-sample covariances,
/// [`Record::covariance`]); `None` when none does.
///
/// # Errors
/// [`crate::EstimateError::Noise`] when some records carry covariances and others do not (their
/// rows could not be weighted alike), when a covariance cannot whiten, or when `noise` is a
/// declared model (the sensors' σ already declare the noise).
pub fn whitening(
    campaign: &Campaign,
    noise: &crate::noise::NoiseChoice,
) -> Result<Option<crate::noise::SampleWhitening>, crate::EstimateError> {
    let records: Vec<&CampaignRecord> = campaign.records.iter().collect();
    whitening_of(&records, noise)
}

/// [`whitening`] of `records`, in their order.
///
/// # Errors
/// As [`whitening`].
pub(crate) fn whitening_of(
    records: &[&CampaignRecord],
    noise: &crate::noise::NoiseChoice,
) -> Result<Option<crate::noise::SampleWhitening>, crate::EstimateError> {
    let with: Vec<&str> = records
        .iter()
        .filter(|r| !r.record.covariance.is_empty())
        .map(|r| r.label.as_str())
        .collect();
    if with.is_empty() {
        return Ok(None);
    }
    if with.len() != records.len() {
        let without: Vec<&str> = records
            .iter()
            .filter(|r| r.record.covariance.is_empty())
            .map(|r| r.label.as_str())
            .collect();
        return Err(crate::noise::NoiseError::Whitening(format!(
            "records {} were read through an instrument (per-sample covariances) and records {} were not: a campaign weights all its records alike, so read every record through the instrument or none",
            with.join(", "),
            without.join(", ")
        ))
        .into());
    }
    let mut all = Record::default();
    for r in records {
        all.samples.extend(r.record.samples.iter().cloned());
        all.covariance.extend(r.record.covariance.iter().copied());
    }
    crate::identify::sample_whitening(&all, noise)
}
