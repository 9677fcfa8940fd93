//! A re-check through the command line: head-table-bc calibrated with a touch probe and
//! recorded; after a head change (XOB moved by 12 µm) and a new sphere mounting, one sphere
//! probed at four poses re-checks the pivot (`validate --refit XOB,ZOB`), writes the updated
//! calibration that `compensate` takes, and records two re-checks as their own history series.
//! Refusals: a name that is no machine parameter, a change beyond --max-change-um, --record
//! without --refit; nothing written.

use crate::common::{entries, fails, ok, read_json, temp_dir};
use std::path::Path;

const PROBE: &str =
    "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\nnoise_um = 0.5\n";

/// The calibration's truth, and the machine after the head change: XOB −14 → −2 µm, ZOB 9 →
/// 1 µm, the sphere mounted anew (XOW 10 → 30, YOW 5 → −10, ZOW 0 → 9 µm).
const BEFORE: &str = "machine = \"head-table-bc\"\n[errors]\nYOW = 5\nXOW = 10\nXOB = -14\nZOB = 9\nAOB = 16\nCOB = -21\nYOC = 8\nAOC = -15\nBOC = 19\n";
const AFTER: &str = "machine = \"head-table-bc\"\n[errors]\nYOW = -10\nXOW = 30\nZOW = 9\nXOB = -2\nZOB = 1\nAOB = 16\nCOB = -21\nYOC = 8\nAOC = -15\nBOC = 19\n";

/// Nine calibration poses (B and C swept) and four re-check poses.
const CALIBRATION: &str = "B,C\n0,0\n-60,0\n-30,0\n30,0\n60,0\n0,72\n0,144\n0,216\n0,288\n";
const RECHECK: &str = "B,C\n-45,0\n0,0\n45,0\n0,90\n";

/// The calibration identified and recorded (machine H1, 2026-11-01), and two re-checks'
/// hits simulated after the head change.
fn calibrated(dir: &Path) {
    for (file, text) in [
        ("probe.toml", PROBE),
        ("before.toml", BEFORE),
        ("after.toml", AFTER),
        ("cal.csv", CALIBRATION),
        ("re.csv", RECHECK),
    ] {
        std::fs::write(dir.join(file), text).unwrap();
    }
    let simulate = |truth: &str, path: &str, seed: &str, out: &str| {
        ok(
            dir,
            &[
                "simulate",
                "--machine",
                "head-table-bc",
                "--truth",
                truth,
                "--path",
                path,
                "--probe",
                "probe.toml",
                "--seed",
                seed,
                "-o",
                out,
            ],
        )
    };
    simulate("before.toml", "cal.csv", "1", "cal_hits.csv");
    simulate("after.toml", "re.csv", "5", "re1.csv");
    simulate("after.toml", "re.csv", "6", "re2.csv");
    ok(
        dir,
        &[
            "identify",
            "--machine",
            "head-table-bc",
            "--terms",
            "XOW,YOW,ZOW,XOB,ZOB,AOB,COB,XOC,YOC,AOC,BOC",
            "--constraint",
            "zero:XOC,ZOW",
            "--data",
            "cal_hits.csv",
            "--probe",
            "probe.toml",
            "--json",
            "cal.json",
            "--record",
            "--machine-id",
            "H1",
            "--measured-at",
            "2026-11-01",
        ],
    );
}

/// `rtest validate` of the calibration on the probe hits `data`, with `extra` flags.
fn validate<'a>(data: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "validate",
        "--machine",
        "head-table-bc",
        "--params",
        "cal.json",
        "--data",
        data,
        "--probe",
        "probe.toml",
    ];
    args.extend_from_slice(extra);
    args
}

/// `rtest validate --refit XOB,ZOB` of `data`, with `extra` flags.
fn recheck<'a>(data: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = validate(data, &["--refit", "XOB,ZOB"]);
    args.extend_from_slice(extra);
    args
}

#[test]
fn a_recheck_updates_the_pivot_and_is_its_own_history_series() {
    let dir = temp_dir("recheck");
    calibrated(&dir);
    let out = ok(
        &dir,
        &recheck(
            "re1.csv",
            &[
                "--json",
                "re1.json",
                "--params-out",
                "cal2.json",
                "--record",
                "--machine-id",
                "H1",
                "--measured-at",
                "2026-11-08",
                "--record-paths",
                "recheck",
            ],
        ),
    );
    assert!(out.contains("Re-check: XOB, ZOB refitted"), "{out}");
    assert!(out.contains("instrument's declared covariances"), "{out}");
    // The pivot: XOB moved by 12 µm; ZOB cannot be told from the sphere's new height on one
    // sphere, and the re-check gives no number for either.
    let j = read_json(&dir.join("re1.json"));
    let c = &j["recheck"];
    assert_eq!(c["scale"], "declared");
    let xob = &c["pivot"][0];
    assert_eq!(xob["name"], "XOB");
    let (value, std) = (xob["value"].as_f64().unwrap(), xob["std"].as_f64().unwrap());
    assert!((value + 2.0).abs() < 4.0 * std + 0.5, "XOB {value} ± {std}");
    let change = xob["change"].as_f64().unwrap();
    assert!((change - 12.0).abs() < 1.5, "XOB changed by {change}");
    assert!(xob["change_z"].as_f64().unwrap() > 10.0);
    assert!(c["pivot"][1]["value"].is_null(), "{}", c["pivot"][1]);
    // The preset: the sphere's new XOW and YOW refitted on the record.
    let refitted = j["records"][0]["refitted"].as_array().unwrap();
    let xow = refitted.iter().find(|p| p["name"] == "XOW[re1]").unwrap();
    assert!((xow["value"].as_f64().unwrap() - 30.0).abs() < 1.5, "{xow}");
    // The updated calibration: XOB re-checked, everything else the calibration's; compensate
    // takes it and folds the new pivot into the description.
    let updated = read_json(&dir.join("cal2.json"));
    assert_eq!(updated["rechecked"]["changed"][0], "XOB");
    let find = |j: &serde_json::Value, name: &str| {
        j["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    assert_eq!(find(&updated, "XOB"), value);
    let calibration = read_json(&dir.join("cal.json"));
    assert_eq!(find(&updated, "AOB"), find(&calibration, "AOB"));
    assert_eq!(find(&updated, "ZOB"), find(&calibration, "ZOB"));
    let out = ok(
        &dir,
        &[
            "compensate",
            "--machine",
            "head-table-bc",
            "--params",
            "cal2.json",
            "--kinematics-out",
            "k2.toml",
        ],
    );
    assert!(out.contains("Wrote k2.toml"), "{out}");
    let k2 = std::fs::read_to_string(dir.join("k2.toml")).unwrap();
    assert!(k2.contains(&format!("Xb = {}", value / 1000.0)), "{k2}");
    // A second re-check a day later, then the two series.
    ok(
        &dir,
        &recheck(
            "re2.csv",
            &[
                "--record",
                "--machine-id",
                "H1",
                "--measured-at",
                "2026-11-09",
                "--record-paths",
                "recheck",
            ],
        ),
    );
    let out = ok(
        &dir,
        &[
            "history",
            "--machine-id",
            "H1",
            "--error",
            "XOB",
            "--rechecks",
        ],
    );
    assert!(
        out.contains("constraint recheck: XOB, ZOB; 2 checks"),
        "{out}"
    );
    assert!(
        out.contains("check 1 (2026-11-01T00:00:00Z): a calibration, not a re-check"),
        "{out}"
    );
    let out = ok(&dir, &["history", "--machine-id", "H1", "--error", "XOB"]);
    assert!(out.contains("a re-check (its own series"), "{out}");
    assert!(out.contains("; 1 check"), "{out}");
}

#[test]
fn a_bad_recheck_is_refused_and_writes_nothing() {
    let dir = temp_dir("recheck-refused");
    calibrated(&dir);
    let before = entries(&dir);
    fails(
        &dir,
        &validate("re1.csv", &["--refit", "XOW", "--json", "x.json"]),
        2,
        &[
            "--refit: `XOW` is not a machine parameter of the calibration",
            "XOB, ZOB",
        ],
    );
    fails(
        &dir,
        &recheck(
            "re1.csv",
            &[
                "--max-change-um",
                "5",
                "--json",
                "x.json",
                "--record",
                "--machine-id",
                "H1",
            ],
        ),
        3,
        &["the re-check moves XOB by 11.", "beyond --max-change-um 5"],
    );
    fails(
        &dir,
        &validate("re1.csv", &["--record", "--machine-id", "H1"]),
        2,
        &["--record records a re-check (--refit NAMES)"],
    );
    assert_eq!(entries(&dir), before);
    let out = ok(&dir, &["history", "--machine-id", "H1"]);
    assert!(out.contains("1 check"), "{out}");
}
