//! End-to-end tests of `rtest diagnose` (and the diagnosis in `rtest demo`): the binary run in
//! temporary directories on measurements simulated by `rtest simulate` on the exact virtual
//! machine. The demo truth's hidden ECC twice per revolution is found first and named, with the
//! held-out residual falling by more than half; the JSON has its documented fields in µm / µrad;
//! the extended machine description is accepted by `identify` and `generate`; the figures are
//! SVG; without a hidden effect there is no finding; bad input gives one line, the right exit
//! code and no output file.

use serde_json::Value;
use std::path::Path;

// ---------------------------------------------------------------- helpers

use crate::common::{self, num, temp_dir};
use common::{TempDir, entries, fails, ok, read_json};

/// Simulates K4, K1 and K2 of seed-ac with `truth` (and `extra` flags) into k4.csv, k1.csv and
/// k2.csv of `dir`, with different noise seeds.
fn simulate_all(dir: &Path, truth: &str, extra: &[&str]) {
    for (path, seed) in [("K4", "1"), ("K1", "2"), ("K2", "3")] {
        let out = format!("{}.csv", path.to_ascii_lowercase());
        let mut args = vec![
            "simulate",
            "--machine",
            "seed-ac",
            "--path",
            path,
            "--truth",
            truth,
            "--seed",
            seed,
            "-o",
            &out,
        ];
        args.extend_from_slice(extra);
        ok(dir, &args);
    }
}

/// `rtest diagnose` of the reduced model on k4.csv with k1.csv and k2.csv held out, plus `extra`.
fn diagnose(dir: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "diagnose",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
        "--validate",
        "k1.csv,k2.csv",
    ];
    args.extend_from_slice(extra);
    ok(dir, &args)
}

// ---------------------------------------------------------------- the hidden effect is found

#[test]
fn finds_the_demo_truths_ecc_twice_per_revolution_and_halves_the_held_out_residual() {
    let dir = temp_dir("found");
    simulate_all(&dir, "seed-ac-demo", &[]);
    let out = diagnose(
        &dir,
        &[
            "--json",
            "d.json",
            "--model-out",
            "m.toml",
            "--plot",
            "figs",
        ],
    );
    println!("{out}");

    // The text: base fit, structure, the finding named as an engineer reads it, why it stopped,
    // the confounded candidates, the gain and the command.
    for s in [
        "Base fit: model reduced on k4.csv",
        "residual RMS",
        "Residual structure",
        "  1. ECC harmonic:2: angular positioning error of C, twice per revolution: ",
        "(cos), ",
        "(sin) µrad",
        "amplitude ",
        "phase ",
        "explains ",
        "F = ",
        "p = ",
        "Bonferroni",
        "Stopped",
        "Confounded",
        "k1.csv (held out)",
        "k2.csv (held out)",
        "k4.csv (fitted)",
        "rtest identify --machine seed-ac --model reduced --terms ECC@harmonic:2 --data k4.csv",
        "rtest identify --machine m.toml --model extended --data k4.csv",
        "Wrote m.toml",
        "Wrote d.json",
    ] {
        assert!(out.contains(s), "`{s}` not in:\n{out}");
    }
    assert!(!out.contains("  2. "), "one finding only:\n{out}");

    // The JSON: the documented fields, values in µrad.
    let j = read_json(&dir.join("d.json"));
    assert_eq!(j["base_model"], "reduced");
    // The size budget, rates included (µm/s, µrad/s), at its defaults.
    let b = &j["budget"];
    for (k, v) in [("um", 100.0), ("urad", 200.0), ("ms", 20.0), ("1", 0.1)] {
        assert_eq!(b[k].as_f64(), Some(v), "budget {k}: {b}");
    }
    assert_eq!(b["um/s"].as_f64(), Some(0.5), "{b}");
    assert_eq!(b["urad/s"].as_f64(), Some(1.0), "{b}");
    let findings = j["findings"].as_array().expect("findings");
    assert_eq!(findings.len(), 1, "{findings:?}");
    let f = &findings[0];
    assert_eq!(f["error"], "ECC");
    assert_eq!(f["basis"], "harmonic:2");
    assert_eq!(f["unit"], "urad");
    assert!(
        f["description"]
            .as_str()
            .unwrap()
            .contains("angular positioning error of C, twice per revolution")
    );
    let values: Vec<f64> = f["values"].as_array().unwrap().iter().map(num).collect();
    let stds: Vec<f64> = f["stds"].as_array().unwrap().iter().map(num).collect();
    assert_eq!(values.len(), 2);
    // The truth: ECC = 8·cos 2C + 6·sin 2C µrad; within 4 std (µrad, not rad or mrad).
    for ((v, s), want) in values.iter().zip(&stds).zip([8.0, 6.0]) {
        assert!(*s > 0.05 && *s < 2.0, "std {s} µrad");
        assert!((v - want).abs() < 4.0 * s, "{v} ± {s} against {want}");
    }
    let amplitude = num(&f["amplitude"]);
    assert!((amplitude - values[0].hypot(values[1])).abs() < 1e-9);
    let phase = num(&f["phase_deg"]);
    assert!((phase - values[1].atan2(values[0]).to_degrees()).abs() < 1e-9);
    let explained = num(&f["explained_fraction"]);
    assert!(explained > 0.3 && explained <= 1.0, "{explained}");
    assert!(num(&f["p_value"]) < 1e-6);
    assert!(j["confounded"].is_array());
    for c in j["confounded"].as_array().unwrap() {
        assert!(c["error"].is_string() && c["basis"].is_string() && c["with"].is_array());
    }
    let ext = &j["extended_model"];
    let terms: Vec<&str> = ext["terms"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    assert_eq!(
        terms,
        [
            "XOW",
            "YOW",
            "ZOW",
            "YOA",
            "ZOA",
            "BOA",
            "COA",
            "XOC",
            "YOC",
            "AOC",
            "BOC",
            "ECC@harmonic:2"
        ]
    );
    assert_eq!(ext["name"], "extended");
    assert_eq!(ext["file"], "m.toml");

    // The gain: on the fitted data, and by more than half on every held-out file.
    let fit = &j["gain"]["fit"];
    assert!(num(&fit["residual_rms_um_after"]) < num(&fit["residual_rms_um_before"]));
    let validation = j["gain"]["validation"].as_array().unwrap();
    assert_eq!(validation.len(), 2);
    for (v, name) in validation.iter().zip(["k1.csv", "k2.csv"]) {
        assert_eq!(v["data"], name);
        let (before, after) = (
            num(&v["residual_rms_um_before"]),
            num(&v["residual_rms_um_after"]),
        );
        println!("{name}: {before:.3} -> {after:.3} µm");
        assert!(after < 0.5 * before, "{name}: {before} -> {after}");
        assert!(after < 0.7, "{name}: {after} µm, the noise is 0.5 µm");
    }

    // The extended machine description: identify and generate accept it.
    let toml = std::fs::read_to_string(dir.join("m.toml")).unwrap();
    assert!(toml.contains("[models.extended]"), "{toml}");
    assert!(toml.contains("\"ECC@harmonic:2\""), "{toml}");
    let id = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "m.toml",
            "--model",
            "extended",
            "--data",
            "k4.csv",
            // Ordinary least squares, as the diagnosis fits.
            "--noise",
            "white",
            "--json",
            "ext.json",
        ],
    );
    assert!(id.contains("ECC@harmonic:2:cos"), "{id}");
    // Its values are the diagnosis's, within a tenth of their std: the diagnosis fits under the
    // noise model estimated from the three records, identify --noise white by ordinary least
    // squares.
    let idj = read_json(&dir.join("ext.json"));
    let ecc: Vec<f64> = idj["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["error"] == "ECC")
        .map(|p| num(&p["value"]))
        .collect();
    assert_eq!(ecc.len(), 2);
    for ((a, b), s) in ecc.iter().zip(&values).zip(&stds) {
        assert!((a - b).abs() < 0.1 * s, "{a} vs {b} ± {s}");
    }
    ok(
        &dir,
        &["generate", "--machine", "m.toml", "-o", "extended.rs"],
    );
    let rs = std::fs::read_to_string(dir.join("extended.rs")).unwrap();
    assert!(
        rs.contains("pub mod extended"),
        "the generated code has the model"
    );
    ok(
        &dir,
        &[
            "generate",
            "--machine",
            "m.toml",
            "--model",
            "extended",
            "-o",
            "only.rs",
        ],
    );

    // The figures: one path figure and one spectrum per record, SVG, listed.
    let figs = entries(&dir.join("figs"));
    assert_eq!(
        figs,
        [
            "k1-path.svg",
            "k1-spectrum.svg",
            "k2-path.svg",
            "k2-spectrum.svg",
            "k4-path.svg",
            "k4-spectrum.svg"
        ]
    );
    for f in &figs {
        let svg = std::fs::read_to_string(dir.join("figs").join(f)).unwrap();
        assert!(
            svg.starts_with("<svg"),
            "{f}: {}",
            &svg[..40.min(svg.len())]
        );
        assert!(out.contains(&format!("figs/{f}")), "{f} not listed");
    }
    let k1 = std::fs::read_to_string(dir.join("figs/k1-path.svg")).unwrap();
    for s in [
        "x error",
        "y error",
        "z error",
        "C (deg)",
        "measured",
        "extended model",
    ] {
        assert!(k1.contains(s), "`{s}` not in k1-path.svg");
    }
    let k2 = std::fs::read_to_string(dir.join("figs/k2-path.svg")).unwrap();
    assert!(k2.contains("A (deg)"), "K2 turns A");

    // A machine file whose `extended` is taken: the next one is `extended2`, and the file's own
    // text is kept.
    let out2 = ok(
        &dir,
        &[
            "diagnose",
            "--machine",
            "m.toml",
            "--model",
            "reduced",
            "--data",
            "k4.csv",
            "--model-out",
            "m2.toml",
        ],
    );
    assert!(out2.contains("`extended2` of m2.toml"), "{out2}");
    let toml2 = std::fs::read_to_string(dir.join("m2.toml")).unwrap();
    assert!(toml2.starts_with(&toml), "m2.toml keeps m.toml's text");
    assert!(toml2.contains("[models.extended2]"));
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "m2.toml",
            "--model",
            "extended2",
            "--data",
            "k4.csv",
        ],
    );
}

#[test]
fn zeroed_readings_find_it_too() {
    let dir = temp_dir("zeroed");
    simulate_all(&dir, "seed-ac-demo", &["--zeroed"]);
    let out = diagnose(&dir, &["--zeroed", "--json", "d.json"]);
    assert!(out.contains("readings zeroed at the first sample"), "{out}");
    assert!(out.contains("--data k4.csv --zeroed"), "{out}");
    let j = read_json(&dir.join("d.json"));
    assert_eq!(j["zeroed"], true);
    let f = &j["findings"][0];
    assert_eq!(
        (f["error"].as_str(), f["basis"].as_str()),
        (Some("ECC"), Some("harmonic:2"))
    );
    for v in j["gain"]["validation"].as_array().unwrap() {
        assert!(
            num(&v["residual_rms_um_after"]) < 0.6 * num(&v["residual_rms_um_before"]),
            "{v}"
        );
    }
    // The offsets --zeroed adds are not written into the extended model: identify --zeroed adds
    // them again.
    let terms = j["extended_model"]["terms"].as_array().unwrap();
    assert_eq!(terms.len(), 12);
    assert!(!terms.iter().any(|t| t.as_str().unwrap().starts_with("d")));
}

#[test]
fn no_hidden_effect_no_finding() {
    let dir = temp_dir("none");
    simulate_all(&dir, "seed-ac-reduced", &["--noise-um", "0.5"]);
    let out = diagnose(
        &dir,
        &[
            "--json",
            "d.json",
            "--model-out",
            "m.toml",
            "--plot",
            "figs",
        ],
    );
    println!("{out}");
    assert!(out.contains("no finding"), "{out}");
    assert!(out.contains("not significant"), "{out}");
    assert!(out.contains("Nothing to add"), "{out}");
    let j = read_json(&dir.join("d.json"));
    assert_eq!(j["findings"].as_array().unwrap().len(), 0);
    assert_eq!(j["extended_model"]["terms"].as_array().unwrap().len(), 11);
    assert!(num(&j["stop"]["p_value"]) >= 0.01);
    let fit = &j["gain"]["fit"];
    assert_eq!(
        num(&fit["residual_rms_um_before"]),
        num(&fit["residual_rms_um_after"])
    );
    // The description and figures are still written: the extended model is the base model.
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "m.toml",
            "--model",
            "extended",
            "--data",
            "k4.csv",
        ],
    );
    assert_eq!(entries(&dir.join("figs")).len(), 6);
}

/// An effect outside the dictionary (a seventh harmonic of C's radial motion): the text and
/// the JSON say the residual is not the noise and describe what remains; the figure of it is
/// written; nothing is recommended that makes a held-out file worse; the finding fields are
/// there.
#[test]
fn an_effect_outside_the_dictionary_is_described_as_unexplained() {
    let dir = temp_dir("outside");
    let truth = dir.join("t.toml");
    std::fs::write(
        &truth,
        "machine = \"seed-ac\"\nnoise_um = 0.5\n[errors]\nXOC = 10.0\nEYC = { \"harmonic:7\" = [3.0, 0.0] }\n",
    )
    .unwrap();
    simulate_all(&dir, "t.toml", &[]);
    let out = diagnose(&dir, &["--json", "d.json", "--plot", "figs"]);
    println!("{out}");
    assert!(out.contains("Noise model of every test: "), "{out}");
    assert!(out.contains("NOT consistent with the noise"), "{out}");
    assert!(!out.contains("down to the noise"), "{out}");
    let j = read_json(&dir.join("d.json"));
    let a = &j["adequacy"];
    assert_eq!(a["consistent_with_noise"], false);
    assert!(num(&a["p_value"]) < 0.01);
    assert_eq!(a["records"].as_array().unwrap().len(), 3);
    let un = j["unexplained"].as_array().unwrap();
    assert!(!un.is_empty());
    for u in un {
        assert!(u["data"].is_string() && u["direction"].is_string() && u["shape"].is_string());
        assert!(num(&u["rms_um"]) > 0.5);
    }
    assert!(j["noise_model"].as_str().unwrap().contains("estimated"));
    for f in j["findings"].as_array().unwrap() {
        assert!(f["plausible"].is_boolean() && f["status"].is_string() && f["size"].is_number());
    }
    if j["recommended"] == true {
        for v in j["gain"]["validation"].as_array().unwrap() {
            assert!(num(&v["residual_rms_um_after"]) <= num(&v["residual_rms_um_before"]));
        }
    }
    assert!(
        j["recommendation"]
            .as_array()
            .is_some_and(|r| !r.is_empty())
    );
    let figs = entries(&dir.join("figs"));
    assert!(
        figs.iter().any(|f| f.contains("unexplained")),
        "no figure of what remains: {figs:?}"
    );
}

// ---------------------------------------------------------------- help and bad input

#[test]
fn help_names_units_steps_and_exit_codes() {
    let dir = temp_dir("help");
    let help = ok(&dir, &["diagnose", "--help"]);
    for s in [
        "µm",
        "µrad",
        "mm",
        "degrees",
        "Residual structure",
        "Candidates",
        "Selection",
        "Bonferroni",
        "confounded",
        "Gain",
        "--model-out",
        "[models.extended]",
        "--plot",
        "Exit codes: 0 success; 1 bad input",
        "--alpha",
    ] {
        assert!(help.contains(s), "`{s}` not in diagnose --help:\n{help}");
    }
}

/// A directory with good k4.csv, k1.csv and k2.csv and a few things in the way.
fn prepared(name: &str) -> TempDir {
    let dir = temp_dir(name);
    simulate_all(&dir, "seed-ac-demo", &[]);
    std::fs::create_dir(dir.join("sub")).unwrap();
    std::fs::write(dir.join("afile"), "in the way").unwrap();
    std::fs::write(
        dir.join("bad.csv"),
        "X,Y,Z,A,C,dx_um,dy_um,dz_um\n0,0,0,0,0,1,2,3\n0,0,0,0,zero,1,2,3\n",
    )
    .unwrap();
    dir
}

#[test]
fn bad_input_is_one_line_with_the_right_exit_code_and_leaves_nothing() {
    let dir = prepared("bad");
    let before = entries(&dir);
    let base = [
        "diagnose",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--data",
        "k4.csv",
    ];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().copied().chain(extra.iter().copied()).collect()
    };
    // Usage errors (2).
    let usage: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec!["diagnose", "--machine", "seed-ac", "--data", "k4.csv"],
            vec!["--model"],
        ),
        (
            vec!["diagnose", "--machine", "seed-ac", "--model", "reduced"],
            vec!["--data"],
        ),
        (
            vec!["diagnose", "--model", "reduced", "--data", "k4.csv"],
            vec!["--machine"],
        ),
        (
            vec![
                "diagnose",
                "--machine",
                "nope",
                "--model",
                "reduced",
                "--data",
                "k4.csv",
            ],
            vec!["--machine", "nope"],
        ),
        (
            vec![
                "diagnose",
                "--machine",
                "seed-ac",
                "--model",
                "nope",
                "--data",
                "k4.csv",
            ],
            vec!["--model", "nope", "reduced"],
        ),
        (with(&["--alpha", "0"]), vec!["--alpha", "between 0 and 1"]),
        (with(&["--alpha", "1"]), vec!["--alpha"]),
        (with(&["--alpha", "-0.1"]), vec!["--alpha"]),
        (with(&["--alpha", "abc"]), vec!["--alpha"]),
        (with(&["--alpha", "NaN"]), vec!["--alpha"]),
        (with(&["--harmonics", "99"]), vec!["--harmonics"]),
        (with(&["--poly", "x"]), vec!["--poly"]),
        (
            with(&["--validate", "k1.csv,,k2.csv"]),
            vec!["--validate", "empty"],
        ),
        (
            with(&["--validate", "k1.csv,k1.csv"]),
            vec!["--validate", "twice"],
        ),
        (with(&["--bogus"]), vec!["--bogus"]),
    ];
    for (args, needles) in &usage {
        fails(&dir, args, 2, needles);
    }
    // Failures (1).
    let failures: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (
            vec![
                "diagnose",
                "--machine",
                "seed-ac",
                "--model",
                "reduced",
                "--data",
                "none.csv",
            ],
            vec!["--data", "none.csv"],
        ),
        (
            with(&["--validate", "k1.csv,none.csv", "--json", "d.json"]),
            vec!["--validate", "none.csv"],
        ),
        (
            with(&["--validate", "bad.csv", "--json", "d.json"]),
            vec!["--validate", "bad.csv", "3"],
        ),
        (
            with(&[
                "--json",
                "d.json",
                "--plot",
                "figs",
                "--model-out",
                "no-such-dir/m.toml",
            ]),
            vec!["--model-out", "cannot write", "no-such-dir"],
        ),
        (
            with(&["--json", "d.json", "--model-out", "sub"]),
            vec!["--model-out", "directory"],
        ),
        (with(&["--json", "sub"]), vec!["--json", "directory"]),
        (
            with(&["--json", "d.json", "--plot", "afile"]),
            vec!["--plot", "afile", "not a directory"],
        ),
        (
            with(&["--json", "no-such-dir/d.json", "--plot", "figs"]),
            vec!["--json", "cannot write"],
        ),
    ];
    for (args, needles) in &failures {
        fails(&dir, args, 1, needles);
    }
    // Nothing was written: no JSON, no description, no figure directory, no temporary file.
    assert_eq!(entries(&dir), before);
    assert!(entries(&dir.join("sub")).is_empty());
    assert_eq!(
        std::fs::read_to_string(dir.join("afile")).unwrap(),
        "in the way"
    );
}

// ---------------------------------------------------------------- campaigns

/// K4 and K1 fitted together (each its own set-up), K2 held out on a set-up of its own: the
/// missing harmonic is found, every fitted record falls to the noise, K2's set-up errors are
/// refitted on it, and the same outputs as for one record are written (figures of every
/// record included).
#[test]
fn a_campaign_finds_the_missing_harmonic_and_draws_every_record() {
    let dir = temp_dir("campaign");
    simulate_all(&dir, "seed-ac-demo", &[]);
    let text = ok(
        &dir,
        &common::words(
            "diagnose --machine seed-ac --model reduced --data k4.csv,k1.csv --validate k2.csv \
             --harmonics 2 --poly 1 --time 1 --json d.json --model-out ext.toml --plot figs \
             --report r.html",
        ),
    );
    for s in [
        "Campaign: the machine's errors shared",
        "1. ECC harmonic:2",
        "Held out k2: set-up k2 (new: its set-up errors refitted on it",
        "XOW[k2]",
        "rtest identify --machine seed-ac --model reduced --terms ECC@harmonic:2 --data k4.csv,k1.csv",
    ] {
        assert!(text.contains(s), "`{s}` not in:\n{text}");
    }
    let j = read_json(&dir.join("d.json"));
    assert_eq!(j["version"], 2);
    assert_eq!(j["data"], "k4.csv,k1.csv");
    let records = j["records"].as_array().unwrap();
    assert_eq!(records.len(), 3);
    for r in &records[..2] {
        assert_eq!(r["role"], "fitted");
        assert!(num(&r["residual_rms_after_um"]) < 0.56, "{r}");
    }
    let k2 = &records[2];
    assert_eq!(
        (&k2["label"], &k2["data"], &k2["role"], &k2["setup"]),
        (
            &Value::from("k2"),
            &Value::from("k2.csv"),
            &Value::from("held out"),
            &Value::from("k2")
        )
    );
    assert_eq!(k2["setup_fitted"], false);
    assert_eq!(
        k2["refitted"],
        serde_json::json!(["XOW[k2]", "YOW[k2]", "ZOW[k2]"])
    );
    assert_eq!(j["gain"]["validation"][0]["data"], "k2.csv");
    assert_eq!(j["notes"].as_array().unwrap().len(), 2);
    assert!(
        std::fs::read_to_string(dir.join("ext.toml"))
            .unwrap()
            .contains("\"ECC@harmonic:2\"")
    );
    let figs = entries(&dir.join("figs"));
    for f in [
        "k4-path.svg",
        "k1-path.svg",
        "k2-path.svg",
        "k1-spectrum.svg",
    ] {
        assert!(figs.iter().any(|x| x == f), "{f} not in {figs:?}");
    }
    // The HTML report renders the campaign: its records, what was refitted, every path.
    let html = std::fs::read_to_string(dir.join("r.html")).unwrap();
    for s in [
        "Records: the machine",
        "XOW[k2]",
        "k1.csv (fitted)",
        "k2.csv (held out)",
    ] {
        assert!(html.contains(s), "`{s}` not in the HTML report");
    }
}

/// One record's JSON keeps its fields and gains `version` and `records`; a held-out file is on
/// the fitted record's set-up (the ball not moved) and nothing is refitted on it.
#[test]
fn one_record_is_the_campaign_of_that_record() {
    let dir = temp_dir("one");
    simulate_all(&dir, "seed-ac-demo", &[]);
    let text = diagnose(&dir, &["--json", "d.json"]);
    assert!(!text.contains("Campaign:"), "{text}");
    let j = read_json(&dir.join("d.json"));
    assert_eq!(j["version"], 2);
    assert_eq!(j["data"], "k4.csv");
    assert_eq!(j["data_arguments"], serde_json::json!(["--data", "k4.csv"]));
    assert_eq!(
        j["held_out"],
        serde_json::json!([["k1.csv", 361], ["k2.csv", 121]])
    );
    let records = j["records"].as_array().unwrap();
    assert_eq!(records.len(), 3);
    for (r, (label, role)) in
        records
            .iter()
            .zip([("k4", "fitted"), ("k1", "held out"), ("k2", "held out")])
    {
        assert_eq!(
            (r["label"].as_str(), r["role"].as_str()),
            (Some(label), Some(role))
        );
        assert_eq!(r["setup"], "k4");
        assert_eq!(r["setup_fitted"], true);
        assert!(r.get("refitted").is_none(), "{r}");
    }
    assert!(j["notes"].as_array().unwrap().is_empty());
    assert!(j.get("campaign").is_none());
    // A report of another version is refused by the HTML report, with the reason.
    let mut old = j.clone();
    old["version"] = Value::from(1);
    std::fs::write(dir.join("old.json"), old.to_string()).unwrap();
    fails(
        &dir,
        &["report", "old.json", "-o", "r.html"],
        1,
        &["version 1"],
    );
    assert!(!dir.join("r.html").exists());
}

/// The refinement never throws away a converged fit: K4 and K1 of the full error budget (noise
/// seeds 1 and 2) fitted together, K2 (seed 3) held out, stopped with exit code 3 when a step
/// of 3e-9 µm was held against a tolerance of 1e-9 µm; the diagnosis now completes.
#[test]
fn the_budget_campaign_whose_refinement_crawled_at_rounding_is_diagnosed() {
    let dir = temp_dir("budget");
    simulate_all(&dir, "seed-ac-budget", &[]);
    let text = ok(
        &dir,
        &common::words(
            "diagnose --machine seed-ac --model reduced --data k4.csv,k1.csv --validate k2.csv \
             --json d.json",
        ),
    );
    assert!(!text.contains("did not converge"), "{text}");
    let j = read_json(&dir.join("d.json"));
    assert!(!j["findings"].as_array().unwrap().is_empty());
    assert_eq!(j["records"].as_array().unwrap().len(), 3);
}
