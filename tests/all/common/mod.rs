//! What the end-to-end tests of the `rtest` binary share: running it, reading its output,
//! checking a failure (exit code, one stderr line naming the flag, nothing on stdout, no panic),
//! temporary directories and their contents.

#![allow(dead_code)]

pub mod gains;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the binary with `args`, in `dir` when given.
pub fn run(dir: Option<&Path>, args: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtest"));
    c.args(args);
    if let Some(d) = dir {
        c.current_dir(d);
    }
    c.output().expect("the rtest binary runs")
}

/// Standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("utf-8 stdout")
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("utf-8 stderr")
}

/// Asserts that `o` (the run of `args`) failed with `code`, an empty stdout and one stderr line
/// starting with `rtest: error: ` that contains every string of `needles`; returns that line.
pub fn check_fails(o: &Output, args: &[&str], code: i32, needles: &[&str]) -> String {
    let err = stderr(o);
    assert_eq!(
        o.status.code(),
        Some(code),
        "rtest {args:?}: exit code; stderr: {err}"
    );
    assert!(!err.contains("panicked"), "rtest {args:?} panicked: {err}");
    assert!(
        o.stdout.is_empty(),
        "rtest {args:?}: stdout not empty: {}",
        stdout(o)
    );
    assert_eq!(
        err.lines().count(),
        1,
        "rtest {args:?}: not one line: {err}"
    );
    assert!(err.starts_with("rtest: error: "), "rtest {args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "rtest {args:?}: `{n}` not in: {err}");
    }
    err
}

/// A fresh, empty temporary directory for one test, removed when dropped.
pub struct TempDir(pub PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A fresh temporary directory named after the test file (`tag`) and the test (`name`).
pub fn temp_dir_tagged(tag: &str, name: &str) -> TempDir {
    let (pid, n) = (std::process::id(), next_scratch_number());
    let d = std::env::temp_dir().join(format!("rtest-{tag}-{pid}-{n}-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    TempDir(d)
}

/// The names of the entries of `dir`, sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A JSON file, parsed.
pub fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: not JSON: {e}", path.display()))
}

/// Runs `args` in `dir`, asserts success, returns stdout.
pub fn ok(dir: &Path, args: &[&str]) -> String {
    ok_in(Some(dir), args)
}

/// Runs `args` in the test's working directory, asserts success, returns stdout.
pub fn ok_here(args: &[&str]) -> String {
    ok_in(None, args)
}

/// The standard output of `args` (run in the test's working directory), read as JSON.
pub fn json_here(args: &[&str]) -> Value {
    let out = ok_here(args);
    serde_json::from_str(&out).unwrap_or_else(|e| panic!("rtest {args:?}: not JSON ({e}):\n{out}"))
}

/// The built-in seed machine's TOML, copied into `dir` as `my-seed.toml`.
pub fn seed_file(dir: &Path) -> std::path::PathBuf {
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "seed-ac")
        .expect("seed-ac is built in")
        .1;
    let path = dir.join("my-seed.toml");
    std::fs::write(&path, text).expect("write machine file");
    path
}

/// A JSON array of three numbers.
pub fn triple(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    assert_eq!(a.len(), 3, "{v}");
    std::array::from_fn(|k| a[k].as_f64().expect("number"))
}

fn ok_in(dir: Option<&Path>, args: &[&str]) -> String {
    let o = run(dir, args);
    assert!(
        o.status.success(),
        "rtest {args:?} failed ({:?}): {}",
        o.status.code(),
        stderr(&o)
    );
    stdout(&o)
}

/// Runs `args` in `dir` and checks the failure (see [`check_fails`]).
pub fn fails(dir: &Path, args: &[&str], code: i32, needles: &[&str]) -> String {
    check_fails(&run(Some(dir), args), args, code, needles)
}

/// The words of a command line written as one string (`"identify --machine seed-ac"`); for
/// arguments without spaces.
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// A number no other scratch directory of this process has taken: the tests of a crate run in
/// one process, in parallel, so the process id alone does not tell two of them apart.
fn next_scratch_number() -> usize {
    static NEXT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// A fresh temporary directory for the test `name` (numbered, so that tests with the same name
/// in different files do not meet), removed when dropped.
pub fn temp_dir(name: &str) -> TempDir {
    temp_dir_tagged("cli", name)
}

/// A fresh directory (`tag`, `name`) with `k4.csv` (K4 on seed-ac, the demo truth) and `id.json`
/// (its identification with the reduced model, plus the terms `terms` when given, as `--terms`
/// spells them).
pub fn seed_ac_identified(tag: &str, name: &str, terms: Option<&str>) -> TempDir {
    let dir = temp_dir_tagged(tag, name);
    ok(
        &dir,
        &words("simulate --machine seed-ac --path K4 --truth seed-ac-demo -o k4.csv"),
    );
    let mut identify =
        words("identify --machine seed-ac --model reduced --data k4.csv --json id.json");
    if let Some(t) = terms {
        identify.extend(["--terms", t]);
    }
    ok(&dir, &identify);
    dir
}

/// The parameter `name` of a report's JSON (`parameters[].name`).
pub fn param<'a>(json: &'a Value, name: &str) -> &'a Value {
    json["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no parameter {name} in {json}"))
}

/// A JSON number as `f64`.
pub fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// Makes a FIFO at `path` (inside a test's temporary directory).
pub fn mkfifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
}
