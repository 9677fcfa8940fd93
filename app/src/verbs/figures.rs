//! The diagnosis figures drawn: the plain series of `diagnosis::figures` handed to the
//! `plots` crate (path figures through `report::figures::path_svg`, the one conversion the
//! HTML report uses too), which returns SVG text.

use super::{Error, VerbResult};
use diagnosis::figures::Figures;

/// Every figure as (file name, what it shows, SVG text).
pub fn svgs(figures: &Figures) -> VerbResult<Vec<(String, String, String)>> {
    let failed = |e: plots::PlotError| Error::computation(format!("--plot: {e}"));
    let mut out = Vec::new();
    for f in &figures.paths {
        let svg = ::report::figures::path_svg(f).map_err(failed)?;
        out.push((f.file_name.clone(), f.what.clone(), svg));
    }
    for s in &figures.spectra {
        let svg =
            plots::spectrum(&s.title, &s.before_label, &s.after_label, &s.rows).map_err(failed)?;
        out.push((s.file_name.clone(), s.what.clone(), svg));
    }
    Ok(out)
}
