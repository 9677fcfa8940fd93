//! The structure of a residual: what is left after a fit, per direction (x, y, z), against
//! every axis position, time and direction of motion, so that a person can see it.
//!
//! For each direction of the residual and each source it fits, by least squares with an
//! intercept, one shape at a time and reports its amplitude (µm):
//! - a rotary axis that moves: `harmonic:k` (k = 1..K), amplitude `√(a² + b²)` of
//!   `a·cos kθ + b·sin kθ`;
//! - a linear axis that moves: `poly:k` (Legendre of the position normalised over the stroke),
//!   amplitude the largest |value| of the fitted shape over the samples' range of positions;
//! - time: `time:k`, likewise over the record;
//! - the direction of motion of an axis that moves both ways: `reversal`, half the difference of
//!   the mean residual moving forward and backward.
//!
//! Shapes of different sources are not independent on a given path (on K4 every axis moves
//! with C), so amplitudes are indications, not a decomposition; the selection
//! ([`super::select`]) is what decides.

use crate::record::Record;
use model_spec::basis::legendre;
use model_spec::{AxisKind, Machine};
use nalgebra::{DMatrix, DVector};

/// One shape found in the residual.
#[derive(Clone, Debug, PartialEq)]
pub struct Component {
    /// What it follows: an axis name, or `time`.
    pub source: String,
    /// The shape: `harmonic:2`, `poly:1`, `time:1`, `reversal`.
    pub shape: String,
    /// The residual's direction: 0, 1, 2 for x, y, z.
    pub direction: usize,
    /// Amplitude, µm.
    pub amplitude_um: f64,
}

/// Least-squares amplitude of the columns `shape` (plus an intercept) in `y`: the fitted values'
/// largest |value| without the intercept, or the harmonic amplitude for two columns.
fn fit_amplitude(shape: &[Vec<f64>], y: &[f64], harmonic: bool) -> Option<f64> {
    let n = y.len();
    let k = shape.len();
    if n <= k + 1 {
        return None;
    }
    let a = DMatrix::from_fn(n, k + 1, |i, j| if j == 0 { 1.0 } else { shape[j - 1][i] });
    let b = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    let smax = svd.singular_values.max();
    if svd.singular_values.min() <= smax * 1e-9 {
        return None; // the shape does not vary on this record
    }
    let x = svd.solve(&b, smax * 1e-12).ok()?;
    if harmonic {
        Some((x[1] * x[1] + x[2] * x[2]).sqrt())
    } else {
        (0..n)
            .map(|i| (1..=k).map(|j| x[j] * shape[j - 1][i]).sum::<f64>().abs())
            .fold(None, |acc: Option<f64>, v| {
                Some(acc.map_or(v, |a| a.max(v)))
            })
    }
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
    let push = |source: &str,
                shape: String,
                cols: Vec<Vec<f64>>,
                harmonic: bool,
                out: &mut Vec<Component>| {
        for d in 0..3 {
            let y: Vec<f64> = residual.iter().map(|r| r[d] * 1e3).collect();
            if let Some(a) = fit_amplitude(&cols, &y, harmonic) {
                out.push(Component {
                    source: source.into(),
                    shape: shape.clone(),
                    direction: d,
                    amplitude_um: a,
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
                    push(
                        &axis.name,
                        format!("harmonic:{k}"),
                        vec![c, s],
                        true,
                        &mut out,
                    );
                }
            }
            AxisKind::Linear => {
                let [slo, shi] = axis.limits;
                for k in 1..=poly {
                    let p = q
                        .iter()
                        .map(|x| legendre(k, 2.0 * (x - slo) / (shi - slo) - 1.0))
                        .collect();
                    push(&axis.name, format!("poly:{k}"), vec![p], false, &mut out);
                }
            }
        }
        let dirs: Vec<f64> = record.samples.iter().map(|s| s.motion[ai] as f64).collect();
        let (fwd, bwd) = (
            dirs.iter().filter(|&&v| v > 0.0).count(),
            dirs.iter().filter(|&&v| v < 0.0).count(),
        );
        if fwd > 1 && bwd > 1 {
            push(&axis.name, "reversal".into(), vec![dirs], false, &mut out);
        }
    }
    if n > 2 {
        for k in 1..=time {
            let t = (0..n).map(|i| legendre(k, record.tau(i))).collect();
            push("time", format!("time:{k}"), vec![t], false, &mut out);
        }
    }
    out.sort_by(|a, b| b.amplitude_um.total_cmp(&a.amplitude_um));
    out
}
