//! `rtest instrument` and `--instrument` end to end: presets listed and shown, bad
//! descriptions located, a simulated sensor record identified like the ball-centre record of
//! the same run, a declared noise model refused, and a calibration written and read back.

use crate::common;

use common::{fails, ok, read_json, temp_dir_tagged, words};
use std::path::Path;

fn temp(name: &str) -> common::TempDir {
    temp_dir_tagged("instrument", name)
}

#[test]
fn presets_are_listed_and_shown() {
    let d = temp("show");
    let list = ok(&d, &["instrument", "list"]);
    for name in ["orthogonal", "inclined-45", "four-45"] {
        assert!(list.contains(name), "{list}");
    }
    let show = ok(&d, &["instrument", "show", "inclined-45"]);
    assert!(show.contains("ball radius 12.7 mm"), "{show}");
    assert!(
        show.contains("σx 0.115 µm, σy 0.115 µm, σz 0.082 µm"),
        "{show}"
    );
    assert!(
        show.contains("at 50 µm: s1 0.085, s2 0.085, s3 0.085 µm"),
        "{show}"
    );
    // A file with a bad field: exit code 1, the file, line and column.
    std::fs::write(
        d.join("bad.toml"),
        "name = \"bad\"\nball_radius_mm = 12.7\n[[sensor]]\nname = \"s1\"\ndirection = [0, 0, 0]\n",
    )
    .unwrap();
    fails(
        &d,
        &["instrument", "show", "bad.toml"],
        1,
        &["bad.toml:5:13: sensor s1: `direction` is the zero vector"],
    );
    fails(
        &d,
        &["instrument", "show", "nothing"],
        2,
        &["no preset instrument and no file called `nothing`"],
    );
}

/// The `value` and `std` of every parameter of an identification report, by name.
fn parameters(json: &serde_json::Value) -> Vec<(String, f64, f64)> {
    json["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap().to_string(),
                p["value"].as_f64().unwrap(),
                p["std"].as_f64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn a_sensor_record_identifies_like_the_ball_centre_record_of_the_same_run() {
    let d = temp("identify");
    let run = "--machine seed-ac --path K4 --truth seed-ac-reduced --noise-um 0.3 --seed 5";
    ok(
        &d,
        &[words(&format!("simulate {run} -o ball.csv")), vec![]].concat(),
    );
    let out = ok(
        &d,
        &[
            words(&format!(
                "simulate {run} --instrument inclined-45 -o sensors.csv"
            )),
            vec![],
        ]
        .concat(),
    );
    assert!(out.contains("with instrument inclined-45"), "{out}");
    let csv = std::fs::read_to_string(d.join("sensors.csv")).unwrap();
    assert!(
        csv.lines().any(|l| l == "X,Y,Z,A,C,s1_um,s2_um,s3_um,t_s"),
        "{csv}"
    );
    ok(
        &d,
        &words("identify --machine seed-ac --model reduced --data ball.csv --json ball.json"),
    );
    let text = ok(
        &d,
        &words(
            "identify --machine seed-ac --model reduced --data sensors.csv --instrument inclined-45 --json sensors.json",
        ),
    );
    assert!(text.contains("XOC"), "{text}");
    let (a, b) = (
        parameters(&read_json(&d.join("ball.json"))),
        parameters(&read_json(&d.join("sensors.json"))),
    );
    assert_eq!(a.len(), 11);
    for ((name, x, _), (_, y, std)) in a.iter().zip(&b) {
        assert!((x - y).abs() < 2.0 * std, "{name}: {x} vs {y} (std {std})");
    }
    // Read without the instrument, the file has no error vector columns.
    fails(
        &d,
        &words("identify --machine seed-ac --model reduced --data sensors.csv"),
        1,
        &["--data: sensors.csv:", "unknown column `s1_um`"],
    );
    // Validate reads it through the instrument too.
    ok(
        &d,
        &words(
            "validate --machine seed-ac --params ball.json --data sensors.csv --instrument inclined-45",
        ),
    );
    // A declared noise model would declare the sensors' noise twice.
    fails(
        &d,
        &words(
            "identify --machine seed-ac --model reduced --data sensors.csv --instrument inclined-45 --noise white:sigma=0.5",
        ),
        2,
        &["--noise:", "declare the noise a second time"],
    );
    // The wrong frame flag, and a frame without an instrument.
    fails(
        &d,
        &words(
            "identify --machine seed-ac --model reduced --data sensors.csv --instrument inclined-45 --readings-frame bed",
        ),
        2,
        &["--readings-frame"],
    );
    fails(
        &d,
        &words("identify --machine seed-ac --model reduced --data ball.csv --readings-frame tool"),
        2,
        &["--instrument"],
    );
}

#[test]
fn an_instrument_is_calibrated_and_its_description_written() {
    use model_spec::instrument::preset;
    use simulation::instrument::head::SensorHead;
    let d = temp("calibrate");
    let mut real = preset("inclined-45").unwrap().unwrap();
    real.sensors[1].gain = 1.002;
    real.sensors[2].zero_mm = 0.0015;
    let head = SensorHead::new(&real);
    let mut csv = String::from("dx_um,dy_um,dz_um,s1_um,s2_um,s3_um\n");
    for x in [-0.1, 0.0, 0.1] {
        for y in [-0.1, 0.0, 0.1] {
            for z in [-0.1, 0.0, 0.1] {
                let s = head.readings([x, y, z]).unwrap();
                let um = |v: f64| model_spec::units::format_scaled(v, 3);
                csv += &format!(
                    "{},{},{},{},{},{}\n",
                    um(x),
                    um(y),
                    um(z),
                    um(s[0]),
                    um(s[1]),
                    um(s[2])
                );
            }
        }
    }
    std::fs::write(d.join("cal.csv"), csv).unwrap();
    let out = ok(
        &d,
        &words("instrument calibrate --instrument inclined-45 --data cal.csv -o cal.toml"),
    );
    assert!(out.contains("sensor s2: gain error 2000.0 ±"), "{out}");
    assert!(out.contains("Wrote cal.toml"), "{out}");
    let text = std::fs::read_to_string(d.join("cal.toml")).unwrap();
    let back = model_spec::instrument::parse_instrument("cal.toml", &text).unwrap();
    assert!((back.sensors[1].gain - 1.002).abs() < 1e-9, "{text}");
    assert!((back.sensors[2].zero_mm - 0.0015).abs() < 1e-9, "{text}");
    ok(&d, &["instrument", "show", "cal.toml"]);
    // The output may not overwrite the record; a file that does not exist is a bad input.
    fails(
        &d,
        &words("instrument calibrate --instrument inclined-45 --data cal.csv -o cal.csv"),
        2,
        &["cal.csv"],
    );
    fails(
        &d,
        &words("instrument calibrate --instrument inclined-45 --data missing.csv -o x.toml"),
        1,
        &["--data"],
    );
    assert!(!Path::new(&d.join("x.toml")).exists());
}
