//! The HTML writer: escaping of every text that comes from a file, and the few elements the
//! report is made of (headings, paragraphs, tables, definition lists, figures).
//!
//! Text passes through [`escape`] on its way in; only the writer's own markup is raw. A table
//! has its header in a `<thead>`, which a browser repeats on every printed page the table
//! spans.

use std::fmt::Write as _;

/// `text` with `&`, `<`, `>`, `"` and `'` replaced by their character references: safe in
/// element content and in quoted attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// One table cell: escaped text, or markup the writer made.
#[derive(Clone, Debug, PartialEq)]
pub enum Cell {
    /// Text, escaped when written.
    Text(String),
    /// A number or a value with its uncertainty, right-aligned (escaped when written).
    Number(String),
    /// Markup made by this crate (never text from a file).
    Markup(String),
}

impl Cell {
    /// A text cell.
    pub fn text(t: impl Into<String>) -> Cell {
        Cell::Text(t.into())
    }

    /// A right-aligned number cell.
    pub fn number(t: impl Into<String>) -> Cell {
        Cell::Number(t.into())
    }
}

/// An HTML document under construction: the body's elements, in order.
#[derive(Debug, Default)]
pub struct Body {
    html: String,
}

impl Body {
    /// An empty body.
    pub fn new() -> Body {
        Body::default()
    }

    /// The markup written so far.
    pub fn into_markup(self) -> String {
        self.html
    }

    /// Raw markup made by this crate (an SVG figure, a nested element).
    pub fn raw(&mut self, markup: &str) {
        self.html.push_str(markup);
    }

    /// Opens a `<section>` with `id`, headed by `<h2>` `title`.
    pub fn section(&mut self, id: &str, title: &str) {
        let _ = writeln!(
            self.html,
            "<section id=\"{}\">\n<h2>{}</h2>",
            escape(id),
            escape(title)
        );
    }

    /// Closes the current section.
    pub fn end_section(&mut self) {
        self.html.push_str("</section>\n");
    }

    /// An `<h3>` heading.
    pub fn subheading(&mut self, title: &str) {
        let _ = writeln!(self.html, "<h3>{}</h3>", escape(title));
    }

    /// A paragraph of text.
    pub fn paragraph(&mut self, text: &str) {
        let _ = writeln!(self.html, "<p>{}</p>", escape(text));
    }

    /// A paragraph saying that a part is absent, and why.
    pub fn absent(&mut self, text: &str) {
        let _ = writeln!(self.html, "<p class=\"absent\">{}</p>", escape(text));
    }

    /// A bulleted list of texts (nothing when empty).
    pub fn list(&mut self, items: &[String]) {
        if items.is_empty() {
            return;
        }
        self.html.push_str("<ul>\n");
        for i in items {
            let _ = writeln!(self.html, "<li>{}</li>", escape(i));
        }
        self.html.push_str("</ul>\n");
    }

    /// A definition list of (term, description) pairs.
    pub fn facts(&mut self, rows: &[(&str, String)]) {
        self.html.push_str("<dl class=\"facts\">\n");
        for (term, description) in rows {
            let _ = writeln!(
                self.html,
                "<dt>{}</dt><dd>{}</dd>",
                escape(term),
                escape(description)
            );
        }
        self.html.push_str("</dl>\n");
    }

    /// A table with a `caption`, its `header` row (repeated on each printed page) and `rows`.
    pub fn table(&mut self, caption: &str, header: &[&str], rows: &[Vec<Cell>]) {
        let _ = writeln!(
            self.html,
            "<table>\n<caption>{}</caption>\n<thead><tr>{}</tr></thead>\n<tbody>",
            escape(caption),
            header
                .iter()
                .map(|h| format!("<th scope=\"col\">{}</th>", escape(h)))
                .collect::<String>()
        );
        for row in rows {
            self.html.push_str("<tr>");
            for cell in row {
                match cell {
                    Cell::Text(t) => {
                        let _ = write!(self.html, "<td>{}</td>", escape(t));
                    }
                    Cell::Number(t) => {
                        let _ = write!(self.html, "<td class=\"num\">{}</td>", escape(t));
                    }
                    Cell::Markup(m) => {
                        let _ = write!(self.html, "<td>{m}</td>");
                    }
                }
            }
            self.html.push_str("</tr>\n");
        }
        self.html.push_str("</tbody>\n</table>\n");
    }

    /// A `<figure>` with `id`, the SVG markup `svg` (made by [`crate::svg::embed`]) and a
    /// caption `caption` (text).
    pub fn figure(&mut self, id: &str, svg: &str, caption: &str) {
        self.figure_with_data(id, svg, caption, &[]);
    }

    /// A `<figure>` as [`Body::figure`], with `data-NAME="value"` attributes (`data`: the
    /// names after `data-`, the values escaped).
    pub fn figure_with_data(
        &mut self,
        id: &str,
        svg: &str,
        caption: &str,
        data: &[(String, String)],
    ) {
        let attributes: String = data
            .iter()
            .map(|(k, v)| format!(" data-{}=\"{}\"", escape(k), escape(v)))
            .collect();
        let _ = writeln!(
            self.html,
            "<figure id=\"{}\"{attributes}>\n{svg}\n<figcaption>{}</figcaption>\n</figure>",
            escape(id),
            escape(caption)
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_special_character_is_escaped() {
        assert_eq!(
            escape("<script>alert('x & \"y\"')</script>"),
            "&lt;script&gt;alert(&#39;x &amp; &quot;y&quot;&#39;)&lt;/script&gt;"
        );
        assert_eq!(escape("µm ± 0.5"), "µm ± 0.5");
    }

    #[test]
    fn table_cells_and_headers_are_escaped_markup_is_not() {
        let mut b = Body::new();
        b.table(
            "a <caption>",
            &["<th>"],
            &[vec![
                Cell::text("<b>"),
                Cell::number("1 & 2"),
                Cell::Markup("<em>x</em>".into()),
            ]],
        );
        let html = b.into_markup();
        assert!(html.contains("<caption>a &lt;caption&gt;</caption>"));
        assert!(html.contains("<th scope=\"col\">&lt;th&gt;</th>"));
        assert!(html.contains("<td>&lt;b&gt;</td>"));
        assert!(html.contains("<td class=\"num\">1 &amp; 2</td>"));
        assert!(html.contains("<td><em>x</em></td>"));
        assert!(html.contains("<thead>"));
    }
}
