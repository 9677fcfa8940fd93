//! The CSV of commanded poses (`formats::poses`): other columns, quotes, comments and line
//! ends kept byte for byte; axis values written as the shortest decimal that reads back to the
//! same bits; every error with its line and column.

use formats::poses::{AxisWord, PoseCsvError, PoseTable, read_pose_csv, read_pose_file};
use model_spec::AxisKind::{Linear, Rotary};
use proptest::prelude::*;

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

fn read(text: &str) -> Result<PoseTable, PoseCsvError> {
    read_pose_csv("poses.csv", text, &xyzac())
}

fn commands(t: &PoseTable) -> Vec<Vec<f64>> {
    t.poses().iter().map(|p| p.commands.clone()).collect()
}

const TEXT: &str = "# K4 as commanded\n\
id,C, x ,\"note, free\",Y,Z,A,t_s\n\
1,0,-217.504,\"start, \"\"home\"\"\",-0.279,211.537,0,0\n\
\n\
2,1.5,-217.50,,-0.2790 ,211.537,-0.0154,1\n\
# a comment between rows\n\
3,3,\"-217.49\",x,-0.28,211.54,-0.0617,2\n";

#[test]
fn poses_follow_the_axes_whatever_the_column_order() {
    let t = read(TEXT).unwrap();
    let lines: Vec<usize> = t.poses().iter().map(|p| p.line).collect();
    assert_eq!(lines, [3, 5, 7]);
    assert_eq!(
        commands(&t),
        [
            vec![-217.504, -0.279, 211.537, 0.0, 0.0],
            vec![-217.5, -0.279, 211.537, -0.0154, 1.5],
            vec![-217.49, -0.28, 211.54, -0.0617, 3.0],
        ]
    );
}

#[test]
fn unchanged_poses_give_the_same_bytes() {
    for text in [
        TEXT.to_string(),
        TEXT.replace('\n', "\r\n"),
        format!("\u{feff}{}", TEXT.trim_end()),
    ] {
        let t = read(&text).unwrap();
        assert_eq!(t.write(&commands(&t)).unwrap(), text);
    }
}

#[test]
fn corrected_poses_change_only_axis_numbers_and_read_back_bit_for_bit() {
    let text = TEXT.replace('\n', "\r\n");
    let t = read(&text).unwrap();
    // X Y Z A C; the X of row 2 and the C of row 3 are unchanged and keep their text.
    let corrected = vec![
        vec![-217.5041, -0.2787, 211.5372, 0.0012, -0.0003],
        vec![-217.5, -0.2789, 211.5368, -0.0141, 1.5007],
        vec![-217.4896, -0.2801, 211.5404, -0.0605, 3.0],
    ];
    let out = t.write(&corrected).unwrap();
    let expected = "# K4 as commanded\r\n\
id,C, x ,\"note, free\",Y,Z,A,t_s\r\n\
1,-0.0003,-217.5041,\"start, \"\"home\"\"\",-0.2787,211.5372,0.0012,0\r\n\
\r\n\
2,1.5007,-217.50,,-0.2789 ,211.5368,-0.0141,1\r\n\
# a comment between rows\r\n\
3,3,\"-217.4896\",x,-0.2801,211.5404,-0.0605,2\r\n";
    assert_eq!(out, expected);
    let back = read(&out).unwrap();
    for (b, c) in commands(&back).iter().zip(&corrected) {
        for (x, y) in b.iter().zip(c) {
            assert_eq!(x.to_bits(), y.to_bits());
        }
    }
}

#[test]
fn a_file_is_read_with_its_byte_order_mark() {
    let dir = std::env::temp_dir().join(format!("rtest-pose-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("poses.csv");
    let text = format!("\u{feff}{TEXT}");
    std::fs::write(&path, &text).unwrap();
    let t = read_pose_file(&path, &xyzac()).unwrap();
    assert_eq!(t.write(&commands(&t)).unwrap(), text);
    std::fs::write(&path, b"X,Y,Z,A,C\n1,2,3,4,\xff\n").unwrap();
    let e = read_pose_file(&path, &xyzac()).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("poses.csv:2:9: not UTF-8 text (byte 0xff)"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Checks that `text` is refused at `line`, column `column` (index and name, if any), the
/// message containing `why`.
fn refused(text: &str, line: usize, column: Option<(usize, &str)>, why: &str) {
    let e = read(text).unwrap_err();
    let s = e.to_string();
    match e {
        PoseCsvError::Format {
            file,
            line: l,
            column: c,
            message,
        } => {
            assert_eq!(file, "poses.csv");
            assert_eq!(l, line, "{s}");
            assert_eq!(c, column.map(|(i, n)| (i, n.to_string())), "{s}");
            assert!(message.contains(why), "{s}");
        }
        other => panic!("expected a format error, got {other:?}"),
    }
}

#[test]
fn errors_name_line_and_column() {
    let h = "X,Y,Z,A,C,note\n";
    refused(
        &format!("{h}1,2,3,4,5,a\n1,2,,4,5,b\n"),
        3,
        Some((3, "Z")),
        "empty",
    );
    refused(
        &format!("{h}1,2,3,4,abc,a\n"),
        2,
        Some((5, "C")),
        "`abc` is not a decimal",
    );
    refused(
        &format!("{h}1,2,3,inf,5,a\n"),
        2,
        Some((4, "A")),
        "`inf` is not a decimal",
    );
    refused(
        &format!("{h}1,2,3,NaN,5,a\n"),
        2,
        Some((4, "A")),
        "`NaN` is not a decimal",
    );
    refused(
        &format!("{h}1,2,3,4,1e300,a\n"),
        2,
        Some((5, "C")),
        "beyond",
    );
    refused(
        &format!("{h}1,2,3,4,5\n"),
        2,
        None,
        "5 field(s), the header (line 1) has 6 columns",
    );
    refused(
        &format!("{h}1,2,3,4,5,\"open\n"),
        2,
        None,
        "field 6: a quoted field",
    );
    refused(
        "X,Y,Z,A,C,x\n1,2,3,4,5,6\n",
        1,
        Some((6, "x")),
        "axis X has two columns (also column 1)",
    );
    refused("X,Y,A,C\n1,2,3,4\n", 1, None, "missing axis column(s) Z");
    refused("# only a comment\n\n", 2, None, "no header");
    refused("X,Y,Z,A,C\n# no row\n", 1, None, "no pose");
    let long = format!("{h}{}\n", "1".repeat(70_000));
    refused(&long, 2, None, "longer than 65536 bytes");
}

#[test]
fn axis_columns_with_a_unit_get_a_hint() {
    let e = read("X_mm,Y,Z,A (deg),C\n1,2,3,4,5\n").unwrap_err();
    assert_eq!(
        e.to_string(),
        "poses.csv:1: missing axis column(s) X, A: the header needs one column per axis (X, Y, Z, A, C), named by its letter; column 1 `X_mm` is not read as it: name the column `X` exactly (mm for this axis)"
    );
    let e = read("X,Y,Z,A,C[deg]\n1,2,3,4,5\n").unwrap_err();
    assert!(
        e.to_string().contains(
            "column 5 `C[deg]` is not read as it: name the column `C` exactly (deg for this axis)"
        ),
        "{e}"
    );
}

#[test]
fn poses_that_do_not_fit_the_file_are_refused() {
    let t = read("X,Y,Z,A,C\n1,2,3,4,5\n").unwrap();
    let e = t.write(&[]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "poses.csv: cannot write the poses: 0 corrected poses for 1 rows"
    );
    let e = t.write(&[vec![1.0; 4]]).unwrap_err();
    assert!(
        e.to_string().contains("line 2 has 4 values for 5 axes"),
        "{e}"
    );
    let e = t
        .write(&[vec![1.0, 2.0, 3.0, f64::INFINITY, 5.0]])
        .unwrap_err();
    assert!(
        e.to_string().contains("line 2: axis A would be inf deg"),
        "{e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random commands written into a file read back bit for bit, and every other field keeps
    /// its bytes.
    #[test]
    fn random_commands_round_trip(
        values in prop::collection::vec(prop::array::uniform5(-99_999.0f64..99_999.0), 1..30),
        crlf in any::<bool>(),
    ) {
        let end = if crlf { "\r\n" } else { "\n" };
        let mut text = format!("n,A,C,X,Y,Z,\"q,r\"{end}");
        for i in 0..values.len() {
            text += &format!("{i},0,0,0,0,0,\"{i},{i}\"{end}");
        }
        let t = read(&text).unwrap();
        let values: Vec<Vec<f64>> = values.iter().map(|v| v.to_vec()).collect();
        let out = t.write(&values).unwrap();
        let back = read(&out).unwrap();
        for (b, v) in commands(&back).iter().zip(&values) {
            for (x, y) in b.iter().zip(v) {
                prop_assert_eq!(x.to_bits(), y.to_bits());
            }
        }
        for (a, b) in text.split_inclusive('\n').zip(out.split_inclusive('\n')) {
            prop_assert_eq!(a.split(',').next(), b.split(',').next());
            prop_assert_eq!(a.rsplit(',').nth(1), b.rsplit(',').nth(1));
            prop_assert_eq!(a.ends_with("\r\n"), b.ends_with("\r\n"));
        }
    }
}

#[test]
fn the_documented_example() {
    let before =
        "id,X,Y,Z,A,C,t_s\n1,-217.504,-0.279,211.537,0,0,0\n2,-217.504,-0.279,211.537,0,1.5,1\n";
    let after = "id,X,Y,Z,A,C,t_s\n1,-217.5062,-0.2771,211.5384,0.0011,-0.0008,0\n2,-217.5061,-0.2772,211.5384,0.0011,1.4993,1\n";
    let t = read(before).unwrap();
    let corrected = [
        vec![-217.5062, -0.2771, 211.5384, 0.0011, -0.0008],
        vec![-217.5061, -0.2772, 211.5384, 0.0011, 1.4993],
    ];
    assert_eq!(t.write(&corrected).unwrap(), after);
}
