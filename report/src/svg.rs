//! SVG figures made fit for an HTML page: the XML prolog dropped, a `viewBox` added when the
//! figure has only `width` and `height` (so that it scales to the page width and keeps its
//! aspect ratio), and `role="img"`.

/// Why an SVG text cannot be embedded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("figure `{figure}`: {why}")]
pub struct SvgError {
    /// The figure's id.
    pub figure: String,
    /// What is wrong with its SVG text.
    pub why: String,
}

/// The value of attribute `name` in the start tag `tag` (`<svg …>`), if present.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let pattern = format!(" {name}=\"");
    let start = tag.find(&pattern)? + pattern.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// A length in user units (`640`, `640px`), if it is a positive finite number.
fn length(text: &str) -> Option<f64> {
    let v: f64 = text.trim().trim_end_matches("px").parse().ok()?;
    (v.is_finite() && v > 0.0).then_some(v)
}

/// The `<svg>` element of `svg` (the text of figure `figure`), ready to be placed inline in an
/// HTML page: without the XML prolog, with a `viewBox` (`0 0 width height` when it had none)
/// and `role="img"`. Its `width` and `height` (pixels) stay, so that it has a size of its own;
/// the page's style lets it shrink to the page width.
///
/// # Errors
/// [`SvgError`] when the text has no `<svg` element, or neither a `viewBox` nor a positive
/// `width` and `height`.
pub fn embed(figure: &str, svg: &str) -> Result<String, SvgError> {
    let fail = |why: &str| SvgError {
        figure: figure.to_string(),
        why: why.to_string(),
    };
    let start = svg.find("<svg").ok_or_else(|| fail("no <svg> element"))?;
    let body = &svg[start..];
    let tag_end = body
        .find('>')
        .ok_or_else(|| fail("the <svg> tag is not closed"))?;
    let tag = &body[..tag_end];
    let width = attribute(tag, "width").and_then(length);
    let height = attribute(tag, "height").and_then(length);
    let mut extra = String::new();
    if attribute(tag, "viewBox").is_none() {
        match (width, height) {
            (Some(w), Some(h)) => extra.push_str(&format!(" viewBox=\"0 0 {w} {h}\"")),
            _ => return Err(fail("no viewBox and no positive width and height")),
        }
    }
    if width.is_none() || height.is_none() {
        return Err(fail("no positive width and height"));
    }
    if attribute(tag, "role").is_none() {
        extra.push_str(" role=\"img\"");
    }
    let self_closing = tag.ends_with('/');
    // Inside HTML the parser gives <svg> its namespace: the namespace URLs are dropped, so
    // that the page names no address at all.
    let mut tag = tag.trim_end_matches('/').to_string();
    for name in ["xmlns", "xmlns:xlink"] {
        if let Some(v) = attribute(&tag, name) {
            tag = tag.replace(&format!(" {name}=\"{v}\""), "");
        }
    }
    Ok(format!(
        "{tag}{extra}{}>{}",
        if self_closing { "/" } else { "" },
        body[tag_end + 1..].trim_end()
    ))
}

#[cfg(test)]
mod tests {
    use super::embed;

    #[test]
    fn a_view_box_is_added_from_width_and_height() {
        let svg = "<?xml version=\"1.0\"?>\n<svg width=\"640\" height=\"480\" xmlns=\"http://www.w3.org/2000/svg\"><rect/></svg>\n";
        let out = embed("f", svg).unwrap();
        assert!(out.starts_with("<svg width=\"640\" height=\"480\""));
        assert!(out.contains(" viewBox=\"0 0 640 480\" role=\"img\">"));
        assert!(!out.contains("<?xml"));
        assert!(!out.contains("http"));
        assert!(out.ends_with("</svg>"));
    }

    #[test]
    fn an_existing_view_box_is_kept() {
        let svg = "<svg width=\"10\" height=\"20\" viewBox=\"0 0 10 20\"></svg>";
        let out = embed("f", svg).unwrap();
        assert_eq!(out.matches("viewBox").count(), 1);
    }

    #[test]
    fn a_figure_without_size_is_refused() {
        assert!(embed("f", "<svg></svg>").is_err());
        assert!(embed("f", "<svg width=\"0\" height=\"5\"></svg>").is_err());
        assert!(embed("f", "no figure").is_err());
    }

    /// The figures of `plots` embed (a real figure, not a hand-written one).
    #[test]
    fn a_plots_figure_embeds_with_a_view_box() {
        let svg = plots::spectrum("t", "before", "after", &[("x".to_string(), 1.0, 0.5)]).unwrap();
        let out = embed("f", &svg).unwrap();
        assert!(out.starts_with("<svg"));
        assert!(out.contains("viewBox=\""));
    }
}
