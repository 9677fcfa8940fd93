//! A harmonic finding as an engineer reads it: amplitude and phase, with their standard
//! uncertainties propagated from the covariance of the extended fit.
//!
//! With `c` and `s` the cos and sin coefficients (`c·cos kθ + s·sin kθ = A·cos(kθ − φ)`):
//! `A = √(c² + s²)`, `φ = atan2(s, c)`, and to first order
//! `var A = (c²·var c + s²·var s + 2cs·cov) / A²`,
//! `var φ = (s²·var c + c²·var s − 2cs·cov) / A⁴`.

use super::{Diagnosis, Finding};
use model_spec::Machine;
use simulation::model::{Basis, Term};

/// The amplitude and phase of a harmonic finding, in the units people see.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Harmonic {
    /// `√(c² + s²)`, µm or µrad.
    pub amplitude: f64,
    /// Its standard uncertainty, µm or µrad.
    pub amplitude_std: Option<f64>,
    /// `atan2(s, c)`, degrees.
    pub phase_deg: f64,
    /// Its standard uncertainty, degrees.
    pub phase_std_deg: Option<f64>,
}

/// The columns of `term` in the extended fit.
fn columns_of(d: &Diagnosis, term: &Term) -> Vec<usize> {
    let layout = &d.extended_fit.layout;
    (0..layout.columns.len())
        .filter(|&j| layout.columns[j].term == *term)
        .collect()
}

/// Amplitude and phase of a harmonic finding; `None` for other bases or values that are not
/// determined.
pub fn harmonic(m: &Machine, d: &Diagnosis, f: &Finding) -> Option<Harmonic> {
    if !matches!(f.term.basis, Basis::Harmonic(_)) || f.values.len() != 2 {
        return None;
    }
    let k = f.term.display_factor(m);
    let (c, s) = (f.values[0]? * k, f.values[1]? * k);
    let a = c.hypot(s);
    let cols = columns_of(d, &f.term);
    let cov = &d.extended_fit.fit.covariance;
    let (amplitude_std, phase_std_deg) = if cols.len() == 2 && a > 0.0 {
        let (i, j) = (cols[0], cols[1]);
        let (vcc, vss, vcs) = (
            cov[(i, i)] * k * k,
            cov[(j, j)] * k * k,
            cov[(i, j)] * k * k,
        );
        let var_a = (c * c * vcc + s * s * vss + 2.0 * c * s * vcs) / (a * a);
        let var_p = (s * s * vcc + c * c * vss - 2.0 * c * s * vcs) / (a * a * a * a);
        let ok = |v: f64| (v.is_finite() && v >= 0.0).then(|| v.sqrt());
        (ok(var_a), ok(var_p).map(f64::to_degrees))
    } else {
        (None, None)
    };
    Some(Harmonic {
        amplitude: a,
        amplitude_std,
        phase_deg: s.atan2(c).to_degrees(),
        phase_std_deg,
    })
}
