//! The block reader: a long measurement file read in blocks of samples, never held whole.

use crate::csv::checks::SampleChecks;
use crate::csv::lines::Lines;
use crate::csv::read::{Header, RowIk, header_only, is_data, read_header};
use crate::csv::{CsvError, Ctx, Need, ReadOptions};
use model_spec::Machine;
use simulation::record::{Record, samples_from};
use std::io::Read;
use std::path::Path;

/// Most samples the first block of a [`MeasurementBlocks`] holds while waiting for every axis to
/// move.
pub const FIRST_LOOKAHEAD: usize = 65_536;

/// A long measurement file read in blocks of samples, without holding the record: each block
/// is a [`Record`] with its measurements (commands mm and rad, readings mm, times s). The
/// direction of motion of every axis carries over from one block to the next, and times (the
/// `t_s` column, or the sample index in s) keep counting, so the blocks are exactly the slices
/// of [`crate::csv::parse_csv`]'s record. (The direction of an axis before its first move is
/// that of its first move; the first block grows until every axis, linear axes filled by the
/// inverse kinematics included, has moved, up to [`FIRST_LOOKAHEAD`] samples. An axis whose
/// first move comes later starts at +1 here, as if it had not moved.)
///
/// Lines go through the same bounded line reader as the whole-file reader, and each block is
/// checked as the whole file is (nest on the ball, strokes, plausible readings): a block that
/// fails a check is an error that lists the offending samples of that block (the reader cannot
/// look ahead). After an error the iterator ends.
pub struct MeasurementBlocks<'m, R: Read> {
    m: &'m Machine,
    file: String,
    lines: Lines<R>,
    header: Header,
    /// Fills the linear axes row by row when the file has none.
    ik: Option<RowIk<'m>>,
    checks: SampleChecks<'m>,
    block: usize,
    samples: usize,
    last_t: Option<(f64, usize)>,
    /// The previous sample's commands and directions of motion.
    previous: Option<(Vec<f64>, Vec<i8>)>,
    failed: bool,
}

impl<'m> MeasurementBlocks<'m, std::fs::File> {
    /// Opens `path` (a measurement CSV of machine `m`) and reads its header; blocks hold
    /// `block` samples (the last one fewer).
    ///
    /// # Errors
    /// [`CsvError::Io`] when the file cannot be opened; see [`MeasurementBlocks::new`].
    pub fn open(
        path: &Path,
        m: &'m Machine,
        block: usize,
        opts: &ReadOptions,
    ) -> Result<Self, CsvError> {
        let (file, f) = crate::csv::open(path)?;
        MeasurementBlocks::new(file, f, m, block, opts)
    }
}

impl<'m, R: Read> MeasurementBlocks<'m, R> {
    /// Reads the header from `reader` (named `file` in messages); blocks hold `block` samples
    /// (the last one fewer).
    ///
    /// # Errors
    /// [`CsvError::Format`] for an empty file or a malformed header (or a line before it that
    /// is too long or not UTF-8); [`CsvError::Io`] when `reader` fails.
    pub fn new(
        file: String,
        reader: R,
        m: &'m Machine,
        block: usize,
        opts: &ReadOptions,
    ) -> Result<Self, CsvError> {
        let mut lines = Lines::new(reader, opts);
        let header = read_header(&Ctx { file: &file }, &mut lines, m, Need::Measured)?;
        Ok(MeasurementBlocks {
            m,
            file,
            lines,
            ik: header.row_ik(m),
            checks: header.checks(m, opts),
            header,
            block: block.max(1),
            samples: 0,
            last_t: None,
            previous: None,
            failed: false,
        })
    }

    fn next_block(&mut self) -> Result<Option<Record>, CsvError> {
        let cx = Ctx { file: &self.file };
        let mut commands: Vec<Vec<f64>> = Vec::new();
        let (mut times, mut measured, mut row_lines) = (Vec::new(), Vec::new(), Vec::new());
        // The first block looks ahead until every axis has moved (its direction before the first
        // move is that of the first move, as in the whole-file reader), up to FIRST_LOOKAHEAD.
        // The linear axes are filled as the rows come, so their moves count too.
        let first = self.previous.is_none();
        let n_axes = self.m.axes.len();
        let mut moved = vec![false; n_axes];
        let mut n_moved = 0;
        let mut timed = true;
        while commands.len() < self.block
            || (first && commands.len() < FIRST_LOOKAHEAD && n_moved < n_axes)
        {
            let Some((line, text)) = self.lines.next_line(&cx)? else {
                break;
            };
            if !is_data(text) {
                continue;
            }
            let (mut c, time, d) = self.header.row(&cx, line, text, self.m, &mut self.last_t)?;
            if let Some(ik) = &self.ik {
                ik.fill(&cx, line, &mut c)?;
            }
            if first && let Some(c0) = commands.first() {
                for a in 0..n_axes {
                    if !moved[a] && c[a] != c0[a] {
                        moved[a] = true;
                        n_moved += 1;
                    }
                }
            }
            timed &= time.is_some();
            times.push(time.unwrap_or((self.samples + commands.len()) as f64));
            commands.push(c);
            measured.push(d);
            row_lines.push(line);
        }
        if commands.is_empty() {
            if self.samples == 0 {
                return Err(header_only(&cx, &self.header));
            }
            return Ok(None);
        }
        self.checks
            .check(&self.file, &commands, Some(&measured), &row_lines)?;
        let lines = row_lines;
        self.samples += commands.len();
        // Directions of motion, continuing from the previous block.
        let motion = match self.previous.take() {
            None => simulation::record::motion_directions(&commands),
            Some((mut last, mut dir)) => commands
                .iter()
                .map(|c| {
                    for a in 0..c.len() {
                        if c[a] > last[a] {
                            dir[a] = 1;
                        } else if c[a] < last[a] {
                            dir[a] = -1;
                        }
                    }
                    last.clone_from(c);
                    dir.clone()
                })
                .collect(),
        };
        self.previous = Some((
            commands.last().cloned().unwrap_or_default(),
            motion.last().cloned().unwrap_or_default(),
        ));
        let mut samples = samples_from(commands, times, motion);
        for s in &mut samples {
            s.timed = timed;
        }
        Ok(Some(Record {
            samples,
            measured,
            lines,
            ..Default::default()
        }))
    }
}

impl<R: Read> Iterator for MeasurementBlocks<'_, R> {
    type Item = Result<Record, CsvError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        match self.next_block() {
            Ok(b) => b.map(Ok),
            Err(e) => {
                self.failed = true;
                Some(Err(e))
            }
        }
    }
}

/// The first and last time of a measurement file (s), for normalising `time:K` terms over the
/// whole record when it is read in blocks (a pass over the file that keeps nothing else; the
/// samples are read and checked as [`MeasurementBlocks`] reads them).
///
/// # Errors
/// As [`MeasurementBlocks`].
pub fn time_span(path: &Path, m: &Machine, opts: &ReadOptions) -> Result<(f64, f64), CsvError> {
    let mut span: Option<(f64, f64)> = None;
    for block in MeasurementBlocks::open(path, m, 65_536, opts)? {
        let b = block?;
        if let (Some(first), Some(last)) = (b.samples.first(), b.samples.last()) {
            span = Some(span.map_or((first.t, last.t), |(a, _)| (a, last.t)));
        }
    }
    Ok(span.unwrap_or((0.0, 0.0)))
}
