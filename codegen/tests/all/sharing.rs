//! The shared form is the expanded form, written smaller.
//!
//! For every machine where expanding is cheap (the built-in machines, synthetic chains of up to
//! six rotary axes, machines with inclined axes, exact and numeric), and for several bounds
//! of terms (down to naming every quantity of two terms or more):
//! - the shared gains, expanded, are exactly the polynomials derived without intermediates;
//! - the identically zero gains are the same: a gain zero in the expanded form is an exact zero
//!   in the shared form (never a polynomial over intermediates that merely evaluates to zero),
//!   and so a literal zero in the compiled program;
//! - the compiled shared form evaluates to the expanded gains.
//!
//! And the built-in machines name no intermediate at the default bound, so their gains, tables
//! and programs are exactly the expanded ones.

use codegen::ir::Output;
use codegen::{DeriveOptions, GainModel, compile};
use model_spec::{Machine, all_builtin, parse_machine};

use crate::support::chains;

/// A head on X, Y, Z whose rotary axes are given by their `directions` (TOML values), each
/// offset from the last by `offset` (TOML value).
fn head(name: &str, directions: &[&str], offset: &str) -> Machine {
    let mut text = format!(
        "name = \"{name}\"\n[symbols]\nL = 100.0\nW = 10.0\nD = 5.0\n\n\
         [[work]]\nend = \"ball\"\noffset = [\"W\", 0, 0]\n\n"
    );
    for axis in ["x", "y", "z"] {
        text.push_str(&format!(
            "[[tool]]\naxis = \"{}\"\ntype = \"linear\"\ndirection = \"+{axis}\"\n\
             stroke = [-1000, 1000]\n\n",
            axis.to_ascii_uppercase()
        ));
    }
    for (letter, d) in ["A", "B", "C", "D", "F"].iter().zip(directions) {
        text.push_str(&format!(
            "[[tool]]\naxis = \"{letter}\"\ntype = \"rotary\"\ndirection = {d}\n\
             offset = {offset}\n\n"
        ));
    }
    text.push_str("[[tool]]\nend = \"probe\"\noffset = [0, 0, \"L\"]\n");
    parse_machine(&format!("{name}.toml"), &text).expect("a valid test machine")
}

/// The machines of the comparison.
fn machines() -> Vec<Machine> {
    let mut ms = all_builtin();
    ms.extend((1..=6).map(|n| chains::synthetic(n, false)));
    ms.push(chains::synthetic(4, true));
    let (none, lateral) = ("[0, 0, 0]", "[0, \"D\", 0]");
    let wrist = ["\"+z\"", "\"+y\"", "\"+z\"", "\"+x\""];
    let parallel = ["[0, 1, 1]", "[0, 1, 1]", "[0, 1, 1]"];
    let numeric = ["[0.3, 0.4, 0.5]", "\"+z\"", "[0.3, 0.4, 0.5]", "\"+x\""];
    for (name, directions) in [
        ("wrist", &wrist[..]),
        ("parallel", &parallel),
        ("numeric", &numeric),
    ] {
        ms.push(head(name, directions, none));
        ms.push(head(name, directions, lateral));
    }
    ms
}

#[test]
fn builtin_machines_name_no_intermediates() {
    for m in all_builtin() {
        let all: Vec<usize> = (0..m.catalogue.len()).collect();
        let models = m.model_names();
        let lists = models
            .iter()
            .map(|n| m.model_errors(n).unwrap().to_vec())
            .chain([all]);
        for errors in lists {
            let g = GainModel::derive(&m, &errors);
            assert!(g.intermediates().is_empty(), "{}", m.name);
        }
    }
}

#[test]
fn shared_gains_expand_to_the_expanded_derivation_with_the_same_zeros() {
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    for m in machines() {
        let errors: Vec<usize> = (0..m.catalogue.len()).collect();
        let expanded = GainModel::derive_with(&m, &errors, DeriveOptions::EXPANDED);
        assert!(expanded.intermediates().is_empty());
        for max_terms in [1, 2, 4, DeriveOptions::DEFAULT_MAX_TERMS] {
            let shared = GainModel::derive_with(&m, &errors, DeriveOptions { max_terms });
            let program = compile(&m, &shared);
            let (s, x) = (shared.gains.shared(), expanded.gains.shared());
            let again = shared.gains.expanded();
            for i in 0..errors.len() {
                for k in 0..6 {
                    let what = || {
                        format!(
                            "{} {} row {k}, bound {max_terms}",
                            m.name, shared.error_names[i]
                        )
                    };
                    assert_eq!(again[i][k], x[i][k], "{}: expansion", what());
                    assert_eq!(s[i][k].is_zero(), x[i][k].is_zero(), "{}: zero", what());
                    if x[i][k].is_zero() {
                        assert_eq!(program.outputs[6 * i + k], Output::Const(0.0), "{}", what());
                    }
                }
            }
            for _ in 0..3 {
                let commands: Vec<f64> = (0..m.axes.len()).map(|_| 6.0 * uniform() - 3.0).collect();
                let params: Vec<f64> = m
                    .symbols
                    .iter()
                    .map(|p| p.default + 100.0 * (uniform() - 0.5))
                    .collect();
                let want = expanded.evaluate(&commands, &params);
                let got = shared.evaluate(&commands, &params);
                let mut out = vec![0.0; program.outputs.len()];
                program.eval(
                    &shared.atoms.values(&commands, &params),
                    &mut Vec::new(),
                    &mut out,
                );
                for i in 0..errors.len() {
                    for k in 0..6 {
                        let tol = 1e-10 * (1.0 + want[i][k].abs());
                        assert!(
                            (got[i][k] - want[i][k]).abs() <= tol
                                && (out[6 * i + k] - want[i][k]).abs() <= tol,
                            "{} {} row {k}, bound {max_terms}: expanded {}, shared {}, compiled {}",
                            m.name,
                            shared.error_names[i],
                            want[i][k],
                            got[i][k],
                            out[6 * i + k]
                        );
                    }
                }
            }
        }
    }
}
