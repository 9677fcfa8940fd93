//! End-to-end tests of `rtest simulate`, `rtest identify`, `rtest validate` and `rtest demo`:
//! the binary run in temporary directories. Round trips on the exact virtual machine (values
//! recovered, validation residuals), zeroed readings, a path that cannot separate the model,
//! extra terms, the demo's files and values, and every kind of bad input (one stderr line
//! naming the flag, exit code 2 for usage errors and 1 for other failures, no output file left
//! behind).

use crate::one_record::identify_one;
use fitting::IdentifyOptions;
use formats::truth::builtin_truth;
use model_spec::Machine;
use serde_json::Value;
use simulation::model::Model;
use simulation::record::Record;
use simulation::truth::Truth;
use std::path::Path;

// ---------------------------------------------------------------- helpers

use crate::common::{self, num, temp_dir};
use common::{TempDir, entries, fails, ok, read_json};

/// Two JSON values equal, numbers to 1e-9 relative.
fn assert_close(a: &Value, b: &Value) {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-9 * (1.0 + x.abs().max(y.abs())),
                "{x} vs {y}"
            );
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{a} vs {b}");
            x.iter().zip(y).for_each(|(x, y)| assert_close(x, y));
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(x.len(), y.len(), "{a} vs {b}");
            for (k, v) in x {
                assert_close(v, y.get(k).unwrap_or_else(|| panic!("{k} missing in {b}")));
            }
        }
        _ => assert_eq!(a, b),
    }
}

fn machine() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

fn truth(m: &Machine, name: &str) -> Truth {
    builtin_truth(name, m).unwrap().unwrap()
}

/// The truth's constant values by name, µm or µrad (from the built-in truth itself).
fn truth_values(m: &Machine, t: &Truth) -> Vec<(String, f64)> {
    t.entries(m)
        .into_iter()
        .filter(|e| e.values.len() == 1 && e.term.basis == simulation::model::Basis::Const)
        .map(|e| (e.name, e.values[0]))
        .collect()
}

/// The parameter `name` (constant basis) of an identify JSON.
fn param<'a>(json: &'a Value, name: &str) -> &'a Value {
    json["parameters"]
        .as_array()
        .expect("parameters")
        .iter()
        .find(|p| p["error"] == name && p["basis"] == "const")
        .unwrap_or_else(|| panic!("no parameter {name} in {json}"))
}

/// The confounded groups of an identify JSON, each sorted, sorted.
fn groups(json: &Value) -> Vec<Vec<String>> {
    let mut g: Vec<Vec<String>> = json["confounded"]
        .as_array()
        .expect("confounded")
        .iter()
        .map(|g| {
            let mut v: Vec<String> = g
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap().to_string())
                .collect();
            v.sort();
            v
        })
        .collect();
    g.sort();
    g
}

fn sorted(v: &[&[&str]]) -> Vec<Vec<String>> {
    let mut g: Vec<Vec<String>> = v
        .iter()
        .map(|g| {
            let mut x: Vec<String> = g.iter().map(|s| s.to_string()).collect();
            x.sort();
            x
        })
        .collect();
    g.sort();
    g
}

/// Simulates `path` with `extra` flags into `dir/out`.
fn simulate(dir: &Path, path: &str, truth: &str, out: &str, extra: &[&str]) -> String {
    let mut args = vec![
        "simulate",
        "--machine",
        "seed-ac",
        "--path",
        path,
        "--truth",
        truth,
        "-o",
        out,
    ];
    args.extend_from_slice(extra);
    ok(dir, &args)
}

/// The data rows of a CSV (no comments, no header).
fn data_rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect()
}

// ---------------------------------------------------------------- round trips

#[test]
fn noise_free_round_trip_recovers_the_reduced_truth_and_validates_on_k1() {
    let dir = temp_dir("round-trip");
    let m = machine();
    let t = truth(&m, "seed-ac-reduced");

    let line = simulate(&dir, "K4", "seed-ac-reduced", "k4.csv", &[]);
    assert_eq!(line.lines().count(), 1, "{line}");
    for s in [
        "241 samples",
        "RMS of the readings",
        "µm",
        "seed-ac-reduced",
        "k4.csv",
    ] {
        assert!(line.contains(s), "`{s}` not in: {line}");
    }
    simulate(&dir, "k1", "seed-ac-reduced", "k1.csv", &[]);
    let csv = std::fs::read_to_string(dir.join("k4.csv")).unwrap();
    assert!(csv.starts_with("# simulated by rtest"), "{csv}");
    assert!(csv.contains("# path: K4 (241 samples)"), "{csv}");
    let header = csv.lines().find(|l| !l.starts_with('#')).unwrap();
    assert_eq!(header, "X,Y,Z,A,C,dx_um,dy_um,dz_um,t_s");
    assert_eq!(data_rows(&csv).len(), 241);

    let text = ok(
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
        ],
    );
    for s in [
        "model reduced (11 parameters)",
        "refined against the exact machine",
        "rank 11 of 11",
        "condition number 36.7",
        "residual RMS",
        "σ̂",
        "confounded groups: none",
        "near-confounded pairs (|corr| > 0.99): none",
        "µrad",
        "Wrote id.json",
    ] {
        assert!(text.contains(s), "`{s}` not in:\n{text}");
    }
    let json = read_json(&dir.join("id.json"));
    assert_eq!(json["machine"], "seed-ac");
    assert_eq!(json["model"], "reduced");
    assert_eq!(json["rank"], 11);
    assert!(json["condition"].as_f64().unwrap() > 1.0);
    assert_eq!(json["confounded"].as_array().unwrap().len(), 0);
    assert!(json["residual_rms_um"].as_f64().unwrap() < 1e-6);
    let params = json["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 11);
    let values = truth_values(&m, &t);
    assert_eq!(values.len(), 11);
    for (name, want) in &values {
        let p = param(&json, name);
        let got = p["value"].as_f64().unwrap();
        assert!(
            (got - want).abs() < 1e-4,
            "{name}: {got} vs truth {want} (µm or µrad)"
        );
        assert!(p["std"].as_f64().unwrap() >= 0.0);
        let e = m.error_by_name(name).unwrap();
        let unit = if m.catalogue[e].is_angular() {
            "urad"
        } else {
            "um"
        };
        assert_eq!(p["unit"], unit, "{name}");
        // The text row has the value.
        let row = text.lines().find(|l| l.starts_with(name.as_str())).unwrap();
        assert!(row.contains(&format!("{want:.4}")), "{row}");
    }

    let text = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--json",
            "v.json",
        ],
    );
    for s in [
        "361 samples",
        "exact virtual machine",
        "before",
        "after",
        "all",
    ] {
        assert!(text.contains(s), "`{s}` not in:\n{text}");
    }
    assert!(!text.contains("Set to 0"), "{text}");
    let v = read_json(&dir.join("v.json"));
    assert_eq!(v["data"], "k1.csv");
    assert_eq!(v["samples"], 361);
    assert!(v["residual_rms_um"].as_f64().unwrap() < 1e-3, "{v}");
    assert!(v["measured_rms_um"].as_f64().unwrap() > 5.0, "{v}");
    for d in ["x", "y", "z"] {
        let s = &v["per_direction"][d];
        for k in [
            "measured_rms_um",
            "measured_max_um",
            "residual_rms_um",
            "residual_max_um",
        ] {
            assert!(s[k].as_f64().is_some(), "{d}.{k} in {v}");
        }
        assert!(s["residual_max_um"].as_f64().unwrap() < 1e-3);
    }
    // RMS over all three directions is sqrt(Σ r² / 3N).
    let per: f64 = ["x", "y", "z"]
        .iter()
        .map(|d| {
            v["per_direction"][*d]["measured_rms_um"]
                .as_f64()
                .unwrap()
                .powi(2)
        })
        .sum();
    let all = v["measured_rms_um"].as_f64().unwrap();
    assert!((all - (per / 3.0).sqrt()).abs() < 1e-9 * all, "{v}");

    // The first-order prediction differs by the second-order terms only.
    ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--first-order",
            "--json",
            "v1.json",
        ],
    );
    let v1 = read_json(&dir.join("v1.json"));
    let r1 = v1["residual_rms_um"].as_f64().unwrap();
    assert!(
        r1 < 1e-2 && r1 > v["residual_rms_um"].as_f64().unwrap(),
        "{v1}"
    );

    // Without the refinement the values carry the second-order bias, still small.
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--first-order",
            "--json",
            "id1.json",
        ],
    );
    assert!(
        text.contains("first order (not refined against the exact machine)"),
        "{text}"
    );
    let j1 = read_json(&dir.join("id1.json"));
    let worst = values
        .iter()
        .map(|(n, w)| (param(&j1, n)["value"].as_f64().unwrap() - w).abs())
        .fold(0.0, f64::max);
    assert!(worst > 1e-5 && worst < 1e-2, "first-order bias {worst}");
}

#[test]
fn zeroed_readings_name_what_the_offsets_swallow() {
    let dir = temp_dir("zeroed");
    let m = machine();
    let t = truth(&m, "seed-ac-reduced");
    let line = simulate(&dir, "K4", "seed-ac-reduced", "k4.csv", &["--zeroed"]);
    assert!(line.contains("zeroed at the first sample"), "{line}");
    simulate(&dir, "K1", "seed-ac-reduced", "k1.csv", &["--zeroed"]);
    let rows = data_rows(&std::fs::read_to_string(dir.join("k4.csv")).unwrap());
    assert_eq!(
        &rows[0][5..8],
        &[0.0, 0.0, 0.0],
        "zeroed at the first sample"
    );

    let args = [
        "identify",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
        "--zeroed",
        "--json",
        "id.json",
    ];
    let text = ok(&dir, &args);
    for s in [
        "dx0 swallows XOC",
        "dy0 swallows YOA",
        "dz0 swallows ZOA",
        "not determined: confounded with dx0",
        "rank 11 of 14",
    ] {
        assert!(text.contains(s), "`{s}` not in:\n{text}");
    }
    let xoc = text.lines().find(|l| l.starts_with("XOC")).unwrap();
    assert_eq!(
        xoc.split_whitespace().collect::<Vec<_>>(),
        ["XOC", "not", "determined:", "confounded", "with", "dx0"],
        "no number for XOC"
    );
    let json = read_json(&dir.join("id.json"));
    assert_eq!(json["zeroed"], true);
    assert_eq!(json["parameters"].as_array().unwrap().len(), 14);
    for name in ["XOC", "YOA", "ZOA", "dx0", "dy0", "dz0"] {
        assert!(param(&json, name)["value"].is_null(), "{name}: {json}");
        assert!(param(&json, name)["std"].is_null(), "{name}");
    }
    assert_eq!(
        groups(&json),
        sorted(&[&["XOC", "dx0"], &["YOA", "dy0"], &["ZOA", "dz0"]])
    );
    // The other eight values are still right.
    for (name, want) in truth_values(&m, &t) {
        if ["XOC", "YOA", "ZOA"].contains(&name.as_str()) {
            continue;
        }
        let got = param(&json, &name)["value"].as_f64().unwrap();
        assert!((got - want).abs() < 1e-4, "{name}: {got} vs {want}");
    }

    // Zeroed validation: constant effects cancel (the record's zero refitted on it); the
    // parameters set to 0 are named.
    let text = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--zeroed",
            "--json",
            "v.json",
        ],
    );
    assert!(
        text.contains("Set to 0") && text.contains("XOC") && text.contains("dx0"),
        "{text}"
    );
    let v = read_json(&dir.join("v.json"));
    assert_eq!(v["zeroed"], true);
    assert!(v["residual_rms_um"].as_f64().unwrap() < 1e-3, "{v}");
    let unset: Vec<&str> = v["unidentified_set_to_zero"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert_eq!(unset, ["YOA", "ZOA", "XOC"]);
    // The record's own zero is refitted on it (its readings were zeroed at their first sample).
    let refitted: Vec<&str> = v["records"][0]["refitted"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(refitted, ["dx0[k1]", "dy0[k1]", "dz0[k1]"]);
    // Without --zeroed, the zeroed file is noticed.
    let text = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
        ],
    );
    assert!(text.contains("give --zeroed"), "{text}");
    // Refusing undetermined parameters is an error, and writes nothing.
    fails(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--zeroed",
            "--refuse-undetermined",
            "--json",
            "refused.json",
        ],
        1,
        &["--params", "id.json", "XOC", "--refuse-undetermined"],
    );
    assert!(!dir.join("refused.json").exists());

    // A constraint fixes the swallowed errors to 0 and determines the offsets.
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--zeroed",
            "--constraint",
            "zero:X0C,YOA,ZOA",
            "--json",
            "fixed.json",
        ],
    );
    assert!(text.contains("fixed to 0 by --constraint"), "{text}");
    assert!(text.contains("confounded groups: none"), "{text}");
    let json = read_json(&dir.join("fixed.json"));
    assert_eq!(param(&json, "XOC")["value"], 0.0);
    assert!(param(&json, "XOC")["std"].is_null());
    for name in ["dx0", "dy0", "dz0"] {
        assert!(param(&json, name)["value"].is_number(), "{name}");
    }
    assert!(json["constraint"].as_str().unwrap().starts_with("zero"));
}

#[test]
fn k1_alone_cannot_separate_the_reduced_model() {
    let dir = temp_dir("k1-alone");
    simulate(&dir, "K1", "seed-ac-reduced", "k1.csv", &[]);
    simulate(&dir, "K2", "seed-ac-reduced", "k2.csv", &[]);
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k1.csv",
            "--json",
            "id.json",
        ],
    );
    for s in [
        "rank 7 of 11",
        "not determined: confounded with",
        "confounded groups (the data cannot separate them",
    ] {
        assert!(text.contains(s), "`{s}` not in:\n{text}");
    }
    let json = read_json(&dir.join("id.json"));
    assert_eq!(json["rank"], 7);
    assert_eq!(
        groups(&json),
        sorted(&[
            &["XOW", "YOW", "COA"],
            &["ZOW", "ZOA"],
            &["YOA", "YOC"],
            &["BOA", "XOC", "BOC"],
        ])
    );
    for p in json["parameters"].as_array().unwrap() {
        if p["error"] == "AOC" {
            let v = p["value"].as_f64().unwrap();
            assert!((v - 30.0).abs() < 1e-2, "AOC {v}");
        } else {
            assert!(p["value"].is_null() && p["std"].is_null(), "{p}");
            let row = text
                .lines()
                .find(|l| l.starts_with(p["error"].as_str().unwrap()))
                .unwrap();
            assert!(row.contains("not determined: confounded with"), "{row}");
        }
    }
    // Validating with it says which parameters were set to 0.
    let text = ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k2.csv",
        ],
    );
    assert!(text.contains("Set to 0") && text.contains("BOC"), "{text}");
    // A documented constraint gives every parameter a value, said to be a convention.
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k1.csv",
            "--constraint",
            "min-norm",
            "--json",
            "mn.json",
        ],
    );
    assert!(text.contains("minimum-norm value"), "{text}");
    let json = read_json(&dir.join("mn.json"));
    assert!(
        json["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .all(|p| p["value"].is_number())
    );
    assert_eq!(json["constraint"], "minimum-norm");
}

#[test]
fn terms_extend_a_model_or_stand_alone() {
    let dir = temp_dir("terms");
    // The demo truth has ECC twice per revolution, which the reduced model lacks.
    simulate(&dir, "K4", "seed-ac-demo", "k4.csv", &[]);
    simulate(
        &dir,
        "K1",
        "seed-ac-demo",
        "k1.csv",
        &["--seed", "2", "--noise-um", "0.5"],
    );
    let text = ok(
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
            "k4.csv",
            "--json",
            "ext.json",
        ],
    );
    assert!(
        text.contains("model reduced + ECC@harmonic:2 (13 parameters)"),
        "{text}"
    );
    let json = read_json(&dir.join("ext.json"));
    assert_eq!(json["model"], "reduced + ECC@harmonic:2");
    let ecc: Vec<&Value> = json["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["error"] == "ECC")
        .collect();
    assert_eq!(ecc.len(), 2);
    for (p, (basis, want)) in ecc
        .iter()
        .zip([("harmonic:2:cos", 8.0), ("harmonic:2:sin", 6.0)])
    {
        assert_eq!(p["basis"], basis);
        assert_eq!(p["unit"], "urad");
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        assert!((v - want).abs() < 4.0 * s, "{basis}: {v} ± {s} vs {want}");
    }
    // With ECC in the model the residual is the noise; validate reads the harmonic back.
    assert!(json["residual_rms_um"].as_f64().unwrap() < 0.6, "{json}");
    ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "ext.json",
            "--data",
            "k1.csv",
            "--json",
            "v.json",
        ],
    );
    let v = read_json(&dir.join("v.json"));
    assert!(v["residual_rms_um"].as_f64().unwrap() < 0.6, "{v}");

    // Terms alone.
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--terms",
            "XOC, YOC,dx0@time:1",
            "--data",
            "k4.csv",
            "--first-order",
            "--json",
            "alone.json",
        ],
    );
    assert!(text.contains("model XOC + YOC + dx0@time:1"), "{text}");
    let json = read_json(&dir.join("alone.json"));
    assert_eq!(json["parameters"].as_array().unwrap().len(), 3);
    assert_eq!(json["parameters"][2]["basis"], "time:1");
}

#[test]
fn simulate_overrides_defaults_path_files_and_truth_files() {
    let dir = temp_dir("simulate");
    // Default truth of seed-ac: its demo truth.
    let line = ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K2",
            "-o",
            "k2.csv",
        ],
    );
    assert!(
        line.contains("truth seed-ac-demo") && line.contains("121 samples"),
        "{line}"
    );
    // Same seed, same readings; another seed, others.
    let run = |out: &str, seed: &str| {
        ok(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K2",
                "--seed",
                seed,
                "-o",
                out,
            ],
        );
        data_rows(&std::fs::read_to_string(dir.join(out)).unwrap())
    };
    let (a, b, c) = (run("a.csv", "5"), run("b.csv", "5"), run("c.csv", "6"));
    assert_eq!(a, b);
    assert_ne!(a, c);
    // No noise: the readings are the truth's exact values.
    let line = ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K2",
            "--noise-um",
            "0",
            "-o",
            "quiet.csv",
        ],
    );
    assert!(line.contains("noise 0 µm"), "{line}");

    // A path file (rotary axes only: the linear axes come from the inverse kinematics) and a
    // truth file.
    std::fs::write(
        dir.join("path.csv"),
        "# a few poses\nA,C\n0,0\n-30,45\n-60,90\n-90,180\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("truth.toml"),
        "machine = \"seed-ac\"\nnoise_um = 0\n[errors]\nXOC = 10.0\n",
    )
    .unwrap();
    let line = ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "path.csv",
            "--truth",
            "truth.toml",
            "-o",
            "p.csv",
        ],
    );
    assert!(line.contains("4 samples"), "{line}");
    let rows = data_rows(&std::fs::read_to_string(dir.join("p.csv")).unwrap());
    assert_eq!(rows.len(), 4);
    for r in &rows {
        // XOC moves the ball by -1 along x of the tool frame at every pose.
        assert!((r[5] + 10.0).abs() < 1e-9, "{r:?}");
        assert!(r[6].abs() < 1e-9 && r[7].abs() < 1e-9, "{r:?}");
    }
    // A machine given as a file identifies with the evaluator and agrees with the built-in.
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "seed-ac")
        .unwrap()
        .1;
    // (renamed: a file identical to the built-in description uses its compiled code)
    let text = text.replacen("name = \"seed-ac\"", "name = \"my-seed\"", 1);
    assert!(text.contains("my-seed"));
    std::fs::write(dir.join("my-seed.toml"), text).unwrap();
    simulate(&dir, "K4", "seed-ac-reduced", "k4.csv", &[]);
    let id = |machine: &str, out: &str| {
        ok(
            &dir,
            &[
                "identify",
                "--machine",
                machine,
                "--model",
                "reduced",
                "--data",
                "k4.csv",
                "--json",
                out,
            ],
        )
    };
    let file_text = id("my-seed.toml", "file.json");
    id("seed-ac", "builtin.json");
    let (f, b) = (
        read_json(&dir.join("file.json")),
        read_json(&dir.join("builtin.json")),
    );
    assert_eq!(b["gains"], "compiled");
    assert_eq!(f["gains"], "evaluator");
    assert!(file_text.contains("in-process evaluator"), "{file_text}");
    for (p, q) in f["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .zip(b["parameters"].as_array().unwrap())
    {
        let (x, y) = (p["value"].as_f64().unwrap(), q["value"].as_f64().unwrap());
        assert!((x - y).abs() < 1e-9, "{p} vs {q}");
    }
}

// ---------------------------------------------------------------- demo

/// The shift the demo truth's terms outside the reduced model put into the reduced model's
/// values on K4 (µm or µrad, model order): the first-order fit of their noise-free readings.
fn hidden_bias(m: &Machine, t: &Truth, k4: &Record) -> Vec<f64> {
    let reduced = Model::of(m, "reduced").unwrap();
    let hidden = Model {
        terms: t
            .model
            .terms
            .iter()
            .filter(|x| !reduced.terms.contains(x))
            .copied()
            .collect(),
    };
    let values: Vec<Option<f64>> = hidden
        .terms
        .iter()
        .flat_map(|x| t.coefficient(x).unwrap().to_vec())
        .map(Some)
        .collect();
    let measured =
        fitting::refine::exact_prediction(m, &hidden, &values, k4, &t.params).expect("prediction");
    let alone = Record {
        samples: k4.samples.clone(),
        measured,
        lines: k4.lines.clone(),
        ..Default::default()
    };
    let fit = identify_one(m, &reduced, &alone, &IdentifyOptions::default()).expect("identify");
    reduced
        .terms
        .iter()
        .zip(&fit.fit.values)
        .map(|(x, v)| v.unwrap() * x.effect.display_factor(m))
        .collect()
}

#[test]
fn demo_writes_everything_and_recovers_the_demo_truth() {
    let dir = temp_dir("demo");
    let start = std::time::Instant::now();
    let out = ok(&dir, &["demo"]);
    let elapsed = start.elapsed();
    // What the demo diagnoses (the same steps as `rtest diagnose`), checked on this one run.
    {
        for s in [
            "Diagnosis (rtest diagnose --machine seed-ac --model reduced --data rtest-demo/k4.csv --validate rtest-demo/k1.csv,rtest-demo/k2.csv)",
            "  1. ECC harmonic:2: angular positioning error of C, twice per revolution: ",
            "rtest-demo/k1.csv (held out)",
            "Check against the truth",
            "ECC@harmonic:2 found: ",
            "against the truth 8, 6 µrad",
            "rtest-demo/diagnose.json",
            "rtest-demo/seed-ac-extended.toml",
            "rtest-demo/k4-path.svg",
            "rtest-demo/k2-spectrum.svg",
        ] {
            assert!(out.contains(s), "`{s}` not in:\n{out}");
        }
        // The hand-made extension from the truth is gone.
        assert!(!out.contains("Added to the model"), "{out}");
        assert!(!out.contains("NOT found") && !out.contains("false finding"));
        let demo = dir.join("rtest-demo");
        let j = read_json(&demo.join("diagnose.json"));
        assert_eq!(j["findings"][0]["error"], "ECC");
        assert_eq!(j["findings"][0]["basis"], "harmonic:2");
        for v in j["gain"]["validation"].as_array().unwrap() {
            assert!(num(&v["residual_rms_um_after"]) < 0.5 * num(&v["residual_rms_um_before"]));
        }
        ok(
            &demo,
            &[
                "identify",
                "--machine",
                "seed-ac-extended.toml",
                "--model",
                "extended",
                "--data",
                "k4.csv",
            ],
        );
    }
    let files = [
        "compensate-k1.json",
        "diagnose.json",
        "gains-reduced.md",
        "identify-recommended.json",
        "identify.json",
        "k1-compensated.csv",
        "k1-path.svg",
        "k1-spectrum.svg",
        "k1.csv",
        "k2-path.svg",
        "k2-spectrum.svg",
        "k2.csv",
        "k4-path.svg",
        "k4-spectrum.svg",
        "k4.csv",
        "report-compensation.html",
        "report.html",
        "rtest-history.sqlite",
        "seed-ac-extended.toml",
        "seed_ac.rs",
        "validate-k1.json",
        "validate-k2.json",
    ];
    let demo = dir.join("rtest-demo");
    assert_eq!(entries(&demo), files);
    for f in files {
        assert!(
            out.contains(&format!("rtest-demo/{f}")),
            "{f} not listed:\n{out}"
        );
    }
    for s in [
        "seed-ac-demo",
        "Table 4",
        "±12 µm",
        "±15 µm",
        "K4 (fit)",
        "ECC@harmonic:2",
        "Left unexplained",
        "operations",
        "Compensated (rtest compensate) with reduced + ECC@harmonic:2",
    ] {
        assert!(out.contains(s), "`{s}` not in:\n{out}");
    }
    // Compensation with the recommended model leaves under a tenth of the machine's error on
    // the held-out paths, and its summary is what `compensate --json` writes.
    for path in ["K1", "K2"] {
        let line = out
            .lines()
            .find(|l| {
                l.trim_start().starts_with(&format!("{path}: ")) && l.contains("compensated (")
            })
            .unwrap_or_else(|| panic!("no compensation line for {path}:\n{out}"));
        let less: f64 = line
            .rsplit('(')
            .next()
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(less >= 90.0, "{line}");
    }
    // The report of the check says where the compensation is; that report shows it.
    let html = std::fs::read_to_string(demo.join("report.html")).unwrap();
    assert!(
        html.contains("rtest-demo/report-compensation.html is the report of that compensation"),
        "report.html"
    );
    let html = std::fs::read_to_string(demo.join("report-compensation.html")).unwrap();
    assert!(html.contains("identify-recommended.json (model reduced + ECC@harmonic:2)"));
    assert!(!html.contains("No compensation in this report"));
    let summary = read_json(&demo.join("compensate-k1.json"));
    assert_eq!(summary["poses"], 361);
    assert!(summary["position_remainder_um"].as_f64().unwrap() < 1e-3);
    println!("demo: {:.2} s (debug build)", elapsed.as_secs_f64());

    let m = machine();
    let t = truth(&m, "seed-ac-demo");
    let k4 = formats::csv::read_measurement(
        &demo.join("k4.csv"),
        &m,
        &formats::csv::ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(k4.samples.len(), 241);
    let json = read_json(&demo.join("identify.json"));
    assert_eq!(json["machine"], "seed-ac");
    assert_eq!(json["model"], "reduced");
    let params = json["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 11);
    // Every value is within 4 std of the truth once the bias of the hidden ECC term (which the
    // reduced model lacks and the std, describing the noise only, does not cover) is removed.
    let truth = truth_values(&m, &t);
    let bias = hidden_bias(&m, &t, &k4);
    let reduced = Model::of(&m, "reduced").unwrap();
    for ((p, term), b) in params.iter().zip(&reduced.terms).zip(&bias) {
        let name = term.effect.name(&m);
        assert_eq!(p["error"], name.as_str());
        let want = truth.iter().find(|(n, _)| *n == name).unwrap().1;
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        println!(
            "{name}: {v:.4} ± {s:.4}, truth {want}, z {:+.2}, hidden bias {b:+.4}, z without it {:+.2}",
            (v - want) / s,
            (v - want - b) / s
        );
        assert!(
            (v - want - b).abs() <= 4.0 * s,
            "{name}: {v} ± {s}, truth {want}, bias {b}"
        );
    }
    for (name, n) in [("validate-k1.json", 361), ("validate-k2.json", 121)] {
        let v = read_json(&demo.join(name));
        assert_eq!(v["samples"], n, "{name}");
        let (before, after) = (
            v["measured_rms_um"].as_f64().unwrap(),
            v["residual_rms_um"].as_f64().unwrap(),
        );
        assert!(after < before / 5.0 && after < 3.0, "{name}: {v}");
        assert!(after > 0.4, "{name}: the noise and ECC remain: {v}");
    }
    // The demo's identification is what `rtest identify` gives on its file by ordinary least
    // squares (the demo does not estimate the noise).
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "rtest-demo/k4.csv",
            "--noise",
            "white",
            "--json",
            "again.json",
        ],
    );
    let again = read_json(&dir.join("again.json"));
    assert_eq!(again["parameters"], json["parameters"]);
    // So is its validation.
    ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "rtest-demo/identify.json",
            "--data",
            "rtest-demo/k1.csv",
            "--json",
            "v1.json",
        ],
    );
    // (to rounding: the values went through the JSON in µm and µrad)
    assert_close(
        &read_json(&dir.join("v1.json")),
        &read_json(&demo.join("validate-k1.json")),
    );
    let code = std::fs::read_to_string(demo.join("seed_ac.rs")).unwrap();
    assert!(code.contains("pub fn gains") && !code.contains("#!["));
    let md = std::fs::read_to_string(demo.join("gains-reduced.md")).unwrap();
    assert!(md.lines().any(|l| l.starts_with('|') && l.contains("BOA")));

    // Running it again replaces the files and leaves no temporary file.
    ok(&dir, &["demo"]);
    assert_eq!(entries(&demo), files);
}

// ---------------------------------------------------------------- help

#[test]
fn help_says_what_each_verb_does_with_units_and_exit_codes() {
    let dir = temp_dir("help");
    for verb in ["simulate", "identify", "validate", "demo"] {
        let help = ok(&dir, &[verb, "--help"]);
        for s in ["Exit codes: 0 success; 1 bad input", "µm", "mm", "degrees"] {
            assert!(help.contains(s), "{verb}: `{s}` not in:\n{help}");
        }
    }
    let identify = ok(&dir, &["identify", "--help"]);
    for s in [
        "µrad",
        "--first-order",
        "second-order",
        "1e-3 µm",
        "--constraint",
        "min-norm",
        "zero:NAME",
        "--terms",
        "ECC@harmonic:2",
        "dx0 dy0 dz0",
        "not determined",
    ] {
        assert!(identify.contains(s), "`{s}` not in identify --help");
    }
    let validate = ok(&dir, &["validate", "--help"]);
    for s in ["--refuse-undetermined", "set to 0", "before", "after"] {
        assert!(validate.contains(s), "`{s}` not in validate --help");
    }
    let simulate = ok(&dir, &["simulate", "--help"]);
    for s in ["K4", "seed-ac-demo", "--noise-um", "--zeroed", "µrad"] {
        assert!(simulate.contains(s), "`{s}` not in simulate --help");
    }
}

// ---------------------------------------------------------------- bad input

/// A directory with a good K4 measurement and identify JSON, for the bad-input tests.
fn prepared(name: &str) -> TempDir {
    let dir = temp_dir(name);
    simulate(&dir, "K4", "seed-ac-reduced", "k4.csv", &[]);
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--first-order",
            "--json",
            "id.json",
        ],
    );
    dir
}

const PREPARED: [&str; 2] = ["id.json", "k4.csv"];

#[test]
fn missing_and_unknown_flags_are_usage_errors() {
    let dir = prepared("flags");
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["simulate", "--machine", "seed-ac", "-o", "x.csv"],
            &["--path"],
        ),
        (
            &["simulate", "--machine", "seed-ac", "--path", "K4"],
            &["--output"],
        ),
        (&["simulate", "--path", "K4", "-o", "x.csv"], &["--machine"]),
        (
            &["identify", "--machine", "seed-ac", "--model", "reduced"],
            &["--data"],
        ),
        (
            &["identify", "--machine", "seed-ac", "--data", "k4.csv"],
            &["--model", "--terms"],
        ),
        (
            &["validate", "--machine", "seed-ac", "--data", "k4.csv"],
            &["--params"],
        ),
        (
            &["validate", "--machine", "seed-ac", "--params", "id.json"],
            &["--data"],
        ),
        (
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "-o",
                "x.csv",
                "--bogus",
            ],
            &["--bogus", "rtest simulate --help"],
        ),
        (
            &[
                "identify",
                "--machine",
                "seed-ac",
                "--model",
                "reduced",
                "--data",
                "k4.csv",
                "--bogus",
            ],
            &["--bogus", "rtest identify --help"],
        ),
        (
            &[
                "validate",
                "--machine",
                "seed-ac",
                "--params",
                "id.json",
                "--data",
                "k4.csv",
                "--json",
                "v.json",
                "--bogus",
            ],
            &["--bogus", "rtest validate --help"],
        ),
        (&["demo", "--bogus"], &["--bogus"]),
        (
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "--seed",
                "x",
                "-o",
                "x.csv",
            ],
            &["--seed", "'x'"],
        ),
        (
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "--seed",
                "-1",
                "-o",
                "x.csv",
            ],
            &["-1"],
        ),
        (
            &[
                "identify",
                "--machine",
                "nope",
                "--model",
                "reduced",
                "--data",
                "k4.csv",
            ],
            &["--machine", "`nope`"],
        ),
        (
            &[
                "identify",
                "--machine",
                "seed-ac",
                "--model",
                "tiny",
                "--data",
                "k4.csv",
            ],
            &["--model", "`tiny`", "reduced"],
        ),
    ];
    for (args, needles) in cases {
        fails(&dir, args, 2, needles);
    }
    assert_eq!(entries(&dir), PREPARED, "no output file left behind");
}

#[test]
fn malformed_measurement_files_name_file_line_and_column() {
    let dir = prepared("bad-csv");
    let header = "X,Y,Z,A,C,dx_um,dy_um,dz_um\n";
    let good = "217.504,-0.279,56.661,0,0,1,2,3\n";
    let cases: &[(&str, String, &[&str])] = &[
        (
            "text.csv",
            format!("{header}{good}217.504,-0.279,56.661,0,1,1,2,abc\n"),
            &["text.csv:3:", "column 8 `dz_um`", "`abc` is not a number"],
        ),
        (
            "nan.csv",
            format!("{header}{good}217.504,-0.279,56.661,0,1,NaN,2,3\n"),
            &["nan.csv:3:", "column 6 `dx_um`", "finite"],
        ),
        (
            "ragged.csv",
            format!("# comment\n{header}{good}1,2,3\n"),
            &["ragged.csv:4:", "ragged row"],
        ),
        (
            "unknown.csv",
            format!("X,Y,Z,A,B,dx_um,dy_um,dz_um\n{good}"),
            &["unknown.csv:1:", "column 5 `B`", "unknown column"],
        ),
        (
            "missing.csv",
            "X,Y,Z,A,C,dx_um,dy_um\n217.504,-0.279,56.661,0,0,1,2\n".to_string(),
            &["missing.csv:1:", "dz_um"],
        ),
        ("empty.csv", String::new(), &["empty.csv:1:", "empty file"]),
        (
            "header-only.csv",
            header.to_string(),
            &["header-only.csv:1:", "no samples"],
        ),
    ];
    for (name, text, needles) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let mut n = vec!["--data"];
        n.extend_from_slice(needles);
        fails(
            &dir,
            &[
                "identify",
                "--machine",
                "seed-ac",
                "--model",
                "reduced",
                "--data",
                name,
                "--json",
                "out.json",
            ],
            1,
            &n,
        );
        fails(
            &dir,
            &[
                "validate",
                "--machine",
                "seed-ac",
                "--params",
                "id.json",
                "--data",
                name,
                "--json",
                "out.json",
            ],
            1,
            &n,
        );
        std::fs::remove_file(dir.join(name)).unwrap();
    }
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--data",
            "absent.csv",
        ],
        1,
        &["--data", "cannot read `absent.csv`"],
    );
    // A malformed path file.
    std::fs::write(dir.join("path.csv"), "A,C\n0,0\n10,x\n").unwrap();
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "path.csv",
            "-o",
            "out.csv",
        ],
        1,
        &["--path", "path.csv:3:", "column 2 `C`"],
    );
    std::fs::remove_file(dir.join("path.csv")).unwrap();
    assert_eq!(entries(&dir), PREPARED, "no output file left behind");
}

#[test]
fn bad_truths_paths_terms_constraints_and_params() {
    let dir = prepared("bad-args");
    let sim = |extra: &[&'static str]| {
        let mut a = vec!["simulate", "--machine", "seed-ac", "-o", "out.csv"];
        a.extend_from_slice(extra);
        a
    };
    fails(
        &dir,
        &sim(&["--path", "K4", "--truth", "nope"]),
        2,
        &["--truth", "`nope`", "seed-ac-demo"],
    );
    fails(
        &dir,
        &sim(&["--path", "K7"]),
        2,
        &["--path", "`K7`", "K1, K2, K4"],
    );
    fails(
        &dir,
        &sim(&["--path", "K4", "--noise-um", "-0.5"]),
        2,
        &["--noise-um", "`-0.5`"],
    );
    fails(
        &dir,
        &sim(&["--path", "K4", "--noise-um", "abc"]),
        2,
        &["--noise-um", "`abc`", "not a number"],
    );
    fails(
        &dir,
        &sim(&["--path", "K4", "--noise-um", "inf"]),
        2,
        &["--noise-um", "finite"],
    );
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "head-table-bc",
            "--path",
            "K4",
            "-o",
            "out.csv",
        ],
        2,
        &["--path", "A and C", "head-table-bc"],
    );
    std::fs::write(
        dir.join("bad.toml"),
        "noise_um = 0.5\n[errors]\nFOO = 1.0\n",
    )
    .unwrap();
    fails(
        &dir,
        &sim(&["--path", "K4", "--truth", "bad.toml"]),
        1,
        &["--truth", "bad.toml:3:1", "`FOO`"],
    );
    std::fs::remove_file(dir.join("bad.toml")).unwrap();

    let id = |extra: &[&'static str]| {
        let mut a = vec![
            "identify",
            "--machine",
            "seed-ac",
            "--data",
            "k4.csv",
            "--json",
            "out.json",
        ];
        a.extend_from_slice(extra);
        a
    };
    for (terms, needles) in [
        ("FOO", &["`FOO`", "seed-ac", "rtest machines"][..]),
        ("ECC@harm:2", &["`ECC@harm:2`", "unknown basis"][..]),
        ("EXX@harmonic:2", &["`EXX@harmonic:2`", "rotary axis"][..]),
        ("XOW@poly:1", &["`XOW@poly:1`", "linear axis"][..]),
        ("ECC@harmonic:0", &["harmonic:K", "1 to 64"][..]),
        ("XOC,,YOC", &["empty item"][..]),
        ("", &["empty list"][..]),
        ("XOC,X0C", &["`X0C`", "twice"][..]),
    ] {
        let mut n = vec!["--terms"];
        n.extend_from_slice(needles);
        fails(&dir, &id(&["--terms", terms]), 2, &n);
    }
    fails(
        &dir,
        &id(&["--model", "reduced", "--terms", "XOC"]),
        2,
        &["--terms", "`XOC`", "already in model reduced"],
    );
    for (c, needles) in [
        ("foo", &["`foo`", "min-norm", "zero:NAME"][..]),
        ("zero:", &["empty list"][..]),
        ("zero:XOC,XOC", &["`XOC`", "twice"][..]),
        ("zero:FOO", &["`FOO`", "not a parameter", "BOC"][..]),
        ("zero:ECC", &["`ECC`", "not a parameter"][..]),
    ] {
        let mut n = vec!["--constraint"];
        n.extend_from_slice(needles);
        fails(&dir, &id(&["--model", "reduced", "--constraint", c]), 2, &n);
    }

    // Params JSON: another machine, not JSON, a wrong field, absent.
    let other = std::fs::read_to_string(dir.join("id.json"))
        .unwrap()
        .replace("\"seed-ac\"", "\"seed-3axis\"");
    std::fs::write(dir.join("other.json"), other).unwrap();
    std::fs::write(dir.join("junk.json"), "{ not json").unwrap();
    let unit = std::fs::read_to_string(dir.join("id.json"))
        .unwrap()
        .replacen("\"urad\"", "\"um\"", 1);
    std::fs::write(dir.join("unit.json"), unit).unwrap();
    let val = |params: &'static str| {
        vec![
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            params,
            "--data",
            "k4.csv",
            "--json",
            "out.json",
        ]
    };
    fails(
        &dir,
        &val("other.json"),
        1,
        &["--params", "other.json", "machine", "seed-3axis"],
    );
    fails(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-3axis",
            "--params",
            "id.json",
            "--data",
            "k4.csv",
        ],
        1,
        &["--params", "id.json", "seed-ac", "not `seed-3axis`"],
    );
    fails(
        &dir,
        &val("junk.json"),
        1,
        &["--params", "junk.json", "not valid JSON"],
    );
    fails(
        &dir,
        &val("unit.json"),
        1,
        &["--params", "unit.json", "unit"],
    );
    fails(
        &dir,
        &val("absent.json"),
        1,
        &["--params", "absent.json", "cannot read"],
    );
    for f in ["other.json", "junk.json", "unit.json"] {
        std::fs::remove_file(dir.join(f)).unwrap();
    }
    assert_eq!(entries(&dir), PREPARED, "no output file left behind");
}

#[test]
fn unwritable_outputs_leave_nothing_behind() {
    let dir = prepared("unwritable");
    std::fs::create_dir(dir.join("sub")).unwrap();
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "-o",
            "no-such-dir/k4.csv",
        ],
        1,
        &["-o", "cannot write", "no-such-dir"],
    );
    fails(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            "K4",
            "-o",
            "sub",
        ],
        1,
        &["-o", "directory"],
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
            "k4.csv",
            "--json",
            "sub",
        ],
        1,
        &["--json", "directory"],
    );
    fails(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k4.csv",
            "--json",
            "no-such-dir/v.json",
        ],
        1,
        &["--json", "cannot write"],
    );
    assert_eq!(entries(&dir), ["id.json", "k4.csv", "sub"]);
    assert!(entries(&dir.join("sub")).is_empty());
    // A demo that cannot create its directory writes nothing.
    std::fs::write(dir.join("rtest-demo"), "in the way").unwrap();
    fails(&dir, &["demo"], 1, &["demo", "rtest-demo"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("rtest-demo")).unwrap(),
        "in the way"
    );
}
