//! What `rtest history` shows and exports: the list of machines and checks, and one error's
//! trend as a table for people, a CSV and a JSON report.
//!
//! Text for people uses fixed decimals (`model_spec::units`); the CSV and JSON numbers are the
//! shortest decimals that read back to the same `f64`, values in the error's unit (the column
//! names carry it: `value_um`, `value_urad`).

use crate::check::same_name;
use crate::store::{MachineSummary, RecordedCheck};
use crate::trend::{Assessment, LeftOut, Row, Series, SeriesHead, Slope, Test, first_flag};
use model_spec::units::{fixed, format_scaled, p_value, readable, symbol};
use serde::Serialize;
use std::fmt::Write as _;

/// The scatter ratio beyond which the text warns that the checks scatter more than their
/// uncertainties say.
pub const SCATTER_NOTE: f64 = 2.0;

/// The list of `machines` and their `checks` for people (the caller picks which: all, or one
/// machine's).
pub fn listing(db: &str, machines: &[MachineSummary], checks: &[RecordedCheck]) -> String {
    let mut t = format!(
        "History {db}: {} machine{}, {} check{}\n",
        machines.len(),
        model_spec::units::plural(machines.len(), "s"),
        checks.len(),
        model_spec::units::plural(checks.len(), "s")
    );
    for m in machines {
        let mine: Vec<&RecordedCheck> = checks
            .iter()
            .filter(|c| c.check.machine_id == m.machine_id)
            .collect();
        let _ = writeln!(
            t,
            "\nMachine {} ({}; fingerprint {}): {} check{}, measured {} to {}",
            m.machine_id,
            m.machines.join(", "),
            m.fingerprints.join(", "),
            m.checks,
            model_spec::units::plural(m.checks, "s"),
            m.first,
            m.last
        );
        if m.fingerprints.len() > 1 {
            t.push_str("  The machine description changed between checks (more than one fingerprint): trends compare only checks of one description.\n");
        }
        let model_w = mine
            .iter()
            .map(|c| c.check.model.chars().count())
            .max()
            .unwrap_or(5)
            .max(5);
        let paths_w = mine
            .iter()
            .map(|c| c.check.paths.join(",").chars().count())
            .max()
            .unwrap_or(5)
            .max(5);
        let _ = writeln!(
            t,
            "  {:>5}  {:<20}  {:<model_w$}  {:<paths_w$}  {:>13}  {:>7}",
            "check", "measured (UTC)", "model", "paths", "residual (µm)", "rank"
        );
        for c in mine {
            let k = &c.check;
            let _ = writeln!(
                t,
                "  {:>5}  {:<20}  {:<model_w$}  {:<paths_w$}  {:>13}  {:>7}",
                c.id,
                k.measured_at.to_string(),
                k.model,
                k.paths.join(","),
                fixed(k.residual_rms_um, 3),
                format!("{}/{}", k.rank, k.free_parameters)
            );
        }
        if let Some(latest) = checks
            .iter()
            .rev()
            .find(|c| c.check.machine_id == m.machine_id)
        {
            let names: Vec<&str> = latest
                .check
                .parameters
                .iter()
                .map(|p| p.name.as_str())
                .collect();
            let _ = writeln!(
                t,
                "  Errors of the latest check (rtest history --machine-id {} --error NAME): {}",
                report::text::shell(&m.machine_id),
                names.join(" ")
            );
        }
    }
    t
}

/// The listing as JSON: the machines and every check with all it holds.
#[derive(Serialize)]
struct ListingJson<'a> {
    kind: &'static str,
    db: &'a str,
    machines: &'a [MachineSummary],
    checks: &'a [RecordedCheck],
}

/// The listing as JSON: `{"kind": "history", "db", "machines": [...], "checks": [...]}`, each
/// check with everything recorded (parameters with `value`, `std`, `unit`; `inputs` with
/// their SHA-256).
///
/// # Errors
/// The serializer's (none for finite numbers).
pub fn listing_json(
    db: &str,
    machines: &[MachineSummary],
    checks: &[RecordedCheck],
) -> Result<String, serde_json::Error> {
    let j = ListingJson {
        kind: "history",
        db,
        machines,
        checks,
    };
    Ok(serde_json::to_string_pretty(&j)? + "\n")
}

/// Where a tolerance came from, for people (`tol.toml:3`, `--tolerance`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ToleranceSource {
    /// The limit, in the error's unit.
    pub limit: f64,
    /// `FILE:LINE` or `--tolerance`.
    pub from: String,
}

/// One error's trend with everything needed to report it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrendReport {
    /// Always `history-trend`.
    pub kind: &'static str,
    /// The database.
    pub db: String,
    /// The series (without its points: those are the rows).
    #[serde(flatten)]
    pub series: SeriesHead,
    /// The flags.
    #[serde(flatten)]
    pub assessment: Assessment,
    /// Where the tolerance came from, if one was given.
    pub tolerance_from: Option<String>,
    /// The checks left out, with their reasons.
    pub left_out: Vec<LeftOut>,
}

impl TrendReport {
    /// The report of `assessment` on `series`, from the database `db`.
    pub fn new(
        db: &str,
        series: &Series,
        assessment: Assessment,
        tolerance_from: Option<String>,
    ) -> TrendReport {
        TrendReport {
            kind: "history-trend",
            db: db.to_string(),
            series: series.head.clone(),
            assessment,
            tolerance_from,
            left_out: series.left_out.clone(),
        }
    }

    /// The report as JSON.
    ///
    /// # Errors
    /// The serializer's (none for finite numbers).
    pub fn json(&self) -> Result<String, serde_json::Error> {
        Ok(serde_json::to_string_pretty(self)? + "\n")
    }

    fn unit(&self) -> &str {
        symbol(&self.series.unit)
    }

    /// The trend for people: what the series is, the table with the flags of every check,
    /// the tests that fired first and on the latest check, the trend over the whole series,
    /// and the checks left out.
    pub fn text(&self) -> String {
        let s = &self.series;
        let a = &self.assessment;
        let u = self.unit().to_string();
        let mut t = String::new();
        let _ = writeln!(
            t,
            "{} of machine {} ({}, fingerprint {}): model {}, paths {}, constraint {}; {} check{}",
            s.parameter,
            s.machine_id,
            s.machine,
            s.fingerprint,
            s.model,
            s.paths.join(", "),
            s.constraint,
            a.rows.len(),
            model_spec::units::plural(a.rows.len(), "s")
        );
        let _ = writeln!(
            t,
            "Baseline: check {}. Tests at two-sided α = {}: change against the baseline |Δ| > z·√(σ² + σ_b²), z = {}; trend: weighted least-squares slope from the baseline to the check, its standard error scaled by the checks' scatter, |t| beyond Student's quantile (|t| max).",
            a.baseline,
            a.alpha,
            fixed(a.z, 3)
        );
        match (a.tolerance, &self.tolerance_from) {
            (Some(l), Some(from)) => {
                let _ = writeln!(
                    t,
                    "Tolerance: |{}| ≤ {} {u} ({from}).",
                    s.parameter,
                    model_spec::units::short(l)
                );
            }
            _ => {
                t.push_str("Tolerance: none given (--tolerance NAME=LIMIT or --tolerances FILE).\n")
            }
        }
        t.push('\n');
        let _ = writeln!(
            t,
            "{:>5}  {:<20}  {:>10}  {:>7}  {:>10}  {:>6}  {:>18}  {:>7}  {:>7}  flags",
            "check",
            "measured (UTC)",
            format!("value ({u})"),
            "± σ",
            "Δ baseline",
            "z",
            format!("slope ({u}/day)"),
            "t",
            "|t| max",
        );
        for r in &a.rows {
            let _ = writeln!(t, "{}", row_line(r, a.baseline));
        }
        t.push('\n');
        for test in [Test::Tolerance, Test::Baseline, Test::Trend] {
            if let Some((id, at)) = first_flag(&a.rows, test) {
                let flag = flag_text(&a.rows, id, test);
                let _ = writeln!(t, "First {} flag: check {id} ({at}): {flag}", test.name());
            }
        }
        if let Some(last) = a.rows.last() {
            if last.flags.is_empty() {
                let _ = writeln!(t, "Latest check {}: no flag.", last.point.id);
            } else {
                let _ = writeln!(t, "Latest check {}:", last.point.id);
                for f in &last.flags {
                    let _ = writeln!(t, "  {}: {}", f.test.name(), f.text);
                }
            }
        }
        match &a.trend {
            Some(sl) => t.push_str(&trend_text(sl, a.alpha, &u)),
            None => t.push_str(
                "Trend: fewer than 3 checks from the baseline at 2 times or more: no slope.\n",
            ),
        }
        if let Some(sl) = &a.trend
            && sl.scatter_ratio > SCATTER_NOTE
        {
            let _ = writeln!(
                t,
                "Note: the checks scatter {} times more about the trend line than their uncertainties say: each check's σ does not hold the reproducibility between checks (set-up, temperature). The trend test allows for it; a change against the baseline may be that scatter.",
                fixed(sl.scatter_ratio, 1)
            );
        }
        if !self.left_out.is_empty() {
            let _ = writeln!(
                t,
                "Left out ({} check{} of machine {} not comparable with the series):",
                self.left_out.len(),
                model_spec::units::plural(self.left_out.len(), "s"),
                s.machine_id
            );
            for l in &self.left_out {
                let _ = writeln!(t, "  check {} ({}): {}", l.id, l.at, l.reason);
            }
        }
        t
    }

    /// The rows as CSV: a `# ` comment saying what the series is, then
    /// `check,measured_at,value_U,std_U,change_U,change_z,slope_U_per_day,slope_std_U_per_day,
    /// slope_t,slope_dof,tolerance_flag,baseline_flag,trend_flag` (`U` the unit, `/` written
    /// `_per_`: `value_um_per_s`; empty where a number does not exist; flags 0 or 1).
    pub fn csv(&self) -> String {
        let s = &self.series;
        let a = &self.assessment;
        let suffix = match s.unit.as_str() {
            "1" => String::new(),
            // A rate's unit is written with `_per_` for `/` (`value_um_per_s`): a CSV header
            // name without a slash.
            u => format!("_{}", u.replace('/', "_per_")),
        };
        let num = |x: f64| format_scaled(x, 0);
        let opt = |x: Option<f64>| x.map_or_else(String::new, num);
        let mut t = format!(
            "# rtest history: {} of machine {} (fingerprint {}, model {}, paths {}, constraint {}); baseline check {}; two-sided alpha {}{}\n",
            s.parameter,
            s.machine_id,
            s.fingerprint,
            s.model,
            s.paths.join(" "),
            s.constraint,
            a.baseline,
            a.alpha,
            a.tolerance.map_or_else(String::new, |l| format!(
                "; tolerance {} {}",
                num(l),
                s.unit
            ))
        );
        let _ = writeln!(
            t,
            "check,measured_at,value{suffix},std{suffix},change{suffix},change_z,slope{suffix}_per_day,slope_std{suffix}_per_day,slope_t,slope_dof,tolerance_flag,baseline_flag,trend_flag"
        );
        for r in &a.rows {
            let flag = |test| u8::from(r.flags.iter().any(|f| f.test == test));
            let sl = r.slope.as_ref();
            let _ = writeln!(
                t,
                "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                r.point.id,
                r.point.at,
                num(r.point.value),
                num(r.point.std),
                num(r.change),
                opt(r.change_z),
                opt(sl.map(|s| s.per_day)),
                opt(sl.map(|s| s.std_per_day)),
                opt(sl.map(|s| s.t)),
                sl.map_or_else(String::new, |s| s.dof.to_string()),
                flag(Test::Tolerance),
                flag(Test::Baseline),
                flag(Test::Trend)
            );
        }
        t
    }
}

/// One row of the table.
fn row_line(r: &Row, baseline: i64) -> String {
    let flags: Vec<&str> = r.flags.iter().map(|f| f.test.name()).collect();
    let (change, z) = if r.point.id == baseline {
        ("baseline".to_string(), String::new())
    } else {
        let sign = if r.change >= 0.0 { "+" } else { "" };
        (
            format!("{sign}{}", fixed(r.change, 3)),
            r.change_z.map_or_else(String::new, |z| fixed(z, 2)),
        )
    };
    let (slope, t, limit) = match &r.slope {
        Some(s) => (
            format!(
                "{} ± {}",
                readable(s.per_day, 4),
                readable(s.std_per_day, 4)
            ),
            fixed(s.t, 2),
            fixed(s.critical, 2),
        ),
        None => (String::new(), String::new(), String::new()),
    };
    format!(
        "{:>5}  {:<20}  {:>10}  {:>7}  {:>10}  {:>6}  {:>18}  {:>7}  {:>7}  {}",
        r.point.id,
        r.point.at.to_string(),
        fixed(r.point.value, 3),
        fixed(r.point.std, 3),
        change,
        z,
        slope,
        t,
        limit,
        flags.join(", ")
    )
    .trim_end()
    .to_string()
}

/// The text of `test`'s flag on check `id`.
fn flag_text(rows: &[Row], id: i64, test: Test) -> String {
    rows.iter()
        .find(|r| r.point.id == id)
        .and_then(|r| r.flags.iter().find(|f| f.test == test))
        .map_or_else(String::new, |f| f.text.clone())
}

/// The whole series' trend for people.
fn trend_text(s: &Slope, alpha: f64, unit: &str) -> String {
    format!(
        "Trend over checks {}–{} ({} checks): {}{} ± {} {unit}/day, t = {} with {} degrees of freedom (p = {}): {} at α = {alpha}. Scatter about the line: {} times the checks' uncertainties.\n",
        s.from,
        s.to,
        s.checks,
        if s.per_day >= 0.0 { "+" } else { "" },
        readable(s.per_day, 4),
        readable(s.std_per_day, 4),
        fixed(s.t, 2),
        s.dof,
        p_value(s.p_value),
        if s.flagged {
            "a drift"
        } else {
            "no significant drift"
        },
        fixed(s.scatter_ratio, 2)
    )
}

/// The parameter names of `checks` of `machine_id`, latest check first, each once: what
/// `--error` and a tolerance file may name.
pub fn known_parameters(checks: &[RecordedCheck], machine_id: &str) -> Vec<String> {
    let mut known: Vec<String> = Vec::new();
    for c in checks
        .iter()
        .rev()
        .filter(|c| c.check.machine_id == machine_id)
    {
        for p in &c.check.parameters {
            if !known.iter().any(|k| same_name(k, &p.name)) {
                known.push(p.name.clone());
            }
        }
    }
    known
}
