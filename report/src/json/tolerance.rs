//! The verdicts of a validation against a tolerance file (`rtest validate --tolerance FILE`):
//! per test and direction, the largest |deviation| and the range (max − min) of the deviation
//! over the record, before (the readings: the machine as measured) and after (the readings
//! minus the identified model's prediction: the machine as the model would leave it once
//! compensated), each with its expanded uncertainty and its ISO 14253-1 verdict
//! ([`fitting::verdict`]). Values in µm. The `tolerance` field of the validation report:
//!
//! ```json
//! "tolerance": {"file": "tol.toml", "rule": "ISO 14253-1: …", "coverage_k": 2,
//!   "noise": {"source": "…", "sigma_um": [0.49, 0.54, 0.52]},
//!   "tests": [{"name": "K1", "record": "k1", "direction": "x", "max_um": 20, "range_um": 30,
//!     "before": {"u_um": 0.49, "lack_of_fit_um": null,
//!                "max": {"value_um": 33.9, "expanded_um": 0.99, "tolerance_um": 20, "verdict": "fail"},
//!                "range": {…}, "verdict": "fail"},
//!     "after": {"u_um": 1.25, "lack_of_fit_um": 1.15, "max": {…}, "range": {…}, "verdict": "pass"}}],
//!   "counts": {"before": {"pass": 0, "fail": 1, "undecided": 0}, "after": {…}}}
//! ```
//!
//! `max` or `range` is `null` where the file gives no such tolerance.

use super::validate::ValidationReport;
use super::{NonFinite, finite};
use fitting::validate::Extent;
use fitting::verdict::{
    COVERAGE, Quantity, State, Verdict, judge, lack_of_fit, tolerance_uncertainty,
};
use formats::tolerance::{Direction, TestTolerances};
use model_spec::units::UM_PER_MM;
use serde::{Deserialize, Serialize};

/// The decision rule, as the report states it.
pub const RULE: &str = "ISO 14253-1: pass when value + U ≤ tolerance, fail when value − U > tolerance, undecided otherwise; U = k·u_c (the range: k·√2·u_c, two readings); before: u_c = the reading noise σ; after: u_c = √(σ² + b²), b = √max(0, s² − σ²) the model's lack of fit, s the residual RMS of the record in that direction";

/// A verdict in a report: `pass`, `fail` or `undecided`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VerdictReport {
    /// Conformance proven.
    Pass,
    /// Nonconformance proven.
    Fail,
    /// Neither.
    Undecided,
}

impl From<Verdict> for VerdictReport {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Pass => VerdictReport::Pass,
            Verdict::Fail => VerdictReport::Fail,
            Verdict::Undecided => VerdictReport::Undecided,
        }
    }
}

impl From<VerdictReport> for Verdict {
    fn from(v: VerdictReport) -> Self {
        match v {
            VerdictReport::Pass => Verdict::Pass,
            VerdictReport::Fail => Verdict::Fail,
            VerdictReport::Undecided => Verdict::Undecided,
        }
    }
}

impl VerdictReport {
    /// `pass`, `fail` or `undecided`.
    pub fn name(self) -> &'static str {
        match self {
            VerdictReport::Pass => "pass",
            VerdictReport::Fail => "fail",
            VerdictReport::Undecided => "undecided",
        }
    }
}

/// One quantity judged, µm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QuantityReport {
    /// The value over the record (largest |deviation|, or max − min), µm.
    pub value_um: f64,
    /// Its expanded uncertainty U, µm.
    pub expanded_um: f64,
    /// The tolerance, µm.
    pub tolerance_um: f64,
    /// The verdict.
    pub verdict: VerdictReport,
}

/// The verdicts of one test and direction in one state (before or after).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateReport {
    /// The combined standard uncertainty u_c of one reading, µm.
    pub u_um: f64,
    /// After: the model's lack of fit b on the record in that direction, µm; `null` before (no
    /// model involved).
    pub lack_of_fit_um: Option<f64>,
    /// The largest |deviation|, when the file gives `max_um`.
    pub max: Option<QuantityReport>,
    /// The range, when the file gives `range_um`.
    pub range: Option<QuantityReport>,
    /// The verdict of the test and direction: fail when one quantity fails, pass when each
    /// passes, undecided otherwise.
    pub verdict: VerdictReport,
}

/// One test and direction of the tolerance file, judged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TestVerdictReport {
    /// The test's name as the file gives it.
    pub name: String,
    /// The label of the validated record it names.
    pub record: String,
    /// `x`, `y` or `z` of the tool frame.
    pub direction: String,
    /// The largest allowed |deviation|, µm.
    pub max_um: Option<f64>,
    /// The largest allowed range, µm.
    pub range_um: Option<f64>,
    /// The machine as measured.
    pub before: StateReport,
    /// The machine as the identified model would leave it once compensated.
    pub after: StateReport,
}

/// The reading noise the verdicts assume.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseReport {
    /// Where it comes from, for people.
    pub source: String,
    /// The standard uncertainty of one reading per direction x, y, z, µm.
    pub sigma_um: [f64; 3],
}

/// How many tests and directions got each verdict.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CountsReport {
    /// Passed.
    pub pass: usize,
    /// Failed.
    pub fail: usize,
    /// Undecided.
    pub undecided: usize,
}

impl CountsReport {
    fn add(&mut self, v: VerdictReport) {
        match v {
            VerdictReport::Pass => self.pass += 1,
            VerdictReport::Fail => self.fail += 1,
            VerdictReport::Undecided => self.undecided += 1,
        }
    }
}

/// The counts before and after.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StateCounts {
    /// The machine as measured.
    pub before: CountsReport,
    /// As the model would leave it.
    pub after: CountsReport,
}

/// The verdicts of a validation against a tolerance file (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ToleranceReport {
    /// The tolerance file.
    pub file: String,
    /// The decision rule ([`RULE`]).
    pub rule: String,
    /// The coverage factor k.
    pub coverage_k: f64,
    /// The reading noise assumed.
    pub noise: NoiseReport,
    /// Per test and direction, in the file's order.
    pub tests: Vec<TestVerdictReport>,
    /// The verdicts counted.
    pub counts: StateCounts,
}

/// Why verdicts cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum JudgeError {
    /// A test of the file that no validated record is called.
    #[error(transparent)]
    Name(#[from] formats::located::Located),
    /// Not one extent per record.
    #[error("{extents} extents for {records} records")]
    Extents {
        /// Records of the validation.
        records: usize,
        /// Extents given.
        extents: usize,
    },
    /// A value that is not finite.
    #[error(transparent)]
    NonFinite(#[from] NonFinite),
}

/// The extents of one validated record per direction, mm: of the readings and of the residual.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RecordExtents {
    /// The readings (before).
    pub measured: [Extent; 3],
    /// Measured minus predicted (after).
    pub residual: [Extent; 3],
}

impl ToleranceReport {
    /// The verdicts of `report` (the validation) against `tolerances`, `extents` one per
    /// record of `report`, `noise` the reading noise.
    ///
    /// # Errors
    /// [`JudgeError::Name`] for a test no record of `report` is called
    /// ([`TestTolerances::record_index`]), [`JudgeError::Extents`] when `extents` has not one
    /// entry per record, [`JudgeError::NonFinite`] when a value is not finite.
    pub fn new(
        tolerances: &TestTolerances,
        report: &ValidationReport,
        extents: &[RecordExtents],
        noise: NoiseReport,
    ) -> Result<ToleranceReport, JudgeError> {
        let labels: Vec<String> = report.records.iter().map(|r| r.label.clone()).collect();
        if extents.len() != labels.len() {
            return Err(JudgeError::Extents {
                records: labels.len(),
                extents: extents.len(),
            });
        }
        let mut tests = Vec::with_capacity(tolerances.entries.len());
        let mut counts = StateCounts::default();
        for (i, t) in tolerances.entries.iter().enumerate() {
            let r = tolerances.record_index(t, &labels)?;
            let (record, ext) = (&report.records[r], &extents[r]);
            let d = t.direction;
            let sigma = noise.sigma_um[d.index()];
            let rms = direction_report(record, d).residual_rms_um;
            let field = |s: &str| format!("tolerance.tests[{i}].{s}");
            let state = |st: State, e: &Extent| -> Result<StateReport, NonFinite> {
                let u = tolerance_uncertainty(st, sigma, rms);
                let q = |quantity: Quantity, limit: Option<f64>, value_mm: f64| {
                    limit
                        .map(|l| {
                            let at = format!("{}.{}", st.name(), quantity.name());
                            let j = judge(quantity, value_mm * UM_PER_MM, u, l);
                            Ok(QuantityReport {
                                value_um: finite(|| field(&format!("{at}.value_um")), j.value)?,
                                expanded_um: finite(
                                    || field(&format!("{at}.expanded_um")),
                                    j.expanded,
                                )?,
                                tolerance_um: l,
                                verdict: j.verdict.into(),
                            })
                        })
                        .transpose()
                };
                let max = q(Quantity::Max, t.max_um, e.max_abs())?;
                let range = q(Quantity::Range, t.range_um, e.range())?;
                let verdict = Verdict::all(max.iter().chain(&range).map(|x| x.verdict.into()));
                Ok(StateReport {
                    u_um: finite(|| field(&format!("{}.u_um", st.name())), u)?,
                    lack_of_fit_um: match st {
                        State::Before => None,
                        State::After => Some(lack_of_fit(sigma, rms)),
                    },
                    max,
                    range,
                    verdict: verdict.into(),
                })
            };
            let before = state(State::Before, &ext.measured[d.index()])?;
            let after = state(State::After, &ext.residual[d.index()])?;
            counts.before.add(before.verdict);
            counts.after.add(after.verdict);
            tests.push(TestVerdictReport {
                name: t.name.clone(),
                record: record.label.clone(),
                direction: d.name().to_string(),
                max_um: t.max_um,
                range_um: t.range_um,
                before,
                after,
            });
        }
        Ok(ToleranceReport {
            file: tolerances.file.clone(),
            rule: RULE.to_string(),
            coverage_k: COVERAGE,
            noise,
            tests,
            counts,
        })
    }
}

/// The statistics of `record` in direction `d`.
fn direction_report(
    record: &super::validate::RecordValidationReport,
    d: Direction,
) -> &super::validate::DirectionReport {
    match d {
        Direction::X => &record.per_direction.x,
        Direction::Y => &record.per_direction.y,
        Direction::Z => &record.per_direction.z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A validation of one record `k1` whose residual RMS is `s` µm in every direction.
    fn validation(s: f64) -> ValidationReport {
        let d = format!(
            r#"{{"measured_rms_um": 10, "measured_max_um": 20, "residual_rms_um": {s}, "residual_max_um": 3}}"#
        );
        let text = format!(
            r#"{{"machine": "seed-ac", "model": "reduced", "params": "id.json", "data": "k1.csv",
               "samples": 10, "prediction": "exact", "measured_rms_um": 10, "measured_max_um": 20,
               "residual_rms_um": {s}, "residual_max_um": 3, "zeroed": false,
               "per_direction": {{"x": {d}, "y": {d}, "z": {d}}}}}"#
        );
        ValidationReport::from_json("v.json", &text).unwrap()
    }

    fn extents() -> RecordExtents {
        // Readings from −0.012 to 0.020 mm, residual from −0.002 to 0.003 mm, every direction.
        let e = |min, max| [Extent { min, max }; 3];
        RecordExtents {
            measured: e(-0.012, 0.020),
            residual: e(-0.002, 0.003),
        }
    }

    fn noise(s: f64) -> NoiseReport {
        NoiseReport {
            source: "test".into(),
            sigma_um: [s; 3],
        }
    }

    #[test]
    fn the_extents_are_judged_in_um_before_and_after() {
        let file = "[[test]]\nname = \"K1\"\ndirection = \"y\"\nmax_um = 22\nrange_um = 10\n";
        let t = formats::tolerance::parse_file("tol.toml", file).unwrap();
        // σ = 0.5 µm, s = 2 µm: b = √(4 − 0.25), u_c after = 2 µm.
        let r = ToleranceReport::new(&t, &validation(2.0), &[extents()], noise(0.5)).unwrap();
        let x = &r.tests[0];
        assert_eq!((x.record.as_str(), x.direction.as_str()), ("k1", "y"));
        let before_max = x.before.max.as_ref().unwrap();
        assert!((before_max.value_um - 20.0).abs() < 1e-9);
        assert!((before_max.expanded_um - 1.0).abs() < 1e-12);
        assert_eq!(before_max.verdict, VerdictReport::Pass); // 20 + 1 ≤ 22
        let before_range = x.before.range.as_ref().unwrap();
        assert!((before_range.value_um - 32.0).abs() < 1e-9);
        assert_eq!(before_range.verdict, VerdictReport::Fail); // 32 − 1.41 > 10
        assert_eq!(x.before.verdict, VerdictReport::Fail);
        assert_eq!(x.before.lack_of_fit_um, None);
        assert!((x.after.u_um - 2.0).abs() < 1e-12);
        assert!((x.after.lack_of_fit_um.unwrap() - 3.75f64.sqrt()).abs() < 1e-12);
        let after_max = x.after.max.as_ref().unwrap();
        assert!((after_max.value_um - 3.0).abs() < 1e-9);
        assert_eq!(after_max.verdict, VerdictReport::Pass); // 3 + 4 ≤ 22
        let after_range = x.after.range.as_ref().unwrap();
        assert!((after_range.expanded_um - 4.0 * 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(after_range.verdict, VerdictReport::Undecided); // 5 ± 5.66 about 10
        assert_eq!(x.after.verdict, VerdictReport::Undecided);
        assert_eq!((r.counts.before.fail, r.counts.after.undecided), (1, 1));
        assert_eq!(r.coverage_k, 2.0);
    }

    #[test]
    fn a_test_without_its_record_and_missing_extents_are_errors() {
        let t = formats::tolerance::parse_file(
            "tol.toml",
            "[[test]]\nname = \"K2\"\ndirection = \"x\"\nmax_um = 5\n",
        )
        .unwrap();
        let e = ToleranceReport::new(&t, &validation(1.0), &[extents()], noise(0.5)).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("tol.toml:2:8: `test[0].name`: no validated record is called `K2`"),
            "{e}"
        );
        let t = formats::tolerance::parse_file(
            "tol.toml",
            "[[test]]\nname = \"k1\"\ndirection = \"x\"\nmax_um = 5\n",
        )
        .unwrap();
        let e = ToleranceReport::new(&t, &validation(1.0), &[], noise(0.5)).unwrap_err();
        assert_eq!(e.to_string(), "0 extents for 1 records");
        let nan = RecordExtents {
            measured: [Extent {
                min: f64::NAN,
                max: f64::NAN,
            }; 3],
            ..extents()
        };
        let e = ToleranceReport::new(&t, &validation(1.0), &[nan], noise(0.5)).unwrap_err();
        assert!(
            e.to_string()
                .contains("tolerance.tests[0].before.max.value_um"),
            "{e}"
        );
    }
}
