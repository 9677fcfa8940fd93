//! End-to-end tests of campaigns on the command line: `identify --data a.csv,b.csv` and
//! `--campaign FILE`, `validate` on fitted and new set-ups, and bad campaign files (file, line,
//! column and field named; nothing written). The diagnosis of a campaign: `tests/all/cli_diagnose.rs`.

use model_spec::Machine;
use simulation::model::{Model, Term};
use simulation::paths::{fill_linear_ik, record_from_commands};
use simulation::readings::simulate;
use simulation::truth::Truth;
use std::path::Path;

use crate::common::{self, param, temp_dir};
use common::{entries, fails, ok, read_json};

/// Simulates the built-in `path` of seed-ac with the reduced truth and noise into `dir/out`.
fn simulate_seed(dir: &Path, path: &str, out: &str, seed: &str, extra: &[&str]) {
    let mut args = vec![
        "simulate",
        "--machine",
        "seed-ac",
        "--path",
        path,
        "--truth",
        "seed-ac-reduced",
        "--noise-um",
        "0.3",
        "--seed",
        seed,
        "-o",
        out,
    ];
    args.extend_from_slice(extra);
    ok(dir, &args);
}

#[test]
fn two_files_are_two_set_ups_sharing_the_machine_errors() {
    let dir = temp_dir("two-files");
    simulate_seed(&dir, "K4", "k4.csv", "1", &[]);
    simulate_seed(&dir, "K1", "k1.csv", "2", &[]);
    simulate_seed(&dir, "K2", "k2.csv", "3", &[]);
    let text = ok(
        &dir,
        &common::words(
            "identify --machine seed-ac --model reduced --data k4.csv,k1.csv --json c.json",
        ),
    );
    assert!(text.contains("2 records on 2 set-ups"), "{text}");
    assert!(text.contains("Shared (the machine's errors"), "{text}");
    assert!(text.contains("Set-up k4 (records k4)") && text.contains("Set-up k1 (records k1)"));
    let j = read_json(&dir.join("c.json"));
    assert_eq!(j["kind"], "campaign");
    assert_eq!(j["setups"].as_array().unwrap().len(), 2);
    let labels: Vec<&str> = j["records"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["k4", "k1"]);
    for r in j["records"].as_array().unwrap() {
        let rms = r["residual_rms_um"].as_f64().unwrap();
        assert!((0.2..0.4).contains(&rms), "{r}");
    }
    // The machine's errors once, the set-up errors per set-up, both near the truth.
    let xoc = param(&j, "XOC");
    assert_eq!(xoc["owner"], "shared");
    assert!(xoc.get("of").is_none());
    let xow = param(&j, "XOW[k1]");
    assert_eq!(
        (xow["owner"].as_str(), xow["of"].as_str()),
        (Some("setup"), Some("k1"))
    );
    let (a, b) = (
        param(&j, "XOW[k4]")["value"].as_f64().unwrap(),
        xow["value"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 0.5, "one ball, two set-ups: {a} and {b}");
    assert_eq!(j["rank"], 14);

    // Validation: K2 on a new set-up (its set-up refitted), and on set-up k4 (its values).
    let v = ok(
        &dir,
        &common::words("validate --machine seed-ac --params c.json --data k2.csv --json v.json"),
    );
    assert!(v.contains("set-up k2 (new: not fitted); refitted"), "{v}");
    let vj = read_json(&dir.join("v.json"));
    let rec = &vj["records"][0];
    assert_eq!(rec["setup_fitted"], false);
    let refitted: Vec<&str> = rec["refitted"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(refitted, ["XOW[k2]", "YOW[k2]", "ZOW[k2]"]);
    let after = rec["residual_rms_um"].as_f64().unwrap();
    assert!(after < 0.4, "{rec}");
    let v = ok(
        &dir,
        &common::words(
            "validate --machine seed-ac --params c.json --data k2.csv --setup k4 --json w.json",
        ),
    );
    assert!(
        v.contains("set-up k4 (fitted); every value from the identification"),
        "{v}"
    );
    let wj = read_json(&dir.join("w.json"));
    assert_eq!(wj["records"][0]["refitted"].as_array().unwrap().len(), 0);
    assert!(wj["records"][0]["residual_rms_um"].as_f64().unwrap() < 0.4);

    // One file stays the single identification, and its report is the single one.
    ok(
        &dir,
        &common::words("identify --machine seed-ac --model reduced --data k4.csv --json s.json"),
    );
    let s = read_json(&dir.join("s.json"));
    assert!(s.get("kind").is_none() && s["parameters"][0]["name"] == "XOW");
    // A record's report: the fields of a single identification, plus its version, set-up and
    // record.
    let mut keys: Vec<&str> = s.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort_unstable();
    let mut want = vec![
        "machine",
        "fingerprint",
        "data",
        "model",
        "base_model",
        "terms",
        "parameters",
        "residual_rms_um",
        "rank",
        "free_parameters",
        "condition",
        "confounded",
        "samples",
        "readings",
        "dof",
        "zeroed",
        "constraint",
        "sigma_um",
        "near_confounded",
        "swallowed",
        "gains",
        "refinement",
        "noise_model",
        "notes",
        "version",
        "setups",
        "records",
    ];
    want.sort_unstable();
    assert_eq!(keys, want);
    assert_eq!(s["version"], 2);
    assert_eq!(
        s["setups"],
        serde_json::json!([{"label": "k4", "records": ["k4"]}])
    );
    assert_eq!(s["records"][0]["data"], "k4.csv");
    assert_eq!(s["records"][0]["params"]["Zw"], 211.537);
    assert!(
        s["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .all(|p| p.get("owner").is_none())
    );
}

#[test]
fn zeroed_records_have_their_own_zero() {
    let dir = temp_dir("zeroed");
    simulate_seed(&dir, "K4", "k4.csv", "1", &["--zeroed"]);
    simulate_seed(&dir, "K2", "k2.csv", "2", &["--zeroed"]);
    ok(
        &dir,
        &common::words(
            "identify --machine seed-ac --model reduced --data k4.csv,k2.csv --zeroed --json c.json",
        ),
    );
    let j = read_json(&dir.join("c.json"));
    let d = param(&j, "dx0[k2]");
    assert_eq!(
        (d["owner"].as_str(), d["of"].as_str()),
        (Some("record"), Some("k2"))
    );
    // XOC is swallowed by every record's zero: no number.
    assert!(param(&j, "XOC")["value"].is_null());
    let groups: Vec<String> = j["confounded"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| g.to_string())
        .collect();
    assert!(
        groups
            .iter()
            .any(|g| g.contains("XOC") && g.contains("dx0[k4]") && g.contains("dx0[k2]")),
        "{groups:?}"
    );
}

/// The head-head test machine.
fn head_head() -> (Machine, String) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/machines/head-head-ca.toml"
    );
    (model_spec::load_machine(path).unwrap(), path.to_string())
}

/// A C turn with A at `a_deg`, planned at `params`, simulated with the location errors, the
/// tilts of Z varying along its stroke and the set-up `setup` (µm), written as CSV.
fn head_head_record(m: &Machine, params: &[f64], a_deg: f64, setup: [f64; 3], seed: u64) -> String {
    let n = 121;
    let mut commands: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            vec![
                0.0,
                0.0,
                0.0,
                (-180.0 + 3.0 * i as f64).to_radians(),
                a_deg.to_radians(),
            ]
        })
        .collect();
    fill_linear_ik(m, params, &mut commands).unwrap();
    let path = record_from_commands(commands, (0..n).map(|i| i as f64).collect());
    let mut model = Model::default();
    let mut coefficients = Vec::new();
    let entries = [
        ("COY", 12.0),
        ("AOZ", -9.0),
        ("BOZ", 14.0),
        ("XOC", 11.0),
        ("YOC", -7.0),
        ("AOC", 16.0),
        ("BOC", -13.0),
        ("YOA", 8.0),
        ("ZOA", -10.0),
        ("BOA", 18.0),
        ("COA", -15.0),
        ("EAZ@poly:1", 22.0),
        ("EBZ@poly:1", -17.0),
        ("ECZ@poly:1", 25.0),
        ("XOW", setup[0]),
        ("YOW", setup[1]),
        ("ZOW", setup[2]),
    ];
    for (name, v) in entries {
        let t = Term::parse(m, name).unwrap();
        coefficients.push(v / t.display_factor(m));
        model.terms.push(t);
    }
    let truth = Truth {
        source: "<cli_campaign>".into(),
        description: String::new(),
        params: params.to_vec(),
        model,
        coefficients,
        noise_mm: 0.3e-3,
        noise_phi: 0.0,
        seed,
        zeroed: false,
    };
    let r = simulate(m, &truth, &path).unwrap();
    formats::csv::format_record(m, &r, &[]).unwrap()
}

#[test]
fn a_campaign_file_of_two_ball_heights_on_a_head_head_machine() {
    let dir = temp_dir("heights");
    let (m, machine) = head_head();
    let zw = m.symbol_by_name("Zw").unwrap();
    let low = m.default_parameters();
    let mut high = low.clone();
    high[zw] = 400.0;
    std::fs::create_dir_all(dir.join("data")).unwrap();
    for (name, p, a, s, seed) in [
        ("low-p30", &low, 30.0, [12.0, -8.0, 5.0], 1),
        ("low-m30", &low, -30.0, [12.0, -8.0, 5.0], 2),
        ("high-p30", &high, 30.0, [-15.0, 9.0, -6.0], 3),
        ("high-m30", &high, -30.0, [-15.0, 9.0, -6.0], 4),
    ] {
        let csv = head_head_record(&m, p, a, s, seed);
        std::fs::write(dir.join("data").join(format!("{name}.csv")), csv).unwrap();
    }
    let toml = "\
machine = \"head-head-ca\"
description = \"C turns at A = +-30 deg, ball at two heights\"

[[record]]
file = \"low-p30.csv\"
setup = \"low\"

[[record]]
file = \"low-m30.csv\"
setup = \"low\"

[[record]]
file = \"high-p30.csv\"
setup = \"high\"
params = { Zw = 400.0 }

[[record]]
file = \"high-m30.csv\"
setup = \"high\"
params = { Zw = 400 }
";
    std::fs::write(dir.join("data/heights.toml"), toml).unwrap();
    let terms =
        "COY,AOZ,BOZ,XOW,YOW,ZOW,XOC,YOC,AOC,BOC,YOA,ZOA,BOA,COA,EAZ@poly:1,EBZ@poly:1,ECZ@poly:1";
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            &machine,
            "--terms",
            terms,
            "--campaign",
            "data/heights.toml",
            "--json",
            "h.json",
        ],
    );
    assert!(text.contains("4 records on 2 set-ups"), "{text}");
    assert!(text.contains("Zw = 400"), "{text}");
    let j = read_json(&dir.join("h.json"));
    assert_eq!(j["rank"], 15);
    for (name, truth) in [
        ("EAZ@poly:1", 22.0),
        ("EBZ@poly:1", -17.0),
        ("ECZ@poly:1", 25.0),
    ] {
        let p = param(&j, name);
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        assert!(((v - truth) / s).abs() < 4.0, "{name}: {v} ± {s}");
    }
    assert!(
        param(&j, "XOW[high]")["value"].is_null(),
        "the ball against C's line: no number"
    );
    assert_eq!(j["records"][2]["params"]["Zw"], 400.0);

    // One height cannot: the same model on the low records only.
    let low_only = toml
        .split("[[record]]\nfile = \"high-p30.csv\"")
        .next()
        .unwrap();
    std::fs::write(dir.join("data/low.toml"), low_only).unwrap();
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            &machine,
            "--terms",
            terms,
            "--campaign",
            "data/low.toml",
            "--json",
            "l.json",
        ],
    );
    let l = read_json(&dir.join("l.json"));
    assert_eq!(l["rank"], 9);
    assert!(param(&l, "EAZ@poly:1")["value"].is_null());
}

#[test]
fn bad_campaign_files_name_file_line_column_and_field() {
    let dir = temp_dir("bad");
    simulate_seed(&dir, "K4", "k4.csv", "1", &[]);
    let cases: &[(&str, &[&str])] = &[
        (
            "[[record]]\nfile = \"k4.csv\"\ncolour = 1\n",
            &["c.toml:3:1", "unknown key `colour`"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nparams = { Qw = 1 }\n",
            &["c.toml:3:12", "no kinematic symbol `Qw`"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nparams = { Zw = \"x\" }\n",
            &["c.toml:3:17", "`params.Zw` must be a number"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nzeroed = 1\n",
            &["c.toml:3:10", "`zeroed` must be true or false"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nlabel = \"a b\"\n",
            &["c.toml:3:9", "`label`", "is not allowed"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nlabel = \"a\"\n[[record]]\nfile = \"k4.csv\"\nlabel = \"a\"\n",
            &["c.toml:6:9", "already the label of the record at line 2"],
        ),
        (
            "[[record]]\nlabel = \"a\"\n",
            &["c.toml:1:1", "needs `file"],
        ),
        (
            "machine = \"seed-3axis\"\n[[record]]\nfile = \"k4.csv\"\n",
            &["c.toml:1:11", "not `seed-ac`"],
        ),
        ("description = \"x\"\n", &["no record"]),
        (
            "[[record]]\nfile = \"missing.csv\"\n",
            &["record `missing`", "c.toml:2", "missing.csv"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nsetup = \"s\"\n[[record]]\nfile = \"k4.csv\"\nsetup = \"s\"\nparams = { Zw = 300 }\n",
            &["c.toml:5", "`params.Zw`", "same set-up `s`"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nstart = 0\n[[record]]\nfile = \"k4.csv\"\n",
            &["give every record a start, or none"],
        ),
        (
            "[[record]]\nfile = \"k4.csv\"\nstart = inf\n",
            &["c.toml:3:9", "`start` must be a finite number"],
        ),
    ];
    for (toml, needles) in cases {
        std::fs::write(dir.join("c.toml"), toml).unwrap();
        let args = common::words(
            "identify --machine seed-ac --model reduced --campaign c.toml --json out.json",
        );
        fails(&dir, &args, 1, needles);
        assert!(!dir.join("out.json").exists(), "{toml}: no output");
    }
    // Flags that belong to the records are refused with a campaign file.
    std::fs::write(dir.join("c.toml"), "[[record]]\nfile = \"k4.csv\"\n").unwrap();
    fails(
        &dir,
        &common::words("identify --machine seed-ac --model reduced --campaign c.toml --zeroed"),
        2,
        &["--zeroed"],
    );
    // A record label made from a file stem is unique.
    std::fs::write(
        dir.join("c.toml"),
        "[[record]]\nfile = \"k4.csv\"\n[[record]]\nfile = \"./k4.csv\"\n",
    )
    .unwrap();
    let text = ok(
        &dir,
        &common::words("identify --machine seed-ac --model reduced --campaign c.toml"),
    );
    assert!(text.contains("k4-2"), "{text}");
    assert_eq!(entries(&dir), ["c.toml", "k4.csv"]);
}

#[test]
fn param_sets_the_ball_position_of_one_record() {
    let dir = temp_dir("param");
    let (m, machine) = head_head();
    let mut high = m.default_parameters();
    high[m.symbol_by_name("Zw").unwrap()] = 400.0;
    let csv = head_head_record(&m, &high, 30.0, [12.0, -8.0, 5.0], 1);
    std::fs::write(dir.join("high.csv"), csv).unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "identify",
            "--machine",
            machine.as_str(),
            "--terms",
            "XOW,YOW,ZOW,AOC,BOC",
            "--data",
            "high.csv",
        ];
        a.extend_from_slice(extra);
        a.iter().map(|s| s.to_string()).collect::<Vec<String>>()
    };
    let without = args(&[]);
    let without: Vec<&str> = without.iter().map(String::as_str).collect();
    fails(
        &dir,
        &without,
        1,
        &["high.csv", "off the nominal workpiece point"],
    );
    let with = args(&["--param", "Zw=400", "--json", "h.json"]);
    let with: Vec<&str> = with.iter().map(String::as_str).collect();
    let text = ok(&dir, &with);
    assert!(text.contains("Zw = 400 mm"), "{text}");
    let j = read_json(&dir.join("h.json"));
    assert!(j.get("kind").is_none(), "one record: the single report");
    assert!(j["notes"].to_string().contains("Zw = 400 mm"));
}

#[test]
fn a_campaign_clock_shares_a_drift_and_the_report_reads_back() {
    let dir = temp_dir("clock");
    simulate_seed(&dir, "K4", "k4.csv", "1", &[]);
    simulate_seed(&dir, "K1", "k1.csv", "2", &[]);
    simulate_seed(&dir, "K2", "k2.csv", "3", &[]);
    std::fs::write(
        dir.join("c.toml"),
        "[[record]]\nfile = \"k4.csv\"\nsetup = \"ball\"\nstart = 0\n\n[[record]]\nfile = \"k1.csv\"\nsetup = \"ball\"\nstart = 600\n",
    )
    .unwrap();
    ok(
        &dir,
        &common::words(
            "identify --machine seed-ac --model reduced --terms XOC@time:1 --campaign c.toml --json c.json",
        ),
    );
    let j = read_json(&dir.join("c.json"));
    assert_eq!(j["clock"]["start_s"], 0.0);
    assert_eq!(j["clock"]["end_s"], 960.0);
    assert_eq!(j["records"][1]["start_s"], 600.0);
    assert_eq!(param(&j, "XOC@time:1")["owner"], "shared");
    assert_eq!(j["setups"][0]["records"].as_array().unwrap().len(), 2);
    // The report reads back; a record predicted on the clock needs its start.
    std::fs::write(
        dir.join("v.toml"),
        "[[record]]\nfile = \"k2.csv\"\nsetup = \"ball\"\nstart = 1000\n",
    )
    .unwrap();
    let v = ok(
        &dir,
        &common::words("validate --machine seed-ac --params c.json --campaign v.toml"),
    );
    assert!(v.contains("set-up ball (fitted)"), "{v}");
    fails(
        &dir,
        &common::words("validate --machine seed-ac --params c.json --data k2.csv --setup ball"),
        1,
        &["no start on the campaign clock"],
    );
    // A report whose parameters do not match its terms and records is refused, naming the field.
    let text = std::fs::read_to_string(dir.join("c.json")).unwrap();
    std::fs::write(
        dir.join("bad.json"),
        text.replace("\"XOW[ball]\"", "\"XOW[other]\""),
    )
    .unwrap();
    fails(
        &dir,
        &common::words("validate --machine seed-ac --params bad.json --campaign v.toml"),
        1,
        &["bad.json", "parameters[", ".name", "`XOW[other]`"],
    );
    std::fs::write(
        dir.join("bad.json"),
        text.replace("\"owner\": \"setup\"", "\"owner\": \"shared\""),
    )
    .unwrap();
    fails(
        &dir,
        &common::words("validate --machine seed-ac --params bad.json --campaign v.toml"),
        1,
        &["bad.json", ".owner"],
    );
}

/// Four weekly campaigns of seed-ac (K4 and K1, each on its own ball set-up) recorded in a
/// history: each is one check whose paths are its records, and `history --error XOC` trends the
/// campaign's shared value, flagging the change the truth made.
#[test]
fn a_recorded_campaign_is_one_check_whose_shared_errors_trend() {
    let dir = temp_dir("history");
    for (week, xoc) in [(1, 10.0), (2, 10.0), (3, 13.0), (4, 16.0)] {
        let w = format!("w{week}");
        std::fs::create_dir_all(dir.join(&w)).unwrap();
        std::fs::write(
            dir.join(&w).join("truth.toml"),
            format!(
                "machine = \"seed-ac\"\nnoise_um = 0.3\nseed = {week}\n[errors]\nXOW = 12.0\nYOW = -18.0\nZOW = 15.0\nYOA = 20.0\nZOA = -15.0\nBOA = 25.0\nCOA = -18.0\nXOC = {xoc}\nYOC = -22.0\nAOC = 30.0\nBOC = -12.0\n"
            ),
        )
        .unwrap();
        for (path, seed) in [("K4", 10 * week), ("K1", 10 * week + 1)] {
            let out = format!("{w}/{}.csv", path.to_ascii_lowercase());
            ok(
                &dir,
                &[
                    "simulate",
                    "--machine",
                    "seed-ac",
                    "--path",
                    path,
                    "--truth",
                    &format!("{w}/truth.toml"),
                    "--seed",
                    &seed.to_string(),
                    "-o",
                    &out,
                ],
            );
        }
        let text = ok(
            &dir,
            &[
                "identify",
                "--machine",
                "seed-ac",
                "--model",
                "reduced",
                "--data",
                &format!("{w}/k4.csv,{w}/k1.csv"),
                "--record",
                "--db",
                "h.sqlite",
                "--machine-id",
                "M7",
                "--measured-at",
                &format!("2025-03-{:02}", 3 + 7 * (week - 1)),
            ],
        );
        assert!(
            text.contains(&format!("Recorded as check {week} of machine M7")),
            "{text}"
        );
    }
    ok(&dir, &["history", "--db", "h.sqlite", "--json", "l.json"]);
    let checks = read_json(&dir.join("l.json"))["checks"].clone();
    assert_eq!(checks.as_array().unwrap().len(), 4);
    for c in checks.as_array().unwrap() {
        assert_eq!(c["kind"], "campaign");
        assert_eq!(c["paths"], serde_json::json!(["k4", "k1"]));
    }
    let text = ok(
        &dir,
        &[
            "history",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M7",
            "--error",
            "XOC",
            "--json",
            "xoc.json",
        ],
    );
    assert!(text.contains("paths k4, k1"), "{text}");
    let t = read_json(&dir.join("xoc.json"));
    let rows = t["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 4, "every campaign is in the series");
    for (r, truth) in rows.iter().zip([10.0, 10.0, 13.0, 16.0]) {
        let (v, s) = (r["value"].as_f64().unwrap(), r["std"].as_f64().unwrap());
        assert!(
            ((v - truth) / s).abs() < 4.0,
            "XOC {v} ± {s}, truth {truth}"
        );
    }
    let flagged = |i: usize| {
        rows[i]["flags"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["test"] == "baseline")
    };
    assert!(!flagged(1), "week 2 is the baseline's machine");
    assert!(
        flagged(2) && flagged(3),
        "XOC moved by 3 and 6 µm: {rows:?}"
    );
    // A set-up's value is no error of the machine, but the history keeps it with its owner.
    let c = &checks[0];
    let xow = c["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "XOW[k4]")
        .unwrap();
    assert_eq!(
        (xow["owner"].as_str(), xow["of"].as_str()),
        (Some("setup"), Some("k4"))
    );
}
