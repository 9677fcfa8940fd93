//! The files of a touch-probe calibration (a probe in the spindle touching a calibration
//! sphere on the table, as Heidenhain's KinematicsOpt or Siemens' CYCLE996 do;
//! `docs/probe.md`): read and written back bit for bit.
//!
//! - [`hits`]: the probe hits CSV: one row per hit, the axes latched at the trigger and the
//!   approach direction, grouped by pose ([`read_probe_hits`], [`format_probe_hits`]);
//! - [`centres`]: the sphere centres CSV: one row per pose, the centre another device fitted
//!   ([`read_sphere_centres`], [`format_sphere_centres`]);
//! - [`instrument`]: the probe instrument file (TOML): the stylus tip's radius, the sphere's
//!   calibrated radius and the probe's noise ([`parse_probe_instrument`]).
//!
//! The CSVs follow the text rules of the measurement CSV ([`crate::csv`]): UTF-8 (a byte-order
//! mark accepted), lines ending in `\n` or `\r\n`, no line longer than 64 KiB (read through
//! the same bounded line reader, so a file is never held whole as text), `#` comment lines and
//! blank lines skipped, fields separated by commas without quoting, column names matched
//! without regard to case, blanks or double quotes around them. Axis columns are named after
//! the machine's axes (linear axes in mm, rotary axes in degrees, in machine coordinates), and
//! every axis value must lie below [`MAX_COMMAND`](crate::poses::MAX_COMMAND) in magnitude and
//! within the axis's limits (inclusive to within 1e-9 mm or degree). Every problem is a
//! [`CsvError::Format`](crate::csv::CsvError::Format) naming the file, the line and, where there
//! is one, the column (`file:line: column N `NAME`: why`); a reader returns the whole file or
//! an error, never part of it.
//!
//! Values are held as the files write them (mm, degrees): the writers write each as the
//! shortest decimal that reads back to the same `f64` ([`model_spec::units::format_scaled`]),
//! so write → read gives the same bits. [`crate::poses::from_file_units`] gives the commands in
//! mm and rad the computation takes.
//!
//! [`mod@file`] reads either CSV, told apart by its header ([`read_probe_file`]).
//!
//! Files: `table` (the header and rows both CSVs share), `hits`, `centres`, `file`, `instrument`.

pub mod centres;
pub mod file;
pub mod hits;
pub mod instrument;
mod table;

pub use centres::{
    CENTRE_COLUMNS, SphereCentre, SphereCentres, format_sphere_centres, parse_sphere_centres,
    read_sphere_centres,
};
pub use file::{ProbeFile, read_probe_file, read_probe_from};
pub use hits::{
    HIT_COLUMNS, ProbeHit, ProbeHits, ProbePose, format_probe_hits, parse_probe_hits,
    read_probe_hits,
};
pub use instrument::{
    ProbeInstrument, ProbeInstrumentError, parse_probe_instrument, read_probe_instrument,
};

/// The name of the column holding a pose's label, in both CSVs.
pub const POSE_COLUMN: &str = "pose";

/// The most rows of hits read from one probe hits CSV (1 000 000): a probe campaign touches
/// the sphere some ten times at each of a few hundred poses; beyond this the file is refused
/// at the first row too many.
pub const MAX_HITS: usize = 1_000_000;

/// The most poses read from one probe file (100 000): hits CSV or sphere centres CSV.
pub const MAX_PROBE_POSES: usize = 100_000;

/// The longest pose label, characters (64).
pub const MAX_LABEL_CHARS: usize = 64;

/// How far the norm of an approach direction may be off 1 (1e-6): beyond it the direction is
/// refused, never normalised.
pub const UNIT_NORM_TOLERANCE: f64 = 1e-6;

/// How far a rotary axis may move between the hits of one pose, degrees (1e-9): a probe
/// cycle does not turn the rotary axes during a pose.
pub const ROTARY_CONSTANT_DEG: f64 = 1e-9;

/// The axes of `m` in the order the writers write them ([`crate::csv::column_order`]: linear,
/// then rotary, each in ISO order), and their names (the header of those columns).
fn axis_header(m: &model_spec::Machine) -> (Vec<usize>, Vec<String>) {
    let order = crate::csv::column_order(m);
    let names = order.iter().map(|&a| m.axes[a].name.clone()).collect();
    (order, names)
}
