//! The trend of one error over a machine's checks: each check's value with its uncertainty
//! bar, the tolerance band, the baseline, and a fitted trend line.

use super::*;

const TREND_WIDTH: u32 = 1000;
const TREND_HEIGHT: u32 = 540;
const TREND_HEADER: u32 = 100;

/// Light green of the tolerance band, and its edges.
const BAND: RGBColor = RGBColor(0xE3, 0xF2, 0xE6);
const BAND_EDGE: RGBColor = RGBColor(0x00, 0x9E, 0x73);
/// A flagged check: vermillion (Okabe–Ito), darker than the band.
const FLAGGED: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
/// The trend line: blue.
const LINE: RGBColor = RGBColor(0x00, 0x72, 0xB2);

/// One check of a trend figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrendPoint {
    /// Its abscissa (e.g. days since the first check).
    pub x: f64,
    /// Its value, in the figure's unit.
    pub value: f64,
    /// Its standard uncertainty, same unit (≥ 0): the bar is `value ± std`.
    pub std: f64,
    /// Whether a test flagged it (drawn in another colour and shape).
    pub flagged: bool,
}

/// What a trend figure shows. Values are in `unit`; the abscissa is whatever `x_label` says.
#[derive(Debug, Clone, PartialEq)]
pub struct TrendFigure<'a> {
    /// Figure title, e.g. `"XOC of machine M123"`.
    pub title: &'a str,
    /// The abscissa's label **with its unit**, e.g. `"days since 2025-01-06"`.
    pub x_label: &'a str,
    /// What the values are, without unit (`"XOC"`); the ordinate reads `"<name> (<unit>)"`.
    pub name: &'a str,
    /// The values' unit as people read it (`"µm"`, `"µrad"`).
    pub unit: &'a str,
    /// The checks, in any order; at least one.
    pub points: &'a [TrendPoint],
    /// The tolerance `|value| ≤ limit` (> 0), drawn as a band; `None`: no band.
    pub tolerance: Option<f64>,
    /// The baseline's value and its legend label (`"baseline: check 1"`).
    pub baseline: Option<(f64, String)>,
    /// A fitted line from `(x0, y0)` to `(x1, y1)` and its legend label.
    pub line: Option<([(f64, f64); 2], String)>,
}

/// A figure of one error's trend over the checks: every check's value as a point with a bar
/// of ± its standard uncertainty (flagged checks as vermillion diamonds), the tolerance band
/// `±limit` (shaded, when it lies near the data; otherwise named in the legend as outside the
/// plotted range), the baseline as a dotted line and the fitted trend line. Returns the SVG
/// document as text.
///
/// # Errors
/// [`PlotError`] for no point, a non-finite number, a negative uncertainty or a tolerance
/// that is not positive.
pub fn trend(fig: &TrendFigure<'_>) -> Result<String, PlotError> {
    if fig.points.is_empty() {
        return Err(PlotError::Empty {
            what: "trend points".into(),
        });
    }
    for (what, values) in [
        (
            "abscissa",
            fig.points.iter().map(|p| p.x).collect::<Vec<_>>(),
        ),
        (fig.name, fig.points.iter().map(|p| p.value).collect()),
        ("uncertainty", fig.points.iter().map(|p| p.std).collect()),
    ] {
        check_finite(what, &values)?;
    }
    if let Some(index) = fig.points.iter().position(|p| p.std < 0.0) {
        return Err(PlotError::NonFinite {
            series: "uncertainty (negative)".into(),
            index,
            value: fig.points[index].std,
        });
    }
    if let Some(l) = fig.tolerance
        && !(l.is_finite() && l > 0.0)
    {
        return Err(PlotError::NonFinite {
            series: "tolerance".into(),
            index: 0,
            value: l,
        });
    }
    let mut extra: Vec<f64> = Vec::new();
    if let Some((b, _)) = &fig.baseline {
        extra.push(*b);
    }
    if let Some((ends, _)) = &fig.line {
        extra.extend(ends.iter().flat_map(|(x, y)| [*x, *y]));
    }
    check_finite("baseline and line", &extra)?;
    ensure_font()?;

    let data = fig
        .points
        .iter()
        .flat_map(|p| [p.value - p.std, p.value + p.std])
        .chain(fig.baseline.as_ref().map(|(b, _)| *b))
        .chain(fig.line.iter().flat_map(|(e, _)| [e[0].1, e[1].1]));
    let (lo, hi) = padded_range(data.clone(), 0.0);
    // An edge of the tolerance band is shown when it lies within one data span of the data;
    // the band is shaded when one edge is shown (clipped to the plotted range).
    let span = hi - lo;
    let edges: Vec<f64> = fig
        .tolerance
        .into_iter()
        .flat_map(|l| [-l, l])
        .filter(|&e| e >= lo - span && e <= hi + span)
        .collect();
    let band = fig.tolerance.filter(|_| !edges.is_empty());
    let (ylo, yhi) = padded_range(data.chain(edges.iter().copied()), 0.08);
    let xs = fig
        .points
        .iter()
        .map(|p| p.x)
        .chain(fig.line.iter().flat_map(|(e, _)| [e[0].0, e[1].0]));
    let (xlo, xhi) = padded_range(xs, 0.04);

    let mut svg = String::new();
    {
        let root =
            SVGBackend::with_string(&mut svg, (TREND_WIDTH, TREND_HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(render_err)?;
        let cx = TREND_WIDTH as i32 / 2;
        draw_title(&root, fig.title, (cx, 14))?;
        let mut marks = vec![(
            Glyph::Dot(INK),
            format!("{} ± σ (standard uncertainty)", fig.name),
        )];
        if fig.points.iter().any(|p| p.flagged) {
            marks.push((Glyph::Swatch(FLAGGED), "flagged check".to_string()));
        }
        let mut lines = Vec::new();
        if let Some(l) = fig.tolerance {
            let text = format!("tolerance ±{} {}", tick_label(l), fig.unit);
            if band.is_some() {
                lines.push((Glyph::Swatch(BAND), text));
            } else {
                lines.push((
                    Glyph::Line(BAND_EDGE, Some((5, 3))),
                    format!("{text} (outside the plotted range)"),
                ));
            }
        }
        if let Some((_, label)) = &fig.baseline {
            lines.push((Glyph::Line(MUTED, Some((2, 3))), label.clone()));
        }
        if let Some((_, label)) = &fig.line {
            lines.push((Glyph::Line(LINE, None), label.clone()));
        }
        draw_legend(&root, &marks, (cx, 52))?;
        if !lines.is_empty() {
            draw_legend(&root, &lines, (cx, 76))?;
        }
        let (_, body) = root.split_vertically(TREND_HEADER - 10);
        let mut chart = ChartBuilder::on(&body)
            .margin_top(10)
            .margin_left(6)
            .margin_right(28)
            .margin_bottom(8)
            .x_label_area_size(52)
            .y_label_area_size(90)
            .build_cartesian_2d(xlo..xhi, ylo..yhi)
            .map_err(render_err)?;
        if let Some(l) = band {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(xlo, (-l).max(ylo)), (xhi, l.min(yhi))],
                    BAND.filled(),
                )))
                .map_err(render_err)?;
        }
        let fmt = |v: &f64| tick_label(*v);
        chart
            .configure_mesh()
            .label_style(text(12.5, &INK))
            .axis_desc_style(text(14.0, &INK))
            .y_desc(format!("{} ({})", fig.name, fig.unit))
            .x_desc(fig.x_label)
            .x_labels(10)
            .y_labels(8)
            .max_light_lines(0)
            .bold_line_style(GRID.stroke_width(1))
            .axis_style(AXIS.stroke_width(1))
            .x_label_formatter(&fmt)
            .y_label_formatter(&fmt)
            .draw()
            .map_err(render_err)?;
        for &edge in &edges {
            chart
                .draw_series(std::iter::once(DashedPathElement::new(
                    vec![(xlo, edge), (xhi, edge)],
                    5,
                    3,
                    BAND_EDGE.stroke_width(1),
                )))
                .map_err(render_err)?;
        }
        if let Some((b, _)) = &fig.baseline {
            chart
                .draw_series(std::iter::once(DashedPathElement::new(
                    vec![(xlo, *b), (xhi, *b)],
                    2,
                    3,
                    MUTED.stroke_width(1),
                )))
                .map_err(render_err)?;
        }
        if let Some((ends, _)) = &fig.line {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    ends.to_vec(),
                    LINE.stroke_width(2),
                )))
                .map_err(render_err)?;
        }
        for p in fig.points {
            let colour = if p.flagged { FLAGGED } else { INK };
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.x, p.value - p.std), (p.x, p.value + p.std)],
                    colour.stroke_width(1),
                )))
                .map_err(render_err)?;
            let (px, py) = chart.backend_coord(&(p.x, p.value));
            for y in [p.value - p.std, p.value + p.std] {
                let (_, cy) = chart.backend_coord(&(p.x, y));
                root.draw(&PathElement::new(
                    vec![(px - 4, cy), (px + 4, cy)],
                    colour.stroke_width(1),
                ))
                .map_err(render_err)?;
            }
            if p.flagged {
                root.draw(&Polygon::new(
                    vec![(px, py - 6), (px + 6, py), (px, py + 6), (px - 6, py)],
                    FLAGGED.filled(),
                ))
                .map_err(render_err)?;
            } else {
                root.draw(&Circle::new((px, py), 4, INK.filled()))
                    .map_err(render_err)?;
            }
        }
        root.present().map_err(render_err)?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> Vec<TrendPoint> {
        (0..12)
            .map(|k| TrendPoint {
                x: 7.0 * f64::from(k),
                value: 10.0 + if k > 6 { 0.5 * f64::from(k - 6) } else { 0.0 },
                std: 0.4,
                flagged: k > 9,
            })
            .collect()
    }

    fn figure<'a>(points: &'a [TrendPoint], tolerance: Option<f64>) -> TrendFigure<'a> {
        TrendFigure {
            title: "XOC of machine M123",
            x_label: "days since 2025-01-06",
            name: "XOC",
            unit: "µm",
            points,
            tolerance,
            baseline: Some((10.0, "baseline: check 1".into())),
            line: Some(([(0.0, 9.5), (77.0, 12.6)], "trend: +0.041 µm/day".into())),
        }
    }

    #[test]
    fn a_trend_figure_names_everything_it_draws() {
        let p = points();
        let svg = trend(&figure(&p, Some(13.0))).unwrap();
        for s in [
            "XOC of machine M123",
            "XOC (µm)",
            "days since 2025-01-06",
            "XOC ± σ (standard uncertainty)",
            "flagged check",
            "tolerance ±13 µm",
            "baseline: check 1",
            "trend: +0.041 µm/day",
        ] {
            assert!(svg.contains(s), "`{s}` not in the SVG");
        }
        assert!(!svg.contains("outside the plotted range"));
        // Deterministic.
        assert_eq!(svg, trend(&figure(&p, Some(13.0))).unwrap());
        // A tolerance far from the data is named, not drawn.
        let far = trend(&figure(&p, Some(500.0))).unwrap();
        assert!(far.contains("tolerance ±500 µm (outside the plotted range)"));
        // No tolerance, one point: still a figure.
        let one = [p[0]];
        let svg = trend(&figure(&one, None)).unwrap();
        assert!(!svg.contains("tolerance"));
    }

    #[test]
    fn bad_input_is_refused() {
        let mut p = points();
        assert!(matches!(
            trend(&figure(&[], None)),
            Err(PlotError::Empty { .. })
        ));
        p[3].value = f64::NAN;
        assert!(matches!(
            trend(&figure(&p, None)),
            Err(PlotError::NonFinite { index: 3, .. })
        ));
        let mut p = points();
        p[2].std = -1.0;
        assert!(trend(&figure(&p, None)).is_err());
        assert!(trend(&figure(&points(), Some(0.0))).is_err());
    }
}
