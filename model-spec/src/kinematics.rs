//! The kinematic chains lowered to one list of elementary steps per chain.
//!
//! This list is the single definition of how an axis is composed (the seed's eqs. (1)–(2):
//! `offset · location · component(command)`). The symbolic engine (`codegen`) and the exact
//! simulator (`simulation`) both walk it, so they cannot disagree on the order of the factors.
//!
//! The homogeneous transform of a chain is the product of its steps from the bed outwards:
//! `T = S1 · S2 · … · Sn`; a point of the end frame is mapped to the bed frame by `T`.
//!
//! Per linear axis moving along `d` by the command `q` (mm):
//! `Offset · ErrorRotation(squareness) · Motion(q) · ErrorTranslation(EX?,EY?,EZ?) · ErrorRotation(EA?,EB?,EC?)`.
//!
//! Per rotary axis turning about `d` by the command `θ`:
//! `Offset · ErrorTranslation(location) · ErrorRotation(location) · ErrorTranslation(EX?,EY?,EZ?)
//!  · ErrorRotation(the two tilts) · Motion(θ + positioning error)`.
//!
//! An inclined axis (see [`crate::AxisDirection`]) is described in its own frame: its steps
//! are wrapped as `Frame(F) · … · Frame(Fᵀ)`, where the rows of `F` are its own axes
//! `x' y' z'` in the machine frame and the steps between are those of an axis along `+z'`, so
//! its errors act along and about its own axes. At command zero the wrap is the identity, so the
//! offsets of later links stay in machine coordinates.
//!
//! The work end adds `Offset · ErrorTranslation(XOW, YOW, ZOW)`; the tool end adds `Offset`.
//!
//! An `ErrorRotation(a, b, c)` is, exactly, `Rx(a)·Ry(b)·Rz(c)`, and to first order the seed's
//! small-angle matrix `[[1, -c, b], [c, 1, -a], [-b, a, 1]]`. A rotary `Motion` is the rotation
//! about the signed direction by `θ`, followed by (first order: multiplied by) the rotation about
//! the positive coordinate direction by the positioning error: `R(d, ±θ) · R(d, e)`.

use crate::catalogue::{ErrorId, ErrorKind, Motion as ErrMotion};
use crate::geometry::Dir;
use crate::machine::{AxisId, AxisKind, Link, Machine, Offset, Side, Value};

/// One elementary transform of a chain.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A fixed translation (mm).
    Offset(Offset),
    /// A small translation by error terms along x, y, z (`None`: no error there).
    ErrorTranslation([Option<ErrorId>; 3]),
    /// A small rotation by error terms about x, y, z (`None`: no error there).
    ErrorRotation([Option<ErrorId>; 3]),
    /// The constant rotation into (or back out of) an inclined axis's own frame.
    Frame {
        /// The inclined axis.
        axis: AxisId,
        /// Into the own frame or back.
        turn: FrameTurn,
    },
    /// The commanded motion of an axis: a translation along, or rotation about, its own
    /// direction ([`crate::AxisDirection::own`]; `+z'` inside an inclined axis's frame).
    Motion {
        /// The axis.
        axis: AxisId,
        /// For a rotary axis, its angular positioning error (rotation about the positive
        /// coordinate direction of the axis); `None` for linear axes, whose positioning error is
        /// in the following `ErrorTranslation`.
        positioning_error: Option<ErrorId>,
    },
}

/// Which way a [`Step::Frame`] turns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameTurn {
    /// Into the axis's own frame: a vector `v'` in own coordinates is `Fᵀ·v'` in the parent
    /// frame (the columns of `Fᵀ` are `x' y' z'`).
    Into,
    /// Back to the machine-aligned frame: `F·v`.
    Back,
}

impl Step {
    /// `true` when the step holds no error and no motion and is the identity (a zero offset).
    pub fn is_identity(&self) -> bool {
        match self {
            Step::Offset(o) => o.iter().all(Value::is_zero),
            Step::ErrorTranslation(e) | Step::ErrorRotation(e) => e.iter().all(Option::is_none),
            Step::Motion { .. } | Step::Frame { .. } => false,
        }
    }
}

fn find(m: &Machine, pred: impl Fn(&ErrorKind) -> bool) -> Option<ErrorId> {
    m.catalogue.iter().position(|e| pred(&e.kind))
}

fn triple(f: impl Fn(Dir) -> Option<ErrorId>) -> [Option<ErrorId>; 3] {
    [f(Dir::X), f(Dir::Y), f(Dir::Z)]
}

fn axis_steps(m: &Machine, axis: AxisId) -> Vec<Step> {
    let a = &m.axes[axis];
    let comp = |motion: ErrMotion| find(m, |k| *k == ErrorKind::Component { axis, motion });
    let comp_t = triple(|d| comp(ErrMotion::Translation(d)));
    let mut steps = vec![Step::Offset(a.offset)];
    let inclined = a.direction.inclined.is_some();
    if inclined {
        steps.push(Step::Frame {
            axis,
            turn: FrameTurn::Into,
        });
    }
    match a.kind {
        AxisKind::Linear => {
            let sq = triple(|d| find(m, |k| *k == ErrorKind::Squareness { axis, about: d }));
            steps.push(Step::ErrorRotation(sq));
            steps.push(Step::Motion {
                axis,
                positioning_error: None,
            });
            steps.push(Step::ErrorTranslation(comp_t));
            steps.push(Step::ErrorRotation(triple(|d| {
                comp(ErrMotion::Rotation(d))
            })));
        }
        AxisKind::Rotary => {
            let loc = |motion: ErrMotion| find(m, |k| *k == ErrorKind::Location { axis, motion });
            steps.push(Step::ErrorTranslation(triple(|d| {
                loc(ErrMotion::Translation(d))
            })));
            steps.push(Step::ErrorRotation(triple(|d| loc(ErrMotion::Rotation(d)))));
            steps.push(Step::ErrorTranslation(comp_t));
            let own = a.direction.own.dir;
            steps.push(Step::ErrorRotation(triple(|d| {
                if d == own {
                    None
                } else {
                    comp(ErrMotion::Rotation(d))
                }
            })));
            steps.push(Step::Motion {
                axis,
                positioning_error: comp(ErrMotion::Rotation(own)),
            });
        }
    }
    if inclined {
        steps.push(Step::Frame {
            axis,
            turn: FrameTurn::Back,
        });
    }
    steps
}

/// The steps of the chain on `side`, from the bed to its end. Identity steps are dropped.
pub fn chain_steps(m: &Machine, side: Side) -> Vec<Step> {
    let chain = m.chain(side);
    let mut steps = Vec::new();
    for link in &chain.links {
        match link {
            Link::Axis(axis) => steps.extend(axis_steps(m, *axis)),
            Link::Fixed { offset, .. } => steps.push(Step::Offset(*offset)),
        }
    }
    steps.push(Step::Offset(chain.end_offset));
    if side == Side::Work {
        let setup = triple(|d| find(m, |k| *k == ErrorKind::Setup { along: d }));
        steps.push(Step::ErrorTranslation(setup));
    }
    steps.retain(|s| !s.is_identity());
    steps
}
