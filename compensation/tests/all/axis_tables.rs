//! Axis compensation tables (`compensation::tables`): their values are the identified
//! errors at each position, the correction has the sign of the axis's own sense, and commanding
//! the position plus the correction on the exact machine cancels the positioning error.

use crate::common;

use common::builtin;
use compensation::tables::{AxisTable, MAX_TABLE_POINTS, Pitch, axis_tables};
use compensation::values::MachineErrors;
use fitting::campaign::CampaignValues;
use model_spec::units::parse_scaled;
use model_spec::{AxisKind, Machine, parse_machine};
use simulation::exact::chain_transform;
use simulation::model::{Model, Term};

fn neg_table() -> Machine {
    parse_machine(
        "tests/machines/neg-table.toml",
        include_str!("../../../tests/machines/neg-table.toml"),
    )
    .unwrap()
}

/// The compensated errors of `terms` (spelling, coefficients in mm or rad) on `m`.
fn errors_of(m: &Machine, terms: &[(&str, &[f64])]) -> MachineErrors {
    let model = Model {
        terms: terms
            .iter()
            .map(|(s, _)| Term::parse(m, s).unwrap_or_else(|e| panic!("{s}: {e}")))
            .collect(),
    };
    let values: Vec<Option<f64>> = terms
        .iter()
        .flat_map(|(_, v)| v.iter().map(|x| Some(*x)))
        .collect();
    assert_eq!(values.len(), model.width());
    let id = CampaignValues::of_model(m, &model, &values, "k4", m.default_parameters()).unwrap();
    MachineErrors::from_values(m, &id, "id.json").unwrap().0
}

/// Positioning, straightness and angular errors of a linear axis `X` and a rotary axis `C`,
/// position-dependent and constant.
const TERMS: &[(&str, &[f64])] = &[
    ("EXX", &[0.004]),
    ("EXX@poly:1", &[0.012]),
    ("EXX@poly:3", &[-0.003]),
    ("EXX@period:25", &[0.0015, -0.001]),
    ("EYX@poly:2", &[0.006]),
    ("EAX@poly:1", &[8e-6]),
    ("ECC@harmonic:1", &[15e-6, -9e-6]),
    ("ECC@harmonic:2", &[4e-6, 3e-6]),
    ("EXC@harmonic:1", &[0.002, 0.001]),
    ("XOC", &[0.01]),
];

fn table<'a>(tables: &'a [AxisTable], axis: &str) -> &'a AxisTable {
    tables
        .iter()
        .find(|t| t.axis == axis)
        .unwrap_or_else(|| panic!("no table of axis {axis}"))
}

/// The commands of `m` with axis `axis` at `position` (mm or degrees), the others at zero.
fn at(m: &Machine, axis: &str, position: f64) -> Vec<f64> {
    let i = m.axis_by_name(axis).unwrap();
    let mut q = vec![0.0; m.axes.len()];
    q[i] = match m.axes[i].kind {
        AxisKind::Linear => position,
        AxisKind::Rotary => position.to_radians(),
    };
    q
}

#[test]
fn the_rows_are_the_identified_errors_over_the_stroke_and_read_back_exactly() {
    let m = builtin("seed-ac");
    let errors = errors_of(&m, TERMS);
    let tables = axis_tables(
        &m,
        &errors,
        Pitch {
            linear_mm: 30.0,
            rotary_deg: 7.5,
        },
    )
    .unwrap();
    // One table per axis with component errors: X and C (XOC is a location error).
    let axes: Vec<&str> = tables.iter().map(|t| t.axis.as_str()).collect();
    assert_eq!(axes, ["X", "C"]);
    let x = table(&tables, "X");
    assert_eq!(x.error_names, ["EXX", "EYX", "EAX"]);
    assert_eq!(x.file_name(), "axis_X.csv");
    // −500, −470, …, 490, then the end of the stroke.
    let pos: Vec<f64> = x.rows.iter().map(|r| r.position).collect();
    assert_eq!(pos.len(), 35);
    assert_eq!(
        (pos[0], pos[1], pos[33], pos[34]),
        (-500.0, -470.0, 490.0, 500.0)
    );
    let c = table(&tables, "C");
    assert_eq!(c.error_names, ["EXC", "ECC"]);
    assert_eq!(c.rows.len(), 49, "0 … 360° at 7.5°");
    assert_eq!(c.rows.last().unwrap().position, 360.0);
    // Every value is `values_at` at that position.
    let mut values = vec![0.0; errors.errors().len()];
    for t in [x, c] {
        for r in &t.rows {
            errors.values_at(&m, &at(&m, &t.axis, r.position), &mut values);
            for (k, &e) in t.errors.iter().enumerate() {
                let slot = errors.errors().iter().position(|&x| x == e).unwrap();
                assert_eq!(r.errors[k], values[slot], "{} {}", t.axis, t.error_names[k]);
            }
        }
    }
    // The CSV: comments, header, one row per position; every number reads back to the bits.
    let csv = x.to_csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with(
        "# Compensation table of axis X (linear, along +x) of machine seed-ac (fingerprint "
    ));
    assert!(csv.contains("# deviation_um: actual minus commanded position in the axis's own sense (+EXX); correction_um: add it to the command to cancel the deviation (= -deviation).\n"));
    let header = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    assert_eq!(
        lines[header],
        "X_mm,EXX_um,EYX_um,EAX_urad,deviation_um,correction_um"
    );
    assert_eq!(lines.len() - header - 1, x.rows.len());
    for (line, r) in lines[header + 1..].iter().zip(&x.rows) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(parse_scaled(f[0], 0), Some(r.position));
        assert_eq!(
            parse_scaled(f[1], -3).map(f64::to_bits),
            Some(r.errors[0].to_bits())
        );
        assert_eq!(
            parse_scaled(f[3], -6).map(f64::to_bits),
            Some(r.errors[2].to_bits())
        );
        assert_eq!(parse_scaled(f[4], -3), r.deviation);
        assert_eq!(parse_scaled(f[5], -3), r.correction());
    }
    assert!(lines[header + 1].starts_with("-500,"));
    let ccsv = c.to_csv();
    assert!(ccsv.contains("\nC_deg,EXC_um,ECC_urad,deviation_urad,correction_urad\n0,"));
    assert!(ccsv.contains("\n7.5,"), "positions as people write them");
}

#[test]
fn a_negative_direction_flips_the_sign_of_the_deviation_and_the_correction() {
    let terms: &[(&str, &[f64])] = &[("EXX@poly:1", &[0.012]), ("ECC@harmonic:1", &[15e-6, 4e-6])];
    let pitch = Pitch {
        linear_mm: 100.0,
        rotary_deg: 45.0,
    };
    let plus = builtin("seed-ac");
    let minus = neg_table();
    let tp = axis_tables(&plus, &errors_of(&plus, terms), pitch).unwrap();
    let tm = axis_tables(&minus, &errors_of(&minus, terms), pitch).unwrap();
    for axis in ["X", "C"] {
        let (p, n) = (table(&tp, axis), table(&tm, axis));
        assert!(!p.direction.negative && n.direction.negative);
        let mut compared = 0;
        for (rp, rn) in p.rows.iter().zip(&n.rows) {
            assert_eq!(rp.position, rn.position);
            // The error in rtest's convention is the same; its sign in the axis's sense is not.
            assert_eq!(rp.errors[0], rn.errors[0]);
            assert_eq!(rp.deviation, Some(rp.errors[0]));
            assert_eq!(rn.deviation, Some(-rn.errors[0]));
            assert_eq!(rp.correction(), Some(-rp.errors[0]));
            assert_eq!(rn.correction(), Some(rn.errors[0]));
            compared += usize::from(rp.errors[0] != 0.0);
        }
        assert!(compared > 3, "{axis}");
    }
    assert!(table(&tm, "X").to_csv().contains("own sense (-EXX)"));
}

/// The largest difference (mm, or the entries of the rotation) between the chain of `axis` of
/// `m` commanded at `position + correction` with its errors there, and the nominal chain at
/// `position`; and the same without the correction.
fn residual(m: &Machine, errors: &MachineErrors, t: &AxisTable) -> (f64, f64) {
    let i = m.axis_by_name(&t.axis).unwrap();
    let side = m.axes[i].side;
    let params = m.default_parameters();
    let mut values = vec![0.0; errors.errors().len()];
    let chain = |q: &[f64], with_errors: bool, values: &mut Vec<f64>| {
        let mut all = vec![0.0; m.catalogue.len()];
        if with_errors {
            errors.values_at(m, q, values);
            // The errors of this axis: the others are corrected by their own tables.
            for (k, &e) in errors.errors().iter().enumerate() {
                if m.catalogue[e].axis() == Some(i) {
                    all[e] = values[k];
                }
            }
        }
        chain_transform(m, side, q, &params, &all).to_homogeneous()
    };
    let (mut corrected, mut uncorrected) = (0.0f64, 0.0f64);
    for r in &t.rows {
        let q = at(m, &t.axis, r.position);
        let nominal = chain(&q, false, &mut values);
        let mut commanded = q.clone();
        commanded[i] += r.correction().unwrap();
        let c = chain(&commanded, true, &mut values);
        let u = chain(&q, true, &mut values);
        corrected = corrected.max((c - nominal).abs().max());
        uncorrected = uncorrected.max((u - nominal).abs().max());
    }
    (corrected, uncorrected)
}

#[test]
fn commanding_the_position_plus_the_correction_cancels_the_positioning_error_on_the_exact_machine()
{
    // Positioning errors only: the tables correct them, nothing else moves the chains.
    let terms: &[(&str, &[f64])] = &[
        ("EXX", &[0.004]),
        ("EXX@poly:1", &[0.012]),
        ("EXX@period:25", &[0.0015, -0.001]),
        ("EAA@harmonic:1", &[12e-6, -5e-6]),
        ("ECC@harmonic:1", &[15e-6, -9e-6]),
        ("ECC@harmonic:2", &[4e-6, 3e-6]),
    ];
    let pitch = Pitch {
        linear_mm: 12.5,
        rotary_deg: 5.0,
    };
    for m in [builtin("seed-ac"), neg_table()] {
        let errors = errors_of(&m, terms);
        let tables = axis_tables(&m, &errors, pitch).unwrap();
        assert_eq!(tables.len(), 3);
        for t in &tables {
            let (corrected, uncorrected) = residual(&m, &errors, t);
            println!(
                "{} {} ({}): largest chain difference {corrected:.2e} corrected, {uncorrected:.2e} uncorrected",
                m.name, t.axis, t.direction
            );
            assert!(uncorrected > 1e-5, "{} {}: {uncorrected}", m.name, t.axis);
            // What remains is second order: the table is read at the commanded position
            // `p + c`, not at `p`, so it is off by `c·E'`; the steepest slope here is that of
            // `EXX@period:25` with 1.8 µm amplitude, E' ≤ 4.8e-4, so `c·E' ≤ 4.8e-4·|c|`.
            assert!(
                corrected < 1e-3 * uncorrected,
                "{} {}: corrected {corrected:e}, uncorrected {uncorrected:e}",
                m.name,
                t.axis
            );
        }
    }
}

#[test]
fn a_pitch_that_is_not_positive_or_gives_too_many_rows_is_refused() {
    let m = builtin("seed-ac");
    let errors = errors_of(&m, TERMS);
    let ok = Pitch {
        linear_mm: 10.0,
        rotary_deg: 1.0,
    };
    for (pitch, expected) in [
        (
            Pitch {
                linear_mm: 0.0,
                ..ok
            },
            "axis X: the pitch 0 mm is not a positive number",
        ),
        (
            Pitch {
                linear_mm: -2.0,
                ..ok
            },
            "axis X: the pitch -2 mm is not a positive number",
        ),
        (
            Pitch {
                rotary_deg: f64::NAN,
                ..ok
            },
            "axis C: the pitch NaN degrees is not a positive number",
        ),
        (
            Pitch {
                linear_mm: 0.001,
                ..ok
            },
            "axis X: the pitch 0.001 mm over -500 .. 500 mm gives 1000001 points, more than 100000: choose a larger pitch",
        ),
    ] {
        let e = axis_tables(&m, &errors, pitch).unwrap_err().to_string();
        assert_eq!(e, expected);
    }
    // At the limit: 100 000 rows are allowed.
    let pitch = Pitch {
        linear_mm: 1000.0 / (MAX_TABLE_POINTS - 1) as f64,
        ..ok
    };
    let t = axis_tables(&m, &errors, pitch).unwrap();
    assert_eq!(table(&t, "X").rows.len(), MAX_TABLE_POINTS);
    assert_eq!(table(&t, "X").rows.last().unwrap().position, 500.0);
}
