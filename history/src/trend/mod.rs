//! The trend of one error over the checks of a machine, and its flags.
//!
//! Pure functions over recorded checks: [`select`] picks the comparable checks (a [`Series`]),
//! [`assess`] flags them. Three tests, each at the two-sided level `alpha` (default
//! [`DEFAULT_ALPHA`]):
//!
//! - **tolerance**: `|v| > limit`. It says too whether the value is beyond the limit by more
//!   than its expanded uncertainty `U = 2σ` (ISO 14253-1: nonconformance proven);
//! - **change against the baseline** (a chosen check, by default the first of the series):
//!   `|v − v_b| > z·√(σ² + σ_b²)`, `z` the two-sided normal quantile of `alpha` (2.576 for
//!   0.01). `σ` is the check's own standard uncertainty from its fit: it does not hold the
//!   reproducibility of the set-up between checks;
//! - **trend**: the weighted least-squares line `v = a + b·t` (weights `1/σ²`, `t` in days)
//!   through the checks from the baseline up to this one (at least 3 checks at 2 times or
//!   more). The weights give the checks' relative precision; the scale comes from the
//!   checks' own scatter about the line: the slope's standard error is
//!   `√(1/Σw(t − t̄)²)` times the Birge ratio `√(χ²/(n − 2))`, and the flag fires when
//!   `|b|/SE` exceeds Student's two-sided quantile of `alpha` with `n − 2` degrees of freedom.
//!   The level is exactly `alpha` when the checks' variances are proportional to their
//!   recorded `σ²` (right, or all understated by one factor, as when the set-up's
//!   reproducibility adds to every check alike), whatever the number of checks.
//!
//! Each row's flags use only that check and the checks before it (a later check never changes
//! an earlier row); the trend over the whole series is [`Assessment::trend`].

mod select;

pub use select::{LeftOut, Point, Series, SeriesHead, select};

use crate::stats::{ALPHA_RANGE, normal_two_sided, student_p_value, student_two_sided};
use formats::time::Timestamp;
use model_spec::units::{fixed, significant, symbol};
use serde::Serialize;

/// The default two-sided level of the change and trend tests.
pub const DEFAULT_ALPHA: f64 = 0.01;

/// The coverage factor of the expanded uncertainty in the tolerance flag (ISO 14253-1).
pub const COVERAGE: f64 = 2.0;

/// Why no trend can be shown.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrendError {
    /// The database holds no check.
    #[error("the history is empty: no check recorded")]
    EmptyHistory,
    /// No check of that machine id.
    #[error("no check of machine `{machine_id}` (machines: {})", known.join(", "))]
    UnknownMachine {
        /// The id asked for.
        machine_id: String,
        /// The ids recorded.
        known: Vec<String>,
    },
    /// No check of the machine has that parameter.
    #[error("no check of machine `{machine_id}` identified `{parameter}` (its parameters: {})", known.join(", "))]
    UnknownParameter {
        /// The machine id.
        machine_id: String,
        /// The name asked for.
        parameter: String,
        /// The parameters its checks have, latest check first.
        known: Vec<String>,
    },
    /// The parameter exists but no check determined it with an uncertainty.
    #[error("no check of machine `{machine_id}` determined `{parameter}` with an uncertainty")]
    NeverDetermined {
        /// The machine id.
        machine_id: String,
        /// The parameter.
        parameter: String,
    },
    /// The chosen baseline cannot be one.
    #[error("check {id} cannot be the baseline: {reason}")]
    Reference {
        /// The check id given.
        id: i64,
        /// Why.
        reason: String,
    },
    /// A level outside [`ALPHA_RANGE`].
    #[error("{0}")]
    Alpha(String),
    /// A tolerance that is not a positive number.
    #[error("{0}")]
    Tolerance(String),
}

/// What to flag.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// The two-sided level of the change and trend tests.
    pub alpha: f64,
    /// The baseline's check id; `None`: the first check of the series.
    pub baseline: Option<i64>,
    /// The tolerance `|v| ≤ limit`, in the series' unit; `None`: no tolerance flag.
    pub tolerance: Option<f64>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            alpha: DEFAULT_ALPHA,
            baseline: None,
            tolerance: None,
        }
    }
}

/// The test behind a flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Test {
    /// `|v| > limit`.
    Tolerance,
    /// `|v − v_b| > z·√(σ² + σ_b²)`.
    Baseline,
    /// The slope's `|t|` beyond Student's quantile.
    Trend,
}

impl Test {
    /// `tolerance`, `baseline` or `trend`.
    pub fn name(self) -> &'static str {
        match self {
            Test::Tolerance => "tolerance",
            Test::Baseline => "baseline",
            Test::Trend => "trend",
        }
    }
}

/// A test that fired on a check.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Flag {
    /// Which test.
    pub test: Test,
    /// Its statistic: `|v|` (tolerance, in the unit), `|v − v_b|/√(σ² + σ_b²)` (baseline) or
    /// `|t|` (trend).
    pub statistic: f64,
    /// What the statistic exceeded: the limit, `z`, or Student's quantile.
    pub threshold: f64,
    /// The test in words, with its numbers.
    pub text: String,
}

/// The weighted least-squares slope over a run of checks and its t-test.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Slope {
    /// The first check of the run (the baseline).
    pub from: i64,
    /// The last check of the run.
    pub to: i64,
    /// Checks in the run.
    pub checks: usize,
    /// The slope, unit per day.
    pub per_day: f64,
    /// The weighted mean time of the run, days after its first check: the line is
    /// `centre_value + per_day·(t − centre_days)`.
    pub centre_days: f64,
    /// The weighted mean value of the run, in the unit.
    pub centre_value: f64,
    /// Its standard error, unit per day: the one the recorded uncertainties give, times the
    /// scatter ratio.
    pub std_per_day: f64,
    /// The Birge ratio `√(χ²/(n − 2))` of the checks about the line: how much more they
    /// scatter than their uncertainties say (about 1 when those are right).
    pub scatter_ratio: f64,
    /// `b/SE`.
    pub t: f64,
    /// Degrees of freedom, `n − 2`.
    pub dof: usize,
    /// Student's two-sided quantile of `alpha` with `dof` degrees of freedom.
    pub critical: f64,
    /// The two-sided p-value of `t`.
    pub p_value: f64,
    /// `|t| > critical`.
    pub flagged: bool,
}

/// One check of the series with its flags.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// The check.
    #[serde(flatten)]
    pub point: Point,
    /// `v − v_b`, in the unit (0 for the baseline).
    pub change: f64,
    /// `(v − v_b)/√(σ² + σ_b²)`; `None` for the baseline itself.
    pub change_z: Option<f64>,
    /// The trend from the baseline to this check; `None` before the baseline, with fewer than
    /// 3 checks, or when they span no time.
    pub slope: Option<Slope>,
    /// The tests that fired, in the order tolerance, baseline, trend.
    pub flags: Vec<Flag>,
}

/// A series with its flags.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Assessment {
    /// The two-sided level of the tests.
    pub alpha: f64,
    /// `z`, the normal quantile of the change test.
    pub z: f64,
    /// The baseline check's id.
    pub baseline: i64,
    /// The tolerance, in the unit, if one was given.
    pub tolerance: Option<f64>,
    /// One row per check of the series, by time.
    pub rows: Vec<Row>,
    /// The trend over every check from the baseline to the last; `None` as for a row.
    pub trend: Option<Slope>,
}

/// The weighted least-squares slope of `points` (the run's first is at `t = 0`), or `None`
/// with fewer than 3 points or a run that spans no time.
pub fn slope(points: &[Point], alpha: f64) -> Option<Slope> {
    let n = points.len();
    if n < 3 {
        return None;
    }
    let t0 = points[0].at;
    let x: Vec<f64> = points.iter().map(|p| p.at.days_since(t0)).collect();
    if x.iter().all(|&xi| xi == x[0]) {
        return None;
    }
    let w: Vec<f64> = points.iter().map(|p| 1.0 / (p.std * p.std)).collect();
    let sw: f64 = w.iter().sum();
    let xm = w.iter().zip(&x).map(|(w, x)| w * x).sum::<f64>() / sw;
    let ym = w.iter().zip(points).map(|(w, p)| w * p.value).sum::<f64>() / sw;
    let sxx: f64 = w.iter().zip(&x).map(|(w, x)| w * (x - xm) * (x - xm)).sum();
    let sxy: f64 = (0..n)
        .map(|i| w[i] * (x[i] - xm) * (points[i].value - ym))
        .sum();
    let b = sxy / sxx;
    let a = ym - b * xm;
    let chi2: f64 = (0..n)
        .map(|i| w[i] * (points[i].value - a - b * x[i]).powi(2))
        .sum();
    let dof = n - 2;
    let scatter_ratio = (chi2 / dof as f64).sqrt();
    // Checks on a line to rounding (noise-free data: a ratio below 1e-6, which noisy checks
    // reach with a probability below 1e-6) have no scatter to scale by: then the recorded
    // uncertainties give the standard error.
    let scale = if scatter_ratio >= 1e-6 {
        scatter_ratio
    } else {
        1.0
    };
    let se = (1.0 / sxx).sqrt() * scale;
    let t = b / se;
    let critical = student_two_sided(alpha, dof);
    let values = [b, se, t, scatter_ratio];
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(Slope {
        from: points[0].id,
        to: points[n - 1].id,
        checks: n,
        per_day: b,
        centre_days: xm,
        centre_value: ym,
        std_per_day: se,
        scatter_ratio,
        t,
        dof,
        critical,
        p_value: student_p_value(t, dof),
        flagged: t.abs() > critical,
    })
}

/// The flags of `series` under `options`.
///
/// # Errors
/// [`TrendError::Alpha`] for a level outside [`ALPHA_RANGE`], [`TrendError::Tolerance`] for
/// a tolerance that is not a positive finite number; [`TrendError::Reference`] for a baseline not in the series.
pub fn assess(series: &Series, options: &Options) -> Result<Assessment, TrendError> {
    let alpha = options.alpha;
    if !(ALPHA_RANGE.0..=ALPHA_RANGE.1).contains(&alpha) {
        return Err(TrendError::Alpha(format!(
            "the level alpha must be between {} and {}, not {}",
            significant(ALPHA_RANGE.0),
            significant(ALPHA_RANGE.1),
            significant(alpha)
        )));
    }
    if let Some(l) = options.tolerance
        && !(l.is_finite() && l > 0.0)
    {
        return Err(TrendError::Tolerance(format!(
            "a tolerance must be a positive number, not {}",
            significant(l)
        )));
    }
    let points = &series.points;
    let b = match options.baseline {
        None => 0,
        Some(id) => points.iter().position(|p| p.id == id).ok_or_else(|| {
            let why = series.left_out.iter().find(|l| l.id == id).map_or_else(
                || "it is not a check of this machine".to_string(),
                |l| format!("it is left out of the series: {}", l.reason),
            );
            TrendError::Reference { id, reason: why }
        })?,
    };
    let Some(base) = points.get(b).copied() else {
        return Err(TrendError::NeverDetermined {
            machine_id: series.head.machine_id.clone(),
            parameter: series.head.parameter.clone(),
        });
    };
    let unit = symbol(&series.head.unit).to_string();
    let z = normal_two_sided(alpha);
    let mut rows = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let mut flags = Vec::new();
        if let Some(limit) = options.tolerance {
            let v = p.value.abs();
            if v > limit {
                let proven = fitting::verdict::Verdict::of(v, COVERAGE * p.std, limit)
                    == fitting::verdict::Verdict::Fail;
                flags.push(Flag {
                    test: Test::Tolerance,
                    statistic: v,
                    threshold: limit,
                    text: format!(
                        "|{}| = {} {unit} > tolerance {} {unit}{}",
                        series.head.parameter,
                        fixed(v, 3),
                        model_spec::units::short(limit),
                        if proven {
                            format!(" by more than U = 2σ = {} {unit} (nonconformance proven, ISO 14253-1)", fixed(COVERAGE * p.std, 3))
                        } else {
                            format!(" but within U = 2σ = {} {unit} of it (not proven, ISO 14253-1)", fixed(COVERAGE * p.std, 3))
                        }
                    ),
                });
            }
        }
        let change = p.value - base.value;
        let spread = (p.std * p.std + base.std * base.std).sqrt();
        let change_z = (i != b).then(|| change / spread);
        if let Some(cz) = change_z
            && cz.abs() > z
        {
            flags.push(Flag {
                test: Test::Baseline,
                statistic: cz.abs(),
                threshold: z,
                text: format!(
                    "changed by {}{} {unit} since check {}: |Δ| > z·√(σ² + σ_b²) = {} × {} = {} {unit} (two-sided α = {alpha})",
                    if change >= 0.0 { "+" } else { "" },
                    fixed(change, 3),
                    base.id,
                    fixed(z, 3),
                    fixed(spread, 3),
                    fixed(z * spread, 3)
                ),
            });
        }
        let run = if i >= b {
            slope(&points[b..=i], alpha)
        } else {
            None
        };
        if let Some(s) = run.as_ref().filter(|s| s.flagged) {
            flags.push(Flag {
                test: Test::Trend,
                statistic: s.t.abs(),
                threshold: s.critical,
                text: format!(
                    "drift {}{} ± {} {unit}/day over checks {}–{} ({} checks): |t| = {} > {}, Student's two-sided quantile of α = {alpha} with {} degrees of freedom",
                    if s.per_day >= 0.0 { "+" } else { "" },
                    model_spec::units::readable(s.per_day, 4),
                    model_spec::units::readable(s.std_per_day, 4),
                    s.from,
                    s.to,
                    s.checks,
                    fixed(s.t.abs(), 2),
                    fixed(s.critical, 3),
                    s.dof
                ),
            });
        }
        rows.push(Row {
            point: *p,
            change,
            change_z,
            slope: run,
            flags,
        });
    }
    let trend = rows.last().and_then(|r| r.slope.clone());
    Ok(Assessment {
        alpha,
        z,
        baseline: base.id,
        tolerance: options.tolerance,
        rows,
        trend,
    })
}

/// When the first check of `rows` flagged by `test` was measured, and its id.
pub fn first_flag(rows: &[Row], test: Test) -> Option<(i64, Timestamp)> {
    rows.iter()
        .find(|r| r.flags.iter().any(|f| f.test == test))
        .map(|r| (r.point.id, r.point.at))
}
