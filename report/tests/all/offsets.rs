//! Kinematic offsets as unknowns: the gain of a symbol against central differences of the
//! exact chain; a pivot length off its nominal recovered within 4 standard uncertainties; a
//! ball position reported as not separable from its set-up error; the seed machine's own
//! symbols and what its paths confound them with; campaigns (a machine's length shared, a
//! ball's position per set-up, records that disagree on a shared length refused); the report
//! written and read back; validation on records modelled with another value; bad terms and
//! bad symbol names refused with their reason.

use crate::one_record::{
    identify_one, identify_refined_campaign, identify_refined_one, validate_one,
};
use crate::one_report::{IdentificationSource, report_of_one};
use fitting::campaign::{CampaignValues, Owner};
use fitting::hmatrix::h_matrix_auto;
use fitting::noise::NoiseChoice;
use fitting::offsets::{OffsetGains, is_setup_symbol};
use fitting::refine::RefineOptions;
use fitting::{Identification, IdentifyOptions, ValidateOptions};
use model_spec::{Machine, builtin, parse_machine};
use report::json::read::parse_identification;
use report::json::{IdentificationReport, to_json};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::exact::VirtualMachine;
use simulation::generator::{GeneratorOptions, find_test, generate_test, tests};
use simulation::model::{Effect, Model, Term};
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::rng::Rng;
use simulation::truth::Truth;

fn machine(name: &str) -> Machine {
    builtin(name).unwrap().unwrap()
}

fn file_machine(file: &str) -> Machine {
    let path = format!("{}/../tests/machines/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    parse_machine(&path, &text).unwrap()
}

/// A machine with inclined axes and symbols in the offsets after them: a C table tilted 45°
/// about x on the work side (the ball on it), a linear U slide along [0, 1, 1] and a B head
/// about [1, 2, 3] on the tool side, its pivot and tool length symbols.
fn inclined_machine() -> Machine {
    let text = r#"
name = "inclined-offsets"
[symbols]
Xc = 10.0
Zc = 40.0
Xw = 100.0
Yw = 20.0
Zw = 80.0
Yu = 5.0
Zb = 150.0
Lt = 120.0
[[work]]
axis = "C"
type = "rotary"
direction = [0, -1, 1]
offset = ["Xc", 0, "Zc"]
[[work]]
end = "ball"
offset = ["Xw", "Yw", "Zw"]
[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-900.0, 900.0]
[[tool]]
axis = "U"
type = "linear"
direction = [0, 1, 1]
offset = [0, "Yu", 0]
stroke = [-900.0, 900.0]
[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-900.0, 900.0]
[[tool]]
axis = "B"
type = "rotary"
direction = [1, 2, 3]
offset = [0, "Yu", "Zb"]
range = [-180.0, 180.0]
[[tool]]
end = "probe"
offset = [0, 0, "Lt"]
[errors]
squareness_order = ["X", "Z", "U"]
"#;
    parse_machine("inclined-offsets.toml", text).unwrap()
}

fn symbol(m: &Machine, name: &str) -> usize {
    m.symbol_by_name(name).unwrap()
}

/// `model` of `m` with `terms` (a comma list) appended.
fn model(m: &Machine, base: Option<&str>, terms: &str) -> Model {
    let mut model = base.map_or_else(Model::default, |b| Model::of(m, b).unwrap());
    for t in terms.split(',').filter(|t| !t.is_empty()) {
        model.terms.push(Term::parse(m, t).unwrap());
    }
    model
}

/// The test `name` of `m` planned at `params` (mm).
fn path_at(m: &Machine, name: &str, params: &[f64]) -> Record {
    let all = tests(m);
    let spec = find_test(&all, name).unwrap();
    generate_test(m, spec, params, &GeneratorOptions::default()).unwrap()
}

/// The location errors of head-table-bc that pair-B-C cannot separate from others (AOZ from
/// YOC, ZOB from ZOW, XOB from XOC): left out of [`determined`] and of the truth of
/// [`head_table_truth`] without them.
const CONFOUNDED_ON_PAIR: [&str; 3] = ["AOZ", "ZOB", "XOB"];

/// The errors of head-table-bc's location model (µm, µrad; without [`CONFOUNDED_ON_PAIR`]
/// unless `all`), its pivot length 40 µm shorter than the description says (the tool point
/// 40 µm higher), reading noise `noise_um`.
fn head_table_truth(m: &Machine, noise_um: f64, seed: u64, all: bool) -> Truth {
    let mut errors = vec![
        ("COY", 8.0),
        ("AOZ", -6.0),
        ("BOZ", 5.0),
        ("XOW", 12.0),
        ("YOW", -9.0),
        ("ZOW", 7.0),
        ("XOB", 15.0),
        ("ZOB", -11.0),
        ("AOB", 20.0),
        ("COB", -14.0),
        ("XOC", 10.0),
        ("YOC", -13.0),
        ("AOC", 16.0),
        ("BOC", -12.0),
    ];
    if !all {
        errors.retain(|(n, _)| !CONFOUNDED_ON_PAIR.contains(n));
    }
    let mut text =
        format!("noise_um = {noise_um}\nseed = {seed}\n[parameters]\nZt = -250.04\n[errors]\n");
    for (n, v) in errors {
        text += &format!("{n} = {v}\n");
    }
    formats::truth::parse_truth("head-table.toml", &text, m).unwrap()
}

/// The location model of head-table-bc without [`CONFOUNDED_ON_PAIR`], with the pivot length
/// `Zt`: every parameter determined on pair-B-C.
fn determined(m: &Machine) -> Model {
    let mut model = model(m, Some("location"), "Zt");
    model
        .terms
        .retain(|t| !CONFOUNDED_ON_PAIR.contains(&t.effect.name(m).as_str()));
    model
}

/// The value and standard uncertainty (mm) of parameter `name`.
fn value(id: &Identification, name: &str) -> (Option<f64>, Option<f64>) {
    let j = id.fit.names.iter().position(|n| n == name).unwrap();
    (id.fit.values[j], id.fit.std[j])
}

fn groups(names: &[String], confounded: &[Vec<usize>]) -> Vec<Vec<String>> {
    let mut g: Vec<Vec<String>> = confounded
        .iter()
        .map(|g| {
            let mut g: Vec<String> = g.iter().map(|&j| names[j].clone()).collect();
            g.sort();
            g
        })
        .collect();
    g.sort();
    g
}

#[test]
fn the_gain_of_every_symbol_is_the_central_difference_of_the_exact_chain() {
    // Built-in machines and test machines with axes in negative directions, a head-head
    // machine, symbols shared by several offsets and inclined axes (linear and rotary, exact
    // and numeric directions, symbols after them); random poses on and off the ball, random
    // kinematic parameters. The nominal chain is affine in its symbols, so the difference is
    // exact whatever the step: a 0.5 mm and a 20 mm step give the same gain.
    let machines = [
        machine("seed-ac"),
        machine("seed-3axis"),
        machine("head-table-bc"),
        file_machine("neg-table.toml"),
        file_machine("neg-head.toml"),
        file_machine("head-head-ca.toml"),
        file_machine("shared-offsets.toml"),
        inclined_machine(),
    ];
    let mut rng = Rng::new(11);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    for m in &machines {
        assert!(!m.symbols.is_empty(), "{}", m.name);
        let vm = VirtualMachine::new(m);
        let gains = OffsetGains::new(m);
        for _ in 0..12 {
            let commands: Vec<f64> = m
                .axes
                .iter()
                .map(|a| {
                    let [lo, hi] = a.limits;
                    match a.kind {
                        model_spec::AxisKind::Linear => rng.uniform_in(lo, hi),
                        model_spec::AxisKind::Rotary => {
                            let (lo, hi) = if lo.is_finite() {
                                (lo, hi)
                            } else {
                                (-180.0, 180.0)
                            };
                            rng.uniform_in(lo, hi).to_radians()
                        }
                    }
                })
                .collect();
            let params: Vec<f64> = m
                .symbols
                .iter()
                .map(|s| s.default + rng.uniform_in(-100.0, 100.0))
                .collect();
            let g = gains.gains(&commands);
            for s in 0..m.symbols.len() {
                for step in [0.5, 20.0] {
                    let at = |d: f64| {
                        let mut p = params.clone();
                        p[s] += d;
                        vm.nominal_error_vector(&commands, &p)
                    };
                    let (plus, minus) = (at(step), at(-step));
                    for (d, gain) in g[s].iter().enumerate() {
                        let fd = (plus.position[d] - minus.position[d]) / (2.0 * step);
                        let err = (fd - gain).abs();
                        worst = worst.max(err);
                        assert!(
                            err < 1e-10,
                            "{} {} step {step}: {d} gain {gain} fd {fd}",
                            m.name,
                            m.symbols[s].name,
                        );
                        // A symbol turns no frame.
                        assert_eq!(plus.orientation[d], 0.0);
                    }
                }
                checked += 1;
            }
        }
    }
    println!("{checked} symbol gains, largest difference {worst:.1e} mm/mm");
}

#[test]
fn the_h_matrix_column_of_a_symbol_is_its_gain_and_a_pivot_length_reads_along_the_tool() {
    let m = machine("head-table-bc");
    let rec = builtin_path(&m, "pair-B-C").unwrap().unwrap();
    let h = h_matrix_auto(&m, &model(&m, None, "Zt,Xc"), &rec, &m.default_parameters()).unwrap();
    let gains = OffsetGains::new(&m);
    let (zt, xc) = (symbol(&m, "Zt"), symbol(&m, "Xc"));
    for (i, s) in rec.samples.iter().enumerate() {
        let g = gains.gains(&s.commands);
        for d in 0..3 {
            assert_eq!(h[(3 * i + d, 0)], g[zt][d]);
            assert_eq!(h[(3 * i + d, 1)], g[xc][d]);
        }
        // The tool point hangs from the B pivot along the tool's own axis: a longer pivot
        // moves it along +z of the tool frame, whatever B.
        assert!((g[zt][0]).abs() < 1e-15 && (g[zt][1]).abs() < 1e-15);
        assert!((g[zt][2] - 1.0).abs() < 1e-15);
    }
}

#[test]
fn a_pivot_length_off_its_nominal_is_recovered_within_four_standard_uncertainties() {
    let m = machine("head-table-bc");
    let location_zt = model(&m, Some("location"), "Zt");
    let rec = builtin_path(&m, "pair-B-C").unwrap().unwrap();
    let opts = IdentifyOptions::new();
    let refine = RefineOptions::default();
    // Noise-free, every parameter determined: the change is found exactly once refined
    // against the exact machine.
    let clean = simulate(&m, &head_table_truth(&m, 0.0, 0, false), &rec).unwrap();
    let (id, _) = identify_refined_one(&m, &determined(&m), &clean, &opts, &refine).unwrap();
    assert_eq!(id.fit.rank, id.fit.names.len());
    let (v, _) = value(&id, "Zt");
    let v = v.expect("Zt is determined on pair-B-C");
    assert!((v + 0.040).abs() < 1e-10, "{v}");
    let first = identify_one(&m, &determined(&m), &clean, &opts).unwrap();
    let first_order = value(&first, "Zt").0.unwrap();
    println!(
        "noise-free: Zt change {:.6e} µm off (refined), {:.3e} µm off (first order)",
        (v + 0.040) * 1e3,
        (first_order + 0.040) * 1e3
    );
    // With 0.3 µm of noise and the whole location model (three pairs of it confounded on
    // pair-B-C, Zt not), over seeds: within 4 std, and the z-scores have a spread near 1.
    let mut z2 = 0.0;
    let seeds = 20;
    for seed in 1..=seeds {
        let noisy = simulate(&m, &head_table_truth(&m, 0.3, seed, true), &rec).unwrap();
        let (id, _) = identify_refined_one(&m, &location_zt, &noisy, &opts, &refine).unwrap();
        let (v, s) = value(&id, "Zt");
        let (v, s) = (v.unwrap(), s.unwrap());
        let z = (v + 0.040) / s;
        assert!(
            z.abs() < 4.0,
            "seed {seed}: Zt {} ± {} µm",
            v * 1e3,
            s * 1e3
        );
        z2 += z * z;
        // The change is relative to the description's value, which the report gives.
        let j = id.fit.names.iter().position(|n| n == "Zt").unwrap();
        assert_eq!(id.nominal_mm[j], Some(-250.0));
        assert!(id.nominal_mm.iter().filter(|n| n.is_some()).count() == 1);
    }
    let mean_z2 = z2 / seeds as f64;
    println!("Zt over {seeds} seeds: mean z² {mean_z2:.2}");
    assert!((0.2..3.0).contains(&mean_z2), "{mean_z2}");
}

#[test]
fn a_ball_position_is_not_separable_from_its_set_up_error() {
    let m = machine("head-table-bc");
    let rec = simulate(
        &m,
        &head_table_truth(&m, 0.3, 5, true),
        &builtin_path(&m, "pair-B-C").unwrap().unwrap(),
    )
    .unwrap();
    let id = identify_one(
        &m,
        &model(&m, Some("location"), "Xw,Zt"),
        &rec,
        &IdentifyOptions::new(),
    )
    .unwrap();
    let g = groups(&id.fit.names, &id.fit.identifiability.confounded);
    assert!(
        g.contains(&vec!["XOW".to_string(), "Xw".to_string()]),
        "{g:?}"
    );
    assert_eq!(value(&id, "Xw").0, None);
    assert_eq!(value(&id, "XOW").0, None);
    // One rank short of the columns the location model already leaves undetermined.
    let alone = identify_one(
        &m,
        &model(&m, Some("location"), "Zt"),
        &rec,
        &IdentifyOptions::new(),
    )
    .unwrap();
    assert_eq!(id.fit.rank, alone.fit.rank);
    // The report names the group and gives neither a value.
    let report = report_of_one(
        &m,
        IdentificationSource {
            data: "rec.csv",
            label: "location + Xw + Zt",
            base_model: Some("location"),
        },
        &id,
        None,
    )
    .unwrap();
    let xw = report.parameters.iter().find(|p| p.name == "Xw").unwrap();
    assert_eq!(xw.value, None);
    assert_eq!(xw.nominal_mm, Some(120.0));
    assert_eq!(xw.identified_mm, Some(None));
    assert!(
        report
            .confounded
            .iter()
            .any(|g| g.contains(&"Xw".to_string()) && g.contains(&"XOW".to_string())),
        "{:?}",
        report.confounded
    );
    let json = to_json(&report).unwrap();
    assert!(json.contains("\"identified_mm\": null"), "{json}");
    let text = report::text::identify::identification(&report);
    assert!(
        text.contains("not determined: confounded with XOW"),
        "{text}"
    );
    assert!(text.contains("(nominal 120 mm)"), "{text}");
}

#[test]
fn on_the_seed_machine_its_own_symbols_are_found_or_named_with_what_they_confound() {
    let m = machine("seed-ac");
    let k4 = builtin_path(&m, "K4").unwrap().unwrap();
    // The probe 25 µm longer than the description says; the reduced truth without ZOA, which a
    // probe length cannot be told from.
    let text = r#"
noise_um = 0.3
seed = 3
[parameters]
Zp = 184.695
[errors]
XOW = 12.0
YOW = -18.0
ZOW = 15.0
YOA = 20.0
BOA = 25.0
COA = -18.0
XOC = 10.0
YOC = -22.0
AOC = 30.0
BOC = -12.0
"#;
    let truth = formats::truth::parse_truth("zp.toml", text, &m).unwrap();
    let rec = simulate(&m, &truth, &k4).unwrap();
    // The reduced model with Zp: Zp and ZOA both move the nest along z of the (unturned) tool
    // frame at every pose, so K4 cannot separate them.
    let both = identify_one(
        &m,
        &model(&m, Some("reduced"), "Zp"),
        &rec,
        &IdentifyOptions::new(),
    )
    .unwrap();
    let g = groups(&both.fit.names, &both.fit.identifiability.confounded);
    assert_eq!(g, vec![vec!["ZOA".to_string(), "Zp".to_string()]]);
    // Every symbol of seed-ac is confounded with an error of the reduced model on K4.
    let all = identify_one(
        &m,
        &model(
            &m,
            Some("reduced"),
            "Xa,Ya,Za,Zc,Xw,Yw,Zw,Xz,Yz,Zz,Xh,Zh,Zp",
        ),
        &rec,
        &IdentifyOptions::new(),
    )
    .unwrap();
    let g = groups(&all.fit.names, &all.fit.identifiability.confounded);
    let want: Vec<Vec<String>> = [
        "XOC Xa Xh Xz",
        "XOW Xw",
        "YOA Ya Yz",
        "YOW Yw",
        "ZOA Za Zh Zp Zz",
        "ZOW Zc Zw",
    ]
    .iter()
    .map(|g| g.split(' ').map(str::to_string).collect())
    .collect();
    assert_eq!(g, want);
    // Zp in place of ZOA: found.
    let mut zp_model = model(&m, Some("reduced"), "Zp");
    let zoa = m.error_by_name("ZOA").unwrap();
    zp_model.terms.retain(|t| t.effect != Effect::Error(zoa));
    let (id, _) = identify_refined_one(
        &m,
        &zp_model,
        &rec,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let (v, s) = value(&id, "Zp");
    let (v, s) = (v.unwrap(), s.unwrap());
    println!("seed-ac Zp: {:.4} ± {:.4} µm (truth 25)", v * 1e3, s * 1e3);
    assert!(((v - 0.025) / s).abs() < 4.0);
}

#[test]
fn a_campaign_shares_a_machine_length_and_gives_each_set_up_its_ball_position() {
    let m = machine("head-table-bc");
    let (xw, zt) = (symbol(&m, "Xw"), symbol(&m, "Zt"));
    assert!(is_setup_symbol(&m, xw) && !is_setup_symbol(&m, zt));
    let base = head_table_truth(&m, 0.3, 9, true);
    let mut records = Vec::new();
    for (label, ball_x, path, seed) in [("near", 120.0, "pair-B-C", 9), ("far", 60.0, "turn-B", 10)]
    {
        let mut params = m.default_parameters();
        params[xw] = ball_x;
        let mut truth = base.clone();
        truth.params[xw] = ball_x;
        truth.seed = seed;
        let rec = simulate(&m, &truth, &path_at(&m, path, &params)).unwrap();
        records.push(CampaignRecord::new(label, rec, params, label, false));
    }
    let campaign = Campaign::new(records.clone()).unwrap();
    let model_zt = model(&m, Some("location"), "Zt,Xw");
    let (id, _) = identify_refined_campaign(
        &m,
        &model_zt,
        &campaign,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let owner = |name: &str| {
        let j = id.fit.names.iter().position(|n| n == name).unwrap();
        (id.layout.columns[j].owner, j)
    };
    let (o, j) = owner("Zt");
    assert_eq!(o, Owner::Shared);
    let (v, s) = (id.fit.values[j].unwrap(), id.fit.std[j].unwrap());
    assert!(((v + 0.040) / s).abs() < 4.0, "{v} ± {s}");
    assert!(matches!(owner("Xw[near]").0, Owner::Setup(_)));
    assert!(matches!(owner("Xw[far]").0, Owner::Setup(_)));
    let nominal = id.layout.nominal_mm();
    assert_eq!(nominal[owner("Xw[near]").1], Some(120.0));
    assert_eq!(nominal[owner("Xw[far]").1], Some(60.0));
    assert_eq!(nominal[j], Some(-250.0));
    let g = groups(&id.fit.names, &id.fit.identifiability.confounded);
    assert!(
        g.contains(&vec!["XOW[near]".to_string(), "Xw[near]".to_string()]),
        "{g:?}"
    );
    // The report gives each column's nominal length and reads back only with the records' own.
    let source = report::json::CampaignSource {
        label: "location + Zt + Xw",
        base_model: Some("location"),
        data: &["near.csv".to_string(), "far.csv".to_string()],
    };
    let report = IdentificationReport::of_campaign(&m, source, &id, None).unwrap();
    let json = to_json(&report).unwrap();
    let back = parse_identification("c.json", &json, &m).unwrap();
    // The same values, to the rounding of the report's units (µm, µrad) and back.
    assert_eq!(back.values.values.len(), id.fit.values.len());
    for (a, b) in back.values.values.iter().zip(&id.fit.values) {
        match (a, b) {
            (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-12 * b.abs(), "{a} vs {b}"),
            _ => assert_eq!(a, b),
        }
    }
    let tampered = json.replacen("\"nominal_mm\": 60.0", "\"nominal_mm\": 61.0", 1);
    let e = parse_identification("c.json", &tampered, &m)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("nominal_mm")
            && e.contains("61 mm, but the records of `Xw[far]` are modelled with 60 mm"),
        "{e}"
    );
    // Records that disagree on a machine's length cannot share one change of it.
    let mut other = records.clone();
    other[1].params[zt] = -250.01;
    let e = identify_refined_campaign(
        &m,
        &model_zt,
        &Campaign::new(other).unwrap(),
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("kinematic offset `Zt`")
            && e.contains("`near` and `far`")
            && e.contains("-250.01"),
        "{e}"
    );
}

#[test]
fn the_report_reads_back_and_validates_records_modelled_with_another_length() {
    let m = machine("head-table-bc");
    let zt = symbol(&m, "Zt");
    let location_zt = determined(&m);
    let truth = head_table_truth(&m, 0.3, 21, false);
    let rec = simulate(&m, &truth, &builtin_path(&m, "pair-B-C").unwrap().unwrap()).unwrap();
    let (id, r) = identify_refined_one(
        &m,
        &location_zt,
        &rec,
        &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let source = IdentificationSource {
        data: "pair.csv",
        label: "location + Zt",
        base_model: None,
    };
    let report = report_of_one(&m, source, &id, Some(&r)).unwrap();
    let p = report.parameters.iter().find(|p| p.name == "Zt").unwrap();
    assert_eq!(p.unit, "um");
    assert_eq!(p.nominal_mm, Some(-250.0));
    let v = p.value.unwrap();
    assert!((p.identified_mm.unwrap().unwrap() - (-250.0 + v / 1e3)).abs() < 1e-12);
    let text = report::text::identify::identification(&report);
    let line = text.lines().find(|l| l.starts_with("Zt ")).unwrap();
    assert!(
        line.contains("µm  (change; nominal -250 mm, identified -250.0"),
        "{line}"
    );
    let json = to_json(&report).unwrap();
    let back = parse_identification("zt.json", &json, &m).unwrap();
    let (back_model, back_values) = back.single_record().unwrap();
    let k = back_model
        .terms
        .iter()
        .position(|t| *t == Term::parse(&m, "Zt").unwrap())
        .unwrap();
    let j = id.fit.names.iter().position(|n| n == "Zt").unwrap();
    assert_eq!(back_values[k], id.fit.values[j]);
    // Tampered or missing lengths are refused, naming the field.
    let tampered = json.replacen("\"nominal_mm\": -250.0", "\"nominal_mm\": -249.0", 1);
    assert_ne!(tampered, json);
    let e = parse_identification("zt.json", &tampered, &m)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("identified_mm") && e.contains("nominal_mm + value"),
        "{e}"
    );
    let missing = json.replacen("\"nominal_mm\": -250.0,", "", 1);
    let e = parse_identification("zt.json", &missing, &m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nominal_mm") && e.contains("missing"), "{e}");
    // The values predict another record of the same machine to the noise.
    let turn_c = simulate(&m, &truth, &builtin_path(&m, "turn-C").unwrap().unwrap()).unwrap();
    let v = validate_one(
        &m,
        &back_model,
        &back_values,
        &turn_c,
        false,
        &ValidateOptions::new().exact(true),
    )
    .unwrap();
    println!(
        "turn-C: {:.3} µm RMS before, {:.3} µm after",
        v.overall.measured_rms * 1e3,
        v.overall.residual_rms * 1e3
    );
    assert!(v.overall.residual_rms < 0.4e-3, "{:?}", v.overall);
    // A record planned by a controller that believes Zt = -250.02 (the machine's is -250.04):
    // the identified length minus the record's, -20 µm, predicts it, with its ball set-up
    // refitted on the record.
    let mut params = m.default_parameters();
    params[zt] = -250.02;
    let mut t2 = truth.clone();
    t2.seed = 22;
    let other = simulate(&m, &t2, &path_at(&m, "turn-B", &params)).unwrap();
    let values = CampaignValues::of(
        &fitting::campaign::identify(
            &m,
            &location_zt,
            &Campaign::new(vec![CampaignRecord::new(
                "pair",
                rec.clone(),
                m.default_parameters(),
                "pair",
                false,
            )])
            .unwrap(),
            &IdentifyOptions::new().noise(NoiseChoice::Ordinary),
        )
        .unwrap(),
    );
    let check = Campaign::new(vec![CampaignRecord::new("b", other, params, "b", false)]).unwrap();
    let v = fitting::validate(
        &m,
        &values,
        &check,
        &ValidateOptions::new().exact(true),
        &formats::progress::Unwatched,
    )
    .unwrap();
    println!(
        "turn-B at Zt = -250.02: {:.3} µm RMS before, {:.3} µm after",
        v.overall.measured_rms * 1e3,
        v.overall.residual_rms * 1e3
    );
    assert!(v.overall.measured_rms > 10e-3);
    assert!(v.overall.residual_rms < 0.5e-3, "{:?}", v.overall);
}

#[test]
fn a_change_identified_at_another_value_is_read_back_against_the_default() {
    // Identified with the controller's Zt = -250.01 (the machine's is -250.04): the change is
    // -30 µm from -250.01; on the description (default -250) it is -40 µm: what a report of
    // version 1 (which does not say what the record was modelled with) reads back, and what
    // compensation folds into the description.
    let m = machine("head-table-bc");
    let zt = symbol(&m, "Zt");
    let mut params = m.default_parameters();
    params[zt] = -250.01;
    let rec = simulate(
        &m,
        &head_table_truth(&m, 0.0, 0, false),
        &path_at(&m, "pair-B-C", &params),
    )
    .unwrap();
    let (id, r) = identify_refined_one(
        &m,
        &determined(&m),
        &rec,
        &IdentifyOptions::clone(&IdentifyOptions::new().params(params))
            .noise(NoiseChoice::Ordinary),
        &RefineOptions::default(),
    )
    .unwrap();
    let (v, _) = value(&id, "Zt");
    assert!((v.unwrap() + 0.030).abs() < 1e-10, "{v:?}");
    let source = IdentificationSource {
        data: "pair.csv",
        label: "location + Zt",
        base_model: None,
    };
    let json = to_json(&report_of_one(&m, source, &id, Some(&r)).unwrap()).unwrap();
    assert!(json.contains("\"nominal_mm\": -250.01"), "{json}");
    // Version 2: the record says it was modelled with Zt = -250.01, and the change is from it.
    let back = parse_identification("zt.json", &json, &m).unwrap();
    assert_eq!(back.values.layout.records[0].params[zt], -250.01);
    let (back_model, back_values) = back.single_record().unwrap();
    let k = back_model.terms.len() - 1;
    assert_eq!(back_model.terms[k], Term::parse(&m, "Zt").unwrap());
    let change = back_values[back_model.width() - 1].unwrap();
    assert!((change + 0.030).abs() < 1e-9, "{change}");
    // Version 1 (no record): read back on the description, the change is from its default.
    let root: serde_json::Value = serde_json::from_str(&json).unwrap();
    let mut v1 = root.as_object().unwrap().clone();
    for key in ["version", "records", "setups"] {
        v1.remove(key);
    }
    let v1 = serde_json::to_string(&v1).unwrap();
    let old = parse_identification("zt.json", &v1, &m).unwrap();
    assert_eq!(old.version, 1);
    let (_, old_values) = old.single_record().unwrap();
    let last = old_values[back_model.width() - 1].unwrap();
    assert!((last + 0.040).abs() < 1e-9, "{last}");
    // A compensation leaves the length out and says where it belongs.
    let (errors, left_out) =
        compensation::values::MachineErrors::from_values(&m, &back.values, &back.file).unwrap();
    assert!(!errors.errors().is_empty());
    let zt = left_out.iter().find(|l| l.term == "Zt").unwrap();
    assert!(
        zt.reason.contains("kinematic offset") && zt.reason.contains("[symbols]"),
        "{}",
        zt.reason
    );
    assert_eq!(zt.values, vec![Some(last)]);
}

#[test]
fn a_kinematic_offset_is_a_constant_and_its_name_is_its_own() {
    let m = machine("head-table-bc");
    let e = Term::parse(&m, "Zt@harmonic:1").unwrap_err().0;
    assert!(
        e.contains("kinematic offset") && e.contains("constants only") && e.contains("harmonic:1"),
        "{e}"
    );
    assert!(Term::parse(&m, "Zt@time:1").is_err());
    assert_eq!(
        Term::parse(&m, "Zt@const").unwrap(),
        Term::parse(&m, "Zt").unwrap()
    );
    let e = Term::parse(&m, "zt").unwrap_err().0;
    assert!(e.contains("written `Zt`"), "{e}");
    // Truths give real lengths under [parameters], never as errors.
    assert_eq!(Effect::parse(&m, "Zt"), None);
    assert_eq!(
        Effect::parse_term(&m, "Zt"),
        Some(Effect::KinematicOffset(symbol(&m, "Zt")))
    );
    let t = Term::parse(&m, "Zt").unwrap();
    assert_eq!(t.unit(&m), "um");
    assert_eq!(t.display_factor(&m), 1e3);
    assert_eq!(t.spelling(&m), "Zt");
    assert!(
        t.describe(&m)
            .contains("kinematic offset Zt: z of the offset of the end probe (tool chain)"),
        "{}",
        t.describe(&m)
    );
    assert!(
        Term::parse(&m, "Xw")
            .unwrap()
            .describe(&m)
            .contains("ball position Xw")
    );
}

#[test]
fn a_description_names_symbols_apart_from_errors_and_lists_them_in_models() {
    let base = r#"name = "m"
[symbols]
Zt = -100.0
NAME = 1.0

[[work]]
axis = "C"
type = "rotary"
direction = "+z"

[[work]]
end = "ball"

[[tool]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-100, 100]

[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-100, 100]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-100, 100]

[[tool]]
end = "probe"
offset = [0, 0, "Zt"]

[models.with_length]
errors = ["XOC", "Zt"]
"#;
    let m = parse_machine("m.toml", &base.replace("NAME", "Lx")).unwrap();
    let terms = &m.models["with_length"].terms;
    assert_eq!(terms[1].effect, Effect::KinematicOffset(0));
    assert_eq!(m.models["with_length"].errors.len(), 1);
    for (bad, error) in [("xoc", "XOC"), ("X0C", "XOC"), ("y0c", "YOC")] {
        let e = parse_machine("m.toml", &base.replace("NAME", bad))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!(
                "m.toml:4:1: symbol `{bad}` reads as the error {error} of this machine (error names are read without regard to case, with 0 for O): terms name errors and kinematic symbols alike, so rename the symbol"
            )
        );
    }
    let e = parse_machine("m.toml", &base.replace("NAME", "XOC"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("has the name of an error of this machine"),
        "{e}"
    );
    let e = parse_machine(
        "m.toml",
        &base
            .replace("NAME", "Lx")
            .replace("\"XOC\", \"Zt\"]", "\"XOC\", \"Zt@time:1\"]"),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "m.toml:37:18: model `with_length`: Zt: `Zt` is a kinematic offset of the machine (a length of its description, mm): constants only, not `time:1`; a length does not change with position, direction of motion or time (what does is an error of an axis or a drift)"
    );
    let e = parse_machine(
        "m.toml",
        &base
            .replace("NAME", "Lx")
            .replace("\"XOC\", \"Zt\"]", "\"XOC\", \"zt\"]"),
    )
    .unwrap_err()
    .to_string();
    assert_eq!(
        e,
        "m.toml:37:18: model `with_length`: `zt` is no error of this machine; the kinematic symbol is written `Zt` (symbols are named exactly as [symbols] writes them)"
    );
}

#[test]
fn what_every_symbol_is_confounded_with_on_the_test_paths() {
    // The groups docs/identification.md §15 lists: every symbol of the machine next to the
    // errors of its model, on the built-in tests (noise-free readings of the nominal machine:
    // the groups depend on the path only).
    let cases = [
        (
            "seed-ac",
            "reduced",
            "Xa,Ya,Za,Zc,Xw,Yw,Zw,Xz,Yz,Zz,Xh,Zh,Zp",
            "K1",
            7,
            vec![
                "BOA BOC XOC Xa Xh Xz",
                "COA XOW Xw YOW Yw",
                "YOA YOC Ya Yz",
                "ZOA ZOW Za Zc Zh Zp Zw Zz",
            ],
        ),
        (
            "seed-ac",
            "reduced",
            "Xa,Ya,Za,Zc,Xw,Yw,Zw,Xz,Yz,Zz,Xh,Zh,Zp",
            "K2",
            7,
            vec![
                "AOC BOC XOC XOW Xa Xh Xw Xz YOC YOW Yw ZOW Zc Zw",
                "YOA Ya Yz",
                "ZOA Za Zh Zp Zz",
            ],
        ),
        (
            "head-table-bc",
            "location",
            "Xc,Yc,Zc,Xb,Yb,Zb,Zt,Xw,Yw,Zw",
            "pair-B-C",
            12,
            vec![
                "AOZ YOC Yb Yc",
                "XOB XOC Xb Xc",
                "XOW Xw",
                "YOW Yw",
                "ZOB ZOW Zb Zc Zw",
            ],
        ),
        (
            "head-table-bc",
            "location",
            "Zt",
            "turn-C",
            8,
            vec!["AOB AOZ YOC", "BOZ XOB XOC", "COB", "ZOB ZOW Zt"],
        ),
    ];
    for (name, base, symbols, path, rank, want) in cases {
        let m = machine(name);
        let mut rec = builtin_path(&m, path).unwrap().unwrap();
        rec.measured = vec![[0.0; 3]; rec.samples.len()];
        let id = identify_one(
            &m,
            &model(&m, Some(base), symbols),
            &rec,
            &IdentifyOptions::new(),
        )
        .unwrap();
        let got: Vec<String> = groups(&id.fit.names, &id.fit.identifiability.confounded)
            .into_iter()
            .map(|g| g.join(" "))
            .collect();
        println!(
            "{name} {base} + {symbols} on {path}: rank {} of {}; {got:?}",
            id.fit.rank,
            id.fit.names.len()
        );
        assert_eq!(id.fit.rank, rank, "{name} {path}");
        assert_eq!(got, want, "{name} {path}");
    }
}
