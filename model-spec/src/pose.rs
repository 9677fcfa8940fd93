//! Whether a pose is within the limits of a machine's axes.
//!
//! A pose is one command per axis, in axis order: mm for linear axes, **radians** for rotary
//! axes (the unit inside rtest). The limits are those of the description ([`Axis::limits`]):
//! the `stroke` in mm, the `range` in degrees; a rotary axis without a range is unlimited.
//! Messages give values and limits in the units people see: mm and degrees.
//!
//! A limit is inclusive, with a margin of [`LIMIT_TOLERANCE`] in the unit people see, so that a
//! command computed to be exactly at a limit (`120f64.to_radians()` read back as
//! 119.99999999999999 or 120.00000000000001 degrees) is within it.

use crate::machine::{Axis, AxisId, AxisKind, Machine};
use crate::units::{compact, short};
use std::fmt;

/// How far (mm for a linear axis, degrees for a rotary axis) a command may lie beyond a limit
/// and still be taken as at the limit: the rounding of a conversion, not a tolerance of the
/// machine.
pub const LIMIT_TOLERANCE: f64 = 1e-9;

/// Why a pose is not one the machine can take.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// Not one command per axis.
    #[error("a pose of machine {machine} has one command per axis ({expected}), found {found}")]
    WrongLength {
        /// The machine's name.
        machine: String,
        /// The number of axes.
        expected: usize,
        /// The number of commands given.
        found: usize,
    },
    /// A command that is NaN or infinite.
    #[error("axis {name}: the command {value} is not a finite number")]
    NotFinite {
        /// The axis, by index into [`Machine::axes`].
        axis: AxisId,
        /// Its letter.
        name: String,
        /// The command as given (mm or rad).
        value: f64,
    },
    /// The first axis, in axis order, whose command lies outside its stroke or range.
    #[error("{0}")]
    OutsideLimits(OutsideLimits),
}

/// A command outside the stroke or range of its axis, in the units people see.
#[derive(Clone, Debug, PartialEq)]
pub struct OutsideLimits {
    /// The axis, by index into [`Machine::axes`].
    pub axis: AxisId,
    /// Its letter.
    pub name: String,
    /// Linear (values in mm) or rotary (values in degrees).
    pub kind: AxisKind,
    /// The command: mm, or degrees.
    pub value: f64,
    /// The axis's `[min, max]`: mm, or degrees.
    pub limits: [f64; 2],
}

impl fmt::Display for OutsideLimits {
    /// `A = 121° outside its range -120 .. 120°`, `X = 612.3 mm outside its stroke -500 .. 500
    /// mm`, `X = 1e300 mm outside …`. The value is written compactly
    /// ([`crate::units::compact`]: a huge value in scientific notation, not with hundreds of
    /// digits), and with every digit when that would show it at the limit.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [lo, hi] = self.limits;
        let (lo_s, hi_s) = (short(lo), short(hi));
        // `+ 0.0` turns a -0 into 0: no negative zero, as `short` writes it.
        let mut value = compact(self.value + 0.0);
        if value == lo_s || value == hi_s {
            value = format!("{}", self.value);
        }
        let what = match self.kind {
            AxisKind::Linear => "stroke",
            AxisKind::Rotary => "range",
        };
        let unit = match self.kind {
            AxisKind::Linear => " mm",
            AxisKind::Rotary => "°",
        };
        write!(
            f,
            "{} = {value}{unit} outside its {what} {lo_s} .. {hi_s}{unit}",
            self.name
        )
    }
}

/// The command `q` of axis `a` (mm or rad) in the unit people see (mm or degrees).
fn for_people(a: &Axis, q: f64) -> f64 {
    match a.kind {
        AxisKind::Linear => q,
        AxisKind::Rotary => q.to_degrees(),
    }
}

impl Machine {
    /// Checks that `commands` (one per axis, in axis order: mm for linear axes, rad for rotary
    /// axes) are finite and within the axes' limits (inclusive, with a margin of
    /// [`LIMIT_TOLERANCE`] mm or degrees). Reports the first axis that is not.
    pub fn check_pose(&self, commands: &[f64]) -> Result<(), PoseError> {
        if commands.len() != self.axes.len() {
            return Err(PoseError::WrongLength {
                machine: self.name.clone(),
                expected: self.axes.len(),
                found: commands.len(),
            });
        }
        for (i, (a, &q)) in self.axes.iter().zip(commands).enumerate() {
            if !q.is_finite() {
                return Err(PoseError::NotFinite {
                    axis: i,
                    name: a.name.clone(),
                    value: q,
                });
            }
        }
        if let Some(first) = self.outside_limits(commands).into_iter().next() {
            return Err(PoseError::OutsideLimits(first));
        }
        Ok(())
    }

    /// Every axis of `commands` (one per axis: mm, rad) outside its stroke or range (inclusive,
    /// with a margin of [`LIMIT_TOLERANCE`] mm or degrees), in axis order. Commands that are
    /// not finite, and commands beyond the number of axes, are not reported here.
    pub fn outside_limits(&self, commands: &[f64]) -> Vec<OutsideLimits> {
        self.axes
            .iter()
            .zip(commands)
            .enumerate()
            .filter_map(|(i, (a, &q))| {
                let value = for_people(a, q);
                let [lo, hi] = a.limits;
                (value < lo - LIMIT_TOLERANCE || value > hi + LIMIT_TOLERANCE).then(|| {
                    OutsideLimits {
                        axis: i,
                        name: a.name.clone(),
                        kind: a.kind,
                        value,
                        limits: a.limits,
                    }
                })
            })
            .collect()
    }
}
