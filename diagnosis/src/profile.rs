//! The scanned parameter of a finding (P of `period:P`, V of `step:V`, TAU of `warmup:TAU` and
//! `exp:TAU`, T of `jump:T`), refined and given an interval from the profile of the fit.
//!
//! The selection picks the best value of the coarse grid ([`super::dictionary::scanned`]). Here
//! the parameter is scanned again on a fine grid around it (41 values: ±1 coarse step in 1/P,
//! every distinct position between the neighbouring grid steps for V, every instant between
//! two samples between the neighbouring grid instants for T, ±half a coarse ratio in ln TAU
//! within the coarse grid's range), with every other term of the model in place, in
//! the whitened rows of every fitted record (a term's columns as the campaign gives them): the
//! value that explains most (largest ΔRSS) is the finding's, and its 95 % interval is the set of
//! values whose ΔRSS lies within `3.84·s²` of the best (`s²` the whitened residual variance of
//! the model with the finding: the profile-likelihood interval of one parameter). The
//! amplitudes' standard uncertainties are then those of the fit at that value: conditional
//! on it.

use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::model::{Basis, Term};
use simulation::record::Record;

use super::select::Span;

/// Where the fine grids come from: the fitted records one after the other (the positions and
/// times of periods, steps and time constants) and every fitted record's sample times on its
/// own clock, sorted (the instants of a jump).
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a> {
    /// The fitted records one after the other.
    pub record: &'a Record,
    /// The sample times of every fitted record on its own clock, s, sorted.
    pub times: &'a [f64],
}

/// A refined scanned parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scan {
    /// The value (mm for P; mm or degrees for V; s for TAU and T).
    pub value: f64,
    /// The lower end of its 95 % interval.
    pub low: f64,
    /// The upper end.
    pub high: f64,
}

/// The scanned parameter of `basis`, in its unit.
pub fn parameter(basis: Basis) -> Option<f64> {
    basis
        .period_mm()
        .or_else(|| basis.step_at())
        .or_else(|| basis.tau_s())
        .or_else(|| basis.jump_at())
}

/// The basis with parameter `v` (same family as `basis`), rounded to the vocabulary's
/// thousandths.
fn with_parameter(basis: Basis, v: f64) -> Basis {
    let milli = (v * 1000.0).round();
    match basis {
        Basis::Period(_) => Basis::Period(milli.max(1.0) as u32),
        Basis::Exp(_) => Basis::Exp(milli.max(1.0) as u32),
        Basis::Warmup(_) => Basis::Warmup(milli.max(1.0) as u32),
        Basis::Step(_) => Basis::Step(milli as i64),
        Basis::Jump(_) => Basis::Jump(milli as i64),
        other => other,
    }
}

/// Every instant between two consecutive distinct values of `x` (sorted) within `half` of `v`.
fn between(x: &[f64], v: f64, half: f64) -> Vec<f64> {
    let mut out: Vec<f64> = x
        .windows(2)
        .filter(|w| w[1] > w[0])
        .map(|w| 0.5 * (w[0] + w[1]))
        .filter(|m| (m - v).abs() <= half)
        .collect();
    out.dedup();
    out
}

/// The fine grid around the coarse value of `basis` on axis values `x` (sorted; for steps) or
/// the records' sample times `times` (sorted; for jumps).
fn grid(basis: Basis, x: &[f64], times: &[f64], tau_range: (f64, f64)) -> Vec<f64> {
    let n = 41;
    match basis {
        Basis::Jump(_) => {
            // Within one spacing of the dictionary's grid, between the same quantiles.
            let v = basis.jump_at().unwrap_or(0.0);
            let Some((q0, q1)) = (times.len() >= 20).then(|| {
                (
                    times[times.len() / 20],
                    times[times.len() - 1 - times.len() / 20],
                )
            }) else {
                return Vec::new();
            };
            between(times, v, (q1 - q0) / super::dictionary::JUMPS as f64)
        }
        Basis::Period(_) => {
            let p = basis.period_mm().unwrap_or(1.0);
            let range = x.last().copied().unwrap_or(0.0) - x.first().copied().unwrap_or(0.0);
            let df = 0.2 / range.max(1e-9);
            (0..n)
                .map(|k| 1.0 / (1.0 / p + df * (2.0 * k as f64 / (n - 1) as f64 - 1.0)))
                .filter(|p| p.is_finite() && *p > 0.0)
                .collect()
        }
        Basis::Step(_) => {
            let v = basis.step_at().unwrap_or(0.0);
            let n_steps = super::dictionary::STEPS as f64;
            let (lo, hi) = (
                x.first().copied().unwrap_or(v),
                x.last().copied().unwrap_or(v),
            );
            between(x, v, (hi - lo) / n_steps)
        }
        Basis::Exp(_) | Basis::Warmup(_) => {
            let t = basis.tau_s().unwrap_or(1.0);
            let (lo, hi) = tau_range;
            (0..n)
                .map(|k| t * (0.5 * (2.0 * k as f64 / (n - 1) as f64 - 1.0)).exp())
                .filter(|v| (lo..=hi).contains(v))
                .collect()
        }
        _ => Vec::new(),
    }
}

/// What a term explains beyond `q` in the whitened rows, from its whitened columns `h`:
/// ΔRSS, or `None` when it adds no direction.
fn explains(h: &DMatrix<f64>, q: &Span, y: &DVector<f64>) -> Option<f64> {
    let d = q.new_directions(h);
    (d.ncols() > 0).then(|| d.tr_mul(&q.project_out(y)).norm_squared())
}

/// The refined term and its interval: `term`'s scanned parameter on the fine grid around its
/// value, with the model `q` (orthonormal, whitened, every other term) in place; `columns`
/// gives the whitened columns of a term in the rows of `y` (the whitened readings); `at` is
/// where the fine grid is built from. `None` for a term without a scanned parameter.
///
/// # Errors
/// The error of `columns`.
pub fn refine<E>(
    m: &Machine,
    term: Term,
    at: &Grid,
    columns: &mut dyn FnMut(Term) -> Result<DMatrix<f64>, E>,
    q: &Span,
    y: &DVector<f64>,
) -> Result<Option<(Term, Scan)>, E> {
    if parameter(term.basis).is_none() {
        return Ok(None);
    }
    let record = at.record;
    let axis = match term.effect.carrier(m) {
        model_spec::basis::Carrier::Axis(a) => Some(a),
        model_spec::basis::Carrier::None => None,
    };
    let mut x: Vec<f64> = match axis {
        Some(a) => {
            let k = if m.axes[a].kind == model_spec::AxisKind::Rotary {
                180.0 / std::f64::consts::PI
            } else {
                1.0
            };
            record.samples.iter().map(|s| s.commands[a] * k).collect()
        }
        None => Vec::new(),
    };
    x.sort_by(f64::total_cmp);
    let mut profile: Vec<(f64, Term, f64)> = Vec::new();
    let coarse = parameter(term.basis).unwrap_or(0.0);
    let tau_range = match (record.samples.first(), record.samples.last()) {
        (Some(a), Some(b)) if record.samples.len() > 1 => {
            let duration = b.t - a.t;
            (
                2.0 * duration / (record.samples.len() - 1) as f64,
                0.5 * duration,
            )
        }
        _ => (coarse, coarse),
    };
    for v in grid(term.basis, &x, at.times, tau_range)
        .into_iter()
        .chain([coarse])
    {
        let t = Term {
            effect: term.effect,
            basis: with_parameter(term.basis, v),
        };
        if t.check(m).is_err() {
            continue;
        }
        if let Some(gain) = explains(&columns(t)?, q, y) {
            profile.push((parameter(t.basis).unwrap_or(v), t, gain));
        }
    }
    let Some(&(value, best, top)) = profile.iter().max_by(|a, b| a.2.total_cmp(&b.2)) else {
        return Ok(None);
    };
    let rss = q.project_out(y).norm_squared() - top;
    let dof = y.len().saturating_sub(q.rank() + best.basis.width()).max(1);
    let s2 = rss / dof as f64;
    let inside: Vec<f64> = profile
        .iter()
        .filter(|(_, _, g)| top - g <= 3.84 * s2)
        .map(|(v, _, _)| *v)
        .collect();
    let low = inside.iter().copied().fold(value, f64::min);
    let high = inside.iter().copied().fold(value, f64::max);
    Ok(Some((best, Scan { value, low, high })))
}
