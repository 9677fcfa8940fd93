//! Probing in the real LinuxCNC (`support::linuxcnc`): a calibration sphere made of stock HAL
//! components drives `motion.probe-input` (`sum2` for the tip's offsets from the sphere's
//! centre, `hypot` for the distance, `wcomp` for "inside"), `G38.2` moves probe it, and the
//! positions LinuxCNC latches lie on the sphere within the feed times two servo periods. The
//! harness sets the sphere's centre per pose (`setp` between blocks), as the probing programs'
//! check needs.

use crate::common::temp_dir_tagged;
use crate::support::linuxcnc::{Config, for_test, number};

/// The sphere's radius plus the tip's (mm): where the tip's centre touches it.
const RADIUS: f64 = 12.5;
/// The probing feed, mm/min: 60 mm/min is 1 µm per 1 ms servo period.
const FEED: f64 = 60.0;
/// How far outside the sphere a probing move starts and inside it aims (mm).
const CLEARANCE: f64 = 0.3;

/// The HAL of the sphere: the tip's offsets from the centre, their length, and the probe input
/// true while it is below the radius.
fn sphere_hal(centre: [f64; 3]) -> String {
    // Named instances; the simulation is loaded without its own `hypot` (`-no_make_ddts`).
    let mut h = String::from(
        "loadrt sum2 names=sphere-dx,sphere-dy,sphere-dz\nloadrt hypot names=sphere-distance\n\
         loadrt wcomp names=sphere-inside\n\
         addf sphere-dx servo-thread\naddf sphere-dy servo-thread\naddf sphere-dz servo-thread\n\
         addf sphere-distance servo-thread\naddf sphere-inside servo-thread\n",
    );
    for (j, (c, d)) in centre.iter().zip(["dx", "dy", "dz"]).enumerate() {
        h += &format!(
            "net J{j}:pos-fb => sphere-{d}.in0\nsetp sphere-{d}.gain0 1\nsetp sphere-{d}.gain1 0\nsetp sphere-{d}.offset {}\nnet sphere-{d} sphere-{d}.out => sphere-distance.in{j}\n",
            number(-c)
        );
    }
    h += &format!(
        "net sphere-distance sphere-distance.out => sphere-inside.in\nsetp sphere-inside.min -1\nsetp sphere-inside.max {}\nnet sphere-probe sphere-inside.out => motion.probe-input\n",
        number(RADIUS)
    );
    h
}

/// The default pattern's 9 approach directions (unit, inward): ±X, ±Y at the centre's height,
/// four at R/2 above it, the pole.
fn directions() -> Vec<[f64; 3]> {
    let mut d = Vec::new();
    for (x, y) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
        d.push([-x, -y, 0.0]);
    }
    let z = 0.5;
    let across = (1.0f64 - z * z).sqrt();
    for k in 0..4 {
        let a = (45.0 + 90.0 * k as f64).to_radians();
        d.push([-across * a.cos(), -across * a.sin(), -z]);
    }
    d.push([0.0, 0.0, -1.0]);
    d
}

/// The blocks probing a sphere at `centre`: per hit, from a safe height above it down outside
/// it at the hit's azimuth to the hit's height, in to just outside the sphere on the approach
/// line, `G38.2` towards a point just inside, and back out the same way (no rapid crosses the
/// sphere: the probe would trip during it, which LinuxCNC treats as an error).
fn probing_blocks(centre: [f64; 3]) -> Vec<String> {
    let safe = centre[2] + RADIUS + 5.0;
    let xyz = |p: [f64; 3]| format!("X{} Y{} Z{}", number(p[0]), number(p[1]), number(p[2]));
    let mut b = Vec::new();
    for n in directions() {
        let start: [f64; 3] = std::array::from_fn(|i| centre[i] - n[i] * (RADIUS + CLEARANCE));
        let target: [f64; 3] = std::array::from_fn(|i| centre[i] - n[i] * (RADIUS - CLEARANCE));
        let azimuth = if n[0] == 0.0 && n[1] == 0.0 {
            0.0
        } else {
            (-n[1]).atan2(-n[0])
        };
        let outside = [
            centre[0] + (RADIUS + 1.0) * azimuth.cos(),
            centre[1] + (RADIUS + 1.0) * azimuth.sin(),
            start[2],
        ];
        b.push(format!("G0 Z{}", number(safe)));
        b.push(format!(
            "G0 X{} Y{}",
            number(outside[0]),
            number(outside[1])
        ));
        b.push(format!("G0 {}", xyz(outside)));
        b.push(format!("G0 {}", xyz(start)));
        b.push(format!("G38.2 {} F{}", xyz(target), number(FEED)));
        b.push(format!("G0 {}", xyz(start)));
        b.push(format!("G0 {}", xyz(outside)));
    }
    b.push(format!("G0 Z{}", number(safe)));
    b
}

#[test]
fn g38_2_on_a_hal_sphere_latches_points_on_it_at_two_poses() {
    let Some(lc) = for_test("linuxcnc_probe") else {
        return;
    };
    let centres = [[10.0, -20.0, 5.0], [-35.5, 12.25, -8.0]];
    let mut blocks = vec!["G90 G21 G17 G40 G49 G94".to_string()];
    // Start far above the first sphere, outside it.
    blocks.push("G0 X0 Y0 Z100".to_string());
    let mut probing = Vec::new();
    for (k, c) in centres.iter().enumerate() {
        if k > 0 {
            blocks.push("G0 Z100".to_string());
            for (v, d) in c.iter().zip(["dx", "dy", "dz"]) {
                blocks.push(format!("setp sphere-{d}.offset {}", number(-v)));
            }
        }
        for line in probing_blocks(*c) {
            if line.starts_with("G38.2") {
                probing.push((blocks.len(), *c));
            }
            blocks.push(line);
        }
    }
    let dir = temp_dir_tagged("linuxcnc", "probe");
    let config = Config {
        kinematics: "trivkins coordinates=XYZAC",
        coordinates: "XYZAC",
        hal: &sphere_hal(centres[0]),
    };
    let rows = lc
        .run_probing(&dir, &config, &blocks)
        .unwrap_or_else(|e| panic!("{e}"));
    // Two servo periods at the feed: the input is sampled once a period and the latch is the
    // position of the period it trips in.
    let bound = FEED / 60.0 * 2e-3;
    let mut largest = 0.0f64;
    for (i, c) in &probing {
        let r = &rows[*i];
        assert!(r.tripped, "block {i}: the probe did not trip");
        let d = (0..3)
            .map(|k| (r.probed[k] - c[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        largest = largest.max((d - RADIUS).abs());
    }
    eprintln!(
        "{} hits at {} poses: the latched points lie within {:.2e} mm of the sphere (bound {bound:.0e} mm)",
        probing.len(),
        centres.len(),
        largest
    );
    assert_eq!(probing.len(), 18);
    assert!(largest <= bound, "{largest} mm");
}
