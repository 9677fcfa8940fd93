//! What a probe cycle does at each pose: the hit pattern (approach directions in the probe's
//! frame, turned into the bed frame by the pose's nominal tool rotation and an azimuth about
//! the stylus that changes from pose to pose), the clearance a simulated approach starts from,
//! its clock and the pre-travel of the probe's trigger.

use nalgebra::{Matrix3, Vector3};

/// The hits of the pattern at every pose (9).
pub const PATTERN_HITS: usize = 9;

/// How far outside the nominal sphere (of radius `R_eff`) the tip centre starts each approach,
/// mm (2): the machine's errors must be smaller than this, or the probe would start inside the
/// sphere.
pub const CLEARANCE_MM: f64 = 2.0;

/// The probing feed, mm/s (2 mm/s, 120 mm/min): the speed of the tip centre along the approach
/// (for the truth's `velocity` terms, and the clock).
pub const PROBING_FEED_MM_PER_S: f64 = 2.0;

/// The time of one hit's cycle, s (4): the approach from the start point at the probing feed
/// (1 s over [`CLEARANCE_MM`]), the retract to the start point and the move to the next start
/// point.
pub const HIT_CYCLE_S: f64 = 4.0;

/// The time of a pose change, s (6): the rotary axes turn and the probe comes to the new
/// pose's first start point; added once before every pose but the first.
pub const POSE_CHANGE_S: f64 = 6.0;

/// The time from the start of an approach to its (nominal) latch, s: [`CLEARANCE_MM`] at
/// [`PROBING_FEED_MM_PER_S`].
pub const APPROACH_S: f64 = CLEARANCE_MM / PROBING_FEED_MM_PER_S;

/// The approach directions of the pattern in the probe's (tool) frame, at azimuth 0, in hit
/// order: the directions of `fitting::sphere::default_pattern` (computed with the same
/// operations, so bit for bit the same):
///
/// - 0–3: at the centre's height (across the stylus), approaching along −x, −y, +x, +y of the
///   tool frame (the hits on the sphere at +x, +y, −x, −y);
/// - 4–7: from the height `R/2` above the centre (along the tool axis), at azimuths 45°, 135°,
///   225°, 315° (of the point hit), pointing down and in;
/// - 8: the pole, approached along −z of the tool frame (along the stylus).
///
/// Every hit lies on the sphere's half towards the spindle, so none is below the sphere's
/// equator seen along the tool axis ([`crate::probe::below_equator`]) at any pose. At a pose
/// the directions are [`PatternTurn::apply`]'d into the bed frame.
pub fn approach_directions() -> [Vector3<f64>; PATTERN_HITS] {
    let quarter = std::f64::consts::FRAC_PI_2;
    let h: f64 = 0.5; // z / R
    let rho = (1.0 - h * h).sqrt();
    let equator = (0..4).map(|k: i32| {
        let a = f64::from(k) * quarter;
        Vector3::new(a.cos(), a.sin(), 0.0)
    });
    let upper = (0..4).map(|k: i32| {
        let a = std::f64::consts::FRAC_PI_4 + f64::from(k) * quarter;
        Vector3::new(rho * a.cos(), rho * a.sin(), h)
    });
    let mut out = [Vector3::zeros(); PATTERN_HITS];
    for (slot, point) in out
        .iter_mut()
        .zip(equator.chain(upper).chain([Vector3::z()]))
    {
        *slot = -point;
    }
    out
}

/// The azimuth offsets of [`PatternAzimuth::Cycled`], degrees, pose after pose.
pub const AZIMUTH_CYCLE_DEG: [f64; 4] = [0.0, 22.5, 45.0, 67.5];

/// How the pattern turns about the stylus from pose to pose.
///
/// A three-lobed pre-travel ([`PreTravel`]) moves the centre a ring of four equally spaced
/// hits gives across the stylus by a tool-frame vector proportional to
/// `(L_c·cos 4φ₀ + L_s·sin 4φ₀, L_c·sin 4φ₀ − L_s·cos 4φ₀)`, `φ₀` the ring's azimuth in the
/// probe's frame (the terms in 2φ₀ cancel over the ring). A pattern fixed in the probe's frame
/// (`φ₀` the same at every pose) moves every centre by the same tool-frame vector, which the
/// probe's zero (`dx0 dy0 dz0`) takes: the lobing is confounded with it. Turning the pattern
/// by 22.5° from pose to pose turns that vector by 90°, so the lobing and the probe's zero
/// separate; hence the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PatternAzimuth {
    /// Pose `i` (0-based, in probing order) turned by [`AZIMUTH_CYCLE_DEG`]`[i mod 4]` about
    /// the stylus (the default).
    #[default]
    Cycled,
    /// Every pose at azimuth 0: on a machine whose tool does not turn (table-table), the
    /// pattern fixed in the bed frame.
    Fixed,
}

impl PatternAzimuth {
    /// The azimuth offset of pose `pose` (0-based, in probing order), rad.
    pub fn offset_rad(self, pose: usize) -> f64 {
        match self {
            PatternAzimuth::Cycled => {
                AZIMUTH_CYCLE_DEG[pose % AZIMUTH_CYCLE_DEG.len()].to_radians()
            }
            PatternAzimuth::Fixed => 0.0,
        }
    }
}

/// The turn of the pattern from the probe's frame into the bed frame at one pose:
/// `R = R_tool · R_z(φ₀)`, `R_tool` the pose's nominal tool rotation (bed ← tool), `φ₀` its
/// azimuth offset about the stylus.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatternTurn {
    /// `R` (bed ← pattern).
    pub rotation: Matrix3<f64>,
    /// `φ₀`, rad.
    pub azimuth_rad: f64,
}

impl PatternTurn {
    /// The turn at a pose of nominal tool rotation `tool_rotation` (bed ← tool) and azimuth
    /// offset `azimuth_rad` (rad).
    pub fn new(tool_rotation: &Matrix3<f64>, azimuth_rad: f64) -> PatternTurn {
        let (s, c) = azimuth_rad.sin_cos();
        let about_stylus = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
        PatternTurn {
            rotation: tool_rotation * about_stylus,
            azimuth_rad,
        }
    }

    /// `R·d`, bed frame, for `d` in the pattern's frame; `d` itself, bit for bit, when `R` is
    /// the identity (a table-table machine at azimuth 0: the bed-frame pattern as it was).
    pub fn apply(&self, d: &Vector3<f64>) -> Vector3<f64> {
        if self.rotation == Matrix3::identity() {
            *d
        } else {
            self.rotation * d
        }
    }

    /// The approach directions of the pattern at this pose (unit, bed frame), in hit order.
    pub fn approach_directions(&self) -> [Vector3<f64>; PATTERN_HITS] {
        approach_directions().map(|d| self.apply(&d))
    }
}

/// The time of the latch of hit `hit` (0-based over the whole run) of pose `pose` (0-based), s:
/// `pose·`[`POSE_CHANGE_S`]` + hit·`[`HIT_CYCLE_S`]` + `[`APPROACH_S`] (the clock starts when
/// the first approach starts). It is the nominal latch time: the actual contact comes earlier
/// or later by the machine's error along the approach over the feed (a few µs).
pub fn latch_time_s(pose: usize, hit: usize) -> f64 {
    pose as f64 * POSE_CHANGE_S + hit as f64 * HIT_CYCLE_S + APPROACH_S
}

/// The time of a whole run of `poses` poses and `hits` hits in all, s: from the start of the
/// first approach to the end of the last hit's cycle.
pub fn run_time_s(poses: usize, hits: usize) -> f64 {
    poses.saturating_sub(1) as f64 * POSE_CHANGE_S + hits as f64 * HIT_CYCLE_S
}

/// The probe's pre-travel: how far beyond the contact, along the approach, its tip centre is
/// when it latches (mm), constant and three-lobed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreTravel {
    /// The constant part `δ0`, mm.
    pub constant_mm: f64,
    /// The three-lobed part's amplitudes `[L_c, L_s]`, mm.
    pub lobing_mm: [f64; 2],
}

impl PreTravel {
    /// The pre-travel of an approach `approach` (unit, bed frame) of a probe whose frame is
    /// turned by `tool_rotation` (bed ← tool): `δ = δ0 + ρ·(L_c·cos 3φ + L_s·sin 3φ)` (mm),
    /// with `n_t = tool_rotationᵀ·approach`, `ρ = √(n_t.x² + n_t.y²)` its part across the
    /// stylus and `φ = atan2(n_t.y, n_t.x)` its azimuth about the stylus (0 when `ρ` is 0).
    pub fn along(&self, tool_rotation: &Matrix3<f64>, approach: &Vector3<f64>) -> f64 {
        let (rho, phi) = approach_in_probe_frame(&(tool_rotation.transpose() * approach));
        let [c, s] = self.lobing_mm;
        self.constant_mm + rho * (c * (3.0 * phi).cos() + s * (3.0 * phi).sin())
    }

    /// `true` when every part is zero.
    pub fn is_zero(&self) -> bool {
        self.constant_mm == 0.0 && self.lobing_mm == [0.0, 0.0]
    }
}

/// `(ρ, φ)` of an approach direction `n_t` in the probe's (tool) frame (unit vector): its part
/// across the stylus `√(n_t.x² + n_t.y²)` and its azimuth about it `atan2(n_t.y, n_t.x)` (rad;
/// 0 when `ρ` is 0).
pub fn approach_in_probe_frame(n_t: &Vector3<f64>) -> (f64, f64) {
    let rho = n_t.x.hypot(n_t.y);
    let phi = if rho > 0.0 { n_t.y.atan2(n_t.x) } else { 0.0 };
    (rho, phi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_directions_are_unit_and_point_in() {
        let d = approach_directions();
        for n in &d {
            assert!((n.norm() - 1.0).abs() < 1e-15);
        }
        assert_eq!(d[0], Vector3::new(-1.0, -0.0, -0.0));
        assert_eq!(d[8], Vector3::new(-0.0, -0.0, -1.0));
        assert!(d[4..8].iter().all(|n| (n.z + 0.5).abs() < 1e-15));
    }

    #[test]
    fn the_turn_is_the_tool_rotation_after_the_azimuth_about_the_stylus() {
        // Identity and azimuth 0: the pattern's directions bit for bit.
        let still = PatternTurn::new(&Matrix3::identity(), PatternAzimuth::Fixed.offset_rad(5));
        assert_eq!(still.approach_directions(), approach_directions());
        // 22.5° about z (the second pose of the cycle), then a tool tilted 90° about y (its
        // z along the bed's x): the −x approach of the pattern turns to
        // R_y(90°)·(−cos 22.5°, −sin 22.5°, 0).
        let phi = PatternAzimuth::Cycled.offset_rad(1);
        assert_eq!(phi, 22.5f64.to_radians());
        assert_eq!(PatternAzimuth::Cycled.offset_rad(4), 0.0);
        let tilt = Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0);
        let turn = PatternTurn::new(&tilt, phi);
        let n = turn.approach_directions()[0];
        let want = Vector3::new(0.0, -phi.sin(), phi.cos());
        assert!((n - want).norm() < 1e-15, "{n:?}");
        // The pole stays along the stylus: −z of the tool, −x of the bed.
        let pole = turn.approach_directions()[8];
        assert!((pole + Vector3::x()).norm() < 1e-15, "{pole:?}");
    }

    #[test]
    fn lobing_vanishes_along_the_stylus_and_has_three_lobes_across_it() {
        let p = PreTravel {
            constant_mm: 0.001,
            lobing_mm: [0.002, 0.0],
        };
        let id = Matrix3::identity();
        assert_eq!(p.along(&id, &Vector3::new(0.0, 0.0, -1.0)), 0.001);
        assert!((p.along(&id, &Vector3::new(1.0, 0.0, 0.0)) - 0.003).abs() < 1e-15);
        assert!((p.along(&id, &Vector3::new(-1.0, 0.0, 0.0)) + 0.001).abs() < 1e-15);
        // 120° apart: the same lobe.
        let a = 120f64.to_radians();
        let n = Vector3::new(a.cos(), a.sin(), 0.0);
        assert!((p.along(&id, &n) - 0.003).abs() < 1e-15);
        // A tool turned 90° about Z sees +Y of the bed as its +X.
        let turn = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        assert!((p.along(&turn, &Vector3::new(0.0, 1.0, 0.0)) - 0.003).abs() < 1e-15);
    }
}
