//! A probing program's log turned into the probe hits CSV with its plan
//! (`programs::probe::{read_probe_log, hits_from_log}`): synthetic logs of every dialect, made
//! from the plan's contacts (exactly, and with the sphere moved), become hits that
//! `formats::probe` writes and reads back, and whose sphere fits give the sphere's centre
//! within 1e-9 mm; the probe plan CSV read back bit for bit; every refusal of a log, at its line.

use crate::common::{Scratch, builtin};
use crate::probe_program::{DIALECTS, options, seed_poses};
use fitting::sphere::{Latch, RadiusMode, SphereFitOptions, fit_sphere};
use formats::nc::Dialect;
use formats::probe::{format_probe_hits, read_probe_hits};
use model_spec::{AxisKind, Machine};
use programs::probe::{
    LogOptions, ProbePlan, format_probe_plan, hits_from_log, parse_probe_log, parse_probe_plan,
    probe_program, read_probe_log, read_probe_plan,
};
use simulation::exact::tool_centre_point_ik;

/// The nominal centre's linear commands (X, Y, Z; mm) of the plan's pose `row` (its rotary
/// axes), by the nominal inverse kinematics.
fn nominal_centre(m: &Machine, axes: &[f64]) -> [f64; 3] {
    let mut q = formats::poses::from_file_units(m, axes);
    tool_centre_point_ik(m, &mut q, &m.default_parameters()).unwrap();
    let x = |n: &str| q[m.axis_by_name(n).unwrap()];
    [x("X"), x("Y"), x("Z")]
}

/// A log of `dialect` whose trips are the plan's contacts moved by `shift` (mm, on X, Y, Z),
/// every number written in full.
fn synthetic_log(m: &Machine, plan: &ProbePlan, dialect: Dialect, shift: [f64; 3]) -> String {
    let mut out = String::new();
    if dialect == Dialect::Iso {
        out += "%\n";
    }
    let at = |r: &[f64], n: &str| r[m.axis_by_name(n).unwrap()];
    for row in &plan.rows {
        let xyz = [
            at(&row.axes, "X") + shift[0],
            at(&row.axes, "Y") + shift[1],
            at(&row.axes, "Z") + shift[2],
        ];
        out += &match dialect {
            Dialect::LinuxCnc => format!(
                "{} {} {} {} 0.000000 {} 0.000000 0.000000 0.000000\n",
                xyz[0],
                xyz[1],
                xyz[2],
                at(&row.axes, "A"),
                at(&row.axes, "C")
            ),
            Dialect::Iso => format!("X {} Y {} Z {}\n", xyz[0], xyz[1], xyz[2]),
            Dialect::Heidenhain => format!("X {:+} Y {:+} Z {:+}\n", xyz[0], xyz[1], xyz[2]),
        };
    }
    if dialect == Dialect::Iso {
        out += "%\n";
    }
    out
}

#[test]
fn synthetic_logs_become_hits_whose_spheres_are_the_nominal_centres() {
    let m = builtin("seed-ac");
    let poses = seed_poses(&m);
    let dir = Scratch::new("probe-log");
    let template = fitting::sphere::default_pattern(1.0)[0].point_mm;
    let v3 = |v: [f64; 3]| {
        let mut t = template;
        (t.x, t.y, t.z) = (v[0], v[1], v[2]);
        t
    };
    for d in DIALECTS {
        let o = options(&m, d);
        let p = probe_program(&m, &poses, &o).unwrap();
        // The plan goes through its CSV.
        let plan_path = dir.0.join(format!("{}.plan.csv", d.name()));
        std::fs::write(
            &plan_path,
            format_probe_plan(&m, &p.plan, &["a plan".into()]).unwrap(),
        )
        .unwrap();
        let plan = read_probe_plan(&plan_path, &m).unwrap();
        assert_eq!(plan, p.plan, "{d:?}: the plan reads back bit for bit");
        for shift in [[0.0; 3], [0.05, -0.03, 0.02]] {
            let log_path = dir.0.join(format!("{}.log", d.name()));
            std::fs::write(&log_path, synthetic_log(&m, &plan, d, shift)).unwrap();
            let trips = read_probe_log(&log_path, d, &m).unwrap();
            assert_eq!(trips.len(), 27);
            let hits = hits_from_log(&m, &plan, &trips, "x.log", &LogOptions::default()).unwrap();
            let csv = format_probe_hits(&m, &hits, &["from a log".into()]).unwrap();
            let hits_path = dir.0.join(format!("{}.hits.csv", d.name()));
            std::fs::write(&hits_path, csv).unwrap();
            let back = read_probe_hits(&hits_path, &m).unwrap();
            assert_eq!(back.poses.len(), 3);
            for (pose, expected_label) in back.poses.iter().zip(["p1", "p2", "p3"]) {
                assert_eq!(pose.label, expected_label);
                assert_eq!(pose.hits.len(), 9);
                let centre = nominal_centre(&m, &pose.hits[0].axes);
                let at = |h: &[f64], n: &str| h[m.axis_by_name(n).unwrap()];
                let latches: Vec<Latch> = pose
                    .hits
                    .iter()
                    .map(|h| {
                        let p = [at(&h.axes, "X"), at(&h.axes, "Y"), at(&h.axes, "Z")];
                        // The approach in the axes' space: towards the centre.
                        let v = [centre[0] - p[0], centre[1] - p[1], centre[2] - p[2]];
                        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                        Latch {
                            tip_mm: v3(p),
                            approach: v3([v[0] / n, v[1] / n, v[2] / n]),
                        }
                    })
                    .collect();
                let fit = fit_sphere(
                    &latches,
                    &SphereFitOptions {
                        radius: RadiusMode::Free {
                            calibrated_mm: Some(12.5),
                        },
                        tip_radius_mm: 1.5,
                        noise_mm: 0.0005,
                    },
                )
                .unwrap();
                for k in 0..3 {
                    let e = fit.centre_mm[k] - (centre[k] + shift[k]);
                    assert!(e.abs() < 1e-9, "{d:?} {} {k}: {e}", pose.label);
                }
                assert!((fit.sphere_radius_mm - 12.5).abs() < 1e-9);
                // The rotary axes and times are the plan's.
                let first = plan.rows.iter().find(|r| r.pose == pose.label).unwrap();
                for (a, ax) in m.axes.iter().enumerate() {
                    if ax.kind == AxisKind::Rotary {
                        assert_eq!(pose.hits[0].axes[a], first.axes[a]);
                    }
                }
                assert_eq!(pose.hits[0].t_s, first.t_s);
                assert_eq!(pose.hits[0].direction, first.direction);
            }
        }
    }
}

/// The error of the log `text` of `dialect` against the plan of the seed's program.
fn refused(d: Dialect, edit: &dyn Fn(&mut Vec<String>)) -> String {
    let m = builtin("seed-ac");
    let p = probe_program(&m, &seed_poses(&m), &options(&m, d)).unwrap();
    let text = synthetic_log(&m, &p.plan, d, [0.0; 3]);
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    edit(&mut lines);
    let text = lines.join("\n") + "\n";
    parse_probe_log("probe.txt", &text, d, &m)
        .and_then(|trips| hits_from_log(&m, &p.plan, &trips, "probe.txt", &LogOptions::default()))
        .unwrap_err()
        .to_string()
}

#[test]
fn logs_that_do_not_fit_their_plan_are_refused_at_their_line() {
    // A missing trip: the log is one line short.
    let e = refused(Dialect::LinuxCnc, &|l| {
        l.pop();
    });
    assert_eq!(
        e,
        "probe.txt:27: the log ends after 26 trip(s), the plan has 27 hits: the first without a trip is pose p3, hit 9 (program line 201): the probe did not trip there, or the program stopped"
    );
    // A trip too many (a log appended to).
    let e = refused(Dialect::Heidenhain, &|l| {
        let first = l[0].clone();
        l.push(first);
    });
    assert!(
        e.starts_with(
            "probe.txt:28: trip 28: the plan has only 27 hits (a log an earlier run appended to?"
        ),
        "{e}"
    );
    // A latched point 0.6 mm off its contact (a chip on the sphere, or G38.3's untripped end).
    let e = refused(Dialect::LinuxCnc, &|l| {
        let mut f: Vec<String> = l[4].split(' ').map(str::to_string).collect();
        let x: f64 = f[0].parse().unwrap();
        f[0] = format!("{}", x + 0.6);
        l[4] = f.join(" ");
    });
    assert!(
        e.starts_with("probe.txt:5: trip 5 (pose p1, hit 5 (program line "),
        "{e}"
    );
    assert!(
        e.contains(") latched 0.6 mm from its planned contact X"),
        "{e}"
    );
    assert!(e.contains("beyond the 0.5 mm allowed"), "{e}");
    // A LinuxCNC log of other rotary angles.
    let e = refused(Dialect::LinuxCnc, &|l| {
        let mut f: Vec<String> = l[10].split(' ').map(str::to_string).collect();
        f[3] = "31".into();
        l[10] = f.join(" ");
    });
    assert!(
        e.starts_with("probe.txt:11: trip 11 (pose p2, hit 2 (program line "),
        "{e}"
    );
    assert!(
        e.ends_with("axis A at 31 deg, the plan's pose is at 30 deg: the log is not of this plan"),
        "{e}"
    );
    // Lines that are not a log's.
    assert_eq!(
        refused(Dialect::LinuxCnc, &|l| l[2] = "1 2 3".into()),
        "probe.txt:3: 3 field(s): a LinuxCNC probe log line holds nine numbers, X Y Z A B C U V W"
    );
    assert_eq!(
        refused(Dialect::LinuxCnc, &|l| l[2] =
            l[2].replacen(' ', " nan ", 1)),
        "probe.txt:3: 10 field(s): a LinuxCNC probe log line holds nine numbers, X Y Z A B C U V W"
    );
    assert_eq!(
        refused(Dialect::LinuxCnc, &|l| l[2] =
            l[2].replacen(char::is_numeric, "x", 1)),
        format!(
            "probe.txt:3: `{}` (axis X) is not a finite decimal number",
            refused_field()
        )
    );
    assert_eq!(
        refused(Dialect::Iso, &|l| l[3] = "X 1.5 Z 2".into()),
        "probe.txt:4: `Z 2` where Y belongs: a DPRNT line of the probe log is `X<number> Y<number> Z<number>`"
    );
    assert_eq!(
        refused(Dialect::Heidenhain, &|l| l[0] =
            "X +1 Y +2 Z +3 A +4".into()),
        "probe.txt:1: `A +4` after the last axis: a FN 16 line of the probe log is `X<number> Y<number> Z<number>`"
    );
    assert_eq!(
        refused(Dialect::Iso, &|l| l[1] = "X 1.5 Y -- Z 2".into()),
        "probe.txt:2: axis Y: `-- Z 2` is not a finite decimal number: a DPRNT line of the probe log is `X<number> Y<number> Z<number>`"
    );
    assert_eq!(
        refused(Dialect::Iso, &|l| l.retain(|x| x == "%")),
        "probe.txt:3: a probe log without a trip: the probe did not trip, or this is not the log the program wrote"
    );
}

/// The first field of the seed's LinuxCNC log's third line, with its first digit an `x`.
fn refused_field() -> String {
    let m = builtin("seed-ac");
    let p = probe_program(&m, &seed_poses(&m), &options(&m, Dialect::LinuxCnc)).unwrap();
    let text = synthetic_log(&m, &p.plan, Dialect::LinuxCnc, [0.0; 3]);
    let line = text.lines().nth(2).unwrap();
    line.split(' ')
        .next()
        .unwrap()
        .replacen(char::is_numeric, "x", 1)
}

#[test]
fn a_damaged_plan_is_refused_at_its_line_and_column() {
    let m = builtin("seed-ac");
    let p = probe_program(&m, &seed_poses(&m), &options(&m, Dialect::LinuxCnc)).unwrap();
    let text = format_probe_plan(&m, &p.plan, &[]).unwrap();
    assert_eq!(parse_probe_plan("p.csv", &text, &m).unwrap(), p.plan);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "pose,hit,X,Y,Z,A,C,nx,ny,nz,t_s,line");
    let edited = |k: usize, f: &dyn Fn(&str) -> String| {
        let mut l: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
        l[k] = f(&l[k]);
        parse_probe_plan("p.csv", &(l.join("\n") + "\n"), &m)
            .unwrap_err()
            .to_string()
    };
    let field = |k: usize, i: usize, v: &str| {
        edited(k, &|line: &str| {
            let mut f: Vec<&str> = line.split(',').collect();
            f[i] = v;
            f.join(",")
        })
    };
    assert_eq!(
        edited(0, &|h: &str| h.replace("nz", "nq")),
        "p.csv:1: column 10 `nq`: unknown column in a probe plan of machine seed-ac (columns pose,hit,X,Y,Z,A,C,nx,ny,nz,t_s,line)"
    );
    assert_eq!(
        edited(0, &|h: &str| h.replace(",line", ",x")),
        "p.csv:1: column 12 `x`: a second column `X` (also column 3)"
    );
    assert_eq!(
        field(2, 1, "3"),
        "p.csv:3: column 2 `hit`: hit 3 of pose `p1` where hit 2 belongs"
    );
    assert_eq!(
        field(2, 0, "p 1"),
        "p.csv:3: column 1 `pose`: `p 1`: a pose label is one token, without blanks, control characters or quotes (found ' ')"
    );
    assert_eq!(
        field(11, 0, "p1"),
        "p.csv:12: column 1 `pose`: pose `p1` comes back (it began at line 2): the hits of a pose are contiguous rows"
    );
    assert_eq!(
        field(3, 5, "1"),
        "p.csv:4: rotary axis A moves within pose `p1` (1 deg, 0 deg at line 2)"
    );
    assert_eq!(
        field(2, 7, "0.5"),
        "p.csv:3: column 8 `nx`: the direction has norm 1.118033988749895, not 1 within 0.000001"
    );
    assert_eq!(
        field(3, 10, "0.1"),
        format!(
            "p.csv:4: column 11 `t_s`: time goes backwards: 0.1 s after {} s at line 3",
            lines[2].split(',').nth(10).unwrap()
        )
    );
    assert_eq!(
        field(2, 2, "600"),
        "p.csv:3: the contact is refused: X = 600 mm outside its stroke -500 .. 500 mm"
    );
    assert_eq!(
        field(2, 3, "1mm"),
        "p.csv:3: column 4 `Y`: `1mm` is not a finite decimal number (mm)"
    );
    assert_eq!(
        field(3, 11, "2"),
        "p.csv:4: column 12 `line`: program line 2 is not after the previous hit's (68)"
    );
    assert_eq!(
        parse_probe_plan("p.csv", &format!("{}\n", lines[0]), &m)
            .unwrap_err()
            .to_string(),
        "p.csv:2: a probe plan with a header and no hit"
    );
}
