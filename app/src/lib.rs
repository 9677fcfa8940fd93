//! What rtest's verbs do, above every numeric crate and the reports.
//!
//! - [`demo`]: the seed's experiment replayed on the exact virtual machine, through
//!   simulation, identification, validation, diagnosis and compensation.

#![warn(missing_docs)]

pub mod demo;
