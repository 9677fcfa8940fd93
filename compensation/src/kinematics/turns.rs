//! The angular location errors of a rotary axis folded into its direction, and the turn this
//! gives to what the axis carries.
//!
//! A rotary axis is composed as `Trans(offset) · Fᵀ · Trans(t) · R · X(θ) · F` with `R =
//! Rx(a)·Ry(b)` its angular location errors about its own `x′ y′`, `X(θ)` its motion (with its
//! component errors) about its own `z′` and `F` its own frame (the identity for an axis along a
//! coordinate direction; [`model_spec::kinematics::chain_steps`]). With `M = Fᵀ·R`, the same
//! product is `Trans(offset + Fᵀt) · M·X(θ)·Mᵀ · Q` with `Q = Fᵀ·R·F`: an axis turning about
//! `M·z` (the folded direction), followed by the constant turn `Q` of everything it carries.
//! The folded direction therefore holds the angular errors exactly only together with `Q`:
//! - an axis it carries is turned too: its direction becomes `Q·d` (with its own angular errors
//!   folded on top), its offset `Q·(links + offset) − links` (the fixed links between stay as
//!   they are), and the turn is passed on;
//! - the ball at the work chain's end keeps its place in the description: the original machine
//!   has it at `Q·(p + w)`, the corrected one at `p + w′`: its set-up `w′ = Q·(p + w) − p` is
//!   what an identification with the corrected description finds, exactly.
//!
//! The description builds an inclined axis's own frame from its direction (`x′` the machine x
//! projected across it), which is `M`'s turned frame up to a turn `γ` about the new direction:
//! `γ = 0` for an axis along z and for an inclined one with no x component (its `x′` is the
//! machine x), first order in the angles otherwise. The axis's motion is exact either way; its
//! component errors then act along directions turned by `γ`, a difference of `γ` times the
//! component error (second order: 10 µrad × 10 µm = 1e-7 mm).

use model_spec::catalogue::Motion;
use model_spec::{AxisDirection, AxisId, AxisKind, Dir, ErrorId, ErrorKind, Link, Machine, Side};
use nalgebra::{Matrix3, Vector3};
use simulation::exact::coordinate_rotation;

/// Whether the corrected description folds angular location errors into axis directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Directions {
    /// Fold them where the description can hold them exactly (see the module documentation of
    /// [`crate::kinematics`]).
    Fold,
    /// Keep every axis direction as written: for a controller whose kinematics has fixed axis
    /// directions (LinuxCNC's trt modules); the angular errors are then listed as not folded.
    Keep,
}

/// An angular location error folded into its axis's direction.
#[derive(Clone, Debug, PartialEq)]
pub struct FoldedAngle {
    /// The error.
    pub error: ErrorId,
    /// Its name (`AOC`).
    pub name: String,
    /// Its value, rad (a rotation about the axis's own `x′` or `y′`).
    pub value_rad: f64,
}

/// An axis whose direction the corrected description turns.
#[derive(Clone, Debug, PartialEq)]
pub struct FoldedDirection {
    /// The axis (`C`).
    pub axis: String,
    /// Its own angular location errors folded here (none for an axis only turned by the axes
    /// that carry it).
    pub errors: Vec<FoldedAngle>,
    /// The axes carrying it whose folded errors turn it as well, from the bed outwards.
    pub carried_by: Vec<String>,
    /// The unit direction before, in machine coordinates.
    pub before: [f64; 3],
    /// The direction written into the corrected description (a unit vector).
    pub after: [f64; 3],
    /// The turn (rad) about the new direction from the exactly turned own frame to the one the
    /// description builds from the direction: the angle by which the axis's component errors
    /// act along other directions than in the original machine.
    pub frame_turn_rad: f64,
}

/// An offset coordinate of a carried axis changed by the turn of the axes that carry it.
#[derive(Clone, Debug, PartialEq)]
pub struct TurnedOffset {
    /// The axis whose offset it is.
    pub axis: String,
    /// The coordinate.
    pub coordinate: Dir,
    /// The axes whose folded angular errors turn it, from the bed outwards.
    pub by: Vec<String>,
    /// The symbol whose default changed; `None` where a number changed or was written.
    pub symbol: Option<String>,
    /// The coordinate before, mm (after the location translations were folded).
    pub before_mm: f64,
    /// The coordinate after, mm.
    pub after_mm: f64,
    /// Where it went, for people (`symbol Zc (offset z of axis C)`).
    pub place: String,
}

/// Why the angular location errors of `axis` cannot be folded into its direction, `None` when
/// they can.
pub fn blocked(m: &Machine, axis: AxisId, directions: Directions) -> Option<String> {
    let a = &m.axes[axis];
    if directions == Directions::Keep {
        return Some(
            "an angular location error: it turns the axis line, and the directions are kept for a controller whose kinematics has fixed axis directions"
                .into(),
        );
    }
    if let Some((what, why)) = cannot_turn(m, axis) {
        return Some(format!(
            "an angular location error of an axis {what}: {why}"
        ));
    }
    if a.side == Side::Tool {
        return Some(format!(
            "an angular location error of an axis on the tool side: the {} end it carries would turn with its line at command zero, which the end's offset in the description does not follow (the angle times the length to the end)",
            m.tool.end_name
        ));
    }
    let chain = m.chain(a.side);
    let at = chain
        .links
        .iter()
        .position(|l| *l == Link::Axis(axis))
        .unwrap_or(chain.links.len());
    for l in &chain.links[at + 1..] {
        if let Link::Axis(b) = l
            && let Some((what, why)) = cannot_turn(m, *b)
        {
            return Some(format!(
                "an angular location error: axis {} carries axis {} ({what}), which would turn with it at command zero: {why}",
                a.name, m.axes[*b].name
            ));
        }
    }
    None
}

/// Why axis `b` cannot be given an inclined direction, as (what it is, why), `None` when it
/// can (a rotary axis along +z or inclined already).
fn cannot_turn(m: &Machine, b: AxisId) -> Option<(&'static str, &'static str)> {
    let a = &m.axes[b];
    if a.kind == AxisKind::Linear {
        return Some((
            "linear",
            "an inclined linear axis has its errors named in its own frame (its positioning error EZ…), which would rename them",
        ));
    }
    match a.direction.as_coordinate() {
        None => None,
        Some(d) if d.dir == Dir::Z && !d.negative => None,
        Some(d) if d.dir == Dir::Z => Some((
            "along -z",
            "as an inclined axis it would turn about +z′ ≈ -z with y′ ≈ -y, which flips the signs of its errors along and about y and z",
        )),
        Some(_) => Some((
            "along x or y",
            "inclined, its errors would be named in its own frame (x′ y′ z′, as those of a C axis), which would rename them and break the models written for it",
        )),
    }
}

/// The rotation `Rx(a)·Ry(b)·Rz(c)` of an axis's angular location errors `angles` (own
/// directions and values, rad).
pub fn location_rotation(m: &Machine, angles: &[FoldedAngle]) -> Matrix3<f64> {
    let mut abc = [0.0; 3];
    for f in angles {
        if let ErrorKind::Location {
            motion: Motion::Rotation(d),
            ..
        } = m.catalogue[f.error].kind
        {
            abc[d.index()] = f.value_rad;
        }
    }
    (coordinate_rotation(Dir::X, abc[0])
        * coordinate_rotation(Dir::Y, abc[1])
        * coordinate_rotation(Dir::Z, abc[2]))
    .into_inner()
}

/// The own frame of `direction` as the matrix whose columns are `x′ y′ z′` (`Fᵀ`).
pub fn frame_columns(direction: &AxisDirection) -> Matrix3<f64> {
    Matrix3::from(direction.frame())
}

/// One axis turned: the folded direction (`M·z` with `M = Q·Fᵀ·R`), the turn about it from `M`'s
/// columns to the frame the description builds, and the turn passed on (`M·F`).
pub struct Turned {
    /// The direction to write (unit, machine coordinates).
    pub direction: AxisDirection,
    /// Its components as written.
    pub written: [f64; 3],
    /// The turn about the new direction between the two frames, rad.
    pub frame_turn_rad: f64,
    /// The turn of what the axis carries.
    pub passed_on: Matrix3<f64>,
}

/// Axis `axis` turned by `q` (the turn of the axes carrying it) and its own location rotation
/// `r`; `None` when the direction the description would build does not read (a direction within
/// rounding of x, whose own frame cannot be formed).
pub fn turn(m: &Machine, axis: AxisId, q: &Matrix3<f64>, r: &Matrix3<f64>) -> Option<Turned> {
    let ft = frame_columns(&m.axes[axis].direction);
    let mm = q * ft * r;
    let z = mm * Vector3::z();
    let written = [z[0] + 0.0, z[1] + 0.0, z[2] + 0.0];
    let direction = AxisDirection::from_vector(written)?;
    let built = frame_columns(&direction);
    // The description's frame is M·Rz(−γ): M's x′ seen in the built frame is (cos γ, sin γ, 0).
    let x = built.transpose() * (mm * Vector3::x());
    Some(Turned {
        direction,
        written,
        frame_turn_rad: x[1].atan2(x[0]),
        passed_on: mm * ft.transpose(),
    })
}

/// `true` when `q` is exactly the identity.
pub fn is_identity(q: &Matrix3<f64>) -> bool {
    *q == Matrix3::identity()
}
