//! End-to-end: position against time. A trunnion's campaign of `turn-B` at two ball heights
//! (B turns monotonically in time on both records) with a small angular error of B; `rtest
//! diagnose` says that B's error and a drift cannot be told apart on these records and gives the
//! `rtest plan` command that checks the separation; the plan names `turn-B-rev` or
//! `turn-B-back`, and with it added the plan separates them. `rtest path` writes the versions.

use crate::common;
use common::{ok, read_json, temp_dir_tagged, words};

/// A truth for `table-table-bc` with set-up errors `setup` (µm) and a small error of B.
fn truth(setup: [f64; 3]) -> String {
    format!(
        r#"machine = "table-table-bc"
noise_um = 0.5

[errors]
COY = 8.0
AOZ = -12.0
BOZ = 6.0
XOB = 15.0
ZOB = -10.0
AOB = 30.0
COB = -14.0
XOC = 9.0
YOC = -11.0
AOC = 12.0
BOC = -16.0
EBB = {{ "harmonic:1" = [0.5, 2.5] }}
XOW = {}
YOW = {}
ZOW = {}
"#,
        setup[0], setup[1], setup[2]
    )
}

const CAMPAIGN: &str = r#"machine = "table-table-bc"
[[record]]
file = "low.csv"
label = "turn-B-low"
setup = "low"
[[record]]
file = "high.csv"
label = "turn-B-high"
setup = "high"
params = { Zw = 220.0 }
"#;

#[test]
fn the_diagnosis_says_b_s_error_and_a_drift_cannot_be_told_apart_and_the_plan_separates_them() {
    let dir = temp_dir_tagged("cli-reversal", "diagnose");
    std::fs::write(dir.join("low.toml"), truth([12.0, -8.0, 5.0])).unwrap();
    std::fs::write(dir.join("high.toml"), truth([-15.0, 9.0, -6.0])).unwrap();
    std::fs::write(dir.join("c.toml"), CAMPAIGN).unwrap();
    let sim = "simulate --machine table-table-bc --path turn-B";
    ok(
        &dir,
        &words(&format!("{sim} --truth low.toml --seed 1 -o low.csv")),
    );
    ok(
        &dir,
        &words(&format!(
            "{sim} --param Zw=220 --truth high.toml --seed 51 -o high.csv"
        )),
    );
    let out = ok(
        &dir,
        &words(
            "diagnose --machine table-table-bc --model location --campaign c.toml --json d.json --report d.html",
        ),
    );
    assert!(
        out.contains("Cannot be told apart on these records: EBB harmonic:1"),
        "{out}"
    );
    assert!(
        out.contains(
            "To separate them, measure turn-B-back (there and back in one record) or turn-B-rev"
        ),
        "{out}"
    );
    let d = read_json(&dir.join("d.json"));
    let e = &d["position_or_time"][0];
    assert_eq!(e["position"], "EBB@harmonic:1");
    assert_eq!(e["axis"], "B");
    assert_eq!(e["verdict"], "cannot be told apart");
    assert_eq!(e["monotonic"][0], "low.csv");
    assert_eq!(e["monotonic"][1], "high.csv");
    let time = e["time"].as_str().unwrap();
    let command = e["plan_command"].as_str().unwrap();
    assert_eq!(
        command,
        format!("rtest plan --machine table-table-bc --terms EBB@harmonic:1,{time} --paths turn-B")
    );
    assert!(out.contains(&format!("Plan it first: {command}")), "{out}");
    // The HTML report says the same.
    let html = std::fs::read_to_string(dir.join("d.html")).unwrap();
    assert!(html.contains("Position against time:"), "{html}");
    assert!(
        html.contains("EBB@harmonic:1 (an error of B&#39;s position)"),
        "{html}"
    );
    assert!(
        html.contains(&format!("Plan it first: {command}")),
        "{html}"
    );
    // The finding names the other term as its alternative.
    let finding = d["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["error"] == "EBB")
        .unwrap();
    let alternatives: Vec<&str> = finding["alternatives"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    assert!(alternatives.contains(&time), "{alternatives:?}");

    // The plan it gives: the two terms are not separated on turn-B; a version of turn-B is.
    let plan: Vec<&str> = words(command)[1..].to_vec();
    let mut args = plan.clone();
    args.extend(["--json", "p.json"]);
    let out = ok(&dir, &args);
    assert!(
        out.contains("Position against time: the plan does not separate EBB@harmonic:1:"),
        "{out}"
    );
    let p = read_json(&dir.join("p.json"));
    let best = p["separation"]["candidates"][0]["paths_item"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(best == "turn-B-back" || best == "turn-B-rev", "{best}");
    assert!(
        out.contains(&format!("Separation: add {best} to --paths")),
        "{out}"
    );
    // Followed, the plan separates them.
    let mut args: Vec<String> = plan.iter().map(|s| s.to_string()).collect();
    let paths = args.iter().position(|a| a == "--paths").unwrap() + 1;
    args[paths] = format!("turn-B,{best}");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = ok(&dir, &args);
    assert!(!out.contains("Position against time"), "{out}");
}

#[test]
fn a_record_s_own_drift_is_separated_by_there_and_back_not_by_the_reversed_test() {
    let dir = temp_dir_tagged("cli-reversal", "plan");
    let out = ok(
        &dir,
        &words(
            "plan --machine table-table-bc --terms EBB@harmonic:1,BOC@time:1 --paths turn-B --json p.json",
        ),
    );
    assert!(
        out.contains("Separation: add turn-B-back to --paths"),
        "{out}"
    );
    let p = read_json(&dir.join("p.json"));
    let s = &p["separation"];
    assert_eq!(s["threshold"], 0.9);
    assert_eq!(s["pairs"][0]["time"], "BOC@time:1[turn-B]");
    let c = s["candidates"].as_array().unwrap();
    assert_eq!(c.len(), 2);
    assert_eq!(
        (c[0]["test"].as_str(), c[1]["test"].as_str()),
        (Some("turn-B-back"), Some("turn-B-rev"))
    );
    assert!(c[0]["largest_correlation"].as_f64().unwrap() < 0.7);
    // The general ranking has the versions of the planned test among its candidates.
    let ranked: Vec<&str> = p["suggestion"]["ranking"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["test"].as_str().unwrap())
        .collect();
    assert!(ranked.contains(&"turn-B-rev") && ranked.contains(&"turn-B-back"));
    // Planned there and back, nothing is left to separate.
    let out = ok(
        &dir,
        &words(
            "plan --machine table-table-bc --terms EBB@harmonic:1,BOC@time:1 --paths turn-B-back",
        ),
    );
    assert!(!out.contains("Position against time"), "{out}");
}

#[test]
fn path_writes_the_reversed_and_there_and_back_versions() {
    let dir = temp_dir_tagged("cli-reversal", "path");
    let out = ok(
        &dir,
        &words("path --machine table-table-bc --test TURN-B-BACK -o back.csv"),
    );
    assert!(
        out.starts_with("Test turn-B-back of machine table-table-bc: 361 samples."),
        "{out}"
    );
    let text = std::fs::read_to_string(dir.join("back.csv")).unwrap();
    assert!(
        text.contains("# rtest path: test turn-B-back of machine table-table-bc"),
        "{text}"
    );
    let out = ok(
        &dir,
        &words("path --machine table-table-bc --test turn-B-rev -o rev.csv"),
    );
    assert!(
        out.starts_with("Test turn-B-rev of machine table-table-bc: 181 samples."),
        "{out}"
    );
    // simulate takes them by name.
    let out = ok(
        &dir,
        &words("simulate --machine table-table-bc --path pair-B-C-back -o s.csv"),
    );
    assert!(out.contains("s.csv"), "{out}");
}
