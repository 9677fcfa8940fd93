//! The warning that the tool-side length cannot be told from what is compensated: in the text
//! after `Warning: `, in the JSON as `length_confounded`; a report without it has no field, and
//! a report written before the field existed reads back.

use crate::common::builtin;

use compensation::confounded::LengthConfounded;
use compensation::run::{CommandedPose, compensate_poses};
use report::json::compensate::{CompensationReport, CompensationSource, LengthReport};
use report::text;
use simulation::exact::tool_centre_point_ik;

/// The report of one pose of seed-ac compensated with ZOA = 12 µm, with `length` as the
/// warning.
fn report_of(length: Option<LengthReport>) -> CompensationReport {
    let m = builtin("seed-ac");
    let mut q = vec![0.0; m.axes.len()];
    q[m.axis_by_name("A").unwrap()] = -30f64.to_radians();
    tool_centre_point_ik(&m, &mut q, &m.default_parameters()).unwrap();
    let e = m.error_by_name("ZOA").unwrap();
    let values_at = |_: &[f64], out: &mut [f64]| out[0] = 0.012;
    let pose = [CommandedPose {
        line: 2,
        commands: q,
    }];
    let done =
        compensate_poses(&m, &[e], m.default_parameters(), "p.csv", &pose, &values_at).unwrap();
    let source = CompensationSource {
        machine: m.name.clone(),
        model: "zoa".into(),
        params_file: "zoa.json".into(),
        input: "p.csv".into(),
        output: "out.csv".into(),
        format: "csv".into(),
        compensated: vec!["ZOA".into()],
        left_out: Vec::new(),
        rounding: None,
        kinematics: None,
        tables: Vec::new(),
        length_confounded: length,
    };
    CompensationReport::new(source, &done.summary).unwrap()
}

#[test]
fn the_length_warning_is_in_the_text_and_the_json() {
    let found = LengthConfounded {
        symbol: "Zp".into(),
        end: "probe".into(),
        identified: false,
        with: vec!["ZOA".into()],
    };
    let r = report_of(Some(LengthReport::of(&found)));
    let said = text::compensate::compensation(&r);
    let line = said
        .lines()
        .find(|l| l.starts_with("Warning: "))
        .unwrap_or_else(|| panic!("{said}"));
    assert!(
        line.starts_with("Warning: The probe's length Zp (the offset of the tool chain's end along the tool axis) cannot be told from ZOA"),
        "{line}"
    );
    assert!(
        line.ends_with("give it with --param Zp=LENGTH (mm) when identifying and compensating."),
        "{line}"
    );
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["length_confounded"]["symbol"], "Zp");
    assert_eq!(
        json["length_confounded"]["with"],
        serde_json::json!(["ZOA"])
    );
    assert_eq!(
        json["length_confounded"]["warning"],
        line["Warning: ".len()..]
    );
    // An identified length: the other way round, and its own fix.
    let identified = LengthReport::of(&LengthConfounded {
        identified: true,
        ..found
    });
    assert!(
        identified
            .warning
            .starts_with("The identified change of the probe's length Zp cannot be told from ZOA, which the model does not hold"),
        "{}",
        identified.warning
    );
    assert!(identified.warning.ends_with("identify ZOA instead of Zp."));
}

#[test]
fn a_report_without_the_warning_has_no_field_and_reads_back() {
    let r = report_of(None);
    let said = text::compensate::compensation(&r);
    assert!(!said.contains("Warning"), "{said}");
    let json = serde_json::to_string(&r).unwrap();
    assert!(!json.contains("length_confounded"), "{json}");
    let back: CompensationReport = serde_json::from_str(&json).unwrap();
    assert_eq!(back, r);
}
