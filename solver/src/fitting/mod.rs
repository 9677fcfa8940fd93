//! From records to values: the H matrix, least squares with identifiability, the refinement
//! against the exact machine, streaming identification, and validation on other records.
//!
//! - [`hmatrix`]: the design matrix of a model on a record, with gains from compiled code or
//!   the in-process evaluator ([`hmatrix::GainSource`]);
//! - [`estimate`]: column-scaled least squares with a stated numerical rank, uncertainties, and
//!   no number for what the data cannot determine; identification of a model on a record;
//! - [`identifiability`]: what the data can and cannot tell apart;
//! - [`refine`]: Gauss–Newton against the exact machine, removing the second-order bias;
//! - [`streaming`]: identification of long records in blocks, memory bounded by the model;
//! - [`mod@validate`]: the identified model's prediction against another record;
//! - [`distributions`]: the F and t distributions of the significance tests.

pub mod distributions;
pub mod estimate;
pub mod hmatrix;
pub mod identifiability;
pub mod refine;
pub mod streaming;
pub mod validate;

pub use estimate::{
    Constraint, EstimateError, Fit, Identification, IdentifyOptions, Tolerances, identify,
    identify_with, least_squares,
};
pub use hmatrix::{Backend, GainSource, HMatrixError, h_matrix};
pub use refine::{RefineError, RefineOptions, Refinement, identify_refined};
pub use validate::{ValidateError, ValidateOptions, Validation, validate};
