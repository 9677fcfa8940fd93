//! The identification report built from the identification of a campaign (a record is a
//! campaign of one): [`IdentificationReport::of_campaign`].

use super::super::fit_summary::{
    fit_report, noise_report, notes, parameter_report, refinement_report,
};
use super::super::{NonFinite, Ordered, finite};
use super::{
    CAMPAIGN_KIND, CampaignSource, ClockReport, IdentificationReport, REPORT_VERSION, RecordReport,
    SetupReport, SwallowedReport, backend_name,
};
use fitting::campaign::{CampaignIdentification, Owner};
use fitting::hmatrix::parameter_name;
use fitting::refine::Refinement;
use model_spec::Machine;
use model_spec::units::UM_PER_MM;

impl IdentificationReport {
    /// The report of `ident` on machine `m`, refined as `refinement` says (`None`: first
    /// order): a record's report when it has one record, a campaign's otherwise (see the module
    /// documentation).
    ///
    /// # Errors
    /// [`NonFinite`] when a value, uncertainty or statistic is not finite.
    pub fn of_campaign(
        m: &Machine,
        source: CampaignSource,
        ident: &CampaignIdentification,
        refinement: Option<&Refinement>,
    ) -> Result<IdentificationReport, NonFinite> {
        let fit = &ident.fit;
        let layout = &ident.layout;
        let one = layout.records.len() == 1;
        // A record's report names its columns as a single fit does, in its model's order.
        let names: Vec<String> = if one {
            layout
                .columns
                .iter()
                .map(|c| parameter_name(m, &c.term, c.component))
                .collect()
        } else {
            layout.names()
        };
        let order: Vec<usize> = if one {
            layout.records[0].columns.clone()
        } else {
            (0..layout.columns.len()).collect()
        };
        let nominal = layout.nominal_mm();
        let mut parameters = Vec::with_capacity(order.len());
        for &j in &order {
            let c = &layout.columns[j];
            let owner = match (one, c.owner) {
                (true, _) => None,
                (false, Owner::Shared) => Some(("shared", None)),
                (false, Owner::Setup(_)) => Some(("setup", Some(layout.owner_label(c.owner)))),
                (false, Owner::Record(_)) => Some(("record", Some(layout.owner_label(c.owner)))),
            };
            parameters.push(parameter_report(
                m,
                &c.term,
                c.component,
                fit,
                j,
                names[j].clone(),
                nominal[j],
                owner,
            )?);
        }
        let rename = |n: &String| -> String {
            layout
                .columns
                .iter()
                .position(|c| c.name == *n)
                .map_or_else(|| n.clone(), |j| names[j].clone())
        };
        let swallowed: Vec<(Vec<String>, Vec<String>)> = ident
            .swallowed
            .iter()
            .map(|s| {
                (
                    s.offsets.iter().map(rename).collect(),
                    s.errors.iter().map(rename).collect(),
                )
            })
            .collect();
        let refinement = refinement_report(refinement, fit)?;
        let mut summary = fit_report(fit, &names)?;
        if let fitting::Constraint::Zero(zero) = &fit.constraint {
            let zero: Vec<String> = zero.iter().map(rename).collect();
            summary.constraint = format!("zero: {}", zero.join(", "));
        }
        let mut all_notes = notes(fit, &names, &swallowed, &refinement);
        all_notes.extend(setup_notes(ident, &names));
        let records = layout
            .records
            .iter()
            .zip(&ident.records)
            .enumerate()
            .map(|(r, (rc, rf))| {
                Ok(RecordReport {
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
            .collect::<Result<Vec<_>, NonFinite>>()?;
        let terms = if one {
            &layout.records[0].model
        } else {
            &ident.model
        };
        Ok(IdentificationReport {
            version: REPORT_VERSION,
            kind: (!one).then(|| CAMPAIGN_KIND.to_string()),
            machine: m.name.clone(),
            fingerprint: m.fingerprint(),
            data: one.then(|| records[0].data.clone()),
            model: source.label.to_string(),
            base_model: source.base_model.map(str::to_string),
            terms: terms.terms.iter().map(|t| t.spelling(m)).collect(),
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
            zeroed: one.then(|| records[0].zeroed),
            records,
            clock: layout.clock.map(|(a, b)| ClockReport {
                start_s: a,
                end_s: b,
            }),
            parameters,
            residual_rms_um: summary.residual_rms_um,
            rank: summary.rank,
            free_parameters: summary.free_parameters,
            condition: summary.condition,
            confounded: summary.confounded,
            samples: ident.records.iter().map(|r| r.samples).sum(),
            readings: summary.readings,
            dof: summary.dof,
            constraint: summary.constraint,
            sigma_um: summary.sigma_um,
            near_confounded: summary.near_confounded,
            swallowed: swallowed
                .into_iter()
                .map(|(offsets, errors)| SwallowedReport { offsets, errors })
                .collect(),
            gains: backend_name(ident.backend).into(),
            refinement,
            noise_model: Some(noise_report(&ident.noise, ident.whitened_sigma)?),
            streaming: None,
            probe: None,
            notes: all_notes,
        })
    }
}

/// The set-up errors the records cannot separate from the machine's, named by `names`.
fn setup_notes(ident: &CampaignIdentification, names: &[String]) -> Vec<String> {
    let fit = &ident.fit;
    let layout = &ident.layout;
    let mut out = Vec::new();
    for g in &fit.identifiability.confounded {
        let of = |owner: fn(Owner) -> bool| -> Vec<&str> {
            g.iter()
                .filter(|&&j| owner(layout.columns[j].owner))
                .map(|&j| names[j].as_str())
                .collect()
        };
        let setup = of(|o| matches!(o, Owner::Setup(_)));
        let shared = of(|o| o == Owner::Shared);
        if !setup.is_empty() && !shared.is_empty() {
            out.push(format!(
                "the set-up error{} {} cannot be told from the machine's {} on {}{}",
                if setup.len() > 1 { "s" } else { "" },
                setup.join(", "),
                shared.join(", "),
                if layout.records.len() > 1 {
                    "these records"
                } else {
                    "this record"
                },
                if fit.constraint == fitting::Constraint::None {
                    ": no number for either"
                } else {
                    ""
                }
            ));
        }
    }
    out
}
