//! Fuzzing of the readers of campaign files and report JSONs (proptest at scale): valid files
//! with random damage, and random text, never panic; a file that reads is sound (counts and
//! lengths within their limits, every number finite), and a file that does not is refused with
//! a message that names it (and, for a campaign file, a line and column inside the text).
//!
//! The default run takes `fuzzing::CASES` cases per property; `RTEST_FUZZ_CASES=100000 cargo test
//! --test readers_fuzz` runs the documented fuzzing pass (docs/conventions.md §9, "Fuzzing the
//! readers"). Inputs are bounded (a few hundred kB at most), so memory is too.

use crate::common;
use crate::support::fuzz as fuzzing;

use common::{ok, temp_dir_tagged, words};
use formats::campaign::{CampaignFileError, parse_campaign};
use fuzzing::fuzz;
use model_spec::Machine;
use proptest::prelude::*;
use simulation::campaign::{MAX_LABEL_CHARS, MAX_RECORDS};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::sync::OnceLock;

/// Text-level damage to a valid file; positions are fractions of the text or of its lines.
#[derive(Clone, Debug)]
enum Damage {
    /// Replace the byte at a position by a character.
    Flip(f64, char),
    /// Delete a range of bytes (start, length in bytes).
    Delete(f64, usize),
    /// Duplicate a line.
    DuplicateLine(f64),
    /// Swap two lines.
    SwapLines(f64, f64),
    /// Insert a token at a position.
    Insert(f64, String),
    /// Replace the n-th number (fraction of the numbers) by an odd one.
    Number(f64, &'static str),
    /// Replace the n-th quoted string's content.
    Str(f64, String),
    /// Cut the end off.
    Cut(f64),
}

const ODD_NUMBERS: [&str; 18] = [
    "1e308",
    "-1e308",
    "1e309",
    "-1e-400",
    "inf",
    "-inf",
    "nan",
    "NaN",
    "1e99999999999999999999",
    "99999999999999999999999999999",
    "0x10",
    "0b11",
    "-0",
    "\"12\"",
    "true",
    "[]",
    "{}",
    "1_000",
];

/// Tokens that mean something to TOML or JSON, and text that readers must refuse or bound.
fn tokens() -> Vec<String> {
    let mut t: Vec<String> = [
        "[[record]]\n",
        "[record]\n",
        "\n[[record]]\nfile = \"k4.csv\"\n",
        "\"",
        "'",
        "\"\"\"",
        "'''",
        "=",
        "{",
        "}",
        "[",
        "]",
        ",",
        ":",
        "#",
        "\n",
        "\r",
        "\t",
        "\\",
        "\\u0000",
        "\u{0}",
        "\u{202e}",
        "\u{feff}",
        "é",
        "params = { Zw = 1e308 }\n",
        "start = nan\n",
        "label = \"\"\n",
        "zeroed = 1\n",
        "machine = \"other\"\n",
        "null",
        "\"version\": 99,",
        "\"kind\": \"diagnosis\",",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    t.push(format!("label = \"{}\"\n", "a".repeat(MAX_LABEL_CHARS + 1)));
    t.push("[".repeat(300));
    t.push("{\"a\":".repeat(200));
    t
}

fn damage() -> impl Strategy<Value = Damage> {
    let f = 0.0f64..1.0;
    let chars = prop_oneof![
        any::<char>(),
        proptest::sample::select(vec![
            '"', '\'', '=', '[', ']', '{', '}', ',', '\n', '#', '.', '-', 'e', '0'
        ]),
    ];
    let strings = prop_oneof![
        Just(String::new()),
        Just("a".repeat(MAX_LABEL_CHARS + 1)),
        Just("x\u{202e}y".to_string()),
        Just("../../etc/passwd".to_string()),
        Just("/dev/zero".to_string()),
        Just("line\nbreak".to_string()),
        "[a-zA-Z0-9_.+-]{0,40}",
        any::<String>(),
    ];
    prop_oneof![
        (f.clone(), chars).prop_map(|(p, c)| Damage::Flip(p, c)),
        (f.clone(), 1usize..200).prop_map(|(p, n)| Damage::Delete(p, n)),
        f.clone().prop_map(Damage::DuplicateLine),
        (f.clone(), f.clone()).prop_map(|(a, b)| Damage::SwapLines(a, b)),
        (f.clone(), proptest::sample::select(tokens())).prop_map(|(p, t)| Damage::Insert(p, t)),
        (f.clone(), proptest::sample::select(&ODD_NUMBERS[..]))
            .prop_map(|(p, v)| Damage::Number(p, v)),
        (f.clone(), strings).prop_map(|(p, s)| Damage::Str(p, s)),
        f.prop_map(Damage::Cut),
    ]
}

/// The char boundary at or before fraction `p` of `text`.
fn boundary(text: &str, p: f64) -> usize {
    let mut i = ((p * text.len() as f64) as usize).min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Byte ranges of the numbers of `text` (digits with an optional sign, point and exponent).
fn numbers(text: &str) -> Vec<std::ops::Range<usize>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit());
        if starts && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) {
            let s = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b"+-.eE".contains(&b[i])) {
                i += 1;
            }
            out.push(s..i);
        } else {
            i += 1;
        }
    }
    out
}

/// Byte ranges of the contents of the double-quoted strings of `text`.
fn strings(text: &str) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut open: Option<usize> = None;
    let mut escaped = false;
    for (i, c) in text.char_indices() {
        match (open, c) {
            (Some(_), '\\') if !escaped => escaped = true,
            (Some(s), '"') if !escaped => {
                out.push(s..i);
                open = None;
            }
            (None, '"') => open = Some(i + 1),
            _ => escaped = false,
        }
    }
    out
}

fn apply(text: &str, d: &Damage) -> String {
    let mut lines: Vec<&str> = text.split('\n').collect();
    let line = |p: f64| ((p * lines.len() as f64) as usize).min(lines.len() - 1);
    let pick = |p: f64, n: usize| ((p * n as f64) as usize).min(n - 1);
    match d {
        Damage::Flip(p, c) => {
            let i = boundary(text, *p);
            let end = text[i..].chars().next().map_or(i, |x| i + x.len_utf8());
            format!("{}{c}{}", &text[..i], &text[end..])
        }
        Damage::Delete(p, n) => {
            let i = boundary(text, *p);
            let mut j = (i + n).min(text.len());
            while !text.is_char_boundary(j) {
                j += 1;
            }
            format!("{}{}", &text[..i], &text[j..])
        }
        Damage::DuplicateLine(p) => {
            let k = line(*p);
            lines.insert(k, lines[k]);
            lines.join("\n")
        }
        Damage::SwapLines(a, b) => {
            let (a, b) = (line(*a), line(*b));
            lines.swap(a, b);
            lines.join("\n")
        }
        Damage::Insert(p, t) => {
            let i = boundary(text, *p);
            format!("{}{t}{}", &text[..i], &text[i..])
        }
        Damage::Number(p, v) => {
            let n = numbers(text);
            if n.is_empty() {
                return text.to_string();
            }
            let r = n[pick(*p, n.len())].clone();
            format!("{}{v}{}", &text[..r.start], &text[r.end..])
        }
        Damage::Str(p, s) => {
            let n = strings(text);
            if n.is_empty() {
                return text.to_string();
            }
            let r = n[pick(*p, n.len())].clone();
            let escaped = s.replace('\\', "\\\\").replace('"', "\\\"");
            format!("{}{escaped}{}", &text[..r.start], &text[r.end..])
        }
        Damage::Cut(p) => text[..boundary(text, *p)].to_string(),
    }
}

/// The first run of more than 24 digits in `message` that `input` does not hold: a number
/// printed in full (messages print at most six significant digits).
fn long_number<'a>(message: &'a str, input: &str) -> Option<&'a str> {
    message
        .split(|c: char| !c.is_ascii_digit())
        .find(|run| run.len() > 24 && !input.contains(*run))
}

/// Runs `f`, failing the case when it panics.
fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> Result<T, TestCaseError> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|_| TestCaseError::fail(format!("{what} panicked")))
}

// ---------------------------------------------------------------------------------------------
// Campaign files.

const CAMPAIGN: &str = "c.toml";

fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// Valid campaign files: one record, several with parameters, zeroing and starts, shared
/// set-ups, many records.
fn campaigns() -> Vec<String> {
    let mut many = String::from("machine = \"seed-ac\"\n");
    for k in 0..40 {
        many += &format!(
            "\n[[record]]\nfile = \"r{k}.csv\"\nsetup = \"s{}\"\n",
            k % 3
        );
    }
    vec![
        "[[record]]\nfile = \"k4.csv\"\n".to_string(),
        concat!(
            "machine = \"seed-ac\"\n",
            "description = \"two ball heights\"  # low and high\n",
            "\n[[record]]\nfile = \"k4-low.csv\"\nlabel = \"k4-low\"\nsetup = \"low\"\n",
            "params = { Zw = 211.537 }\nzeroed = true\nstart = 0.0\n",
            "\n[[record]]\nfile = \"k1-low.csv\"\nlabel = \"k1-low\"\nsetup = \"low\"\n",
            "params = { Zw = 211.537 }\nzeroed = true\nstart = 600.5\n",
            "\n[[record]]\nfile = \"sub/k4-high.csv\"\nsetup = \"high\"\n",
            "params = { Zw = 311.537, Xw = -20 }\nstart = 1300\n",
        )
        .to_string(),
        many,
    ]
}

/// The properties of one campaign text: no panic; read → sound; refused → located inside it.
/// `Ok(true)` when the text was read.
fn check_campaign(m: &Machine, text: &str) -> Result<bool, TestCaseError> {
    let result = no_panic("parse_campaign", || {
        parse_campaign(CAMPAIGN, text, Path::new("dir"), m)
    })?;
    let fail = |why: String| Err(TestCaseError::fail(format!("{why}\n--- text:\n{text}")));
    match result {
        Ok(c) => {
            if c.records.is_empty() || c.records.len() > MAX_RECORDS {
                return fail(format!("read with {} records", c.records.len()));
            }
            for r in &c.records {
                let long = |s: &str| s.chars().count() > MAX_LABEL_CHARS;
                if long(&r.label) || long(&r.setup) || r.label.is_empty() {
                    return fail(format!("label `{}` or set-up `{}`", r.label, r.setup));
                }
                if r.params.iter().any(|x| !x.is_finite())
                    || r.start_s.is_some_and(|s| !s.is_finite())
                {
                    return fail(format!("a number that is not finite: {r:?}"));
                }
            }
            Ok(true)
        }
        Err(CampaignFileError::Invalid {
            file,
            line,
            column,
            message,
        }) => {
            let lines: Vec<&str> = text.split('\n').collect();
            if file != CAMPAIGN || message.is_empty() {
                return fail(format!("file `{file}`, message `{message}`"));
            }
            if line < 1 || line > lines.len() {
                return fail(format!(
                    "line {line} outside 1..={} ({message})",
                    lines.len()
                ));
            }
            let width = lines[line - 1].chars().count();
            if column < 1 || column > width + 1 {
                return fail(format!(
                    "column {column} outside 1..={} of line {line} ({message})",
                    width + 1
                ));
            }
            if message.chars().count() > 2000 {
                return fail(format!(
                    "a message of {} characters",
                    message.chars().count()
                ));
            }
            if let Some(run) = long_number(&message, text) {
                return fail(format!(
                    "a number printed with {} digits: {message}",
                    run.len()
                ));
            }
            Ok(false)
        }
        Err(CampaignFileError::Campaign { file, .. }) if file == CAMPAIGN => Ok(false),
        Err(e) => fail(format!("an error that names no place in the file: {e}")),
    }
}

#[test]
fn damaged_campaign_files_read_soundly_or_are_refused_at_a_place() {
    let m = seed_ac();
    let bases = campaigns();
    let input = (0..bases.len(), proptest::collection::vec(damage(), 1..6));
    let check = |(base, damages): (usize, Vec<Damage>)| {
        let mut text = bases[base].clone();
        for d in &damages {
            text = apply(&text, d);
        }
        check_campaign(&m, &text)
    };
    fuzz("damaged campaign files", &input, check, true);
}

#[test]
fn random_text_as_a_campaign_file_never_panics() {
    let m = seed_ac();
    let alphabet: Vec<char> =
        "[]{}=\"',.#\n\r\t -+0123456789eEabcdefghijklmnopqrstuvwxyzZXw_é\u{202e}"
            .chars()
            .collect();
    let tomlish = proptest::collection::vec(proptest::sample::select(alphabet), 0..800)
        .prop_map(|v| v.into_iter().collect::<String>());
    let input = prop_oneof![any::<String>(), tomlish];
    fuzz(
        "random campaign text",
        &input,
        |text| check_campaign(&m, &text),
        false,
    );
}

#[test]
fn a_campaign_of_more_records_than_the_limit_is_refused_at_the_first_one_too_many() {
    let m = seed_ac();
    let mut text = String::new();
    for k in 0..=MAX_RECORDS {
        text += &format!("[[record]]\nfile = \"r{k}.csv\"\n");
    }
    let e = parse_campaign(CAMPAIGN, &text, Path::new("dir"), &m).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains(&format!("{}", MAX_RECORDS)) && message.starts_with("c.toml:"),
        "{message}"
    );
}

// ---------------------------------------------------------------------------------------------
// Report JSONs.

/// The JSON reports of every kind, written by the verbs once per test run: (name, text).
fn reports() -> &'static [(String, String)] {
    static REPORTS: OnceLock<Vec<(String, String)>> = OnceLock::new();
    REPORTS.get_or_init(|| {
        let d = temp_dir_tagged("fuzz", "reports");
        for (test, seed) in [("K4", "1"), ("K1", "2")] {
            ok(
                &d,
                &words(&format!(
                    "simulate --machine seed-ac --truth seed-ac-reduced --path {test} --noise-um 0.3 --seed {seed} -o {}.csv",
                    test.to_lowercase()
                )),
            );
        }
        let id = "identify --machine seed-ac --model reduced";
        ok(&d, &words(&format!("{id} --data k4.csv --json id.json")));
        ok(&d, &words(&format!("{id} --data k4.csv,k1.csv --json campaign.json")));
        ok(
            &d,
            &words("validate --machine seed-ac --params id.json --data k1.csv --json val.json"),
        );
        ok(
            &d,
            &words("diagnose --machine seed-ac --model reduced --data k4.csv --validate k1.csv --json diag.json"),
        );
        ok(
            &d,
            &words("compensate --machine seed-ac --params id.json --path k1.csv -o k1c.csv --json comp.json"),
        );
        ["id", "campaign", "val", "diag", "comp"]
            .iter()
            .map(|n| {
                let name = format!("{n}.json");
                let text = std::fs::read_to_string(d.join(&name)).unwrap();
                (name, text)
            })
            .collect()
    })
}

/// The properties of one report text: no panic; refused → the message names the file.
/// `Ok(true)` when the text was read.
fn check_report(text: &str) -> Result<bool, TestCaseError> {
    let result = no_panic("classify", || report::inputs::classify("r.json", text))?;
    match result {
        Ok(doc) => {
            if doc.machine().is_empty() {
                return Err(TestCaseError::fail(format!(
                    "a {} report of no machine was read",
                    doc.kind()
                )));
            }
            Ok(true)
        }
        Err(e) => {
            let message = e.to_string();
            if !message.starts_with("r.json")
                || message.chars().count() > 4000
                || long_number(&message, text).is_some()
            {
                return Err(TestCaseError::fail(format!(
                    "a message that does not start with the file, is too long or prints a long number: {message}"
                )));
            }
            Ok(false)
        }
    }
}

#[test]
fn every_kind_of_report_reads_back() {
    for (name, text) in reports() {
        let doc = report::inputs::classify(name, text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.machine(), "seed-ac", "{name}");
    }
}

#[test]
fn damaged_report_jsons_are_read_or_refused_naming_the_file() {
    let bases = reports();
    let input = (0..bases.len(), proptest::collection::vec(damage(), 1..6));
    let check = |(base, damages): (usize, Vec<Damage>)| {
        let mut text = bases[base].1.clone();
        for d in &damages {
            text = apply(&text, d);
        }
        check_report(&text)
    };
    fuzz("damaged report JSONs", &input, check, true);
}

#[test]
fn random_text_as_a_report_json_never_panics() {
    let alphabet: Vec<char> = "{}[]:,\"\\ \n0123456789.-+eEtruefalsnmachiderpotvky_"
        .chars()
        .collect();
    let jsonish = proptest::collection::vec(proptest::sample::select(alphabet), 0..800)
        .prop_map(|v| v.into_iter().collect::<String>());
    let input = prop_oneof![any::<String>(), jsonish];
    fuzz(
        "random report text",
        &input,
        |text| check_report(&text),
        false,
    );
}

#[test]
fn what_the_fuzzing_found_stays_refused() {
    let m = seed_ac();
    let long = "a".repeat(MAX_LABEL_CHARS + 1);
    let e = parse_campaign(
        CAMPAIGN,
        &format!("[[record]]\nfile = \"{long}.csv\"\n"),
        Path::new("dir"),
        &m,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("c.toml:2:8: `file`: the label made from its name `aaaaaaaaaaaaaaaa…` has 257 characters, more than 256")
            && e.ends_with("give the record a `label`"),
        "{e}"
    );
    let e = parse_campaign(
        CAMPAIGN,
        "[[record]]\nfile = \"k4.csv\"\nstart = 1e308\n",
        Path::new("dir"),
        &m,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "c.toml:3:9: `start`: 1e308 s is beyond ±1e9 s (about 30 years)"
    );
    let (name, text) = &reports()[2];
    let empty = text.replacen("\"machine\": \"seed-ac\"", "\"machine\": \"\"", 1);
    assert_ne!(&empty, text, "{name}");
    let e = report::inputs::classify("r.json", &empty)
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "r.json: validation report: field `machine` is empty: a report names the machine it is of"
    );
}
