//! The touch probe's part of section 3: each record's sphere fits and, per rotary axis, the
//! dispersion of the sphere centres before and after the fit (µm; `docs/probe.md`).

use super::num;
use crate::html::{Body, Cell};
use crate::json::probe::ProbeReport;

/// Writes the probe's subsection of the identification.
pub fn write(b: &mut Body, p: &ProbeReport) {
    b.subheading("Touch probe: sphere fits and the centres' dispersion");
    b.paragraph(&format!(
        "Probe{}: tip radius {} mm, sphere radius {} mm, σ {}. Each pose's hits are fitted by a sphere (free radius, checked against the calibrated one); its centre's offset from where the nominal kinematics puts it is the pose's reading of the error vector.",
        p.name.as_ref().map(|n| format!(" {n}")).unwrap_or_default(),
        model_spec::units::short(p.tip_radius_mm),
        model_spec::units::short(p.sphere_radius_mm),
        p.noise_um
            .map_or("not declared".to_string(), |s| format!("{} µm declared", model_spec::units::short(s)))
    ));
    let opt_um = |v: Option<f64>| v.map_or(Cell::text("—"), |v| Cell::number(num(v, 2)));
    let rows: Vec<Vec<Cell>> = p
        .records
        .iter()
        .map(|r| {
            vec![
                Cell::text(r.label.clone()),
                Cell::text(r.kind.clone()),
                Cell::number(r.poses.to_string()),
                Cell::number(r.hits.to_string()),
                opt_um(r.sigma_posterior_um),
                opt_um(r.largest_residual_um),
                Cell::text(r.largest_residual_at.clone().unwrap_or_else(|| "—".into())),
                opt_um(r.largest_radius_deviation_um),
                match (r.pre_travel_um, r.pre_travel_std_um) {
                    (Some(v), Some(s)) => Cell::number(format!("{} ± {}", num(v, 2), num(s, 2))),
                    _ => Cell::text("—"),
                },
            ]
        })
        .collect();
    b.table(
        "Sphere fits per record (µm): the residuals' σ pooled over the poses, the largest residual and where, the largest radius deviation, the constant pre-travel the radii show beyond the declared one",
        &[
            "Record",
            "Kind",
            "Poses",
            "Hits",
            "σ of the residuals",
            "Largest residual",
            "At",
            "Radius deviation",
            "Pre-travel",
        ],
        &rows,
    );
    if !p.axes.is_empty() {
        let rows: Vec<Vec<Cell>> = p
            .axes
            .iter()
            .map(|a| {
                vec![
                    Cell::text(a.axis.clone()),
                    Cell::number(a.poses.to_string()),
                    Cell::number(num(a.measured_um, 2)),
                    Cell::number(num(a.after_um, 2)),
                ]
            })
            .collect();
        b.table(
            "Dispersion of the sphere centres per rotary axis (RMS, µm): measured (about their mean) and after the fit (the residuals)",
            &["Axis", "Poses", "Measured", "After the fit"],
            &rows,
        );
    }
}
