//! The built-in machine templates: their catalogues, their `location` models, the own frames of
//! their inclined axes, and the spellings of a direction that give the same machine.

use model_spec::{
    AxisKind, ErrorKind, Machine, Side, builtin, kinematics::Step, parse_machine, surd::Real,
};

fn machine(name: &str) -> Machine {
    builtin(name).expect("listed").expect("valid")
}

fn catalogue(m: &Machine) -> Vec<&str> {
    m.catalogue.iter().map(|e| e.name.as_str()).collect()
}

fn location_names(m: &Machine) -> Vec<&str> {
    m.catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Location { .. }))
        .map(|e| e.name.as_str())
        .collect()
}

const TEMPLATES: [&str; 5] = [
    "table-table-bc",
    "head-head-ca",
    "nutating-head-bc",
    "nutating-table-bc",
    "horizontal-4axis-b",
];

#[test]
fn the_templates_have_the_catalogues_of_their_topologies() {
    let cases: [(&str, usize, &str, &str); 5] = [
        (
            "table-table-bc",
            44,
            "COY AOZ BOZ",
            "XOB ZOB AOB COB XOC YOC AOC BOC",
        ),
        (
            "head-head-ca",
            44,
            "COY AOZ BOZ",
            "YOA ZOA BOA COA XOC YOC AOC BOC",
        ),
        // The inclined B axes have the location errors of their own frame, as a C axis.
        (
            "nutating-head-bc",
            44,
            "COY AOZ BOZ",
            "XOB YOB AOB BOB XOC YOC AOC BOC",
        ),
        (
            "nutating-table-bc",
            44,
            "COY AOZ BOZ",
            "XOB YOB AOB BOB XOC YOC AOC BOC",
        ),
        ("horizontal-4axis-b", 34, "COY AOZ BOZ", "XOB ZOB AOB COB"),
    ];
    for (name, count, squareness, location) in cases {
        let m = machine(name);
        assert_eq!(m.catalogue.len(), count, "{name}: {:?}", catalogue(&m));
        assert_eq!(
            m.errors.len(),
            count,
            "{name}: the full model is the catalogue"
        );
        let sq: Vec<&str> = m
            .catalogue
            .iter()
            .filter(|e| matches!(e.kind, ErrorKind::Squareness { .. }))
            .map(|e| e.name.as_str())
            .collect();
        assert_eq!(sq.join(" "), squareness, "{name}");
        assert_eq!(location_names(&m).join(" "), location, "{name}");
        assert_eq!(m.model_names(), ["full", "location"], "{name}");
    }
}

#[test]
fn every_template_location_model_holds_the_location_squareness_and_set_up_errors() {
    for name in TEMPLATES.into_iter().chain(["head-table-bc"]) {
        let m = machine(name);
        let mut model: Vec<&str> = m
            .model_errors("location")
            .unwrap()
            .iter()
            .map(|&e| m.catalogue[e].name.as_str())
            .collect();
        let mut want: Vec<&str> = m
            .catalogue
            .iter()
            .filter(|e| {
                matches!(
                    e.kind,
                    ErrorKind::Location { .. }
                        | ErrorKind::Squareness { .. }
                        | ErrorKind::Setup { .. }
                )
            })
            .map(|e| e.name.as_str())
            .collect();
        model.sort_unstable();
        want.sort_unstable();
        assert_eq!(model, want, "{name}");
        assert!(!m.description.is_empty() && !m.description.contains('\n'));
    }
}

#[test]
fn every_template_with_rotary_axes_has_three_linear_axes_and_a_ball_above_its_table() {
    for name in TEMPLATES {
        let m = machine(name);
        assert_eq!(m.linear_axes().count(), 3, "{name}");
        assert!(m.rotary_axes().count() >= 1, "{name}");
        // Every stroke holds the home position 0 (the inverse kinematics moves from there).
        for a in &m.axes {
            let [lo, hi] = a.limits;
            if a.kind == AxisKind::Linear {
                assert!(lo < 0.0 && hi > 0.0, "{name} {}", a.name);
            }
        }
    }
}

/// The own frame of an inclined axis as exact numbers, rows x' y' z'.
fn frame_text(m: &Machine, axis: &str) -> Vec<String> {
    let a = &m.axes[m.axis_by_name(axis).unwrap()];
    let inclined = a.direction.inclined.expect("an inclined axis");
    inclined
        .frame
        .axes
        .iter()
        .map(|row| {
            row.iter()
                .map(Real::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        })
        .collect()
}

#[test]
fn the_nutating_axes_have_exact_own_frames() {
    let head = machine("nutating-head-bc");
    assert_eq!(
        frame_text(&head, "B"),
        ["1, 0, 0", "0, √2/2, -√2/2", "0, √2/2, √2/2"]
    );
    let b = &head.axes[head.axis_by_name("B").unwrap()];
    assert_eq!(b.side, Side::Tool);
    assert_eq!(b.direction.to_string(), "[0, 1, 1]");
    let table = machine("nutating-table-bc");
    assert_eq!(
        frame_text(&table, "B"),
        ["1, 0, 0", "0, √2/2, √2/2", "0, -√2/2, √2/2"]
    );
    // The chains wrap the inclined axis in its frame: into it after the offset, back after the
    // motion.
    let steps = model_spec::kinematics::chain_steps(&table, Side::Work);
    let frames: Vec<usize> = steps
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s, Step::Frame { .. }))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(frames.len(), 2);
    assert!(matches!(steps[frames[0] - 1], Step::Offset(_)));
    assert!(matches!(steps[frames[1] - 1], Step::Motion { .. }));
}

#[test]
fn a_direction_spelt_by_length_or_by_long_decimals_is_the_same_machine() {
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "nutating-head-bc")
        .unwrap()
        .1;
    let base = machine("nutating-head-bc");
    for spelling in [
        "[0, 2, 2]",
        "[0.0, 0.5, 0.5]",
        "[0, 0.7071067811865476, 0.7071067811865476]",
    ] {
        let edited = text.replace("direction = [0, 1, 1]", &format!("direction = {spelling}"));
        assert_ne!(edited, text);
        let m = parse_machine("m.toml", &edited).unwrap();
        assert_eq!(
            frame_text(&m, "B"),
            frame_text(&base, "B"),
            "{spelling}: the same exact frame"
        );
        assert_eq!(catalogue(&m), catalogue(&base));
    }
    // The opposite direction is another axis: z' and y' turn over, x' stays.
    let opposite = text.replace("direction = [0, 1, 1]", "direction = [0, -1, -1]");
    let m = parse_machine("m.toml", &opposite).unwrap();
    assert_eq!(
        frame_text(&m, "B"),
        ["1, 0, 0", "0, -√2/2, √2/2", "0, -√2/2, -√2/2"]
    );
    assert_ne!(m.fingerprint(), base.fingerprint());
    // A direction the reader cannot make exact stays numeric, and still orthonormal.
    let numeric = text.replace(
        "direction = [0, 1, 1]",
        "direction = [0, 0.766044443118978, 0.6427876096865394]",
    );
    let m = parse_machine("m.toml", &numeric).unwrap();
    let b = m.axes[m.axis_by_name("B").unwrap()].direction;
    let frame = b.inclined.unwrap().frame;
    assert!(frame.axes.iter().flatten().all(|r| !r.is_exact()));
    let f = b.frame();
    for i in 0..3 {
        for j in 0..3 {
            let dot: f64 = (0..3).map(|k| f[i][k] * f[j][k]).sum();
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((dot - want).abs() < 1e-15, "{i} {j}: {dot}");
        }
    }
}

#[test]
fn the_head_head_template_is_the_test_fixture_machine() {
    let file = format!(
        "{}/../tests/machines/head-head-ca.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let fixture = parse_machine(&file, &std::fs::read_to_string(&file).unwrap()).unwrap();
    let m = machine("head-head-ca");
    assert_eq!(m.fingerprint(), fixture.fingerprint());
    assert_eq!(catalogue(&m), catalogue(&fixture));
    assert_eq!(m.model_errors("location"), fixture.model_errors("location"));
}
