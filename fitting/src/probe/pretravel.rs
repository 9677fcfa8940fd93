//! The probe's pre-travel: how much farther than the contact the probe moves before it
//! triggers, as a function of the approach direction in the probe's own frame.
//!
//! `δ(n) = δ0 + ρ·(L_c·cos 3φ + L_s·sin 3φ)` (mm), with `n_t = R_toolᵀ·n` the approach
//! direction in the probe's (tool) frame, `φ = atan2(n_t.y, n_t.x)` its azimuth about the
//! stylus and `ρ = √(n_t.x² + n_t.y²)` its part across the stylus: a kinematic (three-point)
//! probe triggers on a force that depends on the direction of the push across the stylus with
//! three lobes, and not on the azimuth of a push along the stylus, where `ρ = 0`. A hit that
//! pre-travels by `δ` latches the tip centre `δ·n` beyond the contact, towards the sphere's
//! centre.

use nalgebra::Vector3;

/// A probe's pre-travel: constant and three-lobed parts (mm).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreTravel {
    /// The constant pre-travel `δ0`, mm: the same as an effective tip radius `δ0` too small.
    pub constant_mm: f64,
    /// The three-lobed part's amplitudes `[L_c, L_s]`, mm.
    pub lobing_mm: [f64; 2],
}

impl PreTravel {
    /// The pre-travel of an approach whose direction in the probe's frame is `approach_tool`
    /// (unit), mm.
    pub fn along(&self, approach_tool: &Vector3<f64>) -> f64 {
        let (rho, phi) = approach_in_probe_frame(approach_tool);
        let [c, s] = self.lobing_mm;
        self.constant_mm + rho * (c * (3.0 * phi).cos() + s * (3.0 * phi).sin())
    }

    /// `true` when every part is zero.
    pub fn is_zero(&self) -> bool {
        self.constant_mm == 0.0 && self.lobing_mm == [0.0, 0.0]
    }
}

/// `(ρ, φ)` of an approach direction in the probe's frame (unit vector): its part across the
/// stylus and its azimuth about it (rad; 0 when `ρ` is 0).
pub fn approach_in_probe_frame(approach_tool: &Vector3<f64>) -> (f64, f64) {
    let rho = approach_tool.x.hypot(approach_tool.y);
    let phi = if rho > 0.0 {
        approach_tool.y.atan2(approach_tool.x)
    } else {
        0.0
    };
    (rho, phi)
}
