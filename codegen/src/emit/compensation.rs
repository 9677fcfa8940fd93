//! The `compensation` module of a model: the corrected pose of a commanded pose, emitted from
//! the compensation programs ([`crate::compensation`]) in `f64` (bit for bit the host's
//! evaluation) and the first-order correction in `f32` (for single-precision controllers).

use super::body::{Float, cell_with, float_literal, ident, lets_with};
use super::names::local_names;
use crate::compensation::{CompensationPrograms, DAMPING, RESIDUALS, STEPS};
use crate::ir::Program;
use proc_macro2::{Literal, TokenStream};
use quote::quote;

/// Where each input of a compensation program comes from, by index range.
struct Layout {
    pose: usize,
    params: usize,
    values: usize,
}

impl Layout {
    /// The load of input `k` from the arguments of a struct-taking function (`pose.sin_a`,
    /// `params.Zc`, `values[3]`, `target[1]`).
    fn structured(&self, p: &Program, k: usize) -> String {
        let field = &p.inputs[k].field;
        if k < self.pose {
            format!("pose.{field}")
        } else if k < self.pose + self.params {
            format!("params.{field}")
        } else if k < self.pose + self.params + self.values {
            format!("values[{}]", k - self.pose - self.params)
        } else {
            format!("target[{}]", k - self.pose - self.params - self.values)
        }
    }

    /// The load of input `k` from the arrays of the `f32` function.
    fn arrays(&self, k: usize) -> String {
        let (array, i) = if k < self.pose {
            ("pose", k)
        } else if k < self.pose + self.params {
            ("params", k - self.pose)
        } else {
            ("values", k - self.pose - self.params)
        };
        format!("{array}[{i}]")
    }
}

/// `name` or, for a program that reads none of the inputs `range`, `_name` (no unused
/// argument in the emitted code).
fn argument_name(p: &Program, range: std::ops::Range<usize>, name: &str) -> proc_macro2::Ident {
    let reads = p
        .ops
        .iter()
        .any(|op| matches!(*op, crate::ir::Op::Input(k) if range.contains(&(k as usize))));
    if reads {
        ident(name)
    } else {
        ident(&format!("_{name}"))
    }
}

/// `params` or, for a program that reads no kinematic parameter, `_params`.
fn params_name(p: &Program, layout: &Layout) -> proc_macro2::Ident {
    argument_name(p, layout.pose..layout.pose + layout.params, "params")
}

/// The body of a program: its `let`s, then `out[k] = …` per output (or an array expression
/// when `array` is set).
fn body(p: &Program, load: &dyn Fn(usize) -> String, float: Float) -> TokenStream {
    let locals = local_names(p);
    let lets = lets_with(p, &locals, load, float);
    let stores = p.outputs.iter().enumerate().map(|(k, o)| {
        let k = Literal::usize_unsuffixed(k);
        let c = cell_with(&locals, o, float);
        quote!(out[#k] = #c;)
    });
    quote!(#lets #(#stores)*)
}

/// The `compensation` module of one model (inside the model's module, so `super::N` is its
/// number of errors and `super::super::{Pose, Params}` the machine's structs).
pub(crate) fn compensation_module(c: &CompensationPrograms) -> TokenStream {
    let layout = Layout {
        pose: c.pose_inputs,
        params: c.params,
        values: c.errors.len(),
    };
    let n_axes = c.axis_count();
    let axes_lit = Literal::usize_unsuffixed(n_axes);
    let out_len = Literal::usize_unsuffixed(n_axes + RESIDUALS);
    let pose_len = Literal::usize_unsuffixed(c.pose_inputs);
    let params_len = Literal::usize_unsuffixed(c.params);
    let names = c.axes.iter().map(|(n, _)| n.as_str());
    let rotary = c.axes.iter().map(|(_, r)| *r);
    let steps = Literal::usize_unsuffixed(STEPS);
    let damping = float_literal(DAMPING);
    let target_body = body(&c.target, &|k| layout.structured(&c.target, k), Float::F64);
    let step_body = body(&c.step, &|k| layout.structured(&c.step, k), Float::F64);
    let first_body = body(&c.first_step, &|k| layout.arrays(k), Float::F32);
    let (tp, sp, fp) = (
        params_name(&c.target, &layout),
        params_name(&c.step, &layout),
        params_name(&c.first_step, &layout),
    );
    let first_pose = argument_name(&c.first_step, 0..layout.pose, "pose");
    let counts = |p: &Program| p.op_counts().to_string();
    let target_doc = format!(" Straight-line code: {}.", counts(&c.target));
    let step_doc = format!(" Straight-line code: {}.", counts(&c.step));
    let first_doc = format!(" Straight-line code: {}.", counts(&c.first_step));
    // `pose_of`: one `sin_cos` call per rotary axis, then the struct in field order.
    let mut trig = Vec::new();
    let mut fields = Vec::new();
    for (i, (name, is_rotary)) in c.axes.iter().enumerate() {
        let lower = name.to_ascii_lowercase();
        let i = Literal::usize_unsuffixed(i);
        if *is_rotary {
            let (s, co) = (
                ident(&format!("sin_{lower}")),
                ident(&format!("cos_{lower}")),
            );
            trig.push(quote!(let (#s, #co) = sin_cos(commands[#i]);));
            fields.push(quote!(#s));
            fields.push(quote!(#co));
        } else {
            let f = ident(&lower);
            fields.push(quote!(#f: commands[#i]));
        }
    }
    let sc = if trig.is_empty() {
        ident("_sin_cos")
    } else {
        ident("sin_cos")
    };
    quote! {
        /// Compensation with this model: the corrected commands of a commanded pose, so that
        /// the predicted tool point and tool axis at the corrected pose (nominal kinematics
        /// plus the model's first-order error) are the nominal ones at the commanded pose,
        /// in the workpiece's frame. Commands are in machine axis order
        /// ([`compensation::AXES`]): mm for linear axes, rad for rotary ones. Error values are
        /// the model's errors at the pose ([`ERRORS`], mm and rad): constants, and the
        /// position-dependent ones from the axis compensation tables or the identified terms.
        /// Set-up errors, sensor and time terms are no machine errors: pass them as zero.
        pub mod compensation {
            use super::super::{Params, Pose};
            use super::N;
            /// Number of axes.
            pub const AXIS_COUNT: usize = #axes_lit;
            /// Axis names, in command order.
            pub const AXES: [&str; #axes_lit] = [#(#names),*];
            /// `true` for rotary axes (commands in rad), `false` for linear axes (mm).
            pub const ROTARY: [bool; #axes_lit] = [#(#rotary),*];
            /// Steps of [`compensate`].
            pub const STEPS: usize = #steps;
            /// Damping of the rotary axes' least squares, (rad/rad)²: near a singular pose
            /// the orientation correction fades to zero instead of growing without bound.
            pub const DAMPING: f64 = #damping;
            /// The target of a commanded pose: the tool point (mm) and the tool axis in the
            /// last frame of the work chain.
            #[doc = #target_doc]
            pub fn target(pose: &Pose, #tp: &Params) -> [f64; 6] {
                let mut out = [0.0f64; 6];
                #target_body
                out
            }
            /// One step from `pose` towards `target`: `out[..AXIS_COUNT]` the change of every
            /// command (mm, rad), `out[AXIS_COUNT..]` the predicted residual at `pose` in the
            /// tool frame (position x, y, z in mm; tilt of the tool axis about x and y and
            /// roll about it, rad).
            #[doc = #step_doc]
            pub fn step(
                pose: &Pose,
                #sp: &Params,
                values: &[f64; N],
                target: &[f64; 6],
                out: &mut [f64; #out_len],
            ) {
                #step_body
            }
            /// The pose inputs of `commands` (mm, rad), the sines and cosines by `sin_cos`.
            pub fn pose_of<F: Fn(f64) -> (f64, f64)>(commands: &[f64; #axes_lit], #sc: &F) -> Pose {
                #(#trig)*
                Pose { #(#fields),* }
            }
            /// The corrected commands of `commanded` (mm, rad): [`STEPS`] steps of [`step`]
            /// from the commanded pose, the sines and cosines of each new pose by `sin_cos`
            /// (the caller's: `f64::sin_cos` on a host, the controller's own on a target).
            /// With `f64::sin_cos` the result is bit for bit the host's (`rtest compensate`
            /// before its check). The remainder after the steps is far below 1 nm where the
            /// values are those of the corrected pose; the values are those of the commanded
            /// pose, which differ by the error's slope times the correction.
            pub fn compensate<F: Fn(f64) -> (f64, f64)>(
                commanded: &[f64; #axes_lit],
                params: &Params,
                values: &[f64; N],
                sin_cos: F,
            ) -> [f64; #axes_lit] {
                let target = target(&pose_of(commanded, &sin_cos), params);
                let mut q = *commanded;
                let mut out = [0.0f64; #out_len];
                for _ in 0..STEPS {
                    step(&pose_of(&q, &sin_cos), params, values, &target, &mut out);
                    for (qi, d) in q.iter_mut().zip(out.iter()) {
                        *qi += *d;
                    }
                }
                q
            }
            /// [`compensate`] on slices: `commanded` and `out` one command per axis,
            /// `params` in the order of [`super::super::PARAMETERS`], `values` one per error.
            ///
            /// # Panics
            /// When a slice has another length.
            #[track_caller]
            pub fn compensate_slice(
                commanded: &[f64],
                params: &[f64],
                values: &[f64],
                sin_cos: fn(f64) -> (f64, f64),
                out: &mut [f64],
            ) {
                let commanded: &[f64; #axes_lit] = commanded.try_into().expect("compensate_slice: one command per axis");
                let values: &[f64; N] = values.try_into().expect("compensate_slice: one value per error");
                out.copy_from_slice(&compensate(commanded, &Params::from_slice(params), values, sin_cos));
            }
            /// [`first_order_f32`] on slices of the same lengths.
            ///
            /// # Panics
            /// When a slice has another length.
            #[track_caller]
            pub fn first_order_f32_slice(pose: &[f32], params: &[f32], values: &[f32], out: &mut [f32]) {
                let out: &mut [f32; #out_len] = out.try_into().expect("first_order_f32_slice: one change per axis and six residuals");
                first_order_f32(
                    pose.try_into().expect("first_order_f32_slice: one value per pose input"),
                    params.try_into().expect("first_order_f32_slice: one value per parameter"),
                    values.try_into().expect("first_order_f32_slice: one value per error"),
                    out,
                );
            }
            /// The first-order correction in single precision: `out[..AXIS_COUNT]` the
            /// change to add to every command (mm, rad), `out[AXIS_COUNT..]` the predicted
            /// error at the commanded pose (as [`step`]'s residual). `pose` and `params` in the
            /// order of [`super::super::POSE_INPUTS`] and [`super::super::PARAMETERS`]. One
            /// step, no iteration: it leaves the second order of the correction (its angle
            /// squared times the lever arm) and the rounding of `f32`; the bound is stated and
            /// tested in the documentation of rtest's compensation.
            ///
            #[doc = #first_doc]
            pub fn first_order_f32(
                #first_pose: &[f32; #pose_len],
                #fp: &[f32; #params_len],
                values: &[f32; N],
                out: &mut [f32; #out_len],
            ) {
                #first_body
            }
        }
    }
}
