//! What an identification is made of: its options ([`IdentifyOptions`]), a record's
//! measurement vector, the fit of rows ([`fit_rows`]: ordinary or generalized least squares,
//! each sample whitened by its covariance first), the noise model chosen from a residual, and a
//! fit as one record's model has it ([`Identification`], with what the sensor zero offsets
//! `dx0 dy0 dz0` swallow). The identification itself is [`crate::identify()`]: it takes a
//! campaign (a record is a campaign of one), first order or refined against the exact machine
//! ([`super::refine`]).
//!
//! Under a noise model ([`IdentifyOptions::noise`]): first an ordinary fit, then the noise model
//! ([`choose_noise`]: declared, from a static record, or estimated from the ordinary fit's
//! residual), then the generalized least-squares fit of the whitened rows
//! ([`super::least_squares_whitened`]), whose uncertainties are honest under correlated noise.
//!
//! A record with covariances (read through an instrument) has every sample's rows whitened by
//! its covariance first ([`SampleWhitening`]: the shape, the mean noise kept as the scale), in
//! the ordinary fit and under a noise model alike ([`fit_rows`]); the noise model is then
//! estimated from, or describes, the whitened rows, and a declared one is refused
//! ([`NoiseError::DeclaredTwice`]). The values, uncertainties and correlations are the whitened
//! fit's; the residual, σ̂, rank and identifiability those of the readings and the path.

use super::factored::{RowsFactored, check_readings_of};
use super::hmatrix::{Backend, GainSource};
use super::identifiability::{Swallowed, swallowed_by_offsets};
use super::least_squares::{Constraint, EstimateError, Fit, Tolerances};
use super::noise::{NoiseChoice, NoiseError, NoiseModel, NoiseSource, SampleWhitening};
use super::refine::RefineOptions;
use model_spec::{Dir, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::model::{Basis, Effect, Model, Term};
use simulation::record::Record;

/// The stacked measured error vectors of `record` (mm): `[x₀, y₀, z₀, x₁, …]`.
///
/// # Errors
/// No measurements, one row per sample missing, or a value that is not finite.
pub fn measurement_vector(record: &Record) -> Result<DVector<f64>, EstimateError> {
    if record.measured.len() != record.samples.len() {
        return Err(EstimateError::Shape(format!(
            "the record has {} samples but {} measured error vectors",
            record.samples.len(),
            record.measured.len()
        )));
    }
    let y = DVector::from_iterator(
        3 * record.measured.len(),
        record.measured.iter().flat_map(|r| r.iter().copied()),
    );
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(EstimateError::NotFinite(format!(
            "the measured {} of sample {}",
            ["dx", "dy", "dz"][i % 3],
            i / 3
        )));
    }
    Ok(y)
}

/// `model` with the constant sensor offsets `dx0 dy0 dz0` appended (those it lacks).
pub fn with_offsets(model: &Model) -> Model {
    let mut out = model.clone();
    for d in Dir::ALL {
        let t = Term {
            effect: Effect::SensorOffset(d),
            basis: Basis::Const,
        };
        if !out.terms.contains(&t) {
            out.terms.push(t);
        }
    }
    out
}

/// Options of [`crate::identify()`] (`IdentifyOptions::default()`, then set the fields wanted; new
/// fields come with defaults that keep today's behaviour).
#[derive(Clone, Debug, PartialEq, Default)]
#[non_exhaustive]
pub struct IdentifyOptions {
    /// For a streamed record ([`crate::streaming::identify_file`]), which is read in blocks and
    /// never held as a campaign: its readings were zeroed at the first sample, so the constant
    /// offsets `dx0 dy0 dz0` join the model (they absorb the unknown reading subtracted), and
    /// [`Identification::swallowed`] says which errors they cannot be told from. A campaign's
    /// records say it themselves (`CampaignRecord::zeroed`), and [`crate::identify()`] refuses
    /// it here.
    pub zeroed: bool,
    /// What to do with undetermined parameters.
    pub constraint: Constraint,
    /// Rank and identifiability tolerances.
    pub tolerances: Tolerances,
    /// For a streamed record: its kinematic parameters (mm, symbol order); `None`: the
    /// machine's defaults. A campaign's records carry their own (`CampaignRecord::params`), and
    /// [`crate::identify()`] refuses them here.
    pub params: Option<Vec<f64>>,
    /// The noise model the fit assumes: ordinary least squares by default; estimated from the
    /// residual, or a given model, for a generalized least-squares fit (see the module
    /// documentation).
    pub noise: NoiseChoice,
    /// Refine the first-order fit against the exact machine (Gauss–Newton) with these options;
    /// `None` (the default): the first-order fit.
    pub refine: Option<RefineOptions>,
}

impl IdentifyOptions {
    /// The defaults: readings not zeroed, no constraint, default tolerances and parameters.
    pub fn new() -> IdentifyOptions {
        IdentifyOptions::default()
    }

    /// With readings zeroed at the first sample (or not).
    pub fn zeroed(mut self, zeroed: bool) -> IdentifyOptions {
        self.zeroed = zeroed;
        self
    }

    /// With `constraint` for undetermined parameters.
    pub fn constraint(mut self, constraint: Constraint) -> IdentifyOptions {
        self.constraint = constraint;
        self
    }

    /// With the kinematic parameters `params` (mm, symbol order).
    pub fn params(mut self, params: Vec<f64>) -> IdentifyOptions {
        self.params = Some(params);
        self
    }

    /// Under the noise model `noise`.
    pub fn noise(mut self, noise: NoiseChoice) -> IdentifyOptions {
        self.noise = noise;
        self
    }

    /// Refined against the exact machine with `refine` (see [`IdentifyOptions::refine`]).
    pub fn refined(mut self, refine: RefineOptions) -> IdentifyOptions {
        self.refine = Some(refine);
        self
    }

    /// The model fitted for `model`: with the sensor offsets when the readings are zeroed.
    pub fn fitted_model(&self, model: &Model) -> Model {
        if self.zeroed {
            with_offsets(model)
        } else {
            model.clone()
        }
    }

    /// The kinematic parameters: those given, else the machine's defaults.
    pub fn parameters(&self, m: &Machine) -> Vec<f64> {
        self.params
            .clone()
            .unwrap_or_else(|| m.default_parameters())
    }
}

/// Checks that `samples` give at least one reading more than `parameters` (3N − p ≥ 1, so that
/// σ̂ and the uncertainties exist), before any fitting.
///
/// # Errors
/// [`EstimateError::TooFewReadings`].
pub fn check_readings(samples: usize, parameters: usize) -> Result<(), EstimateError> {
    if 3 * samples < parameters + 1 {
        return Err(EstimateError::TooFewReadings {
            samples,
            readings: 3 * samples,
            parameters,
        });
    }
    Ok(())
}

/// An identification: the fitted model and its fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Identification {
    /// The machine's name.
    pub machine: String,
    /// The model fitted (with `dx0 dy0 dz0` when the readings were zeroed); its columns are the
    /// fit's parameters.
    pub model: Model,
    /// The least-squares fit.
    pub fit: Fit,
    /// Number of samples used.
    pub samples: usize,
    /// Whether the readings were zeroed at the first sample.
    pub zeroed: bool,
    /// Per confounded group with a sensor offset: the errors it swallows.
    pub swallowed: Vec<Swallowed>,
    /// Which code computed the gains.
    pub backend: Backend,
    /// The noise model the uncertainties assume: white with the residual's σ̂ for an ordinary
    /// fit ([`crate::noise::NoiseSource::Residual`]), else the model the rows were
    /// whitened by.
    pub noise: NoiseModel,
    /// σ̂ of the whitened residual (unitless; about 1 when the noise model's σ, or the
    /// covariances' of a record read through an instrument, are right), for a fit whitened by
    /// a noise model or by covariances; `None` for an ordinary fit.
    pub whitened_sigma: Option<f64>,
    /// One entry per parameter: for a kinematic offset, the value of its symbol the change is
    /// relative to (the kinematic parameter the record was modelled with, mm); `None` for
    /// every other parameter.
    pub nominal_mm: Vec<Option<f64>>,
}

/// The gain source an identification of `model` with `opts` needs: every error of the fitted
/// model, at the options' kinematic parameters.
///
/// # Errors
/// A model that does not fit `m`, parameters of the wrong length or not finite.
pub fn gain_source(
    m: &Machine,
    model: &Model,
    opts: &IdentifyOptions,
) -> Result<GainSource, EstimateError> {
    let fitted = opts.fitted_model(model);
    crate::hmatrix::check_model(m, &fitted)?;
    Ok(GainSource::new(m, &fitted.errors(), &opts.parameters(m))?)
}

/// The noise model of `choice` for an ordinary fit with `residual` (mm, 3 rows per sample, one
/// record) and σ̂ `sigma` (mm): [`NoiseChoice::Ordinary`] is white with σ̂;
/// [`NoiseChoice::Model`] the model; [`NoiseChoice::Estimate`] the estimate from the residual
/// ([`NoiseModel::estimate`]), or, when the residual cannot give one (too short, or at
/// rounding level on noise-free data), white with σ̂, the source saying why.
pub fn choose_noise(choice: &NoiseChoice, residual: &[f64], sigma: Option<f64>) -> NoiseModel {
    let sigma = sigma.unwrap_or(0.0);
    match choice {
        NoiseChoice::Ordinary => NoiseModel::residual(sigma, "ordinary least squares"),
        NoiseChoice::Instrument => NoiseModel::residual(
            sigma,
            "ordinary least squares: the record declares no covariances",
        ),
        NoiseChoice::Model(m) => m.clone(),
        NoiseChoice::Estimate => {
            let rows: Vec<[f64; 3]> = residual
                .chunks_exact(3)
                .map(|r| [r[0], r[1], r[2]])
                .collect();
            NoiseModel::estimate(&[&rows]).unwrap_or_else(|e| {
                NoiseModel::residual(sigma, format!("ordinary least squares: {e}"))
            })
        }
    }
}

/// The whitening of `record`'s covariances, when it has any, with the noise choice checked
/// against it.
///
/// # Errors
/// [`EstimateError::Noise`]: covariances that cannot whiten ([`SampleWhitening::of`]), or a
/// declared noise model for a record with covariances ([`NoiseError::DeclaredTwice`]).
pub fn sample_whitening(
    record: &Record,
    noise: &NoiseChoice,
) -> Result<Option<SampleWhitening>, EstimateError> {
    let w = SampleWhitening::of(record)?;
    if w.is_some()
        && let NoiseChoice::Model(model) = noise
        && model.source == NoiseSource::Declared
    {
        return Err(NoiseError::DeclaredTwice.into());
    }
    Ok(w)
}

/// The fit of the rows `h` (mm per unit of each parameter) and `y` (mm) of records of `layout`
/// samples: ordinary least squares, or generalized under `noise`
/// ([`super::least_squares_whitened`]); first whitened per sample by `weights` when the
/// readings carry covariances. With `weights`, the values, uncertainties, covariance,
/// correlation and near-confounded pairs are the whitened fit's; the residual, RSS and σ̂ those
/// of the readings (`y − H·p̂`, mm), the rank and identifiability those of `h`. The second value
/// is the σ̂ of the whitened residual relative to what the whitening assumed (about 1 when the
/// covariances' or the noise model's σ are right): `None` for an ordinary fit without weights.
///
/// # Errors
/// As [`super::least_squares()`] and [`super::least_squares_whitened`];
/// [`EstimateError::Noise`] when the weights do not fit the rows or change the rank.
#[allow(clippy::too_many_arguments)]
pub fn fit_rows(
    h: &DMatrix<f64>,
    y: &DVector<f64>,
    names: &[String],
    constraint: &Constraint,
    tolerances: &Tolerances,
    noise: Option<&NoiseModel>,
    layout: &[usize],
    weights: Option<&SampleWhitening>,
) -> Result<(Fit, Option<f64>), EstimateError> {
    check_readings_of(h, y, names)?;
    RowsFactored::for_readings(h, y, names, constraint, tolerances, noise, layout, weights)?
        .fit(h, y)
}

/// [`choose_noise`] for a fit of a record whitened by `weights` (when it has covariances): the
/// noise model is estimated from the whitened residual, the rows it will whiten.
///
/// # Errors
/// [`EstimateError::Noise`] when the weights do not fit the residual.
pub fn choose_noise_weighted(
    choice: &NoiseChoice,
    fit: &Fit,
    weights: Option<&SampleWhitening>,
) -> Result<NoiseModel, EstimateError> {
    let Some(w) = weights else {
        return Ok(choose_noise(choice, fit.residual.as_slice(), fit.sigma));
    };
    let mut r = fit.residual.clone();
    w.whiten_vector(&mut r)?;
    let sigma = (fit.dof > 0).then(|| (r.norm_squared() / fit.dof as f64).sqrt());
    Ok(choose_noise(choice, r.as_slice(), sigma))
}

impl Identification {
    /// An identification of `model` (the model fitted, offsets included) by `fit` with gains
    /// from `source` (its backend; its kinematic parameters, the values the changes of
    /// kinematic offsets are relative to), with what the sensor offsets swallow derived from
    /// the fit's confounded groups; an ordinary fit (noise model: white with the fit's σ̂).
    pub fn new(
        m: &Machine,
        model: Model,
        fit: Fit,
        samples: usize,
        zeroed: bool,
        source: &GainSource,
    ) -> Identification {
        let backend = source.backend();
        let nominal_mm = crate::offsets::nominal_of_columns(&model, source.params());
        let is_offset: Vec<bool> = model
            .columns()
            .iter()
            .map(|&(t, _)| matches!(model.terms[t].effect, Effect::SensorOffset(_)))
            .collect();
        let swallowed =
            swallowed_by_offsets(&fit.names, &fit.identifiability.confounded, &is_offset);
        let noise = NoiseModel::residual(fit.sigma.unwrap_or(0.0), "ordinary least squares");
        Identification {
            machine: m.name.clone(),
            model,
            fit,
            samples,
            zeroed,
            swallowed,
            backend,
            noise,
            whitened_sigma: None,
            nominal_mm,
        }
    }
}
