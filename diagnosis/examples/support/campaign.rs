//! The campaign of the diagnosis bench (`diagnose-campaign/budget-five`), shared with the
//! example `diagnose_campaign`.

use formats::truth::builtin_truth;
use model_spec::Machine;
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::paths::builtin_path;
use simulation::readings::simulate;

/// The five records of the campaign bench: (path, noise seed, ball raised) on `seed-ac-budget`,
/// each simulated with the path planned at its ball position and the truth's real parameters
/// moved by as much.
pub fn campaign(m: &Machine) -> Campaign {
    let truth = builtin_truth("seed-ac-budget", m)
        .expect("built in")
        .expect("valid");
    let zw = m.symbol_by_name("Zw").expect("Zw");
    let records = [
        ("K4", 1, false),
        ("K1", 2, false),
        ("K2", 3, false),
        ("K4", 4, true),
        ("K1", 5, true),
    ]
    .into_iter()
    .map(|(path, seed, raised)| {
        let mut params = m.default_parameters();
        let mut t = truth.clone();
        t.seed = seed;
        if raised {
            params[zw] += 50.0;
            t.params[zw] += 50.0;
        }
        let at = formats::campaign::machine_at(m, &params);
        let planned = builtin_path(&at, path).expect("built in").expect("path");
        let record = simulate(&at, &t, &planned).expect("simulate");
        let (label, setup) = if raised {
            (format!("{}-high", path.to_lowercase()), "high")
        } else {
            (path.to_lowercase(), "low")
        };
        CampaignRecord::new(label, record, params, setup, false)
    })
    .collect();
    Campaign::new(records).expect("campaign")
}
