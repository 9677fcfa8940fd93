//! End-to-end tests of `rtest plan --probe`: the binary run in temporary directories. The text
//! (poses, every parameter's std and valuation, the valuation per rotary axis, how `auto`
//! chose), the JSON, the poses CSV read by `simulate --path` and `simulate --probe` and the
//! hits it gives identified, a constraint, targets out of reach, and bad flags and files (one
//! line naming the flag; nothing written).

use crate::common::{self, num, temp_dir};
use common::{entries, fails, ok, read_json};
use serde_json::Value;
use std::path::Path;

/// The probe of docs/probe.md's checks: sphere 12.5 mm, tip 1.5 mm, σ 0.5 µm.
const PROBE: &str =
    "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\nnoise_um = 0.5\n";

/// The location errors of B and C and the sphere's set-up errors.
const LOCATION_BC: &str = "XOW,YOW,ZOW,XOB,ZOB,AOB,COB,XOC,YOC,AOC,BOC";

fn with_probe(dir: &Path) {
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
}

fn parameter<'a>(j: &'a Value, name: &str) -> &'a Value {
    j["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no parameter {name}"))
}

#[test]
fn a_probe_plan_prints_its_poses_and_valuations_and_writes_the_json_and_the_poses() {
    let dir = temp_dir("plan-probe");
    with_probe(&dir);
    let out = ok(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--json",
            "plan.json",
            "--poses-out",
            "poses.csv",
        ],
    );
    for needle in [
        "Probe plan on machine seed-ac, model reduced (11 parameters): 5 positions per rotary axis (auto",
        "A: -60° .. 60°, both ends: -60, -30, 0, 30, 60°",
        "C: a full turn from 0° in 5 equal steps: 0, 72, 144, 216, 288°",
        "A-60 ",
        "C288 ",
        "predicted std",
        "valuation per rotary axis",
        "auto: 5 positions per rotary axis give every determined parameter of interest a valuation of 2 or more",
        "Wrote plan.json",
        "Wrote poses.csv",
    ] {
        assert!(out.contains(needle), "{needle}:\n{out}");
    }
    let j = read_json(&dir.join("plan.json"));
    assert_eq!(j["machine"], "seed-ac");
    assert_eq!(j["per_axis"], 5);
    assert_eq!(j["mode"], "auto");
    assert_eq!(j["auto"]["met"], true);
    assert_eq!(j["samples"], 10);
    assert_eq!(j["poses"].as_array().unwrap().len(), 10);
    assert_eq!(j["rank"], 11);
    assert!(j["skipped"].as_array().unwrap().is_empty());
    // The valuation is the target over the std: 1 µm and 5 µrad.
    for p in j["parameters"].as_array().unwrap() {
        let (std, v) = (num(&p["std"]), num(&p["valuation"]));
        let target = if p["unit"] == "urad" { 5.0 } else { 1.0 };
        assert!((v - target / std).abs() < 1e-9 * v, "{p}");
        if p["owner"] == "shared" {
            assert!(v >= 2.0, "{p}");
        }
    }
    let axes = j["axes"].as_array().unwrap();
    assert_eq!(axes.len(), 2);
    assert_eq!(axes[0]["axis"], "A");
    let least = num(&axes[1]["valuation"]);
    assert_eq!(
        num(&parameter(&j, axes[1]["parameter"].as_str().unwrap())["valuation"]),
        least
    );

    // The poses CSV: a path the other verbs read, one sample per pose in the plan's order.
    let csv = std::fs::read_to_string(dir.join("poses.csv")).unwrap();
    assert!(
        csv.contains("# poses, in order: A-60, A-30, A0, A30, A60, C0, C72, C144, C216, C288"),
        "{csv}"
    );
    assert_eq!(
        csv.lines().filter(|l| !l.starts_with('#')).count(),
        11,
        "{csv}"
    );
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "poses.csv",
            "-o",
            "readings.csv",
        ],
    );
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "poses.csv",
            "--probe",
            "probe.toml",
            "-o",
            "hits.csv",
        ],
    );
    let id = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--data",
            "hits.csv",
        ],
    );
    assert!(id.contains("rank 11 of 11"), "{id}");
}

#[test]
fn a_given_number_of_positions_and_a_constraint() {
    let dir = temp_dir("plan-probe-ht");
    with_probe(&dir);
    let out = ok(
        &dir,
        &[
            "plan",
            "--machine",
            "head-table-bc",
            "--terms",
            LOCATION_BC,
            "--probe",
            "probe.toml",
            "--per-axis",
            "6",
            "--constraint",
            "zero:XOC,ZOW",
            "--json",
            "-",
        ],
    );
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["per_axis"], 6);
    assert_eq!(j["mode"], "given");
    assert!(j["auto"].is_null());
    assert_eq!(j["constraint"], serde_json::json!(["XOC", "ZOW[probe]"]));
    assert_eq!(j["samples"], 12);
    assert!(j["confounded"].as_array().unwrap().is_empty());
    for name in ["XOC", "ZOW[probe]"] {
        let p = parameter(&j, name);
        assert_eq!(p["fixed"], true);
        assert!(p["std"].is_null() && p["valuation"].is_null(), "{p}");
    }
    assert!(num(&parameter(&j, "XOB")["std"]) > 0.0);
    let sweeps = j["sweeps"].as_array().unwrap();
    assert_eq!(sweeps[0]["axis"], "B");
    assert_eq!(
        sweeps[1]["positions_deg"],
        serde_json::json!([0.0, 60.0, 120.0, 180.0, 240.0, 300.0])
    );
    // Without the constraint XOB goes with XOC and ZOB with the sphere's ZOW.
    let out = ok(
        &dir,
        &[
            "plan",
            "--machine",
            "head-table-bc",
            "--terms",
            LOCATION_BC,
            "--probe",
            "probe.toml",
            "--per-axis",
            "6",
        ],
    );
    assert!(out.contains("[XOB, XOC] [ZOB, ZOW[probe]]"), "{out}");
    assert!(out.contains("not determined: confounded with XOC"), "{out}");
}

#[test]
fn targets_out_of_reach_name_the_parameters_below() {
    let dir = temp_dir("plan-probe-strict");
    with_probe(&dir);
    let out = ok(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--target-um",
            "0.01",
            "--target-urad",
            "0.05",
            "--json",
            "strict.json",
        ],
    );
    assert!(
        out.contains("auto: not even 12 positions per rotary axis give every determined parameter of interest a valuation of 2: below it: YOA,"),
        "{out}"
    );
    let j = read_json(&dir.join("strict.json"));
    assert_eq!(j["per_axis"], 12);
    assert_eq!(j["auto"]["met"], false);
    assert_eq!(j["auto"]["tried"].as_array().unwrap().len(), 10);
    assert_eq!(j["auto"]["below"].as_array().unwrap().len(), 8);
}

#[test]
fn bad_flags_and_files_are_refused_and_nothing_is_written() {
    let dir = temp_dir("plan-probe-bad");
    with_probe(&dir);
    std::fs::write(
        dir.join("silent.toml"),
        "tip_radius_mm = 1.5\nsphere_radius_mm = 12.5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bad.toml"),
        "tip_radius_mm = -1\nsphere_radius_mm = 12.5\nnoise_um = 0.5\n",
    )
    .unwrap();
    let with = |rest: &[&'static str]| -> Vec<&'static str> {
        let mut v = vec![
            "plan",
            "--machine",
            "seed-ac",
            "--json",
            "p.json",
            "--poses-out",
            "p.csv",
        ];
        if !rest.contains(&"--model") {
            v.extend_from_slice(&["--model", "reduced"]);
        }
        v.extend_from_slice(rest);
        v
    };
    let cases: [(&[&str], i32, &[&str]); 11] = [
        (
            &["--probe", "bad.toml"],
            1,
            &["--probe: bad.toml:1:17: `tip_radius_mm` is -1 mm"],
        ),
        (
            &["--probe", "silent.toml"],
            1,
            &["--probe: silent.toml: the probe instrument declares no noise_um"],
        ),
        (
            &["--probe", "missing.toml"],
            1,
            &["--probe", "missing.toml"],
        ),
        (
            &["--probe", "probe.toml", "--per-axis", "2"],
            2,
            &["--per-axis", "from 3 to 12"],
        ),
        (
            &["--probe", "probe.toml", "--per-axis", "13"],
            2,
            &["--per-axis", "from 3 to 12"],
        ),
        (
            &["--probe", "probe.toml", "--per-axis", "many"],
            2,
            &["--per-axis", "`many` is neither"],
        ),
        (
            &["--paths", "K4", "--per-axis", "4"],
            2,
            &["--per-axis: only with --probe"],
        ),
        (
            &["--probe", "probe.toml", "--paths", "K4"],
            2,
            &["--probe", "cannot be used with", "--paths"],
        ),
        (
            &["--probe", "probe.toml", "--constraint", "zero:FOO"],
            2,
            &["--constraint: `FOO` is not a parameter of the model"],
        ),
        (
            &[
                "--probe",
                "probe.toml",
                "--model",
                "full",
                "--per-axis",
                "3",
            ],
            2,
            &["--per-axis 3: the poses give too few readings"],
        ),
        (
            &[
                "--probe",
                "probe.toml",
                "--per-axis",
                "4",
                "--min-valuation",
                "0",
            ],
            2,
            &["--min-valuation"],
        ),
    ];
    for (rest, code, needles) in cases {
        let args = with(rest);
        fails(&dir, &args, code, needles);
        assert_eq!(
            entries(&dir),
            ["bad.toml", "probe.toml", "silent.toml"],
            "{args:?}"
        );
    }
    // An output that names the probe file, or two outputs on standard output.
    fails(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--poses-out",
            "probe.toml",
        ],
        2,
        &["--poses-out", "is also the input of --probe"],
    );
    fails(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--probe",
            "probe.toml",
            "--json",
            "-",
            "--poses-out",
            "-",
        ],
        2,
        &["--poses-out: standard output is also the output of --json"],
    );
    fails(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-3axis",
            "--model",
            "full",
            "--probe",
            "probe.toml",
        ],
        2,
        &["--machine: machine seed-3axis has no rotary axis"],
    );
    assert_eq!(entries(&dir), ["bad.toml", "probe.toml", "silent.toml"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("probe.toml")).unwrap(),
        PROBE
    );
}
