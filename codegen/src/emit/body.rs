//! Function bodies: one `let` per instruction of the IR, in order, then the stores of the
//! outputs. Inputs are loaded into locals named after their fields, intermediates are `t0`,
//! `t1`, … ([`super::names`]).

use super::lets;
use super::names::local_names;
use crate::ir::{Op, Output, Program};
use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;

/// An exact `f64` literal (shortest round-trip decimal, `f64` suffix), negative values as a
/// unary minus.
pub fn float_literal(x: f64) -> TokenStream {
    if named_constant(x, Float::F64).is_some() {
        let text = literal_text(x.to_bits(), Float::F64);
        return text.parse().expect("a path to a core constant");
    }
    let lit = Literal::f64_suffixed(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// An identifier (a field, module or constant name that the machine description made valid).
pub(crate) fn ident(name: &str) -> Ident {
    Ident::new(name, Span::call_site())
}

/// The `core` constant whose value `|x|` is in the type `float`, for the constants an exact
/// inclined direction brings (`√2`, written as a literal Clippy reads as an approximation of
/// `SQRT_2`).
fn named_constant(x: f64, float: Float) -> Option<&'static str> {
    match float {
        Float::F64 => {
            let a = x.abs();
            (a == core::f64::consts::SQRT_2)
                .then_some("core::f64::consts::SQRT_2")
                .or((a == core::f64::consts::FRAC_1_SQRT_2)
                    .then_some("core::f64::consts::FRAC_1_SQRT_2"))
        }
        Float::F32 => {
            let a = (x as f32).abs();
            (a == core::f32::consts::SQRT_2)
                .then_some("core::f32::consts::SQRT_2")
                .or((a == core::f32::consts::FRAC_1_SQRT_2)
                    .then_some("core::f32::consts::FRAC_1_SQRT_2"))
        }
    }
}

/// One output cell: a value, a negated value or a literal.
fn cell(locals: &[String], o: &Output) -> TokenStream {
    cell_with(locals, o, Float::F64)
}

/// One output cell, literals of type `float`.
pub(crate) fn cell_with(locals: &[String], o: &Output, float: Float) -> TokenStream {
    match *o {
        Output::Var(v) => {
            let v = ident(&locals[v as usize]);
            quote!(#v)
        }
        Output::Neg(v) => {
            let v = ident(&locals[v as usize]);
            quote!(-#v)
        }
        Output::Const(c) => match float {
            Float::F64 => float_literal(c),
            Float::F32 => float_literal_f32(c),
        },
    }
}

/// Which arguments a program reads: `(pose, params)`.
pub fn reads(p: &Program) -> (bool, bool) {
    let mut r = (false, false);
    for op in &p.ops {
        if let Op::Input(k) = *op {
            if p.inputs[k as usize].parameter {
                r.1 = true;
            } else {
                r.0 = true;
            }
        }
    }
    r
}

/// An exact `f32` literal of `x` rounded to single precision (shortest round-trip decimal,
/// `f32` suffix), negative values as a unary minus.
pub fn float_literal_f32(x: f64) -> TokenStream {
    if named_constant(x, Float::F32).is_some() {
        let text = literal_text(x.to_bits(), Float::F32);
        return text.parse().expect("a path to a core constant");
    }
    let x = x as f32;
    let lit = Literal::f32_suffixed(x.abs());
    if x.is_sign_negative() && x != 0.0 {
        quote!(-#lit)
    } else {
        quote!(#lit)
    }
}

/// The floating-point type of emitted code.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Float {
    /// `f64`: bit for bit the in-process evaluation.
    F64,
    /// `f32`: the same instructions in single precision.
    F32,
}

/// One `let` per instruction: `let zc = params.Zc;`, `let t3 = t1 * zc;`.
fn lets(p: &Program, locals: &[String]) -> TokenStream {
    let load = |k: usize| {
        let input = &p.inputs[k];
        let from = if input.parameter { "params" } else { "pose" };
        format!("{from}.{}", input.field)
    };
    lets_with(p, locals, &load, Float::F64)
}

/// The text of a literal as `prettyplease` prints it (`1.5f64`, `-0.25f32`).
fn literal_text(bits: u64, float: Float) -> String {
    let x = f64::from_bits(bits);
    let magnitude = match (named_constant(x, float), float) {
        (Some(name), _) => name.to_string(),
        (None, Float::F64) => Literal::f64_suffixed(x.abs()).to_string(),
        (None, Float::F32) => Literal::f32_suffixed((x as f32).abs()).to_string(),
    };
    let negative = match float {
        Float::F64 => x.is_sign_negative() && x != 0.0,
        Float::F32 => (x as f32).is_sign_negative() && x as f32 != 0.0,
    };
    if negative {
        format!("-{magnitude}")
    } else {
        magnitude
    }
}

/// One `let` per instruction, inputs loaded by `load(input index)` (the text of the
/// expression: `pose.sin_a`, `values[3]`), literals of type `float`. Written as text and
/// carried in runs ([`super::lets`]); a statement too long for a run goes through `syn`.
pub(crate) fn lets_with(
    p: &Program,
    names: &[String],
    load: &dyn Fn(usize) -> String,
    float: Float,
) -> TokenStream {
    use std::fmt::Write;
    let mut run = lets::Run::default();
    let mut out = TokenStream::new();
    let mut line = String::new();
    for (op, dst) in p.ops.iter().zip(names) {
        let l = |v: u32| names[v as usize].as_str();
        line.clear();
        // Writing to a `String` cannot fail.
        let _ = match *op {
            Op::Input(k) => write!(line, "let {dst} = {};", load(k as usize)),
            Op::Const(bits) => write!(line, "let {dst} = {};", literal_text(bits, float)),
            Op::Add(a, b) => write!(line, "let {dst} = {} + {};", l(a), l(b)),
            Op::Sub(a, b) => write!(line, "let {dst} = {} - {};", l(a), l(b)),
            Op::Mul(a, b) => write!(line, "let {dst} = {} * {};", l(a), l(b)),
            Op::Neg(a) => write!(line, "let {dst} = -{};", l(a)),
            Op::Div(a, b) => write!(line, "let {dst} = {} / {};", l(a), l(b)),
        };
        run.push(&line, &mut out);
    }
    run.flush(&mut out);
    out
}

/// The statements of a six-row program's body: one `let` per instruction, then one store of
/// `[gx, gy, gz, gi, gj, gk]` per error.
///
/// The runs of `let` statements are carried as `__rtest_lets!(r"…")` markers: print the
/// tokens with [`super::pretty`], which writes them out.
pub fn body(p: &Program, error_consts: &[Ident]) -> TokenStream {
    let locals = local_names(p);
    let lets = lets(p, &locals);
    let stores = p.outputs.chunks(6).zip(error_consts).map(|(row, name)| {
        let cells = row.iter().map(|o| cell(&locals, o));
        quote!(out[#name] = [#(#cells),*];)
    });
    quote!(#lets #(#stores)*)
}

/// The statements of a position program's body ([`crate::compile_position`]): one `let` per
/// instruction, then one store per direction of the gains of all `n` errors.
///
/// The runs of `let` statements are carried as `__rtest_lets!(r"…")` markers: print the
/// tokens with [`super::pretty`], which writes them out.
pub fn position_body(p: &Program, n: usize) -> TokenStream {
    let locals = local_names(p);
    let lets = lets(p, &locals);
    let stores = p.outputs.chunks(n.max(1)).enumerate().map(|(d, row)| {
        let d = Literal::usize_unsuffixed(d);
        let cells = row.iter().map(|o| cell(&locals, o));
        quote!(out[#d] = [#(#cells),*];)
    });
    quote!(#lets #(#stores)*)
}

/// The body of one part of a split position program: its `let`s, then one store per cell
/// `out[d][ERROR] = …` (the part's errors only).
pub(crate) fn position_part_body(p: &Program, error_consts: &[Ident]) -> TokenStream {
    let locals = local_names(p);
    let lets = lets(p, &locals);
    let n = error_consts.len().max(1);
    let stores = p.outputs.chunks(n).enumerate().flat_map(|(d, row)| {
        let (d, locals) = (Literal::usize_unsuffixed(d), &locals);
        row.iter().zip(error_consts).map(move |(o, name)| {
            let c = cell(locals, o);
            quote!(out[#d][#name] = #c;)
        })
    });
    quote!(#lets #(#stores)*)
}
