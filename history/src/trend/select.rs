//! Which checks make one error's series: the checks of one machine id whose values mean the
//! same thing. A value is comparable with another only when both come from the same machine
//! description (fingerprint), the same model (the same terms: another term changes what the
//! others absorb), the same set of test paths (other paths see other combinations of errors,
//! and confounded parts differ), and the same constraint; and only when the check determined
//! it with an uncertainty. Every other check of the machine is left out, with its reason.

use super::TrendError;
use crate::check::{Check, Parameter, canonical_key, same_name};
use crate::store::RecordedCheck;
use formats::time::Timestamp;
use serde::Serialize;

/// One check of a series: its value of the error with its standard uncertainty.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Point {
    /// The check's id.
    pub id: i64,
    /// When it was measured.
    pub at: Timestamp,
    /// The value, in the series' unit (µm, µrad).
    pub value: f64,
    /// Its standard uncertainty, same unit, > 0.
    pub std: f64,
}

/// A check of the machine left out of the series, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LeftOut {
    /// The check's id.
    pub id: i64,
    /// When it was measured.
    pub at: Timestamp,
    /// Why it is not comparable (or has no value).
    pub reason: String,
}

/// What makes the checks of a series comparable: one error of one machine, measured with the
/// same description, model, paths and constraint.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeriesHead {
    /// The machine id.
    pub machine_id: String,
    /// The parameter's name as recorded (`XOC`, `ECC@harmonic:2:cos`).
    pub parameter: String,
    /// Its unit (`um`, `urad`, `ms`, `1`).
    pub unit: String,
    /// The machine description's fingerprint.
    pub fingerprint: String,
    /// The description's name.
    pub machine: String,
    /// The model's label, as the reference check has it.
    pub model: String,
    /// The model's terms.
    pub terms: Vec<String>,
    /// The test paths.
    pub paths: Vec<String>,
    /// The constraint.
    pub constraint: String,
}

/// One error's series on one machine: what makes the checks comparable, and the checks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// What makes the checks comparable (its fields are written inline).
    #[serde(flatten)]
    pub head: SeriesHead,
    /// The check that defined the series (the baseline when one was chosen, else the latest
    /// check that determined the error).
    pub reference: i64,
    /// The checks of the series, by measurement time (then id).
    pub points: Vec<Point>,
    /// The other checks of the machine, by measurement time, each with its reason.
    pub left_out: Vec<LeftOut>,
}

fn sorted_keys<'a>(
    names: impl Iterator<Item = &'a String>,
    key: impl Fn(&str) -> String,
) -> Vec<String> {
    let mut v: Vec<String> = names.map(|n| key(n)).collect();
    v.sort();
    v.dedup();
    v
}

fn term_set(c: &Check) -> Vec<String> {
    sorted_keys(c.terms.iter(), canonical_key)
}

fn path_set(c: &Check) -> Vec<String> {
    sorted_keys(c.paths.iter(), str::to_lowercase)
}

/// Why `p` gives no point, if it gives none.
fn no_value(name: &str, p: &Parameter) -> Option<String> {
    if p.fixed {
        return Some(format!("{name} was fixed to 0 by the constraint"));
    }
    match (p.determined, p.value, p.std) {
        (false, _, _) | (_, None, _) => Some(format!("{name} was not determined by the data")),
        (true, Some(_), None) => Some(format!(
            "{name} has no uncertainty (the fit had no degree of freedom)"
        )),
        (true, Some(_), Some(s)) if s <= 0.0 || !s.is_finite() => Some(format!(
            "{name} has a zero uncertainty (noise-free data): it cannot be weighed"
        )),
        _ => None,
    }
}

/// The series of `parameter` for `machine_id` among `checks` (all checks of the database, or
/// those of the machine), defined by the check `reference` when given, else by the latest
/// check (by measurement time, then id) that determined it among the calibrations, or among
/// the re-checks when `rechecks` ([`Check::recheck`]: a re-check and a calibration are
/// never in one series).
///
/// # Errors
/// [`TrendError::EmptyHistory`], [`TrendError::UnknownMachine`] (with the known ids),
/// [`TrendError::UnknownParameter`] (with the parameters of the machine's checks),
/// [`TrendError::NeverDetermined`], [`TrendError::Reference`].
pub fn select(
    checks: &[RecordedCheck],
    machine_id: &str,
    parameter: &str,
    reference: Option<i64>,
    rechecks: bool,
) -> Result<Series, TrendError> {
    if checks.is_empty() {
        return Err(TrendError::EmptyHistory);
    }
    let mut mine: Vec<&RecordedCheck> = checks
        .iter()
        .filter(|c| c.check.machine_id == machine_id)
        .collect();
    if mine.is_empty() {
        let mut known: Vec<String> = checks.iter().map(|c| c.check.machine_id.clone()).collect();
        known.sort();
        known.dedup();
        return Err(TrendError::UnknownMachine {
            machine_id: machine_id.to_string(),
            known,
        });
    }
    mine.sort_by_key(|c| (c.check.measured_at, c.id));
    if !mine.iter().any(|c| c.check.parameter(parameter).is_some()) {
        let mut known: Vec<String> = Vec::new();
        for c in mine.iter().rev() {
            for p in &c.check.parameters {
                if !known.contains(&p.name) {
                    known.push(p.name.clone());
                }
            }
        }
        return Err(TrendError::UnknownParameter {
            machine_id: machine_id.to_string(),
            parameter: parameter.to_string(),
            known,
        });
    }
    let reference = match reference {
        Some(id) => {
            let c = mine
                .iter()
                .find(|c| c.id == id)
                .ok_or_else(|| TrendError::Reference {
                    id,
                    reason: format!(
                        "it is not a check of machine {machine_id} (its checks: {})",
                        mine.iter()
                            .map(|c| c.id.to_string())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                })?;
            match c.check.parameter(parameter) {
                None => {
                    return Err(TrendError::Reference {
                        id,
                        reason: format!("its model ({}) has no {parameter}", c.check.model),
                    });
                }
                Some(p) => {
                    if let Some(why) = no_value(&p.name, p) {
                        return Err(TrendError::Reference { id, reason: why });
                    }
                }
            }
            *c
        }
        None => *mine
            .iter()
            .rev()
            .find(|c| {
                c.check.recheck == rechecks
                    && c.check
                        .parameter(parameter)
                        .is_some_and(|p| no_value(&p.name, p).is_none())
            })
            .ok_or_else(|| TrendError::NeverDetermined {
                machine_id: machine_id.to_string(),
                parameter: parameter.to_string(),
            })?,
    };
    let r = &reference.check;
    let q = r
        .parameter(parameter)
        .expect("the reference has the parameter");
    let (terms, paths) = (term_set(r), path_set(r));
    let mut points = Vec::new();
    let mut left_out = Vec::new();
    for c in &mine {
        let k = &c.check;
        let reason = if k.recheck != r.recheck {
            Some(if k.recheck {
                "a re-check (its own series: rtest history --rechecks)".to_string()
            } else {
                "a calibration, not a re-check".to_string()
            })
        } else if k.fingerprint != r.fingerprint {
            Some(format!(
                "another machine description (fingerprint {}, the series' is {})",
                k.fingerprint, r.fingerprint
            ))
        } else if term_set(k) != terms {
            Some(format!("another model ({}: other terms)", k.model))
        } else if path_set(k) != paths {
            Some(format!(
                "other test paths ({}; the series measured {})",
                k.paths.join(", "),
                r.paths.join(", ")
            ))
        } else if k.constraint != r.constraint {
            Some(format!(
                "another constraint ({}; the series' is {})",
                k.constraint, r.constraint
            ))
        } else {
            match k.parameters.iter().find(|p| same_name(&p.name, &q.name)) {
                None => Some(format!("{} is not a parameter of its fit", q.name)),
                Some(p) => no_value(&q.name, p).or_else(|| {
                    (p.unit != q.unit)
                        .then(|| format!("{} is in {}, not {}", q.name, p.unit, q.unit))
                }),
            }
        };
        match reason {
            Some(reason) => left_out.push(LeftOut {
                id: c.id,
                at: k.measured_at,
                reason,
            }),
            None => {
                let p = k.parameter(&q.name).expect("checked above");
                points.push(Point {
                    id: c.id,
                    at: k.measured_at,
                    value: p.value.expect("checked above"),
                    std: p.std.expect("checked above"),
                });
            }
        }
    }
    Ok(Series {
        head: SeriesHead {
            machine_id: machine_id.to_string(),
            parameter: q.name.clone(),
            unit: q.unit.clone(),
            fingerprint: r.fingerprint.clone(),
            machine: r.machine.clone(),
            model: r.model.clone(),
            terms: r.terms.clone(),
            paths: r.paths.clone(),
            constraint: r.constraint.clone(),
        },
        reference: reference.id,
        points,
        left_out,
    })
}
