//! Writing a program back: the axis words of every pose replaced by the corrected commands,
//! the words of axes the block left modal inserted where the correction changes them, every
//! other byte kept.

use crate::io::nc::NcProgram;
use crate::io::nc::error::NcError;
use crate::io::nc::number::{NumberStyle, write_number};
use crate::io::poses::MAX_COMMAND;

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
    /// Axis words whose text changed.
    pub changed_words: usize,
    /// Axis words inserted in blocks that had left the axis modal.
    pub inserted_words: usize,
}

impl NcProgram {
    /// The program with the commands of pose `i` replaced by `corrected[i]` (every axis, in the
    /// order of the axis words, mm and degrees).
    ///
    /// In a block that moves, each axis word is written with the decimals of the program's
    /// word (at least `options.min_decimals`), rounded to nearest, its `+` sign, leading zeros
    /// and decimal point kept; a value equal (bit for bit) to the one read keeps its text. An
    /// axis the block does not name keeps the value in force from an earlier block; when the
    /// correction, written like that earlier word, differs from it, the word is inserted after
    /// the last axis word of the block (separated by a space, unless the block is written
    /// without spaces). Every other byte is kept: lines that do not move, comments, block
    /// numbers, spaces, line ends.
    ///
    /// # Errors
    /// [`NcError::Program`] when `corrected` does not hold one pose per pose of the program, a
    /// pose does not hold one value per axis, or `options.min_decimals` is above
    /// [`MAX_DECIMALS`]; [`NcError::Value`] for a value that is not finite or, written, not
    /// below [`MAX_COMMAND`] in magnitude (five digits before the decimal point).
    pub fn write(
        &self,
        corrected: &[Vec<f64>],
        options: &WriteOptions,
    ) -> Result<Written, NcError> {
        let whole = |message: String| NcError::Program {
            file: self.file.clone(),
            message,
        };
        if options.min_decimals > MAX_DECIMALS {
            return Err(whole(format!(
                "{} decimals asked for, at most {MAX_DECIMALS}",
                options.min_decimals
            )));
        }
        if corrected.len() != self.poses.len() {
            return Err(whole(format!(
                "{} corrected poses for the {} poses of the program",
                corrected.len(),
                self.poses.len()
            )));
        }
        let n = self.axes.len();
        let mut out = String::with_capacity(self.text.len() + self.text.len() / 8);
        let mut at = 0;
        let mut in_force: Vec<Option<(f64, NumberStyle)>> = vec![None; n];
        let mut rounding = vec![0.0f64; n];
        let (mut changed_words, mut inserted_words) = (0, 0);
        let mut named = vec![false; n];
        for ((pose, block), c) in self.poses.iter().zip(&self.blocks).zip(corrected) {
            if c.len() != n {
                return Err(whole(format!(
                    "the pose of line {} has {} values for {n} axes",
                    pose.line,
                    c.len()
                )));
            }
            let value_err = |axis: usize, message: String| NcError::Value {
                file: self.file.clone(),
                line: pose.line,
                axis: self.axes[axis].letter,
                message,
            };
            let write = |out: &mut String, axis: usize, style: &NumberStyle| {
                let x = c[axis];
                let decimals = style.decimals.max(options.min_decimals);
                write_number(out, x, style, decimals).ok_or_else(|| {
                    value_err(
                        axis,
                        format!(
                            "cannot write {x} {}: not a number below ±{MAX_COMMAND} with {decimals} decimals",
                            self.axes[axis].unit()
                        ),
                    )
                })
            };
            named.fill(false);
            for f in &block.fields {
                named[f.axis] = true;
                out.push_str(&self.text[at..f.start]);
                at = f.end;
                let value = if c[f.axis].to_bits() == f.value.to_bits() {
                    out.push_str(&self.text[f.start..f.end]);
                    f.value
                } else {
                    let mark = out.len();
                    let value = write(&mut out, f.axis, &f.style)?;
                    if out[mark..] != self.text[f.start..f.end] {
                        changed_words += 1;
                    }
                    value
                };
                in_force[f.axis] = Some((value, f.style));
                rounding[f.axis] = rounding[f.axis].max((value - c[f.axis]).abs());
            }
            out.push_str(&self.text[at..block.insert_at]);
            at = block.insert_at;
            for a in (0..n).filter(|&a| !named[a]) {
                let Some((held, style)) = in_force[a] else {
                    return Err(value_err(a, "no value in force before the pose".into()));
                };
                let value = if c[a].to_bits() == held.to_bits() {
                    held
                } else {
                    let mark = out.len();
                    if block.spaced {
                        out.push(' ');
                    }
                    out.push(style.letter as char);
                    let value = write(&mut out, a, &style)?;
                    if value == held {
                        out.truncate(mark);
                    } else {
                        inserted_words += 1;
                        in_force[a] = Some((value, style));
                    }
                    value
                };
                rounding[a] = rounding[a].max((value - c[a]).abs());
            }
        }
        out.push_str(&self.text[at..]);
        Ok(Written {
            text: out,
            rounding,
            changed_words,
            inserted_words,
        })
    }
}
