//! The full calibration loop on a full error budget (`seed-ac-budget`), on the exact virtual
//! machine: a five-record campaign at two ball heights diagnosed, identified with the model the
//! diagnosis extends the reduced one to, compensated, and checked on 200 random five-axis poses
//! at a ball position no record had (the study in `full_loop/study.rs`; docs/compensation.md
//! §6, "The full loop on a full budget").
//!
//! `cargo test -p compensation --test all full_loop:: -- --nocapture` prints the figures at noise
//! seeds 1, 2 and 3 (`FULL_LOOP_SEEDS=1,2,3,4,5` for others) and asserts the gate: with the model
//! the diagnosis recommends (its findings and the error groups it confirms) and the new ball's
//! set-up refitted, the machine's own error falls by at least 90 % (92.3–94.7 % at seeds 1–5,
//! docs/compensation.md §6).

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

/// The study at every seed (the seeds on threads of their own: each is a whole campaign's
/// identification, diagnosis and compensation), printed in seed order.
fn studies() -> Vec<study::Study> {
    let studies: Vec<study::Study> = std::thread::scope(|scope| {
        let runs: Vec<_> = seeds()
            .into_iter()
            .map(|seed| scope.spawn(move || study::run(seed)))
            .collect();
        runs.into_iter()
            .map(|r| r.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    for s in &studies {
        eprint!("{}", study::text(s));
    }
    studies
}

/// The loop at every seed (the set-up of the new ball refitted): the reduced model takes at
/// least 75 % of the machine's error, the model the diagnosis recommends at least 90 % (the
/// gate), and the truth's own terms under the minimum-norm constraint at least 98 %.
#[test]
fn the_recommended_model_compensates_ninety_percent_of_the_full_budget() {
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
        assert!(s.recommended, "noise seed {seed}: {}", s.reasons.join("; "));
        assert!(
            extended.fall_refitted() >= 0.9,
            "noise seed {seed}: the recommended model compensates {:.1} % ({:.3} → {:.3} µm)",
            100.0 * extended.fall_refitted(),
            extended.before_um,
            extended.after_refitted_um
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
