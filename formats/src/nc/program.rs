//! Reading a program: the lines handed to the dialect's block reader, the modal positions kept
//! from block to block ([`Moves`]), a pose for every block that moves, held flat.

use crate::nc::error::{NcError, Place};
use crate::nc::heidenhain::HeidenhainReader;
use crate::nc::iso::IsoReader;
use crate::nc::number::NumberStyle;
use crate::nc::{Dialect, NcProgram};
use crate::poses::{
    AxisWord, Lines, MAX_FILE_BYTES, MAX_LINE_BYTES, letters, lines, read_flat, strip_bom,
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
        Dialect::Iso | Dialect::LinuxCnc => &[
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

/// The blocks of a program that move, read one at a time with every check of the reading
/// (lines, the dialect's blocks, the end of the program, axes without a value): what the reader
/// and the writer both go through, so that the writer finds the words the reader read.
pub(crate) struct Moves<'a> {
    file: &'a str,
    axes: &'a [AxisWord],
    reader: Box<dyn BlockReader + 'a>,
    lines: Lines<'a>,
    /// The line and the word that ended the program.
    end: Option<(usize, &'static str)>,
    /// The value in force of every axis, `None` before its first word.
    modal: Vec<Option<f64>>,
}

impl<'a> Moves<'a> {
    /// The moves of program `text` (named `file`), of dialect `dialect`, for the axes `axes`
    /// (checked by [`parse`]).
    pub(crate) fn new(
        file: &'a str,
        text: &'a str,
        dialect: Dialect,
        axes: &'a [AxisWord],
    ) -> Self {
        Moves {
            file,
            axes,
            reader: match dialect {
                Dialect::Iso => Box::new(IsoReader::new(axes)),
                Dialect::LinuxCnc => Box::new(IsoReader::linuxcnc(axes)),
                Dialect::Heidenhain => Box::new(HeidenhainReader::new(axes)),
            },
            lines: lines(text),
            end: None,
            modal: vec![None; axes.len()],
        }
    }

    /// The values in force after the last move (mm, degrees), one per axis, into `out`.
    pub(crate) fn commands(&self, out: &mut [f64]) {
        for (o, v) in out.iter_mut().zip(&self.modal) {
            *o = v.unwrap_or(0.0);
        }
    }

    /// The next block that moves: its line and axis words; `None` after the last line.
    pub(crate) fn next(&mut self) -> Result<Option<(usize, BlockAxes)>, NcError> {
        let (file, axes) = (self.file, self.axes);
        while let Some((number, offset, raw)) = self.lines.next() {
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
            if let Some((line, what)) = self.end {
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
            let read = self.reader.block(&place, offset + bom)?;
            if let Some(what) = self.reader.ended() {
                self.end = Some((number, what));
            }
            let Some(block) = read else {
                continue;
            };
            for f in &block.fields {
                self.modal[f.axis] = Some(f.value);
            }
            let unknown: Vec<String> = (0..axes.len())
                .filter(|&a| self.modal[a].is_none())
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
            return Ok(Some((number, block)));
        }
        Ok(None)
    }
}

/// Reads program `text` (named `file`): its poses, at most `max_poses`
/// ([`crate::poses::MAX_POSES`] but in tests).
pub(crate) fn parse(
    file: &str,
    text: String,
    dialect: Dialect,
    axes: &[AxisWord],
    max_poses: usize,
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
    let too_many = |line: usize| {
        whole(format!(
            "more than {max_poses} poses (blocks that move; line {line} holds the first beyond): rtest reads at most {max_poses} poses from one program; split it"
        ))
    };
    let poses = read_flat(&text, axes.len(), max_poses, too_many, |pose| {
        let mut moves = Moves::new(file, &text, dialect, axes);
        let mut commands = vec![0.0; axes.len()];
        while let Some((line, _)) = moves.next()? {
            moves.commands(&mut commands);
            pose(line, &commands)?;
        }
        Ok(())
    })?;
    if poses.is_empty() {
        return Err(whole(format!(
            "no move in the program (no block with a word of axis {}): nothing to read",
            letters(axes)
        )));
    }
    Ok(NcProgram {
        file: file.to_string(),
        text,
        dialect,
        axes: axes.to_vec(),
        poses,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use model_spec::AxisKind::{Linear, Rotary};

    fn axes() -> [AxisWord; 2] {
        [
            AxisWord {
                letter: 'X',
                kind: Linear,
            },
            AxisWord {
                letter: 'C',
                kind: Rotary,
            },
        ]
    }

    #[test]
    fn a_program_over_the_pose_limit_is_refused() {
        let text = "%\nG90 G1 X0 C0\nC1 (second)\n\nC2\nC3\nM30\n%\n";
        let p = parse("p.nc", text.into(), Dialect::Iso, &axes(), 4).unwrap();
        assert_eq!(p.pose_list().len(), 4);
        let e = parse("p.nc", text.into(), Dialect::Iso, &axes(), 3).unwrap_err();
        assert_eq!(
            e.to_string(),
            "p.nc: more than 3 poses (blocks that move; line 6 holds the first beyond): rtest reads at most 3 poses from one program; split it"
        );
        // The refusal names the line of the first pose beyond the limit.
        let e = parse("p.nc", text.into(), Dialect::Iso, &axes(), 2).unwrap_err();
        assert!(
            e.to_string().contains("line 5 holds the first beyond"),
            "{e}"
        );
        let h = "1 L X+0 C+0 R0 FMAX\n2 L C+1\n; a comment\n; another\n3 L C+2\n";
        let p = parse("p.h", h.into(), Dialect::Heidenhain, &axes(), 3).unwrap();
        assert_eq!(p.pose_list().commands(2), [0.0, 2.0]);
        assert_eq!(p.pose_list().line(2), 5);
        let e = parse("p.h", h.into(), Dialect::Heidenhain, &axes(), 2).unwrap_err();
        assert!(
            e.to_string().contains("line 5 holds the first beyond"),
            "{e}"
        );
        // A refused block before the limit is reached is what is reported.
        let bad = "G90 G1 X0 C0\nC1\nG91\nC2\nC3\n";
        let e = parse("p.nc", bad.into(), Dialect::Iso, &axes(), 2).unwrap_err();
        assert!(e.to_string().starts_with("p.nc:3:1: `G91`"), "{e}");
    }
}
