//! Times of checks: UTC, to the second, written as RFC 3339 (`2025-03-04T08:15:00Z`).
//!
//! The stored text has one fixed form, so that the text order is the time order. Read back, a
//! time may be given with a UTC offset (`2025-03-04T09:15:00+01:00`), with fractional seconds
//! (dropped: times are kept to the second), or as a date alone (`2025-03-04`: the start of
//! that day, UTC). Years 0001 to 9999, as RFC 3339 writes them. No leap second is represented
//! (`:60` is refused).

use std::fmt;
use std::time::{SystemTime, UNIX_EPOCH};

/// A time, UTC, in whole seconds since 1970-01-01T00:00:00Z (negative before it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Timestamp(pub i64);

/// Seconds per day.
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// The first and last seconds written (0001-01-01T00:00:00Z, 9999-12-31T23:59:59Z).
const FIRST: i64 = -62_135_596_800;
const LAST: i64 = 253_402_300_799;

/// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// The date (year, month, day) of a day count since 1970-01-01 (`civil_from_days`).
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

fn days_in_month(y: i64, m: i64) -> i64 {
    match m {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        _ if (y % 4 == 0 && y % 100 != 0) || y % 400 == 0 => 29,
        _ => 28,
    }
}

impl Timestamp {
    /// Now, from the system clock, to the second.
    ///
    /// # Errors
    /// A message when the clock is before 1970 or beyond year 9999.
    pub fn now() -> Result<Timestamp, String> {
        Timestamp::of(SystemTime::now())
    }

    /// The time `t` (a file's modification time, say), to the second.
    ///
    /// # Errors
    /// A message when `t` is before 1970 or beyond year 9999.
    pub fn of(t: SystemTime) -> Result<Timestamp, String> {
        let secs = t
            .duration_since(UNIX_EPOCH)
            .map_err(|_| "the time is before 1970".to_string())?
            .as_secs();
        match i64::try_from(secs) {
            Ok(s) if s <= LAST => Ok(Timestamp(s)),
            _ => Err("the time is beyond the year 9999".into()),
        }
    }

    /// Days from `earlier` to `self` (negative when `self` is earlier).
    pub fn days_since(self, earlier: Timestamp) -> f64 {
        (self.0 - earlier.0) as f64 / SECONDS_PER_DAY
    }

    /// Reads an RFC 3339 date-time (`2025-03-04T08:15:00Z`, `…+01:00`, `…T08:15:00.25Z`, a `t`,
    /// `z` or space instead of `T` and `Z`) or a full date alone (`2025-03-04`, 00:00:00 UTC).
    ///
    /// # Errors
    /// What is wrong with the text, in words.
    pub fn parse(text: &str) -> Result<Timestamp, String> {
        let bad = |why: &str| {
            format!(
                "`{text}` is not an RFC 3339 time ({why}); write e.g. 2025-03-04T08:15:00Z, 2025-03-04T09:15:00+01:00 or 2025-03-04"
            )
        };
        let b = text.as_bytes();
        let digits = |from: usize, n: usize| -> Option<i64> {
            let s = b.get(from..from + n)?;
            s.iter()
                .all(u8::is_ascii_digit)
                .then(|| s.iter().fold(0i64, |v, c| v * 10 + i64::from(c - b'0')))
        };
        let (Some(y), Some(mo), Some(d)) = (digits(0, 4), digits(5, 2), digits(8, 2)) else {
            return Err(bad("the date must be YYYY-MM-DD"));
        };
        if b.get(4) != Some(&b'-') || b.get(7) != Some(&b'-') {
            return Err(bad("the date must be YYYY-MM-DD"));
        }
        if y == 0 || !(1..=12).contains(&mo) || d < 1 || d > days_in_month(y, mo) {
            return Err(bad("no such date"));
        }
        let day = days_from_civil(y, mo, d);
        if b.len() == 10 {
            return Ok(Timestamp(day * 86_400));
        }
        if !matches!(b.get(10), Some(b'T' | b't' | b' ')) {
            return Err(bad("a `T` must separate the date and the time"));
        }
        let (Some(h), Some(mi), Some(s)) = (digits(11, 2), digits(14, 2), digits(17, 2)) else {
            return Err(bad("the time must be HH:MM:SS"));
        };
        if b.get(13) != Some(&b':') || b.get(16) != Some(&b':') {
            return Err(bad("the time must be HH:MM:SS"));
        }
        if h > 23 || mi > 59 || s > 59 {
            return Err(bad(
                "no such time of day (hours 00-23, minutes and seconds 00-59)",
            ));
        }
        let mut at = 19;
        if b.get(at) == Some(&b'.') {
            at += 1;
            let start = at;
            while b.get(at).is_some_and(u8::is_ascii_digit) {
                at += 1;
            }
            if at == start {
                return Err(bad("a decimal point needs digits after it"));
            }
        }
        let offset = match b.get(at) {
            Some(b'Z' | b'z') if b.len() == at + 1 => 0,
            Some(sign @ (b'+' | b'-')) if b.len() == at + 6 => {
                let (Some(oh), Some(om)) = (digits(at + 1, 2), digits(at + 4, 2)) else {
                    return Err(bad("the offset must be +HH:MM or -HH:MM"));
                };
                if b[at + 3] != b':' || oh > 23 || om > 59 {
                    return Err(bad("the offset must be +HH:MM or -HH:MM"));
                }
                let o = oh * 3600 + om * 60;
                if *sign == b'-' { -o } else { o }
            }
            None => return Err(bad("the UTC offset is missing: end with Z or +HH:MM")),
            _ => return Err(bad("end with Z or a UTC offset +HH:MM")),
        };
        let t = day * 86_400 + h * 3600 + mi * 60 + s - offset;
        if !(FIRST..=LAST).contains(&t) {
            return Err(bad("in UTC it is outside the years 0001-9999"));
        }
        Ok(Timestamp(t))
    }
}

impl serde::Serialize for Timestamp {
    /// As its RFC 3339 text.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl fmt::Display for Timestamp {
    /// `YYYY-MM-DDTHH:MM:SSZ`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let days = self.0.div_euclid(86_400);
        let secs = self.0.rem_euclid(86_400);
        let (y, m, d) = civil_from_days(days);
        write!(
            f,
            "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
            secs / 3600,
            secs / 60 % 60,
            secs % 60
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_times() {
        assert_eq!(Timestamp(0).to_string(), "1970-01-01T00:00:00Z");
        assert_eq!(Timestamp(951_782_400).to_string(), "2000-02-29T00:00:00Z");
        assert_eq!(Timestamp(1_741_076_100).to_string(), "2025-03-04T08:15:00Z");
        assert_eq!(Timestamp(FIRST).to_string(), "0001-01-01T00:00:00Z");
        assert_eq!(Timestamp(LAST).to_string(), "9999-12-31T23:59:59Z");
        assert_eq!(Timestamp(-1).to_string(), "1969-12-31T23:59:59Z");
    }

    #[test]
    fn parse_round_trips_and_offsets() {
        for t in [FIRST, -1, 0, 951_782_400, 1_741_076_100, LAST] {
            let s = Timestamp(t).to_string();
            assert_eq!(Timestamp::parse(&s), Ok(Timestamp(t)), "{s}");
        }
        let utc = Timestamp::parse("2025-03-04T08:15:00Z").unwrap();
        assert_eq!(Timestamp::parse("2025-03-04T09:15:00+01:00"), Ok(utc));
        assert_eq!(Timestamp::parse("2025-03-04T03:45:00-04:30"), Ok(utc));
        assert_eq!(Timestamp::parse("2025-03-04t08:15:00.999z"), Ok(utc));
        assert_eq!(Timestamp::parse("2025-03-04 08:15:00Z"), Ok(utc));
        assert_eq!(
            Timestamp::parse("2025-03-04"),
            Ok(Timestamp(utc.0 - 8 * 3600 - 15 * 60))
        );
        assert_eq!(
            Timestamp::parse("2024-02-29T00:00:00Z").map(|t| t.to_string()),
            Ok("2024-02-29T00:00:00Z".into())
        );
    }

    #[test]
    fn bad_times_are_refused_with_the_reason() {
        for (text, why) in [
            ("2025-3-04", "YYYY-MM-DD"),
            ("2025-02-29", "no such date"),
            ("2025-13-01T00:00:00Z", "no such date"),
            ("0000-01-01", "no such date"),
            ("2025-03-04T24:00:00Z", "no such time"),
            ("2025-03-04T23:59:60Z", "no such time"),
            ("2025-03-04T08:15:00", "offset is missing"),
            ("2025-03-04T08:15Z", "HH:MM:SS"),
            ("2025-03-04T08:15:00.Z", "digits after it"),
            ("2025-03-04T08:15:00+0100", "Z or a UTC offset"),
            ("2025-03-04T08:15:00+01:60", "+HH:MM"),
            ("0001-01-01T00:00:00+00:01", "outside the years"),
            ("2025-03-04X08:15:00Z", "`T`"),
            ("", "YYYY-MM-DD"),
            ("yesterday", "YYYY-MM-DD"),
        ] {
            let e = Timestamp::parse(text).unwrap_err();
            assert!(e.contains(why), "{text}: {e}");
            assert!(e.contains(text), "{text}: {e}");
        }
    }

    #[test]
    fn days_between() {
        let a = Timestamp::parse("2025-03-04").unwrap();
        let b = Timestamp::parse("2025-03-11T12:00:00Z").unwrap();
        assert_eq!(b.days_since(a), 7.5);
        assert_eq!(a.days_since(b), -7.5);
    }
}
