//! R-test instruments: the sensor nest that reads the ball, described in TOML
//! (`docs/instrument.md`).
//!
//! An instrument is a precision ball of radius `ball_radius_mm` and three or more displacement
//! sensors fixed in the nest. Everything is given in the **nest frame**, which is the tool frame
//! (the nest sits in the spindle), with its origin at the **nest centre**: where the ball centre
//! sits when the error vector is zero. Each sensor has
//!
//! - a **measuring direction** `m` (unit vector): a positive reading means the plunger is pushed
//!   in, which happens when the error vector (nest centre minus ball centre) moves along `m`.
//!   The sensor sits on the `−m` side of the ball and its plunger is pushed in along `−m`; to
//!   first order its travel is `m·e`;
//! - a **tip**: `flat` (a face perpendicular to the plunger, of radius `face_radius_mm`) or
//!   `sphere` (a ball tip of radius `tip_radius_mm` whose centre moves along the plunger axis);
//! - the **position** of its tip at zero reading (mm): the centre of the ball tip, or the centre
//!   of the flat face. By default on the plunger axis through the nest centre,
//!   `−(R + r)·m` (sphere) or `−R·m` (flat). A given position defines the plunger axis (the
//!   line through it along `m`); it must touch the ball at zero reading within
//!   [`POSITION_TOLERANCE_MM`], and [`Sensor::tip_at_zero`] moves it along the axis onto the
//!   exact contact;
//! - a calibrated **gain** (reading = gain × plunger travel, 1 nominal), a **noise** σ (µm,
//!   default [`DEFAULT_NOISE_UM`]) and a **zero** (µm, the reading at zero travel, default 0).
//!
//! `frame = "tool"` (default) says that the displacements the sensors give are in the tool
//! frame; `frame = "machine"` that they are in the machine frame (a nest that does not turn
//! with the tool): they are then rotated into the tool frame at each pose.
//!
//! [`parse_instrument`] validates a description (every problem names the file, line and
//! column); [`load_instrument`] takes a preset name ([`PRESETS`]) or a file;
//! [`to_toml`](write::to_toml) writes one back.
//!
//! ```
//! let i = model_spec::instrument::preset("inclined-45").unwrap().unwrap();
//! assert_eq!(i.sensors.len(), 3);
//! assert_eq!(i.ball_radius_mm, 12.7);
//! let e = model_spec::instrument::parse_instrument("i.toml", "name = \"x\"\nball_radius_mm = -1\n")
//!     .unwrap_err();
//! assert_eq!(
//!     e.to_string(),
//!     "i.toml:2:18: `ball_radius_mm` is -1 mm; the ball's radius must be above 0 and at most 100 mm"
//! );
//! ```

mod layout;
mod raw;
mod validate;
pub mod write;

pub use layout::{first_order_matrix, smallest_singular_value};
pub use validate::parse_instrument;

use crate::SpecError;
use crate::limits::MAX_FILE_BYTES;
use crate::text::{TextError, read_text_hashed};
use std::path::Path;

/// The noise σ of a sensor whose description gives none, µm: the repeatability of a good
/// contacting length gauge (LVDT or incremental probe), 0.1 µm.
pub const DEFAULT_NOISE_UM: f64 = 0.1;

/// How far the given tip position may be from touching the ball at zero reading, mm (1 µm):
/// the rounding of positions written with a few decimals, not a different geometry.
pub const POSITION_TOLERANCE_MM: f64 = 1e-3;

/// The largest angle between a spherical tip's plunger axis and the line from the ball centre
/// to the tip centre at zero reading, degrees: a plunger that points further off the ball
/// centre reads the displacement with a gain far from 1 and touches with the tip's flank.
pub const MAX_CONTACT_ANGLE_DEG: f64 = 30.0;

/// The fewest sensors: three readings for the three components of the displacement.
pub const MIN_SENSORS: usize = 3;

/// The most sensors an instrument may have.
pub const MAX_SENSORS: usize = 8;

/// The largest ball radius, mm (R-test balls are 10 to 50 mm in diameter).
pub const MAX_BALL_RADIUS_MM: f64 = 100.0;

/// The largest tip or face radius, mm.
pub const MAX_TIP_RADIUS_MM: f64 = 50.0;

/// The range of a calibrated gain: a gain outside it is a unit error, not a calibration.
pub const GAIN_RANGE: (f64, f64) = (0.5, 2.0);

/// The largest noise σ of a sensor, µm.
pub const MAX_NOISE_UM: f64 = 1000.0;

/// The largest zero of a sensor, µm.
pub const MAX_ZERO_UM: f64 = 10_000.0;

/// The smallest singular value of the first-order matrix of the sensors' directions (rows
/// `gain·m`, see [`first_order_matrix`]) an instrument may have: a displacement of 1 µm in the
/// worst direction must move the readings by at least 0.1 µm (root sum of squares). Below it
/// the directions do not span the three dimensions (a flat or collinear layout).
pub const MIN_LAYOUT_SINGULAR_VALUE: f64 = 0.1;

/// The frame the displacements of the sensors are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadingsFrame {
    /// The tool frame: the nest turns with the tool (a nest in the spindle). The default.
    Tool,
    /// The machine (bed) frame: the displacements are rotated into the tool frame with the
    /// nominal tool-chain rotation at each pose.
    Machine,
}

impl ReadingsFrame {
    /// `tool` or `machine`, as written in a description and on the command line.
    pub fn keyword(self) -> &'static str {
        match self {
            ReadingsFrame::Tool => "tool",
            ReadingsFrame::Machine => "machine",
        }
    }

    /// The frame of a keyword (`tool`, `machine`).
    pub fn parse(s: &str) -> Option<ReadingsFrame> {
        match s {
            "tool" => Some(ReadingsFrame::Tool),
            "machine" => Some(ReadingsFrame::Machine),
            _ => None,
        }
    }
}

/// The tip of a sensor's plunger.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tip {
    /// A flat face perpendicular to the plunger axis, of radius `face_radius_mm` (mm): it
    /// stays tangent to the ball, and the reading is exactly linear in the displacement while
    /// the contact stays on the face.
    Flat {
        /// Radius of the face, mm.
        face_radius_mm: f64,
    },
    /// A ball tip of radius `radius_mm` (mm) whose centre moves along the plunger axis: it
    /// touches the ball where the two centres are `R + r` apart.
    Sphere {
        /// Radius of the ball tip, mm.
        radius_mm: f64,
    },
}

impl Tip {
    /// `flat` or `sphere`, as written in a description.
    pub fn keyword(&self) -> &'static str {
        match self {
            Tip::Flat { .. } => "flat",
            Tip::Sphere { .. } => "sphere",
        }
    }
}

/// One displacement sensor of the nest.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// Its name (`s1`, …); its CSV column is the name followed by `_um`.
    pub name: String,
    /// The measuring direction `m` (unit vector, nest frame): the reading grows when the error
    /// vector moves along it; the plunger is pushed in along `−m`.
    pub direction: [f64; 3],
    /// The tip centre (sphere) or face centre (flat) at zero reading, mm, nest frame, as
    /// given or by default on the axis through the nest centre (see the module documentation).
    pub position_mm: [f64; 3],
    /// Its tip.
    pub tip: Tip,
    /// Calibrated gain: reading = gain × plunger travel (1 nominal).
    pub gain: f64,
    /// Standard deviation of one reading, mm (independent between readings and sensors).
    pub noise_mm: f64,
    /// The reading at zero travel, mm.
    pub zero_mm: f64,
}

/// An R-test instrument: the ball and the sensors of the nest.
#[derive(Clone, Debug, PartialEq)]
pub struct Instrument {
    /// Its short name.
    pub name: String,
    /// What it is, for people.
    pub description: String,
    /// Radius of the precision ball, mm.
    pub ball_radius_mm: f64,
    /// The frame the sensors' displacements are in.
    pub frame: ReadingsFrame,
    /// The sensors, in the order of the description (three or more).
    pub sensors: Vec<Sensor>,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn add_scaled(a: [f64; 3], s: f64, b: [f64; 3]) -> [f64; 3] {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

impl Sensor {
    /// The plunger axis `n = −m`: the direction the tip moves when the plunger is pushed in
    /// (from the ball towards the sensor body).
    pub fn plunger_axis(&self) -> [f64; 3] {
        self.direction.map(|v| -v)
    }

    /// The tip centre (sphere) or face centre (flat) at zero reading, mm: the given position
    /// moved along the plunger axis so that the tip touches the ball exactly (a ball tip's
    /// centre at `R + r` from the nest centre, a face on the plane tangent to the ball).
    pub fn tip_at_zero(&self, ball_radius_mm: f64) -> [f64; 3] {
        let n = self.plunger_axis();
        let p = self.position_mm;
        let b = dot(n, p);
        match self.tip {
            Tip::Flat { .. } => add_scaled(p, ball_radius_mm - b, n),
            Tip::Sphere { radius_mm } => {
                let rho = ball_radius_mm + radius_mm;
                // The root of |p + t·n| = ρ nearest t = 0; validation checked that it exists.
                let disc = (b * b - dot(p, p) + rho * rho).max(0.0);
                add_scaled(p, -b + disc.sqrt(), n)
            }
        }
    }

    /// The default position of the tip at zero reading, mm: on the plunger axis through the
    /// nest centre.
    pub fn default_position(direction: [f64; 3], tip: Tip, ball_radius_mm: f64) -> [f64; 3] {
        let d = match tip {
            Tip::Flat { .. } => ball_radius_mm,
            Tip::Sphere { radius_mm } => ball_radius_mm + radius_mm,
        };
        direction.map(|v| -d * v)
    }

    /// The sensor's CSV column: its name followed by `_um`.
    pub fn column(&self) -> String {
        format!("{}_um", self.name)
    }
}

impl Instrument {
    /// The index of the sensor called `name` (without regard to case).
    pub fn sensor_by_name(&self, name: &str) -> Option<usize> {
        self.sensors
            .iter()
            .position(|s| s.name.eq_ignore_ascii_case(name))
    }

    /// The CSV columns of the sensors' readings, in sensor order (`s1_um`, `s2_um`, …).
    pub fn columns(&self) -> Vec<String> {
        self.sensors.iter().map(Sensor::column).collect()
    }
}

/// Name and TOML text of every preset, in the order `rtest instrument list` lists them.
pub const PRESETS: &[(&str, &str)] = &[
    (
        "orthogonal",
        include_str!("../../instruments/orthogonal.toml"),
    ),
    (
        "inclined-45",
        include_str!("../../instruments/inclined-45.toml"),
    ),
    ("four-45", include_str!("../../instruments/four-45.toml")),
];

/// The preset called `name`, validated (`None` when there is none of that name).
pub fn preset(name: &str) -> Option<Result<Instrument, SpecError>> {
    PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| parse_instrument(&format!("<preset {n}>"), text))
}

/// Why an instrument could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum InstrumentLoadError {
    /// Neither a preset nor an existing file.
    #[error("no preset instrument and no file called `{0}` (presets: {names})", names = PRESETS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", "))]
    NotFound(String),
    /// The file could not be read as text (I/O, too large, not UTF-8).
    #[error("{0}")]
    Io(TextError),
    /// The description is invalid.
    #[error("{0}")]
    Spec(SpecError),
}

/// An instrument given by preset name or by the path of a TOML file (read with
/// [`crate::text::read_text`], at most [`MAX_FILE_BYTES`] bytes, named in messages as given).
pub fn load_instrument(name_or_path: &str) -> Result<Instrument, InstrumentLoadError> {
    load_instrument_hashed(name_or_path).map(|(i, _)| i)
}

/// [`load_instrument`], with the digest of the file's bytes as read (the file is opened once;
/// `None` for a preset).
pub fn load_instrument_hashed(
    name_or_path: &str,
) -> Result<(Instrument, Option<crate::sha256::Digest>), InstrumentLoadError> {
    if let Some(found) = preset(name_or_path) {
        return found.map(|i| (i, None)).map_err(InstrumentLoadError::Spec);
    }
    let path = Path::new(name_or_path);
    if !path.exists() {
        return Err(InstrumentLoadError::NotFound(name_or_path.to_string()));
    }
    let (text, digest) = read_text_hashed(path, MAX_FILE_BYTES).map_err(InstrumentLoadError::Io)?;
    let i = parse_instrument(name_or_path, &text).map_err(InstrumentLoadError::Spec)?;
    Ok((i, Some(digest)))
}
