//! Instrument descriptions: every bad field is refused with the file, line and column of the
//! offending value, key or entry; the presets are valid and as documented.

use model_spec::instrument::{PRESETS, ReadingsFrame, Tip, parse_instrument, preset};

const GOOD: &str = r#"name = "t"
ball_radius_mm = 12.7

[[sensor]]
name = "s1"
direction = [1, 0, 0]
tip = "flat"
face_radius_mm = 4

[[sensor]]
name = "s2"
direction = [0, 1, 0]
tip = "flat"
face_radius_mm = 4

[[sensor]]
name = "s3"
direction = [0, 0, -1]
tip = "sphere"
tip_radius_mm = 2
"#;

fn error(text: &str) -> String {
    parse_instrument("i.toml", text).unwrap_err().to_string()
}

#[test]
fn the_presets_are_valid_and_as_documented() {
    assert_eq!(PRESETS.len(), 3);
    let o = preset("orthogonal").unwrap().unwrap();
    assert_eq!(o.frame, ReadingsFrame::Tool);
    assert!(
        o.sensors
            .iter()
            .all(|s| matches!(s.tip, Tip::Flat { face_radius_mm } if face_radius_mm == 4.0))
    );
    let i = preset("inclined-45").unwrap().unwrap();
    for s in &i.sensors {
        // 45° to the spindle axis: the measuring direction's z component is −cos 45°.
        assert!((s.direction[2] + std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        assert_eq!(s.noise_mm, 1e-4);
        assert!(matches!(s.tip, Tip::Sphere { radius_mm } if radius_mm == 2.0));
    }
    assert_eq!(preset("four-45").unwrap().unwrap().sensors.len(), 4);
    assert!(preset("nothing").is_none());
    let t = parse_instrument("i.toml", GOOD).unwrap();
    assert_eq!(t.sensors[0].noise_mm, 1e-4, "the default σ, 0.1 µm");
    assert_eq!(t.sensors[0].gain, 1.0);
    assert_eq!(
        t.sensors[2].position_mm,
        [0.0, 0.0, 14.7],
        "above the ball, on its axis"
    );
}

#[test]
fn every_bad_field_names_its_line_and_column() {
    let cases: Vec<(String, &str)> = vec![
        (
            GOOD.replace("name = \"t\"\n", ""),
            "i.toml:1:1: no `name = \"...\"` at the top of the file",
        ),
        (
            GOOD.replace("name = \"t\"", "name = \"a b\""),
            "i.toml:1:8: instrument name `a b` must be letters, digits, `-` or `_`",
        ),
        (
            GOOD.replace(
                "name = \"t\"\n",
                "name = \"t\"\ndescription = \"\\u202d\"\n",
            ),
            "i.toml:2:15: description holds U+202D at character 1, a text-direction control (it shows the text in another order than it is stored): remove it",
        ),
        (
            GOOD.replace("ball_radius_mm = 12.7\n", ""),
            "i.toml:1:8: instrument `t` has no `ball_radius_mm`",
        ),
        (
            GOOD.replace("12.7", "0"),
            "i.toml:2:18: `ball_radius_mm` is 0 mm; the ball's radius must be above 0 and at most 100 mm",
        ),
        (
            GOOD.replace("ball_radius_mm = 12.7", "ball_radius_mm = 12.7\ncolour = 1"),
            "i.toml:3:1: unknown field `colour`, expected one of `name`, `description`, `ball_radius_mm`, `frame`, `sensor`",
        ),
        (
            GOOD.replace(
                "ball_radius_mm = 12.7",
                "ball_radius_mm = 12.7\nframe = \"bed\"",
            ),
            "i.toml:3:9: unknown frame `bed`",
        ),
        (
            GOOD.replace(
                "face_radius_mm = 4\n\n[[sensor]]\nname = \"s2\"",
                "face_radius_mm = 4\nspeed = 3\n\n[[sensor]]\nname = \"s2\"",
            ),
            "i.toml:9:1: unknown field `speed`",
        ),
        (
            GOOD.replace("[0, 1, 0]", "[0, 0, 0]"),
            "i.toml:12:13: sensor s2: `direction` is the zero vector",
        ),
        (
            GOOD.replace("[0, 1, 0]", "[0, 1]"),
            "i.toml:12:13: sensor s2: `direction` needs three numbers [x, y, z] (nest frame), found 2",
        ),
        (
            GOOD.replace("[0, 1, 0]", "[0, nan, 0]"),
            "i.toml:12:17: sensor s2: `direction` has the number NaN",
        ),
        (
            GOOD.replace("name = \"s2\"", "name = \"S1\""),
            "i.toml:11:8: sensor name `S1` is used twice (first on line 5",
        ),
        (
            GOOD.replace("name = \"s2\"", "name = \"dx\""),
            "i.toml:11:8: sensor name `dx` is reserved",
        ),
        (
            GOOD.replace("name = \"s2\"", "name = \"2nd\""),
            "i.toml:11:8: sensor name `2nd` must be a letter",
        ),
        (
            GOOD.replace("name = \"s2\"\n", ""),
            "i.toml:10:1: this [[sensor]] entry has no `name`",
        ),
        (
            GOOD.replace("direction = [0, 1, 0]\n", ""),
            "i.toml:11:8: sensor s2 has no `direction = [x, y, z]`",
        ),
        (
            GOOD.replace("tip = \"sphere\"", "tip = \"cone\""),
            "i.toml:19:7: sensor s3: unknown tip `cone` (\"flat\" or \"sphere\")",
        ),
        (
            GOOD.replace("tip_radius_mm = 2", "face_radius_mm = 2"),
            "i.toml:20:18: sensor s3: `face_radius_mm` belongs to a flat tip",
        ),
        (
            GOOD.replace("tip_radius_mm = 2", "tip_radius_mm = -2"),
            "i.toml:20:17: sensor s3: `tip_radius_mm` is -2 mm; it must be above 0 and at most 50 mm",
        ),
        (
            GOOD.replace("tip = \"sphere\"\ntip_radius_mm = 2", "tip = \"sphere\""),
            "i.toml:19:7: sensor s3: a ball tip needs `tip_radius_mm`",
        ),
        (
            GOOD.replace(
                "face_radius_mm = 4\n\n[[sensor]]\nname = \"s2\"",
                "face_radius_mm = 4\ngain = 3\n\n[[sensor]]\nname = \"s2\"",
            ),
            "i.toml:9:8: sensor s1: `gain` is 3; a calibrated gain (reading per plunger travel, 1 nominal) must be from 0.5 to 2",
        ),
        (
            GOOD.replace("tip_radius_mm = 2", "tip_radius_mm = 2\nnoise_um = 0"),
            "i.toml:21:12: sensor s3: `noise_um` is 0 µm; the standard deviation of a reading must be above 0 and at most 1000 µm",
        ),
        (
            GOOD.replace("tip_radius_mm = 2", "tip_radius_mm = 2\nzero_um = inf"),
            "i.toml:21:11: sensor s3: `zero_um` is inf µm; it must be finite",
        ),
        (
            GOOD.replace(
                "tip_radius_mm = 2",
                "tip_radius_mm = 2\nposition_mm = [0, 0, 15]",
            ),
            "i.toml:21:15: sensor s3: the tip centre is 15 mm from the nest centre; a ball tip of radius 2 mm touching the ball (radius 12.7 mm) at zero reading is 14.7 mm from it",
        ),
        (
            GOOD.replace(
                "tip_radius_mm = 2",
                "tip_radius_mm = 2\nposition_mm = [10.394, 0, 10.394]",
            ),
            "i.toml:21:15: sensor s3: the plunger axis points 45° away from the ball centre",
        ),
        (
            GOOD.replace(
                "face_radius_mm = 4\n\n[[sensor]]\nname = \"s2\"",
                "face_radius_mm = 4\nposition_mm = [-12, 0, 0]\n\n[[sensor]]\nname = \"s2\"",
            ),
            "i.toml:9:15: sensor s1: the face centre is 12 mm from the nest centre along the plunger axis",
        ),
        (
            GOOD.replace(
                "face_radius_mm = 4\n\n[[sensor]]\nname = \"s2\"",
                "face_radius_mm = 4\nposition_mm = [-12.7, 5, 0]\n\n[[sensor]]\nname = \"s2\"",
            ),
            "i.toml:9:15: sensor s1: the ball touches the face 5 mm from its centre at zero reading, beyond its radius of 4 mm",
        ),
        (
            GOOD.split("\n[[sensor]]\nname = \"s3\"")
                .next()
                .unwrap()
                .to_string(),
            "i.toml:10:1: the instrument has 2 sensors; at least 3 are needed",
        ),
        (
            GOOD.replace("[0, 0, -1]", "[1, 1, 0]"),
            "i.toml:4:1: the sensors' measuring directions do not span the three dimensions",
        ),
        (
            GOOD.replace("[0, 0, -1]", "[1, 1, 0.05]"),
            "i.toml:4:1: the sensors' measuring directions do not span the three dimensions: a displacement in the worst direction moves the readings by only 0.025 of its size",
        ),
        (
            "name = \"t\"\nball_radius_mm = [1]\n".into(),
            "i.toml:2:18: invalid type: sequence, expected a number",
        ),
    ];
    for (text, want) in cases {
        let e = error(&text);
        assert!(e.starts_with(want), "{e}\nwanted: {want}\n{text}");
    }
    // More than eight sensors.
    let mut many = String::from("name = \"t\"\nball_radius_mm = 12.7\n");
    for k in 0..9 {
        many += &format!(
            "[[sensor]]\nname = \"s{k}\"\ndirection = [{}, {}, 1]\ntip = \"flat\"\nface_radius_mm = 4\n",
            (k as f64).cos(),
            (k as f64).sin()
        );
    }
    assert!(
        error(&many).starts_with("i.toml:43:1: the instrument has 9 sensors, more than 8"),
        "{}",
        error(&many)
    );
}
