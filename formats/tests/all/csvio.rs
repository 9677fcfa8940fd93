//! The measurement CSV: every malformed file is an error naming file, line and column;
//! write → read gives the same record bit for bit; files are written atomically.

#![allow(clippy::needless_range_loop)] // x, y, z components read best by index

use crate::common;

use common::{Scratch, builtin};
use formats::csv::{CsvError, ReadOptions, format_record, parse_measurement, read_measurement};
use formats::truth::seed_ac_demo_truth;
use model_spec::Machine;
use simulation::paths::builtin_path;
use simulation::readings::{provenance, simulate};
use simulation::record::Record;

fn seed_ac() -> Machine {
    builtin("seed-ac")
}

fn message(text: &str) -> String {
    match parse_measurement("m.csv", text, &seed_ac(), &ReadOptions::default()) {
        Ok(r) => panic!("accepted: {r:?}"),
        Err(e) => e.to_string(),
    }
}

const H: &str = "X,Y,Z,A,C,dx_um,dy_um,dz_um,t_s\n";
const ROW: &str = "1,2,3,0,0,0.5,0.25,-1,0\n";

#[test]
fn every_malformed_file_names_file_line_and_column() {
    let cases: Vec<(String, &str)> = vec![
        (
            String::new(),
            "m.csv:1: empty file: expected a header line naming the columns (columns of machine seed-ac: X (mm), Y (mm), Z (mm), A (deg), C (deg), dx_um, dy_um, dz_um, t_s)",
        ),
        (
            "# only a comment\n\n".into(),
            "m.csv:3: empty file: expected a header line",
        ),
        (
            H.into(),
            "m.csv:1: header only: the file has no samples (one row per sample expected after the header)",
        ),
        (
            "X,Y,Z,A,C,dx_um,dy_um\n1,2,3,0,0,1,2\n".into(),
            "m.csv:1: missing column(s) dz_um (measured error vector, µm): a measurement file needs dx_um, dy_um and dz_um",
        ),
        (
            "X,Y,Z,A,dx_um,dy_um,dz_um\n1,2,3,0,1,2,3\n".into(),
            "m.csv:1: missing column(s) C (rotary axes, degrees): every rotary axis needs a column",
        ),
        (
            "X,Y,Z,A,B,C,dx_um,dy_um,dz_um\n".into(),
            "m.csv:1: column 5 `B`: unknown column `B` (expected columns of machine seed-ac: X (mm), Y (mm), Z (mm), A (deg), C (deg), dx_um, dy_um, dz_um, t_s)",
        ),
        (
            "X,Y,Z,A,C,dx_mm,dy_um,dz_um\n".into(),
            "m.csv:1: column 6 `dx_mm`: unknown column `dx_mm`",
        ),
        (
            "X,Y,Z,A,C,,dx_um,dy_um,dz_um\n".into(),
            "m.csv:1: column 6 ``: empty column name",
        ),
        (
            "X,Y,Z,A,C,dx_um,dy_um,dz_um,x\n".into(),
            "m.csv:1: column 9 `x`: column `x` appears twice (also column 1)",
        ),
        (
            format!("{H}{ROW}1,2,3,0,0,0.5,abc,-1,1\n"),
            "m.csv:3: column 7 `dy_um`: `abc` is not a number (µm)",
        ),
        (
            format!("{H}{ROW}1,2,3,0,NaN,0.5,0,-1,1\n"),
            "m.csv:3: column 5 `C`: `NaN` is not a finite number (degrees)",
        ),
        (
            format!("{H}{ROW}1,2,inf,0,0,0.5,0,-1,1\n"),
            "m.csv:3: column 3 `Z`: `inf` is not a finite number (mm)",
        ),
        (
            format!("{H}{ROW}1,2,3,0,0,0.5,0,-1,-infinity\n"),
            "m.csv:3: column 9 `t_s`: `-infinity` is not a finite number (s)",
        ),
        (
            format!("{H}{ROW}1,2,3,0,0,0.5,0,-1\n"),
            "m.csv:3: ragged row: 8 field(s), the header (line 1) has 9 columns",
        ),
        (
            format!("{H}# c\n{ROW}1,2,3,0,0,0.5,0,-1,1,7\n"),
            "m.csv:4: ragged row: 10 field(s), the header (line 1) has 9 columns",
        ),
        (
            format!("{H}{ROW}1,2,3,0,0,0.5, ,-1,1\n"),
            "m.csv:3: column 7 `dy_um`: empty field: expected a number (µm)",
        ),
        (
            format!("{H}1,2,3,0,0,0.5,0,-1,5\n1,2,3,0,0,0.5,0,-1,4\n"),
            "m.csv:3: column 9 `t_s`: time 4 s is before the time of the previous sample (5 s, line 2): times must not decrease",
        ),
        (
            "X,A,C,dx_um,dy_um,dz_um\n1,0,0,0,0,0\n".into(),
            "m.csv:1: missing column(s) Y, Z (linear axes, mm): give every linear axis or none",
        ),
        (
            format!("{H}1,2,3,0,0,1e999,0,-1,0\n"),
            "m.csv:2: column 6 `dx_um`: `1e999` is not a finite number (µm)",
        ),
        (
            format!("{H}1,2,3,0,0,\"1\",0,-1,0\n"),
            "m.csv:2: column 6 `dx_um`: `\"1\"` is not a number (µm)",
        ),
    ];
    for (text, want) in &cases {
        let got = message(text);
        assert!(
            got.starts_with(want),
            "for\n{text}\ngot:  {got}\nwant: {want}"
        );
    }
}

#[test]
fn errors_carry_their_parts() {
    let e = parse_measurement(
        "m.csv",
        &format!("{H}{ROW}1,2,3,0,0,0.5,abc,-1,1\n"),
        &seed_ac(),
        &ReadOptions::default(),
    )
    .unwrap_err();
    match e {
        CsvError::Format {
            file,
            line,
            column,
            message,
        } => {
            assert_eq!(file, "m.csv");
            assert_eq!(line, 3);
            assert_eq!(column, Some((7, "dy_um".to_string())));
            assert_eq!(message, "`abc` is not a number (µm)");
        }
        other => panic!("{other:?}"),
    }
    // A file that does not exist, in a fresh scratch directory.
    let dir = Scratch::new("missing");
    let f = dir.0.join("no-such-file.csv");
    let e = read_measurement(&f, &seed_ac(), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, CsvError::Io { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with(&format!("cannot read `{}`: ", f.display())),
        "{e}"
    );
}

#[test]
fn units_order_case_comments_and_line_endings() {
    let m = seed_ac();
    // At A = -45°, C = 90° the nest is on the ball at X, Y, Z = -0.279, 16.848, 139.775 mm.
    let text = "\u{feff}# comment\r\n\r\n  \"t_s\" , c,A , z,Y,x,DZ_UM,dy_um,dx_um\r\n# another\r\n2.5,90,-45,139.775,16.848,-0.279,12.5,-0.25,1000\r\n";
    let r = parse_measurement("m.csv", text, &m, &ReadOptions::default()).unwrap();
    assert_eq!(r.samples.len(), 1);
    let s = &r.samples[0];
    let ax = |n: &str| s.commands[m.axis_by_name(n).unwrap()];
    assert_eq!((ax("X"), ax("Y"), ax("Z")), (-0.279, 16.848, 139.775));
    assert_eq!(ax("A"), (-45f64).to_radians());
    assert_eq!(ax("C"), 90f64.to_radians());
    assert_eq!(s.t, 2.5);
    assert_eq!(r.measured, vec![[1.0, -0.00025, 0.0125]]);
    assert_eq!(s.motion, vec![1; 5]);
}

#[test]
fn without_time_the_sample_index_is_the_time() {
    let m = seed_ac();
    let r = parse_measurement(
        "m.csv",
        "A,C,dx_um,dy_um,dz_um\n0,0,0,0,0\n0,1,0,0,0\n0,2,0,0,0\n",
        &m,
        &ReadOptions::default(),
    )
    .unwrap();
    let t: Vec<f64> = r.samples.iter().map(|s| s.t).collect();
    assert_eq!(t, vec![0.0, 1.0, 2.0]);
}

#[test]
fn missing_linear_columns_are_filled_by_inverse_kinematics() {
    let m = seed_ac();
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let mut text = String::from("A,C,dx_um,dy_um,dz_um,t_s\n");
    for s in &k4.samples {
        text += &format!(
            "{},{},1,2,3,{}\n",
            model_spec::units::degrees_for(s.commands[a]),
            model_spec::units::degrees_for(s.commands[c]),
            s.t
        );
    }
    let r = parse_measurement("m.csv", &text, &m, &ReadOptions::default()).unwrap();
    assert_eq!(r.samples, k4.samples);
    assert!(r.measured.iter().all(|v| *v == [0.001, 0.002, 0.003]));
}

#[test]
fn the_fixture_reads() {
    let m = seed_ac();
    let f = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/measurement-small.csv"
    );
    let r = read_measurement(std::path::Path::new(f), &m, &ReadOptions::default()).unwrap();
    assert_eq!(r.samples.len(), 2);
    assert_eq!(r.measured[0], [0.0015, -0.00225, 0.000125]);
    assert_eq!(r.measured[1], [-0.003, 0.0045, -0.0005]);
}

fn demo_k4() -> (Machine, Record) {
    let m = seed_ac();
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    let r = simulate(&m, &seed_ac_demo_truth(), &k4).unwrap();
    (m, r)
}

#[test]
fn write_then_read_is_bit_exact() {
    let (m, r) = demo_k4();
    let dir = Scratch::new("roundtrip");
    let f = dir.0.join("k4.csv");
    let truth = seed_ac_demo_truth();
    let comments = provenance(&m, "K4", &truth, r.samples.len());
    std::fs::write(&f, format_record(&m, &r, &comments).unwrap()).unwrap();
    let text = std::fs::read_to_string(&f).unwrap();
    assert!(text.starts_with("# simulated by rtest "), "{text}");
    assert!(text.contains("# machine: seed-ac\n# path: K4 (241 samples)\n# truth seed-ac-demo: "));
    assert!(text.contains("\nX,Y,Z,A,C,dx_um,dy_um,dz_um,t_s\n"));
    let back = read_measurement(&f, &m, &ReadOptions::default()).unwrap();
    assert_eq!(back.samples.len(), r.samples.len());
    for (a, b) in back.samples.iter().zip(&r.samples) {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.commands), bits(&b.commands));
        assert_eq!(a.t.to_bits(), b.t.to_bits());
        assert_eq!(a.motion, b.motion);
    }
    for (a, b) in back.measured.iter().zip(&r.measured) {
        for k in 0..3 {
            assert_eq!(a[k].to_bits(), b[k].to_bits());
        }
    }
    assert_eq!(back, r);
    // Writing what was read gives the same text.
    assert_eq!(format_record(&m, &back, &comments).unwrap(), text);
}

#[test]
fn a_bare_path_is_written_without_measured_columns() {
    let m = seed_ac();
    let k1 = builtin_path(&m, "K1").unwrap().unwrap();
    let text = format_record(&m, &k1, &[]).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("X,Y,Z,A,C,t_s"));
    assert!(lines.next().unwrap().ends_with(",0,0,0"), "{text}");
    assert_eq!(lines.nth(89).unwrap().split(',').nth(4), Some("90"));
    let back = formats::paths::parse_path("k1.csv", &text, &m, &ReadOptions::default()).unwrap();
    assert_eq!(back, k1);
}

#[test]
fn bad_records_are_refused_before_anything_is_written() {
    let (m, mut r) = demo_k4();
    r.measured.pop();
    let e = format_record(&m, &r, &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "cannot write the record: it has 241 samples but 240 measured vectors"
    );
    let (m, mut r) = demo_k4();
    r.measured[3][1] = f64::NAN;
    let e = format_record(&m, &r, &[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "cannot write the record: sample 3 has a non-finite value"
    );
}
