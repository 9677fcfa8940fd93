//! Inclined axes (docs/conventions.md §2): the symbolic gains are right, they follow the
//! rotated-axis formula of the documentation, they are those of the old description by two held
//! rotary axes, and the sign rule holds on the exact machine.
//!
//! - Test machines with inclined axes that are not built in (`tests/machines/tilted-table.toml`:
//!   a C table inclined to `[1, 1, 4]` on an A table and an inclined linear Z ram;
//!   `tests/machines/numeric-head.toml`: a head whose direction is numeric, not exact): every
//!   error's symbolic gains equal central finite differences of the exact chain at random
//!   on-ball poses and offsets, position and orientation rows (the built-in `nutating-head-bc`
//!   and `nutating-table-bc` are checked by `tests/all/gains_property.rs` with every built-in).
//! - The location errors of the nutating head and of the nutating table against the formula.
//! - `tests/machines/nutating-head-two-dummies.toml` (the nutating head as a B axis about z
//!   between rotary axes about x held at −45° and +45°) has, with the dummies held, the gains of
//!   `nutating-head-bc` for every error the two descriptions share.
//! - A B axis about `[0, −1, −1]` at `−θ` reads exactly as one about `[0, 1, 1]` at `θ`, with its
//!   errors along and about `y'` and `z'` of the opposite sign.

use codegen::GainModel;
use model_spec::{Machine, Side, builtin, parse_machine};
use simulation::exact::{chain_transform, error_vector, tool_centre_point_ik};
use simulation::fd::fd_gains;

use crate::common;
use common::gains::{close, pose};

fn fixture(file: &str, text: &str) -> Machine {
    parse_machine(file, text).unwrap_or_else(|e| panic!("{e}"))
}

fn tilted_table() -> Machine {
    fixture(
        "tests/machines/tilted-table.toml",
        include_str!("../machines/tilted-table.toml"),
    )
}

fn numeric_head() -> Machine {
    fixture(
        "tests/machines/numeric-head.toml",
        include_str!("../machines/numeric-head.toml"),
    )
}

fn two_dummies() -> Machine {
    fixture(
        "tests/machines/nutating-head-two-dummies.toml",
        include_str!("../machines/nutating-head-two-dummies.toml"),
    )
}

fn nutating(name: &str) -> Machine {
    builtin(name).unwrap().unwrap()
}

/// Numbers in [0, 1) from a fixed seed (xorshift64*), `n` at a time.
struct Units(u64);

impl Units {
    fn take(&mut self, n: usize) -> Vec<f64> {
        (0..n)
            .map(|_| {
                self.0 ^= self.0 >> 12;
                self.0 ^= self.0 << 25;
                self.0 ^= self.0 >> 27;
                (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
            })
            .collect()
    }
}

fn all_errors(m: &Machine) -> GainModel {
    GainModel::derive(m, &(0..m.catalogue.len()).collect::<Vec<_>>())
}

#[test]
fn the_test_machines_have_the_inclined_axes_they_are_written_for() {
    let t = tilted_table();
    let c = &t.axes[t.axis_by_name("C").unwrap()];
    let frame = c.direction.inclined.unwrap().frame;
    assert!(frame.axes.iter().flatten().all(|r| r.is_exact()));
    assert_eq!(frame.axes[2][0].to_string(), "√2/6");
    let z = &t.axes[t.axis_by_name("Z").unwrap()];
    assert!(z.direction.inclined.is_some());
    // The inclined linear axis is third in the squareness order: its squareness errors are
    // about its own x' and y'.
    assert!(t.error_by_name("AOZ").is_some() && t.error_by_name("BOZ").is_some());
    let n = numeric_head();
    let b = &n.axes[n.axis_by_name("B").unwrap()];
    assert!(
        b.direction
            .inclined
            .unwrap()
            .frame
            .axes
            .iter()
            .flatten()
            .all(|r| !r.is_exact())
    );
}

#[test]
fn symbolic_gains_of_inclined_axes_equal_finite_differences_of_the_exact_chain() {
    let mut units = Units(0x5eed_1234_abcd_0001);
    for m in [tilted_table(), numeric_head()] {
        let model = all_errors(&m);
        for _ in 0..24 {
            let (commands, params) = pose(&m, &units.take(32));
            let symbolic = model.evaluate(&commands, &params);
            let numeric = fd_gains(&m, &commands, &params, &model.errors);
            for (i, (s, n)) in symbolic.iter().zip(&numeric).enumerate() {
                for k in 0..6 {
                    assert!(
                        close(s[k], n[k], 1e-8),
                        "{} {} row {k}: symbolic {} vs finite difference {} at {commands:?}",
                        m.name,
                        model.error_names[i],
                        s[k],
                        n[k]
                    );
                }
            }
        }
    }
}

/// The gains of the named errors of `m` at `commands`, `params`.
fn gains_of(m: &Machine, names: &[&str], commands: &[f64], params: &[f64]) -> Vec<[f64; 6]> {
    let ids: Vec<usize> = names
        .iter()
        .map(|n| {
            m.error_by_name(n)
                .unwrap_or_else(|| panic!("{} has no {n}", m.name))
        })
        .collect();
    GainModel::derive(m, &ids).evaluate(commands, params)
}

fn assert_row(what: &str, got: &[f64; 6], want: [f64; 6]) {
    for k in 0..6 {
        assert!(
            close(got[k], want[k], 1e-12),
            "{what} row {k}: {} against the formula's {}",
            got[k],
            want[k]
        );
    }
}

#[test]
fn the_nutating_head_location_gains_follow_the_rotated_axis_formula() {
    // docs/conventions.md §2, the table worked for nutating-head-bc: with h = 1/√2,
    //   XOB (cos B, −h·sin B, h·sin B)        orientation 0
    //   YOB (sin B, h·cos B, −h·cos B)        orientation 0
    //   AOB Zt·(−h·sin B, −cos B, 0)           orientation (−h·sin B, −cos B, 0)
    //   BOB Zt·(h·cos B, −sin B, 0)            orientation (h·cos B, −sin B, 0)
    let m = nutating("nutating-head-bc");
    let names = ["XOB", "YOB", "AOB", "BOB"];
    let (b_axis, zt) = (
        m.axis_by_name("B").unwrap(),
        m.symbol_by_name("Zt").unwrap(),
    );
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let mut units = Units(0x0b0b_5eed_0000_0002);
    for _ in 0..32 {
        let (commands, params) = pose(&m, &units.take(32));
        let (s, c) = commands[b_axis].sin_cos();
        let l = params[zt];
        let g = gains_of(&m, &names, &commands, &params);
        assert_row("XOB", &g[0], [c, -h * s, h * s, 0.0, 0.0, 0.0]);
        assert_row("YOB", &g[1], [s, h * c, -h * c, 0.0, 0.0, 0.0]);
        assert_row("AOB", &g[2], [-l * h * s, -l * c, 0.0, -h * s, -c, 0.0]);
        assert_row("BOB", &g[3], [l * h * c, -l * s, 0.0, h * c, -s, 0.0]);
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[test]
fn the_nutating_table_location_gains_follow_the_rotated_axis_formula() {
    // The B swivel body is first on the work chain and the tool frame is the bed's: XOB and
    // YOB are −x' and −y' at every pose, AOB and BOB −u × (P − p) with P the ball and p the
    // B frame's origin (Xb, Yb, Zb), orientation −u × z with z the C table's axis.
    let m = nutating("nutating-table-bc");
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let (x1, y1) = ([1.0, 0.0, 0.0], [0.0, h, h]);
    let names = ["XOB", "YOB", "AOB", "BOB"];
    let origin: Vec<usize> = ["Xb", "Yb", "Zb"]
        .iter()
        .map(|s| m.symbol_by_name(s).unwrap())
        .collect();
    let mut units = Units(0x7ab1_e5ee_d000_0003);
    for _ in 0..32 {
        let (commands, params) = pose(&m, &units.take(32));
        let zeros = vec![0.0; m.catalogue.len()];
        let work = chain_transform(&m, Side::Work, &commands, &params, &zeros);
        let ball = work.translation.vector;
        let arm: [f64; 3] = std::array::from_fn(|k| ball[k] - params[origin[k]]);
        let z: [f64; 3] = std::array::from_fn(|k| work.rotation.matrix()[(k, 2)]);
        let neg = |v: [f64; 3]| v.map(|x| -x);
        let g = gains_of(&m, &names, &commands, &params);
        let row = |p: [f64; 3], o: [f64; 3]| [p[0], p[1], p[2], o[0], o[1], o[2]];
        assert_row("XOB", &g[0], row(neg(x1), [0.0; 3]));
        assert_row("YOB", &g[1], row(neg(y1), [0.0; 3]));
        assert_row("AOB", &g[2], row(neg(cross(x1, arm)), neg(cross(x1, z))));
        assert_row("BOB", &g[3], row(neg(cross(y1, arm)), neg(cross(y1, z))));
    }
}

/// How the errors of the head's B axis are named in the two descriptions. In the description
/// with two held axes, B turns about the z axis of the frame that U (about x, at −45°) turned
/// onto the head's axis; the x and y axes of that frame are x' and y' of the inclined
/// description. So the errors of B keep their names: the radial errors `EXB EYB` (along x',
/// y'), the axial `EZB`, the tilts `EAB EBB`, the positioning `ECB` (about z'), the location
/// errors `XOB YOB AOB BOB`. Every other error (of X, Y, Z, C, the squareness and the ball's
/// set-up) is the same error in both; the errors of the held axes U and V have no counterpart.
const CORRESPONDENCE: [(&str, &str); 10] = [
    ("EXB", "EXB"),
    ("EYB", "EYB"),
    ("EZB", "EZB"),
    ("EAB", "EAB"),
    ("EBB", "EBB"),
    ("ECB", "ECB"),
    ("XOB", "XOB"),
    ("YOB", "YOB"),
    ("AOB", "AOB"),
    ("BOB", "BOB"),
];

#[test]
fn the_two_dummy_axis_description_has_the_gains_of_the_inclined_description() {
    let inclined = nutating("nutating-head-bc");
    let dummies = two_dummies();
    assert_eq!(
        inclined.symbols.iter().map(|s| &s.name).collect::<Vec<_>>(),
        dummies.symbols.iter().map(|s| &s.name).collect::<Vec<_>>()
    );
    // Every error of the inclined description, with its name in the other.
    let pairs: Vec<(usize, usize)> = inclined
        .catalogue
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let other = CORRESPONDENCE
                .iter()
                .find(|(a, _)| *a == e.name)
                .map_or(e.name.as_str(), |(_, b)| b);
            (
                i,
                dummies
                    .error_by_name(other)
                    .unwrap_or_else(|| panic!("{} has no counterpart {other}", e.name)),
            )
        })
        .collect();
    assert_eq!(pairs.len(), 44);
    let model_i = GainModel::derive(&inclined, &pairs.iter().map(|p| p.0).collect::<Vec<_>>());
    let model_d = GainModel::derive(&dummies, &pairs.iter().map(|p| p.1).collect::<Vec<_>>());
    let axis = |m: &Machine, n: &str| m.axis_by_name(n).unwrap();
    let mut units = Units(0xd0d0_5eed_0000_0004);
    for _ in 0..32 {
        let (q, params) = pose(&inclined, &units.take(32));
        let mut d = vec![0.0; dummies.axes.len()];
        for name in ["C", "B"] {
            d[axis(&dummies, name)] = q[axis(&inclined, name)];
        }
        d[axis(&dummies, "U")] = (-45.0f64).to_radians();
        d[axis(&dummies, "V")] = 45.0f64.to_radians();
        tool_centre_point_ik(&dummies, &mut d, &params).unwrap();
        for name in ["X", "Y", "Z"] {
            let (a, b) = (q[axis(&inclined, name)], d[axis(&dummies, name)]);
            assert!(close(a, b, 1e-12), "{name}: {a} against {b}");
        }
        let (gi, gd) = (model_i.evaluate(&q, &params), model_d.evaluate(&d, &params));
        for (k, (a, b)) in gi.iter().zip(&gd).enumerate() {
            for r in 0..6 {
                assert!(
                    close(a[r], b[r], 1e-12),
                    "{} row {r}: inclined {} against two dummies {} at B = {}°",
                    model_i.error_names[k],
                    a[r],
                    b[r],
                    q[axis(&inclined, "B")].to_degrees()
                );
            }
        }
    }
}

#[test]
fn an_axis_turned_the_other_way_reads_the_same_at_the_opposite_command() {
    // [0, −1, −1] against [0, 1, 1]: z' and y' turn over, x' stays. At −θ with the errors along
    // and about y' and z' negated, the exact machine reads exactly the same.
    let base = nutating("nutating-head-bc");
    let text = model_spec::BUILTIN
        .iter()
        .find(|(n, _)| *n == "nutating-head-bc")
        .unwrap()
        .1
        .replace("direction = [0, 1, 1]", "direction = [0, -1, -1]")
        .replace("range = [0.0, 180.0]", "range = [-180.0, 0.0]");
    let flipped = fixture("m.toml", &text);
    let values = [
        ("EXB", 0.004, 1.0),
        ("EYB", -0.003, -1.0),
        ("EZB", 0.002, -1.0),
        ("EAB", 2e-5, 1.0),
        ("EBB", -3e-5, -1.0),
        ("ECB", 4e-5, -1.0),
        ("XOB", 0.005, 1.0),
        ("YOB", -0.006, -1.0),
        ("AOB", 5e-5, 1.0),
        ("BOB", -6e-5, -1.0),
    ];
    let errors = |m: &Machine, sign: bool| {
        let mut e = vec![0.0; m.catalogue.len()];
        for (name, v, s) in values {
            e[m.error_by_name(name).unwrap()] = if sign { v * s } else { v };
        }
        e
    };
    let b = base.axis_by_name("B").unwrap();
    let params = base.default_parameters();
    for deg in [0.0, 17.0, 90.0, 133.0, 180.0] {
        let mut q = vec![0.0; base.axes.len()];
        q[base.axis_by_name("C").unwrap()] = 25f64.to_radians();
        q[b] = f64::to_radians(deg);
        tool_centre_point_ik(&base, &mut q, &params).unwrap();
        let mut p = q.clone();
        p[b] = -q[b];
        let a = error_vector(&base, &q, &params, &errors(&base, false)).to_array();
        let f = error_vector(&flipped, &p, &params, &errors(&flipped, true)).to_array();
        for k in 0..6 {
            assert!(
                (a[k] - f[k]).abs() < 1e-12,
                "B = {deg}°, row {k}: {} against {}",
                a[k],
                f[k]
            );
        }
        // Not trivially: the errors move the reading by micrometres.
        assert!(a[..3].iter().any(|x| x.abs() > 1e-3), "{a:?}");
    }
}
