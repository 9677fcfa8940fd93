//! `rtest validate --tolerance FILE`: the verdicts of ISO 14253-1 per test and direction, before
//! and after, on simulated records (pass, fail and undecided each reached), in the text, the
//! JSON and the HTML report; bad tolerance files refused at their file, line and field.

use crate::common::{self, TempDir, fails, num, ok, read_json};
use serde_json::Value;
use std::path::Path;

/// K4 and K1 of seed-ac simulated with the demo truth (0.5 µm noise), the reduced model
/// identified on K4 (`id.json`).
fn identified(name: &str) -> TempDir {
    let dir = common::temp_dir_tagged("validate-tolerance", name);
    for (path, seed) in [("K4", "4"), ("K1", "1")] {
        let out = format!("{}.csv", path.to_ascii_lowercase());
        ok(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--truth",
                "seed-ac-demo",
                "--path",
                path,
                "--seed",
                seed,
                "-o",
                &out,
            ],
        );
    }
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
            "--json",
            "id.json",
        ],
    );
    dir
}

/// Runs validate of `id.json` on K1 against `tolerances` (the file's text, written as
/// `tol.toml`) with `extra` flags; returns the text and the JSON's `tolerance`.
fn judged(dir: &Path, tolerances: &str, extra: &[&str]) -> (String, Value) {
    std::fs::write(dir.join("tol.toml"), tolerances).unwrap();
    let mut args = vec![
        "validate",
        "--machine",
        "seed-ac",
        "--params",
        "id.json",
        "--data",
        "k1.csv",
        "--tolerance",
        "tol.toml",
        "--json",
        "v.json",
    ];
    args.extend_from_slice(extra);
    let text = ok(dir, &args);
    let json = read_json(&dir.join("v.json"));
    (text, json["tolerance"].clone())
}

/// The entry of test `name` in `direction`.
fn test<'a>(t: &'a Value, name: &str, direction: &str) -> &'a Value {
    t["tests"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["name"] == name && x["direction"] == direction)
        .unwrap_or_else(|| panic!("no {name} {direction} in {t:#}"))
}

/// Value, U and verdict of `quantity` (`max` or `range`) in `state` (`before` or `after`).
fn quantity(x: &Value, state: &str, quantity: &str) -> (f64, f64, String) {
    let q = &x[state][quantity];
    (
        num(&q["value_um"]),
        num(&q["expanded_um"]),
        q["verdict"].as_str().unwrap().to_string(),
    )
}

#[test]
fn pass_fail_and_undecided_follow_iso_14253_1_before_and_after() {
    let dir = identified("verdicts");
    // First, the values and uncertainties of K1 under a loose tolerance.
    let loose = "[[test]]\nname = \"k1\"\ndirection = [\"x\", \"y\", \"z\"]\nmax_um = 500\nrange_um = 500\n";
    let (_, t) = judged(&dir, loose, &[]);
    let noise = common::triple(&t["noise"]["sigma_um"]);
    assert!(
        noise.iter().all(|s| (0.3..0.8).contains(s)),
        "the identification's noise model (0.5 µm simulated): {noise:?}"
    );
    assert_eq!(t["coverage_k"], 2.0);
    for d in ["x", "y", "z"] {
        let x = test(&t, "k1", d);
        assert_eq!(x["before"]["verdict"], "pass", "{d}: {x:#}");
        assert_eq!(x["after"]["verdict"], "pass", "{d}: {x:#}");
        // Before: U = 2σ of the reading noise; after: 2·max(σ, s), s the residual RMS.
        let k = ["x", "y", "z"].iter().position(|e| *e == d).unwrap();
        let (_, u_before, _) = quantity(x, "before", "max");
        assert!((u_before - 2.0 * noise[k]).abs() < 1e-9, "{d}: {x:#}");
        let (_, u_range, _) = quantity(x, "before", "range");
        assert!((u_range - 2.0 * 2f64.sqrt() * noise[k]).abs() < 1e-9);
        let s = num(
            &read_json(&dir.join("v.json"))["records"][0]["per_direction"][d]["residual_rms_um"],
        );
        let (_, u_after, _) = quantity(x, "after", "max");
        assert!(
            (u_after - 2.0 * noise[k].max(s)).abs() < 1e-9,
            "{d}: {u_after} {s}"
        );
        assert!(
            (num(&x["after"]["lack_of_fit_um"]) - (s * s - noise[k] * noise[k]).max(0.0).sqrt())
                .abs()
                < 1e-9
        );
        assert!(x["before"]["lack_of_fit_um"].is_null());
    }
    let at = |d: &str, state: &str, q: &str| quantity(test(&t, "k1", d), state, q);
    // x: a tolerance between the residual's max + U and the reading's max − U: the machine as
    // measured fails, compensated with the model it passes.
    let (after_x, u_after_x, _) = at("x", "after", "max");
    let (before_x, u_before_x, _) = at("x", "before", "max");
    let limit_x = after_x + u_after_x + 1.0;
    assert!(limit_x < before_x - u_before_x, "{limit_x} {before_x}");
    // y: the tolerance is the residual's max itself: within U of it, undecided.
    let (after_y, _, _) = at("y", "after", "max");
    // z: the range after, less its U and 0.1 µm: nonconformance proven.
    let (range_z, u_range_z, _) = at("z", "after", "range");
    let limit_z = range_z - u_range_z - 0.1;
    assert!(limit_z > 0.0, "{range_z} {u_range_z}");
    let file = format!(
        "# K1, µm\n[[test]]\nname = \"K1\"\ndirection = \"x\"\nmax_um = {limit_x}\n\n[[test]]\nname = \"k1\"\ndirection = \"y\"\nmax_um = {after_y}\n\n[[test]]\nname = \"k1\"\ndirection = \"z\"\nmax_um = 1000\nrange_um = {limit_z}\n"
    );
    let (text, t) = judged(&dir, &file, &[]);
    let verdicts = |name: &str, d: &str| {
        let x = test(&t, name, d);
        (
            x["before"]["verdict"].as_str().unwrap().to_string(),
            x["after"]["verdict"].as_str().unwrap().to_string(),
        )
    };
    assert_eq!(verdicts("K1", "x"), ("fail".into(), "pass".into()));
    assert_eq!(test(&t, "K1", "x")["record"], "k1");
    assert_eq!(verdicts("k1", "y").1, "undecided");
    assert_eq!(verdicts("k1", "z"), ("fail".into(), "fail".into()));
    let z = test(&t, "k1", "z");
    // The max passes, the range fails: the test fails.
    assert_eq!(quantity(z, "after", "max").2, "pass");
    assert_eq!(quantity(z, "after", "range").2, "fail");
    assert!(test(&t, "K1", "x")["before"]["range"].is_null());
    assert_eq!(t["counts"]["after"]["pass"], 1);
    assert_eq!(t["counts"]["after"]["fail"], 1);
    assert_eq!(t["counts"]["after"]["undecided"], 1);
    assert!(
        text.contains("Tolerances of tol.toml (ISO 14253-1, coverage k = 2)"),
        "{text}"
    );
    assert!(text.contains("Verdicts: before "), "{text}");
    assert!(
        text.contains("after 1 pass, 1 fail, 1 undecided."),
        "{text}"
    );
    for needle in ["pass", "fail", "undecided", "max |dev|", "range"] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    // The report of the check shows the verdicts (the JSON read back).
    ok(
        &dir,
        &[
            "report",
            "id.json",
            "v.json",
            "--machine",
            "seed-ac",
            "-o",
            "check.html",
        ],
    );
    let html = std::fs::read_to_string(dir.join("check.html")).unwrap();
    assert!(
        html.contains("<h3>Verdicts against the tolerances of tol.toml</h3>"),
        "no verdicts"
    );
    for v in ["pass", "fail", "undecided"] {
        assert!(
            html.contains(&format!("class=\"verdict-{v}\">{v}<")),
            "{v} not in the report"
        );
    }
    assert!(
        html.contains("After: 1 pass, 1 fail, 1 undecided."),
        "no counts"
    );
    // A verdict that is not one of the three words is refused when the report is read back.
    let json = std::fs::read_to_string(dir.join("v.json")).unwrap();
    let at = json.find("\"pass\"").expect("a pass");
    let bad = format!("{}\"ok\"{}", &json[..at], &json[at + 6..]);
    std::fs::write(dir.join("bad.json"), bad).unwrap();
    fails(
        &dir,
        &["report", "id.json", "bad.json", "-o", "bad.html"],
        1,
        &["bad.json", "`ok`"],
    );
    assert!(!dir.join("bad.html").exists());
}

#[test]
fn an_uncertainty_beyond_the_tolerance_is_never_a_pass() {
    let dir = identified("honest");
    // A reading noise of 40 µm: U = 80 µm against tolerances of 60 µm.
    let file = "[[test]]\nname = \"k1\"\ndirection = [\"x\", \"y\", \"z\"]\nmax_um = 60\n";
    let (text, t) = judged(&dir, file, &["--noise-um", "40"]);
    assert_eq!(t["noise"]["source"], "--noise-um 40");
    for x in t["tests"].as_array().unwrap() {
        for state in ["before", "after"] {
            assert_eq!(x[state]["verdict"], "undecided", "{x:#}");
            assert!(num(&x[state]["max"]["expanded_um"]) >= 80.0);
        }
    }
    assert!(
        text.contains("before 0 pass, 0 fail, 3 undecided"),
        "{text}"
    );
}

#[test]
fn the_noise_of_a_static_record_can_be_given() {
    let dir = identified("static");
    let mut still = String::from("A,C\n");
    for _ in 0..150 {
        still.push_str("0,0\n");
    }
    std::fs::write(dir.join("still-path.csv"), still).unwrap();
    ok(
        &dir,
        &[
            "simulate",
            "--machine",
            "seed-ac",
            "--truth",
            "seed-ac-demo",
            "--path",
            "still-path.csv",
            "--noise-um",
            "2",
            "--seed",
            "9",
            "-o",
            "still.csv",
        ],
    );
    let file = "[[test]]\nname = \"k1\"\ndirection = \"x\"\nmax_um = 60\n";
    let (_, t) = judged(&dir, file, &["--noise-record", "still.csv"]);
    let s = common::triple(&t["noise"]["sigma_um"]);
    assert!(s.iter().all(|s| (1.5..2.5).contains(s)), "{s:?}");
    assert_eq!(t["noise"]["source"], "the static record still.csv");
}

#[test]
fn bad_tolerance_files_are_refused_with_file_line_and_field() {
    let dir = identified("refused");
    let head = "[[test]]\nname = \"k1\"\ndirection = \"x\"\n";
    for (text, needles) in [
        (
            format!("{head}max_um = -3\n"),
            vec![
                "--tolerance tol.toml:4:10: `test[0].max_um`: a tolerance must be a positive number (µm), not -3",
            ],
        ),
        (
            format!("{head}max_um = 3\nlimit_um = 4\n"),
            vec!["tol.toml:5:1: unknown key `limit_um` in `test[0]`"],
        ),
        (
            "[[test]]\nname = \"K9\"\ndirection = \"x\"\nmax_um = 3\n".to_string(),
            vec![
                "tol.toml:2:8: `test[0].name`: no validated record is called `K9` (the records: k1;",
            ],
        ),
        (
            format!(
                "{head}max_um = 3\n[[test]]\nname = \"K1\"\ndirection = [\"z\", \"x\"]\nrange_um = 3\n"
            ),
            vec![
                "tol.toml:7:19: `test[1].direction`: test `K1` in direction x is given twice (first at tol.toml:2)",
            ],
        ),
        (
            "[[test]]\nname = \"k1\"\ndirection = \"radial\"\nmax_um = 3\n".to_string(),
            vec!["tol.toml:3:13: `test[0].direction`: `radial` is not a direction"],
        ),
        (
            format!("{head}max_um = \"3\"\n"),
            vec!["tol.toml:4:10: `test[0].max_um` must be a number, not string"],
        ),
    ] {
        std::fs::write(dir.join("tol.toml"), &text).unwrap();
        let args = [
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "id.json",
            "--data",
            "k1.csv",
            "--tolerance",
            "tol.toml",
            "--json",
            "v.json",
        ];
        fails(&dir, &args, 1, &needles);
        assert!(!dir.join("v.json").exists(), "{text}: no partial output");
    }
    // The noise flags need a tolerance file; a noise that is not a number is refused.
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
            "--noise-um",
            "1",
        ],
        2,
        &["--tolerance"],
    );
    std::fs::write(dir.join("tol.toml"), format!("{head}max_um = 3\n")).unwrap();
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
            "--tolerance",
            "tol.toml",
            "--noise-um=-1",
        ],
        2,
        &["--noise-um: -1 is not a standard uncertainty"],
    );
    // An identification without a noise model: the noise must be given.
    let mut id = read_json(&dir.join("id.json"));
    id.as_object_mut().unwrap().remove("noise_model");
    std::fs::write(dir.join("old.json"), id.to_string()).unwrap();
    fails(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "old.json",
            "--data",
            "k1.csv",
            "--tolerance",
            "tol.toml",
        ],
        1,
        &[
            "--params: old.json has no `noise_model`",
            "--noise-um or --noise-record",
        ],
    );
    ok(
        &dir,
        &[
            "validate",
            "--machine",
            "seed-ac",
            "--params",
            "old.json",
            "--data",
            "k1.csv",
            "--tolerance",
            "tol.toml",
            "--noise-um",
            "0.5",
        ],
    );
}
