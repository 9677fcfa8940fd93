//! The golden corpus: every verb of the binary run on fixed inputs (`tests/golden/cases.txt`),
//! its exit code, standard output (timings stripped), standard error and every file it writes
//! compared byte for byte with `tests/golden/expected/`. It locks the outputs while the code
//! under them is reorganised; a deliberate change of an output is rewritten with
//! `RTEST_BLESS=1 cargo test --test all golden::` and reviewed in the diff like code.

use crate::common;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Text files up to this size are kept whole in `expected/files/`; larger or binary files are
/// kept as their size and digest.
const WHOLE_MAX_BYTES: usize = 64 * 1024;

/// File endings kept as text (every other file is compared by its digest).
const TEXT_ENDINGS: [&str; 10] = [
    "csv", "json", "toml", "rs", "md", "nc", "h", "txt", "tex", "lock",
];

/// Files whose bytes are not determined by the inputs: SQLite pages carry the library's own
/// bookkeeping. What they hold is compared through `rtest history`'s outputs instead.
const UNCOMPARED_ENDINGS: [&str; 1] = ["sqlite"];

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// One line of `cases.txt`: the case's name and its arguments.
struct Case {
    name: String,
    args: Vec<String>,
}

fn cases() -> Vec<Case> {
    let file = golden_dir().join("cases.txt");
    let text = std::fs::read_to_string(&file).expect("tests/golden/cases.txt");
    let mut out: Vec<Case> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let (name, args) = line
            .split_once(':')
            .unwrap_or_else(|| panic!("cases.txt:{}: no `NAME:`", i + 1));
        let name = name.trim().to_string();
        assert!(
            !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_'),
            "cases.txt:{}: a case name is letters, digits, - and _",
            i + 1
        );
        assert!(
            out.iter().all(|c| c.name != name),
            "cases.txt:{}: `{name}` twice",
            i + 1
        );
        let args = args.split_whitespace().map(str::to_string).collect();
        out.push(Case { name, args });
    }
    out
}

/// Replaces the durations the binary prints (`Done in 0.45 s`) by `<time>`.
fn strip_timings(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        match line.find("Done in ") {
            Some(at) => {
                let rest = &line[at + "Done in ".len()..];
                let digits = rest
                    .find(|c: char| !(c.is_ascii_digit() || c == '.'))
                    .unwrap_or(rest.len());
                out.push_str(&line[..at]);
                out.push_str("Done in <time>");
                out.push_str(&rest[digits..]);
            }
            None => out.push_str(line),
        }
    }
    out
}

/// Seconds since 1970 of the UTC time `YYYY-MM-DDTHH:MM:SSZ` at the start of `b`, if it is one.
fn utc_seconds(b: &[u8]) -> Option<i64> {
    const SHAPE: &[u8; 20] = b"dddd-dd-ddTdd:dd:ddZ";
    if b.len() < 20
        || !SHAPE.iter().zip(b).all(|(s, c)| {
            if *s == b'd' {
                c.is_ascii_digit()
            } else {
                s == c
            }
        })
    {
        return None;
    }
    let n = |r: std::ops::Range<usize>| b[r].iter().fold(0i64, |a, c| a * 10 + i64::from(c - b'0'));
    let (y, m, d) = (n(0..4), n(5..7), n(8..10));
    // Days from the civil date (proleptic Gregorian), as in Howard Hinnant's algorithm.
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * ((m + 9) % 12) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days * 86_400 + n(11..13) * 3600 + n(14..16) * 60 + n(17..19))
}

/// Replaces every UTC time within `run` (seconds since 1970, the corpus's start and end, a
/// second of slack each side) by `<now>`: file modification and recording times depend on
/// when the corpus ran, not on its inputs. Fixed times (a `--measured-at`) are kept.
fn strip_run_times(bytes: &[u8], run: (i64, i64)) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match utc_seconds(&bytes[i..]) {
            Some(t) if t >= run.0 - 1 && t <= run.1 + 1 => {
                out.extend_from_slice(b"<now>");
                i += 20;
            }
            _ => {
                out.push(bytes[i]);
                i += 1;
            }
        }
    }
    out
}

/// Now, in seconds since 1970.
fn now_seconds() -> i64 {
    let d = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .expect("a clock after 1970");
    i64::try_from(d.as_secs()).expect("seconds in i64")
}

/// What one case printed, as stored in `expected/NAME.out`.
fn run_case(dir: &Path, case: &Case) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_rtest"))
        .args(&case.args)
        .current_dir(dir)
        .output()
        .expect("the rtest binary runs");
    let stdout = String::from_utf8(out.stdout).expect("utf-8 stdout");
    let stderr = String::from_utf8(out.stderr).expect("utf-8 stderr");
    assert!(!stderr.contains("panicked"), "{}: {stderr}", case.name);
    let mut s = format!(
        "rtest {}\nexit: {:?}\n--- stdout\n",
        case.args.join(" "),
        out.status.code()
    );
    s.push_str(&strip_timings(&stdout));
    s.push_str("--- stderr\n");
    s.push_str(&stderr);
    s
}

/// FNV-1a, 64 bits: a digest to tell two files apart, not a cryptographic one.
fn fnv64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Every file below `dir`, relative paths with `/`, sorted.
fn files_below(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).expect("read_dir") {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                out.insert(rel, std::fs::read(&p).expect("read"));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

fn ending(path: &str) -> &str {
    path.rsplit_once('.').map_or("", |(_, e)| e)
}

/// Splits the scratch directory's files into those kept whole and the digests of the others.
fn outputs(dir: &Path, run: (i64, i64)) -> (BTreeMap<String, Vec<u8>>, String) {
    let inputs = files_below(&golden_dir().join("inputs"));
    let mut whole = BTreeMap::new();
    let mut digests = String::new();
    for (path, bytes) in files_below(dir) {
        if inputs.get(&path) == Some(&bytes) || UNCOMPARED_ENDINGS.contains(&ending(&path)) {
            continue;
        }
        let bytes = strip_run_times(&bytes, run);
        let text = TEXT_ENDINGS.contains(&ending(&path)) && std::str::from_utf8(&bytes).is_ok();
        if text && bytes.len() <= WHOLE_MAX_BYTES {
            whole.insert(path, bytes);
        } else {
            writeln!(digests, "{path} {} {:016x}", bytes.len(), fnv64(&bytes)).unwrap();
        }
    }
    (whole, digests)
}

fn copy_inputs(to: &Path) {
    for (path, bytes) in files_below(&golden_dir().join("inputs")) {
        std::fs::write(to.join(path), bytes).expect("copy an input");
    }
}

/// Writes `expected/` anew from this run.
fn bless(outs: &[(String, String)], whole: &BTreeMap<String, Vec<u8>>, digests: &str) {
    let expected = golden_dir().join("expected");
    let _ = std::fs::remove_dir_all(&expected);
    std::fs::create_dir_all(expected.join("files")).unwrap();
    for (name, text) in outs {
        std::fs::write(expected.join(format!("{name}.out")), text).unwrap();
    }
    for (path, bytes) in whole {
        let p = expected.join("files").join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    std::fs::write(expected.join("digests.txt"), digests).unwrap();
}

/// The first line where `a` and `b` differ, for the failure message.
fn first_difference(a: &str, b: &str) -> String {
    let (la, lb): (Vec<_>, Vec<_>) = (a.lines().collect(), b.lines().collect());
    for i in 0..la.len().max(lb.len()) {
        let (x, y) = (la.get(i), lb.get(i));
        if x != y {
            return format!(
                "line {}:\n  expected: {}\n  now:      {}",
                i + 1,
                x.unwrap_or(&"<none>"),
                y.unwrap_or(&"<none>")
            );
        }
    }
    "the same lines, other line endings".into()
}

#[test]
fn every_verb_writes_what_it_wrote_before() {
    let dir = common::temp_dir_tagged("golden", "corpus");
    let start = now_seconds();
    copy_inputs(&dir);
    let cases = cases();
    let outs: Vec<(String, String)> = cases
        .iter()
        .map(|c| (c.name.clone(), run_case(&dir, c)))
        .collect();
    let run = (start, now_seconds());
    let outs: Vec<(String, String)> = outs
        .into_iter()
        .map(|(n, o)| {
            let o = String::from_utf8(strip_run_times(o.as_bytes(), run)).expect("utf-8");
            (n, o)
        })
        .collect();
    let (whole, digests) = outputs(&dir, run);
    if std::env::var_os("RTEST_BLESS").is_some() {
        bless(&outs, &whole, &digests);
        return;
    }
    let expected = golden_dir().join("expected");
    let mut failures = Vec::new();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    for (name, now) in &outs {
        let was = read(&expected.join(format!("{name}.out")));
        if &was != now {
            failures.push(format!("case {name}: {}", first_difference(&was, now)));
        }
    }
    let expected_files = files_below(&expected.join("files"));
    for (path, bytes) in &whole {
        match expected_files.get(path) {
            None => failures.push(format!("{path}: a new output")),
            Some(b) if b != bytes => failures.push(format!(
                "{path}: {}",
                first_difference(&String::from_utf8_lossy(b), &String::from_utf8_lossy(bytes))
            )),
            Some(_) => {}
        }
    }
    for path in expected_files.keys() {
        if !whole.contains_key(path) {
            failures.push(format!("{path}: no longer written"));
        }
    }
    let was = read(&expected.join("digests.txt"));
    if was != digests {
        failures.push(format!("digests.txt: {}", first_difference(&was, &digests)));
    }
    assert!(
        failures.is_empty(),
        "{} outputs differ from tests/golden/expected (RTEST_BLESS=1 rewrites them after a \
         deliberate change):\n{}",
        failures.len(),
        failures.join("\n")
    );
}
