//! One line of a Heidenhain conversational program: a positioning block, a dwell, the touch
//! probe cycle 0 (`TCH PROBE 0.0 REFERENCE PLANE Q… X-`, `TCH PROBE 0.1 X… Y… Z…`), the log
//! (`FN 16: F-PRINT format / output`).

use super::{Motion, ProbeKind, ProbeMove, Raw, Step};
use formats::nc::NcError;
use formats::nc::number::read_number;
use formats::poses::AxisWord;

/// The axis words of `tokens` (`X+217.5`, …) as (axis, value), for the axes `axes`.
fn axis_words(
    tokens: &[&str],
    axes: &[AxisWord],
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Vec<(usize, f64)>, NcError> {
    let mut named = Vec::new();
    for t in tokens {
        let letter = t.chars().next().unwrap_or(' ');
        let num = &t[letter.len_utf8()..];
        let Some(a) = axes.iter().position(|a| a.letter == letter) else {
            return Err(err(t, "a word the reader does not know".into()));
        };
        let v = read_number(letter as u8, num)
            .map(|(v, _)| v)
            .ok_or_else(|| err(t, "cannot read its number".into()))?;
        named.push((a, v));
    }
    Ok(named)
}

/// The touch probe cycle's blocks: `0.0 REFERENCE PLANE Q<n> <axis><sign>` (kept in `cycle0`
/// for the `0.1` block) and `0.1 <axis words>` (the position the cycle starts from).
fn touch_probe(
    r: &mut Raw,
    tokens: &[&str],
    axes: &[AxisWord],
    pose: &mut [f64],
    cycle0: &mut Option<ProbeKind>,
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<(), NcError> {
    match tokens.get(2).copied() {
        Some("0.0") => {
            let [_, _, _, "REFERENCE", "PLANE", q, dir] = tokens else {
                return Err(err(
                    &tokens.join(" "),
                    "a touch probe cycle 0 the reader does not know (TCH PROBE 0.0 REFERENCE PLANE Q<n> <axis><+|->)".into(),
                ));
            };
            let result: u32 = q
                .strip_prefix('Q')
                .and_then(|n| n.parse().ok())
                .ok_or_else(|| err(q, "cannot read the result's Q parameter".into()))?;
            let letter = dir.chars().next().unwrap_or(' ');
            let sign = &dir[letter.len_utf8()..];
            let axis = axes
                .iter()
                .position(|a| a.letter == letter)
                .filter(|_| sign == "+" || sign == "-")
                .ok_or_else(|| err(dir, "not a probing axis and direction".into()))?;
            let kind = ProbeKind::ReferencePlane {
                axis,
                positive: sign == "+",
                result,
                part: 0,
            };
            *cycle0 = Some(kind);
            r.probe = Some(ProbeMove { kind, feed: None });
        }
        Some("0.1") => {
            let Some(ProbeKind::ReferencePlane {
                axis,
                positive,
                result,
                ..
            }) = cycle0.take()
            else {
                return Err(err(
                    "TCH PROBE 0.1",
                    "the position of a touch probe cycle 0 without its TCH PROBE 0.0 block just before".into(),
                ));
            };
            let named = axis_words(&tokens[3..], axes, err)?;
            if named.is_empty() {
                return Err(err(
                    "TCH PROBE 0.1",
                    "a position without an axis word".into(),
                ));
            }
            for &(a, v) in &named {
                pose[a] = v;
            }
            r.motion = Some(Motion {
                rapid: false,
                machine: false,
                inverse_time: false,
                feed: None,
                named: named.iter().map(|&(a, _)| a).collect(),
                pose: pose.to_vec(),
            });
            r.probe = Some(ProbeMove {
                kind: ProbeKind::ReferencePlane {
                    axis,
                    positive,
                    result,
                    part: 1,
                },
                feed: None,
            });
        }
        _ => {
            return Err(err(
                &tokens.join(" "),
                "a touch probe cycle the reader does not know (cycle 0 only)".into(),
            ));
        }
    }
    Ok(())
}

/// One line of a Heidenhain conversational program; `None` for a comment line. `cycle0`: the
/// touch probe cycle 0 defined by the line before, for its `0.1` block.
pub(super) fn line(
    n: usize,
    line: &str,
    axes: &[AxisWord],
    pose: &mut [f64],
    cycle0: &mut Option<ProbeKind>,
    err: &dyn Fn(&str, String) -> NcError,
) -> Result<Option<Raw>, NcError> {
    let (body, comment) = match line.split_once(';') {
        Some((b, c)) => (b, Some(c.trim().to_string())),
        None => (line, None),
    };
    let mut tokens: Vec<&str> = body.split_whitespace().collect();
    if tokens
        .first()
        .is_some_and(|t| t.bytes().all(|b| b.is_ascii_digit()))
    {
        tokens.remove(0);
    }
    let Some(&kw) = tokens.first() else {
        return Ok(None);
    };
    let mut r = Raw::new(n, comment);
    if cycle0.is_some() && (kw, tokens.get(2).copied()) != ("TCH", Some("0.1")) {
        return Err(err(
            kw,
            "a touch probe cycle 0 whose TCH PROBE 0.0 block is not followed by its TCH PROBE 0.1 block".into(),
        ));
    }
    match (kw, tokens.get(1).copied()) {
        ("BEGIN", Some("PGM")) | ("FUNCTION", Some("RESET")) => return Ok(Some(r)),
        ("END", Some("PGM")) => {
            r.end = true;
            return Ok(Some(r));
        }
        ("STOP", _) => {
            r.stop = true;
            return Ok(Some(r));
        }
        ("CYCL", Some("DEF")) => {
            r.dwell_block = true;
            match tokens.get(2).copied() {
                Some("9.0") => {}
                Some("9.1") if tokens.get(3) == Some(&"DWELL") => {
                    let t = tokens.get(4).copied().unwrap_or("");
                    r.dwell_s = Some(
                        read_number(b'D', t)
                            .map(|(v, _)| v)
                            .ok_or_else(|| err(t, "cannot read the dwell time".into()))?,
                    );
                }
                _ => return Err(err(body.trim(), "a cycle the reader does not know".into())),
            }
            return Ok(Some(r));
        }
        ("TCH", Some("PROBE")) => {
            touch_probe(&mut r, &tokens, axes, pose, cycle0, err)?;
            return Ok(Some(r));
        }
        ("FN", Some("16:")) => {
            let statement = tokens.join(" ");
            let valid = tokens.get(2) == Some(&"F-PRINT")
                && tokens.len() == 6
                && tokens.get(4) == Some(&"/");
            if !valid {
                return Err(err(
                    &statement,
                    "an FN 16 the reader does not know (FN 16: F-PRINT <format> / <output>)".into(),
                ));
            }
            r.special = Some((Step::Log, statement));
            return Ok(Some(r));
        }
        ("L", _) => {}
        _ => return Err(err(kw, "a block the reader does not know".into())),
    }
    let (mut rapid, mut m91, mut feed) = (false, false, None);
    let mut words: Vec<&str> = Vec::new();
    for t in &tokens[1..] {
        let letter = t.chars().next().unwrap_or(' ');
        let num = &t[letter.len_utf8()..];
        match letter {
            'R' if *t == "R0" => {}
            'F' if *t == "FMAX" => rapid = true,
            'F' => {
                feed = Some(
                    read_number(b'F', num)
                        .map(|(v, _)| v)
                        .ok_or_else(|| err(t, "cannot read the feed".into()))?,
                )
            }
            'M' => {
                let code: u32 = num
                    .parse()
                    .map_err(|_| err(t, "cannot read the M function".into()))?;
                m91 |= code == 91;
                r.m_codes.push(code);
            }
            _ => words.push(t),
        }
    }
    let named = axis_words(&words, axes, err)?;
    r.m_codes.retain(|&c| c != 91);
    r.stop |= r.m_codes.contains(&0);
    if !named.is_empty() {
        for &(a, v) in &named {
            pose[a] = v;
        }
        r.motion = Some(Motion {
            rapid,
            machine: m91,
            inverse_time: false,
            feed: if rapid { None } else { feed },
            named: named.iter().map(|&(a, _)| a).collect(),
            pose: pose.to_vec(),
        });
    }
    Ok(Some(r))
}
