//! The limits of `model_spec::limits`: a description at a limit is accepted, one beyond it is
//! refused with a message that names the file, line and column, the limit and the value.
//! The messages are checked in full, like those of `errors.rs`.

use model_spec::limits::{
    MAX_AXES, MAX_FILE_BYTES, MAX_LENGTH_MM, MAX_LINKS, MAX_MODELS, MAX_NAME_CHARS, MAX_RANGE_DEG,
    MAX_SYMBOLS, MAX_TERMS, MIN_STROKE_MM,
};
use model_spec::locate::line_col;
use model_spec::{AxisKind, Machine, parse_machine};

/// A valid machine (work X, C; tool Z). Line numbers: 1 `name`, 4 `Zc`, 7 `axis = "X"`,
/// 10 X's stroke, 13 `axis = "C"`, 17 C's range, 21 the ball's offset, 29 `[[tool]]` of the
/// end, 32 `[models.location]`, 33 its `errors`.
const BASE: &str = r#"name = "t3"

[symbols]
Zc = 30.0

[[work]]
axis = "X"
type = "linear"
direction = "+x"
stroke = [-500.0, 500.0]

[[work]]
axis = "C"
type = "rotary"
direction = "+z"
offset = [0, 0, "Zc"]
range = [-360.0, 360.0]

[[work]]
end = "ball"
offset = [10.0, 0, 5.0]

[[tool]]
axis = "Z"
type = "linear"
direction = "+z"
stroke = [-300.0, 300.0]

[[tool]]
end = "probe"

[models.location]
errors = ["XOC", "YOC"]
"#;

/// `BASE` with `old` (which must occur exactly once) replaced by `new`.
fn edit(old: &str, new: &str) -> String {
    assert_eq!(BASE.matches(old).count(), 1, "`{old}` must occur once");
    BASE.replacen(old, new, 1)
}

fn parse(text: &str) -> Machine {
    parse_machine("m.toml", text).unwrap_or_else(|e| panic!("{e}"))
}

#[track_caller]
fn check(text: &str, expected: &str) {
    match parse_machine("m.toml", text) {
        Ok(m) => panic!("expected an error, got machine `{}`", m.name),
        Err(e) => assert_eq!(e.to_string(), expected),
    }
}

#[test]
fn base_is_valid() {
    assert_eq!(parse(BASE).axes.len(), 3);
}

// ---------------------------------------------------------------- file size

#[test]
fn file_size() {
    let max = MAX_FILE_BYTES as usize;
    assert_eq!(max, 1 << 20);
    // Padded with a comment to exactly the limit: accepted.
    let pad = |total: usize| {
        let mut t = BASE.to_string();
        t.push_str("# ");
        t.push_str(&"x".repeat(total - t.len() - 1));
        t.push('\n');
        assert_eq!(t.len(), total);
        t
    };
    parse(&pad(max));
    // One byte more: refused, at the first byte past the limit (the comment's newline).
    let text = pad(max + 1);
    assert_eq!(line_col(&text, max), (34, 1048172));
    check(
        &text,
        "m.toml:34:1048172: the description has 1048577 bytes, more than 1048576 (1 MiB), the most a machine description may have",
    );
    // Far beyond (16 MiB): refused before the TOML is read.
    let big = BASE.to_string() + &"\n".repeat(16 << 20);
    let e = parse_machine("m.toml", &big).unwrap_err();
    let expected = format!("the description has {} bytes, more than 1048576", big.len());
    assert!(e.message.starts_with(&expected), "{e}");
    assert_eq!((e.line, e.column), (line_col(&big, max).0, 1));
}

// ---------------------------------------------------------------- counts

/// A machine with the given axes on the tool chain (linear `X Y Z U V W`, the rest rotary),
/// each axis entry 6 lines long: axis `k` (0-based) is named on line `7 + 6k`.
fn machine_with_axes(letters: &str) -> String {
    let mut t = String::from("name = \"many\"\n\n[[work]]\nend = \"ball\"\n\n");
    for (i, letter) in letters.chars().enumerate() {
        let dir = ["+x", "+y", "+z"][i % 3];
        let (kind, travel) = if "XYZUVW".contains(letter) {
            ("linear", "stroke = [-100, 100]")
        } else {
            ("rotary", "range = [-100, 100]")
        };
        t.push_str(&format!(
            "[[tool]]\naxis = \"{letter}\"\ntype = \"{kind}\"\ndirection = \"{dir}\"\n{travel}\n\n"
        ));
    }
    t.push_str("[[tool]]\nend = \"probe\"\n");
    t
}

#[test]
fn sixteen_axes_are_accepted() {
    assert_eq!(MAX_AXES, 16);
    let m = parse(&machine_with_axes("XYZUVWABCDFGHIJK"));
    assert_eq!(m.axes.len(), 16);
    assert_eq!(m.linear_axes().count(), 6);
    assert_eq!(m.rotary_axes().count(), 10);
    assert!(m.axes.iter().all(|a| a.side == model_spec::Side::Tool));
    // 6 component errors per axis, 4 location errors per rotary axis, 1 + 2·4 squareness
    // errors for 6 linear axes, 3 set-up errors.
    assert_eq!(m.catalogue.len(), 16 * 6 + 10 * 4 + 9 + 3);
    assert_eq!(m.axes[15].kind, AxisKind::Rotary);
}

#[test]
fn seventeen_axes_are_refused() {
    check(
        &machine_with_axes("XYZUVWABCDFGHIJKL"),
        "m.toml:103:8: the description has 17 axes, more than 16, the most a machine may have",
    );
    // Counted over both chains, the work chain first: with one axis on the work chain, the
    // 17th is the tool chain's 16th, K (on line 97 + 5).
    let text = machine_with_axes("XYZUVWABCDFGHIJK").replace(
        "[[work]]\nend = \"ball\"",
        "[[work]]\naxis = \"L\"\ntype = \"rotary\"\ndirection = \"+z\"\n\n[[work]]\nend = \"ball\"",
    );
    check(
        &text,
        "m.toml:102:8: the description has 17 axes, more than 16, the most a machine may have",
    );
}

/// `BASE` with `n` fixed links before the probe.
fn with_links(n: usize) -> String {
    let links: String = (1..=n)
        .map(|i| format!("[[tool]]\nlink = \"part {i}\"\noffset = [0, 0, 1]\n\n"))
        .collect();
    edit(
        "[[tool]]\nend = \"probe\"",
        &format!("{links}[[tool]]\nend = \"probe\""),
    )
}

#[test]
fn links() {
    assert_eq!(MAX_LINKS, 32);
    let m = parse(&with_links(32));
    assert_eq!(m.tool.links.len(), 33);
    // The 33rd link is named on line 29 + 4·32 + 1.
    check(
        &with_links(33),
        "m.toml:158:8: the description has 33 fixed links, more than 32, the most a machine may have",
    );
}

/// `BASE` with `n` more symbols after `Zc`, one a line (`S1` on line 5).
fn with_symbols(n: usize) -> String {
    let symbols: String = (1..=n).map(|i| format!("S{i} = {i}.0\n")).collect();
    edit("Zc = 30.0\n", &format!("Zc = 30.0\n{symbols}"))
}

#[test]
fn symbols() {
    assert_eq!(MAX_SYMBOLS, 256);
    assert_eq!(parse(&with_symbols(255)).symbols.len(), 256);
    check(
        &with_symbols(256),
        "m.toml:260:1: the description has 257 symbols, more than 256, the most a machine may declare",
    );
}

/// `BASE` with `n` more sub-models `m1`, `m2`, … after `location`, three lines each.
fn with_models(n: usize) -> String {
    let models: String = (1..=n)
        .map(|i| format!("\n[models.m{i}]\nerrors = [\"XOC\"]\n"))
        .collect();
    format!("{BASE}{models}")
}

#[test]
fn sub_models() {
    assert_eq!(MAX_MODELS, 64);
    assert_eq!(parse(&with_models(63)).models.len(), 64);
    // The 65th (`m64`) on line 33 + 3·64 − 1, its name after `[models.`.
    check(
        &with_models(64),
        "m.toml:224:9: the description has 65 sub-models, more than 64, the most a machine may have",
    );
}

#[test]
fn terms_of_a_sub_model() {
    assert_eq!(MAX_TERMS, 1000);
    // Counted before the terms are read: the list's 1001st entry is pointed at, whatever
    // the entries are.
    let list = |n: usize| vec!["\"XOC\""; n].join(", ");
    check(
        &edit(
            r#"errors = ["XOC", "YOC"]"#,
            &format!("errors = [{}]", list(1001)),
        ),
        "m.toml:33:7011: model `location` has 1001 terms, more than 1000, the most a sub-model may have",
    );
    // 1000 distinct terms are accepted: 6 errors × 64 orders for each of X, Z (poly) and C
    // (harmonic) give 1152.
    let mut terms = Vec::new();
    for (axis, basis) in [("X", "poly"), ("Z", "poly"), ("C", "harmonic")] {
        for e in ["EX", "EY", "EZ", "EA", "EB", "EC"] {
            for k in 1..=64 {
                terms.push(format!("\"{e}{axis}@{basis}:{k}\""));
            }
        }
    }
    terms.truncate(1000);
    let m = parse(&edit(
        r#"errors = ["XOC", "YOC"]"#,
        &format!("errors = [{}]", terms.join(", ")),
    ));
    assert_eq!(m.models["location"].terms.len(), 1000);
}

#[test]
fn basis_order() {
    parse(&edit(
        r#"errors = ["XOC", "YOC"]"#,
        r#"errors = ["ECC@harmonic:64"]"#,
    ));
    check(
        &edit(
            r#"errors = ["XOC", "YOC"]"#,
            r#"errors = ["ECC@harmonic:65"]"#,
        ),
        "m.toml:33:11: model `location`: `harmonic:65`: the order of `harmonic:K` must be a whole number from 1 to 64",
    );
}

// ---------------------------------------------------------------- names

#[test]
fn name_length() {
    assert_eq!(MAX_NAME_CHARS, 64);
    let long = |first: char, n: usize| format!("{first}{}", "é".repeat(n - 1));
    // 64 characters (not bytes: `é` is two) are accepted, 65 refused, everywhere.
    let ascii = |n: usize| format!("Z{}", "c".repeat(n - 1));
    parse(&edit(
        "Zc = 30.0\n",
        &format!("Zc = 30.0\n{} = 1\n", ascii(64)),
    ));
    check(
        &edit("Zc = 30.0\n", &format!("Zc = 30.0\n{} = 1\n", ascii(65))),
        "m.toml:5:1: symbol name `Zccccccccccccccc…` has 65 characters, more than 64, the longest name",
    );
    parse(&edit(
        r#"name = "t3""#,
        &format!("name = \"{}\"", ascii(64)),
    ));
    check(
        &edit(r#"name = "t3""#, &format!("name = \"{}\"", ascii(65))),
        "m.toml:1:8: machine name `Zccccccccccccccc…` has 65 characters, more than 64, the longest name",
    );
    parse(&edit(
        "[models.location]",
        &format!("[models.{}]", ascii(64)),
    ));
    check(
        &edit("[models.location]", &format!("[models.{}]", ascii(65))),
        "m.toml:32:9: model name `Zccccccccccccccc…` has 65 characters, more than 64, the longest name",
    );
    parse(&edit(
        r#"end = "ball""#,
        &format!("end = \"{}\"", long('b', 64)),
    ));
    check(
        &edit(r#"end = "ball""#, &format!("end = \"{}\"", long('b', 65))),
        "m.toml:20:7: end name `bééééééééééééééé…` has 65 characters, more than 64, the longest name",
    );
    parse(&with_links(1).replace("part 1", &long('p', 64)));
    check(
        &with_links(1).replace("part 1", &long('p', 65)),
        "m.toml:30:8: link name `pééééééééééééééé…` has 65 characters, more than 64, the longest name",
    );
}

// ---------------------------------------------------------------- magnitudes

#[test]
fn lengths() {
    assert_eq!(MAX_LENGTH_MM, 1e5);
    // At the bound: accepted.
    let m = parse(
        &edit("Zc = 30.0", "Zc = 100000")
            .replace("[-500.0, 500.0]", "[-100000, 1e5]")
            .replace("[10.0, 0, 5.0]", "[-1e5, 0, 5.0]"),
    );
    assert_eq!(m.symbols[0].default, 1e5);
    assert_eq!(m.axes[0].limits, [-1e5, 1e5]);
    // Beyond: refused where the number is, with the number as written.
    check(
        &edit("Zc = 30.0", "Zc = 1e308"),
        "m.toml:4:6: symbol `Zc` has the default 1e308 mm, beyond ±100000 mm (100 m), the largest length of a machine description",
    );
    check(
        &edit("Zc = 30.0", "Zc = -100000.5"),
        "m.toml:4:6: symbol `Zc` has the default -100000.5 mm, beyond ±100000 mm (100 m), the largest length of a machine description",
    );
    check(
        &edit("[-500.0, 500.0]", "[-1e308, 1e308]"),
        "m.toml:10:11: axis X: `stroke` has the number -1e308 mm, beyond ±100000 mm (100 m), the largest length of a machine description",
    );
    check(
        &edit("[-300.0, 300.0]", "[-300.0, 9223372036854775807]"),
        "m.toml:27:19: axis Z: `stroke` has the number 9.223372036854776e18 mm, beyond ±100000 mm (100 m), the largest length of a machine description",
    );
    check(
        &edit("[10.0, 0, 5.0]", "[10.0, 0, 1e308]"),
        "m.toml:21:20: `offset` has the number 1e308 mm, beyond ±100000 mm (100 m), the largest length of a machine description",
    );
}

#[test]
fn shortest_stroke() {
    assert_eq!(MIN_STROKE_MM, 1e-3);
    assert_eq!(
        parse(&edit("[-500.0, 500.0]", "[0, 0.001]")).axes[0].limits,
        [0.0, 1e-3]
    );
    check(
        &edit("[-500.0, 500.0]", "[0.0, 0.0005]"),
        "m.toml:10:10: axis X: `stroke` is 0.0005 mm long, shorter than 0.001 mm (1 µm), the shortest stroke of a linear axis",
    );
    check(
        &edit("[-500.0, 500.0]", "[1e-300, 2e-300]"),
        "m.toml:10:10: axis X: `stroke` is 1e-300 mm long, shorter than 0.001 mm (1 µm), the shortest stroke of a linear axis",
    );
}

#[test]
fn rotary_ranges() {
    assert_eq!(MAX_RANGE_DEG, 3600.0);
    assert_eq!(
        parse(&edit("[-360.0, 360.0]", "[-3600, 3600.0]")).axes[1].limits,
        [-3600.0, 3600.0]
    );
    check(
        &edit("[-360.0, 360.0]", "[-3601, 360.0]"),
        "m.toml:17:10: axis C: `range` has the number -3601 degrees, beyond ±3600 degrees (ten turns), the largest range of a rotary axis; leave `range` out for an axis that turns without limit",
    );
    check(
        &edit("[-360.0, 360.0]", "[-1e308, 1e308]"),
        "m.toml:17:10: axis C: `range` has the number -1e308 degrees, beyond ±3600 degrees (ten turns), the largest range of a rotary axis; leave `range` out for an axis that turns without limit",
    );
}
