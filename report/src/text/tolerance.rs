//! The verdicts of a validation against a tolerance file, for people: per test and direction,
//! each quantity's tolerance, its value before and after with the expanded uncertainty U, and
//! the ISO 14253-1 verdicts; then the counts and the rule.

use super::{header, table};
use crate::json::tolerance::{QuantityReport, ToleranceReport};
use model_spec::units::{fixed, significant};

/// The verdicts' text: the table, the counts before and after, the noise and the rule.
pub fn verdicts(t: &ToleranceReport) -> String {
    let head = header(&[
        "test",
        "dir",
        "quantity",
        "tolerance µm",
        "before µm",
        "U µm",
        "before",
        "after µm",
        "U µm",
        "after",
    ]);
    let mut rows: Vec<Vec<String>> = Vec::new();
    for x in &t.tests {
        let quantities: Vec<(&str, Option<&QuantityReport>, Option<&QuantityReport>)> = [
            ("max |dev|", x.before.max.as_ref(), x.after.max.as_ref()),
            ("range", x.before.range.as_ref(), x.after.range.as_ref()),
        ]
        .into_iter()
        .filter(|(_, b, _)| b.is_some())
        .collect();
        let several = quantities.len() > 1;
        for (k, (what, b, a)) in quantities.iter().enumerate() {
            let first = k == 0;
            let mut row = vec![
                if first { x.name.clone() } else { String::new() },
                if first {
                    x.direction.clone()
                } else {
                    String::new()
                },
                what.to_string(),
            ];
            let tolerance = b.or(*a).map_or(0.0, |q| q.tolerance_um);
            row.push(fixed(tolerance, 3));
            row.extend(cells(*b));
            row.extend(cells(*a));
            rows.push(row);
        }
        if several {
            rows.push(vec![
                String::new(),
                String::new(),
                "test".into(),
                String::new(),
                String::new(),
                String::new(),
                x.before.verdict.name().into(),
                String::new(),
                String::new(),
                x.after.verdict.name().into(),
            ]);
        }
    }
    let s = &t.noise.sigma_um;
    let mut out = format!(
        "\nTolerances of {} (ISO 14253-1, coverage k = {}): verdict per test and direction\n",
        t.file,
        significant(t.coverage_k)
    );
    out.push_str(&table(&head, &rows));
    out.push_str(&format!(
        "Verdicts: before {}; after {}.\n",
        counts(&t.counts.before),
        counts(&t.counts.after)
    ));
    out.push_str(&format!(
        "Before: the readings (the machine as measured); U = {k}·σ (a range: {k}·√2·σ), σ the reading noise {} (x), {} (y), {} µm (z), from {}.\nAfter: readings minus prediction (the machine as the identified model would leave it once compensated); U = {k}·√(σ² + b²), b = √max(0, s² − σ²) the model's lack of fit, s the record's residual RMS in that direction.\nPass: value + U ≤ tolerance; fail: value − U > tolerance; otherwise undecided.\n",
        fixed(s[0], 3),
        fixed(s[1], 3),
        fixed(s[2], 3),
        t.noise.source,
        k = significant(t.coverage_k),
    ));
    out
}

/// Value, U and verdict of one quantity in one state.
fn cells(q: Option<&QuantityReport>) -> [String; 3] {
    match q {
        Some(q) => [
            fixed(q.value_um, 3),
            fixed(q.expanded_um, 3),
            q.verdict.name().to_string(),
        ],
        None => [String::new(), String::new(), String::new()],
    }
}

/// `2 pass, 1 fail, 0 undecided`.
fn counts(c: &crate::json::tolerance::CountsReport) -> String {
    format!(
        "{} pass, {} fail, {} undecided",
        c.pass, c.fail, c.undecided
    )
}
