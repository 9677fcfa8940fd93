//! Machine-tool descriptions for rtest.
//!
//! A machine is described in TOML (see `docs/model-spec.md`): the work chain and the tool chain
//! from the bed, each axis linear or rotary with its direction, kinematic offset (numbers or
//! named symbols with defaults) and stroke or range, the ISO 230 error terms of its model and
//! named sub-models. [`parse_machine`] validates a description into a [`Machine`];
//! [`kinematics::chain_steps`] lowers its chains to the one list of elementary transforms that
//! every consumer (symbolic engine, exact simulator) walks.
//!
//! Around the description: [`limits`] bounds what a description may hold; [`text`] reads a
//! text file for people (bounded, UTF-8, located errors) and [`locate`] turns byte offsets into
//! the `file:line:column` every message names; [`write`](mod@write) gives a machine's text and appends a
//! model to it; [`Machine::fingerprint`] tells whether two descriptions are the same machine;
//! [`Machine::check_pose`] checks commands against the strokes and ranges; [`describe`] writes
//! a machine for people. Beside it, for every reader: [`sha256`] hashes the files read, and
//! [`parallel`] shares the work of a long record out over the cores.
//!
//! Units: offsets and linear commands in mm, rotary commands in degrees at every boundary a
//! person sees (radians inside), translational errors in mm inside (µm for people), angular
//! errors in rad inside (µrad for people).
//!
//! ```
//! let text = r#"
//! name = "mill3"
//!
//! [[work]]
//! end = "ball"
//!
//! [[tool]]
//! axis = "X"
//! type = "linear"
//! direction = "+x"
//! stroke = [-400, 400]
//!
//! [[tool]]
//! axis = "Y"
//! type = "linear"
//! direction = "+y"
//! stroke = [-300, 300]
//!
//! [[tool]]
//! axis = "Z"
//! type = "linear"
//! direction = "+z"
//! stroke = [-300, 300]
//!
//! [[tool]]
//! end = "probe"
//! "#;
//! let m = model_spec::parse_machine("mill3.toml", text).unwrap();
//! assert_eq!(m.catalogue.len(), 24); // 18 component errors, COY AOZ BOZ, XOW YOW ZOW
//! assert_eq!(m.error_by_name("C0Y"), m.error_by_name("COY"));
//!
//! let bad = text.replace("[-300, 300]", "[300, -300]");
//! let e = model_spec::parse_machine("mill3.toml", &bad).unwrap_err();
//! assert_eq!(
//!     e.to_string(),
//!     "mill3.toml:17:10: axis Y: `stroke` minimum 300 is not below maximum -300 (mm)"
//! );
//! ```

#![warn(missing_docs)]

pub mod basis;
pub mod builtin;
pub mod catalogue;
pub mod describe;
mod error;
pub mod fingerprint;
pub mod geometry;
pub mod instrument;
pub mod kinematics;
pub mod limits;
pub mod locate;
pub mod machine;
pub mod parallel;
pub mod pose;
mod raw;
pub mod sha256;
pub mod surd;
pub mod terms;
pub mod text;
pub mod units;
mod validate;
pub mod write;

pub use builtin::{
    BUILTIN, LoadError, LoadedMachine, all_builtin, builtin, load_machine, load_machine_and_text,
    load_machine_read,
};
pub use catalogue::{ErrorId, ErrorKind, ErrorTerm, Motion, canonical_name};
pub use catalogue::{build_catalogue, default_squareness_order};
pub use error::SpecError;
pub use geometry::{AxisDirection, Dir, Direction, Inclined};
pub use machine::{
    Axis, AxisId, AxisKind, Chain, FULL_MODEL, Link, Machine, Offset, Side, SubModel, Symbol,
    SymbolId, Value,
};
pub use validate::{RUST_KEYWORDS, parse_machine, reserved_names};
