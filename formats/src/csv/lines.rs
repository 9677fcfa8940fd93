//! The one line reader of every CSV reader (whole file, blocks, paths): lines of any
//! [`Read`], never more than [`ReadOptions::max_line_bytes`] of a line held, each checked to be
//! UTF-8 text before it is handed out.
//!
//! A line ends at `\n`; a `\r` before it is removed, and so is a UTF-8 byte-order mark at the
//! start of the first line. The last line needs no `\n`. Lines are numbered from 1, every line
//! counted (comments and blank lines too).

use crate::csv::{CsvError, Ctx, ReadOptions};
use std::io::Read;

/// Bytes read from the source at a time: a reader consumes at most
/// [`ReadOptions::max_line_bytes`] plus this much before it refuses a line that is too long.
pub const READ_BUFFER_BYTES: usize = 65_536;

const BOM: &[u8] = b"\xEF\xBB\xBF";

/// Lines of a byte source, bounded in length.
pub struct Lines<R> {
    reader: R,
    buf: Box<[u8]>,
    /// The unread bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    /// The beginning of the current line when it spans refills of `buf`.
    pending: Vec<u8>,
    /// Longest line accepted, bytes (its end not counted).
    max: usize,
    /// Lines handed out so far: the number of the last one.
    number: usize,
    /// The source has no more bytes.
    eof: bool,
    /// The last line handed out ended with the source, without a line end.
    open_end: bool,
    /// Bytes read from the source so far.
    read: u64,
    /// Told of every read ([`ReadOptions::progress`]).
    progress: Option<crate::progress::ReadProgress>,
}

impl<R: Read> Lines<R> {
    /// Lines of `reader`, each at most `opts.max_line_bytes` long.
    pub fn new(reader: R, opts: &ReadOptions) -> Self {
        Lines {
            reader,
            buf: vec![0; READ_BUFFER_BYTES].into_boxed_slice(),
            start: 0,
            end: 0,
            pending: Vec::new(),
            max: opts.max_line_bytes,
            number: 0,
            eof: false,
            open_end: false,
            read: 0,
            progress: opts.progress.clone(),
        }
    }

    /// The number a line starting here would have: after the last line handed out, or the
    /// number of the last line when the source ended without a line end (1 for an empty source).
    pub fn number_at_end(&self) -> usize {
        if self.open_end {
            self.number
        } else {
            self.number + 1
        }
    }

    /// The next line (its number and text, without its end), `None` at the end of the source.
    ///
    /// # Errors
    /// [`CsvError::Format`] for a line longer than the bound or not UTF-8 (at its line and
    /// column); [`CsvError::Io`] when the source cannot be read.
    pub fn next_line(&mut self, cx: &Ctx) -> Result<Option<(usize, &str)>, CsvError> {
        self.pending.clear();
        // The line's bytes are `buf[from..to]` when it lies in the buffer, or `pending`.
        let (from, to, in_pending) = loop {
            let unread = &self.buf[self.start..self.end];
            if let Some(i) = unread.iter().position(|&b| b == b'\n') {
                let (from, to) = (self.start, self.start + i);
                self.start = to + 1;
                if self.pending.is_empty() {
                    break (from, to, false);
                }
                self.take(cx, from, to)?;
                break (0, 0, true);
            }
            let (from, to) = (self.start, self.end);
            self.take(cx, from, to)?;
            self.start = self.end;
            if self.eof || !self.fill(cx)? {
                if self.pending.is_empty() {
                    return Ok(None);
                }
                self.open_end = true;
                break (0, 0, true);
            }
        };
        self.number += 1;
        let mut bytes: &[u8] = if in_pending {
            &self.pending
        } else {
            &self.buf[from..to]
        };
        if let [rest @ .., b'\r'] = bytes {
            bytes = rest;
        }
        if self.number == 1
            && let Some(rest) = bytes.strip_prefix(BOM)
        {
            bytes = rest;
        }
        if bytes.len() > self.max {
            return Err(too_long(cx, self.number, self.max));
        }
        match std::str::from_utf8(bytes) {
            Ok(text) => Ok(Some((self.number, text))),
            Err(e) => Err(not_utf8(cx, self.number, bytes, e.valid_up_to())),
        }
    }

    /// Appends `buf[from..to]` to the pending line, refusing it when it grows past the bound
    /// (one byte more is held for a `\r` before the line end, and the byte-order mark of the
    /// first line; the sum saturates, so `usize::MAX` is no bound).
    fn take(&mut self, cx: &Ctx, from: usize, to: usize) -> Result<(), CsvError> {
        if to > from {
            if self.pending.len() + (to - from) > self.max.saturating_add(1 + BOM.len()) {
                return Err(too_long(cx, self.number + 1, self.max));
            }
            self.pending.extend_from_slice(&self.buf[from..to]);
        }
        Ok(())
    }

    /// Reads more bytes into the (consumed) buffer; `false` at the end of the source.
    fn fill(&mut self, cx: &Ctx) -> Result<bool, CsvError> {
        loop {
            match self.reader.read(&mut self.buf) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(false);
                }
                Ok(n) => {
                    (self.start, self.end) = (0, n);
                    self.read += n as u64;
                    if let Some(p) = &self.progress {
                        p.read(self.read);
                    }
                    return Ok(true);
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(CsvError::Io {
                        file: cx.file.to_string(),
                        source,
                    });
                }
            }
        }
    }
}

fn too_long(cx: &Ctx, line: usize, max: usize) -> CsvError {
    cx.err(
        line,
        None,
        format!("line longer than {max} bytes: not a measurement CSV"),
    )
}

/// The error for line `line` whose bytes `bytes` are UTF-8 up to `valid`: located like every
/// text reader's (`file:line:column`, the column counted in characters).
fn not_utf8(cx: &Ctx, line: usize, bytes: &[u8], valid: usize) -> CsvError {
    let column = std::str::from_utf8(&bytes[..valid]).map_or(valid, |s| s.chars().count()) + 1;
    CsvError::Text(model_spec::text::TextError::NotUtf8 {
        file: cx.file.to_string(),
        line,
        column,
        byte: bytes[valid],
    })
}
