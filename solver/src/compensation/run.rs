//! Compensation of a list of commanded poses (a path file or an NC program): every pose
//! corrected on the host ([`super::correct`]), the corrected poses checked against the strokes
//! and ranges, and the summary a person reads.

use super::correct::{Compensator, Corrected, POSITION_TOLERANCE};
use model_spec::{AxisKind, ErrorId, Machine};

/// A tilt remainder above this (rad) marks a pose whose orientation the rotary axes could not
/// fully correct (near a singular pose, where the correction is damped): 1 µrad.
pub const TILT_REPORTED: f64 = 1e-6;

/// One commanded pose and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandedPose {
    /// The 1-based line of the input file.
    pub line: usize,
    /// The command of every axis (mm, rad), machine order.
    pub commands: Vec<f64>,
}

/// What one axis's corrections came to over the file.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisCorrections {
    /// The axis.
    pub axis: String,
    /// `true` for a rotary axis (values in rad), `false` for a linear one (mm).
    pub rotary: bool,
    /// The largest correction, by magnitude, with its sign (mm or rad).
    pub largest: f64,
    /// The line of the pose with the largest correction.
    pub largest_line: usize,
    /// The RMS of the corrections (mm or rad).
    pub rms: f64,
}

/// The summary of a compensated file.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// The number of poses.
    pub poses: usize,
    /// Per axis, machine order.
    pub axes: Vec<AxisCorrections>,
    /// The largest predicted position remainder after correction (mm): below 1 nm.
    pub position_remainder: f64,
    /// The largest predicted tilt of the tool axis that remains (rad).
    pub tilt_remainder: f64,
    /// The lines whose tilt remainder exceeds [`TILT_REPORTED`] (near a singular pose).
    pub tilt_uncorrected: Vec<usize>,
    /// The largest predicted rotation about the tool axis (rad): no axis removes it.
    pub roll_largest: f64,
    /// Its RMS over the poses (rad).
    pub roll_rms: f64,
    /// `true` when the machine has rotary axes that correct the orientation.
    pub orientation_corrected: bool,
    /// The poses that needed refinement steps after the fixed ones.
    pub refined: usize,
}

/// Why a file cannot be compensated.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RunError {
    /// Corrected poses leave a stroke or a range.
    #[error("{file}: {} corrected pose(s) leave a stroke or range: {}", .lines.len(), list(.lines))]
    OutOfLimits {
        /// The input file.
        file: String,
        /// `(line, what)` of each pose outside.
        lines: Vec<(usize, String)>,
    },
    /// The corrected pose did not converge.
    #[error(
        "{file}:{line}: the corrected pose does not reach the model's prediction (remainder {remainder_um:.3e} µm after the refinement steps)"
    )]
    NotConverged {
        /// The input file.
        file: String,
        /// The line.
        line: usize,
        /// The remainder, µm.
        remainder_um: f64,
    },
    /// Commanded poses already outside a stroke or range (or not finite).
    #[error("{file}: {} commanded pose(s) are outside a stroke or range: {}", .lines.len(), list(.lines))]
    CommandedOutside {
        /// The input file.
        file: String,
        /// `(line, what)` of each pose outside.
        lines: Vec<(usize, String)>,
    },
    /// The machine's topology is outside what the corrected-pose solver handles.
    #[error(transparent)]
    Topology(#[from] codegen::compensation::CompensationError),
    /// The input holds no pose.
    #[error("{file}: no commanded pose to compensate")]
    Empty {
        /// The input file.
        file: String,
    },
}

fn list(lines: &[(usize, String)]) -> String {
    let shown: Vec<String> = lines
        .iter()
        .take(10)
        .map(|(l, w)| format!("line {l}: {w}"))
        .collect();
    let more = lines.len().saturating_sub(10);
    if more > 0 {
        format!("{}; and {more} more", shown.join("; "))
    } else {
        shown.join("; ")
    }
}

/// The corrected poses of a file, and its summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Compensated {
    /// The corrected commands, one per input pose (mm, rad).
    pub poses: Vec<Vec<f64>>,
    /// The summary.
    pub summary: Summary,
}

/// Compensates every pose of `poses` (from the file `file`) with the model errors `errors`
/// (catalogue ids of `m`), kinematic parameters `params` (mm) and their values at any pose
/// (`values_at(commands, out)`, mm and rad, one per error). The poses are shared among the
/// available cores.
///
/// # Errors
/// [`RunError::Empty`] without poses; [`RunError::NotConverged`] where a pose does not
/// converge; [`RunError::OutOfLimits`] listing every corrected pose outside a stroke or range.
pub fn compensate_poses(
    m: &Machine,
    errors: &[ErrorId],
    params: Vec<f64>,
    file: &str,
    poses: &[CommandedPose],
    values_at: &(dyn Fn(&[f64], &mut [f64]) + Sync),
) -> Result<Compensated, RunError> {
    if poses.is_empty() {
        return Err(RunError::Empty {
            file: file.to_string(),
        });
    }
    let commanded_outside = outside(m, poses, poses.iter().map(|p| p.commands.as_slice()));
    if !commanded_outside.is_empty() {
        return Err(RunError::CommandedOutside {
            file: file.to_string(),
            lines: commanded_outside,
        });
    }
    let comp = Compensator::new(m, errors, params)?;
    // Poses are independent: split them over the cores, each with its own buffers. The result
    // does not depend on the split.
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, 16)
        .min(poses.len().div_ceil(256));
    let chunk = poses.len().div_ceil(threads);
    let results: Vec<Result<Vec<Corrected>, RunError>> = std::thread::scope(|scope| {
        let handles: Vec<_> = poses
            .chunks(chunk)
            .map(|part| {
                let mut comp = comp.clone();
                scope.spawn(move || {
                    let mut values_at = |q: &[f64], out: &mut [f64]| values_at(q, out);
                    part.iter()
                        .map(|p| {
                            comp.correct(&p.commands, &mut values_at).map_err(|r| {
                                RunError::NotConverged {
                                    file: file.to_string(),
                                    line: p.line,
                                    remainder_um: r * 1e3,
                                }
                            })
                        })
                        .collect()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a correction thread does not panic"))
            .collect()
    });
    let mut corrected: Vec<Corrected> = Vec::with_capacity(poses.len());
    for r in results {
        corrected.extend(r?);
    }
    let corrected_outside = outside(m, poses, corrected.iter().map(|c| c.commands.as_slice()));
    if !corrected_outside.is_empty() {
        return Err(RunError::OutOfLimits {
            file: file.to_string(),
            lines: corrected_outside,
        });
    }
    let summary = summarise(m, poses, &corrected);
    Ok(Compensated {
        poses: corrected.into_iter().map(|c| c.commands).collect(),
        summary,
    })
}

/// `(line, what)` of every pose of `commands` (in the order of `poses`) outside a stroke or
/// range.
fn outside<'a>(
    m: &Machine,
    poses: &[CommandedPose],
    commands: impl Iterator<Item = &'a [f64]>,
) -> Vec<(usize, String)> {
    poses
        .iter()
        .zip(commands)
        .filter_map(|(p, c)| m.check_pose(c).err().map(|e| (p.line, e.to_string())))
        .collect()
}

fn summarise(m: &Machine, poses: &[CommandedPose], corrected: &[Corrected]) -> Summary {
    let n = poses.len() as f64;
    let axes = m
        .axes
        .iter()
        .enumerate()
        .map(|(a, axis)| {
            let (mut largest, mut largest_line, mut sum2) = (0.0f64, poses[0].line, 0.0);
            for (p, c) in poses.iter().zip(corrected) {
                let d = c.commands[a] - p.commands[a];
                sum2 += d * d;
                if d.abs() > largest.abs() {
                    (largest, largest_line) = (d, p.line);
                }
            }
            AxisCorrections {
                axis: axis.name.clone(),
                rotary: axis.kind == AxisKind::Rotary,
                largest,
                largest_line,
                rms: (sum2 / n).sqrt(),
            }
        })
        .collect();
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let fold = |f: &dyn Fn(&Corrected) -> f64| corrected.iter().map(f).fold(0.0f64, f64::max);
    let orientation_corrected = m.rotary_axes().count() > 0;
    Summary {
        poses: poses.len(),
        axes,
        position_remainder: fold(&|c| norm(&c.position)),
        tilt_remainder: fold(&|c| norm(&c.tilt)),
        tilt_uncorrected: if orientation_corrected {
            poses
                .iter()
                .zip(corrected)
                .filter(|(_, c)| norm(&c.tilt) > TILT_REPORTED)
                .map(|(p, _)| p.line)
                .collect()
        } else {
            Vec::new()
        },
        roll_largest: fold(&|c| c.roll.abs()),
        roll_rms: (corrected.iter().map(|c| c.roll * c.roll).sum::<f64>() / n).sqrt(),
        orientation_corrected,
        refined: corrected.iter().filter(|c| c.refinements > 0).count(),
    }
}

/// `true` when every remainder is within the tolerance (for tests and reports).
pub fn converged(s: &Summary) -> bool {
    s.position_remainder < POSITION_TOLERANCE
}
