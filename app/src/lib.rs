//! What rtest's verbs do: one function per verb, taking its parsed options, above every
//! numeric crate and the reports. The `rtest` binary is clap, that call and printing.
//!
//! - [`error`]: the error of a verb and its class (bad input, usage, failed computation), which
//!   decides the exit code.
//! - [`verbs`]: the verbs, one module each, with their options (clap `Args`) and what they
//!   share: loading a machine, reading records, checking and writing the outputs.
//! - [`done`]: what a verb hands back (its text, its outputs, the check it records) and how
//!   it is finished: outputs written all or none, then the check recorded.
//! - [`demo`]: the seed's experiment replayed on the exact virtual machine, through
//!   simulation, identification, validation, diagnosis and compensation.

#![warn(missing_docs)]

pub mod demo;
pub mod done;
pub mod error;
pub mod verbs;

pub use done::{Done, Shown};
pub use error::{Class, Error, VerbResult};
