//! ISO (G-code) blocks: words of a letter and a number, `( … )` and `;` comments.
//!
//! Read: `N` block numbers, `G0 G1` (modal), `G90` (required before the first move), the G
//! codes of [`ACCEPTED`], `M` (not `M98 M99 M198`), `F S T`, `P` with `G4`, `O` program numbers,
//! `%`, a `/` block without G codes and moves, and the machine's axis letters. Everything else
//! is refused with the reason ([`g_refusal`], [`IsoReader::word`]). Letters may be lower case.
//!
//! LinuxCNC programs ([`IsoReader::linuxcnc`]) are read by the same rules but for what
//! LinuxCNC reads otherwise: `O` words are subroutines, calls and loops there (refused: the
//! blocks would not run in the order of the file); `G15` and `G69` are not LinuxCNC codes
//! (refused); `G61.1` (exact stop) is read, and `G64` may carry its tolerances `P` and `Q`.
//! `G4 P` is a dwell in seconds there, in ms on Fanuc-type controls: no pose depends on it.

use crate::nc::error::{NcError, Place};
use crate::nc::number::read_number;
use crate::nc::program::{AxisField, BlockAxes, BlockReader};
use crate::poses::{AxisWord, MAX_COMMAND, letters};

/// The G codes read, with the group of the modal ones (two of a group in a block are refused).
const ACCEPTED: &[(u32, Option<u32>, Option<Group>)] = &[
    (0, None, Some(Group::Motion)),
    (1, None, Some(Group::Motion)),
    (4, None, Some(Group::Dwell)),
    (9, None, None),
    (15, None, None),
    (17, None, Some(Group::Plane)),
    (18, None, Some(Group::Plane)),
    (19, None, Some(Group::Plane)),
    (21, None, Some(Group::Units)),
    (40, None, None),
    (49, None, None),
    (61, None, Some(Group::PathMode)),
    (64, None, Some(Group::PathMode)),
    (69, None, None),
    (80, None, None),
    (90, None, Some(Group::Distance)),
    (93, None, Some(Group::Feed)),
    (94, None, Some(Group::Feed)),
    (95, None, Some(Group::Feed)),
];

/// The accepted G codes, for messages.
pub(crate) const ACCEPTED_LIST: &str =
    "G0 G1 G4 G9 G15 G17 G18 G19 G21 G40 G49 G61 G64 G69 G80 G90 G93 G94 G95";

/// The G codes of LinuxCNC programs, for messages.
pub(crate) const LINUXCNC_LIST: &str =
    "G0 G1 G4 G9 G17 G18 G19 G21 G40 G49 G61 G61.1 G64 G80 G90 G93 G94 G95";

/// Whether G code `major.minor` is read in a LinuxCNC program, with its group: the codes of
/// [`ACCEPTED`] but `G15` and `G69` (not LinuxCNC codes), and `G61.1` (exact stop).
fn linuxcnc_code(major: u32, minor: Option<u32>) -> Option<Option<Group>> {
    match (major, minor) {
        (15 | 69, None) => None,
        (61, Some(1)) => Some(Some(Group::PathMode)),
        _ => ACCEPTED
            .iter()
            .find(|(a, b, _)| *a == major && *b == minor)
            .map(|&(.., g)| g),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Group {
    Motion,
    Dwell,
    Plane,
    Units,
    PathMode,
    Distance,
    Feed,
}

/// Why G code `major.minor` is refused (in a LinuxCNC program when `linuxcnc`).
fn g_refusal(major: u32, minor: Option<u32>, linuxcnc: bool) -> String {
    const MACHINE: &str = "the program must be in machine coordinates, so nothing in it may move the coordinate system";
    match (major, minor) {
        (2 | 3, None) => "circular arcs are refused: only straight moves (G0, G1) are read, and a corrected end point would no longer lie on the arc's circle".into(),
        (91, None) => "incremental positions are refused: the poses are absolute positions, so the program must be absolute (G90)".into(),
        (20, None) => "inch input is refused: the program must be in mm (G21)".into(),
        (28 | 30, _) => "a return to the reference position is refused: it moves through an intermediate point to a position the program does not hold".into(),
        (53, None) => "a one-shot move in machine coordinates is refused: every move must be a modal G0/G1 block read the same way (the program is in machine coordinates already: write it as G0 or G1)".into(),
        (43, Some(4 | 5)) => "tool centre point control is refused: the program must command the axes themselves (TCP off), in machine coordinates".into(),
        (41 | 42, None) => "cutter radius compensation is refused: the control would move the axes away from the programmed positions".into(),
        (43 | 44, None) | (43, Some(1)) => "tool length compensation is refused: the control would add the tool length to the programmed positions".into(),
        (52 | 92, _) | (54..=59, _) => format!("a work offset or coordinate shift is refused: {MACHINE}"),
        (10, _) => format!("setting offsets from the program is refused: {MACHINE}"),
        (68, _) | (16, None) => format!("a coordinate rotation (or polar coordinates) is refused: {MACHINE}"),
        (50 | 51, _) => format!("scaling and mirroring are refused: {MACHINE}"),
        (73 | 74 | 76 | 81..=89, None) => "canned cycles are refused: their moves are not written in the program".into(),
        (65 | 66, _) => "macro calls are refused: their moves are not written in the program".into(),
        (7 | 12 | 13, Some(1)) | (107 | 112 | 113, None) => "cylindrical and polar interpolation are refused: the program must command the axes themselves".into(),
        (15 | 69, None) if linuxcnc => format!(
            "not a LinuxCNC G code (LinuxCNC has neither G15/G16 polar coordinates nor G68/G69 rotation; read: {LINUXCNC_LIST})"
        ),
        _ if linuxcnc => {
            format!("not a G code rtest reads in a LinuxCNC program (read: {LINUXCNC_LIST})")
        }
        _ => format!("not a G code rtest reads in an ISO program (read: {ACCEPTED_LIST})"),
    }
}

/// The block reader of ISO programs; its modal state is whether `G90` has been given.
pub(crate) struct IsoReader<'a> {
    axes: &'a [AxisWord],
    /// LinuxCNC's rules ([`IsoReader::linuxcnc`]).
    linuxcnc: bool,
    absolute: bool,
    /// A line with a word was read (a `%` before it starts the program, one after ends it).
    started: bool,
    /// What ended the program: a `%` after the first block, or `M2` / `M30`.
    ended: Option<&'static str>,
}

/// A word: its letter (upper case) and the byte range of the word and of its number in the line.
struct Word {
    letter: u8,
    start: usize,
    number: usize,
    end: usize,
}

/// What a block holds besides its axis words.
#[derive(Default)]
struct Seen {
    /// Column (byte) of the first word of each letter.
    letters: [Option<usize>; 26],
    groups: Vec<(Group, usize, usize)>,
    any_g: bool,
    g90: bool,
    /// A `G64` (LinuxCNC: its `P` and `Q` are tolerances).
    g64: bool,
    p: Option<(usize, usize)>,
    q: Option<(usize, usize)>,
    /// The block ends the program (`M2`, `M30`).
    end: Option<&'static str>,
}

impl<'a> IsoReader<'a> {
    pub(crate) fn new(axes: &'a [AxisWord]) -> Self {
        IsoReader {
            axes,
            linuxcnc: false,
            absolute: false,
            started: false,
            ended: None,
        }
    }

    /// The reader of LinuxCNC programs (see the module documentation).
    pub(crate) fn linuxcnc(axes: &'a [AxisWord]) -> Self {
        IsoReader {
            linuxcnc: true,
            ..IsoReader::new(axes)
        }
    }

    /// Reads word `w` of the line at `place`: an axis word into `fields`, the rest into `seen`.
    fn word(
        &self,
        place: &Place,
        offset: usize,
        w: &Word,
        seen: &mut Seen,
        fields: &mut Vec<AxisField>,
    ) -> Result<(), NcError> {
        let line = place.text;
        let num = &line[w.number..w.end];
        let err = |m: String| place.err(w.start, w.end, m);
        let l = w.letter as char;
        if !matches!(l, 'G' | 'M')
            && let Some(first) = seen.letters[(w.letter - b'A') as usize]
        {
            return Err(err(format!(
                "a second `{l}` word in the block (the first at column {})",
                line[..first].chars().count() + 1
            )));
        }
        seen.letters[(w.letter - b'A') as usize].get_or_insert(w.start);
        let integer = || !num.is_empty() && num.bytes().all(|b| b.is_ascii_digit());
        let unreadable = || err(format!("cannot read the number `{num}` of the `{l}` word"));
        if let Some(axis) = self.axes.iter().position(|a| a.letter == l) {
            let (value, mut style) = read_number(w.letter, num).ok_or_else(unreadable)?;
            style.letter = line.as_bytes()[w.start];
            if value.abs() >= MAX_COMMAND {
                return Err(err(format!(
                    "{num} {} is beyond ±{MAX_COMMAND}: no axis command reaches it",
                    self.axes[axis].unit()
                )));
            }
            fields.push(AxisField {
                axis,
                start: offset + w.number,
                end: offset + w.end,
                value,
                style,
            });
            return Ok(());
        }
        match l {
            'O' if self.linuxcnc => {
                return Err(err(
                    "`O` words are refused in a LinuxCNC program: there they are subroutines, calls and loops, so the blocks would not run in the order of the file".into(),
                ));
            }
            'Q' if self.linuxcnc && read_number(w.letter, num).is_some_and(|(v, _)| v >= 0.0) => {
                seen.q = Some((w.start, w.end));
            }
            'N' | 'O' if integer() => {}
            'F' | 'S' | 'T' | 'P' if read_number(w.letter, num).is_some_and(|(v, _)| v < 0.0) => {
                return Err(err(format!(
                    "a negative {} is meaningless",
                    match l {
                        'F' => "feed",
                        'S' => "spindle speed",
                        'T' => "tool number",
                        _ => "dwell time",
                    }
                )));
            }
            'F' | 'S' | 'T' if read_number(w.letter, num).is_some() => {}
            'P' if read_number(w.letter, num).is_some() => seen.p = Some((w.start, w.end)),
            'M' if integer() => {
                let code: u32 = num.parse().map_err(|_| unreadable())?;
                match code {
                    2 => seen.end = Some("`M2`"),
                    30 => seen.end = Some("`M30`"),
                    _ => {}
                }
                if matches!(code, 98 | 99 | 198) {
                    return Err(err(
                        "subprogram calls and returns are refused: the moves of a subprogram are not in this program, and M99 repeats it".into(),
                    ));
                }
            }
            'G' => {
                let (major, minor) = match num.split_once('.') {
                    Some((a, b)) => (a, Some(b)),
                    None => (num, None),
                };
                let code = |s: &str| {
                    (!s.is_empty() && s.len() <= 4 && s.bytes().all(|b| b.is_ascii_digit()))
                        .then(|| s.parse::<u32>().ok())
                        .flatten()
                };
                let major = code(major).ok_or_else(unreadable)?;
                let minor = match minor {
                    Some(m) => Some(code(m).ok_or_else(unreadable)?),
                    None => None,
                };
                let group = if self.linuxcnc {
                    linuxcnc_code(major, minor).ok_or_else(|| err(g_refusal(major, minor, true)))?
                } else {
                    ACCEPTED
                        .iter()
                        .find(|(a, b, _)| *a == major && *b == minor)
                        .map(|&(.., g)| g)
                        .ok_or_else(|| err(g_refusal(major, minor, false)))?
                };
                seen.any_g = true;
                seen.g90 |= major == 90;
                seen.g64 |= major == 64 && minor.is_none();
                if let Some(g) = group {
                    if let Some(&(_, s, e)) = seen.groups.iter().find(|(h, ..)| *h == g) {
                        return Err(err(format!(
                            "`{}` and `{}` in one block: both set the same mode",
                            &line[s..e],
                            &line[w.start..w.end]
                        )));
                    }
                    seen.groups.push((g, w.start, w.end));
                }
            }
            'N' | 'O' | 'F' | 'S' | 'T' | 'P' | 'M' => return Err(unreadable()),
            'I' | 'J' | 'K' | 'R' => {
                return Err(err(
                    "arc words are refused: I, J, K and R give the centre or radius of a G2/G3 arc, and only straight moves are read".into(),
                ));
            }
            'H' | 'D' => {
                return Err(err(
                    "tool offset words are refused: no tool length or radius compensation may act on the programmed positions".into(),
                ));
            }
            'X' | 'Y' | 'Z' | 'U' | 'V' | 'W' | 'A' | 'B' | 'C' => {
                return Err(err(format!(
                    "`{l}` is not an axis of this machine (its axes: {})",
                    letters(self.axes)
                )));
            }
            _ => {
                return Err(err(format!(
                    "a `{l}` word is not read in {} program (read: N, G, M, F, S, T, P with G4, {}and the axes {})",
                    if self.linuxcnc {
                        "a LinuxCNC"
                    } else {
                        "an ISO"
                    },
                    if self.linuxcnc {
                        "P and Q with G64, "
                    } else {
                        "O, "
                    },
                    letters(self.axes)
                )));
            }
        }
        Ok(())
    }
}

impl BlockReader for IsoReader<'_> {
    fn ended(&self) -> Option<&'static str> {
        self.ended
    }

    fn block(&mut self, place: &Place, offset: usize) -> Result<Option<BlockAxes>, NcError> {
        let line = place.text;
        let b = line.as_bytes();
        let mut seen = Seen::default();
        let mut fields: Vec<AxisField> = Vec::new();
        let mut block_delete = None;
        let mut tokens = 0usize;
        let mut words = 0usize;
        let mut spaced = false;
        let mut insert_at = 0;
        let mut i = 0;
        while i < b.len() {
            let blank_before = i > 0 && matches!(b[i - 1], b' ' | b'\t');
            match b[i] {
                b' ' | b'\t' => {
                    i += 1;
                    continue;
                }
                b'(' => match b[i + 1..].iter().position(|&c| c == b')') {
                    Some(j) => i += j + 2,
                    None => {
                        return Err(place.err(
                            i,
                            0,
                            "a comment `(` that does not close on its line",
                        ));
                    }
                },
                b';' => break,
                b'%' if tokens == 0 => {
                    if self.started && line.trim() == "%" {
                        self.ended = Some("`%`");
                    }
                    i += 1
                }
                b'/' if tokens == 0 => {
                    block_delete = Some(i);
                    i += 1;
                }
                c if c.is_ascii_alphabetic() => {
                    let start = i;
                    i += 1;
                    while i < b.len()
                        && !matches!(b[i], b' ' | b'\t' | b'(' | b';')
                        && !b[i].is_ascii_alphabetic()
                    {
                        i += 1;
                    }
                    let w = Word {
                        letter: c.to_ascii_uppercase(),
                        start,
                        number: start + 1,
                        end: i,
                    };
                    let before = fields.len();
                    self.word(place, offset, &w, &mut seen, &mut fields)?;
                    if fields.len() > before {
                        insert_at = offset + i;
                    }
                    spaced |= tokens > 0 && blank_before;
                    words += 1;
                }
                _ => {
                    let c = line[i..].chars().next().unwrap_or('?');
                    return Err(place.err(
                        i,
                        i + c.len_utf8(),
                        "a character that is not part of an ISO word",
                    ));
                }
            }
            tokens += 1;
        }
        if let Some(at) = block_delete
            && (seen.any_g || !fields.is_empty())
        {
            return Err(place.err(
                at,
                at + 1,
                "a block the operator may skip must not move or set a G code: whether it runs would change the positions of the blocks after it",
            ));
        }
        let dwell = seen.groups.iter().any(|(g, ..)| *g == Group::Dwell);
        let tolerance = self.linuxcnc && seen.g64;
        if let Some((s, e)) = seen.p
            && !dwell
            && !tolerance
        {
            let what = if self.linuxcnc {
                "a `P` word outside a dwell (G4) or a path tolerance (G64) is not read"
            } else {
                "a `P` word outside a dwell (G4) is not read"
            };
            return Err(place.err(s, e, what));
        }
        if let Some((s, e)) = seen.q
            && !tolerance
        {
            return Err(place.err(
                s,
                e,
                "a `Q` word outside a path tolerance (G64) is not read in a LinuxCNC program",
            ));
        }
        if dwell && let Some(f) = fields.first() {
            return Err(place.err(
                f.start - offset - 1,
                f.end - offset,
                "an axis word in a dwell (G4) block: on many controls it is the dwell time; give the dwell with P",
            ));
        }
        self.absolute |= seen.g90;
        self.started |= words > 0;
        if seen.end.is_some() {
            self.ended = seen.end;
        }
        let Some(first) = fields.first() else {
            return Ok(None);
        };
        if !self.absolute {
            return Err(place.err(
                first.start - offset - 1,
                first.end - offset,
                "a move before G90: say G90 (absolute positions) before the first move; the control's default is a parameter the program does not show",
            ));
        }
        Ok(Some(BlockAxes {
            fields,
            insert_at,
            spaced: spaced || words == 1,
        }))
    }
}

#[cfg(test)]
mod tests {
    use crate::nc::{Dialect, parse_program};
    use crate::poses::AxisWord;
    use model_spec::AxisKind::{Linear, Rotary};

    fn axes() -> [AxisWord; 3] {
        [
            AxisWord {
                letter: 'X',
                kind: Linear,
            },
            AxisWord {
                letter: 'Z',
                kind: Linear,
            },
            AxisWord {
                letter: 'C',
                kind: Rotary,
            },
        ]
    }

    fn err(text: &str, dialect: Dialect) -> String {
        parse_program("p.ngc", text, dialect, &axes())
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn linuxcnc_programs_are_read_by_the_iso_rules_but_for_what_linuxcnc_reads_otherwise() {
        // Dwells (in seconds there), path tolerances, exact stop and comments: the poses.
        let text = "%\n(a LinuxCNC program)\nG90 G21 G94 G17 G40 G49 G80 G64 P0.01 Q0.01\nG0 X10 Z5 C0\nG4 P1.5\nG61.1\nG1 C360 F500 ; the last pose\nM2\n%\n";
        let p = parse_program("p.ngc", text, Dialect::LinuxCnc, &axes()).unwrap();
        assert_eq!(p.pose_list().len(), 2);
        assert_eq!(p.pose_list().commands(1), [10.0, 5.0, 360.0]);
        // The same text is not an ISO program: a Q word, P outside a dwell.
        let e = err(text, Dialect::Iso);
        assert!(e.starts_with("p.ngc:3:39: `Q0.01`"), "{e}");
        let e = err(&text.replace(" Q0.01", ""), Dialect::Iso);
        assert!(e.contains("`P0.01`: a `P` word outside a dwell"), "{e}");
        // G53 stays refused in every G-code dialect: the programs compensate corrects are
        // modal G0/G1 blocks in machine coordinates.
        for d in [Dialect::Iso, Dialect::LinuxCnc] {
            let e = err("G90\nG53 G0 X0 Z0 C0\n", d);
            assert!(e.starts_with("p.ngc:2:1: `G53`: a one-shot move"), "{e}");
            let e = err("G90\nG10 L2 P1 X0 Z0 C0\n", d);
            assert!(e.starts_with("p.ngc:2:1: `G10`: setting offsets"), "{e}");
        }
        // O words are subroutines and loops in LinuxCNC; G15 and G69 are not LinuxCNC codes.
        let e = err("o100 sub\nG90 G0 X0 Z0 C0\n", Dialect::LinuxCnc);
        assert!(
            e.starts_with("p.ngc:1:1: `o100`: `O` words are refused"),
            "{e}"
        );
        let e = err("G90 G69\nG0 X0 Z0 C0\n", Dialect::LinuxCnc);
        assert!(e.contains("`G69`: not a LinuxCNC G code"), "{e}");
        let e = err("G90 G0 X0 Z0 C0 Q1\n", Dialect::LinuxCnc);
        assert!(
            e.contains("`Q1`: a `Q` word outside a path tolerance"),
            "{e}"
        );
        let e = err("G90 G0 X0 Z0 C0\nG5.1 X1\n", Dialect::LinuxCnc);
        assert!(
            e.contains("not a G code rtest reads in a LinuxCNC program"),
            "{e}"
        );
        // An ISO program keeps its O number and G69.
        let iso = "%\nO1000\nG90 G69 G15\nG0 X0 Z0 C0\nM30\n%\n";
        assert!(parse_program("p.nc", iso, Dialect::Iso, &axes()).is_ok());
    }
}
