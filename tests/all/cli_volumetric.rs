//! End-to-end tests of `rtest volumetric`: laser files simulated on the exact virtual machine
//! written into a temporary directory, the binary run on them; the grid, the corrected path
//! and the summary checked against the library; every kind of bad input refused with one
//! stderr line, the right exit code and no output file.

use compensation::volumetric::path::correct_poses;
use compensation::volumetric::simulate::{LaserPlan, measure};
use compensation::volumetric::{
    VolumetricModel, correct, format_laser, format_squareness, parse_squareness,
};
use formats::poses::{axis_words, read_pose_csv};
use model_spec::Machine;
use serde_json::Value;

use crate::common;
use common::{TempDir, entries, fails, ok};

const TRUTH: &str = r#"
[parameters]
Xx = 50.0
Zx = 150.0
Zh = 120.0
Zt = 100.0

[errors]
EXX = { "poly:1" = 9.0, "poly:2" = 5.0 }
EYX = { "poly:2" = 4.0 }
EAX = { "poly:1" = 20.0 }
EBX = { "poly:1" = -30.0 }
EYY = { "poly:1" = -12.0 }
EBY = { "poly:2" = -35.0 }
ECY = { "poly:1" = 30.0 }
EZZ = { "poly:1" = 8.0 }
EXZ = { "poly:2" = 4.0 }
COX = 20.0
AOZ = -15.0
BOZ = 20.0
"#;

fn machine() -> Machine {
    model_spec::builtin("seed-3axis").unwrap().unwrap()
}

/// A directory with `x.csv`, `y.csv`, `z.csv` (21 positions per axis) and `sq.toml`, and the
/// model the library builds from them.
fn set_up(name: &str) -> (TempDir, VolumetricModel) {
    let m = machine();
    let dir = common::temp_dir_tagged("cli-vol", name);
    let t = formats::truth::parse_truth("t.toml", TRUTH, &m).unwrap();
    let s = measure(&m, &t, &LaserPlan::over_strokes(&m, 21).unwrap()).unwrap();
    for x in &s.measurements {
        let file = format!("{}.csv", m.axes[x.axis].name.to_lowercase());
        std::fs::write(dir.join(file), format_laser(&m, x, &["simulated".into()])).unwrap();
    }
    std::fs::write(
        dir.join("sq.toml"),
        format_squareness(&m, &s.squareness, &[]),
    )
    .unwrap();
    let model = VolumetricModel::new(&m, &s.measurements, &s.squareness).unwrap();
    (dir, model)
}

const BASE: [&str; 7] = [
    "volumetric",
    "--machine",
    "seed-3axis",
    "--laser",
    "X=x.csv,Y=y.csv,Z=z.csv",
    "--squareness",
    "sq.toml",
];

fn with(extra: &[&'static str]) -> Vec<&'static str> {
    BASE.iter().copied().chain(extra.iter().copied()).collect()
}

const PATH: &str = "N,X,Y,Z,F\n1,0,0,0,900\n2,-120.5,200,-50,900\n# end\n";

#[test]
fn grid_path_and_summary() {
    let m = machine();
    let (dir, model) = set_up("grid");
    std::fs::write(dir.join("p.csv"), PATH).unwrap();
    let out = ok(
        &dir,
        &with(&[
            "--grid", "grid.csv", "--pitch", "100", "--path", "p.csv", "-o", "out.csv",
        ]),
    );
    assert!(out.contains("Volumetric model of seed-3axis"), "{out}");
    assert!(
        out.contains("Over the grid (pitch 100 mm), 441 poses"),
        "{out}"
    );
    assert!(out.contains("Over the path, 2 poses"), "{out}");
    assert!(
        out.contains("Wrote grid.csv") && out.contains("Wrote out.csv"),
        "{out}"
    );
    // The grid: header, 9 × 7 × 7 rows, each the library's du.
    let grid = std::fs::read_to_string(dir.join("grid.csv")).unwrap();
    let rows: Vec<&str> = grid.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(rows[0], "X_mm,Y_mm,Z_mm,dx_um,dy_um,dz_um");
    assert_eq!(rows.len(), 1 + 9 * 7 * 7);
    let (xi, yi, zi) = (
        m.axis_by_name("X").unwrap(),
        m.axis_by_name("Y").unwrap(),
        m.axis_by_name("Z").unwrap(),
    );
    for row in &rows[1..] {
        let f: Vec<&str> = row.split(',').collect();
        let mut pose = vec![0.0; 3];
        pose[xi] = f[0].parse().unwrap();
        pose[yi] = f[1].parse().unwrap();
        pose[zi] = f[2].parse().unwrap();
        let du = model.du(&pose).unwrap();
        for i in 0..3 {
            let back = model_spec::units::parse_scaled(f[3 + i], -3).unwrap();
            assert_eq!(back, du[i], "{row}");
        }
    }
    // The corrected path: what the library writes.
    let written = std::fs::read_to_string(dir.join("out.csv")).unwrap();
    let table = read_pose_csv("p.csv", PATH, &axis_words(&m)).unwrap();
    let poses: Vec<(usize, Vec<f64>)> = table
        .poses()
        .iter()
        .map(|p| (p.line, p.commands.clone()))
        .collect();
    let corrected = correct_poses("p.csv", &m, &model, &poses).unwrap();
    let commands: Vec<Vec<f64>> = corrected.iter().map(|c| c.commands.clone()).collect();
    let expected = table.write(&commands).unwrap();
    assert_eq!(written, expected);
    assert!(written.starts_with("N,X,Y,Z,F\n1,") && written.ends_with(",900\n# end\n"));
}

#[test]
fn json_summary_and_the_flag_repeated() {
    let m = machine();
    let (dir, model) = set_up("json");
    let args = [
        "volumetric",
        "--machine",
        "seed-3axis",
        "--laser",
        "X=x.csv",
        "--laser",
        "y=y.csv,Z=z.csv",
        "--squareness",
        "sq.toml",
        "--json",
    ];
    let out = ok(&dir, &args);
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["machine"], "seed-3axis");
    assert_eq!(j["measurements"][0]["axis"], "X");
    assert_eq!(j["measurements"][0]["points"], 21);
    // The squareness the simulated measurement gives: the angle between the tool-point lines,
    // which holds the linear part of the Abbe terms besides the chain's COX.
    let sq = parse_squareness(
        "sq.toml",
        &std::fs::read_to_string(dir.join("sq.toml")).unwrap(),
        &m,
    )
    .unwrap();
    let cox = sq.values[0].1 * 1e6;
    assert!((j["squareness_urad"]["COX"].as_f64().unwrap() - cox).abs() < 1e-9);
    let set = &j["sets"][0];
    assert_eq!(set["over"], "lattice");
    assert_eq!(set["points"], 11 * 11 * 11);
    // The largest |du_x| over the lattice, recomputed with the library.
    let mut largest = 0.0f64;
    let mut largest_corr = 0.0f64;
    let axes: Vec<[f64; 2]> = (0..3).map(|a| model.measured_range(a).unwrap()).collect();
    for i in 0..11 {
        for j in 0..11 {
            for k in 0..11 {
                let at = |r: [f64; 2], n: usize| {
                    if n == 10 {
                        r[1]
                    } else {
                        r[0] + (r[1] - r[0]) * n as f64 / 10.0
                    }
                };
                let p = vec![at(axes[0], i), at(axes[1], j), at(axes[2], k)];
                largest = largest.max(model.du(&p).unwrap()[0].abs());
                let c = correct(&model, &p).unwrap();
                let x = m.axis_by_name("X").unwrap();
                largest_corr = largest_corr.max((c.commands[x] - p[x]).abs());
            }
        }
    }
    let got = set["error_um"]["x"]["max_abs"].as_f64().unwrap();
    assert!(
        (got - largest * 1e3).abs() < 1e-9,
        "{got} vs {}",
        largest * 1e3
    );
    let got = set["correction_um"]["X"]["max_abs"].as_f64().unwrap();
    assert!((got - largest_corr * 1e3).abs() < 1e-9);
    assert!(set["iterations_max"].as_u64().unwrap() >= 2);
    assert_eq!(entries(&dir), ["sq.toml", "x.csv", "y.csv", "z.csv"]);
}

#[test]
fn bad_input_is_refused_and_nothing_is_written() {
    let (dir, _) = set_up("bad");
    std::fs::write(dir.join("p.csv"), PATH).unwrap();
    let both = [
        "--grid", "grid.csv", "--pitch", "100", "--path", "off.csv", "-o", "out.csv",
    ];
    // A path pose whose correction leaves the stroke: exit 1, neither output written.
    std::fs::write(dir.join("off.csv"), "X,Y,Z\n0,0,0\n400,300,300\n400,-300,300\n-400,300,300\n-400,-300,300\n400,300,-300\n400,-300,-300\n-400,300,-300\n-400,-300,-300\n").unwrap();
    fails(
        &dir,
        &with(&both),
        1,
        &[
            "--path: off.csv:",
            "the corrected command",
            "outside the stroke",
        ],
    );
    assert!(!dir.join("grid.csv").exists() && !dir.join("out.csv").exists());
    // A malformed laser file: file, line and column.
    let x = std::fs::read_to_string(dir.join("x.csv")).unwrap();
    std::fs::write(dir.join("bad.csv"), x.replacen(",0,0,0,", ",0,0,zz,", 1)).unwrap();
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "X=bad.csv,Y=y.csv,Z=z.csv",
            "--squareness",
            "sq.toml",
        ],
        1,
        &["--laser: bad.csv:3: column 4 `EXX_um`: `zz` is not a finite number (µm)"],
    );
    // A missing axis, an unknown axis, an axis twice.
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "X=x.csv,Y=y.csv",
            "--squareness",
            "sq.toml",
        ],
        1,
        &["axis Z has no laser measurement"],
    );
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "X=x.csv,Q=y.csv",
            "--squareness",
            "sq.toml",
        ],
        2,
        &["--laser: `Q` is not a linear axis of seed-3axis"],
    );
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "X=x.csv,x=y.csv",
            "--squareness",
            "sq.toml",
        ],
        2,
        &["--laser: axis X is given twice"],
    );
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "x.csv",
            "--squareness",
            "sq.toml",
        ],
        2,
        &["--laser: `x.csv` is not AXIS=FILE"],
    );
    // The squareness file.
    std::fs::write(dir.join("sq2.toml"), "COX = 1\nAOZ = 2\n").unwrap();
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-3axis",
            "--laser",
            "X=x.csv,Y=y.csv,Z=z.csv",
            "--squareness",
            "sq2.toml",
        ],
        1,
        &["--squareness: sq2.toml:1:1: the squareness file misses BOZ"],
    );
    // A pitch that does not divide a range, a pitch that is no number, flags without partner.
    fails(
        &dir,
        &with(&["--grid", "g.csv", "--pitch", "30"]),
        2,
        &["--pitch: the grid pitch 30 mm does not divide"],
    );
    fails(
        &dir,
        &with(&["--grid", "g.csv", "--pitch", "-1"]),
        2,
        &["--pitch: `-1` is not a positive number of mm"],
    );
    fails(&dir, &with(&["--path", "p.csv"]), 2, &["-o"]);
    fails(&dir, &with(&["--grid", "g.csv"]), 2, &["--pitch"]);
    // An output that names an input.
    fails(
        &dir,
        &with(&["--path", "p.csv", "-o", "x.csv"]),
        2,
        &["x.csv"],
    );
    // A machine the model does not cover.
    fails(
        &dir,
        &[
            "volumetric",
            "--machine",
            "seed-ac",
            "--laser",
            "X=x.csv,Y=y.csv,Z=z.csv",
            "--squareness",
            "sq.toml",
        ],
        1,
        &[],
    );
    assert_eq!(
        entries(&dir),
        [
            "bad.csv", "off.csv", "p.csv", "sq.toml", "sq2.toml", "x.csv", "y.csv", "z.csv"
        ]
    );
}
