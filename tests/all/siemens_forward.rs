//! `rtest compensate --siemens`: the swivel data record it writes, read back from the part
//! program's text and run through an independent implementation of the documented chain of
//! SINUMERIK's orientable toolholder (W1 §2.5, the CYCLE800 commissioning manual IM9: types T,
//! P and M), must put the tool where the machine with the identified location errors puts it,
//! relative to its table, to 1e-9 mm at 50 poses. Nothing of rtest's kinematics is used for
//! the chain: the record's vectors, the machine axes and the rotary axes' order come from the
//! file; the machine side is the exact virtual machine with the identified values.

use crate::common::{self, ok, words};
use model_spec::{Machine, Side};
use nalgebra::{Matrix3, Vector3};
use simulation::exact::VirtualMachine;
use std::collections::BTreeMap;

/// A swivel data record as the part program sets it.
#[derive(Clone, Debug)]
struct Record {
    kind: char,
    l1: Vector3<f64>,
    l2: Vector3<f64>,
    l3: Vector3<f64>,
    l4: Vector3<f64>,
    v1: Vector3<f64>,
    v2: Vector3<f64>,
    /// `$TC_CARR24`, `25`: the rotary axes' offsets (degrees).
    offsets: [f64; 2],
}

/// A linear machine axis: the description's axis it is and the sign, in X1, Y1, Z1 order.
struct Axes {
    linear: Vec<(String, f64)>,
    rotary: [String; 2],
}

/// The `$TC_CARRn[1]=value` assignments of `text` (every one; a repeated one is refused).
fn assignments(text: &str) -> BTreeMap<u32, String> {
    let mut out = BTreeMap::new();
    for line in text.lines() {
        let code = line.split(';').next().unwrap();
        for word in code.split_whitespace() {
            let rest = word
                .strip_prefix("$TC_CARR")
                .unwrap_or_else(|| panic!("{word}"));
            let (n, value) = rest.split_once("[1]=").unwrap_or_else(|| panic!("{word}"));
            let old = out.insert(n.parse::<u32>().unwrap(), value.to_string());
            assert!(old.is_none(), "$TC_CARR{n} set twice");
        }
    }
    out
}

fn parse_record(text: &str) -> Record {
    let body: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with(';') && !l.is_empty())
        .collect();
    assert_eq!(body.last(), Some(&"M30"), "{text}");
    let a = assignments(&body[..body.len() - 1].join("\n"));
    let num = |n: u32| -> f64 { a[&n].parse().unwrap_or_else(|_| panic!("{n}: {}", a[&n])) };
    let v = |first: u32| Vector3::new(num(first), num(first + 1), num(first + 2));
    // The fine offsets are 0: the basic values are the whole record.
    for n in (41..=46).chain(55..=60).chain(64..=65) {
        assert_eq!(num(n), 0.0, "$TC_CARR{n}");
    }
    let kind = a[&23].trim_matches('"');
    assert_eq!(kind.len(), 1, "{kind}");
    Record {
        kind: kind.chars().next().unwrap(),
        l1: v(1),
        l2: v(4),
        v1: v(7),
        v2: v(10),
        l3: v(15),
        l4: v(18),
        offsets: [num(24), num(25)],
    }
}

/// The axes from the comments: `; Machine axes: X1 = -X, Y1 = Y, ...` and `rotary axis 1 = A,
/// rotary axis 2 = C`.
fn parse_axes(text: &str) -> Axes {
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("; Machine axes: "))
        .unwrap();
    let map: BTreeMap<&str, &str> = line
        .trim_end_matches('.')
        .split(", ")
        .map(|p| p.split_once(" = ").unwrap())
        .collect();
    let linear = ["X1", "Y1", "Z1"]
        .iter()
        .map(|n| {
            let a = map[n];
            match a.strip_prefix('-') {
                Some(a) => (a.to_string(), -1.0),
                None => (a.to_string(), 1.0),
            }
        })
        .collect();
    let after = |key: &str| {
        let i = text.find(key).unwrap() + key.len();
        text[i..].chars().next().unwrap().to_string()
    };
    Axes {
        linear,
        rotary: [after("rotary axis 1 = "), after("rotary axis 2 = ")],
    }
}

/// The right-handed rotation by `deg` degrees about `v` (Rodrigues, `v` normalised).
fn rot(v: &Vector3<f64>, deg: f64) -> Matrix3<f64> {
    let k = v / v.norm();
    let (s, c) = deg.to_radians().sin_cos();
    let kx = Matrix3::new(0.0, -k.z, k.y, k.z, 0.0, -k.x, -k.y, k.x, 0.0);
    Matrix3::identity() + kx * s + kx * kx * (1.0 - c)
}

/// The documented chain: the tool tip relative to the table (machine coordinates of the table
/// at rotary axes 0) for the linear machine axes at `j` and the axis positions `a1`, `a2`
/// (degrees). Tool length 0: the controlled point is the tool reference.
///
/// - T: `tip = J − (l1 + R1·(l2 + R2·l3))`, the table does not move;
/// - P: the tool tip is `J`; the table turns about `v1` through `l2` and about `v2` through
///   `l2 + l3` (W1: l2 from the machine reference point to the first axis, l3 to the second);
///   its reference point moves from `T(0) = l2 + l3 + l4` to `T(α) = l2 + R1·(l3 + R2·l4)`
///   while it turns by `R1·R2`;
/// - M: `tip = J − (l1 + R1·l2)`; the table turns about `v2` through `l3`, its reference point
///   from `l3 + l4` to `l3 + R2·l4`.
fn forward(r: &Record, j: &Vector3<f64>, a1: f64, a2: f64) -> Vector3<f64> {
    let (r1, r2) = (rot(&r.v1, a1 - r.offsets[0]), rot(&r.v2, a2 - r.offsets[1]));
    match r.kind.to_ascii_uppercase() {
        'T' => j - (r.l1 + r1 * (r.l2 + r2 * r.l3)),
        'P' => {
            // A table point p goes to T(α) + R1·R2·(p − T(0)); the tool at J is over the point
            // p = T(0) + (R1·R2)ᵀ·(J − T(α)).
            let t0 = r.l2 + r.l3 + r.l4;
            let ta = r.l2 + r1 * (r.l3 + r2 * r.l4);
            t0 + (r1 * r2).transpose() * (j - ta)
        }
        'M' => {
            let tip = j - (r.l1 + r1 * r.l2);
            let t0 = r.l3 + r.l4;
            let ta = r.l3 + r2 * r.l4;
            t0 + r2.transpose() * (tip - ta)
        }
        other => panic!("kinematic type {other}"),
    }
}

/// The values (mm, rad; catalogue order) of the errors the record's comments say it holds
/// (`; Held: NAME = …`), read from the identification `id`.
fn held_values(m: &Machine, text: &str, id: &serde_json::Value) -> (Vec<f64>, Vec<String>) {
    let held: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("; Held: "))
        .filter_map(|l| l.split_once(" = ").map(|(n, _)| n.to_string()))
        .collect();
    let mut values = vec![0.0; m.catalogue.len()];
    for name in &held {
        let p = id["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name.as_str())
            .unwrap_or_else(|| panic!("{name}"));
        let scale = match p["unit"].as_str().unwrap() {
            "um" => 1e-3,
            "urad" => 1e-6,
            u => panic!("{u}"),
        };
        values[m.error_by_name(name).unwrap()] = p["value"].as_f64().unwrap() * scale;
    }
    (values, held)
}

/// The largest miss (mm), at 50 poses over the axes' ranges, between `r` and machine `m` with
/// the error values `values`: the tool point relative to the table (the work chain at every
/// axis 0), from the tool point at every axis 0.
fn largest_miss(m: &Machine, values: &[f64], r: &Record, axes: &Axes) -> f64 {
    let vm = VirtualMachine::new(m);
    let params = m.default_parameters();
    let zero = vec![0.0; m.axes.len()];
    let origin = vm
        .chain_transform(Side::Tool, &zero, &params, values)
        .translation
        .vector;
    let w0 = vm.chain_transform(Side::Work, &zero, &params, values);
    let mut largest = 0.0f64;
    for k in 0..50 {
        let q: Vec<f64> = m
            .axes
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let [lo, hi] = if a.limits[0].is_finite() {
                    a.limits
                } else {
                    [-360.0, 360.0]
                };
                // A scrambled fraction per pose and axis (a fixed, spread set of poses).
                let f = ((k as f64 + 0.31) * (0.754_877_666 + 0.0917 * i as f64) * 7.13).fract();
                let v = lo + f * (hi - lo);
                if a.kind == model_spec::AxisKind::Rotary {
                    v.to_radians()
                } else {
                    v
                }
            })
            .collect();
        let tool = vm.chain_transform(Side::Tool, &q, &params, values);
        let work = vm.chain_transform(Side::Work, &q, &params, values);
        let want =
            (w0 * work.inverse_transform_point(&tool.translation.vector.into())).coords - origin;
        let command = |name: &str| q[m.axis_by_name(name).unwrap()];
        let j = Vector3::from_iterator(axes.linear.iter().map(|(a, s)| s * command(a)));
        let got = forward(
            r,
            &j,
            command(&axes.rotary[0]).to_degrees(),
            command(&axes.rotary[1]).to_degrees(),
        );
        largest = largest.max((got - want).abs().max());
    }
    largest
}

/// The record, the axes, the held errors' values and the program's text of `compensate
/// --siemens` for machine `name` measured on `path` with the errors of `truth` (TOML lines of
/// `[errors]`), identified with model `model`.
fn written(
    name: &str,
    path: &str,
    truth: &str,
    model: &str,
) -> (Machine, Record, Axes, Vec<f64>, String) {
    let dir = common::temp_dir_tagged("siemens-forward", name);
    std::fs::write(
        dir.join("truth.toml"),
        format!("machine = \"{name}\"\n[errors]\n{truth}\n"),
    )
    .unwrap();
    ok(
        &dir,
        &words(&format!(
            "simulate --machine {name} --path {path} --truth truth.toml -o m.csv"
        )),
    );
    ok(
        &dir,
        &words(&format!(
            "identify --machine {name} --model {model} --data m.csv --json id.json"
        )),
    );
    ok(
        &dir,
        &words(&format!(
            "compensate --machine {name} --params id.json --siemens out"
        )),
    );
    let text = std::fs::read_to_string(dir.join("out/TC_CARR_1.MPF")).unwrap();
    let id = common::read_json(&dir.join("id.json"));
    let m = model_spec::builtin::builtin(name).unwrap().unwrap();
    let (values, held) = held_values(&m, &text, &id);
    assert!(held.len() >= 4, "{held:?}\n{text}");
    (m, parse_record(&text), parse_axes(&text), values, text)
}

/// Checks the record of `name` against the machine with its held errors, and that the same
/// record misses the nominal machine by the errors' size; the record.
fn check(name: &str, path: &str, truth: &str, model: &str, kind: char) -> Record {
    let (m, r, axes, values, text) = written(name, path, truth, model);
    assert_eq!(r.kind, kind, "{text}");
    let miss = largest_miss(&m, &values, &r, &axes);
    assert!(miss < 1e-9, "{name}: {miss} mm\n{text}");
    // The check can fail: the machine without its errors is missed by their size (tens of µm).
    let nominal = largest_miss(&m, &vec![0.0; values.len()], &r, &axes);
    assert!(nominal > 5e-3 && nominal < 0.2, "{name}: {nominal} mm");
    // And a rotary axis turned the other way misses by far more.
    let mut flipped = r.clone();
    flipped.v2 = -flipped.v2;
    assert!(largest_miss(&m, &values, &flipped, &axes) > 1.0);
    r
}

#[test]
fn seed_ac_record_puts_the_tool_where_the_machine_with_its_location_errors_does() {
    check(
        "seed-ac",
        "K4",
        "YOA = 19.0\nZOA = -14.0\nXOC = 10.0\nYOC = -21.0\nAOC = 12.0\nBOC = -9.0\nXOW = 5.0\nYOW = -4.0\nZOW = 3.0",
        "reduced",
        'P',
    );
}

#[test]
fn table_table_bc_record_puts_the_tool_where_the_machine_with_its_location_errors_does() {
    check(
        "table-table-bc",
        "pair-B-C",
        "XOB = 18.0\nZOB = -22.0\nXOC = -15.0\nYOC = 25.0\nAOC = 12.0\nBOC = -9.0\nXOW = 5.0\nYOW = -4.0\nZOW = 3.0",
        "location",
        'P',
    );
}

#[test]
fn nutating_table_record_puts_the_tool_where_the_machine_with_its_location_errors_does() {
    let r = check(
        "nutating-table-bc",
        "pair-B-C",
        "XOB = 14.0\nYOB = -11.0\nXOC = -15.0\nYOC = 21.0\nAOC = 8.0\nBOC = -13.0\nXOW = 5.0\nYOW = -4.0\nZOW = 3.0",
        "location",
        'P',
    );
    // v1 is the inclined B axis, (0, −1, 1)/√2, turned by the identified AOB, BOB (none in the
    // truth: a fraction of a µrad).
    let s = std::f64::consts::FRAC_1_SQRT_2;
    assert!((r.v1 - Vector3::new(0.0, -s, s)).norm() < 1e-6, "{}", r.v1);
}

#[test]
fn head_table_bc_record_of_type_m_puts_the_tool_where_the_machine_does() {
    // pair-B-C cannot tell XOB from XOC, YOC from AOZ nor ZOB from ZOW: the constraint fixes the
    // ones the truth does not have.
    check(
        "head-table-bc",
        "pair-B-C",
        "XOB = 18.0\nZOB = -12.0\nYOC = 25.0\nAOC = 12.0\nBOC = -9.0",
        "location --constraint zero:AOZ,XOC,ZOW",
        'M',
    );
}

#[test]
fn head_head_ca_record_of_type_t_puts_the_tool_where_the_machine_does() {
    // K4 cannot tell the set-up XOW YOW ZOW from XOC YOC ZOA: the truth places the ball exactly.
    check(
        "head-head-ca",
        "K4",
        "XOC = 11.0\nYOC = -13.0\nYOA = 17.0\nZOA = -9.0",
        "location --constraint zero:XOW,YOW,ZOW",
        'T',
    );
}
