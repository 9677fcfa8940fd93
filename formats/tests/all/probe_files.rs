//! The touch-probe files (`formats::probe`): the probe hits CSV and the sphere centres CSV read
//! and written back bit for bit, every refusal with its exact message, the contiguity and
//! rotary rules of the hits, and damaged files refused without a panic.

use crate::common::{Rng, Scratch, builtin};
use formats::csv::CsvError;
use formats::probe::{
    ProbeHit, ProbeHits, ProbePose, SphereCentre, SphereCentres, format_probe_hits,
    format_sphere_centres, parse_probe_hits, parse_sphere_centres, read_probe_hits,
    read_sphere_centres,
};
use model_spec::{AxisKind, Machine};
use proptest::prelude::*;

const HITS: &str = "# probe cycle on the sphere, seed-ac\n\
# 2 poses\n\
pose,X,Y,Z,A,C,nx,ny,nz,t_s\n\
p1,10.5,-3.25,100,0,0,1,0,0,0.5\n\
p1,-14.5,-3.25,100,0,0,-1,0,0,1\n\
p1,-2,9.75,100,0,0,0,0.6,0.8,1.5\n\
a30c90,0.001,0.1,-12.75,30,90,0,0,-1,2\n";

const CENTRES: &str = "# centres fitted by the control\n\
pose,X,Y,Z,A,C,cx,cy,cz,u_cx,u_cy,u_cz,r\n\
p1,0,0,100,0,0,-2,-3.25,87.5,0.0005,0.0005,0.0008,12.4998\n\
a30c90,0,0,100,30,90,-2.003,-3.2499,87.5012,0.0006,0.0005,0.0009,12.5001\n";

fn machine() -> Machine {
    builtin("seed-ac")
}

fn axis(m: &Machine, name: &str) -> usize {
    m.axes.iter().position(|a| a.name == name).unwrap()
}

fn hits_err(text: &str) -> String {
    parse_probe_hits("h.csv", text, &machine())
        .unwrap_err()
        .to_string()
}

fn centres_err(text: &str) -> String {
    parse_sphere_centres("c.csv", text, &machine())
        .unwrap_err()
        .to_string()
}

/// `HITS` with its data row `i` (0-based) replaced by `row`.
fn hits_with(i: usize, row: &str) -> String {
    let mut lines: Vec<&str> = HITS.lines().collect();
    lines[3 + i] = row;
    lines.join("\n") + "\n"
}

#[test]
fn a_hits_file_is_grouped_by_pose_and_written_back_bit_for_bit() {
    let m = machine();
    let h = parse_probe_hits("h.csv", HITS, &m).unwrap();
    assert_eq!(h.poses.len(), 2);
    assert_eq!(h.hit_count(), 4);
    let p1 = &h.poses[0];
    assert_eq!(p1.label, "p1");
    assert_eq!(p1.hits.len(), 3);
    assert_eq!(p1.hits[2].line, 6);
    assert_eq!(p1.hits[2].direction, [0.0, 0.6, 0.8]);
    assert_eq!(p1.hits[0].axes[axis(&m, "X")], 10.5);
    let last = &h.poses[1].hits[0];
    assert_eq!(last.axes[axis(&m, "A")], 30.0);
    assert_eq!(last.axes[axis(&m, "C")], 90.0);
    assert_eq!(last.axes[axis(&m, "X")], 1e-3);
    assert_eq!(last.t_s, 2.0);
    let comments = vec![
        "probe cycle on the sphere, seed-ac".to_string(),
        "2 poses".to_string(),
    ];
    assert_eq!(format_probe_hits(&m, &h, &comments).unwrap(), HITS);
    // Another spelling of the same numbers reads the same bits; it is written the shortest way.
    let spelled = hits_with(3, "a30c90, 1E-3 ,+0.10,-12.750,30.0,9e1,0,-0,-1.0,2");
    let again = parse_probe_hits("h.csv", &spelled, &m).unwrap();
    assert_eq!(again.poses[1].hits[0].axes, last.axes);
    assert_eq!(
        again.poses[1].hits[0].direction[1].to_bits(),
        (-0.0f64).to_bits()
    );
}

#[test]
fn a_centres_file_reads_and_writes_back_with_and_without_its_optional_columns() {
    let m = machine();
    let c = parse_sphere_centres("c.csv", CENTRES, &m).unwrap();
    assert_eq!(c.poses.len(), 2);
    let p = &c.poses[1];
    assert_eq!((p.label.as_str(), p.line), ("a30c90", 4));
    assert_eq!(p.centre, [-2.003, -3.2499, 87.5012]);
    assert_eq!(p.uncertainty_mm, Some([0.0006, 0.0005, 0.0009]));
    assert_eq!(p.radius_mm, Some(12.5001));
    assert_eq!(p.axes[axis(&m, "A")], 30.0);
    let comments = vec!["centres fitted by the control".to_string()];
    assert_eq!(format_sphere_centres(&m, &c, &comments).unwrap(), CENTRES);

    let bare = "pose,X,Y,Z,A,C,cx,cy,cz\np1,0,0,100,0,0,-2,-3.25,87.5\n";
    let c = parse_sphere_centres("c.csv", bare, &m).unwrap();
    assert_eq!(c.poses[0].uncertainty_mm, None);
    assert_eq!(c.poses[0].radius_mm, None);
    assert_eq!(format_sphere_centres(&m, &c, &[]).unwrap(), bare);

    // Columns in another order, names in another case, a radius without uncertainties.
    let shuffled = "R, CZ,cy,cx,c,a,z,y,x,Pose\r\n12.5,1,2,3,0,0,0,0,0,q\r\n";
    let c = parse_sphere_centres("c.csv", shuffled, &m).unwrap();
    assert_eq!(c.poses[0].centre, [3.0, 2.0, 1.0]);
    assert_eq!(c.poses[0].radius_mm, Some(12.5));
    let back = format_sphere_centres(&m, &c, &[]).unwrap();
    assert_eq!(back, "pose,X,Y,Z,A,C,cx,cy,cz,r\nq,0,0,0,0,0,3,2,1,12.5\n");
}

/// Random hits of `m`: `poses` poses of up to 6 hits, axes within the limits, unit directions.
fn random_hits(m: &Machine, rng: &mut Rng, poses: usize) -> ProbeHits {
    let mut t = 0.0;
    let poses = (0..poses)
        .map(|i| {
            let rotary: Vec<f64> = m
                .axes
                .iter()
                .map(|a| {
                    let [lo, hi] = a.limits;
                    rng.range(lo.max(-360.0), hi.min(360.0))
                })
                .collect();
            let n = 1 + (rng.unit() * 6.0) as usize;
            let hits = (0..n)
                .map(|_| {
                    let axes = m
                        .axes
                        .iter()
                        .enumerate()
                        .map(|(a, axis)| match axis.kind {
                            AxisKind::Rotary => rotary[a],
                            AxisKind::Linear => {
                                let [lo, hi] = axis.limits;
                                rng.range(lo, hi)
                            }
                        })
                        .collect();
                    let v = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.5];
                    let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    t += rng.unit() * 0.3;
                    ProbeHit {
                        line: 0,
                        axes,
                        direction: v.map(|x| x / norm),
                        t_s: t,
                    }
                })
                .collect();
            ProbePose {
                label: format!("P{i}"),
                hits,
            }
        })
        .collect();
    ProbeHits { poses }
}

/// The hits without their lines, to compare what was written with what was read.
fn without_lines(h: &ProbeHits) -> ProbeHits {
    let mut h = h.clone();
    for p in &mut h.poses {
        for hit in &mut p.hits {
            hit.line = 0;
        }
    }
    h
}

fn bits(h: &ProbeHits) -> Vec<u64> {
    h.poses
        .iter()
        .flat_map(|p| &p.hits)
        .flat_map(|x| x.axes.iter().chain(&x.direction).chain([&x.t_s]))
        .map(|v| v.to_bits())
        .collect()
}

#[test]
fn random_hits_and_centres_read_back_bit_for_bit_through_a_file() {
    let m = machine();
    let dir = Scratch::new("probe-files");
    for seed in 0..20 {
        let mut rng = Rng::new(seed);
        let h = random_hits(&m, &mut rng, 1 + seed as usize % 7);
        let text = format_probe_hits(&m, &h, &["seed".to_string()]).unwrap();
        let path = dir.0.join(format!("hits-{seed}.csv"));
        std::fs::write(&path, &text).unwrap();
        let back = read_probe_hits(&path, &m).unwrap();
        assert_eq!(bits(&back), bits(&h));
        assert_eq!(without_lines(&back), h);
        assert_eq!(
            format_probe_hits(&m, &back, &["seed".to_string()]).unwrap(),
            text
        );

        let c = SphereCentres {
            poses: h
                .poses
                .iter()
                .map(|p| SphereCentre {
                    line: 0,
                    label: p.label.clone(),
                    axes: p.hits[0].axes.clone(),
                    centre: [rng.range(-500.0, 500.0), rng.unit(), -rng.unit() * 1e-7],
                    uncertainty_mm: (seed % 2 == 0)
                        .then(|| [rng.unit() + 1e-9, 1e-4 / 3.0, 0.1 + 0.2]),
                    radius_mm: (seed % 3 == 0).then(|| 12.5 + rng.unit() * 1e-3),
                })
                .collect(),
        };
        let text = format_sphere_centres(&m, &c, &[]).unwrap();
        let path = dir.0.join(format!("centres-{seed}.csv"));
        std::fs::write(&path, &text).unwrap();
        let mut back = read_sphere_centres(&path, &m).unwrap();
        for p in &mut back.poses {
            p.line = 0;
        }
        assert_eq!(back, c);
        for (a, b) in back.poses.iter().zip(&c.poses) {
            assert_eq!(a.centre.map(f64::to_bits), b.centre.map(f64::to_bits));
        }
    }
    let missing = dir.0.join("none.csv");
    let e = read_probe_hits(&missing, &m).unwrap_err();
    assert!(matches!(e, CsvError::Io { .. }), "{e}");
    assert!(
        e.to_string()
            .starts_with(&format!("cannot read `{}`", missing.display()))
    );
}

#[test]
fn the_hits_of_a_pose_must_be_contiguous_rows() {
    let text = format!("{HITS}p1,0,0,100,0,0,1,0,0,3\n");
    assert_eq!(
        hits_err(&text),
        "h.csv:8: column 1 `pose`: pose `p1` comes back: its hits are on lines 4 to 6, then pose `a30c90` begins at line 7; the hits of a pose must be contiguous rows"
    );
}

#[test]
fn the_rotary_axes_stand_still_within_a_pose() {
    let m = machine();
    // Within 1e-9 degrees: accepted; the pose keeps each hit's value.
    let text = hits_with(1, "p1,-14.5,-3.25,100,0,0.0000000005,-1,0,0,1");
    let h = parse_probe_hits("h.csv", &text, &m).unwrap();
    assert_eq!(h.poses[0].hits[1].axes[axis(&m, "C")], 5e-10);
    let text = hits_with(2, "p1,-2,9.75,100,0.000001,0,0,0.6,0.8,1.5");
    assert_eq!(
        hits_err(&text),
        "h.csv:6: column 5 `A`: rotary axis A is at 0.000001 deg, but at 0 deg at line 4, the pose's first hit: a probe cycle does not turn the rotary axes during a pose (tolerance 0.000000001 deg)"
    );
    // The linear axes move between hits: that is how a probe touches the sphere.
    assert!(parse_probe_hits("h.csv", HITS, &m).is_ok());
}

#[test]
fn every_refusal_of_a_hits_file_names_its_line_and_column() {
    let cols = "columns pose, X (mm), Y (mm), Z (mm), A (deg), C (deg), nx, ny, nz, t_s";
    let cases: Vec<(String, String)> = vec![
        (
            "# only a comment\n\n".into(),
            format!("h.csv:3: no header: a probe hits CSV names its columns in its first line that is not a comment ({cols})"),
        ),
        (
            "pose,X,Y,Z,A,C,nx,ny,nz,t_s,B\n".into(),
            format!("h.csv:1: column 11 `B`: unknown column in a probe hits CSV of machine seed-ac ({cols})"),
        ),
        (
            "pose,X,Y,Z,A,C,nx,ny,nz,t_s,x\n".into(),
            "h.csv:1: column 11 `x`: a second column `X` (also column 2)".into(),
        ),
        (
            "pose,X,Z,A,C,nx,ny,nz,t_s\n".into(),
            format!("h.csv:1: missing column(s) Y: a probe hits CSV of machine seed-ac has {cols}"),
        ),
        (
            "X,Y,Z,A,C,nx,ny,nz,t_s\n".into(),
            format!("h.csv:1: missing column(s) pose: a probe hits CSV of machine seed-ac has {cols}"),
        ),
        (
            "pose,X,Y,Z,A,C,nx,ny,nz\n".into(),
            "h.csv:1: missing column t_s: every hit gives its approach direction nx, ny, nz and its time t_s".into(),
        ),
        (
            "# c\npose,X,Y,Z,A,C,nx,ny,nz,t_s\n# no hit\n".into(),
            "h.csv:2: a header and no row: a probe hits CSV without data".into(),
        ),
        (
            hits_with(0, "p1,10.5,-3.25,100,0,0,1,0,0"),
            "h.csv:4: 9 field(s), the header (line 3) has 10 columns".into(),
        ),
        (
            hits_with(0, " ,10.5,-3.25,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 1 `pose`: empty: every row names its pose".into(),
        ),
        (
            hits_with(0, "p 1,10.5,-3.25,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 1 `pose`: `p 1`: a pose label is one token, without blanks, control characters or quotes (found ' ')".into(),
        ),
        (
            hits_with(0, "p1,10.5mm,-3.25,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 2 `X`: `10.5mm` is not a finite decimal number (mm)".into(),
        ),
        (
            hits_with(0, "p1,10.5,,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 3 `Y`: empty: a number (mm) belongs here".into(),
        ),
        (
            hits_with(0, "p1,10.5,-3.25,100,0,0,1,0,0,inf"),
            "h.csv:4: column 10 `t_s`: `inf` is not a finite decimal number (s)".into(),
        ),
        (
            hits_with(0, "p1,500.1,-3.25,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 2 `X`: 500.1 mm is outside the limits [-500, 500] mm of axis X of machine seed-ac".into(),
        ),
        (
            hits_with(0, "p1,10.5,-3.25,100,-120.5,0,1,0,0,0.5"),
            "h.csv:4: column 5 `A`: -120.5 deg is outside the limits [-120, 120] deg of axis A of machine seed-ac".into(),
        ),
        (
            hits_with(0, "p1,1e6,-3.25,100,0,0,1,0,0,0.5"),
            "h.csv:4: column 2 `X`: 1e6 mm is beyond ±100000 (no axis command reaches it)".into(),
        ),
        (
            hits_with(0, "p1,10.5,-3.25,100,0,0,1.00001,0,0,0.5"),
            "h.csv:4: column 7 `nx`: the approach direction (1.00001, 0, 0) has norm 1.00001, not 1 within 0.000001: give a unit vector (rtest normalises nothing)".into(),
        ),
        (
            hits_with(0, "p1,10.5,-3.25,100,0,0,0,0,0,0.5"),
            "h.csv:4: column 7 `nx`: the approach direction (0, 0, 0) has norm 0, not 1 within 0.000001: give a unit vector (rtest normalises nothing)".into(),
        ),
        (
            hits_with(1, "p1,-14.5,-3.25,100,0,0,-1,0,0,0.25"),
            "h.csv:5: column 10 `t_s`: time goes backwards: 0.25 s after 0.5 s at line 4".into(),
        ),
    ];
    for (text, message) in cases {
        assert_eq!(hits_err(&text), message, "for {text:?}");
    }
}

#[test]
fn every_refusal_of_a_centres_file_names_its_line_and_column() {
    let head = "pose,X,Y,Z,A,C,cx,cy,cz,u_cx,u_cy,u_cz,r\n";
    let cases: Vec<(String, &str)> = vec![
        (
            "pose,X,Y,Z,A,C,cx,cz\n".into(),
            "c.csv:1: missing column(s) cy: every pose gives its fitted centre cx, cy, cz (mm)",
        ),
        (
            "pose,X,Y,Z,A,C,cx,cy,cz,u_cx,u_cz\n".into(),
            "c.csv:1: missing column(s) u_cy: the uncertainties u_cx, u_cy, u_cz are given all three or none",
        ),
        (
            format!("{head}p1,0,0,100,0,0,1,2,3,0.001,0,0.001,12.5\n"),
            "c.csv:2: column 11 `u_cy`: a standard uncertainty must be above 0 mm, not 0",
        ),
        (
            format!("{head}p1,0,0,100,0,0,1,2,3,0.001,0.001,0.001,-12.5\n"),
            "c.csv:2: column 13 `r`: the fitted radius must be above 0 mm, not -12.5",
        ),
        (
            format!(
                "{head}p1,0,0,100,0,0,1,2,3,0.001,0.001,0.001,12.5\n#\np1,0,0,100,0,0,1,2,3,0.001,0.001,0.001,12.5\n"
            ),
            "c.csv:4: column 1 `pose`: pose `p1` is given twice (also line 2): one row per pose",
        ),
        (
            format!("{head}p1,0,0,100,0,0,1,2,3,0.001,0.001,0.001\n"),
            "c.csv:2: 12 field(s), the header (line 1) has 13 columns",
        ),
        (
            format!("{head}p1,0,0,100,0,0,1,2,x,0.001,0.001,0.001,12.5\n"),
            "c.csv:2: column 9 `cz`: `x` is not a finite decimal number (mm)",
        ),
        (
            head.into(),
            "c.csv:1: a header and no row: a sphere centres CSV without data",
        ),
    ];
    for (text, message) in cases {
        assert_eq!(centres_err(&text), message, "for {text:?}");
    }
}

#[test]
fn the_writers_refuse_what_the_readers_would() {
    let m = machine();
    let good = parse_probe_hits("h.csv", HITS, &m).unwrap();
    let mut h = good.clone();
    h.poses[0].hits[1].direction = [0.5, 0.0, 0.0];
    let e = format_probe_hits(&m, &h, &[]).unwrap_err().to_string();
    assert!(e.contains("norm 0.5, not 1"), "{e}");
    let mut h = good.clone();
    h.poses[1].label = "p1".into();
    assert!(
        format_probe_hits(&m, &h, &[])
            .unwrap_err()
            .to_string()
            .contains("given twice")
    );
    let mut h = good.clone();
    h.poses[0].hits[2].axes[axis(&m, "C")] = 1.0;
    let e = format_probe_hits(&m, &h, &[]).unwrap_err().to_string();
    assert!(e.contains("a rotary axis moves within the pose"), "{e}");
    let mut h = good.clone();
    h.poses[0].hits[0].t_s = f64::NAN;
    assert!(
        format_probe_hits(&m, &h, &[])
            .unwrap_err()
            .to_string()
            .contains("non-finite")
    );
    let mut h = good.clone();
    h.poses[0].hits.clear();
    assert!(
        format_probe_hits(&m, &h, &[])
            .unwrap_err()
            .to_string()
            .contains("has no hit")
    );

    let c = parse_sphere_centres("c.csv", CENTRES, &m).unwrap();
    let mut d = c.clone();
    d.poses[1].radius_mm = None;
    let e = format_sphere_centres(&m, &d, &[]).unwrap_err().to_string();
    assert!(e.contains("for every pose or for none"), "{e}");
    let mut d = c.clone();
    d.poses[0].axes[axis(&m, "Y")] = 400.5;
    let e = format_sphere_centres(&m, &d, &[]).unwrap_err().to_string();
    assert!(e.contains("axis Y at 400.5 is beyond its limits"), "{e}");
    let mut d = c;
    d.poses[0].label = "#x".into();
    assert!(format_sphere_centres(&m, &d, &[]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Bytes changed, inserted or removed anywhere in either file: read again, the file is
    /// refused with a message naming it, or read whole; never a panic.
    #[test]
    fn damaged_files_are_refused_or_read_never_a_panic(
        edits in proptest::collection::vec((0usize..400, any::<u8>(), 0u8..3), 1..6),
        centres in any::<bool>(),
    ) {
        let m = machine();
        let mut bytes = if centres { CENTRES } else { HITS }.as_bytes().to_vec();
        for (at, byte, how) in edits {
            let i = at % (bytes.len() + 1);
            match how {
                0 if i < bytes.len() => bytes[i] = byte,
                1 => bytes.insert(i, byte),
                _ if i < bytes.len() => { bytes.remove(i); }
                _ => bytes.push(byte),
            }
        }
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let dir = Scratch::new("probe-damaged");
        let path = dir.0.join("f.csv");
        std::fs::write(&path, &bytes).unwrap();
        if centres {
            for r in [parse_sphere_centres("f.csv", &text, &m).map(|_| ()), read_sphere_centres(&path, &m).map(|_| ())] {
                if let Err(e) = r {
                    prop_assert!(e.to_string().contains("f.csv"), "{e}");
                }
            }
        } else {
            for r in [parse_probe_hits("f.csv", &text, &m).map(|_| ()), read_probe_hits(&path, &m).map(|_| ())] {
                if let Err(e) = r {
                    prop_assert!(e.to_string().contains("f.csv"), "{e}");
                }
            }
        }
    }
}

#[test]
fn lines_too_long_or_not_utf8_are_refused_by_the_shared_line_reader() {
    let long = format!("{HITS}# {}\n", "x".repeat(70_000));
    assert_eq!(
        hits_err(&long),
        "h.csv:8: line longer than 65536 bytes: not a measurement CSV"
    );
    let dir = Scratch::new("probe-utf8");
    let path = dir.0.join("c.csv");
    let mut bytes = CENTRES.as_bytes().to_vec();
    bytes.extend_from_slice(b"p\xff,0,0,0,0,0,1,2,3,1,1,1,1\n");
    std::fs::write(&path, bytes).unwrap();
    let e = read_sphere_centres(&path, &machine())
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        format!("{}:5:2: not UTF-8 text (byte 0xff)", path.display())
    );
}
