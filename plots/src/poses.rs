//! Readings at discrete poses (a touch probe's sphere centres): per pose and direction the
//! measured reading with its ±1σ bar, the prediction, and the residual, one stacked panel per
//! direction.

use super::*;

const POSES_WIDTH: u32 = 1100;
const POSES_PANEL_HEIGHT: u32 = 250;
const POSES_HEADER: u32 = 78;
/// Room under the last panel for the tick labels (one line per row of a label) and the
/// abscissa's name.
const POSES_FOOTER: u32 = 24;
/// Height of one line of a tick label, px.
const TICK_LINE_PX: u32 = 16;
/// The residual's colour: blue (dark in greyscale), the prediction's: orange (light).
const RESIDUAL: RGBColor = PREDICTION_COLOURS[1];
const PREDICTED: RGBColor = PREDICTION_COLOURS[0];

/// One direction of a pose figure; every value in **µm**, one per pose.
#[derive(Debug, Clone, PartialEq)]
pub struct PosePanel {
    /// What the panel shows, without unit (`"x"`); the ordinate reads `"<name> (µm)"`.
    pub name: String,
    /// The measured reading per pose, µm; drawn as dots.
    pub measured: Vec<f64>,
    /// The standard uncertainty of each reading, µm (≥ 0), drawn as a bar `measured ± std`;
    /// empty: no bars (the readings carry no uncertainty of their own).
    pub std: Vec<f64>,
    /// The prediction per pose, µm; drawn as open diamonds.
    pub predicted: Vec<f64>,
}

/// What a pose figure shows.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseFigure<'a> {
    /// Figure title.
    pub title: &'a str,
    /// The abscissa's label **with its unit** (`"C (deg)"`, `"pose (A, C in deg)"`).
    pub x_label: &'a str,
    /// The abscissa of each pose (an angle, or the pose's number).
    pub x: &'a [f64],
    /// A label per pose, drawn under its abscissa (one text line per element, e.g.
    /// `["A −30", "C 0"]`) instead of numeric ticks; empty: numeric ticks. Labels that would
    /// overlap are thinned to every k-th pose.
    pub ticks: &'a [Vec<String>],
    /// The legend's name of the prediction (`"identified model (reduced)"`).
    pub predicted_label: &'a str,
    /// The panels, normally x, y and z.
    pub panels: &'a [PosePanel],
}

/// A figure of readings at discrete poses: per panel (direction) the measured reading as a
/// dot with a bar of ± its standard uncertainty, the prediction as an open orange diamond and
/// the residual (measured − predicted) as a small blue square, with the RMS of the residual
/// above the panel. Returns the SVG document as text.
///
/// # Errors
/// [`PlotError`] for no pose or panel, a series of another length than the abscissa, a tick
/// list of another length, a non-finite value or a negative uncertainty.
pub fn probe_poses(fig: &PoseFigure<'_>) -> Result<String, PlotError> {
    check_finite("abscissa", fig.x)?;
    if fig.panels.is_empty() {
        return Err(PlotError::Empty {
            what: "panels".into(),
        });
    }
    let n = fig.x.len();
    if !fig.ticks.is_empty() && fig.ticks.len() != n {
        return Err(PlotError::LengthMismatch {
            series: "tick labels".into(),
            expected: n,
            found: fig.ticks.len(),
        });
    }
    for p in fig.panels {
        for (what, values, may_be_empty) in [
            ("measured", &p.measured, false),
            ("std", &p.std, true),
            ("predicted", &p.predicted, false),
        ] {
            let name = format!("{}: {what}", p.name);
            if values.is_empty() && may_be_empty {
                continue;
            }
            if values.len() != n {
                return Err(PlotError::LengthMismatch {
                    series: name,
                    expected: n,
                    found: values.len(),
                });
            }
            check_finite(&name, values)?;
        }
        if let Some(index) = p.std.iter().position(|s| *s < 0.0) {
            return Err(PlotError::NonFinite {
                series: format!("{}: std (negative)", p.name),
                index,
                value: p.std[index],
            });
        }
    }
    ensure_font()?;

    let tick_lines = fig.ticks.iter().map(Vec::len).max().unwrap_or(0) as u32;
    let footer = POSES_FOOTER + tick_lines.saturating_sub(1) * TICK_LINE_PX;
    let panels = fig.panels.len() as u32;
    let height = POSES_HEADER + panels * POSES_PANEL_HEIGHT + footer;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (POSES_WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(render_err)?;
        let cx = POSES_WIDTH as i32 / 2;
        draw_title(&root, fig.title, (cx, 14))?;
        let bars = fig.panels.iter().any(|p| !p.std.is_empty());
        let entries = vec![
            (
                if bars {
                    Glyph::DotBar(INK)
                } else {
                    Glyph::Dot(INK)
                },
                if bars {
                    "measured ± σ".to_string()
                } else {
                    "measured".to_string()
                },
            ),
            (
                Glyph::Diamond(PREDICTED),
                format!("predicted: {}", fig.predicted_label),
            ),
            (
                Glyph::Square(RESIDUAL),
                "residual (measured − predicted)".to_string(),
            ),
        ];
        draw_legend(&root, &entries, (cx, 56))?;
        let (xlo, xhi) = padded_range(fig.x.iter().copied(), 0.04);
        let (xlo, xhi) = if n == 1 {
            (fig.x[0] - 1.0, fig.x[0] + 1.0)
        } else {
            (xlo, xhi)
        };
        let mut breaks: Vec<i32> = (0..=panels)
            .map(|i| (POSES_HEADER + i * POSES_PANEL_HEIGHT) as i32)
            .collect();
        // The last panel takes the footer too, so that its tick labels fit.
        if let Some(last) = breaks.last_mut() {
            *last += footer as i32;
        }
        let areas = root.split_by_breakpoints([] as [i32; 0], &breaks);
        for (k, (panel, area)) in fig.panels.iter().zip(&areas[1..]).enumerate() {
            let last = k + 1 == fig.panels.len();
            draw_pose_panel(
                &root,
                area,
                fig,
                panel,
                (xlo, xhi),
                last.then_some(tick_lines.max(1)),
            )?;
        }
        root.present().map_err(render_err)?;
    }
    Ok(svg)
}

/// One panel; `ticks_below` is the number of tick-label lines of the last panel (`None`: a
/// panel above, without abscissa labels).
fn draw_pose_panel(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    fig: &PoseFigure<'_>,
    panel: &PosePanel,
    (xlo, xhi): (f64, f64),
    ticks_below: Option<u32>,
) -> Result<(), PlotError> {
    let residual: Vec<f64> = panel
        .measured
        .iter()
        .zip(&panel.predicted)
        .map(|(m, p)| m - p)
        .collect();
    let low_high = |i: usize| {
        let s = panel.std.get(i).copied().unwrap_or(0.0);
        [panel.measured[i] - s, panel.measured[i] + s]
    };
    let all = (0..panel.measured.len())
        .flat_map(low_high)
        .chain(panel.predicted.iter().copied())
        .chain(residual.iter().copied())
        .chain(std::iter::once(0.0));
    let (ylo, yhi) = padded_range(all, 0.06);

    let rms = (residual.iter().map(|r| r * r).sum::<f64>() / residual.len() as f64).sqrt();
    let header = format!(
        "{}   ·   RMS of measured − predicted: {rms:.2} µm over {} pose{}",
        panel.name,
        residual.len(),
        if residual.len() == 1 { "" } else { "s" }
    );
    let left = panel_header(area, header)?;

    let categorical = !fig.ticks.is_empty();
    let label_area = match ticks_below {
        Some(lines) => 36 + lines * TICK_LINE_PX,
        None => 26,
    };
    let mut chart = ChartBuilder::on(area)
        .margin_top(30)
        .margin_left(6)
        .margin_right(28)
        .margin_bottom(if ticks_below.is_some() { 0 } else { 8 })
        .x_label_area_size(label_area)
        .y_label_area_size(left - 2)
        .build_cartesian_2d(xlo..xhi, ylo..yhi)
        .map_err(render_err)?;
    let fmt = |v: &f64| tick_label(*v);
    let blank = |_: &f64| String::new();
    let mut mesh = chart.configure_mesh();
    mesh.label_style(text(12.5, &INK))
        .axis_desc_style(text(14.0, &INK))
        .y_desc(format!("{} (µm)", panel.name))
        .x_labels(if categorical { 0 } else { 12 })
        .y_labels(6)
        .max_light_lines(0)
        .bold_line_style(GRID.stroke_width(1))
        .axis_style(AXIS.stroke_width(1))
        .y_label_formatter(&fmt);
    if categorical || ticks_below.is_none() {
        mesh.x_label_formatter(&blank);
    } else {
        mesh.x_label_formatter(&fmt);
    }
    if ticks_below.is_some() {
        mesh.x_desc(fig.x_label);
    }
    mesh.draw().map_err(render_err)?;

    if categorical {
        // A light vertical line at every pose.
        chart
            .draw_series(
                fig.x
                    .iter()
                    .map(|&x| PathElement::new(vec![(x, ylo), (x, yhi)], GRID.stroke_width(1))),
            )
            .map_err(render_err)?;
    }
    if ylo < 0.0 && yhi > 0.0 {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(xlo, 0.0), (xhi, 0.0)],
                RGBColor(0xA0, 0xA0, 0xA0).stroke_width(1),
            )))
            .map_err(render_err)?;
    }
    for (i, &x) in fig.x.iter().enumerate() {
        let (px, py) = chart.backend_coord(&(x, panel.measured[i]));
        if let Some(&s) = panel.std.get(i) {
            let [lo, hi] = low_high(i);
            let (_, y_lo) = chart.backend_coord(&(x, lo));
            let (_, y_hi) = chart.backend_coord(&(x, hi));
            root.draw(&PathElement::new(
                vec![(px, y_lo), (px, y_hi)],
                INK.stroke_width(1),
            ))
            .map_err(render_err)?;
            if s > 0.0 {
                for y in [y_lo, y_hi] {
                    root.draw(&PathElement::new(
                        vec![(px - 4, y), (px + 4, y)],
                        INK.stroke_width(1),
                    ))
                    .map_err(render_err)?;
                }
            }
        }
        let (qx, qy) = chart.backend_coord(&(x, panel.predicted[i]));
        root.draw(&PathElement::new(
            vec![
                (qx, qy - 6),
                (qx + 6, qy),
                (qx, qy + 6),
                (qx - 6, qy),
                (qx, qy - 6),
            ],
            PREDICTED.stroke_width(2),
        ))
        .map_err(render_err)?;
        let (rx, ry) = chart.backend_coord(&(x, residual[i]));
        root.draw(&Rectangle::new(
            [(rx - 3, ry - 3), (rx + 3, ry + 3)],
            RESIDUAL.filled(),
        ))
        .map_err(render_err)?;
        root.draw(&Circle::new((px, py), 3, INK.filled()))
            .map_err(render_err)?;
    }

    if let (true, Some(_)) = (categorical, ticks_below) {
        let at: Vec<(i32, i32)> = fig
            .x
            .iter()
            .map(|&x| chart.backend_coord(&(x, ylo)))
            .collect();
        draw_pose_ticks(root, &at, fig.ticks)?;
    }
    Ok(())
}

/// The pose labels under the last panel (`at`: each pose's pixel on the abscissa), every k-th
/// pose when they would overlap.
fn draw_pose_ticks(
    root: &DrawingArea<SVGBackend<'_>, Shift>,
    at: &[(i32, i32)],
    ticks: &[Vec<String>],
) -> Result<(), PlotError> {
    let style = text(12.5, &INK);
    let mut widest = 0i32;
    for t in ticks.iter().flatten() {
        let (w, _) = root.estimate_text_size(t, &style).map_err(render_err)?;
        widest = widest.max(w as i32);
    }
    let span = match (at.first(), at.last()) {
        (Some(a), Some(b)) if at.len() > 1 => ((b.0 - a.0).abs() / (at.len() as i32 - 1)).max(1),
        _ => i32::MAX,
    };
    let every = ((widest + 8) / span + 1).max(1) as usize;
    let centred = style.pos(Pos::new(HPos::Center, VPos::Top));
    for (i, (&(px, py), lines)) in at.iter().zip(ticks).enumerate() {
        root.draw(&PathElement::new(
            vec![(px, py), (px, py + 5)],
            AXIS.stroke_width(1),
        ))
        .map_err(render_err)?;
        if i % every != 0 {
            continue;
        }
        for (l, line) in lines.iter().enumerate() {
            root.draw(&Text::new(
                line.as_str(),
                (px, py + 8 + l as i32 * TICK_LINE_PX as i32),
                centred.clone(),
            ))
            .map_err(render_err)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panels() -> Vec<PosePanel> {
        (0..3)
            .map(|k| PosePanel {
                name: ["x", "y", "z"][k].into(),
                measured: (0..6)
                    .map(|i| f64::from(i) * 2.0 - 5.0 + k as f64)
                    .collect(),
                std: vec![0.5; 6],
                predicted: (0..6)
                    .map(|i| f64::from(i) * 2.0 - 5.2 + k as f64)
                    .collect(),
            })
            .collect()
    }

    fn ticks() -> Vec<Vec<String>> {
        (0..6)
            .map(|i| vec![format!("A {}", -15 * i), "C 0".into()])
            .collect()
    }

    #[test]
    fn a_pose_figure_names_what_it_draws() {
        let p = panels();
        let t = ticks();
        let x: Vec<f64> = (1..=6).map(f64::from).collect();
        let fig = PoseFigure {
            title: "low.csv: probe readings per pose, µm",
            x_label: "pose (A, C in deg)",
            x: &x,
            ticks: &t,
            predicted_label: "identified model (reduced)",
            panels: &p,
        };
        let svg = probe_poses(&fig).unwrap();
        for s in [
            "low.csv: probe readings per pose, µm",
            "pose (A, C in deg)",
            "measured ± σ",
            "predicted: identified model (reduced)",
            "residual (measured − predicted)",
            "x (µm)",
            "RMS of measured − predicted: 0.20 µm over 6 poses",
            "A -75",
            "C 0",
        ] {
            assert!(svg.contains(s), "`{s}` not in the SVG");
        }
        assert_eq!(svg, probe_poses(&fig).unwrap(), "deterministic");
        // A swept angle: numeric ticks, and no bars without uncertainties.
        let mut p = panels();
        for q in &mut p {
            q.std.clear();
        }
        let angles = [0.0, 60.0, 120.0, 180.0, 240.0, 300.0];
        let svg = probe_poses(&PoseFigure {
            x_label: "C (deg)",
            x: &angles,
            ticks: &[],
            panels: &p,
            ..fig
        })
        .unwrap();
        assert!(svg.contains("C (deg)") && svg.contains("\n300\n"), "{svg}");
        assert!(!svg.contains("measured ± σ"));
    }

    #[test]
    fn bad_input_is_refused() {
        let x: Vec<f64> = (1..=6).map(f64::from).collect();
        let t = ticks();
        let mut p = panels();
        let fig = |p: &[PosePanel], t: &[Vec<String>]| {
            probe_poses(&PoseFigure {
                title: "t",
                x_label: "pose",
                x: &x,
                ticks: t,
                predicted_label: "m",
                panels: p,
            })
        };
        assert!(fig(&p, &t[..3]).is_err(), "ticks of another length");
        p[1].predicted.pop();
        assert!(matches!(fig(&p, &t), Err(PlotError::LengthMismatch { .. })));
        let mut p = panels();
        p[2].measured[4] = f64::INFINITY;
        assert!(matches!(
            fig(&p, &t),
            Err(PlotError::NonFinite { index: 4, .. })
        ));
        let mut p = panels();
        p[0].std[1] = -0.1;
        assert!(fig(&p, &t).is_err());
        assert!(fig(&[], &t).is_err());
    }
}
