//! The exact contact of one approach: the distance along the approach at which the tip
//! centre, on the actual machine with the truth's errors and zero offsets evaluated where the
//! axes are, is `R_eff` from the actual sphere centre.

use crate::exact::VirtualMachine;
use crate::model::BasisContext;
use crate::truth::Truth;
use model_spec::Side;
use nalgebra::Vector3;

/// The largest step of a converged contact solve, mm.
pub const CONTACT_TOLERANCE_MM: f64 = 1e-12;

/// Iterations before a contact solve that has not converged is refused.
pub const MAX_CONTACT_ITERATIONS: usize = 200;

/// One approach of the probe: the commands move from `start` by `step` per mm of the nominal
/// gap's change along the approach direction `approach`; the truth's errors are evaluated with
/// the motion, times and velocities of the approach.
pub(super) struct Approach<'a, 'm> {
    /// The machine.
    pub vm: &'a VirtualMachine<'m>,
    /// The truth (its kinematic parameters and errors).
    pub truth: &'a Truth,
    /// The commands at the start point (mm, rad).
    pub start: &'a [f64],
    /// The change of every command per mm of approach (mm/mm; 0 for the rotary axes).
    pub step: &'a [f64],
    /// The approach direction, unit, bed frame.
    pub approach: Vector3<f64>,
    /// The direction of motion of every axis during the approach.
    pub motion: &'a [i8],
    /// The velocity of every axis during the approach (mm/ms, rad/ms).
    pub velocity: &'a [f64],
    /// τ, the time since the first latch and the time since the clock's start (s).
    pub times: [f64; 3],
    /// `R_eff`, mm.
    pub radius_mm: f64,
}

/// Why a contact was not found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum ContactFailure {
    /// The start point is already inside the actual sphere, by this much (mm).
    StartsInside(f64),
    /// The tip reaches the nominal centre without touching: its distance from the actual
    /// centre there (mm).
    NeverTouches(f64),
    /// No step below the tolerance in the allowed iterations; the last step (mm).
    NotConverged(f64),
}

impl Approach<'_, '_> {
    /// The commands at `s` mm along the approach, into `q`.
    pub fn commands_at(&self, s: f64, q: &mut [f64]) {
        for ((q, a), d) in q.iter_mut().zip(self.start).zip(self.step) {
            *q = a + s * d;
        }
    }

    /// The actual gap `P_tip − P_work` (bed frame, mm) at `s`, the truth's errors and zero
    /// offsets evaluated at the commands there: `P_tip = P_tool + R_tool·(dx0, dy0, dz0)`.
    fn gap(&self, s: f64, q: &mut [f64], errors: &mut [f64]) -> Vector3<f64> {
        self.commands_at(s, q);
        let m = self.vm.machine();
        let cx = BasisContext {
            commands: q,
            motion: self.motion,
            tau: self.times[0],
            elapsed_s: self.times[1],
            since_start_s: self.times[2],
            velocity: self.velocity,
            reading: [0.0; 3],
        };
        let mut offsets = [0.0; 3];
        self.truth.evaluate_into(m, &cx, errors, &mut offsets);
        let value = |id: usize| errors[id];
        let params = &self.truth.params;
        let tool = self.vm.transform_with(Side::Tool, q, params, &value);
        let work = self.vm.transform_with(Side::Work, q, params, &value);
        // The truth's zero offsets: the tip centre off the tool point, tool frame.
        let tip = tool.translation.vector + tool.rotation * Vector3::from(offsets);
        tip - work.translation.vector
    }

    /// The distance `s` (mm) along the approach of the exact contact, `‖gap(s)‖ = R_eff`, and
    /// the iterations it took. `s` is bracketed between the start (0, outside the sphere) and
    /// the nominal centre (`reach`, inside it), and found by Newton steps with the nominal
    /// slope `d‖gap‖/ds ≈ ĝap·n`, a step leaving the bracket replaced by bisection; converged
    /// when a step is at most [`CONTACT_TOLERANCE_MM`].
    pub fn contact(&self, reach: f64) -> Result<(f64, usize), ContactFailure> {
        let m = self.vm.machine();
        let mut q = vec![0.0; m.axes.len()];
        let mut errors = vec![0.0; m.catalogue.len()];
        let r = self.radius_mm;
        let mut f = |s: f64| {
            let g = self.gap(s, &mut q, &mut errors);
            let norm = g.norm();
            (norm - r, g.dot(&self.approach) / norm)
        };
        let (mut lo, mut hi) = (0.0, reach);
        let (f_lo, _) = f(lo);
        if f_lo.is_nan() || f_lo <= 0.0 {
            return Err(ContactFailure::StartsInside(-f_lo));
        }
        let (f_hi, _) = f(hi);
        if f_hi.is_nan() || f_hi >= 0.0 {
            return Err(ContactFailure::NeverTouches(f_hi + r));
        }
        let mut s = reach - r;
        let mut last = f64::INFINITY;
        for k in 1..=MAX_CONTACT_ITERATIONS {
            let (fs, slope) = f(s);
            if fs == 0.0 {
                return Ok((s, k));
            }
            if fs > 0.0 {
                lo = s;
            } else {
                hi = s;
            }
            let newton = s - fs / slope;
            let next = if slope < 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            last = (next - s).abs();
            if last <= CONTACT_TOLERANCE_MM || hi - lo <= CONTACT_TOLERANCE_MM {
                return Ok((next, k));
            }
            s = next;
        }
        Err(ContactFailure::NotConverged(last))
    }
}
