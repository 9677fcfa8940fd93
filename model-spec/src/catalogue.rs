//! The ISO 230 error catalogue of a topology: which errors exist, what they are called and what
//! each one does to the kinematic chain.
//!
//! Names follow ISO 230-1/-7 with the seed's spelling:
//! - component errors `E<direction><axis>`: `EXX EYX EZX EAX EBX ECX` for a linear axis X
//!   (positioning, two straightness, three angular errors), `EXC … ECC` for a rotary axis C
//!   (`ECC` is its angular positioning error);
//! - location errors of a rotary axis: two translations and two tilts perpendicular to it
//!   (`XOC YOC AOC BOC` for C, `YOA ZOA BOA COA` for A, `XOB ZOB AOB COB` for B);
//! - squareness of the linear axes, by the squareness order (reference first): the reference has
//!   none, the second axis one (rotation about the direction perpendicular to both; two, about
//!   the directions perpendicular to its own, if it is parallel to the reference), every later
//!   axis two (rotations about the directions perpendicular to its own): `COX AOZ BOZ` for the
//!   seed machine whose order is Y, X, Z (see [`crate::default_squareness_order`]);
//! - workpiece set-up errors `XOW YOW ZOW` (translations of the workpiece point in the last
//!   frame of the work chain).
//!
//! An inclined axis ([`crate::AxisDirection`]) is described in its own frame `x' y' z'`, where
//! it moves along (turns about) `z'`; the letters of its errors name the directions of that
//! frame. An inclined rotary axis B thus has `EXB EYB` (radial), `EZB` (axial), `EAB EBB`
//! (tilts), `ECB` (angular positioning) and the location errors `XOB YOB AOB BOB`, like a C axis;
//! an inclined linear axis U has `EZU` as its positioning error. Its errors are translations
//! along and small rotations about the own axes.
//!
//! The digit-zero spelling (`X0C`, `C0X`) is accepted wherever a name is read.
//!
//! Translational errors are in mm inside (µm at every boundary a person sees); angular errors are
//! small rotations in rad (µrad for people) about the positive coordinate directions.
//!
//! Canonical order: component errors of the linear axes (axes in ISO order X Y Z U V W, then the
//! rest by letter), squareness in squareness order, workpiece set-up, then for each rotary axis
//! (ISO order A B C, then by letter) its component errors and its location errors. Within a
//! block: translations x, y, z, then rotations about x, y, z.

use crate::geometry::Dir;
use crate::machine::{Axis, AxisId, AxisKind, Side};

/// Index of an error term in [`crate::Machine::catalogue`].
pub type ErrorId = usize;

/// Whether an error is a translation (mm) or a small rotation (rad).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Motion {
    /// A translation along the direction, mm.
    Translation(Dir),
    /// A small rotation about the direction, rad.
    Rotation(Dir),
}

impl Motion {
    /// `true` for a small rotation.
    pub fn is_angular(self) -> bool {
        matches!(self, Motion::Rotation(_))
    }

    /// The ISO letter: `X Y Z` for translations, `A B C` for rotations.
    pub fn letter(self) -> char {
        match self {
            Motion::Translation(d) => d.translation_letter(),
            Motion::Rotation(d) => d.rotation_letter(),
        }
    }
}

/// What an error term is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// A component error of an axis (varies with the axis command).
    Component {
        /// The axis.
        axis: AxisId,
        /// Its motion.
        motion: Motion,
    },
    /// A location error of a rotary axis (constant).
    Location {
        /// The rotary axis.
        axis: AxisId,
        /// Its motion.
        motion: Motion,
    },
    /// A squareness error of a linear axis against the earlier linear axes (constant).
    Squareness {
        /// The linear axis.
        axis: AxisId,
        /// The rotation direction.
        about: Dir,
    },
    /// A translation of the workpiece point (set-up error, constant).
    Setup {
        /// Its direction.
        along: Dir,
    },
}

/// One error of the catalogue.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct ErrorTerm {
    /// Canonical name (`EXX`, `XOC`, `COX`, `XOW`).
    pub name: String,
    /// What it is.
    pub kind: ErrorKind,
}

impl ErrorTerm {
    /// Its motion: a translation or a small rotation, and the direction.
    pub fn motion(&self) -> Motion {
        match self.kind {
            ErrorKind::Component { motion, .. } | ErrorKind::Location { motion, .. } => motion,
            ErrorKind::Squareness { about, .. } => Motion::Rotation(about),
            ErrorKind::Setup { along } => Motion::Translation(along),
        }
    }

    /// `true` for angular errors (rad inside, µrad for people).
    pub fn is_angular(&self) -> bool {
        self.motion().is_angular()
    }

    /// The unit people see: `"um"` or `"urad"`.
    pub fn unit(&self) -> &'static str {
        if self.is_angular() { "urad" } else { "um" }
    }

    /// The axis the error belongs to, if any.
    pub fn axis(&self) -> Option<AxisId> {
        match self.kind {
            ErrorKind::Component { axis, .. }
            | ErrorKind::Location { axis, .. }
            | ErrorKind::Squareness { axis, .. } => Some(axis),
            ErrorKind::Setup { .. } => None,
        }
    }
}

/// The canonical spelling of an error name: surrounding white space removed, upper case, and
/// the digit zero in the middle of a three-character name (`X0C`, `c0x`) read as the letter O.
pub fn canonical_name(name: &str) -> String {
    let mut chars: Vec<char> = name.trim().to_ascii_uppercase().chars().collect();
    if chars.len() == 3 && chars[1] == '0' {
        chars[1] = 'O';
    }
    chars.into_iter().collect()
}

/// Builds the name of a component error.
pub fn component_name(motion: Motion, axis: &str) -> String {
    format!("E{}{}", motion.letter(), axis)
}

/// Builds the name of a location or squareness error (`XOC`, `COX`).
pub fn location_name(motion: Motion, axis: &str) -> String {
    format!("{}O{}", motion.letter(), axis)
}

/// The six motions of a component block, in canonical order.
pub fn six_motions() -> [Motion; 6] {
    [
        Motion::Translation(Dir::X),
        Motion::Translation(Dir::Y),
        Motion::Translation(Dir::Z),
        Motion::Rotation(Dir::X),
        Motion::Rotation(Dir::Y),
        Motion::Rotation(Dir::Z),
    ]
}

/// The four location errors of a rotary axis turning about `d`: translations along, then
/// rotations about, the two perpendicular directions.
pub fn location_motions(d: Dir) -> [Motion; 4] {
    let [p, q] = d.perpendicular();
    [
        Motion::Translation(p),
        Motion::Translation(q),
        Motion::Rotation(p),
        Motion::Rotation(q),
    ]
}

/// The squareness rotations of the `rank`-th linear axis of the squareness order (0-based),
/// moving along `d`, where `reference` is the direction of the first axis of the order.
pub fn squareness_rotations(rank: usize, d: Dir, reference: Dir) -> Vec<Dir> {
    match rank {
        0 => vec![],
        1 if reference != d => d
            .perpendicular()
            .into_iter()
            .filter(|&p| p != reference)
            .collect(),
        _ => d.perpendicular().to_vec(),
    }
}

/// The rank used to order axes the ISO way: X Y Z U V W A B C, then the other letters.
pub fn iso_rank(name: &str) -> (usize, String) {
    const ORDER: &str = "XYZUVWABC";
    let first = name.chars().next().unwrap_or(' ');
    (ORDER.find(first).unwrap_or(ORDER.len()), name.to_string())
}

/// The default squareness order of the linear axes: by depth among the linear axes of their
/// chain (the first linear axis from the bed has depth 0), the tool chain first on equal depth,
/// then by ISO letter order. For the seed machine (work X; tool Y, Z) this is Y, X, Z.
pub fn default_squareness_order(axes: &[Axis]) -> Vec<AxisId> {
    let depth = |id: AxisId| {
        (0..id)
            .filter(|&j| axes[j].kind == AxisKind::Linear && axes[j].side == axes[id].side)
            .count()
    };
    let mut order: Vec<AxisId> = (0..axes.len())
        .filter(|&i| axes[i].kind == AxisKind::Linear)
        .collect();
    order.sort_by_key(|&i| {
        let side_rank = match axes[i].side {
            Side::Tool => 0,
            Side::Work => 1,
        };
        (depth(i), side_rank, iso_rank(&axes[i].name))
    });
    order
}

/// Every ISO 230 error of the topology, in canonical order (see [`crate::catalogue`]).
pub fn build_catalogue(axes: &[Axis], squareness_order: &[AxisId]) -> Vec<ErrorTerm> {
    let mut by_iso: Vec<AxisId> = (0..axes.len()).collect();
    by_iso.sort_by_key(|&i| iso_rank(&axes[i].name));
    let mut out = Vec::new();
    let component = |i: AxisId, out: &mut Vec<ErrorTerm>| {
        for motion in six_motions() {
            out.push(ErrorTerm {
                name: component_name(motion, &axes[i].name),
                kind: ErrorKind::Component { axis: i, motion },
            });
        }
    };
    for &i in by_iso.iter().filter(|&&i| axes[i].kind == AxisKind::Linear) {
        component(i, &mut out);
    }
    if let Some(&first) = squareness_order.first() {
        let reference = axes[first].direction.own.dir;
        for (rank, &i) in squareness_order.iter().enumerate() {
            for about in squareness_rotations(rank, axes[i].direction.own.dir, reference) {
                out.push(ErrorTerm {
                    name: location_name(Motion::Rotation(about), &axes[i].name),
                    kind: ErrorKind::Squareness { axis: i, about },
                });
            }
        }
    }
    for along in Dir::ALL {
        out.push(ErrorTerm {
            name: format!("{}OW", along.translation_letter()),
            kind: ErrorKind::Setup { along },
        });
    }
    for &i in by_iso.iter().filter(|&&i| axes[i].kind == AxisKind::Rotary) {
        component(i, &mut out);
        for motion in location_motions(axes[i].direction.own.dir) {
            out.push(ErrorTerm {
                name: location_name(motion, &axes[i].name),
                kind: ErrorKind::Location { axis: i, motion },
            });
        }
    }
    debug_assert!({
        let mut names: Vec<_> = out.iter().map(|e| e.name.clone()).collect();
        names.sort();
        names.windows(2).all(|w| w[0] != w[1])
    });
    out
}
