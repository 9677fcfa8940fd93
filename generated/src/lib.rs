//! Error-gain functions of the built-in machines, generated at build time by `codegen` from
//! `model-spec/machines/*.toml`.
//!
//! `#![no_std]`, no allocation, straight-line `+ − ×` bodies: the sines and cosines of the
//! rotary commands are inputs, so the code runs on a controller without a maths library (CI
//! builds it for `thumbv7em-none-eabihf`, a Cortex-M4F).
//!
//! Each machine is a module (`seed_ac`, `head_table_bc`, `nutating_head_bc`, …: one per file
//! of `model-spec/machines/`) with `Pose`, `Params` and one module per model (`full`,
//! `reduced`, `location`, …) whose `gains(pose, params, out)` writes
//! `[gx, gy, gz, gi, gj, gk]` per error: the error vector (tool minus workpiece) and the
//! orientation error in the nominal tool frame per unit of error (mm per mm for translational
//! errors, mm per rad for angular errors). They are the exact first-order gains where the
//! nominal tool point is on the nominal workpiece point, as at every R-test pose.
//!
//! ```
//! use generated::seed_ac::{Params, Pose, reduced};
//! let (a, c) = (30f64.to_radians(), 45f64.to_radians());
//! let pose = Pose { sin_a: a.sin(), cos_a: a.cos(), sin_c: c.sin(), cos_c: c.cos(), ..Pose::default() };
//! let mut g = [[0.0; 6]; reduced::N];
//! reduced::gains(&pose, &Params::default(), &mut g);
//! assert_eq!(g[reduced::XOC][0], -1.0); // XOC moves the ball along x: tool minus ball is -1
//! ```

#![no_std]
#![warn(missing_docs)]

/// `compensate(commanded, params, values, sin_cos, out)` of a compiled model, on slices.
pub type CompensateFn = fn(&[f64], &[f64], &[f64], fn(f64) -> (f64, f64), &mut [f64]);

/// `first_order_f32(pose, params, values, out)` of a compiled model, on slices.
pub type FirstOrderF32Fn = fn(&[f32], &[f32], &[f32], &mut [f32]);

/// A compiled model, for callers that choose the machine and model at run time.
#[derive(Clone, Copy, Debug)]
pub struct CompiledModel {
    /// Machine name (`seed-ac`).
    pub machine: &'static str,
    /// Model name (`full`, `reduced`, …).
    pub model: &'static str,
    /// Error names in output order.
    pub errors: &'static [&'static str],
    /// Names of the pose inputs in slice order (sines and cosines of rotary commands, then
    /// linear commands in mm).
    pub pose_inputs: &'static [&'static str],
    /// Names of the kinematic parameters in slice order (mm).
    pub parameters: &'static [&'static str],
    /// Arithmetic operations of one evaluation.
    pub operations: usize,
    /// `gains(pose, params, out)`: `out` holds `6 * errors.len()` values, row-major.
    pub gains: fn(&[f64], &[f64], &mut [f64]),
    /// `position_gains(pose, params, out)`: `out` holds `3 * errors.len()` values, direction
    /// after direction (three rows of an H matrix); orientation rows are not computed.
    pub position_gains: fn(&[f64], &[f64], &mut [f64]),
    /// Arithmetic operations of one position-gain evaluation.
    pub position_operations: usize,
    /// `compensate(commanded, params, values, sin_cos, out)`: the model's `compensation::compensate`
    /// on slices; `commanded` and `out` one command per axis (mm, rad, machine order), `values`
    /// one per error (mm, rad).
    pub compensate: CompensateFn,
    /// `first_order_f32(pose, params, values, out)`: the model's
    /// `compensation::first_order_f32` on slices; `out` holds one change per axis then the six
    /// residuals.
    pub first_order_f32: FirstOrderF32Fn,
}

/// The compiled model `model` of the built-in machine `machine`.
pub fn lookup(machine: &str, model: &str) -> Option<&'static CompiledModel> {
    MODELS
        .iter()
        .find(|m| m.machine == machine && m.model == model)
}

include!(concat!(env!("OUT_DIR"), "/machines.rs"));
