//! Test paths: the built-in `K1`, `K2`, `K4` of machines with rotary axes A and C (`seed-ac`),
//! paths for any machine from a CSV file, and the nominal tool-centre-point inverse kinematics
//! that fills the linear commands.
//!
//! Built-in paths (docs/conventions.md; the seed's sample counts, ISO 10791-6 style), sample `i`:
//! - `K1`: `C = i°`, `A = 0°`, `i = 0…360` (361 samples);
//! - `K2`: `A = (−90 + i)°`, `C = 0°`, `i = 0…120` (121 samples);
//! - `K4`: `C = 1.5·i°`, `A = −45·(1 − cos C)°`, `i = 0…240` (241 samples; all five axes move).
//!
//! The rotary commands are computed in degrees and converted with `to_radians()`; the linear
//! axes follow the ball by the nominal tool-centre-point inverse kinematics
//! ([`crate::simulation::exact::VirtualMachine::tool_centre_point_ik`]) with the machine's default kinematic
//! parameters (what the controller believes). Sample `i` is taken at `t = i·`[`SAMPLE_PERIOD_S`]
//! (1 s): the R-test samples at rest after each step, so only the order of the samples matters
//! for `time:K` effects, which are normalised over the record. Directions of motion come from
//! [`crate::record::motion_directions`].
//!
//! A path file is a CSV in the measurement format ([`crate::io::csv`]): rotary columns required
//! (degrees), linear columns optional (filled by the inverse kinematics), `t_s` optional,
//! measured columns optional and ignored. It is read by the same bounded line reader and
//! checked as a measurement file is (nest on the ball when the linear axes are given, strokes
//! and ranges, and the plausibility of the readings when there are any), under the same
//! [`ReadOptions`]. The built-in paths lie within the strokes and ranges of `seed-ac`.

use crate::io::csv::{CsvError, Need, ReadOptions, read_csv};
use crate::record::{Record, motion_directions, samples_from};
use crate::simulation::exact::{ExactError, VirtualMachine};
use model_spec::Machine;

/// Time between two samples of the built-in paths, s.
pub const SAMPLE_PERIOD_S: f64 = 1.0;

/// Names of the built-in paths (matched without regard to case).
pub const BUILTIN_PATHS: [&str; 3] = ["K1", "K2", "K4"];

/// Why a path could not be made or read.
#[derive(Debug, thiserror::Error)]
pub enum PathError {
    /// A built-in path asked of a machine whose rotary axes are not A and C.
    #[error(
        "path {path} is defined only for machines whose rotary axes are A and C (like seed-ac); machine {machine} has {has}: give the path as a CSV file"
    )]
    NotAC {
        /// The path.
        path: String,
        /// The machine.
        machine: String,
        /// What rotary axes it has (`rotary axes B, C`, `no rotary axes`).
        has: String,
    },
    /// The inverse kinematics failed at a sample of a built-in path.
    #[error("path {path}, sample {sample}: {source}")]
    Ik {
        /// The path.
        path: String,
        /// The sample (0-based).
        sample: usize,
        /// Why.
        source: ExactError,
    },
    /// Neither a built-in path nor an existing file.
    #[error("`{0}` is neither a built-in path (K1, K2, K4) nor an existing file")]
    NotFound(String),
    /// The path file is malformed or unreadable.
    #[error("{0}")]
    Csv(#[from] CsvError),
}

/// The rotary commands `(A, C)` (degrees) of a sample index.
type RotaryDegrees = fn(usize) -> (f64, f64);

/// The rotary commands (A, C) in degrees of sample `i` of built-in path `name` (`K1`, `K2`,
/// `K4`, already upper case), and the number of samples.
fn builtin_degrees(name: &str) -> Option<(usize, RotaryDegrees)> {
    match name {
        "K1" => Some((361, |i| (0.0, i as f64))),
        "K2" => Some((121, |i| (-90.0 + i as f64, 0.0))),
        "K4" => Some((241, |i| {
            let c = 1.5 * i as f64;
            // `+ 0.0` turns the −0 of C = 0° into 0.
            (-45.0 * (1.0 - c.to_radians().cos()) + 0.0, c)
        })),
        _ => None,
    }
}

/// The built-in path `name` (`K1`, `K2`, `K4`, any case) of machine `m`; `None` when `name` is
/// not one of them.
///
/// # Errors
/// [`PathError::NotAC`] unless the rotary axes of `m` are exactly A and C;
/// [`PathError::Ik`] when the inverse kinematics has no solution at a sample.
pub fn builtin_path(m: &Machine, name: &str) -> Option<Result<Record, PathError>> {
    let upper = name.trim().to_ascii_uppercase();
    let (n, degrees) = builtin_degrees(&upper)?;
    Some(make_builtin(m, &upper, n, degrees))
}

fn make_builtin(
    m: &Machine,
    name: &str,
    n: usize,
    degrees: RotaryDegrees,
) -> Result<Record, PathError> {
    let rotary: Vec<usize> = m.rotary_axes().collect();
    let (a, c) = (m.axis_by_name("A"), m.axis_by_name("C"));
    let (Some(a), Some(c)) = (a, c) else {
        return Err(not_ac(m, name, &rotary));
    };
    if rotary.len() != 2 || !rotary.contains(&a) || !rotary.contains(&c) {
        return Err(not_ac(m, name, &rotary));
    }
    let mut commands: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let (da, dc) = degrees(i);
            let mut q = vec![0.0; m.axes.len()];
            q[a] = da.to_radians();
            q[c] = dc.to_radians();
            q
        })
        .collect();
    fill_linear_ik(m, &m.default_parameters(), &mut commands).map_err(|(sample, source)| {
        PathError::Ik {
            path: name.to_string(),
            sample,
            source,
        }
    })?;
    let times = (0..n).map(|i| i as f64 * SAMPLE_PERIOD_S).collect();
    Ok(record_from_commands(commands, times))
}

fn not_ac(m: &Machine, name: &str, rotary: &[usize]) -> PathError {
    let mut has: Vec<&str> = rotary.iter().map(|&i| m.axes[i].name.as_str()).collect();
    has.sort_by_key(|n| model_spec::catalogue::iso_rank(n));
    PathError::NotAC {
        path: name.to_string(),
        machine: m.name.clone(),
        has: if has.is_empty() {
            "no rotary axes".into()
        } else {
            format!("rotary axes {}", has.join(", "))
        },
    }
}

/// A path given by built-in name ([`BUILTIN_PATHS`]) or by the name of a CSV file, read with
/// `opts` (a built-in path is made, not read: `opts` do not apply to it).
///
/// # Errors
/// [`PathError::NotFound`] when it is neither; see [`builtin_path`] and [`read_path`].
pub fn load_path(m: &Machine, name_or_file: &str, opts: &ReadOptions) -> Result<Record, PathError> {
    if let Some(r) = builtin_path(m, name_or_file) {
        return r;
    }
    let path = std::path::Path::new(name_or_file);
    // Anything that exists and is not a directory is read (a file, a FIFO, a link to one).
    if !path.exists() || path.is_dir() {
        return Err(PathError::NotFound(name_or_file.to_string()));
    }
    let f = std::fs::File::open(path).map_err(|source| CsvError::Io {
        file: name_or_file.to_string(),
        source,
    })?;
    Ok(read_path(name_or_file, f, m, opts)?)
}

/// Reads a path CSV (text `text`, named `file` in messages) of machine `m`; see [`read_path`].
///
/// # Errors
/// As [`read_path`].
pub fn parse_path(
    file: &str,
    text: &str,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    read_path(file, text.as_bytes(), m, opts)
}

/// Reads a path CSV of machine `m` from `reader` (named `file` in messages): a record without
/// measurements (commands in mm and rad, times in s; see the module documentation).
///
/// # Errors
/// [`CsvError::Format`] naming the line and column of the first problem (a line too long or
/// not UTF-8 included); [`CsvError::Refused`] for poses off the ball or off the strokes, or
/// implausible readings; [`CsvError::Io`] when `reader` fails.
pub fn read_path<R: std::io::Read>(
    file: &str,
    reader: R,
    m: &Machine,
    opts: &ReadOptions,
) -> Result<Record, CsvError> {
    let mut r = read_csv(file, reader, m, Need::Path, opts)?;
    r.measured.clear();
    Ok(r)
}

/// Fills the linear entries (mm) of every command vector by the nominal tool-centre-point
/// inverse kinematics of `m` with kinematic parameters `params` (mm), keeping the rotary
/// entries (rad). The chains are lowered once.
///
/// # Errors
/// The index of the first sample where the inverse kinematics fails, and why; the commands
/// before it are filled, the others unchanged.
///
/// # Panics
/// When a command vector is not one per axis, or `params` not one per symbol.
pub fn fill_linear_ik(
    m: &Machine,
    params: &[f64],
    commands: &mut [Vec<f64>],
) -> Result<(), (usize, ExactError)> {
    let vm = VirtualMachine::new(m);
    for (i, q) in commands.iter_mut().enumerate() {
        vm.tool_centre_point_ik(q, params).map_err(|e| (i, e))?;
    }
    Ok(())
}

/// A record without measurements from commands (mm, rad; one vector per sample) and times (s):
/// directions of motion by [`motion_directions`].
///
/// # Panics
/// When `times` is not one per sample.
pub fn record_from_commands(commands: Vec<Vec<f64>>, times: Vec<f64>) -> Record {
    assert_eq!(commands.len(), times.len(), "one time per sample");
    let motion = motion_directions(&commands);
    Record {
        samples: samples_from(commands, times, motion),
        ..Default::default()
    }
}
