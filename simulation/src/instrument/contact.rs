//! The exact contact of one sensor with the ball: the plunger travel for a displacement of the
//! nest relative to the ball, and its gradient.
//!
//! With `e` the error vector (nest centre minus ball centre, mm), the ball centre is at
//! `c = −e` in the nest frame. `n = −m` is the plunger axis (the tip moves along `n` when the
//! plunger is pushed in) and `q` the tip centre (ball tip) or face centre (flat tip) at zero
//! reading ([`model_spec::instrument::Sensor::tip_at_zero`]). The travel `t` (mm, positive
//! pushed in) is
//!
//! - **flat tip**: the face stays tangent to the ball, `n·(q + t·n) = n·c + R`, so
//!   `t = n·c = m·e` exactly; the contact, at `c + R·n`, stays on the face while
//!   `|(c − q)⊥| ≤ face radius` (the part perpendicular to `n`);
//! - **ball tip** of radius `r`: the tip centre `q + t·n` is at `R + r` from the ball centre,
//!   `|q + t·n − c| = R + r`, the root `t = −b + √(b² − |w|² + (R + r)²)` with `w = q − c`,
//!   `b = n·w`. When the axis passes through the nest centre this is
//!   `t = m·e − (R + r) + √((R + r)² − |e⊥|²) ≈ m·e − |e⊥|²/(2(R + r))`, `e⊥` the displacement
//!   perpendicular to the axis. The contact is on the tip's ball while the line between the
//!   two centres is within [`MAX_TIP_CONTACT_ANGLE_DEG`] of the plunger axis.
//!
//! The gradient of `t` with respect to `e` is `m` (flat) and `−k/(n·k)` (ball tip), `k` the
//! vector from the ball centre to the tip centre.

use model_spec::instrument::{Sensor, Tip};
use model_spec::units::significant;
use nalgebra::Vector3;

/// The largest angle between a ball tip's plunger axis and the line from the ball centre to
/// the tip centre, degrees: beyond it a real tip touches with its flank or stem.
pub const MAX_TIP_CONTACT_ANGLE_DEG: f64 = 60.0;

/// Why a sensor cannot touch the ball at a displacement.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// The contact point left a flat face.
    #[error(
        "sensor {sensor}: the ball touches the flat face {} mm from its centre, off the face (radius {} mm)", significant(*lateral_mm), significant(*face_radius_mm)
    )]
    OffFace {
        /// The sensor's name.
        sensor: String,
        /// Distance of the contact from the face centre, mm.
        lateral_mm: f64,
        /// The face's radius, mm.
        face_radius_mm: f64,
    },
    /// A ball tip whose axis passes too far from the ball centre to touch it, or touches it
    /// beyond [`MAX_TIP_CONTACT_ANGLE_DEG`].
    #[error(
        "sensor {sensor}: the ball tip cannot touch the ball on its face: the ball centre is {} mm off the plunger axis (the tip's ball touches within {} mm)", significant(*off_axis_mm), significant(*limit_mm)
    )]
    NoContact {
        /// The sensor's name.
        sensor: String,
        /// Distance of the ball centre from the plunger axis, mm.
        off_axis_mm: f64,
        /// The largest such distance at which the tip still touches with its face, mm.
        limit_mm: f64,
    },
}

/// One sensor's geometry, ready for the exact contact (mm, nest frame).
#[derive(Clone, Debug, PartialEq)]
pub struct SensorGeometry {
    /// The sensor's name.
    pub name: String,
    /// Measuring direction `m` (unit).
    pub direction: Vector3<f64>,
    /// Tip (or face) centre at zero reading, on the exact contact, mm.
    pub tip_at_zero: Vector3<f64>,
    /// Ball radius, mm.
    pub ball_radius_mm: f64,
    /// The tip.
    pub tip: Tip,
    /// The travel the contact equations give at zero displacement (rounding of the tip
    /// position, about 1e-15 mm), subtracted so that zero displacement reads exactly zero.
    rounding_mm: f64,
}

impl SensorGeometry {
    /// The geometry of `sensor` on a ball of radius `ball_radius_mm`.
    pub fn new(sensor: &Sensor, ball_radius_mm: f64) -> SensorGeometry {
        let mut g = SensorGeometry {
            name: sensor.name.clone(),
            direction: Vector3::from(sensor.direction),
            tip_at_zero: Vector3::from(sensor.tip_at_zero(ball_radius_mm)),
            ball_radius_mm,
            tip: sensor.tip,
            rounding_mm: 0.0,
        };
        // A description that validated touches the ball at zero; if rounding says otherwise,
        // the travel there is 0 and the first call reports it.
        g.rounding_mm = g.travel(&Vector3::zeros()).map_or(0.0, |(t, _)| t);
        g
    }

    /// The plunger travel (mm, positive pushed in) at the error vector `e` (mm), and its
    /// gradient with respect to `e` (mm/mm).
    ///
    /// # Errors
    /// [`ContactError`] when the sensor cannot touch the ball there.
    pub fn travel(&self, e: &Vector3<f64>) -> Result<(f64, Vector3<f64>), ContactError> {
        let n = -self.direction;
        let c = -e;
        match self.tip {
            Tip::Flat { face_radius_mm } => {
                let v = c - self.tip_at_zero;
                let lateral = (v - n * n.dot(&v)).norm();
                if !(lateral.is_finite() && lateral <= face_radius_mm) {
                    return Err(ContactError::OffFace {
                        sensor: self.name.clone(),
                        lateral_mm: lateral,
                        face_radius_mm,
                    });
                }
                Ok((self.direction.dot(e) - self.rounding_mm, self.direction))
            }
            Tip::Sphere { radius_mm } => {
                let rho = self.ball_radius_mm + radius_mm;
                let w = self.tip_at_zero - c;
                let b = n.dot(&w);
                let off_axis2 = (w.norm_squared() - b * b).max(0.0);
                let limit = rho * MAX_TIP_CONTACT_ANGLE_DEG.to_radians().sin();
                let disc = rho * rho - off_axis2;
                // The message's distance from the perpendicular part itself: the difference
                // of squares above loses it for a far-off ball (it can even be NaN).
                let no_contact = || ContactError::NoContact {
                    sensor: self.name.clone(),
                    off_axis_mm: (w - n * b).norm(),
                    limit_mm: limit,
                };
                if !(w.norm_squared().is_finite() && off_axis2 <= limit * limit && disc > 0.0) {
                    return Err(no_contact());
                }
                let t = -b + disc.sqrt();
                let k = w + n * t;
                let along = n.dot(&k);
                if along.is_nan() || along <= 0.0 {
                    return Err(no_contact());
                }
                Ok((t - self.rounding_mm, -k / along))
            }
        }
    }
}
