//! The campaign fit refined against the exact machine: Gauss–Newton with the stacked design
//! matrix as the Jacobian ([`crate::refine`]), the prediction of each record the exact
//! virtual machine at its own kinematic parameters with the shared values, its set-up's values
//! and its own (time bases on the campaign clock rewritten onto its own clock,
//! [`super::clock::own_clock_terms`]).

use super::clock::own_clock_terms;
use super::design::{Design, Solved, measurements};
use super::fit::{
    CampaignIdentification, check_options, choose_campaign_noise_weighted, ordinary_identification,
    to_layout_order, to_solve_order,
};
use crate::factored::{RowsFactored, check_readings_of};
use crate::identify::check_readings;
use crate::noise::{NoiseChoice, NoiseModel, SampleWhitening};
use crate::refine::{
    GaussNewton, IdentifyError, RefineOptions, Refinement, exact_prediction, gauss_newton,
};
use crate::{IdentifyOptions, Tolerances};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::Model;

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
) -> Result<DVector<f64>, IdentifyError> {
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

/// The system a campaign's refinements solve: the design matrix's columns in solve order and
/// their names, the readings, the per-sample weights of records read through an instrument and
/// the largest coordinate of the machines and paths (mm, at least 1).
struct System {
    order: Vec<usize>,
    h: DMatrix<f64>,
    names: Vec<String>,
    y: DVector<f64>,
    weights: Option<SampleWhitening>,
    coordinates: f64,
}

impl System {
    /// The system of `design` (its H copied into solve order).
    fn new(campaign: &Campaign, design: &Design) -> Result<System, IdentifyError> {
        System::of(campaign, Solved::copied(design))
    }

    /// The system of the design's H in solve order (`solved`).
    fn of(campaign: &Campaign, solved: Solved) -> Result<System, IdentifyError> {
        let Solved { h, names, order } = solved;
        let coordinates = campaign
            .records
            .iter()
            .flat_map(|r| {
                r.params
                    .iter()
                    .chain(r.record.samples.iter().flat_map(|s| s.commands.iter()))
            })
            .fold(1.0f64, |a, v| a.max(v.abs()));
        Ok(System {
            order,
            h,
            names,
            y: measurements(campaign)?,
            // Records read through an instrument weight every correction by their covariances
            // (a declared noise model was refused by the first-order fit).
            weights: super::whitening(campaign, &NoiseChoice::Estimate)?,
            coordinates,
        })
    }
}

/// Refines `ident` (identified on `campaign` with `design`) against the exact machine, by
/// ordinary least squares (`noise` `None`) or generalized least squares under `noise`, from
/// `ident`'s solution as it is; the records' residuals and, under a noise model, the whitened σ̂
/// are updated.
///
/// # Errors
/// As [`super::identify`]: the exact prediction and its fits.
pub fn refine_campaign(
    m: &Machine,
    campaign: &Campaign,
    design: &Design,
    ident: &mut CampaignIdentification,
    tolerances: &Tolerances,
    opts: &RefineOptions,
    noise: Option<&NoiseModel>,
) -> Result<Refinement, IdentifyError> {
    let system = System::new(campaign, design)?;
    let run = Run {
        m,
        campaign,
        design,
        system: &system,
        tolerances,
        opts,
    };
    run.refine(ident, noise, None)
}

/// A campaign's refinements: the campaign, its system and the options.
struct Run<'a> {
    m: &'a Machine,
    campaign: &'a Campaign,
    design: &'a Design,
    system: &'a System,
    tolerances: &'a Tolerances,
    opts: &'a RefineOptions,
}

impl Run<'_> {
    /// [`refine_campaign`] with the system made, every fit made from `factored` (the
    /// factorisations of the system under `noise`) when given.
    fn refine(
        &self,
        ident: &mut CampaignIdentification,
        noise: Option<&NoiseModel>,
        factored: Option<&RowsFactored>,
    ) -> Result<Refinement, IdentifyError> {
        let System {
            order,
            h,
            names,
            y,
            weights,
            coordinates,
        } = self.system;
        let problem = GaussNewton {
            h,
            y,
            layout: &self.design.rows,
            tolerances: self.tolerances,
            noise,
            coordinates: *coordinates,
            weights: weights.as_ref(),
            factored,
        };
        // The first-order fit in solve order: the iteration runs on the system as solved.
        let mut start = ident.fit.clone();
        start.names = names.clone();
        start.solution = to_solve_order(&ident.fit.solution, order);
        let n = order.len();
        let mut predict = |xs: &[f64]| -> Result<DVector<f64>, IdentifyError> {
            let mut x = vec![0.0; n];
            for (k, &c) in order.iter().enumerate() {
                x[c] = xs[k];
            }
            exact_campaign_prediction(self.m, self.campaign, self.design, &x)
        };
        let (fit, whitened_sigma, refinement) =
            gauss_newton(&problem, &start, self.opts, &mut predict)?;
        ident.fit = to_layout_order(fit, order);
        let residual = ident.fit.residual.clone();
        ident.set_residual(&residual);
        if noise.is_some() || weights.is_some() {
            ident.whitened_sigma = whitened_sigma;
        }
        Ok(refinement)
    }
}

/// Identifies `model` on `campaign` and refines the fit against the exact machine: the ordinary
/// refinement, then, unless the options' noise is [`NoiseChoice::Ordinary`], the noise model from
/// its exact residual (pooled over the records) and the refinement by generalized least squares
/// from its solution. The [`Refinement`] (in [`CampaignIdentification::refinement`]) counts the
/// steps of both; its first-order RMS is the ordinary linear fit's. The ordinary system is
/// factorised once for the first-order fit and both refinements (the generalized one adds the
/// whitened system's).
///
/// # Errors
/// As [`super::identify`]; [`IdentifyError::NotConverged`] when a refinement does not
/// converge (its values are no identification).
pub(crate) fn identify_refined(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    opts: &IdentifyOptions,
    refine_opts: &RefineOptions,
) -> Result<CampaignIdentification, IdentifyError> {
    let noise = &opts.noise;
    check_options(opts)?;
    let (design, solved) = Solved::design(m, model, campaign)?;
    check_readings(campaign.samples(), design.names.len())?;
    let system = System::of(campaign, solved)?;
    let (h, names, y) = (&system.h, &system.names, &system.y);
    let (c, t) = (&opts.constraint, &opts.tolerances);
    check_readings_of(h, y, names)?;
    let weights = system.weights.as_ref();
    let factored = RowsFactored::for_readings(h, y, names, c, t, None, &design.rows, weights)?;
    let fit = factored.fit(h, y)?;
    let mut ident = ordinary_identification(m, model, &design, &system.order, fit, weights);
    let run = Run {
        m,
        campaign,
        design: &design,
        system: &system,
        tolerances: t,
        opts: refine_opts,
    };
    let ordinary = run.refine(&mut ident, None, Some(&factored))?;
    ordinary.converged()?;
    if *noise == NoiseChoice::Ordinary {
        ident.refinement = Some(ordinary);
        return Ok(ident);
    }
    let weights = super::whitening(campaign, noise)?;
    let chosen = choose_campaign_noise_weighted(noise, &ident.fit, &design.rows, weights.as_ref())?;
    let under = factored.under(h, None, names, c, t, &chosen)?;
    let r = run.refine(&mut ident, Some(&chosen), Some(&under))?;
    ident.noise = chosen;
    r.converged()?;
    super::fit::at_declared_scale(&mut ident);
    ident.refinement = Some(ordinary.followed_by(&r));
    Ok(ident)
}
