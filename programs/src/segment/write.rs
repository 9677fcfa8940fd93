//! A log cut into samples, written: the measurement record and the windows' report.

use crate::measure::TimingPlan;
use crate::segment::Segmented;
use formats::csv::{CsvError, column_order, comment_lines};
use model_spec::units::{degrees_for, format_scaled};
use model_spec::{AxisKind, Machine};

/// The measurement record of `seg` (cut by `plan`, of machine `m`) as CSV text: `comments` as
/// `# ` lines, the header (the axes as [`column_order`] orders them, the reading columns under
/// the log's names, `t_s`), one row per pose: axes in mm and degrees, readings in µm, `t_s` in
/// s, each the shortest decimal that reads back to the same value.
///
/// # Errors
/// [`CsvError::Record`] when `seg` does not have one window per row of `plan`, or a value is
/// not finite.
pub fn format_segmented(
    m: &Machine,
    plan: &TimingPlan,
    seg: &Segmented,
    comments: &[String],
) -> Result<String, CsvError> {
    if seg.windows.len() != plan.rows.len() {
        return Err(CsvError::Record(format!(
            "{} samples for the {} poses of the plan",
            seg.windows.len(),
            plan.rows.len()
        )));
    }
    let axes = column_order(m);
    let mut out = comment_lines(comments);
    let mut header: Vec<&str> = axes.iter().map(|&a| m.axes[a].name.as_str()).collect();
    header.extend(seg.columns.iter().map(String::as_str));
    header.push("t_s");
    out += &header.join(",");
    out.push('\n');
    for (row, w) in plan.rows.iter().zip(&seg.windows) {
        let mut fields: Vec<String> = Vec::with_capacity(header.len());
        for &a in &axes {
            let q = *row.commands.get(a).unwrap_or(&f64::NAN);
            fields.push(match m.axes[a].kind {
                AxisKind::Linear => format_scaled(q, 0),
                AxisKind::Rotary => format_scaled(degrees_for(q), 0),
            });
        }
        fields.extend(w.mean_mm.iter().map(|&v| format_scaled(v, 3)));
        fields.push(format_scaled(w.t_s, 0));
        if row
            .commands
            .iter()
            .chain(&w.mean_mm)
            .any(|v| !v.is_finite())
            || !w.t_s.is_finite()
        {
            return Err(CsvError::Record(format!(
                "sample {} has a value that is not finite",
                w.sample
            )));
        }
        out += &fields.join(",");
        out.push('\n');
    }
    Ok(out)
}

/// The windows of `seg` as a CSV for people and tools: `sample`, `log_start_s`, `log_end_s`
/// (the log's clock), `readings`, `t_s` (program clock), `shift_s` (the timing drift),
/// `anchor`, the standard deviation of each reading column within the window (`<column>_sd`,
/// µm), and `flags` (`spread`, `motion`, separated by spaces).
pub fn format_windows(seg: &Segmented) -> String {
    let mut header = vec![
        "sample".to_string(),
        "log_start_s".into(),
        "log_end_s".into(),
        "readings".into(),
        "t_s".into(),
        "shift_s".into(),
        "anchor".into(),
    ];
    header.extend(seg.columns.iter().map(|c| format!("{c}_sd")));
    header.push("flags".into());
    let mut out = header.join(",");
    out.push('\n');
    for w in &seg.windows {
        let mut f = vec![
            w.sample.to_string(),
            format_scaled(w.log_start_s, 0),
            format_scaled(w.log_end_s, 0),
            w.readings.to_string(),
            format_scaled(w.t_s, 0),
            format_scaled(w.shift_s, 0),
            w.anchor.name().to_string(),
        ];
        f.extend(w.sd_mm.iter().map(|&s| format_scaled(s, 3)));
        f.push(
            w.flags
                .iter()
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(" "),
        );
        out += &f.join(",");
        out.push('\n');
    }
    out
}
