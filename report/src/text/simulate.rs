//! A simulation for people: one line with the path, the truth, the noise and the RMS of the
//! readings per direction (µm).

use super::zeroed_text;
use fitting::validate::statistics;
use model_spec::Machine;
use model_spec::units::{UM_PER_MM, fixed, short};
use simulation::record::Record;
use simulation::truth::Truth;

/// `simulated K4 on seed-ac (truth …, noise 0.5 µm, seed 1, not zeroed): 241 samples, RMS of
/// the readings … µm (x …, y …, z …); wrote k4.csv`, one line (`written`: the file, if any).
pub fn simulation(
    m: &Machine,
    path: &str,
    truth: &Truth,
    record: &Record,
    written: Option<&str>,
) -> String {
    let zeros = vec![[0.0; 3]; record.measured.len()];
    let (per, all) = statistics(&record.measured, &zeros);
    let um = |mm: f64| fixed(mm * UM_PER_MM, 3);
    format!(
        "simulated {path} on {} (truth {}, noise {} µm, seed {}, {}): {} samples, RMS of the readings {} µm (x {}, y {}, z {}){}\n",
        m.name,
        truth.source,
        short(truth.noise_mm * UM_PER_MM),
        truth.seed,
        zeroed_text(truth.zeroed),
        record.samples.len(),
        um(all.measured_rms),
        um(per[0].measured_rms),
        um(per[1].measured_rms),
        um(per[2].measured_rms),
        written.map_or(String::new(), |f| format!("; wrote {f}")),
    )
}
