//! Numbers read and written without double rounding: µm moved to mm (and back) in the decimal
//! text, degrees written as the shortest decimal whose conversion gives the command exactly.

/// The degree value written for the rotary command `rad`: among the few `f64` next to
/// `rad.to_degrees()`, the one with the shortest decimal whose `to_radians()` gives `rad`
/// exactly (the nearest such one on a tie); `rad.to_degrees()` if none does.
pub fn degrees_for(rad: f64) -> f64 {
    let d0 = rad.to_degrees();
    if !d0.is_finite() {
        return d0;
    }
    let mut best: Option<(usize, u32, f64)> = None;
    let (mut up, mut down) = (d0, d0);
    for k in 0..=4u32 {
        for d in [up, down] {
            if d.to_radians().to_bits() == rad.to_bits() {
                let len = format_scaled(d, 0).len();
                if best.is_none_or(|(l, bk, _)| (len, k) < (l, bk)) {
                    best = Some((len, k, d));
                }
            }
        }
        up = up.next_up();
        down = down.next_down();
    }
    best.map_or(d0, |(_, _, d)| d)
}

/// The decimal number `text` times `10^shift`, rounded once to the nearest `f64`: the decimal
/// point is moved in the text, then the text is parsed. `None` when `text` is not a plain
/// decimal (`[+-]digits[.digits][e[+-]digits]`; `inf` and `nan` are not).
pub fn parse_scaled(text: &str, shift: i32) -> Option<f64> {
    let t = text.trim();
    let (sign, rest) = match t.as_bytes().first()? {
        b'-' => ("-", &t[1..]),
        b'+' => ("", &t[1..]),
        _ => ("", t),
    };
    let (mantissa, exp) = match rest.find(['e', 'E']) {
        Some(i) => (&rest[..i], rest[i + 1..].parse::<i64>().ok()?),
        None => (rest, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = |s: &str| s.bytes().all(|b| b.is_ascii_digit());
    if (int.is_empty() && frac.is_empty()) || !digits(int) || !digits(frac) {
        return None;
    }
    let e = exp
        .checked_sub(frac.len() as i64)?
        .checked_add(shift as i64)?;
    // The digits and the exponent, written without allocating when they are short.
    let mut digits = [0u8; 20];
    let exponent = decimal(e, &mut digits);
    let parts = [sign, int, frac, "e", exponent];
    let mut buf = [0u8; 64];
    let len: usize = parts.iter().map(|p| p.len()).sum();
    if len > buf.len() {
        return parts.concat().parse().ok();
    }
    let mut n = 0;
    for p in parts {
        buf[n..n + p.len()].copy_from_slice(p.as_bytes());
        n += p.len();
    }
    std::str::from_utf8(&buf[..n]).ok()?.parse().ok()
}

/// `e` in decimal, written at the end of `buf` (20 bytes hold every `i64`).
fn decimal(e: i64, buf: &mut [u8; 20]) -> &str {
    let mut i = buf.len();
    let mut u = e.unsigned_abs();
    loop {
        i -= 1;
        buf[i] = b'0' + (u % 10) as u8;
        u /= 10;
        if u == 0 {
            break;
        }
    }
    if e < 0 {
        i -= 1;
        buf[i] = b'-';
    }
    std::str::from_utf8(&buf[i..]).unwrap_or("0")
}

/// The shortest decimal of `x` (the one that reads back to the same `f64`) times `10^shift`,
/// exactly (the decimal point is moved in the text, nothing is rounded): plain notation,
/// scientific (`1.5e-12`) outside 1e-7 … 1e21. `parse_scaled(&format_scaled(x, k), -k)` is `x`
/// bit for bit. Non-finite values are written as Rust prints them (`NaN`, `inf`).
pub fn format_scaled(x: f64, shift: i32) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let sign = if x.is_sign_negative() { "-" } else { "" };
    if x == 0.0 {
        return format!("{sign}0");
    }
    let e = format!("{:e}", x.abs());
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i64 = exp.parse().unwrap_or(0);
    let digits: String = mantissa.chars().filter(|c| *c != '.').collect();
    // Number of digits before the decimal point.
    let point = exp + 1 + shift as i64;
    let n = digits.len() as i64;
    let body = if !(-6..=21).contains(&point) {
        let (first, rest) = digits.split_at(1);
        if rest.is_empty() {
            format!("{first}e{}", point - 1)
        } else {
            format!("{first}.{rest}e{}", point - 1)
        }
    } else if point <= 0 {
        format!("0.{}{digits}", "0".repeat((-point) as usize))
    } else if point >= n {
        format!("{digits}{}", "0".repeat((point - n) as usize))
    } else {
        let (a, b) = digits.split_at(point as usize);
        format!("{a}.{b}")
    };
    format!("{sign}{body}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaled_numbers() {
        assert_eq!(format_scaled(0.012345, 3), "12.345");
        assert_eq!(format_scaled(-0.01, 3), "-10");
        assert_eq!(format_scaled(1.5, 0), "1.5");
        assert_eq!(format_scaled(1e-20, 3), "1e-17");
        assert_eq!(format_scaled(1234.5, 3), "1234500");
        assert_eq!(format_scaled(-0.0, 3), "-0");
        assert_eq!(parse_scaled("12.345", -3), Some(0.012345));
        assert_eq!(parse_scaled("-10", -3), Some(-0.01));
        assert_eq!(parse_scaled(".5", 0), Some(0.5));
        assert_eq!(parse_scaled("5.", 0), Some(5.0));
        assert_eq!(parse_scaled("1.5E2", -3), Some(0.15));
        assert_eq!(parse_scaled("inf", 0), None);
        assert_eq!(parse_scaled("nan", 0), None);
        assert_eq!(parse_scaled("1.2.3", 0), None);
        assert_eq!(parse_scaled("", 0), None);
        assert_eq!(parse_scaled("-", 0), None);
        assert_eq!(parse_scaled("-1e-5", -3), Some(-1e-8));
        assert_eq!(parse_scaled("25e-9223372036854775807", 0), Some(0.0));
        assert_eq!(parse_scaled("1e-9223372036854775808", 0), Some(0.0));
        assert_eq!(parse_scaled("1.5e-9223372036854775808", 0), None);
        // Longer than the stack buffer.
        let long = format!("{}.{}", "1".repeat(70), "2".repeat(30));
        assert_eq!(parse_scaled(&long, -3), format!("{long}e-3").parse().ok());
        // SplitMix64: numbers with every exponent from 1e-20 to 1e20 and random digits.
        let mut state = 3u64;
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..20_000 {
            let x = (2.0 * next() - 1.0) * 10f64.powi((next() * 40.0) as i32 - 20);
            for k in [0, 3, 6, -3] {
                let s = format_scaled(x, k);
                assert_eq!(
                    parse_scaled(&s, -k).map(f64::to_bits),
                    Some(x.to_bits()),
                    "{x} {k} {s}"
                );
            }
        }
    }

    #[test]
    fn degrees_round_trip() {
        for i in 0..=3600 {
            let d = -180.0 + 0.1 * i as f64;
            let r = d.to_radians();
            assert_eq!(degrees_for(r).to_radians().to_bits(), r.to_bits(), "{d}");
        }
        assert_eq!(degrees_for(1.5f64.to_radians()), 1.5);
        assert_eq!(degrees_for(0.0), 0.0);
    }
}
