//! Writing a program back: the axis words of every pose replaced by the corrected commands,
//! the words of axes the block left modal inserted where the correction changes them, every
//! other byte kept. The blocks are read again as the writer goes ([`Moves`]), pose after pose.

use crate::nc::NcProgram;
use crate::nc::error::NcError;
use crate::nc::number::{NumberStyle, write_number};
use crate::nc::program::Moves;
use crate::poses::MAX_COMMAND;

/// The most decimals [`WriteOptions::min_decimals`] may ask for (1 nm, 1e-9 degree).
pub const MAX_DECIMALS: usize = 9;

/// How a program is written back.
#[non_exhaustive]
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// The fewest decimals of a written axis word: a word is written with as many decimals as
    /// the program's word had, or this many if that is more. Default 0 (the program's own
    /// resolution); at most [`MAX_DECIMALS`].
    pub min_decimals: usize,
}

impl WriteOptions {
    /// The default options: every word with the decimals of the program's word.
    pub fn new() -> Self {
        WriteOptions::default()
    }

    /// Words written with at least `n` decimals.
    pub fn with_min_decimals(n: usize) -> Self {
        WriteOptions { min_decimals: n }
    }
}

/// A program written back.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    /// The program's text with the corrected axis words.
    pub text: String,
    /// Per axis (in the order of the axis words), the largest |written − corrected| over the
    /// poses: mm for linear axes, degrees for rotary axes. The written value is the one in
    /// force after the block: the word written, or, for an axis the block leaves modal and
    /// whose correction rounds to the value in force, that value. What the program's
    /// resolution costs.
    pub rounding: Vec<f64>,
    /// Per axis (in the order of the axis words), where its largest rounding is: the word
    /// there and its decimals; `None` where no written value differs from its correction.
    pub largest_rounding: Vec<Option<RoundingAt>>,
    /// Axis words whose text changed.
    pub changed_words: usize,
    /// Axis words inserted in blocks that had left the axis modal.
    pub inserted_words: usize,
}

/// Where an axis's largest rounding ([`Written::rounding`]) is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RoundingAt {
    /// The 1-based line of the pose.
    pub line: usize,
    /// The axis word as written (`C+90`), or for an axis the block leaves modal, the word that
    /// set the value in force, written at the correction (which rounds to that value).
    pub word: String,
    /// The decimals the word is written with.
    pub decimals: usize,
    /// `true` when the block names the axis, `false` when it leaves it modal.
    pub in_block: bool,
}

/// The largest rounding of an axis so far: line, value written, style, decimals, in the block.
type Largest = (usize, f64, NumberStyle, usize, bool);

impl NcProgram {
    /// A writer of the program with corrected poses, given one at a time in the order of the
    /// program ([`ProgramWriter::pose`]): the way to write a long program without holding its
    /// corrected poses.
    ///
    /// # Errors
    /// [`NcError::Program`] when `options.min_decimals` is above [`MAX_DECIMALS`].
    pub fn writer(&self, options: &WriteOptions) -> Result<ProgramWriter<'_>, NcError> {
        if options.min_decimals > MAX_DECIMALS {
            return Err(self.whole(format!(
                "{} decimals asked for, at most {MAX_DECIMALS}",
                options.min_decimals
            )));
        }
        let n = self.axes.len();
        Ok(ProgramWriter {
            program: self,
            moves: Moves::new(&self.file, &self.text, self.dialect, &self.axes),
            min_decimals: options.min_decimals,
            out: String::with_capacity(self.text.len() + self.text.len() / 8),
            at: 0,
            in_force: vec![None; n],
            rounding: vec![0.0; n],
            largest: vec![None; n],
            named: vec![false; n],
            changed_words: 0,
            inserted_words: 0,
            given: 0,
        })
    }

    /// The program with the commands of pose `i` replaced by `corrected[i]`: every pose given
    /// to [`NcProgram::writer`] in turn (see [`ProgramWriter::pose`]).
    ///
    /// # Errors
    /// [`NcError::Program`] when `corrected` does not hold one pose per pose of the program, or
    /// `options.min_decimals` is above [`MAX_DECIMALS`]; as [`ProgramWriter::pose`].
    pub fn write(
        &self,
        corrected: &[Vec<f64>],
        options: &WriteOptions,
    ) -> Result<Written, NcError> {
        let mut w = self.writer(options)?;
        if corrected.len() != self.poses.len() {
            return Err(self.whole(format!(
                "{} corrected poses for the {} poses of the program",
                corrected.len(),
                self.poses.len()
            )));
        }
        for c in corrected {
            w.pose(c)?;
        }
        w.finish()
    }

    fn whole(&self, message: String) -> NcError {
        NcError::Program {
            file: self.file.clone(),
            message,
        }
    }
}

/// A program being written back, pose after pose ([`NcProgram::writer`]).
pub struct ProgramWriter<'a> {
    program: &'a NcProgram,
    moves: Moves<'a>,
    min_decimals: usize,
    out: String,
    /// Byte of the text up to which `out` holds it.
    at: usize,
    /// Per axis, the value in force and the style of the word that set it.
    in_force: Vec<Option<(f64, NumberStyle)>>,
    rounding: Vec<f64>,
    /// Per axis, where its rounding is largest.
    largest: Vec<Option<Largest>>,
    /// Per axis, whether the block being written names it.
    named: Vec<bool>,
    changed_words: usize,
    inserted_words: usize,
    /// Poses given.
    given: usize,
}

impl ProgramWriter<'_> {
    /// Writes the next block that moves with the commands `corrected` (every axis, in the
    /// order of the axis words, mm and degrees).
    ///
    /// Each axis word of the block is written with the decimals of the program's word (at
    /// least the options' `min_decimals`), rounded to nearest, its `+` sign, leading zeros and
    /// decimal point kept; a value equal (bit for bit) to the one read keeps its text. An axis
    /// the block does not name keeps the value in force from an earlier block; when the
    /// correction, written like that earlier word, differs from it, the word is inserted after
    /// the last axis word of the block (separated by a space, unless the block is written
    /// without spaces). Every other byte is kept: lines that do not move, comments, block
    /// numbers, spaces, line ends.
    ///
    /// # Errors
    /// [`NcError::Program`] for a pose beyond the last of the program, or one that does not
    /// hold one value per axis; [`NcError::Value`] for a value that is not finite or, written,
    /// not below [`MAX_COMMAND`] in magnitude (five digits before the decimal point).
    pub fn pose(&mut self, corrected: &[f64]) -> Result<(), NcError> {
        let p = self.program;
        let n = p.axes.len();
        let Some((line, block)) = self.moves.next()? else {
            return Err(p.whole(format!(
                "more corrected poses than the {} poses of the program",
                p.poses.len()
            )));
        };
        self.given += 1;
        let c = corrected;
        if c.len() != n {
            return Err(p.whole(format!(
                "the pose of line {line} has {} values for {n} axes",
                c.len()
            )));
        }
        let min_decimals = self.min_decimals;
        let value_err = |axis: usize, message: String| NcError::Value {
            file: p.file.clone(),
            line,
            axis: p.axes[axis].letter,
            message,
        };
        let write = |out: &mut String, axis: usize, style: &NumberStyle| {
            let x = c[axis];
            let decimals = style.decimals.max(min_decimals);
            write_number(out, x, style, decimals).ok_or_else(|| {
                value_err(
                    axis,
                    format!(
                        "cannot write {x} {}: not a number below ±{MAX_COMMAND} with {decimals} decimals",
                        p.axes[axis].unit()
                    ),
                )
            })
        };
        let out = &mut self.out;
        self.named.fill(false);
        for f in &block.fields {
            self.named[f.axis] = true;
            out.push_str(&p.text[self.at..f.start]);
            self.at = f.end;
            let value = if c[f.axis].to_bits() == f.value.to_bits() {
                out.push_str(&p.text[f.start..f.end]);
                f.value
            } else {
                let mark = out.len();
                let value = write(out, f.axis, &f.style)?;
                if out[mark..] != p.text[f.start..f.end] {
                    self.changed_words += 1;
                }
                value
            };
            self.in_force[f.axis] = Some((value, f.style));
            let r = (value - c[f.axis]).abs();
            if r > self.rounding[f.axis] {
                self.rounding[f.axis] = r;
                let d = f.style.decimals.max(min_decimals);
                self.largest[f.axis] = Some((line, value, f.style, d, true));
            }
        }
        out.push_str(&p.text[self.at..block.insert_at]);
        self.at = block.insert_at;
        for a in (0..n).filter(|&a| !self.named[a]) {
            let Some((held, style)) = self.in_force[a] else {
                return Err(value_err(a, "no value in force before the pose".into()));
            };
            let decimals = style.decimals.max(min_decimals);
            let value = if c[a].to_bits() == held.to_bits() {
                held
            } else {
                let mark = out.len();
                if block.spaced {
                    out.push(' ');
                }
                out.push(style.letter as char);
                let value = write(out, a, &style)?;
                if value == held {
                    out.truncate(mark);
                } else {
                    self.inserted_words += 1;
                    self.in_force[a] = Some((value, style));
                }
                value
            };
            let r = (value - c[a]).abs();
            if r > self.rounding[a] {
                self.rounding[a] = r;
                self.largest[a] = Some((line, value, style, decimals, false));
            }
        }
        Ok(())
    }

    /// The whole program written back.
    ///
    /// # Errors
    /// [`NcError::Program`] when fewer poses were given than the program has.
    pub fn finish(mut self) -> Result<Written, NcError> {
        let p = self.program;
        if self.given != p.poses.len() {
            return Err(p.whole(format!(
                "{} corrected poses for the {} poses of the program",
                self.given,
                p.poses.len()
            )));
        }
        self.out.push_str(&p.text[self.at..]);
        let largest_rounding = self
            .largest
            .iter()
            .map(|l| {
                l.map(|(line, value, style, decimals, in_block)| {
                    let mut word = String::from(style.letter as char);
                    // The value was written so once: it is written again.
                    write_number(&mut word, value, &style, decimals);
                    RoundingAt {
                        line,
                        word,
                        decimals,
                        in_block,
                    }
                })
            })
            .collect();
        Ok(Written {
            text: self.out,
            rounding: self.rounding,
            largest_rounding,
            changed_words: self.changed_words,
            inserted_words: self.inserted_words,
        })
    }
}
