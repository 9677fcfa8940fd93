//! The numbers of NC words: read with the way they are written ([`NumberStyle`]), and written
//! back in that way, at a given number of decimals.
//!
//! A number is `[+|-]digits[.digits]` or `[+|-].digits`: no exponent, no spaces, no
//! parameters. Its style keeps what a control or a person would notice: a `+` sign, the number
//! of decimals, a decimal point without decimals (`X10.`), `.5` without the leading zero, and
//! leading zeros of the integer part (`X010.5`).

use crate::poses::MAX_COMMAND;
use std::fmt::Write;

/// How an axis word was written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NumberStyle {
    /// The letter as written (its case kept).
    pub letter: u8,
    /// A `+` before a value that is not negative.
    pub plus: bool,
    /// `0.5` rather than `.5` for a value below 1.
    pub leading_zero: bool,
    /// A decimal point, even without decimals (`X10.`).
    pub point: bool,
    /// Digits after the decimal point.
    pub decimals: usize,
    /// The integer part is padded with zeros to this many digits (0: not padded).
    pub int_width: usize,
}

/// The most decimals of a word read: far beyond any control (four or five), short enough to be
/// written back on the stack.
pub const MAX_WORD_DECIMALS: usize = 40;

/// The value of NC number `text` (of a word of letter `letter`) and its style, `None` when it
/// is not a plain decimal.
pub fn read_number(letter: u8, text: &str) -> Option<(f64, NumberStyle)> {
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
        || frac.is_some_and(|f| f.len() > MAX_WORD_DECIMALS)
    {
        return None;
    }
    // A plain decimal without exponent: Rust's parser rounds it once, to nearest.
    let value: f64 = text.parse().ok()?;
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

/// Appends `x` written in `style` with `decimals` decimals (rounded to nearest) to `out`, and
/// gives the value the written text reads back as; `None` (and `out` as it was) when `x` is not
/// finite or its written value is not below [`MAX_COMMAND`] in magnitude. A value that rounds
/// to zero is written without a minus sign.
pub fn write_number(out: &mut String, x: f64, style: &NumberStyle, decimals: usize) -> Option<f64> {
    if !x.is_finite() || x.abs() >= 2.0 * MAX_COMMAND {
        return None;
    }
    let mark = out.len();
    // The digits of |x|, at most 6 + 1 + decimals characters here.
    let mut digits = Digits::default();
    write!(digits, "{:.*}", decimals, x.abs()).ok()?;
    let digits = digits.as_str();
    let (int, frac) = digits.split_once('.').unwrap_or((digits, ""));
    let zero = digits.bytes().all(|b| b == b'0' || b == b'.');
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
    match out[mark..].parse::<f64>() {
        Ok(value) if value.abs() < MAX_COMMAND => Some(value),
        _ => {
            out.truncate(mark);
            None
        }
    }
}

/// A small buffer for the digits of a number, on the stack: room for six digits, the point
/// and [`MAX_WORD_DECIMALS`] decimals.
struct Digits {
    buf: [u8; 64],
    len: usize,
}

impl Default for Digits {
    fn default() -> Self {
        Digits {
            buf: [0; 64],
            len: 0,
        }
    }
}

impl Digits {
    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.buf[..self.len]).unwrap_or("")
    }
}

impl std::fmt::Write for Digits {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        if end > self.buf.len() {
            return Err(std::fmt::Error);
        }
        self.buf[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(text: &str) -> String {
        let (v, s) = read_number(b'X', text).unwrap();
        written(v, &s, s.decimals).unwrap().0
    }

    fn written(x: f64, s: &NumberStyle, decimals: usize) -> Option<(String, f64)> {
        let mut out = String::from("X");
        let v = write_number(&mut out, x, s, decimals);
        if v.is_none() {
            assert_eq!(out, "X");
        }
        v.map(|v| (out[1..].to_string(), v))
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
        let many = format!("1.{}", "1".repeat(MAX_WORD_DECIMALS + 1));
        for t in [
            "", "+", ".", "1.2.3", "1e5", "#1", "1,5", "- 1", "0x1", &many,
        ] {
            assert!(read_number(b'X', t).is_none(), "{t}");
        }
    }

    #[test]
    fn rounding_and_limits() {
        let (_, s) = read_number(b'X', "+10.000").unwrap();
        assert_eq!(written(-0.0004, &s, 3).unwrap().0, "+0.000");
        assert_eq!(written(-0.0006, &s, 3).unwrap().0, "-0.001");
        assert_eq!(written(9.99951, &s, 3).unwrap(), ("+10.000".into(), 10.0));
        assert_eq!(written(1.25, &s, 5).unwrap().0, "+1.25000");
        assert!(written(99_999.999_6, &s, 3).is_none());
        assert!(written(f64::NAN, &s, 3).is_none());
        let (_, dot) = read_number(b'X', ".5").unwrap();
        assert_eq!(written(1.5, &dot, 1).unwrap().0, "1.5");
        assert_eq!(written(0.0, &dot, 0).unwrap().0, "0.");
    }
}
