//! Units at the boundaries people see, and the one way numbers are written for them.
//!
//! Inside rtest, lengths and translational errors are in mm and angles in rad. People read
//! translational errors in µm, angular errors in µrad, positions in mm and rotary positions in
//! degrees. The conversion factors live here, and so do the formatters every text report,
//! table and description uses:
//!
//! - [`fixed`]: a fixed number of decimals (`12.3400`), for aligned table columns;
//! - [`readable`]: [`fixed`], or two significant digits in scientific notation when the value
//!   would print as zero (`3.2e-7`), so that a noise-free fit does not claim an exact 0;
//! - [`short`]: at most six decimals with trailing zeros removed (`-217.504`, `45`), for
//!   values given by people (offsets, strokes, poses);
//! - [`p_value`]: a probability (`0.034`, `2.1e-15`, `< 1e-300`).
//!
//! None of them prints a negative zero. Non-finite numbers are written as Rust writes them
//! (`NaN`, `inf`); the reports check for them before they format anything.
//!
//! - [`compact`]: a value as it would be written back, for echoing inputs in messages
//!   (`1e308`, `-2400`, `217.504`).
//!
//! Numbers written to files that are read back use [`exact`]: the shortest decimal that reads
//! back to the same `f64`, µm moved to mm in the decimal text ([`format_scaled`],
//! [`parse_scaled`]), degrees that convert back to the radian command exactly
//! ([`degrees_for`]).

pub mod exact;

pub use exact::{degrees_for, format_scaled, parse_scaled};

/// µm per mm.
pub const UM_PER_MM: f64 = 1e3;
/// µrad per rad.
pub const URAD_PER_RAD: f64 = 1e6;

/// The unit symbol people read for an ASCII unit name: `um` → `µm`, `urad` → `µrad`,
/// `um/s` → `µm/s`, `urad/s` → `µrad/s` (the unit of a `rate` term); any other name unchanged.
pub fn symbol(unit: &str) -> &str {
    match unit {
        "um" => "µm",
        "urad" => "µrad",
        "um/s" => "µm/s",
        "urad/s" => "µrad/s",
        other => other,
    }
}

/// Removes the sign of a formatted zero (`-0.000` → `0.000`).
fn unsigned_zero(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => s,
    }
}

/// `x` with exactly `decimals` decimals, no negative zero (`fixed(-0.00001, 3)` is `0.000`).
pub fn fixed(x: f64, decimals: usize) -> String {
    unsigned_zero(format!("{x:.decimals$}"))
}

/// [`fixed`], except that a non-zero value that would print as zero is written with two
/// significant digits in scientific notation (`readable(3.2e-7, 4)` is `3.2e-7`).
pub fn readable(x: f64, decimals: usize) -> String {
    let limit = 0.5 * 10f64.powi(-(decimals as i32));
    if x != 0.0 && x.abs() < limit {
        return format!("{x:.1e}");
    }
    fixed(x, decimals)
}

/// At most six decimals, trailing zeros and a trailing point removed, no negative zero
/// (`-217.504`, `0`, `45`, `153.601271`).
pub fn short(x: f64) -> String {
    let s = fixed(x, 6);
    if !x.is_finite() {
        return s;
    }
    without_trailing_zeros(&s)
}

/// A fixed-point decimal without its trailing zeros and point, no negative zero (`-0.000` is
/// `0`).
fn without_trailing_zeros(s: &str) -> String {
    match s.trim_end_matches('0').trim_end_matches('.') {
        "" | "-" | "-0" => "0".to_string(),
        s => s.to_string(),
    }
}

/// `suffix` when `n` is not 1 (`format!("{n} reading{}", plural(n, "s"))`), for counts in
/// sentences.
pub fn plural(n: usize, suffix: &str) -> &str {
    if n == 1 { "" } else { suffix }
}

/// A probability for people: three decimals from 0.001 up, two significant digits in
/// scientific notation below, `< 1e-300` for an underflow to zero.
pub fn p_value(p: f64) -> String {
    if p == 0.0 {
        "< 1e-300".into()
    } else if p < 1e-3 {
        format!("{p:.1e}")
    } else {
        format!("{p:.3}")
    }
}

/// A value as it would be written back: the shortest decimal that reads back to `x` when it
/// has at most twelve digits (`1e308`, `-2400`, `1.5e-12`), else six decimals at most from
/// 1e-3 to 1e12 ([`short`]: `0.30000000000000004` is `0.3`), and six significant digits
/// outside ([`significant`]: `-2.5e12`, `1.23457e-7`).
pub fn compact(x: f64) -> String {
    let shortest = format_scaled(x, 0);
    let digits = shortest.bytes().filter(u8::is_ascii_digit).count();
    if digits <= 12 || !x.is_finite() {
        shortest
    } else if (1e-3..1e12).contains(&x.abs()) {
        short(x)
    } else {
        significant(x)
    }
}

/// A number for a message: at most six significant digits, trailing zeros removed, in
/// scientific notation below 1e-4 and from 1e6 on (`0.168855`, `1e-12`, `1e308`,
/// `1.23457e7`, `-2400`, `0`).
///
/// ```
/// use model_spec::units::significant;
/// assert_eq!(significant(1e308), "1e308");
/// assert_eq!(significant(1e-12), "1e-12");
/// assert_eq!(significant(0.16885531), "0.168855");
/// assert_eq!(significant(-2400.0), "-2400");
/// assert_eq!(significant(12_345_678.0), "1.23457e7");
/// assert_eq!(significant(0.0), "0");
/// ```
pub fn significant(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if !x.is_finite() {
        return format!("{x}");
    }
    let exponent = x.abs().log10().floor();
    if !(-4.0..6.0).contains(&exponent) {
        let s = format!("{x:.5e}");
        let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exp}");
    }
    let decimals = (5.0 - exponent).max(0.0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        without_trailing_zeros(&s)
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formatters() {
        assert_eq!(fixed(-0.0000001, 6), "0.000000");
        assert_eq!(fixed(1.25, 1), "1.2");
        assert_eq!(fixed(-3.5, 2), "-3.50");
        assert_eq!(readable(3.2e-7, 4), "3.2e-7");
        assert_eq!(readable(-3.2e-7, 4), "-3.2e-7");
        assert_eq!(readable(0.0, 4), "0.0000");
        assert_eq!(readable(12.34567, 4), "12.3457");
        assert_eq!(readable(0.0004, 3), "4.0e-4");
        assert_eq!(short(-217.504), "-217.504");
        assert_eq!(short(45.0), "45");
        assert_eq!(short(-0.0), "0");
        assert_eq!(short(153.6012714), "153.601271");
        assert_eq!(short(1e-9), "0");
        assert_eq!(p_value(0.0), "< 1e-300");
        assert_eq!(p_value(2.1e-15), "2.1e-15");
        assert_eq!(p_value(0.0341), "0.034");
        assert_eq!(symbol("um"), "µm");
        assert_eq!(symbol("urad"), "µrad");
        assert_eq!(symbol("um/s"), "µm/s");
        assert_eq!(symbol("urad/s"), "µrad/s");
        assert_eq!(symbol("mm"), "mm");
        assert_eq!(compact(1e308), "1e308");
        assert_eq!(compact(-2400.0), "-2400");
        assert_eq!(compact(0.1 + 0.2), "0.3");
        assert_eq!(compact(217.504), "217.504");
    }
}
