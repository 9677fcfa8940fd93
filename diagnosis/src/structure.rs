//! The structure of a residual: what is left after a fit, per direction (x, y, z), against
//! every axis position, time and direction of motion, so that a person can see it.
//!
//! For each direction of the residual and each source, one shape at a time is fitted by least
//! squares with an intercept, and reported as the RMS of what it explains: the RMS over the
//! samples of the fitted shape minus its mean (µm). That measure is comparable between shapes
//! and does not blow up when a shape is nearly constant on the path (a harmonic of an axis that
//! covers a quarter turn, where the coefficients alone would be huge and cancel). The shapes:
//! - a rotary axis that moves: `harmonic:k` (k = 1..K), `a·cos kθ + b·sin kθ`;
//! - a linear axis that moves: `poly:k` (Legendre of the position normalised over the stroke);
//! - time: `time:k`, Legendre over the record;
//! - the direction of motion of an axis that moves both ways: `reversal` (±1).
//!
//! Shapes of different sources are not independent on a given path (on K4 every axis moves
//! with C), so these are indications, not a decomposition; the selection ([`super::select`])
//! is what decides.

use model_spec::basis::legendre;
use model_spec::{AxisKind, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::record::Record;

/// One shape found in the residual.
#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    /// What it follows: an axis name, or `time`.
    pub source: String,
    /// The shape: `harmonic:2`, `poly:1`, `time:1`, `reversal`.
    pub shape: String,
    /// The residual's direction: 0, 1, 2 for x, y, z.
    pub direction: usize,
    /// RMS of what the shape alone explains of the residual in that direction, µm.
    pub explained_rms_um: f64,
}

/// The RMS of what the columns `shape` (plus an intercept) explain of `y`: the fitted shape
/// minus its mean, over the samples. `None` when the shape does not vary on the samples.
fn explained_rms(shape: &[Vec<f64>], y: &[f64]) -> Option<f64> {
    let n = y.len();
    let k = shape.len();
    if n <= k + 1 {
        return None;
    }
    let a = DMatrix::from_fn(n, k + 1, |i, j| if j == 0 { 1.0 } else { shape[j - 1][i] });
    let b = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    let tol = smax * 1e-9;
    if svd.singular_values.iter().filter(|&&s| s > tol).count() < 2 {
        return None; // the shape is constant on this record
    }
    let x = svd.solve(&b, tol).ok()?;
    let fitted: Vec<f64> = (0..n)
        .map(|i| (1..=k).map(|j| x[j] * shape[j - 1][i]).sum())
        .collect();
    let mean = fitted.iter().sum::<f64>() / n as f64;
    Some((fitted.iter().map(|f| (f - mean).powi(2)).sum::<f64>() / n as f64).sqrt())
}

/// The components of `residual` (mm, one `[x, y, z]` per sample of `record`), largest first.
pub fn analyse(
    m: &Machine,
    record: &Record,
    residual: &[[f64; 3]],
    harmonics: u32,
    poly: u32,
    time: u32,
) -> Vec<Component> {
    let n = record.samples.len();
    let mut out = Vec::new();
    let push = |source: &str, shape: String, cols: Vec<Vec<f64>>, out: &mut Vec<Component>| {
        for d in 0..3 {
            let y: Vec<f64> = residual.iter().map(|r| r[d] * 1e3).collect();
            if let Some(a) = explained_rms(&cols, &y) {
                out.push(Component {
                    source: source.into(),
                    shape: shape.clone(),
                    direction: d,
                    explained_rms_um: a,
                });
            }
        }
    };
    for (ai, axis) in m.axes.iter().enumerate() {
        let q: Vec<f64> = record.samples.iter().map(|s| s.commands[ai]).collect();
        let (lo, hi) = q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if hi <= lo || !hi.is_finite() {
            continue;
        }
        match axis.kind {
            AxisKind::Rotary => {
                for k in 1..=harmonics {
                    let c = q.iter().map(|t| (k as f64 * t).cos()).collect();
                    let s = q.iter().map(|t| (k as f64 * t).sin()).collect();
                    push(&axis.name, format!("harmonic:{k}"), vec![c, s], &mut out);
                }
            }
            AxisKind::Linear => {
                let [slo, shi] = axis.limits;
                for k in 1..=poly {
                    let p = q
                        .iter()
                        .map(|x| legendre(k, 2.0 * (x - slo) / (shi - slo) - 1.0))
                        .collect();
                    push(&axis.name, format!("poly:{k}"), vec![p], &mut out);
                }
            }
        }
        let dirs: Vec<f64> = record.samples.iter().map(|s| s.motion[ai] as f64).collect();
        let (fwd, bwd) = (
            dirs.iter().filter(|&&v| v > 0.0).count(),
            dirs.iter().filter(|&&v| v < 0.0).count(),
        );
        if fwd > 1 && bwd > 1 {
            push(&axis.name, "reversal".into(), vec![dirs], &mut out);
        }
    }
    if n > 2 {
        for k in 1..=time {
            let t = (0..n).map(|i| legendre(k, record.tau(i))).collect();
            push("time", format!("time:{k}"), vec![t], &mut out);
        }
    }
    out.sort_by(|a, b| b.explained_rms_um.total_cmp(&a.explained_rms_um));
    out
}
