//! `rtest compensate --linuxcnc DIR`: the pins of LinuxCNC's trt module and the joint
//! compensation files written from an identification, what they do not hold listed, machines
//! the modules do not cover refused without writing anything. (What the files do in the real
//! LinuxCNC: `linuxcnc_oracle`.)

use crate::common;
use common::{TempDir, entries, fails, ok, words};

/// A directory with `id.json`: seed-ac's reduced model with `ECC@harmonic:2`, on K4 of the demo
/// truth.
fn seed_ac(name: &str) -> TempDir {
    common::seed_ac_identified("cli-linuxcnc", name, Some("ECC@harmonic:2"))
}

/// The value of `setp COMPONENT.PIN VALUE` in a HAL file.
fn pin(hal: &str, name: &str) -> f64 {
    let prefix = format!("setp xyzac-trt-kins.{name} ");
    let line = hal
        .lines()
        .find(|l| l.starts_with(&prefix))
        .unwrap_or_else(|| panic!("no {name} in\n{hal}"));
    line[prefix.len()..].parse().unwrap()
}

#[test]
fn seed_ac_gets_xyzac_pins_a_joint_file_for_c_and_the_list_of_what_they_do_not_hold() {
    let dir = seed_ac("seed-ac");
    let out = ok(
        &dir,
        &words("compensate --machine seed-ac --params id.json --linuxcnc lc --pitch-deg 10"),
    );
    assert!(
        out.contains(
            "LinuxCNC (xyzac-trt-kins, joints X=-X Y=Y Z=Z A=A C=C): kinematics.hal, joint_4.comp"
        ),
        "{out}"
    );
    for angular in ["BOA", "COA", "AOC", "BOC"] {
        assert!(
            out.contains(&format!("    {angular} = ")),
            "{angular}: {out}"
        );
    }
    assert_eq!(entries(&dir.join("lc")), ["joint_4.comp", "kinematics.hal"]);
    let hal = std::fs::read_to_string(dir.join("lc/kinematics.hal")).unwrap();
    // Every line is a comment or a setp of the module's seven pins.
    let setp: Vec<&str> = hal.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(setp.len(), 7, "{hal}");
    assert!(setp.iter().all(|l| l.starts_with("setp xyzac-trt-kins.")));
    for held in ["YOA", "ZOA", "XOC", "YOC"] {
        assert!(hal.contains(&format!("# Held: {held} = ")), "{held}: {hal}");
    }
    assert!(hal.contains("# Joint compensation: [JOINT_4] COMP_FILE = joint_4.comp"));
    // xyzac-trt-kins reads no x-offset; the y-offset is the distance between the axis lines,
    // tens of µm here (the identified YOA and YOC).
    assert_eq!(pin(&hal, "x-offset"), 0.0);
    assert!(pin(&hal, "y-offset").abs() > 1e-3 && pin(&hal, "y-offset").abs() < 0.1);
    // The joint file: three numbers per line, 0..360° every 10°, no header.
    let comp = std::fs::read_to_string(dir.join("lc/joint_4.comp")).unwrap();
    let rows: Vec<Vec<f64>> = comp
        .lines()
        .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 37);
    assert!(rows.iter().all(|r| r.len() == 3));
    assert_eq!((rows[0][0], rows[36][0]), (0.0, 360.0));
    // No reversal was identified: forward and reverse corrections agree.
    assert!(rows.iter().all(|r| r[1] == r[2]));
}

#[test]
fn a_joint_file_past_linuxcncs_256_points_is_refused_and_nothing_is_written() {
    let dir = seed_ac("too-fine");
    fails(
        &dir,
        &words("compensate --machine seed-ac --params id.json --linuxcnc lc --pitch-deg 1"),
        2,
        &[
            "--linuxcnc: axis C: joint 4: 361 points, more than the 256 LinuxCNC reads per joint",
            "--pitch-deg",
        ],
    );
    assert!(!dir.join("lc").exists() || entries(&dir.join("lc")).is_empty());
}

#[test]
fn a_machine_the_trt_modules_do_not_cover_is_refused_and_nothing_is_written() {
    let dir = common::temp_dir_tagged("cli-linuxcnc", "head-table");
    ok(
        &dir,
        &words("simulate --machine head-table-bc --path pair-B-C -o h.csv"),
    );
    ok(
        &dir,
        &words(
            "identify --machine head-table-bc --model location --data h.csv --constraint zero:AOZ,XOB,ZOB,XOC,YOC --json id.json",
        ),
    );
    fails(
        &dir,
        &words("compensate --machine head-table-bc --params id.json --linuxcnc lc"),
        2,
        &[
            "--linuxcnc: machine `head-table-bc` is not covered by LinuxCNC's xyzac-trt-kins or xyzbc-trt-kins",
            "is on the tool side",
        ],
    );
    assert!(!dir.join("lc").exists() || entries(&dir.join("lc")).is_empty());
}

/// The blocks of an ISG_CSV file: `(header, rows)`, comments and `#` breaks dropped.
fn isg_blocks(text: &str) -> Vec<(Vec<String>, Vec<Vec<f64>>)> {
    let mut blocks = Vec::new();
    for part in text.split("\n#\n") {
        let mut lines = part.lines().filter(|l| !l.starts_with("//"));
        let header: Vec<String> = lines
            .next()
            .unwrap()
            .split_whitespace()
            .map(String::from)
            .collect();
        let rows = lines
            .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
            .collect();
        blocks.push((header, rows));
    }
    blocks
}

#[test]
fn isg_gets_the_position_errors_and_a_block_per_axis_and_an_inclined_machine_is_refused() {
    let dir = seed_ac("isg");
    let out = ok(
        &dir,
        &words("compensate --machine seed-ac --params id.json --isg vol.csv --pitch-deg 30"),
    );
    assert!(
        out.contains(
            "ISG volumetric compensation: 2 blocks (Y0A Z0A B0A C0A X0C Y0C A0C B0C; C ECC)"
        ),
        "{out}"
    );
    let text = std::fs::read_to_string(dir.join("vol.csv")).unwrap();
    assert!(text.starts_with("// ISG volumetric compensation (ISG_CSV) of machine seed-ac"));
    let blocks = isg_blocks(&text);
    assert_eq!(blocks.len(), 2);
    assert_eq!(blocks[0].1.len(), 1);
    assert_eq!(blocks[0].1[0].len(), 8);
    // The location errors are tens of µm and µrad: mm and rad in the file.
    assert!(blocks[0].1[0].iter().all(|v| v.abs() < 0.1));
    assert_eq!(blocks[1].0, ["C", "ECC"]);
    assert_eq!(blocks[1].1.len(), 13);

    let dir = common::temp_dir_tagged("cli-linuxcnc", "isg-nutating");
    ok(
        &dir,
        &words("simulate --machine nutating-table-bc --path pair-B-C -o n.csv"),
    );
    ok(
        &dir,
        &words("identify --machine nutating-table-bc --model location --data n.csv --json id.json"),
    );
    fails(
        &dir,
        &words("compensate --machine nutating-table-bc --params id.json --isg vol.csv"),
        2,
        &[
            "--isg: machine `nutating-table-bc` is not covered by ISG's volumetric compensation: its axis B is inclined",
        ],
    );
    assert!(!dir.join("vol.csv").exists());
}
