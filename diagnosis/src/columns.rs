//! The columns the selection works on: the campaign's design matrix of the base model and of
//! every candidate ([`fitting::campaign::design_matrix`]), grouped term by term (a
//! group is every column the campaign gives a term: one set for a machine error, one column
//! per record for a drift of the R-test's zero, one per set-up for a set-up error), and the
//! readings, both whitened: per sample by the covariances of records read through an
//! instrument, then by the noise model.

use super::DiagnoseError;
use super::weights::Weights;
use fitting::campaign::CampaignIdentification;
use fitting::campaign::design::{Layout, columns_in_order, design_matrix, measurements};
use fitting::noise::NoiseModel;
use model_spec::{Dir, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::Campaign;
use simulation::model::{Basis, Effect, Model, Term};

/// The groups of columns of the base model and the candidates, and the readings.
pub(super) struct Columns {
    /// The term of every group: the base model's terms (with the zeroed records' constant zero
    /// offsets), then the candidates.
    pub terms: Vec<Term>,
    /// Number of base groups: group `t < nb` is a base term, group `nb + c` candidate `c`.
    pub nb: usize,
    /// The columns, group after group, as the design gives them (mm per unit).
    pub h_raw: DMatrix<f64>,
    /// The same whitened.
    pub h_all: DMatrix<f64>,
    /// The readings whitened.
    pub y: DVector<f64>,
    /// The first column of every group.
    pub starts: Vec<usize>,
    /// The number of columns of every group.
    pub widths: Vec<usize>,
    /// The design's layout column of every column of `h_raw`.
    pub order: Vec<usize>,
    /// The layout of the base model with every candidate.
    pub layout: Layout,
}

impl Columns {
    /// The columns of `base` (as given) and `candidates` on the records of `c` (outliers left
    /// out), whitened by `weights` and `whitening`. The instrument candidates act on the
    /// displacement, which the design takes from the readings; those carry the very misfit the
    /// selection looks for, so that a gain term would "explain" a share of any residual: their
    /// displacement is the base fit's prediction instead (first order in S all the same).
    ///
    /// # Errors
    /// A design that cannot be built; readings or weights that do not whiten.
    pub fn new(
        m: &Machine,
        base: &Model,
        candidates: &[Term],
        c: &Campaign,
        base_fit: &CampaignIdentification,
        weights: &Weights,
        whitening: &NoiseModel,
    ) -> Result<Columns, DiagnoseError> {
        let mut all = base.clone();
        all.terms.extend(candidates.iter().copied());
        let design = design_matrix(m, &all, c)?;
        let mut y = measurements(c)?;
        let mut h = design.h;
        let predicted = &y - &base_fit.fit.residual;
        for (j, col) in design.layout.columns.iter().enumerate() {
            if let Effect::Instrument {
                reading,
                displacement,
            } = col.term.effect
            {
                let mut column = h.column_mut(j);
                column.fill(0.0);
                for i in 0..predicted.len() / 3 {
                    column[3 * i + reading.index()] = predicted[3 * i + displacement.index()];
                }
            }
        }
        // Groups: the base terms (and the zeroed records' zero offsets), then the candidates.
        let mut terms: Vec<Term> = base.terms.clone();
        if c.records.iter().any(|r| r.zeroed) {
            for d in Dir::ALL {
                let t = Term {
                    effect: Effect::SensorOffset(d),
                    basis: Basis::Const,
                };
                if !terms.contains(&t) {
                    terms.push(t);
                }
            }
        }
        let nb = terms.len();
        terms.extend(candidates.iter().copied());
        let columns: Vec<Vec<usize>> = terms
            .iter()
            .map(|t| {
                (0..design.layout.columns.len())
                    .filter(|&j| design.layout.columns[j].term == *t)
                    .collect()
            })
            .collect();
        let order: Vec<usize> = columns.iter().flatten().copied().collect();
        // The design's own matrix, its columns put in group order (in place when the groups
        // cover every column): the candidates' columns are the bulk of a diagnosis's memory.
        let h_raw = columns_in_order(h, &order);
        let widths: Vec<usize> = columns.iter().map(Vec::len).collect();
        let starts: Vec<usize> = widths
            .iter()
            .scan(0, |s, &w| {
                let a = *s;
                *s += w;
                Some(a)
            })
            .collect();
        let mut h_all = h_raw.clone();
        weights.fitted_matrix(&mut h_all)?;
        weights.fitted_vector(&mut y)?;
        whitening.whiten(&design.rows, &mut h_all, &mut y)?;
        Ok(Columns {
            terms,
            nb,
            h_raw,
            h_all,
            y,
            starts,
            widths,
            order,
            layout: design.layout,
        })
    }

    /// The whitened columns of group `g`.
    pub fn group(&self, g: usize) -> DMatrix<f64> {
        self.h_all
            .columns(self.starts[g], self.widths[g])
            .into_owned()
    }

    /// `true` when group `g` is zero at every sample: the records cannot excite it.
    pub fn unexcited(&self, g: usize) -> bool {
        self.h_raw
            .columns(self.starts[g], self.widths[g])
            .iter()
            .all(|v| v.abs() < 1e-15)
    }

    /// The columns of `groups`, in order: the indices of their columns in `h_raw`.
    pub fn columns_of(&self, groups: &[usize]) -> Vec<usize> {
        groups
            .iter()
            .flat_map(|&g| self.starts[g]..self.starts[g] + self.widths[g])
            .collect()
    }

    /// The rows of record `r` of `h` (the columns `columns` of `h_raw`, weighted or not), with
    /// the columns that belong to it (its owners': shared, its set-up's, its own): what a fit
    /// of that record alone has.
    pub fn record_block(&self, h: &DMatrix<f64>, columns: &[usize], r: usize) -> DMatrix<f64> {
        let rc = &self.layout.records[r];
        let first: usize = self.layout.records[..r].iter().map(|x| 3 * x.samples).sum();
        let own: Vec<usize> = (0..columns.len())
            .filter(|&k| rc.columns.contains(&self.order[columns[k]]))
            .collect();
        h.rows(first, 3 * rc.samples)
            .into_owned()
            .select_columns(&own)
    }

    /// The whitened columns of `term` (any term of the machine, a scanned value of a
    /// candidate's family among them) on the records of `c`, as [`Columns::new`] whitens them.
    ///
    /// # Errors
    /// As [`Columns::new`].
    pub fn term_columns(
        &self,
        m: &Machine,
        term: Term,
        c: &Campaign,
        weights: &Weights,
        whitening: &NoiseModel,
    ) -> Result<DMatrix<f64>, DiagnoseError> {
        let design = design_matrix(m, &Model { terms: vec![term] }, c)?;
        let cols: Vec<usize> = (0..design.layout.columns.len())
            .filter(|&j| design.layout.columns[j].term == term)
            .collect();
        let mut h = design.h.select_columns(&cols);
        weights.fitted_matrix(&mut h)?;
        whitening.whiten_matrix(&design.rows, &mut h)?;
        Ok(h)
    }
}
