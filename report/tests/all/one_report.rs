//! The identification report of one record identified alone, as the tests of several crates
//! need it: the record's fit in its model's terms made a campaign of one (labelled by the stem
//! of its file, on a set-up of that label), then the one report of a campaign
//! ([`IdentificationReport::of_campaign`]). Included by `#[path]`.

#![allow(dead_code)]

use fitting::campaign::CampaignIdentification;
use fitting::{Identification, Refinement};
use model_spec::Machine;
use report::json::{CampaignSource, IdentificationReport};

/// Where an identification of one record came from, as its report names it.
#[derive(Clone, Copy, Debug)]
pub struct IdentificationSource<'a> {
    /// The measurement file.
    pub data: &'a str,
    /// The model's label.
    pub label: &'a str,
    /// The model named, when it was one.
    pub base_model: Option<&'a str>,
}

/// The report of `ident`, one record identified on `m` at the machine's default kinematic
/// parameters, except the symbols identified as terms (`Zt`), at the values the identification
/// modelled them with.
pub fn report_of_one(
    m: &Machine,
    source: IdentificationSource,
    ident: &Identification,
    refinement: Option<&Refinement>,
) -> Result<IdentificationReport, String> {
    let mut params = m.default_parameters();
    for (j, (t, _)) in ident.model.columns().into_iter().enumerate() {
        if let (Some(s), Some(Some(v))) = (
            ident.model.terms[t].effect.symbol(),
            ident.nominal_mm.get(j),
        ) {
            params[s] = *v;
        }
    }
    let label = formats::campaign::stem_label(std::path::Path::new(source.data));
    let campaign = CampaignIdentification::of_record(m, ident, &label, params)
        .map_err(|e| format!("{}: {e}", source.data))?;
    let data = [source.data.to_string()];
    let source = CampaignSource {
        label: source.label,
        base_model: source.base_model,
        data: &data,
    };
    IdentificationReport::of_campaign(m, source, &campaign, refinement).map_err(|e| e.to_string())
}
