//! End-to-end tests of the vocabulary beyond constants, harmonics and polynomials: a truth file
//! with `period:P`, `step:V`, `exp:TAU`, `velocity` and an instrument term simulated by
//! `rtest simulate`, identified back by `rtest identify --terms` (values in µm, ms and 1), read
//! by `rtest validate`, and refused on a record without times.

use crate::common::{self, param, temp_dir};
use common::{fails, ok, read_json};

/// The reduced truth of seed-ac plus one term of every new family (values in µm, ms, 1).
const TRUTH: &str = r#"machine = "seed-ac"
noise_um = 0.0
seed = 0

[errors]
XOW = 12.0
YOW = -18.0
ZOW = 15.0
YOA = 20.0
ZOA = -15.0
BOA = 25.0
COA = -18.0
XOC = 10.0
YOC = -22.0
AOC = 30.0
BOC = -12.0
EXX = { "period:10" = [2.0, -1.0], "step:100" = 3.0 }
EAA = { velocity = 1.5 }
dy0 = { "exp:20" = 4.0 }
SXY = 0.03
"#;

const TERMS: &str = "EXX@period:10,EXX@step:100,EAA@velocity,dy0@exp:20,SXY";

#[test]
fn new_terms_are_simulated_identified_and_validated() {
    let dir = temp_dir("round-trip");
    std::fs::write(dir.join("truth.toml"), TRUTH).unwrap();
    let sim = [
        "simulate",
        "--machine",
        "seed-ac",
        "--path",
        "K4",
        "--truth",
        "truth.toml",
        "-o",
        "k4.csv",
    ];
    ok(&dir, &sim);
    let id = [
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--terms",
        TERMS,
        "--data",
        "k4.csv",
        "--json",
        "id.json",
    ];
    let text = ok(&dir, &id);
    let json = read_json(&dir.join("id.json"));
    for (name, want, unit) in [
        ("EXX@period:10:cos", 2.0, "um"),
        ("EXX@period:10:sin", -1.0, "um"),
        ("EXX@step:100", 3.0, "um"),
        ("EAA@velocity", 1.5, "ms"),
        ("dy0@exp:20", 4.0, "um"),
        ("SXY", 0.03, "1"),
    ] {
        let p = param(&json, name);
        assert_eq!(p["unit"], unit, "{name}");
        let v = p["value"].as_f64().unwrap();
        assert!(
            (v - want).abs() <= 1e-6 * want.abs(),
            "{name}: {v} vs {want}"
        );
    }
    assert!(text.contains("EAA@velocity"), "{text}");
    // validate reads the report back (units ms and 1 included) and predicts the record.
    let v = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k4.csv",
        ],
    );
    let all: Vec<f64> = v
        .lines()
        .find(|l| l.trim_start().starts_with("all"))
        .unwrap_or_else(|| panic!("{v}"))
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    // Before: the readings (tens of µm); after: the exact machine at the identified values.
    assert!(all[0] > 10.0 && all[2] < 1e-6, "{v}");
}

#[test]
fn terms_that_need_times_refuse_a_record_without_t_s() {
    let dir = temp_dir("no-times");
    std::fs::write(dir.join("truth.toml"), TRUTH).unwrap();
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "--truth",
            "truth.toml",
            "-o",
            "k4.csv",
        ],
    );
    // The same record without its t_s column: samples only numbered.
    let text = std::fs::read_to_string(dir.join("k4.csv")).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    let t = header.split(',').position(|c| c == "t_s").unwrap();
    let stripped: String = text
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                return format!("{l}\n");
            }
            let mut f: Vec<&str> = l.split(',').collect();
            f.remove(t);
            format!("{}\n", f.join(","))
        })
        .collect();
    std::fs::write(dir.join("untimed.csv"), stripped).unwrap();
    for term in ["EAA@velocity", "dy0@exp:20"] {
        let args = [
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            term,
            "--data",
            "untimed.csv",
        ];
        fails(
            &dir,
            &args,
            1,
            &[
                "--data untimed.csv",
                &format!("term `{term}` needs the real sample times"),
                "no `t_s` column",
            ],
        );
    }
    // Read in blocks: exp:TAU is refused block by block, velocity outright.
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            "dy0@exp:20",
            "--data",
            "untimed.csv",
            "--stream",
        ],
        1,
        &["--data untimed.csv", "term `dy0@exp:20`", "only numbered"],
    );
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            "EAA@velocity",
            "--data",
            "k4.csv",
            "--stream",
        ],
        1,
        &["term `EAA@velocity`", "read in blocks"],
    );
}
