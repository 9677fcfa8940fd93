//! Machine-tool descriptions for rtest.
//!
//! A machine is described in TOML (see `docs/model-spec.md`): the work chain and the tool chain
//! from the bed, each axis linear or rotary with its direction, kinematic offset (numbers or
//! named symbols with defaults) and stroke or range, the ISO 230 error terms of its model and
//! named sub-models. [`parse_machine`] validates a description into a [`Machine`];
//! [`kinematics::chain_steps`] lowers its chains to the one list of elementary transforms that
//! every consumer (symbolic engine, exact simulator) walks.
//!
//! Units: offsets and linear commands in mm, rotary commands in degrees at every boundary a
//! person sees (radians inside), translational errors in mm inside (µm for people), angular
//! errors in rad inside (µrad for people).

#![warn(missing_docs)]

pub mod builtin;
pub mod catalogue;
mod error;
pub mod geometry;
pub mod kinematics;
pub mod machine;
mod raw;
mod validate;

pub use builtin::{BUILTIN, LoadError, all_builtin, builtin, load_machine};
pub use catalogue::{ErrorId, ErrorKind, ErrorTerm, Motion, canonical_name};
pub use error::SpecError;
pub use geometry::{Dir, Direction};
pub use machine::{
    Axis, AxisId, AxisKind, Chain, FULL_MODEL, Link, Machine, Offset, Side, SubModel, Symbol,
    SymbolId, Value,
};
pub use validate::{build_catalogue, parse_machine, reserved_names};
