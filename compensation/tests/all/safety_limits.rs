//! The safety limits of a compensation (`compensation::limits`, `compensation::confounded`):
//! each error's largest value over the machine's ranges against `--max-change-um` and
//! `--max-change-urad`, the folded changes of the corrected description, the words of a program
//! that cannot carry the correction, and the tool-side length hidden in the pivot.

use crate::common::builtin;
use compensation::confounded::tool_length;
use compensation::kinematics::corrected_description;
use compensation::limits::{ChangeLimits, LimitError, check_changes, coarse_words, largest_values};
use compensation::values::MachineErrors;
use fitting::campaign::CampaignValues;
use formats::nc::{Dialect, WriteOptions, parse_program};
use formats::poses::axis_words;
use model_spec::Machine;
use simulation::model::{Model, Term};

/// The identification of the terms `names` (spellings) with these values (mm, rad; a
/// harmonic's cos and sin in turn) on `m`, at its default kinematic parameters.
fn identified(m: &Machine, names: &[&str], values: &[f64]) -> CampaignValues {
    let model = Model {
        terms: names
            .iter()
            .map(|s| Term::parse(m, s).unwrap_or_else(|e| panic!("{s}: {e}")))
            .collect(),
    };
    let values: Vec<Option<f64>> = values.iter().copied().map(Some).collect();
    CampaignValues::of_model(m, &model, &values, "k4", m.default_parameters()).unwrap()
}

fn errors(m: &Machine, v: &CampaignValues) -> MachineErrors {
    MachineErrors::from_values(m, v, "id.json").unwrap().0
}

#[test]
fn the_largest_value_of_an_error_is_over_its_axis_range() {
    let m = builtin("seed-ac");
    // EXX@poly:1 is the Legendre P1 over X's stroke (-500..500 mm): its largest is at an end.
    // ECC@harmonic:2 (cos 3 µrad, sin 4 µrad) has the amplitude 5 µrad.
    let v = identified(
        &m,
        &["XOC", "EXX@poly:1", "ECC@harmonic:2"],
        &[0.012, -0.02, 3e-6, 4e-6],
    );
    let e = errors(&m, &v);
    let largest = largest_values(&m, &e);
    let get = |n: &str| largest.iter().find(|l| l.name == n).unwrap();
    assert_eq!(get("XOC").value, 0.012);
    assert!(get("XOC").at.is_none());
    let exx = get("EXX");
    assert!((exx.value.abs() - 0.02).abs() < 1e-12, "{exx:?}");
    let (axis, at) = exx.at.clone().unwrap();
    assert_eq!(axis, "X");
    assert_eq!(at.abs(), 500.0);
    let ecc = get("ECC");
    assert!(ecc.angular);
    assert!((ecc.value.abs() - 5e-6).abs() < 5e-6 * 2e-3, "{ecc:?}");
}

#[test]
fn a_change_beyond_its_limit_is_refused_and_named() {
    let m = builtin("seed-ac");
    let limits = ChangeLimits::default();
    // Below the limits (49 µm, 240 µrad, 45 µm at the end of X): accepted.
    let below = identified(&m, &["ZOA", "AOC", "EXX@poly:1"], &[0.049, 240e-6, 0.045]);
    check_changes(&m, &errors(&m, &below), None, limits).unwrap();
    // Above: every one named, with its value, the limit and the flag.
    let above = identified(
        &m,
        &["ZOA", "AOC", "EXX@poly:1", "XOC"],
        &[-0.0623, 260e-6, 0.055, 0.01],
    );
    let e = check_changes(&m, &errors(&m, &above), None, limits).unwrap_err();
    let LimitError::Beyond { beyond, .. } = &e;
    assert_eq!(beyond.len(), 3, "{e}");
    let text = e.to_string();
    assert!(text.starts_with("id.json: "), "{text}");
    for part in [
        "ZOA = -62.3 µm (limit 50 µm, --max-change-um)",
        "AOC = 260 µrad (limit 250 µrad, --max-change-urad)",
        "EXX at X = -500 mm (its largest over X's stroke) = -55 µm (limit 50 µm",
        "raise the limit with --max-change-um or --max-change-urad",
    ] {
        assert!(text.contains(part), "{part}: {text}");
    }
    assert!(!text.contains("XOC"), "{text}");
    // The limits are the caller's.
    check_changes(
        &m,
        &errors(&m, &above),
        None,
        ChangeLimits::from_display(70.0, 300.0),
    )
    .unwrap();
}

#[test]
fn a_folded_change_beyond_the_limit_is_refused() {
    let m = builtin("head-table-bc");
    let text = &model_spec::write::source_text("head-table-bc").unwrap();
    // A pivot length 60 µm off: no compensated error holds it, the description's default does.
    let v = identified(&m, &["XOC", "Zt"], &[0.01, -0.06]);
    let e = errors(&m, &v);
    let limits = ChangeLimits::default();
    check_changes(&m, &e, None, limits).unwrap();
    let corrected = corrected_description(&m, text, &e).unwrap();
    let refused = check_changes(&m, &e, Some(&corrected), limits)
        .unwrap_err()
        .to_string();
    assert!(
        refused.contains("Zt folded into its default = -60 µm (limit 50 µm, --max-change-um)"),
        "{refused}"
    );
    let small = errors(&m, &identified(&m, &["XOC", "Zt"], &[0.01, -0.04]));
    let corrected = corrected_description(&m, text, &small).unwrap();
    check_changes(&m, &small, Some(&corrected), limits).unwrap();
}

#[test]
fn words_that_cannot_carry_the_correction_are_found() {
    let m = builtin("seed-ac");
    let words = axis_words(&m);
    // Machine axes X, A, C, Y, Z.
    let text = "G90 G1 X10 A0. C90 Y0.0000 Z5.1234\nG1 X10.5\n";
    let p = parse_program("p.nc", text, Dialect::Iso, &words).unwrap();
    let corrected = [
        vec![10.0, 0.0001, 90.00009, 0.00002, 5.12342],
        vec![10.50003, 0.0001, 90.00009, 0.00002, 5.12342],
    ];
    let w = p.write(&corrected, &WriteOptions::new()).unwrap();
    let coarse = coarse_words(&m, &w.rounding, &w.largest_rounding);
    let named: Vec<&str> = coarse.iter().map(|c| c.axis.as_str()).collect();
    assert_eq!(named, ["A", "C"], "{coarse:?}");
    let a = &coarse[0];
    assert_eq!(
        (a.at.line, a.at.word.as_str(), a.at.decimals),
        (1, "A0.", 0)
    );
    assert!(a.at.in_block);
    assert_eq!(a.needed, 4);
    let people = coarse[1].for_people();
    assert!(
        people.starts_with("line 1: `C90` (0 decimals) loses 1.571 µrad of the correction of C"),
        "{people}"
    );
    assert!(people.ends_with("4 decimals needed"), "{people}");
    // X: 0.03 µm lost in N2 (one decimal, but 10.50003 rounds to 10.5): within the limit.
    assert!((w.rounding[0] - 3e-5).abs() < 1e-12);
    // Four decimals carry every correction.
    let w = p
        .write(&corrected, &WriteOptions::with_min_decimals(4))
        .unwrap();
    assert!(coarse_words(&m, &w.rounding, &w.largest_rounding).is_empty());
}

#[test]
fn a_modal_word_that_rounds_its_correction_away_is_found() {
    let m = builtin("seed-ac");
    let words = axis_words(&m);
    let text = "G90 G1 X10.0000 A0.0000 C90 Y0.0000 Z0.0000\nG1 X11.0000\n";
    let p = parse_program("p.nc", text, Dialect::Iso, &words).unwrap();
    let corrected = [
        vec![10.0, 0.0, 90.0, 0.0, 0.0],
        vec![11.0, 0.0, 90.0003, 0.0, 0.0],
    ];
    let w = p.write(&corrected, &WriteOptions::new()).unwrap();
    let coarse = coarse_words(&m, &w.rounding, &w.largest_rounding);
    assert_eq!(coarse.len(), 1, "{coarse:?}");
    assert_eq!(coarse[0].at.line, 2);
    assert!(!coarse[0].at.in_block);
    assert!(
        coarse[0]
            .for_people()
            .starts_with("line 2: C left at `C90` from an earlier block (0 decimals) loses"),
        "{}",
        coarse[0].for_people()
    );
}

#[test]
fn the_probe_length_hides_in_the_first_rotary_axis_of_a_table_table_machine() {
    // seed-ac: the reduced model's ZOA cannot be told from the probe length Zp.
    let m = builtin("seed-ac");
    let names = [
        "XOW", "YOW", "ZOW", "YOA", "ZOA", "BOA", "COA", "XOC", "YOC", "AOC", "BOC",
    ];
    let v = identified(&m, &names, &[1e-3; 11]);
    let found = tool_length(&m, &v, &errors(&m, &v)).unwrap().unwrap();
    assert_eq!(found.symbol, "Zp");
    assert_eq!(found.end, "probe");
    assert!(!found.identified);
    assert_eq!(found.with, ["ZOA"]);
    // table-table-bc: its location model's ZOB.
    let m = builtin("table-table-bc");
    let model = Model::of(&m, "location").unwrap();
    let names: Vec<String> = model.terms.iter().map(|t| t.spelling(&m)).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let v = identified(&m, &names, &vec![1e-6; names.len()]);
    let found = tool_length(&m, &v, &errors(&m, &v)).unwrap().unwrap();
    assert_eq!(found.symbol, "Zp");
    assert_eq!(found.with, ["ZOB"]);
    // Without a location error along z, nothing compensated holds the length.
    let v = identified(&m, &["XOB", "XOC", "YOC", "AOC", "BOC"], &[1e-3; 5]);
    assert_eq!(tool_length(&m, &v, &errors(&m, &v)).unwrap(), None);
}

#[test]
fn an_identified_length_is_tested_against_the_location_errors_the_model_lacks() {
    // seed-ac with Zp identified instead of ZOA: the change of Zp may be ZOA's.
    let m = builtin("seed-ac");
    let names = [
        "XOW", "YOW", "ZOW", "YOA", "BOA", "COA", "XOC", "YOC", "AOC", "BOC", "Zp",
    ];
    let v = identified(&m, &names, &[1e-3; 11]);
    let found = tool_length(&m, &v, &errors(&m, &v)).unwrap().unwrap();
    assert!(found.identified);
    assert_eq!(found.with, ["ZOA"]);
    // head-table-bc: the pivot length turns with the B head, and the location errors of the
    // table and the head do not hold it: determinable, no warning.
    let m = builtin("head-table-bc");
    let names = [
        "COY", "BOZ", "XOW", "YOW", "ZOW", "AOB", "COB", "XOC", "YOC", "AOC", "BOC", "Zt",
    ];
    let v = identified(&m, &names, &[1e-3; 12]);
    assert_eq!(tool_length(&m, &v, &errors(&m, &v)).unwrap(), None);
    // Its location model without Zt: nothing holds the length either.
    let model = Model::of(&m, "location").unwrap();
    let names: Vec<String> = model.terms.iter().map(|t| t.spelling(&m)).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let v = identified(&m, &names, &vec![1e-6; names.len()]);
    assert_eq!(tool_length(&m, &v, &errors(&m, &v)).unwrap(), None);
}

#[test]
fn an_offset_turned_by_a_folded_direction_is_a_folded_change_too() {
    // The nutating B's AOB turns B's direction and the C table it carries: C's offset (Zc =
    // 90 mm along B's z) turns by 90 mm × 200 µrad = 18 µm.
    let m = builtin("nutating-table-bc");
    let text = &model_spec::write::source_text("nutating-table-bc").unwrap();
    let e = errors(&m, &identified(&m, &["AOB"], &[200e-6]));
    let corrected = corrected_description(&m, text, &e).unwrap();
    assert!(!corrected.turned.is_empty(), "{corrected:?}");
    let limits = ChangeLimits::from_display(10.0, 250.0);
    check_changes(&m, &e, None, limits).unwrap();
    let refused = check_changes(&m, &e, Some(&corrected), limits)
        .unwrap_err()
        .to_string();
    assert!(refused.contains("turned by the axes B"), "{refused}");
    check_changes(
        &m,
        &e,
        Some(&corrected),
        ChangeLimits::from_display(20.0, 250.0),
    )
    .unwrap();
}
