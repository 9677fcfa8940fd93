//! The seed's experiment replayed on the exact virtual machine (docs/seed-replication.md):
//! `seed-ac` with the seed's Table 3 geometry and a full error budget (`seed-ac-budget`), the
//! reduced model (Table 2) identified on K4 and checked on K1 and K2, and what the reduced model
//! leaves unexplained, attributed to the groups of errors it lacks.
//!
//! Run: `cargo run --release -p fitting --example seed_replication`. Prints Markdown tables.

use fitting::campaign::CampaignValues;
use fitting::refine::RefineOptions;
use fitting::validate::ValidateOptions;
use fitting::{Identification, IdentifyOptions, identify, validate};
use formats::progress::Unwatched;
use formats::truth::builtin_truth;
use model_spec::{ErrorKind, Machine, builtin};
use simulation::campaign::{Campaign, CampaignRecord};
use simulation::model::{Effect, Model};
use simulation::paths::builtin_path;
use simulation::readings::simulate;
use simulation::record::Record;
use simulation::truth::Truth;

/// Per path: name, max |measured| per direction, max |residual| per direction, RMS before and
/// after (µm).
type PathStats = (&'static str, [f64; 3], [f64; 3], f64, f64);
/// A group of the budget: its label and which effects it holds.
type Group<'a> = (&'a str, Box<dyn Fn(Effect) -> bool + 'a>);

struct Run {
    ident: Identification,
    paths: Vec<PathStats>,
}

fn run(m: &Machine, truth: &Truth) -> Run {
    let model = Model::constant(m.model_errors("reduced").unwrap());
    let mut t = truth.clone();
    let mut records = Vec::new();
    for (k, name) in ["K4", "K1", "K2"].into_iter().enumerate() {
        t.seed = truth.seed + k as u64;
        let path = builtin_path(m, name).unwrap().unwrap();
        records.push((name, simulate(m, &t, &path).unwrap()));
    }
    let k4: &Record = &records[0].1;
    let params = m.default_parameters();
    let one = Campaign::of_record(k4.clone(), params.clone(), false);
    let opts = IdentifyOptions::default().refined(RefineOptions::default());
    let fit = identify(m, &model, &one, &opts).unwrap();
    let values = CampaignValues::of(&fit);
    let ident: Identification = fit.single_record(m).unwrap();
    let opts = ValidateOptions::new().exact(true);
    let paths = records
        .iter()
        .map(|(name, rec)| {
            // Each path on K4's ball set-up (the campaign of one's set-up).
            let r = CampaignRecord::new(
                name.to_lowercase(),
                rec.clone(),
                params.clone(),
                "record",
                false,
            );
            let c = Campaign::new(vec![r]).unwrap();
            let v = validate(m, &values, &c, &opts, &Unwatched).unwrap();
            let d = &v.per_direction;
            (
                *name,
                std::array::from_fn(|k| d[k].measured_max * 1e3),
                std::array::from_fn(|k| d[k].residual_max * 1e3),
                v.overall.measured_rms * 1e3,
                v.overall.residual_rms * 1e3,
            )
        })
        .collect();
    Run { ident, paths }
}

/// The truth restricted to the reduced errors plus the terms `keep` accepts; no noise.
fn subset(m: &Machine, truth: &Truth, keep: &dyn Fn(Effect) -> bool) -> Truth {
    let reduced = m.model_errors("reduced").unwrap();
    let mut out = truth.clone();
    out.model.terms.clear();
    out.coefficients.clear();
    let mut at = 0;
    for term in &truth.model.terms {
        let w = term.basis.width();
        let is_reduced = matches!(term.effect, Effect::Error(e) if reduced.contains(&e));
        if is_reduced || keep(term.effect) {
            out.model.terms.push(*term);
            out.coefficients
                .extend_from_slice(&truth.coefficients[at..at + w]);
        }
        at += w;
    }
    out.noise_mm = 0.0;
    out
}

fn main() {
    let m = builtin("seed-ac").unwrap().unwrap();
    let budget = builtin_truth("seed-ac-budget", &m).unwrap().unwrap();
    let full = run(&m, &budget);

    println!("## Deviations, full budget (0.5 µm noise)\n");
    println!(
        "| path | max \\|measured\\| x, y, z (µm) | max \\|residual\\| x, y, z (µm) | RMS before (µm) | RMS after (µm) |"
    );
    println!("|---|---|---|---|---|");
    for (name, meas, res, before, after) in &full.paths {
        println!(
            "| {name} | {:.1}, {:.1}, {:.1} | {:.1}, {:.1}, {:.1} | {before:.2} | {after:.2} |",
            meas[0], meas[1], meas[2], res[0], res[1], res[2]
        );
    }

    println!("\n## Identified reduced errors against the truth (full budget)\n");
    println!("| error | truth | identified ± std | bias / std |");
    println!("|---|---|---|---|");
    for (j, term) in full.ident.model.terms.iter().enumerate() {
        let f = term.effect.display_factor(&m);
        let unit = term
            .effect
            .unit(&m)
            .replace("um", "µm")
            .replace("urad", "µrad");
        let truth = budget
            .model
            .terms
            .iter()
            .position(|t| t == term)
            .and_then(|_| budget.coefficient(term))
            .map_or(0.0, |c| c[0])
            * f;
        let (v, s) = (
            full.ident.fit.values[j].unwrap() * f,
            full.ident.fit.std[j].unwrap() * f,
        );
        println!(
            "| {} | {truth:.1} {unit} | {v:.2} ± {s:.2} | {:.0} |",
            term.effect.name(&m),
            (v - truth) / s
        );
    }
    println!(
        "\nrank {}, condition {:.1}, σ̂ = {:.2} µm (residual RMS on K4)",
        full.ident.fit.rank,
        full.ident.fit.condition.unwrap(),
        full.ident.fit.sigma.unwrap() * 1e3
    );

    println!(
        "\n## What each missing group leaves unexplained (no noise; reduced errors + the group)\n"
    );
    println!(
        "| missing group | K4 max \\|residual\\| (µm) | K1 | K2 | K4 RMS after (µm) | K1 | K2 |"
    );
    println!("|---|---|---|---|---|---|---|");
    let axis_is = |e: Effect, letter: &str| match e {
        Effect::Error(id) => match m.catalogue[id].kind {
            ErrorKind::Component { axis, .. } => m.axes[axis].name == letter,
            _ => false,
        },
        _ => false,
    };
    let groups: Vec<Group> = vec![
        ("none (reduced errors only)", Box::new(|_| false)),
        (
            "linear-axis component errors (18)",
            Box::new(move |e| ["X", "Y", "Z"].iter().any(|l| axis_is(e, l))),
        ),
        (
            "squareness COX AOZ BOZ",
            Box::new(
                |e| matches!(e, Effect::Error(id) if matches!(m.catalogue[id].kind, ErrorKind::Squareness { .. })),
            ),
        ),
        ("A component errors (6)", Box::new(move |e| axis_is(e, "A"))),
        ("C component errors (6)", Box::new(move |e| axis_is(e, "C"))),
        (
            "reading drift dx0, dz0 (rate)",
            Box::new(|e| matches!(e, Effect::SensorOffset(_))),
        ),
        ("everything (no noise)", Box::new(|_| true)),
    ];
    for (label, keep) in &groups {
        let r = run(&m, &subset(&m, &budget, keep.as_ref()));
        let max = |k: usize| r.paths[k].2.iter().fold(0.0f64, |a, &b| a.max(b));
        println!(
            "| {label} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
            max(0),
            max(1),
            max(2),
            r.paths[0].4,
            r.paths[1].4,
            r.paths[2].4
        );
    }
}
