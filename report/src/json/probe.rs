//! The touch probe's part of an identification report: what each record's sphere fits say,
//! and per rotary axis the dispersion of the sphere centres before and after the fit — the
//! figures the controllers' probing cycles report (`docs/probe.md`).
//!
//! ```json
//! "probe": {"name": "TS 460", "tip_radius_mm": 1.5, "sphere_radius_mm": 12.5, "noise_um": 0.5,
//!   "records": [{"label": "p", "kind": "hits", "poses": 12, "hits": 108,
//!                "sigma_posterior_um": 0.49, "largest_residual_um": -1.3,
//!                "largest_residual_at": "p.csv:57 (pose a30c90)",
//!                "largest_radius_deviation_um": 0.6, "pre_travel_um": 0.1,
//!                "pre_travel_std_um": 0.07}],
//!   "axes": [{"axis": "C", "poses": 8, "measured_um": 31.2, "after_um": 0.6}],
//!   "file": "probe.toml", "sha256": "3f0c…", "bytes": 84}
//! ```
//!
//! `file` is the probe instrument file as `--probe` named it, `sha256` and `bytes` the digest
//! and size of the bytes `identify` read from it: `rtest report` reads the same file (relative
//! to the report's directory, as it reads the records) to read the records again through the
//! same sphere fits, and refuses one whose bytes differ. Reports written before these fields
//! existed have none of them (they are read all the same; their records are not drawn).

use fitting::campaign::CampaignIdentification;
use fitting::probe::ProbeSummary;
use formats::probe::ProbeInstrument;
use model_spec::Machine;
use model_spec::sha256::Digest;
use serde::{Deserialize, Serialize};
use simulation::campaign::Campaign;

/// The probe, its records' sphere fits and the dispersion per rotary axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeReport {
    /// The probe's name, when its file gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The stylus tip's radius, mm.
    pub tip_radius_mm: f64,
    /// The sphere's calibrated radius, mm.
    pub sphere_radius_mm: f64,
    /// The probe's declared σ, µm.
    pub noise_um: Option<f64>,
    /// Per record, its sphere fits.
    pub records: Vec<ProbeRecordReport>,
    /// Per rotary axis swept by some record, the centres' dispersion before and after the fit.
    pub axes: Vec<ProbeAxisReport>,
    /// The probe instrument file, as `--probe` named it; absent in reports written before it
    /// was given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// The SHA-256 of the bytes read from `file` (64 lower-case hex digits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
    /// How many bytes were read from `file`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<u64>,
}

/// One probe record's sphere fits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeRecordReport {
    /// The record's label.
    pub label: String,
    /// `hits` (fitted here) or `centres` (fitted by another device).
    pub kind: String,
    /// Poses.
    pub poses: usize,
    /// Hits (0 for centres).
    pub hits: usize,
    /// The σ the residuals show, pooled over the poses, µm.
    pub sigma_posterior_um: Option<f64>,
    /// The largest |residual| of a hit (signed), µm.
    pub largest_residual_um: Option<f64>,
    /// Where it is: `FILE:LINE (pose LABEL)`.
    pub largest_residual_at: Option<String>,
    /// The largest |R_fit − R_sphere| over the poses, µm.
    pub largest_radius_deviation_um: Option<f64>,
    /// The constant pre-travel the radii show beyond the declared one, µm.
    pub pre_travel_um: Option<f64>,
    /// Its standard uncertainty, µm.
    pub pre_travel_std_um: Option<f64>,
}

/// A rotary axis's sweep: the poses where it alone moves (the other rotary axes at the value
/// most poses give them), and the sphere centres' scatter there.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeAxisReport {
    /// The axis.
    pub axis: String,
    /// Poses of its sweep, over every probe record.
    pub poses: usize,
    /// Measured: the RMS distance of the centres' readings from their mean over the sweep
    /// (each record about its own mean), µm: what the kinematics must explain.
    pub measured_um: f64,
    /// After the fit: the RMS length of the residuals over the sweep, µm.
    pub after_um: f64,
}

impl ProbeReport {
    /// The report of `campaign`'s probe records (`summaries`, per record; `None` for a record
    /// not read through the probe) identified as `ident`, with `probe`'s description.
    pub fn of(
        m: &Machine,
        probe: &ProbeInstrument,
        campaign: &Campaign,
        files: &[String],
        summaries: &[Option<ProbeSummary>],
        ident: &CampaignIdentification,
    ) -> ProbeReport {
        let records = campaign
            .records
            .iter()
            .zip(files)
            .zip(summaries)
            .filter_map(|((r, file), s)| s.as_ref().map(|s| record_report(&r.label, file, s)))
            .collect();
        ProbeReport {
            name: probe.name.clone(),
            tip_radius_mm: probe.tip_radius_mm,
            sphere_radius_mm: probe.sphere_radius_mm,
            noise_um: probe.noise_um,
            records,
            axes: axes(m, campaign, summaries, ident),
            file: None,
            sha256: None,
            bytes: None,
        }
    }

    /// The report naming the probe instrument `file` (as `--probe` named it) and the `digest`
    /// of the bytes read from it.
    pub fn read_from(mut self, file: &str, digest: &Digest) -> ProbeReport {
        self.file = Some(file.to_string());
        self.sha256 = Some(digest.sha256.clone());
        self.bytes = Some(digest.bytes);
        self
    }
}

fn record_report(label: &str, file: &str, s: &ProbeSummary) -> ProbeRecordReport {
    ProbeRecordReport {
        label: label.to_string(),
        kind: s.kind.to_string(),
        poses: s.poses,
        hits: s.hits,
        sigma_posterior_um: s.sigma_posterior_um,
        largest_residual_um: s.largest_residual.as_ref().map(|(r, _, _)| *r),
        largest_residual_at: s
            .largest_residual
            .as_ref()
            .map(|(_, pose, line)| format!("{file}:{line} (pose {pose})")),
        largest_radius_deviation_um: s.largest_radius_deviation_um,
        pre_travel_um: s.pre_travel_um.map(|p| p.0),
        pre_travel_std_um: s.pre_travel_um.map(|p| p.1),
    }
}

/// Rotary commands agree when within this, rad (1e-9°-ish).
const SAME_RAD: f64 = 1e-9;

fn axes(
    m: &Machine,
    campaign: &Campaign,
    summaries: &[Option<ProbeSummary>],
    ident: &CampaignIdentification,
) -> Vec<ProbeAxisReport> {
    let rotary: Vec<usize> = m.rotary_axes().collect();
    let probed: Vec<usize> = (0..campaign.records.len())
        .filter(|&r| summaries.get(r).is_some_and(Option::is_some))
        .collect();
    let mut out = Vec::new();
    for &k in &rotary {
        let others: Vec<usize> = rotary.iter().copied().filter(|&j| j != k).collect();
        // The value most poses give each other rotary axis.
        let modal: Vec<f64> = others
            .iter()
            .map(|&j| {
                let values: Vec<f64> = probed
                    .iter()
                    .flat_map(|&r| campaign.records[r].record.samples.iter())
                    .map(|s| s.commands[j])
                    .collect();
                values
                    .iter()
                    .copied()
                    .max_by_key(|v| values.iter().filter(|w| (*w - v).abs() <= SAME_RAD).count())
                    .unwrap_or(0.0)
            })
            .collect();
        let (mut n, mut measured, mut after) = (0usize, 0.0, 0.0);
        let mut positions: Vec<f64> = Vec::new();
        for &r in &probed {
            let record = &campaign.records[r].record;
            let residual = ident.record_residual(r);
            let sweep: Vec<usize> = (0..record.samples.len())
                .filter(|&i| {
                    others
                        .iter()
                        .zip(&modal)
                        .all(|(&j, v)| (record.samples[i].commands[j] - v).abs() <= SAME_RAD)
                })
                .collect();
            if sweep.is_empty() {
                continue;
            }
            let mut mean = [0.0; 3];
            for &i in &sweep {
                for (m, e) in mean.iter_mut().zip(record.measured[i]) {
                    *m += e / sweep.len() as f64;
                }
            }
            for &i in &sweep {
                let e = record.measured[i];
                measured += (0..3).map(|d| (e[d] - mean[d]).powi(2)).sum::<f64>();
                after += residual[i].iter().map(|x| x * x).sum::<f64>();
                let q = record.samples[i].commands[k];
                if !positions.iter().any(|p| (p - q).abs() <= SAME_RAD) {
                    positions.push(q);
                }
            }
            n += sweep.len();
        }
        if positions.len() >= 2 {
            out.push(ProbeAxisReport {
                axis: m.axes[k].name.clone(),
                poses: n,
                measured_um: (measured / n as f64).sqrt() * 1e3,
                after_um: (after / n as f64).sqrt() * 1e3,
            });
        }
    }
    out
}
