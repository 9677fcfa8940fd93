//! The sections of the report, one module each, and the number formats they share. A section
//! whose report was not given is one line saying so.

pub mod compensation;
pub mod data;
pub mod diagnosis;
pub mod identification;
pub mod machine;
pub mod probe;
pub mod validation;

use model_spec::units::{fixed, readable};

/// The sections in order: (HTML id, heading).
pub const SECTIONS: [(&str, &str); 6] = [
    ("machine", "1. Machine and model"),
    ("data", "2. Data"),
    ("identification", "3. Identified values"),
    ("validation", "4. Validation"),
    ("diagnosis", "5. Diagnosis"),
    ("compensation", "6. Compensation"),
];

/// Decimals that show a value with its uncertainty `std` to two significant digits of the
/// uncertainty (0 to 6); 3 without an uncertainty.
pub fn decimals_for(std: Option<f64>) -> usize {
    match std {
        Some(s) if s > 0.0 && s.is_finite() => (1 - s.log10().floor() as i64).clamp(0, 6) as usize,
        _ => 3,
    }
}

/// `12.34 ± 0.05`, `12.340` (no uncertainty), or `not determined`.
pub fn value_std(value: Option<f64>, std: Option<f64>) -> String {
    match value {
        None => "not determined".into(),
        Some(v) => {
            let d = decimals_for(std);
            match std {
                Some(s) => format!("{} ± {}", readable(v, d), readable(s, d)),
                None => readable(v, d),
            }
        }
    }
}

/// A value in µm (or any unit) with `d` decimals.
pub fn num(x: f64, d: usize) -> String {
    readable(x, d)
}

/// An optional number with `d` decimals, `none` when absent (undetermined).
pub fn opt(x: Option<f64>, d: usize) -> String {
    x.map_or_else(|| "none".into(), |x| fixed(x, d))
}

/// The unit symbol of a report's unit name (`um` → `µm`).
pub fn unit(u: &str) -> &str {
    model_spec::units::symbol(u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_show_two_digits_of_their_uncertainty() {
        assert_eq!(value_std(Some(12.3456), Some(0.052)), "12.346 ± 0.052");
        assert_eq!(value_std(Some(12.3456), Some(1.5)), "12.3 ± 1.5");
        assert_eq!(value_std(Some(-3.0), Some(25.0)), "-3 ± 25");
        assert_eq!(value_std(None, None), "not determined");
        assert_eq!(value_std(Some(1.0), None), "1.000");
    }
}
