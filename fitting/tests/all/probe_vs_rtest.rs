//! The same machine and truth measured with an R-test and with a touch probe: the identified
//! values agree within 3 combined standard uncertainties.

use crate::probe_campaign::{case, identified, sweep};
use fitting::{Constraint, IdentifyOptions, identify};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::generator::{GeneratorOptions, generate_test, tests_with};
use simulation::probe::PreTravel;
use simulation::readings::simulate;

#[test]
fn r_test_and_probe_agree_within_three_combined_std() {
    for name in ["seed-ac", "table-table-bc", "head-table-bc"] {
        let case = case(name);
        let m = &case.m;
        let params = m.default_parameters();
        // The R-test: every test of the machine's generator, one ball set-up, σ 0.5 µm.
        let mut truth = case.truth.clone();
        truth.noise_mm = 0.5e-3;
        truth.seed = 3;
        let opts = GeneratorOptions::default();
        let records: Vec<CampaignRecord> = tests_with(m, &opts.clearance)
            .iter()
            .filter_map(|spec| generate_test(m, spec, &params, &opts).ok())
            .enumerate()
            .map(|(i, path)| {
                truth.seed = 3 + i as u64;
                let r = simulate(m, &truth, &path).unwrap();
                CampaignRecord::new(format!("t{i}"), r, params.clone(), "ball", false)
            })
            .collect();
        assert!(!records.is_empty(), "{name}: no R-test");
        let samples: usize = records.iter().map(|r| r.record.samples.len()).sum();
        let seconds: f64 = records
            .iter()
            .map(|r| r.record.samples.last().map_or(0.0, |s| s.t))
            .sum();
        let poses = sweep(m, 6);
        println!(
            "{name}: R-test {} records, {samples} samples, {seconds:.0} s of paths; probe {} poses, {} hits, {:.0} s",
            records.len(),
            poses.len(),
            9 * poses.len(),
            simulation::probe::run_time_s(poses.len(), 9 * poses.len())
        );
        // The same constraint, its set-up errors named as a campaign of several records names
        // them (`ZOW[ball]`).
        let constraint = match &case.constraint {
            Constraint::Zero(names) => Constraint::Zero(
                names
                    .iter()
                    .map(|n| match n.as_str() {
                        "XOW" | "YOW" | "ZOW" => format!("{n}[ball]"),
                        _ => n.clone(),
                    })
                    .collect(),
            ),
            other => other.clone(),
        };
        let rtest = identify(
            m,
            &case.model,
            &Campaign::new(records).unwrap(),
            &IdentifyOptions::new().constraint(constraint),
        )
        .unwrap();
        let probe = identified(
            &case,
            &sweep(m, 6),
            9,
            PreTravel::default(),
            Default::default(),
        );
        let base = |n: &str| n.split('[').next().unwrap_or(n).to_string();
        let mut compared = 0;
        for (k, n) in probe.fit.names.iter().enumerate() {
            let (Some(vp), Some(sp)) = (probe.fit.values[k], probe.fit.std[k]) else {
                continue;
            };
            let Some(j) = rtest.fit.names.iter().position(|r| base(r) == base(n)) else {
                continue;
            };
            let (Some(vr), Some(sr)) = (rtest.fit.values[j], rtest.fit.std[j]) else {
                continue;
            };
            let z = (vp - vr) / sp.hypot(sr);
            println!("{name} {n}: probe {vp:.6} ± {sp:.6}, R-test {vr:.6} ± {sr:.6}, z {z:.2}");
            assert!(
                z.abs() < 3.0,
                "{name}: {n} probe and R-test {z:.2} combined std apart"
            );
            compared += 1;
        }
        assert!(compared >= 8, "{name}: only {compared} values compared");
    }
}
