//! Plausibility: a finding is named as a cause only when its size is one a machine can have.
//!
//! A term's **size** is the magnitude of its coefficient: `|v|` for one column, `√(c² + s²)`
//! (the amplitude) for a pair. Every basis of the vocabulary but `rate` is at most 1 in
//! magnitude over the stroke or the revolution, so the size bounds what the term adds anywhere
//! on the machine; a `rate`'s size is a rate (µm/s, µrad/s), with budgets of its own.
//! It is compared with the [`Budget`] of its unit; a larger term fits the data but is not
//! reported as a cause ("fits, but implausible"): a 3756 µrad cubic pitch error of X that
//! explains a step of the C axis is a look-alike, not a finding.

use model_spec::Machine;
use simulation::model::Term;

/// The largest plausible size of a term, per unit (configurable: `rtest diagnose --budget`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Translational errors, sensor offsets and their drifts, µm (default 100).
    pub um: f64,
    /// Angular errors, µrad (default 200).
    pub urad: f64,
    /// Servo lag τ of a velocity term, ms (default 20).
    pub ms: f64,
    /// Instrument gain and cross-talk, a fraction (default 0.1: a gain 10 % off, or a sensor 6°
    /// off its axis; a realistic 5 % must lie well inside, since its estimate scatters around
    /// it).
    pub fraction: f64,
    /// Rates of translational errors and sensor offsets (`rate`), µm/s (default 0.5: 30 µm
    /// per minute; thermal drifts are a few µm per minute at most).
    pub um_per_s: f64,
    /// Rates of angular errors (`rate`), µrad/s (default 1).
    pub urad_per_s: f64,
}

impl Default for Budget {
    fn default() -> Self {
        Budget {
            um: 100.0,
            urad: 200.0,
            ms: 20.0,
            fraction: 0.1,
            um_per_s: 0.5,
            urad_per_s: 1.0,
        }
    }
}

impl Budget {
    /// Parses `um=100,urad=200,ms=20,1=0.1,um/s=0.5,urad/s=1` (any subset; the others keep
    /// their defaults).
    ///
    /// # Errors
    /// A message naming the entry that is not `KEY=VALUE` with a known key and a positive
    /// finite value, or a key given twice.
    pub fn parse(s: &str) -> Result<Budget, String> {
        let mut b = Budget::default();
        let mut seen = Vec::new();
        for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
            let Some((k, v)) = item.split_once('=') else {
                return Err(format!(
                    "`{item}`: expected KEY=VALUE with KEY one of um, urad, ms, 1, um/s, urad/s"
                ));
            };
            let k = k.trim();
            let v: f64 = match v.trim().parse() {
                Ok(v) if f64::is_finite(v) && v > 0.0 => v,
                _ => {
                    return Err(format!("`{item}`: the value must be a positive number"));
                }
            };
            if seen.contains(&k.to_string()) {
                return Err(format!("`{k}` is given twice"));
            }
            seen.push(k.to_string());
            match k {
                "um" => b.um = v,
                "urad" => b.urad = v,
                "ms" => b.ms = v,
                "1" => b.fraction = v,
                "um/s" => b.um_per_s = v,
                "urad/s" => b.urad_per_s = v,
                _ => {
                    return Err(format!(
                        "`{k}`: unknown unit (expected um, urad, ms, 1, um/s or urad/s)"
                    ));
                }
            }
        }
        Ok(b)
    }

    /// The limit for a term of unit `unit` (`um`, `urad`, `ms`, `1`, `um/s`, `urad/s`), in
    /// that unit.
    pub fn limit(&self, unit: &str) -> f64 {
        match unit {
            "urad" => self.urad,
            "ms" => self.ms,
            "1" => self.fraction,
            "um/s" => self.um_per_s,
            "urad/s" => self.urad_per_s,
            _ => self.um,
        }
    }
}

/// Size of a term with `values` (internal units), in the unit people see, and its limit.
pub fn size_and_limit(m: &Machine, term: &Term, values: &[f64], budget: &Budget) -> (f64, f64) {
    let size = values.iter().map(|v| v * v).sum::<f64>().sqrt() * term.display_factor(m);
    (size, budget.limit(term.unit(m)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_budgets() {
        assert_eq!(Budget::parse("").unwrap(), Budget::default());
        let b = Budget::parse("um=50, urad=100,1=0.2").unwrap();
        assert_eq!((b.um, b.urad, b.ms, b.fraction), (50.0, 100.0, 20.0, 0.2));
        assert_eq!(b.limit("urad"), 100.0);
        assert!(Budget::parse("mm=1").unwrap_err().contains("unknown unit"));
        assert!(Budget::parse("um=-1").unwrap_err().contains("positive"));
        assert!(Budget::parse("um=inf").unwrap_err().contains("positive"));
        assert!(Budget::parse("um").unwrap_err().contains("KEY=VALUE"));
        assert!(Budget::parse("um=1,um=2").unwrap_err().contains("twice"));
        let b = Budget::parse("um/s=0.1,urad/s=0.2").unwrap();
        assert_eq!((b.um_per_s, b.urad_per_s, b.um), (0.1, 0.2, 100.0));
        assert_eq!(b.limit("um/s"), 0.1);
        assert_eq!(b.limit("urad/s"), 0.2);
        assert!(
            Budget::parse("mm/s=1")
                .unwrap_err()
                .contains("unknown unit")
        );
    }
}
