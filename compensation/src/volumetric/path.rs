//! Commanded poses corrected by the volumetric model, pose by pose, each refusal naming the
//! file and line of its pose. Reading and writing the file of poses (other columns kept byte
//! for byte) is the job of [`formats::poses`]; this module only corrects.

use super::VolumetricError;
use super::compensate::{Corrected, correct_within_strokes};
use super::model::VolumetricModel;
use model_spec::Machine;

/// The corrected poses of `poses` (`(line, commands)`: the 1-based line of the file `file` and
/// the command of every axis of `m`, mm).
///
/// # Errors
/// [`VolumetricError::Format`] naming the line for a pose outside the measured ranges or a
/// corrected command outside a stroke, and for a file without a pose;
/// [`VolumetricError::Computation`] (naming the line) for a correction that fails.
pub fn correct_poses(
    file: &str,
    m: &Machine,
    model: &VolumetricModel,
    poses: &[(usize, Vec<f64>)],
) -> Result<Vec<Corrected>, VolumetricError> {
    let err = |line: usize, message: String| VolumetricError::Format {
        file: file.to_string(),
        line,
        column: None,
        message,
    };
    if poses.is_empty() {
        return Err(err(1, "the path has no pose".into()));
    }
    poses
        .iter()
        .map(|(line, pose)| {
            correct_within_strokes(model, m, pose).map_err(|e| match e {
                VolumetricError::Computation(msg) => {
                    VolumetricError::Computation(format!("{file}:{line}: {msg}"))
                }
                other => err(*line, format!("the pose: {other}")),
            })
        })
        .collect()
}
