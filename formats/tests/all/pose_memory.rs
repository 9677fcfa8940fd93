//! Poses held flat: the limit on their number, what a program or a pose CSV holds per pose,
//! and the writers fed pose after pose giving the text back.

use formats::nc::{Dialect, NcError, WriteOptions, parse_program};
use formats::poses::{AxisWord, MAX_POSES, PoseCsvError, read_pose_csv};
use model_spec::AxisKind::{Linear, Rotary};
use proptest::prelude::*;

fn xyzac() -> Vec<AxisWord> {
    let w = |letter, kind| AxisWord { letter, kind };
    vec![
        w('X', Linear),
        w('Y', Linear),
        w('Z', Linear),
        w('A', Rotary),
        w('C', Rotary),
    ]
}

/// The reader itself refuses a program of one pose more than [`MAX_POSES`]: a start position
/// and then `C1` blocks (3 bytes a pose). It counts the poses before holding any, so the test
/// holds the text alone.
#[test]
fn the_reader_checks_the_real_pose_limit() {
    let mut text = String::with_capacity(3 * MAX_POSES + 64);
    text.push_str("G90 G1 X0 Y0 Z0 A0 C0\n");
    for _ in 0..MAX_POSES {
        text.push_str("C1\n");
    }
    let e = parse_program("long.nc", &text, Dialect::Iso, &xyzac()).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "long.nc: more than {MAX_POSES} poses (blocks that move; line {} holds the first beyond): rtest reads at most {MAX_POSES} poses from one program; split it",
            MAX_POSES + 1
        )
    );
}

/// What a program or a pose CSV holds besides its text is its poses, flat: 8 bytes per axis
/// and 4 per pose (44 for five axes), within 64 bytes a pose, on files of the shortest moves.
#[test]
fn held_bytes_per_pose() {
    let n = 20_000;
    let mut iso = String::from("%\nG90 G1 X0 Y0 Z0 A0 C0\n");
    let mut hh = String::from("0 BEGIN PGM P MM\n1 L X+0 Y+0 Z+0 A+0 C+0 R0 FMAX\n");
    let mut csv = String::from("X,Y,Z,A,C\n");
    for i in 1..n {
        iso += if i % 2 == 1 { "C1\n" } else { "C2\n" };
        hh += &format!("{} L C+{}\n", i + 1, i % 2 + 1);
    }
    for i in 0..n {
        csv += &format!("0,0,0,0,{}\n", i % 2);
    }
    iso += "M30\n%\n";
    hh += &format!("{} END PGM P MM\n", n + 1);
    let programs = [(iso, Dialect::Iso), (hh, Dialect::Heidenhain)];
    for (text, dialect) in &programs {
        let p = parse_program("p", text, *dialect, &xyzac()).unwrap();
        assert_eq!(p.pose_list().len(), n);
        assert_eq!(p.pose_list().held_bytes(), 44 * n);
        assert!(
            p.held_bytes() <= 64 * n + text.len(),
            "{dialect:?}: {} bytes for {n} poses and {} of text",
            p.held_bytes(),
            text.len()
        );
    }
    let t = read_pose_csv("p.csv", &csv, &xyzac()).unwrap();
    assert_eq!(t.pose_list().len(), n);
    assert_eq!(t.pose_list().held_bytes(), 44 * n);
    assert!(t.held_bytes() <= 64 * n + csv.len(), "{}", t.held_bytes());
}

/// The writers take one pose at a time: one too many, or one too few, is refused.
#[test]
fn writers_count_the_poses_given() {
    let text = "G90 G1 X0 Y0 Z0 A0 C0\nC1\n";
    let p = parse_program("p.nc", text, Dialect::Iso, &xyzac()).unwrap();
    let mut w = p.writer(&WriteOptions::new()).unwrap();
    w.pose(&[0.0; 5]).unwrap();
    let e = w.finish().unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.nc: 1 corrected poses for the 2 poses of the program"
    );
    let mut w = p.writer(&WriteOptions::new()).unwrap();
    for q in p.pose_list().iter().map(|(_, q)| q) {
        w.pose(q).unwrap();
    }
    let e = w.pose(&[0.0; 5]).unwrap_err();
    assert!(matches!(e, NcError::Program { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        "p.nc: more corrected poses than the 2 poses of the program"
    );
    assert!(p.writer(&WriteOptions::with_min_decimals(10)).is_err());

    let t = read_pose_csv("p.csv", "X,Y,Z,A,C\n1,2,3,4,5\n", &xyzac()).unwrap();
    let w = t.writer();
    let e = w.finish().unwrap_err();
    assert_eq!(
        e.to_string(),
        "p.csv: cannot write the poses: 0 corrected poses for 1 rows"
    );
    let mut w = t.writer();
    w.pose(&[1.0, 2.0, 3.0, 4.0, 5.5]).unwrap();
    let e = w.pose(&[0.0; 5]).unwrap_err();
    assert!(matches!(e, PoseCsvError::Write { .. }), "{e}");
    let mut w = t.writer();
    w.pose(&[1.0, 2.0, 3.0, 4.0, 5.5]).unwrap();
    assert_eq!(w.finish().unwrap(), "X,Y,Z,A,C\n1,2,3,4,5.5\n");
}

/// A number as a program writes it (`-12.5`, `+.25`, `7.`, `010.50`), and its value.
fn nc_number() -> impl Strategy<Value = (String, f64)> {
    (
        any::<bool>(),
        0u32..99_990,
        prop::option::of(0usize..5),
        any::<u32>(),
        any::<bool>(),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(neg, int, decimals, frac, plus, lead, pad)| {
            let d = decimals.unwrap_or(0);
            let frac = frac % 10u32.pow(d as u32);
            let sign = if neg && (int > 0 || frac > 0) {
                "-"
            } else if plus {
                "+"
            } else {
                ""
            };
            let int = match (int, d > 0 && !lead, pad) {
                (0, true, _) => String::new(),
                (i, _, true) => format!("0{i}"),
                (i, _, false) => i.to_string(),
            };
            let text = match decimals {
                None => format!("{sign}{int}"),
                Some(0) => format!("{sign}{int}."),
                Some(d) => format!("{sign}{int}.{frac:0d$}"),
            };
            let value = text.parse().unwrap();
            (text, value)
        })
}

/// A line of a program: `Some(words)` a block naming these axes (index, number), `None` a line
/// that does not move; with a flavour byte for block numbers, feeds, spaces and comments.
type Line = (Option<Vec<(usize, (String, f64))>>, u8);

fn program_lines() -> impl Strategy<Value = Vec<Line>> {
    let words = prop::collection::btree_map(0usize..5, nc_number(), 1..=5)
        .prop_map(|m| m.into_iter().collect::<Vec<_>>());
    prop::collection::vec((prop::option::weighted(0.8, words), any::<u8>()), 1..40)
}

/// The ISO and Heidenhain texts of `lines` after a start position, line ends `end`, and the
/// poses they command.
fn program_texts(lines: &[Line], end: &str) -> (String, String, Vec<[f64; 5]>) {
    let letters = ['X', 'Y', 'Z', 'A', 'C'];
    let mut iso = format!("%{end}O1 (RANDOM){end}G90 G21 G0 X0 Y0 Z0 A0 C0{end}");
    let mut hh = format!("0 BEGIN PGM R MM{end}1 L X+0 Y+0 Z+0 A+0 C+0 R0 FMAX{end}");
    let mut poses = vec![[0.0; 5]];
    for (k, (words, flavour)) in lines.iter().enumerate() {
        let n = k + 2;
        let Some(words) = words else {
            match flavour % 3 {
                0 => {
                    iso += &format!("(NO MOVE {n}){end}");
                    hh += &format!("; no move {n}{end}");
                }
                1 => {
                    iso += end;
                    hh += end;
                }
                _ => {
                    iso += &format!("N{n} M8 S1000{end}");
                    hh += &format!("{n} TOOL CALL 0 Z S1000{end}");
                }
            }
            continue;
        };
        let mut pose = *poses.last().unwrap();
        let sep = if flavour % 4 == 0 { "" } else { " " };
        let iso_words: Vec<String> = words
            .iter()
            .map(|(a, (t, _))| format!("{}{t}", letters[*a]))
            .collect();
        let hh_words: Vec<String> = words
            .iter()
            .map(|(a, (t, _))| {
                let t = if t.starts_with(['-', '+']) {
                    t.clone()
                } else {
                    format!("+{t}")
                };
                format!("{}{t}", letters[*a])
            })
            .collect();
        for (a, (_, v)) in words {
            pose[*a] = *v;
        }
        poses.push(pose);
        iso += &match flavour % 3 {
            0 => format!("N{n}{sep}G1{sep}{}{end}", iso_words.join(sep)),
            1 => format!("{} F{} (cut){end}", iso_words.join(" "), flavour),
            _ => format!("{}  ; note{end}", iso_words.join("  ")),
        };
        hh += &match flavour % 2 {
            0 => format!("{n} L {} R0 F{flavour} M3 ; cut{end}", hh_words.join(" ")),
            _ => format!("{n} L  {}{end}", hh_words.join("  ")),
        };
    }
    iso += &format!("M30{end}%{end}");
    hh += &format!("{} END PGM R MM{end}", lines.len() + 2);
    (iso, hh, poses)
}

/// A CSV of `rows` (values of X Y Z A C) with the axis columns in the order `order`, an `id`
/// and a `note` column, fields spaced or quoted as `flavours` say, comment and blank lines.
fn csv_text(rows: &[([f64; 5], u8)], order: &[usize], end: &str) -> String {
    let letters = ['X', 'Y', 'Z', 'A', 'C'];
    let mut header = vec!["id".to_string()];
    header.extend(order.iter().map(|&a| letters[a].to_string()));
    header.push("\"note, free\"".into());
    let mut text = format!("# poses{end}{}{end}", header.join(","));
    for (k, (row, flavour)) in rows.iter().enumerate() {
        let mut fields = vec![k.to_string()];
        for &a in order {
            let v = row[a];
            fields.push(match (flavour >> a) % 4 {
                0 => format!("{v}"),
                1 => format!(" {v} "),
                2 => format!("\"{v}\""),
                _ => format!("{v:e}"),
            });
        }
        fields.push(format!("\"row {k}, \"\"quoted\"\"\""));
        text += &format!("{}{end}", fields.join(","));
        if flavour % 7 == 0 {
            text += &format!("{end}# a comment{end}");
        }
    }
    text
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random programs: the flat list holds the poses the text commands (the modal rule), and
    /// the writer given those poses one at a time writes the text back byte for byte.
    #[test]
    fn flat_programs_round_trip(lines in program_lines(), crlf in any::<bool>()) {
        let end = if crlf { "\r\n" } else { "\n" };
        let (iso, hh, poses) = program_texts(&lines, end);
        for (text, dialect) in [(iso, Dialect::Iso), (hh, Dialect::Heidenhain)] {
            let p = parse_program("r", &text, dialect, &xyzac()).unwrap();
            let list = p.pose_list();
            prop_assert_eq!(list.len(), poses.len());
            for (i, pose) in poses.iter().enumerate() {
                prop_assert_eq!(list.commands(i), pose.as_slice());
            }
            let mut w = p.writer(&WriteOptions::new()).unwrap();
            for (_, q) in list.iter() {
                w.pose(q).unwrap();
            }
            let written = w.finish().unwrap();
            prop_assert_eq!(&written.text, &text);
            prop_assert_eq!((written.changed_words, written.inserted_words), (0, 0));
            prop_assert!(p.held_bytes() <= text.len() + 64 * list.len() + 64);
        }
    }

    /// Random pose CSVs: the same, for the rows.
    #[test]
    fn flat_tables_round_trip(
        rows in prop::collection::vec(
            (prop::array::uniform5(-99_999.0f64..99_999.0), any::<u8>()),
            1..40,
        ),
        order in Just(vec![0usize, 1, 2, 3, 4]).prop_shuffle(),
        crlf in any::<bool>(),
    ) {
        let end = if crlf { "\r\n" } else { "\n" };
        let text = csv_text(&rows, &order, end);
        let t = read_pose_csv("r.csv", &text, &xyzac()).unwrap();
        let list = t.pose_list();
        prop_assert_eq!(list.len(), rows.len());
        for (i, (row, _)) in rows.iter().enumerate() {
            prop_assert_eq!(list.commands(i), row.as_slice());
        }
        let mut w = t.writer();
        for (_, q) in list.iter() {
            w.pose(q).unwrap();
        }
        prop_assert_eq!(w.finish().unwrap(), text);
    }
}
