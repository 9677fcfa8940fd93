//! Error gains by central finite differences of the exact virtual machine.
//!
//! The gain of an error `ε` at a pose is `∂v/∂ε` at `ε = 0` (every other error zero), where
//! `v = [position; orientation]` is the exact [`ErrorVector`](crate::ErrorVector) (tool minus
//! workpiece, tool frame). Position rows are in mm/mm for translational errors and mm/rad for
//! angular ones; orientation rows in 1/mm (always 0) and rad/rad. They are computed as
//! `(v(+h) − v(−h)) / 2h`: this is the reference the symbolic engine is tested against.
//!
//! Step sizes ([`FdSteps::default`]), from the step study in `tests/all/fd.rs` (largest deviation
//! from the seed's Table 2 over 20 random poses of `seed-ac`, lever arms ≈ 250 mm):
//! - translational errors enter the exact chain linearly (a translation moves the end points by
//!   a fixed vector and turns no frame), so the difference quotient has no truncation error and
//!   a larger step only lowers the rounding error `≈ u·L/h` (`u` = 1.1e-16, `L` the size of the
//!   intermediate positions): 1e-6 mm → 3e-8, 1e-4 → 3e-10, 1e-2 → 3e-12, 1 mm → 3e-14. The
//!   default is `h = 1e-2` mm: 3e-12 mm/mm while staying a small perturbation;
//! - angular errors: a single central difference has truncation error `≈ h²·L/6` and rounding
//!   error `≈ u·L/h`, balanced near `h ≈ 1e-5` rad at ~1e-8 mm/rad (measured 6.8e-9; 1e-6 rad
//!   gives 4e-8, 1e-4 rad 5e-7). Richardson extrapolation of the steps `h` and `h/2`,
//!   `(4·D(h/2) − D(h))/3`, removes the `h²` term, so a much larger step fits: measured 6.8e-9 at
//!   1e-2 rad, 7e-11 at 3e-3, 1.1e-10 at 1e-3, 8e-10 at 1e-4. The default is `h = 1e-3` rad with
//!   Richardson: ~1e-10 mm/rad, with a margin of 10 in `h` before the `h⁴` term shows.

use crate::exact::{VirtualMachine, error_vector_of};
use model_spec::{ErrorId, Machine, Side};

/// Finite-difference steps and scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FdSteps {
    /// Step for translational errors, mm.
    pub translational: f64,
    /// Step for angular errors, rad.
    pub angular: f64,
    /// Combine the steps `h` and `h/2` by Richardson extrapolation (fourth order) instead of a
    /// single central difference (second order).
    pub richardson: bool,
}

impl Default for FdSteps {
    /// `1e-2` mm, `1e-3` rad, with Richardson extrapolation (see the module documentation).
    fn default() -> Self {
        FdSteps {
            translational: 1e-2,
            angular: 1e-3,
            richardson: true,
        }
    }
}

/// The gains of the errors `ids` of `machine` at the pose `commands` (mm, rad) with `params`
/// (mm), every error zero, by central finite differences with [`FdSteps::default`]. One
/// `[∂x, ∂y, ∂z, ∂I, ∂J, ∂K]` per requested id, in the order of `ids`.
///
/// # Panics
/// When a slice's length does not match the machine or an id is not in its catalogue.
pub fn fd_gains(
    machine: &Machine,
    commands: &[f64],
    params: &[f64],
    ids: &[ErrorId],
) -> Vec<[f64; 6]> {
    fd_gains_with(
        &VirtualMachine::new(machine),
        commands,
        params,
        ids,
        FdSteps::default(),
    )
}

/// As [`fd_gains`], on an already lowered machine and with the given steps.
///
/// # Panics
/// When a slice's length does not match the machine or an id is not in its catalogue.
pub fn fd_gains_with(
    vm: &VirtualMachine<'_>,
    commands: &[f64],
    params: &[f64],
    ids: &[ErrorId],
    steps: FdSteps,
) -> Vec<[f64; 6]> {
    let m = vm.machine();
    vm.check_pose(commands, params);
    let tool0 = vm.transform_with(Side::Tool, commands, params, &|_| 0.0);
    let work0 = vm.transform_with(Side::Work, commands, params, &|_| 0.0);
    let at = |id: ErrorId, value: f64| -> [f64; 6] {
        let err = |e: ErrorId| if e == id { value } else { 0.0 };
        let tool = vm.transform_with(Side::Tool, commands, params, &err);
        let work = vm.transform_with(Side::Work, commands, params, &err);
        error_vector_of(&tool, &work, &tool0, &work0).to_array()
    };
    let central = |id: ErrorId, h: f64| -> [f64; 6] {
        let (p, n) = (at(id, h), at(id, -h));
        std::array::from_fn(|k| (p[k] - n[k]) / (2.0 * h))
    };
    ids.iter()
        .map(|&id| {
            let term = m.catalogue.get(id).unwrap_or_else(|| {
                panic!(
                    "machine `{}`: error id {id} is not in its catalogue ({} entries)",
                    m.name,
                    m.catalogue.len()
                )
            });
            if term.is_angular() {
                let h = steps.angular;
                if steps.richardson {
                    let (d1, d2) = (central(id, h), central(id, h / 2.0));
                    std::array::from_fn(|k| (4.0 * d2[k] - d1[k]) / 3.0)
                } else {
                    central(id, h)
                }
            } else {
                central(id, steps.translational)
            }
        })
        .collect()
}
