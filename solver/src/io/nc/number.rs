//! The numbers of NC words: read with the way they are written ([`NumberStyle`]), and written
//! back in that way, at a given number of decimals.
//!
//! A number is `[+|-]digits[.digits]` or `[+|-].digits`: no exponent, no spaces, no
//! parameters. Its style keeps what a control or a person would notice: a `+` sign, the number
//! of decimals, a decimal point without decimals (`X10.`), `.5` without the leading zero, and
//! leading zeros of the integer part (`X010.5`).

use crate::io::poses::MAX_COMMAND;
use model_spec::units::parse_scaled;

/// How an axis word was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NumberStyle {
    /// The letter as written (its case kept).
    pub(crate) letter: u8,
    /// A `+` before a value that is not negative.
    pub(crate) plus: bool,
    /// `0.5` rather than `.5` for a value below 1.
    pub(crate) leading_zero: bool,
    /// A decimal point, even without decimals (`X10.`).
    pub(crate) point: bool,
    /// Digits after the decimal point.
    pub(crate) decimals: usize,
    /// The integer part is padded with zeros to this many digits (0: not padded).
    pub(crate) int_width: usize,
}

/// The value of NC number `text` (of a word of letter `letter`) and its style, `None` when it
/// is not a plain decimal.
pub(crate) fn read_number(letter: u8, text: &str) -> Option<(f64, NumberStyle)> {
    let (plus, body) = match text.as_bytes().first()? {
        b'+' => (true, &text[1..]),
        b'-' => (false, &text[1..]),
        _ => (false, text),
    };
    let (int, frac) = match body.split_once('.') {
        Some((i, f)) => (i, Some(f)),
        None => (body, None),
    };
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if !digits(int)
        || !frac.is_none_or(digits)
        || (int.is_empty() && frac.is_none_or(str::is_empty))
    {
        return None;
    }
    let value = parse_scaled(text, 0)?;
    Some((
        value,
        NumberStyle {
            letter,
            plus,
            leading_zero: !int.is_empty(),
            point: frac.is_some(),
            decimals: frac.map_or(0, str::len),
            int_width: if int.len() > 1 && int.starts_with('0') {
                int.len()
            } else {
                0
            },
        },
    ))
}

/// `x` written in `style` with `decimals` decimals (rounded to nearest), and the value the
/// written text reads back as; `None` when `x` is not finite or its written value is not
/// below [`MAX_COMMAND`] in magnitude. A value that rounds to zero is written without a minus
/// sign.
pub(crate) fn write_number(x: f64, style: &NumberStyle, decimals: usize) -> Option<(String, f64)> {
    if !x.is_finite() {
        return None;
    }
    let digits = format!("{:.*}", decimals, x.abs());
    let (int, frac) = digits.split_once('.').unwrap_or((&digits, ""));
    let zero = digits.bytes().all(|b| b == b'0' || b == b'.');
    let mut out = String::with_capacity(digits.len() + 4);
    if x < 0.0 && !zero {
        out.push('-');
    } else if style.plus {
        out.push('+');
    }
    if int == "0" && !style.leading_zero && decimals > 0 {
        // `.5`: the integer part left out, as the program writes it.
    } else {
        for _ in int.len()..style.int_width {
            out.push('0');
        }
        out.push_str(int);
    }
    if decimals > 0 {
        out.push('.');
        out.push_str(frac);
    } else if style.point {
        out.push('.');
    }
    let value = parse_scaled(&out, 0)?;
    (value.abs() < MAX_COMMAND).then_some((out, value))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(text: &str) -> String {
        let (v, s) = read_number(b'X', text).unwrap();
        write_number(v, &s, s.decimals).unwrap().0
    }

    #[test]
    fn styles_are_kept() {
        for t in [
            "10.5", "+10.5", "-10.5", ".5", "-.5", "+.5", "10.", "10", "0.250", "010.5", "-0",
            "+0.000",
        ] {
            let expected = if t == "-0" { "0" } else { t };
            assert_eq!(round_trip(t), expected, "{t}");
        }
        for t in ["", "+", ".", "1.2.3", "1e5", "#1", "1,5", "- 1", "0x1"] {
            assert!(read_number(b'X', t).is_none(), "{t}");
        }
    }

    #[test]
    fn rounding_and_limits() {
        let (_, s) = read_number(b'X', "+10.000").unwrap();
        assert_eq!(write_number(-0.0004, &s, 3).unwrap().0, "+0.000");
        assert_eq!(write_number(-0.0006, &s, 3).unwrap().0, "-0.001");
        assert_eq!(
            write_number(9.99951, &s, 3).unwrap(),
            ("+10.000".into(), 10.0)
        );
        assert_eq!(write_number(1.25, &s, 5).unwrap().0, "+1.25000");
        assert!(write_number(99_999.999_6, &s, 3).is_none());
        assert!(write_number(f64::NAN, &s, 3).is_none());
        let (_, dot) = read_number(b'X', ".5").unwrap();
        assert_eq!(write_number(1.5, &dot, 1).unwrap().0, "1.5");
        assert_eq!(write_number(0.0, &dot, 0).unwrap().0, "0.");
    }
}
