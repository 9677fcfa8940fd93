//! Heidenhain conversational (Klartext) blocks: a block number, a block keyword, words
//! separated by spaces, a `;` comment to the end of the line.
//!
//! Read: `L` blocks (axis words `X+10.5`, `R0`, `F…`, `M…`), and passed through unchanged
//! `BEGIN PGM … MM`, `END PGM`, `BLK FORM`, `TOOL CALL`, `TOOL DEF`, `CYCL DEF 9` (dwell) and
//! `CYCL DEF 32` (tolerance), `STOP`, `FUNCTION RESET TCPM`, `*` structure blocks, `;` comment
//! lines and blank lines. Every other block is refused with the reason ([`keyword_refusal`]).
//! Keywords and letters are upper case, as the control writes them.

use crate::nc::error::{NcError, Place};
use crate::nc::number::read_number;
use crate::nc::program::{AxisField, BlockAxes, BlockReader};
use crate::poses::{AxisWord, MAX_COMMAND, letters};

/// The blocks passed through, for messages.
pub(crate) const PASSED: &str = "BEGIN PGM, END PGM, BLK FORM, TOOL CALL, TOOL DEF, CYCL DEF 9 (dwell), CYCL DEF 32 (tolerance), STOP, FUNCTION RESET TCPM, `*` and `;` lines";

const MACHINE: &str =
    "the program must be in machine coordinates, so nothing in it may move the coordinate system";

/// Why a block of keyword `kw` (followed by `next`) is refused; `None` for one passed through.
fn keyword_refusal(kw: &str, next: &[&str]) -> Option<String> {
    let second = next.first().copied().unwrap_or("");
    let unknown = || {
        Some(format!(
            "a block rtest does not read (read: L; passed through: {PASSED})"
        ))
    };
    match kw {
        "BEGIN" | "END" if second == "PGM" => match next.last().copied() {
            Some("MM") => None,
            Some("INCH") => Some("inch programs are refused: the program must be in mm".into()),
            _ => Some("a program header without its unit MM".into()),
        },
        "BLK" if second == "FORM" => None,
        "TOOL" if second == "CALL" || second == "DEF" => None,
        "STOP" => None,
        "CYCL" if second == "DEF" => {
            let number = next.get(1).copied().unwrap_or("");
            let major = number.split('.').next().unwrap_or("");
            match major {
                "9" | "32" => None,
                "7" | "247" => Some(format!("a datum shift is refused: {MACHINE}")),
                "8" => Some(format!("mirroring is refused: {MACHINE}")),
                "10" => Some(format!("a rotation is refused: {MACHINE}")),
                "11" | "26" => Some(format!("scaling is refused: {MACHINE}")),
                "19" => Some(format!("a tilted working plane is refused: {MACHINE}")),
                _ => Some("machining cycles are refused: their moves are not written in the program (read: CYCL DEF 9 and 32)".into()),
            }
        }
        "CYCL" => Some("a cycle call is refused: the cycle's moves are not written in the program".into()),
        "FUNCTION" if next == ["RESET", "TCPM"] => None,
        "FUNCTION" if second == "TCPM" => Some("tool centre point control (FUNCTION TCPM) is refused: the program must command the axes themselves (TCP off)".into()),
        "FUNCTION" => Some("FUNCTION blocks other than FUNCTION RESET TCPM are refused".into()),
        "PLANE" => Some(format!("a tilted working plane is refused: {MACHINE}")),
        "TRANS" => Some(format!("a datum shift is refused: {MACHINE}")),
        "LN" => Some("vector blocks (LN) are refused: the control corrects them with the tool's geometry, away from the programmed positions".into()),
        "LP" => Some("polar coordinates (LP) are refused: the program must give the axis positions".into()),
        "CC" | "C" | "CR" | "CT" | "CP" => Some("circles and arcs are refused: only straight moves (L) are read, and a corrected end point would no longer lie on the circle".into()),
        "RND" | "CHF" => Some("roundings and chamfers are refused: the control inserts a move that is not written in the program".into()),
        "APPR" | "DEP" => Some("approach and departure functions are refused: their moves are not written in the program".into()),
        "FL" | "FLT" | "FC" | "FCT" | "FPOL" | "FSELECT" => Some("free contour programming (FK) is refused: its positions are computed by the control".into()),
        "LBL" | "CALL" => Some("labels and calls are refused: the order the blocks run in would not be the order of the file".into()),
        "FN" => Some("Q parameter functions are refused: the positions must be numbers in the program".into()),
        k if k.starts_with('Q') => Some("Q parameters are refused: the positions must be numbers in the program".into()),
        "TCH" => Some("probing cycles are refused: their moves are not written in the program".into()),
        _ => unknown(),
    }
}

/// Why M function `code` in an `L` block is refused, `None` for one that passes.
fn m_refusal(code: u32) -> Option<&'static str> {
    match code {
        128 => Some(
            "tool centre point control (M128) is refused: the program must command the axes themselves (TCP off)",
        ),
        114 | 144 => Some(
            "the control's own compensation of the rotary axes' kinematics (M114, M144) is refused: the program must command the axes themselves",
        ),
        118 => Some(
            "handwheel superimposition (M118) is refused: the positions would not be the programmed ones",
        ),
        140 => Some(
            "a retraction along the tool axis (M140) is refused: its move is not written in the program",
        ),
        92 => Some(
            "positions relative to the maker's reference (M92) are refused: the program must be in machine coordinates",
        ),
        89 | 99 => Some(
            "a cycle call (M89, M99) is refused: the cycle's moves are not written in the program",
        ),
        _ => None,
    }
}

/// The block reader of Heidenhain conversational programs (no modal state beyond the axes).
pub(crate) struct HeidenhainReader<'a> {
    axes: &'a [AxisWord],
    /// `END PGM` was read.
    ended: bool,
}

impl<'a> HeidenhainReader<'a> {
    pub(crate) fn new(axes: &'a [AxisWord]) -> Self {
        HeidenhainReader { axes, ended: false }
    }

    /// The words of an `L` block: `tokens` (text and byte start in the line) after the `L`.
    fn line_block(
        &self,
        place: &Place,
        offset: usize,
        tokens: &[(&str, usize)],
    ) -> Result<Option<BlockAxes>, NcError> {
        let mut fields: Vec<AxisField> = Vec::new();
        let mut firsts: [Option<usize>; 26] = [None; 26];
        let mut ms: Vec<u32> = Vec::new();
        let mut insert_at = 0;
        for &(t, at) in tokens {
            let end = at + t.len();
            let err = |m: String| place.err(at, end, m);
            let b = t.as_bytes();
            let l = b[0] as char;
            let number = |s: &str| read_number(b'F', s).is_some_and(|(v, _)| v >= 0.0);
            if !l.is_ascii_uppercase() {
                return Err(err("not a word of an L block".into()));
            }
            if l != 'M'
                && let Some(first) = firsts[(b[0] - b'A') as usize]
            {
                return Err(err(format!(
                    "a second `{l}` word in the block (the first at column {})",
                    place.text[..first].chars().count() + 1
                )));
            }
            firsts[(b[0] - b'A') as usize].get_or_insert(at);
            if let Some(axis) = self.axes.iter().position(|a| a.letter == l) {
                let (value, style) = read_number(b[0], &t[1..]).ok_or_else(|| {
                    err(format!(
                        "cannot read the number `{}` of the `{l}` word",
                        &t[1..]
                    ))
                })?;
                if value.abs() >= MAX_COMMAND {
                    return Err(err(format!(
                        "{} {} is beyond ±{MAX_COMMAND}: no axis command reaches it",
                        &t[1..],
                        self.axes[axis].unit()
                    )));
                }
                fields.push(AxisField {
                    axis,
                    start: offset + at + 1,
                    end: offset + end,
                    value,
                    style,
                });
                insert_at = offset + end;
                continue;
            }
            match l {
                'I' if b.len() > 1 && b[1].is_ascii_uppercase() => {
                    return Err(err(
                        "incremental positions are refused: the poses are absolute positions"
                            .into(),
                    ));
                }
                'R' if t == "R0" => {}
                'R' if matches!(t, "RL" | "RR" | "R+" | "R-") => {
                    return Err(err("tool radius compensation is refused: the control would move the axes away from the programmed positions (write R0)".into()));
                }
                'F' if matches!(t, "FMAX" | "FAUTO")
                    || number(&t[1..])
                    || (t.len() > 2 && matches!(&t[..2], "FU" | "FZ") && number(&t[2..])) => {}
                'M' if b.len() > 1 && b[1..].iter().all(u8::is_ascii_digit) && b.len() <= 5 => {
                    let code: u32 = t[1..].parse().unwrap_or(u32::MAX);
                    if let Some(why) = m_refusal(code) {
                        return Err(err(why.into()));
                    }
                    if ms.contains(&code) {
                        return Err(err(format!("`{t}` twice in the block")));
                    }
                    ms.push(code);
                }
                'X' | 'Y' | 'Z' | 'U' | 'V' | 'W' | 'A' | 'B' | 'C' => {
                    return Err(err(format!(
                        "`{l}` is not an axis of this machine (its axes: {})",
                        letters(self.axes)
                    )));
                }
                _ => {
                    return Err(err(format!(
                        "not read in an L block (read: the axes {}, R0, F, M)",
                        letters(self.axes)
                    )));
                }
            }
        }
        Ok((!fields.is_empty()).then_some(BlockAxes {
            fields,
            insert_at,
            spaced: true,
        }))
    }
}

impl BlockReader for HeidenhainReader<'_> {
    fn block(&mut self, place: &Place, offset: usize) -> Result<Option<BlockAxes>, NcError> {
        let line = place.text;
        let b = line.as_bytes();
        let content = &line[..b.iter().position(|&c| c == b';').unwrap_or(b.len())];
        let mut tokens: Vec<(&str, usize)> = Vec::with_capacity(16);
        let mut i = 0;
        let cb = content.as_bytes();
        while i < cb.len() {
            if matches!(cb[i], b' ' | b'\t') {
                i += 1;
                continue;
            }
            let at = i;
            while i < cb.len() && !matches!(cb[i], b' ' | b'\t') {
                i += 1;
            }
            tokens.push((&content[at..i], at));
        }
        let mut k = 0;
        if tokens
            .first()
            .is_some_and(|(t, _)| t.bytes().all(|b| b.is_ascii_digit()))
        {
            k = 1;
        }
        let Some(&(kw, at)) = tokens.get(k) else {
            return Ok(None);
        };
        if kw.starts_with('*') {
            return Ok(None);
        }
        if kw == "L" {
            return self.line_block(place, offset, &tokens[k + 1..]);
        }
        let next: Vec<&str> = tokens[k + 1..].iter().map(|(t, _)| *t).collect();
        match keyword_refusal(kw, &next) {
            None => {
                self.ended |= kw == "END";
                Ok(None)
            }
            Some(why) => Err(place.err(at, content.trim_end().len(), why)),
        }
    }

    fn ended(&self) -> Option<&'static str> {
        self.ended.then_some("`END PGM`")
    }
}
