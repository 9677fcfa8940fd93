//! The campaign fit refined against the exact machine: Gauss–Newton with the stacked design
//! matrix as the Jacobian ([`crate::fitting::refine`]), the prediction of each record the exact
//! virtual machine at its own kinematic parameters with the shared values, its set-up's values
//! and its own (time bases on the campaign clock rewritten onto its own clock,
//! [`super::clock::own_clock_terms`]).

use super::Campaign;
use super::clock::own_clock_terms;
use super::design::{Design, design_matrix, measurements};
use super::fit::{
    CampaignIdentification, check_options, choose_campaign_noise_weighted, identify_campaign_with,
    solve_system, to_layout_order, to_solve_order,
};
use crate::fitting::noise::{NoiseChoice, NoiseModel};
use crate::fitting::refine::{
    GaussNewton, RefineError, RefineOptions, Refinement, exact_prediction, gauss_newton,
};
use crate::fitting::{IdentifyOptions, Tolerances};
use crate::model::Model;
use model_spec::Machine;
use nalgebra::DVector;

/// The exact machine's readings (mm, every record's rows in campaign order) with every layout
/// column at `x` (mm, rad; layout order).
///
/// # Errors
/// A record or model the exact machine cannot run (named by record).
pub fn exact_campaign_prediction(
    m: &Machine,
    campaign: &Campaign,
    design: &Design,
    x: &[f64],
) -> Result<DVector<f64>, RefineError> {
    let mut out = Vec::with_capacity(3 * campaign.samples());
    for (rc, rec) in design.layout.records.iter().zip(&campaign.records) {
        let local: Vec<f64> = rc.columns.iter().map(|&c| x[c]).collect();
        let p = match (design.layout.clock, rc.start_s) {
            (Some(span), Some(start)) => {
                let (model, coef) = own_clock_terms(&rc.model, &local, &rec.record, start, span);
                let values: Vec<Option<f64>> = coef.into_iter().map(Some).collect();
                exact_prediction(m, &model, &values, &rec.record, &rc.params)?
            }
            _ => {
                let values: Vec<Option<f64>> = local.into_iter().map(Some).collect();
                exact_prediction(m, &rc.model, &values, &rec.record, &rc.params)?
            }
        };
        out.extend(p.iter().flat_map(|r| r.iter().copied()));
    }
    Ok(DVector::from_vec(out))
}

/// Refines `ident` (identified on `campaign` with `design`) against the exact machine, by
/// ordinary least squares (`noise` `None`) or generalized least squares under `noise`, from
/// `ident`'s solution as it is; the records' residuals and, under a noise model, the whitened σ̂
/// are updated.
///
/// # Errors
/// As [`crate::fitting::refine::refine`].
pub fn refine_campaign(
    m: &Machine,
    campaign: &Campaign,
    design: &Design,
    ident: &mut CampaignIdentification,
    tolerances: &Tolerances,
    opts: &RefineOptions,
    noise: Option<&NoiseModel>,
) -> Result<Refinement, RefineError> {
    let order = design.layout.solve_order();
    let (h, names) = solve_system(design, &order);
    let y = measurements(campaign)?;
    let coordinates = campaign
        .records
        .iter()
        .flat_map(|r| {
            r.params
                .iter()
                .chain(r.record.samples.iter().flat_map(|s| s.commands.iter()))
        })
        .fold(1.0f64, |a, v| a.max(v.abs()));
    // Records read through an instrument weight every correction by their covariances (a
    // declared noise model was refused by the first-order fit).
    let weights = campaign.whitening(&NoiseChoice::Estimate)?;
    let problem = GaussNewton {
        h: &h,
        y: &y,
        layout: &design.rows,
        tolerances,
        noise,
        coordinates,
        weights: weights.as_ref(),
    };
    // The first-order fit in solve order: the iteration runs on the system as solved.
    let mut start = ident.fit.clone();
    start.names = names;
    start.solution = to_solve_order(&ident.fit.solution, &order);
    let n = order.len();
    let mut predict = |xs: &[f64]| -> Result<DVector<f64>, RefineError> {
        let mut x = vec![0.0; n];
        for (k, &c) in order.iter().enumerate() {
            x[c] = xs[k];
        }
        exact_campaign_prediction(m, campaign, design, &x)
    };
    let (fit, whitened_sigma, refinement) = gauss_newton(&problem, &start, opts, &mut predict)?;
    ident.fit = to_layout_order(fit, &order);
    let residual = ident.fit.residual.clone();
    ident.set_residual(&residual);
    if noise.is_some() || weights.is_some() {
        ident.whitened_sigma = whitened_sigma;
    }
    Ok(refinement)
}

/// Identifies `model` on `campaign` and refines the fit against the exact machine: the
/// ordinary refinement, then, unless `noise` is [`NoiseChoice::Ordinary`], the noise model
/// from its exact residual (pooled over the records) and the refinement by generalized least
/// squares from its solution (as [`crate::fitting::identify_refined_with_noise`]).
///
/// # Errors
/// As [`super::identify_campaign`]; [`RefineError::NotConverged`] when a refinement does not
/// converge (its values are no identification).
pub fn identify_campaign_refined(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    opts: &IdentifyOptions,
    refine_opts: &RefineOptions,
    noise: &NoiseChoice,
) -> Result<(CampaignIdentification, Refinement), RefineError> {
    check_options(opts)?;
    let design = design_matrix(m, model, campaign)?;
    let mut ident =
        identify_campaign_with(m, model, campaign, &design, opts, &NoiseChoice::Ordinary)?;
    let ordinary = refine_campaign(
        m,
        campaign,
        &design,
        &mut ident,
        &opts.tolerances,
        refine_opts,
        None,
    )?;
    not_converged(&ordinary)?;
    if *noise == NoiseChoice::Ordinary {
        return Ok((ident, ordinary));
    }
    let weights = campaign.whitening(noise)?;
    let chosen = choose_campaign_noise_weighted(noise, &ident.fit, &design.rows, weights.as_ref())?;
    let r = refine_campaign(
        m,
        campaign,
        &design,
        &mut ident,
        &opts.tolerances,
        refine_opts,
        Some(&chosen),
    )?;
    ident.noise = chosen;
    not_converged(&r)?;
    let mut steps_mm = ordinary.steps_mm;
    steps_mm.extend(&r.steps_mm);
    Ok((
        ident,
        Refinement {
            iterations: steps_mm.len(),
            steps_mm,
            tolerance_mm: r.tolerance_mm,
            converged: true,
            rms_mm: (ordinary.rms_mm.0, r.rms_mm.1),
        },
    ))
}

fn not_converged(r: &Refinement) -> Result<(), RefineError> {
    if r.converged {
        return Ok(());
    }
    Err(RefineError::NotConverged {
        iterations: r.iterations,
        last_step_mm: r.steps_mm.last().copied().unwrap_or(0.0),
        tolerance_mm: r.tolerance_mm,
    })
}
