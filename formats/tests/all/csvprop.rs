//! Property tests of the CSV readers (whole file, blocks, path files): fed random bytes or a
//! valid file with random damage (bytes flipped, lines deleted, duplicated or swapped, bytes
//! that are not UTF-8 inserted, very long lines inserted, numbers replaced by huge or
//! non-finite ones, fields removed, the end cut off), they never panic and either read the file,
//! with every number finite and every reading within its bound, or say where the problem is
//! (`file:line:`, or `file: …` with the offending samples listed by `line N`). The whole-file
//! and block readers agree on whether a file reads.
//!
//! Inputs are bounded (at most a few hundred kB), so memory is too; the bound on what a reader
//! takes from an endless source is tested with a counting reader in `csvlines.rs`. The numbers
//! of cases (96 random inputs, 160 damaged files) keep the test to a few seconds in a debug
//! build.

use crate::common;
use crate::csvfiles;

use common::builtin;
use csvfiles::{drop_columns, k4_text, located};
use formats::csv::{CsvError, MeasurementBlocks, Need, ReadOptions, read_csv};
use formats::paths::read_path;
use model_spec::Machine;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use simulation::record::Record;

const FILE: &str = "p.csv";

/// A record that was read: every number finite, every reading within the bound.
fn sound(r: &Record, o: &ReadOptions) -> Result<(), String> {
    for (i, s) in r.samples.iter().enumerate() {
        if !s.t.is_finite() || s.commands.iter().any(|c| !c.is_finite()) {
            return Err(format!("sample {i} is not finite: {s:?}"));
        }
    }
    for v in &r.measured {
        if v.iter().any(|x| x.abs() > o.max_reading_mm || x.is_nan()) {
            return Err(format!("reading {v:?} beyond the bound"));
        }
    }
    Ok(())
}

fn judged(what: &str, r: Result<Record, CsvError>, o: &ReadOptions) -> Result<bool, String> {
    match r {
        Ok(r) => sound(&r, o).map(|()| true),
        Err(e) => {
            let msg = e.to_string();
            if located(&msg, FILE) {
                Ok(false)
            } else {
                Err(format!("{what}: error without a location: {msg}"))
            }
        }
    }
}

/// Reads `bytes` with every reader; `Err` names a broken property.
fn every_reader(m: &Machine, bytes: &[u8], block: usize, o: &ReadOptions) -> Result<(), String> {
    let whole = judged("whole file", read_csv(FILE, bytes, m, Need::Measured, o), o)?;
    judged("path", read_path(FILE, bytes, m, o), o)?;
    let blocks = match MeasurementBlocks::new(FILE.into(), bytes, m, block, o) {
        Err(e) => judged("blocks", Err(e), o)?,
        Ok(blocks) => {
            let mut all = Record::default();
            let mut ok = true;
            for b in blocks {
                match b {
                    Ok(b) => {
                        all.samples.extend(b.samples);
                        all.measured.extend(b.measured);
                    }
                    Err(e) => ok = judged("blocks", Err(e), o)?,
                }
            }
            if ok {
                sound(&all, o)?;
            }
            ok
        }
    };
    if whole != blocks {
        return Err(format!(
            "the whole-file reader {} the file, the block reader {} it",
            if whole { "reads" } else { "refuses" },
            if blocks { "reads" } else { "refuses" }
        ));
    }
    Ok(())
}

/// Options with a short line bound, so that long lines are cheap to make.
fn options(short_lines: bool) -> ReadOptions {
    let mut o = ReadOptions::default();
    if short_lines {
        o.max_line_bytes = 300;
    }
    o
}

#[test]
fn random_bytes_never_panic_and_errors_are_located() {
    let m = builtin("seed-ac");
    // Bytes of any value, and bytes from the alphabet of the format (more of them get past the
    // header), with a header in front or not.
    let alphabet: Vec<u8> = b"0123456789,.-+eE\n\r# XYZACdxyz_umts\"".to_vec();
    let raw = proptest::collection::vec(any::<u8>(), 0..2048);
    let csvish = proptest::collection::vec(proptest::sample::select(alphabet), 0..2048);
    let input = (
        prop_oneof![raw, csvish],
        any::<bool>(),
        1usize..40,
        any::<bool>(),
    );
    let mut runner = TestRunner::new(Config {
        cases: 96,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&input, |(body, with_header, block, short)| {
            let mut bytes = Vec::new();
            if with_header {
                bytes.extend_from_slice(b"A,C,dx_um,dy_um,dz_um,t_s\n");
            }
            bytes.extend_from_slice(&body);
            every_reader(&m, &bytes, block, &options(short)).map_err(TestCaseError::fail)
        })
        .unwrap();
}

/// One kind of damage to a valid file; positions are fractions of the file or of its lines.
#[derive(Clone, Debug)]
enum Damage {
    FlipByte(f64, u8),
    DeleteLine(f64),
    DuplicateLine(f64),
    SwapLines(f64, f64),
    InsertNotUtf8(f64, Vec<u8>),
    InsertLongLine(f64, usize),
    ReplaceNumber(f64, f64, &'static str),
    RemoveField(f64, f64),
    CutEnd(f64),
}

const ODD_NUMBERS: [&str; 16] = [
    "1e308",
    "-1e308",
    "1e309",
    "-1e-400",
    "inf",
    "-infinity",
    "NaN",
    "nan",
    "1e99999999999999999999",
    "99999999999999999999999999999",
    "0x10",
    "",
    " ",
    "1,5",
    "1000.0001",
    "-180000",
];

fn damage() -> impl Strategy<Value = Damage> {
    let f = 0.0f64..1.0;
    prop_oneof![
        (f.clone(), 1u8..=255).prop_map(|(p, x)| Damage::FlipByte(p, x)),
        f.clone().prop_map(Damage::DeleteLine),
        f.clone().prop_map(Damage::DuplicateLine),
        (f.clone(), f.clone()).prop_map(|(a, b)| Damage::SwapLines(a, b)),
        (f.clone(), proptest::collection::vec(0x80u8..=0xff, 1..4))
            .prop_map(|(p, b)| Damage::InsertNotUtf8(p, b)),
        (f.clone(), 250usize..400).prop_map(|(p, n)| Damage::InsertLongLine(p, n)),
        (
            f.clone(),
            f.clone(),
            proptest::sample::select(&ODD_NUMBERS[..])
        )
            .prop_map(|(l, c, v)| Damage::ReplaceNumber(l, c, v)),
        (f.clone(), f.clone()).prop_map(|(l, c)| Damage::RemoveField(l, c)),
        f.prop_map(Damage::CutEnd),
    ]
}

fn at(p: f64, n: usize) -> usize {
    ((p * n as f64) as usize).min(n.saturating_sub(1))
}

fn apply(bytes: &mut Vec<u8>, d: &Damage) {
    let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let n = lines.len();
    let field_op = |line: &mut Vec<u8>, c: f64, with: Option<&str>| {
        let mut fields: Vec<Vec<u8>> = line.split(|&b| b == b',').map(<[u8]>::to_vec).collect();
        let k = at(c, fields.len());
        match with {
            Some(v) => fields[k] = v.as_bytes().to_vec(),
            None => {
                fields.remove(k);
            }
        }
        *line = fields.join(&b","[..]);
    };
    match d {
        Damage::FlipByte(p, x) => {
            if !bytes.is_empty() {
                let i = at(*p, bytes.len());
                bytes[i] ^= x;
            }
            return;
        }
        Damage::InsertNotUtf8(p, b) => {
            let i = at(*p, bytes.len() + 1);
            bytes.splice(i..i, b.iter().copied());
            return;
        }
        Damage::CutEnd(p) => {
            bytes.truncate(at(*p, bytes.len() + 1));
            return;
        }
        Damage::DeleteLine(p) => {
            lines.remove(at(*p, n));
        }
        Damage::DuplicateLine(p) => {
            let i = at(*p, n);
            lines.insert(i, lines[i].clone());
        }
        Damage::SwapLines(a, b) => lines.swap(at(*a, n), at(*b, n)),
        Damage::InsertLongLine(p, len) => {
            let line = format!("# {}", "9,".repeat(len / 2)).into_bytes();
            lines.insert(at(*p, n + 1), line);
        }
        Damage::ReplaceNumber(l, c, v) => field_op(&mut lines[at(*l, n)], *c, Some(v)),
        Damage::RemoveField(l, c) => field_op(&mut lines[at(*l, n)], *c, None),
    }
    *bytes = lines.join(&b"\n"[..]);
}

#[test]
fn damaged_files_never_panic_and_errors_are_located() {
    let m = builtin("seed-ac");
    // Valid files: the first 40 samples of simulated K4, with every column and with the rotary
    // columns only (linear axes filled by the inverse kinematics), and a short path file.
    let k4: String = k4_text(&m)
        .lines()
        .take(41)
        .map(|l| format!("{l}\n"))
        .collect();
    let rotary = drop_columns(&k4, &["X", "Y", "Z"]);
    let path = drop_columns(&k4, &["X", "Y", "Z", "dx_um", "dy_um", "dz_um"]);
    let o = options(true);
    for text in [&k4, &rotary] {
        assert!(read_csv(FILE, text.as_bytes(), &m, Need::Measured, &o).is_ok());
    }
    assert!(read_path(FILE, path.as_bytes(), &m, &o).is_ok());
    let bases = [k4.into_bytes(), rotary.into_bytes(), path.into_bytes()];
    let input = (
        0..bases.len(),
        proptest::collection::vec(damage(), 1..4),
        1usize..30,
        any::<bool>(),
    );
    let mut runner = TestRunner::new(Config {
        cases: 160,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&input, |(base, damages, block, short)| {
            let mut bytes = bases[base].clone();
            for d in &damages {
                apply(&mut bytes, d);
            }
            every_reader(&m, &bytes, block, &options(short)).map_err(TestCaseError::fail)
        })
        .unwrap();
}
