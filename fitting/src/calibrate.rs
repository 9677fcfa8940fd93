//! Calibration of an instrument's own errors from known displacements, and what sensor gain
//! errors mean for the instrument terms `S` of the model.
//!
//! **Calibration.** A calibration record gives, per row, a known error vector `e_i` (nest frame,
//! from a reference artefact or a calibrated three-axis move) and every sensor's reading. Each
//! sensor is fitted on its own: its reading is
//!
//! ```text
//! s_i = g₀·(1 + δg)·t(R(ω)ᵀ·e_i) + z
//! ```
//!
//! with `t` the exact travel of the described geometry ([`simulation::instrument::contact`]), `g₀`
//! its described gain, and four parameters: the **gain error** `δg` (relative), the **zero** `z`
//! (mm) and the **direction error** `ω = α·p₁ + β·p₂` (rad): a small rotation of the whole sensor
//! (its direction and tip position) about the nest centre, about two axes `p₁`, `p₂` perpendicular
//! to its measuring direction (`p₁ = m × z`, or `m × x` when `m` is along z, normalised;
//! `p₂ = m × p₁`). Gauss–Newton with the exact geometry; each correction is the least-squares fit of
//! [`crate::least_squares()`] (column scaling, numerical rank), so a quantity the record does not
//! determine (displacements that never move across the sensor leave its tilt about that axis free)
//! gets no number and stays as described. Uncertainties are the fit's, from the residual's σ̂
//! (which also measures the sensor's noise plus the reference's error).
//!
//! **Instrument terms.** Read with the described head, sensors whose gains are off by
//! `δg_k` give, to first order, the error vector `(I + S)·e` with
//!
//! ```text
//! S = (Aᵀ·W·A)⁻¹·Aᵀ·W·diag(δg)·A
//! ```
//!
//! (`A` the first-order matrix, `W = diag(1/σ²)`; for three sensors `S = A⁻¹·diag(δg)·A`, and
//! `U⁻¹·diag(δg)·U` with `U` the directions when the gains are 1). That is the reading model of
//! the instrument terms `SXX … SZY` (`docs/conventions.md`): identifying `S` with the machine is
//! identifying the sensors' gain errors, in the nest frame ([`instrument_terms`]).

use crate::least_squares::{Constraint, EstimateError, Fit, Tolerances, least_squares};
use model_spec::instrument::{GAIN_RANGE, Instrument, MAX_ZERO_UM, Sensor};
use model_spec::units::significant;
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};
use simulation::instrument::CalibrationRecord;
use simulation::instrument::contact::{ContactError, SensorGeometry};
use simulation::instrument::head::SensorHead;

/// The parameters fitted per sensor, in the order of the fit's columns.
pub const PARAMETERS: [&str; 4] = ["gain_error", "zero", "tilt_1", "tilt_2"];

/// The most Gauss–Newton steps of a sensor's calibration.
pub const MAX_ITERATIONS: usize = 20;

/// A step whose largest change of the predicted readings is below this ends the iteration, mm.
pub const CONVERGED_MM: f64 = 1e-12;

/// The largest direction error a calibration may find, rad (about 5.7°): beyond it the
/// description is of another head.
pub const MAX_TILT_RAD: f64 = 0.1;

/// What a calibration found for one sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorCalibration {
    /// The sensor's name.
    pub sensor: String,
    /// The axes `p₁`, `p₂` of the tilts (unit vectors, nest frame).
    pub tilt_axes: [[f64; 3]; 2],
    /// The least-squares fit at the solution: parameters [`PARAMETERS`] (relative, mm, rad,
    /// rad); `values[j]` is `None` where the record does not determine it.
    pub fit: Fit,
    /// Gauss–Newton steps taken.
    pub iterations: usize,
}

impl SensorCalibration {
    /// The value and standard uncertainty of parameter `j` of [`PARAMETERS`], when determined.
    pub fn value(&self, j: usize) -> Option<(f64, Option<f64>)> {
        self.fit.values[j].map(|v| (v, self.fit.std[j]))
    }
}

/// A calibration: the calibrated description and what was found per sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// The description with every determined quantity calibrated (gain, zero, direction and tip
    /// position); undetermined ones as they were.
    pub instrument: Instrument,
    /// Per sensor, in the instrument's order.
    pub sensors: Vec<SensorCalibration>,
    /// Rows of the record.
    pub rows: usize,
}

/// Why a calibration failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CalibrationError {
    /// A record that does not fit the instrument or is too short.
    #[error("{0}")]
    Record(String),
    /// A known displacement at which a sensor cannot touch the ball.
    #[error("{place}: {error}")]
    Contact {
        /// `file:line` (or `row N`).
        place: String,
        /// Why.
        error: ContactError,
    },
    /// A fit that failed.
    #[error("sensor {sensor}: {error}")]
    Fit {
        /// The sensor.
        sensor: String,
        /// Why.
        error: EstimateError,
    },
    /// The iteration did not converge.
    #[error(
        "sensor {sensor}: the calibration did not converge in {MAX_ITERATIONS} steps (last step {} µm)", significant(*last_step_um)
    )]
    NotConverged {
        /// The sensor.
        sensor: String,
        /// The last step's largest change of a predicted reading, µm.
        last_step_um: f64,
    },
    /// A step of the iteration that is not finite: the record's readings are far from
    /// anything the head can give.
    #[error(
        "sensor {sensor}: the calibration diverged at step {step} (a correction is not a finite number): check the record's readings against its known displacements"
    )]
    Diverged {
        /// The sensor.
        sensor: String,
        /// The step, from 1.
        step: usize,
    },
    /// A value beyond what a calibration of this head can find.
    #[error(
        "sensor {sensor}: implausible calibration: {why}; the description is not that of the head the record was taken with"
    )]
    Implausible {
        /// The sensor.
        sensor: String,
        /// What is beyond its bound.
        why: String,
    },
}

/// The axes `p₁ = m × z` (or `m × x` when `m` is nearly along z), normalised, and
/// `p₂ = m × p₁` of the tilts of a sensor of measuring direction `m`.
pub fn tilt_axes(m: [f64; 3]) -> [[f64; 3]; 2] {
    let m = Vector3::from(m);
    let reference = if m.z.abs() > 0.9 {
        Vector3::x()
    } else {
        Vector3::z()
    };
    let p1 = m.cross(&reference).normalize();
    let p2 = m.cross(&p1);
    [[p1.x, p1.y, p1.z], [p2.x, p2.y, p2.z]]
}

/// `sensor` turned by `rotation` about the nest centre (direction and tip position), with gain
/// `gain` and zero `zero_mm`.
fn turned(sensor: &Sensor, rotation: &Rotation3<f64>, gain: f64, zero_mm: f64) -> Sensor {
    let d = rotation * Vector3::from(sensor.direction);
    let p = rotation * Vector3::from(sensor.position_mm);
    let unit = d / d.norm();
    Sensor {
        direction: [unit.x, unit.y, unit.z],
        position_mm: [p.x, p.y, p.z],
        gain,
        zero_mm,
        ..sensor.clone()
    }
}

/// Calibrates `instrument` on `record` (see the module documentation).
///
/// # Errors
/// [`CalibrationError`]: rows not one reading per sensor or fewer than five, a known
/// displacement at which a sensor cannot touch the ball (naming the line), a fit that fails or
/// does not converge, or a value beyond its plausibility bound (a gain outside
/// [`GAIN_RANGE`], a zero beyond [`MAX_ZERO_UM`], a tilt beyond [`MAX_TILT_RAD`]).
pub fn calibrate(
    instrument: &Instrument,
    record: &CalibrationRecord,
) -> Result<Calibration, CalibrationError> {
    let rows = record.displacements.len();
    let n_sensors = instrument.sensors.len();
    if record.readings.len() != rows || record.readings.iter().any(|r| r.len() != n_sensors) {
        return Err(CalibrationError::Record(format!(
            "the calibration record has {rows} known displacements and {} rows of readings, each needing {n_sensors} readings",
            record.readings.len()
        )));
    }
    if rows < PARAMETERS.len() + 1 {
        return Err(CalibrationError::Record(format!(
            "the calibration record has {rows} rows; at least {} are needed to fit the {} parameters of each sensor with a degree of freedom left for the uncertainties",
            PARAMETERS.len() + 1,
            PARAMETERS.len()
        )));
    }
    let place = |i: usize| match (record.file.is_empty(), record.lines.get(i)) {
        (false, Some(l)) => format!("{}:{l}", record.file),
        (true, Some(l)) => format!("line {l}"),
        _ => format!("row {}", i + 1),
    };
    let mut out = instrument.clone();
    let mut found = Vec::with_capacity(n_sensors);
    for (k, sensor) in instrument.sensors.iter().enumerate() {
        let readings: Vec<f64> = record.readings.iter().map(|r| r[k]).collect();
        let (cal, calibrated) = calibrate_sensor(
            sensor,
            instrument.ball_radius_mm,
            &record.displacements,
            &readings,
            &place,
        )?;
        out.sensors[k] = calibrated;
        found.push(cal);
    }
    Ok(Calibration {
        instrument: out,
        sensors: found,
        rows,
    })
}

/// One sensor's calibration, and the sensor with its determined quantities calibrated.
fn calibrate_sensor(
    sensor: &Sensor,
    ball_radius_mm: f64,
    displacements: &[[f64; 3]],
    readings: &[f64],
    place: &dyn Fn(usize) -> String,
) -> Result<(SensorCalibration, Sensor), CalibrationError> {
    let axes = tilt_axes(sensor.direction);
    let p = axes.map(Vector3::from);
    let names: Vec<String> = PARAMETERS.iter().map(|s| s.to_string()).collect();
    let fit_error = |error| CalibrationError::Fit {
        sensor: sensor.name.clone(),
        error,
    };
    let y = DVector::from_column_slice(readings);
    if y.iter().any(|v| !v.is_finite()) {
        return Err(CalibrationError::Record(format!(
            "sensor {}: a reading is not finite",
            sensor.name
        )));
    }
    // The state: gain error, zero (mm), the sensor's rotation about the nest centre.
    let (mut gain_error, mut zero, mut rotation) = (0.0, sensor.zero_mm, Rotation3::identity());
    let system = |gain_error: f64, zero: f64, rotation: &Rotation3<f64>| {
        let g = sensor.gain * (1.0 + gain_error);
        let geometry = SensorGeometry::new(&turned(sensor, rotation, g, zero), ball_radius_mm);
        let n = displacements.len();
        let mut h = DMatrix::zeros(n, PARAMETERS.len());
        let mut r = DVector::zeros(n);
        for (i, e) in displacements.iter().enumerate() {
            let e = Vector3::from(*e);
            let (t, grad) = geometry
                .travel(&e)
                .map_err(|error| CalibrationError::Contact {
                    place: place(i),
                    error,
                })?;
            r[i] = y[i] - (g * t + zero);
            h[(i, 0)] = sensor.gain * t;
            h[(i, 1)] = 1.0;
            h[(i, 2)] = g * grad.dot(&e.cross(&p[0]));
            h[(i, 3)] = g * grad.dot(&e.cross(&p[1]));
        }
        Ok::<_, CalibrationError>((h, r))
    };
    let mut last_step = f64::INFINITY;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ITERATIONS {
        let (h, r) = system(gain_error, zero, &rotation)?;
        let fit = least_squares(&h, &r, &names, &Constraint::None, &Tolerances::default())
            .map_err(fit_error)?;
        let d = &fit.solution;
        gain_error += d[0];
        zero += d[1];
        rotation = Rotation3::new(p[0] * d[2] + p[1] * d[3]) * rotation;
        iterations += 1;
        last_step = (&h * DVector::from_column_slice(d)).amax();
        if !last_step.is_finite() {
            return Err(CalibrationError::Diverged {
                sensor: sensor.name.clone(),
                step: iterations,
            });
        }
        if last_step <= CONVERGED_MM {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(CalibrationError::NotConverged {
            sensor: sensor.name.clone(),
            last_step_um: last_step * 1e3,
        });
    }
    // The fit at the solution: its correction is below the tolerance; its uncertainties and
    // identifiability are the calibration's.
    let (h, r) = system(gain_error, zero, &rotation)?;
    let mut fit = least_squares(&h, &r, &names, &Constraint::None, &Tolerances::default())
        .map_err(fit_error)?;
    let omega = rotation.scaled_axis();
    let tilts = [omega.dot(&p[0]), omega.dot(&p[1])];
    let state = [gain_error, zero, tilts[0], tilts[1]];
    for (v, s) in fit.values.iter_mut().zip(state) {
        *v = v.map(|_| s);
    }
    fit.solution = state.to_vec();
    let bad = |why: String| CalibrationError::Implausible {
        sensor: sensor.name.clone(),
        why,
    };
    let gain = sensor.gain * (1.0 + gain_error);
    if fit.values[0].is_some() && !(GAIN_RANGE.0..=GAIN_RANGE.1).contains(&gain) {
        return Err(bad(format!(
            "its gain would be {gain:.6}, outside {} to {}",
            GAIN_RANGE.0, GAIN_RANGE.1
        )));
    }
    if fit.values[1].is_some() && (zero.is_nan() || zero.abs() * 1e3 > MAX_ZERO_UM) {
        return Err(bad(format!(
            "its zero would be {:.3} µm, beyond ±{MAX_ZERO_UM} µm",
            zero * 1e3
        )));
    }
    for (j, t) in tilts.iter().enumerate() {
        if fit.values[2 + j].is_some() && (t.is_nan() || t.abs() > MAX_TILT_RAD) {
            return Err(bad(format!(
                "its direction would be off by {:.0} µrad about tilt axis {}, beyond {} µrad",
                t * 1e6,
                j + 1,
                MAX_TILT_RAD * 1e6
            )));
        }
    }
    // Only what the record determines is calibrated.
    let kept = |j: usize, calibrated: f64, described: f64| {
        if fit.values[j].is_some() {
            calibrated
        } else {
            described
        }
    };
    let turn = Rotation3::new(p[0] * kept(2, tilts[0], 0.0) + p[1] * kept(3, tilts[1], 0.0));
    let calibrated = turned(
        sensor,
        &turn,
        kept(0, gain, sensor.gain),
        kept(1, zero, sensor.zero_mm),
    );
    Ok((
        SensorCalibration {
            sensor: sensor.name.clone(),
            tilt_axes: axes,
            fit,
            iterations,
        },
        calibrated,
    ))
}

/// The instrument terms `S` (row: reading direction x, y, z; column: displacement direction)
/// that gain errors `gain_errors` (relative, one per sensor) of `head`'s sensors give to first
/// order: `S = (Aᵀ·W·A)⁻¹·Aᵀ·W·diag(δg)·A` (see the module documentation).
///
/// `None` when `gain_errors` is not one per sensor or the head's layout is singular (which a
/// validated description never is).
pub fn instrument_terms(head: &SensorHead, gain_errors: &[f64]) -> Option<[[f64; 3]; 3]> {
    let (a, w) = head.first_order();
    if gain_errors.len() != a.nrows() {
        return None;
    }
    let mut ata = Matrix3::zeros();
    let mut atda = Matrix3::zeros();
    for k in 0..a.nrows() {
        let row = Vector3::new(a[(k, 0)], a[(k, 1)], a[(k, 2)]);
        ata += row * row.transpose() * w[k];
        atda += row * row.transpose() * (w[k] * gain_errors[k]);
    }
    let s = ata.try_inverse()? * atda;
    Some([
        [s[(0, 0)], s[(0, 1)], s[(0, 2)]],
        [s[(1, 0)], s[(1, 1)], s[(1, 2)]],
        [s[(2, 0)], s[(2, 1)], s[(2, 2)]],
    ])
}
