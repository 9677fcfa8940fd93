//! A touch-probe campaign on the exact virtual machine identifies the machine's location
//! errors: probe hits simulated with `simulation::probe`, fitted into readings by
//! `fitting::probe`, identified as any campaign. The uncertainties hold over seeds.

use crate::common::builtin;
use fitting::campaign::CampaignIdentification;
use fitting::noise::NoiseChoice;
use fitting::plan::Targets;
use fitting::plan::probe::{ProbePlanInputs, ProbeSetup, choose_per_axis};
use fitting::probe::{PreTravel as DeclaredPreTravel, ProbeSettings, probe_record};
use fitting::{Constraint, IdentifyOptions, Tolerances, identify};
use formats::probe::{ProbeHit, ProbeHits, ProbePose};
use model_spec::{AxisKind, Machine};
use simulation::campaign::Campaign;
use simulation::generator::Clearance;
use simulation::model::Model;
use simulation::probe::{self as sim, PreTravel, ProbeRun, simulate_probe};
use simulation::truth::Truth;

const SPHERE_MM: f64 = 12.5;
const TIP_MM: f64 = 1.5;
const NOISE_MM: f64 = 0.5e-3;

/// A machine, its truth (location and set-up errors), the model fitted and its constraint.
pub struct Case {
    pub m: Machine,
    pub truth: Truth,
    pub model: Model,
    pub constraint: Constraint,
}

fn truth(m: &Machine, errors: &str) -> Truth {
    formats::truth::parse_truth(
        "t.toml",
        &format!("machine = \"{}\"\n[errors]\n{errors}", m.name),
        m,
    )
    .unwrap()
}

/// The cases of the acceptance: seed-ac's reduced model; on table-table-bc and head-table-bc
/// the location errors of B and C and the sphere's set-up errors (the squareness of the
/// linear axes needs the sphere at several positions), head-table-bc with XOC and ZOW held at
/// zero (a sphere at one position does not separate them from the others).
pub fn case(name: &str) -> Case {
    let m = builtin(name);
    let (errors, model, constraint) = match name {
        "seed-ac" => (
            "XOW = 12\nYOW = -18\nZOW = 15\nYOA = 20\nZOA = -15\nBOA = 25\nCOA = -18\nXOC = 10\nYOC = -22\nAOC = 30\nBOC = -12\n",
            "reduced",
            Constraint::None,
        ),
        "table-table-bc" => (
            "XOW = -8\nYOW = 14\nZOW = 6\nXOB = 15\nZOB = -12\nAOB = 20\nCOB = -25\nXOC = 9\nYOC = -11\nAOC = 18\nBOC = 22\n",
            "XOW YOW ZOW XOB ZOB AOB COB XOC YOC AOC BOC",
            Constraint::None,
        ),
        _ => (
            "YOW = 5\nXOW = 10\nXOB = -14\nZOB = 9\nAOB = 16\nCOB = -21\nYOC = 8\nAOC = -15\nBOC = 19\n",
            "XOW YOW ZOW XOB ZOB AOB COB XOC YOC AOC BOC",
            Constraint::Zero(vec!["XOC".into(), "ZOW".into()]),
        ),
    };
    let model = Model::of(&m, model).unwrap_or_else(|| {
        let ids: Vec<usize> = model
            .split(' ')
            .map(|e| m.error_by_name(e).unwrap())
            .collect();
        Model::constant(&ids)
    });
    Case {
        truth: truth(&m, errors),
        model,
        m,
        constraint,
    }
}

/// `n` equally spaced positions of each rotary axis over its range (a full turn: `n` steps of
/// 360°/n), the others at 0; the pose with every rotary axis at 0 once.
pub fn sweep(m: &Machine, n: usize) -> Vec<Vec<f64>> {
    let mut poses: Vec<Vec<f64>> = Vec::new();
    for k in m.rotary_axes() {
        let [lo, hi] = m.axes[k].limits;
        for i in 0..n {
            let deg = if lo.is_finite() && hi.is_finite() && hi - lo < 360.0 {
                lo + (hi - lo) * i as f64 / (n - 1) as f64
            } else {
                360.0 * i as f64 / n as f64
            };
            let mut q = vec![0.0; m.axes.len()];
            q[k] = deg.to_radians();
            if !poses.iter().any(|p| p == &q) {
                poses.push(q);
            }
        }
    }
    poses
}

/// The hits of `run` as the probe hits file gives them (rotary axes in degrees).
pub fn hits_of(m: &Machine, run: &ProbeRun) -> ProbeHits {
    let mut line = 1;
    ProbeHits {
        poses: run
            .poses
            .iter()
            .enumerate()
            .map(|(i, p)| ProbePose {
                label: sim::pose_label(i),
                hits: p
                    .hits
                    .iter()
                    .map(|h| {
                        line += 1;
                        ProbeHit {
                            line,
                            axes: m
                                .axes
                                .iter()
                                .zip(&h.latched)
                                .map(|(a, &x)| match a.kind {
                                    AxisKind::Linear => x,
                                    AxisKind::Rotary => x.to_degrees(),
                                })
                                .collect(),
                            direction: [h.approach.x, h.approach.y, h.approach.z],
                            t_s: h.t_s,
                        }
                    })
                    .collect(),
            })
            .collect(),
    }
}

/// The probe campaign of `case` at `poses` with noise seed `seed` and pre-travel `pre`,
/// declared to the reader as `declared`, identified.
pub fn identified(
    case: &Case,
    poses: &[Vec<f64>],
    seed: u64,
    pre: PreTravel,
    declared: DeclaredPreTravel,
) -> CampaignIdentification {
    identified_as(case, &case.model, false, poses, seed, pre, declared)
}

/// [`identified`] with the model `model` (the probe's zero fitted when `zeroed`).
pub fn identified_as(
    case: &Case,
    model: &Model,
    zeroed: bool,
    poses: &[Vec<f64>],
    seed: u64,
    pre: PreTravel,
    declared: DeclaredPreTravel,
) -> CampaignIdentification {
    let campaign = probe_campaign(case, zeroed, poses, seed, pre, declared);
    let opts = IdentifyOptions::new()
        .constraint(case.constraint.clone())
        .noise(NoiseChoice::Instrument);
    identify(&case.m, model, &campaign, &opts).unwrap()
}

/// The campaign of one record of `case`'s probe hits at `poses` (noise seed `seed`, pre-travel
/// `pre`, declared to the reader as `declared`), zeroed or not, with the default pattern.
pub fn probe_campaign(
    case: &Case,
    zeroed: bool,
    poses: &[Vec<f64>],
    seed: u64,
    pre: PreTravel,
    declared: DeclaredPreTravel,
) -> Campaign {
    let azimuth = sim::PatternAzimuth::default();
    probe_campaign_with(case, zeroed, poses, seed, (pre, declared), azimuth)
}

/// [`probe_campaign`] with the pattern's azimuth `azimuth`; `pre` the pre-travel and the one
/// declared to the reader.
pub fn probe_campaign_with(
    case: &Case,
    zeroed: bool,
    poses: &[Vec<f64>],
    seed: u64,
    (pre, declared): (PreTravel, DeclaredPreTravel),
    azimuth: sim::PatternAzimuth,
) -> Campaign {
    let m = &case.m;
    let params = m.default_parameters();
    let run = simulate_probe(
        m,
        &params,
        &case.truth,
        poses,
        &sim::ProbeSettings {
            tip_radius_mm: TIP_MM,
            sphere_radius_mm: SPHERE_MM,
            pre_travel: pre,
            noise_mm: NOISE_MM,
            seed,
            azimuth,
        },
    )
    .unwrap();
    let settings = ProbeSettings {
        tip_radius_mm: TIP_MM,
        sphere_radius_mm: SPHERE_MM,
        noise_mm: Some(NOISE_MM),
        declared,
        max_reading_mm: 1.0,
        off_sphere_mm: 0.5,
    };
    let read = probe_record("h.csv", m, &params, &hits_of(m, &run), &settings).unwrap();
    Campaign::of_record(read.record, params, zeroed)
}

/// Per determined parameter, `(name, z = (value − truth)/std)`; panics when a parameter of the
/// model that the constraint does not fix is undetermined.
pub fn z_scores(case: &Case, ident: &CampaignIdentification) -> Vec<(String, f64)> {
    z_scores_of(case, ident, |_| true)
}

/// [`z_scores`] of the parameters whose names `keep` accepts.
pub fn z_scores_of(
    case: &Case,
    ident: &CampaignIdentification,
    keep: impl Fn(&str) -> bool,
) -> Vec<(String, f64)> {
    let fit = &ident.fit;
    let mut out = Vec::new();
    for (k, name) in fit.names.iter().enumerate() {
        if fit.fixed[k] || !keep(name) {
            continue;
        }
        let (Some(v), Some(s)) = (fit.values[k], fit.std[k]) else {
            panic!("{}: {name} is not determined: {:?}", case.m.name, fit.names);
        };
        let column = &ident.layout.columns[k];
        let t = case
            .truth
            .coefficient(&column.term)
            .map_or(0.0, |c| c[column.component]);
        out.push((name.clone(), (v - t) / s));
    }
    out
}

/// `f` of the probe plan's inputs for `case` with `model` (the case's probe, its default
/// kinematic parameters and constraint).
fn with_plan_inputs<T>(case: &Case, model: &Model, f: impl FnOnce(&ProbePlanInputs) -> T) -> T {
    let params = case.m.default_parameters();
    f(&ProbePlanInputs {
        machine: &case.m,
        model,
        params: &params,
        clearance: &Clearance::default(),
        probe: &ProbeSetup {
            tip_radius_mm: TIP_MM,
            sphere_radius_mm: SPHERE_MM,
            noise_mm: NOISE_MM,
        },
        constraint: &case.constraint,
        tol: &Tolerances::default(),
    })
}

/// The poses `rtest plan --probe --per-axis auto` chooses for `case` (targets 1 µm, 5 µrad,
/// valuation 2), with the number of positions per axis.
pub fn planned(case: &Case) -> (usize, Vec<Vec<f64>>) {
    let choice = with_plan_inputs(case, &case.model, |inputs| {
        choose_per_axis(inputs, &Targets::default(), 2.0).unwrap()
    });
    assert!(
        choice.met,
        "{}: the plan meets no valuation of 2",
        case.m.name
    );
    let poses = choice.plan.poses;
    (
        poses.per_axis,
        poses.poses.iter().map(|p| p.commands.clone()).collect(),
    )
}

#[test]
fn a_probe_campaign_chosen_by_the_plan_identifies_the_location_errors_within_four_std() {
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let case = case(name);
        let (n, poses) = planned(&case);
        println!(
            "{name}: the plan chose {n} positions per rotary axis, {} poses",
            poses.len()
        );
        let ident = identified(&case, &poses, 11, PreTravel::default(), Default::default());
        let z = z_scores(&case, &ident);
        assert!(!z.is_empty());
        for (n, z) in &z {
            assert!(z.abs() < 4.0, "{name}: {n} is {z:.2} std off the truth");
        }
    }
}

/// The mean z² over the determined parameters of `case` over `seeds` noise seeds.
pub fn mean_z2(case: &Case, poses: &[Vec<f64>], seeds: std::ops::Range<u64>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for seed in seeds {
        let ident = identified(case, poses, seed, PreTravel::default(), Default::default());
        for (_, z) in z_scores(case, &ident) {
            sum += z * z;
            n += 1;
        }
    }
    sum / n as f64
}

#[test]
fn the_uncertainties_hold_over_200_seeds() {
    // Measured at the plan's poses (5, 8, 5 per axis), the uncertainties at the probe's
    // declared σ, the pattern turning with the probe and about the stylus pose after pose:
    // mean z² 0.982 (seed-ac), 0.951 (table-table-bc), 0.982 (head-table-bc).
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let case = case(name);
        let (_, poses) = planned(&case);
        let z2 = mean_z2(&case, &poses, 0..200);
        println!("{name}: mean z² {z2:.3} over 200 seeds");
        assert!(
            (0.8..1.25).contains(&z2),
            "{name}: mean z² {z2:.3} over 200 seeds"
        );
    }
}

#[test]
fn a_declared_lobing_is_removed_and_an_undeclared_one_is_seen_on_a_head() {
    // 2 µm of three-lobed pre-travel. The pattern turns about the stylus from pose to pose,
    // so the lobing moves each pose's centre differently: undeclared, it pulls the fit off the
    // truth (the same noise seed both times: the difference is the lobing's bias alone);
    // declared, it is removed before the sphere fits.
    let case = case("head-table-bc");
    let poses = sweep(&case.m, 6);
    let lobing = PreTravel {
        constant_mm: 0.0,
        lobing_mm: [2e-3, 0.0],
    };
    let declared = DeclaredPreTravel {
        constant_mm: 0.0,
        lobing_mm: [2e-3, 0.0],
    };
    let clean = identified(&case, &poses, 5, lobing, declared);
    for (n, z) in z_scores(&case, &clean) {
        assert!(z.abs() < 4.0, "declared: {n} is {z:.2} std off");
    }
    let blind = identified(&case, &poses, 5, lobing, Default::default());
    // The same noise: the difference is the lobing's bias alone, in std of the fit.
    let bias: Vec<(String, f64)> = clean
        .fit
        .names
        .iter()
        .enumerate()
        .filter_map(|(k, n)| {
            let (a, b, s) = (
                blind.fit.values[k]?,
                clean.fit.values[k]?,
                clean.fit.std[k]?,
            );
            Some((n.clone(), (a - b) / s))
        })
        .collect();
    println!("the undeclared lobing's bias, in std of the fit: {bias:?}");
    // Measured: AOB −1.66 std, YOW[record] 1.54, YOC −1.08, XOW[record] 0.45, XOB −0.32, the
    // rest below 0.2 std: a bias a single campaign cannot tell from its noise, which is why a
    // lobing is declared (the probe calibrated) or fitted (PRE@harmonic:3) rather than left
    // in the data.
    let (name, worst) = bias
        .iter()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap();
    assert!(
        worst.abs() > 1.0,
        "undeclared lobing: worst bias {worst:.2} std on {name}"
    );
}

#[test]
fn a_lobing_is_identified_on_a_head_and_on_a_table_table_machine() {
    // The pattern turns with the probe, and pose after pose by 22.5° about the stylus: a
    // three-lobed pre-travel moves each pose's centre across the stylus by L/7 in a direction
    // that turns by 90° from one pose to the next (probe_simulation.rs), so the lobing
    // separates from what takes a constant offset in the tool frame: on table-table-bc the
    // probe's zero (px0 py0 pz0, fitted: the record zeroed), on head-table-bc the B head's
    // offsets (its record not zeroed: with the probe's zero fitted too, one sphere position
    // leaves YOC with it).
    let lobing = PreTravel {
        constant_mm: 0.0,
        lobing_mm: [2e-3, -1e-3],
    };
    for (name, zeroed) in [("head-table-bc", false), ("table-table-bc", true)] {
        let case = case(name);
        let mut model = case.model.clone();
        model
            .terms
            .push(simulation::model::Term::parse(&case.m, "PRE@harmonic:3").unwrap());
        let poses = sweep(&case.m, 6);
        let ident = identified_as(
            &case,
            &model,
            zeroed,
            &poses,
            21,
            lobing,
            Default::default(),
        );
        let fit = &ident.fit;
        for (k, want) in [("PRE@harmonic:3:cos", 2e-3), ("PRE@harmonic:3:sin", -1e-3)] {
            let j = fit
                .names
                .iter()
                .position(|n| n == k)
                .unwrap_or_else(|| panic!("{name}: {k} not among {:?}", fit.names));
            let (Some(v), Some(s)) = (fit.values[j], fit.std[j]) else {
                panic!("{name}: {k} is not determined");
            };
            println!(
                "{name}, {} poses: {k}: {:.3} ± {:.3} µm (truth {:.3})",
                poses.len(),
                v * 1e3,
                s * 1e3,
                want * 1e3
            );
            assert!(
                ((v - want) / s).abs() < 4.0,
                "{name}: {k}: {v} ± {s}, truth {want}"
            );
            // Measured (12 poses, σ 0.5 µm): head-table-bc cos 1.20 ± 0.66 µm, sin −1.80 ±
            // 0.65 µm; table-table-bc cos 1.89 ± 0.68 µm, sin −1.96 ± 0.67 µm: 2 µm of lobing
            // moves a centre by 0.29 µm against the centre's 0.27 µm, the two components
            // alike (with the bed-frame pattern the head saw cos ± 0.43, sin ± 1.29 µm).
            assert!(s < 1e-3, "{name}: {k}: std {s} mm");
        }
        // The determined parameters (on table-table-bc the probe's zero leaves XOB, XOW, …
        // confounded with it, as it does without a lobing) within 4 std of the truth.
        for (k, n) in fit.names.iter().enumerate() {
            let (Some(v), Some(s)) = (fit.values[k], fit.std[k]) else {
                continue;
            };
            let column = &ident.layout.columns[k];
            let t = case
                .truth
                .coefficient(&column.term)
                .map_or(0.0, |c| c[column.component]);
            let t = if n.starts_with("PRE@harmonic:3:cos") {
                2e-3
            } else if n.starts_with("PRE@harmonic:3:sin") {
                -1e-3
            } else {
                t
            };
            assert!(
                ((v - t) / s).abs() < 4.0,
                "{name}: {n} is {} std off",
                (v - t) / s
            );
        }
        if zeroed {
            // The pattern at a fixed azimuth: the lobing is one tool-frame offset at every
            // pose, which the probe's zero takes; not determined, only declared.
            let campaign = probe_campaign_with(
                &case,
                true,
                &poses,
                21,
                (lobing, Default::default()),
                sim::PatternAzimuth::Fixed,
            );
            let opts = IdentifyOptions::new()
                .constraint(case.constraint.clone())
                .noise(NoiseChoice::Instrument);
            let fixed = identify(&case.m, &model, &campaign, &opts).unwrap();
            for k in ["PRE@harmonic:3:cos", "PRE@harmonic:3:sin"] {
                let j = fixed.fit.names.iter().position(|n| n == k).unwrap();
                assert!(
                    fixed.fit.values[j].is_none(),
                    "{name}: {k} is determined with the pattern at a fixed azimuth"
                );
            }
        }
    }
}

#[test]
fn a_rotary_axis_backlash_is_identified_from_poses_approached_from_both_sides() {
    // seed-ac's C with 15 µrad of reversal (30 µrad of lost motion): C stepped up 0…300° and
    // back down 240…60°, so that each angle but the ends is approached from both sides.
    let mut case = case("seed-ac");
    case.truth = truth(
        &case.m,
        "XOW = 12\nYOW = -18\nZOW = 15\nYOA = 20\nZOA = -15\nBOA = 25\nCOA = -18\nXOC = 10\nYOC = -22\nAOC = 30\nBOC = -12\nECC = { reversal = 15 }\n",
    );
    case.model
        .terms
        .push(simulation::model::Term::parse(&case.m, "ECC@reversal").unwrap());
    let mut poses = sweep(&case.m, 6);
    let c = case.m.axis_by_name("C").unwrap();
    for deg in [240.0f64, 180.0, 120.0, 60.0] {
        let mut q = vec![0.0; case.m.axes.len()];
        q[c] = deg.to_radians();
        poses.push(q);
    }
    let ident = identified(&case, &poses, 4, PreTravel::default(), Default::default());
    let z = z_scores(&case, &ident);
    let (_, zr) = z.iter().find(|(n, _)| n.starts_with("ECC")).unwrap();
    let j = ident
        .fit
        .names
        .iter()
        .position(|n| n.starts_with("ECC"))
        .unwrap();
    println!(
        "ECC@reversal: {:.2} ± {:.2} µrad (truth 15)",
        ident.fit.values[j].unwrap() * 1e6,
        ident.fit.std[j].unwrap() * 1e6
    );
    assert!(zr.abs() < 4.0, "ECC@reversal {zr:.2} std off");
    assert!(ident.fit.std[j].unwrap() < 5e-6, "ECC@reversal std");
    for (n, z) in &z {
        assert!(z.abs() < 4.0, "{n} is {z:.2} std off");
    }
}

#[test]
fn a_linear_axis_backlash_or_a_servo_lag_is_refused_on_probe_records() {
    let case = case("seed-ac");
    let poses = sweep(&case.m, 4);
    for (term, why) in [
        ("EXX@reversal", "both directions of every linear axis"),
        ("EXX@velocity", "stands still at every hit"),
    ] {
        let mut model = case.model.clone();
        model
            .terms
            .push(simulation::model::Term::parse(&case.m, term).unwrap());
        let campaign = probe_campaign(
            &case,
            false,
            &poses,
            1,
            PreTravel::default(),
            Default::default(),
        );
        let m = &case.m;
        let e = identify(m, &model, &campaign, &IdentifyOptions::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains(term) && e.contains(why), "{term}: {e}");
    }
}

#[test]
fn the_plan_predicts_the_lobings_uncertainty_the_campaign_reports() {
    // The plan's poses carry their hits' responses to pre-travel (the pattern as it will be
    // probed, turned pose by pose), so a model with PRE@harmonic:3 is predicted: its std is
    // the one the identification of the simulated campaign at those poses reports.
    let lobing = PreTravel {
        constant_mm: 0.0,
        lobing_mm: [2e-3, -1e-3],
    };
    for name in ["head-table-bc", "table-table-bc"] {
        let case = case(name);
        let mut model = case.model.clone();
        model
            .terms
            .push(simulation::model::Term::parse(&case.m, "PRE@harmonic:3").unwrap());
        let plan = with_plan_inputs(&case, &model, |inputs| inputs.plan(6).unwrap());
        let poses: Vec<Vec<f64>> = plan
            .poses
            .poses
            .iter()
            .map(|p| p.commands.clone())
            .collect();
        let ident = identified_as(&case, &model, false, &poses, 3, lobing, Default::default());
        for k in ["PRE@harmonic:3:cos", "PRE@harmonic:3:sin"] {
            let jp = plan.prediction.names.iter().position(|n| n == k).unwrap();
            let jf = ident.fit.names.iter().position(|n| n == k).unwrap();
            let (predicted, reported) =
                (plan.prediction.std[jp].unwrap(), ident.fit.std[jf].unwrap());
            println!(
                "{name}, {} poses: {k}: predicted ± {:.3} µm, reported ± {:.3} µm",
                poses.len(),
                predicted * 1e3,
                reported * 1e3
            );
            assert!(
                (predicted / reported - 1.0).abs() < 0.02,
                "{name}: {k}: predicted {predicted}, reported {reported}"
            );
        }
    }
}
