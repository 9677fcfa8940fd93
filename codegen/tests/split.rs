//! Large models are split into parts of bounded size, which compute the same gains.

use codegen::{GainModel, compile, compile_parts};
use model_spec::builtin;

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
fn split_code_compiles() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let code = codegen::emit::generate_machine_with(&m, &["full"], 20).unwrap();
    assert!(
        code.contains("fn gains_part0(") && code.contains("fn position_gains_part1("),
        "split into part functions"
    );
    assert!(
        code.contains("in ") && code.contains(" parts;"),
        "the header says the model is split"
    );
    let dir = std::env::temp_dir().join(format!("rtest-split-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("split.rs");
    std::fs::write(&file, format!("#![no_std]\n{code}")).unwrap();
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let out = std::process::Command::new(rustc)
        .args([
            "--edition",
            "2024",
            "--crate-type",
            "lib",
            "--emit",
            "metadata",
            "-D",
            "warnings",
            "-o",
        ])
        .arg(dir.join("split.rmeta"))
        .arg(&file)
        .output()
        .expect("rustc runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
