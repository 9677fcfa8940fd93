//! The items of an emitted machine: the `Pose` and `Params` structs, and one module per model
//! with its constants, `gains`, `position_gains` and the slice helpers.

use super::body::{body, float_literal, ident, position_body, position_part_body, reads};
use super::docs;
use super::names::snake_case;
use crate::GainModel;
use crate::atoms::AtomKind;
use crate::compensation::CompensationPrograms;
use crate::ir::{Input, OpCounts, Program};
use crate::lower::Part;
use model_spec::Machine;
use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

/// The argument `name` of a function, `_name` when the function does not read it (so that no
/// lint fires and the signature says so).
fn argument(name: &str, read: bool) -> Ident {
    if read {
        ident(name)
    } else {
        format_ident!("_{}", name)
    }
}

/// The `pose` and `params` arguments of a function whose body is `p`.
fn arguments(p: &Program) -> (Ident, Ident) {
    let (pose, params) = reads(p);
    (argument("pose", pose), argument("params", params))
}

/// The bodies of `gains` and `position_gains`, their arguments and the part functions they call
/// (none when the model is one part).
struct Bodies {
    gains: TokenStream,
    gains_args: (Ident, Ident),
    position: TokenStream,
    position_args: (Ident, Ident),
    part_fns: TokenStream,
}

fn model_bodies(parts: &[Part], consts: &[Ident], n: &Literal, n_value: usize) -> Bodies {
    if let [one] = parts {
        return Bodies {
            gains: body(&one.gains, consts),
            gains_args: arguments(&one.gains),
            position: position_body(&one.position, n_value),
            position_args: arguments(&one.position),
            part_fns: quote!(),
        };
    }
    let mut fns = Vec::new();
    let (mut calls, mut pos_calls) = (Vec::new(), Vec::new());
    for (k, part) in parts.iter().enumerate() {
        let part_consts: Vec<Ident> = part.rows.iter().map(|&i| consts[i].clone()).collect();
        let (g, q) = (
            format_ident!("gains_part{}", k),
            format_ident!("position_gains_part{}", k),
        );
        let doc = format!(
            " Part {k} of [`gains`] ({} errors, {}).",
            part.rows.len(),
            part.gains.op_counts()
        );
        let pos_doc = format!(
            " Part {k} of [`position_gains`] ({} errors, {}).",
            part.rows.len(),
            part.position.op_counts()
        );
        let gb = body(&part.gains, &part_consts);
        let pb = position_part_body(&part.position, &part_consts);
        let (gp, gq) = arguments(&part.gains);
        let (pp, pq) = arguments(&part.position);
        fns.push(quote! {
            #[doc = #doc]
            fn #g(#gp: &Pose, #gq: &Params, out: &mut [[f64; 6]; #n]) { #gb }
            #[doc = #pos_doc]
            fn #q(#pp: &Pose, #pq: &Params, out: &mut [[f64; #n]; 3]) { #pb }
        });
        calls.push(quote!(#g(pose, params, out);));
        pos_calls.push(quote!(#q(pose, params, out);));
    }
    let both = (ident("pose"), ident("params"));
    Bodies {
        gains: quote!(#(#calls)*),
        gains_args: both.clone(),
        position: quote!(#(#pos_calls)*),
        position_args: both,
        part_fns: quote!(#(#fns)*),
    }
}

/// Operation counts of a program list, added up.
pub(crate) fn sum_counts<'a>(programs: impl Iterator<Item = &'a Program>) -> OpCounts {
    programs.fold(OpCounts::default(), |a, p| {
        let c = p.op_counts();
        OpCounts {
            add: a.add + c.add,
            mul: a.mul + c.mul,
            neg: a.neg + c.neg,
            div: a.div + c.div,
        }
    })
}

/// `(reads pose, reads params)` of a function with these arguments.
fn read_flags(args: &(Ident, Ident)) -> (bool, bool) {
    let read = |i: &Ident| !i.to_string().starts_with('_');
    (read(&args.0), read(&args.1))
}

/// One model's module (`pub mod reduced { … }`).
///
/// With `compensation`, the module holds a `compensation` module too
/// (the corrected pose of a commanded pose, [`crate::compensation`]).
///
/// The runs of `let` statements are carried as `__rtest_lets!(r"…")` markers: print the
/// tokens with [`super::pretty`], which writes them out.
pub fn model_module(
    module: &str,
    model: &GainModel,
    parts: &[Part],
    compensation: Option<&CompensationPrograms>,
) -> TokenStream {
    let module_doc = format!(" Model `{module}` of machine `{}`.", model.machine);
    let module = ident(module);
    let n_value = model.errors.len();
    let n = Literal::usize_unsuffixed(n_value);
    let names = &model.error_names;
    let consts: Vec<Ident> = names.iter().map(|e| ident(e)).collect();
    let indices = (0..n_value).map(Literal::usize_unsuffixed);
    let const_docs = names.iter().zip(&model.angular).map(|(e, &ang)| {
        format!(
            " Index of `{e}` in the outputs ({}).",
            if ang {
                "angular error, gains per rad"
            } else {
                "translational error, gains per mm"
            }
        )
    });
    let angular = &model.angular;
    let counts = sum_counts(parts.iter().map(|p| &p.gains));
    let ops_total = Literal::usize_unsuffixed(counts.total());
    let b = model_bodies(parts, &consts, &n, n_value);
    let (pose_read, params_read) = read_flags(&b.gains_args);
    let doc_gains = docs::gains(n_value, counts, pose_read, params_read);
    let pos_counts = sum_counts(parts.iter().map(|p| &p.position));
    let pos_total = Literal::usize_unsuffixed(pos_counts.total());
    let (pose_read, params_read) = read_flags(&b.position_args);
    let doc_position = docs::position_gains(pos_counts, pose_read, params_read);
    let (body, pos_body, part_fns) = (b.gains, b.position, b.part_fns);
    let ((gp, gq), (pp, pq)) = (b.gains_args, b.position_args);
    let kinds = &model.atoms.kinds;
    let n_params = kinds
        .iter()
        .filter(|k| matches!(k, AtomKind::Symbol(_)))
        .count();
    let args = [
        (
            "pose",
            "one per entry of `POSE_INPUTS`",
            kinds.len() - n_params,
        ),
        ("params", "one per entry of `PARAMETERS`", n_params),
    ];
    let gains_slice_doc = docs::panics(&[args[0], args[1], ("out", "`6 * N`", 6 * n_value)]);
    let pos_slice_doc = docs::panics(&[args[0], args[1], ("out", "`3 * N`", 3 * n_value)]);
    let compensation = compensation.map(super::compensation::compensation_module);
    quote! {
        #[doc = #module_doc]
        pub mod #module {
            use super::{Params, Pose};
            /// Number of errors of the model.
            pub const N: usize = #n;
            /// Error names (ISO 230), in output order.
            pub const ERRORS: [&str; #n] = [#(#names),*];
            /// `true` for angular errors (rad), `false` for translational errors (mm).
            pub const ANGULAR: [bool; #n] = [#(#angular),*];
            /// Arithmetic operations in [`gains`].
            pub const OPERATIONS: usize = #ops_total;
            #(
                #[doc = #const_docs]
                pub const #consts: usize = #indices;
            )*
            #part_fns
            #(#[doc = #doc_gains])*
            pub fn gains(#gp: &Pose, #gq: &Params, out: &mut [[f64; 6]; #n]) {
                #body
            }
            /// Arithmetic operations in [`position_gains`].
            pub const POSITION_OPERATIONS: usize = #pos_total;
            #(#[doc = #doc_position])*
            pub fn position_gains(#pp: &Pose, #pq: &Params, out: &mut [[f64; #n]; 3]) {
                #pos_body
            }
            /// [`position_gains`] on slices: `pose` and `params` in the order of
            /// [`super::POSE_INPUTS`] and [`super::PARAMETERS`], `out` of length `3 * N`,
            /// direction after direction.
            #(#[doc = #pos_slice_doc])*
            #[track_caller]
            pub fn position_gains_slice(pose: &[f64], params: &[f64], out: &mut [f64]) {
                assert_eq!(out.len(), 3 * N, "position_gains_slice: `out` holds 3 * N gains");
                let mut g = [[0.0f64; N]; 3];
                position_gains(&Pose::from_slice(pose), &Params::from_slice(params), &mut g);
                for (dst, src) in out.chunks_exact_mut(N).zip(g.iter()) {
                    dst.copy_from_slice(src);
                }
            }
            /// [`gains`] on slices: `pose` and `params` in the order of [`super::POSE_INPUTS`]
            /// and [`super::PARAMETERS`], `out` of length `6 * N`, row-major.
            #(#[doc = #gains_slice_doc])*
            #[track_caller]
            pub fn gains_slice(pose: &[f64], params: &[f64], out: &mut [f64]) {
                assert_eq!(out.len(), 6 * N, "gains_slice: `out` holds 6 * N gains");
                let mut g = [[0.0f64; 6]; N];
                gains(&Pose::from_slice(pose), &Params::from_slice(params), &mut g);
                for (dst, src) in out.chunks_exact_mut(6).zip(g.iter()) {
                    dst.copy_from_slice(src);
                }
            }
            #compensation
        }
    }
}

/// The `Pose` and `Params` structs of a machine, from the inputs of any of its programs.
pub fn input_structs(m: &Machine, inputs: &[Input]) -> TokenStream {
    let pose: Vec<&Input> = inputs.iter().filter(|i| !i.parameter).collect();
    let params: Vec<&Input> = inputs.iter().filter(|i| i.parameter).collect();
    let pose_fields: Vec<Ident> = pose.iter().map(|i| ident(&i.field)).collect();
    let pose_docs = pose.iter().map(|i| {
        let axis = i
            .field
            .trim_start_matches("sin_")
            .trim_start_matches("cos_")
            .to_ascii_uppercase();
        if i.field.starts_with("sin_") {
            format!(" Sine of the {axis} command.")
        } else if i.field.starts_with("cos_") {
            format!(" Cosine of the {axis} command.")
        } else {
            format!(" {axis} command, mm.")
        }
    });
    let param_fields: Vec<Ident> = params.iter().map(|i| ident(&i.field)).collect();
    let pose_idx = (0..pose.len()).map(Literal::usize_unsuffixed);
    let param_idx = (0..params.len()).map(Literal::usize_unsuffixed);
    let (n_pose, n_params) = (
        Literal::usize_unsuffixed(pose.len()),
        Literal::usize_unsuffixed(params.len()),
    );
    let pose_names = pose.iter().map(|i| i.name.as_str());
    let param_names = params.iter().map(|i| i.name.as_str());
    let default_of = |i: &Input| {
        let s = m
            .symbol_by_name(&i.field)
            .expect("parameter inputs are symbols");
        m.symbols[s].default
    };
    let defaults = params.iter().map(|i| float_literal(default_of(i)));
    let param_docs = params.iter().map(|i| {
        format!(
            " Kinematic parameter `{}`, mm (default {}).",
            i.field,
            default_of(i)
        )
    });
    // Fields keep the symbols' names (`Zc`): allow that only where a name is not snake case.
    let params_allow = if params.iter().any(|i| snake_case(&i.field) != i.field) {
        quote!(#[allow(non_snake_case)])
    } else {
        quote!()
    };
    let pose_panics = docs::panics(&[("v", "one per entry of `POSE_INPUTS`", pose.len())]);
    let params_panics = docs::panics(&[("v", "one per entry of `PARAMETERS`", params.len())]);
    quote! {
        /// Axis commands at one pose: sines and cosines of the rotary commands (so that the
        /// generated bodies need no trigonometry), linear commands in mm.
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct Pose {
            #( #[doc = #pose_docs] pub #pose_fields: f64, )*
        }
        /// Kinematic parameters of the machine, mm.
        #params_allow
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params {
            #( #[doc = #param_docs] pub #param_fields: f64, )*
        }
        /// Names of the pose inputs in slice order (`Sa`, `Ca`, …, `Xm`, …).
        pub const POSE_INPUTS: [&str; #n_pose] = [#(#pose_names),*];
        /// Names of the kinematic parameters in slice order.
        pub const PARAMETERS: [&str; #n_params] = [#(#param_names),*];
        impl Pose {
            /// A pose from a slice in the order of [`POSE_INPUTS`]: sines and cosines of the
            /// rotary commands, linear commands in mm.
            #(#[doc = #pose_panics])*
            #[track_caller]
            pub fn from_slice(v: &[f64]) -> Pose {
                assert_eq!(v.len(), POSE_INPUTS.len(), "Pose::from_slice: one value per pose input");
                Pose { #( #pose_fields: v[#pose_idx], )* }
            }
        }
        impl Params {
            /// Parameters from a slice in the order of [`PARAMETERS`], mm.
            #(#[doc = #params_panics])*
            #[track_caller]
            pub fn from_slice(v: &[f64]) -> Params {
                assert_eq!(v.len(), PARAMETERS.len(), "Params::from_slice: one value per parameter");
                Params { #( #param_fields: v[#param_idx], )* }
            }
        }
        impl Default for Params {
            /// The defaults of the machine description.
            fn default() -> Self {
                Params { #( #param_fields: #defaults, )* }
            }
        }
    }
}

/// What one model's module is emitted from.
#[derive(Clone, Debug)]
pub struct ModelCode<'a> {
    /// The model's name (the module's).
    pub name: &'a str,
    /// Its gains.
    pub model: &'a GainModel,
    /// Its compiled parts.
    pub parts: Vec<Part>,
    /// Its compensation programs (none for a topology the solver does not handle).
    pub compensation: Option<CompensationPrograms>,
}

/// The code of one machine: its `Pose`, `Params` and one module per model, as a token stream
/// (the content of a module; no crate attributes, so it can be `include!`d once printed).
///
/// The runs of `let` statements are carried as `__rtest_lets!(r"…")` markers: print the
/// tokens with [`super::pretty`], which writes them out.
pub fn machine_tokens(m: &Machine, models: &[ModelCode<'_>]) -> TokenStream {
    let inputs = crate::lower::inputs(m, models.first().expect("at least one model").model);
    let structs = input_structs(m, &inputs);
    let modules = models
        .iter()
        .map(|c| model_module(c.name, c.model, &c.parts, c.compensation.as_ref()));
    quote!(#structs #(#modules)*)
}
