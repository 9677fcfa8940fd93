//! Two ball heights determine what one height cannot: on the head-head machine
//! `tests/machines/head-head-ca.toml` (ball on a fixed table; X, Y, Z, a C head and an A fork on
//! the tool side), the angular errors of the Z slide that vary along its stroke (`EAZ@poly:1`,
//! `EBZ@poly:1`, `ECZ@poly:1`).
//!
//! The R-test paths turn the C head a full turn with the A fork at +30° and at −30°, the ball
//! followed by X, Y, Z. Along such a path Z stands still (the tool point stays at the ball's
//! height and the fork's tilt is fixed), so a linear variation of an angular error of Z along
//! its stroke is, within one ball height, a constant tilt below Z: the same as tilts of the C
//! head's line (`AOC BOC`), the squareness of Z (`AOZ BOZ`) and the A fork's location about z
//! (`COA`). A second ball height puts Z elsewhere on its stroke: the variation is then seen as
//! the difference between the heights, while the location errors are the same at both. Each
//! height is its own ball set-up (its own `XOW YOW ZOW`).
//!
//! Checked: the rank and the confounded groups at one height and at two, and the estimates at
//! two heights against a hidden truth (0.3 µm noise, refined against the exact machine):
//! every determined value within 4 standard uncertainties.

use crate::one_record::{identify_one, identify_refined_campaign};
use fitting::IdentifyOptions;
use fitting::noise::NoiseChoice;
use fitting::refine::RefineOptions;
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Basis, Effect, Model, Term};
use simulation::paths::{fill_linear_ik, record_from_commands};
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

fn machine() -> Machine {
    model_spec::load_machine(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/machines/head-head-ca.toml"
    ))
    .unwrap()
}

/// The model: the machine's `location` model and the linear variation of Z's angular errors.
fn model(m: &Machine) -> Model {
    let mut model = Model::of(m, "location").unwrap();
    for t in ["EAZ@poly:1", "EBZ@poly:1", "ECZ@poly:1"] {
        model.terms.push(Term::parse(m, t).unwrap());
    }
    model
}

/// A full turn of the C head (−180° … 180°, 121 samples, 1 s apart) with the A fork at `a_deg`,
/// the linear axes following the ball of kinematic parameters `params`.
fn c_turn(m: &Machine, params: &[f64], a_deg: f64) -> Record {
    let n = 121;
    let mut commands: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let c = (-180.0 + 3.0 * i as f64).to_radians();
            vec![0.0, 0.0, 0.0, c, a_deg.to_radians()]
        })
        .collect();
    fill_linear_ik(m, params, &mut commands).unwrap();
    record_from_commands(commands, (0..n).map(|i| i as f64).collect())
}

/// The hidden truth (µm, µrad as written; mm, rad inside) without the ball set-up.
const MACHINE_TRUTH: &[(&str, f64)] = &[
    ("COY", 12.0),
    ("AOZ", -9.0),
    ("BOZ", 14.0),
    ("XOC", 11.0),
    ("YOC", -7.0),
    ("AOC", 16.0),
    ("BOC", -13.0),
    ("YOA", 8.0),
    ("ZOA", -10.0),
    ("BOA", 18.0),
    ("COA", -15.0),
    ("EAZ@poly:1", 22.0),
    ("EBZ@poly:1", -17.0),
    ("ECZ@poly:1", 25.0),
];

/// The truth of one ball set-up (`XOW YOW ZOW`, µm) with the machine's errors, at `params`.
fn truth(m: &Machine, params: &[f64], setup: [f64; 3], seed: u64) -> Truth {
    let mut model = Model::default();
    let mut coefficients = Vec::new();
    let entries = MACHINE_TRUTH.iter().copied().chain([
        ("XOW", setup[0]),
        ("YOW", setup[1]),
        ("ZOW", setup[2]),
    ]);
    for (name, value) in entries {
        let t = Term::parse(m, name).unwrap();
        coefficients.push(value / t.display_factor(m));
        model.terms.push(t);
    }
    Truth {
        source: "<campaign_heights>".into(),
        description: String::new(),
        params: params.to_vec(),
        model,
        coefficients,
        noise_mm: 0.3e-3,
        noise_phi: 0.0,
        seed,
        zeroed: false,
    }
}

/// The truth's value of a campaign column (`XOW[high]` is the `high` set-up's XOW), in the
/// unit of the fit (mm, rad).
fn true_value(m: &Machine, name: &str, setups: &[(&str, [f64; 3])]) -> f64 {
    let (bare, owner) = match name.split_once('[') {
        Some((b, o)) => (b, Some(o.trim_end_matches(']'))),
        None => (name, None),
    };
    let t = Term::parse(m, bare).unwrap();
    let um = match owner {
        Some(o) => {
            let s = setups.iter().find(|(l, _)| *l == o).unwrap().1;
            s[["XOW", "YOW", "ZOW"]
                .iter()
                .position(|n| *n == bare)
                .unwrap()]
        }
        None => MACHINE_TRUTH.iter().find(|(n, _)| *n == bare).unwrap().1,
    };
    um / t.display_factor(m)
}

/// The records of one ball height: the C turns at A = +30° and −30°, on one set-up.
fn height(
    m: &Machine,
    label: &str,
    params: &[f64],
    setup: [f64; 3],
    seed: u64,
) -> Vec<CampaignRecord> {
    [30.0, -30.0]
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            let path = c_turn(m, params, a);
            let measured = simulate(m, &truth(m, params, setup, seed + k as u64), &path).unwrap();
            CampaignRecord::new(
                format!("{label}{}", if a > 0.0 { "+30" } else { "-30" }),
                measured,
                params.to_vec(),
                label,
                false,
            )
        })
        .collect()
}

fn group_names(names: &[String], groups: &[Vec<usize>]) -> Vec<Vec<String>> {
    groups
        .iter()
        .map(|g| g.iter().map(|&j| names[j].clone()).collect())
        .collect()
}

#[test]
fn two_ball_heights_determine_the_variation_of_z_tilts_that_one_height_cannot() {
    let m = machine();
    let model = model(&m);
    let zw = m.symbol_by_name("Zw").unwrap();
    let low = m.default_parameters();
    let mut high = low.clone();
    high[zw] += 250.0;
    let setups = [("low", [12.0, -8.0, 5.0]), ("high", [-15.0, 9.0, -6.0])];
    let opts = IdentifyOptions::new();
    let ordinary = NoiseChoice::Ordinary;

    // One height: Z stands still, its tilt varying along the stroke is a constant tilt.
    let one = Campaign::new(height(&m, "low", &low, setups[0].1, 1)).unwrap();
    let (a, _) = identify_refined_campaign(
        &m,
        &model,
        &one,
        &opts.clone().noise(ordinary.clone()),
        &RefineOptions::default(),
    )
    .unwrap();
    assert_eq!((a.fit.names.len(), a.fit.rank), (17, 9));
    assert_eq!(
        group_names(&a.fit.names, &a.fit.identifiability.confounded),
        [
            vec!["AOZ", "YOC", "AOC", "EAZ@poly:1", "YOW[low]"],
            vec!["BOZ", "XOC", "BOC", "EBZ@poly:1", "XOW[low]"],
            vec!["ZOA", "ZOW[low]"],
            vec!["COA", "ECZ@poly:1"],
        ]
    );
    for name in ["EAZ@poly:1", "EBZ@poly:1", "ECZ@poly:1", "BOA"] {
        let j = a.fit.names.iter().position(|n| n == name).unwrap();
        let determined = a.fit.identifiability.determined[j];
        assert_eq!(determined, name == "BOA", "{name} at one height");
        assert_eq!(
            a.fit.values[j].is_some(),
            determined,
            "{name}: a value only if determined"
        );
    }
    // The same without a campaign: one record at one height is no better.
    let single = identify_one(
        &m,
        &model,
        &one.records[0].record,
        &opts.clone().noise(ordinary.clone()),
    )
    .unwrap();
    assert!(single.fit.rank <= 9);

    // Two heights, each its own ball set-up.
    let mut records = height(&m, "low", &low, setups[0].1, 1);
    records.extend(height(&m, "high", &high, setups[1].1, 3));
    let two = Campaign::new(records).unwrap();
    let (b, refinement) = identify_refined_campaign(
        &m,
        &model,
        &two,
        &opts.clone().noise(ordinary.clone()),
        &RefineOptions::default(),
    )
    .unwrap();
    assert!(refinement.converged);
    assert_eq!((b.fit.names.len(), b.fit.rank), (20, 15));
    // What remains undetermined is the ball's position against the C head's line and the A
    // fork's height: the same at every height, so no campaign of ball positions separates it.
    assert_eq!(
        group_names(&b.fit.names, &b.fit.identifiability.confounded),
        [
            vec!["AOZ", "YOC", "AOC", "YOW[low]", "YOW[high]"],
            vec!["BOZ", "XOC", "BOC", "XOW[low]", "XOW[high]"],
            vec!["ZOA", "ZOW[low]", "ZOW[high]"],
        ]
    );
    let mut checked = Vec::new();
    for (j, name) in b.fit.names.iter().enumerate() {
        let Some(v) = b.fit.values[j] else {
            continue;
        };
        let s = b.fit.std[j].unwrap();
        let t = true_value(&m, name, &setups);
        let z = (v - t) / s;
        assert!(
            z.abs() < 4.0,
            "{name}: {v} ± {s} against the truth {t} (z = {z:.2})"
        );
        let f = Term::parse(&m, name.split('[').next().unwrap())
            .unwrap()
            .display_factor(&m);
        println!(
            "{name:>12}: {:8.3} ± {:.3} (truth {:7.3}, z = {z:+.2})",
            v * f,
            s * f,
            t * f
        );
        checked.push(name.clone());
    }
    for name in [
        "EAZ@poly:1",
        "EBZ@poly:1",
        "ECZ@poly:1",
        "BOA",
        "COA",
        "COY",
        "YOA",
    ] {
        assert!(
            checked.iter().any(|n| n == name),
            "{name} is determined at two heights"
        );
    }
    let term = Term {
        effect: Effect::Error(m.error_by_name("EAZ").unwrap()),
        basis: Basis::Poly(1),
    };
    let j = b.fit.names.iter().position(|n| *n == "EAZ@poly:1").unwrap();
    println!(
        "EAZ@poly:1 at two heights: {:.2} ± {:.2} µrad (truth 22); rank {} of {} against {} of {} at one height",
        b.fit.values[j].unwrap() * term.display_factor(&m),
        b.fit.std[j].unwrap() * term.display_factor(&m),
        b.fit.rank,
        b.fit.names.len(),
        a.fit.rank,
        a.fit.names.len()
    );
}
