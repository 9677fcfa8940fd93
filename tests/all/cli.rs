//! End-to-end tests of the `rtest` command line: every verb's happy path with real content,
//! and every kind of bad input (message on one stderr line naming the flag and the item, exit
//! code 2 for usage errors and 1 for other failures, no panic, no output file left behind).

use std::path::Path;
use std::process::Output;

use crate::common::{self, temp_dir};
use common::{entries, json_here as json, ok_here as ok, seed_file, stderr, triple};

fn rtest_in(dir: Option<&Path>, args: &[&str]) -> Output {
    common::run(dir, args)
}

fn fails(args: &[&str], code: i32, needles: &[&str]) -> String {
    fails_in(None, args, code, needles)
}

fn fails_in(dir: Option<&Path>, args: &[&str], code: i32, needles: &[&str]) -> String {
    common::check_fails(&rtest_in(dir, args), args, code, needles)
}

fn rtest(args: &[&str]) -> Output {
    rtest_in(None, args)
}

/// Keys of a JSON object in the order they appear in the text.
fn key_order(text: &str, keys: &[&str]) -> Vec<usize> {
    keys.iter()
        .map(|k| {
            text.find(&format!("\"{k}\""))
                .unwrap_or_else(|| panic!("{k} missing"))
        })
        .collect()
}

// ---------------------------------------------------------------- machines

#[test]
fn machines_lists_every_builtin_with_axes_symbols_errors_and_models() {
    let out = ok(&["machines"]);
    for name in ["seed-ac:", "seed-3axis:", "head-table-bc:"] {
        assert!(out.contains(name), "{name} missing:\n{out}");
    }
    assert!(
        out.contains("work chain: bed -> X -> A -> C -> ball"),
        "{out}"
    );
    assert!(
        out.contains("tool chain: bed -> Y -> Z -> holder -> probe"),
        "{out}"
    );
    let x = out
        .lines()
        .find(|l| l.trim_start().starts_with("X   linear"))
        .expect("X axis line");
    assert!(
        x.contains("+x") && x.contains("-500 .. 500 mm") && x.contains("work chain"),
        "{x}"
    );
    let a = out
        .lines()
        .find(|l| l.trim_start().starts_with("A   rotary"))
        .expect("A axis line");
    assert!(a.contains("-120 .. 120 deg"), "{a}");
    assert!(
        out.contains("Xw = -217.504") && out.contains("Zp = 184.67"),
        "{out}"
    );
    assert!(
        out.contains("errors (44 of the 44 of its topology"),
        "{out}"
    );
    assert!(out.contains("COX AOZ BOZ XOW YOW ZOW"), "{out}");
    assert!(out.contains("reduced (11 errors)"), "{out}");
    assert!(
        out.contains("XOW YOW ZOW YOA ZOA BOA COA XOC YOC AOC BOC"),
        "{out}"
    );
}

#[test]
fn machines_describes_a_machine_file() {
    let dir = temp_dir("machines-file");
    let file = seed_file(&dir);
    let from_file = ok(&["machines", "--machine", file.to_str().unwrap()]);
    let builtin = ok(&["machines", "--machine", "seed-ac"]);
    assert_eq!(from_file, builtin);
    assert!(!builtin.contains("seed-3axis"));
}

// ---------------------------------------------------------------- gains, symbolic

#[test]
fn gains_symbolic_text_markdown_latex() {
    let text = ok(&["gains", "--machine", "seed-ac", "--model", "reduced"]);
    assert!(
        text.starts_with("Error gains of seed-ac, model reduced (11 errors)"),
        "{text}"
    );
    let boa = text.lines().find(|l| l.contains(" BOA ")).expect("BOA row");
    assert!(boa.contains("Sa*Sc*Xw") && boa.contains("-Ca"), "{boa}");
    let md = ok(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--format",
        "markdown",
    ]);
    assert!(
        md.lines().any(|l| l.starts_with('|') && l.contains("XOC")),
        "{md}"
    );
    let tex = ok(&["gains", "--machine", "seed-ac", "--format", "latex"]);
    assert!(
        tex.contains("\\begin{longtable}") && tex.contains("EXX"),
        "{tex}"
    );
    // The default model is `full`.
    let full = ok(&["gains", "--machine", "seed-ac"]);
    assert!(
        full.starts_with("Error gains of seed-ac, model full (44 errors)"),
        "{full}"
    );
}

#[test]
fn gains_symbolic_json() {
    let args = [
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--format",
        "json",
    ];
    let v = json(&args);
    assert_eq!(v["machine"], "seed-ac");
    assert_eq!(v["model"], "reduced");
    assert!(v["atoms"]["Sa"].as_str().unwrap().contains("A command"));
    assert!(v["atoms"]["Xw"].as_str().unwrap().contains("-217.504"));
    let gains = v["gains"].as_object().unwrap();
    assert_eq!(gains.len(), 11);
    assert_eq!(
        v["gains"]["XOC"],
        serde_json::json!(["-1", "0", "0", "0", "0", "0"])
    );
    let boa: Vec<&str> = v["gains"]["BOA"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert_eq!(boa.len(), 6);
    assert!(boa[0].contains("Sa*Sc*Xw") && boa[1] == "0", "{boa:?}");
    // Errors keep the model's order.
    let text = ok(&args);
    let order = key_order(&text, &["XOW", "YOA", "BOA", "XOC", "BOC"]);
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{text}");
}

#[test]
fn gains_errors_list_keeps_order_and_accepts_digit_zero() {
    let args = [
        "gains",
        "--machine",
        "seed-ac",
        "--errors",
        "boa,X0C",
        "--format",
        "json",
    ];
    let v = json(&args);
    assert_eq!(v["model"], serde_json::Value::Null);
    let gains = v["gains"].as_object().unwrap();
    assert_eq!(gains.len(), 2);
    assert_eq!(v["gains"]["XOC"][0], "-1");
    let text = ok(&args);
    let order = key_order(&text, &["BOA", "XOC"]);
    assert!(order[0] < order[1], "{text}");
}

// ---------------------------------------------------------------- generate

#[test]
fn generate_writes_a_rust_file() {
    let dir = temp_dir("generate");
    let out = dir.join("seed.rs");
    let o = rtest(&[
        "generate",
        "--machine",
        "seed-ac",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    let code = std::fs::read_to_string(&out).unwrap();
    assert!(code.contains("pub fn gains"), "{code}");
    assert!(!code.contains("#!["), "no crate attributes");
    assert!(code.contains("pub mod full") && code.contains("pub mod reduced"));
    assert_eq!(entries(&dir), ["seed.rs"], "no temporary file left");
    // Standard output gives the same code.
    assert_eq!(ok(&["generate", "--machine", "seed-ac"]), code);
    // One model only; a machine file works too.
    let file = seed_file(&dir);
    let only = ok(&[
        "generate",
        "--machine",
        file.to_str().unwrap(),
        "--model",
        "reduced",
    ]);
    assert!(only.contains("pub mod reduced") && !only.contains("pub mod full"));
    assert!(only.contains("pub fn gains"));
    // An existing file is replaced.
    std::fs::write(&out, "old").unwrap();
    assert!(
        rtest(&[
            "generate",
            "--machine",
            "seed-ac",
            "-o",
            out.to_str().unwrap()
        ])
        .status
        .success()
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), code);
}

// ---------------------------------------------------------------- demo
#[test]
fn every_verb_documents_units_and_exit_codes() {
    for verb in ["machines", "gains", "generate", "demo"] {
        let help = ok(&[verb, "--help"]);
        assert!(
            help.contains("Exit codes: 0 success; 1 bad input"),
            "{verb}: {help}"
        );
        assert!(help.contains("3 a computation failed"), "{verb}: {help}");
        assert!(help.contains("mm"), "{verb}: {help}");
    }
    let gains = ok(&["gains", "--help"]);
    for s in [
        "degrees",
        "mm/rad",
        "mm/mm",
        "inverse kinematics",
        "--param",
    ] {
        assert!(gains.contains(s), "`{s}` not in gains --help");
    }
    assert!(ok(&["--help"]).contains("µrad"));
    assert!(ok(&["demo", "--help"]).contains("rtest-demo"));
}

/// `text` folded at `width` columns at spaces, as `fold -s -w width` does: the number of lines.
fn folded_lines(text: &str, width: usize) -> usize {
    text.lines()
        .map(|line| {
            let (mut lines, mut used) = (1, 0);
            for word in line.split(' ') {
                let w = word.chars().count();
                if used > 0 && used + 1 + w > width {
                    lines += 1;
                    used = w;
                } else {
                    used += if used > 0 { 1 + w } else { w };
                }
            }
            lines
        })
        .sum()
}

#[test]
fn every_verb_says_what_it_does_in_at_most_25_lines_and_points_at_the_docs() {
    let top = ok(&["--help"]);
    let verbs: Vec<&str> = top
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|v| *v != "help")
        .collect();
    assert!(verbs.len() >= 17, "{verbs:?}");
    for verb in verbs {
        let help = ok(&[verb, "--help"]);
        let description = help.split("\nUsage:").next().unwrap();
        let lines = folded_lines(description.trim_end(), 100);
        assert!(
            lines <= 25,
            "{verb}: {lines} lines of description at 100 columns:\n{description}"
        );
        assert!(
            description.contains("docs/") || description.contains(".md"),
            "{verb}: no pointer to the docs:\n{description}"
        );
    }
}

// ---------------------------------------------------------------- bad input

#[test]
fn bad_machine() {
    fails(
        &["gains", "--machine", "nope"],
        2,
        &["--machine", "`nope`", "seed-ac"],
    );
    fails(
        &["gains", "--machine", "missing.toml"],
        2,
        &["--machine", "`missing.toml`"],
    );
    fails(
        &["machines", "--machine", "nope"],
        2,
        &["--machine", "`nope`"],
    );
    let dir = temp_dir("bad-machine");
    let text = model_spec::BUILTIN[0]
        .1
        .replace("stroke = [-500.0, 500.0]", "stroke = [500.0, -500.0]");
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text).unwrap();
    let bad = bad.to_str().unwrap();
    fails(
        &["gains", "--machine", bad],
        1,
        &["--machine", bad, "stroke"],
    );
    std::fs::write(dir.join("junk.toml"), "this is [not toml").unwrap();
    let junk = dir.join("junk.toml");
    fails(
        &["machines", "--machine", junk.to_str().unwrap()],
        1,
        &["--machine", "junk.toml:1:"],
    );
    fails(
        &["gains", "--machine", dir.to_str().unwrap()],
        1,
        &["--machine", "cannot read"],
    );
}

#[test]
fn bad_model_and_errors() {
    fails(
        &["gains", "--machine", "seed-ac", "--model", "tiny"],
        2,
        &["--model", "`tiny`", "full, reduced"],
    );
    fails(
        &["gains", "--machine", "seed-ac", "--errors", "XOC,FOO"],
        2,
        &["--errors", "`FOO`", "EXX", "BOC"],
    );
    fails(
        &["gains", "--machine", "seed-ac", "--errors", "XOC,,BOA"],
        2,
        &["--errors", "empty item"],
    );
    fails(
        &["gains", "--machine", "seed-ac", "--errors", ""],
        2,
        &["--errors", "empty list"],
    );
    fails(
        &["gains", "--machine", "seed-ac", "--errors", "XOC,X0C"],
        2,
        &["--errors", "XOC given twice"],
    );
    fails(
        &[
            "gains",
            "--machine",
            "seed-ac",
            "--model",
            "full",
            "--errors",
            "XOC",
        ],
        2,
        &["--model", "--errors"],
    );
    // An error that exists in another machine only.
    fails(
        &["gains", "--machine", "seed-ac", "--errors", "XOB"],
        2,
        &["--errors", "`XOB`"],
    );
}

#[test]
fn bad_at() {
    let base = ["gains", "--machine", "seed-ac", "--format", "json", "--at"];
    let at = |s: &'static str| [&base[..], &[s]].concat();
    fails(
        &at("X=abc,A=0,C=0"),
        2,
        &["--at", "`X=abc`", "`abc` is not a number"],
    );
    fails(&at("X,A=0,C=0"), 2, &["--at", "`X` is not NAME=VALUE"]);
    fails(&at("A=0,C=0,A=1"), 2, &["--at", "`A` is given twice"]);
    fails(&at("A=0,C=0,c=1"), 2, &["--at", "`c` is given twice"]);
    fails(
        &at("A=0,C=0,Q=1"),
        2,
        &["--at", "no axis `Q`", "X, A, C, Y, Z"],
    );
    fails(&at("A=0,C=inf"), 2, &["--at", "`C=inf`", "finite"]);
    fails(&at("A=NaN,C=0"), 2, &["--at", "`A=NaN`", "finite"]);
    fails(&at("A=1e999,C=0"), 2, &["--at", "`A=1e999`", "finite"]);
    fails(
        &at("X=0,Y=0,Z=0,A=0"),
        2,
        &["--at", "rotary axis C is missing"],
    );
    fails(&at("A=0,C=0,"), 2, &["--at", "empty item"]);
    fails(&at(""), 2, &["--at", "empty list"]);
    fails(&at("=3,A=0,C=0"), 2, &["--at", "`=3` has no name"]);
    fails(&at("X=,A=0,C=0"), 2, &["--at", "`X=`"]);
}

#[test]
fn bad_param() {
    let args = [
        "gains",
        "--machine",
        "seed-ac",
        "--at",
        "A=0,C=0",
        "--param",
    ];
    let with = |p: &'static str| [&args[..], &[p]].concat();
    fails(&with("Foo=1"), 2, &["--param", "`Foo`", "Xw", "Zp"]);
    fails(&with("Xw=abc"), 2, &["--param", "`Xw=abc`", "not a number"]);
    fails(&with("Xw=1,Xw=2"), 2, &["--param", "`Xw` is given twice"]);
    fails(&with("Xw=inf"), 2, &["--param", "finite"]);
    fails(
        &["gains", "--machine", "seed-ac", "--param", "Xw=1"],
        2,
        &["--at"],
    );
}

#[test]
fn bad_format_and_verb() {
    fails(
        &["gains", "--machine", "seed-ac", "--format", "yaml"],
        2,
        &["--format", "'yaml'", "json"],
    );
    fails(
        &[
            "gains",
            "--machine",
            "seed-ac",
            "--at",
            "A=0,C=0",
            "--format",
            "csv",
        ],
        2,
        &["--format", "'csv'"],
    );
    fails(&["gains"], 2, &["--machine"]);
    fails(&["frobnicate"], 2, &["frobnicate"]);
    fails(
        &["gains", "--machine", "seed-ac", "--bogus"],
        2,
        &["--bogus"],
    );
}

#[test]
fn inverse_kinematics_failure_is_not_a_usage_error() {
    let dir = temp_dir("two-linear");
    let file = dir.join("two.toml");
    std::fs::write(
        &file,
        "name = \"two-linear\"\ndescription = \"C table, X and Y only\"\n\
         [[work]]\naxis = \"C\"\ntype = \"rotary\"\ndirection = \"+z\"\n\
         [[work]]\nend = \"ball\"\n\
         [[tool]]\naxis = \"X\"\ntype = \"linear\"\ndirection = \"+x\"\nstroke = [-100, 100]\n\
         [[tool]]\naxis = \"Y\"\ntype = \"linear\"\ndirection = \"+y\"\nstroke = [-100, 100]\n\
         [[tool]]\nend = \"probe\"\n",
    )
    .unwrap();
    let file = file.to_str().unwrap();
    fails(
        &["gains", "--machine", file, "--at", "C=10"],
        1,
        &["--at", "inverse kinematics", "three linear axes"],
    );
    // With every axis given, no inverse kinematics is needed.
    let v = json(&[
        "gains",
        "--machine",
        file,
        "--at",
        "C=10,X=0,Y=0",
        "--errors",
        "XOC",
        "--format",
        "json",
    ]);
    assert_eq!(triple(&v["gains"]["XOC"]["position"]), [-1.0, 0.0, 0.0]);
}

#[test]
fn generate_failures_leave_no_file() {
    let dir = temp_dir("generate-bad");
    let out = dir.join("code.rs");
    let o = out.to_str().unwrap();
    fails(
        &[
            "generate",
            "--machine",
            "seed-ac",
            "--model",
            "tiny",
            "-o",
            o,
        ],
        2,
        &["--model", "`tiny`"],
    );
    fails(
        &["generate", "--machine", "nope", "-o", o],
        2,
        &["--machine", "`nope`"],
    );
    fails(
        &[
            "generate",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--model",
            "reduced",
            "-o",
            o,
        ],
        2,
        &["--model", "twice"],
    );
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    // Unwritable destinations.
    let missing = dir.join("no-such-dir").join("code.rs");
    fails(
        &[
            "generate",
            "--machine",
            "seed-ac",
            "-o",
            missing.to_str().unwrap(),
        ],
        1,
        &["-o", "cannot write", "no-such-dir"],
    );
    std::fs::create_dir(dir.join("sub")).unwrap();
    fails(
        &[
            "generate",
            "--machine",
            "seed-ac",
            "-o",
            dir.join("sub").to_str().unwrap(),
        ],
        1,
        &["-o", "directory"],
    );
    assert_eq!(entries(&dir), ["sub"]);
    assert!(entries(&dir.join("sub")).is_empty());
}

#[test]
fn demo_failure_leaves_no_partial_file() {
    let dir = temp_dir("demo-bad");
    // `rtest-demo` is a file, so the directory cannot be created.
    std::fs::write(dir.join("rtest-demo"), "in the way").unwrap();
    fails_in(Some(&dir), &["demo"], 1, &["demo", "rtest-demo"]);
    assert_eq!(entries(&dir), ["rtest-demo"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("rtest-demo")).unwrap(),
        "in the way"
    );
}
