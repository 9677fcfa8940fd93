//! End-to-end tests of the time bases `rate` and `warmup:TAU`: a truth with a drift of the
//! R-test's zero in µm/s and a warm-up of the Z slide is simulated by `rtest simulate` on K4
//! sampled every 2.5 s (600 s), identified back by `rtest identify --terms` (in memory and in
//! blocks), its rate reported in µm/s and never in µm, read back by `rtest validate`, left out
//! of `rtest compensate` and listed; bad spellings are refused with the flag, file, line and
//! column.

use crate::common::{self, param, temp_dir};
use common::{fails, ok, read_json};

/// The reduced truth of seed-ac with a drift of dx0 of 0.02 µm/s and a warm-up of EXZ to 3 µm
/// with a time constant of 40 s, noise free.
const TRUTH: &str = r#"machine = "seed-ac"
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
dx0 = { rate = 0.02 }
EXZ = { "warmup:40" = 3.0 }
"#;

const TERMS: &str = "dx0@rate,EXZ@warmup:40";

/// K4's poses every 2.5 s from `t0` s (a path file: rotary axes and times), 600 s in all,
/// simulated with `truth.toml` into `out`.
fn slow_k4(dir: &std::path::Path, t0: f64, out: &str) {
    let mut text = String::from("t_s,A,C\n");
    for i in 0..241 {
        let c = 1.5 * i as f64;
        let a = -45.0 * (1.0 - c.to_radians().cos());
        text += &format!("{},{a},{c}\n", t0 + 2.5 * i as f64);
    }
    std::fs::write(dir.join("slow-k4.csv"), text).unwrap();
    ok(
        dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "slow-k4.csv",
            "--truth",
            "truth.toml",
            "-o",
            out,
        ],
    );
}

#[test]
fn a_rate_and_a_warm_up_are_simulated_identified_validated_and_left_out_of_compensation() {
    let dir = temp_dir("round-trip");
    std::fs::write(dir.join("truth.toml"), TRUTH).unwrap();
    slow_k4(&dir, 0.0, "k4.csv");
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
    for (name, basis, want, unit) in [
        ("dx0@rate", "rate", 0.02, "um/s"),
        ("EXZ@warmup:40", "warmup:40", 3.0, "um"),
    ] {
        let p = param(&json, name);
        assert_eq!(p["unit"], unit, "{name}");
        assert_eq!(p["basis"], basis, "{name}");
        let v = p["value"].as_f64().unwrap();
        assert!((v - want).abs() <= 1e-6 * want, "{name}: {v} vs {want}");
    }
    // The text gives the rate in µm/s, never in µm.
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("dx0@rate"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.trim_end().ends_with("µm/s"), "{line}");
    // In blocks: the same values, without a first pass for the time span.
    let streamed = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            TERMS,
            "--data",
            "k4.csv",
            "--stream",
            "--block",
            "50",
            "--json",
            "stream.json",
        ],
    );
    assert!(streamed.contains("µm/s"), "{streamed}");
    // Blocks give the first-order fit (no refinement against the exact machine).
    let mut first_order = id[..id.len() - 2].to_vec();
    first_order.extend(["--first-order", "--json", "fo.json"]);
    ok(&dir, &first_order);
    let (f, s) = (
        read_json(&dir.join("fo.json")),
        read_json(&dir.join("stream.json")),
    );
    for name in ["dx0@rate", "EXZ@warmup:40"] {
        let (a, b) = (
            param(&f, name)["value"].as_f64().unwrap(),
            param(&s, name)["value"].as_f64().unwrap(),
        );
        assert!((a - b).abs() < 1e-9 * a.abs(), "{name}: {a} vs {b}");
    }
    // validate reads the report back (unit um/s) and predicts the record exactly.
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
    assert!(all[0] > 10.0 && all[2] < 1e-5, "{v}");
    // A report whose rate claims µm is refused, naming the field.
    let wrong = std::fs::read_to_string(dir.join("id.json"))
        .unwrap()
        .replace("\"um/s\"", "\"um\"");
    std::fs::write(dir.join("wrong.json"), wrong).unwrap();
    fails(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "wrong.json",
            "--data",
            "k4.csv",
        ],
        1,
        &["wrong.json", "unit", "um/s"],
    );
    // Compensation leaves both out and lists them.
    let text = ok(
        &dir,
        &[
            "compensate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--path",
            "k4.csv",
            "-o",
            "k4-comp.csv",
            "--json",
            "comp.json",
        ],
    );
    for t in ["dx0@rate", "EXZ@warmup:40"] {
        assert!(text.contains(&format!("  {t}: ")), "{t}: {text}");
    }
    let comp = read_json(&dir.join("comp.json"));
    let left: Vec<&str> = comp["left_out"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["term"].as_str().unwrap())
        .collect();
    assert!(
        left.contains(&"EXZ@warmup:40") && left.contains(&"dx0@rate"),
        "{left:?}"
    );
}

#[test]
fn a_warm_up_refuses_a_record_with_samples_before_its_start() {
    let dir = temp_dir("before-start");
    // A drift is defined before its start (its line goes on); a warm-up is not.
    let drift_only: String = TRUTH
        .lines()
        .filter(|l| !l.starts_with("EXZ"))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("truth.toml"), drift_only).unwrap();
    slow_k4(&dir, -5.0, "early.csv");
    let args = |terms: &'static str| {
        [
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            terms,
            "--data",
            "early.csv",
        ]
    };
    ok(&dir, &args("dx0@rate"));
    fails(
        &dir,
        &args("EXZ@warmup:40"),
        1,
        &[
            "--data early.csv",
            "term `EXZ@warmup:40` is a warm-up from time 0",
            "is at -5 s, before it",
        ],
    );
}

#[test]
fn bad_spellings_are_refused_with_the_flag_file_line_and_column() {
    let dir = temp_dir("bad");
    for (term, why) in [
        ("dx0@rate:1", "unknown basis `rate:1`"),
        ("EXZ@warmup", "unknown basis `warmup`"),
        ("EXZ@warmup:0", "must be positive"),
        ("EXZ@warmup:1.2345", "at most three decimals"),
        ("SXY@rate", "constants only, not `rate`"),
    ] {
        fails(
            &dir,
            &[
                "identify",
                "--machine",
                "seed-ac",
                "--model",
                "reduced",
                "--terms",
                term,
                "--data",
                "k4.csv",
            ],
            2,
            &["--terms", why],
        );
    }
    for (entry, at, why) in [
        (
            "EXZ = { \"warmup:0\" = 3.0 }",
            "t.toml:2:9",
            "EXZ: `warmup:0`: the time constant TAU of `warmup:TAU` (s) must be positive",
        ),
        (
            "dx0 = { \"rate:2\" = 1.0 }",
            "t.toml:2:9",
            "dx0: unknown basis `rate:2`",
        ),
        (
            "dx0 = { rate = [1, 2] }",
            "t.toml:2:16",
            "dx0 `rate` (µm/s) takes one number; only `harmonic:K` and `period:P` take a pair [cos, sin]",
        ),
    ] {
        std::fs::write(dir.join("t.toml"), format!("[errors]\n{entry}\n")).unwrap();
        fails(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "--truth",
                "t.toml",
                "-o",
                "out.csv",
            ],
            1,
            &[at, why],
        );
        assert!(!dir.join("out.csv").exists());
    }
}
