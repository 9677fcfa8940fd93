//! The sensor head: every sensor's exact contact together, forward (displacement → readings)
//! and inverse (readings → displacement, with its covariance).
//!
//! **Forward.** Sensor `k` reads `s_k = g_k·t_k(e) + z_k` (mm): `t_k` its exact plunger travel
//! ([`super::contact`]), `g_k` its gain, `z_k` its zero.
//!
//! **Inverse.** The displacement `e` that explains readings `s` is found by Gauss–Newton on the
//! readings weighted by the sensors' noise, `min Σ_k ((s_k − g_k·t_k(e) − z_k)/σ_k)²`, starting
//! from the first-order solution: with three sensors the exact root (Newton), with more the
//! weighted least-squares solution, the best linear unbiased combination of the readings. It
//! stops when a step is below [`CONVERGED_MM`] (1e-13 mm); it has not converged after
//! [`MAX_ITERATIONS`] steps. The iteration contracts by about `|e|/(R + r)` per step for
//! ball tips (quadratically close to the solution) and ends after one step for flat tips,
//! whose readings are linear.
//!
//! **Covariance.** The readings' noise (σ_k, independent) propagates through the inverse's
//! Jacobian at the solution: `Σ = (Jᵀ·W·J)⁻¹` with `J = ∂s/∂e` (rows `g_k·∇t_k`) and
//! `W = diag(1/σ_k²)`. With three sensors this is `J⁻¹·diag(σ²)·J⁻ᵀ`; with more and equal σ it
//! is `J⁺·diag(σ²)·J⁺ᵀ`.

use super::contact::{ContactError, SensorGeometry};
use model_spec::instrument::{Instrument, first_order_matrix};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// A Gauss–Newton step below this (mm, largest component) ends the inverse.
pub const CONVERGED_MM: f64 = 1e-13;

/// The most Gauss–Newton steps of the inverse.
pub const MAX_ITERATIONS: usize = 30;

/// The largest condition number (ratio of the largest to the smallest eigenvalue) of
/// `Jᵀ·W·J` the inverse accepts: beyond it the sensors no longer determine the displacement
/// (their contact normals are nearly coplanar at that displacement).
pub const MAX_CONDITION: f64 = 1e10;

/// How far the readings of more than three sensors may disagree, in units of each sensor's σ:
/// beyond it the readings are not those of the described head (a sensor off the ball, the wrong
/// description or columns), not noise.
pub const MAX_DISAGREEMENT_SIGMAS: f64 = 1000.0;

/// Why readings give no displacement.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InverseError {
    /// The readings are not one per sensor, or not finite.
    #[error("{0}")]
    Readings(String),
    /// A sensor cannot touch the ball at the displacement tried.
    #[error(transparent)]
    Contact(#[from] ContactError),
    /// The sensors do not determine the displacement there.
    #[error(
        "the sensors do not determine the displacement at ({x:.4}, {y:.4}, {z:.4}) µm: their contact normals are nearly coplanar (condition number {condition:.2e}, at most {MAX_CONDITION:.0e})"
    )]
    Singular {
        /// The displacement reached, µm.
        x: f64,
        /// y, µm.
        y: f64,
        /// z, µm.
        z: f64,
        /// Condition number of `Jᵀ·W·J`.
        condition: f64,
    },
    /// The iteration did not converge.
    #[error(
        "the exact inverse of the sensor geometry did not converge in {MAX_ITERATIONS} steps (last step {last_step_um:.3e} µm): the readings are far from any displacement the head can read"
    )]
    NotConverged {
        /// The last step, µm.
        last_step_um: f64,
    },
    /// More than three sensors whose readings disagree beyond any noise.
    #[error(
        "the readings of the {sensors} sensors disagree: no displacement of the ball explains them within {sigmas:.0} times a sensor's noise σ (largest residual {residual_um:.3} µm, at sensor {sensor}): they are not the readings of this head (a sensor off the ball, or the wrong description or columns)"
    )]
    Disagree {
        /// How many sensors the head has.
        sensors: usize,
        /// The sensor with the largest residual in units of its σ (with one redundant sensor
        /// the residual is spread over all of them: this is not necessarily the faulty one).
        sensor: String,
        /// Its residual, µm.
        residual_um: f64,
        /// The residual in units of its σ.
        sigmas: f64,
    },
}

/// The displacement the readings give.
#[derive(Clone, Debug, PartialEq)]
pub struct Inverse {
    /// The error vector, mm (nest frame).
    pub displacement: [f64; 3],
    /// Its covariance from the sensors' noise, mm².
    pub covariance: [[f64; 3]; 3],
    /// Gauss–Newton steps taken.
    pub iterations: usize,
    /// The last step, mm.
    pub last_step_mm: f64,
    /// Per sensor, the reading minus what the displacement gives, mm (zero to rounding with
    /// three sensors).
    pub residual_mm: Vec<f64>,
}

/// An instrument ready for exact forward and inverse computations.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorHead {
    /// The sensors' geometries, in the instrument's order.
    pub sensors: Vec<SensorGeometry>,
    /// Gains (reading per travel).
    pub gains: Vec<f64>,
    /// Zeros, mm.
    pub zeros_mm: Vec<f64>,
    /// Noise σ of each reading, mm.
    pub noise_mm: Vec<f64>,
    /// The first-order matrix (rows: change of each reading per error vector at zero).
    first_order: DMatrix<f64>,
}

fn to_array(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

impl SensorHead {
    /// The head of `instrument`.
    pub fn new(instrument: &Instrument) -> SensorHead {
        let rows = first_order_matrix(instrument);
        SensorHead {
            sensors: instrument
                .sensors
                .iter()
                .map(|s| SensorGeometry::new(s, instrument.ball_radius_mm))
                .collect(),
            gains: instrument.sensors.iter().map(|s| s.gain).collect(),
            zeros_mm: instrument.sensors.iter().map(|s| s.zero_mm).collect(),
            noise_mm: instrument.sensors.iter().map(|s| s.noise_mm).collect(),
            first_order: DMatrix::from_fn(rows.len(), 3, |i, j| rows[i][j]),
        }
    }

    /// The readings (mm) at the error vector `e` (mm, nest frame), zeros included.
    ///
    /// # Errors
    /// [`ContactError`] when a sensor cannot touch the ball there.
    pub fn readings(&self, e: [f64; 3]) -> Result<Vec<f64>, ContactError> {
        let e = Vector3::from(e);
        self.sensors
            .iter()
            .enumerate()
            .map(|(k, s)| Ok(self.gains[k] * s.travel(&e)?.0 + self.zeros_mm[k]))
            .collect()
    }

    /// The readings without zeros and the Jacobian `∂s/∂e` (one row per sensor) at `e`.
    fn linearised(&self, e: &Vector3<f64>) -> Result<(DVector<f64>, DMatrix<f64>), ContactError> {
        let n = self.sensors.len();
        let mut s = DVector::zeros(n);
        let mut j = DMatrix::zeros(n, 3);
        for (k, g) in self.sensors.iter().enumerate() {
            let (t, grad) = g.travel(e)?;
            s[k] = self.gains[k] * t;
            for c in 0..3 {
                j[(k, c)] = self.gains[k] * grad[c];
            }
        }
        Ok((s, j))
    }

    /// `Jᵀ·W·J` and `Jᵀ·W·r` for the weights `1/σ²`.
    fn normal_equations(&self, j: &DMatrix<f64>, r: &DVector<f64>) -> (Matrix3<f64>, Vector3<f64>) {
        let mut a = Matrix3::zeros();
        let mut b = Vector3::zeros();
        for k in 0..j.nrows() {
            let w = 1.0 / (self.noise_mm[k] * self.noise_mm[k]);
            let row = Vector3::new(j[(k, 0)], j[(k, 1)], j[(k, 2)]);
            a += row * row.transpose() * w;
            b += row * (w * r[k]);
        }
        (a, b)
    }

    /// `a⁻¹` when its condition number is at most [`MAX_CONDITION`].
    fn solve_inverse(a: &Matrix3<f64>, at: &Vector3<f64>) -> Result<Matrix3<f64>, InverseError> {
        let eigen = a.symmetric_eigenvalues();
        let (lo, hi) = (eigen.min(), eigen.max());
        let condition = if lo > 0.0 { hi / lo } else { f64::INFINITY };
        let singular = || InverseError::Singular {
            x: at.x * 1e3,
            y: at.y * 1e3,
            z: at.z * 1e3,
            condition,
        };
        if condition.is_nan() || condition > MAX_CONDITION {
            return Err(singular());
        }
        a.try_inverse().ok_or_else(singular)
    }

    /// The displacement (mm, nest frame) that the readings `readings` (mm, one per sensor)
    /// give, with its covariance; `zeroed` when the readings were zeroed at the zero position
    /// (the sensors' zeros are then not subtracted: the zeroing replaced them).
    ///
    /// # Errors
    /// [`InverseError`]: readings not one per sensor or not finite, a sensor that cannot touch
    /// the ball, a singular layout at the displacement, no convergence, or (more than three
    /// sensors) readings that disagree beyond [`MAX_DISAGREEMENT_SIGMAS`].
    pub fn displacement(&self, readings: &[f64], zeroed: bool) -> Result<Inverse, InverseError> {
        let n = self.sensors.len();
        if readings.len() != n {
            return Err(InverseError::Readings(format!(
                "{} readings for {n} sensors",
                readings.len()
            )));
        }
        if let Some(k) = readings.iter().position(|v| !v.is_finite()) {
            return Err(InverseError::Readings(format!(
                "the reading of sensor {} is not finite",
                self.sensors[k].name
            )));
        }
        let target = DVector::from_fn(n, |k, _| {
            readings[k] - if zeroed { 0.0 } else { self.zeros_mm[k] }
        });
        // First-order start: the weighted least-squares solution of the linear map.
        let (a0, b0) = self.normal_equations(&self.first_order, &target);
        let mut e = Self::solve_inverse(&a0, &Vector3::zeros())? * b0;
        let mut last_step = f64::INFINITY;
        for iteration in 1..=MAX_ITERATIONS {
            let (s, j) = self.linearised(&e)?;
            let r = &target - &s;
            let (a, b) = self.normal_equations(&j, &r);
            let step = Self::solve_inverse(&a, &e)? * b;
            e += step;
            last_step = step.amax();
            if !e.iter().all(|v| v.is_finite()) {
                break;
            }
            if last_step <= CONVERGED_MM {
                let (s, j) = self.linearised(&e)?;
                let residual = &target - &s;
                let (a, _) = self.normal_equations(&j, &residual);
                let covariance = Self::solve_inverse(&a, &e)?;
                self.agree(&residual)?;
                return Ok(Inverse {
                    displacement: [e.x, e.y, e.z],
                    covariance: to_array(&covariance),
                    iterations: iteration,
                    last_step_mm: last_step,
                    residual_mm: residual.iter().copied().collect(),
                });
            }
        }
        Err(InverseError::NotConverged {
            last_step_um: last_step * 1e3,
        })
    }

    /// Checks that the readings of a redundant head agree within [`MAX_DISAGREEMENT_SIGMAS`].
    fn agree(&self, residual: &DVector<f64>) -> Result<(), InverseError> {
        let worst = (0..residual.len())
            .map(|k| (k, residual[k].abs() / self.noise_mm[k]))
            .fold((0, 0.0f64), |a, b| if b.1 > a.1 { b } else { a });
        if worst.1 > MAX_DISAGREEMENT_SIGMAS {
            return Err(InverseError::Disagree {
                sensors: self.sensors.len(),
                sensor: self.sensors[worst.0].name.clone(),
                residual_um: residual[worst.0] * 1e3,
                sigmas: worst.1,
            });
        }
        Ok(())
    }

    /// The first-order inverse: the weighted least-squares solution of the linear map of the
    /// sensors' first-order directions, `(Aᵀ·W·A)⁻¹·Aᵀ·W·(s − z)` (mm); what a head read as
    /// linear gives.
    ///
    /// # Errors
    /// As [`SensorHead::displacement`] for a singular layout or readings not one per sensor.
    pub fn first_order_displacement(&self, readings: &[f64]) -> Result<[f64; 3], InverseError> {
        let n = self.sensors.len();
        if readings.len() != n {
            return Err(InverseError::Readings(format!(
                "{} readings for {n} sensors",
                readings.len()
            )));
        }
        let target = DVector::from_fn(n, |k, _| readings[k] - self.zeros_mm[k]);
        let (a, b) = self.normal_equations(&self.first_order, &target);
        let e = Self::solve_inverse(&a, &Vector3::zeros())? * b;
        Ok([e.x, e.y, e.z])
    }

    /// The first-order matrix `A` (one row per sensor: the change of its reading per error
    /// vector at zero, mm/mm) and the weights `1/σ_k²` (1/mm²).
    pub fn first_order(&self) -> (&DMatrix<f64>, Vec<f64>) {
        (
            &self.first_order,
            self.noise_mm.iter().map(|s| 1.0 / (s * s)).collect(),
        )
    }
}
