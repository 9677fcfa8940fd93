//! Identification of a model on a record: the H matrix of the model (with the sensor zero
//! offsets `dx0 dy0 dz0` when the readings were zeroed), the least-squares fit of
//! [`super::least_squares()`], and what the offsets swallow. First order; [`super::refine`]
//! refines it against the exact machine.
//!
//! Under a noise model ([`identify_with_noise`]): first an ordinary fit, then the noise model
//! ([`choose_noise`]: declared, from a static record, or estimated from the ordinary fit's
//! residual), then the generalized least-squares fit of the whitened rows
//! ([`super::least_squares_whitened`]), whose uncertainties are honest under correlated noise.

use super::hmatrix::{Backend, GainSource, h_matrix, parameter_names};
use super::identifiability::{Swallowed, swallowed_by_offsets};
use super::least_squares::{
    Constraint, EstimateError, Fit, Tolerances, least_squares, least_squares_whitened,
};
use super::noise::{NoiseChoice, NoiseModel};
use crate::model::{Basis, Effect, Model, Term};
use crate::record::Record;
use model_spec::{Dir, Machine};
use nalgebra::DVector;

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

/// Options of [`identify`] (`IdentifyOptions::default()`, then set the fields wanted; new
/// fields come with defaults that keep today's behaviour).
#[derive(Clone, Debug, PartialEq, Default)]
#[non_exhaustive]
pub struct IdentifyOptions {
    /// The readings were zeroed at the first sample: the constant offsets `dx0 dy0 dz0` join
    /// the model (they absorb the unknown reading subtracted), and [`Identification::swallowed`]
    /// says which errors they cannot be told from.
    pub zeroed: bool,
    /// What to do with undetermined parameters.
    pub constraint: Constraint,
    /// Rank and identifiability tolerances.
    pub tolerances: Tolerances,
    /// Kinematic parameters (mm, symbol order); `None`: the machine's defaults.
    pub params: Option<Vec<f64>>,
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
    /// fit ([`crate::fitting::noise::NoiseSource::Residual`]), else the model the rows were
    /// whitened by.
    pub noise: NoiseModel,
    /// σ̂ of the whitened residual (unitless; about 1 when the noise model's σ is right), for a
    /// fit whitened by a noise model; `None` for an ordinary fit.
    pub whitened_sigma: Option<f64>,
}

/// Identifies `model` of `m` from the measured `record` (first order), with the best gain
/// source (compiled code for built-in machines, the evaluator otherwise) for the fitted model
/// (offsets included when the readings are zeroed) at the options' kinematic parameters.
///
/// # Errors
/// See [`identify_with`].
pub fn identify(
    m: &Machine,
    model: &Model,
    record: &Record,
    opts: &IdentifyOptions,
) -> Result<Identification, EstimateError> {
    let mut source = gain_source(m, model, opts)?;
    identify_with(m, model, record, &mut source, opts)
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
    crate::fitting::hmatrix::check_model(m, &fitted)?;
    Ok(GainSource::new(m, &fitted.errors(), &opts.parameters(m))?)
}

/// As [`identify`], under the noise model `noise` (see the module documentation).
///
/// # Errors
/// See [`identify_with_noise`].
pub fn identify_noise(
    m: &Machine,
    model: &Model,
    record: &Record,
    opts: &IdentifyOptions,
    noise: &NoiseChoice,
) -> Result<Identification, EstimateError> {
    let mut source = gain_source(m, model, opts)?;
    identify_with_noise(m, model, record, &mut source, opts, noise)
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

/// As [`identify_with`], under the noise model `noise`: an ordinary fit, the noise model of
/// [`choose_noise`] from its residual, then generalized least squares
/// ([`super::least_squares_whitened`]) unless the choice is [`NoiseChoice::Ordinary`].
///
/// # Errors
/// As [`identify_with`]; [`EstimateError::Noise`] when the model cannot whiten or whitening
/// changes the rank.
pub fn identify_with_noise(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    opts: &IdentifyOptions,
    noise: &NoiseChoice,
) -> Result<Identification, EstimateError> {
    let fitted = opts.fitted_model(model);
    check_readings(record.samples.len(), fitted.width())?;
    let y = measurement_vector(record)?;
    let h = h_matrix(m, &fitted, record, source)?;
    let names = parameter_names(m, &fitted);
    let ordinary = least_squares(&h, &y, &names, &opts.constraint, &opts.tolerances)?;
    let samples = record.samples.len();
    if *noise == NoiseChoice::Ordinary {
        return Ok(Identification::new(
            m,
            fitted,
            ordinary,
            samples,
            opts.zeroed,
            source.backend(),
        ));
    }
    let model_of_noise = choose_noise(noise, ordinary.residual.as_slice(), ordinary.sigma);
    let w = least_squares_whitened(
        &h,
        &y,
        &names,
        &opts.constraint,
        &opts.tolerances,
        &model_of_noise,
        &[samples],
    )?;
    let mut ident = Identification::new(m, fitted, w.fit, samples, opts.zeroed, source.backend());
    ident.noise = model_of_noise;
    ident.whitened_sigma = w.whitened_sigma;
    Ok(ident)
}

/// As [`identify`], with gains from `source` (which must cover the model's errors; its
/// parameters are used, `opts.params` is ignored).
///
/// # Errors
/// A model or record that does not fit `m`, a record without (finite) measurements, fewer
/// readings than parameters plus one ([`check_readings`]), a bad constraint, an SVD that does
/// not converge.
pub fn identify_with(
    m: &Machine,
    model: &Model,
    record: &Record,
    source: &mut GainSource,
    opts: &IdentifyOptions,
) -> Result<Identification, EstimateError> {
    identify_with_noise(m, model, record, source, opts, &NoiseChoice::Ordinary)
}

impl Identification {
    /// An identification of `model` (the model fitted, offsets included) by `fit`, with what
    /// the sensor offsets swallow derived from the fit's confounded groups; an ordinary fit
    /// (noise model: white with the fit's σ̂).
    pub fn new(
        m: &Machine,
        model: Model,
        fit: Fit,
        samples: usize,
        zeroed: bool,
        backend: Backend,
    ) -> Identification {
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
        }
    }
}
