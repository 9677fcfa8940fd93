//! The built-in machine templates measured on their own generated paths: every template with a
//! rotary axis has a test turning each rotary axis; a truth with location errors of every
//! rotary axis and the ball's set-up errors (a few µm and µrad, noise 0.3 µm), simulated on all
//! of the machine's tests one after the other (one ball set-up), identified with the machine's
//! `location` model: every parameter the paths determine lies within 4 standard uncertainties
//! of the truth, and the others are reported as confounded, in the groups the geometry says.

use crate::common;
use crate::one_record::identify_refined_one;

use common::builtin;
use fitting::{IdentifyOptions, RefineOptions};
use model_spec::{ErrorKind, Machine};
use simulation::generator::{GeneratorError, GeneratorOptions, generate, tests};
use simulation::model::Model;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

/// The built-in machines with a `location` model: the templates with rotary axes.
const TEMPLATES: [&str; 6] = [
    "head-table-bc",
    "table-table-bc",
    "head-head-ca",
    "nutating-head-bc",
    "nutating-table-bc",
    "horizontal-4axis-b",
];

/// Every test of `m` at the default options and parameters, one after the other, times
/// running on (one ball set-up, one R-test zero).
fn all_tests(m: &Machine) -> Record {
    let mut out = Record::default();
    let mut start = 0.0;
    for spec in tests(m) {
        let r = builtin_path(m, &spec.name)
            .expect("a test of the machine")
            .unwrap_or_else(|e| panic!("{} {}: {e}", m.name, spec.name));
        for mut s in r.samples {
            s.t += start;
            out.samples.push(s);
        }
        start = out.samples.last().unwrap().t + 1.0;
    }
    out
}

/// A truth of `m`: every location error of its rotary axes and `XOW YOW ZOW`, constants of
/// 2 to 7 µm or µrad of both signs, reading noise 0.3 µm.
fn truth(m: &Machine, seed: u64) -> Truth {
    let values = [
        3.0, -4.0, 5.5, -2.5, 6.0, -3.5, 4.5, -5.5, 2.0, -6.5, 3.8, -4.2,
    ];
    let names: Vec<&str> = m
        .catalogue
        .iter()
        .filter(|e| matches!(e.kind, ErrorKind::Location { .. } | ErrorKind::Setup { .. }))
        .map(|e| e.name.as_str())
        .collect();
    let mut text = format!("noise_um = 0.3\nseed = {seed}\n\n[errors]\n");
    for (i, n) in names.iter().enumerate() {
        text += &format!("{n} = {}\n", values[i % values.len()]);
    }
    formats::truth::parse_truth("<test truth>", &text, m).unwrap_or_else(|e| panic!("{e}"))
}

/// The confounded groups of the identification, by name.
type Groups = Vec<Vec<&'static str>>;

/// What the paths of each template cannot separate. An error whose gain is a constant
/// translation of the tool point relative to the ball in the bed frame, at every sample, is one
/// of three directions: a head's translational location errors when only linear axes are
/// above it, those of the first rotary axis of the work chain, the ball's set-up error along a
/// turntable's axis, and a squareness error whose lever arm the paths keep constant. More
/// such errors than three are confounded.
fn expected_groups(name: &str) -> Groups {
    match name {
        // B head and C table translations along x (+x and −x in the bed); ZOB and ZOW along z;
        // AOZ tilts the Z ram about x with a constant lever arm (the ball's height above the Y
        // carriage's frame): a constant −80 mm·AOZ along y, as YOC.
        "head-table-bc" => vec![vec!["AOZ", "YOC"], vec!["XOB", "XOC"], vec!["ZOB", "ZOW"]],
        // Only XOB and ZOB of the trunnion are constant in the bed: everything is determined.
        "table-table-bc" | "nutating-table-bc" => vec![],
        // The ball on a fixed table: its set-up errors and the translations of the C head (and
        // of A along z, the axis of C) are the ball's position relative to the head.
        "head-head-ca" => vec![vec!["XOC", "XOW"], vec!["YOC", "YOW"], vec!["ZOA", "ZOW"]],
        // XOB and YOB act along x' = x and y' = (0, 1, −1)/√2 in the bed, XOC and YOC along x
        // and y, ZOW along z: five constant translations in three directions.
        "nutating-head-bc" => vec![vec!["XOB", "XOC"], vec!["YOB", "YOC", "ZOW"]],
        // B turns about the vertical y axis: the ball keeps its height Y and its z (the nest's,
        // fixed on the spindle), so COY and AOZ have constant lever arms; with XOB, ZOB and YOW
        // (along the B axis) they are constant translations.
        "horizontal-4axis-b" => vec![vec!["COY", "XOB"], vec!["AOZ", "ZOB", "YOW"]],
        _ => unreachable!("{name}"),
    }
}

#[test]
fn every_rotary_axis_of_every_template_has_its_turn_and_every_test_generates() {
    for name in TEMPLATES.into_iter().chain(["seed-ac"]) {
        let m = builtin(name);
        let list = tests(&m);
        for a in m.rotary_axes() {
            let turn = list
                .iter()
                .find(|t| t.name == format!("turn-{}", m.axes[a].name))
                .unwrap_or_else(|| panic!("{name}: no turn of {}", m.axes[a].name));
            assert!(
                turn.sweep.span_deg() >= 180.0 - 1e-9,
                "{name} {}: {}",
                turn.name,
                turn.description
            );
        }
        for spec in &list {
            let r = builtin_path(&m, &spec.name).unwrap().unwrap();
            assert!(r.samples.len() > 100, "{name} {}", spec.name);
        }
    }
    // The three-axis machine has no R-test test: its ball allows one pose on the ball, and it
    // is measured by the laser scheme.
    let m = builtin("seed-3axis");
    assert!(tests(&m).is_empty());
    let e = generate(
        &m,
        "turn-C",
        &m.default_parameters(),
        &GeneratorOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, GeneratorError::NoRotaryAxis { .. }), "{e}");
}

#[test]
fn the_nutating_axes_turn_their_whole_range() {
    // The tilt reaches the rule's 90° exactly at B = 180°: the turn is not cut short by the
    // rounding of the closed form.
    for name in ["nutating-head-bc", "nutating-table-bc"] {
        let m = builtin(name);
        let turn = tests(&m).into_iter().find(|t| t.name == "turn-B").unwrap();
        assert_eq!((turn.sweep.from_deg, turn.sweep.to_deg), (0.0, 180.0));
        assert_eq!(
            turn.description,
            "B turns 0° .. 180° (its range) in 1° steps, C at 0° (181 samples)"
        );
    }
}

#[test]
fn identify_on_the_templates_own_paths_recovers_the_truth() {
    for (k, name) in TEMPLATES.into_iter().enumerate() {
        let m = builtin(name);
        let path = all_tests(&m);
        let t = truth(&m, 11 + k as u64);
        let data = simulate(&m, &t, &path).unwrap();
        let model = Model::constant(m.model_errors("location").unwrap());
        let (ident, refinement) = identify_refined_one(
            &m,
            &model,
            &data,
            &IdentifyOptions::new(),
            &RefineOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(refinement.converged);
        let fit = &ident.fit;
        let sigma = fit.sigma.unwrap();
        assert!((0.27e-3..0.33e-3).contains(&sigma), "{name}: σ̂ {sigma} mm");
        for (j, term) in model.terms.iter().enumerate() {
            let truth = t.coefficient(term).map_or(0.0, |c| c[0]);
            let what = format!("{name} {}", fit.names[j]);
            if fit.identifiability.determined[j] {
                let (v, s) = (fit.values[j].unwrap(), fit.std[j].unwrap());
                assert!(
                    (v - truth).abs() <= 4.0 * s,
                    "{what}: {} ± {} against the truth {}",
                    v,
                    s,
                    truth
                );
                // Known to 0.2 µm or 1 µrad at most (0.3 µm of noise on some 800 samples).
                let bound = if term.effect.is_angular(&m) {
                    1e-6
                } else {
                    2e-4
                };
                assert!(s < bound, "{what}: ± {s}");
            } else {
                assert_eq!(fit.values[j], None, "{what} has no value");
                assert_eq!(fit.std[j], None, "{what} has no uncertainty");
            }
        }
        let sorted = |groups: Vec<Vec<&str>>| {
            let mut g: Vec<Vec<String>> = groups
                .into_iter()
                .map(|mut g| {
                    g.sort_unstable();
                    g.into_iter().map(String::from).collect()
                })
                .collect();
            g.sort();
            g
        };
        let groups: Vec<Vec<&str>> = fit
            .identifiability
            .confounded
            .iter()
            .map(|g| g.iter().map(|&j| fit.names[j].as_str()).collect())
            .collect();
        assert_eq!(sorted(groups), sorted(expected_groups(name)), "{name}");
    }
}
