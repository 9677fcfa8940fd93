//! Rust source from the straight-line IR: `no_std`, allocation-free, `+ − ×` only.
//!
//! The tokens are built with `quote`, parsed by `syn` and printed by `prettyplease`; the
//! emitter holds no logic of its own beyond walking [`Program::ops`] in order. Float literals
//! are the shortest decimal that round-trips the `f64` exactly, with an `f64` suffix.
//!
//! For a machine, the emitted module holds:
//! - `Pose`: the sines and cosines of the rotary commands and the linear commands (mm);
//! - `Params`: the kinematic parameters (mm) with the description's defaults;
//! - one module per model (`full`, `reduced`, …) with `N`, `ERRORS`, `ANGULAR`, one index
//!   constant per error (`reduced::XOC`), `OPERATIONS`, and
//!   `gains(pose, params, out: &mut [[f64; 6]; N])` writing `[gx, gy, gz, gi, gj, gk]` per error
//!   (tool minus workpiece, tool frame; mm per mm for translational errors, mm per rad for
//!   angular ones; orientation rows per mm and per rad).

use crate::GainModel;
use crate::ir::{Input, Op, Output, Program};
use crate::lower::{MAX_INSTRUCTIONS, Part, compile_parts};
use model_spec::Machine;
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

/// Why code could not be generated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GenerateError {
    /// A model asked for is not a model of the machine.
    #[error("machine `{machine}` has no model `{model}` (its models: {})", models.join(", "))]
    UnknownModel {
        /// The machine's name.
        machine: String,
        /// The model asked for.
        model: String,
        /// The machine's models.
        models: Vec<String>,
    },
    /// The emitted tokens do not parse as a Rust file: a bug in the emitter (the parser's
    /// message).
    #[error("emitted code does not parse (a bug in codegen): {0}")]
    Unparsable(String),
}

/// An exact `f64` literal (shortest round-trip decimal, `f64` suffix), negative values as a
/// unary minus.
pub fn float_literal(x: f64) -> TokenStream {
    let lit = Literal::f64_suffixed(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

fn var(v: u32) -> Ident {
    format_ident!("v{}", v)
}

fn field(name: &str) -> Ident {
    Ident::new(name, Span::call_site())
}

/// One output cell: a value, a negated value or a literal.
fn cell(o: &Output) -> TokenStream {
    match *o {
        Output::Var(v) => {
            let v = var(v);
            quote!(#v)
        }
        Output::Neg(v) => {
            let v = var(v);
            quote!(-#v)
        }
        Output::Const(c) => float_literal(c),
    }
}

/// The statements of a six-row program's body: one `let` per instruction, then one store of
/// `[gx, gy, gz, gi, gj, gk]` per error.
pub fn body(p: &Program, error_consts: &[Ident]) -> TokenStream {
    let lets = lets(p);
    let stores = p.outputs.chunks(6).zip(error_consts).map(|(row, name)| {
        let cells = row.iter().map(cell);
        quote!(out[#name] = [#(#cells),*];)
    });
    quote!(#lets #(#stores)*)
}

/// The statements of a position program's body ([`crate::compile_position`]): one `let` per
/// instruction, then one store per direction of the gains of all `n` errors.
pub fn position_body(p: &Program, n: usize) -> TokenStream {
    let lets = lets(p);
    let stores = p.outputs.chunks(n.max(1)).enumerate().map(|(d, row)| {
        let d = Literal::usize_unsuffixed(d);
        let cells = row.iter().map(cell);
        quote!(out[#d] = [#(#cells),*];)
    });
    quote!(#lets #(#stores)*)
}

/// The body of one part of a split position program: its `let`s, then one store per cell
/// `out[d][ERROR] = …` (the part's errors only).
fn position_part_body(p: &Program, error_consts: &[Ident]) -> TokenStream {
    let lets = lets(p);
    let n = error_consts.len().max(1);
    let stores = p.outputs.chunks(n).enumerate().flat_map(|(d, row)| {
        let d = Literal::usize_unsuffixed(d);
        row.iter().zip(error_consts).map(move |(o, name)| {
            let c = cell(o);
            quote!(out[#d][#name] = #c;)
        })
    });
    quote!(#lets #(#stores)*)
}

/// The bodies of `gains` and `position_gains` and the part functions they call (none when the
/// model is one part).
fn model_bodies(
    parts: &[Part],
    consts: &[Ident],
    n: &Literal,
    n_value: usize,
) -> (TokenStream, TokenStream, TokenStream) {
    if let [one] = parts {
        return (
            body(&one.gains, consts),
            position_body(&one.position, n_value),
            quote!(),
        );
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
        fns.push(quote! {
            #[doc = #doc]
            #[allow(clippy::all, unused_variables)]
            fn #g(pose: &Pose, params: &Params, out: &mut [[f64; 6]; #n]) { #gb }
            #[doc = #pos_doc]
            #[allow(clippy::all, unused_variables)]
            fn #q(pose: &Pose, params: &Params, out: &mut [[f64; #n]; 3]) { #pb }
        });
        calls.push(quote!(#g(pose, params, out);));
        pos_calls.push(quote!(#q(pose, params, out);));
    }
    (quote!(#(#calls)*), quote!(#(#pos_calls)*), quote!(#(#fns)*))
}

/// Operation counts of a program list, added up.
fn sum_counts<'a>(programs: impl Iterator<Item = &'a Program>) -> crate::ir::OpCounts {
    programs.fold(crate::ir::OpCounts::default(), |a, p| {
        let c = p.op_counts();
        crate::ir::OpCounts {
            add: a.add + c.add,
            mul: a.mul + c.mul,
            neg: a.neg + c.neg,
        }
    })
}

/// One `let` per instruction.
fn lets(p: &Program) -> TokenStream {
    let lets = p.ops.iter().enumerate().map(|(i, op)| {
        let dst = var(i as u32);
        let rhs = match *op {
            Op::Input(k) => {
                let Input {
                    field: f,
                    parameter,
                    ..
                } = &p.inputs[k as usize];
                let f = field(f);
                if *parameter {
                    quote!(params.#f)
                } else {
                    quote!(pose.#f)
                }
            }
            Op::Const(bits) => float_literal(f64::from_bits(bits)),
            Op::Add(a, b) => {
                let (a, b) = (var(a), var(b));
                quote!(#a + #b)
            }
            Op::Sub(a, b) => {
                let (a, b) = (var(a), var(b));
                quote!(#a - #b)
            }
            Op::Mul(a, b) => {
                let (a, b) = (var(a), var(b));
                quote!(#a * #b)
            }
            Op::Neg(a) => {
                let a = var(a);
                quote!(-#a)
            }
        };
        quote!(let #dst = #rhs;)
    });
    quote!(#(#lets)*)
}

/// One model's module (`pub mod reduced { … }`).
pub fn model_module(module: &str, model: &GainModel, parts: &[Part]) -> TokenStream {
    let module_doc = format!(" Model `{module}` of machine `{}`.", model.machine);
    let module = field(module);
    let n_value = model.errors.len();
    let n = Literal::usize_unsuffixed(n_value);
    let names = &model.error_names;
    let consts: Vec<Ident> = names.iter().map(|e| field(e)).collect();
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
    let doc_gains = [
        format!(
            " Gains of the {n_value} errors at `pose`: `out[i] = [gx, gy, gz, gi, gj, gk]`, the error"
        ),
        " vector (tool minus workpiece) and the orientation error in the tool frame per unit of"
            .to_string(),
        " error `i` (mm per mm for translational errors, mm per rad for angular ones).".to_string(),
        String::new(),
        format!(" Straight-line code, no allocation, no branches: {counts}."),
    ];
    let (body, pos_body, part_fns) = model_bodies(parts, &consts, &n, n_value);
    let pos_counts = sum_counts(parts.iter().map(|p| &p.position));
    let pos_total = Literal::usize_unsuffixed(pos_counts.total());
    let doc_position = [
        " Position gains only, in the layout of three rows of an H matrix: `out[d][i]` is the"
            .to_string(),
        " gain of error `i` in direction `d` (x, y, z of the tool frame; mm per mm or mm per rad)."
            .to_string(),
        " The orientation rows are not computed.".to_string(),
        String::new(),
        format!(" Straight-line code, no allocation, no branches: {pos_counts}."),
    ];
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
            #[allow(clippy::all, unused_variables)]
            pub fn gains(pose: &Pose, params: &Params, out: &mut [[f64; 6]; #n]) {
                #body
            }
            /// Arithmetic operations in [`position_gains`].
            pub const POSITION_OPERATIONS: usize = #pos_total;
            #(#[doc = #doc_position])*
            #[allow(clippy::all, unused_variables)]
            pub fn position_gains(pose: &Pose, params: &Params, out: &mut [[f64; #n]; 3]) {
                #pos_body
            }
            /// [`position_gains`] on slices: `out` of length `3 * N`, direction after direction.
            pub fn position_gains_slice(pose: &[f64], params: &[f64], out: &mut [f64]) {
                let mut g = [[0.0f64; N]; 3];
                position_gains(&Pose::from_slice(pose), &Params::from_slice(params), &mut g);
                for (dst, src) in out.chunks_exact_mut(N).zip(g.iter()) {
                    dst.copy_from_slice(src);
                }
            }
            /// [`gains`] on slices: `pose` and `params` in the order of [`super::POSE_INPUTS`]
            /// and [`super::PARAMETERS`], `out` of length `6 * N`, row-major.
            pub fn gains_slice(pose: &[f64], params: &[f64], out: &mut [f64]) {
                let mut g = [[0.0f64; 6]; N];
                gains(&Pose::from_slice(pose), &Params::from_slice(params), &mut g);
                for (dst, src) in out.chunks_exact_mut(6).zip(g.iter()) {
                    dst.copy_from_slice(src);
                }
            }
        }
    }
}

/// The `Pose` and `Params` structs of a machine, from the inputs of any of its programs.
pub fn input_structs(m: &Machine, inputs: &[Input]) -> TokenStream {
    let pose: Vec<&Input> = inputs.iter().filter(|i| !i.parameter).collect();
    let params: Vec<&Input> = inputs.iter().filter(|i| i.parameter).collect();
    let pose_fields = pose.iter().map(|i| field(&i.field));
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
    let param_fields: Vec<Ident> = params.iter().map(|i| field(&i.field)).collect();
    let pose_fields2 = pose.iter().map(|i| field(&i.field));
    let pose_idx = (0..pose.len()).map(Literal::usize_unsuffixed);
    let param_idx = (0..params.len()).map(Literal::usize_unsuffixed);
    let (n_pose, n_params) = (
        Literal::usize_unsuffixed(pose.len()),
        Literal::usize_unsuffixed(params.len()),
    );
    let pose_names = pose.iter().map(|i| i.name.as_str());
    let param_names = params.iter().map(|i| i.name.as_str());
    let defaults = params.iter().map(|i| {
        let s = m
            .symbol_by_name(&i.field)
            .expect("parameter inputs are symbols");
        float_literal(m.symbols[s].default)
    });
    let param_docs = params.iter().map(|i| {
        let s = m
            .symbol_by_name(&i.field)
            .expect("parameter inputs are symbols");
        format!(
            " Kinematic parameter `{}`, mm (default {}).",
            i.field, m.symbols[s].default
        )
    });
    quote! {
        /// Axis commands at one pose: sines and cosines of the rotary commands (so that the
        /// generated bodies need no trigonometry), linear commands in mm.
        #[derive(Clone, Copy, Debug, Default, PartialEq)]
        pub struct Pose {
            #( #[doc = #pose_docs] pub #pose_fields: f64, )*
        }
        /// Kinematic parameters of the machine, mm.
        #[allow(non_snake_case)]
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params {
            #( #[doc = #param_docs] pub #param_fields: f64, )*
        }
        /// Names of the pose inputs in slice order (`Sa`, `Ca`, …, `Xm`, …).
        pub const POSE_INPUTS: [&str; #n_pose] = [#(#pose_names),*];
        /// Names of the kinematic parameters in slice order.
        pub const PARAMETERS: [&str; #n_params] = [#(#param_names),*];
        impl Pose {
            /// A pose from a slice in the order of [`POSE_INPUTS`].
            pub fn from_slice(v: &[f64]) -> Pose {
                Pose { #( #pose_fields2: v[#pose_idx], )* }
            }
        }
        impl Params {
            /// Parameters from a slice in the order of [`PARAMETERS`].
            pub fn from_slice(v: &[f64]) -> Params {
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

/// The code of one machine: its `Pose`, `Params` and one module per model, as a token stream
/// (the content of a module; no crate attributes, so it can be `include!`d).
pub fn machine_tokens(m: &Machine, models: &[(&str, &GainModel, Vec<Part>)]) -> TokenStream {
    let inputs = crate::lower::inputs(m, models.first().expect("at least one model").1);
    let structs = input_structs(m, &inputs);
    let modules = models
        .iter()
        .map(|(name, model, parts)| model_module(name, model, parts));
    quote!(#structs #(#modules)*)
}

/// Pretty-prints a token stream as a Rust file, with a header comment.
pub fn pretty(header: &str, tokens: TokenStream) -> Result<String, GenerateError> {
    let file: syn::File =
        syn::parse2(tokens).map_err(|e| GenerateError::Unparsable(e.to_string()))?;
    let mut out = String::new();
    for line in header.lines() {
        out.push_str("// ");
        out.push_str(line);
        out.push('\n');
    }
    out.push('\n');
    out.push_str(&prettyplease::unparse(&file));
    Ok(out)
}

/// Derives, compiles and emits the models `model_names` of `m` (every model when empty) as one
/// Rust source file; models larger than [`MAX_INSTRUCTIONS`] are split into parts.
pub fn generate_machine(m: &Machine, model_names: &[&str]) -> Result<String, GenerateError> {
    generate_machine_with(m, model_names, MAX_INSTRUCTIONS)
}

/// [`generate_machine`] with a bound on the instructions of one generated function.
pub fn generate_machine_with(
    m: &Machine,
    model_names: &[&str],
    max_instructions: usize,
) -> Result<String, GenerateError> {
    let names: Vec<&str> = if model_names.is_empty() {
        m.model_names()
    } else {
        model_names.to_vec()
    };
    let mut built = Vec::new();
    for name in &names {
        let errors = m
            .model_errors(name)
            .ok_or_else(|| GenerateError::UnknownModel {
                machine: m.name.clone(),
                model: name.to_string(),
                models: m.model_names().iter().map(|s| s.to_string()).collect(),
            })?;
        let model = GainModel::derive(m, errors);
        let parts = compile_parts(m, &model, max_instructions);
        built.push((name.replace('-', "_"), model, parts));
    }
    let header = format!(
        "Generated by rtest codegen from machine `{}` ({}). Do not edit.\n\
         Models: {}.\n\
         no_std-compatible: core arithmetic only, no allocation, sin/cos of rotary commands are inputs.",
        m.name,
        m.description.trim_end_matches('.'),
        built
            .iter()
            .map(|(n, g, parts)| {
                let split = if parts.len() > 1 {
                    format!(" in {} parts", parts.len())
                } else {
                    String::new()
                };
                format!(
                    "{n} ({} errors{split}; gains {}; position gains {})",
                    g.errors.len(),
                    sum_counts(parts.iter().map(|p| &p.gains)),
                    sum_counts(parts.iter().map(|p| &p.position))
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    );
    let refs: Vec<(&str, &GainModel, Vec<Part>)> = built
        .iter()
        .map(|(n, g, p)| (n.as_str(), g, p.clone()))
        .collect();
    pretty(&header, machine_tokens(m, &refs))
}
