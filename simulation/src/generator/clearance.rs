//! The clearance rule of an R-test set-up: the nest and the spindle must not meet the table.
//!
//! rtest knows the machine's frames, not the shape of its table or of the instrument, so the
//! rule is stated on two things it can compute, under two conventions of the description
//! (docs/paths.md):
//!
//! - the **tool axis** is the z axis of the tool frame, pointing from the tool point (the nest)
//!   towards the spindle;
//! - the **table** is the half-space below the xy-plane of the frame the ball is given in (the
//!   frame of the last axis of the work chain, the bed when the work chain has no axis); its
//!   z axis, the **table normal**, points from the table towards the ball.
//!
//! The rule, with `R` the reach of the nest (every point of the nest and spindle lies within `R`
//! of the ball centre or within `R` of the tool axis on the spindle side):
//!
//! 1. **tilt**: at every sample, the angle between the tool axis and the table normal is at
//!    most [`Clearance::max_tilt_deg`] (default 90°: the tool never reaches towards the table
//!    from below its face);
//! 2. **height**: the ball centre stands at least [`Clearance::min_ball_height_mm`] above the
//!    table face (a property of the set-up, checked once).
//!
//! With a tilt of at most 90°, the lowest point of the tool side is at least `h − R` above the
//! table (`h` the ball's height), so `min_ball_height_mm ≥ R` keeps the nest off the table at
//! every allowed pose. The table is taken infinite, which is conservative.

use crate::exact::VirtualMachine;
use model_spec::{Link, Machine, Side, Value};
use nalgebra::Vector3;

/// Default of [`Clearance::max_tilt_deg`], degrees.
pub const DEFAULT_MAX_TILT_DEG: f64 = 90.0;

/// Default of [`Clearance::min_ball_height_mm`], mm. A chosen lower bound (the radius of a
/// compact nest around a 25.4 mm ball), not a property of any instrument: set the reach of
/// yours.
pub const DEFAULT_MIN_BALL_HEIGHT_MM: f64 = 30.0;

/// How far, degrees, a tilt may exceed [`Clearance::max_tilt_deg`] and still be taken as at
/// it: the rounding of the trigonometry, as [`model_spec::pose::LIMIT_TOLERANCE`] for ranges.
pub const TILT_TOLERANCE_DEG: f64 = 1e-9;

/// The clearance rule (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Largest angle between the tool axis and the table normal, degrees, from 0 to 180.
    pub max_tilt_deg: f64,
    /// Smallest height of the ball centre above the table face, mm: the reach of the nest.
    pub min_ball_height_mm: f64,
}

impl Default for Clearance {
    fn default() -> Self {
        Clearance {
            max_tilt_deg: DEFAULT_MAX_TILT_DEG,
            min_ball_height_mm: DEFAULT_MIN_BALL_HEIGHT_MM,
        }
    }
}

/// The height of the ball centre above the table face, mm: its z coordinate in the frame it is
/// given in (the offsets of the links after the last work-side axis and of the work end, at the
/// kinematic parameters `params`, mm, one per symbol).
///
/// # Panics
/// When `params` is not one per symbol.
pub fn ball_height_mm(m: &Machine, params: &[f64]) -> f64 {
    assert_eq!(params.len(), m.symbols.len(), "one parameter per symbol");
    let z = |v: &Value| match *v {
        Value::Number(x) => x,
        Value::Symbol(s) => params[s],
    };
    let links = &m.work.links;
    let after_last_axis = links
        .iter()
        .rposition(|l| matches!(l, Link::Axis(_)))
        .map_or(0, |i| i + 1);
    let links_z: f64 = links[after_last_axis..]
        .iter()
        .map(|l| match l {
            Link::Fixed { offset, .. } => z(&offset[2]),
            Link::Axis(_) => 0.0,
        })
        .sum();
    links_z + z(&m.work.end_offset[2])
}

/// What the table is, for messages: `the C table` or `the table (bed frame)`.
pub fn table_name(m: &Machine) -> String {
    match m.work.axes().last() {
        Some(a) => format!("the {} table", m.axes[a].name),
        None => "the table (bed frame)".to_string(),
    }
}

/// The tilt of the tool axis from the table normal of a machine, with its chains lowered once.
pub struct TiltGauge<'m> {
    vm: VirtualMachine<'m>,
    params: Vec<f64>,
}

impl<'m> TiltGauge<'m> {
    /// The gauge of machine `m`. Rotations do not depend on the kinematic parameters, so none
    /// are asked for.
    pub fn new(m: &'m Machine) -> Self {
        TiltGauge {
            vm: VirtualMachine::new(m),
            params: m.default_parameters(),
        }
    }

    /// The tool axis and the table normal (unit vectors, bed frame) at `commands` (one per
    /// axis: mm, rad) on the nominal machine.
    fn axes(&self, commands: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let z = |side| {
            self.vm
                .nominal_chain_transform(side, commands, &self.params)
                .rotation
                .matrix()
                .column(2)
                .into_owned()
        };
        (z(Side::Tool), z(Side::Work))
    }

    /// The cosine of the angle between the tool axis and the table normal at `commands` (one
    /// per axis: mm, rad) on the nominal machine.
    pub fn cos_tilt(&self, commands: &[f64]) -> f64 {
        let (t, w) = self.axes(commands);
        t.dot(&w)
    }

    /// The angle between the tool axis and the table normal at `commands` (mm, rad), degrees
    /// from 0 to 180 (from the sine and the cosine, accurate near 0° and 180° too).
    pub fn tilt_deg(&self, commands: &[f64]) -> f64 {
        let (t, w) = self.axes(commands);
        t.cross(&w).norm().atan2(t.dot(&w)).to_degrees()
    }

    /// The interval of commands of rotary axis `axis` (degrees), the others held at
    /// `commands` (mm, rad), that contains `from_deg` and keeps the tilt at most `max_tilt_deg`
    /// (ends inclusive, to within [`TILT_TOLERANCE_DEG`]); `[-inf, inf]` when the axis does not
    /// change the tilt or every angle keeps it. `None` when `from_deg` itself tilts too far.
    ///
    /// The tool axis and the table normal are on different chains and the axis turns one of
    /// them about a fixed direction (a coordinate direction or an inclined one alike), so the
    /// cosine of the tilt is `α + β·cos q + γ·sin q` exactly; the three coefficients come from
    /// `q = 0°, 90°, 180°`, and the interval is solved in closed form for the largest tilt plus
    /// [`TILT_TOLERANCE_DEG`], the tolerance of the check of every sample.
    pub fn allowed_interval(
        &self,
        commands: &[f64],
        axis: usize,
        from_deg: f64,
        max_tilt_deg: f64,
    ) -> Option<[f64; 2]> {
        let at = |deg: f64| {
            let mut q = commands.to_vec();
            q[axis] = deg.to_radians();
            q
        };
        let (g0, g90, g180) = (
            self.cos_tilt(&at(0.0)),
            self.cos_tilt(&at(90.0)),
            self.cos_tilt(&at(180.0)),
        );
        let alpha = 0.5 * (g0 + g180);
        let beta = 0.5 * (g0 - g180);
        let gamma = g90 - alpha;
        let rho = beta.hypot(gamma);
        // The tilt at `from_deg` within the limit (with the tolerance of the check).
        if self.tilt_deg(&at(from_deg)) > max_tilt_deg + TILT_TOLERANCE_DEG {
            return None;
        }
        // The limit with the tolerance of the check: a tilt that reaches the limit exactly (an
        // A table at ±90°, a 45° nutating head at 180°) is within the rule, and the rounding of
        // α, β, γ must not cut the interval short of it.
        let kappa = (max_tilt_deg + TILT_TOLERANCE_DEG)
            .min(180.0)
            .to_radians()
            .cos();
        if rho < 1e-12 || (kappa - alpha) / rho <= -1.0 {
            return Some([f64::NEG_INFINITY, f64::INFINITY]);
        }
        // cos(q − ψ) ≥ c on [ψ − δ, ψ + δ] + 360°·k.
        let c = ((kappa - alpha) / rho).min(1.0);
        let psi = gamma.atan2(beta).to_degrees();
        let delta = c.acos().to_degrees();
        let k = ((from_deg - psi) / 360.0).round();
        let centre = psi + 360.0 * k;
        Some([centre - delta, centre + delta])
    }
}

/// `x` (degrees) rounded towards the inside of an interval to a multiple of 1e-6°, taking a
/// value within [`TILT_TOLERANCE_DEG`] of a multiple as that multiple: `lower` rounds up, the
/// upper end down. Infinite values stay.
pub(crate) fn round_inward(x: f64, lower: bool) -> f64 {
    if !x.is_finite() {
        return x;
    }
    let micro = x * 1e6;
    let tol = TILT_TOLERANCE_DEG * 1e6;
    if lower {
        (micro - tol).ceil() / 1e6
    } else {
        (micro + tol).floor() / 1e6
    }
}
