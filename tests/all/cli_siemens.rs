//! `rtest compensate --siemens DIR [--carrier N]`: the swivel data record, the transformation's
//! machine data and the compensation tables written from an identification, what they do not
//! hold listed, machines no record covers, tables past the point limit and bad record numbers
//! refused without writing anything. (What the record does: `siemens_forward`.)

use crate::common;
use common::{TempDir, entries, fails, ok, words};

/// A directory with `id.json`: seed-ac's reduced model with `ECC@harmonic:2` and X's
/// straightness `EYX` and positioning `EXX` (linear in X), on K4 of the demo truth.
fn seed_ac(name: &str) -> TempDir {
    common::seed_ac_identified(
        "cli-siemens",
        name,
        Some("ECC@harmonic:2,EYX@poly:1,EXX@poly:1"),
    )
}

/// The lines of `text` that are not comments.
fn blocks(text: &str) -> Vec<&str> {
    text.lines().filter(|l| !l.starts_with(';')).collect()
}

#[test]
fn seed_ac_gets_its_record_the_trafo_data_and_tables_with_what_they_do_not_hold() {
    let dir = seed_ac("seed-ac");
    let out = ok(
        &dir,
        &words("compensate --machine seed-ac --params id.json --siemens sm --pitch-deg 10"),
    );
    assert!(
        out.contains(
            "Siemens (swivel data record 1, type P, X1 = -X, Y1 = Y, Z1 = Z, A1 = A, C1 = C): TC_CARR_1.MPF, TRAFO_1.INI, AX_EEC.INI, NC_CEC.INI"
        ),
        "{out}"
    );
    // A's angular location errors: seed-ac's A is along x, its direction is not turned.
    for angular in ["BOA", "COA"] {
        assert!(
            out.contains(&format!("    {angular} = ")),
            "{angular}: {out}"
        );
    }
    assert_eq!(
        entries(&dir.join("sm")),
        ["AX_EEC.INI", "NC_CEC.INI", "TC_CARR_1.MPF", "TRAFO_1.INI"]
    );
    let mpf = std::fs::read_to_string(dir.join("sm/TC_CARR_1.MPF")).unwrap();
    for held in ["YOA", "ZOA", "XOC", "YOC", "AOC", "BOC"] {
        assert!(mpf.contains(&format!("; Held: {held} = ")), "{held}: {mpf}");
    }
    assert!(mpf.contains("; Held in a table: AX_EEC.INI: ECC of axis C as $AA_ENC_COMP of C1"));
    assert!(mpf.contains("; Held in a table: AX_EEC.INI: EXX of axis X as $AA_ENC_COMP of X1"));
    assert!(
        mpf.contains("; Held in a table: NC_CEC.INI: EYX as $AN_CEC table 0, input X1, output Y1")
    );
    // Not held: per error, its value and why.
    let not_held = mpf.find("; Not held here").expect("the not-held list");
    for angular in ["BOA", "COA"] {
        let line = mpf[not_held..]
            .lines()
            .find(|l| l.starts_with(&format!(";   {angular} = ")))
            .unwrap_or_else(|| panic!("{angular}: {mpf}"));
        assert!(line.contains(" µrad: an angular location error"), "{line}");
    }
    // The blocks: the record's assignments and M30, nothing else.
    let b = blocks(&mpf);
    assert_eq!(*b.last().unwrap(), "M30");
    assert!(
        b[..b.len() - 1].iter().all(|l| l.starts_with("$TC_CARR")),
        "{mpf}"
    );
    assert!(mpf.contains("$TC_CARR23[1]=\"P\""));
    // No number in exponent notation.
    assert!(
        !b.iter().any(|l| l.contains("e-") || l.contains("e+")),
        "{mpf}"
    );

    let trafo = std::fs::read_to_string(dir.join("sm/TRAFO_1.INI")).unwrap();
    assert_eq!(
        blocks(&trafo),
        [
            "CHANDATA(1)",
            "$MC_TRAFO_TYPE_1=72 ; generic 5-axis transformation from a toolholder record",
            "$MC_TRAFO5_TCARR_NO_1=1 ; the swivel data record",
            "M17"
        ]
    );
    assert!(trafo.contains("NEW CONF or POWER ON"));

    let eec = std::fs::read_to_string(dir.join("sm/AX_EEC.INI")).unwrap();
    assert!(eec.starts_with("%_N_AX_EEC_INI\n"));
    assert!(eec.ends_with("M17\n"));
    // X1 over the stroke of X (-500 .. 500) every 10 mm; C1 modulo over 0 .. 360 every 10°.
    assert!(eec.contains("$AA_ENC_COMP_MIN[0,X1]=-500\n$AA_ENC_COMP_MAX[0,X1]=500\n"));
    assert!(eec.contains("$AA_ENC_COMP[0,100,X1]="));
    assert!(!eec.contains("$AA_ENC_COMP[0,101,X1]="));
    assert!(eec.contains("$AA_ENC_COMP_MAX[0,C1]=360\n$AA_ENC_COMP_IS_MODULO[0,C1]=1\n"));
    let cec = std::fs::read_to_string(dir.join("sm/NC_CEC.INI")).unwrap();
    assert!(cec.starts_with("%_N_NC_CEC_INI\n"));
    assert!(cec.contains("$AN_CEC_INPUT_AXIS[0]=(X1)\n$AN_CEC_OUTPUT_AXIS[0]=(Y1)\n"));
    assert!(cec.contains("SIGN NOT DOCUMENTED"));
}

#[test]
fn another_record_number_goes_into_every_index_and_the_trafo_data() {
    let dir = seed_ac("carrier");
    ok(
        &dir,
        &words(
            "compensate --machine seed-ac --params id.json --siemens sm --carrier 3 --pitch-deg 10",
        ),
    );
    let mpf = std::fs::read_to_string(dir.join("sm/TC_CARR_3.MPF")).unwrap();
    let assignments: Vec<&str> = blocks(&mpf)
        .iter()
        .flat_map(|l| l.split(';').next().unwrap().split_whitespace())
        .filter(|w| w.starts_with("$TC_CARR"))
        .collect();
    assert!(assignments.len() > 30);
    assert!(assignments.iter().all(|w| w.contains("[3]=")), "{mpf}");
    let trafo = std::fs::read_to_string(dir.join("sm/TRAFO_1.INI")).unwrap();
    assert!(trafo.contains("$MC_TRAFO5_TCARR_NO_1=3 "));
}

#[test]
fn bad_record_numbers_are_refused_and_nothing_is_written() {
    let dir = seed_ac("bad-carrier");
    fails(
        &dir,
        &words("compensate --machine seed-ac --params id.json --siemens sm --carrier 0"),
        2,
        &["--carrier 0: swivel data records are numbered from 1"],
    );
    for bad in ["-1", "1.5", "x", "4294967296"] {
        let flag = format!("--carrier={bad}");
        fails(
            &dir,
            &[
                "compensate",
                "--machine",
                "seed-ac",
                "--params",
                "id.json",
                "--siemens",
                "sm",
                &flag,
            ],
            2,
            &["--carrier"],
        );
    }
    fails(
        &dir,
        &words("compensate --machine seed-ac --params id.json --tables t --carrier 2"),
        2,
        &["--siemens"],
    );
    assert!(!dir.join("sm").exists() || entries(&dir.join("sm")).is_empty());
    assert!(!dir.join("t").exists() || entries(&dir.join("t")).is_empty());
}

#[test]
fn a_table_past_the_point_limit_is_refused_naming_the_pitch_and_nothing_is_written() {
    let dir = seed_ac("too-fine");
    fails(
        &dir,
        &words("compensate --machine seed-ac --params id.json --siemens sm --pitch 2"),
        2,
        &[
            "--siemens: the table of ",
            "over axis X would have 501 points at a pitch of 2 mm, more than the 200 written per table",
            "choose a coarser --pitch",
        ],
    );
    assert!(!dir.join("sm").exists() || entries(&dir.join("sm")).is_empty());
}

#[test]
fn a_machine_no_record_covers_is_refused_and_nothing_is_written() {
    let dir = common::temp_dir_tagged("cli-siemens", "four-axis");
    ok(
        &dir,
        &words("simulate --machine horizontal-4axis-b --path turn-B -o h.csv"),
    );
    ok(
        &dir,
        &words(
            "identify --machine horizontal-4axis-b --model location --data h.csv --constraint zero:COY,AOZ,XOB,ZOB --json id.json",
        ),
    );
    fails(
        &dir,
        &words("compensate --machine horizontal-4axis-b --params id.json --siemens sm"),
        2,
        &[
            "--siemens: machine `horizontal-4axis-b` is not covered by a SINUMERIK swivel data record",
            "this machine has 3 linear and 1 rotary",
        ],
    );
    assert!(!dir.join("sm").exists() || entries(&dir.join("sm")).is_empty());
}
