//! `rtest identify` under a noise model and `rtest simulate --noise-phi`: the binary run in
//! temporary directories. The noise model a report assumes (estimated, declared, from a static
//! record, or white with σ̂ on noise-free data), and every refused flag (one stderr line naming
//! it, exit code 2 for usage errors and 1 for bad input).

use serde_json::Value;

use crate::common::{self, temp_dir};
use common::{fails, ok, read_json, words};

/// Simulates K4 on seed-ac with the reduced truth and `extra` flags into `dir/k4.csv`.
fn simulate_k4(dir: &std::path::Path, extra: &str) {
    let line =
        format!("simulate --machine seed-ac --path K4 --truth seed-ac-reduced -o k4.csv {extra}");
    ok(dir, &words(&line));
}

/// `identify` of the reduced model on `k4.csv` with `extra` flags: the text and the JSON.
fn identify(dir: &std::path::Path, extra: &[&str]) -> (String, Value) {
    let mut args = words("identify --machine seed-ac --model reduced --data k4.csv --json id.json");
    args.extend_from_slice(extra);
    let text = ok(dir, &args);
    (text, read_json(&dir.join("id.json")))
}

fn triple(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn correlated_noise_is_estimated_by_default_and_reported() {
    let dir = temp_dir("estimated");
    simulate_k4(&dir, "--noise-um 0.3 --noise-phi 0.8 --seed 4");
    let csv = std::fs::read_to_string(dir.join("k4.csv")).unwrap();
    assert!(
        csv.contains("noise 0.3 um AR(1) phi 0.8"),
        "the provenance says the noise"
    );
    let (text, json) = identify(&dir, &[]);
    let n = &json["noise_model"];
    assert_eq!(n["source"], "estimated", "{n}");
    for p in triple(&n["phi"]) {
        assert!((0.6..=0.95).contains(&p), "φ {p}: {n}");
    }
    for s in triple(&n["sigma_um"]) {
        assert!((0.15..=0.6).contains(&s), "σ {s} µm: {n}");
    }
    let w = n["whitened_sigma"].as_f64().unwrap();
    assert!((0.8..=1.25).contains(&w), "whitened σ̂ {w}");
    assert!(text.contains("Generalized least squares"), "{text}");
    assert!(
        text.contains("Noise model (the uncertainties assume it): AR(1) φ = ")
            && text.contains("estimated from 1 record (241 samples)"),
        "{text}"
    );
    // Ordinary least squares trusts white noise: smaller, dishonest uncertainties.
    let (_, ordinary) = identify(&dir, &["--noise", "white"]);
    assert_eq!(ordinary["noise_model"]["source"], "residual");
    assert_eq!(
        ordinary["noise_model"]["phi"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
    let std = |j: &Value| j["parameters"][0]["std"].as_f64().unwrap();
    assert!(
        std(&json) > 1.5 * std(&ordinary),
        "{} vs {}",
        std(&json),
        std(&ordinary)
    );
}

#[test]
fn a_declared_model_and_a_static_record_are_used_as_given() {
    let dir = temp_dir("declared");
    simulate_k4(&dir, "--noise-um 0.3 --noise-phi 0.8 --seed 5");
    let (text, json) = identify(&dir, &["--noise", "ar1:phi=0.8,sigma=0.3"]);
    let n = &json["noise_model"];
    assert_eq!(n["source"], "declared");
    assert_eq!(triple(&n["phi"]), vec![0.8; 3]);
    assert_eq!(triple(&n["sigma_um"]), vec![0.3; 3]);
    assert!(
        text.contains("AR(1) φ = 0.80 (x, y, z), σ = 0.30 µm (x, y, z), declared"),
        "{text}"
    );
    // The machine standing still at A = C = 0 for 200 samples, recorded with the same noise.
    let mut path = String::from("t_s,A,C\n");
    for i in 0..200 {
        path.push_str(&format!("{},0,0\n", i as f64 * 0.1));
    }
    std::fs::write(dir.join("still-path.csv"), path).unwrap();
    ok(
        &dir,
        &words(
            "simulate --machine seed-ac --path still-path.csv --truth seed-ac-reduced --noise-um 0.3 --noise-phi 0.8 --seed 6 -o still.csv",
        ),
    );
    let (text, json) = identify(&dir, &["--noise-record", "still.csv"]);
    let n = &json["noise_model"];
    assert_eq!(n["source"], "static-record");
    for p in triple(&n["phi"]) {
        assert!((0.6..=0.95).contains(&p), "φ {p}: {n}");
    }
    assert!(
        text.contains("from a static record of 200 samples"),
        "{text}"
    );
}

#[test]
fn noise_free_data_fall_back_to_white_and_say_why() {
    let dir = temp_dir("noise-free");
    simulate_k4(&dir, "--noise-um 0");
    let (text, json) = identify(&dir, &[]);
    assert_eq!(json["noise_model"]["source"], "residual");
    assert!(text.contains("below the floor"), "{text}");
    assert!(
        text.contains("Least squares on the column-scaled H"),
        "{text}"
    );
}

#[test]
fn bad_noise_flags_are_refused_naming_the_flag() {
    let dir = temp_dir("refused");
    simulate_k4(&dir, "--noise-um 0.3");
    let base = "identify --machine seed-ac --model reduced --data k4.csv";
    let line = |extra: &str| format!("{base} {extra}");
    fails(
        &dir,
        &words(&line("--noise pink:sigma=1")),
        2,
        &["--noise", "unknown kind `pink`"],
    );
    fails(
        &dir,
        &words(&line("--noise ar1:phi=0.99,sigma=0.3")),
        2,
        &["--noise", "below 0.99"],
    );
    fails(
        &dir,
        &words(&line("--noise white:sigma=-1")),
        2,
        &["--noise", "above 0"],
    );
    fails(
        &dir,
        &words(&line("--noise white --noise-record k4.csv")),
        2,
        &["--noise"],
    );
    fails(
        &dir,
        &words(&line("--stream --noise ar1:phi=0.5,sigma=0.3")),
        2,
        &["--stream", "--noise"],
    );
    // A record that moves is no static record.
    fails(
        &dir,
        &words(&line("--noise-record k4.csv")),
        1,
        &["--noise-record", "not static"],
    );
    fails(
        &dir,
        &words(&line("--noise-record missing.csv")),
        1,
        &["--noise-record"],
    );
    let sim = "simulate --machine seed-ac --path K4 -o x.csv";
    fails(
        &dir,
        &words(&format!("{sim} --noise-phi 1")),
        2,
        &["--noise-phi", "below 0.99"],
    );
    fails(
        &dir,
        &words(&format!("{sim} --noise-phi abc")),
        2,
        &["--noise-phi", "not a number"],
    );
    assert!(!dir.join("x.csv").exists() && !dir.join("id.json").exists());
}
