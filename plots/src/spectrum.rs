//! The residual spectrum: per component, its amplitude before and after a model change, as
//! paired horizontal bars.

use super::*;

const SPECTRUM_WIDTH: u32 = 1000;
const ROW_HEIGHT: u32 = 28;
const SPECTRUM_HEADER: u32 = 84;
const SPECTRUM_FOOTER: u32 = 54;

/// Residual amplitudes per component, before and after (e.g. base and extended model), as a
/// horizontal grouped bar chart: one row per component, labelled on the left, two bars per row
/// (before: light orange, after: dark blue; distinguishable in greyscale), value printed at the
/// end of each bar. Returns the SVG document as text.
///
/// - `title`: figure title.
/// - `before_label`, `after_label`: legend labels of the two bars, e.g. `"base model"`,
///   `"extended model"`.
/// - `rows`: `(label, before µm, after µm)`, e.g. `("C harmonic:2 y", 6.1, 0.3)`; drawn in the
///   given order, top to bottom. Amplitudes are normally ≥ 0; negative values are drawn to the
///   left of zero.
pub fn spectrum<R>(
    title: &str,
    before_label: &str,
    after_label: &str,
    rows: &[R],
) -> Result<String, PlotError>
where
    R: Clone + Into<SpectrumRow>,
{
    let rows: Vec<SpectrumRow> = rows.iter().cloned().map(Into::into).collect();
    if rows.is_empty() {
        return Err(PlotError::Empty {
            what: "spectrum rows".into(),
        });
    }
    for (index, r) in rows.iter().enumerate() {
        for (which, v) in [(before_label, r.before), (after_label, r.after)] {
            if !v.is_finite() {
                return Err(PlotError::NonFinite {
                    series: format!("{} ({which})", r.label),
                    index,
                    value: v,
                });
            }
        }
    }
    ensure_font()?;

    let n = rows.len();
    let height = SPECTRUM_HEADER + n as u32 * ROW_HEIGHT + SPECTRUM_FOOTER;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (SPECTRUM_WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(render_err)?;
        let cx = SPECTRUM_WIDTH as i32 / 2;
        draw_title(&root, title, (cx, 14))?;
        draw_legend(
            &root,
            &[
                (Glyph::Swatch(BEFORE_COLOUR), before_label.to_string()),
                (Glyph::Swatch(AFTER_COLOUR), after_label.to_string()),
            ],
            (cx, 56),
        )?;

        // Left label column as wide as the widest row label.
        let label_style = text(13.0, &INK);
        let mut label_w = 0;
        for r in &rows {
            let (w, _) = root
                .estimate_text_size(&r.label, &label_style)
                .map_err(render_err)?;
            label_w = label_w.max(w as i32);
        }
        let label_area = (label_w + 18).max(60);

        let values = rows.iter().flat_map(|r| [r.before, r.after]);
        let (vlo, vhi) = padded_range(values.chain([0.0]), 0.0);
        // Room on the right for the printed values.
        let span = vhi - vlo;
        let (xlo, xhi) = (
            if vlo < 0.0 { vlo - 0.14 * span } else { 0.0 },
            if vhi > 0.0 { vhi + 0.14 * span } else { 0.0 },
        );

        let (_, body) = root.split_vertically(SPECTRUM_HEADER - 10);
        let mut chart = ChartBuilder::on(&body)
            .margin_top(10)
            .margin_right(30)
            .margin_bottom(6)
            .x_label_area_size(SPECTRUM_FOOTER - 6)
            .y_label_area_size(label_area)
            .build_cartesian_2d(xlo..xhi, 0.0..n as f64)
            .map_err(render_err)?;

        // Zebra stripes behind every other row.
        chart
            .draw_series((0..n).filter(|i| i % 2 == 1).map(|i| {
                let y = (n - 1 - i) as f64;
                Rectangle::new([(xlo, y), (xhi, y + 1.0)], ZEBRA.filled())
            }))
            .map_err(render_err)?;

        let fmt = |v: &f64| tick_label(*v);
        chart
            .configure_mesh()
            .label_style(text(12.5, &INK))
            .axis_desc_style(text(14.0, &INK))
            .x_desc("residual amplitude (µm)")
            .x_labels(10)
            .max_light_lines(0)
            .disable_y_mesh()
            .y_labels(0)
            .bold_line_style(GRID.stroke_width(1))
            .axis_style(AXIS.stroke_width(1))
            .x_label_formatter(&fmt)
            .draw()
            .map_err(render_err)?;

        // Bars: row i occupies y ∈ [n-1-i, n-i]; before above after.
        let bar = 0.34;
        let mid_gap = 0.02;
        for (i, r) in rows.iter().enumerate() {
            let y = (n - 1 - i) as f64;
            let yb = (y + 0.5 + mid_gap, y + 0.5 + mid_gap + bar);
            let ya = (y + 0.5 - mid_gap - bar, y + 0.5 - mid_gap);
            for (v, (y0, y1), c) in [(r.before, yb, BEFORE_COLOUR), (r.after, ya, AFTER_COLOUR)] {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(0.0, y0), (v, y1)],
                        c.filled(),
                    )))
                    .map_err(render_err)?;
                let (px, py) = chart.backend_coord(&(v, 0.5 * (y0 + y1)));
                let (anchor, dx) = if v < 0.0 {
                    (HPos::Right, -4)
                } else {
                    (HPos::Left, 4)
                };
                root.draw(&Text::new(
                    with_minus(format!("{v:.2}")),
                    (px + dx, py),
                    text(10.5, &MUTED).pos(Pos::new(anchor, VPos::Center)),
                ))
                .map_err(render_err)?;
            }
            // Row label, right-aligned against the axis.
            let (ax, ay) = chart.backend_coord(&(xlo, y + 0.5));
            root.draw(&Text::new(
                r.label.as_str(),
                (ax - 8, ay),
                label_style.pos(Pos::new(HPos::Right, VPos::Center)),
            ))
            .map_err(render_err)?;
        }
        if xlo < 0.0 {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(0.0, 0.0), (0.0, n as f64)],
                    AXIS.stroke_width(1),
                )))
                .map_err(render_err)?;
        }
        root.present().map_err(render_err)?;
    }
    Ok(svg)
}
