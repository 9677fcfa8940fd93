//! The text of a probing program in each dialect, block by block, with what each block must
//! read back as ([`Expected`]: its step and the pose after it), for the read-back.
//!
//! ISO (Fanuc-type): `G53 G0` rapids; the feed moves and `G31` in `G54`, which the program sets
//! to zero (`G10 L2 P1`); after each `G31` the skip position read into `#31`–`#33`, an alarm
//! when it is the end of the move, `DPRNT` of the three; `POPEN` … `PCLOS`. LinuxCNC: `G53` on
//! every move but `G38.2`, which runs in the zeroed `G54` (`G10 L2 P1 … R0`, `G92.1`);
//! `(PROBEOPEN file)` … `(PROBECLOSE)`. Heidenhain: `M91` on every positioning block, touch
//! probe cycle 0 in the active preset's coordinates, `FN 16: F-PRINT` after each.

use crate::reader::Step;
use formats::nc::Dialect;
use formats::nc::number::{NumberStyle, write_number};

/// What a block must read back as.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Expected {
    /// Its 1-based line.
    pub(crate) line: usize,
    /// Its step.
    pub(crate) step: Step,
    /// For a block that moves: the pose after it (file units, NaN for an axis never named),
    /// and whether it is in machine coordinates.
    pub(crate) pose: Option<(Vec<f64>, bool)>,
    /// The statement of a log, latch or check block.
    pub(crate) statement: Option<String>,
}

/// How an axis word's number is written: `+` signs in Heidenhain programs, a decimal point.
fn style(dialect: Dialect, letter: char) -> NumberStyle {
    NumberStyle {
        letter: letter as u8,
        plus: dialect == Dialect::Heidenhain,
        leading_zero: true,
        point: true,
        decimals: 0,
        int_width: 0,
    }
}

/// The comments LinuxCNC acts on: a header line must not start with one.
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

/// `text` as a comment may hold it: ASCII, upper case in ISO programs, no parentheses in
/// G-code comments, no `;` in Heidenhain ones; a LinuxCNC comment that would start like an
/// active one gets `- ` before it.
pub(crate) fn clean_comment(dialect: Dialect, text: &str) -> String {
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

/// A probing program being written.
#[derive(Clone)]
pub(crate) struct Writer {
    pub(crate) dialect: Dialect,
    out: String,
    /// Lines written.
    lines: usize,
    /// The next Heidenhain block number.
    block: usize,
    /// The axis letters, in [`model_spec::Machine::axes`] order.
    letters: Vec<char>,
    /// The axes in the order their words are written (`formats::csv::column_order`).
    order: Vec<usize>,
    decimals: usize,
    /// The pose after the last move as read back (file units; NaN: never named).
    pose: Vec<f64>,
    /// What every block must read back as.
    pub(crate) expected: Vec<Expected>,
}

impl Writer {
    /// A program of `dialect` for axes `letters` (written in `order`) with `decimals`
    /// decimals.
    pub(crate) fn new(
        dialect: Dialect,
        letters: Vec<char>,
        order: Vec<usize>,
        decimals: usize,
    ) -> Writer {
        let n = letters.len();
        Writer {
            dialect,
            out: String::new(),
            lines: 0,
            block: 0,
            letters,
            order,
            decimals,
            pose: vec![f64::NAN; n],
            expected: Vec::new(),
        }
    }

    /// A line of text (a Heidenhain block number is put before it); its line number.
    fn raw(&mut self, body: &str, numbered: bool) -> usize {
        if numbered && self.dialect == Dialect::Heidenhain {
            self.out += &self.block.to_string();
            self.out.push(' ');
            self.block += 1;
        }
        self.out += body;
        self.out.push('\n');
        self.lines += 1;
        self.lines
    }

    /// A block of step `step` that does not move.
    fn block(&mut self, body: &str, step: Step, statement: Option<String>) -> usize {
        let line = self.raw(body, true);
        self.expected.push(Expected {
            line,
            step,
            pose: None,
            statement,
        });
        line
    }

    /// A comment line.
    pub(crate) fn comment(&mut self, text: &str) {
        let text = clean_comment(self.dialect, text);
        match self.dialect {
            Dialect::Iso | Dialect::LinuxCnc => {
                self.raw(&format!("({text})"), false);
            }
            Dialect::Heidenhain => {
                self.raw(&format!("; {text}"), true);
            }
        }
    }

    /// The axis words of `values` (file units, [`model_spec::Machine::axes`] order) for the
    /// axes `which` picks, in the written order: the text and the values it reads back as.
    ///
    /// # Errors
    /// The first axis whose value cannot be written (not finite, beyond the words' range).
    pub(crate) fn words(
        &self,
        values: &[f64],
        which: impl Fn(usize) -> bool,
    ) -> Result<(String, Vec<(usize, f64)>), String> {
        let mut text = String::new();
        let mut read = Vec::new();
        for &a in self.order.iter().filter(|&&a| which(a)) {
            if !text.is_empty() {
                text.push(' ');
            }
            let letter = self.letters[a];
            text.push(letter);
            let v = write_number(
                &mut text,
                values[a],
                &style(self.dialect, letter),
                self.decimals,
            )
            .ok_or_else(|| {
                format!(
                    "axis {letter}: {} cannot be written as an axis word with {} decimals",
                    values[a], self.decimals
                )
            })?;
            read.push((a, v));
        }
        Ok((text, read))
    }

    /// A number written as the axis words are (`217.5040`, Heidenhain `+217.5040`).
    pub(crate) fn number(&self, x: f64, plus: bool) -> String {
        let mut s = String::new();
        let st = NumberStyle {
            plus,
            ..style(Dialect::Iso, 'X')
        };
        write_number(&mut s, x, &st, self.decimals);
        s
    }

    /// A feed `f` (mm/min) as its `F` word's number: three decimals (`1000.000`).
    pub(crate) fn feed_number(f: f64) -> String {
        format!("{f:.3}")
    }

    /// A block that moves the axes of `words` (as [`Writer::words`] gave them).
    fn motion(&mut self, body: &str, step: Step, words: &[(usize, f64)], machine: bool) -> usize {
        for &(a, v) in words {
            self.pose[a] = v;
        }
        let line = self.raw(body, true);
        self.expected.push(Expected {
            line,
            step,
            pose: Some((self.pose.clone(), machine)),
            statement: None,
        });
        line
    }

    /// The start of the program named by `number`, its first comment `title`.
    pub(crate) fn start(&mut self, number: u32, title: &str) {
        match self.dialect {
            Dialect::Iso => {
                self.raw("%", false);
                let t = clean_comment(self.dialect, title);
                self.block(&format!("O{number:04} ({t})"), Step::Setup, None);
            }
            Dialect::LinuxCnc => {
                self.raw("%", false);
                self.comment(title);
            }
            Dialect::Heidenhain => {
                self.block(&format!("BEGIN PGM RTEST{number} MM"), Step::Setup, None);
                self.comment(title);
            }
        }
    }

    /// The modes and machine coordinates, the spindle stopped. ISO: `G10 L2 P1` zeroes `G54`
    /// on every axis (`zero_words`); LinuxCNC the same with `R0` (no rotation), then `G92.1`
    /// (no `G92` offset); Heidenhain: tool centre point control and shortest-path traverse off.
    pub(crate) fn setup(&mut self, zero_words: &str) {
        match self.dialect {
            Dialect::Iso => {
                self.block("G90 G21 G94 G17 G40 G49 G80 G69 G15 G61", Step::Setup, None);
                self.block(&format!("G10 L2 P1 {zero_words}"), Step::Setup, None);
                self.block("G54", Step::Setup, None);
                self.block("M5", Step::Spindle, None);
            }
            Dialect::LinuxCnc => {
                self.block("G90 G21 G94 G17 G40 G49 G80 G61", Step::Setup, None);
                self.block(&format!("G10 L2 P1 {zero_words} R0"), Step::Setup, None);
                self.block("G54", Step::Setup, None);
                self.block("G92.1", Step::Setup, None);
                self.block("M5", Step::Spindle, None);
            }
            Dialect::Heidenhain => {
                self.block("FUNCTION RESET TCPM", Step::Setup, None);
                self.block("L M127", Step::Setup, None);
                self.block("L M5", Step::Spindle, None);
            }
        }
    }

    /// The probe's log opened: LinuxCNC `(PROBEOPEN <name>.txt)`, ISO `POPEN`; nothing in a
    /// Heidenhain program (each `FN 16` appends to its file).
    pub(crate) fn log_open(&mut self, name: &str) {
        match self.dialect {
            Dialect::Iso => {
                self.block("POPEN", Step::LogOpen, Some("POPEN".into()));
            }
            Dialect::LinuxCnc => {
                let file = format!("{name}.txt");
                self.block(&format!("(PROBEOPEN {file})"), Step::LogOpen, Some(file));
            }
            Dialect::Heidenhain => {}
        }
    }

    /// The probe's log closed: LinuxCNC `(PROBECLOSE)`, ISO `PCLOS`.
    pub(crate) fn log_close(&mut self) {
        match self.dialect {
            Dialect::Iso => {
                self.block("PCLOS", Step::LogClose, Some("PCLOS".into()));
            }
            Dialect::LinuxCnc => {
                self.block("(PROBECLOSE)", Step::LogClose, Some("PROBECLOSE".into()));
            }
            Dialect::Heidenhain => {}
        }
    }

    /// A rapid in machine coordinates: `G53 G0 …`, Heidenhain `L … R0 FMAX M91`.
    pub(crate) fn rapid(&mut self, text: &str, words: &[(usize, f64)], step: Step) {
        let body = match self.dialect {
            Dialect::Iso | Dialect::LinuxCnc => format!("G53 G0 {text}"),
            Dialect::Heidenhain => format!("L {text} R0 FMAX M91"),
        };
        self.motion(&body, step, words, true);
    }

    /// A feed move at `f` (its text, mm/min) in machine coordinates: ISO `G1 … F` in the
    /// zeroed `G54`, LinuxCNC `G53 G1 … F`, Heidenhain `L … R0 F… M91`.
    pub(crate) fn feed(&mut self, text: &str, words: &[(usize, f64)], f: &str, step: Step) {
        let body = match self.dialect {
            Dialect::Iso => format!("G1 {text} F{f}"),
            Dialect::LinuxCnc => format!("G53 G1 {text} F{f}"),
            Dialect::Heidenhain => format!("L {text} R0 F{f} M91"),
        };
        self.motion(&body, step, words, true);
    }

    /// Spindle orientation: ISO `M19`, LinuxCNC `M19 R0`, Heidenhain `L M19`.
    pub(crate) fn orient(&mut self) {
        let body = match self.dialect {
            Dialect::Iso => "M19",
            Dialect::LinuxCnc => "M19 R0",
            Dialect::Heidenhain => "L M19",
        };
        self.block(body, Step::Orient, None);
    }

    /// A program stop with `message` for the operator.
    pub(crate) fn stop(&mut self, message: &str) {
        let text = clean_comment(self.dialect, message);
        match self.dialect {
            Dialect::Iso => {
                self.block(&format!("M0 ({text})"), Step::Stop, None);
            }
            Dialect::LinuxCnc => {
                self.raw(&format!("(MSG,{text})"), false);
                self.block("M0", Step::Stop, None);
            }
            Dialect::Heidenhain => {
                self.block(&format!("STOP ; {text}"), Step::Stop, None);
            }
        }
    }

    /// A G-code probing move to `text` at `f` (mm/min): LinuxCNC `G38.2 … F` and ISO `G31 … F`,
    /// both in the zeroed `G54`. Its line.
    pub(crate) fn probe(&mut self, text: &str, words: &[(usize, f64)], f: &str) -> usize {
        let code = if self.dialect == Dialect::Iso {
            "G31"
        } else {
            "G38.2"
        };
        self.motion(&format!("{code} {text} F{f}"), Step::Probe, words, true)
    }

    /// ISO: the skip position read into `#31`, `#32`, `#33` (`#5061`–`#5063`), the alarm
    /// `#3000=101` when it is within `threshold` (its text, mm, summed over the axes) of the
    /// move's end `end` (the three axes' texts), and `DPRNT` of the three with `letters`.
    pub(crate) fn iso_latch(&mut self, letters: [char; 3], end: [String; 3], threshold: &str) {
        let mut terms = Vec::new();
        for (k, e) in end.iter().enumerate() {
            let var = 31 + k;
            let statement = format!("#{var}=#{}", 5061 + k);
            self.block(&statement, Step::Latch, Some(statement.clone()));
            terms.push(match e.strip_prefix('-') {
                Some(abs) => format!("ABS[#{var}+{abs}]"),
                None => format!("ABS[#{var}-{e}]"),
            });
        }
        let check = format!("IF[[{}]LT{threshold}]THEN#3000=101", terms.join("+"));
        self.block(
            &format!("{check}(PROBE DID NOT TRIGGER)"),
            Step::Check,
            Some(check.clone()),
        );
        let digits = format!("[{}{}]", 8 - self.decimals, self.decimals);
        let print = format!(
            "DPRNT[{}#31{digits}*{}#32{digits}*{}#33{digits}]",
            letters[0], letters[1], letters[2]
        );
        self.block(&print, Step::Log, Some(print.clone()));
    }

    /// Heidenhain: touch probe cycle 0 from `text` (the pre-touch point, all three linear
    /// axes) along `axis` (its letter) towards + or −, its result in `Q1`; then `FN 16` of
    /// `format` to `output`. The line of the `0.1` block.
    pub(crate) fn cycle0(
        &mut self,
        text: &str,
        words: &[(usize, f64)],
        axis: char,
        positive: bool,
        format: &str,
        output: &str,
    ) -> usize {
        let sign = if positive { '+' } else { '-' };
        self.block(
            &format!("TCH PROBE 0.0 REFERENCE PLANE Q1 {axis}{sign}"),
            Step::Probe,
            None,
        );
        let line = self.motion(&format!("TCH PROBE 0.1 {text}"), Step::Probe, words, false);
        let statement = format!("FN 16: F-PRINT {format} / {output}");
        self.block(&statement, Step::Log, Some(statement.clone()));
        line
    }

    /// The end of the program: ISO `M30`, `%`; LinuxCNC `M2`, `%`; Heidenhain `END PGM`.
    pub(crate) fn finish(mut self, number: u32) -> (String, Vec<Expected>) {
        match self.dialect {
            Dialect::Iso => {
                self.block("M30", Step::End, None);
                self.raw("%", false);
            }
            Dialect::LinuxCnc => {
                self.block("M2", Step::End, None);
                self.raw("%", false);
            }
            Dialect::Heidenhain => {
                self.block(&format!("END PGM RTEST{number} MM"), Step::End, None);
            }
        }
        (self.out, self.expected)
    }
}
