//! From records to values: the H matrix, least squares with identifiability, the refinement
//! against the exact machine, streaming identification, and validation on other records.
//!
//! - [`hmatrix`]: the design matrix of a model on a record, with gains from compiled code or
//!   the in-process evaluator ([`hmatrix::GainSource`]);
//! - [`mod@least_squares`]: column-scaled least squares with a stated numerical rank,
//!   uncertainties, and no number for what the data cannot determine;
//! - [`mod@identify`]: a model identified on a record (first order), with what the sensor
//!   offsets swallow;
//! - [`identifiability`]: what the data can and cannot tell apart;
//! - [`offsets`]: kinematic offsets (symbols of the description) as unknowns: their gains,
//!   their changes in the exact machine, who owns them in a campaign;
//! - [`noise`]: the reading noise (white or AR(1) per direction: declared, from a static
//!   record, or estimated without trusting the model) and the prewhitening that makes it white;
//! - [`refine`]: Gauss–Newton against the exact machine, removing the second-order bias;
//! - [`streaming`]: identification of long records in blocks, memory bounded by the model;
//! - [`mod@validate`]: the identified model's prediction against another record;
//! - [`distributions`]: the F and t distributions of the significance tests.

pub mod campaign;
pub mod distributions;
pub mod factored;
pub mod hmatrix;
pub mod identifiability;
pub mod identify;
pub mod least_squares;
pub mod noise;
pub mod offsets;
pub mod plan;
pub mod refine;
pub mod sanity;
pub mod streaming;
mod svd;
pub mod validate;

pub use hmatrix::{Backend, GainSource, HMatrixError, h_matrix};
pub use identify::{
    Identification, IdentifyOptions, check_readings, choose_noise, gain_source, identify,
    identify_noise, identify_with, identify_with_noise, measurement_vector, with_offsets,
};
pub use least_squares::{
    Constraint, EstimateError, Fit, RANK_RELATIVE_TOLERANCE, Tolerances, WhitenedFit,
    least_squares, least_squares_reduced, least_squares_whitened,
};
pub use noise::{NoiseChoice, NoiseModel, NoiseSource};
pub use refine::{
    RefineError, RefineOptions, Refinement, identify_refined, identify_refined_noise,
    identify_refined_with, identify_refined_with_noise,
};
pub use sanity::{Implausible, ValueLimits, check_values};
pub use validate::{ValidateError, ValidateOptions, Validation, validate};
