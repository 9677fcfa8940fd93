//! No input panics the TOML and JSON readers of rtest: truth files and identification
//! reports, fed random bytes and random damage of valid files, read soundly or fail with a
//! located message. (The CSV readers have their own properties in `csvprop.rs`; machine
//! descriptions theirs in model-spec's `robustness.rs`.)

use crate::one_record::identify_one;
use crate::one_report::{IdentificationSource, report_of_one};
use fitting::IdentifyOptions;
use formats::truth::builtin_truth;
use formats::truth::{BUILTIN_TRUTHS, TruthError};
use model_spec::Machine;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use report::json::read::parse_identification_bytes;
use report::json::{ReportError, to_json};
use simulation::model::Model;
use simulation::{builtin_path, simulate};
use std::panic::{AssertUnwindSafe, catch_unwind};

fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// One damage of a text: bytes flipped to other bytes (UTF-8 or not), a line deleted or
/// doubled, a number replaced by an odd one, a span cut out.
#[derive(Clone, Debug)]
enum Damage {
    Byte(usize, u8),
    DeleteLine(usize),
    DoubleLine(usize),
    Number(usize, &'static str),
    Cut(usize, usize),
}

const ODD: [&str; 12] = [
    "nan", "inf", "-inf", "1e999", "-1e308", "1e308", "0", "-0.0", "\"x\"", "null", "[]", "{}",
];

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Damage::Byte(i, b)),
        any::<usize>().prop_map(Damage::DeleteLine),
        any::<usize>().prop_map(Damage::DoubleLine),
        (any::<usize>(), proptest::sample::select(&ODD[..]))
            .prop_map(|(i, s)| Damage::Number(i, s)),
        (any::<usize>(), 0usize..40).prop_map(|(i, n)| Damage::Cut(i, n)),
    ]
}

/// Byte ranges of the numbers of `text`.
fn numbers(text: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit() || text[i] == b'-';
        if starts && (i == 0 || !text[i - 1].is_ascii_alphanumeric()) {
            let start = i;
            i += 1;
            while i < text.len() && (text[i].is_ascii_digit() || b".eE+-".contains(&text[i])) {
                i += 1;
            }
            out.push(start..i);
        } else {
            i += 1;
        }
    }
    out
}

fn apply(text: &[u8], damages: &[Damage]) -> Vec<u8> {
    let mut t = text.to_vec();
    for d in damages {
        let lines: Vec<(usize, usize)> = {
            let mut v = Vec::new();
            let mut start = 0;
            for (i, &b) in t.iter().enumerate() {
                if b == b'\n' {
                    v.push((start, i + 1));
                    start = i + 1;
                }
            }
            v.push((start, t.len()));
            v
        };
        match *d {
            Damage::Byte(i, b) if !t.is_empty() => {
                let n = t.len();
                t[i % n] = b;
            }
            Damage::DeleteLine(i) => {
                let (a, b) = lines[i % lines.len()];
                t.drain(a..b);
            }
            Damage::DoubleLine(i) => {
                let (a, b) = lines[i % lines.len()];
                let copy = t[a..b].to_vec();
                t.splice(a..a, copy);
            }
            Damage::Number(i, s) => {
                let found = numbers(&t);
                if !found.is_empty() {
                    let r = found[i % found.len()].clone();
                    t.splice(r, s.bytes());
                }
            }
            Damage::Cut(i, n) if !t.is_empty() => {
                let a = i % t.len();
                let b = (a + n).min(t.len());
                t.drain(a..b);
            }
            _ => {}
        }
    }
    t
}

/// Reads `bytes` as a truth file; panics if reading panics, if an error is not located in the
/// text, or if a truth read has a number out of its bounds.
fn check_truth(m: &Machine, bytes: &[u8]) {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let text = model_spec::text::decode_text("t.toml", bytes.to_vec())?;
        formats::truth::parse_truth("t.toml", &text, m).map_err(TruthErrorOrText::Truth)
    }));
    let Ok(result) = result else {
        panic!(
            "the truth reader panicked on {:?}",
            String::from_utf8_lossy(bytes)
        );
    };
    match result {
        Ok(t) => {
            assert!(
                t.coefficients
                    .iter()
                    .all(|c| c.is_finite() && c.abs() <= 1e3)
            );
            assert!(t.params.iter().all(|p| p.is_finite() && p.abs() <= 1e5));
            assert!(t.noise_mm.is_finite() && (0.0..=1.0).contains(&t.noise_mm));
        }
        Err(TruthErrorOrText::Truth(TruthError::Invalid {
            file,
            line,
            column,
            message,
        })) => {
            let lines = bytes.split(|&b| b == b'\n').count();
            assert_eq!(file, "t.toml");
            assert!(
                line >= 1 && line <= lines,
                "line {line} of {lines}: {message}"
            );
            assert!(column >= 1, "{message}");
            assert!(!message.is_empty());
        }
        Err(TruthErrorOrText::Text(e)) => {
            let s = e.to_string();
            assert!(s.starts_with("t.toml:"), "{s}");
        }
        Err(TruthErrorOrText::Truth(other)) => panic!("not located: {other}"),
    }
}

enum TruthErrorOrText {
    Truth(TruthError),
    Text(model_spec::text::TextError),
}

impl From<model_spec::text::TextError> for TruthErrorOrText {
    fn from(e: model_spec::text::TextError) -> Self {
        TruthErrorOrText::Text(e)
    }
}

/// A valid identification report of seed-ac (the reduced model plus a harmonic, zeroed).
fn report(m: &Machine) -> Vec<u8> {
    let truth = builtin_truth("seed-ac-demo", m).unwrap().unwrap();
    let k4 = simulate(m, &truth, &builtin_path(m, "K4").unwrap().unwrap()).unwrap();
    let mut model = Model::of(m, "reduced").unwrap();
    model
        .terms
        .push(simulation::model::Term::parse(m, "ECC@harmonic:2").unwrap());
    let ident = identify_one(m, &model, &k4, &IdentifyOptions::new().zeroed(true)).unwrap();
    let source = IdentificationSource {
        data: "k4.csv",
        label: "reduced + ECC@harmonic:2",
        base_model: Some("reduced"),
    };
    let r = report_of_one(m, source, &ident, None).unwrap();
    to_json(&r).unwrap().into_bytes()
}

/// Reads `bytes` as an identification report; panics if reading panics, if an error does not
/// name the file and a place (a field, or a line and column), or if values read are not finite.
fn check_report(m: &Machine, bytes: &[u8]) {
    let result = catch_unwind(AssertUnwindSafe(|| {
        parse_identification_bytes("id.json", bytes.to_vec(), m)
    }));
    let Ok(result) = result else {
        panic!(
            "the report reader panicked on {:?}",
            String::from_utf8_lossy(bytes)
        );
    };
    match result {
        Ok(v) => {
            assert_eq!(v.values.values.len(), v.values.layout.columns.len());
            assert!(v.values.values.iter().flatten().all(|x| x.is_finite()));
        }
        Err(ReportError::Field {
            file,
            field,
            message,
        }) => {
            assert_eq!(file, "id.json");
            assert!(!field.is_empty() && !message.is_empty());
        }
        Err(ReportError::Json {
            file,
            line,
            column,
            message,
        }) => {
            assert_eq!(file, "id.json");
            let lines = bytes.split(|&b| b == b'\n').count();
            assert!(
                line >= 1 && line <= lines,
                "line {line} of {lines}: {message}"
            );
            assert!(column >= 1, "{message}");
        }
        Err(ReportError::Text(e)) => {
            let s = e.to_string();
            assert!(s.starts_with("id.json:"), "{s}");
        }
    }
}

fn runner(cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    })
}

/// 200 random byte strings and 300 damaged built-in truths.
#[test]
fn truth_files_never_panic_and_errors_are_located() {
    let m = seed_ac();
    runner(200)
        .run(&proptest::collection::vec(any::<u8>(), 0..600), |bytes| {
            check_truth(&m, &bytes);
            Ok(())
        })
        .unwrap();
    let texts: Vec<&'static str> = BUILTIN_TRUTHS.iter().map(|(_, t)| *t).collect();
    runner(300)
        .run(
            &(
                proptest::sample::select(texts),
                proptest::collection::vec(damage(), 1..4),
            ),
            |(text, damages)| {
                check_truth(&m, &apply(text.as_bytes(), &damages));
                Ok(())
            },
        )
        .unwrap();
}

/// 200 random byte strings and 300 damaged reports.
#[test]
fn identification_reports_never_panic_and_errors_are_located() {
    let m = seed_ac();
    let valid = report(&m);
    check_report(&m, &valid);
    assert!(parse_identification_bytes("id.json", valid.clone(), &m).is_ok());
    runner(200)
        .run(&proptest::collection::vec(any::<u8>(), 0..600), |bytes| {
            check_report(&m, &bytes);
            Ok(())
        })
        .unwrap();
    runner(300)
        .run(&proptest::collection::vec(damage(), 1..4), |damages| {
            check_report(&m, &apply(&valid, &damages));
            Ok(())
        })
        .unwrap();
}
