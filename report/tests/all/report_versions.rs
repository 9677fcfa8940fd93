//! The one reader of identification reports reads what rtest wrote before reports had a version
//! (version 1: a single record's report without records and set-ups, and a campaign's with
//! `"kind": "campaign"`) to the same values, layout and flags as the version-2 reports of the
//! same identifications; the report type reads both and gives a version-1 record its record.
//!
//! Fixtures (`report/tests/data/reports/`): seed-ac, the reduced model with ECC@harmonic:2;
//! `identify-z4-*`: one zeroed K4 record with `--constraint zero:XOC,YOA,ZOA`;
//! `identify-k4-k1-*`: K4 and K1 on two set-ups. The version-1 files have exactly the fields
//! rtest wrote then.

use report::json::identify::{IdentificationReport, REPORT_VERSION};
use report::json::read::parse_identification;
use std::path::Path;

use crate::common;
use common::builtin;

fn fixture(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/reports")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The fields of version 1's report of one record.
const SINGLE_V1_FIELDS: [&str; 24] = [
    "machine",
    "fingerprint",
    "data",
    "model",
    "base_model",
    "terms",
    "parameters",
    "residual_rms_um",
    "rank",
    "free_parameters",
    "condition",
    "confounded",
    "samples",
    "readings",
    "dof",
    "zeroed",
    "constraint",
    "sigma_um",
    "near_confounded",
    "swallowed",
    "gains",
    "refinement",
    "noise_model",
    "notes",
];

#[test]
fn a_version_1_report_of_one_record_reads_to_the_values_of_version_2() {
    let m = builtin("seed-ac");
    let (v1, v2) = (
        fixture("identify-z4-v1.json"),
        fixture("identify-z4-v2.json"),
    );
    // The fixture is today's shape: exactly those fields, no version, records or set-ups.
    let root: serde_json::Value = serde_json::from_str(&v1).unwrap();
    let mut keys: Vec<&str> = root
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    let mut fields = SINGLE_V1_FIELDS;
    fields.sort_unstable();
    assert_eq!(keys, fields);
    let a = parse_identification("v1.json", &v1, &m).unwrap();
    let b = parse_identification("v2.json", &v2, &m).unwrap();
    assert_eq!((a.version, b.version), (1, REPORT_VERSION));
    // One record labelled by its file's stem, on its own set-up, zeroed: its zero is its own.
    assert_eq!(a.values.layout, b.values.layout);
    let layout = &a.values.layout;
    assert_eq!(layout.setups, ["z4"]);
    assert_eq!(layout.records[0].label, "z4");
    assert!(layout.records[0].zeroed);
    assert_eq!(layout.records[0].params, m.default_parameters());
    assert!(layout.names().contains(&"dx0[z4]".to_string()));
    assert_eq!(a.values.model, b.values.model);
    assert!(
        a.values
            .model
            .terms
            .iter()
            .all(|t| !t.spelling(&m).starts_with("dx0")),
        "the model as given: the record adds its zero"
    );
    assert_eq!(a.values.values, b.values.values);
    assert_eq!(a.values.std, b.values.std);
    assert_eq!(a.values.determined, b.values.determined);
    assert_eq!(a.values.fixed, b.values.fixed);
    assert_eq!(
        (a.constraint.as_str(), b.constraint.as_str()),
        ("zero: XOC, YOA, ZOA", "zero: XOC, YOA, ZOA")
    );
    assert_eq!(a.data, ["z4.csv"]);
    // The numbers are the file's, µm → mm: XOC fixed at 0, YOC as written.
    let written = |name: &str| {
        root["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    let (model, values) = a.single_record().unwrap();
    let at = |name: &str| {
        let names = fitting::hmatrix::parameter_names(&m, &model);
        values[names.iter().position(|n| n == name).unwrap()].unwrap()
    };
    assert_eq!(at("XOC"), 0.0);
    assert_eq!(at("YOC"), written("YOC") / 1e3);
    assert_eq!(
        at("ECC@harmonic:2:sin"),
        written("ECC@harmonic:2:sin") / 1e6
    );
    assert_eq!(at("dz0"), written("dz0") / 1e3);
}

#[test]
fn a_version_1_campaign_reads_to_the_values_of_version_2() {
    let m = builtin("seed-ac");
    let (v1, v2) = (
        fixture("identify-k4-k1-v1.json"),
        fixture("identify-k4-k1-v2.json"),
    );
    let root: serde_json::Value = serde_json::from_str(&v1).unwrap();
    assert!(root.get("version").is_none() && root["kind"] == "campaign");
    let a = parse_identification("v1.json", &v1, &m).unwrap();
    let b = parse_identification("v2.json", &v2, &m).unwrap();
    assert_eq!((a.version, b.version), (1, REPORT_VERSION));
    assert_eq!(a.values, b.values);
    assert_eq!(a.data, ["k4.csv", "k1.csv"]);
    assert_eq!(a.values.layout.setups, ["k4", "k1"]);
    let names = a.values.layout.names();
    let j = names.iter().position(|n| n == "XOW[k1]").unwrap();
    let xow = root["parameters"][j]["value"].as_f64().unwrap();
    assert_eq!(a.values.values[j], Some(xow / 1e3));
    assert!(a.single_record().is_none());
}

#[test]
fn the_report_type_reads_either_version_and_gives_a_record_its_record() {
    let v1 = IdentificationReport::from_json("v1.json", &fixture("identify-z4-v1.json")).unwrap();
    let v2 = IdentificationReport::from_json("v2.json", &fixture("identify-z4-v2.json")).unwrap();
    assert_eq!((v1.version, v2.version), (1, 2));
    assert!(!v1.is_campaign() && !v2.is_campaign());
    assert_eq!(v1.records.len(), 1);
    assert_eq!(v1.records[0].label, v2.records[0].label);
    assert_eq!(v1.records[0].data, "z4.csv");
    assert!(v1.records[0].zeroed && v1.any_zeroed());
    assert!(
        v1.records[0].params.0.is_empty(),
        "version 1 does not say: the defaults"
    );
    assert_eq!(v1.setups, v2.setups);
    assert_eq!(v1.parameters, v2.parameters);
    // Written again, a record's report is version 2 with today's fields and its record.
    let again: serde_json::Value =
        serde_json::from_str(&report::json::to_json(&v2).unwrap()).unwrap();
    let keys: Vec<&str> = again
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    let mut expected: Vec<&str> = SINGLE_V1_FIELDS.to_vec();
    expected.extend(["version", "setups", "records"]);
    let mut sorted = keys.clone();
    sorted.sort_unstable();
    expected.sort_unstable();
    assert_eq!(sorted, expected);
    let c = IdentificationReport::from_json("c.json", &fixture("identify-k4-k1-v1.json")).unwrap();
    assert!(c.is_campaign());
    assert_eq!(c.records.len(), 2);
    assert_eq!(c.parameters_of("setup", Some("k4")).len(), 3);
    // A version this rtest does not know is refused, naming the field.
    let newer = fixture("identify-z4-v2.json").replacen("\"version\": 2", "\"version\": 3", 1);
    let e = IdentificationReport::from_json("n.json", &newer).unwrap_err();
    assert!(e.to_string().contains("n.json: field `version`: 3"), "{e}");
    let e = parse_identification("n.json", &newer, &builtin("seed-ac")).unwrap_err();
    assert!(e.to_string().contains("n.json: field `version`"), "{e}");
    let zero = fixture("identify-z4-v2.json").replacen("\"version\": 2", "\"version\": 0", 1);
    let e = IdentificationReport::from_json("z.json", &zero).unwrap_err();
    assert!(e.to_string().contains("z.json: field `version`: 0"), "{e}");
}
