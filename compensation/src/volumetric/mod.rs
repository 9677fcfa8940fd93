//! Three-axis volumetric compensation from 6D laser-interferometer measurements taken at the
//! tool end: the kinematic-parameter independent model of a three-axis machine, its predicted
//! tool-end error `du(X, Y, Z)`, the corrected commands `u_c` with `u_c = u − du(u_c)`, and a
//! volumetric grid of `du` for a controller. Reference and derivation: `docs/volumetric.md`.
//!
//! The scheme, one module each:
//!
//! - [`laser`]: one CSV per linear axis: the commands of every axis (the measured one moving,
//!   the others standing still) and the six component errors measured at the tool end (µm,
//!   µrad);
//! - [`squareness`]: the squareness errors from their own measurement (µrad) and the reference
//!   point where the predicted error is zero, in a small TOML file;
//! - [`table`]: the tables, linear interpolation between measured positions;
//! - [`model`]: the model and `du`;
//! - [`compensate`]: the corrected commands;
//! - [`grid`]: the volumetric grid CSV;
//! - [`path`]: commanded poses corrected, each refusal naming its line;
//! - [`summary`]: largest and RMS predicted error and correction per axis, for people and JSON;
//! - [`simulate`]: the laser measurements, taken on the exact virtual machine, and the exact
//!   tool-end error in the model's frame, to check all of the above.
//!
//! Units inside: mm and rad. µm, µrad and mm are the units of the files.
//!
//! # Example: measure a virtual machine, compensate it
//!
//! ```
//! use compensation::volumetric::{VolumetricModel, simulate};
//! use simulation::Truth;
//!
//! let m = model_spec::builtin("seed-3axis").unwrap().unwrap();
//! let truth = formats::truth::parse_truth(
//!     "t.toml",
//!     "[errors]\nEXX = { \"poly:1\" = 12.0 }\nCOX = 20.0\n",
//!     &m,
//! )
//! .unwrap();
//! let plan = simulate::LaserPlan::over_strokes(&m, 21).unwrap();
//! let sim = simulate::measure(&m, &truth, &plan).unwrap();
//! let model = VolumetricModel::new(&m, &sim.measurements, &sim.squareness).unwrap();
//! // At X = 400, Y = 300 mm the positioning error is 12 µm and COX moves the tool by
//! // 20 µrad · 400 mm = 8 µm along y.
//! let du = model.du(&[300.0, 400.0, 0.0]).unwrap();
//! // (To within the products of two errors, 1e-6 mm here.)
//! assert!((du.x - 0.012).abs() < 1e-6 && (du.y - 0.008).abs() < 1e-6);
//! ```

pub mod compensate;
pub mod grid;
pub mod laser;
pub mod model;
pub mod path;
pub mod simulate;
pub mod squareness;
pub mod summary;
pub mod table;

pub use compensate::{Corrected, MAX_ITERATIONS, TOLERANCE_MM, correct, correct_within_strokes};
use formats::csv::format_located;
pub use grid::{GridSpec, format_grid};
pub use laser::{AxisMeasurement, format_laser, parse_laser, read_laser};
pub use model::VolumetricModel;
pub use squareness::{Squareness, format_squareness, parse_squareness, read_squareness};

/// The largest magnitude of a measured translation, and of a predicted error, mm (1000 µm):
/// beyond it a first-order model of a machine tool has no meaning.
pub const MAX_TRANSLATION_MM: f64 = 1.0;

/// The largest magnitude of a measured angle or squareness error, rad (10 000 µrad).
pub const MAX_ANGLE_RAD: f64 = 0.01;

/// Why the volumetric compensation could not be built or applied. Every message names the
/// file (and line and column) or the axis and position at fault.
#[derive(Debug, thiserror::Error)]
pub enum VolumetricError {
    /// A malformed or implausible entry of a CSV file: `file:line: column N `NAME`: message`.
    #[error("{}", format_located(file, *line, column, message))]
    Format {
        /// The file, as given.
        file: String,
        /// 1-based line (comment lines counted).
        line: usize,
        /// The column: 1-based index and header name (CSV), or `None`.
        column: Option<(usize, String)>,
        /// What is wrong and what would be right.
        message: String,
    },
    /// A malformed or implausible entry of a TOML file: `file:line:column: message`.
    #[error("{file}:{line}:{column}: {message}")]
    Toml {
        /// The file, as given.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters.
        column: usize,
        /// What is wrong and what would be right.
        message: String,
    },
    /// A file that cannot be read, is too large or is not UTF-8 text.
    #[error(transparent)]
    Text(#[from] model_spec::text::TextError),
    /// Measurements that do not make a model of this machine: a machine the model does not
    /// cover, an axis measured twice or not at all, a measurement taken outside another's range.
    #[error("{0}")]
    Setup(String),
    /// A position outside the range an axis was measured over.
    #[error(
        "{axis} = {} mm is outside the range its laser measurement covers, {} .. {} mm",
        model_spec::units::compact(*position),
        model_spec::units::compact(range[0]),
        model_spec::units::compact(range[1])
    )]
    OutOfRange {
        /// The axis letter.
        axis: String,
        /// The position, mm.
        position: f64,
        /// The measured range `[first, last]`, mm.
        range: [f64; 2],
    },
    /// A corrected command outside the axis's stroke: the machine cannot move there.
    #[error(
        "the corrected command {axis} = {} mm (commanded {} mm) is outside the stroke {} .. {} mm",
        model_spec::units::compact(*corrected),
        model_spec::units::compact(*commanded),
        model_spec::units::compact(stroke[0]),
        model_spec::units::compact(stroke[1])
    )]
    OffStroke {
        /// The axis letter.
        axis: String,
        /// The commanded position, mm.
        commanded: f64,
        /// The corrected command, mm.
        corrected: f64,
        /// The axis's stroke, mm.
        stroke: [f64; 2],
    },
    /// A computation that failed: a predicted error beyond [`MAX_TRANSLATION_MM`], a
    /// non-finite value, a correction that does not converge.
    #[error("{0}")]
    Computation(String),
}

impl From<formats::located::Located> for VolumetricError {
    fn from(e: formats::located::Located) -> Self {
        VolumetricError::Toml {
            file: e.file,
            line: e.line,
            column: e.column,
            message: e.message,
        }
    }
}
