//! End-to-end tests of the history: `rtest identify --record` (what is recorded, nothing for a
//! failed identification, campaigns, processes recording at once) and `rtest history` (the
//! listing, one error's trend with its flags, its figure, CSV and JSON, and every kind of bad
//! input: one stderr line, exit code 2 for usage errors and 1 for bad inputs, the database
//! left as it was).

use crate::common::{self, temp_dir};

use common::{entries, fails, ok, read_json};
use history::sha256::sha256_hex;
use serde_json::Value;
use simulation::{builtin_path, simulate};
use std::path::Path;

/// Writes a K4 measurement of seed-ac to `dir/name`: the reduced truth with XOC = `xoc` µm,
/// 0.6 µm of noise from `seed`.
fn k4(dir: &Path, name: &str, xoc: f64, seed: u64) {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let text = format!(
        "noise_um = 0.6\nseed = {seed}\n[errors]\nXOW = 12.0\nYOW = -18.0\nZOW = 15.0\nYOA = 20.0\nZOA = -15.0\nBOA = 25.0\nCOA = -18.0\nXOC = {xoc}\nYOC = -22.0\nAOC = 30.0\nBOC = -12.0\n"
    );
    let t = formats::truth::parse_truth("truth", &text, &m).unwrap();
    let path = builtin_path(&m, "K4").unwrap().unwrap();
    let record = simulate(&m, &t, &path).unwrap();
    let csv = formats::csv::format_record(&m, &record, &[]).unwrap();
    std::fs::write(dir.join(name), csv).unwrap();
}

/// `rtest identify` of the reduced model on `data`, recorded for `machine_id` at `date`.
fn record(dir: &Path, data: &str, machine_id: &str, date: &str) -> String {
    ok(
        dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            data,
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            machine_id,
            "--measured-at",
            date,
            "--record-paths",
            "K4",
        ],
    )
}

/// The date of week `k` (1-based) from 2025-01-06.
fn week(k: u32) -> String {
    let day = 6 + 7 * (k - 1);
    // January has 31 days, February 28 (2025).
    let (month, day) = match day {
        d if d <= 31 => (1, d),
        d if d <= 59 => (2, d - 31),
        d if d <= 90 => (3, d - 59),
        d => (4, d - 90),
    };
    format!("2025-{month:02}-{day:02}T08:00:00Z")
}

/// A history of machine M123: 12 weekly checks of XOC = 10 µm, drifting 0.5 µm per check
/// from check 8 on.
fn drifting_history(dir: &Path) {
    for k in 1..=12u32 {
        let xoc = 10.0 + 0.5 * f64::from(k.saturating_sub(7));
        let name = format!("k4-{k:02}.csv");
        k4(dir, &name, xoc, u64::from(k));
        let out = record(dir, &name, "M123", &week(k));
        assert!(
            out.contains(&format!(
                "Recorded as check {k} of machine M123 in h.sqlite"
            )),
            "{out}"
        );
    }
}

#[test]
fn a_recorded_check_holds_what_the_identification_said_and_its_inputs() {
    let dir = temp_dir("recorded");
    k4(&dir, "k4.csv", 10.0, 1);
    let out = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--json",
            "id.json",
            "--record",
            "--machine-id",
            "SN-4711",
        ],
    );
    assert!(out.contains("Wrote id.json"), "{out}");
    assert!(
        out.contains("Recorded as check 1 of machine SN-4711 in rtest-history.sqlite"),
        "{out}"
    );
    // The default database, in the working directory, and nothing else beside it.
    assert_eq!(entries(&dir), ["id.json", "k4.csv", "rtest-history.sqlite"]);
    let listing = ok(&dir, &["history", "--json", "list.json"]);
    assert!(
        listing.contains("Machine SN-4711 (seed-ac; fingerprint "),
        "{listing}"
    );
    let list = read_json(&dir.join("list.json"));
    let report = read_json(&dir.join("id.json"));
    let c = &list["checks"][0];
    assert_eq!(list["kind"], "history");
    assert_eq!(c["machine_id"], "SN-4711");
    assert_eq!(c["fingerprint"], report["fingerprint"]);
    assert_eq!(c["model"], "reduced");
    assert_eq!(c["terms"], report["terms"]);
    assert_eq!(
        c["paths"],
        serde_json::json!(["k4"]),
        "the data file's stem"
    );
    assert_eq!(c["rank"], report["rank"]);
    assert_eq!(c["residual_rms_um"], report["residual_rms_um"]);
    assert_eq!(c["rtest_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(c["measured_at"], c["recorded_at"]);
    let at = c["measured_at"].as_str().unwrap();
    assert!(
        history::Timestamp::parse(at).is_ok() && at.ends_with('Z'),
        "{at}"
    );
    // Every value with its σ and unit, as the report has them, to the bit.
    let params = c["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 11);
    for (p, q) in params.iter().zip(report["parameters"].as_array().unwrap()) {
        for f in ["name", "value", "std", "unit", "determined", "fixed"] {
            assert_eq!(p[f], q[f], "{f}");
        }
    }
    // The input file's SHA-256 and size.
    let bytes = std::fs::read(dir.join("k4.csv")).unwrap();
    let input = &c["inputs"][0];
    assert_eq!(input["role"], "--data");
    assert_eq!(input["path"], "k4.csv");
    assert_eq!(input["bytes"], bytes.len());
    assert_eq!(input["sha256"], sha256_hex(&bytes));
}

#[test]
fn a_failed_identification_records_nothing() {
    let dir = temp_dir("failed");
    k4(&dir, "k4.csv", 10.0, 1);
    // Implausible values: exit code 3, no database made.
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--record",
            "--machine-id",
            "M1",
            "--max-error-um",
            "1",
        ],
        3,
        &["implausible"],
    );
    assert_eq!(entries(&dir), ["k4.csv"]);
    // With a database: its bytes stay as they were.
    record(&dir, "k4.csv", "M1", "2025-01-06");
    let before = std::fs::read(dir.join("h.sqlite")).unwrap();
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M1",
            "--max-error-um",
            "1",
        ],
        3,
        &["implausible"],
    );
    // An output that cannot be written: nothing recorded either.
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M1",
            "--json",
            "no/such/dir/id.json",
        ],
        1,
        &["--json"],
    );
    assert_eq!(std::fs::read(dir.join("h.sqlite")).unwrap(), before);
    let list = ok(&dir, &["history", "--db", "h.sqlite"]);
    assert!(list.contains("1 machine, 1 check"), "{list}");
}

#[test]
fn record_flags_are_checked() {
    let dir = temp_dir("flags");
    k4(&dir, "k4.csv", 10.0, 1);
    let base = [
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
    ];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    for (extra, needles) in [
        (&["--record"][..], &["--record needs --machine-id"][..]),
        (&["--db", "h.sqlite"], &["required", "--record"]),
        (&["--machine-id", "M1"], &["required", "--record"]),
        (
            &["--record", "--machine-id", " M1"],
            &["--machine-id", "blanks"],
        ),
        (
            &[
                "--record",
                "--machine-id",
                "M1",
                "--measured-at",
                "2025-02-30",
            ],
            &["--measured-at", "no such date"],
        ),
        (
            &[
                "--record",
                "--machine-id",
                "M1",
                "--measured-at",
                "2025-02-03T08:00",
            ],
            &["--measured-at", "RFC 3339"],
        ),
        (
            &["--record", "--machine-id", "M1", "--record-paths", "K4,,K1"],
            &["--record-paths", "empty"],
        ),
        (
            &["--record", "--machine-id", "M1", "--record-paths", "K4,k4"],
            &["test path `k4` is given twice"],
        ),
        (
            &[
                "--record",
                "--machine-id",
                "M1",
                "--json",
                "rtest-history.sqlite",
            ],
            &["--json", "rtest-history.sqlite"],
        ),
    ] {
        fails(&dir, &with(extra), 2, needles);
    }
    assert_eq!(entries(&dir), ["k4.csv"]);
}

#[test]
fn the_trend_of_a_drifting_error_flags_it_and_exports_it() {
    let dir = temp_dir("trend");
    drifting_history(&dir);
    std::fs::write(
        dir.join("tol.toml"),
        "# M123\nmachine_id = \"M123\"\nXOC = 11.5\nAOC = 50\n",
    )
    .unwrap();
    let out = ok(
        &dir,
        &[
            "history",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M123",
            "--error",
            "x0c",
            "--tolerances",
            "tol.toml",
            "--figure",
            "xoc.svg",
            "--csv",
            "xoc.csv",
            "--json",
            "xoc.json",
        ],
    );
    for s in [
        "XOC of machine M123 (seed-ac, fingerprint ",
        "model reduced, paths K4, constraint none; 12 checks",
        "Tolerance: |XOC| ≤ 11.5 µm (tol.toml:3).",
        "First baseline flag: check ",
        "First trend flag: check ",
        "Latest check 12:",
        "Wrote xoc.svg",
        "Wrote xoc.csv",
        "Wrote xoc.json",
    ] {
        assert!(out.contains(s), "`{s}` not in:\n{out}");
    }
    let j = read_json(&dir.join("xoc.json"));
    assert_eq!(j["kind"], "history-trend");
    assert_eq!(j["parameter"], "XOC");
    assert_eq!(j["unit"], "um");
    assert_eq!(j["baseline"], 1);
    assert_eq!(j["tolerance"], 11.5);
    let rows = j["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 12);
    let first = |test: &str| {
        rows.iter()
            .position(|r| {
                r["flags"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|f| f["test"] == test)
            })
            .map(|i| i + 1)
    };
    // Seven stable checks: no flag; the drift (0.5 µm per check from check 8, σ ≈ 0.4 µm) is
    // flagged by the change test and the trend test by check 12.
    let (b, t) = (first("baseline").unwrap(), first("trend").unwrap());
    assert!((8..=12).contains(&b) && (8..=12).contains(&t), "{b} {t}");
    let tol = first("tolerance").unwrap();
    assert!(tol >= 9, "{tol}");
    assert!(j["trend"]["flagged"].as_bool().unwrap());
    assert!(j["trend"]["per_day"].as_f64().unwrap() > 0.0);
    // Every flag says which test fired, with its numbers.
    for r in rows {
        for f in r["flags"].as_array().unwrap() {
            assert!(["tolerance", "baseline", "trend"].contains(&f["test"].as_str().unwrap()));
            assert!(f["statistic"].as_f64().unwrap() > f["threshold"].as_f64().unwrap());
            assert!(!f["text"].as_str().unwrap().is_empty());
        }
    }
    // The CSV: one row per check, the values to the bit.
    let csv = std::fs::read_to_string(dir.join("xoc.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(
        lines[0].starts_with("# rtest history: XOC of machine M123"),
        "{}",
        lines[0]
    );
    assert_eq!(
        lines[1],
        "check,measured_at,value_um,std_um,change_um,change_z,slope_um_per_day,slope_std_um_per_day,slope_t,slope_dof,tolerance_flag,baseline_flag,trend_flag"
    );
    assert_eq!(lines.len(), 14);
    // (Compared with the database itself: serde_json's reader does not round every decimal
    // to the nearest f64.)
    let stored = history::Store::open(&dir.join("h.sqlite"))
        .unwrap()
        .checks(Some("M123"))
        .unwrap();
    for (line, c) in lines[2..].iter().zip(&stored) {
        let f: Vec<&str> = line.split(',').collect();
        let p = c.check.parameter("XOC").unwrap();
        assert_eq!(f[0], c.id.to_string());
        assert_eq!(f[1], c.check.measured_at.to_string());
        assert_eq!(f[2].parse::<f64>().unwrap(), p.value.unwrap());
        assert_eq!(f[3].parse::<f64>().unwrap(), p.std.unwrap());
    }
    let svg = std::fs::read_to_string(dir.join("xoc.svg")).unwrap();
    for s in [
        "XOC of machine M123",
        "XOC (µm)",
        "tolerance ±11.5 µm",
        "baseline (check 1)",
        "flagged check",
    ] {
        assert!(svg.contains(s), "`{s}` not in the figure");
    }

    // Another baseline, a --tolerance, another α; a figure-free run writes nothing else.
    let out = ok(
        &dir,
        &[
            "history",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M123",
            "--error",
            "XOC",
            "--baseline",
            "8",
            "--tolerance",
            "XOC=20",
            "--alpha",
            "0.001",
        ],
    );
    assert!(
        out.contains("Baseline: check 8. Tests at two-sided α = 0.001"),
        "{out}"
    );
    assert!(
        out.contains("Tolerance: |XOC| ≤ 20 µm (--tolerance)."),
        "{out}"
    );
    assert!(!out.contains("Wrote"), "{out}");
    // The listing of one machine names the errors --error takes.
    let out = ok(
        &dir,
        &["history", "--db", "h.sqlite", "--machine-id", "M123"],
    );
    assert!(out.contains("1 machine, 12 checks"), "{out}");
    assert!(
        out.contains("XOW YOW ZOW YOA ZOA BOA COA XOC YOC AOC BOC"),
        "{out}"
    );
}

#[test]
fn checks_of_other_paths_or_models_are_left_out_with_the_reason() {
    let dir = temp_dir("left-out");
    for k in 1..=5u32 {
        k4(&dir, &format!("k4-{k}.csv"), 10.0, u64::from(k));
    }
    record(&dir, "k4-1.csv", "M7", &week(1));
    // Week 2: another model; week 3: other path labels.
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--terms",
            "ECC@harmonic:2",
            "--data",
            "k4-2.csv",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M7",
            "--measured-at",
            &week(2),
            "--record-paths",
            "K4",
        ],
    );
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4-3.csv",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M7",
            "--measured-at",
            &week(3),
            "--record-paths",
            "K4,K1",
        ],
    );
    record(&dir, "k4-4.csv", "M7", &week(4));
    record(&dir, "k4-5.csv", "M7", &week(5));
    // The series of the latest check: the K4 checks of the reduced model.
    let out = ok(
        &dir,
        &[
            "history",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M7",
            "--error",
            "XOC",
        ],
    );
    assert!(
        out.contains("model reduced, paths K4, constraint none; 3 checks"),
        "{out}"
    );
    assert!(
        out.contains("Left out (2 checks of machine M7 not comparable with the series):"),
        "{out}"
    );
    assert!(
        out.contains(
            "check 2 (2025-01-13T08:00:00Z): another model (reduced + ECC@harmonic:2: other terms)"
        ),
        "{out}"
    );
    assert!(
        out.contains(
            "check 3 (2025-01-20T08:00:00Z): other test paths (K4, K1; the series measured K4)"
        ),
        "{out}"
    );
    // A baseline picks its own series.
    let out = ok(
        &dir,
        &[
            "history",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M7",
            "--error",
            "XOC",
            "--baseline",
            "2",
        ],
    );
    assert!(
        out.contains("model reduced + ECC@harmonic:2, paths K4, constraint none; 1 check"),
        "{out}"
    );
}

#[test]
fn a_campaign_is_recorded_with_its_records_as_paths() {
    let dir = temp_dir("campaign");
    k4(&dir, "a.csv", 10.0, 1);
    k4(&dir, "b.csv", 10.0, 2);
    let out = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "a.csv,b.csv",
            "--record",
            "--db",
            "h.sqlite",
            "--machine-id",
            "M9",
        ],
    );
    assert!(out.contains("Recorded as check 1 of machine M9"), "{out}");
    ok(&dir, &["history", "--db", "h.sqlite", "--json", "l.json"]);
    let c = &read_json(&dir.join("l.json"))["checks"][0];
    assert_eq!(c["kind"], "campaign");
    assert_eq!(c["paths"], serde_json::json!(["a", "b"]));
    let inputs: Vec<&str> = c["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["path"].as_str().unwrap())
        .collect();
    assert_eq!(inputs, ["a.csv", "b.csv"]);
    let names: Vec<&str> = c["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"XOC") && names.contains(&"XOW[a]"),
        "{names:?}"
    );
    let owner: Vec<&Value> = c["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| &p["owner"])
        .collect();
    assert!(
        owner
            .iter()
            .all(|o| ["shared", "setup", "record"].contains(&o.as_str().unwrap()))
    );
}

#[test]
fn processes_recording_into_one_database_at_once_lose_nothing() {
    let dir = temp_dir("processes");
    k4(&dir, "k4.csv", 10.0, 1);
    let exe = env!("CARGO_BIN_EXE_rtest");
    let children: Vec<_> = (0..4)
        .map(|p| {
            let dir = dir.to_path_buf();
            std::thread::spawn(move || {
                for i in 0..3 {
                    let o = std::process::Command::new(exe)
                        .current_dir(&dir)
                        .args([
                            "identify",
                            "--machine",
                            "seed-ac",
                            "--model",
                            "reduced",
                            "--data",
                            "k4.csv",
                            "--record",
                            "--db",
                            "h.sqlite",
                            "--machine-id",
                            &format!("P{p}"),
                            "--measured-at",
                            &week(i + 1),
                        ])
                        .output()
                        .unwrap();
                    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                }
            })
        })
        .collect();
    for c in children {
        c.join().unwrap();
    }
    let out = ok(&dir, &["history", "--db", "h.sqlite"]);
    assert!(out.contains("4 machines, 12 checks"), "{out}");
    assert_eq!(entries(&dir), ["h.sqlite", "k4.csv"]);
}

#[test]
fn bad_history_inputs_are_refused_and_the_database_left_as_it_is() {
    let dir = temp_dir("bad");
    // No database.
    fails(
        &dir,
        &["history", "--db", "none.sqlite"],
        1,
        &["--db", "none.sqlite", "no history database"],
    );
    fails(
        &dir,
        &["history"],
        1,
        &["rtest-history.sqlite", "no history database"],
    );
    assert!(entries(&dir).is_empty());
    // An empty history.
    drop(history::Store::open_or_create(&dir.join("empty.sqlite")).unwrap());
    fails(
        &dir,
        &["history", "--db", "empty.sqlite"],
        1,
        &["empty.sqlite", "the history is empty"],
    );

    for k in 1..=3u32 {
        let name = format!("k4-{k}.csv");
        k4(&dir, &name, 10.0, u64::from(k));
        record(&dir, &name, "M123", &week(k));
    }
    let before = std::fs::read(dir.join("h.sqlite")).unwrap();
    let h = ["history", "--db", "h.sqlite"];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        h.iter().copied().chain(extra.iter().copied()).collect()
    };
    // Usage errors: exit code 2, naming the flag and what is known.
    for (extra, needles) in [
        (
            &["--machine-id", "M999"][..],
            &["--machine-id", "`M999`", "machines: M123"][..],
        ),
        (
            &["--machine-id", "M999", "--error", "XOC"],
            &["--machine-id", "machines: M123"],
        ),
        (
            &["--machine-id", "M123", "--error", "XOD"],
            &["--error", "`XOD`", "its parameters: XOW, YOW"],
        ),
        (&["--error", "XOC"], &["--machine-id"]),
        (&["--machine-id", "M123", "--figure", "f.svg"], &["--error"]),
        (
            &["--machine-id", "M123", "--error", "XOC", "--baseline", "99"],
            &[
                "--baseline",
                "check 99 cannot be the baseline",
                "its checks: 1, 2, 3",
            ],
        ),
        (
            &["--machine-id", "M123", "--error", "XOC", "--alpha", "0.5"],
            &["--alpha", "between"],
        ),
        (
            &[
                "--machine-id",
                "M123",
                "--error",
                "XOC",
                "--tolerance",
                "XOC",
            ],
            &["--tolerance", "NAME=LIMIT"],
        ),
        (
            &[
                "--machine-id",
                "M123",
                "--error",
                "XOC",
                "--tolerance",
                "XOC=-1",
            ],
            &["--tolerance", "positive"],
        ),
        (
            &[
                "--machine-id",
                "M123",
                "--error",
                "XOC",
                "--tolerance",
                "XCO=5",
            ],
            &["--tolerance", "`XCO`", "its parameters"],
        ),
        (
            &[
                "--machine-id",
                "M123",
                "--error",
                "XOC",
                "--csv",
                "h.sqlite",
            ],
            &["--csv", "h.sqlite"],
        ),
    ] {
        fails(&dir, &with(extra), 2, needles);
    }
    // A bad tolerance file: exit code 1, its file, line and column.
    for (text, needles) in [
        (
            "XOC = 5\nYOC = -2\n",
            &["--tolerances", "tol.toml:2:7", "`YOC`", "positive"][..],
        ),
        (
            "XOC = 5\nXCO = 2\n",
            &[
                "tol.toml:2:1",
                "`XCO`",
                "no check of machine `M123` identified it",
            ],
        ),
        (
            "machine_id = \"M124\"\nXOC = 5\n",
            &["tol.toml:1:1", "for machine `M124`, not `M123`"],
        ),
        ("XOC = [5\n", &["tol.toml:1:"]),
    ] {
        std::fs::write(dir.join("tol.toml"), text).unwrap();
        fails(
            &dir,
            &with(&[
                "--machine-id",
                "M123",
                "--error",
                "XOC",
                "--tolerances",
                "tol.toml",
            ]),
            1,
            needles,
        );
    }
    assert_eq!(std::fs::read(dir.join("h.sqlite")).unwrap(), before);

    // A damaged database: refused by history and by identify --record, never changed.
    let damaged = dir.join("damaged.sqlite");
    std::fs::write(&damaged, &before[..before.len() / 2]).unwrap();
    let cut = std::fs::read(&damaged).unwrap();
    fails(
        &dir,
        &["history", "--db", "damaged.sqlite"],
        1,
        &[
            "damaged.sqlite",
            "not a readable rtest history database",
            "left as it is",
        ],
    );
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4-1.csv",
            "--record",
            "--db",
            "damaged.sqlite",
            "--machine-id",
            "M123",
            "--json",
            "id.json",
        ],
        1,
        &[
            "--db",
            "damaged.sqlite",
            "not a readable rtest history database",
        ],
    );
    assert_eq!(std::fs::read(&damaged).unwrap(), cut);
    assert!(!dir.join("id.json").exists());
    // A file that is not a database.
    std::fs::write(dir.join("notes.txt"), "check 1: fine\n").unwrap();
    fails(
        &dir,
        &["history", "--db", "notes.txt"],
        1,
        &["notes.txt", "not an SQLite database"],
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "check 1: fine\n"
    );
}

/// A history in a directory one may not write, the file read-only too (a shared drive, an
/// archive): `rtest history` reads it and leaves nothing beside it; recording into it is
/// refused. Run as an unprivileged user (through `setpriv` when the tests run as root, whom
/// permissions do not stop).
#[test]
fn a_history_in_a_directory_one_may_not_write_is_read() {
    use std::os::unix::fs::PermissionsExt;
    let dir = temp_dir("read-only");
    for k in 1..=2u32 {
        let name = format!("k4-{k}.csv");
        k4(&dir, &name, 10.0, u64::from(k));
        record(&dir, &name, "M123", &week(k));
    }
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::copy(dir.join("h.sqlite"), ro.join("h.sqlite")).unwrap();
    let before = std::fs::read(ro.join("h.sqlite")).unwrap();
    let mode = |p: &Path, m: u32| std::fs::set_permissions(p, std::fs::Permissions::from_mode(m));
    mode(&ro.join("h.sqlite"), 0o444).unwrap();
    mode(&ro, 0o555).unwrap();
    let root = std::process::Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    let as_user = |args: &[&str]| {
        let bin = env!("CARGO_BIN_EXE_rtest");
        let mut c = if root {
            let mut c = std::process::Command::new("setpriv");
            c.args([
                "--reuid=65534",
                "--regid=65534",
                "--clear-groups",
                "--",
                bin,
            ]);
            c
        } else {
            std::process::Command::new(bin)
        };
        c.args(args)
            .current_dir(&*dir)
            .output()
            .expect("rtest runs")
    };
    let listed = as_user(&["history", "--db", "ro/h.sqlite"]);
    let out = String::from_utf8_lossy(&listed.stdout).into_owned();
    let err = String::from_utf8_lossy(&listed.stderr).into_owned();
    assert!(listed.status.success(), "{out}{err}");
    assert!(out.contains("1 machine, 2 checks"), "{out}");
    let recorded = as_user(&[
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4-1.csv",
        "--record",
        "--db",
        "ro/h.sqlite",
        "--machine-id",
        "M123",
    ]);
    let err = String::from_utf8_lossy(&recorded.stderr).into_owned();
    assert_eq!(recorded.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot be written"), "{err}");
    assert_eq!(entries(&ro), ["h.sqlite"]);
    assert_eq!(std::fs::read(ro.join("h.sqlite")).unwrap(), before);
    mode(&ro, 0o755).unwrap();
}

/// The commands the output suggests are shell-quoted: pasted back into a shell, a machine id
/// with quotes and a semicolon is one argument, never a second command.
#[test]
fn suggested_commands_are_shell_quoted() {
    let dir = temp_dir("quoted");
    k4(&dir, "k4.csv", 10.0, 1);
    let id = "M'; touch pwned; --";
    let out = record(&dir, "k4.csv", id, &week(1));
    let suggested = out
        .split("(rtest history ")
        .nth(1)
        .and_then(|s| s.split(")\n").next())
        .unwrap_or_else(|| panic!("no suggested command in: {out}"));
    assert!(
        suggested.contains(r"--machine-id 'M'\''; touch pwned; --'"),
        "{suggested}"
    );
    let listed = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "{} history {suggested}",
            env!("CARGO_BIN_EXE_rtest")
        ))
        .current_dir(&*dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&listed.stdout).into_owned();
    assert!(listed.status.success(), "{text}");
    assert!(text.contains(&format!("Machine {id} ")), "{text}");
    assert!(
        text.contains(r"(rtest history --machine-id 'M'\''; touch pwned; --' --error NAME)"),
        "{text}"
    );
    assert!(!dir.join("pwned").exists());
}
