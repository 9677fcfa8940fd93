//! No input panics: mutated versions of the built-in descriptions parse to `Ok` or to an `Err`
//! whose location lies inside the text.

use model_spec::{BUILTIN, parse_machine};
use proptest::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Parses `text`; panics with the mutation's description if parsing panics or if an error's
/// location is outside the text.
fn check(what: &str, text: &str) {
    let result = catch_unwind(AssertUnwindSafe(|| parse_machine("mut.toml", text)));
    let Ok(result) = result else {
        panic!("parse_machine panicked on {what}:\n{text}");
    };
    if let Err(e) = result {
        let lines: Vec<&str> = text.split('\n').collect();
        assert_eq!(e.file, "mut.toml");
        assert!(
            e.line >= 1 && e.line <= lines.len(),
            "{what}: line {} outside 1..={} ({e})",
            e.line,
            lines.len()
        );
        let width = lines[e.line - 1].chars().count();
        assert!(
            e.column >= 1 && e.column <= width + 1,
            "{what}: column {} outside 1..={} of line {} ({e})",
            e.column,
            width + 1,
            e.line
        );
        assert!(!e.message.is_empty(), "{what}: empty message");
        assert_eq!(
            e.to_string(),
            format!("mut.toml:{}:{}: {}", e.line, e.column, e.message)
        );
    }
}

/// Byte ranges of the numbers (integers and floats) in `text`, outside comments.
fn numbers(text: &str) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let bytes = code.as_bytes();
        let mut i = 0;
        let mut in_string = false;
        while i < bytes.len() {
            let c = bytes[i];
            if c == b'"' {
                in_string = !in_string;
                i += 1;
            } else if !in_string
                && (c.is_ascii_digit() || c == b'-')
                && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric())
            {
                let start = i;
                i += 1;
                while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                    i += 1;
                }
                if bytes[start..i].iter().any(u8::is_ascii_digit) {
                    out.push(offset + start..offset + i);
                }
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    out
}

/// `true` when the number at byte `at` of `text` is a component of a direction vector
/// (`direction = [0, 1, 1]`): such a vector is reported as a whole, not by its number.
fn in_direction_vector(text: &str, at: usize) -> bool {
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    text[line_start..at].trim_start().starts_with("direction")
}

/// The numbers of `text` that are not components of a direction vector.
fn scalar_numbers(text: &str) -> Vec<std::ops::Range<usize>> {
    numbers(text)
        .into_iter()
        .filter(|r| !in_direction_vector(text, r.start))
        .collect()
}

/// The numbers of `text` that are components of a direction vector, with the byte where the
/// vector starts.
fn direction_numbers(text: &str) -> Vec<(std::ops::Range<usize>, usize)> {
    numbers(text)
        .into_iter()
        .filter(|r| in_direction_vector(text, r.start))
        .map(|r| {
            let open = text[..r.start].rfind('[').expect("a vector");
            (r, open)
        })
        .collect()
}

#[test]
fn numbers_are_found() {
    let seed = BUILTIN[0].1;
    let found: Vec<&str> = numbers(seed).into_iter().map(|r| &seed[r]).collect();
    assert!(found.contains(&"-217.504"), "{found:?}");
    assert!(found.contains(&"-120.0"), "{found:?}");
    assert!(!found.iter().any(|n| n.contains('a')));
}

#[test]
fn every_line_deleted_or_duplicated() {
    for (name, text) in BUILTIN {
        let lines: Vec<&str> = text.lines().collect();
        for i in 0..lines.len() {
            let mut deleted = lines.clone();
            deleted.remove(i);
            check(
                &format!("{name} without line {}", i + 1),
                &deleted.join("\n"),
            );
            let mut doubled = lines.clone();
            doubled.insert(i, lines[i]);
            check(
                &format!("{name} with line {} twice", i + 1),
                &doubled.join("\n"),
            );
            let mut swapped = lines.clone();
            if i + 1 < lines.len() {
                swapped.swap(i, i + 1);
                check(
                    &format!("{name} with lines {} and {} swapped", i + 1, i + 2),
                    &swapped.join("\n"),
                );
            }
        }
    }
}

#[test]
fn every_number_replaced() {
    let replacements = [
        "nan",
        "+nan",
        "-nan",
        "inf",
        "-inf",
        "1e999",
        "-1e999",
        "0",
        "-0.0",
        "1e-320",
        "9223372036854775807",
        "99999999999999999999",
        "\"x\"",
        "true",
        "[]",
        "[1, 2]",
        "{}",
        "",
    ];
    for (name, text) in BUILTIN {
        for range in numbers(text) {
            for r in replacements {
                let mut mutated = text.to_string();
                mutated.replace_range(range.clone(), r);
                check(
                    &format!(
                        "{name} with `{}` at byte {} replaced by `{r}`",
                        &text[range.clone()],
                        range.start
                    ),
                    &mutated,
                );
            }
        }
    }
}

/// Line and column (1-based, in characters) of byte `at` of `text`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, text[start..at].chars().count() + 1)
}

#[test]
fn every_number_replaced_by_nan_is_reported_where_it_is() {
    for (name, text) in BUILTIN {
        for range in scalar_numbers(text) {
            for r in ["nan", "-inf"] {
                let mut mutated = text.to_string();
                mutated.replace_range(range.clone(), r);
                let e = parse_machine("mut.toml", &mutated).unwrap_err();
                let at = line_col(text, range.start);
                assert_eq!((e.line, e.column), at, "{name}: {e}");
                assert!(e.message.contains("non-finite"), "{name}: {e}");
            }
        }
    }
}

#[test]
fn every_number_replaced_by_a_huge_one_is_reported_where_it_is() {
    // Finite, but beyond the bounds of `model_spec::limits`: an `inf` later on.
    for (name, text) in BUILTIN {
        for range in scalar_numbers(text) {
            for r in ["1e308", "-1e308", "123456"] {
                let mut mutated = text.to_string();
                mutated.replace_range(range.clone(), r);
                let e = parse_machine("mut.toml", &mutated).unwrap_err();
                let at = line_col(text, range.start);
                assert_eq!((e.line, e.column), at, "{name}: {e}");
                assert!(e.message.contains(" beyond ±"), "{name}: {e}");
            }
        }
    }
}

#[test]
fn every_prefix() {
    for (name, text) in BUILTIN {
        for (i, _) in text.char_indices() {
            check(&format!("{name} cut at byte {i}"), &text[..i]);
        }
    }
}

#[test]
fn odd_texts() {
    for text in [
        "",
        "\n",
        "\u{feff}",
        "name",
        "name =",
        "name = \"\"",
        "name = \"é\"\n[[work]]\naxis = \"é\"",
        "[[work]]",
        "work = 1",
        "work = [1]",
        "work = [[]]",
        "[work]\naxis = \"X\"",
        "name = \"a\"\n[symbols]\n\"\" = 1",
        "name = \"a\"\nmodels = 1",
        "name = \"a\"\n[models]\nx = 1",
        "name = \"a\"\n[errors]\ninclude = \"EXX\"",
        "name = \"a\"\n[[work]]\nend = \"b\"\noffset = [[1], 2, 3]",
        "\u{0}",
        "name = \"a\"\r\n[[work]]\r\nend = \"b\"\r\n[[tool]]\r\nend = \"p\"\r\n",
    ] {
        check(&format!("{text:?}"), text);
    }
}

/// Pieces of TOML (and of non-TOML) that random edits insert.
const PIECES: &[&str] = &[
    "\n",
    " ",
    "=",
    "\"",
    "[",
    "]",
    "[[",
    "]]",
    ",",
    "#",
    "nan",
    "inf",
    "-",
    ".",
    "0",
    "1e3",
    "\"X\"",
    "\"A\"",
    "\"W\"",
    "axis",
    "link",
    "end",
    "type",
    "direction",
    "offset",
    "stroke",
    "range",
    "[[work]]\n",
    "[[tool]]\n",
    "[errors]\n",
    "[models.m]\n",
    "errors = [\"XOC\"]\n",
    "include = [\"EXX\"]\n",
    "exclude = [\"X0C\"]\n",
    "squareness_order = [\"X\", \"Y\", \"Z\"]\n",
    "é",
    "\u{1F600}",
    "\t",
    "\r\n",
    "{",
    "}",
    "'",
    "'''",
    "\"\"\"",
];

#[derive(Clone, Debug)]
enum Edit {
    Delete { at: usize, len: usize },
    Insert { at: usize, piece: usize },
    Swap { a: usize, b: usize },
}

fn apply(text: &str, edits: &[Edit]) -> String {
    let mut t = text.to_string();
    for e in edits {
        let boundary = |t: &str, at: usize| {
            let mut at = at % (t.len() + 1);
            while !t.is_char_boundary(at) {
                at -= 1;
            }
            at
        };
        match *e {
            Edit::Delete { at, len } => {
                let start = boundary(&t, at);
                let end = boundary(&t, (start + len).min(t.len()));
                t.replace_range(start..end.max(start), "");
            }
            Edit::Insert { at, piece } => {
                let at = boundary(&t, at);
                t.insert_str(at, PIECES[piece % PIECES.len()]);
            }
            Edit::Swap { a, b } => {
                let mut lines: Vec<&str> = t.lines().collect();
                if !lines.is_empty() {
                    let (a, b) = (a % lines.len(), b % lines.len());
                    lines.swap(a, b);
                }
                t = lines.join("\n");
            }
        }
    }
    t
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), 0usize..40).prop_map(|(at, len)| Edit::Delete { at, len }),
        (any::<usize>(), any::<usize>()).prop_map(|(at, piece)| Edit::Insert { at, piece }),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Edit::Swap { a, b }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn random_edits_never_panic(
        which in 0..BUILTIN.len(),
        edits in proptest::collection::vec(edit(), 1..6),
    ) {
        let text = apply(BUILTIN[which].1, &edits);
        check(&format!("{} with {edits:?}", BUILTIN[which].0), &text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        check("arbitrary text", &text);
    }

    /// Random bytes, decoded as a machine file is read (UTF-8, a byte-order mark dropped):
    /// an error located at a line and column, or a description that parses or is refused
    /// with a location.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        match model_spec::text::decode_text("mut.toml", bytes.clone()) {
            Ok(text) => check("arbitrary bytes", &text),
            Err(e) => {
                let s = e.to_string();
                prop_assert!(s.starts_with("mut.toml:"), "{}", s);
            }
        }
    }
}

#[test]
fn a_direction_vector_with_a_non_finite_component_is_reported_at_the_vector() {
    let mut count = 0;
    for (name, text) in BUILTIN {
        for (range, open) in direction_numbers(text) {
            for r in ["nan", "-inf", "inf"] {
                let mut mutated = text.to_string();
                mutated.replace_range(range.clone(), r);
                let e = parse_machine("mut.toml", &mutated).unwrap_err();
                assert_eq!((e.line, e.column), line_col(text, open), "{name}: {e}");
                assert!(
                    e.message
                        .contains("a direction vector needs three finite numbers"),
                    "{name}: {e}"
                );
                count += 1;
            }
        }
    }
    assert!(
        count >= 12,
        "the inclined built-in machines have direction vectors"
    );
}

#[test]
fn a_direction_vector_whose_own_frame_cannot_be_formed_is_refused() {
    for (name, text) in BUILTIN {
        for (range, _) in direction_numbers(text) {
            for r in ["1e308", "-1e308", "1e-300"] {
                let mut mutated = text.to_string();
                mutated.replace_range(range.clone(), r);
                match parse_machine("mut.toml", &mutated) {
                    Err(e) => assert!(e.message.contains("direction"), "{name}: {e}"),
                    Ok(m) => {
                        for a in &m.axes {
                            let f = a.direction.frame();
                            for i in 0..3 {
                                for j in 0..3 {
                                    let dot: f64 = (0..3).map(|k| f[i][k] * f[j][k]).sum();
                                    let want = if i == j { 1.0 } else { 0.0 };
                                    assert!(
                                        (dot - want).abs() < 1e-12,
                                        "{name} with `{r}`: axis {} has the frame {f:?}",
                                        a.name
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
