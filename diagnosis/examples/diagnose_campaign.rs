//! The campaign diagnosis of the bench `diagnose-campaign/budget-five` (five records of
//! `seed-ac-budget`, none held out), run once: the time of each stage of the diagnosis as it
//! ends and the whole diagnosis's (wall clock, s) on standard error; with `--dump`, the whole
//! `Diagnosis` (its `Debug` form) on standard output, to compare two builds field by field.
//!
//! ```sh
//! /usr/bin/time -f '%U %S %e' cargo run --release -p diagnosis --example diagnose_campaign
//! # The grouped candidates off (DiagnoseOptions::groups; on by default).
//! cargo run --release -p diagnosis --example diagnose_campaign -- --no-groups
//! cargo run --release -p diagnosis --example diagnose_campaign -- --dump > diagnosis.txt
//! ```

#[path = "support/campaign.rs"]
mod campaign;

use diagnosis::{DiagnoseOptions, STAGES, diagnose};
use simulation::campaign::Campaign;
use simulation::model::Model;
use std::cell::RefCell;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(a) = args.iter().find(|a| *a != "--no-groups" && *a != "--dump") {
        eprintln!("diagnose_campaign: unknown argument `{a}` (--no-groups, --dump)");
        std::process::exit(2);
    }
    let options = DiagnoseOptions::default().groups(!args.iter().any(|a| a == "--no-groups"));
    let m = model_spec::builtin("seed-ac")
        .expect("built-in")
        .expect("valid");
    let base = Model::of(&m, "reduced").expect("reduced model");
    let fitted = campaign::campaign(&m);
    let none = Campaign {
        records: Vec::new(),
    };
    // The stage under way and when it began.
    let stage: RefCell<Option<(usize, Instant)>> = RefCell::new(None);
    let end_stage = || {
        if let Some((k, at)) = stage.borrow_mut().take() {
            eprintln!("{:>8.3} s  {}", at.elapsed().as_secs_f64(), STAGES[k]);
        }
    };
    let watch = |what: &str, done: u64, _: u64| {
        if what == "diagnosis" {
            end_stage();
            *stage.borrow_mut() = Some((done as usize, Instant::now()));
        }
    };
    let start = Instant::now();
    let d = diagnose(&m, &base, &fitted, &none, &options, &watch).expect("diagnosis");
    end_stage();
    eprintln!(
        "{:>8.3} s  the diagnosis ({} findings)",
        start.elapsed().as_secs_f64(),
        d.findings.len()
    );
    if args.iter().any(|a| a == "--dump") {
        println!("{d:#?}");
    }
}
