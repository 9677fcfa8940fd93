//! `rtest gains --at`: the numbers at one pose in every format, as a new user reads them: the
//! pose with the axes the inverse kinematics filled, the units of every number, the position
//! and orientation rows, and zeros written `0` (identically zero, or vanishing at the pose
//! within the bound on the rounding error), never floating-point noise.

use crate::common;
use common::{json_here as json, ok_here as ok, seed_file, triple};

/// Table 3 of the seed (mm).
const XW: f64 = -217.504;
const YW: f64 = -0.279;
const ZW: f64 = 211.537;
const ZC: f64 = 29.794;
const TABLE_3: &str = "Xw=-217.504,Yw=-0.279,Zw=211.537,Zc=29.794";

/// The position gains of `error` in a `gains --at --format json` report.
fn position(v: &serde_json::Value, error: &str) -> [f64; 3] {
    triple(&v["gains"][error]["position"])
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
}

/// The seed's Table 2 formulas of BOA (ΔX and ΔZ).
fn boa_expected(a_deg: f64, c_deg: f64, xw: f64, yw: f64, zw: f64, zc: f64) -> [f64; 3] {
    let (sa, ca) = a_deg.to_radians().sin_cos();
    let (sc, cc) = c_deg.to_radians().sin_cos();
    [
        -ca * (zw + zc) - sa * sc * xw - sa * cc * yw,
        0.0,
        -sc * yw + cc * xw,
    ]
}

#[test]
fn gains_at_pose_match_the_seed_table_2() {
    let param = format!("{TABLE_3},Zp=184.67");
    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--at",
        "X=0,Y=0,Z=0,A=30,C=45",
        "--param",
        &param,
        "--format",
        "json",
    ]);
    let map = v["gains"].as_object().unwrap();
    assert_eq!(map.len(), 44, "every error of the full model");
    assert_eq!(position(&v, "XOC"), [-1.0, 0.0, 0.0]);
    let boa = position(&v, "BOA");
    let want = boa_expected(30.0, 45.0, XW, YW, ZW, ZC);
    for k in 0..3 {
        assert!(
            close(boa[k], want[k]),
            "BOA[{k}] = {} want {}",
            boa[k],
            want[k]
        );
    }
}

#[test]
fn gains_param_overrides_defaults() {
    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--at",
        "A=-60,C=200",
        "--param",
        "Xw=-100,Zc=10",
        "--format",
        "json",
    ]);
    assert_eq!(v["gains"].as_object().unwrap().len(), 11);
    let boa = position(&v, "BOA");
    let want = boa_expected(-60.0, 200.0, -100.0, YW, ZW, 10.0);
    for k in 0..3 {
        assert!(
            close(boa[k], want[k]),
            "BOA[{k}] = {} want {}",
            boa[k],
            want[k]
        );
    }
}

#[test]
fn gains_fill_missing_linear_axes_by_inverse_kinematics() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let params = m.default_parameters();
    let mut commands = vec![0.0; m.axes.len()];
    commands[m.axis_by_name("A").unwrap()] = 30f64.to_radians();
    commands[m.axis_by_name("C").unwrap()] = 45f64.to_radians();
    simulation::tool_centre_point_ik(&m, &mut commands, &params).unwrap();
    let model = codegen::GainModel::derive(&m, &m.errors);
    let want = model.evaluate(&commands, &params);

    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--at",
        "A=30,C=45",
        "--format",
        "json",
    ]);
    for (name, w) in model.error_names.iter().zip(&want) {
        let row = &v["gains"][name.as_str()];
        let got: Vec<f64> = [triple(&row["position"]), triple(&row["orientation"])].concat();
        for k in 0..6 {
            assert!(
                (got[k] - w[k]).abs() <= 1e-9 * (1.0 + w[k].abs()),
                "{name}[{k}]: {} vs {}",
                got[k],
                w[k]
            );
        }
    }
    // A given linear axis is kept, the others come from the inverse kinematics.
    let text = ok(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--at",
        "x=5,A=30,C=45",
    ]);
    assert!(text.contains("X = 5 mm,"), "{text}");
    let y = format!("Y = {:.6}", commands[m.axis_by_name("Y").unwrap()]);
    assert!(text.contains(&y) && text.contains("(IK)"), "{y} in {text}");
    assert!(text.contains("mm/rad") && text.contains("mm/mm"), "{text}");
    let boa = text
        .lines()
        .find(|l| l.starts_with("BOA"))
        .expect("BOA row");
    let want = boa_expected(30.0, 45.0, XW, YW, ZW, ZC);
    assert!(boa.contains(&format!("{:.6}", want[0])), "{boa}");
}

#[test]
fn gains_at_pose_other_formats() {
    let md = ok(&[
        "gains",
        "--machine",
        "seed-ac",
        "--errors",
        "XOC",
        "--at",
        "A=0,C=0",
        "--format",
        "markdown",
    ]);
    assert!(
        md.contains(
            "| XOC | mm/mm | -1.000000 | 0.000000 | 0.000000 | 0.000000 | 0.000000 | 0.000000 |"
        ),
        "{md}"
    );
    let tex = ok(&[
        "gains",
        "--machine",
        "seed-ac",
        "--errors",
        "BOA",
        "--at",
        "A=0,C=0",
        "--format",
        "latex",
    ]);
    assert!(tex.contains("$BOA$ & mm/rad"), "{tex}");
}

#[test]
fn machine_file_gives_the_same_numbers_as_the_builtin() {
    let dir = common::temp_dir_tagged("cli-gains", "gains-file");
    let file = seed_file(&dir);
    let file = file.to_str().unwrap();
    for (machine_args, at) in [
        ("full", "X=1,Y=2,Z=3,A=30,C=45"),
        ("reduced", "A=-45,C=120"),
    ] {
        let run = |machine: &str| {
            ok(&[
                "gains",
                "--machine",
                machine,
                "--model",
                machine_args,
                "--at",
                at,
                "--format",
                "json",
            ])
        };
        assert_eq!(run(file), run("seed-ac"));
    }
    let sym = |machine: &str| ok(&["gains", "--machine", machine, "--model", "reduced"]);
    assert_eq!(sym(file), sym("seed-ac"));
}

/// Every number of a JSON value, with its path.
fn numbers(v: &serde_json::Value, path: &str, out: &mut Vec<(String, serde_json::Number)>) {
    match v {
        serde_json::Value::Number(n) => out.push((path.to_string(), n.clone())),
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                numbers(x, &format!("{path}[{i}]"), out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                numbers(x, &format!("{path}.{k}"), out);
            }
        }
        _ => {}
    }
}

#[test]
fn the_json_gives_the_pose_the_units_and_both_rows() {
    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--at",
        "y=5,A=30,C=45",
        "--format",
        "json",
    ]);
    assert_eq!(v["machine"], "seed-ac");
    assert_eq!(v["model"], "reduced");
    let pose = &v["pose"];
    let axes: Vec<&String> = pose["commands"].as_object().unwrap().keys().collect();
    assert_eq!(axes.len(), 5, "{pose}");
    assert_eq!(pose["commands"]["Y"], 5.0, "a given axis is kept");
    assert_eq!(pose["commands"]["C"], 45.0);
    assert_eq!(
        pose["filled_by_inverse_kinematics"],
        serde_json::json!(["X", "Z"])
    );
    assert_eq!(pose["parameters"]["Xw"], XW);
    let units = &v["units"];
    assert_eq!(units["commands"]["X"], "mm");
    assert_eq!(units["commands"]["A"], "deg");
    assert_eq!(units["parameters"], "mm");
    let boa = &v["gains"]["BOA"];
    assert_eq!(boa["kind"], "angular");
    assert_eq!(boa["position_unit"], "mm/rad");
    assert_eq!(boa["orientation_unit"], "1/rad");
    let xoc = &v["gains"]["XOC"];
    assert_eq!(xoc["position_unit"], "mm/mm");
    assert_eq!(xoc["orientation_unit"], "1/mm");
    assert_eq!(
        triple(&xoc["orientation"]),
        [0.0, 0.0, 0.0],
        "a translation turns nothing"
    );
    // BOA turns the tool axis about y: its orientation row is (-cos C·…, …) and not all zero.
    assert!(
        triple(&boa["orientation"]).iter().any(|g| *g != 0.0),
        "{boa}"
    );
}

#[test]
fn zeros_are_written_0_and_no_gain_is_rounding_noise() {
    // Poses where sines and cosines of whole quarter turns round to about 1e-16.
    for at in [
        "A=0,C=0",
        "A=-90,C=180",
        "A=90,C=270",
        "A=30,C=90",
        "A=-45,C=-180",
    ] {
        let text = ok(&[
            "gains",
            "--machine",
            "seed-ac",
            "--at",
            at,
            "--format",
            "json",
        ]);
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let mut all = Vec::new();
        numbers(&v["gains"], "gains", &mut all);
        assert_eq!(all.len(), 44 * 6, "{at}");
        for (path, n) in &all {
            let x = n.as_f64().unwrap();
            if x == 0.0 {
                assert!(n.is_u64(), "{at}: {path} is a zero written {n}, not 0");
            } else {
                assert!(x.abs() > 1e-9, "{at}: {path} = {x} is rounding noise");
            }
        }
        assert!(!text.contains("e-1"), "{at}: a tiny number in\n{text}");
    }
}

#[test]
fn a_cancellation_at_the_pose_is_zero_and_listed() {
    // At C = 180° the sine of C is 1.2e-16 in floating point: the gains that carry sin C alone
    // vanish there, though their polynomials do not.
    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--at",
        "A=30,C=180",
        "--format",
        "json",
    ]);
    let listed: Vec<&str> = v["vanishing_at_this_pose"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert!(listed.contains(&"XOW gy"), "{listed:?}");
    assert_eq!(
        v["gains"]["XOW"]["position"],
        serde_json::json!([1.0, 0, 0])
    );
    // At C = 45° the same gains are not zero and nothing of XOW is listed.
    let v = json(&[
        "gains",
        "--machine",
        "seed-ac",
        "--model",
        "reduced",
        "--at",
        "A=30,C=45",
        "--format",
        "json",
    ]);
    let listed = v["vanishing_at_this_pose"].to_string();
    assert!(!listed.contains("XOW"), "{listed}");
    assert!(position(&v, "XOW")[1].abs() > 0.1, "{v}");
}

#[test]
fn every_table_format_has_both_rows_the_ik_mark_and_the_zero_rule() {
    for format in ["text", "markdown", "latex"] {
        let out = ok(&[
            "gains",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--at",
            "A=30,C=180",
            "--format",
            format,
        ]);
        assert!(out.contains("(IK)"), "{format}: {out}");
        assert!(out.contains("gi") || out.contains("g_i"), "{format}: {out}");
        assert!(out.contains("identically zero"), "{format}: {out}");
        assert!(out.contains("XOW gy"), "{format}: {out}");
        assert!(
            !out.contains("-0.000000"),
            "{format}: a negative zero in {out}"
        );
        assert!(!out.contains("e-"), "{format}: {out}");
    }
}
