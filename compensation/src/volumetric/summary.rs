//! What `rtest volumetric` reports: the measurements the model was built from, and over each
//! set of poses (the grid, the path, or a default lattice) the largest and RMS predicted error
//! per direction and correction per axis, for people and as JSON.

use super::VolumetricError;
use super::compensate::{Corrected, correct};
use super::laser::{AxisMeasurement, column_axes};
use super::model::VolumetricModel;
use super::squareness::Squareness;
use model_spec::Machine;
use model_spec::units::{fixed, format_scaled, parse_scaled, short};
use nalgebra::Vector3;
use serde::Serialize;
use std::collections::BTreeMap;

/// The largest magnitude and the RMS of one quantity over a set of poses, µm.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Stats {
    /// Largest magnitude, µm.
    pub max_abs: f64,
    /// Root mean square, µm.
    pub rms: f64,
}

impl Stats {
    /// The statistics of `values` (mm), in µm.
    pub fn of(values: impl Iterator<Item = f64>) -> Stats {
        let (mut max, mut sum, mut n) = (0.0f64, 0.0, 0usize);
        for v in values {
            max = max.max(v.abs());
            sum += v * v;
            n += 1;
        }
        let rms = if n == 0 { 0.0 } else { (sum / n as f64).sqrt() };
        Stats {
            max_abs: um(max),
            rms: um(rms),
        }
    }
}

/// A value in mm as µm, the decimal point moved in the shortest decimal (0.012 mm is 12 µm).
fn um(mm: f64) -> f64 {
    parse_scaled(&format_scaled(mm, 3), 0).unwrap_or(mm * 1e3)
}

/// The predicted error and the correction over one set of poses.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SetSummary {
    /// What the poses are: `grid`, `path` or `lattice`.
    pub over: String,
    /// How many poses.
    pub points: usize,
    /// The grid pitch, mm (`grid` and `lattice` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pitch_mm: Option<f64>,
    /// The predicted error `du` at the commanded poses along `x`, `y`, `z`, µm.
    pub error_um: BTreeMap<String, Stats>,
    /// The correction `u_c − u` of each axis (by letter), µm.
    pub correction_um: BTreeMap<String, Stats>,
    /// The most evaluations of `du` a pose needed (see
    /// [`crate::volumetric::compensate`]).
    pub iterations_max: usize,
}

impl SetSummary {
    /// The predicted errors at `poses` ([`Machine::axes`] order, mm) and their corrections
    /// (without the stroke check), summarised; and the predicted errors (mm).
    ///
    /// # Errors
    /// As [`VolumetricModel::du`] and [`correct`].
    pub fn over_poses(
        m: &Machine,
        model: &VolumetricModel,
        over: &str,
        pitch_mm: Option<f64>,
        poses: &[Vec<f64>],
    ) -> Result<(SetSummary, Vec<Vector3<f64>>), VolumetricError> {
        let mut du = Vec::with_capacity(poses.len());
        let mut corrected = Vec::with_capacity(poses.len());
        for p in poses {
            du.push(model.du(p)?);
            corrected.push(correct(model, p)?);
        }
        Ok((SetSummary::new(m, over, pitch_mm, &du, &corrected), du))
    }

    /// The summary of the corrections `corrected` and the predicted errors `du` (mm) at their
    /// commanded poses.
    pub fn new(
        m: &Machine,
        over: &str,
        pitch_mm: Option<f64>,
        du: &[Vector3<f64>],
        corrected: &[Corrected],
    ) -> SetSummary {
        let mut error_um = BTreeMap::new();
        for (i, d) in ["x", "y", "z"].iter().enumerate() {
            error_um.insert(d.to_string(), Stats::of(du.iter().map(|v| v[i])));
        }
        let mut correction_um = BTreeMap::new();
        for a in column_axes(m) {
            let s = Stats::of(corrected.iter().map(|c| c.commands[a] - c.commanded[a]));
            correction_um.insert(m.axes[a].name.clone(), s);
        }
        SetSummary {
            over: over.to_string(),
            points: corrected.len(),
            pitch_mm,
            error_um,
            correction_um,
            iterations_max: corrected.iter().map(|c| c.iterations).max().unwrap_or(0),
        }
    }
}

/// One laser measurement, as the report lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeasurementSummary {
    /// The measured axis's letter.
    pub axis: String,
    /// The file.
    pub file: String,
    /// The number of measured positions.
    pub points: usize,
    /// The measured range `[first, last]`, mm.
    pub range_mm: [f64; 2],
    /// Where the other axes stood, mm, by letter.
    pub stood_mm: BTreeMap<String, f64>,
}

/// The report of `rtest volumetric`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VolumetricReport {
    /// The machine's name.
    pub machine: String,
    /// The laser measurements, in column order of the axes.
    pub measurements: Vec<MeasurementSummary>,
    /// The squareness errors, µrad, by name.
    pub squareness_urad: BTreeMap<String, f64>,
    /// The reference point (where `du` is zero), mm, by axis letter.
    pub reference_mm: BTreeMap<String, f64>,
    /// The sets of poses the errors and corrections are summarised over.
    pub sets: Vec<SetSummary>,
}

impl VolumetricReport {
    /// The report of `model` of `m` built from `measurements` and `squareness`, over `sets`.
    pub fn new(
        m: &Machine,
        model: &VolumetricModel,
        measurements: &[AxisMeasurement],
        squareness: &Squareness,
        sets: Vec<SetSummary>,
    ) -> VolumetricReport {
        let mut list = Vec::new();
        for a in column_axes(m) {
            if let Some(x) = measurements.iter().find(|x| x.axis == a) {
                let stood = column_axes(m)
                    .into_iter()
                    .filter(|&b| b != a)
                    .map(|b| (m.axes[b].name.clone(), x.pose[b]))
                    .collect();
                list.push(MeasurementSummary {
                    axis: m.axes[a].name.clone(),
                    file: x.source.clone(),
                    points: x.positions.len(),
                    range_mm: model.measured_range(a).unwrap_or([f64::NAN; 2]),
                    stood_mm: stood,
                });
            }
        }
        let squareness_urad = squareness
            .values
            .iter()
            .map(|&(e, v)| {
                let urad = parse_scaled(&format_scaled(v, 6), 0).unwrap_or(v * 1e6);
                (m.catalogue[e].name.clone(), urad)
            })
            .collect();
        let reference = model.reference();
        let reference_mm = column_axes(m)
            .into_iter()
            .map(|a| (m.axes[a].name.clone(), reference[a]))
            .collect();
        VolumetricReport {
            machine: m.name.clone(),
            measurements: list,
            squareness_urad,
            reference_mm,
            sets,
        }
    }

    /// The report for people.
    pub fn text(&self) -> String {
        let mut out = format!(
            "Volumetric model of {} (kinematic-parameter independent), from the laser measurements:\n",
            self.machine
        );
        for x in &self.measurements {
            let stood: Vec<String> = x
                .stood_mm
                .iter()
                .map(|(a, v)| format!("{a} = {}", short(*v)))
                .collect();
            out += &format!(
                "  {}: {} positions, {} .. {} mm, with {} mm ({})\n",
                x.axis,
                x.points,
                short(x.range_mm[0]),
                short(x.range_mm[1]),
                stood.join(", "),
                x.file
            );
        }
        let sq: Vec<String> = self
            .squareness_urad
            .iter()
            .map(|(n, v)| format!("{n} = {}", short(*v)))
            .collect();
        let reference: Vec<String> = self
            .reference_mm
            .iter()
            .map(|(a, v)| format!("{a} = {}", short(*v)))
            .collect();
        out += &format!(
            "  squareness {} µrad; du = 0 at {} mm\n",
            sq.join(", "),
            reference.join(", ")
        );
        for s in &self.sets {
            let what = match (s.over.as_str(), s.pitch_mm) {
                ("path", _) => "the path".to_string(),
                (o, Some(p)) => format!("the {o} (pitch {} mm)", short(p)),
                (o, None) => format!("the {o}"),
            };
            out += &format!(
                "\nOver {what}, {} poses; each correction converged in at most {} iterations:\n",
                s.points, s.iterations_max
            );
            out += &format!("  {:<20} {:>10} {:>10}\n", "(µm)", "max |.|", "RMS");
            let rows = s
                .error_um
                .iter()
                .map(|(d, st)| (format!("predicted error {d}"), st))
                .chain(
                    s.correction_um
                        .iter()
                        .map(|(a, st)| (format!("correction of {a}"), st)),
                );
            for (label, st) in rows {
                out += &format!(
                    "  {label:<20} {:>10} {:>10}\n",
                    fixed(st.max_abs, 3),
                    fixed(st.rms, 3)
                );
            }
        }
        out
    }
}
