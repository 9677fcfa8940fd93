//! The first-order campaign fit: least squares on the stacked design matrix, ordinary or
//! generalized (the rows of each record whitened by one noise model, records independent).
//!
//! The columns are solved in [`Layout::solve_order`] and the fit is then given in layout order:
//! a campaign of one record is solved in its model's column order, and
//! [`CampaignIdentification::single_record`] gives its fit back in that order, named as the
//! record's model names it (`XOW`, not `XOW[k4]`).

use super::design::{Design, Layout, Owner, Solved, measurements};
use super::names::single_record_names;
use crate::factored::{RowsFactored, check_readings_of};
use crate::hmatrix::Backend;
use crate::identifiability::{NearPair, Swallowed, swallowed_by_offsets};
use crate::identify::check_readings;
use crate::least_squares::{EstimateError, Fit};
use crate::noise::{NoiseChoice, NoiseModel, NoiseSource, SampleWhitening};
use crate::refine::{IdentifyError, Refinement};
use crate::{Identification, IdentifyOptions};
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::{Effect, Model};

/// One record's share of a campaign fit.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordFit {
    /// The record's label.
    pub label: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its samples.
    pub samples: usize,
    /// Whether its readings were zeroed (its `dx0 dy0 dz0` fitted).
    pub zeroed: bool,
    /// The residual sum of squares of its rows, mm².
    pub rss: f64,
}

impl RecordFit {
    /// The residual RMS of its rows, `√(RSS / 3N)`, mm.
    pub fn residual_rms(&self) -> f64 {
        (self.rss / (3 * self.samples).max(1) as f64).sqrt()
    }
}

/// A campaign identification: the layout, the fit (in layout order) and each record's share.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignIdentification {
    /// The machine's name.
    pub machine: String,
    /// The model as given (each record's own model is in [`Layout::records`]).
    pub model: Model,
    /// Which column belongs to whom.
    pub layout: Layout,
    /// The least-squares fit, one parameter per layout column (names [`Layout::names`]);
    /// its residual has the records' rows in campaign order.
    pub fit: Fit,
    /// Per record, in campaign order.
    pub records: Vec<RecordFit>,
    /// Per confounded group with a sensor offset: the parameters it swallows.
    pub swallowed: Vec<Swallowed>,
    /// Which code computed the gains.
    pub backend: Backend,
    /// The noise model the uncertainties assume.
    pub noise: NoiseModel,
    /// σ̂ of the whitened residual for a fit whitened by a noise model; `None` for an ordinary
    /// fit.
    pub whitened_sigma: Option<f64>,
    /// What the refinement against the exact machine did, when it was asked for
    /// ([`IdentifyOptions::refine`]); the fit is then the refined one.
    pub refinement: Option<Refinement>,
}

impl CampaignIdentification {
    /// The residual of record `r`, one `[x, y, z]` per sample (mm).
    pub fn record_residual(&self, r: usize) -> Vec<[f64; 3]> {
        let start: usize = self.records[..r].iter().map(|x| 3 * x.samples).sum();
        let res = &self.fit.residual;
        (0..self.records[r].samples)
            .map(|i| {
                let k = start + 3 * i;
                [res[k], res[k + 1], res[k + 2]]
            })
            .collect()
    }

    /// The solution (mm, rad; undetermined columns one representative of their group) of
    /// record `r`'s own model: the values its prediction is made of, in its model's column
    /// order.
    pub fn record_solution(&self, r: usize) -> Vec<f64> {
        self.layout.records[r]
            .columns
            .iter()
            .map(|&c| self.fit.solution[c])
            .collect()
    }
}

/// `fit` (solved with its columns in `order`: entry `k` the layout column solved `k`-th) with
/// its columns put back in layout order.
pub(crate) fn to_layout_order(fit: Fit, order: &[usize]) -> Fit {
    let n = order.len();
    let mut at = vec![0; n];
    for (k, &c) in order.iter().enumerate() {
        at[c] = k;
    }
    let pick = |v: &[f64]| -> Vec<f64> { (0..n).map(|j| v[at[j]]).collect() };
    let pick_opt = |v: &[Option<f64>]| -> Vec<Option<f64>> { (0..n).map(|j| v[at[j]]).collect() };
    let square = |a: &DMatrix<f64>| DMatrix::from_fn(n, n, |i, j| a[(at[i], at[j])]);
    let id = fit.identifiability;
    let null = DMatrix::from_fn(n, id.null_space.ncols(), |i, j| id.null_space[(at[i], j)]);
    let mut confounded: Vec<Vec<usize>> = id
        .confounded
        .iter()
        .map(|g| {
            let mut g: Vec<usize> = g.iter().map(|&k| order[k]).collect();
            g.sort_unstable();
            g
        })
        .collect();
    confounded.sort_by_key(|g| g.first().copied());
    let near_confounded = id
        .near_confounded
        .iter()
        .map(|p| NearPair {
            a: order[p.a].min(order[p.b]),
            b: order[p.a].max(order[p.b]),
            correlation: p.correlation,
        })
        .collect();
    Fit {
        names: (0..n).map(|j| fit.names[at[j]].clone()).collect(),
        values: pick_opt(&fit.values),
        solution: pick(&fit.solution),
        std: pick_opt(&fit.std),
        fixed: (0..n).map(|j| fit.fixed[at[j]]).collect(),
        column_norms: pick(&fit.column_norms),
        covariance: square(&fit.covariance),
        correlation: square(&fit.correlation),
        identifiability: crate::identifiability::Identifiability {
            null_space: null,
            null_weight: pick(&id.null_weight),
            determined: (0..n).map(|j| id.determined[at[j]]).collect(),
            confounded,
            near_confounded,
        },
        ..fit
    }
}

/// `x` in layout order, put in solve `order`.
pub(crate) fn to_solve_order(x: &[f64], order: &[usize]) -> Vec<f64> {
    order.iter().map(|&c| x[c]).collect()
}

/// The noise model of `choice` for an ordinary campaign fit with `residual` (mm, the records'
/// rows in order, `rows` samples each) and σ̂ `sigma` (mm): as
/// [`crate::choose_noise`], the estimate pooled over the records.
pub fn choose_campaign_noise(
    choice: &NoiseChoice,
    residual: &[f64],
    rows: &[usize],
    sigma: Option<f64>,
) -> NoiseModel {
    let sigma = sigma.unwrap_or(0.0);
    match choice {
        NoiseChoice::Ordinary => NoiseModel::residual(sigma, "ordinary least squares"),
        NoiseChoice::Instrument => NoiseModel::residual(
            sigma,
            "ordinary least squares: the records declare no covariances",
        ),
        NoiseChoice::Model(m) => m.clone(),
        NoiseChoice::Estimate => {
            let mut series: Vec<Vec<[f64; 3]>> = Vec::with_capacity(rows.len());
            let mut at = 0;
            for &n in rows {
                series.push(
                    residual[at..at + 3 * n]
                        .chunks_exact(3)
                        .map(|r| [r[0], r[1], r[2]])
                        .collect(),
                );
                at += 3 * n;
            }
            let refs: Vec<&[[f64; 3]]> = series.iter().map(Vec::as_slice).collect();
            NoiseModel::estimate(&refs).unwrap_or_else(|e| {
                NoiseModel::residual(sigma, format!("ordinary least squares: {e}"))
            })
        }
    }
}

/// As [`choose_campaign_noise`] from the residual of `fit` (mm, the records' rows in order),
/// whitened first per sample by `weights` when the readings carry covariances (the noise model
/// then describes the whitened rows, as the fits of a record read through an instrument do).
///
/// # Errors
/// [`EstimateError::Noise`] when the weights do not fit the rows.
pub fn choose_campaign_noise_weighted(
    choice: &NoiseChoice,
    fit: &Fit,
    rows: &[usize],
    weights: Option<&SampleWhitening>,
) -> Result<NoiseModel, EstimateError> {
    if let (NoiseChoice::Instrument, Some(w)) = (choice, weights) {
        return Ok(NoiseModel::white(w.scale_mm, NoiseSource::Instrument));
    }
    let Some(w) = weights else {
        return Ok(choose_campaign_noise(
            choice,
            fit.residual.as_slice(),
            rows,
            fit.sigma,
        ));
    };
    let mut r = fit.residual.clone();
    w.whiten_vector(&mut r)?;
    let sigma = (fit.dof > 0).then(|| (r.norm_squared() / fit.dof as f64).sqrt());
    Ok(choose_campaign_noise(choice, r.as_slice(), rows, sigma))
}

/// Identifies `model` of `m` on `campaign` (a record is a campaign of one): the design matrix
/// with the best gain sources ([`super::design::design_matrix`]), the first-order fit ([`fit_design`]) under
/// the options' noise model, and, when the options ask for it ([`IdentifyOptions::refine`]),
/// its refinement against the exact machine ([`CampaignIdentification::refinement`]). A
/// constraint of a campaign of one record may name the record's columns as the record's model
/// does (`XOW`, `dx0`: [`single_record_names`]).
///
/// # Errors
/// As [`super::design::design_matrix`] and [`fit_design`]; [`IdentifyError::NotConverged`] when a refinement
/// does not converge (its values are no identification).
pub fn identify(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    opts: &IdentifyOptions,
) -> Result<CampaignIdentification, IdentifyError> {
    check_options(opts)?;
    let mut opts = opts.clone();
    opts.constraint = single_record_names(m, model, campaign, opts.constraint);
    if let Some(refine) = &opts.refine {
        return super::refine::identify_refined(m, model, campaign, &opts, refine);
    }
    let (design, solved) = Solved::design(m, model, campaign)?;
    Ok(fit_system(m, model, campaign, &design, &solved, &opts)?)
}

/// Refuses options that belong to the records in a campaign.
pub(crate) fn check_options(opts: &IdentifyOptions) -> Result<(), EstimateError> {
    if opts.zeroed || opts.params.is_some() {
        return Err(EstimateError::Shape(
            "in a campaign every record says whether it is zeroed and what its kinematic parameters are (CampaignRecord::zeroed, ::params); the identification options must leave them unset".into(),
        ));
    }
    Ok(())
}

/// The first-order fit of `model` on `campaign` with its `design` matrix, for a caller that
/// keeps the design (the refinement in [`IdentifyOptions::refine`] is not done here): the ordinary fit
/// (`opts`: constraint and tolerances; the records carry zeroing and parameters), then, unless the
/// options' noise is [`NoiseChoice::Ordinary`], the noise model from its residual (pooled over the
/// records) and the generalized least-squares fit, each record's rows whitened on their own.
///
/// # Errors
/// Readings missing or not finite (the record named), fewer readings than parameters plus
/// one, a bad constraint, an SVD that does not converge, a noise model that cannot whiten.
pub fn fit_design(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    design: &Design,
    opts: &IdentifyOptions,
) -> Result<CampaignIdentification, EstimateError> {
    fit_system(m, model, campaign, design, &Solved::copied(design), opts)
}

/// [`fit_design`] with the design's H in solve order (`solved`): the design gives the layout
/// and the records' rows, not its H.
fn fit_system(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    design: &Design,
    solved: &Solved,
    opts: &IdentifyOptions,
) -> Result<CampaignIdentification, EstimateError> {
    let Solved { h, names, order } = solved;
    let noise = &opts.noise;
    check_options(opts)?;
    let samples = campaign.samples();
    check_readings(samples, design.names.len())?;
    let y = measurements(campaign)?;
    let weights = super::whitening(campaign, noise)?;
    let (c, t) = (&opts.constraint, &opts.tolerances);
    check_readings_of(h, &y, names)?;
    let w = weights.as_ref();
    let factored = RowsFactored::for_readings(h, &y, names, c, t, None, &design.rows, w)?;
    let (ordinary, weighted_sigma) = factored.fit(h, &y)?;
    if *noise == NoiseChoice::Ordinary {
        let ordinary = (ordinary, weighted_sigma);
        return Ok(ordinary_identification(
            m, model, design, order, ordinary, w,
        ));
    }
    let chosen = choose_campaign_noise_weighted(noise, &ordinary, &design.rows, w)?;
    // The generalized fit reuses the ordinary factorisation: only the whitened H is new.
    let (fit, whitened_sigma) = factored
        .under(h, Some(&y), names, c, t, &chosen)?
        .fit(h, &y)?;
    let mut ident = CampaignIdentification::new(m, model, design, to_layout_order(fit, order));
    ident.noise = chosen;
    ident.whitened_sigma = whitened_sigma;
    at_declared_scale(&mut ident);
    Ok(ident)
}

/// The p-value below which a fit's residual refutes the instrument's declared noise
/// (the uncertainties of an identification under [`NoiseChoice::Instrument`]): 1 %.
pub const DECLARED_REFUTED: f64 = 0.01;

/// Under the instrument's declared noise ([`NoiseChoice::Instrument`]): the uncertainties at the
/// declared scale (the fit's own scale the σ̂ of its whitened residual, about 1 when the declared
/// σ is right), unless the residual refutes it (`χ² = σ̂_w²·dof`, upper tail below
/// [`DECLARED_REFUTED`]): the model then misses something or the σ is optimistic, and the
/// uncertainties keep the residual's scale, the noise model saying why.
pub(crate) fn at_declared_scale(ident: &mut CampaignIdentification) {
    if ident.noise.source != NoiseSource::Instrument {
        return;
    }
    let dof = ident.fit.dof;
    let Some(ws) = ident.whitened_sigma.filter(|w| *w > 0.0 && w.is_finite()) else {
        return;
    };
    if dof == 0 {
        return;
    }
    let p = crate::distributions::chi2_upper_tail(ws * ws * dof as f64, dof as f64);
    if p < DECLARED_REFUTED {
        let sigma = ident.noise.sigma_mm[0] * ws;
        ident.noise = NoiseModel::residual(
            sigma,
            format!(
                "the instrument's declared σ is refuted by the residual: σ̂ of the whitened residual {ws:.3} over {dof} degrees of freedom, χ² upper tail {p:.1e} < {DECLARED_REFUTED}; the model misses something or the σ is optimistic (rtest diagnose)"
            ),
        );
        return;
    }
    for s in ident.fit.std.iter_mut().flatten() {
        *s /= ws;
    }
    ident.fit.covariance /= ws * ws;
}

/// The ordinary identification of `model` on the campaign of `design` from `fit`, the fit of
/// the system in solve `order` and the σ̂ of its rows whitened by `weights` (as
/// [`crate::identify::fit_rows`] gives them).
pub(crate) fn ordinary_identification(
    m: &Machine,
    model: &Model,
    design: &Design,
    order: &[usize],
    (fit, weighted_sigma): (Fit, Option<f64>),
    weights: Option<&SampleWhitening>,
) -> CampaignIdentification {
    let mut ident = CampaignIdentification::new(m, model, design, to_layout_order(fit, order));
    if let (Some(w), Some(s)) = (weights, weighted_sigma) {
        ident.noise = NoiseModel::residual(
            s * w.scale_mm,
            "ordinary least squares of the rows whitened by each sample's covariance",
        );
        ident.whitened_sigma = Some(s);
    }
    ident
}

impl CampaignIdentification {
    /// The identification of `model` on the campaign of `design` by `fit` (layout order): the
    /// records' shares of the residual, what the sensor offsets swallow; an ordinary fit (noise
    /// model: white with the fit's σ̂).
    pub fn new(m: &Machine, model: &Model, design: &Design, fit: Fit) -> CampaignIdentification {
        let layout = design.layout.clone();
        let is_offset: Vec<bool> = layout
            .columns
            .iter()
            .map(|c| matches!(c.term.effect, Effect::SensorOffset(_)))
            .collect();
        let swallowed =
            swallowed_by_offsets(&fit.names, &fit.identifiability.confounded, &is_offset);
        let noise = NoiseModel::residual(fit.sigma.unwrap_or(0.0), "ordinary least squares");
        let mut at = 0;
        let records = layout
            .records
            .iter()
            .map(|r| {
                let rows = 3 * r.samples;
                let rss = fit.residual.rows(at, rows).norm_squared();
                at += rows;
                RecordFit {
                    label: r.label.clone(),
                    setup: layout.setups[r.setup].clone(),
                    samples: r.samples,
                    zeroed: r.zeroed,
                    rss,
                }
            })
            .collect();
        CampaignIdentification {
            machine: m.name.clone(),
            model: model.clone(),
            layout,
            fit,
            records,
            swallowed,
            backend: design.backend,
            noise,
            whitened_sigma: None,
            refinement: None,
        }
    }

    /// The records' shares of `residual` (mm, the records' rows in order) as [`RecordFit`]s
    /// (their RSS).
    pub(crate) fn set_residual(&mut self, residual: &DVector<f64>) {
        let mut at = 0;
        for r in &mut self.records {
            let rows = 3 * r.samples;
            r.rss = residual.rows(at, rows).norm_squared();
            at += rows;
        }
    }

    /// The campaign fit as an [`crate::Identification`] of the layout's columns (one term
    /// per column group, named with their owners: `XOW[k4]`), for code that reports a fit:
    /// samples over every record, zeroed when any record is.
    pub fn as_identification(&self) -> crate::Identification {
        crate::Identification {
            machine: self.machine.clone(),
            model: Model {
                terms: self
                    .layout
                    .columns
                    .iter()
                    .filter(|c| c.component == 0)
                    .map(|c| c.term)
                    .collect(),
            },
            fit: self.fit.clone(),
            samples: self.records.iter().map(|r| r.samples).sum(),
            zeroed: self.records.iter().any(|r| r.zeroed),
            swallowed: self.swallowed.clone(),
            backend: self.backend,
            noise: self.noise.clone(),
            whitened_sigma: self.whitened_sigma,
            nominal_mm: self.layout.nominal_mm(),
        }
    }

    /// For a campaign of one record, its fit as that record's model has it: the columns in
    /// the record's model order (the sensor offsets `dx0 dy0 dz0` appended when its readings
    /// were zeroed), named without owners (`XOW`, not `XOW[k4]`), its nominal kinematic
    /// values; the same values, uncertainties and residual. `None` for several records.
    pub fn single_record(&self, m: &Machine) -> Option<Identification> {
        let [record] = self.layout.records.as_slice() else {
            return None;
        };
        let n = self.layout.columns.len();
        if record.columns.len() != n {
            return None;
        }
        // Layout column `record.columns[p]` becomes column `p`.
        let mut order = vec![0; n];
        for (p, &c) in record.columns.iter().enumerate() {
            order[c] = p;
        }
        let mut fit = to_layout_order(self.fit.clone(), &order);
        fit.names = record
            .columns
            .iter()
            .map(|&c| {
                let col = &self.layout.columns[c];
                crate::hmatrix::parameter_name(m, &col.term, col.component)
            })
            .collect();
        let is_offset: Vec<bool> = record
            .columns
            .iter()
            .map(|&c| matches!(self.layout.columns[c].term.effect, Effect::SensorOffset(_)))
            .collect();
        let swallowed =
            swallowed_by_offsets(&fit.names, &fit.identifiability.confounded, &is_offset);
        let nominal = self.layout.nominal_mm();
        Some(Identification {
            machine: self.machine.clone(),
            model: record.model.clone(),
            fit,
            samples: record.samples,
            zeroed: record.zeroed,
            swallowed,
            backend: self.backend,
            noise: self.noise.clone(),
            whitened_sigma: self.whitened_sigma,
            nominal_mm: record.columns.iter().map(|&c| nominal[c]).collect(),
        })
    }

    /// The columns owned by `owner`.
    pub fn columns_of(&self, owner: Owner) -> Vec<usize> {
        (0..self.layout.columns.len())
            .filter(|&j| self.layout.columns[j].owner == owner)
            .collect()
    }
}
