//! The full calibration loop on a full error budget (`seed-ac-budget`), on the exact virtual
//! machine: a five-record campaign at two ball heights diagnosed, identified with the model the
//! diagnosis extends the reduced one to, compensated, and checked on 200 random five-axis poses
//! at a ball position no record had (the study in `full_loop/study.rs`; docs/compensation.md
//! §6, "The full loop on a full budget").
//!
//! `cargo test -p solver --test full_loop -- --nocapture` prints the figures at noise seeds 1,
//! 2 and 3 (`FULL_LOOP_SEEDS=1,2,3,4,5` for others) and asserts what holds today. The gate the
//! loop is meant to meet, 90 % less with the extended model and the new ball's set-up refitted,
//! is the ignored test: it fails (83–89 % at seeds 1–5; with the grouped candidates
//! 84.8–93.3 %; docs/compensation.md §6 says why).

// The example `full_loop` uses the rest of the study (its other investigations).
#[allow(dead_code)]
#[path = "full_loop/study.rs"]
mod study;

/// The noise seeds: `FULL_LOOP_SEEDS` (comma-separated) or 1, 2, 3.
fn seeds() -> Vec<u64> {
    std::env::var("FULL_LOOP_SEEDS")
        .ok()
        .map(|s| {
            s.split(',')
                .map(|x| {
                    x.trim()
                        .parse()
                        .expect("FULL_LOOP_SEEDS: whole numbers ≥ 1")
                })
                .collect()
        })
        .unwrap_or_else(|| vec![1, 2, 3])
}

/// The study at every seed, printed.
fn studies() -> Vec<study::Study> {
    seeds()
        .into_iter()
        .map(|seed| {
            let s = study::run(seed);
            eprint!("{}", study::text(&s));
            s
        })
        .collect()
}

/// What the loop does today, at every seed (the set-up of the new ball refitted): the reduced
/// model takes at least 75 % of the machine's error, the model the diagnosis extends it to at
/// least 65 %, and the truth's own terms under the minimum-norm constraint at least 98 %: the
/// campaign holds what compensation needs, the models are what miss it.
#[test]
fn the_full_loop_on_a_full_budget() {
    for s in studies() {
        let [reduced, extended, _, oracle] = &s.figures[..] else {
            unreachable!("four identifications")
        };
        let seed = s.seed;
        assert!(
            reduced.fall_refitted() >= 0.75,
            "noise seed {seed}: the reduced model compensates {:.1} %",
            100.0 * reduced.fall_refitted()
        );
        assert!(
            extended.fall_refitted() >= 0.65,
            "noise seed {seed}: the extended model compensates {:.1} %",
            100.0 * extended.fall_refitted()
        );
        assert!(
            oracle.fall_refitted() >= 0.98,
            "noise seed {seed}: the truth's terms (minimum norm) compensate {:.1} %",
            100.0 * oracle.fall_refitted()
        );
        // Without the set-up refitted the error is larger: the campaign cannot tell part of
        // the machine's errors from its balls' set-ups.
        assert!(extended.after_um >= extended.after_refitted_um);
    }
}

/// The gate: with the model the diagnosis recommends and the new ball's set-up refitted, the
/// machine's own error falls by at least 90 % at every seed.
#[test]
#[ignore = "not met: 83–89 % at noise seeds 1–5; every selected error group would take 93–95 %, but the records left out in turn do not confirm A's (docs/compensation.md §6)"]
fn the_recommended_model_compensates_ninety_percent_of_the_full_budget() {
    let failed: Vec<String> = studies()
        .iter()
        .filter(|s| s.figures[1].fall_refitted() < 0.9)
        .map(|s| {
            let f = &s.figures[1];
            format!(
                "noise seed {}: {:.1} % less ({:.3} → {:.3} µm)",
                s.seed,
                100.0 * f.fall_refitted(),
                f.before_um,
                f.after_refitted_um
            )
        })
        .collect();
    assert!(
        failed.is_empty(),
        "the recommended model misses 90 %: {}",
        failed.join("; ")
    );
}
