//! A candidate's prediction as an update of the plan's: what one more record adds to the
//! plan's information in the parameters of interest, at a cost that does not grow with the
//! plan.
//!
//! **Groups.** The columns of a planned campaign other than the parameters of interest (the
//! shared ones, [`super::choose::interest`]) are nuisances of one ball set-up: its `XOW YOW
//! ZOW` and the columns of the records measured on it (their zeros `dx0 dy0 dz0`, their own
//! drifts). A **group** is a set-up with its records; no two groups share a nuisance column.
//! Each group's rows (whitened per record as the noise model says) are compressed once by a QR
//! factorisation to a square `R_g` over the group's columns (the column norms and every
//! decision below are those of the rows themselves: the factorisation is orthogonal).
//!
//! **Elimination.** The nuisance columns `E` of a block `[E | K]` (rows of one group, `K` the
//! columns of interest) are taken out with the singular value decomposition of the
//! column-scaled `Ẽ = U·Σ·Vᵀ` (rank `r_E`: the singular values above the identification's
//! tolerance, `σ_max(Ẽ)·max(ρ, max(m, n)·ε)`): what remains of the columns of interest is
//! `(I − U_r·U_rᵀ)·K`, compressed by a QR factorisation to at most `|K|` rows, the square root
//! of the group's Schur complement. `W = Σ_r⁻¹·U_rᵀ·K` is kept as `G = Σ WᵀW`: how far the
//! nuisances move along a direction of the columns of interest, for the null weights below.
//!
//! **A candidate** is one more record: its own group (its own set-up), or a member of a planned
//! group (with a shared set-up, at a planned ball position), whose `R_g` then takes its rows.
//! The plan's other groups enter through their stacked square roots, compressed once; the
//! candidate's prediction is then an SVD of at most `2·|K|` rows by `|K|` columns, scaled by the
//! columns' norms over every row of the plan and the candidate. In exact arithmetic it is the
//! prediction of the whole campaign ([`super::predict()`]):
//!
//! - rank = `Σ r_E` over the groups + the rank of the stacked square roots (tolerance relative
//!   to the largest singular value met, at least 1: the column-scaled H has unit columns);
//! - a parameter of interest is determined iff its null weight in the whole campaign,
//!   `w_j² = e_jᵀ·Z·(I + Zᵀ·G̃·Z)⁻¹·Zᵀ·e_j` (`Z` the null space of the stacked square roots,
//!   `G̃` scaled as they are), is at most τ_d: the null vectors of the campaign are `(−Ẽ⁺·B̃·z,
//!   z)` for `z` in the span of `Z`;
//! - its standard uncertainty is `√(V_r·Σ_r⁻²·V_rᵀ)_jj / s_j` of the whitened system (the
//!   estimable functions have one variance, however the nuisances are eliminated).
//!
//! Memory: the plan's design once, each group's `R_g` (its columns squared) and, per group a
//! candidate can join, the other groups' stacked roots (`|K|²`); a candidate's block (its rows
//! by its columns) while it is evaluated.

use super::PlanError;
use crate::campaign::design::{Design, Owner};
use crate::identify::check_readings;
use crate::least_squares::{EstimateError, Tolerances};
use crate::noise::{NoiseError, NoiseModel};
use nalgebra::{DMatrix, SVD};

/// What the plan with a candidate gives on the parameters of interest.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Rank of the column-scaled H of the plan with the candidate.
    pub rank: usize,
    /// Its columns (parameters).
    pub columns: usize,
    /// Per parameter of interest (in the order of [`Information::interest`]): its predicted
    /// standard uncertainty (mm, rad, ms) when the plan with the candidate determines it.
    pub std: Vec<Option<f64>>,
}

/// The square root of some rows' information in the columns of interest, their nuisance
/// columns eliminated.
#[derive(Clone, Debug)]
struct Reduced {
    /// The square root of the Schur complement (at most `|K|` rows by `|K|`; unscaled).
    root: DMatrix<f64>,
    /// `Σ WᵀW` (`|K|` × `|K|`; unscaled columns).
    leverage: DMatrix<f64>,
    /// Rank of the eliminated columns.
    rank: usize,
    /// The largest singular value of the column-scaled eliminated blocks (0 without).
    sigma_max: f64,
    /// Sum of squares of each column of interest over the rows.
    norms2: Vec<f64>,
}

/// The triangular factor of `a` (at most as many rows as columns), rows beyond it dropped.
fn compress(a: DMatrix<f64>) -> DMatrix<f64> {
    if a.nrows() <= a.ncols() {
        a
    } else {
        a.qr().r()
    }
}

/// `a` on top of `b` (same columns).
fn stack(a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(a.nrows() + b.nrows(), a.ncols());
    out.rows_mut(0, a.nrows()).copy_from(a);
    out.rows_mut(a.nrows(), b.nrows()).copy_from(b);
    out
}

/// The SVD of `a` or the error naming its shape.
fn svd(a: DMatrix<f64>) -> Result<SVD<f64, nalgebra::Dyn, nalgebra::Dyn>, EstimateError> {
    let (m, n) = a.shape();
    SVD::try_new(a, true, true, f64::EPSILON, 1000 + 200 * n).ok_or(EstimateError::Svd(m, n))
}

impl Reduced {
    /// Nothing: no rows.
    fn empty(k: usize) -> Reduced {
        Reduced {
            root: DMatrix::zeros(0, k),
            leverage: DMatrix::zeros(k, k),
            rank: 0,
            sigma_max: 0.0,
            norms2: vec![0.0; k],
        }
    }

    /// The block `a` with its columns' places `kept` (`Some(i)`: column `i` of interest; `None`:
    /// a nuisance, eliminated) of `k` columns of interest; `relative` the rank tolerance
    /// relative to the largest singular value.
    fn eliminate(
        a: &DMatrix<f64>,
        kept: &[Option<usize>],
        k: usize,
        relative: f64,
    ) -> Result<Reduced, EstimateError> {
        let rows = a.nrows();
        let mut b = DMatrix::zeros(rows, k);
        let mut norms2 = vec![0.0; k];
        let nuisance: Vec<usize> = (0..kept.len()).filter(|&c| kept[c].is_none()).collect();
        for (c, place) in kept.iter().enumerate() {
            if let Some(i) = *place {
                let mut col = b.column_mut(i);
                col += a.column(c);
                norms2[i] = col.norm_squared();
            }
        }
        if nuisance.is_empty() || rows == 0 {
            return Ok(Reduced {
                root: compress(b),
                leverage: DMatrix::zeros(k, k),
                rank: 0,
                sigma_max: 0.0,
                norms2,
            });
        }
        let mut e = DMatrix::zeros(rows.max(nuisance.len()), nuisance.len());
        for (c, &j) in nuisance.iter().enumerate() {
            let s = a.column(j).norm();
            let s = if s > 0.0 { s } else { 1.0 };
            e.view_mut((0, c), (rows, 1)).copy_from(&(a.column(j) / s));
        }
        let d = svd(e.clone())?;
        let vt = d
            .v_t
            .as_ref()
            .ok_or(EstimateError::Svd(rows, nuisance.len()))?;
        let sv = &d.singular_values;
        let smax = sv.iter().copied().fold(0.0, f64::max);
        let tau = smax * relative;
        let rank = sv.iter().filter(|&&s| s > tau && s > 0.0).count();
        // The singular values in descending order; those above the tolerance kept.
        let order: Vec<usize> = {
            let mut o: Vec<usize> = (0..sv.len()).collect();
            o.sort_by(|&x, &y| sv[y].total_cmp(&sv[x]));
            o.truncate(rank);
            o
        };
        // An orthonormal basis of the range, U_r = Ẽ·V_r·Σ_r⁻¹ made orthonormal again.
        let vr = DMatrix::from_fn(nuisance.len(), rank, |i, c| vt[(order[c], i)]);
        let mut ur = e.rows(0, rows) * &vr;
        for (c, &o) in order.iter().enumerate() {
            ur.column_mut(c).unscale_mut(sv[o]);
        }
        let ur = if rank > 0 { ur.qr().q() } else { ur };
        // Ẽ⁺·B = V_r·Σ_r⁻²·V_rᵀ·Ẽᵀ·B: how far the nuisances move along each column of interest.
        let mut x = vr.transpose() * (e.rows(0, rows).transpose() * &b);
        for (c, &o) in order.iter().enumerate() {
            x.row_mut(c).unscale_mut(sv[o] * sv[o]);
        }
        let x = &vr * x;
        // Twice: the second pass takes what rounding left of the first.
        let w = ur.transpose() * &b;
        b -= &ur * &w;
        let again = ur.transpose() * &b;
        b -= &ur * &again;
        Ok(Reduced {
            root: compress(b),
            leverage: x.transpose() * x,
            rank,
            sigma_max: smax,
            norms2,
        })
    }

    /// The rows of `parts` together (each with its own nuisances).
    fn join<'a>(k: usize, parts: impl IntoIterator<Item = &'a Reduced>) -> Reduced {
        let mut out = Reduced::empty(k);
        for p in parts {
            out.root = compress(stack(&out.root, &p.root));
            out.leverage += &p.leverage;
            out.rank += p.rank;
            out.sigma_max = out.sigma_max.max(p.sigma_max);
            for (x, y) in out.norms2.iter_mut().zip(&p.norms2) {
                *x += y;
            }
        }
        out
    }
}

/// What the whole campaign of reduced rows gives in the columns of interest.
struct Decision {
    /// Rank of the whole campaign (eliminated columns included).
    rank: usize,
    /// Whether each column of interest is determined.
    determined: Vec<bool>,
    /// `√(V_r·Σ_r⁻²·V_rᵀ)_jj / s_j` per column of interest (unit covariance's root).
    unit_std: Vec<f64>,
}

/// The rank, determination and unit uncertainties of the columns of interest of `r` (see the
/// module documentation); `relative` as in [`Reduced::eliminate`].
fn decide(r: &Reduced, relative: f64, tol: &Tolerances) -> Result<Decision, EstimateError> {
    let k = r.norms2.len();
    if k == 0 {
        return Ok(Decision {
            rank: r.rank,
            determined: Vec::new(),
            unit_std: Vec::new(),
        });
    }
    let s: Vec<f64> = r
        .norms2
        .iter()
        .map(|&x| if x > 0.0 { x.sqrt() } else { 1.0 })
        .collect();
    let rows = r.root.nrows().max(k);
    let mut a = DMatrix::zeros(rows, k);
    for (j, sj) in s.iter().enumerate() {
        let col = r.root.column(j) / *sj;
        a.view_mut((0, j), (r.root.nrows(), 1)).copy_from(&col);
    }
    let d = svd(a)?;
    let vt = d.v_t.ok_or(EstimateError::Svd(rows, k))?;
    let raw = d.singular_values.as_slice();
    let mut order: Vec<usize> = (0..raw.len()).collect();
    order.sort_by(|&x, &y| raw[y].total_cmp(&raw[x]));
    let v = DMatrix::from_fn(k, k, |i, c| vt[(order[c], i)]);
    let sv: Vec<f64> = order.iter().map(|&o| raw[o]).collect();
    let smax = sv.first().copied().unwrap_or(0.0);
    let tau = smax.max(r.sigma_max).max(1.0) * relative;
    let rank = sv.iter().take_while(|&&x| x > tau).count();
    // The campaign's null weights: Z (I + Zᵀ G̃ Z)⁻¹ Zᵀ, G̃ the leverage scaled as A.
    let z = v.columns(rank, k - rank).into_owned();
    let g = DMatrix::from_fn(k, k, |i, j| r.leverage[(i, j)] / (s[i] * s[j]));
    let mut m = z.transpose() * &g * &z;
    for i in 0..m.nrows() {
        m[(i, i)] += 1.0;
    }
    let inv = m
        .clone()
        .cholesky()
        .map(|c| c.inverse())
        .or_else(|| m.try_inverse())
        .ok_or_else(|| {
            EstimateError::NotFinite("the null weights of the plan with a candidate".into())
        })?;
    let projector = &z * inv * z.transpose();
    let determined: Vec<bool> = (0..k)
        .map(|j| projector[(j, j)].max(0.0).sqrt() <= tol.determined)
        .collect();
    let unit_std: Vec<f64> = (0..k)
        .map(|j| {
            let c: f64 = (0..rank).map(|i| (v[(j, i)] / sv[i]).powi(2)).sum();
            c.sqrt() / s[j]
        })
        .collect();
    Ok(Decision {
        rank: r.rank + rank,
        determined,
        unit_std,
    })
}

/// One group of the plan: a set-up and its records, compressed.
#[derive(Clone, Debug)]
struct Group {
    /// The plan's columns the group's rows touch, in the order of `root`'s columns.
    columns: Vec<usize>,
    /// The compressed rows, per system ([`Information::systems`]); empty when no candidate
    /// can join the group.
    root: Vec<DMatrix<f64>>,
    /// Its nuisances eliminated, per system.
    reduced: Vec<Reduced>,
    /// The other groups' reduced rows together, per system (for a candidate that joins this
    /// group); `None` when no candidate can.
    others: Option<Vec<Reduced>>,
}

/// The plan's information in its parameters of interest, made once: every candidate's
/// [`Outcome`] comes from it and the candidate's own rows ([`Information::outcome`]).
#[derive(Clone, Debug)]
pub struct Information {
    /// The plan's columns of interest ([`super::choose::interest`]).
    pub interest: Vec<usize>,
    /// Per plan column, its place among the columns of interest.
    place: Vec<Option<usize>>,
    /// The plan's groups, one per set-up of its layout.
    groups: Vec<Group>,
    /// Every group reduced, together, per system.
    all: Vec<Reduced>,
    /// The plan's layout columns' names and owners.
    names: Vec<String>,
    /// Owners of the plan's columns.
    owners: Vec<Owner>,
    /// The plan's terms and components, to find a candidate's set-up columns in a group.
    terms: Vec<(simulation::model::Term, usize)>,
    /// The set-up labels.
    setups: Vec<String>,
    /// Rows of the plan (3 per sample).
    rows: usize,
    /// The noise model.
    noise: NoiseModel,
    /// σ (mm) of a uniformly white noise model: the whitened system is then the ordinary one
    /// divided by σ, and only the ordinary one is reduced.
    white_sigma: Option<f64>,
    /// The tolerances.
    tol: Tolerances,
}

/// The systems reduced: the ordinary H (rank, determination) and, unless the noise is
/// uniformly white, the whitened one (uncertainties).
fn systems(white_sigma: Option<f64>) -> usize {
    if white_sigma.is_some() { 1 } else { 2 }
}

impl Information {
    /// The information of the plan whose design is `design` in its columns of interest
    /// `interest` (plan columns), under `noise` with `tol`; `joinable[s]` says whether a
    /// candidate may join set-up `s` (a shared set-up at a planned ball position).
    ///
    /// # Errors
    /// A noise model that cannot whiten, an SVD that does not converge.
    pub fn new(
        design: &Design,
        interest: Vec<usize>,
        joinable: &[bool],
        noise: &NoiseModel,
        tol: &Tolerances,
    ) -> Result<Information, PlanError> {
        noise.check().map_err(EstimateError::from)?;
        let layout = &design.layout;
        let n = layout.columns.len();
        let k = interest.len();
        let mut place = vec![None; n];
        for (i, &j) in interest.iter().enumerate() {
            place[j] = Some(i);
        }
        let rows = design.h.nrows();
        let relative = relative(tol, rows, n);
        let white_sigma = noise.is_uniform_white().then(|| noise.sigma_mm[0]);
        let count = systems(white_sigma);
        let mut starts = Vec::with_capacity(layout.records.len());
        let mut at = 0;
        for r in &layout.records {
            starts.push(at);
            at += 3 * r.samples;
        }
        let mut groups = Vec::with_capacity(layout.setups.len());
        for s in 0..layout.setups.len() {
            let members: Vec<usize> = (0..layout.records.len())
                .filter(|&r| layout.records[r].setup == s)
                .collect();
            let mut columns: Vec<usize> = Vec::new();
            for &r in &members {
                for &c in &layout.records[r].columns {
                    if !columns.contains(&c) {
                        columns.push(c);
                    }
                }
            }
            let mut root = vec![DMatrix::zeros(0, columns.len()); count];
            for &r in &members {
                let len = 3 * layout.records[r].samples;
                let mut block = DMatrix::zeros(len, columns.len());
                for (c, &j) in columns.iter().enumerate() {
                    block
                        .column_mut(c)
                        .copy_from(&design.h.view((starts[r], j), (len, 1)));
                }
                if count == 2 {
                    let white = whitened(noise, layout.records[r].samples, &block)?;
                    root[1] = compress(stack(&root[1], &white));
                }
                root[0] = compress(stack(&root[0], &block));
            }
            let kept: Vec<Option<usize>> = columns.iter().map(|&j| place[j]).collect();
            let reduced = root
                .iter()
                .map(|r| Reduced::eliminate(r, &kept, k, relative))
                .collect::<Result<Vec<_>, _>>()?;
            let join = joinable.get(s).copied().unwrap_or(false);
            groups.push(Group {
                columns,
                root: if join { root } else { Vec::new() },
                reduced,
                others: None,
            });
        }
        let all: Vec<Reduced> = (0..count)
            .map(|w| Reduced::join(k, groups.iter().map(|g| &g.reduced[w])))
            .collect();
        for s in 0..groups.len() {
            if joinable.get(s).copied().unwrap_or(false) {
                let others = (0..count)
                    .map(|w| {
                        Reduced::join(
                            k,
                            groups
                                .iter()
                                .enumerate()
                                .filter(|(g, _)| *g != s)
                                .map(|(_, g)| &g.reduced[w]),
                        )
                    })
                    .collect();
                groups[s].others = Some(others);
            }
        }
        Ok(Information {
            interest,
            place,
            groups,
            all,
            names: layout.names(),
            owners: layout.owners(),
            terms: layout
                .columns
                .iter()
                .map(|c| (c.term, c.component))
                .collect(),
            setups: layout.setups.clone(),
            rows,
            noise: noise.clone(),
            white_sigma,
            tol: *tol,
        })
    }

    /// The outcome of the plan with record `k` of the candidates' `batch` design added as one
    /// more record, on the plan's set-up `joins` (its index in the plan's layout) or on a
    /// set-up of its own.
    ///
    /// # Errors
    /// A candidate column the plan's layout does not know, a noise model that cannot whiten, an
    /// SVD that does not converge, whitened and ordinary systems that disagree on the rank or
    /// the determination, a determined uncertainty that is not finite.
    pub fn outcome(
        &self,
        batch: &Design,
        k: usize,
        joins: Option<usize>,
    ) -> Result<Outcome, PlanError> {
        let layout = &batch.layout;
        let record = &layout.records[k];
        let start: usize = 3 * layout.records[..k].iter().map(|r| r.samples).sum::<usize>();
        let len = 3 * record.samples;
        let ki = self.interest.len();
        // The candidate's columns: the plan's (shared; its set-up's when it joins one) or new.
        let group = joins.map(|s| &self.groups[s]);
        let mut columns: Vec<Option<usize>> = Vec::with_capacity(record.columns.len());
        let mut new_columns = 0;
        for &c in &record.columns {
            let col = &layout.columns[c];
            let plan_column = match col.owner {
                Owner::Shared => Some(self.names.iter().position(|n| *n == col.name).ok_or_else(
                    || {
                        EstimateError::Shape(format!(
                            "a candidate's column `{}` is not among the plan's",
                            col.name
                        ))
                    },
                )?),
                Owner::Setup(_) => joins.and_then(|s| {
                    (0..self.names.len()).find(|&j| {
                        self.owners[j] == Owner::Setup(s)
                            && self.terms[j] == (col.term, col.component)
                    })
                }),
                Owner::Record(_) => None,
            };
            if plan_column.is_none() {
                new_columns += 1;
            }
            columns.push(plan_column);
        }
        // The block: the joined group's compressed rows over its columns, then the candidate's
        // rows; the candidate's own columns after the group's.
        let base: Vec<usize> = group.map_or_else(Vec::new, |g| g.columns.clone());
        let mut at: Vec<usize> = Vec::with_capacity(columns.len());
        let mut width = base.len();
        let mut all_columns: Vec<Option<usize>> = base.iter().map(|&j| Some(j)).collect();
        for c in &columns {
            match c.and_then(|j| base.iter().position(|&b| b == j)) {
                Some(p) => at.push(p),
                None => {
                    at.push(width);
                    all_columns.push(*c);
                    width += 1;
                }
            }
        }
        let kept: Vec<Option<usize>> = all_columns
            .iter()
            .map(|c| c.and_then(|j| self.place[j]))
            .collect();
        let mut own = DMatrix::zeros(len, width);
        for (c, &src) in record.columns.iter().enumerate() {
            let mut col = own.column_mut(at[c]);
            col += batch.h.view((start, src), (len, 1));
        }
        let rows = self.rows + len;
        let cols = self.names.len() + new_columns;
        check_readings(rows / 3, cols)?;
        let relative = relative(&self.tol, rows, cols);
        let mut blocks = Vec::with_capacity(2);
        if self.white_sigma.is_none() {
            blocks.push(whitened(&self.noise, record.samples, &own)?);
        }
        blocks.insert(0, own);
        let mut decisions = Vec::with_capacity(2);
        for (w, block) in blocks.into_iter().enumerate() {
            let reduced = match group {
                Some(g) => {
                    let mut joined = DMatrix::zeros(g.root[w].nrows() + len, width);
                    joined
                        .view_mut((0, 0), (g.root[w].nrows(), base.len()))
                        .copy_from(&g.root[w]);
                    joined.rows_mut(g.root[w].nrows(), len).copy_from(&block);
                    let mine = Reduced::eliminate(&joined, &kept, ki, relative)?;
                    let others = g.others.as_ref().ok_or_else(|| {
                        EstimateError::Shape(format!(
                            "a candidate joins set-up `{}`, which takes none",
                            self.setups[joins.unwrap_or(0)]
                        ))
                    })?;
                    Reduced::join(ki, [&others[w], &mine])
                }
                None => {
                    let mine = Reduced::eliminate(&block, &kept, ki, relative)?;
                    Reduced::join(ki, [&self.all[w], &mine])
                }
            };
            decisions.push(decide(&reduced, relative, &self.tol)?);
        }
        let (ordinary, white) = (&decisions[0], &decisions[decisions.len() - 1]);
        if white.rank != ordinary.rank || white.determined != ordinary.determined {
            return Err(EstimateError::from(NoiseError::RankChanged {
                ordinary: ordinary.rank,
                whitened: white.rank,
            })
            .into());
        }
        // A uniformly white model's whitened system is the ordinary one divided by σ.
        let factor = self.white_sigma.unwrap_or(1.0);
        let mut std = Vec::with_capacity(ki);
        for i in 0..ki {
            if !ordinary.determined[i] {
                std.push(None);
                continue;
            }
            let s = white.unit_std[i] * factor;
            if !s.is_finite() {
                return Err(EstimateError::NotFinite(format!(
                    "the predicted uncertainty of `{}` with a candidate",
                    self.names[self.interest[i]]
                ))
                .into());
            }
            std.push(Some(s));
        }
        Ok(Outcome {
            rank: ordinary.rank,
            columns: cols,
            std,
        })
    }
}

/// The rank tolerance relative to the largest singular value, for `rows` rows and `columns`
/// columns (as [`crate::least_squares`] takes it).
fn relative(tol: &Tolerances, rows: usize, columns: usize) -> f64 {
    tol.rank_relative
        .max(rows.max(columns) as f64 * f64::EPSILON)
}

/// `block`, one record of `samples` samples, whitened by `noise`.
fn whitened(
    noise: &NoiseModel,
    samples: usize,
    block: &DMatrix<f64>,
) -> Result<DMatrix<f64>, EstimateError> {
    let mut w = block.clone();
    noise.whiten_matrix(&[samples], &mut w)?;
    Ok(w)
}
