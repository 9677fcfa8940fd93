//! The reports as text for people: rendered from the report types of [`crate::json`],
//! so that the text and the JSON say the same thing. Numbers are written with
//! [`model_spec::units`].

pub mod compensate;
pub mod diagnose;
pub mod gains;
pub mod identify;
pub mod plan;
pub mod plan_probe;
pub mod probe;
pub mod simulate;
pub mod tolerance;
pub mod validate;

pub use simulate::simulation;

/// A value in µm or µrad for people: four decimals, or two significant digits in scientific
/// notation when it would print as zero.
pub fn value(x: f64) -> String {
    model_spec::units::readable(x, 4)
}

/// An aligned text table: the first two columns left-aligned, the others right-aligned; every
/// row has the header's number of cells.
pub fn table<R: AsRef<[String]>>(header: &[String], rows: &[R]) -> String {
    let mut widths = vec![0usize; header.len()];
    for r in std::iter::once(header).chain(rows.iter().map(AsRef::as_ref)) {
        for (w, c) in widths.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |r: &[String]| {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(i, (c, &w))| {
                if i < 2 {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect();
        format!("{}\n", cells.join("  ").trim_end())
    };
    let mut out = line(header);
    let rule: Vec<String> = widths.iter().map(|&w| "-".repeat(w)).collect();
    out.push_str(&format!("{}\n", rule.join("  ")));
    for r in rows {
        out.push_str(&line(r.as_ref()));
    }
    out
}

/// Header cells from string literals.
pub fn header(cells: &[&str]) -> Vec<String> {
    cells.iter().map(|c| c.to_string()).collect()
}

/// Every line of `text` with `pad` in front.
pub fn indent(text: &str, pad: &str) -> String {
    text.lines().map(|l| format!("{pad}{l}\n")).collect()
}

/// `items` joined by `sep` in lines of at most `width` characters, each starting with `pad`
/// ([`model_spec::text::wrap`]).
pub fn wrap(items: &[String], sep: &str, pad: &str, width: usize) -> String {
    if items.is_empty() {
        return String::new();
    }
    let pieces = model_spec::text::list_pieces(items, sep.trim_end());
    model_spec::text::wrap(pieces, width.saturating_sub(pad.len()), "")
        .into_iter()
        .map(|l| format!("{pad}{l}\n"))
        .collect()
}

/// A path or argument for a shell command line, quoted when needed.
pub fn shell(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./:@,+=".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// "zeroed at the first sample" or "not zeroed".
pub fn zeroed_text(zeroed: bool) -> &'static str {
    if zeroed {
        "zeroed at the first sample"
    } else {
        "not zeroed"
    }
}
