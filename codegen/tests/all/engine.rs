//! Properties of the engine itself: determinism, exact literals, canonical simplification.

use codegen::emit::float_literal;
use codegen::{GainModel, compile};
use model_spec::all_builtin;
use proptest::prelude::*;

#[test]
fn generation_is_deterministic() {
    for m in all_builtin() {
        let a = codegen::emit::generate_machine(&m, &[]).unwrap();
        let b = codegen::emit::generate_machine(&m, &[]).unwrap();
        assert_eq!(a, b, "{}", m.name);
    }
}

proptest! {
    /// Every float literal the emitter writes reads back as the same f64, bit for bit.
    #[test]
    fn float_literals_round_trip(x in proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO) {
        let text = float_literal(x).to_string().replace(' ', "");
        let digits = text.trim_end_matches("f64");
        let back: f64 = digits.parse().unwrap();
        prop_assert_eq!(back.to_bits(), x.to_bits(), "{} printed as {}", x, text);
    }
}

#[test]
fn literals_are_shortest_decimals() {
    assert_eq!(float_literal(211.537).to_string(), "211.537f64");
    assert_eq!(float_literal(0.1).to_string(), "0.1f64");
    assert_eq!(
        float_literal(-0.279).to_string().replace(' ', ""),
        "-0.279f64"
    );
}

#[test]
fn head_machine_gains_simplify_sin2_plus_cos2() {
    // The tool frame turns with B: rotating the error vector into it multiplies by Ry(B)ᵀ, and a
    // translation error of the B head itself must come out as a constant (−1, 0 or 1) only after
    // sin²B + cos²B = 1 is applied.
    let m = model_spec::builtin("head-table-bc").unwrap().unwrap();
    let ids: Vec<usize> = ["EXB", "EYB", "EZB"]
        .iter()
        .map(|n| m.error_by_name(n).unwrap())
        .collect();
    let g = GainModel::derive(&m, &ids);
    for (name, row) in g.error_names.iter().zip(&g.gains) {
        for p in &row[..3] {
            assert!(p.len() <= 2, "{name}: {p:?} is not simplified");
        }
    }
}

#[test]
fn programs_only_read_inputs_they_need() {
    for m in all_builtin() {
        let g = GainModel::derive(&m, m.model_errors("full").unwrap());
        let p = compile(&m, &g);
        let reads = p
            .ops
            .iter()
            .filter(|o| matches!(o, codegen::ir::Op::Input(_)))
            .count();
        assert!(reads <= p.inputs.len());
        // No instruction is computed twice (hash-consing).
        let mut seen = std::collections::HashSet::new();
        for op in &p.ops {
            assert!(seen.insert(*op), "{}: {op:?} computed twice", m.name);
        }
    }
}
