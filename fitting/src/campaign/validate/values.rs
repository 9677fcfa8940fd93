//! Identified values as a campaign sees them ([`CampaignValues`]): what validation and
//! compensation take from an identification of one record or several, whether just computed
//! or read from a report; a single record's identification as a campaign of one
//! ([`CampaignIdentification::of_record`]).

use super::super::design::{Layout, Owner, RecordSpec};
use super::super::{CampaignIdentification, RecordFit};
use crate::least_squares::EstimateError;
use model_spec::Machine;
use simulation::model::Model;

/// Identified values as a campaign sees them (one record is a campaign of one): the model, the
/// layout it was fitted with, and per layout column the value and standard uncertainty (mm,
/// rad; `None`: not determined) and what the fit says of it. What validation and compensation
/// take from an identification, whether computed here or read from a report.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignValues {
    /// The model as given (without the zero offsets a zeroed record adds: each record's own
    /// model is in [`Layout::records`]).
    pub model: Model,
    /// The layout of the identification.
    pub layout: Layout,
    /// One value per layout column; `None` where the data did not determine it.
    pub values: Vec<Option<f64>>,
    /// One standard uncertainty per layout column.
    pub std: Vec<Option<f64>>,
    /// Per layout column: whether the data determine it (a parameter fixed by the constraint
    /// counts as determined). Under a `minimum-norm` constraint an undetermined column has a
    /// value: the constraint's choice, not a measurement.
    pub determined: Vec<bool>,
    /// Per layout column: fixed to 0 by the constraint.
    pub fixed: Vec<bool>,
}

impl CampaignValues {
    /// The values of a campaign identification.
    pub fn of(ident: &CampaignIdentification) -> CampaignValues {
        CampaignValues {
            model: ident.model.clone(),
            layout: ident.layout.clone(),
            values: ident.fit.values.clone(),
            std: ident.fit.std.clone(),
            determined: ident.fit.identifiability.determined.clone(),
            fixed: ident.fit.fixed.clone(),
        }
    }

    /// Values of `model` on one record labelled `label` (on a set-up of that label, at
    /// kinematic parameters `params`, mm, not zeroed, on its own clock): `values` one per
    /// column of `model` (mm, rad; `None`: none), determined where given, none fixed, without
    /// uncertainties. Values typed in, or from elsewhere, as an identification of one record
    /// gives them.
    ///
    /// # Errors
    /// A model that does not fit `m`; values that are not one per column; a label that is not
    /// one.
    pub fn of_model(
        m: &Machine,
        model: &Model,
        values: &[Option<f64>],
        label: &str,
        params: Vec<f64>,
    ) -> Result<CampaignValues, EstimateError> {
        simulation::campaign::check_label("record", label)
            .map_err(|e| EstimateError::Shape(e.0))?;
        if values.len() != model.width() {
            return Err(EstimateError::Shape(format!(
                "{} values for the {} columns of the model",
                values.len(),
                model.width()
            )));
        }
        let spec = RecordSpec {
            label: label.into(),
            setup: label.into(),
            params,
            zeroed: false,
            start_s: None,
            samples: 0,
        };
        let layout = Layout::of_records(m, model, &[spec], None)?;
        let at = single_columns(&layout, model)
            .ok_or_else(|| EstimateError::Shape("the record's model has other columns".into()))?;
        let n = layout.columns.len();
        let mut v = CampaignValues {
            model: model.clone(),
            layout,
            values: vec![None; n],
            std: vec![None; n],
            determined: vec![false; n],
            fixed: vec![false; n],
        };
        for (k, x) in values.iter().enumerate() {
            v.values[at[k]] = *x;
            v.determined[at[k]] = x.is_some();
        }
        Ok(v)
    }

    /// The layout columns owned by `owner`, in layout order.
    pub fn columns_of(&self, owner: Owner) -> Vec<usize> {
        (0..self.layout.columns.len())
            .filter(|&j| self.layout.columns[j].owner == owner)
            .collect()
    }
}

impl CampaignIdentification {
    /// The identification of one record (`ident`, e.g. a streamed one) as a campaign of one:
    /// the record labelled `label`, on set-up `label`, at kinematic parameters `params` (mm),
    /// on its own clock; its fit's columns put in layout order and named as a campaign names
    /// them (`XOW[k4]`). Values, uncertainties, residual and statistics are `ident`'s, bit for
    /// bit.
    ///
    /// # Errors
    /// A label that is not one, a model that does not fit `m`, parameters that are not one
    /// per symbol.
    pub fn of_record(
        m: &Machine,
        ident: &crate::Identification,
        label: &str,
        params: Vec<f64>,
    ) -> Result<CampaignIdentification, EstimateError> {
        simulation::campaign::check_label("record", label)
            .map_err(|e| EstimateError::Shape(e.0))?;
        if params.len() != m.symbols.len() {
            return Err(EstimateError::Shape(format!(
                "{} kinematic parameters for the {} symbols of machine {}",
                params.len(),
                m.symbols.len(),
                m.name
            )));
        }
        let model = given_model(&ident.model, ident.zeroed);
        let spec = RecordSpec {
            label: label.into(),
            setup: label.into(),
            params,
            zeroed: ident.zeroed,
            start_s: None,
            samples: ident.samples,
        };
        let layout = Layout::of_records(m, &model, &[spec], None)?;
        let order = single_columns(&layout, &ident.model).ok_or_else(|| {
            EstimateError::Shape(
                "the identification's model and its record's have other columns".into(),
            )
        })?;
        let mut fit = super::super::fit::to_layout_order(ident.fit.clone(), &order);
        fit.names = layout.names();
        let is_offset: Vec<bool> = layout
            .columns
            .iter()
            .map(|c| matches!(c.term.effect, simulation::model::Effect::SensorOffset(_)))
            .collect();
        let swallowed = crate::identifiability::swallowed_by_offsets(
            &fit.names,
            &fit.identifiability.confounded,
            &is_offset,
        );
        let records = vec![RecordFit {
            label: label.into(),
            setup: label.into(),
            samples: ident.samples,
            zeroed: ident.zeroed,
            rss: fit.rss,
        }];
        Ok(CampaignIdentification {
            machine: ident.machine.clone(),
            model,
            layout,
            fit,
            records,
            swallowed,
            backend: ident.backend,
            noise: ident.noise.clone(),
            whitened_sigma: ident.whitened_sigma,
            refinement: None,
        })
    }
}

/// The model as given of a record's `fitted` model: without the constant `dx0 dy0 dz0` when
/// the record is `zeroed` (its layout adds them back).
pub fn given_model(fitted: &Model, zeroed: bool) -> Model {
    if !zeroed {
        return fitted.clone();
    }
    Model {
        terms: fitted
            .terms
            .iter()
            .filter(|t| {
                !(matches!(t.effect, simulation::model::Effect::SensorOffset(_))
                    && t.basis == simulation::model::Basis::Const)
            })
            .copied()
            .collect(),
    }
}

/// For a layout of one record, the layout column of each column of `fitted` (the record's
/// model, its columns matched by term and component, in any order); `None` when the two do
/// not have the same columns.
pub fn single_columns(layout: &Layout, fitted: &Model) -> Option<Vec<usize>> {
    let record = layout.records.first()?;
    if layout.records.len() != 1 || record.model.width() != fitted.width() {
        return None;
    }
    let own = record.model.columns();
    fitted
        .columns()
        .into_iter()
        .map(|(t, k)| {
            let term = fitted.terms[t];
            own.iter()
                .position(|&(u, j)| record.model.terms[u] == term && j == k)
                .map(|p| record.columns[p])
        })
        .collect()
}
