//! Names of the locals in emitted code.
//!
//! An input keeps the snake case of its field (`pose.sin_a` is loaded into `sin_a`, `pose.x`
//! into `x`, `params.Zc` into `zc`); only intermediates get generated names, `t0`, `t1`, … in
//! instruction order. The input names of a program are unique, never a Rust keyword, never the
//! name of an argument of the generated functions (`pose`, `params`, `out`, `values`,
//! `target`) and never of the
//! form `t` + digits, so they cannot collide with an intermediate. A name that would be one of
//! those gets a deterministic suffix: a keyword, an argument name or an intermediate-like name
//! gets a trailing `_` (`in_`, `out_`, `t0_`), a name already taken by an earlier input gets
//! `_2`, `_3`, … (`Zc` then `ZC` give `zc` then `zc_2`).

use crate::ir::{Input, Op, Program};
use proc_macro2::{Ident, Span};
use std::collections::HashSet;

/// The arguments of the generated functions, which a local must not shadow.
const ARGUMENTS: &[&str] = &["pose", "params", "out", "values", "target"];

/// The snake case of an ASCII identifier: a word starts at an upper-case letter that follows a
/// lower-case letter or a digit, or that starts a capitalised word after a run of capitals
/// (`ZProbe` → `z_probe`); letters are lower-cased and runs of `_` become one (`Zc` → `zc`,
/// `ZC` → `zc`, `Z__p` → `z_p`, `sin_a` → `sin_a`).
pub fn snake_case(name: &str) -> String {
    let chars: Vec<char> = name.chars().collect();
    let mut out = String::with_capacity(name.len() + 4);
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            let prev = chars[i - 1];
            let next_lower = chars.get(i + 1).is_some_and(|n| n.is_ascii_lowercase());
            if prev.is_ascii_lowercase()
                || prev.is_ascii_digit()
                || (prev.is_ascii_uppercase() && next_lower)
            {
                out.push('_');
            }
        }
        if c == '_' && out.ends_with('_') {
            continue;
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// `true` for the names of intermediates: `t` followed by one or more digits.
fn is_intermediate(name: &str) -> bool {
    name.strip_prefix('t')
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
}

/// `true` for a name no input may take as it is.
fn is_reserved(name: &str) -> bool {
    model_spec::RUST_KEYWORDS.contains(&name) || ARGUMENTS.contains(&name) || is_intermediate(name)
}

/// The local name of every input, in order (see the module documentation for the rules).
pub fn input_locals(inputs: &[Input]) -> Vec<String> {
    let mut taken: HashSet<String> = HashSet::new();
    inputs
        .iter()
        .map(|input| {
            let mut base = snake_case(&input.field);
            if is_reserved(&base) {
                base.push('_');
            }
            let mut name = base.clone();
            let mut k = 2;
            while taken.contains(&name) || is_reserved(&name) {
                let sep = if base.ends_with('_') { "" } else { "_" };
                name = format!("{base}{sep}{k}");
                k += 1;
            }
            taken.insert(name.clone());
            name
        })
        .collect()
}

/// The local of every instruction of `p`, indexed by [`crate::ir::Var`]: the input's name for an
/// input load, `t0`, `t1`, … for the others in order.
pub fn locals(p: &Program) -> Vec<Ident> {
    local_names(p)
        .iter()
        .map(|n| Ident::new(n, Span::call_site()))
        .collect()
}

/// The names of [`locals`], as text.
pub(crate) fn local_names(p: &Program) -> Vec<String> {
    let inputs = input_locals(&p.inputs);
    let mut next = 0usize;
    p.ops
        .iter()
        .map(|op| match *op {
            Op::Input(k) => inputs[k as usize].clone(),
            _ => {
                next += 1;
                format!("t{}", next - 1)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(field: &str) -> Input {
        Input {
            name: field.to_string(),
            field: field.to_string(),
            parameter: true,
        }
    }

    fn names(fields: &[&str]) -> Vec<String> {
        input_locals(&fields.iter().map(|f| input(f)).collect::<Vec<_>>())
    }

    #[test]
    fn snake_case_of_fields() {
        for (field, snake) in [
            ("sin_a", "sin_a"),
            ("x", "x"),
            ("Zc", "zc"),
            ("ZC", "zc"),
            ("Xwo", "xwo"),
            ("ZProbe", "z_probe"),
            ("zProbe", "z_probe"),
            ("L2x", "l2x"),
            ("X2Y", "x2_y"),
            ("Z__p", "z_p"),
            ("Zc_", "zc_"),
        ] {
            assert_eq!(snake_case(field), snake, "{field}");
        }
    }

    #[test]
    fn collisions_keywords_arguments_and_intermediates_get_suffixes() {
        assert_eq!(names(&["Zc", "ZC", "zc"]), ["zc", "zc_2", "zc_3"]);
        assert_eq!(names(&["In", "Type", "Gen"]), ["in_", "type_", "gen_"]);
        assert_eq!(
            names(&["Out", "Pose", "Params"]),
            ["out_", "pose_", "params_"]
        );
        assert_eq!(names(&["T0", "T12", "T", "Tx"]), ["t0_", "t12_", "t", "tx"]);
        assert_eq!(names(&["In", "in_", "In_"]), ["in_", "in_2", "in_3"]);
        assert_eq!(names(&["Zc_2", "Zc", "ZC"]), ["zc_2", "zc", "zc_3"]);
    }

    #[test]
    fn intermediates_are_numbered_in_order_after_the_inputs() {
        let p = Program {
            inputs: vec![input("Zc"), input("T0")],
            ops: vec![Op::Input(0), Op::Input(1), Op::Add(0, 1), Op::Mul(2, 0)],
            outputs: vec![],
        };
        let l: Vec<String> = locals(&p).iter().map(|i| i.to_string()).collect();
        assert_eq!(l, ["zc", "t0_", "t0", "t1"]);
    }
}
