//! SVG figures of R-test records, model predictions and residual spectra, and of a touch
//! probe's readings per pose.
//!
//! This crate has one job: turn plain numbers into self-describing SVG figures. It knows nothing
//! about machines, models or fits (it does not depend on the other rtest crates); callers convert
//! their data into [`Series`], [`Panel`] and [`SpectrumRow`] values.
//!
//! Units follow the project's conventions at every boundary a person sees: the values of every
//! error series and every spectrum amplitude are **µm**; the abscissa of a path figure is whatever
//! the caller says in its label (sample index, an axis position in mm or degrees, time in s).
//!
//! No system fonts are used or looked up: the vendored DejaVu Sans (see `fonts/`) is registered
//! with plotters once per process and is the only font family the SVG text refers to
//! ([`FONT_FAMILY`]). Text stays text in the SVG (it is not converted to outlines); a viewer that
//! lacks DejaVu Sans substitutes its default font.
//!
//! Every function validates its input first: a NaN or infinite value, an empty series or a series
//! whose length differs from the abscissa is a [`PlotError`] that names the series (and index).
//! Output is deterministic: the same input gives the same bytes. Figures are returned as SVG
//! text; writing them to files is the caller's (rtest writes every file through its `output`
//! crate).

use std::fmt::Write as _;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Font family name under which the vendored DejaVu Sans is registered; the only `font-family`
/// that appears in the SVG output.
pub const FONT_FAMILY: &str = "DejaVu Sans";

/// The vendored font file (DejaVu Sans, Bitstream Vera licence, see `fonts/DejaVuSans.LICENSE`).
static FONT_BYTES: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

/// Why a figure could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A value is NaN or infinite. `series` names the series (as `panel: label` for path
    /// figures, `row label (before label|after label)` for spectra), `index` is the 0-based
    /// sample index (row index for spectra).
    #[error("series '{series}' has a non-finite value ({value}) at index {index}")]
    NonFinite {
        /// Name of the offending series.
        series: String,
        /// 0-based index of the offending value.
        index: usize,
        /// The offending value (NaN, +inf or −inf; µm, or the abscissa's unit).
        value: f64,
    },
    /// A series, the list of panels or the list of spectrum rows is empty.
    #[error("'{what}' is empty: nothing to plot")]
    Empty {
        /// Name of what is empty.
        what: String,
    },
    /// A series does not have one value per abscissa sample.
    #[error("series '{series}' has {found} values but the abscissa has {expected}")]
    LengthMismatch {
        /// Name of the offending series.
        series: String,
        /// Number of abscissa samples.
        expected: usize,
        /// Number of values in the series.
        found: usize,
    },
    /// The vendored font could not be parsed (a broken build, not bad input).
    #[error("the vendored font DejaVu Sans could not be registered")]
    Font,
    /// plotters failed while drawing.
    #[error("drawing the figure failed: {0}")]
    Render(String),
}

/// One named series of values along a path; all values in **µm**.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label, e.g. `"measured"`, `"base model"`, `"extended model"`.
    pub label: String,
    /// One value per abscissa sample, µm.
    pub values: Vec<f64>,
}

impl Series {
    /// A series from a label and its values (µm).
    pub fn new(label: impl Into<String>, values: Vec<f64>) -> Self {
        Self {
            label: label.into(),
            values,
        }
    }
}

/// One panel of a path figure: one error direction, measured against predictions.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// What the panel shows, without unit, e.g. `"x error"`; the y axis reads `"<name> (µm)"`.
    pub name: String,
    /// The measured error along the path, µm; drawn as points.
    pub measured: Series,
    /// Predicted errors along the path, µm (e.g. base model, extended model); drawn as lines,
    /// the first dashed, the second solid, further ones in other colours and dash patterns. The
    /// RMS of `measured − prediction` (µm) of each one is printed above the panel.
    pub predictions: Vec<Series>,
}

/// One row of a residual spectrum: a component (e.g. harmonic k of a rotary axis in one
/// direction) and its amplitude before and after a model change, both in **µm**.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectrumRow {
    /// Component label, e.g. `"C harmonic:2 y"`.
    pub label: String,
    /// Amplitude before (e.g. residual of the base model), µm.
    pub before: f64,
    /// Amplitude after (e.g. residual of the extended model), µm.
    pub after: f64,
}

impl From<(String, f64, f64)> for SpectrumRow {
    fn from((label, before, after): (String, f64, f64)) -> Self {
        Self {
            label,
            before,
            after,
        }
    }
}

impl From<&(String, f64, f64)> for SpectrumRow {
    fn from((label, before, after): &(String, f64, f64)) -> Self {
        Self {
            label: label.clone(),
            before: *before,
            after: *after,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Style
// ---------------------------------------------------------------------------------------------

/// Line and marker colours: dark, light-orange, blue first, so that "measured", "base" and
/// "extended" differ in lightness (readable in greyscale) as well as in hue (Okabe–Ito palette,
/// safe for colour-blind readers).
const INK: RGBColor = RGBColor(0x22, 0x22, 0x22);
const GRID: RGBColor = RGBColor(0xE4, 0xE4, 0xE4);
const AXIS: RGBColor = RGBColor(0x55, 0x55, 0x55);
const MUTED: RGBColor = RGBColor(0x55, 0x55, 0x55);
const PREDICTION_COLOURS: [RGBColor; 4] = [
    RGBColor(0xE6, 0x9F, 0x00), // orange (light in greyscale), dashed
    RGBColor(0x00, 0x72, 0xB2), // blue (dark in greyscale), solid
    RGBColor(0x00, 0x9E, 0x73), // bluish green
    RGBColor(0xCC, 0x79, 0xA7), // reddish purple
];
/// Dash pattern (dash, gap) in px per prediction index; `None` is a solid line.
const PREDICTION_DASHES: [Option<(u32, u32)>; 4] =
    [Some((7, 4)), None, Some((2, 3)), Some((10, 3))];
const BEFORE_COLOUR: RGBColor = RGBColor(0xF4, 0xB6, 0x6A); // light orange
const AFTER_COLOUR: RGBColor = RGBColor(0x1F, 0x5F, 0x9E); // dark blue
const ZEBRA: RGBColor = RGBColor(0xF5, 0xF5, 0xF5);

/// plotters' SVG backend writes `font-size = size / 1.24`; this gives text of `px` pixels.
fn font_size(px: f64) -> f64 {
    px * 1.24
}

fn text(px: f64, colour: &'static RGBColor) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, font_size(px)).into_font()).color(colour)
}

fn prediction_style(i: usize) -> (RGBColor, Option<(u32, u32)>) {
    let k = i % PREDICTION_COLOURS.len();
    (PREDICTION_COLOURS[k], PREDICTION_DASHES[k])
}

/// Register the vendored font once per process.
fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT_BYTES).is_ok()
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Draws a panel's `header` (its name and what its residual shows) left-aligned over the
/// panel's plot in `area`; returns the plot's left edge, px (the y labels' area and 2 px).
fn panel_header(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    header: String,
) -> Result<u32, PlotError> {
    const LEFT: u32 = 92;
    area.draw(&Text::new(
        header,
        (LEFT as i32, 16),
        text(13.5, &MUTED).pos(Pos::new(HPos::Left, VPos::Center)),
    ))
    .map_err(render_err)?;
    Ok(LEFT)
}

fn render_err<E: std::fmt::Debug>(e: E) -> PlotError {
    PlotError::Render(format!("{e:?}"))
}

// ---------------------------------------------------------------------------------------------
// Validation and ranges
// ---------------------------------------------------------------------------------------------

fn check_finite(series: &str, values: &[f64]) -> Result<(), PlotError> {
    if values.is_empty() {
        return Err(PlotError::Empty {
            what: series.to_string(),
        });
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(PlotError::NonFinite {
            series: series.to_string(),
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// `[lo, hi]` of the values, widened by `frac` of the span on both sides; a zero span is padded
/// to a visible one (±1 unit around 0, ±10 % around another value).
fn padded_range(values: impl Iterator<Item = f64>, frac: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return (-1.0, 1.0);
    }
    let span = hi - lo;
    if span <= f64::EPSILON * lo.abs().max(hi.abs()).max(1.0) {
        let pad = if lo.abs() < 1e-12 {
            1.0
        } else {
            0.1 * lo.abs()
        };
        return (lo - pad, hi + pad);
    }
    (lo - frac * span, hi + frac * span)
}

/// Root-mean-square of `a − b`.
fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n == 0 {
        return 0.0;
    }
    let s: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    (s / n as f64).sqrt()
}

/// Tick label: the fewest decimals (up to 6) that represent a "nice" tick value, no `-0`, with
/// a typographic minus sign.
fn tick_label(v: f64) -> String {
    let v = if v.abs() < 1e-9 { 0.0 } else { v };
    let s = (0..=6)
        .map(|decimals| format!("{v:.decimals$}"))
        .find(|s| {
            s.parse::<f64>()
                .is_ok_and(|back| (back - v).abs() <= 1e-9 * v.abs().max(1.0))
        })
        .unwrap_or_else(|| format!("{v:.3e}"));
    with_minus(s)
}

/// Replace ASCII hyphen-minus by the minus sign U+2212 (as typeset numbers have it).
fn with_minus(s: String) -> String {
    if s.contains('-') {
        s.replace('-', "\u{2212}")
    } else {
        s
    }
}

// ---------------------------------------------------------------------------------------------
// Legend
// ---------------------------------------------------------------------------------------------

/// What a legend entry's sample glyph looks like.
#[derive(Clone, Copy)]
enum Glyph {
    Dot(RGBColor),
    Line(RGBColor, Option<(u32, u32)>),
    Swatch(RGBColor),
    /// A dot with a vertical bar (a value ± its uncertainty).
    DotBar(RGBColor),
    /// An open diamond.
    Diamond(RGBColor),
    /// A small filled square.
    Square(RGBColor),
}

const LEGEND_PX: f64 = 14.0;
const GLYPH_W: i32 = 28;

/// Draw a one-line legend centred at `(cx, cy)` (pixels of `area`).
fn draw_legend(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    entries: &[(Glyph, String)],
    (cx, cy): (i32, i32),
) -> Result<(), PlotError> {
    let style = text(LEGEND_PX, &INK);
    let gap_glyph = 6;
    let gap_entry = 26;
    let mut widths = Vec::with_capacity(entries.len());
    for (_, label) in entries {
        let (w, _) = area.estimate_text_size(label, &style).map_err(render_err)?;
        widths.push(w as i32);
    }
    let total: i32 = widths.iter().map(|w| GLYPH_W + gap_glyph + w).sum::<i32>()
        + gap_entry * (entries.len() as i32 - 1).max(0);
    let mut x = cx - total / 2;
    let label_style = style.pos(Pos::new(HPos::Left, VPos::Center));
    for ((glyph, label), w) in entries.iter().zip(&widths) {
        draw_glyph(area, *glyph, (x, cy))?;
        area.draw(&Text::new(
            label.as_str(),
            (x + GLYPH_W + gap_glyph, cy),
            label_style.clone(),
        ))
        .map_err(render_err)?;
        x += GLYPH_W + gap_glyph + w + gap_entry;
    }
    Ok(())
}

fn draw_glyph(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    glyph: Glyph,
    (x, cy): (i32, i32),
) -> Result<(), PlotError> {
    match glyph {
        Glyph::Dot(c) => {
            for dx in [GLYPH_W / 4, GLYPH_W / 2, 3 * GLYPH_W / 4] {
                area.draw(&Circle::new((x + dx, cy), 2, c.filled()))
                    .map_err(render_err)?;
            }
        }
        Glyph::Line(c, dash) => {
            let style = c.stroke_width(2);
            let pts = vec![(x, cy), (x + GLYPH_W, cy)];
            match dash {
                None => area.draw(&PathElement::new(pts, style)),
                Some((d, g)) => area.draw(&DashedPathElement::new(pts, d, g, style)),
            }
            .map_err(render_err)?;
        }
        Glyph::Swatch(c) => {
            area.draw(&Rectangle::new(
                [(x + 4, cy - 6), (x + GLYPH_W - 4, cy + 6)],
                c.filled(),
            ))
            .map_err(render_err)?;
        }
        Glyph::DotBar(c) => {
            let mx = x + GLYPH_W / 2;
            area.draw(&PathElement::new(
                vec![(mx, cy - 7), (mx, cy + 7)],
                c.stroke_width(1),
            ))
            .map_err(render_err)?;
            for y in [cy - 7, cy + 7] {
                area.draw(&PathElement::new(
                    vec![(mx - 4, y), (mx + 4, y)],
                    c.stroke_width(1),
                ))
                .map_err(render_err)?;
            }
            area.draw(&Circle::new((mx, cy), 3, c.filled()))
                .map_err(render_err)?;
        }
        Glyph::Diamond(c) => {
            let mx = x + GLYPH_W / 2;
            area.draw(&PathElement::new(
                vec![
                    (mx, cy - 6),
                    (mx + 6, cy),
                    (mx, cy + 6),
                    (mx - 6, cy),
                    (mx, cy - 6),
                ],
                c.stroke_width(2),
            ))
            .map_err(render_err)?;
        }
        Glyph::Square(c) => {
            let mx = x + GLYPH_W / 2;
            area.draw(&Rectangle::new(
                [(mx - 3, cy - 3), (mx + 3, cy + 3)],
                c.filled(),
            ))
            .map_err(render_err)?;
        }
    }
    Ok(())
}

fn draw_title(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    title: &str,
    (cx, y): (i32, i32),
) -> Result<(), PlotError> {
    let style = text(19.0, &INK).pos(Pos::new(HPos::Center, VPos::Top));
    area.draw(&Text::new(title, (cx, y), style))
        .map_err(render_err)
}

// ---------------------------------------------------------------------------------------------
// Path comparison (seed Figures 7–9)
// ---------------------------------------------------------------------------------------------

const PATH_WIDTH: u32 = 1100;
const PANEL_HEIGHT: u32 = 250;
const PATH_HEADER: u32 = 78;
const PATH_FOOTER: u32 = 24;

/// Measured against predicted error along a path, one stacked panel per direction (normally
/// three: x, y and z error), like the seed's Figures 7–9. Returns the SVG document as text.
///
/// - `title`: figure title, e.g. `"K1: measured and predicted error"`.
/// - `x_label`: abscissa label **with its unit**, e.g. `"C (deg)"` or `"sample index"`.
/// - `x`: abscissa value of each sample (any finite values; need not be monotonic).
/// - `panels`: each with the measured error (µm, drawn as points) and predictions (µm, lines);
///   every series must have `x.len()` finite values.
///
/// The legend (one line under the title, never over the data) takes its labels from the first
/// panel. Above each panel the RMS of `measured − prediction` (µm) is printed per prediction.
/// A constant series still plots (its range is padded).
pub fn path_comparison(
    title: &str,
    x_label: &str,
    x: &[f64],
    panels: &[Panel],
) -> Result<String, PlotError> {
    // Validate everything before drawing anything.
    let x_name = if x_label.is_empty() {
        "abscissa"
    } else {
        x_label
    };
    check_finite(x_name, x)?;
    if panels.is_empty() {
        return Err(PlotError::Empty {
            what: "panels".into(),
        });
    }
    for p in panels {
        for s in std::iter::once(&p.measured).chain(&p.predictions) {
            let name = format!("{}: {}", p.name, s.label);
            if s.values.len() != x.len() && !s.values.is_empty() {
                return Err(PlotError::LengthMismatch {
                    series: name,
                    expected: x.len(),
                    found: s.values.len(),
                });
            }
            check_finite(&name, &s.values)?;
        }
    }
    ensure_font()?;

    let n = panels.len() as u32;
    let height = PATH_HEADER + n * PANEL_HEIGHT + PATH_FOOTER;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (PATH_WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(render_err)?;
        let cx = PATH_WIDTH as i32 / 2;
        draw_title(&root, title, (cx, 14))?;

        let first = &panels[0];
        let mut entries = vec![(Glyph::Dot(INK), first.measured.label.clone())];
        for (i, s) in first.predictions.iter().enumerate() {
            let (c, dash) = prediction_style(i);
            entries.push((Glyph::Line(c, dash), s.label.clone()));
        }
        draw_legend(&root, &entries, (cx, 56))?;

        let (xlo, xhi) = padded_range(x.iter().copied(), 0.0);
        let breaks: Vec<i32> = (0..=n)
            .map(|i| (PATH_HEADER + i * PANEL_HEIGHT) as i32)
            .collect();
        let areas = root.split_by_breakpoints([] as [i32; 0], &breaks);
        // areas[0] is the header, areas[1..=n] the panels, areas[n+1] the footer.
        for (k, (panel, area)) in panels.iter().zip(&areas[1..]).enumerate() {
            let last = k + 1 == panels.len();
            draw_path_panel(area, panel, x, (xlo, xhi), last.then_some(x_label))?;
        }
        root.present().map_err(render_err)?;
    }
    Ok(svg)
}

fn draw_path_panel(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    panel: &Panel,
    x: &[f64],
    (xlo, xhi): (f64, f64),
    x_desc: Option<&str>,
) -> Result<(), PlotError> {
    let all = std::iter::once(&panel.measured)
        .chain(&panel.predictions)
        .flat_map(|s| s.values.iter().copied());
    let (ylo, yhi) = padded_range(all, 0.06);

    // Panel header: name and residual RMS per prediction, left-aligned over the plot.
    let mut header = panel.name.clone();
    if !panel.predictions.is_empty() {
        header.push_str("   ·   RMS of measured − predicted: ");
        for (i, s) in panel.predictions.iter().enumerate() {
            if i > 0 {
                header.push_str(", ");
            }
            let _ = write!(
                header,
                "{} {:.2} µm",
                s.label,
                rms_diff(&panel.measured.values, &s.values)
            );
        }
    }
    let left = panel_header(area, header)?;

    let mut chart = ChartBuilder::on(area)
        .margin_top(30)
        .margin_left(6)
        .margin_right(28)
        .margin_bottom(if x_desc.is_some() { 0 } else { 8 })
        .x_label_area_size(if x_desc.is_some() { 52 } else { 26 })
        .y_label_area_size(left - 2)
        .build_cartesian_2d(xlo..xhi, ylo..yhi)
        .map_err(render_err)?;

    let fmt = |v: &f64| tick_label(*v);
    let mut mesh = chart.configure_mesh();
    mesh.label_style(text(12.5, &INK))
        .axis_desc_style(text(14.0, &INK))
        .y_desc(format!("{} (µm)", panel.name))
        .x_labels(12)
        .y_labels(6)
        .max_light_lines(0)
        .bold_line_style(GRID.stroke_width(1))
        .axis_style(AXIS.stroke_width(1))
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt);
    if let Some(d) = x_desc {
        mesh.x_desc(d);
    }
    mesh.draw().map_err(render_err)?;

    if ylo < 0.0 && yhi > 0.0 {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(xlo, 0.0), (xhi, 0.0)],
                RGBColor(0xA0, 0xA0, 0xA0).stroke_width(1),
            )))
            .map_err(render_err)?;
    }

    chart
        .draw_series(
            x.iter()
                .zip(&panel.measured.values)
                .map(|(&xv, &yv)| Circle::new((xv, yv), 2, INK.filled())),
        )
        .map_err(render_err)?;

    for (i, s) in panel.predictions.iter().enumerate() {
        let (c, dash) = prediction_style(i);
        let pts: Vec<(f64, f64)> = x.iter().copied().zip(s.values.iter().copied()).collect();
        let style = c.stroke_width(2);
        match dash {
            None => chart.draw_series(LineSeries::new(pts, style)).map(|_| ()),
            Some((d, g)) => chart
                .draw_series(DashedLineSeries::new(pts, d, g, style))
                .map(|_| ()),
        }
        .map_err(render_err)?;
    }
    Ok(())
}

mod poses;
mod spectrum;
mod trend;

pub use poses::{PoseFigure, PosePanel, probe_poses};
pub use spectrum::spectrum;
pub use trend::{TrendFigure, TrendPoint, trend};

#[cfg(test)]
mod tests;
