//! One line of an ISO (Fanuc-type) or LinuxCNC program: its words, or one of the statements
//! of a probing program (the log, the skip position read, its check).

use super::{GState, Motion, ProbeKind, ProbeMove, Raw, Step};
use formats::nc::number::read_number;
use formats::nc::{Dialect, NcError};
use formats::poses::AxisWord;

/// The comments of a G-code line taken out: its words and the text of its comments.
pub(super) fn split_comments(line: &str) -> (String, Option<String>) {
    let mut words = String::new();
    let mut comment: Option<String> = None;
    let mut rest = line;
    while let Some(at) = rest.find(['(', ';']) {
        words.push_str(&rest[..at]);
        if rest[at..].starts_with(';') {
            comment = Some(rest[at + 1..].trim().to_string());
            rest = "";
            break;
        }
        let close = rest[at..].find(')').map_or(rest.len(), |c| at + c);
        comment = Some(rest[at + 1..close].to_string());
        rest = rest.get(close + 1..).unwrap_or("");
    }
    words.push_str(rest);
    (words, comment)
}

/// A line holding only one of the statements of a probing program, as written: its step and
/// its text; `None` for a line of words. An ISO macro statement the reader does not know is an
/// error.
fn statement(
    body: &str,
    comment: Option<&str>,
    dialect: Dialect,
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Option<(Step, String)>, NcError> {
    if body.is_empty() {
        // LinuxCNC's probe log: a comment that the interpreter acts on.
        let Some(c) = comment.filter(|_| dialect == Dialect::LinuxCnc) else {
            return Ok(None);
        };
        let upper = c.trim().to_ascii_uppercase();
        return Ok(if let Some(file) = upper.strip_prefix("PROBEOPEN") {
            let file = c.trim()[c.trim().len() - file.len()..].trim();
            if file.is_empty() {
                return Err(err("PROBEOPEN", "a probe log without its file".into()));
            }
            Some((Step::LogOpen, file.to_string()))
        } else if upper == "PROBECLOSE" {
            Some((Step::LogClose, "PROBECLOSE".into()))
        } else {
            None
        });
    }
    if dialect != Dialect::Iso {
        return Ok(None);
    }
    let upper = body.to_ascii_uppercase();
    let step = if upper == "POPEN" {
        Step::LogOpen
    } else if upper == "PCLOS" {
        Step::LogClose
    } else if upper.starts_with("DPRNT[") && upper.ends_with(']') {
        Step::Log
    } else if upper.starts_with("IF[") {
        if !upper.contains("THEN#3000=") {
            return Err(err(
                body,
                "a conditional statement the reader does not know (rtest writes IF[…]THEN#3000=… only)".into(),
            ));
        }
        Step::Check
    } else if upper.starts_with('#') {
        let latch = upper
            .split_once('=')
            .is_some_and(|(v, s)| digits_after_hash(v) && digits_after_hash(s));
        if !latch {
            return Err(err(
                body,
                "a macro statement the reader does not know (rtest writes #n=#m only)".into(),
            ));
        }
        Step::Latch
    } else {
        return Ok(None);
    };
    Ok(Some((step, body.to_string())))
}

/// `#` followed by digits only.
fn digits_after_hash(s: &str) -> bool {
    s.strip_prefix('#')
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
}

/// One line of an ISO or LinuxCNC program; `None` for a line without a word (a comment, `%`;
/// the `O` number line counts as a block of the setup).
pub(super) fn line(
    n: usize,
    line: &str,
    dialect: Dialect,
    axes: &[AxisWord],
    pose: &mut [f64],
    g: &mut GState,
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Option<Raw>, NcError> {
    let (body, comment) = split_comments(line);
    let body = body.trim();
    if let Some(special) = statement(body, comment.as_deref(), dialect, err)? {
        let comment = if special.0 == Step::LogOpen || special.0 == Step::LogClose {
            None
        } else {
            comment
        };
        let mut r = Raw::new(n, comment);
        r.special = Some(special);
        return Ok(Some(r));
    }
    if body.is_empty() || body == "%" {
        return Ok(None);
    }
    let mut words: Vec<(char, &str)> = Vec::new();
    let b = body.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b' ' {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < b.len() && !b[i].is_ascii_alphabetic() && b[i] != b' ' {
            i += 1;
        }
        let letter = (b[start] as char).to_ascii_uppercase();
        if !letter.is_ascii_uppercase() {
            return Err(err(&body[start..i], "not a word".into()));
        }
        words.push((letter, &body[start + 1..i]));
    }
    let number = |w: &(char, &str)| {
        read_number(w.0 as u8, w.1)
            .map(|(v, _)| v)
            .ok_or_else(|| err(&format!("{}{}", w.0, w.1), "cannot read its number".into()))
    };
    let mut r = Raw::new(n, comment);
    let (mut g53, mut g10, mut dwell, mut skip) = (false, false, false, false);
    let mut named: Vec<(usize, f64)> = Vec::new();
    let (mut l, mut p) = (None, None);
    for w in &words {
        let v = number(w)?;
        match w.0 {
            'G' => match w.1 {
                "0" => (g.rapid, g.probing) = (true, false),
                "1" => (g.rapid, g.probing) = (false, false),
                "4" => dwell = true,
                "10" => g10 = true,
                "31" if dialect == Dialect::Iso => skip = true,
                "38.2" if dialect == Dialect::LinuxCnc => (g.rapid, g.probing) = (false, true),
                "53" => g53 = true,
                "54" => g.g54 = true,
                "55" | "56" | "57" | "58" | "59" => g.g54 = false,
                "93" => g.inverse_time = true,
                "94" => g.inverse_time = false,
                "92.1" if dialect == Dialect::LinuxCnc => {}
                "17" | "21" | "40" | "49" | "61" | "64" | "69" | "80" | "90" | "15" => {}
                _ => {
                    return Err(err(
                        &format!("G{}", w.1),
                        "a G code the reader does not know".into(),
                    ));
                }
            },
            'M' => {
                let code = v as u32;
                r.m_codes.push(code);
                r.stop |= code == 0;
                r.end |= matches!(code, 2 | 30);
            }
            'F' => g.feed = Some(v),
            'L' => l = Some(v),
            'P' => p = Some(v),
            'R' | 'O' | 'N' => {}
            c => match axes.iter().position(|a| a.letter == c) {
                Some(a) => named.push((a, v)),
                None => {
                    return Err(err(
                        &format!("{c}{}", w.1),
                        "a word the reader does not know".into(),
                    ));
                }
            },
        }
    }
    if g10 {
        // G10 L2 P1 with every axis at 0 zeroes the offsets of G54.
        g.p1_zero = l == Some(2.0)
            && p == Some(1.0)
            && named.len() == axes.len()
            && named.iter().all(|&(_, v)| v == 0.0);
        return Ok(Some(r));
    }
    if dwell {
        r.dwell_block = true;
        r.dwell_s = p;
        return Ok(Some(r));
    }
    let probing = skip || g.probing;
    if probing && named.is_empty() {
        return Err(err(
            if skip { "G31" } else { "G38.2" },
            "a probing block without an axis word".into(),
        ));
    }
    if !named.is_empty() {
        for &(a, v) in &named {
            pose[a] = v;
        }
        let rapid = g.rapid && !probing;
        r.motion = Some(Motion {
            rapid,
            machine: g53 || (g.g54 && g.p1_zero),
            inverse_time: g.inverse_time,
            feed: if rapid { None } else { g.feed },
            named: named.iter().map(|&(a, _)| a).collect(),
            pose: pose.to_vec(),
        });
        if probing {
            r.probe = Some(ProbeMove {
                kind: if skip {
                    ProbeKind::Skip
                } else {
                    ProbeKind::StraightProbe
                },
                feed: g.feed,
            });
        }
    }
    Ok(Some(r))
}
