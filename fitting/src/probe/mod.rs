//! Touch-probe records: the hits of a probe on the calibration sphere (or the centres another
//! device fitted from them) turned into readings of the machine's error vector, one per pose,
//! so that every stage of the campaign pipeline takes a probe campaign as it takes an R-test
//! campaign (`docs/probe.md`).
//!
//! At a pose the rotary axes stand still and the probe touches the sphere several times. The
//! latched axis positions `q_i` give the nominal tip centres relative to the nominal sphere
//! centre, `g_i = P_tool0(q_i) − P_work0(q_i)` (bed frame, mm: the exact nominal chains, so
//! every axis sign and inclination of the description is taken as it is). On the real machine
//! the tip touches the real sphere, `‖g_i + G‖ = R_eff`, `G` the tool-minus-workpiece error in
//! the bed frame: the `g_i` lie on a sphere of radius `R_eff` about `c = −G`. The sphere fit
//! ([`crate::sphere`], free radius) gives `c`, and the pose's reading is
//!
//! ```text
//! e = −R_tool0ᵀ · c        (tool frame, mm)
//! ```
//!
//! the error vector an R-test would read at that pose, with its sign. `G` is taken as constant
//! across the pose's hits: the axes travel about `2·R_eff` while the probe goes round the
//! sphere, and an error's change over that travel (a scale error of 10 µm/m: 0.3 µm over
//! 30 mm) distorts the sphere instead of moving it; that second-order effect is neglected.
//!
//! Each pose becomes one sample of a [`Record`](simulation::record::Record): the pose's nominal commands (rotary axes as
//! probed, linear axes from the nominal inverse kinematics at the record's parameters), the
//! time of its first hit, the reading, and its covariance `R_tool0ᵀ·C·R_tool0` from the fit's
//! centre covariance `C` (the probe's declared σ), so the kinematics fit weights the poses by
//! what their fits know.

mod centres;
mod hits;
mod pose;
mod summary;

pub use centres::centre_record;
pub use hits::{
    OFF_SPHERE_MM, PoseFit, ProbeRecord, ProbeSettings, pretravel_responses, probe_record,
};
pub use pose::pose_frame;
pub use simulation::probe::{PoseFrame, PreTravel, approach_in_probe_frame};
pub use summary::ProbeSummary;
