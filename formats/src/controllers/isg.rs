//! ISG-kernel's volumetric compensation file, format `ISG_CSV` (Beckhoff TwinCAT CNC TF5280,
//! "Volumetric Compensation", the page on the file format): each block is a header line of
//! column names (arguments, then parameters) and its records below it; columns separated by
//! white space; `//` starts a comment line; a line `#` ends a block, after which a new header
//! starts the next. Numbers are the shortest decimals that read back to the same `f64`, in the
//! units the model takes (mm and rad for values, mm and degrees for arguments), right-aligned
//! in their columns for people.

use model_spec::units::format_scaled;

/// One block of the file: a header of column names and its rows.
#[derive(Clone, Debug, PartialEq)]
pub struct IsgBlock {
    /// The column names: arguments (axis letters) first, then parameters (`X0C`, `EXX`).
    pub columns: Vec<String>,
    /// The rows: arguments in mm or degrees, parameters in mm or rad.
    pub rows: Vec<Vec<f64>>,
}

/// Why a file cannot be written.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IsgFileError {
    /// A row whose length is not the header's, or a value that is not finite.
    #[error("block {block} ({columns}): row {row}: {why}")]
    BadRow {
        /// The 1-based block.
        block: usize,
        /// Its columns, for people.
        columns: String,
        /// The 1-based row.
        row: usize,
        /// Why.
        why: String,
    },
}

/// The file: `// ` comment lines, then the blocks separated by `#` lines.
///
/// # Errors
/// [`IsgFileError::BadRow`] for a row of another length than its header, or a value that is
/// not finite.
pub fn isg_csv(comments: &[String], blocks: &[IsgBlock]) -> Result<String, IsgFileError> {
    let mut out = String::new();
    for c in comments {
        for line in c.lines() {
            out += "// ";
            out += line;
            out.push('\n');
        }
    }
    for (b, IsgBlock { columns, rows }) in blocks.iter().enumerate() {
        if b > 0 {
            out += "#\n";
        }
        let mut cells: Vec<Vec<String>> = vec![columns.clone()];
        for (r, row) in rows.iter().enumerate() {
            let bad = |why: String| IsgFileError::BadRow {
                block: b + 1,
                columns: columns.join(" "),
                row: r + 1,
                why,
            };
            if row.len() != columns.len() {
                return Err(bad(format!(
                    "{} values for {} columns",
                    row.len(),
                    columns.len()
                )));
            }
            if let Some(v) = row.iter().find(|v| !v.is_finite()) {
                return Err(bad(format!("the value {v} is not finite")));
            }
            cells.push(row.iter().map(|v| format_scaled(v + 0.0, 0)).collect());
        }
        let widths: Vec<usize> = (0..columns.len())
            .map(|k| cells.iter().map(|r| r[k].len()).max().unwrap_or(0))
            .collect();
        for r in &cells {
            let line: Vec<String> = r
                .iter()
                .zip(&widths)
                .map(|(c, w)| format!("{c:>w$}"))
                .collect();
            out += &line.join("  ");
            out.push('\n');
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block(columns: &[&str], rows: Vec<Vec<f64>>) -> IsgBlock {
        IsgBlock {
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows,
        }
    }

    #[test]
    fn blocks_are_headers_and_rows_separated_by_a_hash_line() {
        let text = isg_csv(
            &["machine m".into()],
            &[
                block(&["X0C", "A0C"], vec![vec![0.01, -2e-5]]),
                block(&["C", "ECC"], vec![vec![0.0, 1e-6], vec![180.0, -0.5e-6]]),
            ],
        )
        .unwrap();
        assert_eq!(
            text,
            "// machine m\n X0C       A0C\n0.01  -0.00002\n#\n  C         ECC\n  0    0.000001\n180  -0.0000005\n"
        );
    }

    #[test]
    fn a_row_of_the_wrong_length_or_a_value_not_finite_is_refused() {
        let e = isg_csv(&[], &[block(&["X", "EXX"], vec![vec![0.0]])]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "block 1 (X EXX): row 1: 1 values for 2 columns"
        );
        let e = isg_csv(&[], &[block(&["X"], vec![vec![f64::INFINITY]])]).unwrap_err();
        assert!(e.to_string().contains("not finite"));
    }
}
