//! From records to values: the H matrix, least squares with identifiability, the refinement
//! against the exact machine, streaming identification, and validation on other records.
//!
//! - [`hmatrix`]: the design matrix of a model on a record, with gains from compiled code or
//!   the in-process evaluator ([`hmatrix::GainSource`]);
//! - [`mod@least_squares`]: column-scaled least squares with a stated numerical rank,
//!   uncertainties, and no number for what the data cannot determine;
//! - [`identify()`] (in [`campaign`]): the one identification, of a campaign (a record is a
//!   campaign of one), first order or refined; [`mod@identify`]: its options, a record's
//!   measurement vector, the fit of a record's model ([`Identification`]) and what the sensor
//!   offsets swallow;
//! - [`identifiability`]: what the data can and cannot tell apart;
//! - [`offsets`]: kinematic offsets (symbols of the description) as unknowns: their gains,
//!   their changes in the exact machine, who owns them in a campaign;
//! - [`noise`]: the reading noise (white or AR(1) per direction: declared, from a static
//!   record, or estimated without trusting the model) and the prewhitening that makes it white;
//! - [`refine`]: Gauss–Newton against the exact machine, removing the second-order bias;
//! - [`streaming`]: identification of long records in blocks, memory bounded by the model;
//! - [`validate()`] (in [`campaign`]): the identified values' prediction of other records;
//!   [`mod@validate`]: its options, errors and statistics;
//! - [`verdict`]: the conformance verdict of ISO 14253-1 (pass, fail, undecided) on a
//!   deviation against its tolerance, with its expanded uncertainty;
//! - [`distributions`]: the F and t distributions of the significance tests;
//! - [`plan`]: the records to measure next for a target uncertainty, chosen from the machine's
//!   tests;
//! - [`sanity`]: plausibility limits on identified values;
//! - [`factored`] (the fits on one factorization of the scaled H), `svd` (for a tall H its QR
//!   decomposition first, then the SVD of R, every SVD checked by rebuilding its matrix) and
//!   `fold` (that QR decomposition folded in blocks of rows, shared with [`streaming`]): the
//!   numerics behind [`mod@least_squares`];
//! - [`mod@calibrate`]: an instrument's own errors (sensor gain errors, zeros, direction
//!   errors) from a calibration record of known displacements;
//! - [`sphere`]: a touch probe's sphere fit of one pose (centre, radius, covariance, dirty hits
//!   refused).
//!
//! It builds on [`simulation`] (the model, the record, the campaign, the exact machine) and
//! [`formats`] (records read in blocks by the streaming identification); the diagnosis and the
//! compensation build on it.
//!
//! Units inside: lengths and translational errors in mm, rotary commands and angular errors in
//! rad. Conversions to degrees, µm and µrad happen at the boundaries people see
//! ([`model_spec::units`]), not here.
//!
//! # Example: simulate, identify, validate
//!
//! ```
//! use model_spec::builtin;
//! use fitting::campaign::CampaignValues;
//! use fitting::{IdentifyOptions, ValidateOptions, identify, validate};
//! use formats::progress::Unwatched;
//! use formats::truth::builtin_truth;
//! use simulation::campaign::{Campaign, CampaignRecord};
//! use simulation::model::Model;
//! use simulation::{builtin_path, simulate};
//!
//! let m = builtin("seed-ac").unwrap().unwrap();
//! // The seed's reduced model, and a virtual machine whose errors are exactly its terms.
//! let model = Model::of(&m, "reduced").unwrap();
//! let truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
//! let k4 = simulate(&m, &truth, &builtin_path(&m, "K4").unwrap().unwrap()).unwrap();
//! let k1 = simulate(&m, &truth, &builtin_path(&m, "K1").unwrap().unwrap()).unwrap();
//!
//! // Identify on K4, a campaign of one record (first order; `IdentifyOptions::refined` removes
//! // the second-order bias).
//! let params = m.default_parameters();
//! let k4 = Campaign::of_record(k4, params.clone(), false);
//! let ident = identify(&m, &model, &k4, &IdentifyOptions::default()).unwrap();
//! let xoc = ident.fit.names.iter().position(|n| n == "XOC").unwrap();
//! let truth_xoc = truth.coefficient(&model.terms[7]).unwrap()[0];
//! assert!((ident.fit.values[xoc].unwrap() - truth_xoc).abs() < 1e-5); // mm
//!
//! // The identified values predict K1, a path they were not fitted on (on K4's ball set-up),
//! // to well below 0.01 µm.
//! let k1 = CampaignRecord::new("k1", k1, params, "record", false);
//! let k1 = Campaign::new(vec![k1]).unwrap();
//! let values = CampaignValues::of(&ident);
//! let v = validate(&m, &values, &k1, &ValidateOptions::default(), &Unwatched).unwrap();
//! assert!(v.overall.residual_rms < 1e-5); // mm
//! ```

#![warn(missing_docs)]

pub mod calibrate;
pub mod campaign;
pub mod distributions;
pub mod factored;
mod fold;
pub mod hmatrix;
pub mod identifiability;
pub mod identify;
pub mod least_squares;
pub mod noise;
pub mod offsets;
pub mod plan;
pub mod probe;
pub mod refine;
pub mod sanity;
pub mod sphere;
pub mod streaming;
mod svd;
pub mod validate;
pub mod verdict;

pub use campaign::identify;
pub use campaign::validate::validate;
pub use hmatrix::{Backend, GainSource, HMatrixError, h_matrix};
pub use identify::{
    Identification, IdentifyOptions, check_readings, choose_noise, gain_source, measurement_vector,
    with_offsets,
};
pub use least_squares::{
    Constraint, EstimateError, Fit, RANK_RELATIVE_TOLERANCE, Tolerances, WhitenedFit,
    least_squares, least_squares_reduced, least_squares_whitened,
};
pub use noise::{NoiseChoice, NoiseModel, NoiseSource};
pub use refine::{IdentifyError, RefineOptions, Refinement};
pub use sanity::{Implausible, ValueLimits, check_values};
pub use validate::{ValidateError, ValidateOptions, Validation};
