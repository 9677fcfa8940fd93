//! A reader of the programs rtest writes for the machine (`docs/measurement-programs.md`): it
//! reads a program's own words, dialect by dialect, and sorts its blocks into the steps of the
//! sequence, so that the order can be checked: setup (machine coordinates) → clearance →
//! orientation → approach → stop → measuring moves → retract → end.
//!
//! It is not [`formats::nc::parse_program`], which reads the programs `rtest compensate`
//! corrects and refuses `G53`: this one reads what rtest's own programs hold (`G53`, `G10 L2`,
//! `G54`, `M91`, `M19`, `M0`, `STOP`, dwells) and says, for each move, whether it runs in
//! machine coordinates, whether it is a rapid, and the pose after it. The measurement program
//! is read back with it before it is written; the tests read every program with it.
//!
//! How a block is sorted:
//!
//! - before the first move: [`Step::Setup`] (modes, `G10 L2`, `G54`, `FUNCTION RESET TCPM`,
//!   `M127`), [`Step::Spindle`] (`M5`);
//! - `M19` (`L M19`): [`Step::Orient`]; `M0` (`STOP`): [`Step::Stop`]; `M2`, `M30`,
//!   `END PGM`: [`Step::End`]; a dwell (`G4`, cycle 9): [`Step::Dwell`]; another M function:
//!   [`Step::Marker`];
//! - a move before the orientation: [`Step::Clearance`]; after it and before the stop:
//!   [`Step::Approach`]; after the stop and up to the last dwell: [`Step::Measure`]; after the
//!   last dwell: [`Step::Retract`].
//!
//! A word the reader does not know is an error naming the line and the word.

use formats::nc::number::read_number;
use formats::nc::{Dialect, NcError};
use formats::poses::AxisWord;

/// What a block does in the sequence of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Modes and coordinate systems, before the first move.
    Setup,
    /// The spindle stopped (`M5`).
    Spindle,
    /// A move before the spindle's orientation: to the clearance, the rotary axes there.
    Clearance,
    /// The spindle oriented (`M19`).
    Orient,
    /// A move after the orientation, before the stop: the approach of the first pose.
    Approach,
    /// The program stop (`M0`, `STOP`).
    Stop,
    /// A move after the stop, up to the last dwell: to a measuring pose.
    Measure,
    /// A dwell.
    Dwell,
    /// Another M function (a marker of the measuring window).
    Marker,
    /// A move after the last dwell: off the ball and to the clearance.
    Retract,
    /// The end of the program.
    End,
}

/// A move of a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// A rapid (`G0`, `FMAX`).
    pub rapid: bool,
    /// In machine coordinates: `G53` or `M91` in the block, or (ISO) the coordinate system
    /// `G54` in force after `G10 L2 P1` set every axis of it to 0.
    pub machine: bool,
    /// Inverse time (`G93`) in force.
    pub inverse_time: bool,
    /// The `F` number in force (`None` before the first, and for a rapid).
    pub feed: Option<f64>,
    /// The axes the block names (indices into the axis words).
    pub named: Vec<usize>,
    /// Every axis after the block (mm, degrees, in the order of the axis words); NaN for an
    /// axis no block has named yet.
    pub pose: Vec<f64>,
}

/// A block of a program (a line that is not only a comment).
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// 1-based line.
    pub line: usize,
    /// Its step in the sequence.
    pub step: Step,
    /// The move, for a block that moves.
    pub motion: Option<Motion>,
    /// A dwell's time, s.
    pub dwell_s: Option<f64>,
    /// The M functions of the block.
    pub m_codes: Vec<u32>,
    /// The comment on the block's line, or (LinuxCNC) the `(MSG,…)` line just before it.
    pub comment: Option<String>,
}

/// A program as read: its blocks in order.
#[derive(Clone, Debug, PartialEq)]
pub struct ReadProgram {
    /// The blocks, in the order of the file.
    pub blocks: Vec<Block>,
}

impl ReadProgram {
    /// The steps in order, a run of blocks of one step given once, dwells and markers taken
    /// as part of the measuring: `[Setup, Spindle, Clearance, Orient, Approach, Stop, Measure,
    /// Retract, End]` for a program rtest writes.
    pub fn steps(&self) -> Vec<Step> {
        let mut out: Vec<Step> = Vec::new();
        for b in &self.blocks {
            let s = match b.step {
                Step::Dwell | Step::Marker => Step::Measure,
                s => s,
            };
            if out.last() != Some(&s) {
                out.push(s);
            }
        }
        out
    }

    /// The moves of step `step`, in order.
    pub fn moves(&self, step: Step) -> Vec<&Motion> {
        self.blocks
            .iter()
            .filter(|b| b.step == step)
            .filter_map(|b| b.motion.as_ref())
            .collect()
    }

    /// The measuring poses: where the approach ends (the nest on the ball at the first pose)
    /// and the pose after each measuring move (mm, degrees).
    pub fn measuring_poses(&self) -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<f64>> = self
            .moves(Step::Approach)
            .last()
            .map(|m| vec![m.pose.clone()])
            .unwrap_or_default();
        out.extend(self.moves(Step::Measure).iter().map(|m| m.pose.clone()));
        out
    }

    /// The blocks of step `step`.
    pub fn blocks_of(&self, step: Step) -> Vec<&Block> {
        self.blocks.iter().filter(|b| b.step == step).collect()
    }
}

/// What one line holds, before its step is known.
struct Raw {
    line: usize,
    motion: Option<Motion>,
    dwell_s: Option<f64>,
    dwell_block: bool,
    m_codes: Vec<u32>,
    end: bool,
    stop: bool,
    comment: Option<String>,
}

/// The modal state of a G-code program.
struct GState {
    rapid: bool,
    inverse_time: bool,
    feed: Option<f64>,
    /// `G10 L2 P1` set every axis to 0.
    p1_zero: bool,
    /// `G54` is in force.
    g54: bool,
}

/// Reads program `text` (named `file` in messages) of `dialect`, for the axes `axes`: its
/// blocks and their steps (see the module documentation).
///
/// # Errors
/// [`NcError::Block`] for a word or block the reader does not know, a number it cannot read,
/// a move before every axis is known is not an error (its pose holds NaN).
pub fn read_program(
    file: &str,
    text: &str,
    dialect: Dialect,
    axes: &[AxisWord],
) -> Result<ReadProgram, NcError> {
    let mut raws: Vec<Raw> = Vec::new();
    let mut pose = vec![f64::NAN; axes.len()];
    let mut g = GState {
        rapid: false,
        inverse_time: false,
        feed: None,
        p1_zero: false,
        g54: false,
    };
    let mut message: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let err = |word: &str, message: String| NcError::Block {
            file: file.to_string(),
            line: n,
            column: 1,
            word: (!word.is_empty()).then(|| word.to_string()),
            message,
        };
        let raw = match dialect {
            Dialect::Iso | Dialect::LinuxCnc => {
                g_code_line(n, line, axes, &mut pose, &mut g, &err)?
            }
            Dialect::Heidenhain => heidenhain_line(n, line, axes, &mut pose, &err)?,
        };
        match raw {
            Some(mut r) => {
                if r.comment.is_none() {
                    r.comment = message.take();
                }
                message = None;
                raws.push(r);
            }
            None => {
                let t = line.trim();
                if let Some(m) = t.strip_prefix("(MSG,").and_then(|m| m.strip_suffix(')')) {
                    message = Some(m.to_string());
                }
            }
        }
    }
    Ok(ReadProgram { blocks: sort(raws) })
}

/// The steps of the lines read.
fn sort(raws: Vec<Raw>) -> Vec<Block> {
    let orient = raws.iter().position(|r| r.m_codes.contains(&19));
    let stop = raws.iter().position(|r| r.stop);
    let last_dwell = raws.iter().rposition(|r| r.dwell_block);
    let first_move = raws.iter().position(|r| r.motion.is_some());
    raws.into_iter()
        .enumerate()
        .map(|(i, r)| {
            let before = |x: Option<usize>| x.is_none_or(|x| i < x);
            let step = if r.end {
                Step::End
            } else if r.stop {
                Step::Stop
            } else if r.motion.is_some() {
                if before(orient) && before(stop) {
                    Step::Clearance
                } else if before(stop) {
                    Step::Approach
                } else if last_dwell.is_some_and(|d| i < d) {
                    Step::Measure
                } else {
                    Step::Retract
                }
            } else if r.dwell_block {
                Step::Dwell
            } else if r.m_codes.contains(&19) {
                Step::Orient
            } else if r.m_codes.contains(&5) {
                Step::Spindle
            } else if before(first_move) && r.m_codes.iter().all(|&c| c == 127) {
                Step::Setup
            } else if !r.m_codes.is_empty() {
                Step::Marker
            } else {
                Step::Setup
            };
            Block {
                line: r.line,
                step,
                motion: r.motion,
                dwell_s: r.dwell_s,
                m_codes: r.m_codes,
                comment: r.comment,
            }
        })
        .collect()
}

/// The comments of a G-code line taken out: its words and the text of its comments.
fn split_comments(line: &str) -> (String, Option<String>) {
    let mut words = String::new();
    let mut comment: Option<String> = None;
    let mut rest = line;
    while let Some(at) = rest.find(['(', ';']) {
        words.push_str(&rest[..at]);
        if rest[at..].starts_with(';') {
            comment = Some(rest[at + 1..].trim().to_string());
            rest = "";
            break;
        }
        let close = rest[at..].find(')').map_or(rest.len(), |c| at + c);
        comment = Some(rest[at + 1..close].to_string());
        rest = rest.get(close + 1..).unwrap_or("");
    }
    words.push_str(rest);
    (words, comment)
}

/// One line of an ISO or LinuxCNC program; `None` for a line without a word (a comment, `%`,
/// the `O` number line counts as a block of the setup).
fn g_code_line(
    n: usize,
    line: &str,
    axes: &[AxisWord],
    pose: &mut [f64],
    g: &mut GState,
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Option<Raw>, NcError> {
    let (body, comment) = split_comments(line);
    let body = body.trim();
    if body.is_empty() || body == "%" {
        return Ok(None);
    }
    let mut words: Vec<(char, &str)> = Vec::new();
    let b = body.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b' ' {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < b.len() && !b[i].is_ascii_alphabetic() && b[i] != b' ' {
            i += 1;
        }
        let letter = (b[start] as char).to_ascii_uppercase();
        if !letter.is_ascii_uppercase() {
            return Err(err(&body[start..i], "not a word".into()));
        }
        words.push((letter, &body[start + 1..i]));
    }
    let number = |w: &(char, &str)| {
        read_number(w.0 as u8, w.1)
            .map(|(v, _)| v)
            .ok_or_else(|| err(&format!("{}{}", w.0, w.1), "cannot read its number".into()))
    };
    let mut r = Raw {
        line: n,
        motion: None,
        dwell_s: None,
        dwell_block: false,
        m_codes: Vec::new(),
        end: false,
        stop: false,
        comment,
    };
    let (mut g53, mut g10, mut dwell) = (false, false, false);
    let mut named: Vec<(usize, f64)> = Vec::new();
    let (mut l, mut p) = (None, None);
    for w in &words {
        let v = number(w)?;
        match w.0 {
            'G' => match w.1 {
                "0" => g.rapid = true,
                "1" => g.rapid = false,
                "4" => dwell = true,
                "10" => g10 = true,
                "53" => g53 = true,
                "54" => g.g54 = true,
                "55" | "56" | "57" | "58" | "59" => g.g54 = false,
                "93" => g.inverse_time = true,
                "94" => g.inverse_time = false,
                "17" | "21" | "40" | "49" | "61" | "64" | "69" | "80" | "90" | "15" => {}
                _ => {
                    return Err(err(
                        &format!("G{}", w.1),
                        "a G code the reader does not know".into(),
                    ));
                }
            },
            'M' => {
                let code = v as u32;
                r.m_codes.push(code);
                r.stop |= code == 0;
                r.end |= matches!(code, 2 | 30);
            }
            'F' => g.feed = Some(v),
            'L' => l = Some(v),
            'P' => p = Some(v),
            'R' | 'O' | 'N' => {}
            c => match axes.iter().position(|a| a.letter == c) {
                Some(a) => named.push((a, v)),
                None => {
                    return Err(err(
                        &format!("{c}{}", w.1),
                        "a word the reader does not know".into(),
                    ));
                }
            },
        }
    }
    if g10 {
        // G10 L2 P1 with every axis at 0 zeroes the offsets of G54.
        g.p1_zero = l == Some(2.0)
            && p == Some(1.0)
            && named.len() == axes.len()
            && named.iter().all(|&(_, v)| v == 0.0);
        return Ok(Some(r));
    }
    if dwell {
        r.dwell_block = true;
        r.dwell_s = p;
        return Ok(Some(r));
    }
    if !named.is_empty() {
        for &(a, v) in &named {
            pose[a] = v;
        }
        r.motion = Some(Motion {
            rapid: g.rapid,
            machine: g53 || (g.g54 && g.p1_zero),
            inverse_time: g.inverse_time,
            feed: if g.rapid { None } else { g.feed },
            named: named.iter().map(|&(a, _)| a).collect(),
            pose: pose.to_vec(),
        });
    }
    Ok(Some(r))
}

/// One line of a Heidenhain conversational program; `None` for a comment line.
fn heidenhain_line(
    n: usize,
    line: &str,
    axes: &[AxisWord],
    pose: &mut [f64],
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Option<Raw>, NcError> {
    let (body, comment) = match line.split_once(';') {
        Some((b, c)) => (b, Some(c.trim().to_string())),
        None => (line, None),
    };
    let mut tokens: Vec<&str> = body.split_whitespace().collect();
    if tokens
        .first()
        .is_some_and(|t| t.bytes().all(|b| b.is_ascii_digit()))
    {
        tokens.remove(0);
    }
    let Some(&kw) = tokens.first() else {
        return Ok(None);
    };
    let mut r = Raw {
        line: n,
        motion: None,
        dwell_s: None,
        dwell_block: false,
        m_codes: Vec::new(),
        end: false,
        stop: false,
        comment,
    };
    match (kw, tokens.get(1).copied()) {
        ("BEGIN", Some("PGM")) | ("FUNCTION", Some("RESET")) => return Ok(Some(r)),
        ("END", Some("PGM")) => {
            r.end = true;
            return Ok(Some(r));
        }
        ("STOP", _) => {
            r.stop = true;
            return Ok(Some(r));
        }
        ("CYCL", Some("DEF")) => {
            r.dwell_block = true;
            match tokens.get(2).copied() {
                Some("9.0") => {}
                Some("9.1") if tokens.get(3) == Some(&"DWELL") => {
                    let t = tokens.get(4).copied().unwrap_or("");
                    r.dwell_s = Some(
                        read_number(b'D', t)
                            .map(|(v, _)| v)
                            .ok_or_else(|| err(t, "cannot read the dwell time".into()))?,
                    );
                }
                _ => return Err(err(body.trim(), "a cycle the reader does not know".into())),
            }
            return Ok(Some(r));
        }
        ("L", _) => {}
        _ => return Err(err(kw, "a block the reader does not know".into())),
    }
    let (mut rapid, mut m91, mut feed) = (false, false, None);
    let mut named: Vec<(usize, f64)> = Vec::new();
    for t in &tokens[1..] {
        let letter = t.chars().next().unwrap_or(' ');
        let num = &t[letter.len_utf8()..];
        match letter {
            'R' if *t == "R0" => {}
            'F' if *t == "FMAX" => rapid = true,
            'F' => {
                feed = Some(
                    read_number(b'F', num)
                        .map(|(v, _)| v)
                        .ok_or_else(|| err(t, "cannot read the feed".into()))?,
                )
            }
            'M' => {
                let code: u32 = num
                    .parse()
                    .map_err(|_| err(t, "cannot read the M function".into()))?;
                m91 |= code == 91;
                r.m_codes.push(code);
            }
            c => match axes.iter().position(|a| a.letter == c) {
                Some(a) => named.push((
                    a,
                    read_number(c as u8, num)
                        .map(|(v, _)| v)
                        .ok_or_else(|| err(t, "cannot read its number".into()))?,
                )),
                None => return Err(err(t, "a word the reader does not know".into())),
            },
        }
    }
    r.m_codes.retain(|&c| c != 91);
    r.stop |= r.m_codes.contains(&0);
    if !named.is_empty() {
        for &(a, v) in &named {
            pose[a] = v;
        }
        r.motion = Some(Motion {
            rapid,
            machine: m91,
            inverse_time: false,
            feed: if rapid { None } else { feed },
            named: named.iter().map(|&(a, _)| a).collect(),
            pose: pose.to_vec(),
        });
    }
    Ok(Some(r))
}
