//! A jump in time on a fitted record described: the ball's set-up or the R-test's zero moved at
//! one sample and stayed there (the ball knocked, a sensor bumped).
//!
//! The selection has each of the six jumps as a candidate (`ZOW@jump:149.5`,
//! [`super::dictionary::jumps`]), which names the term that moved and competes with the
//! look-alikes of the machine; here the jump is described, where the lack-of-fit test fails and
//! wherever the extended model holds a jump. The base fit absorbs much of a jump into the set-up
//! and location errors, so that what the base model leaves is neither a step nor large: on K4 a
//! 3 µm knock of the ball along x leaves 0.93 µm RMS in x, which follows C and time smoothly,
//! under twice the noise. It is looked for as a whole: for a sample k between the 5 % and 95 % quantiles of a fitted record, the columns of
//! the ball's set-up errors (`XOW YOW ZOW`) and of the zero offsets (`dx0 dy0 dz0`) on that
//! record from sample k on (zero before), whitened as the selection's columns, with the base
//! model projected out, are fitted to the base model's residual; k runs over a grid of at most
//! [`COARSE`] positions per record, then over every position around the grid's best.
//!
//! Only where the base model leaves more than the noise: the whitened residual sum of squares
//! beyond its degrees of freedom by more than [`EXCESS`] standard deviations (`√(2·dof)`). (A 5 %
//! gain error of the x sensor, which the base model takes but for 0.045 µm RMS on K4, leaves an
//! excess of 0.65 of them, and a position where a jump happens to explain part of it is no
//! jump.) The best k is kept when
//!
//! - its F-test against the base model, its raw p-value times the number of positions within
//!   the quantiles of every record (Bonferroni), is below α, and
//! - it explains at least [`SHARE`] of the base residual's excess over the noise: a smooth
//!   misfit is explained in part by a jump anywhere, a jump nearly entirely.
//!
//! The most significant jump over the fitted records is described, in every direction it moves
//! by at least a quarter of the largest: a step in time at the instant between samples k − 1
//! and k, `sample` k.

use super::DiagnoseError;
use super::columns::Columns;
use super::select::{Span, f_p_value, f_statistic};
use super::unexplained::{Shape, Unexplained};
use super::weights::Weights;
use fitting::campaign::design::design_matrix;
use fitting::noise::NoiseModel;
use model_spec::{Dir, ErrorKind, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::{Basis, Effect, Model, Term};

/// The share of the base residual's excess over the noise a jump must explain.
pub const SHARE: f64 = 0.75;

/// The positions of a record's coarse scan, at most (every position around the best of them is
/// then tried).
pub const COARSE: usize = 120;

/// A jump is looked for only where the base residual's excess over the noise is more than this
/// many standard deviations of its sum of squares under the noise (`√(2·dof)`, whitened).
pub const EXCESS: f64 = 3.0;

/// The terms whose jump is looked for: the ball's set-up errors and the zero offsets.
fn jumping(m: &Machine) -> Vec<Term> {
    (0..m.catalogue.len())
        .filter(|&e| matches!(m.catalogue[e].kind, ErrorKind::Setup { .. }))
        .map(Effect::Error)
        .chain(Dir::ALL.into_iter().map(Effect::SensorOffset))
        .map(|effect| Term {
            effect,
            basis: Basis::Const,
        })
        .collect()
}

/// The jump in time found on the fitted records of `c` (outliers left out, as the selection's
/// columns `cols` were built), whitened by `weights` and `whitening`, at level `alpha`: the most
/// significant one over the records, described in each direction it moves (see the module
/// documentation); none when there is none. `base_residual` gives each record's base residual
/// per sample (mm).
///
/// # Errors
/// A design that cannot be built; columns that do not whiten.
pub(super) fn find(
    m: &Machine,
    c: &Campaign,
    cols: &Columns,
    weights: &Weights,
    whitening: &NoiseModel,
    alpha: f64,
    base_residual: &dyn Fn(usize) -> Vec<[f64; 3]>,
) -> Result<Vec<Unexplained>, DiagnoseError> {
    let model = Model { terms: jumping(m) };
    let design = design_matrix(m, &model, c)?;
    let n = cols.y.len();
    let group = |g: usize| cols.group(g);
    let base = Span::of_groups(n, 0..cols.nb, &group);
    let r = base.project_out(&cols.y);
    let rss = r.norm_squared();
    let dof = n.saturating_sub(base.rank()) as f64;
    let excess = rss - dof;
    // Nothing to describe where the base model leaves the noise.
    if excess <= EXCESS * (2.0 * dof).sqrt() {
        return Ok(Vec::new());
    }
    // The raw columns of a jump at sample k of record ri (its rows from `first` on).
    let raw_columns = |ri: usize, first: usize, k: usize| -> DMatrix<f64> {
        let own = &design.layout.records[ri].columns;
        let rows = 3 * c.records[ri].record.samples.len();
        let mut j = DMatrix::zeros(n, own.len());
        for (a, &col) in own.iter().enumerate() {
            for row in first + 3 * k..first + rows {
                j[(row, a)] = design.h[(row, col)];
            }
        }
        j
    };
    // The raw p-value of a jump at sample k of record ri.
    let p_of = |ri: usize, first: usize, k: usize| -> Result<f64, DiagnoseError> {
        let mut j = raw_columns(ri, first, k);
        weights.fitted_matrix(&mut j)?;
        whitening.whiten_matrix(&design.rows, &mut j)?;
        let d = base.new_directions(&j);
        let gain = (d.transpose() * &r).norm_squared();
        Ok(match f_statistic(gain, rss, d.ncols(), n, base.rank()) {
            Some(f) if d.ncols() > 0 => f_p_value(f, d.ncols(), n, base.rank()),
            _ => 1.0,
        })
    };
    // Every record's positions, on a coarse grid of at most [`COARSE`] and then every position
    // around its best, and the best over all of them; the Bonferroni factor counts every
    // position within the quantiles.
    let mut tried = 0usize;
    let mut best: Option<(f64, usize, usize, usize)> = None;
    let mut first = 0;
    for (ri, rec) in c.records.iter().enumerate() {
        let samples = rec.record.samples.len();
        if samples >= 20 {
            let edge = (samples / 20).max(1);
            let (lo, hi) = (edge, samples - edge);
            tried += hi - lo;
            let stride = (hi - lo).div_ceil(COARSE).max(1);
            let mut local: Option<(f64, usize)> = None;
            for k in (lo..hi).step_by(stride) {
                let p = p_of(ri, first, k)?;
                if local.is_none_or(|b| p < b.0) {
                    local = Some((p, k));
                }
            }
            if let Some((_, at)) = local {
                for k in (at + 1).saturating_sub(stride).max(lo)..(at + stride).min(hi) {
                    let p = p_of(ri, first, k)?;
                    if local.is_none_or(|b| p < b.0) {
                        local = Some((p, k));
                    }
                }
            }
            if let Some((p, k)) = local
                && best.is_none_or(|b| p < b.0)
            {
                best = Some((p, ri, first, k));
            }
        }
        first += 3 * samples;
    }
    let Some((p, ri, first, k)) = best else {
        return Ok(Vec::new());
    };
    if p * tried as f64 >= alpha {
        return Ok(Vec::new());
    }
    let raw = raw_columns(ri, first, k);
    // The jump's coefficients: least squares of the base residual on its columns with the base
    // projected out; what it explains.
    let mut j = raw.clone();
    weights.fitted_matrix(&mut j)?;
    whitening.whiten_matrix(&design.rows, &mut j)?;
    for mut col in j.column_iter_mut() {
        let v = base.project_out(&col.clone_owned());
        col.copy_from(&v);
    }
    let svd = j.clone().svd(true, true);
    let eps = svd.singular_values.max() * 1e-10;
    let Ok(beta) = svd.solve(&r, eps) else {
        return Ok(Vec::new());
    };
    let explained = (&j * &beta).norm_squared();
    if explained < SHARE * excess {
        return Ok(Vec::new());
    }
    Ok(describe(c, ri, k, &(raw * beta), &base_residual(ri)))
}

/// The descriptions of a jump at sample `k` of record `ri` of `c` whose shape is `shape` (mm,
/// the campaign's rows), `residual` the record's base residual per sample.
fn describe(
    c: &Campaign,
    ri: usize,
    k: usize,
    shape: &DVector<f64>,
    residual: &[[f64; 3]],
) -> Vec<Unexplained> {
    let first: usize = c.records[..ri]
        .iter()
        .map(|r| 3 * r.record.samples.len())
        .sum();
    let rec = &c.records[ri].record;
    let samples = rec.samples.len();
    let t0 = rec.samples[0].t;
    let x: Vec<f64> = rec.samples.iter().map(|s| s.t - t0).collect();
    let at = 0.5 * (x[k - 1] + x[k]);
    let rms = |v: &[f64]| {
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        (v.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / v.len().max(1) as f64).sqrt()
    };
    let fitted: Vec<Vec<f64>> = (0..3)
        .map(|d| (0..samples).map(|i| shape[first + 3 * i + d]).collect())
        .collect();
    let moved: Vec<f64> = fitted.iter().map(|f| rms(f)).collect();
    let largest = moved.iter().cloned().fold(0.0, f64::max);
    (0..3)
        .filter(|&d| largest > 0.0 && moved[d] >= 0.25 * largest)
        .map(|d| {
            let n = residual.len().max(1) as f64;
            Unexplained {
                data: c.records[ri].label.clone(),
                direction: d,
                rms_mm: (residual.iter().map(|v| v[d] * v[d]).sum::<f64>() / n).sqrt(),
                follows: Some("time".into()),
                unit: "s".into(),
                shape: Shape::Step { at },
                explained_rms_mm: moved[d],
                sample: Some(k),
                base: true,
                x: x.clone(),
                fitted: fitted[d].clone(),
            }
        })
        .collect()
}
