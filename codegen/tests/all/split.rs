//! Large models are split into parts of bounded size, which compute the same gains; the code of
//! a split model and of every built-in machine compiles as `no_std` without a warning (rustc's
//! and Clippy's default lints) and allows only the lints of `codegen::emit::ALLOWED_LINTS`.

use codegen::{GainModel, compile, compile_parts};
use model_spec::builtin;

use crate::support;

#[test]
fn parts_partition_the_errors_stay_bounded_and_equal_the_whole_model() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let model = GainModel::derive(&m, m.model_errors("full").unwrap());
    let whole = compile(&m, &model);
    let max = 20;
    let parts = compile_parts(&m, &model, max);
    assert!(
        parts.len() > 1,
        "a bound of {max} instructions splits the 44-error model"
    );
    let mut rows: Vec<usize> = parts.iter().flat_map(|p| p.rows.clone()).collect();
    rows.sort_unstable();
    assert_eq!(
        rows,
        (0..model.errors.len()).collect::<Vec<_>>(),
        "the parts partition the errors"
    );
    for p in &parts {
        assert!(
            p.gains.ops.len() <= max || p.rows.len() == 1,
            "part of {} errors has {} instructions",
            p.rows.len(),
            p.gains.ops.len()
        );
    }
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..20 {
        let commands: Vec<f64> = (0..m.axes.len()).map(|_| 4.0 * uniform() - 2.0).collect();
        let params: Vec<f64> = m
            .symbols
            .iter()
            .map(|s| s.default + 50.0 * (uniform() - 0.5))
            .collect();
        let inputs = model.atoms.values(&commands, &params);
        let mut all = vec![0.0; whole.outputs.len()];
        whole.eval(&inputs, &mut Vec::new(), &mut all);
        for p in &parts {
            let mut out = vec![0.0; p.gains.outputs.len()];
            p.gains.eval(&inputs, &mut Vec::new(), &mut out);
            let mut pos = vec![0.0; p.position.outputs.len()];
            p.position.eval(&inputs, &mut Vec::new(), &mut pos);
            let n = p.rows.len();
            for (k, &i) in p.rows.iter().enumerate() {
                for r in 0..6 {
                    let (a, b) = (all[6 * i + r], out[6 * k + r]);
                    assert!(
                        (a - b).abs() <= 1e-12 * (1.0 + a.abs()),
                        "{}: {a} vs {b}",
                        model.error_names[i]
                    );
                }
                for d in 0..3 {
                    let (a, b) = (all[6 * i + d], pos[d * n + k]);
                    assert!(
                        (a - b).abs() <= 1e-12 * (1.0 + a.abs()),
                        "{} position: {a} vs {b}",
                        model.error_names[i]
                    );
                }
            }
        }
    }
}

#[test]
fn split_code_compiles_without_warnings_and_allows_only_the_named_lints() {
    let dir = support::scratch("split");
    for name in ["seed-ac", "head-table-bc"] {
        let m = builtin(name).unwrap().unwrap();
        let code = codegen::emit::generate_machine_with(&m, &["full"], 20).unwrap();
        assert!(
            code.contains("fn gains_part0(") && code.contains("fn position_gains_part1("),
            "{name}: split into part functions"
        );
        assert!(
            code.contains("in ") && code.contains(" parts;"),
            "{name}: the header says the model is split"
        );
        // Parts that do not read an argument name it `_pose` / `_params` (no lint to allow).
        if name == "seed-ac" {
            assert!(
                code.contains("fn gains_part0(_pose: &Pose, _params: &Params"),
                "the set-up errors of the workpiece do not depend on pose or params"
            );
        }
        assert_eq!(
            support::allowed_lints(&code),
            codegen::emit::ALLOWED_LINTS,
            "{name}: only the named lints are allowed, once each (on Params)"
        );
        assert!(!code.contains("clippy::all") && !code.contains("#!["));
        support::check_no_std_lib(&dir, &code);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn every_builtin_machine_compiles_without_warnings() {
    let dir = support::scratch("builtin");
    for m in model_spec::all_builtin() {
        let code = codegen::emit::generate_machine(&m, &[]).unwrap();
        assert_eq!(
            support::allowed_lints(&code),
            codegen::emit::ALLOWED_LINTS,
            "{}",
            m.name
        );
        support::check_no_std_lib(&dir, &code);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A model whose gains are all constant (the positioning errors of three linear axes): its
/// single-precision correction reads neither the pose nor a parameter, and names both
/// arguments so that nothing is unused.
#[test]
fn a_model_of_constant_gains_compiles_without_warnings() {
    let dir = support::scratch("constant");
    let text = format!(
        "{}\n[models.positioning]\ndescription = \"positioning errors only\"\nerrors = [\"EXX\", \"EYY\", \"EZZ\"]\n",
        include_str!("../machines/no-symbols.toml")
    );
    let m = model_spec::parse_machine("constant.toml", &text).unwrap();
    let code = codegen::emit::generate_machine(&m, &["positioning"]).unwrap();
    assert!(
        code.contains("_pose: &[f32;"),
        "the f32 correction does not read the pose"
    );
    support::check_no_std_lib(&dir, &code);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Machines unlike the built-in ones, compensation module included: no kinematic symbol at all
/// (its functions read no parameter), one rotary axis about a negative direction.
#[test]
fn other_topologies_compile_without_warnings() {
    let dir = support::scratch("topologies");
    for (file, text) in [
        (
            "no-symbols.toml",
            include_str!("../machines/no-symbols.toml"),
        ),
        (
            "one-rotary.toml",
            include_str!("../machines/one-rotary.toml"),
        ),
    ] {
        let m = model_spec::parse_machine(file, text).unwrap();
        let code = codegen::emit::generate_machine(&m, &[]).unwrap();
        assert!(code.contains("pub mod compensation"), "{file}");
        support::check_no_std_lib(&dir, &code);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

use crate::support::chains;

/// Inclined axes and long chains: a table turning about `[0, 1, 1]` (its compensation module
/// holds `√2` in `f64` and `f32`), a chain of twelve rotary axes with inclined ones, whole and
/// split. The roots of the frames are written as `core::f64::consts::SQRT_2`, not as literals
/// Clippy denies (`approx_constant`).
#[test]
fn inclined_axes_and_long_chains_compile_without_warnings() {
    let dir = support::scratch("inclined");
    let tilted = include_str!("../machines/one-rotary.toml").replace("\"-y\"", "[0, 1, 1]");
    let tilted = model_spec::parse_machine("tilted.toml", &tilted).unwrap();
    let code = codegen::emit::generate_machine(&tilted, &[]).unwrap();
    assert!(code.contains("pub mod compensation"));
    assert!(
        code.contains("core::f64::consts::SQRT_2") && code.contains("core::f32::consts::SQRT_2")
    );
    support::check_no_std_lib(&dir, &code);
    let chain = chains::synthetic(12, false);
    for bound in [codegen::MAX_INSTRUCTIONS, 600] {
        let code = codegen::emit::generate_machine_with(&chain, &[], bound).unwrap();
        assert_eq!(bound < 1000, code.contains("fn gains_part1("));
        support::check_no_std_lib(&dir, &code);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
