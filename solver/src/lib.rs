//! The numeric side of rtest: from a machine description and R-test records to identified
//! errors, their check on other paths, and what the model lacks.
//!
//! The modules follow the data, one stage each:
//!
//! - [`simulation`]: the exact virtual machine (exact homogeneous transforms, no
//!   linearisation), finite-difference gains, test paths and the nominal inverse kinematics,
//!   truths (what a virtual machine's errors really are) and simulated readings;
//! - [`io`]: measurement CSV files (read whole or in blocks, written exactly) and the JSON
//!   reports of identification, validation and diagnosis;
//! - [`fitting`]: the H matrix, least squares with identifiability, the refinement against the
//!   exact machine, streaming identification and validation on other records;
//! - [`diagnosis`]: what a model lacks, named, with the extended model and its gain.
//!
//! [`record`] (samples along a path, with readings) and [`model`] (the terms a fit has) are the
//! contract between the stages; [`demo`] replays the seed's experiment through all of them.
//!
//! Units inside: lengths and translational errors in mm, rotary commands and angular errors in
//! rad. Conversions to degrees, µm and µrad happen at the boundaries people see
//! ([`model_spec::units`]), not here.
//!
//! # Example: simulate, identify, validate
//!
//! ```
//! use model_spec::builtin;
//! use solver::fitting::{IdentifyOptions, ValidateOptions, identify, validate};
//! use solver::model::Model;
//! use solver::simulation::{builtin_path, builtin_truth, simulate};
//!
//! let m = builtin("seed-ac").unwrap().unwrap();
//! // The seed's reduced model, and a virtual machine whose errors are exactly its terms.
//! let model = Model::of(&m, "reduced").unwrap();
//! let truth = builtin_truth("seed-ac-reduced", &m).unwrap().unwrap();
//! let k4 = simulate(&m, &truth, &builtin_path(&m, "K4").unwrap().unwrap()).unwrap();
//! let k1 = simulate(&m, &truth, &builtin_path(&m, "K1").unwrap().unwrap()).unwrap();
//!
//! // Identify on K4 (first order; `fitting::identify_refined` removes the second-order bias).
//! let ident = identify(&m, &model, &k4, &IdentifyOptions::default()).unwrap();
//! let xoc = ident.fit.names.iter().position(|n| n == "XOC").unwrap();
//! let truth_xoc = truth.coefficient(&model.terms[7]).unwrap()[0];
//! assert!((ident.fit.values[xoc].unwrap() - truth_xoc).abs() < 1e-5); // mm
//!
//! // The identified values predict K1, a path they were not fitted on, to well below 0.01 µm.
//! let v = validate(&m, &ident.model, &ident.fit.values, &k1, &ValidateOptions::default()).unwrap();
//! assert!(v.overall.residual_rms < 1e-5); // mm
//! ```

#![warn(missing_docs)]

pub mod compensation;
pub mod demo;
pub mod diagnosis;
pub mod fitting;
pub mod instrument;
pub mod io;
pub mod model;
mod parallel;
pub mod record;
pub mod simulation;
