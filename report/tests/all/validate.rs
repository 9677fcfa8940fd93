//! Validation (prediction against measurement on other paths) and the JSON reports: metrics,
//! zeroed readings, unidentified parameters, and reading an `identify` JSON back.

use crate::common;
use crate::one_record::{identify_one, validate_one};
use crate::one_report::{IdentificationSource, report_of_one};

use common::{Rng, builtin};
use fitting::IdentifyOptions;
use fitting::campaign::{CampaignIdentification, CampaignValues};
use fitting::hmatrix::h_matrix_auto;
use fitting::validate::{Unidentified, ValidateError, ValidateOptions, statistics};
use model_spec::Machine;
use nalgebra::DVector;
use report::json::read::parse_identification;
use report::json::{ReportError, ValidationReport, ValidationSource, read_identification};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Model, Term};
use simulation::record::{Record, Sample, motion_directions};
use simulation::tool_centre_point_ik;

fn normal(rng: &mut Rng) -> f64 {
    let u1 = 1.0 - rng.unit();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * rng.unit()).cos()
}

fn path(m: &Machine, poses: impl Iterator<Item = (f64, f64)>) -> Record {
    let p = m.default_parameters();
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    let commands: Vec<Vec<f64>> = poses
        .map(|(aa, cc)| {
            let mut q = vec![0.0; m.axes.len()];
            q[a] = aa;
            q[c] = cc;
            tool_centre_point_ik(m, &mut q, &p).unwrap();
            q
        })
        .collect();
    let motion = motion_directions(&commands);
    Record {
        samples: commands
            .into_iter()
            .zip(motion)
            .enumerate()
            .map(|(i, (commands, motion))| Sample {
                commands,
                t: i as f64,
                motion,
                timed: true,
            })
            .collect(),
        ..Default::default()
    }
}

fn k2(m: &Machine) -> Record {
    path(m, (0..=120).map(|i| ((-90.0 + i as f64).to_radians(), 0.0)))
}

fn reduced(m: &Machine) -> Model {
    Model::constant(m.model_errors("reduced").unwrap())
}

fn truth() -> Vec<f64> {
    vec![
        0.012, -0.008, 0.015, 0.021, -0.011, 35e-6, -22e-6, 0.018, -0.014, 41e-6, -17e-6,
    ]
}

/// Measurements `H·x + σ·noise` (mm) of `model` on `rec`; zeroed at the first sample if asked.
fn measure(
    m: &Machine,
    model: &Model,
    x: &[f64],
    mut rec: Record,
    sigma: f64,
    seed: u64,
    zeroed: bool,
) -> Record {
    let h = h_matrix_auto(m, model, &rec, &m.default_parameters()).unwrap();
    let y = h * DVector::from_column_slice(x);
    let mut rng = Rng::new(seed);
    let mut rows: Vec<[f64; 3]> = (0..rec.samples.len())
        .map(|i| std::array::from_fn(|d| y[3 * i + d] + sigma * normal(&mut rng)))
        .collect();
    if zeroed {
        let first = rows[0];
        for r in &mut rows {
            *r = std::array::from_fn(|d| r[d] - first[d]);
        }
    }
    rec.measured = rows;
    rec
}

#[test]
fn statistics_follow_the_definitions() {
    let measured = [[1.0, 2.0, 2.0], [0.0, -4.0, 0.0]];
    let prediction = [[1.0, 2.0, 0.0], [0.0, -1.0, 0.0]];
    let (per, all) = statistics(&measured, &prediction);
    assert_eq!(per[0].measured_rms, (1.0f64 / 2.0).sqrt());
    assert_eq!(per[1].measured_rms, (20.0f64 / 2.0).sqrt());
    assert_eq!(per[1].measured_max, 4.0);
    assert_eq!(per[1].residual_max, 3.0);
    assert_eq!(per[2].residual_rms, (4.0f64 / 2.0).sqrt());
    assert_eq!(all.measured_rms, (25.0f64 / 6.0).sqrt());
    assert_eq!(all.residual_rms, (13.0f64 / 6.0).sqrt());
    assert_eq!(all.residual_max, 3.0);
}

#[test]
fn identified_on_k4_predicts_k1_and_k2() {
    let m = builtin("seed-ac");
    let model = reduced(&m);
    let x = truth();
    for (sigma, tol) in [(0.0, 1e-12), (0.5e-3, 0.6e-3)] {
        let data = measure(&m, &model, &x, k4(&m), sigma, 1, false);
        let ident = identify_one(&m, &model, &data, &IdentifyOptions::default()).unwrap();
        for (name, rec, seed) in [("K1", k1(&m), 2), ("K2", k2(&m), 3)] {
            let rec = measure(&m, &model, &x, rec, sigma, seed, false);
            let v = validate_one(
                &m,
                &ident.model,
                &ident.fit.values,
                &rec,
                false,
                &ValidateOptions::default(),
            )
            .unwrap();
            eprintln!(
                "σ = {} µm, {name}: before {:.3} µm rms, after {:.2e} µm rms (max {:.2e})",
                sigma * 1e3,
                v.overall.measured_rms * 1e3,
                v.overall.residual_rms * 1e3,
                v.overall.residual_max * 1e3
            );
            assert!(
                v.overall.residual_rms < tol,
                "{name}: {}",
                v.overall.residual_rms
            );
            assert!(
                v.overall.measured_rms > 10e-3,
                "{name}: the errors show before"
            );
            assert!(v.defaulted.is_empty());
            if sigma > 0.0 {
                assert!(v.overall.residual_rms > 0.4e-3, "at the noise level");
            }
            // The one path of validation (a record is a campaign of one, here on the fitted
            // set-up) predicts as the record's own validation does.
            let data = format!("{name}.csv");
            let values = CampaignValues::of(
                &CampaignIdentification::of_record(&m, &ident, "k4", m.default_parameters())
                    .unwrap(),
            );
            let record = CampaignRecord::new(
                name.to_lowercase(),
                rec.clone(),
                m.default_parameters(),
                "k4",
                false,
            );
            let cv = fitting::validate(
                &m,
                &values,
                &Campaign::new(vec![record]).unwrap(),
                &ValidateOptions::default(),
                &formats::progress::Unwatched,
            )
            .unwrap();
            assert_eq!(cv.records[0].validation.prediction, v.prediction);
            assert!(cv.records[0].setup_fitted && cv.records[0].refitted.is_empty());
            let source = ValidationSource {
                model: "reduced",
                params: "id.json",
                data: &[data],
                kinematics: &[m.default_parameters()],
                exact: false,
            };
            let j = ValidationReport::new(&m, source, &cv).unwrap();
            let text = serde_json::to_value(&j).unwrap();
            for key in [
                "data",
                "samples",
                "measured_rms_um",
                "residual_rms_um",
                "per_direction",
            ] {
                assert!(text.get(key).is_some(), "{key}");
            }
            let x_dir = &text["per_direction"]["x"];
            for key in [
                "measured_rms_um",
                "measured_max_um",
                "residual_rms_um",
                "residual_max_um",
            ] {
                assert!(x_dir.get(key).is_some(), "{key}");
            }
            assert!((j.overall.measured_rms_um - v.overall.measured_rms * 1e3).abs() < 1e-12);
            assert_eq!(j.samples, rec.samples.len());
        }
    }
}

#[test]
fn zeroed_readings_refit_their_zero_and_name_what_was_set_to_zero() {
    let m = builtin("seed-ac");
    let model = reduced(&m);
    let x = truth();
    let data = measure(&m, &model, &x, k4(&m), 0.0, 1, true);
    let opts = IdentifyOptions::new().zeroed(true);
    let ident = identify_one(&m, &model, &data, &opts).unwrap();
    let rec = measure(&m, &model, &x, k1(&m), 0.0, 2, true);
    let zeroed = ValidateOptions::new();
    let v = validate_one(&m, &ident.model, &ident.fit.values, &rec, true, &zeroed).unwrap();
    // The record's own zero is refitted on it (its readings start at 0, so does the
    // prediction); what the fit left undetermined is set to 0 and named.
    assert!(v.overall.residual_rms < 1e-12, "{}", v.overall.residual_rms);
    assert!(
        v.prediction[0].iter().all(|p| p.abs() < 1e-12),
        "{:?}",
        v.prediction[0]
    );
    assert_eq!(v.defaulted, ["YOA", "ZOA", "XOC"]);
    // The caller may refuse to predict with parameters that have no value.
    let refuse = ValidateOptions::new().unidentified(Unidentified::Refuse);
    let e = validate_one(&m, &ident.model, &ident.fit.values, &rec, true, &refuse).unwrap_err();
    assert!(matches!(e, ValidateError::Unidentified(_)));
    assert_eq!(
        e.to_string(),
        "the identification gave no value for YOA, ZOA, XOC; cannot predict (choose to set them to 0)"
    );
}

#[test]
fn identify_json_has_the_fields_and_reads_back() {
    let m = builtin("seed-ac");
    let mut model = reduced(&m);
    model.terms.push(Term::parse(&m, "ECC@harmonic:2").unwrap());
    model.terms.push(Term::parse(&m, "EXX@reversal").unwrap());
    let mut x = truth();
    x.extend([12e-6, -7e-6, 0.002]);
    let data = measure(&m, &model, &x, k4(&m), 0.5e-3, 9, true);
    let opts = IdentifyOptions::new().zeroed(true);
    let ident = identify_one(&m, &model, &data, &opts).unwrap();
    let source = IdentificationSource {
        data: "k4.csv",
        label: "reduced+",
        base_model: Some("reduced"),
    };
    let report = report_of_one(&m, source, &ident, None).unwrap();
    let text = serde_json::to_string_pretty(&report).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    for key in [
        "machine",
        "fingerprint",
        "model",
        "base_model",
        "terms",
        "parameters",
        "residual_rms_um",
        "rank",
        "condition",
        "confounded",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    let params = v["parameters"].as_array().unwrap();
    assert_eq!(params.len(), 17);
    let find = |e: &str, b: &str| {
        params
            .iter()
            .find(|p| p["error"] == e && p["basis"] == b)
            .unwrap_or_else(|| panic!("{e} {b}"))
    };
    assert!(find("XOC", "const")["value"].is_null());
    assert!(find("XOC", "const")["std"].is_null());
    assert_eq!(find("BOA", "const")["unit"], "urad");
    assert_eq!(find("dx0", "const")["unit"], "um");
    assert_eq!(find("ECC", "harmonic:2:sin")["unit"], "urad");
    let boa = find("BOA", "const")["value"].as_f64().unwrap();
    assert!((boa - 35.0).abs() < 4.0 * find("BOA", "const")["std"].as_f64().unwrap());
    assert!(text.contains("\"confounded\""));
    assert_eq!(report.confounded.len(), 3);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("dx0 cannot be told from XOC")),
        "{:?}",
        report.notes
    );
    // Read back: same model and values (µm, µrad → mm, rad).
    let back = parse_identification("id.json", &text, &m).unwrap();
    let (back_model, back_values) = back.single_record().unwrap();
    assert_eq!(back_model, ident.model);
    assert_eq!(back.model_name, "reduced+");
    for (a, b) in back_values.iter().zip(&ident.fit.values) {
        match (a, b) {
            (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-15 * b.abs().max(1e-9)),
            (None, None) => {}
            _ => panic!("{a:?} vs {b:?}"),
        }
    }
    // The values validate.
    let rec = measure(&m, &model, &x, k1(&m), 0.0, 2, true);
    let zeroed = ValidateOptions::new();
    let v = validate_one(&m, &back_model, &back_values, &rec, true, &zeroed).unwrap();
    assert!(v.overall.residual_rms < 2e-3);
}

fn field_error(text: &str, m: &Machine) -> String {
    let e = parse_identification("id.json", text, m).unwrap_err();
    assert!(matches!(
        e,
        ReportError::Field { .. } | ReportError::Json { .. }
    ));
    e.to_string()
}

#[test]
fn bad_identify_json_names_the_file_and_the_field() {
    let m = builtin("seed-ac");
    let ok = r#"{"machine": "seed-ac", "fingerprint": "FP", "model": "m",
        "base_model": null, "terms": ["XOC", "ECC@harmonic:1"], "parameters": [
        {"error": "XOC", "basis": "const", "value": 1.5, "std": 0.1, "unit": "um"},
        {"error": "ECC", "basis": "harmonic:1:cos", "value": 2, "std": null, "unit": "urad"},
        {"error": "ECC", "basis": "harmonic:1:sin", "value": null, "std": null, "unit": "urad"}]}"#
        .replace("FP", &m.fingerprint());
    let ok = ok.as_str();
    let v = parse_identification("id.json", ok, &m).unwrap();
    assert_eq!(v.values.values, vec![Some(1.5e-3), Some(2e-6), None]);
    assert_eq!(v.values.model.terms.len(), 2);
    let cases = [
        (
            ok.replace("\"seed-ac\"", "\"other\""),
            "id.json: field `machine`: the values are for machine `other`, not `seed-ac`",
        ),
        (
            ok.replace("\"XOC\"", "\"QQQ\""),
            "id.json: field `parameters[0].error`: `QQQ` is neither an error of machine seed-ac nor dx0/dy0/dz0 nor an instrument term SXX … SZY",
        ),
        (
            ok.replacen("\"um\"", "\"urad\"", 1),
            "id.json: field `parameters[0].unit`: `urad`: `XOC` `const` is in `um`",
        ),
        (
            ok.replace("1.5", "\"1.5\""),
            "id.json: field `parameters[0].value`: expected a number or null, found \"1.5\"",
        ),
        (
            ok.replace("harmonic:1:sin", "harmonic:2:sin"),
            "id.json: field `parameters[2].basis`: expected `harmonic:1:sin` of `ECC` after its `cos` column, found `harmonic:2:sin` of `ECC`",
        ),
        (
            ok.replace("harmonic:1:cos", "harmonic:1"),
            "id.json: field `parameters[1].basis`: `harmonic:1`: a harmonic is written as its `harmonic:1:cos` column followed by its `harmonic:1:sin` column",
        ),
        (
            ok.replace("\"const\"", "\"cubic\""),
            "id.json: field `parameters[0].basis`: unknown basis `cubic` (expected const, harmonic:K, poly:K, reversal, time:K, period:P, step:V, exp:TAU, velocity, rate, warmup:TAU or jump:T)",
        ),
        (
            ok.replace("\"model\": \"m\",", ""),
            "id.json: field `model`: missing",
        ),
        (
            ok.replace(", \"value\": 1.5", ""),
            "id.json: field `parameters[0].value`: missing (write null for no value)",
        ),
        (
            "[]".to_string(),
            "id.json: field `(top level)`: expected a JSON object",
        ),
        (
            ok.replace(&m.fingerprint(), "0123456789abcdef"),
            &format!(
                "id.json: field `fingerprint`: `0123456789abcdef` is not this description of machine seed-ac's (`{}`): the values were identified on a machine with another topology or other kinematic defaults, and do not apply to this one",
                m.fingerprint()
            ),
        ),
        (
            ok.replace(&format!("\"fingerprint\": \"{}\",", m.fingerprint()), ""),
            "id.json: field `fingerprint`: missing: the report does not say which machine description it was identified on (identify again with this rtest)",
        ),
        (
            ok.replace("\"base_model\": null", "\"base_model\": \"tiny\""),
            "id.json: field `base_model`: machine seed-ac has no model `tiny` (models: full, reduced)",
        ),
        (
            ok.replace(
                "[\"XOC\", \"ECC@harmonic:1\"]",
                "[\"XOC\", \"ECC@harmonic:1\", \"YOC\"]",
            ),
            "id.json: field `terms`: [XOC, ECC@harmonic:1, YOC] are not the terms of the parameters [XOC, ECC@harmonic:1]: a parameter is missing or extra",
        ),
        (
            ok.replace("\"base_model\": null", "\"base_model\": \"reduced\""),
            "id.json: field `parameters`: the base model `reduced` has XOW, YOW, ZOW, YOA, ZOA, BOA, COA, YOC, AOC, BOC that the parameters lack",
        ),
        (
            ok.replace("\"terms\": [\"XOC\", \"ECC@harmonic:1\"],", ""),
            "id.json: field `terms`: missing: the report must list the terms it identified (XOC, ECC@harmonic:1)",
        ),
        (
            ok.replace(
                "\"model\": \"m\",",
                "\"model\": \"m\", \"refinement\": {\"converged\": false},",
            ),
            "id.json: field `refinement.converged`: false: the refinement against the exact machine did not converge, so these values are not an identification",
        ),
        (
            ok.replace("1.5", "1e999"),
            "id.json:3:57: not valid JSON: number out of range",
        ),
    ];
    for (text, message) in cases {
        assert_eq!(field_error(&text, &m), message, "{text}");
    }
    // A poly:K value belongs to the stroke it was normalised over.
    let poly = ok
        .replace("[\"XOC\", \"ECC@harmonic:1\"]", "[\"XOC\", \"ECC@harmonic:1\", \"EXX@poly:2\"]")
        .replace(
            "\"unit\": \"urad\"}]}",
            "\"unit\": \"urad\"},\n{\"error\": \"EXX\", \"basis\": \"poly:2\", \"value\": 0.5, \"unit\": \"um\", \"over_mm\": [-500, 500]}]}",
        );
    parse_identification("id.json", &poly, &m).unwrap();
    assert_eq!(
        field_error(&poly.replace("[-500, 500]", "[-800, 800]"), &m),
        "id.json: field `parameters[3].over_mm`: EXX@poly:2 was normalised over the stroke -800 .. 800 mm, but axis X of this machine has -500 .. 500 mm: the value would mean another error"
    );
    assert_eq!(
        field_error(&poly.replace(", \"over_mm\": [-500, 500]", ""), &m),
        "id.json: field `parameters[3].over_mm`: missing or not [min, max]: a poly:K value means something only with the stroke (mm) it was normalised over"
    );
    // Columns count characters, as every reader's do (the parser counts bytes).
    let e = field_error("{\"machine\": \"sé\" x", &m);
    assert_eq!(e, "id.json:1:18: not valid JSON: expected `,` or `}`");
    // A byte-order mark is accepted, as in CSV and TOML files.
    assert!(parse_identification("id.json", &format!("\u{feff}{ok}"), &m).is_ok());
    let e = field_error("{\"machine\": ", &m);
    assert!(
        e.starts_with("id.json:1:12: not valid JSON: EOF while parsing a value"),
        "{e}"
    );
    let missing = std::env::temp_dir().join(format!("rtest-no-such-{}.json", std::process::id()));
    let e = read_identification(&missing, &m).unwrap_err();
    assert!(
        e.to_string()
            .starts_with(&format!("cannot read `{}`: ", missing.display())),
        "{e}"
    );
}

/// The built-in test path K4.
fn k4(m: &Machine) -> Record {
    simulation::paths::builtin_path(m, "K4").unwrap().unwrap()
}

/// The built-in test path K1.
fn k1(m: &Machine) -> Record {
    simulation::paths::builtin_path(m, "K1").unwrap().unwrap()
}
