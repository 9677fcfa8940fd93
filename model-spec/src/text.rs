//! Text for people: reading a file bounded in size, UTF-8, with located errors; and the one
//! way lines are wrapped ([`wrap`]).
//!
//! [`read_text`] reads at most one byte more than its limit, so that a huge file, a device
//! that never ends or a pipe fed without end is refused quickly and with bounded memory;
//! [`read_text_hashed`] gives the [`Digest`] of the bytes it read too, so that a verb names the
//! file it read without opening it again.
//! [`decode_text`] drops a UTF-8 byte-order mark (some editors write one) and refuses bytes
//! that are not UTF-8 with the line and column of the first one, counted like every other
//! location ([`crate::locate`]).
//!
//! ```
//! use model_spec::text::decode_text;
//! let bytes = b"\xef\xbb\xbfname = \"a\"\n# r\xc3\xa9sum\xc3\xa9 \xff\n".to_vec();
//! let e = decode_text("m.toml", bytes).unwrap_err();
//! assert_eq!(e.to_string(), "m.toml:2:10: not UTF-8 text (byte 0xff)");
//! assert_eq!(decode_text("m.toml", b"\xef\xbb\xbfx = 1".to_vec()).unwrap(), "x = 1");
//! ```

use crate::locate::line_col;
use crate::sha256::Digest;
use std::io::Read;
use std::path::Path;

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const BOM: &[u8] = b"\xef\xbb\xbf";

/// Why a text file could not be read. Every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum TextError {
    /// The file could not be opened or read.
    #[error("cannot read `{file}`: {error}")]
    Io {
        /// The file, as given.
        file: String,
        /// What the system said.
        error: std::io::Error,
    },
    /// The file has more bytes than the limit (it was read no further).
    #[error("`{file}` is larger than {}, the most this file may have", bytes(*.limit))]
    TooLarge {
        /// The file, as given.
        file: String,
        /// The most bytes the file may have.
        limit: u64,
    },
    /// A byte that is not part of UTF-8 text; the location is that of the first such byte.
    #[error("{file}:{line}:{column}: not UTF-8 text (byte 0x{byte:02x})")]
    NotUtf8 {
        /// The file, as given.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column, in characters (the byte-order mark not counted).
        column: usize,
        /// The offending byte.
        byte: u8,
    },
}

/// A size for people: `1048576 bytes (1 MiB)`, `2048 bytes (2 KiB)`, `100 bytes`.
fn bytes(n: u64) -> String {
    const KIB: u64 = 1 << 10;
    const MIB: u64 = 1 << 20;
    if n >= MIB && n.is_multiple_of(MIB) {
        format!("{n} bytes ({} MiB)", n / MIB)
    } else if n >= KIB && n.is_multiple_of(KIB) {
        format!("{n} bytes ({} KiB)", n / KIB)
    } else {
        format!("{n} bytes")
    }
}

/// The text of the file at `path`, of at most `max_bytes` bytes, as [`decode_text`] decodes
/// it. Reads at most `max_bytes + 1` bytes whatever the file is (a regular file, a device, a
/// pipe): a longer one gives [`TextError::TooLarge`] without being read to its end. Messages
/// name the file as `path.display()` writes it.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, TextError> {
    read_text_hashed(path, max_bytes).map(|(text, _)| text)
}

/// [`read_text`], with the [`Digest`] of the bytes read (byte-order mark included): what
/// identifies the file the text came from, hashed as it was read (the file is opened once).
pub fn read_text_hashed(path: &Path, max_bytes: u64) -> Result<(String, Digest), TextError> {
    let (bytes, digest) = read_bytes_hashed(path, max_bytes)?;
    Ok((decode_text(&path.display().to_string(), bytes)?, digest))
}

/// The bytes of the file at `path`, at most `max_bytes` of them, with their [`Digest`]: opened
/// once, read at most `max_bytes + 1` bytes whatever the file is (a longer one gives
/// [`TextError::TooLarge`] without being read to its end). For a reader that decodes the
/// bytes itself.
pub fn read_bytes_hashed(path: &Path, max_bytes: u64) -> Result<(Vec<u8>, Digest), TextError> {
    let file = path.display().to_string();
    let io = |error| TextError::Io {
        file: file.clone(),
        error,
    };
    let handle = std::fs::File::open(path).map_err(io)?;
    // Room for the whole file at once (a pipe's length is not known: then grown as read).
    let size = handle.metadata().map_or(0, |m| m.len().min(max_bytes));
    read_into(
        &file,
        handle,
        max_bytes,
        Vec::with_capacity(size as usize + 1),
    )
}

/// At most `max_bytes` bytes of `source` (named `file` in messages) with their [`Digest`]:
/// reads at most `max_bytes + 1` bytes, and a source with more gives [`TextError::TooLarge`].
pub fn read_bytes_from(
    file: &str,
    source: impl Read,
    max_bytes: u64,
) -> Result<(Vec<u8>, Digest), TextError> {
    read_into(file, source, max_bytes, Vec::new())
}

/// [`read_bytes_from`] into `bytes` (empty, with the capacity the caller expects).
fn read_into(
    file: &str,
    source: impl Read,
    max_bytes: u64,
    mut bytes: Vec<u8>,
) -> Result<(Vec<u8>, Digest), TextError> {
    source
        .take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|error| TextError::Io {
            file: file.to_string(),
            error,
        })?;
    if bytes.len() as u64 > max_bytes {
        return Err(TextError::TooLarge {
            file: file.to_string(),
            limit: max_bytes,
        });
    }
    let digest = Digest::of(&bytes);
    Ok((bytes, digest))
}

/// `bytes` as text: without a leading UTF-8 byte-order mark, or [`TextError::NotUtf8`] at the
/// first byte that is not UTF-8 (`file_name` names the source in the message).
pub fn decode_text(file_name: &str, mut bytes: Vec<u8>) -> Result<String, TextError> {
    if bytes.starts_with(BOM) {
        bytes.drain(..BOM.len());
    }
    String::from_utf8(bytes).map_err(|e| {
        let bad = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        // Valid UTF-8 up to `bad`, so the lossy decoding is exact.
        let before = String::from_utf8_lossy(&bytes[..bad]);
        let (line, column) = line_col(&before, before.len());
        TextError::NotUtf8 {
            file: file_name.to_string(),
            line,
            column,
            byte: bytes[bad],
        }
    })
}

/// Why a free text of a description (a machine's, a sub-model's or an instrument's
/// `description`) is refused, or `None` when it is accepted. Refused: the text-direction
/// controls U+202A–U+202E and U+2066–U+2069, which make text display in another order than it
/// is stored (rustc refuses them in generated code's comments and literals, and a terminal or
/// a report would show a misleading text), and control characters other than a tab or a line
/// break. The reason names the code point and its position, counted in characters from 1.
///
/// ```
/// use model_spec::text::free_text_refusal;
/// assert_eq!(free_text_refusal("Five-axis mill\n(trunnion)"), None);
/// assert_eq!(
///     free_text_refusal("x\u{202e}y").unwrap(),
///     "holds U+202E at character 2, a text-direction control (it shows the text in another order than it is stored): remove it"
/// );
/// ```
pub fn free_text_refusal(text: &str) -> Option<String> {
    let (at, c) = text.chars().enumerate().find(|&(_, c)| refused(c))?;
    let what = if is_text_direction_control(c) {
        "a text-direction control (it shows the text in another order than it is stored)"
    } else {
        "a control character"
    };
    Some(format!(
        "holds U+{:04X} at character {}, {what}: remove it",
        u32::from(c),
        at + 1
    ))
}

/// A description's text as a validator takes it: trimmed, empty when there is none, or the
/// span of the TOML value and why it is refused ([`free_text_refusal`]).
pub fn description_text(
    raw: Option<&toml::Spanned<String>>,
) -> Result<String, (std::ops::Range<usize>, String)> {
    let Some(raw) = raw else {
        return Ok(String::new());
    };
    match free_text_refusal(raw.get_ref()) {
        None => Ok(raw.get_ref().trim().to_string()),
        Some(why) => Err((raw.span(), format!("description {why}"))),
    }
}

/// `text` with every character a description may not hold ([`free_text_refusal`]) written
/// as `<U+XXXX>`, for a description rtest writes from text it did not choose (a file name).
///
/// ```
/// use model_spec::text::{free_text_refusal, visible_text};
/// assert_eq!(visible_text("a\u{7}b\u{202e}\tc"), "a<U+0007>b<U+202E>\tc");
/// assert_eq!(free_text_refusal(&visible_text("a\u{7}b\u{202e}")), None);
/// ```
pub fn visible_text(text: &str) -> String {
    text.chars()
        .map(|c| {
            if refused(c) {
                format!("<U+{:04X}>", u32::from(c))
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A character no description may hold: a text-direction control, or a control character
/// other than a tab or a line break.
fn refused(c: char) -> bool {
    is_text_direction_control(c) || (c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
}

/// The bidirectional embedding, override and isolate controls (U+202A–U+202E, U+2066–U+2069).
fn is_text_direction_control(c: char) -> bool {
    matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
}

/// `text` as a message quotes it: whole when it has at most 40 characters, else its first 16
/// and `…` (a 70 000-character name given by mistake makes no 70 kB message).
///
/// ```
/// use model_spec::text::quoted_start;
/// assert_eq!(quoted_start("high"), "high");
/// assert_eq!(quoted_start(&"a".repeat(70_000)), format!("{}…", "a".repeat(16)));
/// ```
pub fn quoted_start(text: &str) -> String {
    if text.chars().count() <= 40 {
        text.to_string()
    } else {
        let start: String = text.chars().take(16).collect();
        format!("{start}…")
    }
}

/// `pieces` joined by single spaces into lines of at most `width` characters, greedily; lines
/// after the first start with `indent` (counted in the width). A piece longer than a line stays
/// whole on a line of its own. No piece gives one empty line.
pub fn wrap<S: AsRef<str>>(
    pieces: impl IntoIterator<Item = S>,
    width: usize,
    indent: &str,
) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for piece in pieces {
        let piece = piece.as_ref();
        if !line.is_empty() && line.chars().count() + 1 + piece.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if line.is_empty() {
            if !lines.is_empty() {
                line.push_str(indent);
            }
        } else {
            line.push(' ');
        }
        line.push_str(piece);
    }
    lines.push(line);
    lines
}

/// `items` as pieces of a list: each but the last followed by `separator` (`a,` `b,` `c`).
pub fn list_pieces(items: &[String], separator: &str) -> Vec<String> {
    let n = items.len();
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            if i + 1 < n {
                format!("{item}{separator}")
            } else {
                item.clone()
            }
        })
        .collect()
}
