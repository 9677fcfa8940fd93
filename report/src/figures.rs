//! The report's figures, drawn by the `plots` crate: measured against predicted error along
//! each path (from the series of `diagnosis::figures`, which the verb that computed the
//! predictions hands over), the residual RMS per direction of each validation, and the residual
//! components of a diagnosis before and after the extension (both from the reports' numbers).

use crate::inputs::Figure;
use crate::json::{DiagnosisReport, ValidationReport};
use diagnosis::figures::{Figures, PathFigure, Series};
use plots::PlotError;

/// An HTML id from a file name (`k4-path.svg` → `fig-k4-path`): letters, digits and `-` only.
pub fn figure_id(name: &str) -> String {
    let stem = name.strip_suffix(".svg").unwrap_or(name);
    let clean: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    format!("fig-{clean}")
}

fn series(s: &Series) -> plots::Series {
    plots::Series::new(s.label.clone(), s.values.clone())
}

/// The SVG of one path figure: the measured error in x, y, z against the predictions along
/// the path, µm (as `rtest diagnose --plot` writes it and the report places it).
///
/// # Errors
/// A series `plots` refuses (empty, non-finite, of the wrong length).
pub fn path_svg(f: &PathFigure) -> Result<String, PlotError> {
    let panels: Vec<plots::Panel> = f
        .panels
        .iter()
        .map(|p| plots::Panel {
            name: p.name.clone(),
            measured: series(&p.measured),
            predictions: p.predictions.iter().map(series).collect(),
        })
        .collect();
    plots::path_comparison(&f.title, &f.x_label, &f.x, &panels)
}

/// The path figures (one per record: the measured error in x, y, z against the predictions
/// along the path, µm), ready for the page.
///
/// # Errors
/// A series `plots` refuses (empty, non-finite, of the wrong length).
pub fn path_figures(figures: &Figures) -> Result<Vec<Figure>, PlotError> {
    figures
        .paths
        .iter()
        .map(|f| {
            let labels: Vec<&str> = f
                .panels
                .first()
                .map(|p| p.predictions.iter().map(|s| s.label.as_str()).collect())
                .unwrap_or_default();
            Ok(Figure {
                id: figure_id(&f.file_name),
                svg: path_svg(f)?,
                caption: format!(
                    "{}. Points: the measured error (µm) in x, y and z of the tool frame; lines: the predictions of the {}; above each panel the RMS of measured minus predicted (µm). Abscissa: {}.",
                    f.title,
                    labels.join(" and the "),
                    f.x_label
                ),
                data: Vec::new(),
            })
        })
        .collect()
}

/// The residual RMS per direction of every validation, on the nominal machine and with the
/// identified model, µm; `None` without validations.
///
/// # Errors
/// A value `plots` refuses.
pub fn validation_figure(
    validations: &[(String, ValidationReport)],
) -> Result<Option<Figure>, PlotError> {
    if validations.is_empty() {
        return Ok(None);
    }
    let mut rows = Vec::new();
    for (_, v) in validations {
        for x in &v.records {
            for (dir, d) in x.rows() {
                rows.push((
                    format!("{} {dir}", record_name(&x.data)),
                    d.measured_rms_um,
                    d.residual_rms_um,
                ));
            }
        }
    }
    let svg = plots::spectrum(
        "Validation: residual RMS per direction",
        "nominal machine (measured)",
        "identified model (measured − predicted)",
        &rows,
    )?;
    Ok(Some(Figure {
        id: "fig-validation".into(),
        svg,
        caption: "Residual RMS (µm, the bar length) on each validation record, per direction x, y, z of the tool frame and over all three: on the nominal machine (the measured error itself) and with the identified model (measured minus predicted). One row per record and direction.".into(),
        data: Vec::new(),
    }))
}

/// The largest residual components of the diagnosed record, with the base model and with the
/// extended model, µm; `None` when the report lists none.
///
/// # Errors
/// A value `plots` refuses.
pub fn spectrum_figure(d: &DiagnosisReport) -> Result<Option<Figure>, PlotError> {
    let rows: Vec<(String, f64, f64)> = d
        .structure
        .before
        .iter()
        .filter_map(|c| {
            c.extended_rms_um.map(|after| {
                (
                    format!("{} {} {}", c.source, c.shape, c.direction),
                    c.explained_rms_um,
                    after,
                )
            })
        })
        .collect();
    if rows.is_empty() {
        return Ok(None);
    }
    let svg = plots::spectrum(
        &format!("{}: residual components", record_name(&d.data)),
        "base model",
        "extended model",
        &rows,
    )?;
    Ok(Some(Figure {
        id: "fig-diagnosis-spectrum".into(),
        svg,
        caption: format!(
            "The largest components of the residual on {} (what each shape alone explains, RMS in µm, the bar length): of the base model {} and of the extended model {}. A row is what the residual follows (an axis, or time), its shape (harmonic:k of a rotary angle, poly:k of a linear position, time:k, reversal) and its direction in the tool frame.",
            d.data, d.base_model, d.extended_model.label
        ),
        data: Vec::new(),
    }))
}

/// A record's name for a figure's rows: its file's stem (`runs/k1.csv` → `k1`).
pub fn record_name(path: &str) -> String {
    std::path::Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_string(), |s| s.to_string_lossy().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_plain() {
        assert_eq!(figure_id("k4-path.svg"), "fig-k4-path");
        assert_eq!(figure_id("K 1<x>.svg"), "fig-k-1-x-");
    }
}
