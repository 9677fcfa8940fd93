//! The data rows of a whole-file read parsed on every core: the line reader hands out lines
//! (cheap), copied into a batch of at most [`BATCH_ROWS`] rows; the batch is cut into one
//! contiguous part per core and the parts are parsed at once. A row's values depend on its text
//! alone, except the check that times do not decrease, which looks at the previous row: each
//! part after the first starts without a previous time, and its first row is parsed again with
//! the last time of the part before it once that part is known to be good. So the samples, and
//! the error of a bad file (the first bad row in file order, as a row-by-row read finds it),
//! are those of one row after another.

use crate::csv::read::{Header, Row, is_data};
use crate::csv::{CsvError, Ctx};
use model_spec::{Machine, parallel};
use std::io::Read;
use std::thread;

use super::lines::Lines;

/// Rows held at once before they are parsed: 65 536 rows of a measurement CSV are about 9 MB of
/// text.
const BATCH_ROWS: usize = 1 << 16;

/// Rows per part at least: a batch of fewer rows is parsed on the calling thread alone.
const PART_ROWS: usize = 4096;

/// The rows of a file as parsed: values, line numbers, and whether every row had a time.
#[derive(Default)]
pub(crate) struct Parsed {
    /// Per data row: commands (mm, rad), time (s), readings (mm).
    pub(crate) rows: Vec<Row>,
    /// Per data row: its line number.
    pub(crate) lines: Vec<usize>,
}

/// A part's rows parsed, and the last time read in it (s, at its line).
type PartRows = (Vec<Row>, Option<(f64, usize)>);

/// Data rows' text: one string, and each row's line number and byte range in it.
#[derive(Default)]
struct Batch {
    text: String,
    rows: Vec<(usize, usize, usize)>,
}

impl Batch {
    fn push(&mut self, line: usize, text: &str) {
        let start = self.text.len();
        self.text.push_str(text);
        self.rows.push((line, start, self.text.len()));
    }

    fn clear(&mut self) {
        self.text.clear();
        self.rows.clear();
    }
}

/// The data rows of `lines` (after the header), parsed by `header` on up to
/// [`thread::available_parallelism`] threads.
///
/// # Errors
/// The first bad row or line in file order: a line the reader refuses, a field that is not a
/// number, a time before the previous row's.
pub(crate) fn parse_rows<R: Read>(
    cx: &Ctx,
    lines: &mut Lines<R>,
    header: &Header,
    m: &Machine,
) -> Result<Parsed, CsvError> {
    let threads = thread::available_parallelism().map_or(1, |t| t.get());
    let mut out = Parsed::default();
    let mut last_t = None;
    let mut batch = Batch::default();
    loop {
        batch.clear();
        // A line the reader refuses ends the file here; the rows before it come first.
        let mut refused = None;
        while batch.rows.len() < BATCH_ROWS {
            match lines.next_line(cx) {
                Ok(Some((line, text))) if is_data(text) => batch.push(line, text),
                Ok(Some(_)) => {}
                Ok(None) => break,
                Err(e) => {
                    refused = Some(e);
                    break;
                }
            }
        }
        let full = batch.rows.len() == BATCH_ROWS;
        parse_batch(cx, header, m, &batch, threads, &mut last_t, &mut out)?;
        if let Some(e) = refused {
            return Err(e);
        }
        if !full {
            return Ok(out);
        }
    }
}

/// Parses `batch` after the rows of `out` (the last time read `last_t`), in parts on up to
/// `threads` threads, and appends its rows to `out`.
fn parse_batch(
    cx: &Ctx,
    header: &Header,
    m: &Machine,
    batch: &Batch,
    threads: usize,
    last_t: &mut Option<(f64, usize)>,
    out: &mut Parsed,
) -> Result<(), CsvError> {
    let n = batch.rows.len();
    let parts = threads.min(n / PART_ROWS).max(1);
    let bounds: Vec<usize> = (0..=parts).map(|p| p * n / parts).collect();
    let part = |p: usize, mut t: Option<(f64, usize)>| {
        let rows = &batch.rows[bounds[p]..bounds[p + 1]];
        let parsed: Result<Vec<Row>, CsvError> = rows
            .iter()
            .map(|&(line, a, b)| header.row(cx, line, &batch.text[a..b], m, &mut t))
            .collect();
        parsed.map(|rows| (rows, t))
    };
    let first_t = *last_t;
    let results: Vec<Result<PartRows, CsvError>> = parallel::map_parts((0..parts).collect(), |p| {
        part(p, if p == 0 { first_t } else { None })
    });
    for (p, result) in results.into_iter().enumerate() {
        if p > 0 {
            // The part's first row against the last time of the rows before it.
            let (line, a, b) = batch.rows[bounds[p]];
            let mut t = *last_t;
            header.row(cx, line, &batch.text[a..b], m, &mut t)?;
        }
        let (rows, t) = result?;
        out.rows.extend(rows);
        out.lines
            .extend(batch.rows[bounds[p]..bounds[p + 1]].iter().map(|r| r.0));
        *last_t = t;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csv::read::read_header;
    use crate::csv::{Need, ReadOptions};

    /// `n` rows of `X,Y,Z,A,C,t_s` (one per second), a comment every 1000 lines, with `edit`
    /// applied to each row's text (row index, text).
    fn text(n: usize, edit: impl Fn(usize, String) -> String) -> String {
        let mut s = String::from("# a test\nX,Y,Z,A,C,t_s\n");
        for i in 0..n {
            if i % 1000 == 999 {
                s.push_str("# a comment line\n");
            }
            let row = format!("{},{},{},{},{},{}", i % 7, -1.5, 2.25, i % 90, i % 360, i);
            s.push_str(&edit(i, row));
            s.push('\n');
        }
        s
    }

    /// The rows of `text` parsed with every batch cut into parts for `threads` threads.
    fn parse(text: &str, threads: usize) -> Result<(Vec<Row>, Vec<usize>), String> {
        let m = model_spec::builtin("seed-ac").unwrap().unwrap();
        let cx = Ctx { file: "t.csv" };
        let opts = ReadOptions::default();
        let mut lines = Lines::new(text.as_bytes(), &opts);
        let header = read_header(&cx, &mut lines, &m, Need::Path).map_err(|e| e.to_string())?;
        let mut out = Parsed::default();
        let mut last_t = None;
        let mut batch = Batch::default();
        while let Some((line, t)) = lines.next_line(&cx).map_err(|e| e.to_string())? {
            if is_data(t) {
                batch.push(line, t);
            }
        }
        parse_batch(&cx, &header, &m, &batch, threads, &mut last_t, &mut out)
            .map_err(|e| e.to_string())?;
        Ok((out.rows, out.lines))
    }

    /// 40 000 rows parsed in 1, 2, 3 and 9 parts give the same rows and line numbers; a file
    /// with a time that goes back at the first row of a part, a bad number just before a part,
    /// or both (the earlier wins), gives the error a row-by-row read gives.
    #[test]
    fn rows_parsed_in_parts_are_the_rows_parsed_one_after_another() {
        let n = 40_000;
        let good = text(n, |_, r| r);
        let one = parse(&good, 1).unwrap();
        assert_eq!(one.0.len(), n);
        for threads in [2, 3, 9] {
            assert!(parse(&good, threads).unwrap() == one, "{threads} threads");
        }
        // Part boundaries for 3 and 9 parts (every part starts at row p·n/parts).
        let starts: Vec<usize> = [3usize, 9]
            .iter()
            .flat_map(|&k| (1..k).map(move |p| p * n / k))
            .collect();
        for &b in &starts {
            let back = text(n, |i, r| {
                if i == b {
                    r.replace(&format!(",{i}"), ",0.5")
                } else {
                    r
                }
            });
            let bad = text(n, |i, r| {
                if i == b - 1 {
                    r.replace("-1.5", "x")
                } else {
                    r
                }
            });
            let both = text(n, |i, r| match i {
                i if i == b => r.replace(&format!(",{i}"), ",0.5"),
                i if i == b + 5 => r.replace("-1.5", "x"),
                _ => r,
            });
            for file in [&back, &bad, &both] {
                let want = parse(file, 1).unwrap_err();
                for threads in [2, 3, 9] {
                    assert_eq!(
                        parse(file, threads).unwrap_err(),
                        want,
                        "row {b}, {threads} threads"
                    );
                }
            }
        }
    }
}
