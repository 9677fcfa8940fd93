//! Why an NC program could not be read or written: every message names the file, and the line,
//! column and word where there is one.

use model_spec::text::TextError;

/// A problem with an NC program, or with the poses given to write it back.
#[derive(Debug, thiserror::Error)]
pub enum NcError {
    /// A block that cannot be read, or that is refused (see `docs/nc-programs.md`).
    #[error("{}", block_message(file, *line, *column, word, message))]
    Block {
        /// The file name, as given.
        file: String,
        /// 1-based line (every line counted).
        line: usize,
        /// 1-based column of the word, in characters.
        column: usize,
        /// The word or block at fault as written (`G91`, `IX+5`, `CYCL DEF 7.0`), if there is one.
        word: Option<String>,
        /// What is wrong, and why it is refused.
        message: String,
    },
    /// The program as a whole: no move in it, a machine whose axis letter is a word of the
    /// dialect, corrected poses that do not fit the program, options out of range.
    #[error("{file}: {message}")]
    Program {
        /// The file name, as given.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A corrected command that cannot be written in the format of the program's word.
    #[error("{file}:{line}: axis {axis}: {message}")]
    Value {
        /// The file name, as given.
        file: String,
        /// 1-based line of the pose.
        line: usize,
        /// The axis letter.
        axis: char,
        /// What is wrong.
        message: String,
    },
    /// The text could not be read: too large, not UTF-8, an I/O error.
    #[error(transparent)]
    Text(TextError),
}

fn block_message(
    file: &str,
    line: usize,
    column: usize,
    word: &Option<String>,
    message: &str,
) -> String {
    match word {
        Some(w) => format!("{file}:{line}:{column}: `{w}`: {message}"),
        None => format!("{file}:{line}:{column}: {message}"),
    }
}

/// The place of the line being read, to locate errors.
pub(crate) struct Place<'a> {
    pub(crate) file: &'a str,
    pub(crate) line: usize,
    /// The line's text (without its end and a byte-order mark).
    pub(crate) text: &'a str,
}

impl Place<'_> {
    /// The error at byte `at` of the line, about `word` (the text of the line from `at` to
    /// `end`, if `end > at`).
    pub(crate) fn err(&self, at: usize, end: usize, message: impl Into<String>) -> NcError {
        let at = at.min(self.text.len());
        let end = end.min(self.text.len());
        NcError::Block {
            file: self.file.to_string(),
            line: self.line,
            column: self.text.get(..at).map_or(at, |s| s.chars().count()) + 1,
            word: (end > at).then(|| self.text.get(at..end).unwrap_or("").to_string()),
            message: message.into(),
        }
    }
}
