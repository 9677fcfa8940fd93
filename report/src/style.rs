//! The report's styles: one inline `<style>` for the screen and for print (A4, figures and
//! table rows kept whole, table headers repeated, links shown), and the vendored font of the
//! figures embedded as an `@font-face` with a `data:` URL, so that the SVG text is drawn in the
//! font it was laid out with and no font is looked up anywhere.

use crate::base64;

/// The font file of the figures: the DejaVu Sans the `plots` crate lays its text out with
/// (Bitstream Vera licence, `plots/fonts/DejaVuSans.LICENSE`), 759 720 bytes.
pub static FONT: &[u8] = include_bytes!("../../plots/fonts/DejaVuSans.ttf");

/// The `@font-face` rule that declares [`plots::FONT_FAMILY`] from [`FONT`], base64-encoded in
/// a `data:font/ttf` URL (about 1.01 MB of text: 4/3 of the font file).
pub fn font_face() -> String {
    format!(
        "@font-face {{ font-family: \"{}\"; font-style: normal; font-weight: 400; src: url(\"data:font/ttf;base64,{}\") format(\"truetype\"); }}\n",
        plots::FONT_FAMILY,
        base64::encode(FONT)
    )
}

/// The styles for screen and print (no font rule: see [`font_face`]).
pub const CSS: &str = r##"
:root { color-scheme: light; }
body { font-family: "DejaVu Sans", sans-serif; font-size: 10.5pt; line-height: 1.4;
       color: #111; background: #fff; max-width: 60rem; margin: 1.5rem auto; padding: 0 1rem; }
header { border-bottom: 2px solid #234; margin-bottom: 1rem; }
h1 { font-size: 1.6em; margin: 0 0 0.3em 0; }
h2 { font-size: 1.3em; margin-top: 1.6em; border-bottom: 1px solid #999; break-after: avoid; }
h3 { font-size: 1.1em; margin-top: 1.2em; break-after: avoid; }
p.subtitle { margin: 0 0 0.6em 0; color: #333; }
p.absent { font-style: italic; color: #444; }
nav ol { columns: 2; margin: 0.3em 0 1em 0; }
dl.facts { display: grid; grid-template-columns: max-content auto; gap: 0.15em 1em; }
dl.facts dt { font-weight: bold; }
dl.facts dd { margin: 0; overflow-wrap: anywhere; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em 0; font-size: 0.95em; min-width: 60%; }
caption { text-align: left; font-weight: bold; padding-bottom: 0.3em; caption-side: top; }
th, td { border: 1px solid #aaa; padding: 0.15em 0.5em; vertical-align: top; }
th { background: #e8edf2; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.hash { font-family: "DejaVu Sans Mono", monospace; font-size: 0.85em; overflow-wrap: anywhere; }
tr.warn td { background: #fdf1d8; }
figure { margin: 1em 0; break-inside: avoid; page-break-inside: avoid; }
figure svg { display: block; max-width: 100%; height: auto; }
figcaption { font-size: 0.92em; color: #222; margin-top: 0.3em; }
.mark { font-weight: bold; }
@page { size: A4; margin: 16mm 14mm 18mm 14mm; }
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 9.5pt; color: #000; background: #fff; }
  nav { break-after: avoid; }
  th { background: #eee; }
  tr.warn td { background: #f6f6f6; }
  table { break-inside: auto; }
  thead { display: table-header-group; }
  tr, figure, dl.facts { break-inside: avoid; page-break-inside: avoid; }
  h2, h3, caption { break-after: avoid; page-break-after: avoid; }
  a { color: #000; text-decoration: underline; }
  a[href^="#"]::after { content: ""; }
  a:not([href^="#"])::after { content: " (" attr(href) ")"; }
}
"##;
