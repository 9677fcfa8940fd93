//! The conformance verdict of ISO 14253-1 (decision rules for proving conformity or
//! nonconformity with specifications): a measured value `y` with its expanded uncertainty `U`
//! against an upper limit `L` (a tolerance, `y ≥ 0`):
//!
//! - **pass** when `y + U ≤ L`: conformance proven, the whole uncertainty interval within the
//!   tolerance;
//! - **fail** when `y − U > L`: nonconformance proven, the whole interval beyond it;
//! - **undecided** otherwise: the interval straddles the limit, and neither statement can be
//!   made. An uncertainty larger than the tolerance (`U > L`) can never pass.
//!
//! `U = k·u_c`, the coverage factor `k` = [`COVERAGE`] = 2 (about 95 % for a normal
//! distribution), `u_c` the combined standard uncertainty of `y`. What goes into `u_c` is the
//! caller's to say: [`tolerance_uncertainty`] is the one rule of `rtest validate --tolerance`
//! (the reading noise, and for a value predicted by the identified model its lack of fit).
//!
//! The same rule, with `U = 2σ` of an identified value, says whether a value beyond its
//! tolerance in `rtest history` is proven so (its fail branch).

/// The coverage factor `k` of the expanded uncertainty `U = k·u_c` (ISO 14253-1, GUM: about
/// 95 % coverage for a normal distribution).
pub const COVERAGE: f64 = 2.0;

/// The verdict of ISO 14253-1 on a value against its tolerance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Verdict {
    /// Conformance proven: value + U ≤ tolerance.
    Pass,
    /// Nonconformance proven: value − U > tolerance.
    Fail,
    /// Neither: the uncertainty interval straddles the tolerance.
    Undecided,
}

impl Verdict {
    /// The verdict of `value` with expanded uncertainty `expanded` against the upper limit
    /// `limit` (one unit for the three). A value or uncertainty that is not a number decides
    /// nothing: [`Verdict::Undecided`].
    pub fn of(value: f64, expanded: f64, limit: f64) -> Verdict {
        if value + expanded <= limit {
            Verdict::Pass
        } else if value - expanded > limit {
            Verdict::Fail
        } else {
            Verdict::Undecided
        }
    }

    /// The verdict of several quantities of one test judged together: fail when one fails,
    /// pass when every one passes, undecided otherwise (and for none).
    pub fn all(verdicts: impl IntoIterator<Item = Verdict>) -> Verdict {
        let mut any = false;
        let mut every_pass = true;
        for v in verdicts {
            any = true;
            match v {
                Verdict::Fail => return Verdict::Fail,
                Verdict::Undecided => every_pass = false,
                Verdict::Pass => {}
            }
        }
        if any && every_pass {
            Verdict::Pass
        } else {
            Verdict::Undecided
        }
    }

    /// `pass`, `fail` or `undecided`: the verdict's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "fail",
            Verdict::Undecided => "undecided",
        }
    }

    /// The verdict named `name` (as [`Verdict::name`] writes it).
    pub fn from_name(name: &str) -> Option<Verdict> {
        match name {
            "pass" => Some(Verdict::Pass),
            "fail" => Some(Verdict::Fail),
            "undecided" => Some(Verdict::Undecided),
            _ => None,
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The quantity of a deviation over a test that a tolerance limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// The largest |deviation| over the test (one reading).
    Max,
    /// The range `max − min` of the deviation over the test (the difference of two readings).
    Range,
}

impl Quantity {
    /// `max` or `range`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Max => "max",
            Quantity::Range => "range",
        }
    }

    /// How many standard uncertainties of one reading the quantity's standard uncertainty is:
    /// 1 for the maximum (one reading), √2 for the range (the difference of two readings,
    /// taken as independent).
    pub fn readings_factor(self) -> f64 {
        match self {
            Quantity::Max => 1.0,
            Quantity::Range => std::f64::consts::SQRT_2,
        }
    }
}

/// Which deviation a verdict judges.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum State {
    /// The machine as measured: the readings themselves (the nominal machine's residual).
    Before,
    /// The machine as the identified model would leave it once compensated: the readings minus
    /// the model's prediction (validate's residual).
    After,
}

impl State {
    /// `before` or `after`.
    pub fn name(self) -> &'static str {
        match self {
            State::Before => "before",
            State::After => "after",
        }
    }
}

/// The combined standard uncertainty `u_c` of one reading of the deviation in `state` (any
/// one unit): `noise` the standard uncertainty of a reading (the R-test's noise), and
/// `residual_rms` the RMS of measured minus predicted over the test in that direction.
///
/// - before: `u_c = noise` (no model is involved: the readings are the deviation);
/// - after: `u_c = √(noise² + b²)`, `b = √max(0, residual_rms² − noise²)` the model's lack of
///   fit on the test (the part of the residual the noise does not explain: counting the whole
///   residual RMS as a bias would count the noise twice). So `u_c = max(noise, residual_rms)`.
pub fn tolerance_uncertainty(state: State, noise: f64, residual_rms: f64) -> f64 {
    match state {
        State::Before => noise,
        State::After => {
            let bias2 = (residual_rms * residual_rms - noise * noise).max(0.0);
            (noise * noise + bias2).sqrt()
        }
    }
}

/// The lack of fit `b = √max(0, residual_rms² − noise²)` of [`tolerance_uncertainty`].
pub fn lack_of_fit(noise: f64, residual_rms: f64) -> f64 {
    (residual_rms * residual_rms - noise * noise)
        .max(0.0)
        .sqrt()
}

/// One quantity judged: its value, expanded uncertainty, limit and verdict (one unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Judged {
    /// The measured value (largest |deviation| or range).
    pub value: f64,
    /// Its expanded uncertainty `U = k·f·u_c` (`f` [`Quantity::readings_factor`]).
    pub expanded: f64,
    /// The tolerance.
    pub limit: f64,
    /// The verdict.
    pub verdict: Verdict,
}

/// The verdict on `value` of `quantity`, `u_c` the combined standard uncertainty of one
/// reading ([`tolerance_uncertainty`]), against `limit`: `U = COVERAGE · factor · u_c`.
pub fn judge(quantity: Quantity, value: f64, u_c: f64, limit: f64) -> Judged {
    let expanded = COVERAGE * quantity.readings_factor() * u_c;
    Judged {
        value,
        expanded,
        limit,
        verdict: Verdict::of(value, expanded, limit),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_verdicts_and_their_edges() {
        assert_eq!(Verdict::of(8.0, 2.0, 10.0), Verdict::Pass);
        assert_eq!(Verdict::of(8.0, 2.000001, 10.0), Verdict::Undecided);
        assert_eq!(Verdict::of(12.0, 2.0, 10.0), Verdict::Undecided);
        assert_eq!(Verdict::of(12.000001, 2.0, 10.0), Verdict::Fail);
        // An uncertainty beyond the tolerance never passes, even at a value of 0.
        assert_eq!(Verdict::of(0.0, 11.0, 10.0), Verdict::Undecided);
        assert_eq!(Verdict::of(f64::NAN, 1.0, 10.0), Verdict::Undecided);
        assert_eq!(Verdict::of(5.0, f64::NAN, 10.0), Verdict::Undecided);
    }

    #[test]
    fn several_quantities_fail_on_one_fail_and_pass_on_all_passes() {
        use Verdict::*;
        assert_eq!(Verdict::all([Pass, Pass]), Pass);
        assert_eq!(Verdict::all([Pass, Undecided]), Undecided);
        assert_eq!(Verdict::all([Undecided, Fail, Pass]), Fail);
        assert_eq!(Verdict::all([]), Undecided);
        for v in [Pass, Fail, Undecided] {
            assert_eq!(Verdict::from_name(v.name()), Some(v));
        }
        assert_eq!(Verdict::from_name("ok"), None);
    }

    #[test]
    fn the_lack_of_fit_adds_to_the_noise_without_counting_it_twice() {
        // Before: the noise alone, whatever the model's residual.
        assert_eq!(tolerance_uncertainty(State::Before, 0.5, 3.0), 0.5);
        // After: a residual that is noise only adds nothing; a larger one adds its excess.
        assert_eq!(tolerance_uncertainty(State::After, 0.5, 0.4), 0.5);
        let u = tolerance_uncertainty(State::After, 0.5, 3.0);
        assert!((u - 3.0).abs() < 1e-12, "{u}");
        let b = lack_of_fit(0.5, 3.0);
        assert!((b * b + 0.25 - 9.0).abs() < 1e-12);
        // The range is two readings: √2 more.
        let j = judge(Quantity::Range, 4.0, 1.0, 10.0);
        assert!((j.expanded - 2.0 * 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(j.verdict, Verdict::Pass);
        let j = judge(Quantity::Max, 4.0, 1.0, 5.0);
        assert_eq!((j.expanded, j.verdict), (2.0, Verdict::Undecided));
    }
}
