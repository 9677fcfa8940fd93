//! The names a constraint of a campaign of one record may use: the record's own (`XOW`,
//! `dx0`), as a single record's report writes them, besides the campaign's (`XOW[k4]`).

use super::design::{Layout, RecordSpec};
use crate::hmatrix::parameter_name;
use crate::least_squares::Constraint;
use model_spec::Machine;
use simulation::campaign::Campaign;
use simulation::model::Model;

/// The constraint of a fit of `campaign`: as given, except that a campaign of one record also
/// takes the names its report writes (`dx0`, `XOW`) for the columns of its record and set-up
/// (`dx0[k4]`, `XOW[k4]`), so that one record is constrained as a single identification always
/// was. A name that is neither stays as it is (the fit names it as unknown).
pub fn single_record_names(
    m: &Machine,
    model: &Model,
    campaign: &Campaign,
    constraint: Constraint,
) -> Constraint {
    let Constraint::Zero(names) = constraint else {
        return constraint;
    };
    let [r] = campaign.records.as_slice() else {
        return Constraint::Zero(names);
    };
    let spec = RecordSpec::of(r);
    let Ok(layout) = Layout::of_records(m, model, &[spec], None) else {
        return Constraint::Zero(names);
    };
    let canonical = |z: &str| match z.trim().split_once('@') {
        Some((e, b)) => format!("{}@{b}", model_spec::canonical_name(e)),
        None => model_spec::canonical_name(z.trim()),
    };
    Constraint::Zero(
        names
            .into_iter()
            .map(|z| {
                if layout.columns.iter().any(|c| c.name == z.trim()) {
                    return z;
                }
                let want = canonical(&z);
                layout
                    .columns
                    .iter()
                    .find(|c| {
                        let bare = parameter_name(m, &c.term, c.component);
                        bare == z.trim() || bare == want
                    })
                    .map_or(z, |c| c.name.clone())
            })
            .collect(),
    )
}
