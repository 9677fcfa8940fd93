//! The symbolic engine of rtest.
//!
//! spec → [`GainModel`] (exact first-order gains, canonical polynomials) → [`ir::Program`]
//! (flat straight-line code after common-subexpression elimination) → Rust source
//! ([`emit`]) or in-process evaluation ([`ir::Program::eval`]); and gain tables for people
//! ([`table`]).

#![warn(missing_docs)]

pub mod atoms;
pub mod compensation;
pub mod derive;
mod hash;
pub mod identity;
pub mod intermediates;
pub mod poly;
pub mod rational;

pub use derive::GainModel;
pub use intermediates::DeriveOptions;
pub mod build;
pub mod emit;
pub mod ir;
pub mod lower;
mod parts;
pub mod table;

pub use ir::Program;
pub use lower::{MAX_INSTRUCTIONS, Part, compile, compile_parts, compile_position};
