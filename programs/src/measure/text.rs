//! The text of a measurement program in each dialect: the frame (program start and end, the
//! modes), comments, the moves in machine coordinates, the spindle, the stop, dwells.
//!
//! ISO (Fanuc-type G-code): `G53 G0` for the clearance, the rotary axes and the rapids of the
//! approach and the retract (Fanuc's `G53` is one-shot and rapid only); the feed moves run in
//! `G54`, whose offsets the program sets to zero first (`G10 L2 P1 X0 Y0 Z0 A0 C0`):
//!
//! ```text
//! %
//! O1000 (RTEST R-TEST MEASUREMENT PROGRAM)
//! (… the header: what the program assumes, what to check …)
//! G90 G21 G94 G17 G40 G49 G80 G69 G15 G61
//! G10 L2 P1 X0 Y0 Z0 A0 C0
//! G54
//! M5
//! G53 G0 Z500.0000
//! G53 G0 A0.0000 C0.0000
//! M19
//! G53 G0 X217.5040 Y-0.2790
//! G53 G0 Z86.6610
//! G94 G1 X217.5040 Y-0.2790 Z56.6610 A0.0000 C0.0000 F500.000
//! M0 (CHECK THE NEST SITS ON THE BALL, THEN CYCLE START)
//! G4 P3000
//! G93 G1 X217.4222 Y-5.9075 Z56.6626 A-0.0154 C1.5000 F355.334
//! …
//! G94 G1 X217.5040 Y-0.2790 Z86.6610 F500.000
//! G53 G0 Z500.0000
//! M30
//! %
//! ```
//!
//! LinuxCNC: the same blocks with `G53` on every move (not modal there, feed moves allowed),
//! `G4 P` in seconds, `(MSG,…)` before `M0`, `M19 R0`, `M2`, no program number. Heidenhain
//! conversational: `M91` on every positioning block, `STOP`, `L M19`, cycle 9 dwells.

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
    /// ISO, LinuxCNC: `G93` is in force.
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

/// The comments LinuxCNC acts on (`(MSG,…)` shows a message, `(DEBUG,…)`, `(PRINT,…)`,
/// `(LOG…)` and `(PROBE…)` write or log): a header line must not start with one.
const LINUXCNC_ACTIVE: [&str; 9] = [
    "msg,",
    "debug,",
    "print,",
    "log,",
    "logopen,",
    "logappend,",
    "logclose",
    "probeopen",
    "probeclose",
];

/// `text` as a comment may hold it: ASCII, upper case in ISO programs (as Fanuc-type controls
/// show comments), no parentheses in G-code comments (they would close it), no `;` in
/// Heidenhain ones; a LinuxCNC comment that would start like an active one gets `- ` before.
fn clean_comment(dialect: Dialect, text: &str) -> String {
    let s: String = text
        .chars()
        .map(|c| match (dialect, c) {
            (_, c) if !c.is_ascii() || c.is_ascii_control() => '?',
            (Dialect::Iso | Dialect::LinuxCnc, '(') => '[',
            (Dialect::Iso | Dialect::LinuxCnc, ')') => ']',
            (Dialect::Iso, c) => c.to_ascii_uppercase(),
            (Dialect::Heidenhain, ';') => ',',
            (_, c) => c,
        })
        .collect();
    let lower = s.trim_start().to_ascii_lowercase();
    if dialect == Dialect::LinuxCnc && LINUXCNC_ACTIVE.iter().any(|k| lower.starts_with(k)) {
        format!("- {s}")
    } else {
        s
    }
}

impl ProgramText {
    /// The start of a program named by `number` (ISO `O` number; Heidenhain `RTEST<number>`;
    /// LinuxCNC has none: its `O` words are subroutines), its first comment `title`.
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
            Dialect::LinuxCnc => {
                p.out += "%\n";
                p.comment(title);
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
            Dialect::Iso | Dialect::LinuxCnc => self.out += &format!("({text})\n"),
            Dialect::Heidenhain => self.line(&format!("; {text}")),
        }
    }

    /// The modes before the first move, and the machine coordinates of the feed moves.
    ///
    /// ISO: absolute, mm, feed per minute, XY plane, radius and length compensation off,
    /// cycles, rotation and polar coordinates off, exact stop (`G61`, static) or continuous
    /// path (`G64`); then `G10 L2 P1` with every axis at 0 (`zero_words`: `X0 Y0 Z0 A0 C0`) and
    /// `G54`, so that the feed moves, which Fanuc's one-shot rapid `G53` cannot make, run in
    /// machine coordinates too. LinuxCNC: the same modes without `G69 G15` (no such codes
    /// there), `G64 P<tolerance>` for the continuous path. Heidenhain: tool centre point control
    /// off, shortest-path traverse of the rotary axes off (`M127`). Every dialect then stops
    /// the spindle (`M5`).
    pub(crate) fn setup(&mut self, exact_stop: bool, zero_words: &str) {
        match self.dialect {
            Dialect::Iso => {
                let path = if exact_stop { "G61" } else { "G64" };
                self.line(&format!("G90 G21 G94 G17 G40 G49 G80 G69 G15 {path}"));
                self.line(&format!("G10 L2 P1 {zero_words}"));
                self.line("G54");
                self.line("M5");
            }
            Dialect::LinuxCnc => {
                let path = if exact_stop { "G61" } else { "G64 P0.01" };
                self.line(&format!("G90 G21 G94 G17 G40 G49 G80 {path}"));
                self.line("M5");
            }
            Dialect::Heidenhain => {
                self.line("FUNCTION RESET TCPM");
                self.line("L M127");
                self.line("L M5");
            }
        }
    }

    /// A rapid move in machine coordinates to the axis words `words`: ISO `G53 G0`, LinuxCNC
    /// `G53 G0`, Heidenhain `L … R0 FMAX M91`.
    pub(crate) fn machine_rapid(&mut self, words: &str) {
        match self.dialect {
            Dialect::Iso | Dialect::LinuxCnc => self.line(&format!("G53 G0 {words}")),
            Dialect::Heidenhain => self.line(&format!("L {words} R0 FMAX M91")),
        }
    }

    /// A feed move at `f` mm/min (its `F` text) in machine coordinates to `words`: the slow
    /// approach onto the ball and the retract off it. ISO `G94 G1 … F` in the zeroed `G54`,
    /// LinuxCNC `G53 G94 G1 … F`, Heidenhain `L … R0 F… M91`. Feed per minute again after an
    /// inverse time run.
    pub(crate) fn machine_feed(&mut self, words: &str, f: &str) {
        self.inverse_time = false;
        match self.dialect {
            Dialect::Iso => self.line(&format!("G94 G1 {words} F{f}")),
            Dialect::LinuxCnc => self.line(&format!("G53 G94 G1 {words} F{f}")),
            Dialect::Heidenhain => self.line(&format!("L {words} R0 F{f} M91")),
        }
    }

    /// Spindle orientation: ISO `M19`, LinuxCNC `M19 R0` (to 0°), Heidenhain `L M19`. The
    /// angle of a bare `M19` is the machine builder's.
    pub(crate) fn orient(&mut self) {
        match self.dialect {
            Dialect::Iso => self.line("M19"),
            Dialect::LinuxCnc => self.line("M19 R0"),
            Dialect::Heidenhain => self.line("L M19"),
        }
    }

    /// A program stop with `message` for the operator: ISO `M0 (MESSAGE)`, LinuxCNC
    /// `(MSG,message)` then `M0` (the control shows the message), Heidenhain `STOP ; message`.
    pub(crate) fn stop(&mut self, message: &str) {
        let text = clean_comment(self.dialect, message);
        match self.dialect {
            Dialect::Iso => self.line(&format!("M0 ({text})")),
            Dialect::LinuxCnc => {
                self.out += &format!("(MSG,{text})\n");
                self.line("M0");
            }
            Dialect::Heidenhain => self.line(&format!("STOP ; {text}")),
        }
    }

    /// A measuring move to the axis words `words` (`X-217.5040 Y…`, in their order) with feed
    /// `feed`: ISO in the zeroed `G54`, LinuxCNC with `G53`, Heidenhain with `M91`. A feed
    /// move is in inverse time in ISO and LinuxCNC (`G93`, written once).
    pub(crate) fn move_to(&mut self, words: &str, feed: &Feed) {
        let g53 = if self.dialect == Dialect::LinuxCnc {
            "G53 "
        } else {
            ""
        };
        let body = match (self.dialect, feed) {
            (Dialect::Iso | Dialect::LinuxCnc, Feed::Rapid) => format!("{g53}G0 {words}"),
            (Dialect::Iso | Dialect::LinuxCnc, Feed::Words(f)) => {
                let f = f.as_deref().map(|f| format!(" F{f}")).unwrap_or_default();
                if self.inverse_time {
                    format!("{g53}G1 {words}{f}")
                } else {
                    self.inverse_time = true;
                    format!("{g53}G93 G1 {words}{f}")
                }
            }
            (Dialect::Heidenhain, Feed::Rapid) => format!("L {words} R0 FMAX M91"),
            (Dialect::Heidenhain, Feed::Words(f)) => match f {
                Some(f) => format!("L {words} R0 F{f} M91"),
                None => format!("L {words} R0 M91"),
            },
        };
        self.line(&body);
    }

    /// A dwell of `ms` milliseconds, with an optional comment at the end of the block. ISO:
    /// `G4 P<ms>` (P in ms without a decimal point, as Fanuc-type controls read it); LinuxCNC:
    /// `G4 P<s>` (seconds, three decimals); Heidenhain: cycle 9, `CYCL DEF 9.0 DWELL TIME` and
    /// `CYCL DEF 9.1 DWELL <s>`, the time in s with at most three decimals (the cycle takes
    /// effect where it is defined).
    pub(crate) fn dwell(&mut self, ms: u64, comment: Option<&str>) {
        let seconds = format!("{}.{:03}", ms / 1000, ms % 1000);
        match self.dialect {
            Dialect::Iso | Dialect::LinuxCnc => {
                let c = comment
                    .map(|c| format!(" ({})", clean_comment(self.dialect, c)))
                    .unwrap_or_default();
                let p = if self.dialect == Dialect::Iso {
                    ms.to_string()
                } else {
                    seconds
                };
                self.line(&format!("G4 P{p}{c}"));
            }
            Dialect::Heidenhain => {
                let c = comment
                    .map(|c| format!(" ; {}", clean_comment(self.dialect, c)))
                    .unwrap_or_default();
                let mut s = seconds;
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

    /// A block of only the miscellaneous function `M<code>` (ISO, LinuxCNC `M<code>`,
    /// Heidenhain `L M<code>`).
    pub(crate) fn m_function(&mut self, code: u16) {
        match self.dialect {
            Dialect::Iso | Dialect::LinuxCnc => self.line(&format!("M{code}")),
            Dialect::Heidenhain => self.line(&format!("L M{code}")),
        }
    }

    /// The end of the program: ISO `M30`, `%`; LinuxCNC `M2`, `%`; Heidenhain `END PGM`.
    pub(crate) fn finish(mut self, number: u32) -> String {
        match self.dialect {
            Dialect::Iso => {
                self.line("M30");
                self.out += "%\n";
            }
            Dialect::LinuxCnc => {
                self.line("M2");
                self.out += "%\n";
            }
            Dialect::Heidenhain => self.line(&format!("END PGM RTEST{number} MM")),
        }
        self.out
    }
}
