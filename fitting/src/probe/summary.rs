//! What a probe record's sphere fits say, for reports: how many poses and hits, the noise
//! they show against the declared one, the worst hit, the radii and the constant pre-travel.

use super::hits::ProbeRecord;
use formats::probe::SphereCentres;

/// The sphere fits of one probe record, summarised (lengths in µm).
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeSummary {
    /// `hits` (sphere fits made here) or `centres` (centres another device fitted).
    pub kind: &'static str,
    /// Poses (one reading each).
    pub poses: usize,
    /// Hits over all poses (0 for centres).
    pub hits: usize,
    /// The probe's declared σ, µm (hits).
    pub noise_um: Option<f64>,
    /// The σ the fits' residuals show, pooled over the poses, µm (hits, when some pose has
    /// more hits than unknowns).
    pub sigma_posterior_um: Option<f64>,
    /// The largest |residual| of a hit, µm, its pose and its line (hits).
    pub largest_residual: Option<(f64, String, usize)>,
    /// The largest |R_fit − R_sphere| over the poses, µm (hits; centres that give `r`).
    pub largest_radius_deviation_um: Option<f64>,
    /// The constant pre-travel the radii show beyond the declared one and its standard
    /// uncertainty, µm (hits).
    pub pre_travel_um: Option<(f64, f64)>,
}

impl ProbeSummary {
    /// The summary of a record fitted from hits, whose first hits are on `lines` (per pose)
    /// and whose hits are numbered from those lines in order.
    pub fn of_hits(r: &ProbeRecord, hit_lines: &[Vec<usize>], sphere_radius_mm: f64) -> Self {
        let mut largest: Option<(f64, String, usize)> = None;
        for (p, lines) in r.poses.iter().zip(hit_lines) {
            for (res, &line) in p.fit.residuals_mm.iter().zip(lines) {
                let um = res * 1e3;
                if largest.as_ref().is_none_or(|(l, _, _)| um.abs() > l.abs()) {
                    largest = Some((um, p.label.clone(), line));
                }
            }
        }
        let radius = r
            .poses
            .iter()
            .map(|p| ((p.fit.sphere_radius_mm - sphere_radius_mm) * 1e3).abs())
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))));
        ProbeSummary {
            kind: "hits",
            poses: r.poses.len(),
            hits: hit_lines.iter().map(Vec::len).sum(),
            noise_um: Some(r.noise_mm * 1e3),
            sigma_posterior_um: r.sigma_posterior_mm.map(|s| s * 1e3),
            largest_residual: largest,
            largest_radius_deviation_um: radius,
            pre_travel_um: Some((r.pre_travel_mm.0 * 1e3, r.pre_travel_mm.1 * 1e3)),
        }
    }

    /// The summary of a record of centres another device fitted.
    pub fn of_centres(c: &SphereCentres, sphere_radius_mm: f64) -> Self {
        let radius = c
            .poses
            .iter()
            .filter_map(|p| p.radius_mm)
            .map(|r| ((r - sphere_radius_mm) * 1e3).abs())
            .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))));
        ProbeSummary {
            kind: "centres",
            poses: c.poses.len(),
            hits: 0,
            noise_um: None,
            sigma_posterior_um: None,
            largest_residual: None,
            largest_radius_deviation_um: radius,
            pre_travel_um: None,
        }
    }
}
