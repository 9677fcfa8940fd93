//! Reading a program: the lines handed to the dialect's block reader, the modal positions kept
//! from block to block, a pose for every block that moves.

use crate::io::nc::error::{NcError, Place};
use crate::io::nc::heidenhain::HeidenhainReader;
use crate::io::nc::iso::IsoReader;
use crate::io::nc::number::NumberStyle;
use crate::io::nc::{Dialect, NcProgram};
use crate::io::poses::{
    AxisWord, CommandedPose, MAX_FILE_BYTES, MAX_LINE_BYTES, letters, lines, strip_bom,
};
use model_spec::text::TextError;

/// One axis word of a block: its value, where its number is in the program's text, and how it
/// is written.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisField {
    /// Index of the axis in the axis words.
    pub(crate) axis: usize,
    /// Byte range of the number (after the letter) in the program's text.
    pub(crate) start: usize,
    pub(crate) end: usize,
    /// mm or degrees.
    pub(crate) value: f64,
    pub(crate) style: NumberStyle,
}

/// The axis words of a block that moves, and where words are inserted.
#[derive(Clone, Debug)]
pub(crate) struct BlockAxes {
    /// In the order of the line.
    pub(crate) fields: Vec<AxisField>,
    /// Byte offset in the program's text just after the last axis word.
    pub(crate) insert_at: usize,
    /// Inserted words are preceded by a space (`false` in a block written without spaces,
    /// `N10G1X10Y5`).
    pub(crate) spaced: bool,
}

/// What reads the blocks of one dialect.
pub(crate) trait BlockReader {
    /// The axis words of line `place.text` (at byte `offset` of the program), `None` for a
    /// line that does not move; the reader keeps its own modal state.
    fn block(&mut self, place: &Place, offset: usize) -> Result<Option<BlockAxes>, NcError>;

    /// The end of the program, once a block has ended it (`%` or `M30` in ISO, `END PGM` in
    /// Heidenhain): what ended it, for messages. The control runs nothing after it.
    fn ended(&self) -> Option<&'static str>;
}

/// Letters that words other than axis words use, per dialect, with what they are.
fn reserved(dialect: Dialect) -> &'static [(char, &'static str)] {
    match dialect {
        Dialect::Iso => &[
            ('D', "radius offset"),
            ('F', "feed"),
            ('G', "preparatory function"),
            ('H', "length offset"),
            ('I', "arc centre"),
            ('J', "arc centre"),
            ('K', "arc centre"),
            ('L', "repetition"),
            ('M', "miscellaneous function"),
            ('N', "block number"),
            ('P', "dwell time"),
            ('Q', "cycle parameter"),
            ('R', "arc radius"),
            ('S', "spindle speed"),
            ('T', "tool"),
        ],
        Dialect::Heidenhain => &[
            ('F', "feed"),
            ('I', "incremental prefix"),
            ('L', "line block"),
            ('M', "miscellaneous function"),
            ('Q', "parameter"),
            ('R', "radius compensation"),
        ],
    }
}

pub(crate) fn parse(
    file: &str,
    text: &str,
    dialect: Dialect,
    axes: &[AxisWord],
) -> Result<NcProgram, NcError> {
    let whole = |message: String| NcError::Program {
        file: file.to_string(),
        message,
    };
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(NcError::Text(TextError::TooLarge {
            file: file.to_string(),
            limit: MAX_FILE_BYTES,
        }));
    }
    if axes.is_empty() {
        return Err(whole("no axis given to read the program for".into()));
    }
    for (i, a) in axes.iter().enumerate() {
        if let Some((_, what)) = reserved(dialect).iter().find(|(c, _)| *c == a.letter) {
            return Err(whole(format!(
                "the machine has an axis {}, the letter of the {what} word of {} programs: its programs cannot be read as {}",
                a.letter,
                dialect.name(),
                dialect.name()
            )));
        }
        if !a.letter.is_ascii_uppercase() || axes[..i].iter().any(|b| b.letter == a.letter) {
            return Err(whole(format!(
                "axis letters must be distinct upper-case letters: {}",
                letters(axes)
            )));
        }
    }
    let mut reader: Box<dyn BlockReader + '_> = match dialect {
        Dialect::Iso => Box::new(IsoReader::new(axes)),
        Dialect::Heidenhain => Box::new(HeidenhainReader::new(axes)),
    };
    let mut modal: Vec<Option<f64>> = vec![None; axes.len()];
    let mut poses = Vec::new();
    let mut blocks = Vec::new();
    let mut end: Option<(usize, &str)> = None;
    for (number, offset, raw) in lines(text) {
        let refused = |column: usize, message: String| NcError::Block {
            file: file.to_string(),
            line: number,
            column,
            word: None,
            message,
        };
        if raw.len() > MAX_LINE_BYTES {
            return Err(refused(
                1,
                format!("line longer than {MAX_LINE_BYTES} bytes: not an NC block"),
            ));
        }
        if let Some(at) = raw.find('\r') {
            return Err(refused(
                raw[..at].chars().count() + 1,
                "a carriage return inside a line: lines end with a line feed (LF or CR LF); a file whose lines end with CR alone is read as one line".into(),
            ));
        }
        if let Some((line, what)) = end {
            if !matches!(raw.trim(), "" | "%") {
                return Err(refused(
                    1,
                    format!(
                        "a block after the end of the program ({what} at line {line}): the control does not run it; remove it"
                    ),
                ));
            }
            continue;
        }
        let (line, bom) = strip_bom(number, raw);
        let place = Place {
            file,
            line: number,
            text: line,
        };
        let read = reader.block(&place, offset + bom)?;
        if let Some(what) = reader.ended() {
            end = Some((number, what));
        }
        let Some(block) = read else {
            continue;
        };
        for f in &block.fields {
            modal[f.axis] = Some(f.value);
        }
        let unknown: Vec<String> = (0..axes.len())
            .filter(|&a| modal[a].is_none())
            .map(|a| axes[a].letter.to_string())
            .collect();
        if !unknown.is_empty() {
            let f = &block.fields[0];
            return Err(place.err(
                f.start - offset - bom - 1,
                f.end - offset - bom,
                format!(
                    "a move with axis {} not yet known: give a start position (a block that sets every axis, {}) before the first move",
                    unknown.join(", "),
                    letters(axes)
                ),
            ));
        }
        poses.push(CommandedPose {
            line: number,
            commands: modal.iter().map(|v| v.unwrap_or(0.0)).collect(),
        });
        blocks.push(block);
    }
    if poses.is_empty() {
        return Err(whole(format!(
            "no move in the program (no block with a word of axis {}): nothing to read",
            letters(axes)
        )));
    }
    Ok(NcProgram {
        file: file.to_string(),
        text: text.to_string(),
        dialect,
        axes: axes.to_vec(),
        poses,
        blocks,
    })
}
