//! Diagnosis of the demo truth (scratch, printing everything).
use solver::diagnose::{DiagnoseOptions, diagnose};
use solver::model::Model;
fn main() {
    let m = model_spec::builtin("seed-ac").unwrap().unwrap();
    let name = std::env::args().nth(1).unwrap_or("seed-ac-demo".into());
    let mut truth = solver::truth::load_truth(&name, &m).unwrap();
    let mut rec = vec![];
    for (k, p) in ["K4", "K1", "K2"].iter().enumerate() {
        truth.seed += k as u64;
        let path = solver::paths::builtin_path(&m, p).unwrap().unwrap();
        rec.push((
            p.to_string(),
            solver::simulate::simulate(&m, &truth, &path).unwrap(),
        ));
    }
    let base = Model::of(&m, "reduced").unwrap();
    let t = std::time::Instant::now();
    let d = diagnose(&m, &base, &rec[0].1, &rec[1..], &DiagnoseOptions::default()).unwrap();
    println!(
        "elapsed {:?}, dictionary {}",
        t.elapsed(),
        d.dictionary_size
    );
    for f in &d.findings {
        println!(
            "FOUND {} values {:?} stds {:?} frac {:.3} F {:.1} p {:.2e} {:?} tried {} alts {:?}",
            f.description,
            f.values,
            f.stds,
            f.explained_fraction,
            f.f,
            f.p_value,
            f.correction,
            f.candidates_tried,
            f.alternatives
                .iter()
                .map(|t| t.spelling(&m))
                .collect::<Vec<_>>()
        );
    }
    println!("stop: {:?}", d.stop.reason);
    println!(
        "fit rms {:.3} -> {:.3} µm",
        d.fit_rms.0 * 1e3,
        d.fit_rms.1 * 1e3
    );
    for v in &d.validation {
        println!("{} {:.3} -> {:.3} µm", v.0, v.1 * 1e3, v.2 * 1e3);
    }
    for c in d.structure_before.iter().take(5) {
        println!(
            "before {} {} {} {:.3}",
            c.source, c.shape, c.direction, c.amplitude_um
        );
    }
    for c in d.structure_after.iter().take(3) {
        println!(
            "after {} {} {} {:.3}",
            c.source, c.shape, c.direction, c.amplitude_um
        );
    }
    println!(
        "confounded {}: {:?}",
        d.confounded.len(),
        d.confounded
            .iter()
            .take(8)
            .map(|c| format!(
                "{} ~ {}",
                c.term.spelling(&m),
                c.with
                    .iter()
                    .map(|t| t.spelling(&m))
                    .collect::<Vec<_>>()
                    .join(",")
            ))
            .collect::<Vec<_>>()
    );
    println!("unexcited {}", d.unexcited.len());
}
