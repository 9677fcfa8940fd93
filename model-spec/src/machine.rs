//! The validated machine: axes, the two kinematic chains, kinematic symbols, the error catalogue
//! and the named sub-models. Built only by [`crate::parse_machine`], so every value here has been
//! checked.

use crate::catalogue::{ErrorId, ErrorTerm};
use crate::geometry::AxisDirection;
use std::collections::BTreeMap;

/// Index of a kinematic symbol in [`Machine::symbols`].
pub type SymbolId = usize;
/// Index of an axis in [`Machine::axes`].
pub type AxisId = usize;

/// A kinematic symbol: a named offset (mm) with the value used when none is given.
#[derive(Clone, Debug, PartialEq)]
pub struct Symbol {
    /// The name, as written in the description (`Xw`, `Zc`, …).
    pub name: String,
    /// Default value, mm.
    pub default: f64,
}

/// One coordinate of a kinematic offset: a number (mm) or a named symbol.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A fixed number, mm.
    Number(f64),
    /// A kinematic symbol, by index into [`Machine::symbols`].
    Symbol(SymbolId),
}

impl Value {
    /// `true` for the number zero.
    pub fn is_zero(&self) -> bool {
        matches!(self, Value::Number(x) if *x == 0.0)
    }
}

/// A fixed translation `[x, y, z]` (mm) between two frames.
pub type Offset = [Value; 3];

/// Linear (prismatic) or rotary axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisKind {
    /// Moves along its direction; commands in mm.
    Linear,
    /// Turns about its direction; commands in degrees at every boundary a person sees, radians inside.
    Rotary,
}

/// Which kinematic chain an axis or link belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// From the bed to the workpiece (the R-test ball).
    Work,
    /// From the bed to the tool point (the R-test sensor nest).
    Tool,
}

/// A servo axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// One upper-case letter (`X`, `A`, …).
    pub name: String,
    /// Linear or rotary.
    pub kind: AxisKind,
    /// Direction of motion (linear) or of the rotation vector (rotary) for a positive command:
    /// a signed coordinate direction or an inclined direction with its own frame.
    pub direction: AxisDirection,
    /// Offset of the axis frame from the previous frame of its chain at command zero (mm).
    pub offset: Offset,
    /// Allowed commands `[min, max]`: mm for linear axes, degrees for rotary axes.
    /// A rotary axis without limits has `[-inf, inf]`.
    pub limits: [f64; 2],
    /// The chain it is on.
    pub side: Side,
}

/// An element of a kinematic chain, from the bed outwards.
#[derive(Clone, Debug, PartialEq)]
pub enum Link {
    /// A servo axis, by index into [`Machine::axes`].
    Axis(AxisId),
    /// A rigid part (spindle holder, fixture) that only translates.
    Fixed {
        /// Its name, for people.
        name: String,
        /// Translation from the previous frame (mm).
        offset: Offset,
    },
}

/// A kinematic chain from the bed to one end (the workpiece or the tool point).
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    /// The links from the bed outwards, the end excluded.
    pub links: Vec<Link>,
    /// The name of the end (`ball`, `probe`, …).
    pub end_name: String,
    /// Translation of the end point from the last frame (mm).
    pub end_offset: Offset,
}

impl Chain {
    /// The axes of the chain, from the bed outwards.
    pub fn axes(&self) -> impl Iterator<Item = AxisId> + '_ {
        self.links.iter().filter_map(|l| match l {
            Link::Axis(a) => Some(*a),
            Link::Fixed { .. } => None,
        })
    }
}

/// A named sub-model: terms over a subset of the machine's errors (and the R-test's sensor
/// offsets).
#[derive(Clone, Debug, PartialEq)]
pub struct SubModel {
    /// What it is for, for people.
    pub description: String,
    /// The machine errors its terms use, in catalogue order, each once.
    pub errors: Vec<ErrorId>,
    /// Its terms in the order written: `NAME` is the constant term of an error, `NAME@BASIS` a
    /// position-, direction- or time-dependent one ([`crate::terms`]).
    pub terms: Vec<crate::terms::Term>,
}

/// A validated machine description.
#[derive(Clone, Debug, PartialEq)]
pub struct Machine {
    /// Short name (`seed-ac`).
    pub name: String,
    /// What the machine is, for people.
    pub description: String,
    /// Kinematic symbols with their defaults (mm), in the order of the description.
    pub symbols: Vec<Symbol>,
    /// All servo axes, work chain first, each chain from the bed outwards.
    pub axes: Vec<Axis>,
    /// Bed → workpiece.
    pub work: Chain,
    /// Bed → tool point.
    pub tool: Chain,
    /// Every ISO 230 error the topology has, in canonical order (see [`crate::catalogue`]).
    pub catalogue: Vec<ErrorTerm>,
    /// The errors of the machine's full model (default: the whole catalogue), in catalogue order.
    pub errors: Vec<ErrorId>,
    /// Named sub-models (`reduced`, …).
    pub models: BTreeMap<String, SubModel>,
    /// Order of the linear axes used by the squareness rule (reference axis first).
    pub squareness_order: Vec<AxisId>,
}

/// The name of the full model of every machine.
pub const FULL_MODEL: &str = "full";

impl Machine {
    /// The axis called `name`.
    pub fn axis_by_name(&self, name: &str) -> Option<AxisId> {
        self.axes.iter().position(|a| a.name == name)
    }

    /// The symbol called `name`.
    pub fn symbol_by_name(&self, name: &str) -> Option<SymbolId> {
        self.symbols.iter().position(|s| s.name == name)
    }

    /// The catalogue entry called `name` (the digit-zero spelling `X0C` is accepted).
    pub fn error_by_name(&self, name: &str) -> Option<ErrorId> {
        let canonical = crate::catalogue::canonical_name(name);
        self.catalogue.iter().position(|e| e.name == canonical)
    }

    /// The chain on `side`.
    pub fn chain(&self, side: Side) -> &Chain {
        match side {
            Side::Work => &self.work,
            Side::Tool => &self.tool,
        }
    }

    /// Default values of all kinematic symbols (mm), in symbol order.
    pub fn default_parameters(&self) -> Vec<f64> {
        self.symbols.iter().map(|s| s.default).collect()
    }

    /// The errors of the model `name`: [`FULL_MODEL`] or a sub-model.
    pub fn model_errors(&self, name: &str) -> Option<&[ErrorId]> {
        if name == FULL_MODEL {
            Some(&self.errors)
        } else {
            self.models.get(name).map(|m| m.errors.as_slice())
        }
    }

    /// Names of all models: [`FULL_MODEL`] first, then the sub-models in name order.
    pub fn model_names(&self) -> Vec<&str> {
        std::iter::once(FULL_MODEL)
            .chain(self.models.keys().map(String::as_str))
            .collect()
    }

    /// The rotary axes, in axis order.
    pub fn rotary_axes(&self) -> impl Iterator<Item = AxisId> + '_ {
        (0..self.axes.len()).filter(|&i| self.axes[i].kind == AxisKind::Rotary)
    }

    /// The linear axes, in axis order.
    pub fn linear_axes(&self) -> impl Iterator<Item = AxisId> + '_ {
        (0..self.axes.len()).filter(|&i| self.axes[i].kind == AxisKind::Linear)
    }
}
