//! Helpers of the CSV reader tests: valid files to start from, field edits, a reader that
//! counts what it hands out.
#![allow(dead_code)]

use formats::csv::format_record;
use formats::truth::seed_ac_demo_truth;
use model_spec::Machine;
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use std::cell::Cell;
use std::io::Read;
use std::rc::Rc;

/// The simulated K4 record of seed-ac (demo truth: readings of tens of µm).
pub fn k4_record(m: &Machine) -> Record {
    simulate(
        m,
        &seed_ac_demo_truth(),
        &builtin_path(m, "K4").unwrap().unwrap(),
    )
    .unwrap()
}

/// The CSV of the simulated K4 record of seed-ac, without comments: the header
/// `X,Y,Z,A,C,dx_um,dy_um,dz_um,t_s` on line 1, sample `i` on line `i + 2`.
pub fn k4_text(m: &Machine) -> String {
    format_record(m, &k4_record(m), &[]).unwrap()
}

/// `text` with the field of column `name` (as in the header on line 1) on line `line` (1-based)
/// replaced by `value`.
pub fn set_field(text: &str, line: usize, name: &str, value: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let col = lines[0].split(',').position(|c| c == name).unwrap();
    let mut fields: Vec<&str> = lines[line - 1].split(',').collect();
    fields[col] = value;
    lines[line - 1] = fields.join(",");
    lines.join("\n") + "\n"
}

/// `text` without the columns named in `drop` (header on line 1).
pub fn drop_columns(text: &str, drop: &[&str]) -> String {
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| !drop.contains(&header[i]))
        .collect();
    text.lines()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            keep.iter().map(|&i| f[i]).collect::<Vec<_>>().join(",") + "\n"
        })
        .collect()
}

/// A reader that counts the bytes it hands out.
pub struct Counting<R> {
    pub inner: R,
    pub count: Rc<Cell<usize>>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.set(self.count.get() + n);
        Ok(n)
    }
}

/// `inner`, counted: the reader and its counter.
pub fn counting<R: Read>(inner: R) -> (Counting<R>, Rc<Cell<usize>>) {
    let count = Rc::new(Cell::new(0));
    (
        Counting {
            inner,
            count: count.clone(),
        },
        count,
    )
}

/// Whether an error message is located: `file:line:` at its start, or `file: ` followed by the
/// offending samples listed by `line N`.
pub fn located(message: &str, file: &str) -> bool {
    let Some(rest) = message.strip_prefix(file) else {
        return false;
    };
    if let Some(rest) = rest.strip_prefix(':')
        && let Some((n, _)) = rest.split_once(':')
        && n.parse::<usize>().is_ok_and(|n| n >= 1)
    {
        return true;
    }
    rest.starts_with(": ")
        && rest.split("line ").skip(1).any(|s| {
            s.split(|c: char| !c.is_ascii_digit())
                .next()
                .is_some_and(|n| n.parse::<usize>().is_ok_and(|n| n >= 1))
        })
}
