//! The LinuxCNC touch-probe program of `programs::probe` run in the real LinuxCNC
//! (`support::linuxcnc`) against a calibration sphere made of HAL components: `seed-ac` at three
//! poses, the sphere at each pose's nominal centre moved by a known offset (an error of the
//! machine, in the axes' commands); the program's blocks sent as MDI with the sphere moved
//! between poses, its `(PROBEOPEN …)` log turned into the probe hits CSV by `rtest probe-log`,
//! and the sphere fits of the hits give each pose's sphere centre within 2 µm.
//!
//! What the harness leaves out of the program: the header's comments and the operator's
//! message, `M19 R0` (the simulation has no spindle to orient: it would wait for the
//! orientation forever), `M0` (a stop for the operator) and `M2`.

use crate::common::{ok, temp_dir_tagged};
use crate::support::linuxcnc::{Config, for_test, sphere_centre_setp, sphere_hal};
use fitting::sphere::{Latch, RadiusMode, SphereFitOptions, fit_sphere};
use formats::nc::Dialect;
use formats::probe::read_probe_hits;
use nalgebra::Vector3;
use programs::probe::{PatternHit, ProbeOptions, format_probe_plan, probe_program};
use simulation::exact::tool_centre_point_ik;
use simulation::paths::record_from_commands;

/// The sphere's radius and the tip's, mm.
const SPHERE_MM: f64 = 12.5;
const TIP_MM: f64 = 1.5;

/// The poses (A, C in degrees) and the sphere's offset from each nominal centre (mm, on the
/// commands X, Y, Z): the machine's error the probing must find.
const POSES: [([f64; 2], [f64; 3]); 3] = [
    ([0.0, 0.0], [0.03, -0.02, 0.01]),
    ([30.0, 90.0], [-0.015, 0.025, -0.02]),
    ([-20.0, 200.0], [0.02, 0.01, 0.03]),
];

#[test]
fn the_linuxcnc_probing_program_finds_the_hal_spheres_within_2_um() {
    let Some(lc) = for_test("linuxcnc_probe_program") else {
        return;
    };
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let axis = |n: &str| m.axis_by_name(n).unwrap();
    let commands: Vec<Vec<f64>> = POSES
        .iter()
        .map(|([a, c], _)| {
            let mut q = vec![0.0; m.axes.len()];
            q[axis("A")] = a.to_radians();
            q[axis("C")] = c.to_radians();
            q
        })
        .collect();
    // The spheres: each pose's nominal centre (the nominal inverse kinematics) moved.
    let spheres: Vec<[f64; 3]> = commands
        .iter()
        .zip(&POSES)
        .map(|(q, (_, shift))| {
            let mut q = q.clone();
            tool_centre_point_ik(&m, &mut q, &m.default_parameters()).unwrap();
            [
                q[axis("X")] + shift[0],
                q[axis("Y")] + shift[1],
                q[axis("Z")] + shift[2],
            ]
        })
        .collect();
    let pattern: Vec<PatternHit> = fitting::sphere::default_pattern(1.0)
        .iter()
        .map(|h| PatternHit {
            point: [h.point_mm.x, h.point_mm.y, h.point_mm.z],
            approach: [h.approach.x, h.approach.y, h.approach.z],
        })
        .collect();
    let mut o = ProbeOptions::new(&m, Dialect::LinuxCnc, pattern, SPHERE_MM, TIP_MM);
    // Short approaches and fast positioning keep the run short; 60 mm/min is 1 µm per 1 ms
    // servo period, the resolution of the latch.
    o.pretouch_mm = 0.1;
    o.overtravel_mm = 0.1;
    o.safe_mm = 1.0;
    o.probe_feed_mm_min = 60.0;
    o.position_feed_mm_min = 30_000.0;
    o.log_name = "probe-log".into();
    let p = probe_program(&m, &record_from_commands(commands, vec![0.0, 1.0, 2.0]), &o).unwrap();
    let dir = temp_dir_tagged("linuxcnc", "probe-program");
    std::fs::write(dir.join("k.ngc"), &p.text).unwrap();
    std::fs::write(
        dir.join("k.plan.csv"),
        format_probe_plan(&m, &p.plan, &[]).unwrap(),
    )
    .unwrap();
    // The program's blocks as MDI, the sphere moved at each pose's comment.
    let mut blocks = Vec::new();
    let mut pose = 0;
    let mut probes = Vec::new();
    for line in p.text.lines().map(str::trim) {
        let logged = line.starts_with("(PROBEOPEN") || line.starts_with("(PROBECLOSE");
        if line.starts_with("(pose ") {
            blocks.extend(sphere_centre_setp(spheres[pose]));
            pose += 1;
        } else if line == "%" || (line.starts_with('(') && !logged) {
            continue;
        } else if !matches!(line, "M19 R0" | "M0" | "M2") {
            if line.starts_with("G38.2") {
                probes.push(blocks.len());
            }
            blocks.push(line.to_string());
        }
    }
    assert_eq!(pose, 3);
    assert_eq!(probes.len(), 27);
    let config = Config {
        kinematics: "trivkins coordinates=XYZAC",
        coordinates: "XYZAC",
        // Far from every position of the program until the first pose moves it.
        hal: &sphere_hal([0.0, 0.0, -5000.0], o.effective_radius_mm()),
    };
    let started = std::time::Instant::now();
    let rows = lc
        .run_probing(&dir, &config, &blocks)
        .unwrap_or_else(|e| panic!("{e}"));
    // Each latch on its sphere: within two servo periods at the probing feed (the input is
    // sampled once a 1 ms period and the latch is the position of the period it trips in).
    let bound = o.probe_feed_mm_min / 60.0 * 2e-3;
    let mut largest = 0.0f64;
    for (n, &i) in probes.iter().enumerate() {
        assert!(
            rows[i].tripped,
            "block {} ({}): the probe did not trip",
            i, blocks[i]
        );
        let c = spheres[n / 9];
        let d = (0..3)
            .map(|k| (rows[i].probed[k] - c[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        largest = largest.max((d - o.effective_radius_mm()).abs());
    }
    eprintln!(
        "{} latches: within {:.2e} mm of their spheres (bound {bound:.0e} mm)",
        probes.len(),
        largest
    );
    assert!(largest <= bound, "{largest} mm");
    let log = std::fs::read_to_string(dir.join("probe-log.txt")).expect("LinuxCNC's probe log");
    assert_eq!(log.lines().count(), 27, "{log}");
    let out = ok(
        &dir,
        &[
            "probe-log",
            "--machine",
            "seed-ac",
            "--plan",
            "k.plan.csv",
            "--log",
            "probe-log.txt",
            "--nc",
            "linuxcnc",
            "-o",
            "hits.csv",
        ],
    );
    let hits = read_probe_hits(&dir.join("hits.csv"), &m).unwrap();
    assert_eq!(hits.poses.len(), 3);
    let mut worst = 0.0f64;
    for (k, pose) in hits.poses.iter().enumerate() {
        let centre = Vector3::from(spheres[k]);
        let latches: Vec<Latch> = pose
            .hits
            .iter()
            .map(|h| {
                let p = Vector3::new(h.axes[axis("X")], h.axes[axis("Y")], h.axes[axis("Z")]);
                Latch {
                    tip_mm: p,
                    approach: (centre - p).normalize(),
                }
            })
            .collect();
        for (what, radius) in [
            (
                "calibrated",
                RadiusMode::Calibrated {
                    sphere_radius_mm: SPHERE_MM,
                },
            ),
            (
                "free",
                RadiusMode::Free {
                    calibrated_mm: Some(SPHERE_MM),
                },
            ),
        ] {
            let fit = fit_sphere(
                &latches,
                &SphereFitOptions {
                    radius,
                    tip_radius_mm: TIP_MM,
                    noise_mm: 0.0005,
                },
            )
            .unwrap_or_else(|e| panic!("pose {}: {e}", pose.label));
            let e = (fit.centre_mm - centre).norm();
            eprintln!(
                "pose {} ({what} radius): centre {:.2} µm from the HAL sphere's, rms {:.2} µm",
                pose.label,
                e * 1e3,
                fit.rms_mm * 1e3
            );
            worst = worst.max(e);
        }
    }
    eprintln!(
        "{} blocks in {:.1} s; {out}",
        blocks.len(),
        started.elapsed().as_secs_f64()
    );
    assert!(worst <= 0.002, "{} µm", worst * 1e3);
}
