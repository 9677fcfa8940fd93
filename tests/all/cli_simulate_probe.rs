//! `rtest simulate --probe`: probe hits CSVs the probe readers read back, their provenance and
//! summary, reproducibility, `-o -`, and the refusals (a bad probe file named at its line and
//! column, hits beyond a stroke, flags that belong to the R-test, an output directory one may
//! not write), none of which writes anything.

use crate::common::{self, check_fails, entries, fails, ok, run, stderr, stdout, words};
use formats::probe::read_probe_hits;
use model_spec::{Machine, Side};
use simulation::VirtualMachine;
use std::path::Path;

const PROBE: &str = "name = \"TS 460\"\ntip_radius_mm = 1.5\nsphere_radius_mm = 12.5\nnoise_um = 0.3\npre_travel_um = 1\nlobing_um = [0.5, 0]\n";

/// A fresh directory with `probe.toml` (above) and `poses.csv` (three poses of seed-ac).
fn setup(name: &str) -> common::TempDir {
    let dir = common::temp_dir_tagged("simprobe", name);
    std::fs::write(dir.join("probe.toml"), PROBE).unwrap();
    std::fs::write(dir.join("poses.csv"), "A,C\n0,0\n-30,90\n-60,200\n").unwrap();
    dir
}

fn seed_ac() -> Machine {
    model_spec::builtin("seed-ac").unwrap().unwrap()
}

/// The distance of the tip centre from the nominal sphere centre at `axes` (file units).
fn nominal_distance(m: &Machine, axes: &[f64]) -> f64 {
    let q = formats::poses::from_file_units(m, axes);
    let vm = VirtualMachine::new(m);
    let p = m.default_parameters();
    let tool = vm.nominal_chain_transform(Side::Tool, &q, &p);
    let work = vm.nominal_chain_transform(Side::Work, &q, &p);
    (tool.translation.vector - work.translation.vector).norm()
}

const SIM: &str = "simulate --machine seed-ac --path poses.csv --probe probe.toml";

#[test]
fn a_probe_run_writes_hits_the_probe_readers_read() {
    let dir = setup("writes");
    let out = ok(&dir, &words(&format!("{SIM} -o hits.csv")));
    assert!(
        out.starts_with("simulated probe hits on seed-ac at the poses of poses.csv (truth seed-ac-demo, probe TS 460, R_eff 14 mm, noise 0.3 µm, seed 1): 3 poses, 27 hits, 2 min 0 s on the machine; wrote hits.csv"),
        "{out}"
    );
    let m = seed_ac();
    let hits = read_probe_hits(&dir.join("hits.csv"), &m).unwrap();
    let labels: Vec<&str> = hits.poses.iter().map(|p| p.label.as_str()).collect();
    assert_eq!(labels, ["p1", "p2", "p3"]);
    assert_eq!(hits.hit_count(), 27);
    let (a, c) = (m.axis_by_name("A").unwrap(), m.axis_by_name("C").unwrap());
    // seed-ac's probe does not turn: the pattern stands in the bed frame, turned about the
    // stylus (z) by 0°, 22.5°, 45° pose after pose; the pole along −z at every pose.
    for ((pose, [want_a, want_c]), phi) in hits
        .poses
        .iter()
        .zip([[0.0, 0.0], [-30.0, 90.0], [-60.0, 200.0]])
        .zip([0.0f64, 22.5, 45.0])
    {
        for h in &pose.hits {
            // The rotary axes as the path gives them, written as the path wrote them.
            assert_eq!((h.axes[a], h.axes[c]), (want_a, want_c));
            // The demo truth's errors are tens of µm: every tip centre is within 0.2 mm of the
            // nominal sphere, and none is exactly on it.
            let d = nominal_distance(&m, &h.axes) - 14.0;
            assert!(d.abs() < 0.2 && d.abs() > 1e-7, "{d} mm");
        }
        let n = pose.hits[0].direction;
        let phi = phi.to_radians();
        assert!(
            (n[0] + phi.cos()).abs() < 1e-15 && (n[1] + phi.sin()).abs() < 1e-15 && n[2] == 0.0,
            "{n:?}"
        );
        assert_eq!(pose.hits[8].direction, [0.0, 0.0, -1.0]);
    }
    let text = std::fs::read_to_string(dir.join("hits.csv")).unwrap();
    for line in [
        "# machine: seed-ac",
        "# path: poses.csv (3 poses, labelled p1 to p3 in the path's order)",
        "# probe: TS 460: tip radius 1.5 mm, sphere radius 12.5 mm (R_eff 14 mm), pre-travel 1 µm, lobing [0.5, 0] µm, noise σ 0.3 µm along the approach from seed 1",
        "# pattern: 9 hits per pose about the nominal sphere centre (+x, +y, -x, -y of the probe at its height, four at R/2 above, the pole), defined in the probe's frame and turned by each pose's nominal tool rotation and by 0, 22.5, 45, 67.5° about the stylus pose after pose, each from 2 mm outside the sphere at 120 mm/min",
        "pose,X,Y,Z,A,C,nx,ny,nz,t_s",
    ] {
        assert!(text.lines().any(|l| l == line), "{line} not in:\n{text}");
    }
}

#[test]
fn runs_are_reproducible_and_the_seed_and_noise_flags_count() {
    let dir = setup("seeds");
    ok(&dir, &words(&format!("{SIM} -o a.csv")));
    ok(&dir, &words(&format!("{SIM} -o b.csv")));
    ok(&dir, &words(&format!("{SIM} --seed 2 -o c.csv")));
    ok(&dir, &words(&format!("{SIM} --noise-um 0 -o d.csv")));
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    assert_eq!(read("a.csv"), read("b.csv"));
    assert_ne!(read("a.csv"), read("c.csv"));
    let m = seed_ac();
    let noisy = read_probe_hits(&dir.join("a.csv"), &m).unwrap();
    let exact = read_probe_hits(&dir.join("d.csv"), &m).unwrap();
    let x = m.axis_by_name("X").unwrap();
    let moved = (noisy.poses[0].hits[0].axes[x] - exact.poses[0].hits[0].axes[x]).abs();
    assert!(moved > 0.0 && moved < 0.003, "{moved} mm");
    // `-o -`: the same bytes on standard output, the summary on standard error.
    let o = run(Some(&dir), &words(&format!("{SIM} -o -")));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(o.stdout, read("a.csv"));
    assert!(stderr(&o).starts_with("simulated probe hits on seed-ac"));
}

#[test]
fn a_built_in_path_gives_one_pose_per_sample() {
    let dir = setup("builtin");
    let out = ok(
        &dir,
        &words(
            "simulate --machine seed-ac --path K2 --probe probe.toml --truth seed-ac-reduced -o k2.csv",
        ),
    );
    assert!(out.contains("121 poses, 1089 hits"), "{out}");
    let hits = read_probe_hits(&dir.join("k2.csv"), &seed_ac()).unwrap();
    assert_eq!(hits.poses.len(), 121);
    assert_eq!(hits.poses[120].label, "p121");
}

#[test]
fn a_bad_probe_file_is_named_at_its_line_and_column_and_nothing_is_written() {
    let dir = setup("bad-probe");
    std::fs::write(
        dir.join("bad.toml"),
        "tip_radius_mm = 1.5\nsphere_radius_mm = -2\n",
    )
    .unwrap();
    let before = entries(&dir);
    fails(
        &dir,
        &words("simulate --machine seed-ac --path poses.csv --probe bad.toml -o hits.csv"),
        1,
        &["--probe: bad.toml:2:20: `sphere_radius_mm` is -2 mm"],
    );
    fails(
        &dir,
        &words("simulate --machine seed-ac --path poses.csv --probe none.toml -o hits.csv"),
        1,
        &["--probe", "none.toml"],
    );
    assert_eq!(entries(&dir), before);
}

#[test]
fn hits_beyond_a_stroke_or_the_clearance_are_a_failed_computation_and_nothing_is_written() {
    let dir = setup("stroke");
    let before = entries(&dir);
    // The ball 495 mm out along x: the pose is within X's stroke, the +X approach's start
    // point 16 mm beyond it is not.
    fails(
        &dir,
        &words(&format!("{SIM} --param Xw=-495 -o hits.csv")),
        3,
        &[
            "--path poses.csv: pose p1, hit 3 (approach (1, 0, 0)): the start point X = 511 mm outside its stroke -500 .. 500 mm; nothing is written",
        ],
    );
    assert_eq!(entries(&dir), before);
    // A ball set up 20 mm off: the probe would start inside it.
    std::fs::write(
        dir.join("far.toml"),
        "machine = \"seed-ac\"\n[errors]\nXOW = 20000\n",
    )
    .unwrap();
    let before = entries(&dir);
    fails(
        &dir,
        &words(&format!("{SIM} --truth far.toml -o hits.csv")),
        3,
        &[
            "--truth far.toml: pose p1, hit 1 (approach (-1, 0, 0)): the start point, 2 mm outside the nominal sphere, is 10000 µm inside the actual sphere: the machine's errors move the sphere by more than the clearance; nothing is written",
        ],
    );
    assert_eq!(entries(&dir), before);
}

#[test]
fn r_test_flags_are_refused_with_a_probe() {
    let dir = setup("flags");
    for flag in [
        "--zeroed",
        "--noise-phi 0.5",
        "--instrument orthogonal",
        "--commanded poses.csv",
    ] {
        let args = format!("{SIM} {flag} -o hits.csv");
        let o = run(Some(&dir), &words(&args));
        assert_eq!(o.status.code(), Some(2), "{args}: {}", stderr(&o));
        assert!(stderr(&o).contains("--probe"), "{args}: {}", stderr(&o));
    }
    assert!(!dir.join("hits.csv").exists());
}

#[test]
fn the_truths_instrument_terms_are_noted_as_unused() {
    let dir = setup("note");
    std::fs::write(
        dir.join("t.toml"),
        "machine = \"seed-ac\"\n[errors]\nXOC = 10\ndx0 = 2\nSXX = 0.001\n",
    )
    .unwrap();
    let args = format!("{SIM} --truth t.toml -o hits.csv");
    let o = run(Some(&dir), &words(&args));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        stderr(&o),
        "note: the truth's R-test instrument terms SXX act on sensor readings a probe has not: not used\n"
    );
    assert!(stdout(&o).contains("3 poses, 27 hits"));
}

#[test]
fn an_output_directory_one_may_not_write_is_refused_and_nothing_is_written() {
    use std::os::unix::fs::PermissionsExt;
    let dir = setup("read-only");
    let ro = dir.join("ro");
    std::fs::create_dir(&ro).unwrap();
    let mode = |p: &Path, m: u32| std::fs::set_permissions(p, std::fs::Permissions::from_mode(m));
    mode(&dir, 0o755).unwrap();
    mode(&ro, 0o555).unwrap();
    let line = format!("{SIM} -o ro/hits.csv");
    let args = words(&line);
    // As root every directory is writable: run as an ordinary user.
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_rtest"));
    c.args(&args).current_dir(&*dir);
    if std::fs::metadata("/proc/self")
        .map(|m| std::os::unix::fs::MetadataExt::uid(&m))
        .unwrap_or(1)
        == 0
    {
        std::os::unix::process::CommandExt::uid(&mut c, 65534);
        std::os::unix::process::CommandExt::gid(&mut c, 65534);
    }
    let o = c.output().expect("rtest runs");
    check_fails(&o, &args, 1, &["-o", "ro/hits.csv"]);
    assert!(entries(&ro).is_empty());
    mode(&ro, 0o755).unwrap();
}
