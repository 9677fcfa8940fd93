//! The truth TOML: parsing, units, evaluation at samples, the built-in truths, and every
//! invalid entry reported with file, line and column.

use crate::common;
use common::context;

use common::{Scratch, builtin, commands, id};
use formats::truth::{
    BUILTIN_TRUTHS, TruthError, builtin_truth, load_truth, seed_ac_demo_truth,
    seed_ac_reduced_truth,
};
use model_spec::{Dir, Machine};
use simulation::model::Basis;
use simulation::model::{Effect, Term};
use simulation::record::Sample;
use simulation::truth::Truth;

fn seed_ac() -> Machine {
    builtin("seed-ac")
}

fn parse(text: &str) -> Result<Truth, TruthError> {
    formats::truth::parse_truth("t.toml", text, &seed_ac())
}

fn message(text: &str) -> String {
    match parse(text) {
        Ok(t) => panic!("accepted: {t:?}"),
        Err(e) => e.to_string(),
    }
}

fn term(m: &Machine, name: &str, basis: &str) -> Term {
    Term::new(
        m,
        Effect::parse(m, name).unwrap(),
        Basis::parse(basis).unwrap(),
    )
    .unwrap()
}

#[test]
fn a_full_example_in_people_units_is_held_in_mm_and_rad() {
    let m = seed_ac();
    let t = parse(
        r#"
machine = "seed-ac"
description = "example"
noise_um = 0.25
noise_phi = 0.8
seed = 42
zeroed = true

[parameters]
Zp = 185.0

[errors]
XOW = 12.5
X0C = -10          # digit-zero alias, integer
AOC = 30.0         # µrad
ECC = { const = 3.0, "harmonic:2" = [8.0, -6.0] }
EXX = { "poly:1" = 4.0, reversal = 1.5 }
dz0 = { const = 1.0, "time:1" = 0.5 }
"#,
    )
    .unwrap();
    assert_eq!(t.description, "example");
    assert_eq!(t.noise_mm, 0.00025);
    assert_eq!(t.noise_phi, 0.8);
    assert!(
        t.summary(&m).contains("noise 0.25 um AR(1) phi 0.8"),
        "{}",
        t.summary(&m)
    );
    assert_eq!(t.seed, 42);
    assert!(t.zeroed);
    let zp = m.symbol_by_name("Zp").unwrap();
    assert_eq!(t.params[zp], 185.0);
    let xw = m.symbol_by_name("Xw").unwrap();
    assert_eq!(t.params[xw], -217.504, "others keep their defaults");

    let c = |name: &str, basis: &str| t.coefficient(&term(&m, name, basis)).unwrap().to_vec();
    assert_eq!(c("XOW", "const"), vec![0.0125]);
    assert_eq!(c("XOC", "const"), vec![-0.01]);
    assert_eq!(c("AOC", "const"), vec![3e-5]);
    assert_eq!(c("ECC", "const"), vec![3e-6]);
    assert_eq!(c("ECC", "harmonic:2"), vec![8e-6, -6e-6]);
    assert_eq!(c("EXX", "poly:1"), vec![0.004]);
    assert_eq!(c("EXX", "reversal"), vec![0.0015]);
    assert_eq!(c("dz0", "const"), vec![0.001]);
    assert_eq!(c("dz0", "time:1"), vec![0.0005]);
    assert_eq!(t.model.terms.len(), 9);
    assert_eq!(t.coefficients.len(), 10);
    // Terms are sorted: catalogue order of the errors, sensor offsets last.
    let mut sorted = t.model.terms.clone();
    sorted.sort();
    assert_eq!(sorted, t.model.terms);
    assert!(t.coefficient(&term(&m, "YOW", "const")).is_none());
}

#[test]
fn values_at_a_sample_follow_the_bases() {
    let m = seed_ac();
    let t = parse(
        r#"
[errors]
XOW = 12.0
ECC = { const = 3.0, "harmonic:2" = [8.0, -6.0] }
EXX = { "poly:1" = 4.0, reversal = 1.5 }
dx0 = 2.0
dz0 = { const = 1.0, "time:1" = 0.5 }
"#,
    )
    .unwrap();
    let c = 30f64.to_radians();
    let x = 250.0; // stroke [-500, 500]: normalised 0.5
    let mut motion = vec![1i8; m.axes.len()];
    motion[m.axis_by_name("X").unwrap()] = -1;
    let s = Sample {
        commands: commands(&m, &[("C", c), ("X", x)]),
        t: 0.0,
        motion,
        timed: true,
    };
    let cx = context(&s, -0.5);
    let e = t.error_values(&m, &cx);
    assert_eq!(e.len(), m.catalogue.len());
    let close = |a: f64, b: f64| (a - b).abs() < 1e-15;
    assert!(close(e[id(&m, "XOW")], 0.012));
    let ecc = 3e-6 + 8e-6 * (2.0 * c).cos() - 6e-6 * (2.0 * c).sin();
    assert!(close(e[id(&m, "ECC")], ecc), "{} {ecc}", e[id(&m, "ECC")]);
    assert!(close(e[id(&m, "EXX")], 0.004 * 0.5 - 0.0015));
    let others: f64 = e.iter().map(|v| v.abs()).sum::<f64>()
        - e[id(&m, "XOW")].abs()
        - e[id(&m, "ECC")].abs()
        - e[id(&m, "EXX")].abs();
    assert_eq!(others, 0.0);
    let o = t.sensor_offsets(&m, &cx);
    assert!(close(o[0], 0.002));
    assert_eq!(o[1], 0.0);
    assert!(close(o[2], 0.001 - 0.5 * 0.0005));
}

#[test]
fn to_toml_reads_back_bit_for_bit() {
    let m = seed_ac();
    let mut t = parse(
        r#"
description = "with \"quotes\""
noise_um = 0.3
noise_phi = 0.35
seed = 9
[parameters]
Zc = 30.1
[errors]
XOW = 12.345678901234
AOC = -0.1
ECC = { const = 3.0, "harmonic:2" = [8.0, -6.0] }
dz0 = { "time:2" = 1e-3 }
"#,
    )
    .unwrap();
    t.coefficients[0] = 0.1 + 0.2; // an awkward number
    let text = formats::truth::truth_to_toml(&t, &m);
    let back = formats::truth::parse_truth("t.toml", &text, &m).unwrap();
    assert_eq!(back.source, "t.toml");
    let mut t2 = t.clone();
    t2.source = back.source.clone();
    assert_eq!(back, t2, "{text}");
    for (a, b) in back.coefficients.iter().zip(&t.coefficients) {
        assert_eq!(a.to_bits(), b.to_bits());
    }
}

#[test]
fn the_builtin_truths_are_valid_and_as_documented() {
    let m = seed_ac();
    for (name, _) in BUILTIN_TRUTHS {
        let t = builtin_truth(name, &m).unwrap().unwrap();
        assert_eq!(t.source, *name);
        assert!(!t.description.is_empty());
    }
    let reduced = seed_ac_reduced_truth();
    let want = m.model_errors("reduced").unwrap();
    assert_eq!(reduced.model.errors(), want);
    assert!(reduced.model.terms.iter().all(|t| t.basis == Basis::Const));
    assert_eq!(reduced.noise_mm, 0.0);
    assert!(!reduced.zeroed);
    for e in reduced.entries(&m) {
        assert!(
            (10.0..=40.0).contains(&e.values[0].abs()),
            "{} = {}",
            e.name,
            e.values[0]
        );
    }

    let demo = seed_ac_demo_truth();
    assert_eq!(demo.noise_mm, 0.0005);
    assert!(!demo.zeroed);
    let errors = demo.model.errors();
    for e in want {
        assert!(errors.contains(e));
    }
    let hidden: Vec<Term> = demo
        .model
        .terms
        .iter()
        .filter(|t| !matches!(t.effect, Effect::Error(e) if want.contains(&e)))
        .copied()
        .collect();
    assert_eq!(hidden, vec![term(&m, "ECC", "harmonic:2")]);
    let ecc = demo.coefficient(&hidden[0]).unwrap();
    assert!((ecc[0].hypot(ecc[1]) - 10e-6).abs() < 1e-12);
    assert_eq!(demo.params, m.default_parameters());
    assert!(
        demo.summary(&m).starts_with(
            "truth seed-ac-demo: 12 term(s) [XOW YOW ZOW YOA ZOA BOA COA ECC@harmonic:2 XOC YOC AOC BOC], noise 0.5 um, seed 1, not zeroed"
        ),
        "{}",
        demo.summary(&m)
    );
}

#[test]
fn builtin_truths_refuse_other_machines() {
    let m = builtin("head-table-bc");
    let e = builtin_truth("seed-ac-demo", &m).unwrap().unwrap_err();
    assert_eq!(
        e.to_string(),
        "<built-in seed-ac-demo>:10:11: this truth is written for machine `seed-ac`, not `head-table-bc`"
    );
}

#[test]
fn load_truth_by_name_or_file() {
    let m = seed_ac();
    assert_eq!(
        load_truth("seed-ac-demo", &m).unwrap(),
        seed_ac_demo_truth()
    );
    let e = load_truth("no-such-truth.toml", &m).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no built-in truth and no file called `no-such-truth.toml` (built-in: seed-ac-demo, seed-ac-reduced, seed-ac-budget)"
    );
    let dir = Scratch::new("truth");
    let f = dir.0.join("t.toml");
    std::fs::write(&f, "[errors]\nXOW = 1\n").unwrap();
    let t = load_truth(f.to_str().unwrap(), &m).unwrap();
    assert_eq!(t.source, f.display().to_string());
    assert_eq!(t.coefficients, vec![0.001]);
}

#[test]
fn an_empty_truth_is_the_nominal_machine() {
    let m = seed_ac();
    let t = parse("").unwrap();
    let mut n = Truth::nominal(&m);
    n.source = "t.toml".into();
    n.description = String::new();
    assert_eq!(t, n);
}

#[test]
fn every_invalid_entry_names_file_line_and_column() {
    let cases: &[(&str, &str)] = &[
        // TOML syntax.
        ("[errors]\nXOW = = 1\n", "t.toml:2:7: "),
        // Unknown keys.
        (
            "noise = 0.5\n",
            "t.toml:1:1: unknown key `noise` (expected machine, description, noise_um, noise_phi, seed, zeroed, [parameters], [errors])",
        ),
        (
            "[offsets]\ndx0 = 1\n",
            "t.toml:1:2: unknown key `offsets` (expected machine, description, noise_um, noise_phi, seed, zeroed, [parameters], [errors])",
        ),
        // Unknown error.
        (
            "[errors]\nXOQ = 1.0\n",
            "t.toml:2:1: `XOQ` is neither an error of machine seed-ac nor a sensor offset dx0 dy0 dz0 nor an instrument term SXX … SZY (errors: EXX EYX",
        ),
        // Bases that do not fit.
        (
            "[errors]\nXOC = { \"harmonic:2\" = [1, 2] }\n",
            "t.toml:2:9: XOC: basis does not fit: `harmonic:2` needs an error of a rotary axis (XOC belongs to no axis)",
        ),
        (
            "[errors]\nEXX = { \"harmonic:1\" = [1, 2] }\n",
            "t.toml:2:9: EXX: basis does not fit: `harmonic:1` needs an error of a rotary axis (EXX is an error of axis X)",
        ),
        (
            "[errors]\nECC = { \"poly:1\" = 1 }\n",
            "t.toml:2:9: ECC: basis does not fit: `poly:1` needs an error of a linear axis (ECC is an error of axis C)",
        ),
        (
            "[errors]\ndx0 = { reversal = 1 }\n",
            "t.toml:2:9: dx0: basis does not fit: `reversal` needs an error of an axis (dx0 belongs to no axis)",
        ),
        (
            "[errors]\nECC = { \"cubic:2\" = 1 }\n",
            "t.toml:2:9: ECC: unknown basis `cubic:2` (expected const, harmonic:K, poly:K, reversal, time:K, period:P, step:V, exp:TAU, velocity, rate, warmup:TAU or jump:T)",
        ),
        (
            "[errors]\nECC = { \"harmonic:0\" = [1, 2] }\n",
            "t.toml:2:9: ECC: `harmonic:0`: the order of `harmonic:K` must be a whole number from 1 to 64",
        ),
        // Array lengths and shapes.
        (
            "[errors]\nECC = { \"harmonic:2\" = [1, 2, 3] }\n",
            "t.toml:2:24: ECC `harmonic:2` (µrad) needs two numbers [cos, sin], got an array of 3",
        ),
        (
            "[errors]\nECC = { \"harmonic:2\" = 1 }\n",
            "t.toml:2:24: ECC `harmonic:2` (µrad) needs two numbers [cos, sin], not integer",
        ),
        (
            "[errors]\nXOW = { const = [1, 2] }\n",
            "t.toml:2:17: XOW `const` (µm) takes one number; only `harmonic:K` and `period:P` take a pair [cos, sin]",
        ),
        (
            "[errors]\nECC = { \"harmonic:2\" = [1, \"a\"] }\n",
            "t.toml:2:28: ECC `harmonic:2` (µrad) must be a number, not string",
        ),
        // Non-finite numbers.
        (
            "[errors]\nXOW = nan\n",
            "t.toml:2:7: XOW `const` (µm) must be a finite number, not `nan`",
        ),
        (
            "[errors]\nXOW = { \"time:1\" = -inf }\n",
            "t.toml:2:20: XOW `time:1` (µm) must be a finite number, not `-inf`",
        ),
        (
            "noise_um = inf\n",
            "t.toml:1:12: `noise_um` (standard deviation of the reading noise, µm) must be a finite number, not `inf`",
        ),
        (
            "[parameters]\nZp = nan\n",
            "t.toml:2:6: parameter `Zp` (mm) must be a finite number, not `nan`",
        ),
        // Other values.
        (
            "noise_um = -0.5\n",
            "t.toml:1:12: `noise_um` (standard deviation of the reading noise, µm) must be from 0 to 1000 µm, not -0.5",
        ),
        (
            "noise_phi = 0.99\n",
            "t.toml:1:13: `noise_phi` (lag-1 autocorrelation of the reading noise) must be at least 0 and below 0.99, not 0.99",
        ),
        (
            "noise_phi = -0.1\n",
            "t.toml:1:13: `noise_phi` (lag-1 autocorrelation of the reading noise) must be at least 0 and below 0.99, not -0.1",
        ),
        (
            "noise_phi = \"high\"\n",
            "t.toml:1:13: `noise_phi` (lag-1 autocorrelation of the reading noise) must be a number, not string",
        ),
        (
            "noise_um = 1e308\n",
            "t.toml:1:12: `noise_um` (standard deviation of the reading noise, µm) must be from 0 to 1000 µm, not 1e308",
        ),
        (
            "[errors]\nXOC = 2e6\n",
            "t.toml:2:7: XOC `const` (µm): 2e6 is beyond the largest magnitude a truth may have, 1000000 µm",
        ),
        (
            "[errors]\nECC = { \"harmonic:2\" = [1, -1e308] }\n",
            "t.toml:2:28: ECC `harmonic:2` (µrad): -1e308 is beyond the largest magnitude a truth may have, 1000000 µrad",
        ),
        (
            "[parameters]\nZc = 1e308\n",
            "t.toml:2:6: parameter `Zc` (mm): 1e308 is beyond the largest magnitude a truth may have, 100000 mm",
        ),
        (
            "seed = -1\n",
            "t.toml:1:8: `seed` must be a whole number from 0 to 9223372036854775807, not `-1`",
        ),
        (
            "seed = 18446744073709551615\n",
            "t.toml:1:8: `seed` must be a whole number from 0 to 9223372036854775807, not `18446744073709551615`",
        ),
        (
            "seed = 1.5\n",
            "t.toml:1:8: `seed` must be a whole number from 0 to 9223372036854775807, not float",
        ),
        (
            "zeroed = \"yes\"\n",
            "t.toml:1:10: `zeroed` must be true or false, not string",
        ),
        (
            "machine = \"head-table-bc\"\n",
            "t.toml:1:11: this truth is written for machine `head-table-bc`, not `seed-ac`",
        ),
        (
            "description = 3\n",
            "t.toml:1:15: `description` must be a string, not integer",
        ),
        (
            "errors = 3\n",
            "t.toml:1:10: `[errors]` must be a table, not integer",
        ),
        (
            "[errors]\nXOW = \"ten\"\n",
            "t.toml:2:7: `XOW` must be a number (a constant, µm) or a table of basis = value, e.g. { const = 1.0, \"harmonic:2\" = [0.5, 0.0] }, not string",
        ),
        (
            "[errors]\nXOW = {}\n",
            "t.toml:2:7: `XOW` has no terms: give e.g. { const = 1.0 } (µm)",
        ),
        // The same term twice (alias).
        (
            "[errors]\nXOC = 1.0\nX0C = { const = 2.0 }\n",
            "t.toml:3:9: XOC with basis `const` is given twice (first at line 2)",
        ),
        // The new vocabulary: bases that do not fit, values of the wrong shape.
        (
            "[errors]\nSXY = { \"time:1\" = 0.1 }\n",
            "t.toml:2:9: SXY: basis does not fit: `SXY` is an instrument term of the R-test: constants only, not `time:1`",
        ),
        (
            "[errors]\nEXY = { velocity = 0.5 }\n",
            "t.toml:2:9: EXY: basis does not fit: `velocity` needs the positioning error of an axis",
        ),
        (
            "[errors]\nEXX = { \"period:10\" = 2.0 }\n",
            "t.toml:2:23: EXX `period:10` (µm) needs two numbers [cos, sin], not float",
        ),
        (
            "[errors]\nECC = { velocity = [1, 2] }\n",
            "t.toml:2:20: ECC `velocity` (ms) takes one number; only `harmonic:K` and `period:P` take a pair [cos, sin]",
        ),
        (
            "[errors]\nXOC = { \"exp:0\" = 1.0 }\n",
            "t.toml:2:9: XOC: `exp:0`: the time constant TAU of `exp:TAU` (s) must be positive",
        ),
        // Unknown kinematic parameter.
        (
            "[parameters]\nZq = 1.0\n",
            "t.toml:2:1: machine seed-ac has no kinematic parameter `Zq` (it has: Xa, Ya, Za, Zc, Xw, Yw, Zw, Xz, Yz, Zz, Xh, Zh, Zp)",
        ),
    ];
    for (text, want) in cases {
        let got = message(text);
        assert!(
            got.starts_with(want),
            "for\n{text}\ngot:  {got}\nwant: {want}"
        );
    }
}

#[test]
fn numbers_are_read_without_double_rounding() {
    let m = seed_ac();
    let t = parse("[errors]\nXOW = 1_000.5\nAOC = 0.1\nYOW = 0x10\nZOW = 1e1\n").unwrap();
    let c = |name: &str| t.coefficient(&term(&m, name, "const")).unwrap()[0];
    assert_eq!(c("XOW"), 1.0005);
    assert_eq!(c("AOC"), 1e-7, "0.1 µrad is the double nearest 1e-7 rad");
    assert_eq!(c("YOW"), 0.016);
    assert_eq!(c("ZOW"), 0.01);
}

#[test]
fn sensor_offsets_are_effects_too() {
    let m = seed_ac();
    let t = parse("[errors]\ndy0 = -3.0\n").unwrap();
    assert_eq!(t.model.terms[0].effect, Effect::SensorOffset(Dir::Y));
    assert_eq!(t.coefficients, vec![-0.003]);
    let e = t.entries(&m);
    assert_eq!((e[0].name.as_str(), e[0].unit), ("dy0", "um"));
    assert_eq!(e[0].values, vec![-3.0]);
}
