//! Where the values a correction changes are written in a machine description's text: the
//! default of every symbol, the `offset` of every axis entry (each coordinate's span, or
//! where a missing `offset` goes) and the `direction` of every axis entry. Read with the TOML parser's spans, so that the text can be
//! edited in place and everything else kept byte for byte.

use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use toml::Spanned;

/// The parts of a description this module reads; every other key is ignored (the description
/// has been validated already).
#[derive(Deserialize)]
struct Doc {
    #[serde(default)]
    symbols: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    work: Vec<Spanned<Entry>>,
    #[serde(default)]
    tool: Vec<Spanned<Entry>>,
}

/// One chain entry: its axis letter (for an axis), its offset and its direction.
#[derive(Deserialize)]
struct Entry {
    axis: Option<Spanned<String>>,
    offset: Option<Spanned<Vec<Spanned<toml::Value>>>>,
    direction: Option<Spanned<toml::Value>>,
}

/// Where an axis's offset is written.
#[derive(Clone, Debug, PartialEq)]
pub enum OffsetPlace {
    /// The byte ranges of its three coordinates (`offset = [x, y, z]`).
    Written([Range<usize>; 3]),
    /// No `offset` key: a new `offset = [x, y, z]` goes at `at` (a byte offset), as its own
    /// line (`inline: false`: after the axis line, which is the entry's line holding `axis`)
    /// or as `, offset = [x, y, z]` inside the inline table (`inline: true`: after the axis
    /// value).
    Missing {
        /// Where the insertion goes.
        at: usize,
        /// The entry is an inline table.
        inline: bool,
    },
}

/// The spans of a description's text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Spans {
    /// Each symbol's default value, by symbol name.
    pub symbols: BTreeMap<String, Range<usize>>,
    /// Each axis's offset, by axis letter.
    pub offsets: BTreeMap<String, OffsetPlace>,
    /// Each axis's direction value (`"+z"` with its quotes, or `[0, -1, 1]`), by axis letter.
    pub directions: BTreeMap<String, Range<usize>>,
}

/// The spans of `text`, or why they cannot be read (a text that does not parse as TOML, or an
/// offset that is not three entries: the text is then not that of a valid description).
pub fn read(text: &str) -> Result<Spans, String> {
    let doc: Doc = toml::from_str(text).map_err(|e| e.to_string())?;
    let mut spans = Spans {
        symbols: doc
            .symbols
            .iter()
            .map(|(k, v)| (k.clone(), v.span()))
            .collect(),
        ..Spans::default()
    };
    for entry in doc.work.iter().chain(&doc.tool) {
        let start = entry.span().start;
        let entry = entry.get_ref();
        let Some(axis) = &entry.axis else { continue };
        if let Some(d) = &entry.direction {
            spans.directions.insert(axis.get_ref().clone(), d.span());
        }
        let place = match &entry.offset {
            Some(list) => {
                let items = list.get_ref();
                if items.len() != 3 {
                    return Err(format!(
                        "the offset of axis {} has {} entries, not three",
                        axis.get_ref(),
                        items.len()
                    ));
                }
                OffsetPlace::Written(std::array::from_fn(|k| items[k].span()))
            }
            None => {
                let inline = text[start..].trim_start().starts_with('{');
                let end = axis.span().end;
                let at = if inline {
                    end
                } else {
                    text[end..].find('\n').map_or(text.len(), |i| end + i + 1)
                };
                OffsetPlace::Missing { at, inline }
            }
        };
        spans.offsets.insert(axis.get_ref().clone(), place);
    }
    Ok(spans)
}

/// `text` with every `(range, replacement)` applied; the ranges do not overlap (an insertion
/// is an empty range).
pub fn apply(text: &str, mut edits: Vec<(Range<usize>, String)>) -> String {
    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = String::with_capacity(text.len() + 64);
    let mut at = 0;
    for (r, with) in edits {
        out.push_str(&text[at..r.start]);
        out.push_str(&with);
        at = r.end;
    }
    out.push_str(&text[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"name = "t"
[symbols]
Xa = 0.0   # comment
"Ya" = 2

[[work]]
axis = "A"   # tilting
type = "rotary"
direction = "+x"
offset = ["Xa", "Ya", 0]

[[work]]
axis = "C"
type = "rotary"
direction = "+z"

[[work]]
end = "ball"

[[tool]]
end = "probe"
"#;

    #[test]
    fn symbols_offsets_and_missing_offsets_are_found() {
        let s = read(TEXT).unwrap();
        assert_eq!(&TEXT[s.symbols["Xa"].clone()], "0.0");
        assert_eq!(&TEXT[s.symbols["Ya"].clone()], "2");
        let OffsetPlace::Written(a) = &s.offsets["A"] else {
            panic!("{:?}", s.offsets["A"])
        };
        assert_eq!(&TEXT[a[0].clone()], "\"Xa\"");
        assert_eq!(&TEXT[a[2].clone()], "0");
        assert_eq!(&TEXT[s.directions["A"].clone()], "\"+x\"");
        assert_eq!(&TEXT[s.directions["C"].clone()], "\"+z\"");
        let OffsetPlace::Missing { at, inline } = s.offsets["C"] else {
            panic!("{:?}", s.offsets["C"])
        };
        assert!(!inline);
        assert!(TEXT[..at].ends_with("axis = \"C\"\n"), "{}", &TEXT[..at]);
        let edited = apply(
            TEXT,
            vec![
                (at..at, "offset = [1, 0, 0]\n".into()),
                (a[2].clone(), "0.5".into()),
            ],
        );
        assert!(edited.contains("offset = [\"Xa\", \"Ya\", 0.5]\n"));
        assert!(edited.contains("axis = \"C\"\noffset = [1, 0, 0]\ntype = \"rotary\""));
    }

    #[test]
    fn an_inline_entry_takes_the_offset_after_its_axis() {
        let text = "name = \"t\"\nwork = [{ axis = \"C\", type = \"rotary\", direction = \"+z\" }, { end = \"b\" }]\n";
        let s = read(text).unwrap();
        let OffsetPlace::Missing { at, inline } = s.offsets["C"] else {
            panic!()
        };
        assert!(inline);
        assert!(text[..at].ends_with("axis = \"C\""));
        assert_eq!(&text[s.directions["C"].clone()], "\"+z\"");
    }
}
