//! Identified values predict other records, each with its own set-up.
//!
//! For every parameter of a validation record's own model (the model with its zero offsets
//! when its readings were zeroed):
//!
//! - **shared** (the machine's errors): the identified value; for a kinematic offset of the
//!   machine (`Zt`) the identified length minus the record's value of the symbol (the change
//!   when the record is modelled with the identification's value);
//! - **set-up** (`XOW YOW ZOW`, and the changes of the ball's position `Xw Yw Zw` when the
//!   model has them): the identified values of its set-up when that set-up was
//!   fitted (the same set-up label: the same ball mounting); otherwise they are **refitted** on
//!   the record itself, with every other value held: a ball set up anew has new set-up errors,
//!   which no identification knows;
//! - **record** (its R-test zero `dx0 dy0 dz0` when zeroed, the drift of its zero, and, on own
//!   clocks, its terms of a time basis): the identified values when the record was fitted (the
//!   same record label), else **refitted** alike: they are the state of one recording. A jump
//!   (`ZOW@jump:149.5`, [`model_spec::basis::Basis::Jump`]) is the exception: an event of the
//!   fitted record it was found on, it is left out of a record that was not fitted.
//!
//! A parameter without a value (not determined by the identification) is set to 0 and named
//! ([`crate::validate::Unidentified`], as for a single record). The refit is least
//! squares on the refitted columns of the record's H matrix (first order; each sample weighted
//! by its covariance when the record was read through an instrument), refined against the
//! exact machine by Gauss–Newton when the prediction is exact; the prediction then uses the
//! refitted values (the minimum-norm solution for those the record cannot separate, which
//! predicts the record as any other solution would). The residual of a refitted record is
//! after those parameters were fitted on it: its RMS is smaller than an independent
//! prediction's by about `√(1 − k/3N)` for `k` refitted parameters, and the report says which
//! were refitted.

mod refit;
mod values;

pub(crate) use refit::refit_held;

pub use values::{CampaignValues, given_model, single_columns};

use super::clock::own_clock_terms;
use super::design::{Owner, block};
use crate::hmatrix::{GainSource, check_model, parameter_name};
use crate::identify::with_offsets;
use crate::measurement_vector;
use crate::refine::{IdentifyError, exact_prediction};
use crate::validate::{
    Stats, Unidentified, ValidateError, ValidateOptions, Validation, statistics,
};
use formats::progress::Progress;
use model_spec::Machine;
use nalgebra::{DMatrix, DVector};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Model, Term};

/// A parameter refitted on a validation record.
#[derive(Clone, Debug, PartialEq)]
pub struct Refitted {
    /// Its name (`XOW[new]`, `dx0[k1]`).
    pub name: String,
    /// Its term.
    pub term: Term,
    /// Which of the term's columns.
    pub component: usize,
    /// Its value on the record (mm, rad); `None` when the record cannot separate it.
    pub value: Option<f64>,
    /// Its standard uncertainty.
    pub std: Option<f64>,
}

/// One validation record's result.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordValidation {
    /// The record's label.
    pub label: String,
    /// Its set-up's label.
    pub setup: String,
    /// Whether its set-up was fitted by the identification (its set-up values came from it).
    pub setup_fitted: bool,
    /// Whether the record itself was fitted (its own values came from the identification).
    pub record_fitted: bool,
    /// Whether its readings were zeroed at the first sample (its own `dx0 dy0 dz0` in its
    /// model).
    pub zeroed: bool,
    /// The parameters refitted on the record (none when every value came from the
    /// identification).
    pub refitted: Vec<Refitted>,
    /// The prediction and its residual statistics.
    pub validation: Validation,
}

/// A validation on every record of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignValidation {
    /// Per record, in campaign order.
    pub records: Vec<RecordValidation>,
    /// Statistics over every record's readings, per direction x, y, z.
    pub per_direction: [Stats; 3],
    /// Statistics over every record's readings.
    pub overall: Stats,
}

/// Validates `values` on every record of `campaign` (a record is a campaign of one; see the
/// module documentation): `opts.exact` and `opts.unidentified` apply, the records carry their
/// own zeroing and parameters; the records validated are reported to `progress` (one unit per
/// record; [`formats::progress::Unwatched`] when nobody watches).
///
/// # Errors
/// As [`validate_record`].
pub fn validate(
    m: &Machine,
    values: &CampaignValues,
    campaign: &Campaign,
    opts: &ValidateOptions,
    progress: &dyn Progress,
) -> Result<CampaignValidation, ValidateError> {
    campaign.check(m).map_err(|e| ValidateError::Shape(e.0))?;
    let mut records = Vec::with_capacity(campaign.records.len());
    let total = campaign.records.len() as u64;
    for (i, r) in campaign.records.iter().enumerate() {
        progress.update("validating records", i as u64, total);
        records.push(validate_record(m, values, r, opts)?);
    }
    progress.update("validating records", total, total);
    Ok(CampaignValidation::of(&campaign.records, records))
}

impl CampaignValidation {
    /// The validation of the records `measured` (in order) by their `records`' predictions,
    /// with the statistics over all of them.
    pub(crate) fn of(measured: &[CampaignRecord], records: Vec<RecordValidation>) -> Self {
        let m: Vec<[f64; 3]> = measured
            .iter()
            .flat_map(|r| r.record.measured.iter().copied())
            .collect();
        let p: Vec<[f64; 3]> = records
            .iter()
            .flat_map(|r| r.validation.prediction.iter().copied())
            .collect();
        let (per_direction, overall) = statistics(&m, &p);
        CampaignValidation {
            records,
            per_direction,
            overall,
        }
    }
}

/// How a validation record's own model takes its values: the model (with the record's zero
/// offsets when zeroed), per column the identification's layout column it takes its value
/// from (`None`: refitted on the record) and its name, whether its set-up and the record itself
/// were fitted, and the campaign clock `(span, start)` its time bases run on.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordPlan {
    /// The record's own model.
    pub model: Model,
    /// Per column: the identification's layout column, or `None` (refitted).
    pub sources: Vec<Option<usize>>,
    /// Per column: its name (`XOC`, `XOW[b]`, `dx0[k1]`).
    pub names: Vec<String>,
    /// Index of the record's set-up among the identification's, if fitted.
    pub setup: Option<usize>,
    /// Index of the record among the identification's, if fitted.
    pub fitted: Option<usize>,
    /// The campaign clock's span and the record's start on it, when the identification has one.
    pub clock: Option<((f64, f64), f64)>,
}

/// The plan of record `r` under `values` (see [`RecordPlan`]).
///
/// # Errors
/// Values that do not match the layout or are not finite; a record on a fitted set-up with
/// other kinematic parameters; time terms on the campaign clock and a record without a start;
/// a model that does not fit `m`.
pub fn record_plan(
    m: &Machine,
    values: &CampaignValues,
    r: &CampaignRecord,
) -> Result<RecordPlan, ValidateError> {
    let layout = &values.layout;
    if values.values.len() != layout.columns.len() {
        return Err(ValidateError::Shape(format!(
            "{} values for the {} columns of the identification",
            values.values.len(),
            layout.columns.len()
        )));
    }
    if let Some(j) =
        (0..values.values.len()).find(|&j| values.values[j].is_some_and(|x| !x.is_finite()))
    {
        return Err(ValidateError::Shape(format!(
            "the value of `{}` is not finite",
            layout.columns[j].name
        )));
    }
    let setup = layout.setups.iter().position(|s| *s == r.setup);
    let fitted = layout.records.iter().position(|x| x.label == r.label);
    if let Some(s) = setup
        && let Some(f) = layout.records.iter().find(|x| x.setup == s)
        && !f.params.is_empty()
        && f.params != r.params
    {
        return Err(ValidateError::Shape(format!(
            "record `{}` is on set-up `{}`, which was fitted with other kinematic parameters (record `{}`): one ball set-up has one position; give the record another set-up label",
            r.label, r.setup, f.label
        )));
    }
    let clock = match (layout.clock, r.start_s) {
        (Some(span), Some(start)) => Some((span, start)),
        (Some(_), None)
            if values
                .model
                .terms
                .iter()
                .any(|t| super::clock::on_clock(t.basis)) =>
        {
            return Err(ValidateError::Shape(format!(
                "record `{}` has no start on the campaign clock, but the identification's time terms are on it: give the record a start (`start` in a campaign file)",
                r.label
            )));
        }
        _ => None,
    };
    let mut model = if r.zeroed {
        with_offsets(&values.model)
    } else {
        values.model.clone()
    };
    // A jump is an event of the fitted record it was found on: a record that was not fitted is
    // predicted without it, not refitted.
    if fitted.is_none() {
        model.terms.retain(|t| t.basis.jump_at().is_none());
    }
    check_model(m, &model)?;
    let mut sources = Vec::with_capacity(model.width());
    let mut names = Vec::with_capacity(model.width());
    for (ti, k) in model.columns() {
        let t = &model.terms[ti];
        let owner = layout.owner_of(
            m,
            t,
            setup.unwrap_or(usize::MAX),
            fitted.unwrap_or(usize::MAX),
        );
        let base = parameter_name(m, t, k);
        let known = |o: Owner| {
            layout
                .columns
                .iter()
                .position(|c| c.term == *t && c.component == k && c.owner == o)
        };
        let (source, name) = match owner {
            Owner::Shared => match known(Owner::Shared) {
                Some(c) => (Some(c), base),
                None => {
                    return Err(ValidateError::Shape(format!(
                        "the identification has no shared value for `{base}`"
                    )));
                }
            },
            Owner::Setup(s) => (
                (s != usize::MAX).then(|| known(Owner::Setup(s))).flatten(),
                format!("{base}[{}]", r.setup),
            ),
            Owner::Record(x) => (
                (x != usize::MAX).then(|| known(Owner::Record(x))).flatten(),
                format!("{base}[{}]", r.label),
            ),
        };
        sources.push(source);
        names.push(name);
    }
    Ok(RecordPlan {
        model,
        sources,
        names,
        setup,
        fitted,
        clock,
    })
}

/// A validation record made ready for its refit: its plan, its columns' values from the
/// identification (mm, rad: the refitted ones 0 until refitted), its H matrix and readings.
pub(crate) struct Prepared<'a> {
    /// The record.
    pub r: &'a CampaignRecord,
    /// Its plan.
    pub plan: RecordPlan,
    /// Per column its value (mm, rad).
    pub v: Vec<f64>,
    /// The identification's parameters without a value (set to 0), as its report names them.
    pub defaulted: Vec<String>,
    /// The record's H matrix (mm per unit of each column).
    pub h: DMatrix<f64>,
    /// Its readings (mm).
    pub y: DVector<f64>,
}

/// Record `r` made ready under `values` (see [`Prepared`]).
///
/// # Errors
/// As [`record_plan`]; readings missing; parameters without a value under
/// [`Unidentified::Refuse`].
pub(crate) fn prepare<'a>(
    m: &Machine,
    values: &CampaignValues,
    r: &'a CampaignRecord,
    opts: &ValidateOptions,
) -> Result<Prepared<'a>, ValidateError> {
    let layout = &values.layout;
    let plan = record_plan(m, values, r)?;
    let mut defaulted = Vec::new();
    let mut v = vec![0.0; plan.sources.len()];
    let nominal = layout.nominal_mm();
    // The identification's columns named as its report names them: a record's as a single fit
    // does (`XOW`), a campaign's with their owners (`XOW[k4]`).
    let report_name = |c: usize| -> String {
        let col = &layout.columns[c];
        if layout.records.len() == 1 {
            parameter_name(m, &col.term, col.component)
        } else {
            col.name.clone()
        }
    };
    for (k, s) in plan.sources.iter().enumerate() {
        if let Some(c) = s {
            match values.values[*c] {
                Some(x) => v[k] = x,
                None => defaulted.push(report_name(*c)),
            }
            // A kinematic offset's value is a change from the identification's value of its
            // symbol: on a record modelled with another value it is the identified length
            // minus the record's.
            if let (Some(sym), Some(n)) = (layout.columns[*c].term.effect.symbol(), nominal[*c]) {
                v[k] += n - r.params[sym];
            }
        }
    }
    if !defaulted.is_empty() && opts.unidentified == Unidentified::Refuse {
        return Err(ValidateError::Unidentified(defaulted));
    }
    let rec = &r.record;
    if rec.samples.is_empty() {
        return Err(ValidateError::Shape(format!(
            "record `{}` has no samples",
            r.label
        )));
    }
    let y = measurement_vector(rec)?;
    let mut source = GainSource::new(m, &plan.model.errors(), &r.params)?;
    let h =
        block(m, &plan.model, rec, &mut source, plan.clock).map_err(ValidateError::Measurements)?;
    Ok(Prepared {
        r,
        plan,
        v,
        defaulted,
        h,
        y,
    })
}

impl Prepared<'_> {
    /// The record's readings predicted with every column at `x` (mm, rad; one per reading):
    /// the exact machine's, or `H·x` when `exact` is false.
    ///
    /// # Errors
    /// An exact prediction that fails.
    pub(crate) fn predict(
        &self,
        m: &Machine,
        x: &[f64],
        exact: bool,
    ) -> Result<DVector<f64>, IdentifyError> {
        if !exact {
            return Ok(&self.h * DVector::from_column_slice(x));
        }
        let (rec, model) = (&self.r.record, &self.plan.model);
        let p = match self.plan.clock {
            Some((span, start)) => {
                let (own, coef) = own_clock_terms(model, x, rec, start, span);
                let c: Vec<Option<f64>> = coef.into_iter().map(Some).collect();
                exact_prediction(m, &own, &c, rec, &self.r.params)?
            }
            None => {
                let c: Vec<Option<f64>> = x.iter().copied().map(Some).collect();
                exact_prediction(m, model, &c, rec, &self.r.params)?
            }
        };
        Ok(DVector::from_iterator(
            self.y.len(),
            p.iter().flat_map(|q| q.iter().copied()),
        ))
    }

    /// A failure of this record's refit or prediction, naming the record.
    pub(crate) fn failed(&self, e: IdentifyError) -> ValidateError {
        ValidateError::Shape(format!("record `{}`: {e}", self.r.label))
    }

    /// The largest coordinate of the record's parameters and commands (mm, at least 1): the
    /// scale of the exact prediction's rounding.
    pub(crate) fn coordinates(&self) -> f64 {
        self.r
            .params
            .iter()
            .chain(self.r.record.samples.iter().flat_map(|s| s.commands.iter()))
            .fold(1.0f64, |a, x| a.max(x.abs()))
    }

    /// The parameter `k` refitted to `value ± std`.
    pub(crate) fn refitted(&self, k: usize, value: Option<f64>, std: Option<f64>) -> Refitted {
        let (ti, c) = self.plan.model.columns()[k];
        Refitted {
            name: self.plan.names[k].clone(),
            term: self.plan.model.terms[ti],
            component: c,
            value,
            std,
        }
    }

    /// The record's validation with every column at `v` (mm, rad) and the parameters
    /// `refitted` on it.
    ///
    /// # Errors
    /// An exact prediction that fails.
    pub(crate) fn finish(
        &self,
        m: &Machine,
        v: &[f64],
        refitted: Vec<Refitted>,
        exact: bool,
    ) -> Result<RecordValidation, ValidateError> {
        let p = self.predict(m, v, exact).map_err(|e| self.failed(e))?;
        let prediction: Vec<[f64; 3]> = p
            .as_slice()
            .chunks_exact(3)
            .map(|q| [q[0], q[1], q[2]])
            .collect();
        let measured: Vec<[f64; 3]> = self.r.record.measured.clone();
        let residual = measured
            .iter()
            .zip(&prediction)
            .map(|(a, b)| std::array::from_fn(|d| a[d] - b[d]))
            .collect();
        let (per_direction, overall) = statistics(&measured, &prediction);
        Ok(RecordValidation {
            label: self.r.label.clone(),
            setup: self.r.setup.clone(),
            setup_fitted: self.plan.setup.is_some(),
            record_fitted: self.plan.fitted.is_some(),
            zeroed: self.r.zeroed,
            refitted,
            validation: Validation {
                samples: self.r.record.samples.len(),
                prediction,
                residual,
                per_direction,
                overall,
                defaulted: self.defaulted.clone(),
                zeroed: false,
            },
        })
    }
}

/// Validates `values` on one record `r` (see the module documentation).
///
/// # Errors
/// As [`record_plan`]; readings missing; parameters without a value under
/// [`Unidentified::Refuse`]; a refit or an exact prediction that fails.
pub fn validate_record(
    m: &Machine,
    values: &CampaignValues,
    r: &CampaignRecord,
    opts: &ValidateOptions,
) -> Result<RecordValidation, ValidateError> {
    let prepared = [prepare(m, values, r, opts)?];
    let what = format!("record `{}`", r.label);
    let p = &prepared[0];
    match refit_held(m, &prepared, &[], opts.exact, &what)? {
        None => p.finish(m, &p.v, Vec::new(), opts.exact),
        Some(f) => {
            let v = f.values(&prepared, &f.fit.solution).swap_remove(0);
            p.finish(m, &v, f.refitted(&prepared, 0, 1.0), opts.exact)
        }
    }
}
