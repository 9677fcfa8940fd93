//! NC programs of commanded poses (`formats::nc`): read in both dialects, written back with
//! only the axis words changed; every refusal names the line, the column and the word; modal
//! axes, inserted words, decimals, signs and the rounding report; random programs round-trip.

use formats::nc::{Dialect, NcError, NcProgram, WriteOptions, parse_program};
use formats::poses::{AxisWord, axis_words};
use model_spec::AxisKind::{Linear, Rotary};
use proptest::prelude::*;

/// X Y Z A C, the axis letters of `seed-ac`, in this order.
fn xyzac() -> Vec<AxisWord> {
    let l = |letter| AxisWord {
        letter,
        kind: Linear,
    };
    let r = |letter| AxisWord {
        letter,
        kind: Rotary,
    };
    vec![l('X'), l('Y'), l('Z'), r('A'), r('C')]
}

fn iso(text: &str) -> Result<NcProgram, NcError> {
    parse_program("p.nc", text, Dialect::Iso, &xyzac())
}

fn hh(text: &str) -> Result<NcProgram, NcError> {
    parse_program("p.h", text, Dialect::Heidenhain, &xyzac())
}

fn commands(p: &NcProgram) -> Vec<Vec<f64>> {
    p.poses().iter().map(|q| q.commands.clone()).collect()
}

const ISO: &str = "%\n\
O1000 (R-TEST PATH K4)\n\
N10 G90 G21 G94 G17 G40 G49 G80\n\
N20 G0 X0 Y0 Z100. A0 C0 ; start position\n\
N30 G1 X-217.504 Y-0.279 Z211.537 F2000  \n\
N40 C1.5\n\
N50 A-0.0154 C3.000 M8\n\
\n\
(two axes in one block without spaces)\n\
N60G1X-217.5Y-0.28\n\
N70 M30\n\
%\n";

const HEIDENHAIN: &str = "0 BEGIN PGM K4 MM\n\
1 BLK FORM 0.1 Z X-500 Y-400 Z-500\n\
2 BLK FORM 0.2 X+500 Y+400 Z+500\n\
3 TOOL CALL 0 Z S0\n\
4 ; start position\n\
5 L X+0 Y+0 Z+100 A+0 C+0 R0 FMAX M3\n\
6 L X-217.504 Y-0.279 Z+211.537 R0 F2000\n\
7 L C+1.5\n\
8 L A-0.0154 C+3.000 ; two axes\n\
9 * - section\n\
10 CYCL DEF 9.0 DWELL TIME\n\
11 CYCL DEF 9.1 DWELL 1.5\n\
12 L  Z+150   FMAX\n\
13 STOP M30\n\
14 END PGM K4 MM\n";

#[test]
fn axis_words_follow_the_machine() {
    let m = model_spec::builtin("head-table-bc").unwrap().unwrap();
    let w = axis_words(&m);
    assert_eq!(w.len(), m.axes.len());
    for (a, w) in m.axes.iter().zip(&w) {
        assert_eq!(a.name, w.letter.to_string());
        assert_eq!(a.kind, w.kind);
    }
    assert!(w.iter().any(|a| a.letter == 'B' && a.kind == Rotary));
    // The order of the description: the work chain, then the tool chain.
    let order = |name: &str| -> String {
        axis_words(&model_spec::builtin(name).unwrap().unwrap())
            .iter()
            .map(|a| a.letter)
            .collect()
    };
    assert_eq!(order("head-table-bc"), "CXYZB");
    assert_eq!(order("seed-ac"), "XACYZ");
    assert_eq!(order("seed-3axis"), "YXZ");
}

#[test]
fn modal_poses_of_both_dialects() {
    let p = iso(ISO).unwrap();
    let lines: Vec<usize> = p.poses().iter().map(|q| q.line).collect();
    assert_eq!(lines, [4, 5, 6, 7, 10]);
    assert_eq!(
        commands(&p),
        [
            vec![0.0, 0.0, 100.0, 0.0, 0.0],
            vec![-217.504, -0.279, 211.537, 0.0, 0.0],
            vec![-217.504, -0.279, 211.537, 0.0, 1.5],
            vec![-217.504, -0.279, 211.537, -0.0154, 3.0],
            vec![-217.5, -0.28, 211.537, -0.0154, 3.0],
        ]
    );
    let h = hh(HEIDENHAIN).unwrap();
    let lines: Vec<usize> = h.poses().iter().map(|q| q.line).collect();
    assert_eq!(lines, [6, 7, 8, 9, 13]);
    assert_eq!(commands(&h)[..4], commands(&p)[..4]);
    assert_eq!(commands(&h)[4], [-217.504, -0.279, 150.0, -0.0154, 3.0]);
}

#[test]
fn unchanged_poses_give_the_same_bytes() {
    for (text, dialect) in [(ISO, Dialect::Iso), (HEIDENHAIN, Dialect::Heidenhain)] {
        for t in [
            text.to_string(),
            text.replace('\n', "\r\n"),
            format!("\u{feff}{}", text.trim_end()),
        ] {
            let p = parse_program("p", &t, dialect, &xyzac()).unwrap();
            for opts in [WriteOptions::new(), WriteOptions::with_min_decimals(4)] {
                let w = p.write(&commands(&p), &opts).unwrap();
                assert_eq!(w.text, t);
                assert_eq!(w.rounding, [0.0; 5]);
                assert_eq!((w.changed_words, w.inserted_words), (0, 0));
            }
        }
    }
}

/// `line` with the number of every axis word (`X`, `Y`, `Z`, `A`, `C` after a blank, a digit or
/// the line start) replaced by `#`: what must not change when only axis words do.
fn mask(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    let mut prev = ' ';
    while let Some(c) = chars.next() {
        out.push(c);
        if "XYZAC".contains(c) && (prev == ' ' || prev.is_ascii_digit() || prev == '.') {
            let mut any = false;
            while let Some(&d) = chars.peek() {
                if d.is_ascii_digit() || "+-.".contains(d) {
                    chars.next();
                    any = true;
                } else {
                    break;
                }
            }
            if any {
                out.push('#');
                prev = '0';
                continue;
            }
        }
        prev = c;
    }
    out
}

/// Whether masked line `y` is masked line `x` with axis words (` X#`, `Y#`) inserted right
/// after the last axis word of `x`.
fn only_inserted(x: &str, y: &str) -> bool {
    let i = x.rfind('#').map_or(0, |i| i + 1);
    let (head, tail) = x.split_at(i);
    let Some(middle) = y.strip_prefix(head).and_then(|r| r.strip_suffix(tail)) else {
        return false;
    };
    middle
        .replace(' ', "")
        .as_bytes()
        .chunks(2)
        .all(|w| w.len() == 2 && b"XYZAC".contains(&w[0]) && w[1] == b'#')
}

#[test]
fn corrected_poses_change_only_axis_words() {
    for (text, dialect) in [(ISO, Dialect::Iso), (HEIDENHAIN, Dialect::Heidenhain)] {
        for t in [text.to_string(), text.replace('\n', "\r\n")] {
            let p = parse_program("p", &t, dialect, &xyzac()).unwrap();
            // A correction that grows by more than the coarsest resolution (1 mm, 1°) from pose
            // to pose, so that modal axes change too.
            let corrected: Vec<Vec<f64>> = commands(&p)
                .iter()
                .enumerate()
                .map(|(k, c)| c.iter().map(|x| x + 0.7 + 1.1 * k as f64).collect())
                .collect();
            let w = p.write(&corrected, &WriteOptions::new()).unwrap();
            assert!(w.inserted_words > 0 && w.changed_words > 0);
            let a: Vec<&str> = t.split_inclusive('\n').collect();
            let b: Vec<&str> = w.text.split_inclusive('\n').collect();
            assert_eq!(a.len(), b.len());
            let posed: Vec<usize> = p.poses().iter().map(|q| q.line).collect();
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                if posed.contains(&(i + 1)) {
                    assert_ne!(x, y, "line {}", i + 1);
                    assert!(
                        only_inserted(&mask(x), &mask(y)),
                        "line {}: {x:?} -> {y:?}",
                        i + 1
                    );
                } else {
                    assert_eq!(x, y, "line {}", i + 1);
                }
            }
            // Read back, the program gives the corrected poses to its own resolution.
            let back = parse_program("p", &w.text, dialect, &xyzac()).unwrap();
            for (q, c) in back.poses().iter().zip(&corrected) {
                for (a, (x, y)) in q.commands.iter().zip(c).enumerate() {
                    assert!((x - y).abs() <= w.rounding[a] + 1e-12, "{x} {y}");
                }
            }
            assert!(
                w.rounding.iter().all(|&r| r <= 0.5 + 1e-12),
                "{:?}",
                w.rounding
            );
        }
    }
}

#[test]
fn words_keep_decimals_and_signs_and_modal_axes_are_inserted() {
    let t = "G90 G0 X0 Y0 Z100. A0 C0\nG1 X10.500 F100\nN5G1Y.25\n";
    let p = iso(t).unwrap();
    let c = vec![
        vec![0.0, 0.0, 100.0, 0.0, 0.0],
        vec![10.5004, 0.0, 100.0, 0.0, 0.0],
        vec![10.5004, 0.2512, 100.2, 0.0, 0.0],
    ];
    let w = p.write(&c, &WriteOptions::new()).unwrap();
    // X keeps its three decimals, Y its two without a leading zero; Z, modal in the last
    // block, rounds to the value in force at the resolution of the word that set it
    // (`Z100.`): nothing changes.
    assert_eq!(w.text, t);
    assert_eq!((w.changed_words, w.inserted_words), (0, 0));
    // With three decimals at least, Z is inserted after Y, without a space in a packed block.
    let w = p.write(&c, &WriteOptions::with_min_decimals(3)).unwrap();
    assert_eq!(
        w.text,
        "G90 G0 X0 Y0 Z100. A0 C0\nG1 X10.500 F100\nN5G1Y.251Z100.200\n"
    );
    assert_eq!((w.changed_words, w.inserted_words), (1, 1));
    assert!((w.rounding[1] - 0.0002).abs() < 1e-12);
    assert!((w.rounding[0] - 0.0004).abs() < 1e-12);

    let t = "1 L X+0 Y+0 Z+100 A+0 C+0 R0 FMAX\n2 L X+10.5 R0 F100 ; cut\n3 L C-90.000\n";
    let p = hh(t).unwrap();
    let c = vec![
        vec![0.0, -0.00004, 100.0, 0.0, 0.0],
        vec![10.5026, -0.0006, 100.0, -0.6, 0.0],
        vec![10.5026, -0.0006, 100.0, -0.6, -90.0011],
    ];
    // A correction that rounds to zero is written without a minus sign (line 1), the `+` of
    // the program is kept, and the modal Y and A are inserted in the order of the axes.
    let w = p.write(&c, &WriteOptions::with_min_decimals(3)).unwrap();
    assert_eq!(
        w.text,
        "1 L X+0 Y+0.000 Z+100 A+0 C+0 R0 FMAX\n\
         2 L X+10.503 Y-0.001 A-0.600 R0 F100 ; cut\n\
         3 L C-90.001\n"
    );
}

#[test]
fn unchanged_words_keep_their_text_and_rounding_is_reported() {
    let t = "G90 G0 X0 Y0 Z0 A0 C0\nG1 X1.25\n";
    let p = iso(t).unwrap();
    let c = vec![vec![0.0; 5], vec![1.2549, 0.3, 0.0, 0.0, 0.0]];
    let w = p.write(&c, &WriteOptions::new()).unwrap();
    // Y0 has no decimals: 0.3 rounds to the 0 in force, nothing inserted.
    assert_eq!(w.text, "G90 G0 X0 Y0 Z0 A0 C0\nG1 X1.25\n");
    assert!((w.rounding[0] - 0.0049).abs() < 1e-12);
    assert!((w.rounding[1] - 0.3).abs() < 1e-12);
}

#[test]
fn values_that_cannot_be_written_are_errors() {
    let p = iso("G90 G0 X0 Y0 Z0 A0 C0\n").unwrap();
    let e = p
        .write(
            &[vec![99_999.999_6, 0.0, 0.0, 0.0, 0.0]],
            &WriteOptions::with_min_decimals(3),
        )
        .unwrap_err();
    assert!(
        matches!(
            e,
            NcError::Value {
                line: 1,
                axis: 'X',
                ..
            }
        ),
        "{e}"
    );
    let e = p
        .write(&[vec![0.0, f64::NAN, 0.0, 0.0, 0.0]], &WriteOptions::new())
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("p.nc:1: axis Y: cannot write NaN"),
        "{e}"
    );
    let e = p.write(&[], &WriteOptions::new()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.nc: 0 corrected poses for the 1 poses of the program"
    );
    let e = p.write(&[vec![0.0; 4]], &WriteOptions::new()).unwrap_err();
    assert!(e.to_string().contains("4 values for 5 axes"), "{e}");
    let e = p
        .write(&[vec![0.0; 5]], &WriteOptions::with_min_decimals(10))
        .unwrap_err();
    assert!(e.to_string().contains("at most 9"), "{e}");
}

/// Checks that `result` is a refused block at `line` and `column`, about `word` (none when
/// empty), its message containing `why`.
fn refused(result: Result<NcProgram, NcError>, line: usize, column: usize, word: &str, why: &str) {
    let e = match result {
        Err(e @ NcError::Block { .. }) => e,
        other => panic!("expected a refused block, got {other:?}"),
    };
    let text = e.to_string();
    if let NcError::Block {
        line: l,
        column: c,
        word: w,
        message,
        ..
    } = e
    {
        assert_eq!((l, c), (line, column), "{text}");
        assert_eq!(w.as_deref(), (!word.is_empty()).then_some(word), "{text}");
        assert!(message.contains(why), "{text}");
        let located = match w {
            Some(w) => format!(":{line}:{column}: `{w}`: {message}"),
            None => format!(":{line}:{column}: {message}"),
        };
        assert!(text.ends_with(&located), "{text}");
    }
}

const START: &str = "N1 G90 G0 X0 Y0 Z0 A0 C0\n";

#[test]
fn iso_refusals_name_line_and_word() {
    let cases: &[(&str, usize, &str, &str)] = &[
        ("G91 G1 X1", 1, "G91", "incremental"),
        ("G2 X1 Y1 I1 J0", 1, "G2", "arcs"),
        ("G03 X1 Y1 R1", 1, "G03", "arcs"),
        ("G1 X1 I1", 7, "I1", "arc words"),
        ("G1 X1 R1", 7, "R1", "arc words"),
        ("G20", 1, "G20", "inch"),
        ("G92 X0", 1, "G92", "machine coordinates"),
        ("G52 X10", 1, "G52", "machine coordinates"),
        ("G54", 1, "G54", "machine coordinates"),
        ("G59", 1, "G59", "machine coordinates"),
        ("G54.1 P1", 1, "G54.1", "machine coordinates"),
        ("G68 X0 Y0 R30", 1, "G68", "rotation"),
        ("G43.4 H1", 1, "G43.4", "tool centre point"),
        ("G43.5 H1", 1, "G43.5", "tool centre point"),
        ("G43 H1 Z100", 1, "G43", "tool length"),
        ("G41 D1 X1", 1, "G41", "radius"),
        ("G28 X0", 1, "G28", "reference position"),
        ("G30 Z0", 1, "G30", "reference position"),
        ("G53 Z0", 1, "G53", "one-shot"),
        ("G81 Z-5 R1", 1, "G81", "canned cycles"),
        ("G5.1 Q1", 1, "G5.1", "not a G code rtest reads"),
        ("G1 U5", 4, "U5", "not an axis of this machine"),
        ("G1 B5", 4, "B5", "not an axis of this machine"),
        ("G1 W5", 4, "W5", "not an axis of this machine"),
        ("G1 X1 X2", 7, "X2", "second `X`"),
        ("G1 X1 F100 F200", 12, "F200", "second `F`"),
        ("G0 G1 X1", 4, "G1", "same mode"),
        ("G1 X1..2", 4, "X1..2", "cannot read the number"),
        ("G1 X#100", 4, "X#100", "cannot read the number"),
        ("G1 X1e3", 6, "e3", "not read in an ISO program"),
        ("M98 P100", 1, "M98", "subprogram"),
        ("G1 X1 H1", 7, "H1", "tool offset"),
        ("G4 X1.5", 4, "X1.5", "dwell"),
        ("G1 X1 P1", 7, "P1", "outside a dwell"),
        ("/G1 X1", 1, "/", "skip"),
        ("G1 X123456", 4, "X123456", "beyond"),
        ("G10 L2 P1 X0", 1, "G10", "machine coordinates"),
        ("G16", 1, "G16", "polar coordinates"),
        ("G51 X0 Y0 P2", 1, "G51", "scaling"),
        ("G50", 1, "G50", "scaling"),
        ("G51.1 X0", 1, "G51.1", "mirroring"),
        ("G68.2 X0 Y0 Z0 I0 J45 K0", 1, "G68.2", "rotation"),
        ("G44 H1", 1, "G44", "tool length"),
        ("G43.1 Z5", 1, "G43.1", "tool length"),
        ("G42 D1", 1, "G42", "radius"),
        ("G65 P9000", 1, "G65", "macro"),
        ("G7.1 C50", 1, "G7.1", "cylindrical"),
        ("G112", 1, "G112", "polar interpolation"),
        ("G73 Z-5 Q1", 1, "G73", "canned cycles"),
        ("M99", 1, "M99", "subprogram"),
        ("M198 P1", 1, "M198", "subprogram"),
        ("G1 X1 Q1", 7, "Q1", "not read in an ISO program"),
        ("G1 X1 L2", 7, "L2", "not read in an ISO program"),
        ("G1 X1 K1", 7, "K1", "arc words"),
        ("G1 X1 D1", 7, "D1", "tool offset"),
        ("G1 X1 M3.5", 7, "M3.5", "cannot read the number"),
        ("N3 G1 X1 N4", 10, "N4", "second `N`"),
        ("X1 [2]", 4, "[", "not part of an ISO word"),
        ("G1 X1 F-100", 7, "F-100", "a negative feed is meaningless"),
        ("G4 P-5", 4, "P-5", "a negative dwell time is meaningless"),
        ("T-1 M6", 1, "T-1", "a negative tool number is meaningless"),
        (
            "S-1000 M3",
            1,
            "S-1000",
            "a negative spindle speed is meaningless",
        ),
    ];
    for &(block, column, word, why) in cases {
        let text = format!("{START}N2 M3\n{block}\n");
        refused(iso(&text), 3, column, word, why);
    }
    refused(iso("G90 G1 X1 (open\n"), 1, 11, "", "does not close");
}

#[test]
fn heidenhain_refusals_name_line_and_word() {
    let cases: &[(&str, usize, &str, &str)] = &[
        ("3 L IX+5 R0", 5, "IX+5", "incremental"),
        ("3 CC X+0 Y+0", 3, "CC X+0 Y+0", "circles"),
        ("3 C X+1 Y+0 DR+", 3, "C X+1 Y+0 DR+", "circles"),
        ("3 CR X+1 Y+0 R+5 DR+", 3, "CR X+1 Y+0 R+5 DR+", "circles"),
        ("3 CT X+1 Y+0", 3, "CT X+1 Y+0", "circles"),
        ("3 CP PA+90 IZ+1", 3, "CP PA+90 IZ+1", "circles"),
        ("3 RND R5", 3, "RND R5", "roundings"),
        ("3 CHF 2", 3, "CHF 2", "chamfers"),
        (
            "3 LN X+1 Y+0 Z+0 NX+0 NY+0 NZ+1",
            3,
            "LN X+1 Y+0 Z+0 NX+0 NY+0 NZ+1",
            "vector",
        ),
        ("3 L X+1 R0 F100 M128", 17, "M128", "M128"),
        (
            "3 FUNCTION TCPM F TCP AXIS POS",
            3,
            "FUNCTION TCPM F TCP AXIS POS",
            "TCPM",
        ),
        (
            "3 CYCL DEF 7.0 DATUM SHIFT",
            3,
            "CYCL DEF 7.0 DATUM SHIFT",
            "datum shift",
        ),
        (
            "3 CYCL DEF 10.0 ROTATION",
            3,
            "CYCL DEF 10.0 ROTATION",
            "rotation",
        ),
        (
            "3 PLANE SPATIAL SPA+0 SPB+45 SPC+0",
            3,
            "PLANE SPATIAL SPA+0 SPB+45 SPC+0",
            "tilted",
        ),
        (
            "3 TRANS DATUM AXIS X+10",
            3,
            "TRANS DATUM AXIS X+10",
            "datum shift",
        ),
        ("3 BEGIN PGM A INCH", 3, "BEGIN PGM A INCH", "inch"),
        (
            "3 CYCL DEF 200 DRILLING",
            3,
            "CYCL DEF 200 DRILLING",
            "machining cycles",
        ),
        ("3 CALL LBL 1", 3, "CALL LBL 1", "labels and calls"),
        ("3 L X+1 U+5", 9, "U+5", "not an axis of this machine"),
        ("3 L X+1 B+5", 9, "B+5", "not an axis of this machine"),
        ("3 L X+1 X+2", 9, "X+2", "second `X`"),
        ("3 L X+1 RL", 9, "RL", "radius compensation"),
        ("3 L X+1.2.3", 5, "X+1.2.3", "cannot read the number"),
        ("3 L X+Q1", 5, "X+Q1", "cannot read the number"),
        ("3 L X+1 DL+1", 9, "DL+1", "not read in an L block"),
        ("3 LP PR+10 PA+45", 3, "LP PR+10 PA+45", "polar"),
        (
            "3 APPR LT X+1 Y+0 LEN5 RL",
            3,
            "APPR LT X+1 Y+0 LEN5 RL",
            "approach",
        ),
        ("3 DEP LT LEN5", 3, "DEP LT LEN5", "approach"),
        ("3 FL X+1 Y+2", 3, "FL X+1 Y+2", "free contour"),
        ("3 FN 0: Q1 = +5", 3, "FN 0: Q1 = +5", "Q parameter"),
        ("3 Q1 = 5", 3, "Q1 = 5", "Q parameters"),
        ("3 L X+1 M114", 9, "M114", "M114"),
        ("3 L X+1 M144", 9, "M144", "M144"),
        ("3 L X+1 M118", 9, "M118", "handwheel"),
        ("3 L Z+1 M140", 9, "M140", "retraction"),
        ("3 L X+1 M92", 9, "M92", "maker's reference"),
        ("3 L X+1 M99", 9, "M99", "cycle call"),
        ("3 L X+1 M89", 9, "M89", "cycle call"),
        ("3 L X+1 RR", 9, "RR", "radius compensation"),
        ("3 L X+1 R+", 9, "R+", "radius compensation"),
        ("3 L X+1 M3 M3", 12, "M3", "twice"),
        ("3 CYCL CALL", 3, "CYCL CALL", "cycle call"),
        (
            "3 CYCL DEF 8.0 MIRROR IMAGE",
            3,
            "CYCL DEF 8.0 MIRROR IMAGE",
            "mirroring",
        ),
        (
            "3 CYCL DEF 11.0 SCALING",
            3,
            "CYCL DEF 11.0 SCALING",
            "scaling",
        ),
        (
            "3 CYCL DEF 26.0 AXIS-SPEC. SCALING",
            3,
            "CYCL DEF 26.0 AXIS-SPEC. SCALING",
            "scaling",
        ),
        (
            "3 CYCL DEF 19.0 WORKING PLANE",
            3,
            "CYCL DEF 19.0 WORKING PLANE",
            "tilted",
        ),
        (
            "3 CYCL DEF 247 DATUM SETTING",
            3,
            "CYCL DEF 247 DATUM SETTING",
            "datum shift",
        ),
        (
            "3 TCH PROBE 400 BASIC ROTATION",
            3,
            "TCH PROBE 400 BASIC ROTATION",
            "probing",
        ),
        ("3 CALL PGM SUB", 3, "CALL PGM SUB", "calls"),
        ("3 LBL 1", 3, "LBL 1", "labels"),
        (
            "3 FUNCTION PARAXCOMP DISPLAY",
            3,
            "FUNCTION PARAXCOMP DISPLAY",
            "FUNCTION",
        ),
        ("3 l x+1", 3, "l x+1", "does not read"),
    ];
    for &(block, column, word, why) in cases {
        let text = format!("1 L X+0 Y+0 Z+0 A+0 C+0 R0 FMAX\n2 ; comment\n{block}\n");
        refused(hh(&text), 3, column, word, why);
    }
}

#[test]
fn a_move_before_every_axis_is_known_needs_a_start_position() {
    let e = iso("G90\nG0 X0 Y0 Z0\nG1 C10\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.nc:2:4: `X0`: a move with axis A, C not yet known: give a start position (a block that sets every axis, X, Y, Z, A, C) before the first move"
    );
    let e = hh("1 L Z+100 R0 FMAX\n").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("p.h:1:5: `Z+100`: a move with axis X, Y, A, C not yet known"),
        "{e}"
    );
    let e = iso("G0 X0 Y0 Z0 A0 C0\n").unwrap_err();
    assert!(e.to_string().contains("before G90"), "{e}");
}

#[test]
fn programs_without_moves_and_clashing_letters_are_refused() {
    let e = iso("%\nG90 G21\nM30\n%\n").unwrap_err();
    assert!(matches!(e, NcError::Program { .. }), "{e}");
    assert!(e.to_string().contains("no move"), "{e}");
    let mut axes = xyzac();
    axes[3].letter = 'F';
    let e = parse_program("p.nc", START, Dialect::Iso, &axes).unwrap_err();
    assert!(
        e.to_string()
            .contains("axis F, the letter of the feed word"),
        "{e}"
    );
    let e = parse_program("p.h", "1 L X+0\n", Dialect::Heidenhain, &axes).unwrap_err();
    assert!(e.to_string().contains("axis F"), "{e}");
    let long = format!("{START}({})\n", "x".repeat(70_000));
    let e = iso(&long).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("p.nc:2:1: line longer than 65536 bytes"),
        "{e}"
    );
}

/// Nothing after the end of a program is read: a block after `%` (the tape's end), `M30`, `M2`
/// or `END PGM` is refused, since the control would not run it; blank lines and a closing `%`
/// after the end pass. A line that ends with a carriage return alone is refused where it is.
#[test]
fn blocks_after_the_end_of_a_program_and_lone_carriage_returns_are_refused() {
    let after = "a block after the end of the program";
    refused(
        iso(&format!("%\n{START}G1 X1\n%\nG1 X2\n")),
        5,
        1,
        "",
        after,
    );
    refused(
        iso(&format!("{START}M30\nG1 X2\n")),
        3,
        1,
        "",
        "(`M30` at line 2)",
    );
    refused(
        iso(&format!("{START}G1 X1 M2\n\nG1 X2\n")),
        4,
        1,
        "",
        "(`M2` at line 2)",
    );
    let hh_text =
        "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 A+0 C+0 R0 FMAX\n2 END PGM T MM\n3 L X+5 R0 FMAX\n";
    refused(hh(hh_text), 4, 1, "", "(`END PGM` at line 3)");
    // What may follow the end.
    let p = iso(&format!("%\n{START}G1 X1\nM30\n%\n\n")).unwrap();
    assert_eq!(p.poses().len(), 2);
    let p = hh("0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 A+0 C+0 R0 FMAX\n2 END PGM T MM\n\n").unwrap();
    assert_eq!(p.poses().len(), 1);
    refused(
        iso(&format!("{START}G1 X1\rG1 X2\r")),
        2,
        6,
        "",
        "a carriage return inside a line",
    );
}

#[test]
fn lower_case_iso_letters_and_comments_pass() {
    let t = "g90 g0 x0 y0 z0 a0 c0 (HOME; X10)\ng1 x5. ; X7\n";
    let p = iso(t).unwrap();
    assert_eq!(p.poses()[1].commands[0], 5.0);
    let w = p
        .write(
            &[vec![0.0; 5], vec![5.25, 0.0, 0.0, 0.0, 0.0]],
            &WriteOptions::with_min_decimals(2),
        )
        .unwrap();
    assert_eq!(w.text, "g90 g0 x0 y0 z0 a0 c0 (HOME; X10)\ng1 x5.25 ; X7\n");
}

/// One random block of an allowed kind: (ISO text, Heidenhain text), each naming the axes
/// given with the numbers given.
fn block_texts(words: &[(usize, String)], extra: u8, n: usize) -> (String, String) {
    const L: [char; 5] = ['X', 'Y', 'Z', 'A', 'C'];
    let iso_words: Vec<String> = words.iter().map(|(a, t)| format!("{}{t}", L[*a])).collect();
    let hh_words: Vec<String> = words
        .iter()
        .map(|(a, t)| {
            let t = if t.starts_with('-') || t.starts_with('+') {
                t.clone()
            } else {
                format!("+{t}")
            };
            format!("{}{t}", L[*a])
        })
        .collect();
    let iso = match extra % 4 {
        0 => format!("N{n} G1 {} F1000", iso_words.join(" ")),
        1 => format!("G0 {} (rapid)", iso_words.join(" ")),
        2 => format!("N{n}{}", iso_words.concat()),
        _ => format!("{} M8 ; coolant", iso_words.join("  ")),
    };
    let hh = match extra % 3 {
        0 => format!("{n} L {} R0 FMAX", hh_words.join(" ")),
        1 => format!("{n} L {} R0 F500 M3 ; cut", hh_words.join(" ")),
        _ => format!("{n} L  {}", hh_words.join("  ")),
    };
    (iso, hh)
}

/// A number as a program may write it: up to five digits before the point (below 99 990, so
/// that a correction of ±2 stays writable), none to four after, with or without the point, a
/// `+`, a leading zero; never a negative zero.
fn number() -> impl Strategy<Value = String> {
    (
        any::<bool>(),
        0u32..99_990,
        prop::option::of(0usize..5),
        any::<u32>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(neg, int, decimals, frac, plus, lead)| {
            let d = decimals.unwrap_or(0);
            let frac = frac % 10u32.pow(d as u32);
            let sign = if neg && (int > 0 || frac > 0) {
                "-"
            } else if plus {
                "+"
            } else {
                ""
            };
            let int = if int == 0 && d > 0 && !lead {
                String::new()
            } else {
                int.to_string()
            };
            match decimals {
                None => format!("{sign}{int}"),
                Some(0) => format!("{sign}{int}."),
                Some(d) => format!("{sign}{int}.{frac:0d$}"),
            }
        })
}

/// A block: the axis words it names (axis index, number text).
type Words = Vec<(usize, String)>;

fn program() -> impl Strategy<Value = (Vec<Words>, Vec<u8>, bool)> {
    let block = prop::collection::btree_map(0usize..5, number(), 1..=5)
        .prop_map(|m| m.into_iter().collect::<Vec<_>>());
    (
        prop::collection::vec(block, 1..20),
        prop::collection::vec(any::<u8>(), 20),
        any::<bool>(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random programs of allowed blocks: written with the commands read, the text is the same;
    /// written with every command moved by far less than the last decimal, it is the same too
    /// (each word rewritten in its own style), and the rounding is that small move.
    #[test]
    fn random_programs_round_trip(
        (blocks, extras, crlf) in program(),
        shifts in prop::collection::vec(-2.0f64..2.0, 1..40),
    ) {
        let end = if crlf { "\r\n" } else { "\n" };
        let start: Vec<(usize, String)> = (0..5).map(|a| (a, "0".to_string())).collect();
        let (mut iso_text, mut hh_text) = (format!("%{end}G90 G21{end}"), format!("0 BEGIN PGM P MM{end}"));
        for (k, words) in std::iter::once(&start).chain(&blocks).enumerate() {
            let (i, h) = block_texts(words, extras[k % extras.len()], k + 1);
            iso_text += &format!("{i}{end}");
            hh_text += &format!("{h}{end}");
            if extras[k % extras.len()] % 5 == 0 {
                iso_text += &format!("(comment){end}");
                hh_text += &format!("* - part{end}");
            }
        }
        iso_text += &format!("M30{end}%{end}");
        hh_text += &format!("{} END PGM P MM{end}", blocks.len() + 2);
        for (text, dialect) in [(iso_text, Dialect::Iso), (hh_text, Dialect::Heidenhain)] {
            let p = parse_program("r", &text, dialect, &xyzac()).unwrap();
            prop_assert_eq!(p.poses().len(), blocks.len() + 1);
            let c = commands(&p);
            let w = p.write(&c, &WriteOptions::new()).unwrap();
            prop_assert_eq!(&w.text, &text);
            let nudged: Vec<Vec<f64>> = c
                .iter()
                .map(|v| v.iter().map(|x| x + 1e-7).collect())
                .collect();
            let w = p.write(&nudged, &WriteOptions::new()).unwrap();
            prop_assert_eq!(&w.text, &text);
            prop_assert!(w.rounding.iter().all(|&r| (r - 1e-7).abs() < 1e-9), "{:?}", w.rounding);
            // Corrections of up to ±2 (mm, degrees), different at every pose: read back, the
            // program gives each corrected pose to within the reported rounding, which is at
            // most half a unit of the coarsest word (1: a word without decimals).
            let moved: Vec<Vec<f64>> = c
                .iter()
                .enumerate()
                .map(|(k, v)| {
                    v.iter()
                        .enumerate()
                        .map(|(a, x)| x + shifts[(k * 5 + a) % shifts.len()])
                        .collect()
                })
                .collect();
            for min_decimals in [0, 4] {
                let w = p.write(&moved, &WriteOptions::with_min_decimals(min_decimals)).unwrap();
                let back = parse_program("r", &w.text, dialect, &xyzac()).unwrap();
                prop_assert_eq!(back.poses().len(), moved.len());
                for (q, m) in back.poses().iter().zip(&moved) {
                    for (a, (x, y)) in q.commands.iter().zip(m).enumerate() {
                        prop_assert!((x - y).abs() <= w.rounding[a] + 1e-9, "{} {} {:?}", x, y, w.rounding);
                    }
                }
                let bound = if min_decimals == 4 { 0.5e-4 } else { 0.5 };
                prop_assert!(w.rounding.iter().all(|&r| r <= bound + 1e-9), "{:?}", w.rounding);
                // Lines that do not move are untouched.
                let posed: Vec<usize> = p.poses().iter().map(|q| q.line).collect();
                for (i, (x, y)) in text.split_inclusive('\n').zip(w.text.split_inclusive('\n')).enumerate() {
                    if !posed.contains(&(i + 1)) {
                        prop_assert_eq!(x, y);
                    }
                }
            }
        }
    }
}

/// The corrected poses of the examples of `docs/nc-programs.md` (X Y Z mm, A C degrees).
fn documented_corrections() -> Vec<Vec<f64>> {
    vec![
        vec![-217.5062, -0.2771, 211.5384, 0.0011, -0.0008],
        vec![-217.5061, -0.2772, 211.5384, 0.0011, 1.4993],
        vec![-217.5058, -0.2774, 211.5386, -0.0142, 2.9991],
        vec![-217.5021, -0.2786, 211.5416, -0.0142, 2.9991],
    ]
}

#[test]
fn the_documented_examples() {
    let before = "%\n\
O1000 (R-TEST K4)\n\
N10 G90 G21 G94 G17 G40 G49 G80\n\
N20 G0 X-217.504 Y-0.279 Z211.537 A0.0000 C0.0000\n\
N30 G1 C1.5000 F2000\n\
N40 A-0.0154 C3.0000\n\
N50 X-217.500 Y-0.280 Z211.540\n\
N60 M30\n\
%\n";
    let after = "%\n\
O1000 (R-TEST K4)\n\
N10 G90 G21 G94 G17 G40 G49 G80\n\
N20 G0 X-217.506 Y-0.277 Z211.538 A0.0011 C-0.0008\n\
N30 G1 C1.4993 F2000\n\
N40 A-0.0142 C2.9991 Z211.539\n\
N50 X-217.502 Y-0.279 Z211.542\n\
N60 M30\n\
%\n";
    let w = iso(before)
        .unwrap()
        .write(&documented_corrections(), &WriteOptions::new())
        .unwrap();
    assert_eq!(w.text, after);
    let um: Vec<i64> = w
        .rounding
        .iter()
        .map(|r| (r * 1e4).round() as i64)
        .collect();
    assert_eq!(um, [2, 4, 4, 0, 0], "{:?}", w.rounding);

    let before = "0 BEGIN PGM K4 MM\n\
1 BLK FORM 0.1 Z X-500 Y-400 Z-500\n\
2 BLK FORM 0.2 X+500 Y+400 Z+500\n\
3 TOOL CALL 0 Z S0\n\
4 L X-217.504 Y-0.279 Z+211.537 A+0.0000 C+0.0000 R0 FMAX\n\
5 L C+1.5000 R0 F2000\n\
6 L A-0.0154 C+3.0000 ; two rotary axes\n\
7 L X-217.500 Y-0.280 Z+211.540\n\
8 STOP M30\n\
9 END PGM K4 MM\n";
    let after = "0 BEGIN PGM K4 MM\n\
1 BLK FORM 0.1 Z X-500 Y-400 Z-500\n\
2 BLK FORM 0.2 X+500 Y+400 Z+500\n\
3 TOOL CALL 0 Z S0\n\
4 L X-217.506 Y-0.277 Z+211.538 A+0.0011 C-0.0008 R0 FMAX\n\
5 L C+1.4993 R0 F2000\n\
6 L A-0.0142 C+2.9991 Z+211.539 ; two rotary axes\n\
7 L X-217.502 Y-0.279 Z+211.542\n\
8 STOP M30\n\
9 END PGM K4 MM\n";
    let w = hh(before)
        .unwrap()
        .write(&documented_corrections(), &WriteOptions::new())
        .unwrap();
    assert_eq!(w.text, after);
}

#[test]
fn what_passes_through() {
    let t = "%\nO1000\nG90 G93 G61 G9 G15 G69\nG95 G64\nG94\nG0 X0 Y0 Z0 A0 C0 T1 M6 S1000 M3 M8\nG4 P500\n/M1\nG1 X1 F100.5\n%\n";
    let p = iso(t).unwrap();
    assert_eq!(p.poses().len(), 2);
    assert_eq!(
        p.write(&commands(&p), &WriteOptions::new()).unwrap().text,
        t
    );
    let t = "0 BEGIN PGM A MM\n\
1 TOOL DEF 1 L+0 R+0\n\
2 TOOL CALL 1 Z S1000\n\
3 CYCL DEF 32.0 TOLERANCE\n\
4 CYCL DEF 32.1 T0.005\n\
5 FUNCTION RESET TCPM\n\
6 L X+0 Y+0 Z+0 A+0 C+0 R0 FAUTO M91\n\
7 L X+1 R0 FU0.1 M126 M3\n\
8 L Z+5 FZ0.05\n\
9 L R0 FMAX M5\n\
10 STOP\n\
11 END PGM A MM\n";
    let p = hh(t).unwrap();
    let lines: Vec<usize> = p.poses().iter().map(|q| q.line).collect();
    assert_eq!(lines, [7, 8, 9]);
    assert_eq!(
        p.write(&commands(&p), &WriteOptions::new()).unwrap().text,
        t
    );
}
