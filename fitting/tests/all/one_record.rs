//! A record identified alone, as the tests of several crates need it: the record as a
//! campaign of one ([`Campaign::of_record`]), the one [`fitting::identify`], and the fit in
//! the model's terms ([`CampaignIdentification::single_record`]). Included by `#[path]`.
//!
//! [`CampaignIdentification::single_record`]: fitting::campaign::CampaignIdentification::single_record

#![allow(dead_code)]

use fitting::{
    EstimateError, Identification, IdentifyError, IdentifyOptions, RefineOptions, Refinement,
    identify,
};
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::Model;
use simulation::record::Record;

/// `record` as a campaign of one, with the zeroing and kinematic parameters `opts` gives
/// (the machine's defaults when none), and the options a campaign takes.
fn campaign_of(
    m: &Machine,
    record: &Record,
    opts: &IdentifyOptions,
) -> (Campaign, IdentifyOptions) {
    let campaign = Campaign::of_record(record.clone(), opts.parameters(m), opts.zeroed);
    let mut opts = opts.clone();
    opts.zeroed = false;
    opts.params = None;
    (campaign, opts)
}

/// `model` of `m` identified on `record` alone (first order), in the model's terms.
pub fn identify_one(
    m: &Machine,
    model: &Model,
    record: &Record,
    opts: &IdentifyOptions,
) -> Result<Identification, EstimateError> {
    let (campaign, mut opts) = campaign_of(m, record, opts);
    opts.refine = None;
    match identify(m, model, &campaign, &opts) {
        Ok(fit) => Ok(fit.single_record(m).expect("a campaign of one record")),
        Err(IdentifyError::Estimate(e)) => Err(e),
        Err(e) => panic!("a first-order identification failed outside its estimate: {e}"),
    }
}

/// `model` of `m` identified on `record` alone and refined against the exact machine with
/// `refine`, in the model's terms, with what the refinement did.
pub fn identify_refined_one(
    m: &Machine,
    model: &Model,
    record: &Record,
    opts: &IdentifyOptions,
    refine: &RefineOptions,
) -> Result<(Identification, Refinement), IdentifyError> {
    let (campaign, opts) = campaign_of(m, record, opts);
    let fit = identify(m, model, &campaign, &opts.refined(*refine))?;
    let refinement = fit.refinement.clone().expect("a refined fit");
    Ok((
        fit.single_record(m).expect("a campaign of one record"),
        refinement,
    ))
}

/// `model` of `m` identified on `campaign` and refined against the exact machine with
/// `refine`, with what the refinement did.
pub fn identify_refined_campaign(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    opts: &IdentifyOptions,
    refine: &RefineOptions,
) -> Result<(fitting::campaign::CampaignIdentification, Refinement), IdentifyError> {
    let fit = identify(m, model, campaign, &opts.clone().refined(*refine))?;
    let refinement = fit.refinement.clone().expect("a refined fit");
    Ok((fit, refinement))
}

/// `values` of `model` (one per model column, mm or rad; `None`: none) validated on `record`
/// alone: the values as an identification of one record gives them (set-up `fitted`, default
/// kinematic parameters), the record on that set-up, zeroed or not (its own zero offsets then
/// refitted on it), as the one [`fitting::validate`] does it.
pub fn validate_one(
    m: &Machine,
    model: &Model,
    values: &[Option<f64>],
    record: &Record,
    zeroed: bool,
    opts: &fitting::ValidateOptions,
) -> Result<fitting::Validation, fitting::ValidateError> {
    let params = m.default_parameters();
    let values =
        fitting::campaign::CampaignValues::of_model(m, model, values, "fitted", params.clone())
            .map_err(|e| fitting::ValidateError::Shape(e.to_string()))?;
    let one = simulation::campaign::CampaignRecord::new(
        "validated",
        record.clone(),
        params,
        "fitted",
        zeroed,
    );
    let campaign = Campaign::new(vec![one]).expect("one record");
    let v = fitting::validate(m, &values, &campaign, opts, &formats::progress::Unwatched)?;
    Ok(v.records.into_iter().next().expect("one record").validation)
}
