//! Finite-difference gains of the exact virtual machine against the seed's Table 2 (seed-ac,
//! Table 3 parameters), and the study behind the default steps.

use crate::common;

use common::{Rng, builtin, commands, id, random_rotary, sym};
use model_spec::Machine;
use simulation::exact::VirtualMachine;
use simulation::fd::{FdSteps, fd_gains, fd_gains_with};

/// The reduced model of the seed's Table 2 (position rows, tool minus workpiece, tool frame) at
/// `A`, `C` (rad), for `Xa = Ya = Za = 0` as in Table 3. Every entry re-derived by hand from the
/// chain `X · [A: loc · Rx(A)] · (0, 0, Zc) · [C: loc · Rz(C)] · (Xw, Yw, Zw) · setup`; all agree
/// with the printed table.
fn table2(m: &Machine, p: &[f64], a: f64, c: f64) -> Vec<(&'static str, [f64; 3])> {
    let (sa, ca) = a.sin_cos();
    let (sc, cc) = c.sin_cos();
    let (xw, yw, zw, zc) = (
        sym(m, p, "Xw"),
        sym(m, p, "Yw"),
        sym(m, p, "Zw"),
        sym(m, p, "Zc"),
    );
    vec![
        ("XOW", [-cc, -ca * sc, -sa * sc]),
        ("YOW", [sc, -ca * cc, -sa * cc]),
        ("ZOW", [0.0, sa, -ca]),
        ("YOA", [0.0, -1.0, 0.0]),
        ("ZOA", [0.0, 0.0, -1.0]),
        (
            "BOA",
            [
                -ca * (zw + zc) - sa * sc * xw - sa * cc * yw,
                0.0,
                -sc * yw + cc * xw,
            ],
        ),
        (
            "COA",
            [
                -sa * (zw + zc) + ca * sc * xw + ca * cc * yw,
                -cc * xw + sc * yw,
                0.0,
            ],
        ),
        ("XOC", [-1.0, 0.0, 0.0]),
        ("YOC", [0.0, -ca, -sa]),
        (
            "AOC",
            [
                0.0,
                sc * sa * xw + cc * sa * yw + ca * zw,
                -cc * ca * yw + sa * zw - sc * ca * xw,
            ],
        ),
        (
            "BOC",
            [
                -zw,
                -cc * sa * xw + sc * sa * yw,
                -sc * ca * yw + cc * ca * xw,
            ],
        ),
    ]
}

/// Largest |FD − Table 2| over the reduced model's angular (`angular = true`) or translational
/// errors at `n` random IK poses of seed-ac.
fn table2_max_error(steps: FdSteps, n: usize, angular: bool) -> f64 {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let vm = VirtualMachine::new(&m);
    let mut rng = Rng::new(7);
    let mut worst: f64 = 0.0;
    for _ in 0..n {
        let mut q = random_rotary(&m, &mut rng);
        vm.tool_centre_point_ik(&mut q, &p).unwrap();
        let (a, c) = (
            q[m.axis_by_name("A").unwrap()],
            q[m.axis_by_name("C").unwrap()],
        );
        let mut expected = table2(&m, &p, a, c);
        expected.retain(|(n, _)| m.catalogue[id(&m, n)].is_angular() == angular);
        let ids: Vec<usize> = expected.iter().map(|(n, _)| id(&m, n)).collect();
        let got = fd_gains_with(&vm, &q, &p, &ids, steps);
        for ((_, e), g) in expected.iter().zip(&got) {
            for k in 0..3 {
                worst = worst.max((e[k] - g[k]).abs());
            }
        }
    }
    worst
}

#[test]
fn fd_gains_match_seed_table2_at_random_poses() {
    for angular in [false, true] {
        let worst = table2_max_error(FdSteps::default(), 50, angular);
        assert!(worst < 1e-9, "largest deviation from Table 2: {worst:e}");
    }
}

#[test]
fn seed_table2_boa_x_and_aoc_y_at_a_nontrivial_pose() {
    let m = builtin("seed-ac");
    let p = m.default_parameters();
    let (a, c) = ((-37.0f64).to_radians(), 123.0f64.to_radians());
    let mut q = commands(&m, &[("A", a), ("C", c)]);
    simulation::tool_centre_point_ik(&m, &mut q, &p).unwrap();
    let (xw, yw, zw, zc) = (
        sym(&m, &p, "Xw"),
        sym(&m, &p, "Yw"),
        sym(&m, &p, "Zw"),
        sym(&m, &p, "Zc"),
    );
    let g = fd_gains(&m, &q, &p, &[id(&m, "BOA"), id(&m, "AOC")]);
    let boa_x = -a.cos() * (zw + zc) - a.sin() * c.sin() * xw - a.sin() * c.cos() * yw;
    let aoc_y = c.sin() * a.sin() * xw + c.cos() * a.sin() * yw + a.cos() * zw;
    assert!((g[0][0] - boa_x).abs() < 1e-8, "{} vs {boa_x}", g[0][0]);
    assert!((g[1][1] - aoc_y).abs() < 1e-8, "{} vs {aoc_y}", g[1][1]);
    // Orientation rows of Table 1 for the same errors: BOA (−cos A, 0, 0), AOC (0, 0, 0)…
    // AOC turns the C table about x, which tilts the workpiece z by Rx(A)·(0, −1, 0)·AOC.
    assert!((g[0][3] + a.cos()).abs() < 1e-9, "BOA I: {}", g[0][3]);
    assert!((g[1][4] - a.cos()).abs() < 1e-9, "AOC J: {}", g[1][4]);
    assert!((g[1][5] - a.sin()).abs() < 1e-9, "AOC K: {}", g[1][5]);
}

/// The step study behind [`FdSteps::default`]: the largest deviation from Table 2 for a range
/// of angular steps, plain central differences and Richardson extrapolation, and for a range of
/// translational steps; it checks the conclusions the defaults rest on (the table is printed
/// with `cargo test -p simulation --test all -- --nocapture fd::step_study`).
#[test]
fn step_study() {
    let angular = |h: f64, richardson: bool| {
        table2_max_error(
            FdSteps {
                angular: h,
                richardson,
                ..FdSteps::default()
            },
            20,
            true,
        )
    };
    println!("angular step  central        richardson");
    let steps = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7];
    let mut central = Vec::new();
    let mut rich = Vec::new();
    for h in steps {
        central.push(angular(h, false));
        rich.push(angular(h, true));
        println!(
            "{h:<12e}  {:<13.3e}  {:.3e}",
            central.last().unwrap(),
            rich.last().unwrap()
        );
    }
    let at = |h: f64| steps.iter().position(|&s| s == h).unwrap();
    // Central differences: truncation error at large steps, rounding error at small ones, a
    // minimum near 1e-5 rad of about 1e-8 mm/rad.
    assert!(central[at(1e-5)] < 1e-7, "{central:?}");
    assert!(central[at(1e-2)] > 10.0 * central[at(1e-5)], "{central:?}");
    assert!(central[at(1e-7)] > central[at(1e-5)], "{central:?}");
    // Richardson extrapolation removes the h² term: at the default 1e-3 rad it is far better
    // than any central difference, about 1e-10 mm/rad.
    let default = FdSteps::default();
    assert_eq!((default.angular, default.richardson), (1e-3, true));
    assert!(rich[at(1e-3)] < 1e-9, "{rich:?}");
    assert!(rich[at(1e-3)] < central.iter().cloned().fold(f64::INFINITY, f64::min));
    // Translational errors enter linearly: a larger step only lowers the rounding error.
    let mut translational = Vec::new();
    for h in [1.0, 1e-2, 1e-3, 1e-4, 1e-6] {
        let e = table2_max_error(
            FdSteps {
                translational: h,
                ..FdSteps::default()
            },
            20,
            false,
        );
        println!("translational step {h:e} mm: {e:.3e}");
        translational.push(e);
    }
    assert_eq!(default.translational, 1e-2);
    assert!(translational[1] < 1e-10, "{translational:?}");
    assert!(translational[4] > translational[1], "{translational:?}");
}
