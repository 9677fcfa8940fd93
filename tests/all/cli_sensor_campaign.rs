//! End to end: a campaign of sensor records (an R-test head of three sensors at 45°, two ball
//! heights) identifies the same machine errors as the ball-centre records of the same runs,
//! within their uncertainties, and its diagnosis names what theirs names; a record of ball
//! centres among sensor records is refused.

use crate::common;
use common::{fails, ok, read_json, temp_dir_tagged};

/// Writes the campaign file `name` of the two records `low` (default ball) and `high`.
fn campaign_file(dir: &std::path::Path, name: &str, low: &str, high: &str) {
    let text = format!(
        "[[record]]\nfile = \"{low}\"\n\n[[record]]\nfile = \"{high}\"\nparams = {{ Zw = 241.537 }}\n"
    );
    std::fs::write(dir.join(name), text).unwrap();
}

#[test]
fn a_campaign_of_sensor_records_identifies_what_the_ball_centre_records_do() {
    let dir = temp_dir_tagged("cli-sensor-campaign", "heights");
    for (z, tag) in [("211.537", "low"), ("241.537", "high")] {
        let param = format!("Zw={z}");
        ok(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "--param",
                &param,
                "--seed",
                "3",
                "--instrument",
                "inclined-45",
                "-o",
                &format!("s-{tag}.csv"),
            ],
        );
        ok(
            &dir,
            &[
                "simulate",
                "--machine",
                "seed-ac",
                "--path",
                "K4",
                "--param",
                &param,
                "--seed",
                "3",
                "-o",
                &format!("b-{tag}.csv"),
            ],
        );
    }
    campaign_file(&dir, "s.toml", "s-low.csv", "s-high.csv");
    campaign_file(&dir, "b.toml", "b-low.csv", "b-high.csv");
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            "s.toml",
            "--instrument",
            "inclined-45",
            "--json",
            "s.json",
        ],
    );
    ok(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            "b.toml",
            "--json",
            "b.json",
        ],
    );
    let (s, b) = (
        read_json(&dir.join("s.json")),
        read_json(&dir.join("b.json")),
    );
    let (ps, pb) = (
        s["parameters"].as_array().unwrap(),
        b["parameters"].as_array().unwrap(),
    );
    assert_eq!(ps.len(), pb.len());
    let mut shared = 0;
    for (a, c) in ps.iter().zip(pb) {
        assert_eq!(a["owner"] == "shared", c["owner"] == "shared");
        if a["owner"] != "shared" {
            continue;
        }
        shared += 1;
        let (va, vc) = (a["value"].as_f64().unwrap(), c["value"].as_f64().unwrap());
        let sd = a["std"].as_f64().unwrap().hypot(c["std"].as_f64().unwrap());
        // The same run read two ways: the sensors add their own noise (0.1 µm each), so the
        // two fits differ by well under their combined uncertainty.
        assert!(
            (va - vc).abs() < 2.0 * sd,
            "{}: sensors {va} against ball centres {vc} (combined std {sd})",
            a["name"]
        );
    }
    assert_eq!(shared, 8);
    // A record of ball-centre vectors among sensor records is refused, naming the sensor
    // column it lacks.
    campaign_file(&dir, "mixed.toml", "s-low.csv", "b-high.csv");
    fails(
        &dir,
        &[
            "identify",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            "mixed.toml",
            "--instrument",
            "inclined-45",
        ],
        1,
        &["s1_um"],
    );
    // The diagnosis weights sensor records by their covariances: the sensor records name what
    // the ball-centre records of the same runs name first (the demo truth's ECC harmonic:2).
    for (campaign, json, sensors) in [("s.toml", "ds.json", true), ("b.toml", "db.json", false)] {
        let mut args = vec![
            "diagnose",
            "--machine",
            "seed-ac",
            "--model",
            "reduced",
            "--campaign",
            campaign,
            "--json",
            json,
        ];
        if sensors {
            args.extend(["--instrument", "inclined-45"]);
        }
        ok(&dir, &args);
        let d = read_json(&dir.join(json));
        assert_eq!(d["records"].as_array().unwrap().len(), 2, "{campaign}");
        let f = &d["findings"][0];
        assert_eq!(
            (f["error"].as_str(), f["basis"].as_str()),
            (Some("ECC"), Some("harmonic:2")),
            "{campaign}: {f}"
        );
    }
}
