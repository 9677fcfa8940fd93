//! End-to-end tests of `rtest plan`: the binary run in temporary directories. The text and the
//! JSON of a plan (no number where the plan determines none), following the suggestion from
//! the JSON, AR(1) noise, and bad input (one stderr line naming the flag, the test and the
//! sample; exit code 2 for usage errors; no output file left behind).

use crate::common::{self, num, temp_dir};
use common::{entries, fails, ok, read_json};
use serde_json::Value;

/// `plan --machine seed-ac --model reduced` with `rest`.
fn plan_args<'a>(rest: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["plan", "--machine", "seed-ac", "--model", "reduced"];
    v.extend_from_slice(rest);
    v
}

#[test]
fn a_plan_says_what_it_determines_and_what_to_add() {
    let dir = temp_dir("k1");
    let out = ok(&dir, &plan_args(&["--paths", "K1", "--json", "k1.json"]));
    assert!(out.contains("rank 7 of 11 parameters"), "{out}");
    assert!(out.contains("not determined: confounded with"), "{out}");
    assert!(out.contains("Suggestion: add "), "{out}");
    assert!(out.contains("Skipped candidate"), "{out}");
    assert!(out.contains("Wrote k1.json"), "{out}");
    let j = read_json(&dir.join("k1.json"));
    assert_eq!(j["machine"], "seed-ac");
    assert_eq!(j["rank"], 7);
    assert_eq!(j["columns"], 11);
    assert_eq!(j["records"][0]["label"], "K1");
    assert_eq!(j["records"][0]["samples"], 361);
    // No number for what the plan cannot determine, a finite one for the rest.
    let confounded: Vec<String> = j["confounded"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|g| {
            g.as_array()
                .unwrap()
                .iter()
                .map(|n| n.as_str().unwrap().to_string())
        })
        .collect();
    for p in j["parameters"].as_array().unwrap() {
        let name = p["name"].as_str().unwrap();
        if p["determined"].as_bool().unwrap() {
            assert!(num(&p["std"]) > 0.0, "{name}");
            assert!(!confounded.iter().any(|c| c == name));
        } else {
            assert!(p["std"].is_null(), "{name}");
            assert!(confounded.iter().any(|c| c == name), "{name}");
        }
    }
    let s = &j["suggestion"];
    let ranking = s["ranking"].as_array().unwrap();
    assert_eq!(num(&s["evaluated"]) as usize, ranking.len());
    assert_eq!(ranking[0]["place"], 1);
    assert!(
        !ranking[0]["newly_determined"]
            .as_array()
            .unwrap()
            .is_empty()
    );
    let skipped = s["skipped"].as_array().unwrap();
    assert!(
        skipped
            .iter()
            .any(|k| k["reason"].as_str().unwrap().contains("outside its stroke")),
        "{skipped:?}"
    );

    // Following the suggestion: its item in --paths, its ball position when it is new.
    let best = &ranking[0];
    let paths = format!("K1,{}", best["paths_item"].as_str().unwrap());
    let mut args = plan_args(&["--paths", &paths, "--json", "followed.json"]);
    let ball;
    if let Some(b) = best["ball_arg"].as_str() {
        ball = b.to_string();
        args.extend_from_slice(&["--ball", &ball]);
    }
    ok(&dir, &args);
    let f = read_json(&dir.join("followed.json"));
    assert_eq!(f["rank"], best["rank"]);
    assert_eq!(f["columns"], best["columns"]);
    let (a, b) = (&f["largest"], &best["largest"]);
    assert_eq!(a["parameter"], b["parameter"]);
    assert!((num(&a["relative"]) - num(&b["relative"])).abs() <= 1e-9 * num(&b["relative"]));
    assert_eq!(entries(&dir), ["followed.json", "k1.json"]);
}

#[test]
fn ball_positions_set_ups_zeroing_and_ar1_noise() {
    let dir = temp_dir("balls");
    let out = ok(
        &dir,
        &plan_args(&[
            "--paths",
            "K4,K2:high",
            "--ball",
            "high:Zw=260",
            "--zeroed",
            "--shared-setup",
            "--noise-um",
            "0.3",
            "--noise-phi",
            "0.8",
            "--top",
            "2",
            "--json",
            "-",
        ]),
    );
    let j: Value = serde_json::from_str(&out).expect("JSON on stdout");
    assert_eq!(j["noise"]["phi"][0], 0.8);
    assert_eq!(j["noise"]["sigma_um"][2], 0.3);
    assert_eq!(j["zeroed"], true);
    assert_eq!(j["shared_setup"], true);
    assert_eq!(j["balls"][1]["name"], "high");
    assert_eq!(j["balls"][1]["params_mm"]["Zw"], 260.0);
    assert_eq!(j["records"][1]["label"], "K2:high");
    assert_eq!(j["records"][1]["setup"], "high");
    let names: Vec<&str> = j["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    for n in ["XOW[base]", "XOW[high]", "dx0[K4]", "dz0[K2:high]"] {
        assert!(names.contains(&n), "{n} in {names:?}");
    }
    // Zeroed readings: the sensor zeros swallow the errors with constant gains.
    let flat = j["confounded"].to_string();
    assert!(flat.contains("XOC") && flat.contains("dx0[K4]"), "{flat}");
}

#[test]
fn bad_input_is_refused_naming_the_flag_the_test_and_the_sample() {
    let dir = temp_dir("bad");
    fails(
        &dir,
        &plan_args(&["--paths", "K4,K5"]),
        2,
        &[
            "--paths",
            "no test `K5`",
            "K1, K2, K4, turn-A, turn-C, pair-A-C",
        ],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--param", "Zx=3"]),
        2,
        &["--param", "no kinematic symbol `Zx`"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4,K1:up", "--ball", "up:Zx=3"]),
        2,
        &["--ball up", "no kinematic symbol `Zx`"],
    );
    // The ball raised by 100 mm puts K4 out of the Y stroke: the generator names the test and
    // the sample.
    fails(
        &dir,
        &plan_args(&[
            "--paths",
            "K1,K4:up",
            "--ball",
            "up:Zw=311.537",
            "--json",
            "p.json",
        ]),
        2,
        &[
            "--ball up",
            "K4 at ball position `up`",
            "sample 170 of 241",
            "Y = 400.002176 mm outside its stroke -400 .. 400 mm",
        ],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--param", "Zw=311.537"]),
        2,
        &["--param", "sample 170 of 241"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4,K1:up"]),
        2,
        &["--paths", "no ball position `up`"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--ball", "up:Zw=260"]),
        2,
        &["--ball up", "no test of --paths is at this position"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4:base", "--ball", "base:Zw=260"]),
        2,
        &["--ball", "not a ball position name"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--terms", "SXY"]),
        2,
        &["--terms", "`SXY` is an instrument term"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--noise-phi", "0.99"]),
        2,
        &["--noise-phi"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--min-ball-height-mm", "300"]),
        2,
        &["K4 at ball position `base`", "less than the 300 mm"],
    );
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--step-deg", "0"]),
        2,
        &["--step-deg"],
    );
    // A machine without rotary axes has no test.
    fails(
        &dir,
        &[
            "plan",
            "--machine",
            "seed-3axis",
            "--model",
            "full",
            "--paths",
            "K4",
        ],
        2,
        &["--paths", "no rotary axis"],
    );
    // An output that cannot be written: nothing is left behind.
    fails(
        &dir,
        &plan_args(&["--paths", "K4", "--json", "missing/p.json"]),
        1,
        &["--json"],
    );
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
}

#[test]
fn too_many_candidates_are_refused_before_the_work() {
    // 25 ball positions, each moved along x, y and z both ways, times the 6 tests of the
    // generator and the reversed and there-and-back K1, K2, K4: more than MAX_CANDIDATES.
    let dir = temp_dir("bound");
    let tests = ["K1", "K2", "K4"];
    let paths: Vec<String> = (1..=25).map(|i| format!("{}:p{i}", tests[i % 3])).collect();
    let balls: Vec<String> = (1..=25).map(|i| format!("p{i}:Zw={}", 211 + i)).collect();
    let paths = paths.join(",");
    let mut args = plan_args(&["--paths", &paths, "--json", "p.json"]);
    for b in &balls {
        args.extend_from_slice(&["--ball", b]);
    }
    fails(
        &dir,
        &args,
        2,
        &[
            "--paths",
            "candidate additions (182 ball positions × 12 tests)",
            "more than the 2000",
            "fewer ball positions (--ball",
        ],
    );
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
}
