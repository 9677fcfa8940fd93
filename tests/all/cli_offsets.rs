//! End-to-end tests of kinematic offsets as unknowns: a pivot length off its nominal simulated,
//! identified with `--terms Zt`, reported (change in µm, nominal and identified lengths in mm)
//! and validated; a ball position reported as not separable from its set-up error; the seed
//! machine's probe length; a campaign sharing a pivot length and refusing records that disagree
//! on it; a sub-model of a description with a symbol; bad terms and symbol names refused.

use std::path::Path;

use crate::common::{self, param, temp_dir};
use common::{fails, ok, read_json, words};

/// head-table-bc's location errors that pair-B-C separates (µm, µrad), its pivot length
/// 40 µm shorter than the description's -250 mm, reading noise 0.3 µm.
const HEAD_TABLE_TRUTH: &str = "noise_um = 0.3
seed = 4
[parameters]
Zt = -250.04
[errors]
COY = 8.0
BOZ = 5.0
XOW = 12.0
YOW = -9.0
ZOW = 7.0
AOB = 20.0
COB = -14.0
XOC = 10.0
YOC = -13.0
AOC = 16.0
BOC = -12.0
";

/// Those errors and the pivot length, as `--terms`.
const DETERMINED: &str = "COY,BOZ,XOW,YOW,ZOW,AOB,COB,XOC,YOC,AOC,BOC,Zt";

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

/// Simulates `path` of head-table-bc with [`HEAD_TABLE_TRUTH`] (`seed`) into `dir/out`.
fn simulate_head_table(dir: &Path, path: &str, seed: &str, out: &str, extra: &[&str]) {
    let mut args = words("simulate --machine head-table-bc --truth truth.toml --seed");
    args.extend([seed, "--path", path, "-o", out]);
    args.extend_from_slice(extra);
    ok(dir, &args);
}

#[test]
fn a_pivot_length_off_its_nominal_is_identified_reported_and_validated() {
    let dir = temp_dir("pivot");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "pair.csv", &[]);
    simulate_head_table(&dir, "turn-B", "5", "turn.csv", &[]);
    let text = ok(
        &dir,
        &[
            "identify",
            "--machine",
            "head-table-bc",
            "--terms",
            DETERMINED,
            "--data",
            "pair.csv",
            "--json",
            "id.json",
        ],
    );
    let line = text.lines().find(|l| l.starts_with("Zt ")).unwrap();
    assert!(
        line.contains("µm  (change; nominal -250 mm, identified -250.04"),
        "{line}"
    );
    let j = read_json(&dir.join("id.json"));
    let zt = param(&j, "Zt");
    assert_eq!(zt["error"], "Zt");
    assert_eq!(zt["basis"], "const");
    assert_eq!(zt["unit"], "um");
    assert_eq!(zt["nominal_mm"], -250.0);
    let (v, s) = (zt["value"].as_f64().unwrap(), zt["std"].as_f64().unwrap());
    assert!(((v + 40.0) / s).abs() < 4.0, "{zt}");
    let identified = zt["identified_mm"].as_f64().unwrap();
    assert!((identified - (-250.0 + v / 1000.0)).abs() < 1e-12, "{zt}");
    // Other parameters carry no lengths.
    assert!(param(&j, "XOC").get("nominal_mm").is_none());
    // The values predict another test of the machine to the noise.
    let text = ok(
        &dir,
        &words("validate --machine head-table-bc --params id.json --data turn.csv --json val.json"),
    );
    assert!(text.contains("turn.csv"), "{text}");
    let v = read_json(&dir.join("val.json"));
    let (before, after) = (
        v["measured_rms_um"].as_f64().unwrap(),
        v["residual_rms_um"].as_f64().unwrap(),
    );
    assert!(before > 20.0 && after < 0.6, "{before} -> {after}");
}

/// The identified pivot length goes into the corrected description's `[symbols]` (beside the
/// folded location errors); identified again with that description, the change is zero
/// within its uncertainty.
#[test]
fn an_identified_pivot_length_is_folded_into_the_corrected_description() {
    let dir = temp_dir("fold");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "pair.csv", &[]);
    let identify = |machine: &str, json: &str| {
        ok(
            &dir,
            &[
                "identify",
                "--machine",
                machine,
                "--terms",
                DETERMINED,
                "--data",
                "pair.csv",
                "--json",
                json,
            ],
        );
        read_json(&dir.join(json))
    };
    let first = identify("head-table-bc", "id.json");
    let zt = param(&first, "Zt")["value"].as_f64().unwrap();
    let text = ok(
        &dir,
        &words(
            "compensate --machine head-table-bc --params id.json --kinematics-out corrected.toml",
        ),
    );
    assert!(
        text.lines()
            .any(|l| l.contains("folded: Zt = ") && l.contains("into its default")),
        "{text}"
    );
    let toml = std::fs::read_to_string(dir.join("corrected.toml")).unwrap();
    let default: f64 = toml
        .lines()
        .find_map(|l| l.trim().strip_prefix("Zt = "))
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("Zt in [symbols]: {toml}"))
        .parse()
        .unwrap();
    assert!(
        (default - (-250.0 + zt / 1000.0)).abs() < 1e-12,
        "{default}, {zt}"
    );
    assert!(toml.contains("#   Zt changed by "), "{toml}");
    let again = identify("corrected.toml", "again.json");
    for name in ["Zt", "XOC", "YOC"] {
        let p = param(&again, name);
        let (v, s) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        assert!((v / s).abs() < 4.0, "{name} identified again: {p}");
    }
}

#[test]
fn a_ball_position_is_reported_as_not_separable_from_its_set_up_error() {
    let dir = temp_dir("ball");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "pair.csv", &[]);
    let text = ok(
        &dir,
        &words(
            "identify --machine head-table-bc --model location --terms Xw,Zt --data pair.csv --json id.json",
        ),
    );
    let line = text.lines().find(|l| l.starts_with("Xw ")).unwrap();
    assert!(
        line.contains("not determined: confounded with XOW  (nominal 120 mm)"),
        "{line}"
    );
    assert!(text.contains("[XOW, Xw]"), "{text}");
    let j = read_json(&dir.join("id.json"));
    let xw = param(&j, "Xw");
    assert!(xw["value"].is_null() && xw["std"].is_null(), "{xw}");
    assert_eq!(xw["determined"], false);
    assert_eq!(xw["nominal_mm"], 120.0);
    assert!(xw["identified_mm"].is_null(), "{xw}");
    let groups = j["confounded"].as_array().unwrap();
    assert!(
        groups
            .iter()
            .any(|g| g == &serde_json::json!(["XOW", "Xw"])),
        "{groups:?}"
    );
    // The pivot length stays determined next to them.
    assert!(param(&j, "Zt")["value"].is_number());
}

#[test]
fn the_seed_machine_probe_length_is_confounded_with_zoa_and_found_without_it() {
    let dir = temp_dir("seed");
    write(
        &dir,
        "truth.toml",
        "noise_um = 0.3
seed = 3
[parameters]
Zp = 184.695
[errors]
XOW = 12.0
YOW = -18.0
ZOW = 15.0
YOA = 20.0
BOA = 25.0
COA = -18.0
XOC = 10.0
YOC = -22.0
AOC = 30.0
BOC = -12.0
",
    );
    ok(
        &dir,
        &words("simulate --machine seed-ac --path K4 --truth truth.toml -o k4.csv"),
    );
    let text = ok(
        &dir,
        &words("identify --machine seed-ac --model reduced --terms Zp --data k4.csv"),
    );
    assert!(text.contains("[ZOA, Zp]"), "{text}");
    ok(
        &dir,
        &words(
            "identify --machine seed-ac --terms XOW,YOW,ZOW,YOA,BOA,COA,XOC,YOC,AOC,BOC,Zp --data k4.csv --json id.json",
        ),
    );
    let j = read_json(&dir.join("id.json"));
    let zp = param(&j, "Zp");
    assert_eq!(zp["nominal_mm"], 184.67);
    let (v, s) = (zp["value"].as_f64().unwrap(), zp["std"].as_f64().unwrap());
    assert!(((v - 25.0) / s).abs() < 4.0, "{zp}");
}

#[test]
fn a_campaign_shares_the_pivot_length_and_refuses_records_that_disagree_on_it() {
    let dir = temp_dir("campaign");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "near.csv", &[]);
    simulate_head_table(&dir, "turn-B", "6", "far.csv", &["--param", "Xw=60"]);
    write(
        &dir,
        "c.toml",
        "[[record]]\nfile = \"near.csv\"\n\n[[record]]\nfile = \"far.csv\"\nparams = { Xw = 60.0 }\n",
    );
    let model = format!("{DETERMINED},Xw");
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "head-table-bc",
            "--terms",
            &model,
            "--campaign",
            "c.toml",
            "--json",
            "c.json",
        ],
    );
    let j = read_json(&dir.join("c.json"));
    let zt = param(&j, "Zt");
    assert_eq!(zt["owner"], "shared");
    assert_eq!(zt["nominal_mm"], -250.0);
    let (v, s) = (zt["value"].as_f64().unwrap(), zt["std"].as_f64().unwrap());
    assert!(((v + 40.0) / s).abs() < 4.0, "{zt}");
    let far = param(&j, "Xw[far]");
    assert_eq!(far["owner"], "setup");
    assert_eq!(far["nominal_mm"], 60.0);
    // The campaign report reads back for validation.
    ok(
        &dir,
        &words(
            "validate --machine head-table-bc --params c.json --data far.csv --setup far --param Xw=60",
        ),
    );
    // Two records modelled with different pivot lengths cannot share one change of it.
    write(
        &dir,
        "bad.toml",
        "[[record]]\nfile = \"near.csv\"\n\n[[record]]\nfile = \"far.csv\"\nparams = { Xw = 60.0, Zt = -250.01 }\n",
    );
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "head-table-bc",
            "--terms",
            &model,
            "--campaign",
            "bad.toml",
            "--json",
            "bad.json",
        ],
        1,
        &[
            "kinematic offset `Zt` is one length of the machine",
            "records `near` and `far`",
            "-250 and -250.01 mm",
        ],
    );
    assert!(!dir.join("bad.json").exists());
}

#[test]
fn a_sub_model_of_a_description_may_hold_a_symbol() {
    let dir = temp_dir("model");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "pair.csv", &[]);
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/model-spec/machines/head-table-bc.toml"
    ))
    .unwrap();
    let list = DETERMINED
        .split(',')
        .map(|t| format!("\"{t}\""))
        .collect::<Vec<_>>()
        .join(", ");
    write(
        &dir,
        "m.toml",
        &format!("{text}\n[models.pivot]\nerrors = [{list}]\n"),
    );
    let out = ok(
        &dir,
        &words("identify --machine m.toml --model pivot --data pair.csv"),
    );
    assert!(
        out.contains("(change; nominal -250 mm, identified -250.04"),
        "{out}"
    );
    // A symbol that reads as an error of the machine is refused where it is written.
    let renamed = text.replace("Zt = -250.0", "x0c = 1.0\nZt = -250.0");
    write(&dir, "bad.toml", &renamed);
    let line = renamed.lines().position(|l| l.starts_with("x0c")).unwrap() + 1;
    fails(
        &dir,
        &words("identify --machine bad.toml --model location --data pair.csv"),
        1,
        &[
            &format!("bad.toml:{line}:1: symbol `x0c` reads as the error XOC"),
            "rename the symbol",
        ],
    );
}

#[test]
fn a_kinematic_offset_takes_no_basis_and_is_named_as_written() {
    let dir = temp_dir("terms");
    write(&dir, "truth.toml", HEAD_TABLE_TRUTH);
    simulate_head_table(&dir, "pair-B-C", "4", "pair.csv", &[]);
    fails(
        &dir,
        &words(
            "identify --machine head-table-bc --model location --terms Zt@harmonic:1 --data pair.csv",
        ),
        2,
        &[
            "--terms: `Zt@harmonic:1`",
            "kinematic offset of the machine",
            "constants only, not `harmonic:1`",
        ],
    );
    fails(
        &dir,
        &words("identify --machine head-table-bc --model location --terms zt --data pair.csv"),
        2,
        &["--terms: `zt`", "its kinematic symbol is written `Zt`"],
    );
    fails(
        &dir,
        &words("identify --machine head-table-bc --model location --terms Qq --data pair.csv"),
        2,
        &[
            "--terms: `Qq`",
            "its kinematic symbols, whose changes a term may identify too: Xc Yc Zc Xw Yw Zw Xb Yb Zb Zt",
        ],
    );
}
