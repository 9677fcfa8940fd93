//! The layout of a campaign fit and its design matrix: the records' H matrices stacked, each
//! record's columns placed where its owner's parameters are.
//!
//! **Columns**, in this order:
//!
//! 1. the **shared** columns: every term of the model that is neither a set-up error
//!    (`XOW YOW ZOW`) nor a sensor offset (`dx0 dy0 dz0`), nor, when the records keep their own
//!    clocks, a term of a time basis: the machine's errors, the same in every record; named as
//!    in a single identification (`XOC`, `ECC@harmonic:2:cos`);
//! 2. per **set-up** (in order of first appearance), the model's set-up terms:
//!    `XOW[high]`, `YOW[high]`, …;
//! 3. per **record**, the terms that belong to one recording: the model's sensor-offset terms
//!    (the R-test's zero and its drift, `dz0@time:1[k4]`, are the instrument's state during one
//!    record, whether or not its readings were zeroed), the constant `dx0 dy0 dz0` of a zeroed
//!    record (`dx0[k4]`), and, when the records keep their own clocks, every other term of a
//!    time basis (`XOC@time:1[k4]`: a drift during that record, on its clock).
//!
//! Kinematic offsets ([`crate::offsets`]): a symbol of the workpiece set-up (`Xw Yw
//! Zw`, used only in the offset of the work chain's end) is a set-up term (`Xw[high]`: where
//! that ball was mounted); every other symbol is a length of the machine, shared, and every
//! record must be modelled with the same value of it
//! ([`crate::offsets::check_shared_symbols`]).
//!
//! The time bases are `time:K`, `exp:TAU`, `rate` and `warmup:TAU` ([`super::clock::on_clock`]).
//! With a campaign clock (every record has a start, [`super::clock`]) terms of a time basis
//! other than sensor offsets are shared: one drift over the campaign (`XOC@rate`: one rate of
//! the C axis line; `EXZ@warmup:40`: one warm-up from the campaign's start). On the records'
//! own clocks they are the record's, as a drift of the R-test's zero always is: a `rate` means
//! the same µm/s on a record of 60 s and one of 600 s, so the records' values can be compared,
//! but nothing says the machine drifted alike during both. Instrument terms (`SXX` … `SZY`,
//! the sensor's gains) are shared: one instrument.
//!
//! **Rows**: the records' rows one after the other (three per sample, x y z), in campaign
//! order. Record `r`'s block is the H matrix of its own model (the model with its zero offsets
//! when zeroed, [`RecordColumns::model`]) with the gains at its own kinematic parameters, placed
//! in the columns of its owners; the other columns are zero in its rows.

use super::clock::{on_clock, shifted, span};
use crate::EstimateError;
use crate::hmatrix::{
    Backend, GainSource, check_model, h_matrix, h_matrix_spanned, parameter_name,
};
use crate::identify::with_offsets;
use crate::offsets::{check_shared_symbols, is_setup_symbol};
use model_spec::{ErrorKind, Machine};
use nalgebra::{DMatrix, DVector};
use simulation::campaign::{Campaign, CampaignError, CampaignRecord};
use simulation::model::{Effect, Model, Term};

/// Whose parameter a column is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    /// The machine's: the same in every record.
    Shared,
    /// One set-up's (index into [`Layout::setups`]).
    Setup(usize),
    /// One record's (index into [`Layout::records`]).
    Record(usize),
}

/// One column of a campaign fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// The term.
    pub term: Term,
    /// Which of the term's columns (0, or 1 for the `sin` of a harmonic).
    pub component: usize,
    /// Whose parameter it is.
    pub owner: Owner,
    /// Its name: the single-fit name ([`parameter_name`]) for a shared column, followed by
    /// `[set-up]` or `[record]` for the others (`XOW[high]`, `dx0[k4]`).
    pub name: String,
}

/// One record's part of the layout.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordColumns {
    /// The record's label.
    pub label: String,
    /// Index of its set-up in [`Layout::setups`].
    pub setup: usize,
    /// The model fitted on this record: the campaign's model, with the constant `dx0 dy0 dz0`
    /// appended (those it lacks) when the record is zeroed.
    pub model: Model,
    /// The campaign column of each of `model`'s columns.
    pub columns: Vec<usize>,
    /// The record's kinematic parameters (mm, symbol order).
    pub params: Vec<f64>,
    /// Whether its readings were zeroed at the first sample.
    pub zeroed: bool,
    /// Its start on the campaign clock (s), when the campaign has one.
    pub start_s: Option<f64>,
    /// Its samples.
    pub samples: usize,
}

/// Which column belongs to whom, for a model of a machine on a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Every column, in order (see the module documentation).
    pub columns: Vec<Column>,
    /// The set-up labels, in order of first appearance.
    pub setups: Vec<String>,
    /// Per record, in campaign order.
    pub records: Vec<RecordColumns>,
    /// The campaign clock's span `(T₀, T₁)` (s) when every record has a start; `None`: every
    /// record on its own clock.
    pub clock: Option<(f64, f64)>,
}

/// Who owns a term of the model, before set-ups and records are numbered.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Shared,
    Setup,
    Record,
}

fn kind(m: &Machine, t: &Term, clock: bool) -> Kind {
    match t.effect {
        Effect::SensorOffset(_) => Kind::Record,
        _ if on_clock(t.basis) && !clock => Kind::Record,
        _ if t.basis.jump_at().is_some() => Kind::Record,
        Effect::Error(e) if matches!(m.catalogue[e].kind, ErrorKind::Setup { .. }) => Kind::Setup,
        Effect::KinematicOffset(s) if is_setup_symbol(m, s) => Kind::Setup,
        _ => Kind::Shared,
    }
}

/// What the layout needs of a record: its label, set-up, kinematic parameters, zeroing, start
/// on the campaign clock and number of samples.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordSpec {
    /// The record's label.
    pub label: String,
    /// Its set-up's label.
    pub setup: String,
    /// Its kinematic parameters (mm, symbol order).
    pub params: Vec<f64>,
    /// Whether its readings were zeroed at the first sample.
    pub zeroed: bool,
    /// Its start on the campaign clock (s), if any.
    pub start_s: Option<f64>,
    /// Its samples.
    pub samples: usize,
}

impl RecordSpec {
    /// What the layout needs of the campaign record `r`.
    pub fn of(r: &CampaignRecord) -> RecordSpec {
        RecordSpec {
            label: r.label.clone(),
            setup: r.setup.clone(),
            params: r.params.clone(),
            zeroed: r.zeroed,
            start_s: r.start_s,
            samples: r.record.samples.len(),
        }
    }
}

impl Layout {
    /// The layout of `model` of `m` on `campaign` (checked against `m` first).
    ///
    /// # Errors
    /// A campaign that does not fit `m` ([`Campaign::check`]); a model whose terms do not fit
    /// `m`.
    pub fn new(m: &Machine, model: &Model, campaign: &Campaign) -> Result<Layout, EstimateError> {
        campaign
            .check(m)
            .map_err(|CampaignError(e)| EstimateError::Shape(e))?;
        let clock = span(
            &campaign
                .records
                .iter()
                .map(|r| (&r.record, r.start_s))
                .collect::<Vec<_>>(),
        );
        let specs: Vec<RecordSpec> = campaign.records.iter().map(RecordSpec::of).collect();
        Layout::of_records(m, model, &specs, clock)
    }

    /// The layout of `model` of `m` on records described by `records` (in campaign order), with
    /// the campaign clock `clock` (its span, s) or none: what a report read back rebuilds.
    ///
    /// # Errors
    /// A model whose terms do not fit `m`; a clock without a start on every record; a shared
    /// kinematic offset the records are modelled with at different values
    /// ([`check_shared_symbols`]).
    pub fn of_records(
        m: &Machine,
        model: &Model,
        records: &[RecordSpec],
        clock: Option<(f64, f64)>,
    ) -> Result<Layout, EstimateError> {
        check_model(m, model)?;
        let labelled: Vec<(&str, &[f64])> = records
            .iter()
            .map(|r| (r.label.as_str(), r.params.as_slice()))
            .collect();
        check_shared_symbols(m, model, &labelled).map_err(EstimateError::Shape)?;
        if clock.is_some() && records.iter().any(|r| r.start_s.is_none()) {
            return Err(EstimateError::Shape(
                "a campaign clock needs a start on every record".into(),
            ));
        }
        let mut setups: Vec<String> = Vec::new();
        for r in records {
            if !setups.contains(&r.setup) {
                setups.push(r.setup.clone());
            }
        }
        let on = clock.is_some();
        let mut columns: Vec<Column> = Vec::new();
        let mut push = |t: &Term, owner: Owner, suffix: Option<&str>| {
            for k in 0..t.basis.width() {
                let base = parameter_name(m, t, k);
                columns.push(Column {
                    term: *t,
                    component: k,
                    owner,
                    name: match suffix {
                        Some(s) => format!("{base}[{s}]"),
                        None => base,
                    },
                });
            }
        };
        for t in model
            .terms
            .iter()
            .filter(|t| kind(m, t, on) == Kind::Shared)
        {
            push(t, Owner::Shared, None);
        }
        for (s, label) in setups.iter().enumerate() {
            for t in model.terms.iter().filter(|t| kind(m, t, on) == Kind::Setup) {
                push(t, Owner::Setup(s), Some(label));
            }
        }
        let mut locals = Vec::with_capacity(records.len());
        for (r, rec) in records.iter().enumerate() {
            let local = if rec.zeroed {
                with_offsets(model)
            } else {
                model.clone()
            };
            for t in local
                .terms
                .iter()
                .filter(|t| kind(m, t, on) == Kind::Record)
            {
                push(t, Owner::Record(r), Some(&rec.label));
            }
            let setup = setups.iter().position(|s| *s == rec.setup).unwrap_or(0);
            locals.push((local, setup));
        }
        let find = |t: &Term, k: usize, owner: Owner| {
            columns
                .iter()
                .position(|c| c.term == *t && c.component == k && c.owner == owner)
        };
        let mut out = Vec::with_capacity(locals.len());
        for (r, (local, setup)) in locals.into_iter().enumerate() {
            let mut cols = Vec::with_capacity(local.width());
            for (ti, k) in local.columns() {
                let t = &local.terms[ti];
                let owner = match kind(m, t, on) {
                    Kind::Shared => Owner::Shared,
                    Kind::Setup => Owner::Setup(setup),
                    Kind::Record => Owner::Record(r),
                };
                let c = find(t, k, owner).ok_or_else(|| {
                    EstimateError::Shape(format!(
                        "campaign layout: no column for `{}` of record `{}`",
                        parameter_name(m, t, k),
                        records[r].label
                    ))
                })?;
                cols.push(c);
            }
            let rec = &records[r];
            out.push(RecordColumns {
                label: rec.label.clone(),
                setup,
                model: local,
                columns: cols,
                params: rec.params.clone(),
                zeroed: rec.zeroed,
                start_s: rec.start_s,
                samples: rec.samples,
            });
        }
        Ok(Layout {
            columns,
            setups,
            records: out,
            clock,
        })
    }

    /// Who owns `term` of this layout's machine: shared, its set-up's or its record's (as the
    /// module documentation says), for a record on set-up `setup` and record index `record`.
    pub fn owner_of(&self, m: &Machine, term: &Term, setup: usize, record: usize) -> Owner {
        match kind(m, term, self.clock.is_some()) {
            Kind::Shared => Owner::Shared,
            Kind::Setup => Owner::Setup(setup),
            Kind::Record => Owner::Record(record),
        }
    }

    /// One entry per column: for a kinematic offset, the value of its symbol (mm) its change
    /// is relative to, the kinematic parameter of its owner's records (shared: every record's,
    /// one value; a set-up's: its records'); `None` for every other column.
    pub fn nominal_mm(&self) -> Vec<Option<f64>> {
        self.columns
            .iter()
            .map(|c| {
                let s = c.term.effect.symbol()?;
                let record = match c.owner {
                    Owner::Shared => self.records.first(),
                    Owner::Setup(k) => self.records.iter().find(|r| r.setup == k),
                    Owner::Record(r) => self.records.get(r),
                }?;
                record.params.get(s).copied()
            })
            .collect()
    }

    /// The column names, in order.
    pub fn names(&self) -> Vec<String> {
        self.columns.iter().map(|c| c.name.clone()).collect()
    }

    /// The column owners, in order.
    pub fn owners(&self) -> Vec<Owner> {
        self.columns.iter().map(|c| c.owner).collect()
    }

    /// Samples per record, in campaign order.
    pub fn rows(&self) -> Vec<usize> {
        self.records.iter().map(|r| r.samples).collect()
    }

    /// The owner's label for people: `shared`, the set-up's or the record's label.
    pub fn owner_label(&self, owner: Owner) -> &str {
        match owner {
            Owner::Shared => "shared",
            Owner::Setup(s) => &self.setups[s],
            Owner::Record(r) => &self.records[r].label,
        }
    }

    /// The order in which the columns are solved: record by record, each record's columns in
    /// its model's order, every column at its first appearance (entry `k`: the layout column
    /// solved `k`-th). For one record it is that record's model order, so that a campaign of
    /// one record is solved exactly as a single identification.
    pub fn solve_order(&self) -> Vec<usize> {
        let mut seen = vec![false; self.columns.len()];
        let mut order = Vec::with_capacity(self.columns.len());
        for r in &self.records {
            for &c in &r.columns {
                if !seen[c] {
                    seen[c] = true;
                    order.push(c);
                }
            }
        }
        order.extend((0..self.columns.len()).filter(|&c| !seen[c]));
        order
    }
}

/// The stacked design matrix of a campaign.
#[derive(Clone, Debug)]
pub struct Design {
    /// `H` (3·Σ samples × columns; mm per unit of each parameter: mm/mm, mm/rad, mm/ms, mm).
    pub h: DMatrix<f64>,
    /// Column names ([`Column::name`]).
    pub names: Vec<String>,
    /// Column owners.
    pub owners: Vec<Owner>,
    /// Samples per record, in row order (each record gives three rows per sample).
    pub rows: Vec<usize>,
    /// The layout the matrix follows.
    pub layout: Layout,
    /// Which code computed the gains (mixed when the records' sources differ).
    pub backend: Backend,
}

/// Gain sources, one per distinct set of kinematic parameters.
struct Sources {
    errors: Vec<model_spec::ErrorId>,
    by_params: Vec<(Vec<f64>, GainSource)>,
}

impl Sources {
    fn get(&mut self, m: &Machine, params: &[f64]) -> Result<&mut GainSource, EstimateError> {
        let i = match self.by_params.iter().position(|(p, _)| p == params) {
            Some(i) => i,
            None => {
                let s = GainSource::new(m, &self.errors, params)?;
                self.by_params.push((params.to_vec(), s));
                self.by_params.len() - 1
            }
        };
        Ok(&mut self.by_params[i].1)
    }

    fn backend(&self) -> Backend {
        let mut b = self.by_params.iter().map(|(_, s)| s.backend());
        let first = b.next().unwrap_or(Backend::Evaluator);
        if b.all(|x| x == first) {
            first
        } else {
            Backend::Mixed
        }
    }
}

/// The H matrix of record `r`'s own model (its columns in its model's order), gains at its
/// parameters, time bases on the campaign clock when the layout has one.
fn record_block(
    m: &Machine,
    layout: &Layout,
    r: usize,
    record: &simulation::record::Record,
    source: &mut GainSource,
) -> Result<DMatrix<f64>, EstimateError> {
    let rc = &layout.records[r];
    let clock = layout.clock.zip(rc.start_s);
    block(m, &rc.model, record, source, clock)
}

/// The H matrix of `model` on `record` (columns in the model's order) with gains from `source`;
/// with `clock` (`(span, start)`: the campaign clock's span and the record's start on it, s) the
/// time bases are taken on the campaign clock ([`super::clock`]).
///
/// # Errors
/// As [`h_matrix`].
pub fn block(
    m: &Machine,
    model: &Model,
    record: &simulation::record::Record,
    source: &mut GainSource,
    clock: Option<((f64, f64), f64)>,
) -> Result<DMatrix<f64>, EstimateError> {
    let Some((span, start)) = clock else {
        return Ok(h_matrix(m, model, record, source)?);
    };
    // Time bases on the campaign clock: the record's times moved onto it and normalised over the
    // campaign's span; every other term as usual (velocities from the record itself).
    let (timed, other): (Vec<Term>, Vec<Term>) =
        model.terms.iter().partition(|t| on_clock(t.basis));
    let h_other = h_matrix(m, &Model { terms: other }, record, source)?;
    let h_timed = h_matrix_spanned(
        m,
        &Model { terms: timed },
        &shifted(record, start),
        source,
        Some(span),
    )?;
    let mut h = DMatrix::zeros(h_other.nrows(), model.width());
    let (mut a, mut b) = (0, 0);
    let mut at = 0;
    for t in &model.terms {
        for _ in 0..t.basis.width() {
            if on_clock(t.basis) {
                h.set_column(at, &h_timed.column(b));
                b += 1;
            } else {
                h.set_column(at, &h_other.column(a));
                a += 1;
            }
            at += 1;
        }
    }
    Ok(h)
}

/// The design matrix of `model` of `m` on `campaign` (see the module documentation), with
/// gains from the best [`GainSource`] at each record's kinematic parameters (one source per
/// distinct set). It needs no readings (a planner calls it on bare paths), except for
/// instrument terms, whose columns are readings.
///
/// # Errors
/// A campaign or model that does not fit `m`; a record whose H matrix cannot be built (named).
pub fn design_matrix(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
) -> Result<Design, EstimateError> {
    design_in(m, model, campaign, |layout| {
        (0..layout.columns.len()).collect()
    })
    .map(|(design, _)| design)
}

/// A design's H with its columns in the order they are solved ([`Layout::solve_order`]), and
/// their names.
#[derive(Clone, Debug)]
pub(crate) struct Solved {
    /// H, column `k` the layout column `order[k]`.
    pub(crate) h: DMatrix<f64>,
    /// The columns' names, in that order.
    pub(crate) names: Vec<String>,
    /// Entry `k`: the layout column solved `k`-th.
    pub(crate) order: Vec<usize>,
}

impl Solved {
    /// The columns of `design` copied into solve order, for a caller that keeps the design.
    pub(crate) fn copied(design: &Design) -> Solved {
        let order = design.layout.solve_order();
        Solved {
            h: design.h.select_columns(&order),
            names: order.iter().map(|&c| design.names[c].clone()).collect(),
            order,
        }
    }

    /// The design of `model` on `campaign` for a fit that does not keep it: its H built in
    /// solve order from the start (a campaign of one record is its record's H as computed, no
    /// column moved), and the design without its H (left 0 × 0: the layout, names and rows).
    ///
    /// # Errors
    /// As [`design_matrix`].
    pub(crate) fn design(
        m: &Machine,
        model: &Model,
        campaign: &Campaign,
    ) -> Result<(Design, Solved), EstimateError> {
        let (mut design, order) = design_in(m, model, campaign, Layout::solve_order)?;
        let h = std::mem::replace(&mut design.h, DMatrix::zeros(0, 0));
        let names = order.iter().map(|&c| design.names[c].clone()).collect();
        Ok((design, Solved { h, names, order }))
    }
}

/// [`design_matrix`] with the columns of its H in the order `order` gives for the layout
/// (entry `k`: the layout column put `k`-th), and that order; `names` and `owners` stay in
/// layout order.
fn design_in(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    order: impl FnOnce(&Layout) -> Vec<usize>,
) -> Result<(Design, Vec<usize>), EstimateError> {
    let layout = Layout::new(m, model, campaign)?;
    let mut sources = Sources {
        errors: model.errors(),
        by_params: Vec::new(),
    };
    let rows: usize = 3 * campaign.samples();
    let mut blocks = Vec::with_capacity(campaign.records.len());
    for (r, rec) in campaign.records.iter().enumerate() {
        let source = sources.get(m, &rec.params)?;
        let block = record_block(m, &layout, r, &rec.record, source).map_err(|e| match e {
            EstimateError::HMatrix(e) => {
                EstimateError::Shape(format!("record `{}`: {e}", rec.label))
            }
            other => other,
        })?;
        blocks.push(block);
    }
    let order = order(&layout);
    let h = stack(&layout, blocks, rows, &order);
    let design = Design {
        h,
        names: layout.names(),
        owners: layout.owners(),
        rows: layout.rows(),
        backend: sources.backend(),
        layout,
    };
    Ok((design, order))
}

/// The records' H matrices (`blocks`, each in its record's model order) stacked into one
/// matrix of `rows` rows whose column `k` is layout column `order[k]`: a campaign of one
/// record is its block with the columns put in that order in place (no copy, no pass of zeros;
/// in solve order nothing moves); several records are copied into a zero matrix, each into its
/// own columns.
fn stack(
    layout: &Layout,
    mut blocks: Vec<DMatrix<f64>>,
    rows: usize,
    order: &[usize],
) -> DMatrix<f64> {
    let n = layout.columns.len();
    // Where each layout column goes.
    let mut to = vec![0; n];
    for (k, &c) in order.iter().enumerate() {
        to[c] = k;
    }
    if let (1, [record]) = (blocks.len(), layout.records.as_slice())
        && record.columns.len() == n
    {
        // Column `k` is the block's column `from[k]`.
        let mut from = vec![0; n];
        for (j, &c) in record.columns.iter().enumerate() {
            from[to[c]] = j;
        }
        let mut h = blocks.pop().unwrap_or_else(|| DMatrix::zeros(rows, n));
        permute_columns(&mut h, &from);
        return h;
    }
    let mut h = DMatrix::zeros(rows, n);
    let mut at = 0;
    for (block, record) in blocks.iter().zip(&layout.records) {
        for (j, &c) in record.columns.iter().enumerate() {
            h.view_mut((at, to[c]), (block.nrows(), 1))
                .copy_from(&block.column(j));
        }
        at += block.nrows();
    }
    h
}

/// The columns `order` of `h` (indices of its columns), in that order. When `order` names every
/// column once, they are put in place by swaps of whole columns and `h` is returned, so that a
/// tall H is never held twice; otherwise (a subset, a repeat) they are copied.
pub fn columns_in_order(mut h: DMatrix<f64>, order: &[usize]) -> DMatrix<f64> {
    let n = h.ncols();
    let mut seen = vec![false; n];
    let every_column_once = order.len() == n
        && order
            .iter()
            .all(|&j| j < n && !std::mem::replace(&mut seen[j], true));
    if every_column_once {
        permute_columns(&mut h, order);
        h
    } else {
        h.select_columns(order)
    }
}

/// Puts the columns of `h` in the order `from` says, in place (column `c` becomes the column
/// that was `from[c]`; `from` a permutation of `0..h.ncols()`): by swaps of whole columns, so
/// that a tall H is never held twice.
fn permute_columns(h: &mut DMatrix<f64>, from: &[usize]) {
    let n = h.ncols();
    debug_assert_eq!(from.len(), n);
    // `at[p]`: the original column now at position p; `pos[j]`: where original column j is.
    let mut at: Vec<usize> = (0..n).collect();
    let mut pos: Vec<usize> = (0..n).collect();
    for (c, &j) in from.iter().enumerate() {
        let p = pos[j];
        if p != c {
            h.swap_columns(c, p);
            let k = at[c];
            at[p] = k;
            pos[k] = p;
            at[c] = j;
            pos[j] = c;
        }
    }
}

/// The stacked readings of every record of `campaign` (mm, three rows per sample, records in
/// order).
///
/// # Errors
/// A record without (finite) readings, named.
pub fn measurements(campaign: &Campaign) -> Result<DVector<f64>, EstimateError> {
    let mut out = Vec::with_capacity(3 * campaign.samples());
    for r in &campaign.records {
        let y = crate::measurement_vector(&r.record)
            .map_err(|e| EstimateError::Shape(format!("record `{}`: {e}", r.label)))?;
        out.extend_from_slice(y.as_slice());
    }
    Ok(DVector::from_vec(out))
}

#[cfg(test)]
mod tests {
    use super::{columns_in_order, permute_columns};
    use nalgebra::DMatrix;

    /// A permutation is put in place, a subset or a repeat is copied: the same columns either
    /// way.
    #[test]
    fn columns_in_order_are_the_selected_columns() {
        let h = DMatrix::from_fn(4, 3, |i, j| (10 * i + j) as f64);
        for order in [
            &[2, 0, 1][..],
            &[0, 1, 2],
            &[1, 2],
            &[1, 1, 0],
            &[2, 2, 2, 0],
        ] {
            assert_eq!(
                columns_in_order(h.clone(), order),
                h.select_columns(order),
                "{order:?}"
            );
        }
    }

    /// Every permutation of five columns (120) put in place gives the matrix that
    /// `select_columns` copies, entry for entry.
    #[test]
    fn columns_permuted_in_place_are_the_selected_columns() {
        let h = DMatrix::from_fn(7, 5, |i, j| (10 * i + j) as f64);
        let mut from: Vec<usize> = (0..5).collect();
        let mut count = 0;
        // Heap's algorithm over the orders of `from`.
        let mut c = [0usize; 5];
        let mut check = |from: &[usize]| {
            let mut permuted = h.clone();
            permute_columns(&mut permuted, from);
            assert_eq!(permuted, h.select_columns(from), "order {from:?}");
            count += 1;
        };
        check(&from);
        let mut i = 1;
        while i < 5 {
            if c[i] < i {
                from.swap(if i % 2 == 0 { 0 } else { c[i] }, i);
                check(&from);
                c[i] += 1;
                i = 1;
            } else {
                c[i] = 0;
                i += 1;
            }
        }
        assert_eq!(count, 120);
    }
}
