//! The three-axis volumetric compensation against the exact virtual machine: laser
//! measurements taken on `seed-3axis` with non-zero kinematic parameters and hidden
//! position-dependent error maps, the kinematic-parameter independent model built from them,
//! its prediction against the exact tool-end error (to within its second-order truncation and
//! the linear interpolation of its tables), the compensation on a 10 × 10 × 10 grid, and every
//! kind of bad input of the files it reads.
//!
//! `cargo test -p compensation --test all volumetric:: -- --nocapture` prints the figures quoted in
//! docs/volumetric.md.

use compensation::volumetric::simulate::{LaserPlan, SimulatedLaser, measure};
use compensation::volumetric::{
    AxisMeasurement, GridSpec, VolumetricError, VolumetricModel, correct, correct_within_strokes,
    format_grid, format_laser, format_squareness, parse_laser, parse_squareness,
};
use model_spec::Machine;
use nalgebra::Vector3;
use simulation::Truth;
use simulation::exact::VirtualMachine;

/// The hidden machine: kinematic offsets of X, Z, the holder and the tool; positioning errors
/// of 10–20 µm over the stroke, straightness of about 5 µm (with slopes, as a machine's bed
/// frame gives them), angular errors of 20–50 µrad, squareness of 15–20 µrad.
const TRUTH: &str = r#"
machine = "seed-3axis"
description = "hidden error maps of the volumetric tests"

[parameters]
Xx = 50.0
Yx = -20.0
Zx = 150.0
Xz = 80.0
Yz = 30.0
Zz = 200.0
Zh = 120.0
Zt = 100.0

[errors]
EXX = { "poly:1" = 9.0, "poly:2" = 5.0, "period:200" = [1.5, 1.0] }
EYX = { "poly:1" = 2.0, "poly:2" = 4.0 }
EZX = { "poly:2" = -3.0, "poly:3" = 2.0 }
EAX = { "poly:1" = 20.0, "poly:2" = 15.0 }
EBX = { "poly:1" = -30.0, "poly:2" = 10.0 }
ECX = { "poly:2" = 25.0 }
EXY = { "poly:1" = 3.0, "poly:2" = -4.0 }
EYY = { "poly:1" = -12.0, "poly:3" = 4.0 }
EZY = { "poly:2" = 5.0 }
EAY = { "poly:1" = 25.0, "poly:3" = 10.0 }
EBY = { "poly:1" = 15.0, "poly:2" = -35.0 }
ECY = { "poly:1" = 30.0, "poly:2" = 20.0 }
EXZ = { "poly:2" = 4.0 }
EYZ = { "poly:1" = -2.0, "poly:3" = 3.0 }
EZZ = { "poly:1" = 8.0, "poly:2" = -7.0 }
EAZ = { "poly:1" = -20.0 }
EBZ = { "poly:2" = 25.0 }
ECZ = { "poly:1" = 15.0 }
COX = 20.0
AOZ = -15.0
BOZ = 20.0
"#;

fn machine() -> Machine {
    model_spec::builtin("seed-3axis").unwrap().unwrap()
}

fn truth(m: &Machine) -> Truth {
    formats::truth::parse_truth("volumetric-truth.toml", TRUTH, m).unwrap()
}

/// 41 positions per axis over the whole stroke (X every 20 mm, Y and Z every 15 mm), the other
/// axes at 0.
fn simulated(m: &Machine, t: &Truth) -> SimulatedLaser {
    measure(m, t, &LaserPlan::over_strokes(m, 41).unwrap()).unwrap()
}

fn model_of(m: &Machine, s: &SimulatedLaser) -> VolumetricModel {
    VolumetricModel::new(m, &s.measurements, &s.squareness).unwrap()
}

/// A small deterministic generator (xorshift), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The second-order truncation bound of the model. The first-order model leaves out products
/// of two errors: a rotation turning another rotation's lever arm, or turning a translation.
/// With ε the largest total rotation of the tool (the largest measured rotation of each axis
/// and the squareness, added as vectors' norms), τ the largest total translation likewise,
/// and L the largest lever (the tool point's distance from the Y carriage's origin over the
/// strokes, with the hidden kinematic offsets), these products are at most ε²·L + ε·τ.
fn truncation_bound(m: &Machine, s: &SimulatedLaser, t: &Truth) -> f64 {
    let norm = |r: &[f64; 3]| Vector3::new(r[0], r[1], r[2]).norm();
    let largest = |rows: &[[f64; 3]]| rows.iter().map(norm).fold(0.0f64, f64::max);
    let sq: Vec<f64> = s.squareness.values.iter().map(|(_, v)| *v).collect();
    let eps: f64 = s
        .measurements
        .iter()
        .map(|x| largest(&x.rotations))
        .sum::<f64>()
        + Vector3::new(sq[0], sq[1], sq[2]).norm();
    let tau: f64 = s
        .measurements
        .iter()
        .map(|x| largest(&x.translations))
        .sum();
    let p = |n: &str| t.params[m.symbol_by_name(n).unwrap()].abs();
    let lever = (400.0 + p("Xx") + p("Xz"))
        .hypot(300.0 + p("Yx") + p("Yz"))
        .hypot(300.0 + p("Zx") + p("Zz") + p("Zh") + p("Zt"));
    eps * eps * lever + eps * tau
}

/// The largest error of linear interpolation between the measured positions: a second
/// difference over 8 per table (h²·f''/8), rotations times the largest lever of the model
/// (the strokes, 800 mm), summed over the tables.
fn interpolation_bound(s: &SimulatedLaser) -> f64 {
    let mut b = 0.0;
    for x in &s.measurements {
        for (rows, scale) in [(&x.translations, 1.0), (&x.rotations, 800.0)] {
            for d in 0..3 {
                let v: Vec<f64> = rows.iter().map(|r| r[d]).collect();
                let dd = v
                    .windows(3)
                    .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
                    .fold(0.0f64, f64::max);
                b += scale * dd / 8.0;
            }
        }
    }
    b
}

#[test]
fn the_model_predicts_the_exact_tool_end_error() {
    let m = machine();
    let t = truth(&m);
    let s = simulated(&m, &t);
    let model = model_of(&m, &s);
    let vm = VirtualMachine::new(&m);
    let bound2 = truncation_bound(&m, &s, &t);
    let interp = interpolation_bound(&s);
    let mut rng = Rng(0x5eed_3a15);
    // Poses at measured positions (no interpolation), and anywhere in the volume.
    let (mut at_nodes, mut anywhere, mut largest) = (0.0f64, 0.0f64, 0.0f64);
    let node = |x: &AxisMeasurement, r: f64| x.positions[(r * x.positions.len() as f64) as usize];
    for _ in 0..300 {
        let mut pose = vec![0.0; 3];
        for x in &s.measurements {
            pose[x.axis] = node(x, rng.unit());
        }
        let exact = s.frame.error(&vm, &t, &pose);
        let du = model.du(&pose).unwrap();
        at_nodes = at_nodes.max((du - exact).amax());
        largest = largest.max(exact.amax());
        let mut pose = vec![0.0; 3];
        for (a, axis) in m.axes.iter().enumerate() {
            let [lo, hi] = axis.limits;
            pose[a] = lo + (hi - lo) * rng.unit();
        }
        let exact = s.frame.error(&vm, &t, &pose);
        anywhere = anywhere.max((model.du(&pose).unwrap() - exact).amax());
    }
    println!(
        "largest exact tool-end error {:.3} µm; model minus exact: at measured positions {:.2e} µm (second-order bound {:.2e} µm), anywhere {:.4} µm (bound with interpolation {:.4} µm)",
        largest * 1e3,
        at_nodes * 1e3,
        bound2 * 1e3,
        anywhere * 1e3,
        (bound2 + interp) * 1e3
    );
    assert!(largest > 0.02, "the hidden errors are of realistic size");
    assert!(at_nodes <= bound2, "{at_nodes} > {bound2}");
    assert!(at_nodes < 1e-3 * largest);
    assert!(
        anywhere <= bound2 + interp,
        "{anywhere} > {}",
        bound2 + interp
    );
}

#[test]
fn the_model_does_not_depend_on_the_kinematic_parameters_or_on_ecx_eaz_ebz_ecz() {
    let m = machine();
    let t = truth(&m);
    let s = simulated(&m, &t);
    let model = model_of(&m, &s);
    // ECX and the rotations of Z removed from the measurements: the same model, to the bit.
    let mut cut = s.clone();
    let z = m.axis_by_name("Z").unwrap();
    let x = m.axis_by_name("X").unwrap();
    for meas in &mut cut.measurements {
        for r in &mut meas.rotations {
            if meas.axis == z {
                *r = [0.0; 3];
            } else if meas.axis == x {
                r[2] = 0.0;
            }
        }
    }
    let without = model_of(&m, &cut);
    let mut rng = Rng(7);
    for _ in 0..100 {
        let pose: Vec<f64> = m
            .axes
            .iter()
            .map(|a| a.limits[0] + (a.limits[1] - a.limits[0]) * rng.unit())
            .collect();
        assert_eq!(model.du(&pose).unwrap(), without.du(&pose).unwrap());
    }
    // Other kinematic parameters change the measurements and the machine alike: the model,
    // which never sees them, still predicts the exact error.
    let mut t2 = t.clone();
    for (i, v) in t2.params.iter_mut().enumerate() {
        *v += 37.0 * (i as f64 + 1.0);
    }
    let s2 = simulated(&m, &t2);
    let model2 = model_of(&m, &s2);
    let vm = VirtualMachine::new(&m);
    let bound = truncation_bound(&m, &s2, &t2);
    for x in &s2.measurements[..1] {
        for &q in &x.positions {
            let mut pose = vec![0.0; 3];
            pose[x.axis] = q;
            pose[m.axis_by_name("Z").unwrap()] = 300.0;
            let e = (model2.du(&pose).unwrap() - s2.frame.error(&vm, &t2, &pose)).amax();
            assert!(e <= bound, "{e} > {bound}");
        }
    }
}

#[test]
fn compensation_removes_most_of_the_volumetric_error() {
    let m = machine();
    let t = truth(&m);
    let s = simulated(&m, &t);
    let model = model_of(&m, &s);
    let vm = VirtualMachine::new(&m);
    let lin =
        |a: &model_spec::Axis, i: usize| a.limits[0] + (a.limits[1] - a.limits[0]) * i as f64 / 9.0;
    let (mut before, mut after) = (Vec::new(), Vec::new());
    let mut iterations = 0;
    let mut first_order = 0.0f64;
    for i in 0..10 {
        for j in 0..10 {
            for k in 0..10 {
                let u = vec![lin(&m.axes[0], i), lin(&m.axes[1], j), lin(&m.axes[2], k)];
                before.push(s.frame.error(&vm, &t, &u).norm());
                let c = correct(&model, &u).unwrap();
                iterations = iterations.max(c.iterations);
                // The first-order correction −du(u) read at the commanded point.
                let du_u = model.du(&u).unwrap();
                for (a, ua) in u.iter().enumerate() {
                    let first = ua - model.direction(a).unwrap().dot(&du_u);
                    first_order = first_order.max((c.commands[a] - first).abs());
                }
                // Where the tool point really goes (model frame) minus where it should go.
                let moved: Vector3<f64> = (0..3)
                    .map(|a| model.direction(a).unwrap() * (c.commands[a] - u[a]))
                    .sum();
                after.push((moved + s.frame.error(&vm, &t, &c.commands)).norm());
            }
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let max = |v: &[f64]| v.iter().fold(0.0f64, |a, &b| a.max(b));
    let (rb, ra, mb, ma) = (rms(&before), rms(&after), max(&before), max(&after));
    println!(
        "10x10x10 grid over the strokes: volumetric error RMS {:.3} -> {:.4} µm ({:.2} % less), max {:.3} -> {:.4} µm ({:.2} % less); at most {iterations} iterations",
        rb * 1e3,
        ra * 1e3,
        100.0 * (1.0 - ra / rb),
        mb * 1e3,
        ma * 1e3,
        100.0 * (1.0 - ma / mb)
    );
    let sq: Vec<String> = s
        .squareness
        .values
        .iter()
        .map(|(e, v)| format!("{} {:.3}", m.catalogue[*e].name, v * 1e6))
        .collect();
    println!(
        "iterated minus first-order correction: at most {:.2e} µm; squareness at the tool end {} µrad (chain: COX 20, AOZ -15, BOZ 20)",
        first_order * 1e3,
        sq.join(", ")
    );
    assert!(ra <= 0.1 * rb && ma <= 0.1 * mb);
    assert!(iterations <= 4, "{iterations} iterations");
}

#[test]
fn corrected_commands_solve_the_fixed_point() {
    let m = machine();
    let t = truth(&m);
    let model = model_of(&m, &simulated(&m, &t));
    let u = [120.0, -250.0, 40.0];
    let c = correct(&model, &u).unwrap();
    let du = model.du(&c.commands).unwrap();
    for (a, ua) in u.iter().enumerate() {
        let n = model.direction(a).unwrap();
        let residual = c.commands[a] - (ua - n.dot(&du));
        assert!(residual.abs() < 1e-9, "axis {a}: {residual}");
    }
    assert_eq!(c.du, du);
    // At the end of a stroke the corrected command can leave it: refused, naming the axis.
    let (edge, a) = outward_corner(&m, &model);
    let e = correct_within_strokes(&model, &m, &edge).unwrap_err();
    assert!(
        matches!(&e, VolumetricError::OffStroke { axis, .. } if *axis == m.axes[a].name),
        "{e}"
    );
    assert!(e.to_string().contains("outside the stroke"), "{e}");
}

/// A corner of the strokes where a corrected command leaves its stroke, and that axis.
fn outward_corner(m: &Machine, model: &VolumetricModel) -> (Vec<f64>, usize) {
    for corner in 0..8 {
        let pose: Vec<f64> = (0..3)
            .map(|a| m.axes[a].limits[(corner >> a) & 1])
            .collect();
        let c = correct(model, &pose).unwrap();
        if let Some(a) = (0..3).find(|&a| {
            let [lo, hi] = m.axes[a].limits;
            c.commands[a] < lo || c.commands[a] > hi
        }) {
            return (pose, a);
        }
    }
    panic!("no corner of the strokes has a correction pointing outwards");
}

#[test]
fn a_position_outside_the_measured_range_is_an_error() {
    let m = machine();
    let t = truth(&m);
    let mut s = simulated(&m, &t);
    // Measure X only from -200 to 200 mm.
    let x = m.axis_by_name("X").unwrap();
    let meas = s.measurements.iter_mut().find(|v| v.axis == x).unwrap();
    let keep: Vec<usize> = (0..meas.positions.len())
        .filter(|&i| meas.positions[i].abs() <= 200.0)
        .collect();
    meas.positions = keep.iter().map(|&i| meas.positions[i]).collect();
    meas.translations = keep.iter().map(|&i| meas.translations[i]).collect();
    meas.rotations = keep.iter().map(|&i| meas.rotations[i]).collect();
    let model = model_of(&m, &s);
    let mut pose = vec![0.0; 3];
    pose[x] = 250.0;
    let e = model.du(&pose).unwrap_err();
    assert_eq!(
        e.to_string(),
        "X = 250 mm is outside the range its laser measurement covers, -200 .. 200 mm"
    );
    assert!(correct(&model, &pose).is_err());
    // The reference point must be measured too.
    s.squareness.reference[x] = -300.0;
    let e = VolumetricModel::new(&m, &s.measurements, &s.squareness).unwrap_err();
    assert!(
        e.to_string()
            .contains("the reference point: X = -300 mm is outside"),
        "{e}"
    );
}

#[test]
fn the_model_refuses_what_it_cannot_describe() {
    let m = machine();
    let t = truth(&m);
    let s = simulated(&m, &t);
    let e = VolumetricModel::new(&m, &s.measurements[..2], &s.squareness).unwrap_err();
    assert!(e.to_string().contains("has no laser measurement"), "{e}");
    let mut twice = s.measurements.clone();
    twice[2] = twice[1].clone();
    let e = VolumetricModel::new(&m, &twice, &s.squareness).unwrap_err();
    assert!(e.to_string().contains("measured twice"), "{e}");
    // The Z axis measured with X beyond X's measured range.
    let mut off = s.measurements.clone();
    let (x, z) = (m.axis_by_name("X").unwrap(), m.axis_by_name("Z").unwrap());
    let zm = off.iter_mut().find(|v| v.axis == z).unwrap();
    zm.pose[x] = 401.0;
    let e = VolumetricModel::new(&m, &off, &s.squareness).unwrap_err();
    assert!(
        e.to_string()
            .contains("axis X stood at 401 mm while axis Z was measured"),
        "{e}"
    );
    let ac = model_spec::builtin("seed-ac").unwrap().unwrap();
    let sq = compensation::volumetric::Squareness::new(&ac, "sq.toml", &[0.0; 3]);
    let e = VolumetricModel::new(&ac, &[], &sq).unwrap_err();
    assert!(
        e.to_string().contains(
            "the volumetric model covers machines whose three linear axes all carry the tool"
        ),
        "{e}"
    );
}

#[test]
fn laser_and_squareness_files_read_back_to_the_bit() {
    let m = machine();
    let t = truth(&m);
    let s = simulated(&m, &t);
    for x in &s.measurements {
        let text = format_laser(&m, x, &["simulated".into()]);
        let back = parse_laser("x.csv", &text, &m, x.axis).unwrap();
        assert_eq!(back.positions, x.positions);
        assert_eq!(back.translations, x.translations);
        assert_eq!(back.rotations, x.rotations);
        assert_eq!(back.pose, x.pose);
    }
    let text = format_squareness(&m, &s.squareness, &["simulated".into()]);
    let back = parse_squareness("sq.toml", &text, &m).unwrap();
    assert_eq!(back.values, s.squareness.values);
    assert_eq!(back.reference, s.squareness.reference);
}

/// A laser file of axis X with `body` after the header.
fn laser_x(m: &Machine, header: &str, body: &str) -> Result<AxisMeasurement, VolumetricError> {
    let x = m.axis_by_name("X").unwrap();
    parse_laser("x.csv", &format!("# X\n{header}\n{body}"), m, x)
}

const HEADER: &str = "X_mm,Y_mm,Z_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad";

#[test]
fn laser_reading_errors_name_the_file_line_and_column() {
    let m = machine();
    let ok = "-400,0,0,0,0,0,0,0,0\n0,0,0,1.5,0.5,-0.2,3,4,5\n";
    let read = laser_x(&m, HEADER, ok).unwrap();
    assert_eq!(read.positions, [-400.0, 0.0]);
    assert_eq!(read.translations[1], [0.0015, 0.0005, -0.0002]);
    assert_eq!(read.rotations[1], [3e-6, 4e-6, 5e-6]);
    // Any order, any case, CRLF, comments and blank lines.
    let shuffled = "ecx_urad , x_mm,Y_MM,\"Z_mm\",EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad\r\n\r\n# c\r\n5,-400,0,0,0,0,0,0,0\r\n6,0,0,0,1.5,0.5,-0.2,3,4\r\n";
    let r = laser_x(&m, "", shuffled).unwrap();
    assert_eq!(r.rotations[1][2], 6e-6);
    let cases: &[(&str, &str, &str)] = &[
        (
            HEADER,
            "",
            "x.csv:3: 0 rows: the laser measurement of axis X needs at least two positions",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n",
            "x.csv:4: 1 row: the laser measurement",
        ),
        (
            "X_mm,Y_mm,Z_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad,T",
            ok,
            "x.csv:2: column 10 `T`: unknown column for the laser measurement of axis X",
        ),
        (
            "X_mm,Y_mm,Z_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad",
            ok,
            "x.csv:2: the laser measurement of axis X misses the column ECX_urad",
        ),
        (
            "X_mm,x_mm,Z_mm,EXX_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad",
            ok,
            "x.csv:2: column 2 `x_mm`: column given twice",
        ),
        (
            "X_mm,Y_mm,Z_mm,EXY_um,EYX_um,EZX_um,EAX_urad,EBX_urad,ECX_urad",
            ok,
            "column 4 `EXY_um`: unknown column",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n-400,0,0,0,0,0,0,0,0\n",
            "x.csv:4: column 1 `X_mm`: X = -400 mm is not above the position of line 3 (-400 mm): the positions of the measured axis must increase strictly",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,1,0,0,0,0,0,0,0\n",
            "x.csv:4: column 2 `Y_mm`: Y = 1 mm, but 0 mm on line 3: axis Y must stand still while axis X is measured",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,0,nan,0,0,0,0,0\n",
            "x.csv:4: column 4 `EXX_um`: `nan` is not a finite number (µm)",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,0,0,,0,0,0,0\n",
            "x.csv:4: column 5 `EYX_um`: empty field: a number (µm) is needed",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,0,0,0,0,0,0\n",
            "x.csv:4: 8 fields, but the header has 9 columns",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,0,1200,0,0,0,0,0\n",
            "x.csv:4: column 4 `EXX_um`: 1200 µm is beyond ±1000 µm",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,0,0,0,0,0,0,20000\n",
            "x.csv:4: column 9 `ECX_urad`: 20000 µrad is beyond ±10000 µrad",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n401,0,0,0,0,0,0,0,0\n",
            "x.csv:4: column 1 `X_mm`: X = 401 mm is outside its stroke -400 .. 400 mm",
        ),
        (
            HEADER,
            "-400,0,0,0,0,0,0,0,0\n0,0,1e400,0,0,0,0,0,0\n",
            "column 3 `Z_mm`: `1e400` is not a finite number (mm)",
        ),
    ];
    for (header, body, needle) in cases {
        let e = laser_x(&m, header, body).unwrap_err().to_string();
        assert!(
            e.contains(needle),
            "{header}\n{body}\n-> {e}\nwanted: {needle}"
        );
    }
    let e = parse_laser("x.csv", "# nothing\n\n", &m, 0)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("x.csv:1: no header"), "{e}");
}

#[test]
fn squareness_reading_errors_name_the_file_line_and_column() {
    let m = machine();
    let ok = "COX = 20\nAOZ = -15.5\nb0z = 1e1\n[reference]\nX = 10\n";
    let s = parse_squareness("sq.toml", ok, &m).unwrap();
    let v: Vec<f64> = s.values.iter().map(|(_, v)| *v).collect();
    assert_eq!(v, [20e-6, -15.5e-6, 10e-6]);
    assert_eq!(s.reference[m.axis_by_name("X").unwrap()], 10.0);
    let cases: &[(&str, &str)] = &[
        (
            "COX = 20\nAOZ = 1\n",
            "sq.toml:1:1: the squareness file misses BOZ",
        ),
        (
            "COX = 20\nAOZ = 1\nBOZ = 2\nEXX = 3\n",
            "sq.toml:4:1: unknown key `EXX`",
        ),
        (
            "COX = 20\nAOZ = 1\nBOZ = 2\nC0X = 3\n",
            "sq.toml:4:1: COX is given twice (first on line 1)",
        ),
        (
            "COX = \"20\"\nAOZ = 1\nBOZ = 2\n",
            "sq.toml:1:7: COX (µrad) must be a number, not string",
        ),
        (
            "COX = nan\nAOZ = 1\nBOZ = 2\n",
            "sq.toml:1:7: COX (µrad) must be a finite number",
        ),
        (
            "COX = 20000\nAOZ = 1\nBOZ = 2\n",
            "sq.toml:1:7: COX = 20000 µrad is beyond ±10000 µrad",
        ),
        (
            "machine = \"seed-ac\"\nCOX = 2\nAOZ = 1\nBOZ = 2\n",
            "sq.toml:1:11: this file was measured on machine `seed-ac`, not `seed-3axis`",
        ),
        (
            "COX = 2\nAOZ = 1\nBOZ = 2\n[reference]\nX = 500\n",
            "sq.toml:5:5: reference X = 500 mm is outside its stroke -400 .. 400 mm",
        ),
        (
            "COX = 2\nAOZ = 1\nBOZ = 2\n[reference]\nA = 5\n",
            "sq.toml:5:1: machine seed-3axis has no axis `A`",
        ),
        (
            "COX = 2\nAOZ = 1\nBOZ = 2\nreference = 3\n",
            "sq.toml:4:13: `reference` must be a table",
        ),
        ("COX = 2\nAOZ = = 1\n", "sq.toml:2:7:"),
    ];
    for (text, needle) in cases {
        let e = parse_squareness("sq.toml", text, &m)
            .unwrap_err()
            .to_string();
        assert!(e.contains(needle), "{text}\n-> {e}\nwanted: {needle}");
    }
}

#[test]
fn the_grid_holds_du_at_every_point() {
    let m = machine();
    let t = truth(&m);
    let model = model_of(&m, &simulated(&m, &t));
    let e = GridSpec::new(&m, &model, 30.0).unwrap_err().to_string();
    assert!(
        e.contains("the grid pitch 30 mm does not divide the measured range of X, -400 .. 400 mm"),
        "{e}"
    );
    assert!(GridSpec::new(&m, &model, 0.0).is_err());
    assert!(
        GridSpec::new(&m, &model, 0.5)
            .unwrap_err()
            .to_string()
            .contains("more than 1000000 points")
    );
    let g = GridSpec::new(&m, &model, 100.0).unwrap();
    assert_eq!(g.len(), 9 * 7 * 7);
    let poses = g.poses(3);
    let du: Vec<Vector3<f64>> = poses.iter().map(|p| model.du(p).unwrap()).collect();
    let text = format_grid(&m, &g, &du, &["grid".into()]);
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    assert_eq!(lines.next(), Some("X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um"));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), poses.len());
    let (x, y, z) = (0usize, 1usize, 2usize);
    let xi = m.axis_by_name("X").unwrap();
    for (row, (p, d)) in rows.iter().zip(poses.iter().zip(&du)) {
        let f: Vec<f64> = row.split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(f[x], p[xi]);
        assert_eq!(f[y], p[m.axis_by_name("Y").unwrap()]);
        assert_eq!(f[z], p[m.axis_by_name("Z").unwrap()]);
        for i in 0..3 {
            let back =
                model_spec::units::parse_scaled(row.split(',').nth(3 + i).unwrap(), -3).unwrap();
            assert_eq!(back, d[i]);
        }
    }
    assert!(rows[0].starts_with("-400,-300,-300,"));
    assert!(rows[1].starts_with("-400,-300,-200,"));
}

#[test]
fn a_path_keeps_its_other_columns_and_refuses_poses_it_cannot_correct() {
    use compensation::volumetric::path::correct_poses;
    use formats::poses::{axis_words, read_pose_csv};
    let m = machine();
    let t = truth(&m);
    let model = model_of(&m, &simulated(&m, &t));
    let words = axis_words(&m);
    let lined = |text: &str| -> Vec<(usize, Vec<f64>)> {
        read_pose_csv("p.csv", text, &words)
            .unwrap()
            .poses()
            .iter()
            .map(|p| (p.line, p.commands.clone()))
            .collect()
    };
    let text = "# a path\r\nN,Z,x,Y,F\r\n10, 5.5 ,100,-20,1500\r\n\r\n20,-100,0,0,keep this\n";
    let table = read_pose_csv("p.csv", text, &words).unwrap();
    let c = correct_poses("p.csv", &m, &model, &lined(text)).unwrap();
    assert_eq!(c.len(), 2);
    let commands: Vec<Vec<f64>> = c.iter().map(|c| c.commands.clone()).collect();
    let out = table.write(&commands).unwrap();
    let lines: Vec<&str> = out.split_inclusive('\n').collect();
    assert_eq!(lines[0], "# a path\r\n");
    assert_eq!(lines[1], "N,Z,x,Y,F\r\n");
    assert_eq!(lines[3], "\r\n");
    let f: Vec<&str> = lines[2].trim_end().split(',').collect();
    assert_eq!((f[0], f[4]), ("10", "1500"));
    let (xi, yi, zi) = (
        m.axis_by_name("X").unwrap(),
        m.axis_by_name("Y").unwrap(),
        m.axis_by_name("Z").unwrap(),
    );
    assert_eq!(f[2].parse::<f64>().unwrap(), c[0].commands[xi]);
    assert_eq!(f[3].parse::<f64>().unwrap(), c[0].commands[yi]);
    assert_eq!(f[1].trim().parse::<f64>().unwrap(), c[0].commands[zi]);
    assert_eq!(
        c[0],
        correct(&model, &{
            let mut u = vec![0.0; 3];
            (u[xi], u[yi], u[zi]) = (100.0, -20.0, 5.5);
            u
        })
        .unwrap()
    );
    assert!(lines[4].ends_with(",keep this\n") && lines[4].starts_with("20,"));
    let (corner, _) = outward_corner(&m, &model);
    let at = |n: &str| corner[m.axis_by_name(n).unwrap()];
    let off = format!("X,Y,Z\n1,2,3\n{},{},{}\n", at("X"), at("Y"), at("Z"));
    let e = correct_poses("p.csv", &m, &model, &lined(&off))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("p.csv:3: the pose: the corrected command"),
        "{e}"
    );
    let e = correct_poses("p.csv", &m, &model, &lined("X,Y,Z\n500,2,3\n"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(
            "p.csv:2: the pose: X = 500 mm is outside the range its laser measurement covers"
        ),
        "{e}"
    );
    let e = correct_poses("p.csv", &m, &model, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("the path has no pose"), "{e}");
}

/// The seed's eqs. (23)–(25): a tilt of the Y carriage seen by a reflector at the offset
/// `L = (Lx, Ly, Lz)` from the carriage's origin. The exact machine gives the cross product
/// `ε × L`: `EXY' = EXY + Lz·EBY − Ly·ECY`, `EYY' = EYY + Lx·ECY − Lz·EAY`,
/// `EZY' = EZY + Ly·EAY − Lx·EBY`; the paper prints every pair with the same sign.
#[test]
fn the_abbe_terms_of_a_reflector_off_the_axis_line_are_a_cross_product() {
    let m = machine();
    let text = "[parameters]\nXx = 70.0\nYx = 40.0\nZx = 100.0\nZt = 150.0\n[errors]\nEAY = { \"poly:1\" = 30.0 }\nEBY = { \"poly:1\" = 40.0 }\nECY = { \"poly:1\" = 50.0 }\n";
    let t = formats::truth::parse_truth("abbe.toml", text, &m).unwrap();
    let s = simulated(&m, &t);
    let y = m.axis_by_name("Y").unwrap();
    let meas = s.measurements.iter().find(|x| x.axis == y).unwrap();
    // The reflector's offset from the Y carriage (X and Z at 0): Xx, Yx, Zx + Zt.
    let l = Vector3::new(70.0, 40.0, 250.0);
    let last = meas.positions.len() - 1;
    // The rotations and translations between the first and the last position.
    let r = meas.rotations[last];
    let d = meas.translations[last];
    let eps = Vector3::new(r[0], r[1], r[2]);
    let expected = eps.cross(&l);
    for i in 0..3 {
        assert!(
            (d[i] - expected[i]).abs() < 1e-8,
            "{i}: {} vs {}",
            d[i],
            expected[i]
        );
    }
    // The printed signs: EXY' = EXY + Ly·ECY + Lz·EBY is off by 2·Ly·ECY.
    let printed_x = l.y * eps.z + l.z * eps.y;
    assert!((d[0] - printed_x).abs() > 1e-3, "{} vs {printed_x}", d[0]);
}
