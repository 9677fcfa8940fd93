//! The limits of a machine description.
//!
//! Every limit is checked when a description is read ([`crate::parse_machine`]); a description
//! beyond one is refused with a message that names the file, line and column, the limit and the
//! value found. The limits are far beyond any real machine: they exist so that no input, however
//! large or mistyped, makes rtest run out of memory or time, or turns a number into an infinity
//! or a NaN further on (a stroke of `±1e308` mm would make `inf` of every result that divides by
//! or adds to it).
//!
//! `docs/model-spec.md` lists them with the reasons; the tests in `model-spec/tests/all/limits.rs`
//! check each message.

/// The largest machine description, in bytes (1 MiB). The built-in descriptions have under
/// 2 kB, and a thoroughly commented description of a 16-axis machine some tens of kB: a
/// larger file is not a machine description (a log, a data file given by mistake).
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// The most servo axes of a machine (both chains together). Accepted with 16: mill-turn
/// centres with twin spindles and turrets have about 12, an R-test needs at most the five or
/// six of a five-axis machine. The error model has six component errors per axis, so the
/// catalogue stays under 200 errors.
pub const MAX_AXES: usize = 16;

/// The most fixed links (`link = "..."` entries) of a machine, both chains together.
pub const MAX_LINKS: usize = 32;

/// The most kinematic symbols (`[symbols]` entries). Every offset of a machine at the limits
/// (16 axes, 32 links, 2 ends) has three coordinates, 150 in all: 256 leave room for spare
/// ones.
pub const MAX_SYMBOLS: usize = 256;

/// The most sub-models (`[models.NAME]` tables) of a machine.
pub const MAX_MODELS: usize = 64;

/// The most terms in one sub-model. A model of every error of a 16-axis machine, each with a
/// few bases, stays under it; a least-squares fit of 1000 unknowns is already far beyond what
/// an R-test measurement identifies.
pub const MAX_TERMS: usize = 1000;

/// The longest name, in characters: of the machine, a symbol, a sub-model, a link or the end
/// of a chain. Generated code uses symbol and model names as identifiers, and reports put
/// names in table columns.
pub const MAX_NAME_CHARS: usize = 64;

/// The largest length, mm (100 m), either sign: every number of an `offset`, every symbol
/// default and both ends of every `stroke` lie in `[-MAX_LENGTH_MM, MAX_LENGTH_MM]`. The
/// largest gantry machines are some 50 m long.
pub const MAX_LENGTH_MM: f64 = 1e5;

/// The shortest stroke of a linear axis, mm (1 µm): `max - min` of a `stroke` is at least
/// this. Position-dependent terms (`poly:K`) normalise the position over the stroke, so a
/// stroke of almost zero width would turn a rounding error into a huge normalised position.
pub const MIN_STROKE_MM: f64 = 1e-3;

/// The largest end of a rotary axis's `range`, degrees (ten turns), either sign. A table
/// limited only by its cables turns a turn or two; an axis that turns without limit has no
/// `range` at all.
pub const MAX_RANGE_DEG: f64 = 3600.0;

/// The highest order `K` of a basis `harmonic:K`, `poly:K` or `time:K` in a sub-model's
/// terms (the lowest is 1).
pub const MAX_BASIS_ORDER: u32 = 64;
