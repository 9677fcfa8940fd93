//! A simulation for people: one line with the path, the truth, the noise and the RMS of the
//! readings per direction (µm).

use super::zeroed_text;
use crate::fitting::validate::statistics;
use crate::record::Record;
use crate::simulation::truth::Truth;
use model_spec::Machine;
use model_spec::units::{fixed, short};

/// `simulated K4 on seed-ac (truth …, noise 0.5 µm, seed 1, not zeroed): 241 samples, RMS of
/// the readings … µm (x …, y …, z …)`.
pub fn simulation(m: &Machine, path: &str, truth: &Truth, record: &Record) -> String {
    let zeros = vec![[0.0; 3]; record.measured.len()];
    let (per, all) = statistics(&record.measured, &zeros);
    let um = |mm: f64| fixed(mm * 1e3, 3);
    format!(
        "simulated {path} on {} (truth {}, noise {} µm, seed {}, {}): {} samples, RMS of the readings {} µm (x {}, y {}, z {})\n",
        m.name,
        truth.source,
        short(truth.noise_mm * 1e3),
        truth.seed,
        zeroed_text(truth.zeroed),
        record.samples.len(),
        um(all.measured_rms),
        um(per[0].measured_rms),
        um(per[1].measured_rms),
        um(per[2].measured_rms),
    )
}
