//! Calibration of an instrument's own errors from known displacements: gains, zeros and
//! directions found within their uncertainties; what the record does not determine gets no
//! number; the calibration record's errors name the file, line and column.

use fitting::calibrate::{CalibrationError, calibrate, tilt_axes};
use formats::csv::ReadOptions;
use formats::sensors::read_calibration;
use model_spec::instrument::{Instrument, parse_instrument, preset, write::to_toml};
use nalgebra::{Rotation3, Vector3};
use simulation::instrument::CalibrationRecord;
use simulation::instrument::head::SensorHead;
use simulation::rng::Rng;

fn instrument(name: &str) -> Instrument {
    preset(name).unwrap().unwrap()
}

/// A 5 × 5 × 5 grid of known displacements, ±100 µm: a calibrated three-axis move.
fn grid() -> Vec<[f64; 3]> {
    let steps = [-0.1, -0.05, 0.0, 0.05, 0.1];
    let mut out = Vec::new();
    for x in steps {
        for y in steps {
            for z in steps {
                out.push([x, y, z]);
            }
        }
    }
    out
}

/// The head `described` really is: gains off by `dg`, zeros `zeros_mm`, each sensor turned
/// about the nest centre by `tilts` (rad) about its tilt axes.
fn real(described: &Instrument, dg: &[f64], zeros_mm: &[f64], tilts: &[[f64; 2]]) -> Instrument {
    let mut r = described.clone();
    for (k, s) in r.sensors.iter_mut().enumerate() {
        let [p1, p2] = tilt_axes(s.direction).map(Vector3::from);
        let turn = Rotation3::new(p1 * tilts[k][0] + p2 * tilts[k][1]);
        let d = turn * Vector3::from(s.direction);
        let p = turn * Vector3::from(s.position_mm);
        s.direction = [d.x, d.y, d.z];
        s.position_mm = [p.x, p.y, p.z];
        s.gain *= 1.0 + dg[k];
        s.zero_mm = zeros_mm[k];
    }
    r
}

fn record(
    head: &SensorHead,
    displacements: Vec<[f64; 3]>,
    noise_mm: f64,
    seed: u64,
) -> CalibrationRecord {
    let mut rng = Rng::new(seed);
    let readings = displacements
        .iter()
        .map(|e| {
            head.readings(*e)
                .unwrap()
                .into_iter()
                .map(|v| v + noise_mm * rng.normal())
                .collect()
        })
        .collect();
    CalibrationRecord {
        lines: (2..2 + displacements.len()).collect(),
        displacements,
        readings,
        file: "cal.csv".into(),
    }
}

#[test]
fn gains_zeros_and_directions_are_found_within_their_uncertainties() {
    for name in ["orthogonal", "inclined-45", "four-45"] {
        let described = instrument(name);
        let n = described.sensors.len();
        let dg: Vec<f64> = (0..n).map(|k| [2e-3, -1.5e-3, 0.7e-3, 1e-3][k]).collect();
        let zeros: Vec<f64> = (0..n).map(|k| [1.5e-3, -0.8e-3, 0.3e-3, 0.0][k]).collect();
        let tilts: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                [
                    [2e-3, -1e-3],
                    [0.0, 1.5e-3],
                    [-2.5e-3, 0.5e-3],
                    [1e-3, 1e-3],
                ][k]
            })
            .collect();
        let truth = real(&described, &dg, &zeros, &tilts);
        let rec = record(&SensorHead::new(&truth), grid(), 0.05e-3, 3);
        let c = calibrate(&described, &rec).unwrap();
        for (k, cal) in c.sensors.iter().enumerate() {
            let want = [dg[k], zeros[k], tilts[k][0], tilts[k][1]];
            for (j, w) in want.iter().enumerate() {
                let (v, std) = cal.value(j).unwrap();
                let std = std.unwrap();
                assert!(std > 0.0 && std < 1e-3, "{name} {}: std {std}", cal.sensor);
                assert!(
                    (v - w).abs() < 4.0 * std,
                    "{name} {} parameter {j}: {v} vs {w} (std {std})",
                    cal.sensor
                );
            }
            // The residual's σ̂ is the readings' noise.
            let s = cal.fit.sigma.unwrap();
            assert!((s / 0.05e-3 - 1.0).abs() < 0.2, "{s}");
        }
        // The calibrated description reads the record's displacements back within the noise.
        let head = SensorHead::new(&c.instrument);
        for (e, s) in rec.displacements.iter().zip(&rec.readings) {
            let d = head.displacement(s, false).unwrap().displacement;
            for a in 0..3 {
                assert!((d[a] - e[a]).abs() < 0.5e-3, "{name}: {d:?} vs {e:?}");
            }
        }
        // And it writes and reads back to itself.
        let text = to_toml(&c.instrument, &["calibrated".into()]);
        assert_eq!(parse_instrument("c.toml", &text).unwrap(), c.instrument);
    }
}

#[test]
fn what_the_record_does_not_determine_gets_no_number() {
    // Flat tips, the known displacements along x only: sensor s1 (along x) sees its gain and
    // zero, but no displacement moves across it, so its tilts are not determined.
    let described = instrument("orthogonal");
    let truth = real(
        &described,
        &[1e-3, 0.0, 0.0],
        &[0.5e-3, 0.0, 0.0],
        &[[1e-3, 1e-3], [0.0, 0.0], [0.0, 0.0]],
    );
    let along_x: Vec<[f64; 3]> = (-10..=10).map(|i| [0.01 * i as f64, 0.0, 0.0]).collect();
    let rec = record(&SensorHead::new(&truth), along_x, 0.02e-3, 5);
    let c = calibrate(&described, &rec).unwrap();
    let s1 = &c.sensors[0];
    assert!(s1.value(0).is_some() && s1.value(1).is_some());
    assert!(
        s1.value(2).is_none() && s1.value(3).is_none(),
        "{:?}",
        s1.fit.values
    );
    // Not determined: kept as described.
    assert_eq!(
        c.instrument.sensors[0].direction,
        described.sensors[0].direction
    );
    assert!((c.instrument.sensors[0].gain - 1.0 - 1e-3).abs() < 1e-4);
    // Sensor s2 (along y) reads nothing of an x displacement but a tilt about z: its gain is
    // not determined and stays as described.
    assert!(c.sensors[1].value(0).is_none());
    assert_eq!(c.instrument.sensors[1].gain, 1.0);
}

#[test]
fn calibration_errors() {
    let described = instrument("orthogonal");
    let head = SensorHead::new(&described);
    let short = record(&head, grid()[..4].to_vec(), 1e-5, 1);
    let e = calibrate(&described, &short).unwrap_err();
    assert!(matches!(e, CalibrationError::Record(_)), "{e}");
    assert!(e.to_string().contains("at least 5"), "{e}");
    // A known displacement 6 mm across the flat faces: off the face, at its line.
    let mut off = record(&head, grid(), 1e-5, 1);
    off.displacements[7] = [0.0, 0.0, 6.0];
    let e = calibrate(&described, &off).unwrap_err().to_string();
    assert!(
        e.starts_with("cal.csv:9: sensor s1: the ball touches the flat face"),
        "{e}"
    );
}

#[test]
fn calibration_files_are_read_with_located_errors() {
    let i = instrument("inclined-45");
    let good =
        "# known moves\ndx_um,dy_um,dz_um,s1_um,s2_um,s3_um,t_s\n10,0,0,1,2,3,0\n0,10,0,1,2,3,1\n";
    let r = read_calibration("cal.csv", good.as_bytes(), &i, &ReadOptions::default()).unwrap();
    assert_eq!(r.displacements[0], [0.01, 0.0, 0.0]);
    assert_eq!(r.readings[1], vec![0.001, 0.002, 0.003]);
    assert_eq!(r.lines, vec![3, 4]);
    let cases = [
        (
            "dx_um,dy_um,s1_um,s2_um,s3_um\n",
            "cal.csv:1: missing column(s) dz_um",
        ),
        (
            "dx_um,dy_um,dz_um,s1_um,s2_um,s3_um,A\n",
            "cal.csv:1: column 7 `A`: unknown column `A`",
        ),
        (
            "dx_um,dy_um,dz_um,s1_um,s2_um,s3_um,s1_um\n",
            "cal.csv:1: column 7 `s1_um`: column `s1_um` appears twice",
        ),
        (
            "dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n1,2,3,4,inf,6\n",
            "cal.csv:2: column 5 `s2_um`: `inf` is not a finite number (µm)",
        ),
        (
            "dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n1,2,3,4,5\n",
            "cal.csv:2: ragged row",
        ),
        (
            "dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n",
            "cal.csv:1: header only",
        ),
        ("", "cal.csv:1: empty file"),
    ];
    for (text, want) in cases {
        let e = read_calibration("cal.csv", text.as_bytes(), &i, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(want), "{e}\nwanted: {want}");
    }
}
