//! Where a byte of a text is, in the words of an editor: the 1-based line and the 1-based
//! column counted in characters (Unicode scalar values), so that `file:line:column` in a
//! message points at the same place in any editor, whatever the text's non-ASCII letters.
//!
//! Every reader of a text file for people (machine descriptions, and the truth, JSON and CSV
//! files of the numeric crates) locates its messages with [`line_col`], so that they agree.
//!
//! ```
//! use model_spec::locate::{Locator, line_col};
//! let text = "name = \"a\"\nZé = 1e999\n";
//! assert_eq!(line_col(text, 0), (1, 1));
//! assert_eq!(line_col(text, text.find('=').unwrap()), (1, 6));
//! assert_eq!(line_col(text, text.find("1e999").unwrap()), (2, 6)); // `é` is one column
//! let e = Locator::new("m.toml", text).error(17..22, "too large");
//! assert_eq!(e.to_string(), "m.toml:2:6: too large");
//! ```

use crate::SpecError;
use std::ops::Range;

/// The 1-based line and column (in characters) of byte offset `byte` of `text`.
///
/// An offset past the end is taken as the end of the text, and an offset inside a multi-byte
/// character as the start of that character, so any offset gives a place in the text. A line
/// ends after each `\n` (a `\r` before it belongs to the line it ends).
pub fn line_col(text: &str, byte: usize) -> (usize, usize) {
    let mut at = byte.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = text[line_start..at].chars().count() + 1;
    (line, column)
}

/// Maps the byte offsets of one source text to lines and columns, and makes located errors.
#[derive(Clone, Copy, Debug)]
pub struct Locator<'a> {
    /// The name of the source in messages: a path, or `<built-in NAME>`.
    pub file: &'a str,
    /// The whole text the offsets refer to.
    pub text: &'a str,
}

impl<'a> Locator<'a> {
    /// A locator for `text`, called `file` in messages.
    pub fn new(file: &'a str, text: &'a str) -> Self {
        Locator { file, text }
    }

    /// The 1-based line and column (in characters) of byte offset `at`; see [`line_col`].
    pub fn line_col(&self, at: usize) -> (usize, usize) {
        line_col(self.text, at)
    }

    /// An error at the start of `span` (a byte range of the text).
    pub fn error(&self, span: Range<usize>, message: impl Into<String>) -> SpecError {
        let (line, column) = self.line_col(span.start);
        SpecError {
            file: self.file.to_string(),
            line,
            column,
            message: message.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::line_col;

    #[test]
    fn lines_and_columns() {
        let text = "ab\r\nçd\n\nx";
        assert_eq!(line_col(text, 0), (1, 1));
        assert_eq!(line_col(text, 2), (1, 3)); // the `\r`
        assert_eq!(line_col(text, 4), (2, 1));
        assert_eq!(line_col(text, 6), (2, 2)); // after the two bytes of `ç`
        assert_eq!(line_col(text, 5), (2, 1)); // inside `ç`: its start
        assert_eq!(line_col(text, 8), (3, 1));
        assert_eq!(line_col(text, 9), (4, 1));
        assert_eq!(line_col(text, 10), (4, 2)); // the end
        assert_eq!(line_col(text, 1000), (4, 2)); // past the end: the end
        assert_eq!(line_col("", 3), (1, 1));
    }
}
