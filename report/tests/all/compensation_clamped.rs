//! A corrected command clamped to a range limit is reported: in the text with its line, axis,
//! corrected value and limit, and in the JSON as `clamped`; a report without one has no
//! `clamped` field.

use crate::common::builtin;

use compensation::run::{CommandedPose, compensate_poses};
use report::json::compensate::{CompensationReport, CompensationSource};
use report::text;
use simulation::exact::tool_centre_point_ik;

/// The report of the nutating table's pose B = 0°, C = 30° (line 7) compensated with B's
/// positioning error `ecb` (rad) alone.
fn report_of(ecb: f64) -> CompensationReport {
    let m = builtin("nutating-table-bc");
    let mut q = vec![0.0; m.axes.len()];
    q[m.axis_by_name("C").unwrap()] = 30f64.to_radians();
    tool_centre_point_ik(&m, &mut q, &m.default_parameters()).unwrap();
    let e = m.error_by_name("ECB").unwrap();
    let values_at = move |_: &[f64], out: &mut [f64]| out[0] = ecb;
    let pose = [CommandedPose {
        line: 7,
        commands: q,
    }];
    let done = compensate_poses(
        &m,
        &[e],
        m.default_parameters(),
        "b-zero.csv",
        &pose,
        &values_at,
    )
    .unwrap();
    let source = CompensationSource {
        machine: m.name.clone(),
        model: "ecb".into(),
        params_file: "ecb.json".into(),
        input: "b-zero.csv".into(),
        output: "out.csv".into(),
        format: "csv".into(),
        compensated: vec!["ECB".into()],
        left_out: Vec::new(),
        rounding: None,
        kinematics: None,
        tables: Vec::new(),
        length_confounded: None,
    };
    CompensationReport::new(source, &done.summary).unwrap()
}

#[test]
fn a_clamped_command_is_in_the_text_and_the_json() {
    let (a, b) = (report_of(50e-6), report_of(-50e-6));
    let clamped = if a.clamped.is_empty() { b } else { a };
    let said = text::compensate::compensation(&clamped);
    assert!(
        said.contains("Clamped to a stroke or range limit they passed by at most 0.01 mm or 0.01° (1 command(s); the pose keeps that much of its error): line 7: B = -0.002865° put on 0°."),
        "{said}"
    );
    let json = serde_json::to_value(&clamped).unwrap();
    assert_eq!(json["clamped"][0]["line"], 7);
    assert_eq!(json["clamped"][0]["axis"], "B");
    assert_eq!(json["clamped"][0]["unit"], "deg");
    assert_eq!(json["clamped"][0]["limit"], 0.0);
}

#[test]
fn a_report_without_a_clamped_command_has_no_clamped_field() {
    let (a, b) = (report_of(50e-6), report_of(-50e-6));
    let inside = if a.clamped.is_empty() { a } else { b };
    let json = serde_json::to_value(&inside).unwrap();
    assert!(json.get("clamped").is_none(), "{json}");
    assert!(!text::compensate::compensation(&inside).contains("Clamped"));
}
