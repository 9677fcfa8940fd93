//! Simulated touch-probe hits: exact contacts on the actual sphere with a truth's errors on
//! three machines, the nominal sphere with the nominal truth, pre-travel and lobing along the
//! approach, backlash from reversal terms, reproducible noise, the clock, and the refusals.

use crate::common::builtin;
use model_spec::{Machine, Side};
use nalgebra::Vector3;
use simulation::VirtualMachine;
use simulation::probe::{
    APPROACH_S, AZIMUTH_CYCLE_DEG, CLEARANCE_MM, HIT_CYCLE_S, PATTERN_HITS, POSE_CHANGE_S,
    PatternAzimuth, PreTravel, ProbeError, ProbeRun, ProbeSettings, SimulatedHit,
    approach_directions, simulate_probe,
};
use simulation::truth::Truth;

const TIP: f64 = 1.5;
const SPHERE: f64 = 12.5;
const R_EFF: f64 = TIP + SPHERE;

fn probe() -> ProbeSettings {
    ProbeSettings {
        tip_radius_mm: TIP,
        sphere_radius_mm: SPHERE,
        pre_travel: PreTravel::default(),
        noise_mm: 0.0,
        seed: 0,
        azimuth: PatternAzimuth::Cycled,
    }
}

fn truth(m: &Machine, text: &str) -> Truth {
    formats::truth::parse_truth("t.toml", &format!("machine = \"{}\"\n{text}", m.name), m).unwrap()
}

/// Poses from rotary angles (degrees) by axis name; the linear commands are left at 0 (the
/// simulation fills them).
fn poses(m: &Machine, angles: &[&[(&str, f64)]]) -> Vec<Vec<f64>> {
    angles
        .iter()
        .map(|pose| {
            let mut q = vec![0.0; m.axes.len()];
            for (name, deg) in pose.iter() {
                q[m.axis_by_name(name).unwrap()] = deg.to_radians();
            }
            q
        })
        .collect()
}

/// A truth with location, set-up, squareness, linear-axis and reversal errors, and kinematic
/// parameters off the plan's, and four poses, per machine.
fn case(name: &str) -> (Machine, Truth, Vec<Vec<f64>>) {
    let m = builtin(name);
    match name {
        "seed-ac" => {
            let t = truth(
                &m,
                "[parameters]\nZw = 211.6\n[errors]\nXOW = 12\nYOW = -18\nZOW = 15\nYOA = 20\nZOA = -15\nBOA = 25\nCOA = -18\nXOC = 10\nYOC = -22\nAOC = 30\nBOC = -12\nECC = { \"harmonic:2\" = [8, 6] }\nCOX = 10\nBOZ = -8\nEXX = { const = 3, reversal = 2, \"poly:1\" = 10 }\nEAX = 15\nEZZ = { \"poly:1\" = 10 }\n",
            );
            let p = poses(
                &m,
                &[
                    &[("A", 0.0), ("C", 0.0)],
                    &[("A", -30.0), ("C", 90.0)],
                    &[("A", -75.0), ("C", 200.0)],
                    &[("A", 40.0), ("C", -120.0)],
                ],
            );
            (m, t, p)
        }
        "table-table-bc" => {
            let t = truth(
                &m,
                "[parameters]\nZc = 60.05\n[errors]\ndy0 = -5\nXOW = -8\nYOW = 14\nZOW = 6\nXOB = 15\nZOB = -12\nAOB = 20\nCOB = -25\nXOC = 9\nYOC = -11\nAOC = 18\nBOC = 22\nCOY = 12\nAOZ = -9\nBOZ = 7\nEYY = { reversal = 3 }\nEBB = { \"harmonic:1\" = [10, -5] }\n",
            );
            let p = poses(
                &m,
                &[
                    &[("B", 0.0), ("C", 0.0)],
                    &[("B", 45.0), ("C", 30.0)],
                    &[("B", -60.0), ("C", 250.0)],
                    &[("B", 90.0), ("C", -90.0)],
                ],
            );
            (m, t, p)
        }
        _ => {
            let t = truth(
                &m,
                "[parameters]\nZt = -250.1\n[errors]\ndx0 = 7\ndy0 = -4\ndz0 = 9\nXOW = 10\nYOW = 5\nZOW = -20\nXOB = -14\nZOB = 9\nAOB = 16\nCOB = -21\nXOC = 12\nYOC = 8\nAOC = -15\nBOC = 19\nCOY = -6\nAOZ = 11\nBOZ = 5\nEZZ = { reversal = 2 }\nEBB = 12\n",
            );
            let p = poses(
                &m,
                &[
                    &[("C", 0.0), ("B", 0.0)],
                    &[("C", 30.0), ("B", 45.0)],
                    &[("C", 200.0), ("B", -60.0)],
                    &[("C", -90.0), ("B", 90.0)],
                ],
            );
            (m, t, p)
        }
    }
}

/// The actual gap `P_tip − P_work` (bed frame, mm) at `commands`, the truth's errors
/// evaluated there with the hit's motion, times and velocities, the tip centre off the tool
/// point by the truth's zero offsets in the actual tool frame.
fn actual_gap(m: &Machine, t: &Truth, hit: &SimulatedHit, commands: &[f64]) -> Vector3<f64> {
    let cx = hit.context(commands);
    let errors = t.error_values(m, &cx);
    let offsets = Vector3::from(t.sensor_offsets(m, &cx));
    let vm = VirtualMachine::new(m);
    let tool = vm.chain_transform(Side::Tool, commands, &t.params, &errors);
    let work = vm.chain_transform(Side::Work, commands, &t.params, &errors);
    tool.translation.vector + tool.rotation * offsets - work.translation.vector
}

/// The nominal gap (bed frame, mm) at `commands`: the tip centre from the nominal sphere
/// centre.
fn nominal_gap(m: &Machine, commands: &[f64]) -> Vector3<f64> {
    let vm = VirtualMachine::new(m);
    let p = m.default_parameters();
    let tool = vm.nominal_chain_transform(Side::Tool, commands, &p);
    let work = vm.nominal_chain_transform(Side::Work, commands, &p);
    tool.translation.vector - work.translation.vector
}

fn run(m: &Machine, t: &Truth, p: &[Vec<f64>], settings: &ProbeSettings) -> ProbeRun {
    simulate_probe(m, &m.default_parameters(), t, p, settings).unwrap()
}

#[test]
fn exact_hits_touch_the_actual_sphere_on_three_machines() {
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let (m, t, p) = case(name);
        let r = run(&m, &t, &p, &probe());
        assert_eq!(r.poses.len(), p.len());
        let mut off_nominal = 0.0f64;
        for pose in &r.poses {
            assert_eq!(pose.hits.len(), PATTERN_HITS);
            for hit in &pose.hits {
                assert_eq!(hit.latched, hit.contact, "{name}: no pre-travel, no noise");
                let d = actual_gap(&m, &t, hit, &hit.latched).norm();
                assert!((d - R_EFF).abs() < 1e-9, "{name}: {} mm", d - R_EFF);
                assert!(
                    hit.iterations <= 10,
                    "{name}: {} iterations",
                    hit.iterations
                );
                let nominal = nominal_gap(&m, &hit.latched).norm();
                off_nominal = off_nominal.max((nominal - R_EFF).abs());
                // The rotary axes stand at the pose's commands.
                for i in m.rotary_axes() {
                    assert_eq!(hit.latched[i], pose.frame.commands[i]);
                }
            }
        }
        // The errors matter: the hits are not on the nominal sphere.
        assert!(off_nominal > 0.005, "{name}: {off_nominal} mm");
    }
}

#[test]
fn with_the_nominal_truth_the_hits_lie_on_the_nominal_sphere() {
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let (m, _, p) = case(name);
        let r = run(&m, &Truth::nominal(&m), &p, &probe());
        for pose in &r.poses {
            assert!(nominal_gap(&m, &pose.frame.commands).norm() < 1e-9);
            for (hit, n) in pose.hits.iter().zip(&pose.turn.approach_directions()) {
                assert_eq!(hit.approach, *n);
                let g = nominal_gap(&m, &hit.latched);
                assert!((g + n * R_EFF).norm() < 1e-9, "{name}: {g:?}");
                let s = nominal_gap(&m, &hit.start);
                assert!((s + n * (R_EFF + CLEARANCE_MM)).norm() < 1e-9);
                assert!((hit.contact_distance_mm - CLEARANCE_MM).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn pre_travel_latches_beyond_the_contact_along_the_approach() {
    let (m, t, p) = case("head-table-bc");
    let delta = 0.003;
    let settings = ProbeSettings {
        pre_travel: PreTravel {
            constant_mm: delta,
            lobing_mm: [0.0, 0.0],
        },
        ..probe()
    };
    let exact = run(&m, &t, &p, &probe());
    let late = run(&m, &t, &p, &settings);
    for (pe, pl) in exact.poses.iter().zip(&late.poses) {
        for (he, hl) in pe.hits.iter().zip(&pl.hits) {
            assert_eq!(he.contact, hl.contact);
            assert_eq!(hl.pre_travel_mm, delta);
            // The nominal gap moves by δ·n: inwards, towards the centre.
            let moved = nominal_gap(&m, &hl.latched) - nominal_gap(&m, &he.latched);
            assert!((moved - hl.approach * delta).norm() < 1e-11, "{moved:?}");
            // On the actual machine the tip moves δ·n too, up to the errors' change over δ (δ
            // times their gradient along the approach, µm/m: 1e-5 of δ at most).
            let actual = actual_gap(&m, &t, hl, &hl.latched) - actual_gap(&m, &t, he, &he.contact);
            assert!(
                (actual - hl.approach * delta).norm() < 1e-4 * delta,
                "{actual:?}"
            );
            // So it is δ closer to the actual sphere's centre, up to δ·(1 − cos θ), θ ≈ |e|/R_eff
            // the angle at which an approach aimed at the nominal centre meets the sphere about
            // −e (34 pm here).
            let d = actual_gap(&m, &t, hl, &hl.latched).norm();
            assert!(
                (d - (R_EFF - delta)).abs() < 5e-5 * delta,
                "{} mm",
                d - R_EFF
            );
        }
    }
}

#[test]
fn lobing_follows_the_approach_in_the_probe_frame() {
    // head-table-bc turns the probe with B: at B = 90° the stylus lies along the bed's x.
    let (m, t, p) = case("head-table-bc");
    let [lc, ls] = [0.002, -0.001];
    let settings = ProbeSettings {
        pre_travel: PreTravel {
            constant_mm: 0.0,
            lobing_mm: [lc, ls],
        },
        ..probe()
    };
    let r = run(&m, &t, &p, &settings);
    for pose in &r.poses {
        for hit in &pose.hits {
            let n = pose.frame.tool_rotation.matrix().transpose() * hit.approach;
            let (rho, phi) = (n.x.hypot(n.y), n.y.atan2(n.x));
            let want = rho * (lc * (3.0 * phi).cos() + ls * (3.0 * phi).sin());
            assert!((hit.pre_travel_mm - want).abs() < 1e-15);
        }
    }
    // The pattern turns with the probe: at every pose the pole's approach is along the stylus
    // (no lobing), and the third hit's (+x of the probe at azimuth 0) sees the lobing at the
    // pose's azimuth offset φ₀: L_c·cos 3φ₀ + L_s·sin 3φ₀, whatever B is.
    for (i, pose) in r.poses.iter().enumerate() {
        let hits = &pose.hits;
        assert!(hits[8].pre_travel_mm.abs() < 1e-15, "pose {i}");
        let phi = AZIMUTH_CYCLE_DEG[i % 4].to_radians();
        let want = lc * (3.0 * phi).cos() + ls * (3.0 * phi).sin();
        assert!((hits[2].pre_travel_mm - want).abs() < 1e-15, "pose {i}");
    }
}

#[test]
fn the_pattern_turns_with_the_probe_and_about_the_stylus_from_pose_to_pose() {
    // head-table-bc tilts the probe with B: the hits are the tool-frame pattern turned by the
    // pose's nominal tool rotation and its azimuth offset (0, 22.5°, 45°, 67.5°, …), so none
    // lies below the sphere's equator seen along the tool axis.
    let (m, t, p) = case("head-table-bc");
    let r = run(&m, &t, &p, &probe());
    let d = approach_directions();
    let mut tilted = false;
    for (i, pose) in r.poses.iter().enumerate() {
        let rot = pose.frame.tool_rotation.matrix();
        tilted |= (pose.frame.tool_axis() - Vector3::z()).norm() > 0.5;
        let phi = AZIMUTH_CYCLE_DEG[i % 4].to_radians();
        assert_eq!(pose.turn.azimuth_rad, phi);
        for (hit, dk) in pose.hits.iter().zip(&d) {
            // In the probe's frame the approach is the pattern's turned by φ₀ about z.
            let n = rot.transpose() * hit.approach;
            let want = Vector3::new(
                dk.x * phi.cos() - dk.y * phi.sin(),
                dk.x * phi.sin() + dk.y * phi.cos(),
                dk.z,
            );
            assert!((n - want).norm() < 1e-14, "pose {i}: {n:?} vs {want:?}");
            // The point hit (−n) is on the spindle's half of the sphere.
            assert!(
                simulation::probe::below_equator(&-hit.approach, &pose.frame.tool_axis()).is_none()
            );
        }
    }
    assert!(tilted, "no pose of the case tilts the probe");
}

#[test]
fn on_table_table_machines_the_fixed_pattern_is_the_bed_frame_pattern_bit_for_bit() {
    // The tool does not turn: with the azimuth fixed every pose gets the bed-frame directions
    // bit for bit; cycled, the first pose of every four does, the others are turned about z.
    for name in ["seed-ac", "table-table-bc"] {
        let (m, t, p) = case(name);
        let fixed = run(
            &m,
            &t,
            &p,
            &ProbeSettings {
                azimuth: PatternAzimuth::Fixed,
                ..probe()
            },
        );
        let cycled = run(&m, &t, &p, &probe());
        let bed = approach_directions();
        for (i, (f, c)) in fixed.poses.iter().zip(&cycled.poses).enumerate() {
            assert_eq!(
                f.frame.tool_rotation.matrix(),
                &nalgebra::Matrix3::identity()
            );
            for (k, (hf, hc)) in f.hits.iter().zip(&c.hits).enumerate() {
                assert_eq!(hf.approach, bed[k], "{name}: pose {i}, hit {k}");
                if i % 4 == 0 {
                    assert_eq!(hc, hf, "{name}: pose {i}, hit {k}");
                } else if k < 8 {
                    assert_ne!(hc.approach, bed[k], "{name}: pose {i}, hit {k}");
                }
            }
        }
    }
}

#[test]
fn backlash_on_x_stretches_the_sphere_along_x_and_shifts_the_hits_at_rest() {
    // seed-ac moves the table with X: the X positioning error EXX moves the sphere, so the
    // tip meets it EXX farther along; reversal flips EXX with the direction X moves.
    let m = builtin("seed-ac");
    let p = poses(&m, &[&[("A", 0.0), ("C", 0.0)]]);
    let x_of = |t: &Truth| -> Vec<f64> {
        let r = run(&m, t, &p, &probe());
        r.poses[0]
            .hits
            .iter()
            .map(|h| nominal_gap(&m, &h.latched).x)
            .collect()
    };
    let c = 0.002;
    let none = x_of(&Truth::nominal(&m));
    let plus = x_of(&truth(&m, "[errors]\nEXX = { reversal = 2 }\n"));
    let minus = x_of(&truth(&m, "[errors]\nEXX = { reversal = -2 }\n"));
    // Hits 0 and 2 are the −X and +X approaches (the points at +X and −X of the sphere).
    assert!((none[0] - none[2] - 2.0 * R_EFF).abs() < 1e-9);
    assert!(
        (plus[0] - plus[2] - 2.0 * (R_EFF + c)).abs() < 1e-9,
        "{plus:?}"
    );
    assert!((minus[0] - minus[2] - 2.0 * (R_EFF - c)).abs() < 1e-9);
    // The −X approach moves X up (the table follows the tip's −x move relative to it): the
    // backlash's +c moves the sphere away from the tip.
    assert!((plus[0] - (R_EFF + c)).abs() < 1e-9);
    // Hit 1 (−Y approach) leaves X at rest: it keeps X's last direction, up, from the move
    // from the +X side to the +Y side (the tip's x falls: the table's X rises); the sphere
    // then stands c off the approach line, which changes the hit by c²/2R only.
    assert!(plus[1].abs() < 1e-12);
    let r = run(
        &m,
        &truth(&m, "[errors]\nEXX = { reversal = 2 }\n"),
        &p,
        &probe(),
    );
    let x = m.axis_by_name("X").unwrap();
    let dirs: Vec<i8> = r.poses[0].hits.iter().map(|h| h.motion[x]).collect();
    assert_eq!(dirs[0], 1);
    assert_eq!(dirs[1], 1);
    assert_eq!(dirs[2], -1);
}

#[test]
fn noise_lies_along_the_approach_with_the_asked_sigma_and_is_reproducible() {
    let m = builtin("seed-ac");
    let angles: Vec<[(&str, f64); 2]> = (0..24)
        .map(|i| {
            [
                ("A", -60.0 + 5.0 * f64::from(i)),
                ("C", 15.0 * f64::from(i)),
            ]
        })
        .collect();
    let refs: Vec<&[(&str, f64)]> = angles.iter().map(|a| a.as_slice()).collect();
    let p = poses(&m, &refs);
    let sigma = 0.0005;
    let noisy = ProbeSettings {
        noise_mm: sigma,
        seed: 7,
        ..probe()
    };
    let t = Truth::nominal(&m);
    let a = run(&m, &t, &p, &noisy);
    assert_eq!(a, run(&m, &t, &p, &noisy));
    let b = run(&m, &t, &p, &ProbeSettings { seed: 8, ..noisy });
    assert_ne!(a, b);
    let mut draws = Vec::new();
    for pose in &a.poses {
        for hit in &pose.hits {
            let moved = nominal_gap(&m, &hit.latched) - nominal_gap(&m, &hit.contact);
            assert!((moved - hit.approach * hit.noise_mm).norm() < 1e-11);
            draws.push(hit.noise_mm);
        }
    }
    let n = draws.len() as f64;
    let rms = (draws.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
    assert!((rms / sigma - 1.0).abs() < 0.15, "{rms}");
}

#[test]
fn the_clock_counts_hits_and_pose_changes() {
    let (m, t, p) = case("seed-ac");
    let r = run(&m, &t, &p, &probe());
    let mut k = 0;
    for (i, pose) in r.poses.iter().enumerate() {
        for hit in &pose.hits {
            let want = i as f64 * POSE_CHANGE_S + k as f64 * HIT_CYCLE_S + APPROACH_S;
            assert_eq!(hit.t_s, want);
            k += 1;
        }
    }
    assert_eq!(r.hit_count(), 36);
    assert_eq!(r.duration_s, 3.0 * POSE_CHANGE_S + 36.0 * HIT_CYCLE_S);
    assert_eq!(r.poses[0].hits[0].tau, -1.0);
    assert_eq!(r.poses[3].hits[8].tau, 1.0);
}

#[test]
fn errors_beyond_the_clearance_and_poses_beyond_the_strokes_are_refused() {
    let m = builtin("seed-ac");
    let p = poses(&m, &[&[("A", 0.0), ("C", 0.0)]]);
    let far = truth(&m, "[errors]\nXOW = 2500\n");
    let e = simulate_probe(&m, &m.default_parameters(), &far, &p, &probe()).unwrap_err();
    assert!(matches!(e, ProbeError::Contact { pose: 0, .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "pose p1, hit 1 (approach (-1, 0, 0)): the start point, 2 mm outside the nominal sphere, is 500 µm inside the actual sphere: the machine's errors move the sphere by more than the clearance"
    );
    // A ball far out along x: the probe's start points leave the X stroke.
    let mut params = m.default_parameters();
    params[m.symbol_by_name("Xw").unwrap()] = -495.0;
    let e = simulate_probe(&m, &params, &Truth::nominal(&m), &p, &probe()).unwrap_err();
    assert!(
        matches!(
            e,
            ProbeError::Limits {
                what: "start point",
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains("outside its stroke -500 .. 500 mm"),
        "{e}"
    );
    let bad = ProbeSettings {
        tip_radius_mm: 0.0,
        ..probe()
    };
    assert!(matches!(
        simulate_probe(&m, &m.default_parameters(), &far, &p, &bad),
        Err(ProbeError::Settings(_))
    ));
    assert!(matches!(
        simulate_probe(&m, &m.default_parameters(), &far, &[], &probe()),
        Err(ProbeError::Poses(_))
    ));
}
