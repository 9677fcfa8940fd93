//! The one helper of the TOML files rtest reads beside the machine description (truths,
//! campaigns, squareness measurements, tolerances): the document parsed, every problem located
//! by file, line and column, and the typed values every reader needs.
//!
//! Lines and columns are 1-based, columns counted in characters, as every other location of
//! rtest ([`model_spec::locate::line_col`]).
//!
//! ```
//! use formats::located::TomlText;
//! let t = TomlText::new("t.toml", "noise_um = \"half\"\n");
//! let root = t.root().unwrap();
//! let (_, v) = formats::located::in_order(root.get_ref())[0];
//! let e = t.number(v, "`noise_um`").unwrap_err();
//! assert_eq!(e.to_string(), "t.toml:1:12: `noise_um` must be a number, not string");
//! ```

use std::borrow::Cow;
use std::ops::Range;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// A key of a TOML table, with its place in the text.
pub type Key<'i> = Spanned<Cow<'i, str>>;

/// A value of a TOML table, with its place in the text.
pub type Val<'i> = Spanned<DeValue<'i>>;

/// A problem at a place in a file: `file:line:column: message`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct Located {
    /// The file, as named in messages (or `<built-in NAME>`).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong and what would be right.
    pub message: String,
}

/// The text of a TOML file being read, and the name messages give it.
#[derive(Clone, Copy, Debug)]
pub struct TomlText<'a> {
    file: &'a str,
    text: &'a str,
}

impl<'a> TomlText<'a> {
    /// The text `text` of the file named `file` in messages, without a leading byte-order
    /// mark (offsets and columns are counted after it).
    pub fn new(file: &'a str, text: &'a str) -> Self {
        TomlText {
            file,
            text: text.strip_prefix('\u{feff}').unwrap_or(text),
        }
    }

    /// The file's name in messages.
    pub fn file(&self) -> &'a str {
        self.file
    }

    /// The text read (without its byte-order mark).
    pub fn text(&self) -> &'a str {
        self.text
    }

    /// The document's root table.
    ///
    /// # Errors
    /// The TOML syntax error, located.
    pub fn root(&self) -> Result<Spanned<DeTable<'a>>, Located> {
        DeTable::parse(self.text).map_err(|e| self.at(e.span().unwrap_or(0..0), e.message()))
    }

    /// The 1-based line and column (in characters) of byte offset `offset`.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        model_spec::locate::line_col(self.text, offset)
    }

    /// The 1-based line of the start of `span`.
    pub fn line(&self, span: &Range<usize>) -> usize {
        self.line_col(span.start).0
    }

    /// `message` located at the start of `span`.
    pub fn at(&self, span: Range<usize>, message: impl Into<String>) -> Located {
        let (line, column) = self.line_col(span.start);
        Located {
            file: self.file.to_string(),
            line,
            column,
            message: message.into(),
        }
    }

    /// The string `v`; `what` names it in the message (`` `machine` ``).
    ///
    /// # Errors
    /// `{what} must be a string, not {type}`.
    pub fn string(&self, v: &Val<'_>, what: &str) -> Result<String, Located> {
        match v.get_ref() {
            DeValue::String(s) => Ok(s.to_string()),
            other => Err(self.at(
                v.span(),
                format!("{what} must be a string, not {}", other.type_str()),
            )),
        }
    }

    /// The finite number `v` and the decimal text it was written as (an integer in another
    /// radix written in decimal); `what` names it in the message.
    ///
    /// # Errors
    /// `{what} must be a number, not {type}`, `{what}: integer out of range`, or
    /// ``{what} must be a finite number, not `{text}` `` (`inf`, `nan`).
    pub fn number(&self, v: &Val<'_>, what: &str) -> Result<(f64, String), Located> {
        number(v, what).map_err(|m| self.at(v.span(), m))
    }
}

/// The finite number `v` and the decimal text it was written as, or the message saying why
/// not (for a reader that locates it itself); `what` names it in the message.
///
/// # Errors
/// As [`TomlText::number`], the message alone.
pub fn number(v: &Val<'_>, what: &str) -> Result<(f64, String), String> {
    let text = match v.get_ref() {
        DeValue::Float(f) => f.as_str().to_string(),
        DeValue::Integer(i) => match i.radix() {
            10 => i.as_str().to_string(),
            r => i64::from_str_radix(i.as_str(), r)
                .map(|x| x.to_string())
                .map_err(|_| format!("{what}: integer out of range"))?,
        },
        other => return Err(format!("{what} must be a number, not {}", other.type_str())),
    };
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok((x, text)),
        _ => Err(format!("{what} must be a finite number, not `{text}`")),
    }
}

/// The entries of table `t` in the order of the file, so that the first problem reported is
/// the first in the file.
pub fn in_order<'t, 'i>(t: &'t DeTable<'i>) -> Vec<(&'t Key<'i>, &'t Val<'i>)> {
    let mut v: Vec<_> = t.iter().collect();
    v.sort_by_key(|(k, _)| k.span().start);
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first(text: &str) -> (TomlText<'_>, Spanned<DeTable<'_>>) {
        let t = TomlText::new("f.toml", text);
        let root = t.root().unwrap();
        (t, root)
    }

    #[test]
    fn numbers_keep_their_decimal_text_and_refuse_what_is_not_finite() {
        let (t, root) = first("a = 1.50\nb = 0x10\nc = inf\nd = [1]\n");
        let v = in_order(root.get_ref());
        assert_eq!(t.number(v[0].1, "`a`").unwrap(), (1.5, "1.50".into()));
        assert_eq!(t.number(v[1].1, "`b`").unwrap(), (16.0, "16".into()));
        assert_eq!(
            t.number(v[2].1, "`c`").unwrap_err().to_string(),
            "f.toml:3:5: `c` must be a finite number, not `inf`"
        );
        assert_eq!(
            t.number(v[3].1, "`d`").unwrap_err().to_string(),
            "f.toml:4:5: `d` must be a number, not array"
        );
    }

    #[test]
    fn syntax_errors_and_places_are_located_after_a_byte_order_mark() {
        let t = TomlText::new("f.toml", "\u{feff}x = 1\ny = \n");
        let e = t.root().unwrap_err();
        assert_eq!((e.file.as_str(), e.line), ("f.toml", 2));
        let (t, root) = first("x = 1\n  \"é\" = \"s\"\n");
        let (k, v) = in_order(root.get_ref())[1];
        assert_eq!(t.line_col(k.span().start), (2, 3));
        // Columns count characters: the value starts after the two-byte `é`.
        assert_eq!(t.line_col(v.span().start), (2, 9));
        assert_eq!(t.string(v, "`é`").unwrap(), "s");
        assert_eq!(
            t.string(in_order(root.get_ref())[0].1, "`x`")
                .unwrap_err()
                .message,
            "`x` must be a string, not integer"
        );
    }
}
