//! A machine of your own, compiled in your own crate: `no_std`, no allocation, no maths
//! library.
//!
//! The machine is described in this crate's `machine.toml`: a five-axis trunnion machine
//! (`trunnion-bc`) whose Y table, moving along −y, carries a B trunnion turning about y, which
//! carries a C table; X and Z move the spindle. It is not one of rtest's built-in machines.
//! `build.rs` turns the description into Rust in `OUT_DIR` at every build
//! (`codegen::build::Machine::from_file("machine.toml")…write_to_out_dir(…)`), and
//! [`trunnion_bc`] includes it. A change of the description is a change of the code, and a
//! bad description fails the build with its file, line, column and field.
//!
//! Two uses of the generated code, as a controller would make them:
//! - [`predicted_error`]: the error vector that the identified errors of the model `location`
//!   predict at a pose (the gains times the values, `f64`), to compare an R-test reading with;
//! - [`correct_pose`]: the commands of one interpolation cycle corrected by the first-order
//!   compensation of the model `location` in single precision (a Cortex-M4F has an `f32` FPU
//!   only). CI builds this crate for `thumbv7em-none-eabihf`.
//!
//! Units: linear commands and translational errors in mm, rotary commands and angular errors
//! in rad; the sines and cosines of the rotary commands are inputs. Axes in the machine's
//! order, work chain first: Y, B, C, X, Z.
//!
//! The tests (`tests/against_exact.rs`) check the generated gains against central finite
//! differences of rtest's exact virtual machine, the predicted error against the exact error
//! vector, and the corrected commands on the exact machine.

#![no_std]
#![warn(missing_docs)]

/// The code generated from `machine.toml` (models `full` and `location`): `Pose`, `Params`,
/// `POSE_INPUTS`, `PARAMETERS` and one module per model with its gains and compensation.
pub mod trunnion_bc {
    include!(concat!(env!("OUT_DIR"), "/trunnion_bc.rs"));
}

use trunnion_bc::location::compensation::{AXIS_COUNT, first_order_f32};
use trunnion_bc::{Params, Pose, location};

/// Number of pose inputs: `sin B, cos B, sin C, cos C, Y, X, Z` ([`trunnion_bc::POSE_INPUTS`]).
pub const POSE_INPUTS: usize = trunnion_bc::POSE_INPUTS.len();

/// Number of kinematic parameters (mm, in the order of [`trunnion_bc::PARAMETERS`]).
pub const PARAMETERS: usize = trunnion_bc::PARAMETERS.len();

/// One cycle's command: the axis commands Y, B, C, X, Z (mm, rad) and the sines and cosines
/// of B and C, which an interpolator has anyway.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Command {
    /// Y, B, C, X, Z (mm, rad): [`trunnion_bc::location::compensation::AXES`].
    pub axes: [f32; AXIS_COUNT],
    /// `sin B, cos B, sin C, cos C`.
    pub trig: [f32; 4],
}

/// The error vector that the values `values` of the model `location` (mm, rad, in the order
/// of [`location::ERRORS`]) predict at `pose`: `[dx, dy, dz]` the tool point minus the ball
/// (mm) and `[di, dj, dk]` the change of the tool direction, both in the nominal tool frame,
/// to first order: `Σ gains[i] · values[i]`. Valid where the nominal tool point is on the
/// ball (every R-test pose).
pub fn predicted_error(pose: &Pose, params: &Params, values: &[f64; location::N]) -> [f64; 6] {
    let mut gains = [[0.0f64; 6]; location::N];
    location::gains(pose, params, &mut gains);
    let mut error = [0.0f64; 6];
    for (g, v) in gains.iter().zip(values) {
        for (e, gk) in error.iter_mut().zip(g) {
            *e += gk * v;
        }
    }
    error
}

/// The compensated command of one cycle: `command` plus the first-order correction of the
/// model `location` with the values `values` (mm, rad; pass the ball's set-up errors
/// `XOW YOW ZOW` as zero: compensation leaves where the ball sits alone) and the kinematic
/// parameters `params` (mm). Writes the corrected axis commands Y, B, C, X, Z to `out`.
pub fn correct_pose(
    command: &Command,
    params: &[f32; PARAMETERS],
    values: &[f32; location::N],
    out: &mut [f32; AXIS_COUNT],
) {
    let [y, _, _, x, z] = command.axes;
    let [sin_b, cos_b, sin_c, cos_c] = command.trig;
    // The order of `trunnion_bc::POSE_INPUTS`: Sb, Cb, Sc, Cc, Ym, Xm, Zm.
    let pose: [f32; POSE_INPUTS] = [sin_b, cos_b, sin_c, cos_c, y, x, z];
    let mut step = [0.0f32; AXIS_COUNT + 6];
    first_order_f32(&pose, params, values, &mut step);
    for ((o, c), d) in out.iter_mut().zip(&command.axes).zip(&step) {
        *o = c + d;
    }
}
