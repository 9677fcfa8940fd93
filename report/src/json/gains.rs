//! The gain tables as JSON (`rtest gains --format json`): the symbolic table of a model, and
//! the numbers at one pose.

use super::{NonFinite, Ordered, finite};
use codegen::GainModel;
use codegen::atoms::AtomKind;
use codegen::table::format_poly;
use model_spec::units::short;
use model_spec::{AxisKind, Machine};
use serde::Serialize;

/// What the columns of a gain table mean.
pub const GAIN_UNITS: &str = "error vector = tool point minus workpiece point, tool frame, first order; dX dY dZ in mm per mm of a translational error or mm per rad of an angular error; dI dJ dK per mm or per rad";

/// The symbolic gain table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GainTableReport {
    /// Machine name.
    pub machine: String,
    /// The model's name; `null` for an explicit list of errors.
    pub model: Option<String>,
    /// What the columns mean ([`GAIN_UNITS`]).
    pub units: String,
    /// `dX dY dZ dI dJ dK`.
    pub columns: Vec<String>,
    /// What every atom of the formulas stands for.
    pub atoms: Ordered<String>,
    /// Per error, in model order: the six formulas.
    pub gains: Ordered<Vec<String>>,
}

/// What each atom of a model's formulas stands for (`Sa`: sine of the A command, `Zc`:
/// kinematic parameter, mm (default 29.794)).
pub fn atom_legend(m: &Machine, model: &GainModel) -> Vec<(String, String)> {
    model
        .atoms
        .kinds
        .iter()
        .zip(&model.atoms.names)
        .map(|(k, name)| {
            let meaning = match *k {
                AtomKind::Sin(a) => format!("sine of the {} command", m.axes[a].name),
                AtomKind::Cos(a) => format!("cosine of the {} command", m.axes[a].name),
                AtomKind::Command(a) => format!("{} command, mm", m.axes[a].name),
                AtomKind::Symbol(s) => format!(
                    "kinematic parameter, mm (default {})",
                    short(m.symbols[s].default)
                ),
                AtomKind::Root(p) => format!("the square root of {p} (an inclined axis's frame)"),
                AtomKind::Constant(bits) => format!(
                    "a numeric entry of an inclined axis's frame ({})",
                    short(f64::from_bits(bits))
                ),
            };
            (name.clone(), meaning)
        })
        .collect()
}

impl GainTableReport {
    /// The table of `model` of `m` (named `model_name`, `None` for a list of errors).
    pub fn new(m: &Machine, model_name: Option<&str>, model: &GainModel) -> GainTableReport {
        GainTableReport {
            machine: m.name.clone(),
            model: model_name.map(str::to_string),
            units: GAIN_UNITS.into(),
            columns: ["dX", "dY", "dZ", "dI", "dJ", "dK"]
                .map(String::from)
                .to_vec(),
            atoms: Ordered(atom_legend(m, model)),
            gains: Ordered(
                model
                    .error_names
                    .iter()
                    .zip(&model.gains)
                    .map(|(name, g)| {
                        let cells = g
                            .iter()
                            .map(|p| format_poly(p, &model.atoms.names, false))
                            .collect();
                        (name.clone(), cells)
                    })
                    .collect(),
            ),
        }
    }
}

/// A gain at a pose: written `0` (a JSON integer) when it is zero, else the shortest decimal
/// that reads back to the same `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gain(pub f64);

impl Serialize for Gain {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.0 == 0.0 {
            s.serialize_u64(0)
        } else {
            s.serialize_f64(self.0)
        }
    }
}

/// The pose the gains were evaluated at.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseReport {
    /// Every axis, in axis order: linear mm, rotary degrees (as given, or as the inverse
    /// kinematics filled them).
    pub commands: Ordered<f64>,
    /// The linear axes the inverse kinematics filled (left out of `--at`), in axis order.
    pub filled_by_inverse_kinematics: Vec<String>,
    /// Every kinematic parameter, mm.
    pub parameters: Ordered<f64>,
    /// Distance from the nominal tool point to the nominal workpiece point, mm (0 to rounding
    /// on the ball).
    pub tool_point_to_workpiece_point: f64,
}

/// The units of every number of a [`PoseGainsReport`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseGainUnits {
    /// Per axis: `mm` or `deg`.
    pub commands: Ordered<String>,
    /// `mm`.
    pub parameters: String,
    /// `mm`.
    pub tool_point_to_workpiece_point: String,
    /// What `position` holds and in which unit (each row also says it).
    pub position: String,
    /// What `orientation` holds and in which unit (each row also says it).
    pub orientation: String,
}

/// The gains of one error at the pose.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseGainRow {
    /// `translational` or `angular`.
    pub kind: String,
    /// `[gx, gy, gz]`: the error vector per unit of the error, tool frame.
    pub position: [Gain; 3],
    /// `mm/mm` (translational) or `mm/rad` (angular).
    pub position_unit: String,
    /// `[gi, gj, gk]`: the change of the tool axis (a unit vector) per unit of the error.
    pub orientation: [Gain; 3],
    /// `1/mm` (translational) or `1/rad` (angular).
    pub orientation_unit: String,
}

/// The gains at one pose (`rtest gains --at … --format json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseGainsReport {
    /// Machine name.
    pub machine: String,
    /// The model's name; `null` for an explicit list of errors.
    pub model: Option<String>,
    /// The pose.
    pub pose: PoseReport,
    /// The units of every number.
    pub units: PoseGainUnits,
    /// What the error vector is.
    pub error_vector: String,
    /// How the zeros are decided.
    pub zeros: String,
    /// Per error, in model order.
    pub gains: Ordered<PoseGainRow>,
    /// The gains that are not identically zero but vanish at this pose (within the bound on
    /// the rounding error of their evaluation), as `ERROR gx` … `ERROR gk`; written `0`.
    pub vanishing_at_this_pose: Vec<String>,
}

/// The gains at one pose, error by error.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseGains<'a> {
    /// The error names, model order.
    pub names: &'a [String],
    /// `true` for angular errors.
    pub angular: &'a [bool],
    /// `[gx, gy, gz, gi, gj, gk]` per error (mm/mm, mm/rad; 1/mm, 1/rad).
    pub gains: &'a [[f64; 6]],
    /// `ERROR gx` … for the gains that vanish at this pose though not identically.
    pub vanishing: Vec<String>,
    /// How the zeros are decided.
    pub zeros: String,
}

impl PoseGainsReport {
    /// The report of `g` for machine `m` (model `model`, `None` for a list of errors) at
    /// `pose`.
    ///
    /// # Errors
    /// [`NonFinite`] when a gain, a command or the distance to the ball is not finite.
    pub fn new(
        m: &Machine,
        model: Option<&str>,
        pose: &simulation::pose::Pose,
        g: &PoseGains<'_>,
    ) -> Result<PoseGainsReport, NonFinite> {
        let mut rows = Vec::with_capacity(g.names.len());
        for ((n, &ang), v) in g.names.iter().zip(g.angular).zip(g.gains) {
            let mut out = [Gain(0.0); 6];
            for d in 0..6 {
                out[d] = Gain(finite(|| format!("{n} {}", COLUMNS[d]), v[d])?);
            }
            rows.push((
                n.clone(),
                PoseGainRow {
                    kind: if ang { "angular" } else { "translational" }.into(),
                    position: [out[0], out[1], out[2]],
                    position_unit: if ang { "mm/rad" } else { "mm/mm" }.into(),
                    orientation: [out[3], out[4], out[5]],
                    orientation_unit: if ang { "1/rad" } else { "1/mm" }.into(),
                },
            ));
        }
        let mut commands = Vec::with_capacity(m.axes.len());
        for (a, &v) in m.axes.iter().zip(&pose.shown) {
            commands.push((a.name.clone(), finite(|| a.name.clone(), v)?));
        }
        let units = m
            .axes
            .iter()
            .map(|a| {
                let u = match a.kind {
                    AxisKind::Linear => "mm",
                    AxisKind::Rotary => "deg",
                };
                (a.name.clone(), u.to_string())
            })
            .collect();
        Ok(PoseGainsReport {
            machine: m.name.clone(),
            model: model.map(str::to_string),
            pose: PoseReport {
                commands: Ordered(commands),
                filled_by_inverse_kinematics: m
                    .axes
                    .iter()
                    .zip(&pose.from_ik)
                    .filter(|(_, f)| **f)
                    .map(|(a, _)| a.name.clone())
                    .collect(),
                parameters: Ordered(
                    m.symbols
                        .iter()
                        .zip(&pose.params)
                        .map(|(s, &v)| (s.name.clone(), v))
                        .collect(),
                ),
                tool_point_to_workpiece_point: finite(
                    || "tool_point_to_workpiece_point".into(),
                    pose.gap_mm,
                )?,
            },
            units: PoseGainUnits {
                commands: Ordered(units),
                parameters: "mm".into(),
                tool_point_to_workpiece_point: "mm".into(),
                position: "error vector per unit of the error: mm/mm for a translational error, mm/rad for an angular one (1 mm/rad = 1 µm per mrad)".into(),
                orientation: "change of the tool axis (a unit vector) per unit of the error: 1/mm for a translational error, 1/rad for an angular one".into(),
            },
            error_vector: "tool point minus workpiece point, tool frame, first order".into(),
            zeros: g.zeros.clone(),
            gains: Ordered(rows),
            vanishing_at_this_pose: g.vanishing.clone(),
        })
    }
}

/// The names of the six gains of a row, as `vanishing_at_this_pose` and errors spell them.
pub const COLUMNS: [&str; 6] = ["gx", "gy", "gz", "gi", "gj", "gk"];
