//! An example of compensation in controller firmware: `no_std`, no allocation, no maths
//! library, single precision (a Cortex-M4F has an `f32` FPU only).
//!
//! Each interpolation cycle the path interpolator hands over the commanded pose of `seed-ac`
//! (X, A, C, Y, Z) with the sines and cosines of its rotary commands, which an interpolator has
//! anyway: here they advance by the angle-addition recurrence, so the loop needs no `sin`.
//! [`correct_pose`] adds the generated first-order correction of the full model
//! (`seed_ac::full::compensation::first_order_f32`) to the commands; [`run_cycles`] is the
//! loop. The error values are the identified constants and, for the position-dependent errors,
//! the axis compensation tables that `rtest compensate --tables` writes (one value per error
//! of the model, mm and rad); the kinematic parameters come from the machine description.
//!
//! Built for `thumbv7em-none-eabihf` in CI; BENCHMARKS.md counts the instructions of
//! [`correct_pose`] from its disassembly.

#![no_std]
#![warn(missing_docs)]

use generated::seed_ac::full;
use generated::seed_ac::full::compensation::{AXIS_COUNT, first_order_f32};

/// The pose inputs of `seed-ac` in order: `sin_a, cos_a, sin_c, cos_c, x, y, z`.
pub const POSE_INPUTS: usize = 7;

/// One cycle's command: the axis commands (X mm, A rad, C rad, Y mm, Z mm) and the sines and
/// cosines of A and C.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Command {
    /// X, A, C, Y, Z (mm, rad).
    pub axes: [f32; AXIS_COUNT],
    /// `sin A, cos A, sin C, cos C`.
    pub trig: [f32; 4],
}

/// The compensated command of one cycle: `command` plus the first-order correction of the
/// model `full` with the error values `values` (mm, rad) and the kinematic parameters
/// `params` (mm, in the order of `generated::seed_ac::PARAMETERS`). Writes the corrected axis
/// commands to `out`.
#[unsafe(no_mangle)]
#[inline(never)]
pub extern "C" fn correct_pose(
    command: &Command,
    params: &[f32; 13],
    values: &[f32; full::N],
    out: &mut [f32; AXIS_COUNT],
) {
    let a = &command.axes;
    let pose: [f32; POSE_INPUTS] = [
        command.trig[0],
        command.trig[1],
        command.trig[2],
        command.trig[3],
        a[0],
        a[3],
        a[4],
    ];
    let mut step = [0.0f32; AXIS_COUNT + 6];
    first_order_f32(&pose, params, values, &mut step);
    for ((o, c), d) in out.iter_mut().zip(a).zip(&step) {
        *o = c + d;
    }
}

/// A control-loop-like run: `cycles` interpolation cycles along a five-axis move that starts
/// at `start` and changes every command by `rate` per cycle (mm, rad), the sines and cosines
/// advanced by the angle-addition recurrence; each cycle's compensated command is handed to
/// `drive` (the servo interface of a real controller).
pub fn run_cycles(
    start: &Command,
    rate: &[f32; AXIS_COUNT],
    cycles: u32,
    params: &[f32; 13],
    values: &[f32; full::N],
    drive: &mut impl FnMut(&[f32; AXIS_COUNT]),
) {
    // sin and cos of the per-cycle increments of A and C (computed once, off the cycle: small
    // angles, so a short series is exact in single precision).
    let step_trig = |d: f32| (d - d * d * d / 6.0, 1.0 - d * d / 2.0);
    let (sa, ca) = step_trig(rate[1]);
    let (sc, cc) = step_trig(rate[2]);
    let mut command = *start;
    let mut out = [0.0f32; AXIS_COUNT];
    for _ in 0..cycles {
        correct_pose(&command, params, values, &mut out);
        drive(&out);
        for (x, r) in command.axes.iter_mut().zip(rate) {
            *x += r;
        }
        let t = command.trig;
        command.trig = [
            t[0] * ca + t[1] * sa,
            t[1] * ca - t[0] * sa,
            t[2] * cc + t[3] * sc,
            t[3] * cc - t[2] * sc,
        ];
    }
}
