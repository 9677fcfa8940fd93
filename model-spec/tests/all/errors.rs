//! Every kind of bad input gets a message that names the file, the line and the column of the
//! offending value or key. The messages are checked in full (`file:line:col: message`).
//!
//! Most cases edit one place of [`BASE`], a small five-axis machine (work X, A, C; tool Y, Z);
//! the line numbers in the comments of `BASE` are the ones the expected messages refer to.

use model_spec::parse_machine;

/// A valid five-axis machine. Line numbers: 1 `name`, 5 `Zc`, 9 `axis = "X"`, 15 `axis = "A"`,
/// 21 `axis = "C"`, 24 C's offset, 26 `[[work]]` of the end, 27 `end = "ball"`, 31 `axis = "Y"`,
/// 37 `axis = "Z"`, 42 `[[tool]]` of the holder, 43 `link = "holder"`, 46 `[[tool]]` of the
/// end, 49 `[errors]`, 50 `exclude`, 52 `[models.reduced]`, 54 its `errors`.
const BASE: &str = r#"name = "t5"
description = "test machine"

[symbols]
Zc = 30.0
Xw = -200.0

[[work]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-500.0, 500.0]

[[work]]
axis = "A"
type = "rotary"
direction = "+x"
range = [-120.0, 120.0]

[[work]]
axis = "C"
type = "rotary"
direction = "+z"
offset = [0, 0, "Zc"]

[[work]]
end = "ball"
offset = ["Xw", 0.0, 10.0]

[[tool]]
axis = "Y"
type = "linear"
direction = "+y"
stroke = [-400.0, 400.0]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-500.0, 500.0]

[[tool]]
link = "holder"
offset = [0, 0, 100.0]

[[tool]]
end = "probe"

[errors]
exclude = ["EXX"]

[models.reduced]
description = "location errors of C"
errors = ["XOC", "YOC", "AOC", "BOC"]
"#;

/// `BASE` with `old` (which must occur exactly once) replaced by `new`.
fn edit(old: &str, new: &str) -> String {
    assert_eq!(
        BASE.matches(old).count(),
        1,
        "`{old}` must occur once in BASE"
    );
    BASE.replacen(old, new, 1)
}

/// The full message of the error `text` gives, read as `m.toml`.
fn err(text: &str) -> String {
    match parse_machine("m.toml", text) {
        Ok(m) => panic!("expected an error, got machine `{}`", m.name),
        Err(e) => e.to_string(),
    }
}

#[track_caller]
fn check(text: &str, expected: &str) {
    assert_eq!(err(text), expected);
}

#[test]
fn base_is_valid() {
    let m = parse_machine("m.toml", BASE).expect("BASE is valid");
    assert_eq!(m.name, "t5");
    assert_eq!(m.errors.len(), m.catalogue.len() - 1);
}

#[test]
fn spec_error_fields_and_display() {
    let e = parse_machine("dir/m.toml", &edit(r#"Zc = 30.0"#, r#"Zc = nan"#)).unwrap_err();
    assert_eq!((e.file.as_str(), e.line, e.column), ("dir/m.toml", 5, 6));
    assert_eq!(e.to_string(), format!("dir/m.toml:5:6: {}", e.message),);
}

// ---------------------------------------------------------------- TOML syntax and layout

#[test]
fn toml_syntax_error() {
    check(
        &edit(r#"name = "t5""#, r#"name = "t5" x"#),
        "m.toml:1:13: unexpected key or value, expected newline, `#`",
    );
}

#[test]
fn toml_unterminated_string() {
    check(
        &edit(r#"end = "probe""#, r#"end = "probe"#),
        "m.toml:47:13: invalid basic string, expected `\"`",
    );
}

#[test]
fn toml_duplicate_key() {
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nZc = 1.0"),
        "m.toml:7:1: duplicate key",
    );
}

#[test]
fn unknown_field_top_level() {
    check(
        &edit(
            r#"description = "test machine""#,
            "description = \"test machine\"\ncolour = \"red\"",
        ),
        "m.toml:3:1: unknown field `colour`, expected one of `name`, `description`, `symbols`, `work`, `tool`, `errors`, `models`",
    );
}

#[test]
fn unknown_field_in_work_entry() {
    check(
        &edit(r#"axis = "X""#, "axis = \"X\"\nspeed = 3"),
        "m.toml:10:1: unknown field `speed`, expected one of `axis`, `type`, `direction`, `offset`, `stroke`, `range`, `link`, `end`",
    );
}

#[test]
fn unknown_field_in_errors() {
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"exlude = ["EXX"]"#),
        "m.toml:50:1: unknown field `exlude`, expected one of `include`, `exclude`, `squareness_order`",
    );
}

#[test]
fn unknown_field_in_model() {
    check(
        &edit(
            r#"description = "location errors of C""#,
            r#"descr = "location errors of C""#,
        ),
        "m.toml:53:1: unknown field `descr`, expected `description` or `errors`",
    );
}

#[test]
fn wrong_value_types() {
    check(
        &edit(r#"name = "t5""#, "name = 5"),
        "m.toml:1:8: invalid type: integer `5`, expected a string",
    );
    check(
        &edit(r#"Zc = 30.0"#, r#"Zc = "30""#),
        r#"m.toml:5:6: invalid type: string "30", expected a number"#,
    );
    check(
        &edit(r#"offset = [0, 0, "Zc"]"#, r#"offset = [0, true, "Zc"]"#),
        "m.toml:24:14: invalid type: boolean `true`, expected a number (mm) or the name of a symbol",
    );
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = [-400.0, "400"]"#),
        r#"m.toml:34:19: invalid type: string "400", expected a number"#,
    );
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = 400.0"#),
        "m.toml:34:10: invalid type: floating point `400.0`, expected a sequence",
    );
}

#[test]
fn integers_are_numbers() {
    let m = parse_machine(
        "m.toml",
        &edit(r#"stroke = [-400.0, 400.0]"#, "stroke = [-400, 400]")
            .replace("Zc = 30.0", "Zc = 30"),
    )
    .unwrap();
    assert_eq!(m.axes[m.axis_by_name("Y").unwrap()].limits, [-400.0, 400.0]);
    assert_eq!(m.symbols[0].default, 30.0);
}

#[test]
fn missing_name() {
    check(
        &edit("name = \"t5\"\n", ""),
        r#"m.toml:1:1: no `name = "..."` at the top of the file: every machine needs a short name"#,
    );
}

#[test]
fn bad_machine_name() {
    check(
        &edit(r#"name = "t5""#, r#"name = "t 5""#),
        "m.toml:1:8: machine name `t 5` must be letters, digits, `-` or `_`",
    );
}

// ---------------------------------------------------------------- axes

#[test]
fn duplicate_axis_within_a_chain() {
    check(
        &edit(r#"axis = "A""#, r#"axis = "X""#),
        "m.toml:15:8: axis letter `X` is used twice (first on line 9): every axis of the machine needs its own letter",
    );
}

#[test]
fn duplicate_axis_across_chains() {
    check(
        &edit(r#"axis = "Z""#, r#"axis = "X""#),
        "m.toml:37:8: axis letter `X` is used twice (first on line 9): every axis of the machine needs its own letter",
    );
}

#[test]
fn axis_letter_lower_case() {
    check(
        &edit(r#"axis = "A""#, r#"axis = "a""#),
        "m.toml:15:8: axis name `a` must be upper case: write `A`",
    );
}

#[test]
fn axis_letter_e_and_o() {
    for letter in ["E", "O"] {
        check(
            &edit(r#"axis = "A""#, &format!(r#"axis = "{letter}""#)),
            &format!(
                "m.toml:15:8: axis name `{letter}` is not allowed: E and O are the letters of the error names (EXX, XOC)"
            ),
        );
    }
    check(
        &edit(r#"axis = "A""#, r#"axis = "E""#),
        "m.toml:15:8: axis name `E` is not allowed: E and O are the letters of the error names (EXX, XOC)",
    );
    check(
        &edit(r#"axis = "A""#, r#"axis = "o""#),
        "m.toml:15:8: axis name `o` must be one upper-case letter other than E and O (X, Y, Z, A, B, C, …)",
    );
}

#[test]
fn axis_letter_two_letters_digit_or_empty() {
    for bad in ["AB", "A1", "1", "", "Ä"] {
        check(
            &edit(r#"axis = "A""#, &format!(r#"axis = "{bad}""#)),
            &format!(
                "m.toml:15:8: axis name `{bad}` must be one upper-case letter other than E and O (X, Y, Z, A, B, C, …)"
            ),
        );
    }
}

#[test]
fn axis_letter_two_letters() {
    check(
        &edit(r#"axis = "A""#, r#"axis = "AB""#),
        "m.toml:15:8: axis name `AB` must be one upper-case letter other than E and O (X, Y, Z, A, B, C, …)",
    );
}

#[test]
fn rotary_axis_called_w() {
    check(
        &edit(r#"axis = "A""#, r#"axis = "W""#),
        "m.toml:15:8: a rotary axis cannot be called W: XOW YOW ZOW are the workpiece set-up errors",
    );
}

#[test]
fn linear_axis_may_be_called_w() {
    let m = parse_machine("m.toml", &edit(r#"axis = "Z""#, r#"axis = "W""#)).unwrap();
    assert!(m.error_by_name("EZW").is_some());
    assert!(m.error_by_name("AOW").is_some());
    assert!(m.error_by_name("XOW").is_some());
}

#[test]
fn missing_type() {
    check(
        &edit("axis = \"A\"\ntype = \"rotary\"\n", "axis = \"A\"\n"),
        r#"m.toml:15:8: axis A has no `type`: add `type = "linear"` or `type = "rotary"`"#,
    );
}

#[test]
fn missing_direction() {
    check(
        &edit(
            "axis = \"A\"\ntype = \"rotary\"\ndirection = \"+x\"\n",
            "axis = \"A\"\ntype = \"rotary\"\n",
        ),
        r#"m.toml:15:8: axis A has no `direction`: add `direction = "+x"` (or -x, +y, -y, +z, -z)"#,
    );
}

#[test]
fn bad_type() {
    check(
        &edit(
            "axis = \"A\"\ntype = \"rotary\"",
            "axis = \"A\"\ntype = \"Rotary\"",
        ),
        r#"m.toml:16:8: axis A: unknown type `Rotary` ("linear" or "rotary")"#,
    );
}

#[test]
fn bad_direction() {
    for bad in ["z+", "+w", "xy", "", "+ z"] {
        check(
            &edit(
                "direction = \"+z\"\noffset",
                &format!("direction = \"{bad}\"\noffset"),
            ),
            &format!(
                "m.toml:23:13: axis C: direction `{bad}` is not one of +x -x +y -y +z -z (or a vector such as [0, 1, 1])"
            ),
        );
    }
}

#[test]
fn bad_direction_vectors() {
    for bad in [
        "[0, 0, 0]",
        "[1, 1]",
        "[1, 1, 1, 1]",
        "[0, nan, 1]",
        "[inf, 0, 1]",
    ] {
        check(
            &edit(
                "direction = \"+z\"\noffset",
                &format!("direction = {bad}\noffset"),
            ),
            "m.toml:23:13: axis C: a direction vector needs three finite numbers, not all zero (e.g. [0, 1, 1])",
        );
    }
}

#[test]
fn direction_vectors_along_an_axis_are_the_signed_letters() {
    use model_spec::{Dir, Direction};
    let m = parse_machine(
        "m.toml",
        &edit(
            "direction = \"+z\"\noffset",
            "direction = [0, 0, -2.5]\noffset",
        ),
    )
    .unwrap();
    let c = &m.axes[m.axis_by_name("C").unwrap()];
    assert_eq!(
        c.direction.as_coordinate(),
        Some(Direction {
            dir: Dir::Z,
            negative: true
        })
    );
    let letters = parse_machine(
        "m.toml",
        &edit("direction = \"+z\"\noffset", "direction = \"-z\"\noffset"),
    )
    .unwrap();
    assert_eq!(m.catalogue, letters.catalogue);
    assert_eq!(m.fingerprint(), letters.fingerprint());
}

#[test]
fn inclined_linear_axes_cannot_lead_the_squareness_order() {
    let text = edit("direction = \"+y\"", "direction = [0, 1, 1]");
    let err = parse_machine("m.toml", &text).unwrap_err().to_string();
    assert!(err.contains("linear axis Y is inclined"), "{err}");
}

#[test]
fn bad_direction_sign_after_letter() {
    check(
        &edit("direction = \"+z\"\noffset", "direction = \"z+\"\noffset"),
        "m.toml:23:13: axis C: direction `z+` is not one of +x -x +y -y +z -z (or a vector such as [0, 1, 1])",
    );
}

#[test]
fn directions_are_case_insensitive_and_sign_optional() {
    use model_spec::{Dir, Direction};
    let m = parse_machine(
        "m.toml",
        &edit(r#"direction = "+y""#, r#"direction = "-Y""#)
            .replace(r#"direction = "+z""#, r#"direction = "z""#),
    )
    .unwrap();
    let y = &m.axes[m.axis_by_name("Y").unwrap()];
    assert_eq!(
        y.direction.as_coordinate().unwrap(),
        Direction {
            dir: Dir::Y,
            negative: true
        }
    );
    let c = &m.axes[m.axis_by_name("C").unwrap()];
    assert_eq!(
        c.direction.as_coordinate().unwrap(),
        Direction {
            dir: Dir::Z,
            negative: false
        }
    );
}

#[test]
fn linear_axis_without_stroke() {
    check(
        &edit(
            "direction = \"+y\"\nstroke = [-400.0, 400.0]\n",
            "direction = \"+y\"\n",
        ),
        "m.toml:31:8: linear axis Y has no `stroke = [min, max]` (mm)",
    );
}

#[test]
fn rotary_axis_without_range_is_unlimited() {
    let m = parse_machine("m.toml", BASE).unwrap();
    let c = &m.axes[m.axis_by_name("C").unwrap()];
    assert_eq!(c.limits, [f64::NEG_INFINITY, f64::INFINITY]);
    let a = &m.axes[m.axis_by_name("A").unwrap()];
    assert_eq!(a.limits, [-120.0, 120.0]);
}

#[test]
fn stroke_min_not_below_max() {
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = [400.0, -400.0]"#),
        "m.toml:34:10: axis Y: `stroke` minimum 400 is not below maximum -400 (mm)",
    );
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = [400.0, 400.0]"#),
        "m.toml:34:10: axis Y: `stroke` minimum 400 is not below maximum 400 (mm)",
    );
    check(
        &edit(r#"range = [-120.0, 120.0]"#, r#"range = [120.0, -120.5]"#),
        "m.toml:18:9: axis A: `range` minimum 120 is not below maximum -120.5 (degrees)",
    );
}

#[test]
fn stroke_wrong_length() {
    check(
        &edit(
            r#"stroke = [-400.0, 400.0]"#,
            r#"stroke = [-400.0, 0.0, 400.0]"#,
        ),
        "m.toml:34:10: axis Y: `stroke` needs two numbers [min, max] (mm), found 3",
    );
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = [400.0]"#),
        "m.toml:34:10: axis Y: `stroke` needs two numbers [min, max] (mm), found 1",
    );
    check(
        &edit(r#"range = [-120.0, 120.0]"#, r#"range = []"#),
        "m.toml:18:9: axis A: `range` needs two numbers [min, max] (degrees), found 0",
    );
}

#[test]
fn range_on_linear_axis() {
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"range = [-400.0, 400.0]"#),
        "m.toml:34:9: linear axis Y takes `stroke = [min, max]` (mm), not `range`",
    );
}

#[test]
fn stroke_on_rotary_axis() {
    check(
        &edit(r#"range = [-120.0, 120.0]"#, r#"stroke = [-120.0, 120.0]"#),
        "m.toml:18:10: rotary axis A takes `range = [min, max]` (degrees), not `stroke`",
    );
}

#[test]
fn axis_fields_on_link_and_end() {
    check(
        &edit(r#"link = "holder""#, "link = \"holder\"\ntype = \"linear\""),
        "m.toml:44:8: `type` belongs to an axis, not to a `link` entry",
    );
    check(
        &edit(r#"end = "probe""#, "end = \"probe\"\nrange = [0, 1]"),
        "m.toml:48:9: `range` belongs to an axis, not to a `end` entry",
    );
}

// ---------------------------------------------------------------- chains

#[test]
fn work_chain_without_end() {
    check(
        &edit(
            "[[work]]\nend = \"ball\"\noffset = [\"Xw\", 0.0, 10.0]\n",
            "",
        ),
        r#"m.toml:20:1: the [[work]] chain has no `end` entry: add a last [[work]] entry with `end = "..."` and the offset of the workpiece point (the R-test ball)"#,
    );
}

#[test]
fn tool_chain_without_end() {
    check(
        &edit("[[tool]]\nend = \"probe\"\n", ""),
        r#"m.toml:42:1: the [[tool]] chain has no `end` entry: add a last [[tool]] entry with `end = "..."` and the offset of the tool point (the R-test sensor nest)"#,
    );
}

#[test]
fn empty_chain() {
    let text = "name = \"e\"\nwork = []\n\n[[tool]]\nend = \"probe\"\n";
    check(
        text,
        r#"m.toml:2:8: the [[work]] chain has no `end` entry: add a last [[work]] entry with `end = "..."` and the offset of the workpiece point (the R-test ball)"#,
    );
}

/// `BASE` without its `[[work]]` (or `[[tool]]`) entries.
fn without_chain(table: &str) -> String {
    let header = format!("[[{table}]]");
    let mut out = String::new();
    let mut skipping = false;
    for line in BASE.lines() {
        if line.starts_with('[') {
            skipping = line == header;
        }
        if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    assert!(!out.contains(&header));
    out
}

#[test]
fn missing_work_chain() {
    check(
        &without_chain("work"),
        r#"m.toml:1:8: machine `t5` has no [[work]] chain: describe the chain from the bed to the workpiece point (the R-test ball) with [[work]] entries, the last one with `end = "..."`"#,
    );
}

#[test]
fn missing_tool_chain() {
    check(
        &without_chain("tool"),
        r#"m.toml:1:8: machine `t5` has no [[tool]] chain: describe the chain from the bed to the tool point (the R-test sensor nest) with [[tool]] entries, the last one with `end = "..."`"#,
    );
}

#[test]
fn entry_after_end() {
    check(
        &edit(
            "offset = [\"Xw\", 0.0, 10.0]\n",
            "offset = [\"Xw\", 0.0, 10.0]\n\n[[work]]\nlink = \"fixture\"\n",
        ),
        "m.toml:30:1: [[work]] entry after the `end` entry of line 26: the `end` entry must be the last of the chain",
    );
}

#[test]
fn entry_with_axis_and_link() {
    check(
        &edit(r#"axis = "C""#, "axis = \"C\"\nlink = \"table\""),
        "m.toml:22:8: this [[work]] entry has both `axis` and `link`: each entry is one axis, one fixed link or the end of the chain; split it",
    );
    check(
        &edit(r#"end = "probe""#, "end = \"probe\"\nlink = \"nest\""),
        "m.toml:48:8: this [[tool]] entry has both `end` and `link`: each entry is one axis, one fixed link or the end of the chain; split it",
    );
}

#[test]
fn entry_with_no_role() {
    check(
        &edit("link = \"holder\"\n", ""),
        "m.toml:42:1: this [[tool]] entry has none of `axis`, `link` or `end`: each entry is an axis, a fixed link or the end of the chain",
    );
}

// ---------------------------------------------------------------- symbols and offsets

#[test]
fn unknown_symbol_in_offset() {
    check(
        &edit(r#"offset = [0, 0, "Zc"]"#, r#"offset = [0, 0, "Zd"]"#),
        "m.toml:24:17: unknown symbol `Zd`: declare it under [symbols] with its default (mm)",
    );
    // No arithmetic on symbols: `-Xw` is a name, and not a declared one.
    check(
        &edit(
            r#"offset = ["Xw", 0.0, 10.0]"#,
            r#"offset = ["-Xw", 0.0, 10.0]"#,
        ),
        "m.toml:28:11: unknown symbol `-Xw`: declare it under [symbols] with its default (mm)",
    );
}

#[test]
fn offset_with_two_entries() {
    check(
        &edit(r#"offset = [0, 0, "Zc"]"#, r#"offset = [0, "Zc"]"#),
        "m.toml:24:10: `offset` needs three entries [x, y, z] (numbers in mm or symbol names), found 2",
    );
    check(
        &edit(r#"offset = [0, 0, 100.0]"#, r#"offset = [0, 0, 100.0, 1]"#),
        "m.toml:44:10: `offset` needs three entries [x, y, z] (numbers in mm or symbol names), found 4",
    );
}

#[test]
fn non_finite_symbol() {
    check(
        &edit(r#"Zc = 30.0"#, r#"Zc = nan"#),
        "m.toml:5:6: symbol `Zc` has the non-finite default NaN: give a number (mm)",
    );
    check(
        &edit(r#"Xw = -200.0"#, r#"Xw = -inf"#),
        "m.toml:6:6: symbol `Xw` has the non-finite default -inf: give a number (mm)",
    );
}

#[test]
fn non_finite_offset() {
    check(
        &edit(r#"offset = [0, 0, "Zc"]"#, r#"offset = [0, 0, inf]"#),
        "m.toml:24:17: `offset` has the non-finite number inf",
    );
    check(
        &edit(r#"offset = [0, 0, 100.0]"#, r#"offset = [nan, 0, 100.0]"#),
        "m.toml:44:11: `offset` has the non-finite number NaN",
    );
}

#[test]
fn non_finite_stroke_and_range() {
    check(
        &edit(r#"stroke = [-400.0, 400.0]"#, r#"stroke = [-inf, 400.0]"#),
        "m.toml:34:11: axis Y: `stroke` has the non-finite number -inf",
    );
    check(
        &edit(r#"range = [-120.0, 120.0]"#, r#"range = [-120.0, +nan]"#),
        "m.toml:18:18: axis A: `range` has the non-finite number NaN",
    );
}

#[test]
fn number_too_large_for_f64() {
    check(
        &edit(r#"Zc = 30.0"#, r#"Zc = 1e999"#),
        "m.toml:5:6: floating-point number overflowed",
    );
}

#[test]
fn symbol_name_not_an_identifier() {
    check(
        &edit(r#"Zc = 30.0"#, r#""Z c" = 30.0"#),
        "m.toml:5:1: symbol name `Z c` is not an identifier (a letter, then letters, digits or `_`)",
    );
}

#[test]
fn first_bad_symbol_in_file_order() {
    // Reported in the order of the file, not alphabetically.
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nb = nan\na = nan"),
        "m.toml:7:5: symbol `b` has the non-finite default NaN: give a number (mm)",
    );
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nZm = 1.0\nXm = 1.0"),
        "m.toml:7:1: symbol `Zm` is reserved for the command of axis Z in formulas: rename the symbol",
    );
}

#[test]
fn first_bad_model_in_file_order() {
    let text = format!(
        "{BASE}\n[models.b]\nerrors = [\"EXX\"]\n\n[models.a]\nerrors = [\"EYX\", \"QQQ\"]\n"
    );
    check(
        &text,
        "m.toml:57:11: model `b`: error `EXX` is not in the machine's full model (it is left out by [errors] include/exclude)",
    );
}

#[test]
fn symbol_name_rust_keyword() {
    check(
        &edit(r#"Zc = 30.0"#, "Zc = 30.0\ntype = 1.0"),
        "m.toml:6:1: symbol name `type` is a Rust keyword (generated code uses symbol names as field names): rename it",
    );
}

#[test]
fn symbol_reserved_for_linear_command() {
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nXm = 1.0"),
        "m.toml:7:1: symbol `Xm` is reserved for the command of axis X in formulas: rename the symbol",
    );
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nZm = 1.0"),
        "m.toml:7:1: symbol `Zm` is reserved for the command of axis Z in formulas: rename the symbol",
    );
}

#[test]
fn symbol_reserved_for_rotary_sine() {
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nSa = 1.0"),
        "m.toml:7:1: symbol `Sa` is reserved for the sine and cosine of the command of axis A in formulas: rename the symbol",
    );
}

#[test]
fn symbol_reserved_for_rotary_sine_and_cosine() {
    for name in ["Sa", "Ca", "Sc", "Cc"] {
        let axis = name[1..].to_ascii_uppercase();
        check(
            &edit(r#"Xw = -200.0"#, &format!("Xw = -200.0\n{name} = 1.0")),
            &format!(
                "m.toml:7:1: symbol `{name}` is reserved for the sine and cosine of the command of axis {axis} in formulas: rename the symbol"
            ),
        );
    }
    // Names of axes the machine does not have are free.
    parse_machine(
        "m.toml",
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nSb = 1.0\nAm = 2.0"),
    )
    .unwrap();
}

#[test]
fn reserved_names_function() {
    use model_spec::{AxisKind, reserved_names};
    assert_eq!(reserved_names("X", AxisKind::Linear), ["Xm"]);
    assert_eq!(reserved_names("A", AxisKind::Rotary), ["Sa", "Ca"]);
}

#[test]
fn symbol_named_like_an_error() {
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nXOC = 1.0"),
        "m.toml:7:1: symbol `XOC` has the name of an error of this machine: rename the symbol",
    );
}

// ---------------------------------------------------------------- errors and models

#[test]
fn unknown_error_in_include() {
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"include = ["EXX", "EXA", "XOA"]"#),
        "m.toml:50:26: error `XOA` does not exist for this machine: the errors of axis A are EXA EYA EZA EAA EBA ECA YOA ZOA BOA COA",
    );
}

#[test]
fn unknown_error_in_exclude() {
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"exclude = ["EXX", "EXB"]"#),
        "m.toml:50:19: error `EXB` does not exist for this machine: the machine has no axis B (axes X A C Y Z)",
    );
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"exclude = ["AOW"]"#),
        "m.toml:50:12: error `AOW` does not exist for this machine: the errors of the workpiece are XOW YOW ZOW",
    );
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"exclude = ["EX"]"#),
        "m.toml:50:12: error `EX` does not exist for this machine: ISO 230 names have three letters: E<motion><axis>, <motion>O<axis> or XOW YOW ZOW (axes X A C Y Z)",
    );
}

#[test]
fn unknown_error_in_model() {
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["XOC", "ZOC", "AOC", "BOC"]"#,
        ),
        "m.toml:54:18: error `ZOC` does not exist for this machine: the errors of axis C are EXC EYC EZC EAC EBC ECC XOC YOC AOC BOC",
    );
    // Squareness follows the squareness order Y, X, Z: X has only COX.
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["BOX"]"#,
        ),
        "m.toml:54:11: error `BOX` does not exist for this machine: the errors of axis X are EXX EYX EZX EAX EBX ECX COX",
    );
}

#[test]
fn error_listed_twice() {
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"include = ["EXX", "EYX", "EXX"]"#),
        "m.toml:50:26: error `EXX` is listed twice (first on line 50)",
    );
    check(
        &edit(
            r#"exclude = ["EXX"]"#,
            "exclude = [\n  \"XOC\",\n  \"X0C\",\n]",
        ),
        "m.toml:52:3: error `X0C` (XOC) is excluded twice (first on line 51)",
    );
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["XOC", "YOC", "AOC", "yoc"]"#,
        ),
        "m.toml:54:32: error `yoc` (YOC) is listed twice (first on line 54)",
    );
}

#[test]
fn model_error_excluded_from_machine() {
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"exclude = ["YOC"]"#),
        "m.toml:54:18: model `reduced`: error `YOC` is not in the machine's full model (it is left out by [errors] include/exclude)",
    );
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"include = ["XOC", "YOC", "AOC"]"#),
        "m.toml:54:32: model `reduced`: error `BOC` is not in the machine's full model (it is left out by [errors] include/exclude)",
    );
}

#[test]
fn model_named_full() {
    check(
        &edit("[models.reduced]", "[models.full]"),
        "m.toml:52:9: model name `full` is reserved for the machine's own error list ([errors]); choose another name",
    );
}

#[test]
fn model_name_not_an_identifier() {
    check(
        &edit("[models.reduced]", "[models.\"re duced\"]"),
        "m.toml:52:9: model name `re duced` is not an identifier (a letter, then letters, digits or `_`)",
    );
}

#[test]
fn model_name_rust_keyword() {
    check(
        &edit("[models.reduced]", "[models.mod]"),
        "m.toml:52:9: model name `mod` is a Rust keyword (generated code uses model names as module names): choose another name",
    );
}

#[test]
fn model_name_of_a_generated_item() {
    for name in ["Pose", "Params", "POSE_INPUTS", "PARAMETERS"] {
        check(
            &edit("[models.reduced]", &format!("[models.{name}]")),
            &format!(
                "m.toml:52:9: model name `{name}` is the name of an item of the generated code (Pose, Params, POSE_INPUTS, PARAMETERS), which uses model names as module names: choose another name"
            ),
        );
    }
}

#[test]
fn model_without_errors() {
    check(
        &edit(r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#, ""),
        "m.toml:52:1: model `reduced` has no `errors = [...]` list",
    );
}

#[test]
fn squareness_order_unknown_axis() {
    check(
        &edit(
            r#"exclude = ["EXX"]"#,
            "exclude = [\"EXX\"]\nsquareness_order = [\"Y\", \"Q\", \"Z\"]",
        ),
        "m.toml:51:26: unknown axis `Q` in squareness_order (the linear axes are X Y Z)",
    );
}

#[test]
fn squareness_order_rotary_twice_and_missing() {
    check(
        &edit(
            r#"exclude = ["EXX"]"#,
            r#"squareness_order = ["Y", "C", "Z"]"#,
        ),
        "m.toml:50:26: squareness_order lists rotary axis C: only linear axes have squareness errors",
    );
    check(
        &edit(
            r#"exclude = ["EXX"]"#,
            r#"squareness_order = ["Y", "Y", "Z"]"#,
        ),
        "m.toml:50:26: axis Y twice in squareness_order",
    );
    check(
        &edit(r#"exclude = ["EXX"]"#, r#"squareness_order = ["Y", "Z"]"#),
        "m.toml:50:20: squareness_order misses linear axis X: it must list every linear axis once",
    );
}

// Sub-models with basis terms (`NAME@BASIS`).

#[test]
fn submodel_terms_with_bases() {
    let text = edit(
        r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
        r#"errors = ["XOC", "ECC@harmonic:2", "dx0@time:1", "EYY@poly:1", "EXY@reversal", "ECC@harmonic:1"]"#,
    );
    let m = parse_machine("m.toml", &text).unwrap();
    let sub = &m.models["reduced"];
    let names: Vec<String> = sub
        .terms
        .iter()
        .map(|t| format!("{}@{}", t.effect.name(&m), t.basis))
        .collect();
    assert_eq!(
        names,
        [
            "XOC@const",
            "ECC@harmonic:2",
            "dx0@time:1",
            "EYY@poly:1",
            "EXY@reversal",
            "ECC@harmonic:1"
        ]
    );
    let errors: Vec<&str> = sub
        .errors
        .iter()
        .map(|&e| m.catalogue[e].name.as_str())
        .collect();
    assert_eq!(
        errors,
        ["EXY", "EYY", "ECC", "XOC"],
        "distinct errors, catalogue order"
    );
}

#[test]
fn submodel_term_errors_are_located() {
    let line = BASE
        .lines()
        .position(|l| l.contains(r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#))
        .unwrap()
        + 1;
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["XOC@harmonic:2"]"#,
        ),
        &format!(
            "m.toml:{line}:11: model `reduced`: XOC: `harmonic:2` needs an error of a rotary axis"
        ),
    );
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["XOC", "ECC@cubic:2"]"#,
        ),
        &format!(
            "m.toml:{line}:18: model `reduced`: unknown basis `cubic:2` (expected const, harmonic:K, poly:K, reversal, time:K, period:P, step:V, exp:TAU, velocity, rate, warmup:TAU or jump:T)"
        ),
    );
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["ECC@harmonic:2", "ECC@harmonic:2"]"#,
        ),
        &format!(
            "m.toml:{line}:29: model `reduced`: term `ECC@harmonic:2` is listed twice (first on line {line})"
        ),
    );
    check(
        &edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            r#"errors = ["dx0@poly:1"]"#,
        ),
        &format!(
            "m.toml:{line}:11: model `reduced`: dx0: `poly:1` needs an error of a linear axis"
        ),
    );
}

#[test]
fn measurement_effect_names_are_refused_as_symbols() {
    for name in ["SXY", "SZZ", "dx0", "DZ0", "px0", "PRE"] {
        let e = err(&edit("Zc = 30.0\n", &format!("Zc = 30.0\n{name} = 1.0\n")));
        assert_eq!(
            e,
            format!(
                "m.toml:6:1: symbol `{name}` has a name reserved for an effect of the measurement (R-test or touch probe: dx0 dy0 dz0 px0 py0 pz0 PRE SXX SXY SXZ SYX SYY SYZ SZX SZY SZZ): rename the symbol"
            )
        );
    }
    // Names that merely look alike are symbols like any other.
    for name in ["SXW", "Sxy", "dx1"] {
        parse_machine(
            "m.toml",
            &edit("Zc = 30.0\n", &format!("Zc = 30.0\n{name} = 1.0\n")),
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

#[test]
fn submodels_take_the_new_vocabulary() {
    let text = edit(
        r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
        r#"errors = ["EYY@velocity", "ECC@velocity", "SXY", "SZZ", "XOC@exp:20", "dz0@exp:0.5", "EYY@period:5", "EZY@step:-12.5", "ECC@step:90"]"#,
    );
    let m = parse_machine("m.toml", &text).unwrap();
    let spelled: Vec<String> = m.models["reduced"]
        .terms
        .iter()
        .map(|t| t.spelling(&m))
        .collect();
    assert_eq!(
        spelled,
        [
            "EYY@velocity",
            "ECC@velocity",
            "SXY",
            "SZZ",
            "XOC@exp:20",
            "dz0@exp:0.5",
            "EYY@period:5",
            "EZY@step:-12.5",
            "ECC@step:90"
        ]
    );
    let line = BASE
        .lines()
        .position(|l| l.contains(r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#))
        .unwrap()
        + 1;
    for (term, why) in [
        (
            "EXY@velocity",
            "XY: `velocity` needs the positioning error of an axis",
        ),
        (
            "SXY@time:1",
            "SXY: `SXY` is an instrument term of the R-test: constants only, not `time:1`",
        ),
        ("EYY@exp:2", "EYY: `exp:2` needs an effect of no axis"),
        (
            "ECC@period:5",
            "ECC: `period:5` needs an error of a linear axis",
        ),
        ("XOC@step:1", "XOC: `step:1` needs an error of an axis"),
        (
            "EYY@period:0.0001",
            "`period:0.0001`: the period P of `period:P` (mm) must be a decimal number with at most three decimals",
        ),
    ] {
        let e = err(&edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            &format!(r#"errors = ["{term}"]"#),
        ));
        assert!(
            e.starts_with(&format!("m.toml:{line}:11: model `reduced`: ")) && e.contains(why),
            "{term}: {e}"
        );
    }
}

#[test]
fn submodels_take_rates_and_warm_ups() {
    let text = edit(
        r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
        r#"errors = ["XOC@rate", "dz0@rate", "ECC@rate", "EXZ@warmup:40", "dx0@warmup:12.500", "BOA@warmup:0.5"]"#,
    );
    let m = parse_machine("m.toml", &text).unwrap();
    let terms = &m.models["reduced"].terms;
    let spelled: Vec<String> = terms.iter().map(|t| t.spelling(&m)).collect();
    assert_eq!(
        spelled,
        [
            "XOC@rate",
            "dz0@rate",
            "ECC@rate",
            "EXZ@warmup:40",
            "dx0@warmup:12.5",
            "BOA@warmup:0.5"
        ]
    );
    // A rate is per second; a warm-up's value is the amplitude, in the effect's unit.
    let units: Vec<&str> = terms.iter().map(|t| t.unit(&m)).collect();
    assert_eq!(units, ["um/s", "um/s", "urad/s", "um", "um", "urad"]);
    assert_eq!(terms[0].display_factor(&m), 1e3);
    assert_eq!(terms[2].display_factor(&m), 1e6);
    let line = BASE
        .lines()
        .position(|l| l.contains(r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#))
        .unwrap()
        + 1;
    for (term, col, why) in [
        ("XOC@rate:1", 11, "unknown basis `rate:1`"),
        ("XOC@Rate", 11, "unknown basis `Rate`"),
        ("XOC@warmup", 11, "unknown basis `warmup`"),
        (
            "XOC@warmup:0",
            11,
            "`warmup:0`: the time constant TAU of `warmup:TAU` (s) must be positive",
        ),
        (
            "XOC@warmup:-5",
            11,
            "`warmup:-5`: the time constant TAU of `warmup:TAU` (s) must be positive",
        ),
        (
            "XOC@warmup:1.0001",
            11,
            "`warmup:1.0001`: the time constant TAU of `warmup:TAU` (s) must be a decimal number with at most three decimals",
        ),
        (
            "XOC@warmup:2000000",
            11,
            "`warmup:2000000`: the time constant TAU of `warmup:TAU` (s) must be at most 1000000 in magnitude",
        ),
        (
            "SXY@rate",
            11,
            "SXY: `SXY` is an instrument term of the R-test: constants only, not `rate`",
        ),
        (
            "SZZ@warmup:40",
            11,
            "SZZ: `SZZ` is an instrument term of the R-test: constants only, not `warmup:40`",
        ),
    ] {
        let e = err(&edit(
            r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
            &format!(r#"errors = ["{term}"]"#),
        ));
        assert!(
            e.starts_with(&format!("m.toml:{line}:{col}: model `reduced`: ")) && e.contains(why),
            "{term}: {e}"
        );
    }
    // A kinematic symbol is a length: constants only.
    let e = err(&edit(
        r#"errors = ["XOC", "YOC", "AOC", "BOC"]"#,
        r#"errors = ["Zc@rate"]"#,
    ));
    assert!(e.contains("constants only, not `rate`"), "{e}");
}

#[test]
fn symbol_spelled_like_an_error_and_symbols_in_models() {
    check(
        &edit(r#"Xw = -200.0"#, "Xw = -200.0\nx0c = 1.0"),
        "m.toml:7:1: symbol `x0c` reads as the error XOC of this machine (error names are read without regard to case, with 0 for O): terms name errors and kinematic symbols alike, so rename the symbol",
    );
    // A kinematic symbol is a term of a model, constant, written as under [symbols].
    let m = parse_machine("m.toml", &edit(r#""BOC"]"#, r#""BOC", "Zc"]"#)).unwrap();
    assert_eq!(m.models["reduced"].terms.len(), 5);
    check(
        &edit(r#""BOC"]"#, r#""BOC", "Zc@time:1"]"#),
        "m.toml:54:39: model `reduced`: Zc: `Zc` is a kinematic offset of the machine (a length of its description, mm): constants only, not `time:1`; a length does not change with position, direction of motion or time (what does is an error of an axis or a drift)",
    );
    check(
        &edit(r#""BOC"]"#, r#""BOC", "zc"]"#),
        "m.toml:54:39: model `reduced`: `zc` is no error of this machine; the kinematic symbol is written `Zc` (symbols are named exactly as [symbols] writes them)",
    );
}

#[test]
fn an_inclined_linear_axis_leading_the_squareness_order_is_reported_at_the_axis() {
    check(
        &edit("direction = \"+y\"", "direction = [0, 1, 1]"),
        "m.toml:31:8: linear axis Y is inclined: an inclined linear axis cannot be first or second in the squareness order (put two axes along x, y or z first with `[errors] squareness_order`)",
    );
    // Third in the order it is accepted, with the squareness errors of its own frame.
    let m = parse_machine(
        "m.toml",
        &edit(
            "direction = \"+z\"\nstroke",
            "direction = [0, 1, 4]\nstroke",
        ),
    )
    .unwrap();
    let z = m.axis_by_name("Z").unwrap();
    assert!(m.axes[z].direction.inclined.is_some());
    for name in ["AOZ", "BOZ", "EZZ"] {
        assert!(m.error_by_name(name).is_some(), "{name}");
    }
}

// ---------------------------------------------------------------- free text

/// A description holding a text-direction control (written as a TOML escape or as the
/// character itself) is refused where it stands: rustc refuses such a character in the
/// comments of the generated code, and a terminal would show the text reordered.
#[test]
fn a_description_with_a_text_direction_control_is_refused() {
    let why = "a text-direction control (it shows the text in another order than it is stored): remove it";
    check(
        &edit(
            r#"description = "test machine""#,
            r#"description = "x\u202e""#,
        ),
        &format!("m.toml:2:15: description holds U+202E at character 2, {why}"),
    );
    check(
        &edit(
            r#"description = "location errors of C""#,
            "description = \"C\u{2067}\"",
        ),
        &format!("m.toml:53:15: description holds U+2067 at character 2, {why}"),
    );
    check(
        &edit(
            r#"description = "test machine""#,
            r#"description = "bell\u0007""#,
        ),
        "m.toml:2:15: description holds U+0007 at character 5, a control character: remove it",
    );
    // Line breaks and tabs are text.
    let m = parse_machine(
        "m.toml",
        &edit(
            r#"description = "test machine""#,
            r#"description = """test\tmachine
on two lines""""#,
        ),
    )
    .unwrap();
    assert_eq!(m.description, "test\tmachine\non two lines");
}
