//! Every result of rtest for people and tools: its JSON ([`json`]), its text ([`text`]) and
//! one self-contained HTML report per R-test check, for the calibration engineer who reads it
//! on screen or prints it to PDF.
//!
//! - [`json`]: the reports of identification, validation, diagnosis, compensation, planning
//!   and the gain tables as serde types, written as JSON; an identification read back;
//! - [`text`]: the same results as text for a terminal;
//! - the HTML report, below: [`inputs`] (the JSON reports it is built from), [`sections`],
//!   [`html`], [`figures`] (and [`probe_figure`], a touch probe's readings per pose) and
//!   [`svg`], [`style`] (with the embedded font, encoded by
//!   [`base64`]).
//!
//! The report is built from the reports rtest writes ([`inputs`]: the JSON of `identify`,
//! `validate`, `diagnose` and `compensate`, recognised by their content and checked to belong
//! to one check) and from the figures a verb has just drawn. [`render`] returns the whole
//! document as a `String`; writing it is the caller's (rtest writes every file through its
//! `output` crate).
//!
//! Sections ([`sections`]): the machine and model; the data (records, samples, input files
//! with their SHA-256); the identified values with their standard uncertainties in µm and
//! µrad, and the groups the data could not separate; the validations; the diagnosis (findings,
//! gain, what remains unexplained); the compensation. A section whose report is absent is one
//! line saying so. An identification or validation may be of one record or of a campaign of
//! several (a record is a campaign of one): a campaign's records are listed with their ball
//! positions and set-ups, its shared values apart from each set-up's and record's, and each
//! validated record with its set-up (fitted, or new and refitted).
//!
//! Self-contained: the document makes no request of any kind. Figures are inline SVG
//! ([`svg`]) drawn by the `plots` crate; their font (the vendored DejaVu Sans) is embedded as
//! an `@font-face` with a `data:` URL ([`style`], about 1.01 MB of the document); a
//! Content-Security-Policy `<meta>` forbids every other source; there is no script. Every text
//! that comes from a file is escaped ([`html::escape`]).

#![warn(missing_docs)]

pub mod base64;
pub mod figures;
pub mod html;
pub mod inputs;
pub mod json;
pub mod probe_figure;
pub mod sections;
pub mod style;
pub mod svg;
pub mod text;

pub use inputs::{Document, Figure, InputError, InputFile, Inputs, MachineFacts};

use html::{Body, escape};

/// The Content-Security-Policy of every report: nothing may be fetched; inline styles, and
/// fonts and images from `data:` URLs only.
pub const CSP: &str =
    "default-src 'none'; style-src 'unsafe-inline'; font-src data:; img-src data:";

/// Why a report cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No report to show.
    #[error("nothing to report: no identification, validation, diagnosis or compensation")]
    Empty,
    /// A figure `plots` could not draw.
    #[error("a figure cannot be drawn: {0}")]
    Plot(#[from] plots::PlotError),
    /// A figure's SVG cannot be placed on the page.
    #[error("{0}")]
    Svg(#[from] svg::SvgError),
}

/// Places figure `f` on the page: its SVG made scalable ([`svg::embed`]) in a `<figure>` with
/// its id and caption.
///
/// # Errors
/// [`RenderError::Svg`].
pub fn place_figure(b: &mut Body, f: &Figure) -> Result<(), RenderError> {
    let svg = svg::embed(&f.id, &f.svg)?;
    b.figure_with_data(&f.id, &svg, &f.caption, &f.data);
    Ok(())
}

/// What the report holds, for its title line (`identification, 2 validations, diagnosis`).
fn contents(inputs: &Inputs) -> String {
    let mut parts = Vec::new();
    if inputs.identification.is_some() {
        parts.push("identification".to_string());
    }
    match inputs.validations.len() {
        0 => {}
        1 => parts.push("validation".into()),
        n => parts.push(format!("{n} validations")),
    }
    if inputs.diagnosis.is_some() {
        parts.push("diagnosis".into());
    }
    if inputs.compensation.is_some() {
        parts.push("compensation".into());
    }
    parts.join(", ")
}

/// The machine the reports are of.
fn machine_name(inputs: &Inputs) -> &str {
    if let Some(m) = &inputs.machine {
        return &m.name;
    }
    inputs
        .identification
        .as_ref()
        .map(|(_, r)| r.machine.as_str())
        .or_else(|| inputs.validations.first().map(|(_, r)| r.machine.as_str()))
        .or_else(|| inputs.diagnosis.as_ref().map(|(_, r)| r.machine.as_str()))
        .or_else(|| {
            inputs
                .compensation
                .as_ref()
                .map(|(_, r)| r.machine.as_str())
        })
        .unwrap_or("")
}

/// The HTML document of `inputs`: head (charset, Content-Security-Policy, title, styles with
/// the embedded font), a title block, a table of contents and the six sections.
///
/// # Errors
/// [`RenderError::Empty`] without any report; a figure that cannot be drawn or placed.
pub fn render(inputs: &Inputs) -> Result<String, RenderError> {
    if inputs.is_empty() {
        return Err(RenderError::Empty);
    }
    let validation = figures::validation_figure(&inputs.validations)?;
    let spectrum = match &inputs.diagnosis {
        Some((_, d)) => figures::spectrum_figure(d)?,
        None => None,
    };
    let machine = machine_name(inputs);
    let title = format!("R-test check of {machine}");
    let mut b = Body::new();
    b.raw(&format!(
        "<header>\n<h1>{}</h1>\n<p class=\"subtitle\">{}</p>\n</header>\n",
        escape(&title),
        escape(&format!(
            "{}. Units: positions in mm, rotary positions in degrees, translational errors in µm, angular errors in µrad.",
            contents(inputs)
        ))
    ));
    b.raw("<nav>\n<ol>\n");
    for (id, heading) in sections::SECTIONS {
        b.raw(&format!(
            "<li><a href=\"#{id}\">{}</a></li>\n",
            escape(heading.split_once(". ").map_or(heading, |(_, h)| h))
        ));
    }
    b.raw("</ol>\n</nav>\n<main>\n");
    sections::machine::write(&mut b, inputs);
    sections::data::write(&mut b, inputs);
    sections::identification::write(&mut b, inputs);
    sections::validation::write(&mut b, inputs, validation.as_ref())?;
    sections::diagnosis::write(&mut b, inputs, spectrum.as_ref())?;
    sections::compensation::write(&mut b, inputs);
    b.raw("</main>\n<footer>\n<p>Written by rtest ");
    b.raw(&escape(env!("CARGO_PKG_VERSION")));
    b.raw(". Self-contained: no external resource; the figures' font (DejaVu Sans, Bitstream Vera licence) is embedded.</p>\n</footer>\n");
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n{}{}</style>\n</head>\n<body>\n{}</body>\n</html>\n",
        escape(&title),
        style::font_face(),
        style::CSS,
        b.into_markup()
    ))
}

#[cfg(test)]
mod tests;
