//! The touch probe's lines of the identification text (`docs/probe.md`).

use crate::json::probe::ProbeReport;

/// The probe's sphere fits per record and the dispersion per rotary axis, for people (µm).
pub fn probe(p: &ProbeReport) -> String {
    let mut out = format!(
        "Touch probe{}: tip radius {} mm, sphere radius {} mm, σ {}.\n",
        p.name.as_ref().map(|n| format!(" {n}")).unwrap_or_default(),
        p.tip_radius_mm,
        p.sphere_radius_mm,
        p.noise_um
            .map_or("not declared".to_string(), |s| format!("{s} µm declared")),
    );
    for r in &p.records {
        out.push_str(&format!("  record {}: {} poses", r.label, r.poses));
        if r.kind == "hits" {
            out.push_str(&format!(", {} hits fitted here", r.hits));
        } else {
            out.push_str(" (centres fitted by another device)");
        }
        if let Some(s) = r.sigma_posterior_um {
            out.push_str(&format!("; the residuals' σ {s:.2} µm"));
        }
        if let (Some(v), Some(at)) = (r.largest_residual_um, &r.largest_residual_at) {
            out.push_str(&format!("; largest residual {v:.2} µm at {at}"));
        }
        if let Some(d) = r.largest_radius_deviation_um {
            out.push_str(&format!("; radius off the calibrated by {d:.2} µm at most"));
        }
        if let (Some(v), Some(s)) = (r.pre_travel_um, r.pre_travel_std_um) {
            out.push_str(&format!(
                "; pre-travel beyond the declared {v:.2} ± {s:.2} µm (from the radii)"
            ));
        }
        out.push_str(".\n");
    }
    for a in &p.axes {
        out.push_str(&format!(
            "  axis {}: {} poses; the centres' dispersion {:.2} µm measured, {:.2} µm after the fit (RMS).\n",
            a.axis, a.poses, a.measured_um, a.after_um
        ));
    }
    out
}
