//! Identified values made by hand: the compensated errors of a model whose terms have the
//! given values, as `MachineErrors::from_values` reads them from an identification. Shared by
//! the compensation tests and the root package's controller tests.

use compensation::values::MachineErrors;
use fitting::campaign::CampaignValues;
use model_spec::Machine;
use simulation::model::{Model, Term};

/// The compensated errors of `terms` (spelling and value, mm or rad; one value per term, so
/// no two-coefficient bases) on `m`, with the description's default parameters.
pub fn errors_of(m: &Machine, terms: &[(&str, f64)]) -> MachineErrors {
    let model = Model {
        terms: terms
            .iter()
            .map(|(s, _)| Term::parse(m, s).unwrap_or_else(|e| panic!("{s}: {e}")))
            .collect(),
    };
    let values: Vec<Option<f64>> = terms.iter().map(|(_, v)| Some(*v)).collect();
    let id = CampaignValues::of_model(m, &model, &values, "k4", m.default_parameters()).unwrap();
    MachineErrors::from_values(m, &id, "id.json").unwrap().0
}
