//! Sensor records: read through the instrument into error vectors with covariances, exactly;
//! their errors name the file, line and column; zeroed readings; machine-frame instruments on a
//! machine whose tool frame turns.

use formats::csv::{CsvError, ReadOptions};
use formats::sensors::{format_sensor_record, parse_sensor_measurement};
use formats::truth::builtin_truth;
use model_spec::instrument::{Instrument, ReadingsFrame, preset};
use model_spec::{Machine, builtin};
use simulation::instrument::convert::{SensorRecord, to_record};
use simulation::instrument::head::SensorHead;
use simulation::instrument::simulate::simulate_sensors;
use simulation::paths::{fill_linear_ik, record_from_commands};
use simulation::record::Record;
use simulation::{builtin_path, simulate};

fn seed_ac() -> Machine {
    builtin("seed-ac").unwrap().unwrap()
}

fn instrument(name: &str) -> Instrument {
    preset(name).unwrap().unwrap()
}

/// The readings `head` gives for the error vectors of `record`, without noise.
fn clean_readings(head: &SensorHead, record: &Record) -> SensorRecord {
    SensorRecord {
        record: Record {
            samples: record.samples.clone(),
            ..Default::default()
        },
        readings: record
            .measured
            .iter()
            .map(|e| head.readings(*e).unwrap())
            .collect(),
    }
}

fn worst(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
}

/// The demo truth's error vectors along K4, noise-free.
fn k4_vectors(m: &Machine) -> Record {
    let mut truth = builtin_truth("seed-ac-demo", m).unwrap().unwrap();
    truth.noise_mm = 0.0;
    truth.zeroed = false;
    simulate(m, &truth, &builtin_path(m, "K4").unwrap().unwrap()).unwrap()
}

#[test]
fn a_sensor_csv_reads_back_to_the_error_vectors_it_was_made_from() {
    let m = seed_ac();
    let vectors = k4_vectors(&m);
    for name in ["orthogonal", "inclined-45", "four-45"] {
        let i = instrument(name);
        let head = SensorHead::new(&i);
        let sensors = clean_readings(&head, &vectors);
        let csv = format_sensor_record(&m, &i, &sensors, &["test".into()]).unwrap();
        assert!(csv.contains(&i.columns().join(",")), "{csv}");
        let r = parse_sensor_measurement(
            "k4.csv",
            &csv,
            &m,
            &i,
            ReadingsFrame::Tool,
            &ReadOptions::default(),
        )
        .unwrap();
        assert_eq!(r.samples.len(), vectors.samples.len());
        // The readings were written in µm as the shortest decimals that read back, so the
        // inverse sees the same readings: the error vectors come back to 1e-12 mm.
        assert!(worst(&r.measured, &vectors.measured) < 1e-12, "{name}");
        assert_eq!(r.covariance.len(), r.samples.len());
        assert_eq!(
            r.lines[0], 3,
            "a comment line, the header, then the first row"
        );
        assert!(!r.looks_zeroed());
    }
}

fn read(text: &str, i: &Instrument) -> Result<Record, CsvError> {
    parse_sensor_measurement(
        "s.csv",
        text,
        &seed_ac(),
        i,
        ReadingsFrame::Tool,
        &ReadOptions::default(),
    )
}

#[test]
fn bad_sensor_files_name_the_file_line_and_column() {
    let i = instrument("inclined-45");
    let rows = "A,C,s1_um,s2_um,s3_um\n0,0,1,2,3\n0,1,1,2,3\n";
    assert!(read(rows, &i).is_ok());
    let cases = [
        (
            "# a comment\nA,C,s1_um,s3_um\n0,0,1,3\n",
            "s.csv:2: missing column(s) s2_um (sensor readings, µm): every sensor of the instrument needs a column",
        ),
        (
            "A,C,s1_um,s2_um,s3_um\n0,0,1,2,3\n0,1,1,nan,3\n",
            "s.csv:3: column 4 `s2_um`: `nan` is not a finite number (µm)",
        ),
        (
            "A,C,s1_um,s2_um,s3_um\n0,0,1,2,3\n0,1,1,,3\n",
            "s.csv:3: column 4 `s2_um`: empty field: expected a number (µm)",
        ),
        (
            "A,C,s1_um,s2_um,s3_um,s4_um\n0,0,1,2,3,4\n",
            "s.csv:1: column 6 `s4_um`: unknown column `s4_um`",
        ),
        (
            "A,C,dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n0,0,0,0,0,1,2,3\n",
            "s.csv:1: a record of the sensor readings of instrument inclined-45 has the columns s1_um, s2_um, s3_um, not dx_um, dy_um, dz_um",
        ),
        (
            // 11.9 mm on every sensor: no displacement puts the ball there.
            "A,C,s1_um,s2_um,s3_um\n0,0,1,2,3\n0,1,11900,11900,11900\n",
            "s.csv:3: the readings of instrument inclined-45 give no error vector: ",
        ),
        (
            // 20 mm: more than any plausible head reads (1 mm × gain 2 + a zero of 10 mm).
            "A,C,s1_um,s2_um,s3_um\n0,0,1,2,3\n0,1,20000,2,3\n",
            "s.csv:3: column 3 `s1_um`: 20000 µm is beyond the plausibility bound of a sensor's reading, ±12000 µm",
        ),
    ];
    for (text, want) in cases {
        let e = read(text, &i).unwrap_err().to_string();
        assert!(e.starts_with(want), "{e}\nwanted: {want}");
    }
    // Readings far beyond the plausibility bound (2 mm along x) are refused with their lines.
    let flat = instrument("orthogonal");
    let e = read("A,C,s1_um,s2_um,s3_um\n0,0,0,0,0\n0,1,2000,0,0\n", &flat)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("1 reading beyond the plausibility bound of 1000 µm: line 3 dx_um = 2000")
            && e.contains("(the error vectors that the readings of instrument orthogonal give)"),
        "{e}"
    );
}

#[test]
fn zeroed_readings_read_as_a_zeroed_record() {
    let m = seed_ac();
    let vectors = k4_vectors(&m);
    let e0 = vectors.measured[0];
    for (name, bound_mm) in [("orthogonal", 1e-12), ("inclined-45", 1e-3)] {
        let i = instrument(name);
        let head = SensorHead::new(&i);
        let mut sensors = clean_readings(&head, &vectors);
        let first = sensors.readings[0].clone();
        for r in &mut sensors.readings {
            for (v, f) in r.iter_mut().zip(&first) {
                *v -= f;
            }
        }
        assert!(sensors.looks_zeroed());
        let r = to_record(&head, &m, ReadingsFrame::Tool, &sensors).unwrap();
        assert_eq!(r.measured[0], [0.0; 3]);
        assert!(r.looks_zeroed());
        // Against the error vectors zeroed in displacement space: exact for flat tips, to first
        // order for ball tips (|e₀|·|e|/(R + r) at most).
        let shifted: Vec<[f64; 3]> = vectors
            .measured
            .iter()
            .map(|e| [e[0] - e0[0], e[1] - e0[1], e[2] - e0[2]])
            .collect();
        let w = worst(&r.measured, &shifted);
        assert!(w < bound_mm, "{name}: {w:e} mm");
        if name == "inclined-45" {
            // Per sensor the neglected term is e₀⊥·(e − e₀)⊥/(R + r), at most
            // |e₀|·|e − e₀|/(R + r); the inverse's first-order matrix (smallest singular value
            // √0.75) turns three of them into at most √3/√0.75 = 2 times that.
            let size = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let largest = shifted.iter().map(size).fold(0.0, f64::max);
            let bound = 2.0 * size(&e0) * largest / 14.7;
            eprintln!(
                "zeroed in sensor space, ball tips: {:.4} µm at most (|e₀| {:.2} µm, |e − e₀| up to {:.2} µm, bound {:.4} µm)",
                w * 1e3,
                size(&e0) * 1e3,
                largest * 1e3,
                bound * 1e3
            );
            assert!(w <= bound, "{w:e}");
        }
    }
}

/// A path on head-table-bc: C turns, B swings the head (and the tool frame) by up to 90°.
fn bc_path(m: &Machine) -> Record {
    let b = m.axis_by_name("B").unwrap();
    let c = m.axis_by_name("C").unwrap();
    let mut commands: Vec<Vec<f64>> = (0..=120)
        .map(|i| {
            let cc = 3.0 * i as f64;
            let mut q = vec![0.0; m.axes.len()];
            q[c] = cc.to_radians();
            q[b] = (-45.0 * (1.0 - cc.to_radians().cos())).to_radians();
            q
        })
        .collect();
    fill_linear_ik(m, &m.default_parameters(), &mut commands).unwrap();
    record_from_commands(commands, (0..=120).map(f64::from).collect())
}

#[test]
fn a_machine_frame_instrument_is_rotated_into_the_turning_tool_frame() {
    let m = builtin("head-table-bc").unwrap().unwrap();
    let text = r#"
machine = "head-table-bc"
noise_um = 0.0
seed = 4
[errors]
XOC = 20.0
YOC = -15.0
XOB = 12.0
ZOB = -10.0
AOB = 40.0
XOW = 8.0
"#;
    let truth = formats::truth::parse_truth("bc.toml", text, &m).unwrap();
    let path = bc_path(&m);
    let vectors = simulate(&m, &truth, &path).unwrap();
    let mut i = instrument("orthogonal");
    for s in &mut i.sensors {
        s.noise_mm = 1e-9; // 1e-6 µm: the comparison is of the geometry, not of the noise
    }
    let sensors = simulate_sensors(&m, &truth, &path, &i, ReadingsFrame::Machine).unwrap();
    let head = SensorHead::new(&i);
    let r = to_record(&head, &m, ReadingsFrame::Machine, &sensors).unwrap();
    assert!(
        worst(&r.measured, &vectors.measured) < 1e-8,
        "back in the tool frame"
    );
    // Read as tool-frame displacements they are wrong where B has turned the head.
    let wrong = to_record(&head, &m, ReadingsFrame::Tool, &sensors).unwrap();
    assert!(worst(&wrong.measured, &vectors.measured) > 5e-3);
    assert!(
        worst(&wrong.measured[..1], &vectors.measured[..1]) < 1e-8,
        "B = 0 at the start"
    );
    // The covariance turns with them: Σ_tool = R₀ᵀ·Σ·R₀ has the same trace, other axes.
    let i45 = instrument("inclined-45");
    let h45 = SensorHead::new(&i45);
    let s45 = simulate_sensors(&m, &truth, &path, &i45, ReadingsFrame::Machine).unwrap();
    let r45 = to_record(&h45, &m, ReadingsFrame::Machine, &s45).unwrap();
    let tool = to_record(&h45, &m, ReadingsFrame::Tool, &s45).unwrap();
    let k = 60; // C = 180°, B = −90°
    let trace = |c: &[[f64; 3]; 3]| c[0][0] + c[1][1] + c[2][2];
    assert!((trace(&r45.covariance[k]) - trace(&tool.covariance[k])).abs() < 1e-20);
    assert!((r45.covariance[k][0][0] - tool.covariance[k][0][0]).abs() > 1e-9);
}
