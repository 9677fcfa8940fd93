//! A record as the text of a measurement or path CSV. Every number is the shortest decimal that
//! reads back to the same value ([`model_spec::units::exact`]).

use crate::csv::{CsvError, MEASURED, column_order};
use model_spec::units::{degrees_for, format_scaled};
use model_spec::{AxisKind, Machine};
use simulation::record::Record;

/// The CSV text of `record` of machine `m`: `comments` as `# ` lines, then the header
/// (axes as in [`column_order`], `dx_um,dy_um,dz_um` when the record is measured, `t_s`), then
/// one row per sample. Linear axes in mm, rotary in degrees, measured in µm, time in s, each the
/// shortest decimal that reads back to the same bits.
///
/// # Errors
/// [`CsvError::Record`] when a sample has the wrong number of commands, `measured` is neither
/// empty nor one per sample, or a value is not finite.
pub fn format_record(
    m: &Machine,
    record: &Record,
    comments: &[String],
) -> Result<String, CsvError> {
    let n = record.samples.len();
    let measured = !record.measured.is_empty();
    if measured && record.measured.len() != n {
        return Err(CsvError::Record(format!(
            "it has {n} samples but {} measured vectors",
            record.measured.len()
        )));
    }
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header: Vec<&str> = axes.iter().map(|&a| m.axes[a].name.as_str()).collect();
    if measured {
        header.extend(MEASURED);
    }
    header.push("t_s");
    out += &header.join(",");
    out.push('\n');
    for (i, s) in record.samples.iter().enumerate() {
        if s.commands.len() != m.axes.len() {
            return Err(CsvError::Record(format!(
                "sample {i} has {} commands, machine {} has {} axes",
                s.commands.len(),
                m.name,
                m.axes.len()
            )));
        }
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for &a in &axes {
            let x = s.commands[a];
            fields.push(match m.axes[a].kind {
                AxisKind::Linear => format_scaled(x, 0),
                AxisKind::Rotary => format_scaled(degrees_for(x), 0),
            });
        }
        if measured {
            fields.extend(record.measured[i].iter().map(|&v| format_scaled(v, 3)));
        }
        fields.push(format_scaled(s.t, 0));
        let bad = |v: &f64| !v.is_finite();
        if s.commands.iter().any(bad)
            || !s.t.is_finite()
            || (measured && record.measured[i].iter().any(bad))
        {
            return Err(CsvError::Record(format!(
                "sample {i} has a non-finite value"
            )));
        }
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

/// `comments` as `# ` lines (a comment of several lines gives several), each ending in `\n`:
/// the head of every CSV and TOML file rtest writes for people to read back.
pub fn comment_lines(comments: &[String]) -> String {
    let mut out = String::new();
    for c in comments {
        for l in c.lines() {
            out += "# ";
            out += l;
            out.push('\n');
        }
    }
    out
}
