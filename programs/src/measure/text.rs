//! The text of a measurement program in each dialect: the frame (program start and end, the
//! modes), comments, moves and dwells.
//!
//! ISO (Fanuc-type G-code):
//!
//! ```text
//! %
//! O1000 (RTEST R-TEST MEASUREMENT PROGRAM)
//! (… the header: what the program assumes …)
//! G90 G21 G94 G17 G40 G49 G80 G69 G15 G61
//! G1 X-217.5040 Y-0.2790 Z211.5370 A0.0000 C0.0000 F500.
//! G4 P3000
//! G93 G1 X-217.5040 Y-0.2790 Z211.5370 A-0.0154 C1.5000 F720.000
//! G4 P3000
//! …
//! G94
//! M30
//! %
//! ```
//!
//! Heidenhain conversational:
//!
//! ```text
//! 0 BEGIN PGM RTEST1000 MM
//! 1 ; … the header …
//! 9 FUNCTION RESET TCPM
//! 10 L X-217.5040 Y-0.2790 Z+211.5370 A+0.0000 C+0.0000 R0 F500
//! 11 CYCL DEF 9.0 DWELL TIME
//! 12 CYCL DEF 9.1 DWELL 3
//! 13 L X-217.5040 Y-0.2790 Z+211.5370 A-0.0154 C+1.5000 R0 F24.612
//! …
//! 500 END PGM RTEST1000 MM
//! ```

use formats::nc::Dialect;
use formats::nc::number::NumberStyle;

/// The feed word of a move.
pub(crate) enum Feed {
    /// ISO `G0`, Heidenhain `FMAX`.
    Rapid,
    /// The text of an `F` number and whether it is inverse time (ISO `G93`) or a feed per
    /// minute; `None` for a Heidenhain move of no axis, which keeps the modal feed.
    Words(Option<String>),
}

/// A program being written, line by line, in one dialect.
pub(crate) struct ProgramText {
    dialect: Dialect,
    out: String,
    /// The next Heidenhain block number.
    block: usize,
    /// ISO: `G93` has been written.
    inverse_time: bool,
}

/// How a number of a word is written: `+` signs in Heidenhain programs, a decimal point always.
pub(crate) fn word_style(dialect: Dialect, letter: char) -> NumberStyle {
    NumberStyle {
        letter: letter as u8,
        plus: dialect == Dialect::Heidenhain,
        leading_zero: true,
        point: true,
        decimals: 0,
        int_width: 0,
    }
}

/// `text` as a comment may hold it: ASCII, upper case in ISO programs (as Fanuc-type controls
/// show comments), no parentheses in ISO comments (they would close it), no `;` in Heidenhain
/// ones.
fn clean_comment(dialect: Dialect, text: &str) -> String {
    text.chars()
        .map(|c| match (dialect, c) {
            (_, c) if !c.is_ascii() || c.is_ascii_control() => '?',
            (Dialect::Iso, '(') => '[',
            (Dialect::Iso, ')') => ']',
            (Dialect::Iso, c) => c.to_ascii_uppercase(),
            (Dialect::Heidenhain, ';') => ',',
            (Dialect::Heidenhain, c) => c,
        })
        .collect()
}

impl ProgramText {
    /// The start of a program named by `number` (ISO `O` number; Heidenhain `RTEST<number>`),
    /// its first comment `title`.
    pub(crate) fn new(dialect: Dialect, number: u32, title: &str) -> ProgramText {
        let mut p = ProgramText {
            dialect,
            out: String::new(),
            block: 0,
            inverse_time: false,
        };
        match dialect {
            Dialect::Iso => {
                p.out += "%\n";
                p.out += &format!("O{number:04} ({})\n", clean_comment(dialect, title));
            }
            Dialect::Heidenhain => {
                p.line(&format!("BEGIN PGM RTEST{number} MM"));
                p.comment(title);
            }
        }
        p
    }

    /// One block (a Heidenhain block number is put before it).
    fn line(&mut self, body: &str) {
        if self.dialect == Dialect::Heidenhain {
            self.out += &self.block.to_string();
            self.out.push(' ');
            self.block += 1;
        }
        self.out += body;
        self.out.push('\n');
    }

    /// A comment line.
    pub(crate) fn comment(&mut self, text: &str) {
        let text = clean_comment(self.dialect, text);
        match self.dialect {
            Dialect::Iso => {
                self.out += &format!("({text})\n");
            }
            Dialect::Heidenhain => self.line(&format!("; {text}")),
        }
    }

    /// The modes before the first move. ISO: absolute, mm, feed per minute, XY plane, radius and
    /// length compensation off, cycles, rotation and polar coordinates off, and exact stop
    /// (`G61`, static) or continuous path mode (`G64`, continuous). Heidenhain: tool centre
    /// point control off.
    pub(crate) fn modes(&mut self, exact_stop: bool) {
        match self.dialect {
            Dialect::Iso => {
                let path = if exact_stop { "G61" } else { "G64" };
                self.line(&format!("G90 G21 G94 G17 G40 G49 G80 G69 G15 {path}"));
            }
            Dialect::Heidenhain => self.line("FUNCTION RESET TCPM"),
        }
    }

    /// A straight move to the axis words `words` (`X-217.5040 Y…`, in their order) with feed
    /// `feed`; the approach (`approach = true`) is a feed per minute move whatever the mode.
    pub(crate) fn move_to(&mut self, words: &str, feed: &Feed, approach: bool) {
        let body = match (self.dialect, feed) {
            (Dialect::Iso, Feed::Rapid) => format!("G0 {words}"),
            (Dialect::Iso, Feed::Words(f)) => {
                let f = f.as_deref().map(|f| format!(" F{f}")).unwrap_or_default();
                if approach {
                    format!("G1 {words}{f}")
                } else if !self.inverse_time {
                    self.inverse_time = true;
                    format!("G93 G1 {words}{f}")
                } else {
                    format!("G1 {words}{f}")
                }
            }
            (Dialect::Heidenhain, Feed::Rapid) => format!("L {words} R0 FMAX"),
            (Dialect::Heidenhain, Feed::Words(f)) => match f {
                Some(f) => format!("L {words} R0 F{f}"),
                None => format!("L {words} R0"),
            },
        };
        self.line(&body);
    }

    /// A dwell of `ms` milliseconds, with an optional comment at the end of the block. ISO:
    /// `G4 P<ms>` (P in ms without a decimal point, as Fanuc-type controls read it);
    /// Heidenhain: cycle 9, `CYCL DEF 9.0 DWELL TIME` and `CYCL DEF 9.1 DWELL <s>`, the time in
    /// s with at most three decimals (the cycle takes effect where it is defined).
    pub(crate) fn dwell(&mut self, ms: u64, comment: Option<&str>) {
        match self.dialect {
            Dialect::Iso => {
                let c = comment
                    .map(|c| format!(" ({})", clean_comment(self.dialect, c)))
                    .unwrap_or_default();
                self.line(&format!("G4 P{ms}{c}"));
            }
            Dialect::Heidenhain => {
                let c = comment
                    .map(|c| format!(" ; {}", clean_comment(self.dialect, c)))
                    .unwrap_or_default();
                let mut s = format!("{}.{:03}", ms / 1000, ms % 1000);
                while s.ends_with('0') {
                    s.pop();
                }
                if s.ends_with('.') {
                    s.pop();
                }
                self.line("CYCL DEF 9.0 DWELL TIME");
                self.line(&format!("CYCL DEF 9.1 DWELL {s}{c}"));
            }
        }
    }

    /// A block of only the miscellaneous function `M<code>` (ISO `M<code>`, Heidenhain
    /// `L M<code>`).
    pub(crate) fn m_function(&mut self, code: u16) {
        match self.dialect {
            Dialect::Iso => self.line(&format!("M{code}")),
            Dialect::Heidenhain => self.line(&format!("L M{code}")),
        }
    }

    /// The end of the program: ISO back to feed per minute (`G94`), `M30`, `%`; Heidenhain
    /// `END PGM`.
    pub(crate) fn finish(mut self, number: u32) -> String {
        match self.dialect {
            Dialect::Iso => {
                if self.inverse_time {
                    self.line("G94");
                }
                self.line("M30");
                self.out += "%\n";
            }
            Dialect::Heidenhain => self.line(&format!("END PGM RTEST{number} MM")),
        }
        self.out
    }
}
