//! The safety limits of a compensation: what `rtest compensate` refuses to put onto a machine.
//!
//! - **Words that cannot carry the correction.** A corrected NC word is written with the
//!   decimals of the program's word. Where that loses more than [`WORD_LOSS_MM`] (0.1 µm) of a
//!   linear correction or [`WORD_LOSS_RAD`] (1 µrad) of a rotary one, the program cannot carry
//!   the correction ([`coarse_words`]): `A0` or `C90` rounds a correction of a few µrad away
//!   entirely. 0.1 µm is half the step of 0.0001 mm (four decimals) rounded up; 1 µrad is half
//!   the step of 0.0001° (0.87 µrad) rounded up: the finest input step of the usual controls,
//!   and the decimals rtest's own programs write. The tool point moves by the angle times its
//!   distance from the axis: 1 µrad is 0.1 µm at 100 mm.
//! - **Changes beyond a limit** ([`ChangeLimits`], default [`MAX_CHANGE_UM`] 50 µm and
//!   [`MAX_CHANGE_URAD`] 250 µrad). A compensated error whose largest value over the machine's
//!   ranges ([`largest_values`]), or a change folded into the description, beyond the limit is
//!   more likely a wrong description, a mistaken identification or a machine that needs repair
//!   than a geometric error to compensate: it is refused ([`check_changes`]). The linear limit
//!   is the default of Heidenhain KinematicsOpt's largest change of the kinematics (0.05 mm);
//!   the angular one moves a point 200 mm from the axis by 50 µm, the same change at the lever
//!   arms of the built-in machines (`docs/compensation.md` §7).
//!
//! Units inside: mm and rad.

use super::kinematics::CorrectedDescription;
use super::values::MachineErrors;
use formats::nc::RoundingAt;
use model_spec::units::{compact, readable, short};
use model_spec::{AxisKind, ErrorId, Machine};

/// The most of a linear correction the written words may lose, mm (0.1 µm).
pub const WORD_LOSS_MM: f64 = 1e-4;

/// The most of a rotary correction the written words may lose, rad (1 µrad).
pub const WORD_LOSS_RAD: f64 = 1e-6;

/// The default largest value of a linear error or change compensated, µm.
pub const MAX_CHANGE_UM: f64 = 50.0;

/// The default largest value of an angular error compensated, µrad.
pub const MAX_CHANGE_URAD: f64 = 250.0;

/// A word of a corrected program that loses more of its correction than the limit.
#[derive(Clone, Debug, PartialEq)]
pub struct CoarseWord {
    /// The axis.
    pub axis: String,
    /// `true` for a rotary axis.
    pub rotary: bool,
    /// Where the loss is largest: the line and the word.
    pub at: RoundingAt,
    /// The loss there: mm or rad.
    pub loss: f64,
    /// The fewest decimals that keep every word of the axis within the limit.
    pub needed: usize,
}

impl CoarseWord {
    /// For people: ``line 4: `C90` (0 decimals) loses 12.3 µrad of its correction, 4 decimals
    /// needed``.
    pub fn for_people(&self) -> String {
        let (k, unit, limit) = if self.rotary {
            (1e6, "µrad", WORD_LOSS_RAD * 1e6)
        } else {
            (1e3, "µm", WORD_LOSS_MM * 1e3)
        };
        let word = if self.at.in_block {
            format!("`{}`", self.at.word)
        } else {
            format!(
                "{} left at `{}` from an earlier block",
                self.axis, self.at.word
            )
        };
        format!(
            "line {}: {word} ({} decimal{}) loses {} {unit} of the correction of {} (at most {} {unit}), {} decimals needed",
            self.at.line,
            self.at.decimals,
            if self.at.decimals == 1 { "" } else { "s" },
            readable(self.loss * k, 3),
            self.axis,
            compact(limit),
            self.needed
        )
    }
}

/// The fewest decimals whose half step (in the word's unit) is at most `limit` (the same unit).
pub fn decimals_needed(limit: f64) -> usize {
    (0..=formats::nc::MAX_DECIMALS)
        .find(|&d| 0.5 * 10f64.powi(-(d as i32)) <= limit * (1.0 + 1e-12))
        .unwrap_or(formats::nc::MAX_DECIMALS)
}

/// The axes of `m` (machine order, as the program's axis words) whose written words lose more
/// than [`WORD_LOSS_MM`] or [`WORD_LOSS_RAD`] of their correction: `rounding` per axis, mm or
/// degrees as the program holds them, and where it is largest (`at`, from
/// `formats::nc::Written`).
pub fn coarse_words(m: &Machine, rounding: &[f64], at: &[Option<RoundingAt>]) -> Vec<CoarseWord> {
    m.axes
        .iter()
        .zip(rounding.iter().zip(at))
        .filter_map(|(a, (&r, at))| {
            let rotary = a.kind == AxisKind::Rotary;
            let (loss, limit_in_word) = if rotary {
                (r.to_radians(), WORD_LOSS_RAD.to_degrees())
            } else {
                (r, WORD_LOSS_MM)
            };
            let limit = if rotary { WORD_LOSS_RAD } else { WORD_LOSS_MM };
            (loss > limit).then(|| CoarseWord {
                axis: a.name.clone(),
                rotary,
                at: at.clone().unwrap_or(RoundingAt {
                    line: 0,
                    word: a.name.clone(),
                    decimals: 0,
                    in_block: true,
                }),
                loss,
                needed: decimals_needed(limit_in_word),
            })
        })
        .collect()
}

/// The largest changes compensate puts onto a machine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChangeLimits {
    /// Of a linear error or change, mm.
    pub linear_mm: f64,
    /// Of an angular error, rad.
    pub angular_rad: f64,
}

impl Default for ChangeLimits {
    /// [`MAX_CHANGE_UM`] and [`MAX_CHANGE_URAD`].
    fn default() -> Self {
        ChangeLimits::from_display(MAX_CHANGE_UM, MAX_CHANGE_URAD)
    }
}

impl ChangeLimits {
    /// The limits given in µm and µrad.
    pub fn from_display(um: f64, urad: f64) -> ChangeLimits {
        ChangeLimits {
            linear_mm: um * 1e-3,
            angular_rad: urad * 1e-6,
        }
    }
}

/// The largest value of a compensated error over the machine's ranges.
#[derive(Clone, Debug, PartialEq)]
pub struct LargestValue {
    /// The error.
    pub error: ErrorId,
    /// Its name (`XOC`, `EXX`).
    pub name: String,
    /// `true` for an angular error (rad), `false` for a translational one (mm).
    pub angular: bool,
    /// The value of largest magnitude, with its sign: mm or rad.
    pub value: f64,
    /// For an error that varies with its axis: the axis and the position of that value (mm or
    /// degrees).
    pub at: Option<(String, f64)>,
}

/// Positions sampled over an axis's range for [`largest_values`]: at least this many.
pub const RANGE_SAMPLES: usize = 4097;

/// Every compensated error of `errors` (of machine `m`) with its value of largest magnitude:
/// a constant error's value; for an error that varies with its axis (a component error), the
/// largest over the axis's stroke or range (0–360° for a rotary axis without one), sampled at
/// [`RANGE_SAMPLES`] evenly spaced positions or more (64 per period of its shortest `period:P`
/// or `harmonic:K`), the ends and each `step:V`'s position and the position just below it:
/// within 0.2 % of the true largest value of a smooth term.
pub fn largest_values(m: &Machine, errors: &MachineErrors) -> Vec<LargestValue> {
    let n = errors.errors().len();
    let mut out = vec![0.0; n];
    let mut q = vec![0.0; m.axes.len()];
    errors.values_at(m, &q, &mut out);
    let constant = out.clone();
    errors
        .errors()
        .iter()
        .enumerate()
        .map(|(slot, &e)| {
            let entry = &m.catalogue[e];
            let mut best = LargestValue {
                error: e,
                name: entry.name.clone(),
                angular: entry.is_angular(),
                value: constant[slot],
                at: None,
            };
            let axis = match entry.kind {
                model_spec::ErrorKind::Component { axis, .. } if errors.varies(e) => axis,
                _ => return best,
            };
            let a = &m.axes[axis];
            let rotary = a.kind == AxisKind::Rotary;
            let (lo, hi) = if rotary && !a.limits[0].is_finite() {
                (0.0, 360.0)
            } else {
                (a.limits[0], a.limits[1])
            };
            best.value = 0.0;
            q.fill(0.0);
            for p in positions(errors, e, rotary, lo, hi) {
                q[axis] = if rotary { p.to_radians() } else { p };
                errors.values_at(m, &q, &mut out);
                if beyond(out[slot], best.value.abs()) {
                    best.value = out[slot];
                    best.at = Some((a.name.clone(), p));
                }
            }
            best
        })
        .collect()
}

/// The positions (mm or degrees) over `[lo, hi]` at which error `e`'s terms are sampled.
fn positions(errors: &MachineErrors, e: ErrorId, rotary: bool, lo: f64, hi: f64) -> Vec<f64> {
    use model_spec::basis::Basis;
    let span = hi - lo;
    let mut count = RANGE_SAMPLES;
    let mut extra = vec![lo, hi];
    for t in errors
        .terms()
        .iter()
        .filter(|t| t.term.effect == simulation::model::Effect::Error(e))
    {
        let period = match t.term.basis {
            Basis::Harmonic(k) if rotary => Some(360.0 / f64::from(k)),
            Basis::Period(_) => t.term.basis.period_mm(),
            Basis::Step(v) => {
                let at = v as f64 / 1000.0;
                extra.extend([at, at - 1e-9 * span.abs().max(1.0)]);
                None
            }
            _ => None,
        };
        if let Some(p) = period.filter(|p| *p > 0.0) {
            let wanted = (span / p * 64.0).ceil();
            if wanted.is_finite() && wanted < 1e7 {
                count = count.max(wanted as usize + 1);
            }
        }
    }
    let step = span / (count - 1) as f64;
    (0..count)
        .map(|k| lo + k as f64 * step)
        .chain(extra.into_iter().filter(|p| (lo..=hi).contains(p)))
        .collect()
}

/// A value beyond its limit.
#[derive(Clone, Debug, PartialEq)]
pub struct Beyond {
    /// What: `ZOA`, `EXX at X = -500 mm (its largest over X's stroke)`, `Zp folded into its
    /// default`.
    pub what: String,
    /// The value, µm or µrad.
    pub value: f64,
    /// `µm` or `µrad`.
    pub unit: &'static str,
    /// The limit, µm or µrad.
    pub limit: f64,
    /// The flag that sets the limit.
    pub flag: &'static str,
}

impl Beyond {
    /// For people: `ZOA = -62.3 µm (limit 50 µm, --max-change-um)`.
    pub fn for_people(&self) -> String {
        format!(
            "{} = {} {} (limit {} {}, {})",
            self.what,
            compact(self.value),
            self.unit,
            compact(self.limit),
            self.unit,
            self.flag
        )
    }
}

/// Why a compensation is refused by a limit.
#[derive(Debug, thiserror::Error)]
pub enum LimitError {
    /// Values beyond the largest change compensate puts onto the machine.
    #[error(
        "{file}: {}: beyond the largest change compensate puts onto a machine; a change this large is more likely a wrong description, a mistaken identification or a machine that needs repair than a geometric error to compensate: check it, and raise the limit with {} only if it is real",
        beyond.iter().map(Beyond::for_people).collect::<Vec<_>>().join("; "),
        flags(beyond)
    )]
    Beyond {
        /// The file of the values.
        file: String,
        /// Every value beyond its limit.
        beyond: Vec<Beyond>,
    },
}

/// Whether `x` is beyond `limit` in magnitude; a value that is not a number is.
fn beyond(x: f64, limit: f64) -> bool {
    x.is_nan() || x.abs() > limit
}

/// The flags of `beyond`, each once.
fn flags(beyond: &[Beyond]) -> String {
    let mut f: Vec<&str> = beyond.iter().map(|b| b.flag).collect();
    f.dedup();
    f.sort_unstable();
    f.dedup();
    f.join(" or ")
}

/// The values beyond `limits`: each compensated error's largest value over the machine's
/// ranges ([`largest_values`]) and, when the corrected description is given, each change
/// folded into it (a location error's share of an offset, an identified length's change, an
/// offset of a carried axis turned by a folded direction).
pub fn beyond_limits(
    m: &Machine,
    errors: &MachineErrors,
    corrected: Option<&CorrectedDescription>,
    limits: ChangeLimits,
) -> Vec<Beyond> {
    let linear = |what: String, mm: f64| Beyond {
        what,
        value: mm * 1e3,
        unit: "µm",
        limit: limits.linear_mm * 1e3,
        flag: "--max-change-um",
    };
    let mut out: Vec<Beyond> = largest_values(m, errors)
        .into_iter()
        .filter(|v| {
            let limit = if v.angular {
                limits.angular_rad
            } else {
                limits.linear_mm
            };
            beyond(v.value, limit)
        })
        .map(|v| {
            let what = match &v.at {
                Some((axis, p)) => {
                    let rotary = m
                        .axis_by_name(axis)
                        .is_some_and(|i| m.axes[i].kind == AxisKind::Rotary);
                    format!(
                        "{} at {axis} = {}{} (its largest over {axis}'s {})",
                        v.name,
                        short(*p),
                        if rotary { "°" } else { " mm" },
                        if rotary { "range" } else { "stroke" }
                    )
                }
                None => v.name.clone(),
            };
            if v.angular {
                Beyond {
                    what,
                    value: v.value * 1e6,
                    unit: "µrad",
                    limit: limits.angular_rad * 1e6,
                    flag: "--max-change-urad",
                }
            } else {
                linear(what, v.value)
            }
        })
        .collect();
    if let Some(c) = corrected {
        for f in c
            .folded
            .iter()
            .filter(|f| beyond(f.value_mm, limits.linear_mm))
        {
            out.push(linear(
                format!("{} folded into {}", f.name, f.place),
                f.value_mm,
            ));
        }
        for s in c
            .symbols
            .iter()
            .filter(|s| beyond(s.change_mm, limits.linear_mm))
        {
            out.push(linear(
                format!("{} folded into its default", s.name),
                s.change_mm,
            ));
        }
        for t in &c.turned {
            let change = t.after_mm - t.before_mm;
            if beyond(change, limits.linear_mm) {
                out.push(linear(
                    format!("{} turned by the axes {}", t.place, t.by.join(", ")),
                    change,
                ));
            }
        }
    }
    out
}

/// [`beyond_limits`], as an error when there are any.
///
/// # Errors
/// [`LimitError::Beyond`] listing every value beyond its limit.
pub fn check_changes(
    m: &Machine,
    errors: &MachineErrors,
    corrected: Option<&CorrectedDescription>,
    limits: ChangeLimits,
) -> Result<(), LimitError> {
    let beyond = beyond_limits(m, errors, corrected, limits);
    if beyond.is_empty() {
        return Ok(());
    }
    Err(LimitError::Beyond {
        file: errors.file().to_string(),
        beyond,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimals_for_the_limits() {
        assert_eq!(decimals_needed(WORD_LOSS_MM), 4);
        assert_eq!(decimals_needed(WORD_LOSS_RAD.to_degrees()), 4);
        assert_eq!(decimals_needed(0.5), 0);
        assert_eq!(decimals_needed(0.05), 1);
        assert_eq!(decimals_needed(0.049), 2);
    }
}
