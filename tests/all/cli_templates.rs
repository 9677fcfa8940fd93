//! The built-in machine templates through the command line: `rtest machines` shows each
//! family in one line; `rtest path --list` offers a turn of every rotary axis of every template,
//! every test within its limits; and `rtest simulate` on each of a template's tests, then
//! `rtest identify` on all of them together (one ball set-up), recovers a truth with location
//! errors of every rotary axis and the ball's set-up errors: every parameter the paths determine
//! within 4 standard uncertainties, the others reported as confounded (`null`).

use crate::common;

use common::{ok, read_json, temp_dir_tagged};
use serde_json::Value;

fn temp_dir(name: &str) -> common::TempDir {
    temp_dir_tagged("templates", name)
}

/// The templates with rotary axes, and what their own paths cannot separate (set-up errors
/// named with their set-up, `s`); the reasons are given in `fitting/tests/all/templates.rs`.
const TEMPLATES: [(&str, &[&[&str]]); 6] = [
    (
        "head-table-bc",
        &[&["AOZ", "YOC"], &["XOB", "XOC"], &["ZOB", "ZOW[s]"]],
    ),
    ("table-table-bc", &[]),
    (
        "head-head-ca",
        &[&["XOC", "XOW[s]"], &["YOC", "YOW[s]"], &["ZOA", "ZOW[s]"]],
    ),
    (
        "nutating-head-bc",
        &[&["XOB", "XOC"], &["YOB", "YOC", "ZOW[s]"]],
    ),
    ("nutating-table-bc", &[]),
    // One test path: a campaign of one record, whose report names its columns as a single
    // identification does (no set-up label).
    (
        "horizontal-4axis-b",
        &[&["COY", "XOB"], &["AOZ", "YOW", "ZOB"]],
    ),
];

#[test]
fn machines_shows_every_family_in_one_line() {
    let dir = temp_dir("machines");
    let out = ok(&dir, &["machines"]);
    let line = |name: &str| {
        out.lines()
            .find(|l| l.starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("no line for {name}:\n{out}"))
            .to_string()
    };
    for (name, family) in [
        ("seed-ac", "table-table A/C"),
        ("seed-3axis", "three-axis"),
        ("head-table-bc", "head-table B/C"),
        ("table-table-bc", "table-table B/C"),
        ("head-head-ca", "head-head C/A"),
        (
            "nutating-head-bc",
            "nutating head-table B/C: B inclined [0, 1, 1]",
        ),
        (
            "nutating-table-bc",
            "nutating table-table B/C: B inclined [0, -1, 1]",
        ),
        ("horizontal-4axis-b", "rotary table B"),
    ] {
        let l = line(name);
        let m = model_spec::builtin(name).unwrap().unwrap();
        assert!(l.contains(family), "{l}");
        assert!(l.ends_with(&m.description), "{l}");
    }
    // Then every machine in full: the inclined axis with its vector and its own error names.
    let one = ok(&dir, &["machines", "--machine", "nutating-head-bc"]);
    assert_eq!(one.lines().filter(|l| l.contains("axes: ")).count(), 1);
    let b = one
        .lines()
        .find(|l| l.trim_start().starts_with("B   rotary"))
        .expect("the B axis line");
    assert!(
        b.contains("direction [0, 1, 1]") && b.contains("tool chain"),
        "{b}"
    );
    assert!(one.contains("XOB YOB AOB BOB XOC YOC AOC BOC"), "{one}");
}

#[test]
fn path_lists_a_turn_of_every_rotary_axis_within_the_limits() {
    let dir = temp_dir("list");
    for (name, _) in TEMPLATES {
        ok(
            &dir,
            &["path", "--machine", name, "--list", "--json", "tests.json"],
        );
        let list = read_json(&dir.join("tests.json"));
        let tests = list["tests"].as_array().unwrap();
        let m = model_spec::builtin(name).unwrap().unwrap();
        for a in m.rotary_axes() {
            let turn = format!("turn-{}", m.axes[a].name);
            assert!(
                tests.iter().any(|t| t["name"] == turn.as_str()),
                "{name}: no {turn}"
            );
        }
        for t in tests {
            assert_eq!(t["within_limits"], true, "{name}: {t}");
            assert_eq!(t["error"], Value::Null, "{name}: {t}");
        }
    }
}

/// A truth for `m`: every location error of its rotary axes and the ball's set-up errors,
/// 2 to 7 µm or µrad, reading noise 0.3 µm. Returns the TOML text and the values by name.
fn truth(m: &model_spec::Machine) -> (String, Vec<(String, f64)>) {
    let values = [
        3.0, -4.0, 5.5, -2.5, 6.0, -3.5, 4.5, -5.5, 2.0, -6.5, 3.8, -4.2,
    ];
    let names: Vec<String> = m
        .catalogue
        .iter()
        .filter(|e| {
            matches!(
                e.kind,
                model_spec::ErrorKind::Location { .. } | model_spec::ErrorKind::Setup { .. }
            )
        })
        .map(|e| e.name.clone())
        .collect();
    let pairs: Vec<(String, f64)> = names
        .into_iter()
        .enumerate()
        .map(|(i, n)| (n, values[i % values.len()]))
        .collect();
    let mut text = format!(
        "machine = \"{}\"\ndescription = \"location and set-up errors\"\nnoise_um = 0.3\nseed = 5\n\n[errors]\n",
        m.name
    );
    for (n, v) in &pairs {
        text += &format!("{n} = {v}\n");
    }
    (text, pairs)
}

#[test]
fn simulate_then_identify_recovers_the_truth_on_every_template() {
    let dir = temp_dir("identify");
    for (name, groups) in TEMPLATES {
        let m = model_spec::builtin(name).unwrap().unwrap();
        let (text, values) = truth(&m);
        std::fs::write(dir.join("truth.toml"), text).unwrap();
        ok(
            &dir,
            &["path", "--machine", name, "--list", "--json", "tests.json"],
        );
        // The tests taken forward (the list also has each reversed and there and back).
        let tests: Vec<String> = read_json(&dir.join("tests.json"))["tests"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|t| t["order"] == "forward")
            .map(|t| t["name"].as_str().unwrap().to_string())
            .collect();
        let mut campaign = format!("machine = \"{name}\"\n");
        for (i, t) in tests.iter().enumerate() {
            let file = format!("{name}-{t}.csv");
            let seed = (i + 1).to_string();
            ok(
                &dir,
                &[
                    "simulate",
                    "--machine",
                    name,
                    "--path",
                    t,
                    "--truth",
                    "truth.toml",
                    "--seed",
                    &seed,
                    "-o",
                    &file,
                ],
            );
            campaign += &format!("\n[[record]]\nfile = \"{file}\"\nsetup = \"s\"\n");
        }
        std::fs::write(dir.join("campaign.toml"), campaign).unwrap();
        ok(
            &dir,
            &[
                "identify",
                "--machine",
                name,
                "--model",
                "location",
                "--campaign",
                "campaign.toml",
                "--json",
                "fit.json",
            ],
        );
        let fit = read_json(&dir.join("fit.json"));
        for p in fit["parameters"].as_array().unwrap() {
            let error = p["error"].as_str().unwrap();
            let truth = values
                .iter()
                .find(|(n, _)| n == error)
                .map_or(0.0, |(_, v)| *v);
            let what = format!("{name} {}", p["name"]);
            if p["determined"] == true {
                let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
                assert!(
                    (v - truth).abs() <= 4.0 * s,
                    "{what}: {v} ± {s} against the truth {truth}"
                );
            } else {
                assert_eq!(p["value"], Value::Null, "{what}");
            }
        }
        let mut found: Vec<Vec<String>> = fit["confounded"]
            .as_array()
            .unwrap()
            .iter()
            .map(|g| {
                let mut g: Vec<String> = g
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|n| n.as_str().unwrap().to_string())
                    .collect();
                g.sort();
                g
            })
            .collect();
        found.sort();
        let mut want: Vec<Vec<String>> = groups
            .iter()
            .map(|g| {
                let mut g: Vec<String> = g.iter().map(|n| n.to_string()).collect();
                g.sort();
                g
            })
            .collect();
        want.sort();
        assert_eq!(found, want, "{name}");
    }
}
